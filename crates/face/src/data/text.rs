//! The small CSV dialect both formats share: comma-separated, no quoting inside fields (a field may be
//! wrapped in one pair of double quotes), LF or CRLF, a UTF-8 BOM allowed, blank lines ignored,
//! spaces around fields ignored.

use crate::error::{shown, Column, FaceError};
use std::path::Path;

/// Reads a file as UTF-8 text.
pub(crate) fn read_text(path: &Path) -> Result<String, FaceError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| FaceError::Io { file: file.clone(), source })?;
    inbetween_io::text::utf8(bytes).map_err(|e| FaceError::File {
        file,
        message: format!("not UTF-8 text (invalid byte at offset {}); expected a text file", e.offset),
    })
}

/// Non-blank lines with their 1-based line numbers, BOM and `\r` removed.
pub(crate) fn lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.split('\n').enumerate().filter_map(|(i, l)| {
        let l = l.strip_suffix('\r').unwrap_or(l);
        (!l.trim().is_empty()).then_some((i + 1, l))
    })
}

/// Splits a line into trimmed fields.
pub(crate) fn fields(line: &str) -> Vec<&str> {
    line.split(',')
        .map(|f| {
            let f = f.trim();
            f.strip_prefix('"').and_then(|g| g.strip_suffix('"')).unwrap_or(f)
        })
        .collect()
}

/// Parses a finite number, or says what was wrong.
pub(crate) fn number<T: std::str::FromStr + Into<f64> + Copy>(field: &str) -> Result<T, String> {
    match field.parse::<T>() {
        Ok(v) if v.into().is_finite() => Ok(v),
        Ok(_) => Err(format!("expected a finite number, found {}", shown(field))),
        Err(_) if field.is_empty() => Err("expected a number, found an empty field".into()),
        Err(_) => Err(format!("expected a number, found {}", shown(field))),
    }
}

/// The [`Column`] for 0-based field `i` of a line, named from the header.
pub(crate) fn column(header: &[&str], i: usize) -> Option<Column> {
    Some(Column { index: i + 1, name: header.get(i).map(|s| s.to_string()).unwrap_or_default() })
}

/// Formats a value so that it parses back to the same `f32` (shortest round-trip form).
pub(crate) fn push_value(out: &mut String, v: f32) {
    use std::fmt::Write;
    let _ = write!(out, "{v}");
}

/// Formats a time so that it parses back to the same `f64`.
pub(crate) fn push_time(out: &mut String, t: f64) {
    use std::fmt::Write;
    let _ = write!(out, "{t}");
}

/// A parse error at a line and column.
pub(crate) fn at(file: &str, line: usize, col: Option<Column>, message: impl Into<String>) -> FaceError {
    FaceError::parse(file, line, col, message)
}
