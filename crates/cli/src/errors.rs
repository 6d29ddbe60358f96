//! How the binary reports failure: `error: …` with its causes and exit code 1, never a backtrace
//! unless asked for (`--debug` or `INBETWEEN_DEBUG=1`), even when `RUST_BACKTRACE` is set in the
//! environment. A panic (a bug) is reported the same way, naming where it happened.

use std::fmt::Write;

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

/// `error: <message>`, one `caused by:` line per cause, and the backtrace when `debug`.
pub fn render(error: &anyhow::Error, debug: bool) -> String {
    let mut out = format!("error: {error}\n");
    for cause in error.chain().skip(1) {
        let _ = writeln!(out, "  caused by: {cause}");
    }
    if debug {
        let _ = writeln!(out, "\nbacktrace:\n{}", error.backtrace());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::Context;

    #[test]
    fn causes_are_listed_after_the_message() {
        let e = Err::<(), _>(std::io::Error::other("disk full")).context("writing out.gif").unwrap_err();
        assert_eq!(render(&e, false), "error: writing out.gif\n  caused by: disk full\n");
        assert!(render(&e, true).contains("backtrace:"));
    }
}
