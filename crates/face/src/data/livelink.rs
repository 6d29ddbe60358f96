//! Live Link Face CSV: the layout of the iPhone app's recordings and of NeuroSync's generated takes.
//!
//! ```text
//! Timecode,BlendshapeCount,EyeBlinkLeft,…,TongueOut[,HeadYaw,…,RightEyeRoll][,Angry,…,Surprised]
//! 14:58:02:44.643,61,0.0000000000,0.0105142975,…
//! ```
//!
//! * `Timecode` is `HH:MM:SS:FF.fff`. In the app's files `FF.fff` is a fractional frame count at 60 fps
//!   (`44.643` = frame 44.643; consecutive rows step by 1.0017 frames, 59.904 fps). NeuroSync's generated
//!   files write `FF` as the frame and `.fff` as the **milliseconds** of the second (`00:00:00:04.083` is
//!   0.083 s). The reader detects that variant: it is chosen when every row has `|FF − fff·0.06| ≤ 1`
//!   (frame and milliseconds agree) and the millisecond times strictly increase, which a real 60 fps
//!   capture breaks within a few rows; otherwise the fractional-frame reading applies. Either way times come out in seconds on the timecode's
//!   clock (`HH·3600 + MM·60 + SS + …`).
//! * `BlendshapeCount` is the number of value columns (52, 61 with head/eye, 68 with emotions too) and
//!   must match the header on every row.
//! * Value columns are matched by name (any order, case-insensitive): all 52 ARKit names are required,
//!   the 9 head/eye names all or none, the 7 emotion names ([`EMOTION_NAMES`]) optional; any other name
//!   is an error.
//!
//! The writer emits the fractional-frame timecode (`round(t·60000)` sixty-thousandths of a second, so
//! millisecond times are exact), `BlendshapeCount`, then every channel in clip order, values in their
//! shortest round-trip form; reading its output gives back the same clip.
//!
//! [`EMOTION_NAMES`]: super::EMOTION_NAMES

use super::clip::{BlendshapeClip, Layout};
use super::names::{is_emotion, NUM_ARKIT};
use super::text::{at, column, fields, lines, number, push_value, read_text};
use super::LIVE_LINK_FPS;
use crate::error::{shown, FaceError};
use std::path::Path;

const EXPECTED_HEADER: &str =
    "a header line 'Timecode,BlendshapeCount,' followed by the 52 ARKit names (then optionally 9 head/eye and 7 emotion names)";

/// A timecode's fields: hours, minutes, seconds, frame, thousandths after the point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Timecode {
    h: u64,
    m: u64,
    s: u64,
    ff: u64,
    frac: u64,
}

impl Timecode {
    fn whole_seconds(self) -> f64 {
        (self.h * 3600 + self.m * 60 + self.s) as f64
    }
    /// Fractional frames at 60 fps (the app's files).
    fn subframe_time(self) -> f64 {
        self.whole_seconds() + (self.ff * 1000 + self.frac) as f64 / (LIVE_LINK_FPS * 1000.0)
    }
    /// Milliseconds after the point (NeuroSync's generated files).
    fn millis_time(self) -> f64 {
        self.whole_seconds() + self.frac as f64 / 1000.0
    }
    /// Whether the frame and the milliseconds tell the same time (the NeuroSync variant).
    fn millis_consistent(self) -> bool {
        // ≤ 1, not < 1: NeuroSync floors the frame (0.25 s → frame 14.9999 → 14, fff 250 → 15.0).
        (self.ff as f64 - self.frac as f64 * LIVE_LINK_FPS / 1000.0).abs() <= 1.0 + 1e-9
    }
}

fn parse_timecode(field: &str) -> Result<Timecode, String> {
    let bad = |why: &str| {
        Err(format!(
            "expected a timecode HH:MM:SS:FF.fff (frames at 60 fps, up to 3 digits after the point){why}, found {}",
            shown(field)
        ))
    };
    let parts: Vec<&str> = field.split(':').collect();
    if parts.len() != 4 {
        return bad("");
    }
    let (ff_text, frac_text) = match parts[3].split_once('.') {
        Some((a, b)) => (a, b),
        None => (parts[3], ""),
    };
    let digits = |s: &str, max_len: usize| -> Option<u64> {
        if s.is_empty() || s.len() > max_len || !s.bytes().all(|b| b.is_ascii_digit()) {
            None
        } else {
            s.parse().ok()
        }
    };
    let (Some(h), Some(m), Some(s), Some(ff)) =
        (digits(parts[0], 3), digits(parts[1], 2), digits(parts[2], 2), digits(ff_text, 2))
    else {
        return bad("");
    };
    if parts[3].contains('.') && frac_text.is_empty() {
        return bad("");
    }
    let frac = if frac_text.is_empty() {
        0
    } else {
        match digits(frac_text, 3) {
            Some(v) => v * 10u64.pow(3 - frac_text.len() as u32),
            None => return bad(""),
        }
    };
    if m >= 60 || s >= 60 {
        return bad(" with minutes and seconds below 60");
    }
    if ff >= 60 {
        return bad(" with the frame below 60");
    }
    Ok(Timecode { h, m, s, ff, frac })
}

/// Formats seconds as a fractional-frame timecode, or `None` when out of range (negative, ≥ 1000 h).
fn format_timecode(t: f64) -> Option<(u64, String)> {
    let units = (t * LIVE_LINK_FPS * 1000.0).round();
    if !(0.0..3.6e6 * 60.0 * 1000.0).contains(&units) {
        return None;
    }
    let u = units as u64;
    let per_second = 60_000;
    let secs = u / per_second;
    let sub = u % per_second;
    let text =
        format!("{:02}:{:02}:{:02}:{:02}.{:03}", secs / 3600, (secs / 60) % 60, secs % 60, sub / 1000, sub % 1000);
    Some((u, text))
}

/// Parses Live Link Face CSV text; `file` names it in errors.
pub fn parse_live_link(text: &str, file: &str) -> Result<BlendshapeClip, FaceError> {
    let mut it = lines(text);
    let Some((hline, header_text)) = it.next() else {
        return Err(FaceError::Empty { file: file.into(), expected: EXPECTED_HEADER.into() });
    };
    let header = fields(header_text);
    for (i, want) in ["Timecode", "BlendshapeCount"].iter().enumerate() {
        match header.get(i) {
            Some(h) if h.eq_ignore_ascii_case(want) => {}
            Some(h) => {
                return Err(at(file, hline, column(&[], i), format!("expected header '{want}', found {}", shown(h))));
            }
            None => {
                return Err(at(
                    file,
                    hline,
                    column(&[], i),
                    format!("expected header '{want}', found the end of the line"),
                ))
            }
        }
    }
    let layout = Layout::from_names(&header[2..], is_emotion).map_err(|(c, m)| {
        let m = if m.starts_with("unknown column") {
            format!("{m}; expected an ARKit blendshape, head/eye rotation or emotion name (Live Link Face layout)")
        } else {
            m
        };
        at(file, hline, c.and_then(|c| column(&header, c + 2)), m)
    })?;
    let nvalues = header.len() - 2;
    let layout_words = if layout.head_eye && !layout.extras.is_empty() {
        format!("52 ARKit + 9 head/eye + {} emotion", layout.extras.len())
    } else if layout.head_eye {
        "52 ARKit + 9 head/eye".to_string()
    } else if !layout.extras.is_empty() {
        format!("52 ARKit + {} emotion", layout.extras.len())
    } else {
        "52 ARKit".to_string()
    };
    let stride = layout.stride();
    let mut times_raw: Vec<(usize, Timecode, &str)> = Vec::new();
    let mut values: Vec<f32> = Vec::new();
    for (line, row_text) in it {
        let row = fields(row_text);
        if row.len() != header.len() {
            return Err(at(
                file,
                line,
                None,
                format!(
                    "expected {} fields as the header declares (Timecode, BlendshapeCount and {nvalues} values: {layout_words}), found {} ({} values)",
                    header.len(),
                    row.len(),
                    row.len().saturating_sub(2)
                ),
            ));
        }
        let tc = parse_timecode(row[0]).map_err(|m| at(file, line, column(&header, 0), m))?;
        match row[1].parse::<usize>() {
            Ok(n) if n == nvalues => {}
            _ => {
                return Err(at(
                    file,
                    line,
                    column(&header, 1),
                    format!("expected {nvalues} (the number of value columns in the header), found {}", shown(row[1])),
                ))
            }
        }
        let base = values.len();
        values.resize(base + stride, 0.0);
        for (c, f) in row[2..].iter().enumerate() {
            let v: f32 = number(f).map_err(|m| at(file, line, column(&header, c + 2), m))?;
            values[base + layout.slot[c]] = v;
        }
        times_raw.push((line, tc, row[0]));
    }
    if times_raw.is_empty() {
        return Err(at(file, hline, None, "expected at least one data row after the header, found none"));
    }
    let millis = times_raw.len() >= 2
        && times_raw.iter().all(|(_, tc, _)| tc.millis_consistent())
        && times_raw.windows(2).all(|w| w[1].1.millis_time() > w[0].1.millis_time());
    let times: Vec<f64> =
        times_raw.iter().map(|(_, tc, _)| if millis { tc.millis_time() } else { tc.subframe_time() }).collect();
    for i in 1..times.len() {
        if times[i] <= times[i - 1] {
            let (line, _, text) = times_raw[i];
            let (pline, _, ptext) = times_raw[i - 1];
            return Err(at(
                file,
                line,
                column(&header, 0),
                format!(
                    "timecode {} is not after {} on line {pline}; expected strictly increasing timecodes{}",
                    shown(text),
                    shown(ptext),
                    if millis { " (read as NeuroSync frame + milliseconds)" } else { "" }
                ),
            ));
        }
    }
    debug_assert!(stride >= NUM_ARKIT);
    BlendshapeClip::new(LIVE_LINK_FPS, times, layout.head_eye, layout.extras, values)
        .map_err(|e| FaceError::File { file: file.into(), message: e.to_string() })
}

/// Reads a Live Link Face CSV file.
pub fn read_live_link(path: &Path) -> Result<BlendshapeClip, FaceError> {
    let text = read_text(path)?;
    parse_live_link(&text, &path.display().to_string())
}

/// Live Link Face CSV text of a clip. Fails (before anything is written) when an extra channel is not
/// an emotion column, a time is negative or ≥ 1000 h, or two times fall on the same 1/60000 s.
pub fn to_live_link_string(clip: &BlendshapeClip) -> Result<String, FaceError> {
    if let Some(bad) = clip.extra_names().iter().find(|n| !is_emotion(n)) {
        return Err(FaceError::Invalid(format!(
            "channel '{bad}' cannot be written as Live Link Face CSV (extra columns there are the 7 emotion names); write the curve format instead"
        )));
    }
    let names = clip.channel_names();
    let n = names.len();
    let mut out = String::with_capacity(clip.num_frames() * n * 12 + 1024);
    out.push_str("Timecode,BlendshapeCount");
    for name in &names {
        out.push(',');
        out.push_str(name);
    }
    out.push('\n');
    let mut prev: Option<u64> = None;
    for f in 0..clip.num_frames() {
        let t = clip.times()[f];
        let (u, tc) = format_timecode(t).ok_or_else(|| {
            FaceError::Invalid(format!("time {t} s of frame {f} cannot be written as a timecode (0 ≤ t < 1000 h)"))
        })?;
        if prev.is_some_and(|p| u <= p) {
            return Err(FaceError::Invalid(format!(
                "frames {} and {f} fall on the same timecode {tc} (resolution 1/60000 s)",
                f - 1
            )));
        }
        prev = Some(u);
        out.push_str(&tc);
        out.push(',');
        out.push_str(&n.to_string());
        for &v in clip.frame(f) {
            out.push(',');
            push_value(&mut out, v);
        }
        out.push('\n');
    }
    Ok(out)
}

/// Writes a clip as Live Link Face CSV, atomically (temp file + rename).
pub fn write_live_link(path: &Path, clip: &BlendshapeClip) -> Result<(), FaceError> {
    let text = to_live_link_string(clip)?;
    inbetween_io::write_atomic(path, text.as_bytes())
        .map_err(|source| FaceError::Io { file: path.display().to_string(), source })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::names::{ARKIT_NAMES, EMOTION_NAMES, HEAD_EYE_NAMES};
    use super::*;

    /// A generated clip: smooth curves in 0..1, head/eye in ±0.3, optional emotions.
    pub(crate) fn generated(frames: usize, head: bool, emotions: bool, t0: f64) -> BlendshapeClip {
        let extras: Vec<String> = if emotions { EMOTION_NAMES.iter().map(|s| s.to_string()).collect() } else { vec![] };
        let stride = 52 + if head { 9 } else { 0 } + extras.len();
        let times: Vec<f64> = (0..frames).map(|f| t0 + f as f64 / 60.0).collect();
        let mut values = Vec::with_capacity(frames * stride);
        for f in 0..frames {
            for c in 0..stride {
                let x = (f as f32 * 0.07 + c as f32 * 0.9).sin();
                values.push(if c < 52 {
                    0.5 + 0.5 * x
                } else if c < 61 && head {
                    0.3 * x
                } else {
                    50.0 + 50.0 * x
                });
            }
        }
        BlendshapeClip::new(60.0, times, head, extras, values).unwrap()
    }

    fn header(n_head: usize, emotions: bool) -> String {
        let mut h = String::from("Timecode,BlendshapeCount");
        let names =
            ARKIT_NAMES.iter().chain(&HEAD_EYE_NAMES[..n_head]).chain(if emotions { &EMOTION_NAMES[..] } else { &[] });
        let mut n = 0;
        for name in names {
            h.push(',');
            h.push_str(name);
            n += 1;
        }
        let _ = n;
        h
    }

    fn row(tc: &str, count: usize, values: usize) -> String {
        let mut r = format!("{tc},{count}");
        for i in 0..values {
            r.push_str(&format!(",{}", i as f32 / 100.0));
        }
        r
    }

    fn err(text: &str) -> String {
        parse_live_link(text, "t.csv").unwrap_err().to_string()
    }

    #[test]
    fn timecodes_parse_and_format() {
        let tc = parse_timecode("14:58:02:44.643").unwrap();
        assert!((tc.subframe_time() - (14.0 * 3600.0 + 58.0 * 60.0 + 2.0 + 44.643 / 60.0)).abs() < 1e-9);
        assert!((parse_timecode("00:00:00:04.083").unwrap().millis_time() - 0.083).abs() < 1e-12);
        assert_eq!(parse_timecode("00:00:01:02").unwrap().frac, 0);
        assert_eq!(parse_timecode("00:00:01:02.5").unwrap().frac, 500);
        for bad in [
            "",
            "1:2:3",
            "00:00:00:60.000",
            "00:61:00:00.000",
            "00:00:00:00.",
            "00:00:00:00.1234",
            "a:b:c:d",
            "00:00:00:-1.0",
        ] {
            assert!(parse_timecode(bad).is_err(), "{bad}");
        }
        let (_, s) = format_timecode(14.0 * 3600.0 + 58.0 * 60.0 + 2.0 + 44.643 / 60.0).unwrap();
        assert_eq!(s, "14:58:02:44.643");
        assert_eq!(format_timecode(0.083).unwrap().1, "00:00:00:04.980");
        assert!(format_timecode(-1.0).is_none());
    }

    #[test]
    fn generated_clips_round_trip() {
        for (head, emotions, t0) in
            [(false, false, 0.0), (true, false, 53882.74405), (true, true, 0.0), (false, true, 12.5)]
        {
            let c = generated(130, head, emotions, t0);
            let text = to_live_link_string(&c).unwrap();
            let back = parse_live_link(&text, "gen.csv").unwrap();
            assert_eq!(back.num_channels(), c.num_channels());
            assert_eq!(back.values(), c.values(), "values exact");
            for (a, b) in back.times().iter().zip(c.times()) {
                assert!((a - b).abs() < 1e-5, "{a} vs {b}");
            }
            // Second round trip is exact in times too (times now lie on the 1/60000 s grid).
            let again = parse_live_link(&to_live_link_string(&back).unwrap(), "gen.csv").unwrap();
            assert_eq!(again, back);
        }
    }

    #[test]
    fn neurosync_millisecond_timecodes_are_detected() {
        let h = header(0, false);
        let text = format!(
            "{h}\n{}\n{}\n{}\n{}\n",
            row("00:00:00:00.000", 52, 52),
            row("00:00:00:01.016", 52, 52),
            row("00:00:00:04.066", 52, 52),
            row("00:00:00:04.083", 52, 52)
        );
        let c = parse_live_link(&text, "gen.csv").unwrap();
        assert_eq!(c.times(), &[0.0, 0.016, 0.066, 0.083]);
        let back = parse_live_link(&to_live_link_string(&c).unwrap(), "gen.csv").unwrap();
        for (a, b) in back.times().iter().zip(c.times()) {
            assert!((a - b).abs() < 1e-12);
        }
        // A real capture's fractional frames are not mistaken for it.
        let text = format!("{h}\n{}\n{}\n", row("00:00:00:00.000", 52, 52), row("00:00:00:01.000", 52, 52));
        assert_eq!(parse_live_link(&text, "t.csv").unwrap().times()[1], 1.0 / 60.0);
    }

    #[test]
    fn layouts_52_61_68_and_crlf_bom() {
        for (nh, emo, n) in [(0, false, 52), (9, false, 61), (9, true, 68), (0, true, 59)] {
            let text = format!("\u{feff}{}\r\n{}\r\n\r\n", header(nh, emo), row("01:02:03:04.500", n, n));
            let c = parse_live_link(&text, "t.csv").unwrap();
            assert_eq!(c.num_channels(), n);
            assert_eq!(c.has_head_eye(), nh == 9);
            assert!((c.times()[0] - (3723.0 + 4.5 / 60.0)).abs() < 1e-9);
        }
    }

    #[test]
    fn bad_files_name_line_column_and_expectation() {
        let h61 = header(9, false);
        let ok = row("00:00:00:00.000", 61, 61);
        assert!(err("").contains("t.csv: empty file; expected a header line"), "{}", err(""));
        assert!(err("\n \r\n").contains("empty file"));
        let e = err(&format!("{h61}\n"));
        assert!(e.starts_with("t.csv:1: expected at least one data row"), "{e}");
        // 52 values where the header declares 61.
        let e = err(&format!("{h61}\n{ok}\n{}\n", row("00:00:00:01.000", 61, 52)));
        assert!(e.starts_with("t.csv:3: expected 63 fields as the header declares (Timecode, BlendshapeCount and 61 values: 52 ARKit + 9 head/eye), found 54"), "{e}");
        // 68 values where the header declares 61.
        let e = err(&format!("{h61}\n{}\n", row("00:00:00:01.000", 68, 68)));
        assert!(e.contains("found 70 (68 values)"), "{e}");
        // BlendshapeCount disagreeing with the header.
        let e = err(&format!("{h61}\n{}\n", row("00:00:00:01.000", 52, 61)));
        assert!(e.starts_with("t.csv:2: column 2 (BlendshapeCount): expected 61"), "{e}");
        // NaN and non-numbers.
        let nan = ok.replacen(",0.03,", ",NaN,", 1);
        let e = err(&format!("{h61}\n{nan}\n"));
        assert_eq!(e, "t.csv:2: column 6 (EyeLookOutLeft): expected a finite number, found 'NaN'");
        let e = err(&format!("{h61}\n{}\n", ok.replacen(",0.03,", ",abc,", 1)));
        assert!(e.ends_with("column 6 (EyeLookOutLeft): expected a number, found 'abc'"), "{e}");
        let e = err(&format!("{h61}\n{}\n", ok.replacen(",0.03,", ",,", 1)));
        assert!(e.ends_with("expected a number, found an empty field"), "{e}");
        // Non-monotonic and bad timecodes.
        let e = err(&format!("{h61}\n{}\n{}\n", row("00:00:01:00.000", 61, 61), row("00:00:00:59.000", 61, 61)));
        assert!(e.starts_with("t.csv:3: column 1 (Timecode): timecode '00:00:00:59.000' is not after '00:00:01:00.000' on line 2; expected strictly increasing"), "{e}");
        let e = err(&format!("{h61}\n{}\n", row("00:00:00:77.000", 61, 61)));
        assert!(e.contains("column 1 (Timecode): expected a timecode HH:MM:SS:FF.fff"), "{e}");
        // Missing and unknown columns.
        let e = err(&h61.replace(",JawOpen", ""));
        assert!(e.starts_with("t.csv:1: missing 1 of the 52 ARKit columns: JawOpen"), "{e}");
        let e = err(&format!("{h61},Blorp\n"));
        assert!(e.starts_with("t.csv:1: column 64 (Blorp): unknown column 'Blorp'; expected an ARKit"), "{e}");
        let e = err(&h61.replace(",HeadRoll", ""));
        assert!(e.contains("missing HeadRoll"), "{e}");
        let e = err(&h61.replace("Timecode", "Time"));
        assert!(e.starts_with("t.csv:1: column 1: expected header 'Timecode', found 'Time'"), "{e}");
        let e = err(&format!("{h61},JawOpen\n"));
        assert!(e.contains("duplicate column 'JawOpen'"), "{e}");
    }

    #[test]
    fn writer_refuses_what_the_reader_would_not_read() {
        let mut names: Vec<(String, Vec<f32>)> = ARKIT_NAMES.iter().map(|n| (n.to_string(), vec![0.0])).collect();
        names.push(("custom".into(), vec![1.0]));
        let c = BlendshapeClip::from_named(60.0, vec![0.0], names).unwrap();
        assert!(to_live_link_string(&c).unwrap_err().to_string().contains("'custom' cannot be written"));
        let c = BlendshapeClip::new(60.0, vec![0.0, 1e-6], false, vec![], vec![0.0; 104]).unwrap();
        assert!(to_live_link_string(&c).unwrap_err().to_string().contains("same timecode"));
        let c = BlendshapeClip::new(60.0, vec![-1.0], false, vec![], vec![0.0; 52]).unwrap();
        assert!(to_live_link_string(&c).is_err());
    }

    #[test]
    fn write_is_atomic_and_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/out.csv");
        let c = generated(10, true, false, 1.0);
        write_live_link(&path, &c).unwrap();
        assert_eq!(read_live_link(&path).unwrap().values(), c.values());
        // A refused clip leaves the old file untouched.
        let bad = BlendshapeClip::new(60.0, vec![-1.0], false, vec![], vec![0.0; 52]).unwrap();
        assert!(write_live_link(&path, &bad).is_err());
        assert_eq!(read_live_link(&path).unwrap().num_frames(), 10);
        let e = read_live_link(&dir.path().join("missing.csv")).unwrap_err().to_string();
        assert!(e.contains("missing.csv"), "{e}");
    }
}
