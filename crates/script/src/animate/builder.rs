//! The per-character context every action plays in ([`Builder`]): the scene and settings
//! ([`Ctx`]), the character's grid, walk choices and the spots it keeps clear of, the shared walk
//! cache, its notes, and the timeline built so far (frames, segments, walks, seats, props), with
//! the pieces the actions share: clips by name, looping, cross-fading, lifting onto a seat.

use inbetween_core::clip::Clip;
use inbetween_core::fk::forward;
use inbetween_core::motion::interpolate_pose;
use inbetween_core::Pose;

use super::context::Ctx;
use super::routes::{WalkCache, WalkChoice, WalkInfo};
use super::{CarriedProp, JointContact, Segment};
use crate::layout::grid::Grid;
use crate::motion::ik::{ground_feet, solve_limb, Limb};
use crate::motion::locomotion::place_clip;
use crate::motion::procedural::SEAT_HEIGHT;
use crate::motion::MotionLibrary;

/// A chair a seated character pulled out from under a table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pulled {
    pub chair: usize,
    /// The spot beside it the character pulled from (x, z metres).
    pub side: [f32; 2],
    /// The chair's offset from its place once pulled out, and once scooted in with the character
    /// on it (x, z metres).
    pub out: [f32; 2],
    pub inside: [f32; 2],
}

/// Where a character is between actions.
#[derive(Debug, Clone, Copy)]
pub(crate) struct State {
    pub pos: [f32; 2],
    pub heading: f64,
    /// Seated: (stand point in front of the seat, seat point, object).
    pub seated: Option<([f32; 2], [f32; 3], usize)>,
    /// Lying (on the seat when seated, else on the floor where it stands).
    pub lying: bool,
    /// Seated on a chair it pulled out from under a table (scooted out and pushed back on
    /// standing up).
    pub pulled: Option<Pulled>,
}

/// Builds one character's frames: what every action of [`super::action`] reads and extends.
pub(crate) struct Builder<'a> {
    pub ctx: &'a Ctx<'a>,
    /// The character's name, for notes.
    pub name: &'a str,
    /// Its occupancy grid (objects plus where earlier characters end up).
    pub grid: &'a Grid,
    /// Spots of earlier characters its stand points and seats keep clear of.
    pub avoid: &'a [[f32; 2]],
    /// Per walk (in order): how long to wait first and which route to take (set by
    /// [`super::crowd::separate`]; the default walks at once along the A* route).
    pub choices: &'a [WalkChoice],
    pub cache: &'a mut WalkCache,
    /// The procedural library, loaded when a clip the library lacks is needed.
    fallback: Option<MotionLibrary>,
    pub st: State,
    pub frames: Vec<Pose>,
    pub segments: Vec<Segment>,
    /// The walks made so far.
    pub walks: Vec<WalkInfo>,
    /// Seat points (x, z) sat on.
    pub seats: Vec<[f32; 2]>,
    /// Props picked up so far.
    pub props: Vec<CarriedProp>,
    /// Furniture slid so far.
    pub slides: Vec<super::Slide>,
    /// What could not be done as asked.
    pub notes: Vec<String>,
    /// While sitting next to someone: the seat nearest this point is taken.
    pub sit_toward: Option<[f32; 2]>,
}

/// Smoothstep on [0, 1] (clamped): the core's one.
pub(crate) use inbetween_core::interp::smoothstep as smooth;

impl<'a> Builder<'a> {
    /// A builder with an empty timeline, standing at `start` facing −Z.
    pub fn new(
        ctx: &'a Ctx<'a>,
        name: &'a str,
        grid: &'a Grid,
        avoid: &'a [[f32; 2]],
        choices: &'a [WalkChoice],
        start: [f32; 2],
        cache: &'a mut WalkCache,
    ) -> Builder<'a> {
        Builder {
            ctx,
            name,
            grid,
            avoid,
            choices,
            cache,
            fallback: None,
            st: State { pos: start, heading: std::f64::consts::PI, seated: None, lying: false, pulled: None },
            frames: Vec::new(),
            segments: Vec::new(),
            walks: Vec::new(),
            seats: Vec::new(),
            props: Vec::new(),
            slides: Vec::new(),
            notes: Vec::new(),
            sit_toward: None,
        }
    }

    /// A clip of the library on the common rig, by exact name, else from the procedural library.
    pub fn named(&mut self, name: &str) -> Clip {
        if let Some(c) = self.ctx.lib.get(name).filter(|c| c.clip.skeleton() == &self.ctx.rig.skeleton) {
            return c.clip.clone();
        }
        let proc = self.fallback.get_or_insert_with(|| MotionLibrary::procedural(0));
        proc.get(name).expect("procedural clip").clip.clone()
    }

    /// The library clip retrieved for `verb` on the common rig, else the procedural clip `name`.
    pub fn retrieved_or(&mut self, verb: &str, name: &str) -> Clip {
        match self.ctx.lib.retrieve(verb).filter(|c| c.clip.skeleton() == &self.ctx.rig.skeleton) {
            Some(c) => c.clip.clone(),
            None => self.named(name),
        }
    }

    pub fn idle_clip(&mut self) -> Clip {
        self.retrieved_or("idle", "procedural idle")
    }

    /// Appends poses, cross-fading the first few from the last frame.
    pub fn append(&mut self, mut poses: Vec<Pose>) {
        if let Some(last) = self.frames.last().cloned() {
            let n = self.ctx.cfg.crossfade.min(poses.len());
            for (k, p) in poses.iter_mut().take(n).enumerate() {
                let w = smooth((k + 1) as f64 / (n + 1) as f64);
                *p = interpolate_pose(&last, p, w);
            }
        }
        for p in &mut poses {
            ground_feet(&self.ctx.rig, p);
        }
        self.frames.extend(poses);
    }

    /// `n` frames of a looped clip with its origin placed at `at`, facing `heading`.
    pub fn looped(&self, clip: &Clip, at: [f32; 2], heading: f64, n: usize) -> Vec<Pose> {
        let placed = placed(clip, at, heading);
        (0..n).map(|k| placed[k % placed.len()].clone()).collect()
    }

    /// `n` frames of the lower body the character holds where it is: still when lying, the seated
    /// loop when seated, else the idle clip looped where it stands.
    pub fn in_place(&mut self, n: usize) -> Vec<Pose> {
        if self.st.lying {
            if let Some(last) = self.frames.last() {
                return vec![last.clone(); n];
            }
        }
        match self.st.seated {
            Some((at, s, _)) => self.seated(at, s, self.st.heading, n),
            None => {
                let idle = self.idle_clip();
                self.looped(&idle, self.st.pos, self.st.heading, n)
            }
        }
    }

    /// Raises the root by `dy(k)` at frame k, re-solving the legs so the ankles stay put.
    pub fn lift(&self, poses: &mut [Pose], dy: impl Fn(usize) -> f64) {
        let rig = &self.ctx.rig;
        for (k, p) in poses.iter_mut().enumerate() {
            let d = dy(k);
            if d.abs() < 1e-5 {
                continue;
            }
            let g = forward(&rig.skeleton, p);
            let ankles = [g.positions[rig.legs[0][2]], g.positions[rig.legs[1][2]]];
            p.translations[rig.hips].y += d;
            for (leg, a) in [Limb::LeftLeg, Limb::RightLeg].into_iter().zip(ankles) {
                solve_limb(rig, p, leg, a, None);
            }
        }
    }

    /// Seated loop frames on a seat (stand point `at`, seat point `seat`, facing `heading`).
    pub fn seated(&mut self, at: [f32; 2], seat: [f32; 3], heading: f64, n: usize) -> Vec<Pose> {
        let clip = self.named("procedural sit");
        let mut poses = self.looped(&clip, at, heading, n);
        let dy = seat[1] as f64 - SEAT_HEIGHT;
        self.lift(&mut poses, |_| dy);
        poses
    }

    /// Closes a segment over frames `[start, now)`.
    pub fn push_segment(
        &mut self,
        verb: &str,
        start: usize,
        object: Option<usize>,
        touching: Vec<usize>,
        contacts: Vec<JointContact>,
    ) {
        let scene = self.ctx.scene;
        self.segments.push(Segment {
            verb: verb.to_string(),
            start,
            end: self.frames.len(),
            target: object.map(|o| scene.objects[o].label.clone()),
            object,
            touching,
            contacts,
        });
    }

    /// Frames of the shortest action, [`super::AnimateConfig::min_action_seconds`].
    pub fn min_action_frames(&self) -> usize {
        (self.ctx.cfg.min_action_seconds * crate::motion::rig::FPS).round() as usize
    }
}

/// The poses of a clip on the common rig placed at `at` facing `heading` ([`place_clip`]).
pub(crate) fn placed(clip: &Clip, at: [f32; 2], heading: f64) -> Vec<Pose> {
    place_clip(clip, at, heading).expect(ON_RIG).poses()
}

/// Why the motion helpers cannot fail on the builder's clips (they are built on, or filtered to,
/// [`super::context::Ctx::rig`]).
pub(crate) const ON_RIG: &str = "the builder's clips are on the common rig";
