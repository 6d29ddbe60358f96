//! Which inputs of a manifest one process runs. Every shard computes the same split from the
//! manifest alone: the inputs by size, largest first (ties in manifest order), each given to the
//! shard with the fewest bytes so far (ties to the lower index), so shards finish close together
//! when cost grows with size ([`split_by_size`]).
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

    /// The manifest positions of this shard's inputs, in manifest order, given every input's size.
    pub fn positions(&self, sizes: &[u64]) -> Vec<usize> {
        let owner = split_by_size(sizes, self.count);
        (0..sizes.len()).filter(|&i| owner[i] == self.index).collect()
    }
}

/// The shard of each input (by manifest position): largest first, each to the shard with the fewest
/// bytes so far; the same on every machine for the same manifest and sizes.
pub fn split_by_size(sizes: &[u64], count: usize) -> Vec<usize> {
    let count = count.max(1);
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by(|&a, &b| sizes[b].cmp(&sizes[a]).then(a.cmp(&b)));
    let mut load = vec![0u128; count];
    let mut owner = vec![0; sizes.len()];
    for i in order {
        let shard = (0..count).min_by_key(|&s| (load[s], s)).expect("at least one shard");
        load[shard] += u128::from(sizes[i]) + 1;
        owner[i] = shard;
    }
    owner
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
    fn every_position_in_exactly_one_shard_and_bytes_balanced() {
        let sizes: Vec<u64> = (0..40u64).map(|i| (i * 7919) % 97 + 1).collect();
        for n in 1..6 {
            let mut seen = vec![0; sizes.len()];
            let mut bytes = vec![0u64; n];
            for (i, b) in bytes.iter_mut().enumerate() {
                for p in Shard::new(i, n).unwrap().positions(&sizes) {
                    seen[p] += 1;
                    *b += sizes[p];
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "{n} shards: {seen:?}");
            let (lo, hi) = (*bytes.iter().min().unwrap(), *bytes.iter().max().unwrap());
            assert!(hi - lo <= 97, "{n} shards: {bytes:?}");
        }
        // One large input and three small: the large one alone.
        assert_eq!(split_by_size(&[10, 100, 10, 10], 2), vec![1, 0, 1, 1]);
        assert!(split_by_size(&[], 3).is_empty());
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
