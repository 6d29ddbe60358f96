//! Where the shared real-data corpus lives: `$INBETWEEN_DATA`, else `../shared/data` next to the
//! workspace (or the current directory).

use std::path::PathBuf;

/// The shared data folder, if present. Tests and benchmarks on real data call this and print
/// `skipped: no data at …` when it returns `Err(path_looked_at)`.
pub fn shared_data_dir() -> Result<PathBuf, PathBuf> {
    if let Some(p) = std::env::var_os("INBETWEEN_DATA") {
        let p = PathBuf::from(p);
        return if p.is_dir() { Ok(p) } else { Err(p) };
    }
    let from_workspace = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
    let from_cwd = PathBuf::from("../shared/data");
    for p in [&from_workspace, &from_cwd] {
        if p.is_dir() {
            return Ok(p.canonicalize().unwrap_or_else(|_| p.clone()));
        }
    }
    Err(from_workspace)
}

/// Runs `f` with the data folder, or prints the standard skip line and returns `None`.
pub fn with_shared_data<T>(what: &str, f: impl FnOnce(PathBuf) -> T) -> Option<T> {
    match shared_data_dir() {
        Ok(p) => Some(f(p)),
        Err(p) => {
            println!("skipped: no data at {} ({what})", p.display());
            None
        }
    }
}
