//! Stated limits on the work an input may ask for: [`LimitExceeded`], the one error every engine
//! returns when an input is over one of its job's limits, checked before the heavy work starts.
//!
//! A limit is a field of an engine's job configuration (`max_rows`, `max_frames`, …); the error
//! names that field, so a front end can say which of its own options raises it (the CLI maps
//! fields to flags, see `crates/cli/src/errors.rs`).
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

#[cfg(test)]
mod tests {
    use super::*;

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
