//! [`ResequenceJob`]: new frame orders from a start frame, measured, explained and (when asked)
//! written.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use inbetween_core::cancel::Cancel;
use inbetween_io::{OutputSet, Progress};
use serde::Serialize;

use super::analyse::{AnalyseJob, AnalyseReport};
use super::BACKWARD_WINDOW;
use crate::frames::write_clip;
use crate::pipeline::resequence_with;
use crate::preview::{write_contact_sheet, SheetOptions};
use crate::render::{render, Blend};
use crate::sdpf::{
    backward_steps, direction_words, distinct_fraction, explain, explain_step, overlap_delta_o, stability_md,
    SdpfParams, SdpfPath, StepKind, StopReason,
};
use crate::VideoError;

/// The clip a [`ResequenceJob`] draws from.
#[derive(Clone, Debug)]
pub enum ResequenceSource {
    /// Analyse it first (one run does both).
    Analyse(Box<AnalyseJob>),
    /// An analysis kept from before: every regeneration reuses it and its caches.
    Analysed(Arc<AnalyseReport>),
}

/// New frame orders of one clip from a start frame (SDPF, Algorithm 1, with issue 41's walk).
#[derive(Clone, Debug)]
pub struct ResequenceJob {
    pub source: ResequenceSource,
    /// Start frame, a source index.
    pub start: usize,
    /// The walk: its length (default: the source's frame count), seed, loop closure, the
    /// constraints and their ablations.
    pub params: SdpfParams,
    /// Distinct orders wanted (fewer come back when fewer exist).
    pub count: usize,
    /// Write each order here (`.mp4` or `.gif`; with `count > 1` numbered: `new-1.mp4`, …), with a
    /// contact sheet; `None`: measure and explain only.
    pub out: Option<PathBuf>,
    /// The contact sheet (numbered likewise); `None`: beside the output, `<out>.sheet.png`.
    pub sheet: Option<PathBuf>,
    /// Cross-fade written clips over this many frames at transitions whose residual is above the
    /// source's own step (Schödl et al. 2000; [`crate::render`]); 0 (the default): none.
    pub blend: usize,
    /// The report prints each step's candidates and choice (`--explain`), and how each shot's
    /// motion was judged.
    pub explain: bool,
}

impl Default for ResequenceJob {
    fn default() -> Self {
        ResequenceJob {
            source: ResequenceSource::Analyse(Box::default()),
            start: 0,
            params: SdpfParams::default(),
            count: 1,
            out: None,
            sheet: None,
            blend: 0,
            explain: false,
        }
    }
}

/// `new.mp4` → `new-2.mp4` for the second of several outputs.
pub fn numbered(path: &Path, i: usize, count: usize) -> PathBuf {
    if count <= 1 {
        return path.to_path_buf();
    }
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let ext = path.extension().map(|e| format!(".{}", e.to_string_lossy())).unwrap_or_default();
    path.with_file_name(format!("{stem}-{}{ext}", i + 1))
}

/// The contact sheet beside an output: `new.mp4` → `new.sheet.png`.
pub fn sheet_path(out: &Path) -> PathBuf {
    out.with_extension("sheet.png")
}

impl ResequenceJob {
    /// The job for a file or folder, with the engine's defaults.
    pub fn for_file(path: impl Into<PathBuf>) -> ResequenceJob {
        ResequenceJob {
            source: ResequenceSource::Analyse(Box::new(AnalyseJob::for_file(path))),
            ..ResequenceJob::default()
        }
    }

    /// The job on an analysis kept from before.
    pub fn on(analysed: Arc<AnalyseReport>) -> ResequenceJob {
        ResequenceJob { source: ResequenceSource::Analysed(analysed), ..ResequenceJob::default() }
    }

    fn limits(&self) -> &crate::pipeline::VideoLimits {
        match &self.source {
            ResequenceSource::Analyse(a) => &a.config.limits,
            ResequenceSource::Analysed(a) => &a.limits,
        }
    }

    /// Checks the request before any work: the output's kind, the walk's parameters, a length and a
    /// count of at least 1 and within the limits, the start frame when the clip is known.
    pub fn validate(&self) -> Result<(), VideoError> {
        if let Some(out) = &self.out {
            let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
            if ext != "mp4" && ext != "gif" {
                return Err(VideoError::Invalid(format!("{}: the output must end in .mp4 or .gif", out.display())));
            }
        }
        self.params.validate()?;
        self.limits().check_request(self.params.length, 0, self.count)?;
        match &self.source {
            ResequenceSource::Analyse(a) => a.validate(),
            ResequenceSource::Analysed(a) => check_start(self.start, a.frames),
        }
    }

    /// Analyses the clip (unless given), walks `count` orders from `start`, measures and explains
    /// each, and writes them when `out` is set: every clip and sheet of the run, or none.
    pub fn run(&self, cancel: &Cancel, progress: &Progress) -> Result<ResequenceReport, VideoError> {
        self.validate()?;
        let analysed = match &self.source {
            ResequenceSource::Analyse(job) => {
                Arc::new(job.run_checked(cancel, progress, &|frames| check_start(self.start, frames))?)
            }
            ResequenceSource::Analysed(a) => a.clone(),
        };
        check_start(self.start, analysed.frames)?;
        let (paths, walk_s) =
            resequence_with(&analysed.analysis, self.start, &self.params, self.count, self.limits(), cancel)?;
        let mut sequences: Vec<Sequence> = paths.into_iter().map(|p| Sequence::of(p, &analysed)).collect();
        if self.blend > 0 {
            let blend = Blend::new(&analysed.clip, &analysed.shot, self.blend);
            for s in &mut sequences {
                let clip = render(&s.order, &blend);
                s.md = stability_md(&clip.frames, &(0..clip.len()).collect::<Vec<_>>());
                s.blended = blend.positions(&s.order);
            }
        }
        if let Some(out) = &self.out {
            self.write(out, &analysed, &mut sequences)?;
        }
        let direction = if self.explain {
            direction_words(
                &analysed.analysis.info,
                &analysed.analysis.direction,
                self.params.allow_reverse,
                self.params.use_cr,
            )
        } else {
            String::new()
        };
        Ok(ResequenceReport {
            analysis: analysed,
            start: self.start,
            requested: self.count.max(1),
            loop_close: self.params.loop_close,
            sequences,
            walk_s,
            direction,
            explain: self.explain,
        })
    }

    /// Writes every order and its sheet, staged and moved into place together.
    fn write(&self, out: &Path, a: &AnalyseReport, sequences: &mut [Sequence]) -> Result<(), VideoError> {
        let mut set = OutputSet::new();
        let count = self.count;
        let blend = Blend::new(&a.clip, &a.shot, self.blend);
        for (i, s) in sequences.iter_mut().enumerate() {
            let file = numbered(out, i, count);
            let staged = set.file(&file).map_err(|e| VideoError::io(&file, e))?;
            write_clip(&staged, &render(&s.order, &blend))?;
            let sheet = self.sheet.as_ref().map(|p| numbered(p, i, count)).unwrap_or_else(|| sheet_path(&file));
            let staged_sheet = set.file(&sheet).map_err(|e| VideoError::io(&sheet, e))?;
            let title = format!(
                "{} from frame {} (seed {}): {} frames (red BACK: backward step, blue CUT, purple LOOP, teal MATCH: matched transition)",
                a.source,
                self.start,
                s.seed,
                s.order.len()
            );
            let opts = SheetOptions {
                title,
                cuts: s.cuts.clone(),
                loops: s.path.loop_positions(),
                transitions: s.path.transition_positions(),
                ..SheetOptions::default()
            };
            write_contact_sheet(&staged_sheet, &a.clip.frames, &s.order, &opts)?;
            s.file = Some(file);
            s.sheet = Some(sheet);
        }
        set.commit().map_err(|e| VideoError::io(out, e))
    }
}

fn check_start(start: usize, frames: usize) -> Result<(), VideoError> {
    if start >= frames {
        return Err(VideoError::StartOutside { start, frames });
    }
    Ok(())
}

/// How a step that is not the source's next frame was taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JumpKind {
    /// Drawn from S2 (Eq. 20) to an earlier frame.
    Back,
    /// Drawn from S2 to a later frame.
    Jump,
    /// A cut to another shot, or a jump cut inside the shot, where no way on was left.
    Cut,
    /// Round 2's loop back (then the loop repeats).
    Loop,
    /// The next source frame, already shown.
    Replay,
    /// A matched transition (Schödl et al. 2000).
    Transition,
    /// A step of a loop that repeats after a loop back (no walk step of its own).
    Repeat,
}

impl JumpKind {
    /// The word the studio's page and the reports use.
    pub fn word(self) -> &'static str {
        match self {
            JumpKind::Back => "back",
            JumpKind::Jump => "jump",
            JumpKind::Cut => "cut",
            JumpKind::Loop => "loop",
            JumpKind::Replay => "replay",
            JumpKind::Transition => "transition",
            JumpKind::Repeat => "repeat",
        }
    }
}

/// A step of a new order that is not the source's next frame, with the engine's words for it.
#[derive(Clone, Debug, Serialize)]
pub struct Jump {
    /// Position in the order of the frame the step enters.
    pub position: usize,
    pub from: usize,
    pub to: usize,
    pub kind: JumpKind,
    /// The step's candidates, what each constraint removed and the choice (`--explain`'s block).
    pub text: String,
}

/// One new order, measured and explained.
#[derive(Clone, Debug, Serialize)]
pub struct Sequence {
    /// Source frame indices in the new order, the start frame first.
    pub order: Vec<usize>,
    /// The seed of the walk that made it.
    pub seed: u64,
    /// Why the walk ended (`TargetLength`, `LoopClosed`, …).
    #[serde(serialize_with = "debug_words")]
    pub stop: StopReason,
    /// Whether the last frame steps back to the start (with loop closure).
    pub closes_loop: bool,
    /// That closing step, when the loop closes.
    pub closing: Option<Jump>,
    /// Positions entered by a cut to another shot or a jump cut inside one.
    pub cuts: Vec<usize>,
    /// Positions entered by a loop back (round 2's walk) or a matched transition.
    pub loops: Vec<usize>,
    /// Steps to one of the [`BACKWARD_WINDOW`] previous source frames.
    pub backward_steps: usize,
    /// M_D (Eq. 21) of the order, or with a blend of the written frames.
    pub md: f64,
    /// Δo (Eq. 23).
    pub delta_o: f64,
    /// Share of the source's frames shown.
    pub distinct: f64,
    /// Every step that is not the source's next frame.
    pub jumps: Vec<Jump>,
    /// Positions whose written frame is a cross-fade (with a blend).
    pub blended: Vec<usize>,
    /// The whole walk in words (`--explain`).
    pub explain: String,
    /// The clip and contact sheet written (with an output).
    pub file: Option<PathBuf>,
    pub sheet: Option<PathBuf>,
    /// The walk itself, every transition's candidate sets.
    #[serde(skip)]
    pub path: SdpfPath,
}

fn inner<S: serde::Serializer>(a: &Arc<AnalyseReport>, s: S) -> Result<S::Ok, S::Error> {
    a.as_ref().serialize(s)
}

fn debug_words<S: serde::Serializer>(stop: &StopReason, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&format!("{stop:?}"))
}

impl Sequence {
    fn of(path: SdpfPath, a: &AnalyseReport) -> Sequence {
        let order = path.frames.clone();
        let n = a.frames;
        Sequence {
            seed: path.seed,
            stop: path.stop,
            closes_loop: path.closes_loop,
            closing: path.closing.as_ref().and_then(|t| {
                let to = t.chosen?;
                Some(Jump {
                    position: order.len(),
                    from: t.from,
                    to,
                    kind: JumpKind::Transition,
                    text: explain_step(t),
                })
            }),
            cuts: [path.cut_positions(), path.jump_cut_positions()].concat(),
            loops: [path.loop_positions(), path.transition_positions()].concat(),
            backward_steps: backward_steps(&order, BACKWARD_WINDOW),
            md: a.md(&order),
            delta_o: overlap_delta_o(&order, n),
            distinct: distinct_fraction(&order, n),
            jumps: jumps(&path),
            blended: Vec::new(),
            explain: explain(&path),
            file: None,
            sheet: None,
            order,
            path,
        }
    }
}

/// Each step of `path` that is not the next source frame, with the engine's words for it. Steps
/// inside a repeating loop (after a loop back the path's frames repeat without new transitions)
/// point to the step they repeat.
fn jumps(path: &SdpfPath) -> Vec<Jump> {
    let order = &path.frames;
    let mut out = Vec::new();
    let mut first_at: std::collections::HashMap<(usize, usize), usize> = std::collections::HashMap::new();
    for p in 1..order.len() {
        let (from, to) = (order[p - 1], order[p]);
        if to == from + 1 {
            continue;
        }
        let (kind, text) = match path.transitions.get(p - 1).filter(|t| t.from == from && t.chosen == Some(to)) {
            Some(t) => {
                let kind = match t.kind {
                    StepKind::Distilled if to < from => JumpKind::Back,
                    StepKind::Distilled => JumpKind::Jump,
                    StepKind::Cut { .. } | StepKind::JumpCut { .. } => JumpKind::Cut,
                    StepKind::LoopBack { .. } => JumpKind::Loop,
                    StepKind::Replay => JumpKind::Replay,
                    StepKind::Transition { .. } => JumpKind::Transition,
                };
                (kind, explain_step(t))
            }
            None => {
                let q = first_at.get(&(from, to)).copied().unwrap_or(p);
                (JumpKind::Repeat, format!("frame {from} → {to}: the loop repeats the step at position {q}"))
            }
        };
        first_at.entry((from, to)).or_insert(p);
        out.push(Jump { position: p, from, to, kind, text });
    }
    out
}

/// What a [`ResequenceJob`] made.
#[derive(Clone, Debug, Serialize)]
pub struct ResequenceReport {
    /// The clip and its analysis.
    #[serde(serialize_with = "inner")]
    pub analysis: Arc<AnalyseReport>,
    pub start: usize,
    /// Orders asked for; `sequences` holds fewer when fewer distinct ones exist.
    pub requested: usize,
    /// Whether loop closure was asked for.
    pub loop_close: bool,
    pub sequences: Vec<Sequence>,
    /// Wall time of the walks, seconds.
    pub walk_s: f64,
    /// With `explain`: how each shot's motion was judged and what C_r does there.
    pub direction: String,
    /// Whether the report prints each walk in full.
    #[serde(skip)]
    pub explain: bool,
}

impl fmt::Display for ResequenceReport {
    /// The analysis's lines, then per order its measures (and with `explain` the walk in words),
    /// then the seconds per stage.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = &self.analysis;
        write!(f, "{a}")?;
        f.write_str(&self.direction)?;
        for (i, s) in self.sequences.iter().enumerate() {
            let name = s.file.as_ref().map_or_else(|| format!("order {}", i + 1), |p| p.display().to_string());
            let closes = match (self.loop_close, s.closes_loop) {
                (false, _) => "",
                (true, true) => ", loop closes",
                (true, false) => ", no loop found",
            };
            let sheet = s.sheet.as_ref().map_or_else(String::new, |p| format!("; contact sheet {}", p.display()));
            writeln!(
                f,
                "{name}: {} frames ({:?}{closes}), {} backward steps, {} cuts, {} jumps back or ahead (loop backs, matched transitions), M_D {:.4} (source {:.4}), Δo {:.3}{sheet}",
                s.order.len(),
                s.stop,
                s.backward_steps,
                s.cuts.len(),
                s.loops.len(),
                s.md,
                a.source_md,
                s.delta_o,
            )?;
            if self.explain {
                f.write_str(&s.explain)?;
            }
        }
        if self.sequences.len() < self.requested {
            writeln!(
                f,
                "only {} distinct sequences exist from frame {} under these constraints",
                self.sequences.len(),
                self.start
            )?;
        }
        for s in &a.stages {
            writeln!(f, "  {}: {:.2} s", s.stage, s.seconds)?;
        }
        writeln!(f, "  SDPF walks: {:.2} s", self.walk_s)
    }
}
