//! How the binary reports failure: `error: …` with its causes and exit code 1, never a backtrace
//! unless asked for (`--debug` or `INBETWEEN_DEBUG=1`), even when `RUST_BACKTRACE` is set in the
//! environment. A panic (a bug) is reported the same way, naming where it happened.

use std::fmt::Write;

use anyhow::Context;
use inbetween_core::cancel::Cancel;

/// Sets up error and panic reporting; call first thing in `main`.
pub fn install(debug: bool) {
    if !debug {
        // anyhow reads RUST_LIB_BACKTRACE before RUST_BACKTRACE: with it at 0 no backtrace is
        // captured for our errors. Set before any thread starts, so the write is not racy.
        std::env::set_var("RUST_LIB_BACKTRACE", "0");
    }
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        let place = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        eprintln!("error: internal error{place}: {message}");
        eprintln!("  this is a bug in inbetween; please report it with the command that caused it");
        if debug {
            eprintln!("\nbacktrace:\n{}", std::backtrace::Backtrace::force_capture());
        }
    }));
}

/// The options the libraries name in their messages and notes as `` `field` `` (they speak of
/// fields; the commands own the flags), and the flag each is given with here.
pub const OPTION_FLAGS: &[(&str, &str)] = &[
    ("unit", "--unit"),
    ("overwrite_committed", "--overwrite-committed"),
    ("allow_reverse", "--allow-reverse"),
    ("models", "--models"),
    ("shared_motions", "--shared-motions"),
    ("data", "--data"),
    ("roles", "--roles"),
    ("frame", "--frame"),
    ("starts", "--starts"),
    ("joints", "--joints"),
    ("skip_first", "--skip-first"),
];

/// Library text with each `` `field` `` of [`OPTION_FLAGS`] written as its flag (other text,
/// other backticked words included, unchanged).
pub fn with_flags(text: &str) -> String {
    inbetween_io::limits::name_fields(text, OPTION_FLAGS)
}

/// `error: <message>`, one `caused by:` line per cause, and the backtrace when `debug`; options
/// the message names are written as flags ([`with_flags`]).
pub fn render(error: &anyhow::Error, debug: bool) -> String {
    let mut out = format!("error: {}\n", with_flags(&error.to_string()));
    for cause in error.chain().skip(1) {
        let _ = writeln!(out, "  caused by: {}", with_flags(&cause.to_string()));
    }
    if debug {
        let _ = writeln!(out, "\nbacktrace:\n{}", error.backtrace());
    }
    out
}

/// A command's error with its own `(field, flag)` table: an error over a limit (or the time
/// limit) becomes one line that names the flag raising it ([`inbetween_io::limits::raise_hint`]);
/// any other error whose messages name a `` `field` `` of the table becomes one line with the
/// flags written in; other errors pass unchanged. The libraries speak of their fields; the
/// commands own the flags.
pub fn name_flags(e: anyhow::Error, flags: &[(&str, &str)]) -> anyhow::Error {
    use inbetween_io::limits::{name_fields, raise_hint};
    if let Some(line) = raise_hint(e.as_ref(), flags, "--time-limit") {
        return anyhow::anyhow!(line);
    }
    let named: Vec<String> = e.chain().map(|c| name_fields(&c.to_string(), flags)).collect();
    if e.chain().zip(&named).all(|(c, n)| c.to_string() == *n) {
        return e;
    }
    anyhow::anyhow!(named.join(": "))
}

/// The cancel token of a command's `--time-limit` (none: never cancelled by time).
pub fn time_limit(seconds: Option<f64>) -> anyhow::Result<Cancel> {
    Cancel::with_optional_limit_s(seconds).map_err(anyhow::Error::msg).context("--time-limit")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_fields_name_their_flags() {
        let limit = inbetween_io::LimitExceeded::check_count("a.csv", 3, 2, "rows", "max_rows").unwrap_err();
        let e = anyhow::Error::new(limit).context("reading the input");
        let named = name_flags(e, &[("max_rows", "--max-rows")]);
        assert_eq!(
            render(&named, false),
            "error: reading the input: a.csv: 3 rows, more than the limit of 2 rows (max_rows); raise it with \
             --max-rows\n"
        );
        let face = inbetween_face::data::FaceError::from(inbetween_core::cancel::Cancelled::TimeLimit { limit_s: 2.0 });
        assert_eq!(
            name_flags(face.into(), &[]).to_string(),
            "face job stopped: time limit of 2 s reached; raise it with --time-limit"
        );
        let batch = name_flags(anyhow::anyhow!("option `keys` does not apply"), &[("keys", "-k")]);
        assert_eq!(batch.to_string(), "option -k does not apply");
        let other = name_flags(anyhow::anyhow!("disk full").context("writing"), &[("keys", "-k")]);
        assert_eq!(render(&other, false), "error: writing\n  caused by: disk full\n");
    }

    #[test]
    fn options_named_by_the_libraries_are_written_as_flags() {
        let e = anyhow::anyhow!("refusing to overwrite w.bpk (set `overwrite_committed` to replace them on purpose)");
        assert_eq!(
            render(&e, false),
            "error: refusing to overwrite w.bpk (set --overwrite-committed to replace them on purpose)\n"
        );
    }

    #[test]
    fn causes_are_listed_after_the_message() {
        let e = Err::<(), _>(std::io::Error::other("disk full")).context("writing out.gif").unwrap_err();
        assert_eq!(render(&e, false), "error: writing out.gif\n  caused by: disk full\n");
        assert!(render(&e, true).contains("backtrace:"));
    }
}
