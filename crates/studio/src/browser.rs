//! Headless Chromium for the browser tests and `inbetween studio bench`, driven over the W3C
//! WebDriver protocol through `chromedriver` (Debian's `chromium-driver`). WebDriver is JSON over
//! HTTP on this machine's loopback, so the client below is a few requests on a `TcpStream` and
//! needs no crate beyond serde_json and base64.
//!
//! Debian's Chromium gives WebGL2 headless through SwiftShader (`--use-angle=swiftshader
//! --enable-unsafe-swiftshader`); as root it needs `--no-sandbox`; on a closed network background
//! networking, component updates and sync are off; every launch gets a new empty profile folder.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use base64::Engine;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};

fn find(env: &str, names: &[&str]) -> Option<PathBuf> {
    if let Some(p) = std::env::var_os(env) {
        let p = PathBuf::from(p);
        return p.is_file().then_some(p);
    }
    names.iter().map(PathBuf::from).find(|p| p.is_file())
}

/// The Chromium binary: `$INBETWEEN_CHROMIUM`, else the first of the usual paths that exists.
pub fn chromium_path() -> Option<PathBuf> {
    find(
        "INBETWEEN_CHROMIUM",
        &["/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome", "/usr/bin/google-chrome-stable"],
    )
}

/// The chromedriver binary: `$INBETWEEN_CHROMEDRIVER`, else the usual paths.
pub fn chromedriver_path() -> Option<PathBuf> {
    find("INBETWEEN_CHROMEDRIVER", &["/usr/bin/chromedriver", "/usr/lib/chromium/chromedriver"])
}

/// Both, or a line saying which is missing (tests print `skipped: no chromium`).
pub fn available() -> std::result::Result<(PathBuf, PathBuf), String> {
    match (chromium_path(), chromedriver_path()) {
        (Some(c), Some(d)) => Ok((c, d)),
        (None, _) => Err("no chromium".into()),
        (_, None) => Err("no chromium (chromedriver missing: install chromium-driver)".into()),
    }
}

fn err(e: impl std::fmt::Display) -> StudioError {
    StudioError::Browser(e.to_string())
}

/// One WebDriver HTTP request; returns the `value` of the answer, or its error message.
fn call(addr: SocketAddr, method: &str, path: &str, body: Option<&Value>) -> Result<Value> {
    let mut s = TcpStream::connect(addr).map_err(err)?;
    s.set_read_timeout(Some(Duration::from_secs(600))).map_err(err)?;
    let body = body.map(|b| b.to_string()).unwrap_or_default();
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Type: application/json; charset=utf-8\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).and_then(|_| s.write_all(body.as_bytes())).map_err(err)?;
    // chromedriver answers `Connection: close` but keeps the socket open, so the body is read by
    // its Content-Length (or chunk by chunk), not to the end of the stream.
    let payload = read_response(&mut s).map_err(|e| err(format!("chromedriver {path}: {e}")))?;
    let v: Value = serde_json::from_slice(&payload).map_err(|e| err(format!("chromedriver {path}: {e}")))?;
    let value = v.get("value").cloned().unwrap_or(Value::Null);
    if let Some(e) = value.get("error").and_then(|e| e.as_str()) {
        let msg = value.get("message").and_then(|m| m.as_str()).unwrap_or("");
        let first = msg.lines().next().unwrap_or("");
        return Err(StudioError::Browser(format!("{method} {path}: {e}: {first}")));
    }
    Ok(value)
}

/// Reads one HTTP response: the head, then `Content-Length` bytes, or chunks up to the last one,
/// or (with neither) to the end of the stream.
fn read_response(s: &mut TcpStream) -> std::io::Result<Vec<u8>> {
    let mut raw = Vec::new();
    let mut buf = [0u8; 16 * 1024];
    let split = loop {
        if let Some(i) = raw.windows(4).position(|w| w == b"\r\n\r\n") {
            break i;
        }
        let n = s.read(&mut buf)?;
        if n == 0 {
            return Err(std::io::Error::new(std::io::ErrorKind::UnexpectedEof, "no response head"));
        }
        raw.extend_from_slice(&buf[..n]);
    };
    let head = String::from_utf8_lossy(&raw[..split]).to_ascii_lowercase();
    let mut body = raw[split + 4..].to_vec();
    let length =
        head.lines().find_map(|l| l.strip_prefix("content-length:").and_then(|v| v.trim().parse::<usize>().ok()));
    let chunked = head.contains("transfer-encoding: chunked") || head.contains("transfer-encoding:chunked");
    loop {
        let done = match length {
            Some(n) => body.len() >= n,
            None if chunked => body.windows(5).any(|w| w == b"0\r\n\r\n"),
            None => false,
        };
        if done {
            break;
        }
        let n = s.read(&mut buf)?;
        if n == 0 {
            break;
        }
        body.extend_from_slice(&buf[..n]);
    }
    if let Some(n) = length {
        body.truncate(n);
    } else if chunked {
        body = dechunk(&body);
    }
    Ok(body)
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    while let Some(eol) = b.windows(2).position(|w| w == b"\r\n") {
        let size = usize::from_str_radix(String::from_utf8_lossy(&b[..eol]).trim(), 16).unwrap_or(0);
        if size == 0 || b.len() < eol + 2 + size {
            break;
        }
        out.extend_from_slice(&b[eol + 2..eol + 2 + size]);
        b = &b[(eol + 4 + size).min(b.len())..];
    }
    out
}

/// One headless Chromium session (its chromedriver is ended on drop).
pub struct Browser {
    driver: Child,
    addr: SocketAddr,
    session: String,
    _profile: tempfile::TempDir,
}

impl Browser {
    /// Starts chromedriver and a headless Chromium with a `width` × `height` window.
    pub fn launch(chromium: &Path, chromedriver: &Path, width: u32, height: u32) -> Result<Browser> {
        let port = TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr()).map_err(err)?.port();
        let addr: SocketAddr = ([127, 0, 0, 1], port).into();
        let driver = Command::new(chromedriver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| err(format!("{}: {e}", chromedriver.display())))?;
        let profile = tempfile::tempdir().map_err(err)?;
        let mut b = Browser { driver, addr, session: String::new(), _profile: profile };
        let start = Instant::now();
        while call(addr, "GET", "/status", None).is_err() {
            if start.elapsed() > Duration::from_secs(30) {
                return Err(err("chromedriver did not answer within 30 s"));
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let args = vec![
            "--headless=new".to_string(),
            "--no-sandbox".into(),
            "--use-angle=swiftshader".into(),
            "--enable-unsafe-swiftshader".into(),
            "--ignore-gpu-blocklist".into(),
            "--disable-background-networking".into(),
            "--disable-component-update".into(),
            "--disable-sync".into(),
            "--no-first-run".into(),
            "--disable-dev-shm-usage".into(),
            "--hide-scrollbars".into(),
            format!("--window-size={width},{height}"),
            format!("--user-data-dir={}", b._profile.path().display()),
        ];
        let caps = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": chromium.display().to_string(), "args": args},
        }}});
        let v = call(addr, "POST", "/session", Some(&caps))?;
        b.session = v["sessionId"].as_str().ok_or_else(|| err(format!("no session in {v}")))?.to_string();
        b.cmd("POST", "timeouts", Some(&json!({"script": 600_000, "pageLoad": 120_000})))?;
        Ok(b)
    }

    fn cmd(&self, method: &str, what: &str, body: Option<&Value>) -> Result<Value> {
        call(self.addr, method, &format!("/session/{}/{what}", self.session), body)
    }

    /// Opens `url` and waits for the page's load event.
    pub fn goto(&self, url: &str) -> Result<()> {
        self.cmd("POST", "url", Some(&json!({"url": url}))).map(|_| ())
    }

    /// Evaluates a JavaScript expression in the page (a promise is awaited) and returns its value
    /// as JSON.
    pub fn eval(&self, expr: &str) -> Result<Value> {
        let script = format!("return (async () => {{ return await ({expr}); }})();");
        self.cmd("POST", "execute/sync", Some(&json!({"script": script, "args": []})))
            .map_err(|e| StudioError::Browser(format!("{expr}: {e}")))
    }

    /// Sets the files of the `<input type=file>` matched by `selector` (its change event fires).
    pub fn set_files(&self, selector: &str, files: &[&Path]) -> Result<()> {
        let el = self.cmd("POST", "element", Some(&json!({"using": "css selector", "value": selector})))?;
        let id = el
            .as_object()
            .and_then(|o| o.values().next())
            .and_then(|v| v.as_str())
            .ok_or_else(|| err(format!("{selector}: no element")))?
            .to_string();
        let text: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
        self.cmd("POST", &format!("element/{id}/value"), Some(&json!({"text": text.join("\n")}))).map(|_| ())
    }

    /// A PNG of the visible page.
    pub fn screenshot(&self) -> Result<Vec<u8>> {
        let v = self.cmd("GET", "screenshot", None)?;
        let b64 = v.as_str().ok_or_else(|| err("screenshot: no data"))?;
        base64::engine::general_purpose::STANDARD.decode(b64).map_err(err)
    }

    /// chromedriver's process id (Chromium runs as its child), for memory figures.
    pub fn pid(&self) -> u32 {
        self.driver.id()
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        if !self.session.is_empty() {
            let _ = call(self.addr, "DELETE", &format!("/session/{}", self.session), None);
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}

/// Resident memory (bytes) of process `pid` and its descendants, from `/proc` (Linux; None
/// elsewhere).
pub fn tree_rss_bytes(pid: u32) -> Option<u64> {
    let page = 4096u64;
    let entries = std::fs::read_dir("/proc").ok()?;
    let mut parents = Vec::new();
    for e in entries.flatten() {
        let Ok(p) = e.file_name().to_string_lossy().parse::<u32>() else { continue };
        let Ok(stat) = std::fs::read_to_string(format!("/proc/{p}/stat")) else { continue };
        let Some(after) = stat.rsplit_once(')').map(|x| x.1) else { continue };
        let ppid: u32 = after.split_whitespace().nth(1).and_then(|s| s.parse().ok()).unwrap_or(0);
        parents.push((p, ppid));
    }
    let mut tree = vec![pid];
    let mut i = 0;
    while i < tree.len() {
        let cur = tree[i];
        tree.extend(parents.iter().filter(|(_, pp)| *pp == cur).map(|(p, _)| *p));
        i += 1;
    }
    let mut total = None;
    for p in tree {
        if let Ok(s) = std::fs::read_to_string(format!("/proc/{p}/statm")) {
            if let Some(rss) = s.split_whitespace().nth(1).and_then(|v| v.parse::<u64>().ok()) {
                total = Some(total.unwrap_or(0) + rss * page);
            }
        }
    }
    total
}
