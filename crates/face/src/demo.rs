//! The face part of `inbetween demo`: a procedural capture with a 3 s occlusion, filled by linear
//! interpolation, cubic interpolation and the committed unguided network, shown side by side as a GIF
//! of the schematic face and as a curve plot.

use std::path::{Path, PathBuf};

use inbetween_io::Progress;

use crate::data::{FaceError, MODEL_FPS, NUM_ARKIT};
use crate::edit::{ConstraintKind, Frame, Segment};
use crate::infer::{EditJob, Guide, Inpainter, Method};
use crate::preview::{span_flags, write_edit_gif, write_edit_png, CurvePreview};
use crate::procedural::{generate, ProceduralConfig};

/// What the demo wrote and measured.
#[derive(Debug)]
pub struct FaceDemo {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Mean squared error inside the occlusion, per method.
    pub mse: Vec<(String, f64)>,
}

impl std::fmt::Display for FaceDemo {
    /// The demo's line: the masked MSE per method and the files.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mse: Vec<String> = self.mse.iter().map(|(m, e)| format!("{m} {e:.5}")).collect();
        let files: Vec<String> = self.files.iter().map(|f| f.display().to_string()).collect();
        write!(f, "face: 3 s occlusion of a procedural capture, masked MSE {} -> {}", mse.join(", "), files.join(", "))
    }
}

/// Occlusion of the demo clip, seconds.
pub const OCCLUSION_S: (f64, f64) = (3.5, 6.5);

/// The demo's example at `k`× its length (`face scale`).
pub struct ScaledExample {
    /// A procedural clip (seed 1), `seconds` long.
    pub clip: crate::data::BlendshapeClip,
    /// The clip's length asked of the generator: 10·k s.
    pub seconds: f64,
    /// The occlusion: from [`OCCLUSION_S`]'s start, `k` times as long (seconds).
    pub span_s: (f64, f64),
}

/// [`ScaledExample`] at `k`×.
pub fn scaled_example(k: usize) -> ScaledExample {
    let seconds = 10.0 * k as f64;
    let clip = generate(&ProceduralConfig { duration_s: seconds, ..ProceduralConfig::default() }, 1).clip;
    let span_s = (OCCLUSION_S.0, OCCLUSION_S.0 + (OCCLUSION_S.1 - OCCLUSION_S.0) * k as f64);
    ScaledExample { clip, seconds, span_s }
}

fn mse(truth: &[Frame], out: &[Frame], seg: Segment) -> f64 {
    let mut s = 0.0;
    for f in seg.start..seg.end {
        for c in 0..NUM_ARKIT {
            s += f64::from(out[f][c] - truth[f][c]).powi(2);
        }
    }
    s / (seg.len() * NUM_ARKIT) as f64
}

/// Run the demo into `dir` (`face-demo.gif`, `face-demo.png`, `face-demo-input.csv`).
pub fn run(dir: &Path, seed: u64, progress: &Progress) -> Result<FaceDemo, FaceError> {
    let clip = generate(&ProceduralConfig { duration_s: 10.0, ..ProceduralConfig::default() }, seed).clip;
    let net = crate::weights::committed(ConstraintKind::None)?;
    let methods: [(&str, Method); 3] =
        [("linear", Method::Linear), ("cubic", Method::Cubic), ("ours", Method::Network(&net as &dyn Inpainter))];
    let mut outs = Vec::new();
    let mut truth = Vec::new();
    let mut seg = Segment { start: 0, end: 0 };
    for (name, method) in methods {
        let job = EditJob {
            clip: &clip,
            spans: vec![OCCLUSION_S],
            channels: Some([true; NUM_ARKIT]),
            guide: Guide::None,
            method,
            seed,
            limits: crate::infer::EditLimits::default(),
            cancel: inbetween_core::cancel::Cancel::new(),
            guide_file: None,
            library: None,
        };
        let out = job.run()?;
        truth = out.before.clone();
        seg = out.mask.segments()[0];
        outs.push((name, out.after));
    }
    let mse: Vec<(String, f64)> = outs.iter().map(|(n, o)| (n.to_string(), mse(&truth, o, seg))).collect();
    std::fs::create_dir_all(dir).map_err(|source| FaceError::Io { file: dir.display().to_string(), source })?;
    let input = dir.join("face-demo-input.csv");
    crate::data::write_curves(&input, &crate::data::BlendshapeClip::from_model_frames(&truth))?;
    let png = dir.join("face-demo.png");
    let title = format!(
        "3 s occlusion ({:.1}-{:.1} s) filled by our unguided network; dashed: cubic",
        OCCLUSION_S.0, OCCLUSION_S.1
    );
    let preview = CurvePreview {
        title: &title,
        fps: MODEL_FPS,
        before: &truth,
        after: &outs[2].1,
        spans: &[seg],
        keys: &[],
        extra: Some(("cubic", &outs[1].1)),
        n_curves: 6,
    };
    write_edit_png(&png, &preview)
        .map_err(|e| FaceError::File { file: png.display().to_string(), message: e.to_string() })?;
    let gif = dir.join("face-demo.gif");
    let columns: Vec<(&str, &[Frame])> =
        std::iter::once(("captured", truth.as_slice())).chain(outs.iter().map(|(n, o)| (*n, o.as_slice()))).collect();
    let window = seg.start.saturating_sub(25)..(seg.end + 25).min(truth.len());
    let cropped: Vec<(&str, &[Frame])> = columns.iter().map(|(n, f)| (*n, &f[window.clone()])).collect();
    let flags = span_flags(window.len(), &[Segment { start: seg.start - window.start, end: seg.end - window.start }]);
    write_edit_gif(&gif, MODEL_FPS, &cropped, None, &flags, progress)
        .map_err(|e| FaceError::File { file: gif.display().to_string(), message: e.to_string() })?;
    Ok(FaceDemo { files: vec![input, png, gif], mse })
}
