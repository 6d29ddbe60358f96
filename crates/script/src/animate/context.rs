//! What every character of a scene is built in ([`Ctx`]: the scene, the query, the catalogue, the
//! motion library, the settings, the rig and the cancel token) and what every animation of a session
//! is made with ([`Setup`]).

use super::AnimateConfig;
use crate::catalogue::Catalogue;
use crate::motion::rig::Rig;
use crate::motion::MotionLibrary;
use crate::scene::Scene;
use crate::ssg::Ssg;
use inbetween_core::cancel::Cancel;

/// The scene, query and settings one character is built in.
pub(crate) struct Ctx<'a> {
    pub scene: &'a Scene,
    pub query: &'a Ssg,
    pub cat: &'a Catalogue,
    pub lib: &'a MotionLibrary,
    pub cfg: &'a AnimateConfig,
    pub rig: Rig,
    /// Checked between characters and between crowd repairs; once cancelled they stop early (the
    /// caller discards what was built).
    pub cancel: &'a Cancel,
}

/// What every animation of a session is made with: the catalogue, the motion library, the
/// settings, and the cancel token the long loops check.
#[derive(Clone, Copy)]
pub(crate) struct Setup<'a> {
    pub cat: &'a Catalogue,
    pub lib: &'a MotionLibrary,
    pub cfg: &'a AnimateConfig,
    pub cancel: &'a Cancel,
}
