//! Trained networks as the edit job uses them: loading a weights file or the committed weights, and
//! the guard that keeps a training run from overwriting the committed weights by accident.
//!
//! The committed weights (`crates/face/weights/<kind>.bpk` + `.json` card) were trained by
//! `inbetween face train` on the procedural generator only ([`crate::procedural`]); weights trained
//! on the face captures are never committed (their licence is unclear).

use std::path::{Path, PathBuf};

use inbetween_nn::weights::Weights;

use crate::data::FaceError;
use crate::edit::{ConstraintKind, Frame};
use crate::infer::Inpainter;
use crate::model::runtime::{load_generator, GeneratorRuntime};

/// A set of trained networks (one per constraint type) under one label.
pub struct NetworkSet {
    /// Label in the tables ("procedural", "real").
    pub label: String,
    /// The networks.
    pub nets: Vec<Box<dyn Inpainter>>,
}

impl NetworkSet {
    pub(crate) fn get(&self, kind: ConstraintKind) -> Option<&dyn Inpainter> {
        self.nets.iter().find(|n| n.kind() == kind).map(|n| n.as_ref())
    }
}

/// A loaded generator and the guidance it takes.
pub struct Network {
    runtime: GeneratorRuntime,
    kind: ConstraintKind,
    /// Where it came from (file or committed name), for messages.
    pub origin: String,
}

impl Inpainter for Network {
    fn kind(&self) -> ConstraintKind {
        self.kind
    }

    fn generate(&self, input: &[f32], frames: usize) -> Vec<Frame> {
        self.runtime.run(input, frames)
    }
}

impl Network {
    fn from_weights(w: &Weights) -> Result<Network, FaceError> {
        let (runtime, kind) = load_generator(w)?;
        Ok(Network { runtime, kind, origin: w.origin().display().to_string() })
    }
}

/// Load a weights file (`x.bpk` with its card `x.json`).
pub fn load(path: &Path) -> Result<Network, FaceError> {
    Network::from_weights(&Weights::from_path(path)?)
}

/// Folder of the committed weights.
pub fn committed_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("weights")
}

/// File name of the committed network of `kind`.
pub fn committed_file(kind: ConstraintKind) -> String {
    format!("{}.bpk", kind.name())
}

/// The committed network of `kind`, compiled into the binary.
pub fn committed(kind: ConstraintKind) -> Result<Network, FaceError> {
    let (bpk, card): (&'static [u8], &'static str) = match kind {
        ConstraintKind::None => (include_bytes!("../weights/unguided.bpk"), include_str!("../weights/unguided.json")),
        ConstraintKind::Keyframes => {
            (include_bytes!("../weights/keyframes.bpk"), include_str!("../weights/keyframes.json"))
        }
        ConstraintKind::Noisy => (include_bytes!("../weights/noisy.bpk"), include_str!("../weights/noisy.json")),
        ConstraintKind::Visemes => (include_bytes!("../weights/visemes.bpk"), include_str!("../weights/visemes.json")),
    };
    let origin = format!("crates/face/weights/{}", committed_file(kind));
    Network::from_weights(&Weights::embedded(&origin, bpk, card)?)
}

/// All four committed networks.
pub fn committed_set() -> Result<NetworkSet, FaceError> {
    let nets = ConstraintKind::ALL
        .iter()
        .map(|k| committed(*k).map(|n| Box::new(n) as Box<dyn Inpainter>))
        .collect::<Result<_, _>>()?;
    Ok(NetworkSet { label: "procedural".into(), nets })
}

/// The networks `<dir>/<kind>.bpk` that exist in `dir` (e.g. weights trained on the real captures).
pub fn set_from_dir(dir: &Path, label: &str) -> Result<NetworkSet, FaceError> {
    let mut nets: Vec<Box<dyn Inpainter>> = Vec::new();
    for kind in ConstraintKind::ALL {
        let path = dir.join(committed_file(kind));
        if path.exists() {
            nets.push(Box::new(load(&path)?));
        }
    }
    if nets.is_empty() {
        return Err(FaceError::Invalid(format!(
            "{} holds no face weights (expected unguided.bpk, keyframes.bpk, noisy.bpk or visemes.bpk)",
            dir.display()
        )));
    }
    Ok(NetworkSet { label: label.into(), nets })
}

/// Refuse to write weights into the committed folder unless asked to.
pub fn check_output(out: &Path, overwrite_committed: bool) -> Result<(), FaceError> {
    let committed = committed_dir();
    let parent =
        out.parent().map(|p| if p.as_os_str().is_empty() { Path::new(".") } else { p }).unwrap_or(Path::new("."));
    let same = match (parent.canonicalize(), committed.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if same && !overwrite_committed {
        return Err(FaceError::Invalid(format!(
            "{} is in the committed weights folder; set `overwrite_committed` to replace the committed weights on purpose",
            out.display()
        )));
    }
    Ok(())
}
