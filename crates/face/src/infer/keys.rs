//! Keyframe files for `face edit --keys`: expressions to reach at given times.
//!
//! JSON: `{"keys": [{"time_s": 4.5, "shapes": {"JawOpen": 0.8, "MouthSmileLeft": 0.6}}, …]}` (a bare
//! array of keys is accepted too). CSV: a header `time_s,<shape>,…` naming any subset of the ARKit
//! shapes, one row per key. Shapes a key leaves out keep the input animation's value at that time, so
//! a key can correct the mouth and leave the eyes as captured. Times are seconds from the clip's first
//! frame; values must lie in [0, 1].

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;

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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyJson {
    time_s: f64,
    shapes: BTreeMap<String, f64>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum KeysJson {
    Wrapped { keys: Vec<KeyJson> },
    Bare(Vec<KeyJson>),
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

/// Parses the JSON form; `file` names it in errors.
pub fn parse_keys_json(text: &str, file: &str) -> Result<Vec<KeyPose>, FaceError> {
    let bad = |message: String| FaceError::File { file: file.into(), message };
    let parsed: KeysJson = serde_json::from_str(text).map_err(|e| {
        FaceError::parse(
            file,
            e.line(),
            None,
            format!("{e}; expected {{\"keys\": [{{\"time_s\": 1.5, \"shapes\": {{\"JawOpen\": 0.8}}}}]}}"),
        )
    })?;
    let keys = match parsed {
        KeysJson::Wrapped { keys } | KeysJson::Bare(keys) => keys,
    };
    if keys.is_empty() {
        return Err(bad("no keys; expected at least one".into()));
    }
    keys.into_iter()
        .enumerate()
        .map(|(i, k)| {
            let time_s = check_time(k.time_s).map_err(|m| bad(format!("key {i}: {m}")))?;
            let shapes = k
                .shapes
                .iter()
                .map(|(name, v)| {
                    let c = arkit_index(name)
                        .ok_or_else(|| bad(format!("key {i}: '{name}' is not an ARKit blendshape name")))?;
                    Ok((c, check_value(*v).map_err(|m| bad(format!("key {i}: {name}: {m}")))?))
                })
                .collect::<Result<Vec<_>, FaceError>>()?;
            if shapes.is_empty() {
                return Err(bad(format!("key {i} sets no shape")));
            }
            Ok(KeyPose { time_s, shapes })
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
