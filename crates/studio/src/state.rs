//! What every part of the studio server shares: the configuration, the jobs and the file store
//! (results served at `/api/files/{name}`); and [`Panel`], one panel's state beside the shared
//! parts, which that panel's handlers receive. The panels import this file, never the server.

use std::collections::HashMap;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use crate::jobs::Jobs;

/// Default `--max-upload`: 512 MB.
pub const DEFAULT_MAX_UPLOAD: u64 = 512 * 1000 * 1000;

/// What `inbetween studio` was asked for.
#[derive(Debug, Clone)]
pub struct StudioConfig {
    /// TCP port; 0 picks a free one.
    pub port: u16,
    /// Address to listen on (default 127.0.0.1).
    pub listen: IpAddr,
    /// The only folder whose files the client may name (the corpus list comes from it).
    pub root: Option<PathBuf>,
    /// Largest request body in bytes.
    pub max_upload: u64,
    /// Adds `POST /api/test/panic`, a route that panics, to test that the server keeps serving.
    #[doc(hidden)]
    pub test_routes: bool,
}

impl Default for StudioConfig {
    fn default() -> StudioConfig {
        StudioConfig {
            port: 7878,
            listen: IpAddr::V4(Ipv4Addr::LOCALHOST),
            root: None,
            max_upload: DEFAULT_MAX_UPLOAD,
            test_routes: false,
        }
    }
}

/// What makes a lazy artifact's bytes.
type MakeBytes = Box<dyn FnOnce() -> Vec<u8> + Send>;

/// A result file: its bytes, or the function that makes them on the first download (files only
/// offered for download, such as a story's BVH and .gltf, cost nothing until asked for).
pub struct Artifact {
    pub content_type: String,
    bytes: std::sync::OnceLock<Arc<Vec<u8>>>,
    make: Mutex<Option<MakeBytes>>,
}

impl Artifact {
    /// The file's bytes (made now on the first call of a lazy artifact).
    pub fn bytes(&self) -> Arc<Vec<u8>> {
        self.bytes
            .get_or_init(|| {
                let make = self.make.lock().unwrap_or_else(|p| p.into_inner()).take();
                Arc::new(make.map(|f| f()).unwrap_or_default())
            })
            .clone()
    }
}

/// Artifacts of the latest jobs, served at `/api/files/{name}`.
pub type Files = Mutex<HashMap<String, Arc<Artifact>>>;

/// The parts of the server every panel uses.
pub struct Shared {
    pub config: StudioConfig,
    pub bound: SocketAddr,
    pub jobs: Jobs,
    pub files: Files,
}

impl Shared {
    pub fn new(config: StudioConfig, bound: SocketAddr) -> Shared {
        Shared { config, bound, jobs: Jobs::default(), files: Files::default() }
    }

    /// Stores an artifact; returns its URL (with a version so the browser never caches an old one).
    pub fn put_file(&self, name: &str, content_type: &str, bytes: Vec<u8>, version: u64) -> String {
        let bytes = std::sync::OnceLock::from(Arc::new(bytes));
        self.put(name, Artifact { content_type: content_type.to_string(), bytes, make: Mutex::new(None) }, version)
    }

    /// Stores an artifact made by `make` on its first download; returns its URL.
    pub fn put_lazy(
        &self,
        name: &str,
        content_type: &str,
        make: impl FnOnce() -> Vec<u8> + Send + 'static,
        version: u64,
    ) -> String {
        let make: MakeBytes = Box::new(make);
        let a = Artifact {
            content_type: content_type.to_string(),
            bytes: std::sync::OnceLock::new(),
            make: Mutex::new(Some(make)),
        };
        self.put(name, a, version)
    }

    fn put(&self, name: &str, artifact: Artifact, version: u64) -> String {
        self.files.lock().unwrap_or_else(|p| p.into_inner()).insert(name.to_string(), Arc::new(artifact));
        format!("/api/files/{name}?v={version}")
    }

    /// The artifact stored under `name`.
    pub fn file(&self, name: &str) -> Option<Arc<Artifact>> {
        self.files.lock().unwrap_or_else(|p| p.into_inner()).get(name).cloned()
    }
}

/// Declares a panel's handler state: a struct `$name` with the shared parts (reached through
/// `Deref`: `st.jobs`, `st.put_file(…)`) and the panel's own state `$state` in field `$field`
/// (`st.mocap.take`), made fresh by `$name::new(shared)`.
macro_rules! panel_state {
    ($name:ident, $field:ident, $state:ty) => {
        /// The handlers' state: the shared parts and this panel's own.
        pub struct $name {
            pub shared: std::sync::Arc<$crate::state::Shared>,
            pub $field: $state,
        }

        impl $name {
            fn new(shared: std::sync::Arc<$crate::state::Shared>) -> std::sync::Arc<$name> {
                std::sync::Arc::new($name { shared, $field: <$state>::default() })
            }
        }

        impl std::ops::Deref for $name {
            type Target = $crate::state::Shared;
            fn deref(&self) -> &$crate::state::Shared {
                &self.shared
            }
        }
    };
}
pub(crate) use panel_state;
