//! UC: `k` keyframes spread as evenly as integer frames allow.

use super::check_k;
use crate::Result;
use inbetween_core::KeyframeSet;

pub fn uniform(n: usize, k: usize) -> Result<KeyframeSet> {
    check_k(n, k)?;
    Ok(KeyframeSet::uniform(n, k)?)
}
