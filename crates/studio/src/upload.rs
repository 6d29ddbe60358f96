//! What every panel's upload shares: the `?name=` query, the name as the studio keeps it (no
//! control characters or path separators, at most 200 characters), the body as UTF-8 text with
//! an error naming file, line and byte, and a job that fails at once (so the page's `ready()`
//! sees a refused upload like any other job's error).

use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};
use crate::jobs::Jobs;

#[derive(Deserialize)]
pub struct UploadQuery {
    /// The file's name as the user picked it (its extension picks the parser).
    pub name: String,
}

impl UploadQuery {
    /// [`clean_name`] of the query's name.
    pub fn name(&self) -> String {
        clean_name(&self.name)
    }
}

/// A file name as the studio shows and stores it: no control characters, no `/` or `\`, at most
/// 200 characters.
pub fn clean_name(name: &str) -> String {
    name.chars().filter(|c| !c.is_control() && *c != '/' && *c != '\\').take(200).collect()
}

/// The upload as text, or an error naming the file, the line and the first byte that is not UTF-8.
pub fn utf8(name: &str, bytes: &[u8]) -> Result<String> {
    inbetween_io::text::utf8(bytes.to_vec()).map_err(|e| {
        StudioError::Engine(format!("{name}:{}: expected UTF-8 text, found byte 0x{:02x}", e.line, e.byte))
    })
}

/// A job that fails at once with `e`; the answer names it like any job's.
pub fn failed_now(jobs: &Jobs, e: StudioError) -> Value {
    let id = jobs.spawn("open", move |_| Err(e));
    json!({"job": id})
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_lose_separators_and_control_characters_and_text_errors_name_the_line() {
        assert_eq!(clean_name("../a\\b/c\n.bvh"), "..abc.bvh");
        assert_eq!(clean_name(&"x".repeat(300)).len(), 200);
        let err = utf8("take.bvh", b"HIERARCHY\nROOT \xff").unwrap_err().to_string();
        assert_eq!(err, "take.bvh:2: expected UTF-8 text, found byte 0xff");
    }
}
