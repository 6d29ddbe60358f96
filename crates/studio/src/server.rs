//! Start/stop and routes of the studio server: its own routes (the page, info, result files,
//! jobs), each panel's router nested under `/api/<panel>`, and the safety layers around them all.

use std::convert::Infallible;
use std::future::IntoFuture;
use std::net::SocketAddr;
use std::sync::Arc;

use axum::body::{Body, Bytes};
use axum::extract::{DefaultBodyLimit, Path as UrlPath, Query, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::{json, Value};

use crate::error::{Result, StudioError};
use crate::state::Shared;
pub use crate::state::{StudioConfig, DEFAULT_MAX_UPLOAD};
use crate::{assets, camera_panel, face_panel, mocap_panel, safety, script_panel, video_panel};

/// The server's own handlers' state: the shared parts (each panel has its own, [`crate::state::Panel`]).
type AppState = Shared;

/// Errors as JSON with their status code.
impl IntoResponse for StudioError {
    fn into_response(self) -> Response {
        let status = StatusCode::from_u16(self.status()).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
        (status, Json(json!({"error": self.to_string()}))).into_response()
    }
}

fn refuse(status: StatusCode, msg: String) -> Response {
    (status, Json(json!({"error": msg}))).into_response()
}

/// Host and Origin checks ([`safety`]) before any route.
async fn guard(State(st): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    let headers = req.headers();
    let host = headers.get(header::HOST).and_then(|v| v.to_str().ok());
    if !safety::host_allowed(host, st.bound) {
        return refuse(
            StatusCode::FORBIDDEN,
            format!("refused: Host '{}' is not this studio's address ({} or localhost)", host.unwrap_or(""), st.bound),
        );
    }
    let origin = headers.get(header::ORIGIN).and_then(|v| v.to_str().ok());
    let site = headers.get("sec-fetch-site").and_then(|v| v.to_str().ok());
    if !safety::origin_allowed(req.method().as_str(), origin, site, st.bound) {
        return refuse(
            StatusCode::FORBIDDEN,
            format!("refused: a {} from another origin ({})", req.method(), origin.unwrap_or("cross-site")),
        );
    }
    next.run(req).await
}

/// The router of a studio answering on `bound`.
pub fn router(state: Arc<AppState>) -> Router {
    let max = usize::try_from(state.config.max_upload).unwrap_or(usize::MAX);
    let mut app = Router::new()
        .route("/", get(static_file))
        .route("/{*path}", get(static_file))
        .route("/api/info", get(info))
        .route("/api/files/{*name}", get(file))
        .route("/api/jobs/{id}/events", get(events))
        .route("/api/jobs/{id}/cancel", post(cancel))
        .route("/api/jobs/{id}", get(job_status));
    if state.config.test_routes {
        app = app.route("/api/test/panic", post(test_panic));
    }
    let app = app
        .with_state(state.clone())
        .nest("/api/script", script_panel::router(state.clone()))
        .nest("/api/mocap", mocap_panel::router(state.clone()))
        .nest("/api/face", face_panel::router(state.clone()))
        .nest("/api/video", video_panel::router(state.clone()))
        .nest("/api/camera", camera_panel::router(state.clone()));
    app.layer(DefaultBodyLimit::max(max))
        .layer(tower_http::limit::RequestBodyLimitLayer::new(max))
        .layer(middleware::from_fn_with_state(state.clone(), guard))
        .layer(tower_http::catch_panic::CatchPanicLayer::custom(panic_response))
}

fn panic_response(err: Box<dyn std::any::Any + Send + 'static>) -> Response {
    let what = err
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| err.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    refuse(StatusCode::INTERNAL_SERVER_ERROR, format!("internal error: {what} (the studio keeps serving)"))
}

async fn test_panic() -> Response {
    panic!("test route: a handler panicked on purpose")
}

async fn static_file(req: Request) -> Response {
    let path = req.uri().path().to_string();
    if let Some(why) = assets::missing() {
        if path == "/" || path == "/index.html" {
            return ([(header::CONTENT_TYPE, "text/html; charset=utf-8")], assets::missing_page(why)).into_response();
        }
    }
    match assets::get(&path) {
        Some((bytes, ct)) => ([(header::CONTENT_TYPE, ct)], Bytes::from_static(bytes)).into_response(),
        None => refuse(StatusCode::NOT_FOUND, format!("no page file {path}")),
    }
}

async fn info(State(st): State<Arc<AppState>>) -> Json<Value> {
    Json(json!({
        "version": env!("CARGO_PKG_VERSION"),
        "root": st.config.root.as_ref().map(|p| p.display().to_string()),
        "max_upload": st.config.max_upload,
        "three": assets::missing().is_none(),
    }))
}

#[derive(Deserialize)]
struct FileQuery {
    download: Option<u8>,
}

async fn file(State(st): State<Arc<AppState>>, UrlPath(name): UrlPath<String>, q: Query<FileQuery>) -> Response {
    let Some(artifact) = st.file(&name) else {
        return StudioError::NotFound(format!("no result file '{name}' (run the job first)")).into_response();
    };
    let ct = artifact.content_type.clone();
    let bytes = match tokio::task::spawn_blocking(move || artifact.bytes()).await {
        Ok(b) => b,
        Err(e) => {
            return StudioError::Engine(format!("making '{name}' failed: {e} (the studio keeps serving)"))
                .into_response()
        }
    };
    let mut headers = HeaderMap::new();
    headers.insert(
        header::CONTENT_TYPE,
        HeaderValue::from_str(&ct).unwrap_or(HeaderValue::from_static("application/octet-stream")),
    );
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    if q.download == Some(1) {
        let base = name.rsplit('/').next().unwrap_or("file").replace('"', "");
        if let Ok(v) = HeaderValue::from_str(&format!("attachment; filename=\"{base}\"")) {
            headers.insert(header::CONTENT_DISPOSITION, v);
        }
    }
    (headers, Body::from(bytes.as_ref().clone())).into_response()
}

async fn events(
    State(st): State<Arc<AppState>>,
    UrlPath(id): UrlPath<u64>,
) -> std::result::Result<Sse<impl futures_util::Stream<Item = std::result::Result<Event, Infallible>>>, StudioError> {
    let job = st.jobs.get(id).ok_or_else(|| StudioError::NotFound(format!("no job {id}")))?;
    let stream = futures_util::stream::unfold((job, 0usize, false), |(job, seen, closed)| async move {
        if closed {
            return None;
        }
        loop {
            let (new, done) = job.events_from(seen);
            if let Some((name, data)) = new.first() {
                let last = done && new.len() == 1;
                let ev = Event::default().event(name).data(data.to_string());
                return Some((Ok::<Event, Infallible>(ev), (job, seen + 1, last)));
            }
            if done {
                return None;
            }
            job.wait_past(seen).await;
        }
    });
    Ok(Sse::new(stream).keep_alive(KeepAlive::default()))
}

/// `GET /api/jobs/{id}`: the job's state ([`crate::jobs::Job::status`]).
async fn job_status(State(st): State<Arc<AppState>>, UrlPath(id): UrlPath<u64>) -> Result<Json<Value>> {
    let job = st.jobs.get(id).ok_or_else(|| StudioError::NotFound(format!("no job {id}")))?;
    Ok(Json(job.status()))
}

async fn cancel(State(st): State<Arc<AppState>>, UrlPath(id): UrlPath<u64>) -> Result<Json<Value>> {
    let job = st.jobs.get(id).ok_or_else(|| StudioError::NotFound(format!("no job {id}")))?;
    job.cancel();
    Ok(Json(json!({"job": id, "cancelled": true})))
}

/// A running studio (tests, the bench): serves on its own runtime thread until dropped.
pub struct Studio {
    addr: SocketAddr,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Studio {
    /// Binds and starts serving in the background.
    pub fn start(config: StudioConfig) -> Result<Studio> {
        let rt = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .map_err(|e| StudioError::Runtime(e.to_string()))?;
        let listener = bind(&rt, &config)?;
        let addr = listener.local_addr().map_err(|e| StudioError::Runtime(e.to_string()))?;
        let app = router(state(config, addr));
        let (tx, rx) = tokio::sync::oneshot::channel::<()>();
        let thread = std::thread::spawn(move || {
            // Not a graceful shutdown: an open event stream or keep-alive connection would hold it.
            rt.block_on(async move {
                tokio::select! {
                    _ = axum::serve(listener, app).into_future() => {}
                    _ = rx => {}
                }
            });
            rt.shutdown_timeout(std::time::Duration::from_secs(1));
        });
        Ok(Studio { addr, stop: Some(tx), thread: Some(thread) })
    }

    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// `http://127.0.0.1:<port>/`.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }
}

impl Drop for Studio {
    fn drop(&mut self) {
        if let Some(tx) = self.stop.take() {
            let _ = tx.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn state(config: StudioConfig, bound: SocketAddr) -> Arc<AppState> {
    Arc::new(Shared::new(config, bound))
}

fn bind(rt: &tokio::runtime::Runtime, config: &StudioConfig) -> Result<tokio::net::TcpListener> {
    let addr = SocketAddr::new(config.listen, config.port);
    rt.block_on(tokio::net::TcpListener::bind(addr))
        .map_err(|source| StudioError::Bind { addr: addr.to_string(), source })
}

/// `inbetween studio`: binds, calls `on_ready` with the page URL, serves until Ctrl-C.
pub fn serve_until_ctrl_c(config: StudioConfig, on_ready: impl FnOnce(&str)) -> Result<()> {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| StudioError::Runtime(e.to_string()))?;
    let listener = bind(&rt, &config)?;
    let addr = listener.local_addr().map_err(|e| StudioError::Runtime(e.to_string()))?;
    let url = if addr.ip().is_unspecified() {
        format!("http://127.0.0.1:{}/", addr.port())
    } else {
        format!("http://{addr}/")
    };
    on_ready(&url);
    let app = router(state(config, addr));
    let served = rt.block_on(async move {
        tokio::select! {
            r = axum::serve(listener, app).into_future() => r.map_err(|e| StudioError::Runtime(e.to_string())),
            _ = tokio::signal::ctrl_c() => Ok(()),
        }
    });
    rt.shutdown_timeout(std::time::Duration::from_secs(1));
    served
}

/// A size with a unit: `512MB`, `1.5 GiB`, `1000` (bytes). Decimal (KB, MB, GB) and binary (KiB,
/// MiB, GiB) units.
pub fn parse_size(s: &str) -> Result<u64> {
    let t = s.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let bad = || StudioError::BadRequest(format!("'{s}': expected a size such as 512MB, 2GiB or 1000B"));
    let n: f64 = num.parse().map_err(|_| bad())?;
    let mult = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "kb" | "k" => 1e3,
        "mb" | "m" => 1e6,
        "gb" | "g" => 1e9,
        "kib" => 1024.0,
        "mib" => 1024.0 * 1024.0,
        "gib" => 1024.0 * 1024.0 * 1024.0,
        _ => return Err(bad()),
    };
    let v = n * mult;
    if !(v.is_finite() && (1.0..1e15).contains(&v)) {
        return Err(bad());
    }
    Ok(v.round() as u64)
}

/// A size as [`parse_size`] reads it: in the largest decimal unit that writes it whole
/// (`512MB`), else in bytes.
pub fn format_size(bytes: u64) -> String {
    let units = [("GB", 1_000_000_000), ("MB", 1_000_000), ("KB", 1000)];
    match units.into_iter().find(|&(_, m)| bytes >= m && bytes.is_multiple_of(m)) {
        Some((unit, m)) => format!("{}{unit}", bytes / m),
        None => format!("{bytes}B"),
    }
}

/// Opens `url` in the system browser (`xdg-open` on Linux, `open` on macOS, `start` on Windows).
pub fn open_browser(url: &str) -> std::io::Result<()> {
    let mut cmd = if cfg!(target_os = "macos") {
        std::process::Command::new("open")
    } else if cfg!(windows) {
        let mut c = std::process::Command::new("cmd");
        c.args(["/C", "start", ""]);
        c
    } else {
        std::process::Command::new("xdg-open")
    };
    cmd.arg(url).stdout(std::process::Stdio::null()).stderr(std::process::Stdio::null()).spawn().map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::{format_size, parse_size};

    #[test]
    fn sizes() {
        assert_eq!(parse_size("512MB").unwrap(), 512_000_000);
        assert_eq!(parse_size("1KiB").unwrap(), 1024);
        assert_eq!(parse_size("1000").unwrap(), 1000);
        assert_eq!(parse_size("2 GiB").unwrap(), 2 * 1024 * 1024 * 1024);
        for bad in ["", "MB", "12 parsecs", "-1MB", "0"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        for (bytes, text) in [(512_000_000, "512MB"), (2_000_000_000, "2GB"), (1500, "1500B"), (1024, "1024B")] {
            assert_eq!(format_size(bytes), text);
            assert_eq!(parse_size(text).unwrap(), bytes, "read back");
        }
    }
}
