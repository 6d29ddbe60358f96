//! The inputs and outputs of SDPF (Algorithm 1): parameters, per-frame motion facts, the motion
//! distance of Eq. 15, and the recorded path with every transition's candidate sets.

use crate::VideoError;

/// Parameters of [`sdpf`](super::sdpf). [`Default`] is the paper's configuration (ξ = π/3, both
/// constraints on) plus our defaults for what the paper lacks, and a choice (Eq. 20) that also
/// weighs content: τ = 0.1 on motion distances relative to ω, content weight λ = 2 (see
/// [`SdpfParams::paper_choice`] for Eq. 20 as printed, and the crate README for why).
#[derive(Debug, Clone, PartialEq)]
pub struct SdpfParams {
    /// ξ of Eq. 12: the largest allowed angle (radians) between the tendencies of two LMS frames.
    pub xi: f32,
    /// Directional distillation C_d (Eq. 12); `false` is the "w/o C_d" ablation of Table 3.
    pub use_cd: bool,
    /// Coherent distillation C_t (Eq. 16–17); `false` is the "w/o C_t" ablation of Table 3.
    pub use_ct: bool,
    /// Reverse distillation C_r (beyond the paper, see [`Ctx::reverse`](super::distill)): no step
    /// that plays the source's motion backwards. `false` is the "w/o C_r" ablation.
    pub use_cr: bool,
    /// Let C_r through in shots whose motion is judged undirected ([`MotionInfo::directed`]: water,
    /// fire, flicker), where playing backwards looks no different. Shots judged directed keep C_r.
    pub allow_reverse: bool,
    /// How many previous source frames a step may not go back to (C_r's replay test): a step
    /// c → c − j, 1 ≤ j ≤ `reverse_window`, replays the source backwards.
    pub reverse_window: usize,
    /// Target length in frames (the start frame included); `None`: the source's frame count, or
    /// with `stop_early`, until the early stop.
    pub length: Option<usize>,
    /// The paper's early stop (§5.2.3): end the walk when S2 is empty. Off (the default), the walk
    /// goes on as an editor would: a cut to the shot that best matches the current frame, or,
    /// when no other shot has frames left, a loop back to the path's best-matching frame.
    pub stop_early: bool,
    /// Loop closure: end on a frame that can transition back to the start frame under the same
    /// constraints (beyond the paper; see [`sdpf`](super::sdpf) for the method).
    pub loop_close: bool,
    /// Allow transitions between frames of different scenes (see [`MotionInfo::cuts`]).
    pub allow_cuts: bool,
    /// Seed of the softmax draws (Eq. 20); every attempt derives its stream from it.
    pub seed: u64,
    /// Seeded attempts tried when the first walk misses its goal (target length or loop closure).
    pub attempts: usize,
    /// Softmax temperature τ: Ω ∝ exp(δ/τ). The paper's Eq. 20 is τ = 1 on its own latent scale.
    pub temperature: f32,
    /// Divide the motion distances by their mean over S1 (ω of Eq. 17) before Eq. 20, so that τ
    /// is in units of ω and the choice does not depend on the arbitrary scale of the latent space
    /// (ours is not the paper's). `false`: δ in latent units, as Eq. 20 prints it.
    pub relative_temperature: bool,
    /// Weight λ of the content distance in the choice (beyond the paper; 0 is Eq. 20 as printed):
    /// Ω_k ∝ exp(−(m_k/ω + λ·e_ck/ē)/τ), with m_k the motion distance, ω its mean over S1, e_ck
    /// the edge weight (Eq. 7) and ē its mean over S1. The paper treats the S1 frames alike
    /// whatever their edge weight (§5.1); with η the mean edge weight, S1 is about half of the
    /// clip, and a choice blind to content jumps across it (measured: M_D 1.8–3× the source's).
    pub content_weight: f32,
    /// Matched transitions (issue 41, after Schödl et al. 2000, "Video Textures"): where S2 is empty
    /// the walk goes on by the next source frame or by a jump `c → j` whose frames around `j − 1`
    /// match those around `c` in content and motion direction ([`texture`](super::texture)), and
    /// cuts to another shot only when no such way leads to an unvisited frame. Off: round 2's walk
    /// (a cut, else one loop back to the closest frame of the path, repeated up to the length).
    pub transitions: bool,
    /// Frames on each side of the window a transition is matched over (`m`: 2m + 1 frame pairs,
    /// binomial weights).
    pub match_window: usize,
    /// θ: a transition is accepted when its windowed distance is at most θ times the shot's median
    /// source step (the distance between adjacent frames of the shot).
    pub match_threshold: f32,
    /// Where no transition under θ leads to an unvisited frame, transitions up to `relax × θ`
    /// are tried before a cut.
    pub match_relax: f32,
    /// κ: with `transitions`, a step drawn by Eq. 20 may be at most κ times the shot's median source
    /// step (or the current frame's own step to its successor, if larger) away in appearance, so that
    /// the new order is about as smooth as the source (M_D, Eq. 21).
    pub step_cap: f32,
    /// Shortest loop, seconds, that the walk repeats once every frame it can reach is used: a shorter
    /// one played over and over reads as a stutter.
    pub min_loop_s: f32,
}

impl SdpfParams {
    /// Eq. 20 exactly as printed: Ω ∝ exp(δ) on the latent motion distances (τ = 1, absolute),
    /// no content term. The bench reports it beside the default.
    pub fn paper_choice(self) -> SdpfParams {
        SdpfParams { temperature: 1.0, relative_temperature: false, content_weight: 0.0, ..self }
    }

    /// Algorithm 1's walk as the paper describes it: no reverse distillation C_r, the early stop
    /// when S2 is empty and, without a target length, no other end (the choice stays ours; add
    /// [`SdpfParams::paper_choice`] for Eq. 20 as printed).
    pub fn paper_walk() -> SdpfParams {
        SdpfParams { use_cr: false, stop_early: true, ..SdpfParams::default() }
    }

    /// The target length for a source of `n` frames: `length`, else `n` (unbounded with `stop_early`).
    pub fn target_length(&self, n: usize) -> usize {
        match self.length {
            Some(l) => l,
            None if self.stop_early => usize::MAX,
            None => n,
        }
    }
}

impl Default for SdpfParams {
    fn default() -> Self {
        SdpfParams {
            xi: std::f32::consts::FRAC_PI_3,
            use_cd: true,
            use_ct: true,
            use_cr: true,
            allow_reverse: false,
            reverse_window: 3,
            length: None,
            stop_early: false,
            loop_close: false,
            allow_cuts: false,
            seed: 0,
            attempts: 8,
            temperature: 0.1,
            relative_temperature: true,
            content_weight: 2.0,
            transitions: true,
            match_window: 2,
            match_threshold: 1.0,
            match_relax: 2.5,
            step_cap: 1.1,
            min_loop_s: 1.0,
        }
    }
}

impl SdpfParams {
    /// Rejects values that would make the walk meaningless (a NaN ξ, a non-positive temperature).
    pub fn validate(&self) -> Result<(), VideoError> {
        if !(self.xi.is_finite() && self.xi >= 0.0) {
            return Err(VideoError::Invalid(format!("SDPF: xi must be a finite angle ≥ 0, got {}", self.xi)));
        }
        if !(self.temperature.is_finite() && self.temperature > 0.0) {
            return Err(VideoError::Invalid(format!("SDPF: temperature must be > 0, got {}", self.temperature)));
        }
        for (name, v) in [
            ("match_threshold", self.match_threshold),
            ("match_relax", self.match_relax),
            ("step_cap", self.step_cap),
            ("min_loop_s", self.min_loop_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(VideoError::Invalid(format!("SDPF: {name} must be a finite number ≥ 0, got {v}")));
            }
        }
        if self.length == Some(0) {
            return Err(VideoError::Invalid(
                "SDPF: a target length of 0 frames asks for nothing; give at least 1 (the start frame), or none for the source's length".into(),
            ));
        }
        Ok(())
    }
}

/// Per-frame motion facts used by the distillation. Each vector is either empty (no such
/// information: the corresponding rule never fires) or has one entry per frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MotionInfo {
    /// Motion tendency T of each frame (Eq. 10), radians; `None` (or a NaN) where no pixel passes.
    pub tendency: Vec<Option<f32>>,
    /// LMS membership of each frame (Eq. 11).
    pub lms: Vec<bool>,
    /// Shot (scene) index of each frame: scene cuts split shots (see
    /// [`detect_shots`](super::detect_shots)); empty or all equal for one shot.
    pub shot: Vec<usize>,
    /// Per shot (indexed by shot, not frame): whether its motion is directed (people, vehicles,
    /// camera moves), so that playing it backwards shows; see
    /// [`judge_directed`](super::judge_directed). Empty, or a shot past its end: directed.
    pub directed: Vec<bool>,
    /// Appearance distances `appearance[i · n + j]` between frames (the pipeline's: RMS of 32-pixel
    /// thumbnails, the proxy of Eq. 21's `D`), for matched transitions and the step cap; empty: the
    /// graph's edge weights stand in.
    pub appearance: Vec<f32>,
    /// Frames per second of the source (0: unknown, read as 25), for [`SdpfParams::min_loop_s`].
    pub fps: f32,
}

impl MotionInfo {
    /// No tendencies, no LMS, no cuts: only Eq. 8 and C_t act.
    pub fn none() -> MotionInfo {
        MotionInfo::default()
    }

    /// Tendencies and LMS flags with the shots that the cut flags of
    /// [`detect_cuts`](super::detect_cuts) delimit (`cuts[i]`: a cut between frames `i − 1` and `i`).
    pub fn with_cuts(tendency: Vec<Option<f32>>, lms: Vec<bool>, cuts: &[bool]) -> MotionInfo {
        MotionInfo { tendency, lms, shot: super::cuts::shots_from_cuts(cuts), ..MotionInfo::default() }
    }

    /// Checks that every non-empty vector has one entry per frame.
    pub fn validate(&self, n: usize) -> Result<(), VideoError> {
        for (name, len) in [("tendency", self.tendency.len()), ("lms", self.lms.len()), ("shot", self.shot.len())] {
            if len != 0 && len != n {
                return Err(VideoError::Invalid(format!("SDPF: motion {name} has {len} entries for {n} frames")));
            }
        }
        if !self.appearance.is_empty() && self.appearance.len() != n * n {
            return Err(VideoError::Invalid(format!(
                "SDPF: the appearance distances have {} entries, expected {n}×{n}",
                self.appearance.len()
            )));
        }
        Ok(())
    }

    /// The tendency of frame `i` when it is known and finite.
    pub fn tendency_of(&self, i: usize) -> Option<f32> {
        self.tendency.get(i).copied().flatten().filter(|t| t.is_finite())
    }

    /// Whether frame `i` is an LMS frame (Eq. 11).
    pub fn is_lms(&self, i: usize) -> bool {
        self.lms.get(i).copied().unwrap_or(false)
    }

    /// The shot of frame `i` (0 when no shots are given).
    pub fn shot_of(&self, i: usize) -> usize {
        self.shot.get(i).copied().unwrap_or(0)
    }

    /// Whether the shot of frame `i` is judged directed (true when unknown).
    pub fn directed_at(&self, i: usize) -> bool {
        self.directed.get(self.shot_of(i)).copied().unwrap_or(true)
    }

    /// The shortest loop [`SdpfParams::min_loop_s`] allows, in frames (at least 2).
    pub fn min_loop_frames(&self, seconds: f32) -> usize {
        let fps = if self.fps.is_finite() && self.fps > 0.0 { self.fps } else { 25.0 };
        ((seconds * fps).round() as usize).max(2)
    }

    /// The number of shots (1 when no shots are given).
    pub fn shots(&self) -> usize {
        self.shot.iter().max().map_or(1, |m| m + 1)
    }
}

/// The motion distance of PMSM (Eq. 15), as a non-negative distance `‖R(X_c^p) − R(X_k^p)‖₂`, so
/// that the paper's δ is its negation. Implementations may compute lazily (pseudo-images per pair).
pub trait MotionDistance {
    /// `−δ(FC, FK)` of Eq. 15 for the transition `c → k`: smaller is a smoother motion change.
    fn distance(&self, c: usize, k: usize) -> f32;
    /// The C_t threshold of Eq. 17 when `n1 < 2`, as a distance: the paper's
    /// `ω = min(δ(FC, A1), δ(FC, A2))` with A1, A2 = FC rotated by ±π/2, i.e.
    /// `max(dist(FC, A1), dist(FC, A2))`. A lone candidate passes when it is no farther from FC
    /// than FC's own quarter-turns are. (Returning the smaller of the two distances instead is a
    /// stricter reading; for a flow and its two quarter-turns both are usually close.)
    fn rotated_floor(&self, c: usize) -> f32;
    /// `distance(c, k)` for every `k` of `ks`; override to batch the work (one network call).
    fn distances(&self, c: usize, ks: &[usize]) -> Vec<f32> {
        ks.iter().map(|&k| self.distance(c, k)).collect()
    }
}

/// Motion distances held in a matrix (`dist[c · n + k]`) with one rotated floor per frame.
#[derive(Debug, Clone, PartialEq)]
pub struct MatrixMotion {
    pub n: usize,
    pub dist: Vec<f32>,
    pub floor: Vec<f32>,
}

impl MotionDistance for MatrixMotion {
    fn distance(&self, c: usize, k: usize) -> f32 {
        self.dist.get(c * self.n + k).copied().unwrap_or(f32::NAN)
    }
    fn rotated_floor(&self, c: usize) -> f32 {
        self.floor.get(c).copied().unwrap_or(f32::NAN)
    }
}

/// No motion information: every motion distance is 0, so C_t keeps every candidate and the
/// softmax of Eq. 20 is uniform over S2 (what the paper says of S1 in §5.1).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoMotion;

impl MotionDistance for NoMotion {
    fn distance(&self, _c: usize, _k: usize) -> f32 {
        0.0
    }
    fn rotated_floor(&self, _c: usize) -> f32 {
        0.0
    }
}

/// One candidate of S1 with the numbers the constraints looked at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    pub frame: usize,
    /// Edge weight e_ck (Eq. 7/8).
    pub edge: f32,
    /// Motion distance −δ(FC, FK) (Eq. 15).
    pub motion: f32,
    /// Its motion tendency (Eq. 10) and LMS membership (Eq. 11).
    pub tendency: Option<f32>,
    pub lms: bool,
}

/// What the directional distillation (Eq. 12) did at one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CdState {
    /// `use_cd` is off (ablation).
    Disabled,
    /// The current frame is not an LMS frame (or its tendency is unknown): C_d is skipped.
    NotLms,
    /// The current frame is an LMS frame but S1 holds no LMS frame: C_d is skipped.
    NoLmsCandidate,
    /// C_d applied with the current frame's tendency T_c and the angle ξ.
    Active { tendency: f32, xi: f32 },
}

/// Which case of Eq. 17 set the C_t threshold ω (as a distance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Omega {
    /// `use_ct` is off (ablation), or S1 is empty.
    Off,
    /// n1 ≥ 2: the mean motion distance over S1.
    Mean(f32),
    /// n1 < 2: the distance of FC to its ±π/2 rotations ([`MotionDistance::rotated_floor`]).
    Rotated(f32),
}

/// One step of Algorithm 1 from frame `from`, with everything `--explain` prints.
///
/// `removed_cd` and `removed_ct` are each constraint's own verdict on S1 (a candidate failing both
/// is listed in both); S2 is S1 minus both (Eq. 18–19), with its softmax probabilities in `probs`.
#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    pub from: usize,
    /// The frame drawn from S2; `None` only on the last transition of an early stop (S2 empty).
    pub chosen: Option<usize>,
    /// S1 (Eq. 8), ascending, after removing frames across a scene cut.
    pub s1: Vec<usize>,
    /// S1's numbers, in the order of `s1`.
    pub candidates: Vec<Candidate>,
    /// Frames under η that lie in another shot (beyond the paper; empty with `allow_cuts`).
    pub removed_cut: Vec<usize>,
    /// C_r (beyond the paper): the S1 frames a step to which would play the motion backwards.
    pub cr: CrState,
    pub removed_cr: Vec<usize>,
    pub cd: CdState,
    pub removed_cd: Vec<usize>,
    pub omega: Omega,
    pub removed_ct: Vec<usize>,
    /// S2 frames that the step cap ([`SdpfParams::step_cap`]) removed: too far in appearance.
    pub removed_cap: Vec<usize>,
    /// S2 with the probabilities of Eq. 20.
    pub probs: Vec<(usize, f32)>,
    /// How the step was taken: drawn from S2, or, S2 being empty, a cut or a loop back.
    pub kind: StepKind,
}

/// What C_r did at one step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CrState {
    /// `use_cr` is off (ablation).
    Disabled,
    /// The shot is judged undirected and `allow_reverse` is on: reverse steps allowed.
    AllowedUndirected,
    /// Applied.
    Active,
}

/// How a step was taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepKind {
    /// Drawn from S2 by Eq. 20 (Algorithm 1, line 22).
    Distilled,
    /// S2 was empty: a cut to the unvisited frame of another shot closest in content (beyond the
    /// paper; what an editor does at a dead end). `edge` is its edge weight e_ck.
    Cut { edge: f32 },
    /// S2 was empty and no other shot had frames left: back to the frame at position `to` of the
    /// path, closest in content among those C_r allows; from there the path's frames repeat (a loop).
    LoopBack { to: usize, edge: f32 },
    /// S2 was empty: the next source frame, already shown (a replay on the way to unvisited frames,
    /// or round and round a loop once every reachable frame is shown).
    Replay,
    /// S2 was empty: a matched transition (Schödl et al. 2000): the frames around `j − 1` match those
    /// around the current frame in content and motion direction, so `j` follows as the next source
    /// frame would. `cost`: the windowed distance over the shot's median source step (θ's unit);
    /// `loop_frames`: when it goes back, the frames from `j` to the current one (the loop it opens).
    Transition { cost: f32, loop_frames: usize },
    /// S2 was empty and no next frame or transition under `relax × θ` leads to the frames of the shot
    /// not yet shown: a jump cut inside the shot to the one that best follows (`cost` as for
    /// [`StepKind::Transition`], or the appearance distance in source steps where no window matches).
    JumpCut { cost: f32 },
}

impl Transition {
    /// The frames of S2.
    pub fn s2(&self) -> Vec<usize> {
        self.probs.iter().map(|&(f, _)| f).collect()
    }

    /// The probability Eq. 20 gave frame `k` (0 when `k` is not in S2).
    pub fn prob_of(&self, k: usize) -> f32 {
        self.probs.iter().find(|&&(f, _)| f == k).map_or(0.0, |&(_, p)| p)
    }
}

/// Why a walk ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// The target length was reached.
    TargetLength,
    /// S2 was empty (§5.2.3: "the algorithm will early stop to maintain the quality").
    EarlyStop,
    /// Every frame is on the path.
    AllVisited,
    /// The path was cut where its last frame can transition back to the start (loop closure).
    LoopClosed,
    /// S2 was empty, no other shot had frames left and no loop back was possible.
    DeadEnd,
}

/// The plan's name for [`SdpfPath`].
pub type Path = SdpfPath;

/// A path found by SDPF: the new frame order and how each step was taken.
#[derive(Debug, Clone, PartialEq)]
pub struct SdpfPath {
    /// Source frame indices in the new order, starting with the start frame. Frames repeat only
    /// after a matched transition or replay ([`StepKind::Transition`], [`StepKind::Replay`]), or
    /// after a loop back ([`StepKind::LoopBack`], round 2's walk), from which the loop's frames repeat.
    pub frames: Vec<usize>,
    /// One entry per step up to and including a loop back (then the loop repeats without new
    /// steps), plus the failed step of an early stop.
    pub transitions: Vec<Transition>,
    pub stop: StopReason,
    /// Whether the last frame can transition back to the start (loop closure succeeded); the same
    /// as `closing.is_some()`.
    pub closes_loop: bool,
    /// With loop closure: the step from the last frame back to the start (its `chosen` is the start).
    pub closing: Option<Transition>,
    /// η of Eq. 8 for this graph.
    pub eta: f32,
    /// The seed of the attempt that produced this path, and that attempt's index.
    pub seed: u64,
    pub attempt: usize,
}

impl SdpfPath {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether the path is empty (never true for a path returned by SDPF).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Whether the last frame transitions back to the start (loop closure succeeded).
    pub fn closed(&self) -> bool {
        self.closes_loop
    }

    /// Positions `i` (in `frames`) entered by a cut (frames[i − 1] → frames[i]).
    pub fn cut_positions(&self) -> Vec<usize> {
        self.kind_positions(|k| matches!(k, StepKind::Cut { .. }))
    }

    /// Positions `i` entered by a jump cut inside a shot.
    pub fn jump_cut_positions(&self) -> Vec<usize> {
        self.kind_positions(|k| matches!(k, StepKind::JumpCut { .. }))
    }

    /// Positions `i` entered by a matched transition.
    pub fn transition_positions(&self) -> Vec<usize> {
        self.kind_positions(|k| matches!(k, StepKind::Transition { .. }))
    }

    /// Positions `i` entered by a loop back.
    pub fn loop_positions(&self) -> Vec<usize> {
        self.kind_positions(|k| matches!(k, StepKind::LoopBack { .. }))
    }

    fn kind_positions(&self, want: impl Fn(&StepKind) -> bool) -> Vec<usize> {
        self.transitions
            .iter()
            .enumerate()
            .filter(|(_, t)| t.chosen.is_some() && want(&t.kind))
            .map(|(i, _)| i + 1)
            .collect()
    }
}
