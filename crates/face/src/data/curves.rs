//! The plain curve format, CSV or JSON: frame times in seconds plus named channels.
//!
//! CSV (`.csv`): an optional `# fps=25` comment (other `#` lines are ignored), then a header
//! `time_s,<name>,…` and one row per frame:
//!
//! ```text
//! # fps=25
//! time_s,EyeBlinkLeft,EyeLookDownLeft,…,TongueOut
//! 0,0.012,0.3,…,0
//! 0.04,0.013,0.31,…,0
//! ```
//!
//! JSON (`.json`):
//!
//! ```json
//! {"fps":25.0,"time_s":[0.0,0.04],"channels":[{"name":"EyeBlinkLeft","values":[0.012,0.013]}, …]}
//! ```
//!
//! Columns/channels are matched by name in any order (ARKit and head/eye names case-insensitively):
//! all 52 ARKit names required, the 9 head/eye names all or none, any other name kept as an extra
//! channel. Without `fps` the nominal rate is `1 / median(Δt)` rounded to 0.001 (60 for one frame).
//! The writers emit every channel in clip order with shortest round-trip numbers, so reading gives
//! back the same clip.

use super::clip::{BlendshapeClip, Layout};
use super::text::{at, column, fields, lines, number, push_time, push_value, read_text};
use super::LIVE_LINK_FPS;
use crate::error::{shown, FaceError};
use serde::{Deserialize, Serialize};
use std::path::Path;

const EXPECTED_HEADER: &str = "a header line 'time_s,' followed by channel names (all 52 ARKit names required)";

/// The JSON form.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CurveFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fps: Option<f64>,
    time_s: Vec<f64>,
    channels: Vec<NamedCurve>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct NamedCurve {
    name: String,
    /// `f64` on purpose: serde_json reads an `f32` through `f64`, and the shortest `f32` text can then
    /// round twice to a neighbouring `f32`; the exact `f64` of each `f32` reads back bit-identical.
    values: Vec<f64>,
}

/// `1 / median(Δt)` rounded to 0.001; 60 for a single frame.
fn estimate_fps(times: &[f64]) -> f64 {
    if times.len() < 2 {
        return LIVE_LINK_FPS;
    }
    let mut dt: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_by(f64::total_cmp);
    let fps = ((1.0 / dt[dt.len() / 2]) * 1000.0).round() / 1000.0;
    if fps.is_finite() && fps > 0.0 {
        fps
    } else {
        LIVE_LINK_FPS
    }
}

/// Parses curve CSV text; `file` names it in errors.
pub fn parse_curve_csv(text: &str, file: &str) -> Result<BlendshapeClip, FaceError> {
    let mut fps: Option<f64> = None;
    let mut header: Option<(usize, Vec<&str>)> = None;
    let mut layout: Option<Layout> = None;
    let mut times: Vec<f64> = Vec::new();
    let mut values: Vec<f32> = Vec::new();
    let mut prev_line = 0;
    for (line, l) in lines(text) {
        let trimmed = l.trim_start();
        if let Some(comment) = trimmed.strip_prefix('#') {
            if let Some(v) = comment.trim().strip_prefix("fps=") {
                let v = v.trim();
                match v.parse::<f64>() {
                    Ok(x) if x.is_finite() && x > 0.0 => fps = Some(x),
                    _ => {
                        return Err(at(
                            file,
                            line,
                            None,
                            format!("expected '# fps=<positive number>', found fps {}", shown(v)),
                        ))
                    }
                }
            }
            continue;
        }
        let Some((_, head)) = &header else {
            let h = fields(l);
            if !h[0].eq_ignore_ascii_case("time_s") {
                return Err(at(file, line, column(&[], 0), format!("expected header 'time_s', found {}", shown(h[0]))));
            }
            let lay = Layout::from_names(&h[1..], |_| true)
                .map_err(|(c, m)| at(file, line, c.and_then(|c| column(&h, c + 1)), m))?;
            header = Some((line, h));
            layout = Some(lay);
            continue;
        };
        let lay = layout.as_ref().expect("set with the header");
        let row = fields(l);
        if row.len() != head.len() {
            return Err(at(
                file,
                line,
                None,
                format!(
                    "expected {} fields as in the header (time_s and {} channels), found {}",
                    head.len(),
                    head.len() - 1,
                    row.len()
                ),
            ));
        }
        let t: f64 = number(row[0]).map_err(|m| at(file, line, column(head, 0), m))?;
        if let Some(&p) = times.last() {
            if t <= p {
                return Err(at(
                    file,
                    line,
                    column(head, 0),
                    format!("time {t} s is not after {p} s on line {prev_line}; expected strictly increasing times"),
                ));
            }
        }
        let stride = lay.stride();
        let base = values.len();
        values.resize(base + stride, 0.0);
        for (c, f) in row[1..].iter().enumerate() {
            let v: f32 = number(f).map_err(|m| at(file, line, column(head, c + 1), m))?;
            values[base + lay.slot[c]] = v;
        }
        times.push(t);
        prev_line = line;
    }
    let (Some((hline, _)), Some(lay)) = (header, layout) else {
        return Err(FaceError::Empty { file: file.into(), expected: EXPECTED_HEADER.into() });
    };
    if times.is_empty() {
        return Err(at(file, hline, None, "expected at least one data row after the header, found none"));
    }
    let fps = fps.unwrap_or_else(|| estimate_fps(&times));
    BlendshapeClip::new(fps, times, lay.head_eye, lay.extras, values)
        .map_err(|e| FaceError::File { file: file.into(), message: e.to_string() })
}

/// Parses curve JSON text; `file` names it in errors.
pub fn parse_curve_json(text: &str, file: &str) -> Result<BlendshapeClip, FaceError> {
    if text.trim().is_empty() {
        return Err(FaceError::Empty {
            file: file.into(),
            expected: "a JSON object {\"time_s\": […], \"channels\": […]}".into(),
        });
    }
    let cf: CurveFile = serde_json::from_str(text).map_err(|e| {
        FaceError::parse(
            file,
            e.line(),
            Some(super::Column { index: e.column(), name: String::new() }),
            format!("{e}; expected {{\"fps\": number (optional), \"time_s\": [numbers], \"channels\": [{{\"name\": text, \"values\": [numbers]}}]}}"),
        )
    })?;
    let to_file = |e: FaceError| FaceError::File { file: file.into(), message: e.to_string() };
    if let Some(f) = cf.fps {
        if !(f.is_finite() && f > 0.0) {
            return Err(to_file(FaceError::clip(format!("fps must be a positive number, got {f}"))));
        }
    }
    let fps = cf.fps.unwrap_or_else(|| estimate_fps(&cf.time_s));
    let channels =
        cf.channels.into_iter().map(|c| (c.name, c.values.into_iter().map(|v| v as f32).collect())).collect();
    BlendshapeClip::from_named(fps, cf.time_s, channels).map_err(to_file)
}

/// Reads a curve file, CSV or JSON by extension (`.json` is JSON, anything else CSV).
pub fn read_curves(path: &Path) -> Result<BlendshapeClip, FaceError> {
    let text = read_text(path)?;
    let file = path.display().to_string();
    if is_json(path) {
        parse_curve_json(&text, &file)
    } else {
        parse_curve_csv(&text, &file)
    }
}

fn is_json(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// Curve CSV text of a clip (with its `# fps=` line).
pub fn to_curve_csv_string(clip: &BlendshapeClip) -> String {
    let names = clip.channel_names();
    let mut out = String::with_capacity(clip.num_frames() * names.len() * 12 + 1024);
    out.push_str("# fps=");
    push_time(&mut out, clip.fps());
    out.push_str("\ntime_s");
    for n in &names {
        out.push(',');
        out.push_str(n);
    }
    out.push('\n');
    for f in 0..clip.num_frames() {
        push_time(&mut out, clip.times()[f]);
        for &v in clip.frame(f) {
            out.push(',');
            push_value(&mut out, v);
        }
        out.push('\n');
    }
    out
}

/// Curve JSON text of a clip.
pub fn to_curve_json_string(clip: &BlendshapeClip) -> String {
    let cf = CurveFile {
        fps: Some(clip.fps()),
        time_s: clip.times().to_vec(),
        channels: clip
            .channel_names()
            .iter()
            .enumerate()
            .map(|(c, n)| NamedCurve {
                name: n.to_string(),
                values: clip.channel(c).into_iter().map(f64::from).collect(),
            })
            .collect(),
    };
    let mut s = serde_json::to_string(&cf).expect("finite numbers and string keys always serialise");
    s.push('\n');
    s
}

/// Writes a curve file, CSV or JSON by extension, atomically (temp file + rename).
pub fn write_curves(path: &Path, clip: &BlendshapeClip) -> Result<(), FaceError> {
    let text = if is_json(path) { to_curve_json_string(clip) } else { to_curve_csv_string(clip) };
    inbetween_io::write_atomic(path, text.as_bytes())
        .map_err(|source| FaceError::Io { file: path.display().to_string(), source })
}

#[cfg(test)]
mod tests {
    use super::super::livelink::tests::generated;
    use super::super::names::ARKIT_NAMES;
    use super::*;

    fn header() -> String {
        let mut h = String::from("time_s");
        for n in ARKIT_NAMES.iter().rev() {
            h.push(',');
            h.push_str(n);
        }
        h
    }

    fn row(t: &str) -> String {
        let mut r = t.to_string();
        for i in 0..52 {
            r.push_str(&format!(",{}", i as f32 / 100.0));
        }
        r
    }

    #[test]
    fn csv_and_json_round_trip() {
        for (head, emo) in [(false, false), (true, true)] {
            let c = generated(77, head, emo, 3.25);
            let back = parse_curve_csv(&to_curve_csv_string(&c), "c.csv").unwrap();
            assert!(back == c, "round trip differs");
            let back = parse_curve_json(&to_curve_json_string(&c), "c.json").unwrap();
            assert!(back == c, "round trip differs");
        }
    }

    #[test]
    fn csv_columns_in_any_order_with_extras_and_estimated_fps() {
        let text = format!("{},mood\n{},7\n{},8\n{},9\n", header(), row("0"), row("0.04"), row("0.08"));
        let c = parse_curve_csv(&text, "c.csv").unwrap();
        assert_eq!(c.fps(), 25.0);
        assert_eq!(c.extra_names(), &["mood".to_string()]);
        assert_eq!(c.arkit(0)[51], 0.0, "TongueOut was the first column");
        assert_eq!(c.arkit(0)[0], 0.51, "EyeBlinkLeft was the last ARKit column");
        assert_eq!(c.channel(52), vec![7.0, 8.0, 9.0]);
    }

    #[test]
    fn bad_curve_files() {
        let err = |t: &str| parse_curve_csv(t, "c.csv").unwrap_err().to_string();
        assert!(err("").contains("c.csv: empty file"));
        assert!(err("# fps=25\n").contains("empty file"));
        assert!(err("# fps=-1\n").starts_with("c.csv:1: expected '# fps=<positive number>'"));
        let e = err(&format!("{}\n{}\n{}\n", header(), row("0.5"), row("0.5")));
        assert!(e.starts_with("c.csv:3: column 1 (time_s): time 0.5 s is not after 0.5 s on line 2"), "{e}");
        let e = err(&format!("{}\n{}\n", header(), row("0").replacen(",0.51", ",inf", 1)));
        assert!(e.starts_with("c.csv:2: column 53 (EyeBlinkLeft): expected a finite number, found 'inf'"), "{e}");
        let e = err(&format!("{}\n{},1\n", header(), row("0")));
        assert!(e.starts_with("c.csv:2: expected 53 fields"), "{e}");
        let e = err(&header().replace(",JawOpen", ""));
        assert!(e.contains("missing 1 of the 52 ARKit columns: JawOpen"), "{e}");
        let e = err(&header().replace("time_s", "t"));
        assert!(e.contains("expected header 'time_s'"), "{e}");

        let jerr = |t: &str| parse_curve_json(t, "c.json").unwrap_err().to_string();
        assert!(jerr("").contains("empty file"));
        let e = jerr("{\"time_s\": [0, 1],\n \"channels\": [1]}");
        assert!(e.starts_with("c.json:2: column"), "{e}");
        let e = jerr("{\"time_s\": [0, 1], \"channels\": []}");
        assert!(e.contains("missing 52 of the 52 ARKit columns"), "{e}");
        let c = generated(3, false, false, 0.0);
        let mut j: serde_json::Value = serde_json::from_str(&to_curve_json_string(&c)).unwrap();
        j["channels"][5]["values"] = serde_json::json!([0.1]);
        let e = jerr(&j.to_string());
        assert!(e.contains("channel \"EyeSquintLeft\" has 1 values; expected 3"), "{e}");
        j["channels"][5]["values"] = serde_json::json!([0.1, 0.2, 0.3]);
        j["time_s"] = serde_json::json!([0.0, 2.0, 1.0]);
        assert!(jerr(&j.to_string()).contains("strictly increasing"));
    }

    #[test]
    fn files_by_extension() {
        let dir = tempfile::tempdir().unwrap();
        let c = generated(12, true, false, 0.0);
        for name in ["a.csv", "b.json", "c.JSON"] {
            let p = dir.path().join(name);
            write_curves(&p, &c).unwrap();
            assert!(read_curves(&p).unwrap() == c, "{name}");
        }
    }
}
