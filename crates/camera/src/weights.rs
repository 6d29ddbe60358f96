//! Camera weights through `inbetween_nn::weights`: a burnpack record plus a card (`kind` "camera",
//! the model configuration, the training summary, metrics, and in `extra` the per-behaviour style
//! codes computed once at save time), loaded into the plain-Rust networks; and where training may
//! write (never over the committed weights unless asked).

use crate::dataset::{Behaviour, Scene};
use crate::infer::style::{behaviour_code, BEHAVIOUR_STYLE_SCENES, BEHAVIOUR_STYLE_SEED};
use crate::infer::{FastModel, NamedStyle, ReferenceClip, Style};
use crate::model::{CameraModel, ModelConfig};
use crate::train::TrainSummary;
use crate::CameraError;
use inbetween_nn::weights::{Weights, WeightsCard};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Folder of the committed weights (`crates/camera/weights/`).
pub fn committed_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("weights")
}

/// The committed weights file (`crates/camera/weights/camera.bpk`).
pub fn committed_path() -> PathBuf {
    committed_dir().join("camera.bpk")
}

/// Where `camera train` writes by default: never the committed weights.
pub fn default_train_output() -> PathBuf {
    PathBuf::from("out/camera/camera.bpk")
}

/// Refuses `out` when it lies in the committed weights folder, unless `overwrite_committed`.
pub fn check_output(out: &Path, overwrite_committed: bool) -> Result<(), CameraError> {
    if overwrite_committed || !is_in_committed_dir(out) {
        return Ok(());
    }
    Err(CameraError::invalid(
        out,
        format!(
            "refusing to overwrite the committed weights in {} (set `overwrite_committed` to replace them on purpose)",
            committed_dir().display()
        ),
    ))
}

fn is_in_committed_dir(out: &Path) -> bool {
    let Ok(committed) = committed_dir().canonicalize() else { return false };
    let absolute = if out.is_absolute() {
        out.to_path_buf()
    } else {
        std::env::current_dir().map(|d| d.join(out)).unwrap_or_else(|_| out.to_path_buf())
    };
    // The file (or its folders) may not exist yet: compare the nearest folder that does.
    absolute.ancestors().skip(1).find_map(|d| d.canonicalize().ok()).is_some_and(|d| d.starts_with(&committed))
}

/// The card's `kind` and architecture version for camera weights.
pub const KIND: &str = "camera";
pub const FORMAT: u32 = 1;

/// What camera inference needs from the card besides the model configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CardExtra {
    /// Per-behaviour style codes (mean z over seeded synthetic sequences), computed once when the
    /// weights were saved ([`FastModel::behaviour_styles`]).
    pub style_codes: Vec<NamedStyle>,
    /// The seed and scene count they were averaged over.
    pub style_codes_seed: u64,
    pub style_codes_scenes: usize,
}

/// Trained networks with the per-behaviour style codes that go with them.
#[derive(Debug, Clone)]
pub struct CameraWeights {
    pub model: FastModel,
    pub styles: Vec<NamedStyle>,
}

impl CameraWeights {
    /// The style code of `behaviour` (main character on the left).
    pub fn style(&self, behaviour: Behaviour) -> Option<Style> {
        behaviour_code(&self.styles, behaviour)
    }

    /// The style code of the behaviour named `name` (direct, relative, side or orbit); an error
    /// naming the behaviours when the name is none of them, or the card when it holds no code for it.
    pub fn named_style(&self, name: &str) -> Result<Style, CameraError> {
        let b = Behaviour::parse(name)
            .ok_or_else(|| CameraError::Request(format!("unknown style `{name}` (direct, relative, side, orbit)")))?;
        self.behaviour_style(b)
    }

    /// The styles one generation runs, each with the behaviour it is the code of (None for a
    /// reference clip): every behaviour's when `all` (the paper's UI flow), else the style of the
    /// `reference` clip over `scene`, else the behaviour `named` (default: relative).
    pub fn requested_styles(
        &self,
        all: bool,
        reference: Option<&Path>,
        named: Option<&str>,
        scene: &Scene,
    ) -> Result<Vec<(Style, Option<Behaviour>)>, CameraError> {
        if all {
            return crate::dataset::BEHAVIOURS.iter().map(|b| Ok((self.behaviour_style(*b)?, Some(*b)))).collect();
        }
        Ok(vec![match reference {
            Some(r) => (self.reference_style(r, scene)?, None),
            None => (self.named_style(named.unwrap_or(Behaviour::Relative.name()))?, None),
        }])
    }

    /// [`CameraWeights::style`], or an error naming the behaviour the card holds no code for.
    pub fn behaviour_style(&self, b: Behaviour) -> Result<Style, CameraError> {
        self.style(b)
            .ok_or_else(|| CameraError::Request(format!("the weights card has no style code for `{}`", b.name())))
    }

    /// The style of a reference clip at `path`: our JSON ([`ReferenceClip`]), or a glTF / GLB camera
    /// animation over `scene`'s characters; the style's name is `reference:<path>`.
    pub fn reference_style(&self, path: &Path, scene: &Scene) -> Result<Style, CameraError> {
        let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
        let clip: ReferenceClip = if matches!(ext.as_deref(), Some("gltf" | "glb")) {
            let bytes = std::fs::read(path).map_err(|source| CameraError::Io { path: path.into(), source })?;
            crate::infer::reference_from_gltf(&bytes, &path.display().to_string(), scene, &Default::default())
                .map_err(CameraError::Request)?
        } else {
            crate::read_json(path)?
        };
        Ok(Style { name: format!("reference:{}", path.display()), code: clip.style(&self.model, path)? })
    }
}

/// The card of weights trained as `summary` says, with the style codes computed from `model`.
pub fn card(summary: &TrainSummary, model: &FastModel) -> Result<WeightsCard, CameraError> {
    let cfg = &summary.config;
    let data = format!(
        "procedural two-character scenes (crate::dataset): {} scenes x 8 sequences of {} frames, seed {}",
        cfg.scenes,
        crate::dataset::SCENE_FRAMES,
        cfg.seed
    );
    let mut card = WeightsCard::new(KIND, FORMAT, to_json(&summary.config.model)?, &data);
    card.training = to_json(summary)?;
    card.metrics = [
        ("final_loss", summary.final_loss),
        ("epochs", summary.epochs_done as f64),
        ("iterations", summary.iterations as f64),
        ("seconds", summary.seconds),
        ("final_lr", summary.lr),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    let extra = CardExtra {
        style_codes: model.behaviour_styles(BEHAVIOUR_STYLE_SEED, BEHAVIOUR_STYLE_SCENES),
        style_codes_seed: BEHAVIOUR_STYLE_SEED,
        style_codes_scenes: BEHAVIOUR_STYLE_SCENES,
    };
    card.extra = to_json(&extra)?;
    Ok(card)
}

fn to_json<T: Serialize>(value: &T) -> Result<serde_json::Value, CameraError> {
    serde_json::to_value(value).map_err(|e| CameraError::Model(format!("weights card: {e}")))
}

/// Saves trained weights as `path` (burnpack) + card (`path` with `.json`), refusing the
/// committed folder unless `overwrite_committed`; returns them ready for inference.
pub fn save(
    model: &CameraModel,
    summary: &TrainSummary,
    path: &Path,
    overwrite_committed: bool,
) -> Result<CameraWeights, CameraError> {
    check_output(path, overwrite_committed)?;
    let fast = FastModel::from_burn(model, summary.config.model);
    let card = card(summary, &fast)?;
    inbetween_nn::weights::save(model, &card, path)?;
    let extra: CardExtra = serde_json::from_value(card.extra).map_err(|e| CameraError::invalid(path, e.to_string()))?;
    Ok(CameraWeights { model: fast, styles: extra.style_codes })
}

/// Camera weights out of a weights file and its card.
pub fn from_weights(w: &Weights) -> Result<CameraWeights, CameraError> {
    w.expect_kind(KIND, FORMAT)?;
    let config: ModelConfig = w.config()?;
    let extra: CardExtra = w.extra()?;
    let model = w.load_into(config.init(&inbetween_nn::backend::cpu()))?;
    Ok(CameraWeights { model: FastModel::from_burn(&model, config), styles: extra.style_codes })
}

/// Weights saved by [`save`] (`x.bpk` + card `x.json`). Weights beside a training summary instead
/// of a card (what `camera train` wrote before weights cards, e.g. an old `last.bpk` + `last.json`)
/// load too; their style codes are computed.
pub fn load(path: &Path) -> Result<CameraWeights, CameraError> {
    let summary_path = path.with_extension("json");
    let text = std::fs::read_to_string(&summary_path)
        .map_err(|source| CameraError::Io { path: summary_path.clone(), source })?;
    if let Ok(summary) = serde_json::from_str::<TrainSummary>(&text) {
        let device = inbetween_nn::backend::cpu();
        let model = crate::train::load_model(&summary.config.model, path, &device)?;
        let model = FastModel::from_burn(&model, summary.config.model);
        let styles = model.behaviour_styles(BEHAVIOUR_STYLE_SEED, BEHAVIOUR_STYLE_SCENES);
        return Ok(CameraWeights { model, styles });
    }
    from_weights(&Weights::from_path(path)?)
}

/// The committed weights (`crates/camera/weights/camera.bpk` + card), compiled into the binary so
/// tools and the demo run from anywhere.
pub fn committed() -> Result<CameraWeights, CameraError> {
    const BPK: &[u8] = include_bytes!("../weights/camera.bpk");
    const CARD: &str = include_str!("../weights/camera.json");
    from_weights(&Weights::embedded("crates/camera/weights/camera.bpk", BPK, CARD)?)
}

impl FastModel {
    /// The networks of [`load`] without their style codes.
    pub fn load(path: &Path) -> Result<FastModel, CameraError> {
        Ok(load(path)?.model)
    }

    /// The networks of [`committed`].
    pub fn committed() -> Result<FastModel, CameraError> {
        Ok(committed()?.model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn committed_card_holds_the_style_codes_the_weights_give() {
        // `camera generate` used to compute these on every call; the card must hold exactly them.
        let w = committed().unwrap();
        let fresh = w.model.behaviour_styles(BEHAVIOUR_STYLE_SEED, BEHAVIOUR_STYLE_SCENES);
        assert_eq!(w.styles.len(), 8);
        for (stored, computed) in w.styles.iter().zip(&fresh) {
            assert_eq!((stored.behaviour, stored.main_is_a), (computed.behaviour, computed.main_is_a));
            let bits = |c: &[f32]| c.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&stored.code), bits(&computed.code), "{:?} main A {}", stored.behaviour, stored.main_is_a);
        }
        assert_ne!(w.styles[0].code, w.styles[6].code, "behaviours have distinct codes");
    }

    #[test]
    fn saved_weights_load_back_with_their_card_and_wrong_files_are_refused() {
        let device = inbetween_nn::backend::cpu();
        let cfg = ModelConfig { hidden: 8, tta_dim: 8, ..ModelConfig::default() };
        let model = inbetween_nn::backend::seeded_module(&device, 2, |d| cfg.init(d));
        let summary = TrainSummary {
            config: crate::train::TrainConfig { model: cfg, scenes: 1, ..Default::default() },
            epochs_done: 1,
            iterations: 2,
            seconds: 0.5,
            loss_history: vec![0.3],
            final_loss: 0.3,
            lr: 1e-3,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cam.bpk");
        let saved = save(&model, &summary, &path, false).unwrap();
        let back = load(&path).unwrap();
        assert_eq!(back.styles, saved.styles);
        assert_eq!(back.model.dec2, saved.model.dec2);
        let card: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(path.with_extension("json")).unwrap()).unwrap();
        assert_eq!((card["kind"].as_str(), card["metrics"]["final_loss"].as_f64()), (Some(KIND), Some(0.3)));
        // Another model's card is refused, naming the file.
        let mut other = card.clone();
        other["kind"] = "mocap-sidql".into();
        std::fs::write(path.with_extension("json"), other.to_string()).unwrap();
        let e = load(&path).unwrap_err().to_string();
        assert!(e.contains("cam.bpk") && e.contains("expected camera"), "{e}");
    }

    #[test]
    fn training_output_refuses_the_committed_folder_unless_asked() {
        let inside = committed_dir().join("camera.bpk");
        let e = check_output(&inside, false).unwrap_err().to_string();
        assert!(e.contains("`overwrite_committed`"), "{e}");
        assert!(check_output(&inside, true).is_ok());
        // The same folder through a relative path with `..` is still refused.
        let sneaky = committed_dir().join("..").join("weights").join("x.bpk");
        assert!(check_output(&sneaky, false).is_err());
        let dir = tempfile::tempdir().unwrap();
        assert!(check_output(&dir.path().join("camera.bpk"), false).is_ok());
        assert!(check_output(&default_train_output(), false).is_ok());
    }
}
