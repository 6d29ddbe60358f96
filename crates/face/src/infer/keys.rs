//! Keyframe files for `face edit --keys`: expressions to reach at given times.
//!
//! JSON: `{"keys": [{"time_s": 4.5, "shapes": {"JawOpen": 0.8, "MouthSmileLeft": 0.6}}, …]}` (a bare
//! array of keys is accepted too). CSV: a header `time_s,<shape>,…` naming any subset of the ARKit
//! shapes, one row per key. Shapes a key leaves out keep the input animation's value at that time, so
//! a key can correct the mouth and leave the eyes as captured. Times are seconds from the clip's first
//! frame; values must lie in [0, 1].

use std::path::Path;

use crate::data::text::{at, column, fields, lines, number, read_text};
use crate::data::{arkit_index, FaceError, ARKIT_NAMES};

/// One key: a time and the shapes it sets.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyPose {
    /// Seconds from the clip's first frame.
    pub time_s: f64,
    /// `(ARKit index, weight)` pairs.
    pub shapes: Vec<(usize, f32)>,
}

/// Reads a keys file, JSON or CSV by extension.
pub fn read_keys(path: &Path) -> Result<Vec<KeyPose>, FaceError> {
    let text = read_text(path)?;
    let file = path.display().to_string();
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json")) {
        parse_keys_json(&text, &file)
    } else {
        parse_keys_csv(&text, &file)
    }
}

fn check_value(v: f64) -> Result<f32, String> {
    if v.is_finite() && (0.0..=1.0).contains(&v) {
        Ok(v as f32)
    } else {
        Err(format!("weight {v} lies outside [0, 1]"))
    }
}

fn check_time(t: f64) -> Result<f64, String> {
    if t.is_finite() && t >= 0.0 {
        Ok(t)
    } else {
        Err(format!("time {t} s must be a finite number of seconds, at least 0"))
    }
}

/// What a keys JSON file must look like, for messages.
const JSON_FORM: &str = r#"{"keys": [{"time_s": 1.5, "shapes": {"JawOpen": 0.8}}, …]}"#;

/// A JSON value's kind, for messages ("a string", "the number 1").
fn kind_of(v: &serde_json::Value) -> String {
    use serde_json::Value;
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("{b}"),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) => {
            let short: String = s.chars().take(40).collect();
            let more = if s.chars().count() > 40 { "…" } else { "" };
            format!("the string \"{short}{more}\"")
        }
        Value::Array(_) => "an array".into(),
        Value::Object(_) => "an object".into(),
    }
}

/// Parses the JSON form; `file` names it in errors. The top level is `{"keys": [...]}` or a bare
/// array of keys; every key is `{"time_s": seconds, "shapes": {name: weight, …}}`.
pub fn parse_keys_json(text: &str, file: &str) -> Result<Vec<KeyPose>, FaceError> {
    use serde_json::Value;
    let bad = |message: String| FaceError::File { file: file.into(), message };
    let parsed: Value = serde_json::from_str(text).map_err(|e| {
        // serde_json reports line 0 only for errors not tied to a position; name line 1 then.
        FaceError::parse(file, e.line().max(1), None, format!("{e}; expected {JSON_FORM}"))
    })?;
    let keys = match parsed {
        Value::Array(keys) => keys,
        Value::Object(mut top) => {
            if let Some(other) = top.keys().find(|k| k.as_str() != "keys") {
                return Err(bad(format!("unknown field '{other}' at the top level; expected {JSON_FORM}")));
            }
            match top.remove("keys") {
                Some(Value::Array(keys)) => keys,
                Some(other) => return Err(bad(format!("\"keys\" is {}; expected an array of keys", kind_of(&other)))),
                None => return Err(bad(format!("an object without \"keys\"; expected {JSON_FORM}"))),
            }
        }
        other => return Err(bad(format!("the file holds {}; expected {JSON_FORM}", kind_of(&other)))),
    };
    if keys.is_empty() {
        return Err(bad("no keys; expected at least one".into()));
    }
    keys.into_iter()
        .enumerate()
        .map(|(i, k)| {
            let k = match k {
                Value::Object(k) => k,
                other => {
                    return Err(bad(format!(
                        "key {i} is {}; expected an object {{\"time_s\": 1.5, \"shapes\": {{\"JawOpen\": 0.8}}}}",
                        kind_of(&other)
                    )))
                }
            };
            if let Some(other) = k.keys().find(|f| !matches!(f.as_str(), "time_s" | "shapes")) {
                return Err(bad(format!("key {i}: unknown field '{other}'; expected \"time_s\" and \"shapes\"")));
            }
            let time_s = match k.get("time_s") {
                Some(Value::Number(n)) => n.as_f64().unwrap_or(f64::NAN),
                Some(other) => {
                    return Err(bad(format!("key {i}: \"time_s\" is {}; expected a number of seconds", kind_of(other))))
                }
                None => return Err(bad(format!("key {i} has no \"time_s\"; expected a number of seconds"))),
            };
            let time_s = check_time(time_s).map_err(|m| bad(format!("key {i}: {m}")))?;
            let shapes = match k.get("shapes") {
                Some(Value::Object(shapes)) => shapes,
                Some(other) => {
                    return Err(bad(format!(
                        "key {i}: \"shapes\" is {}; expected an object of ARKit names and weights",
                        kind_of(other)
                    )))
                }
                None => return Err(bad(format!("key {i} has no \"shapes\"; expected {{\"JawOpen\": 0.8, …}}"))),
            };
            let mut out = Vec::with_capacity(shapes.len());
            for (name, v) in shapes {
                let c = arkit_index(name)
                    .ok_or_else(|| bad(format!("key {i}: '{name}' is not an ARKit blendshape name")))?;
                if out.iter().any(|(d, _)| *d == c) {
                    return Err(bad(format!("key {i}: '{}' is set twice", ARKIT_NAMES[c])));
                }
                let Value::Number(n) = v else {
                    return Err(bad(format!("key {i}: {name} is {}; expected a weight in [0, 1]", kind_of(v))));
                };
                let w =
                    check_value(n.as_f64().unwrap_or(f64::NAN)).map_err(|m| bad(format!("key {i}: {name}: {m}")))?;
                out.push((c, w));
            }
            if out.is_empty() {
                return Err(bad(format!("key {i} sets no shape")));
            }
            Ok(KeyPose { time_s, shapes: out })
        })
        .collect()
}

/// Parses the CSV form; `file` names it in errors.
pub fn parse_keys_csv(text: &str, file: &str) -> Result<Vec<KeyPose>, FaceError> {
    let mut rows = lines(text).filter(|(_, l)| !l.trim_start().starts_with('#'));
    let Some((hline, header)) = rows.next() else {
        return Err(FaceError::Empty {
            file: file.into(),
            expected: "a header 'time_s,<shape>,…' and one row per key".into(),
        });
    };
    let names = fields(header);
    if !names[0].eq_ignore_ascii_case("time_s") {
        return Err(at(file, hline, column(&names, 0), "expected 'time_s' as the first column"));
    }
    let mut channels = Vec::new();
    for (i, name) in names.iter().enumerate().skip(1) {
        let c = arkit_index(name)
            .ok_or_else(|| at(file, hline, column(&names, i), format!("'{name}' is not an ARKit blendshape name")))?;
        if channels.contains(&c) {
            return Err(at(file, hline, column(&names, i), format!("'{}' appears twice", ARKIT_NAMES[c])));
        }
        channels.push(c);
    }
    if channels.is_empty() {
        return Err(at(file, hline, None, "the header names no shape; expected 'time_s,<shape>,…'"));
    }
    let mut keys = Vec::new();
    for (line, row) in rows {
        let f = fields(row);
        if f.len() != names.len() {
            return Err(at(file, line, None, format!("{} fields, the header has {}", f.len(), names.len())));
        }
        let time_s = number::<f64>(f[0]).and_then(check_time).map_err(|m| at(file, line, column(&names, 0), m))?;
        let mut shapes = Vec::new();
        for (i, c) in channels.iter().enumerate() {
            if f[i + 1].is_empty() {
                continue; // an empty cell leaves the shape free
            }
            let v =
                number::<f64>(f[i + 1]).and_then(check_value).map_err(|m| at(file, line, column(&names, i + 1), m))?;
            shapes.push((*c, v));
        }
        keys.push(KeyPose { time_s, shapes });
    }
    if keys.is_empty() {
        return Err(FaceError::Empty { file: file.into(), expected: "at least one key row after the header".into() });
    }
    Ok(keys)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_and_csv_forms_read_the_same_keys() {
        let j = parse_keys_json(r#"{"keys":[{"time_s":1.5,"shapes":{"JawOpen":0.8,"eyeBlinkLeft":1}}]}"#, "k.json")
            .unwrap();
        let c = parse_keys_csv("time_s,EyeBlinkLeft,JawOpen\n1.5,1,0.8\n", "k.csv").unwrap();
        let mut a = j[0].shapes.clone();
        let mut b = c[0].shapes.clone();
        a.sort_by_key(|s| s.0);
        b.sort_by_key(|s| s.0);
        assert_eq!((j[0].time_s, a), (c[0].time_s, b));
        assert_eq!(parse_keys_json(r#"[{"time_s":0,"shapes":{"JawOpen":0}}]"#, "k.json").unwrap().len(), 1);
    }

    #[test]
    fn bad_keys_name_file_line_and_column() {
        let e = parse_keys_csv("time_s,JawOpen\n1.0,1.5\n", "k.csv").unwrap_err().to_string();
        assert!(e.starts_with("k.csv:2: column 2 (JawOpen)") && e.contains("outside [0, 1]"), "{e}");
        let e = parse_keys_csv("time_s,Smile\n", "k.csv").unwrap_err().to_string();
        assert!(e.contains("k.csv:1") && e.contains("'Smile'"), "{e}");
        let e = parse_keys_csv("time_s,JawOpen\n", "k.csv").unwrap_err().to_string();
        assert!(e.contains("at least one key"), "{e}");
        let e =
            parse_keys_json(r#"{"keys":[{"time_s":-1,"shapes":{"JawOpen":0.5}}]}"#, "k.json").unwrap_err().to_string();
        assert!(e.contains("k.json") && e.contains("key 0"), "{e}");
        let e = parse_keys_json("{\n\"keys\": [1,", "k.json").unwrap_err().to_string();
        assert!(e.starts_with("k.json:2"), "{e}");
        assert!(parse_keys_csv("", "k.csv").is_err());
    }
}
