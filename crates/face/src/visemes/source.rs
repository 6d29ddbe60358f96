//! One entry for every file-based viseme source: a TextGrid alignment or phoneme timings, chosen by
//! extension.

use super::spans::{shown, PhonemeSpan};
use super::textgrid::read_textgrid;
use super::timing::{extension, read_phoneme_timing};
use crate::data::FaceError;
use std::path::Path;

/// Reads phoneme spans from `path`: `.TextGrid` (any case) through [`read_textgrid`] with `tier`
/// (`None`: the phone tier), `.csv` / `.json` through [`read_phoneme_timing`] (`tier` must be `None`).
pub fn read_viseme_source(path: &Path, tier: Option<&str>) -> Result<Vec<PhonemeSpan>, FaceError> {
    let file = path.display().to_string();
    match extension(path).as_str() {
        "textgrid" => read_textgrid(path, tier),
        "csv" | "json" => match tier {
            None => read_phoneme_timing(path),
            Some(t) => Err(FaceError::File {
                file,
                message: format!("a tier ({}) was given, but phoneme-timing CSV/JSON files have no tiers", shown(t)),
            }),
        },
        other => Err(FaceError::File {
            file,
            message: format!(
                "unknown extension {}; expected a viseme source: .TextGrid (forced alignment), .csv or .json (phoneme timings)",
                shown(other)
            ),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::super::textgrid::tests::{LONG, SHORT};
    use super::*;

    #[test]
    fn dispatches_on_extension() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, text: &str| {
            let p = dir.path().join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        let long = read_viseme_source(&write("a.TextGrid", LONG), None).unwrap();
        assert_eq!(long.len(), 6);
        let short = read_viseme_source(&write("b.textgrid", SHORT), Some("phones")).unwrap();
        assert_eq!(short.len(), 3);
        let csv = read_viseme_source(&write("c.csv", "start,end,phoneme\n0,0.5,B\n"), None).unwrap();
        assert_eq!(csv, [PhonemeSpan::new(0.0, 0.5, "B")]);
        let json = read_viseme_source(&write("d.json", r#"[{"start":0,"end":0.5,"phoneme":"B"}]"#), None).unwrap();
        assert_eq!(json, csv);
        let e = read_viseme_source(&write("e.txt", "hi"), None).unwrap_err().to_string();
        assert!(e.contains("unknown extension 'txt'") && e.contains(".TextGrid"), "{e}");
        let e = read_viseme_source(&dir.path().join("c.csv"), Some("phones")).unwrap_err().to_string();
        assert!(e.contains("have no tiers"), "{e}");
        // The TextGrid reader names the file it read.
        let bad = write("f.TextGrid", &LONG.replace("\"DH\"", "\"DHX\""));
        let e = read_viseme_source(&bad, None).unwrap_err().to_string();
        assert!(e.starts_with(&format!("{}:44:", bad.display())), "{e}");
    }
}
