//! Which inputs of a manifest one process runs: shard `i` of `n` takes the inputs at positions
//! `i, i + n, i + 2n, …` of the manifest's stable order (round robin, so a folder sorted by size or
//! by subject still spreads evenly).
//!
//! The shard comes from `--shard i/n`, or from the scheduler that started the process: a Slurm job
//! array (`SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_COUNT`, less `SLURM_ARRAY_TASK_MIN` when the
//! array does not start at 0) or a Kubernetes Indexed Job (`JOB_COMPLETION_INDEX`, with the count
//! given as `--shards n` since the pod does not see it).

use crate::BatchError;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Shard `index` (0-based) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Default for Shard {
    fn default() -> Shard {
        Shard::ALL
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// The whole manifest in one process.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// A shard, checked: `count ≥ 1` and `index < count`.
    pub fn new(index: usize, count: usize) -> Result<Shard, BatchError> {
        if count == 0 {
            return Err(BatchError::Invalid("shard count 0: expected at least 1 shard".into()));
        }
        if index >= count {
            return Err(BatchError::Invalid(format!(
                "shard {index} of {count}: expected an index from 0 to {} (shards are numbered from 0)",
                count - 1
            )));
        }
        Ok(Shard { index, count })
    }

    /// `i/n` as `--shard` takes it, `i` from 0.
    pub fn parse(text: &str) -> Result<Shard, BatchError> {
        let bad = || BatchError::Invalid(format!("shard '{text}': expected i/n, e.g. 0/3 for the first of 3 shards"));
        let (i, n) = text.trim().split_once('/').ok_or_else(bad)?;
        let i = i.trim().parse().map_err(|_| bad())?;
        let n = n.trim().parse().map_err(|_| bad())?;
        Shard::new(i, n)
    }

    /// The shard a scheduler gave this process, read through `var` (the environment in the CLI, a
    /// map in tests). `shards` is `--shards n`: the count for a Kubernetes Indexed Job, or an
    /// override of Slurm's. `None` when no scheduler variable is set.
    pub fn from_env(shards: Option<usize>, var: &dyn Fn(&str) -> Option<String>) -> Result<Option<Shard>, BatchError> {
        let number = |name: &str| -> Result<Option<usize>, BatchError> {
            match var(name) {
                None => Ok(None),
                Some(v) if v.trim().is_empty() => Ok(None),
                Some(v) => v.trim().parse().map(Some).map_err(|_| {
                    BatchError::Invalid(format!("environment variable {name}='{v}': expected a whole number"))
                }),
            }
        };
        if let Some(id) = number("SLURM_ARRAY_TASK_ID")? {
            let min = number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let count = match (shards, number("SLURM_ARRAY_TASK_COUNT")?) {
                (Some(n), _) | (None, Some(n)) => n,
                (None, None) => {
                    return Err(BatchError::Invalid(
                        "SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not: give --shards N".into(),
                    ))
                }
            };
            let index = id.checked_sub(min).ok_or_else(|| {
                BatchError::Invalid(format!("SLURM_ARRAY_TASK_ID {id} is below SLURM_ARRAY_TASK_MIN {min}"))
            })?;
            return Shard::new(index, count).map(Some);
        }
        if let Some(index) = number("JOB_COMPLETION_INDEX")? {
            let count = shards.ok_or_else(|| {
                BatchError::Invalid(
                    "JOB_COMPLETION_INDEX is set (a Kubernetes Indexed Job): give the job's completions as --shards N"
                        .into(),
                )
            })?;
            return Shard::new(index, count).map(Some);
        }
        Ok(None)
    }

    /// Whether the input at `position` of the manifest belongs to this shard.
    pub fn contains(&self, position: usize) -> bool {
        position % self.count == self.index
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn env(pairs: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
        let map: HashMap<String, String> = pairs.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
        move |k: &str| map.get(k).cloned()
    }

    #[test]
    fn parses_and_checks() {
        assert_eq!(Shard::parse("1/3").unwrap(), Shard { index: 1, count: 3 });
        assert_eq!(Shard::parse(" 0 / 1 ").unwrap(), Shard::ALL);
        for bad in ["3/3", "0/0", "1", "a/b", "-1/2", ""] {
            let e = Shard::parse(bad).unwrap_err().to_string();
            assert!(e.contains("shard"), "{bad}: {e}");
        }
    }

    #[test]
    fn every_position_in_exactly_one_shard() {
        for n in 1..6 {
            for pos in 0..40 {
                let owners = (0..n).filter(|&i| Shard::new(i, n).unwrap().contains(pos)).count();
                assert_eq!(owners, 1);
            }
        }
    }

    #[test]
    fn reads_slurm_and_kubernetes() {
        let s = Shard::from_env(None, &env(&[("SLURM_ARRAY_TASK_ID", "2"), ("SLURM_ARRAY_TASK_COUNT", "3")]));
        assert_eq!(s.unwrap(), Some(Shard { index: 2, count: 3 }));
        // An array 1-3: ids 1..=3 become shards 0..=2.
        let s = Shard::from_env(
            None,
            &env(&[("SLURM_ARRAY_TASK_ID", "3"), ("SLURM_ARRAY_TASK_COUNT", "3"), ("SLURM_ARRAY_TASK_MIN", "1")]),
        );
        assert_eq!(s.unwrap(), Some(Shard { index: 2, count: 3 }));
        let s = Shard::from_env(Some(4), &env(&[("JOB_COMPLETION_INDEX", "3")]));
        assert_eq!(s.unwrap(), Some(Shard { index: 3, count: 4 }));
        let e = Shard::from_env(None, &env(&[("JOB_COMPLETION_INDEX", "3")])).unwrap_err().to_string();
        assert!(e.contains("--shards"), "{e}");
        let e = Shard::from_env(None, &env(&[("SLURM_ARRAY_TASK_ID", "x")])).unwrap_err().to_string();
        assert!(e.contains("SLURM_ARRAY_TASK_ID='x'"), "{e}");
        assert_eq!(Shard::from_env(None, &env(&[])).unwrap(), None);
    }
}
