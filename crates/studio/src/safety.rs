//! The studio is a server, even if local (issue 23, "Safety"):
//! - it binds 127.0.0.1 unless `--listen ADDR` is given ([`crate::StudioConfig`]);
//! - a request whose `Host` is not the bound address or `localhost` is refused (a DNS-rebinding
//!   page on another name cannot reach it) — [`host_allowed`];
//! - a mutating request (anything but GET/HEAD/OPTIONS) from another origin is refused
//!   (`Origin`, else `Sec-Fetch-Site`) — [`origin_allowed`];
//! - request bodies are capped at `--max-upload` bytes (tower-http's limit, answered 413);
//! - a path the client names is read only under `--root` ([`resolve_under_root`]).

use std::net::{IpAddr, SocketAddr};
use std::path::{Component, Path, PathBuf};

use crate::error::{Result, StudioError};

/// Splits `host[:port]` (IPv6 in brackets) into host and port.
fn split_host(value: &str) -> Option<(&str, Option<u16>)> {
    let value = value.trim();
    if let Some(rest) = value.strip_prefix('[') {
        let end = rest.find(']')?;
        let host = &rest[..end];
        let after = &rest[end + 1..];
        let port = match after.strip_prefix(':') {
            Some(p) => Some(p.parse().ok()?),
            None if after.is_empty() => None,
            None => return None,
        };
        return Some((host, port));
    }
    match value.rsplit_once(':') {
        Some((h, p)) => Some((h, Some(p.parse().ok()?))),
        None => Some((value, None)),
    }
}

/// Whether a `Host` header names this server: `localhost` or an IP literal the server answers on
/// (the bound address; any IP when bound to an unspecified address such as 0.0.0.0), with the
/// bound port when a port is given. Other names are refused: a page on another name that
/// re-resolves to 127.0.0.1 (DNS rebinding) sends its own name.
pub fn host_allowed(host: Option<&str>, bound: SocketAddr) -> bool {
    let Some((name, port)) = host.and_then(split_host) else { return false };
    if port.is_some_and(|p| p != bound.port()) {
        return false;
    }
    if name.eq_ignore_ascii_case("localhost") {
        return bound.ip().is_loopback() || bound.ip().is_unspecified();
    }
    match name.parse::<IpAddr>() {
        Ok(ip) => ip == bound.ip() || bound.ip().is_unspecified() || (bound.ip().is_loopback() && ip.is_loopback()),
        Err(_) => false,
    }
}

/// Whether a request may change state: safe methods always; others only from this server's own
/// origin (`Origin` naming an allowed host), or from a client that sends neither `Origin` nor a
/// cross-site `Sec-Fetch-Site` (curl, the tests).
pub fn origin_allowed(method: &str, origin: Option<&str>, fetch_site: Option<&str>, bound: SocketAddr) -> bool {
    if matches!(method, "GET" | "HEAD" | "OPTIONS") {
        return true;
    }
    match origin {
        Some(o) => match o.strip_prefix("http://") {
            Some(rest) => host_allowed(Some(rest.trim_end_matches('/')), bound) && split_host(rest).is_some(),
            None => false,
        },
        None => !matches!(fetch_site, Some("cross-site") | Some("same-site")),
    }
}

/// `relative` (as the client sent it) resolved inside `root`: relative, no `..`, and after
/// following links still inside the root. Errors name the path and the rule.
pub fn resolve_under_root(root: Option<&Path>, relative: &str) -> Result<PathBuf> {
    let Some(root) = root else {
        return Err(StudioError::Forbidden(format!(
            "cannot read '{relative}': the studio reads files only under --root DIR, and none was given"
        )));
    };
    let rel = Path::new(relative);
    if relative.is_empty()
        || rel.components().any(|c| !matches!(c, Component::Normal(_)) && !matches!(c, Component::CurDir))
    {
        return Err(StudioError::Forbidden(format!(
            "'{relative}': expected a path relative to --root without '..' or a leading '/'"
        )));
    }
    let root = root.canonicalize().map_err(|e| StudioError::io(root, e))?;
    let full = root.join(rel);
    let real = full.canonicalize().map_err(|e| StudioError::NotFound(format!("{relative}: {e}")))?;
    if !real.starts_with(&root) {
        return Err(StudioError::Forbidden(format!("'{relative}' leads outside --root {}", root.display())));
    }
    Ok(real)
}

/// What [`list_under_root`] does with a folder it meets.
pub enum Folder {
    /// List it as one entry (a clip stored as a folder of frames), not what is inside.
    Take,
    /// Look inside.
    Descend,
}

/// Files (and folders `folder` says to take) under `root`, as paths relative to it with `/`
/// separators, sorted: at most six folders deep and `max` entries. `keep` gets the relative path of
/// every file; `folder` the path of every folder (relative, and on disk).
pub fn list_under_root(
    root: &Path,
    max: usize,
    keep: impl Fn(&str) -> bool,
    folder: impl Fn(&str, &Path) -> Folder,
) -> Vec<String> {
    fn walk(
        root: &Path,
        dir: &Path,
        depth: usize,
        max: usize,
        keep: &dyn Fn(&str) -> bool,
        folder: &dyn Fn(&str, &Path) -> Folder,
        out: &mut Vec<String>,
    ) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for e in entries.flatten() {
            if out.len() >= max {
                return;
            }
            let p = e.path();
            let Ok(kind) = e.file_type() else { continue };
            let Ok(rel) = p.strip_prefix(root) else { continue };
            let rel = rel.to_string_lossy().replace('\\', "/");
            if kind.is_dir() {
                match folder(&rel, &p) {
                    Folder::Take => out.push(format!("{rel}/")),
                    Folder::Descend if depth < 6 => walk(root, &p, depth + 1, max, keep, folder, out),
                    Folder::Descend => {}
                }
            } else if kind.is_file() && keep(&rel) {
                out.push(rel);
            }
        }
    }
    let mut out = Vec::new();
    walk(root, root, 0, max, &keep, &folder, &mut out);
    out.sort();
    out
}

/// The lower-case extension of a relative path ("" when none).
pub fn extension_of(rel: &str) -> String {
    Path::new(rel).extension().and_then(|x| x.to_str()).map(|x| x.to_ascii_lowercase()).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn local() -> SocketAddr {
        "127.0.0.1:7878".parse().unwrap()
    }

    #[test]
    fn hosts() {
        assert!(host_allowed(Some("127.0.0.1:7878"), local()));
        assert!(host_allowed(Some("localhost:7878"), local()));
        assert!(host_allowed(Some("localhost"), local()));
        assert!(host_allowed(Some("[::1]:7878"), local()));
        assert!(!host_allowed(Some("evil.example:7878"), local()));
        assert!(!host_allowed(Some("127.0.0.1:80"), local()));
        assert!(!host_allowed(None, local()));
        assert!(!host_allowed(Some("10.0.0.1:7878"), local()));
        let any: SocketAddr = "0.0.0.0:7878".parse().unwrap();
        assert!(host_allowed(Some("10.0.0.1:7878"), any));
        assert!(!host_allowed(Some("studio.example:7878"), any));
    }

    #[test]
    fn origins() {
        assert!(origin_allowed("GET", Some("http://evil.example"), Some("cross-site"), local()));
        assert!(origin_allowed("POST", Some("http://127.0.0.1:7878"), Some("same-origin"), local()));
        assert!(!origin_allowed("POST", Some("http://evil.example"), None, local()));
        assert!(!origin_allowed("POST", Some("null"), None, local()));
        assert!(!origin_allowed("POST", None, Some("cross-site"), local()));
        assert!(origin_allowed("POST", None, None, local()));
    }

    #[test]
    fn root_paths() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.bvh"), "x").unwrap();
        assert!(resolve_under_root(Some(dir.path()), "a.bvh").is_ok());
        for bad in ["../a.bvh", "/etc/passwd", "", "x/../../a"] {
            let e = resolve_under_root(Some(dir.path()), bad).unwrap_err();
            assert_eq!(e.status(), 403, "{bad}: {e}");
        }
        assert_eq!(resolve_under_root(None, "a.bvh").unwrap_err().status(), 403);
        assert_eq!(resolve_under_root(Some(dir.path()), "missing.bvh").unwrap_err().status(), 404);
    }
}
