//! `inbetween studio`: a local web studio where a story or a mocap take is run, seen in 3D and
//! edited (issue 23), a face capture is masked and refilled, a clip is resequenced and a camera is keyed between two
//! characters (issue 24). The server is axum on tokio; every job calls an engine's public library
//! API (the script engine's [`inbetween_script::story_session::StorySession`], the mocap
//! engine's key selectors and `.ibk` codec) on a blocking thread; results reach the page as JSON,
//! glTF and BVH (forms three.js reads), progress as server-sent events.
//!
//! - [`server`]: start/stop, routes (each panel's router nested under `/api/<panel>`);
//! - [`state`]: what the server and the panels share (configuration, jobs, result files) and a
//!   panel's handler state; [`upload`]: the upload helpers every panel uses;
//! - [`safety`]: Host (DNS rebinding) and Origin (cross-site writes) checks, the upload cap, paths
//!   only under `--root`;
//! - [`jobs`]: job registry with progress events and cancellation;
//! - [`script_panel`], [`mocap_panel`], [`face_panel`], [`video_panel`], [`camera_panel`]: each
//!   panel's state, handlers and router, translating requests into engine jobs (the mocap engine's
//!   `SelectJob`, `CompressJob`, the face engine's `EditJob`, the video engine's analysis and SDPF
//!   walks, the camera engine's `GenerateJob`: issue 24);
//! - [`assets`]: the embedded front-end (our files and three.js installed by `build.rs`);
//! - [`browser`], [`bench`]: headless Chromium for the browser tests and `inbetween studio bench`.

// serde_json's json! macro recurses once per token; the job results are large objects.
#![recursion_limit = "256"]

pub mod assets;
pub mod bench;
pub mod browser;
pub mod camera_panel;
pub mod error;
pub mod face_panel;
pub mod jobs;
pub mod mocap_panel;
pub mod safety;
pub mod script_panel;
pub mod server;
pub mod state;
pub mod upload;
pub mod video_panel;

pub use error::{Result, StudioError};
pub use server::{serve_until_ctrl_c, Studio};
pub use state::StudioConfig;
