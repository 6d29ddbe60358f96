//! The inputs of a batch: every file below a folder whose extension the job reads, in one stable
//! order (their paths relative to the folder, compared as `/`-separated text), so that every shard
//! of every machine sees the same list. Hidden files and folders (a name starting with `.`, such as
//! the staging folders of an interrupted run) are left out; links are followed.

use crate::BatchError;
use std::path::{Path, PathBuf};

/// One input: where it is, and its path relative to the batch's folder (with `/` separators), which
/// names it in result lines and places its outputs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Input {
    pub path: PathBuf,
    pub rel: String,
}

/// The inputs below `dir` with one of `extensions` (lower case, without the dot; compared without
/// case), sorted by relative path.
pub fn scan(dir: &Path, extensions: &[&str]) -> Result<Vec<Input>, BatchError> {
    if !dir.is_dir() {
        return Err(BatchError::Invalid(format!("{}: expected a folder of inputs", dir.display())));
    }
    let mut inputs = Vec::new();
    let walk = walkdir::WalkDir::new(dir)
        .follow_links(true)
        .into_iter()
        .filter_entry(|e| e.depth() == 0 || !e.file_name().to_str().is_some_and(|n| n.starts_with('.')));
    for entry in walk {
        let entry = entry.map_err(|e| {
            let path = e.path().unwrap_or(dir).to_path_buf();
            BatchError::Io { path, source: e.into_io_error().unwrap_or_else(|| std::io::Error::other("link loop")) }
        })?;
        if !entry.file_type().is_file() {
            continue;
        }
        let ext = entry.path().extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
        if !ext.is_some_and(|e| extensions.contains(&e.as_str())) {
            continue;
        }
        let rel_path = entry.path().strip_prefix(dir).expect("walkdir yields paths below its root");
        let rel = rel_path
            .components()
            .map(|c| {
                c.as_os_str().to_str().map(str::to_string).ok_or_else(|| {
                    BatchError::Invalid(format!("{}: a file name that is not UTF-8", entry.path().display()))
                })
            })
            .collect::<Result<Vec<_>, _>>()?
            .join("/");
        inputs.push(Input { path: entry.path().to_path_buf(), rel });
    }
    inputs.sort_by(|a, b| a.rel.cmp(&b.rel));
    Ok(inputs)
}

/// `rel` with its extension replaced by `new_ext` (`cmu/01_01.bvh`, `ibk` → `cmu/01_01.ibk`), or
/// removed when `new_ext` is empty (a folder per input).
pub fn with_extension(rel: &str, new_ext: &str) -> String {
    let (dir, name) = rel.rsplit_once('/').map_or(("", rel), |(d, n)| (d, n));
    let stem = name.rsplit_once('.').map_or(name, |(s, _)| s);
    let name = if new_ext.is_empty() { stem.to_string() } else { format!("{stem}.{new_ext}") };
    if dir.is_empty() {
        name
    } else {
        format!("{dir}/{name}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stable_order_hidden_left_out_and_extensions_without_case() {
        let dir = tempfile::tempdir().unwrap();
        for f in ["b/2.bvh", "a.BVH", "b/1.bvh", ".hidden/x.bvh", "b/.y.bvh", "notes.txt", "c/d/e.amc"] {
            let p = dir.path().join(f);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, "x").unwrap();
        }
        let rels: Vec<String> = scan(dir.path(), &["bvh", "amc"]).unwrap().into_iter().map(|i| i.rel).collect();
        assert_eq!(rels, ["a.BVH", "b/1.bvh", "b/2.bvh", "c/d/e.amc"]);
        let e = scan(&dir.path().join("missing"), &["bvh"]).unwrap_err().to_string();
        assert!(e.contains("expected a folder"), "{e}");
    }

    #[test]
    fn output_names_mirror_inputs() {
        assert_eq!(with_extension("cmu/01_01.bvh", "ibk"), "cmu/01_01.ibk");
        assert_eq!(with_extension("walk.amc", "keys.json"), "walk.keys.json");
        assert_eq!(with_extension("s/story.txt", ""), "s/story");
        assert_eq!(with_extension("noext", "ibk"), "noext.ibk");
    }
}
