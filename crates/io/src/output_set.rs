//! A run writes its whole set of outputs or none: [`OutputSet`] stages every file (or folder) of a
//! run in a hidden temporary folder beside its target and moves them all into place only at
//! [`OutputSet::commit`]. A run that fails, is cancelled or panics before the commit drops the set,
//! which deletes everything staged, so no partial set of outputs is left behind.
//!
//! ```
//! # fn main() -> std::io::Result<()> {
//! let dir = tempfile::tempdir()?;
//! let (clip, png) = (dir.path().join("edit.csv"), dir.path().join("edit.png"));
//! let mut set = inbetween_io::OutputSet::new();
//! inbetween_io::write_atomic(&set.file(&clip)?, b"time_s\n")?;
//! inbetween_io::write_atomic(&set.file(&png)?, b"png")?;
//! assert!(!clip.exists(), "nothing is visible before the commit");
//! set.commit()?;
//! assert!(clip.exists() && png.exists());
//! # Ok(()) }
//! ```
//!
//! Writers keep taking paths: [`OutputSet::file`] hands out a staging path with the target's own
//! file name (so a writer that looks at the extension behaves the same) and [`OutputSet::dir`] a
//! staging folder for a writer that fills a folder. The commit renames within each target's parent
//! folder, so it is quick and never copies. A folder target that already exists is merged into
//! (files of the same name replaced, others kept), so a run never deletes a user's unrelated files.
//! The only window in which a set is partly in place is the commit's own renames; a process killed
//! there (or before, by SIGKILL) can leave a hidden `.inbetween-staging-*` folder, never a partial
//! set under the target names.

use std::path::{Path, PathBuf};

/// The prefix of staging folders (hidden on Unix).
pub const STAGING_PREFIX: &str = ".inbetween-staging-";

/// Outputs staged for one run; see the [module docs](self).
#[derive(Debug, Default)]
pub struct OutputSet {
    /// One staging folder per target parent folder (renames must stay on one file system).
    staging: Vec<(PathBuf, tempfile::TempDir)>,
    /// (staging path, final path, is a folder), in the order they were asked for.
    entries: Vec<(PathBuf, PathBuf, bool)>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// Where to write the file that belongs at `target` (its parent folder is created when
    /// missing). Asking twice for the same target gives the same path.
    pub fn file(&mut self, target: &Path) -> std::io::Result<PathBuf> {
        self.stage(target, false)
    }

    /// A staging folder (created, empty) to fill with what belongs in the folder `target`.
    pub fn dir(&mut self, target: &Path) -> std::io::Result<PathBuf> {
        let p = self.stage(target, true)?;
        std::fs::create_dir_all(&p)?;
        Ok(p)
    }

    /// The final paths of the set, in the order they were staged.
    pub fn targets(&self) -> impl Iterator<Item = &Path> {
        self.entries.iter().map(|(_, t, _)| t.as_path())
    }

    fn stage(&mut self, target: &Path, is_dir: bool) -> std::io::Result<PathBuf> {
        if let Some((s, _, d)) = self.entries.iter().find(|(_, t, _)| t == target) {
            if *d != is_dir {
                return Err(std::io::Error::other(format!(
                    "{}: staged both as a file and as a folder",
                    target.display()
                )));
            }
            return Ok(s.clone());
        }
        let name = target.file_name().ok_or_else(|| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!("{}: expected an output path that ends in a file or folder name", target.display()),
            )
        })?;
        let parent = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let existing = self.staging.iter().position(|(p, _)| *p == parent);
        let i = match existing {
            Some(i) => i,
            None => {
                std::fs::create_dir_all(&parent)?;
                let tmp = tempfile::Builder::new().prefix(STAGING_PREFIX).tempdir_in(&parent)?;
                self.staging.push((parent, tmp));
                self.staging.len() - 1
            }
        };
        let path = self.staging[i].1.path().join(name);
        self.entries.push((path.clone(), target.to_path_buf(), is_dir));
        Ok(path)
    }

    /// Moves every staged output into place and removes the staging folders. An entry that was
    /// asked for but never written is an error (the set would not be whole), reported before
    /// anything is moved.
    pub fn commit(mut self) -> std::io::Result<()> {
        for (staged, target, _) in &self.entries {
            if !staged.exists() {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!("{}: staged output was never written", target.display()),
                ));
            }
        }
        for (staged, target, is_dir) in std::mem::take(&mut self.entries) {
            if is_dir {
                move_dir(&staged, &target)?;
            } else {
                std::fs::rename(&staged, &target)?;
            }
        }
        // Dropping the TempDirs removes the (now empty) staging folders.
        for (_, tmp) in self.staging.drain(..) {
            tmp.close()?;
        }
        Ok(())
    }
}

/// Moves the folder `from` to `to`: one rename when `to` does not exist, else a merge (entries of
/// `from` replace those of the same name in `to`, folders merged recursively).
fn move_dir(from: &Path, to: &Path) -> std::io::Result<()> {
    if !to.exists() {
        // Staging folders are created private (0700); outputs are ordinary user folders.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(from, std::fs::Permissions::from_mode(0o755))?;
        }
        return std::fs::rename(from, to);
    }
    if !to.is_dir() {
        return Err(std::io::Error::other(format!("{}: expected a folder, found a file", to.display())));
    }
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let dest = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            move_dir(&entry.path(), &dest)?;
        } else {
            std::fs::rename(entry.path(), &dest)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn dropped_set_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        {
            let mut set = OutputSet::new();
            std::fs::write(set.file(&dir.path().join("a.csv")).unwrap(), b"a").unwrap();
            let sub = set.dir(&dir.path().join("weights")).unwrap();
            std::fs::write(sub.join("w.bpk"), b"w").unwrap();
            assert_eq!(names(dir.path()).len(), 1, "one staging folder");
            assert!(names(dir.path())[0].starts_with(STAGING_PREFIX));
        }
        assert!(names(dir.path()).is_empty(), "a run that fails before the commit leaves no output and no staging");
    }

    #[test]
    fn commit_moves_files_and_folders_into_place() {
        let dir = tempfile::tempdir().unwrap();
        let other = dir.path().join("previews/deep");
        let mut set = OutputSet::new();
        let a = set.file(&dir.path().join("a.csv")).unwrap();
        assert_eq!(a.file_name().unwrap(), "a.csv", "the target's own name, so extensions still choose formats");
        assert_eq!(set.file(&dir.path().join("a.csv")).unwrap(), a, "same target, same staging path");
        std::fs::write(&a, b"a").unwrap();
        std::fs::write(set.file(&other.join("a.png")).unwrap(), b"png").unwrap();
        let w = set.dir(&dir.path().join("weights")).unwrap();
        std::fs::create_dir(w.join("inner")).unwrap();
        std::fs::write(w.join("inner/w.bpk"), b"w").unwrap();
        assert_eq!(set.targets().count(), 3);
        set.commit().unwrap();
        assert_eq!(names(dir.path()), ["a.csv", "previews", "weights"]);
        assert_eq!(std::fs::read(dir.path().join("a.csv")).unwrap(), b"a");
        assert_eq!(std::fs::read(other.join("a.png")).unwrap(), b"png");
        assert_eq!(names(&other), ["a.png"], "no staging folder left in the second parent");
        assert_eq!(std::fs::read(dir.path().join("weights/inner/w.bpk")).unwrap(), b"w");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(dir.path().join("weights")).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o755);
        }
    }

    #[test]
    fn existing_folder_is_merged_not_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out");
        std::fs::create_dir_all(target.join("sub")).unwrap();
        std::fs::write(target.join("keep.txt"), b"user's").unwrap();
        std::fs::write(target.join("sub/old.bpk"), b"old").unwrap();
        std::fs::write(target.join("sub/new.bpk"), b"old").unwrap();
        let mut set = OutputSet::new();
        let s = set.dir(&target).unwrap();
        std::fs::create_dir(s.join("sub")).unwrap();
        std::fs::write(s.join("sub/new.bpk"), b"new").unwrap();
        set.commit().unwrap();
        assert_eq!(std::fs::read(target.join("keep.txt")).unwrap(), b"user's");
        assert_eq!(std::fs::read(target.join("sub/old.bpk")).unwrap(), b"old");
        assert_eq!(std::fs::read(target.join("sub/new.bpk")).unwrap(), b"new");
        assert_eq!(names(dir.path()), ["out"]);
    }

    /// A job that writes its set file by file and is cancelled half-way leaves none of it.
    #[test]
    fn run_cancelled_mid_way_leaves_no_partial_set() {
        use inbetween_core::cancel::{Cancel, Cancelled};
        fn job(dir: &Path, cancel: &Cancel, cancel_after: usize) -> Result<(), Cancelled> {
            let mut set = OutputSet::new();
            for (i, name) in ["track.json", "track.gltf", "preview.gif"].iter().enumerate() {
                cancel.check()?;
                crate::write_atomic(&set.file(&dir.join(name)).unwrap(), name.as_bytes()).unwrap();
                if i + 1 == cancel_after {
                    cancel.cancel(); // the studio's cancel button, pressed while the job runs
                }
            }
            cancel.check()?;
            set.commit().unwrap();
            Ok(())
        }
        let dir = tempfile::tempdir().unwrap();
        for after in 1..=3 {
            assert_eq!(job(dir.path(), &Cancel::new(), after), Err(Cancelled::Requested));
            assert!(names(dir.path()).is_empty(), "cancelled after {after} file(s): nothing left");
        }
        assert_eq!(job(dir.path(), &Cancel::new(), 0), Ok(()));
        assert_eq!(names(dir.path()), ["preview.gif", "track.gltf", "track.json"]);
    }

    #[test]
    fn unwritten_entry_fails_the_commit_before_anything_moves() {
        let dir = tempfile::tempdir().unwrap();
        let mut set = OutputSet::new();
        std::fs::write(set.file(&dir.path().join("a.csv")).unwrap(), b"a").unwrap();
        set.file(&dir.path().join("b.png")).unwrap();
        let e = set.commit().unwrap_err();
        assert!(e.to_string().contains("b.png: staged output was never written"), "{e}");
        assert!(names(dir.path()).is_empty(), "nothing moved, staging removed");
    }

    #[test]
    fn path_without_a_name_is_refused() {
        let mut set = OutputSet::new();
        let e = set.file(Path::new("/")).unwrap_err();
        assert!(e.to_string().contains("expected an output path that ends in a file or folder name"), "{e}");
    }
}
