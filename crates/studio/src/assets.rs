//! The embedded front-end: our page (`web/app/`, plain ES modules) and the three.js files
//! `build.rs` installed from npm (`$OUT_DIR/vendor/three`). Without three.js the page is replaced
//! by one that says exactly what to install.

use include_dir::{include_dir, Dir};

static APP: Dir<'_> = include_dir!("$CARGO_MANIFEST_DIR/web/app");
static VENDOR: Dir<'_> = include_dir!("$OUT_DIR/vendor");

/// Why three.js is missing (the build's message), or None when it was installed.
pub fn missing() -> Option<&'static str> {
    VENDOR.get_file("MISSING.txt").and_then(|f| f.contents_utf8())
}

/// The page served at `/` when three.js was not installed at build time.
pub fn missing_page(why: &str) -> String {
    let esc = why.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;");
    format!(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>inbetween studio: three.js missing</title></head>\
         <body style=\"font-family:sans-serif;max-width:50em;margin:2em auto\">\
         <h1>inbetween studio needs three.js</h1>\
         <p>This binary was built without the studio's front-end dependencies. To get them:</p>\
         <ol><li>install Node.js and npm (Debian/Ubuntu: <code>apt-get install nodejs npm</code>);</li>\
         <li>rebuild: <code>cargo build -p inbetween-cli</code> (the build runs <code>npm ci</code> for \
         <code>crates/studio/web/package-lock.json</code>);</li>\
         <li>run <code>inbetween studio</code> again.</li></ol>\
         <p>The build said:</p><pre data-testid=\"error\">{esc}</pre></body></html>"
    )
}

/// A file of the front-end by its URL path (`/`, `/app.js`, `/vendor/three/build/three.module.js`)
/// and its content type.
pub fn get(path: &str) -> Option<(&'static [u8], &'static str)> {
    let path = path.trim_start_matches('/');
    let path = if path.is_empty() { "index.html" } else { path };
    let file = match path.strip_prefix("vendor/") {
        Some(rest) => VENDOR.get_file(rest)?,
        None => APP.get_file(path)?,
    };
    Some((file.contents(), content_type(path)))
}

fn content_type(path: &str) -> &'static str {
    match path.rsplit('.').next().unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" => "text/javascript; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "json" => "application/json",
        "png" => "image/png",
        "svg" => "image/svg+xml",
        _ => "text/plain; charset=utf-8",
    }
}
