//! Stated limits on the work an input may ask for: [`LimitExceeded`], the one error every engine
//! returns when an input is over one of its job's limits, checked before the heavy work starts.
//!
//! A limit is a field of an engine's job configuration (`max_rows`, `max_frames`, …); the error
//! names that field, so a front end can say which of its own options raises it: [`raise_hint`]
//! gives the one line (`…; raise it with --max-rows`) and [`name_fields`] writes the `` `field` ``s
//! an engine's message names as the front end's options (the CLI's tables of flags are in
//! `crates/cli/src/errors.rs`).
//!
//! ```
//! use inbetween_io::limits::LimitExceeded;
//! let e = LimitExceeded::check_count("take.csv", 250_000, 100_000, "rows", "max_rows").unwrap_err();
//! assert_eq!(e.to_string(), "take.csv: 250000 rows, more than the limit of 100000 rows (max_rows)");
//! assert_eq!(e.field, "max_rows");
//! ```

/// An input over one of a job's limits.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{subject}: {found}, more than the limit of {limit} ({field})")]
pub struct LimitExceeded {
    /// What is too large: a file, or a part of the job ("mask", "keys").
    pub subject: String,
    /// How much the input asks for, with its unit ("250000 rows", "1200.0 s").
    pub found: String,
    /// The limit, with its unit.
    pub limit: String,
    /// The job configuration field that holds the limit.
    pub field: &'static str,
}

impl LimitExceeded {
    /// `Err` when `count` (of `unit`, a plural noun) is above `limit`.
    pub fn check_count(
        subject: impl Into<String>,
        count: usize,
        limit: usize,
        unit: &str,
        field: &'static str,
    ) -> Result<(), LimitExceeded> {
        if count <= limit {
            return Ok(());
        }
        Err(LimitExceeded {
            subject: subject.into(),
            found: format!("{count} {unit}"),
            limit: format!("{limit} {unit}"),
            field,
        })
    }

    /// `Err` when `seconds` is above `limit_s` (or not a number).
    pub fn check_seconds(
        subject: impl Into<String>,
        seconds: f64,
        limit_s: f64,
        field: &'static str,
    ) -> Result<(), LimitExceeded> {
        if seconds <= limit_s {
            return Ok(());
        }
        Err(LimitExceeded {
            subject: subject.into(),
            found: format!("{seconds:.3} s"),
            limit: format!("{limit_s} s"),
            field,
        })
    }
}

/// `text` with each `` `field` `` that `names` lists (`(field, option)`) written as the front
/// end's option; other text, other backticked words included, unchanged.
pub fn name_fields(text: &str, names: &[(&str, &str)]) -> String {
    names.iter().fold(text.to_string(), |t, (field, option)| t.replace(&format!("`{field}`"), option))
}

/// The one line a front end shows for an error whose chain (the error, then its sources) holds a
/// [`LimitExceeded`] for a field that `names` lists, or a time limit reached
/// ([`inbetween_core::cancel::Cancelled::TimeLimit`], raised with `time_limit`):
/// `<contexts>: <limit message>; raise it with <option><what the wrapping errors add after it>`,
/// written with [`name_fields`]. `None` for any other error. An error that shows its source's
/// message (`{0}`, `stopped: {0}`) is not said twice.
pub fn raise_hint(e: &(dyn std::error::Error + 'static), names: &[(&str, &str)], time_limit: &str) -> Option<String> {
    use inbetween_core::cancel::Cancelled;
    let chain: Vec<&(dyn std::error::Error + 'static)> = std::iter::successors(Some(e), |e| e.source()).collect();
    let (at, option) = chain.iter().enumerate().find_map(|(i, cause)| {
        let option = match (cause.downcast_ref::<LimitExceeded>(), cause.downcast_ref::<Cancelled>()) {
            (Some(l), _) => names.iter().find(|(field, _)| *field == l.field).map(|(_, option)| *option)?,
            (_, Some(Cancelled::TimeLimit { .. })) => time_limit,
            _ => return None,
        };
        Some((i, option))
    })?;
    let here = chain[at].to_string();
    let (mut above, mut after) = (Vec::new(), None);
    for cause in &chain[..at] {
        let m = cause.to_string();
        let (own, rest) = m.find(&here).map_or((m.as_str(), None), |i| (&m[..i], Some(&m[i + here.len()..])));
        let own = own.trim_end_matches([':', ' ']);
        if !own.is_empty() {
            above.push(own.to_string());
        }
        // The outermost error that shows the limit's message holds what the inner ones add too.
        after = after.or(rest.map(str::to_string));
    }
    let after = after.unwrap_or_default();
    above.push(format!("{here}; raise it with {option}{after}"));
    Some(name_fields(&above.join(": "), names))
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::cancel::Cancelled;

    /// An engine error that wraps a limit and adds advice after it, and one that only shows it.
    #[derive(Debug, thiserror::Error)]
    enum EngineError {
        #[error("{0}; or read fewer rows with `first_rows`")]
        Advised(#[source] LimitExceeded),
        #[error("job stopped: {0}")]
        Stopped(#[source] Cancelled),
    }

    /// A context around an error, as front ends add them (`reading the input: …`).
    #[derive(Debug, thiserror::Error)]
    #[error("reading the input")]
    struct Context(#[source] EngineError);

    #[test]
    fn a_limit_in_the_chain_names_the_option_that_raises_it() {
        let names = [("max_rows", "--max-rows"), ("first_rows", "--first-rows")];
        let limit = LimitExceeded::check_count("a.csv", 3, 2, "rows", "max_rows").unwrap_err();
        assert_eq!(
            raise_hint(&Context(EngineError::Advised(limit.clone())), &names, "--time-limit").unwrap(),
            "reading the input: a.csv: 3 rows, more than the limit of 2 rows (max_rows); raise it with --max-rows; \
             or read fewer rows with --first-rows"
        );
        assert_eq!(raise_hint(&limit, &[("max_frames", "--max-frames")], "--time-limit"), None, "not a named field");
        let stopped = EngineError::Stopped(Cancelled::TimeLimit { limit_s: 2.0 });
        assert_eq!(
            raise_hint(&stopped, &[], "time_limit_s=").unwrap(),
            "job stopped: time limit of 2 s reached; raise it with time_limit_s="
        );
        assert_eq!(raise_hint(&Cancelled::Requested, &names, "--time-limit"), None);
        assert_eq!(raise_hint(&std::io::Error::other("disk full"), &names, "--time-limit"), None);
    }

    #[test]
    fn backticked_fields_are_written_as_options() {
        let names = [("unit", "--unit"), ("keys", "-k")];
        assert_eq!(
            name_fields("given with `unit` or `keys`; build with `cargo build`; keys", &names),
            "given with --unit or -k; build with `cargo build`; keys"
        );
    }

    #[test]
    fn within_limits_pass_and_over_names_everything() {
        assert!(LimitExceeded::check_count("a", 10, 10, "rows", "max_rows").is_ok());
        assert!(LimitExceeded::check_seconds("mask", 60.0, 60.0, "max_mask_s").is_ok());
        let e = LimitExceeded::check_seconds("mask", 61.25, 60.0, "max_mask_s").unwrap_err();
        assert_eq!(e.to_string(), "mask: 61.250 s, more than the limit of 60 s (max_mask_s)");
        let e = LimitExceeded::check_seconds("mask", f64::NAN, 60.0, "max_mask_s").unwrap_err();
        assert!(e.to_string().contains("NaN s"), "{e}");
    }
}
