//! The codec's jobs (ozz's job shape: inputs, `validate`, then `run`, and a report that prints
//! itself): [`CompressJob`] compresses one clip into an `.ibk` file, choosing the file version
//! from the budget; [`DecompressJob`] rebuilds the clip of any `.ibk` file. The command line, the
//! studio and Python only parse their inputs into a job.

use super::v3_encode::{self, Format};
use super::{Budget, Compressed, IbkFile, RAW_BYTES_PER_BONE};
use crate::{MocapError, PositionError, Result};
use inbetween_core::cancel::Cancel;
use inbetween_core::positions_clip;
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::Motion;
use inbetween_io::Progress;
use inbetween_render::StickOptions;
use serde::Serialize;
use std::fmt;

/// Which file version a job writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Version {
    /// Keyframes (version 2): a key count or a bound on each joint's position.
    V2,
    /// Every frame (version 3 or 4): a bound on the virtual vertices 3 cm from each joint.
    Sampled(Format),
}

impl Version {
    /// `v2`, `v3` or `v4`.
    pub fn parse(s: &str) -> Result<Version> {
        match s {
            "v2" => Ok(Version::V2),
            "v3" => Ok(Version::Sampled(Format::V3)),
            "v4" => Ok(Version::Sampled(Format::V4)),
            other => Err(MocapError::Invalid(format!("unknown format '{other}'; expected v2, v3 or v4"))),
        }
    }
}

/// Compress one clip.
#[derive(Clone, Debug)]
pub struct CompressJob {
    pub budget: Budget,
    /// None: version 4 with an error bound, version 2 with a key count.
    pub version: Option<Version>,
    /// Frames per segment of a sampled file; None: the version's default.
    pub segment_len: Option<usize>,
    /// Longest gap between keys (frames) of a keyframe file.
    pub max_gap: usize,
    pub unit: UnitChoice,
}

/// What a job wrote and how well.
#[derive(Clone, Debug)]
pub enum CompressReport {
    Keys { frames: usize, joints: usize, raw_bytes: usize, bytes_per_key: usize, compressed: Compressed },
    Sampled { frames: usize, joints: usize, raw_bytes: usize, version: u16, compressed: v3_encode::Compressed },
}

impl CompressReport {
    /// The file's bytes.
    pub fn bytes(&self) -> &[u8] {
        match self {
            CompressReport::Keys { compressed, .. } => &compressed.bytes,
            CompressReport::Sampled { compressed, .. } => &compressed.bytes,
        }
    }
}

impl CompressJob {
    /// The job `mocap compress` runs for `motion` given only a budget: the version the budget picks,
    /// the default segment length, the engine's longest gap between keys
    /// ([`crate::select::job::DEFAULT_MAX_GAP_S`]) and the unit inferred from the skeleton.
    pub fn for_motion(motion: &Motion, budget: Budget) -> CompressJob {
        CompressJob {
            budget,
            version: None,
            segment_len: None,
            max_gap: crate::select::job::max_gap_frames(crate::select::job::DEFAULT_MAX_GAP_S, motion.frame_time),
            unit: UnitChoice::resolve(None, &motion.skeleton),
        }
    }

    /// The version the job writes.
    pub fn version(&self) -> Version {
        match (self.version, &self.budget) {
            (Some(v), _) => v,
            (None, Budget::Keys(_)) => Version::V2,
            (None, Budget::MaxErrorCm(_)) => Version::Sampled(Format::V4),
        }
    }

    /// Checks the inputs before any work.
    pub fn validate(&self) -> Result<()> {
        match (self.version(), &self.budget) {
            (Version::Sampled(f), Budget::Keys(_)) => Err(MocapError::Invalid(format!(
                "a key count picks keyframes, which version {} does not store (it keeps every frame): use version 2 or an error bound",
                f.version()
            ))),
            (Version::Sampled(_), Budget::MaxErrorCm(cm)) if !(cm.is_finite() && *cm > 0.0) => {
                Err(MocapError::Invalid(format!("error bound {cm} cm: expected a positive length")))
            }
            _ => Ok(()),
        }
    }

    /// Compresses `motion`.
    pub fn run(&self, motion: &Motion) -> Result<CompressReport> {
        self.validate()?;
        let (frames, joints) = (motion.num_frames(), motion.skeleton.len());
        let raw_bytes = super::raw_bytes(motion);
        match (self.version(), &self.budget) {
            (Version::Sampled(format), Budget::MaxErrorCm(cm)) => {
                let opts = v3_encode::Options {
                    segment_len: self.segment_len.unwrap_or(format.default_segment_len()),
                    ..v3_encode::Options::with_format(*cm, format)
                };
                let compressed = v3_encode::compress_in(motion, self.unit.clone(), &opts)?;
                Ok(CompressReport::Sampled { frames, joints, raw_bytes, version: format.version(), compressed })
            }
            (_, budget) => {
                let compressed = super::compress_in(motion, self.unit.clone(), *budget, self.max_gap)?;
                let bytes_per_key = super::bytes_per_key(&motion.skeleton);
                Ok(CompressReport::Keys { frames, joints, raw_bytes, bytes_per_key, compressed })
            }
        }
    }
}

impl fmt::Display for CompressReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CompressReport::Sampled { frames, joints, raw_bytes, version, compressed: c } => {
                let n = c.bytes.len() as f64;
                let raw40 = RAW_BYTES_PER_BONE * joints * frames;
                writeln!(f, "{}", c.unit)?;
                writeln!(
                    f,
                    "{frames} frames, {joints} joints; version {version}: {} bytes vs {raw_bytes} raw f32 channel bytes ({:.1}x) or {raw40} bytes at {RAW_BYTES_PER_BONE} per joint and frame ({:.1}x)",
                    c.bytes.len(),
                    *raw_bytes as f64 / n,
                    raw40 as f64 / n
                )?;
                write!(
                    f,
                    "virtual-vertex error (3 cm from each joint, decoded file): max {:.4} cm, 99th percentile {:.4} cm",
                    c.max_error_cm, c.p99_error_cm
                )
            }
            CompressReport::Keys { frames, joints, raw_bytes, bytes_per_key, compressed: c } => {
                writeln!(f, "{}", c.unit)?;
                writeln!(
                    f,
                    "{frames} frames, {joints} joints, {} keys; {} bytes ({bytes_per_key} bytes per key) vs {raw_bytes} raw f32 bytes: ratio {:.1}x",
                    c.keys.len(),
                    c.bytes.len(),
                    *raw_bytes as f64 / c.bytes.len() as f64
                )?;
                write!(
                    f,
                    "error: mean {:.3} cm, max {:.3} cm (decoded file); mean local rotation error {:.3} deg",
                    c.decoded_mean_cm,
                    c.decoded_max_cm,
                    c.planned.mean_angle.to_degrees()
                )
            }
        }
    }
}

/// Rebuild the whole clip of an `.ibk` file (any version this build reads).
#[derive(Clone, Copy, Debug, Default)]
pub struct DecompressJob;

/// The decoded file and its clip.
#[derive(Clone, Debug, Serialize)]
pub struct DecompressReport {
    /// What the file holds, in words.
    pub description: String,
    /// The `.ibk` version (1 to 4).
    pub version: u16,
    /// Poses the file stores: its keys (versions 1 and 2) or every frame (3 and 4).
    pub stored_poses: usize,
    pub frames: usize,
    pub joints: usize,
    pub fps: f64,
    /// The length unit inferred from the skeleton (the file keeps the source's unit).
    pub unit: String,
    pub cm_per_unit: f64,
    #[serde(skip)]
    pub unit_choice: UnitChoice,
    /// The rebuilt clip.
    #[serde(skip)]
    pub motion: Motion,
    /// The decoded file.
    #[serde(skip)]
    pub file: IbkFile,
}

impl DecompressJob {
    /// Checks the file's envelope (magic, version, checksum) before any work.
    pub fn validate(&self, bytes: &[u8]) -> Result<()> {
        super::check_envelope(bytes, super::OLDEST_VERSION, super::v4::VERSION).map(|_| ())
    }

    /// Decodes `bytes` and rebuilds every frame.
    pub fn run(&self, bytes: &[u8], cancel: &Cancel, progress: &Progress) -> Result<DecompressReport> {
        self.validate(bytes)?;
        progress.phase(2, "decoding");
        let file = super::read(bytes)?;
        let version = super::check_envelope(bytes, super::OLDEST_VERSION, super::v4::VERSION)?.0;
        cancel.check()?;
        progress.inc(1);
        let motion = file.motion()?;
        progress.inc(1);
        let unit_choice = LengthUnit::infer(file.skeleton());
        Ok(DecompressReport {
            description: file.describe(),
            version,
            stored_poses: file.stored_poses(),
            frames: motion.num_frames(),
            joints: motion.skeleton.len(),
            fps: motion.fps(),
            unit: unit_choice.unit.describe(),
            cm_per_unit: unit_choice.cm_per_unit(),
            unit_choice,
            motion,
            file,
        })
    }
}

/// `mocap preview`: a clip and its reconstruction overlaid in one GIF, titled with the joints'
/// position error of the reconstruction (cm, through `unit`).
pub struct PreviewJob<'a> {
    /// The clip (`name`: its file, named in errors).
    pub original: &'a Motion,
    pub name: &'a std::path::Path,
    pub unit: UnitChoice,
    pub rebuilt: Rebuilt<'a>,
    /// The GIF to write.
    pub out: &'a std::path::Path,
}

/// Where a preview's reconstruction comes from.
pub enum Rebuilt<'a> {
    /// An `.ibk` file of the clip (read from the path), which must have its skeleton and frame count.
    File(&'a std::path::Path, Box<DecompressReport>),
    /// The keys this job chooses, written as a version 2 file (keys only, as the preview shows them).
    Keys(CompressJob),
}

/// What [`PreviewJob`] drew: the reconstruction's stored poses and position error.
#[derive(Clone, Debug)]
pub struct PreviewReport {
    pub keys: usize,
    pub error: PositionError,
    pub out: std::path::PathBuf,
}

impl PreviewJob<'_> {
    /// Rebuilds the clip (or checks that the `.ibk` file is of this clip: the same skeleton and
    /// frame count) and writes the GIF.
    pub fn run(self) -> Result<PreviewReport> {
        let d = match self.rebuilt {
            Rebuilt::File(path, d)
                if *d.file.skeleton() != self.original.skeleton || d.frames != self.original.num_frames() =>
            {
                return Err(MocapError::Mismatch(format!(
                    "{} does not match {} (skeleton or frame count differ; use the same `joints`/`skip_first`)",
                    path.display(),
                    self.name.display()
                )))
            }
            Rebuilt::File(_, d) => *d,
            Rebuilt::Keys(job) => {
                let job = CompressJob { version: Some(Version::V2), segment_len: None, ..job };
                DecompressJob.run(job.run(self.original)?.bytes(), &Cancel::new(), &Progress::hidden())?
            }
        };
        let keys = d.stored_poses;
        let (original, rebuilt) = (positions_clip(self.original), positions_clip(&d.motion));
        let e = PositionError::between(&original, &rebuilt, self.unit.cm_per_unit());
        let opts = StickOptions {
            labels: vec!["original".into(), format!("from {keys} keys")],
            title: Some(format!("{keys} keys: {e}")),
            ..StickOptions::default()
        };
        inbetween_render::render_motion_gif(self.out, &[self.original, &d.motion], &opts)?;
        Ok(PreviewReport { keys, error: e, out: self.out.to_path_buf() })
    }
}

impl fmt::Display for PreviewReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (e, out) = (&self.error, self.out.display());
        write!(f, "{} keys; mean {:.3} cm, max {:.3} cm; wrote {out}", self.keys, e.mean_cm, e.max_cm)
    }
}

impl fmt::Display for DecompressReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} (the file keeps the source's unit)", self.unit_choice)?;
        write!(f, "{} → {} frames at {:.1} fps", self.description, self.frames, self.fps)
    }
}
