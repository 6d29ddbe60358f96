//! Actions done to or with another character (issue 39): "walks to Tom", "follows Mia", "sits
//! next to Ben", "stands behind him", "faces Ben", "talks to Anna", "waves at Ben". The other
//! character is where it ends up ([`Person`]: characters are planned in order of appearance, so
//! someone named earlier is already placed).

use super::{Step, Verb};
use crate::animate::builder::Builder;
use crate::animate::character::Person;
use crate::animate::spots::{dist2, heading_to, SPOT_MARGIN};
use crate::animate::{contacts_of, PASSING_DISTANCE};
use crate::catalogue::ContactKind;
use crate::motion::rig::wrap;

/// How far from the other character's root one stands beside, behind or in front of them, or
/// walks up to, metres (within reach, outside the crowd repair's passing distance).
pub(crate) const WITHIN_REACH: f32 = 0.75;
/// Farther than this (metres) from someone they talk to, a standing character walks up first.
pub(crate) const TALKING_DISTANCE: f32 = 2.0;
/// A character already turned within this of the partner does not turn first, radians.
const FACING_SLACK: f64 = 0.35;

/// Where one stands relative to someone.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Spot {
    /// Walking up to them ("walks to Tom"): on the side one comes from, facing them.
    Up,
    /// Behind them, turned as they are ("follows", "stands behind").
    Behind,
    /// In front of them, facing them.
    Front,
    /// At their side, turned as they are.
    Beside,
}

impl Builder<'_> {
    /// Plays `step` towards `p` (see the module comment); verbs with no sense towards someone
    /// (lying, putting down) play as without them.
    pub fn play_towards(&mut self, step: &Step, p: &Person) {
        let prep = step.action.preposition.as_deref().unwrap_or("");
        let spot = match prep {
            "behind" => Some(Spot::Behind),
            "in front of" | "before" => Some(Spot::Front),
            "next to" | "beside" | "by" | "near" | "alongside" => Some(Spot::Beside),
            _ => None,
        };
        match step.kind {
            Verb::Sit => self.sit_near(step, p.pos),
            Verb::Locomotion => {
                let follow = step.verb == "follow" || step.action.verb == "follow";
                let spot = if follow { Spot::Behind } else { spot.unwrap_or(Spot::Up) };
                self.go_to_person(step, p, spot);
            }
            Verb::Stand | Verb::Act if spot.is_some() && self.st.seated.is_none() && !self.st.lying => {
                self.go_to_person(step, p, spot.unwrap_or(Spot::Up));
                if step.kind == Verb::Act {
                    self.act(step);
                } else {
                    let start = self.frames.len();
                    let n = self.min_action_frames();
                    let poses = self.in_place(n);
                    self.append(poses);
                    self.push_segment("stand", start, None, Vec::new(), Vec::new());
                }
            }
            Verb::Stand => {
                self.play(step);
                self.face_person(p);
            }
            Verb::Turn(_) if self.st.seated.is_none() && !self.st.lying => {
                // "faces Ben", "turns to Ben".
                let dh = wrap(heading_to(self.st.pos, p.pos, self.st.heading) - self.st.heading);
                self.turn(dh, None);
            }
            Verb::Act => {
                // "talks to Ben" from across the room walks up first; "looks at", "waves at"
                // only turn.
                let talk = matches!(prep, "to" | "with") && crate::motion::verbs::social(&step.action.verb);
                if talk && dist2(self.st.pos, p.pos).sqrt() > TALKING_DISTANCE && self.st.seated.is_none() {
                    self.go_to_person(step, p, Spot::Up);
                } else {
                    self.face_person(p);
                }
                self.act(step);
            }
            _ => self.play(step),
        }
    }

    /// Turns on the spot to face `p` when standing and turned away by more than a little.
    fn face_person(&mut self, p: &Person) {
        if self.st.seated.is_some() || self.st.lying {
            return;
        }
        let dh = wrap(heading_to(self.st.pos, p.pos, self.st.heading) - self.st.heading);
        if dh.abs() > FACING_SLACK {
            self.turn(dh, None);
        }
    }

    /// Walks to a free spot [`WITHIN_REACH`] of `p` (behind, in front, beside, or on the side it
    /// comes from), ending turned to them (in front, walking up) or as they are turned.
    fn go_to_person(&mut self, step: &Step, p: &Person, spot: Spot) {
        self.stand_up();
        let f = [p.heading.sin() as f32, p.heading.cos() as f32];
        let left = [f[1], -f[0]];
        let from = self.st.pos;
        let want: Vec<[f32; 2]> = match spot {
            Spot::Up => {
                let d = (dist2(from, p.pos)).sqrt().max(1e-3);
                let toward = [(from[0] - p.pos[0]) / d, (from[1] - p.pos[1]) / d];
                let side = [toward[1], -toward[0]];
                // From the side one comes from first, then round them (their seat or the
                // furniture may fill that side), a little farther out last.
                let mut out = Vec::new();
                for reach in [WITHIN_REACH, 1.0] {
                    for a in [0.0f32, 0.5, -0.5, 1.0, -1.0, 1.6, -1.6, 2.4, -2.4, std::f32::consts::PI] {
                        let (s, c) = a.sin_cos();
                        let dir = [toward[0] * c + side[0] * s, toward[1] * c + side[1] * s];
                        out.push([p.pos[0] + reach * dir[0], p.pos[1] + reach * dir[1]]);
                    }
                }
                out
            }
            // Behind or in front, a little farther when furniture (their seat) fills the spot.
            Spot::Behind | Spot::Front => {
                let s = if spot == Spot::Behind { -1.0 } else { 1.0 };
                let mut out = Vec::new();
                for d in [WITHIN_REACH, 1.0, 1.25, 1.5] {
                    for l in [0.0, 0.3, -0.3] {
                        out.push([p.pos[0] + s * d * f[0] + l * left[0], p.pos[1] + s * d * f[1] + l * left[1]]);
                    }
                }
                out
            }
            Spot::Beside => [WITHIN_REACH, 1.0]
                .iter()
                .flat_map(|&d| [1.0f32, -1.0].map(|s| [p.pos[0] + s * d * left[0], p.pos[1] + s * d * left[1]]))
                .collect(),
        };
        // The first wanted spot whose nearest free cell stays close to it and can be walked to.
        let grid = self.grid;
        let reach = grid.nearest_free(self.st.pos).map(|c| grid.reachable_from(c));
        let reachable = |c: crate::layout::grid::Cell| reach.as_ref().is_none_or(|r| r[c.1 * grid.nx + c.0]);
        let snapped: Vec<([f32; 2], [f32; 2])> = want
            .iter()
            .filter_map(|w| grid.nearest_free(*w).filter(|c| reachable(*c)).map(|c| (grid.center(c), *w)))
            .collect();
        let Some(to) =
            snapped.iter().find(|(s, w)| dist2(*s, *w) <= 0.3 * 0.3).or_else(|| snapped.first()).map(|(s, _)| *s)
        else {
            self.notes.push(format!("{}: no free floor near {}", self.name, p.name));
            return;
        };
        let heading = match spot {
            Spot::Up | Spot::Front => heading_to(to, p.pos, self.st.heading),
            Spot::Behind | Spot::Beside => p.heading,
        };
        let start = self.frames.len();
        if dist2(to, self.st.pos) > 0.2 * 0.2 {
            self.walk(to, heading, &step.verb, step.speed);
        } else {
            let dh = wrap(heading - self.st.heading);
            if dh.abs() > FACING_SLACK {
                self.turn(dh, None);
            }
        }
        let verb = if step.kind == Verb::Locomotion { step.verb.as_str() } else { "walk" };
        self.push_segment(verb, start, None, Vec::new(), Vec::new());
    }

    /// "sits (down) next to Ben": on the free seat nearest `near`, of any seat object.
    pub(crate) fn sit_near(&mut self, step: &Step, near: [f32; 2]) {
        let o = self.free_seat_near(near, |_| true);
        let s = Step {
            action: step.action,
            verb: step.verb.clone(),
            kind: step.kind,
            object: o.or(step.object),
            speed: step.speed,
            destination: step.destination.clone(),
        };
        self.sit_toward = Some(near);
        self.sit(&s);
        self.sit_toward = None;
    }

    /// The seat object (among those `keep` accepts) with the free seat contact nearest `near`:
    /// free when no earlier character stands or sits within the passing distance of it.
    pub(crate) fn free_seat_near(&self, near: [f32; 2], keep: impl Fn(usize) -> bool) -> Option<usize> {
        let scene = self.ctx.scene;
        let mut best: Option<(f32, usize)> = None;
        for (o, obj) in scene.objects.iter().enumerate() {
            if !keep(o) || !self.ctx.cat.get(&obj.category).is_some_and(|c| c.is_seat()) {
                continue;
            }
            for s in contacts_of(scene, self.ctx.cat, o, ContactKind::Seat) {
                let p = [s[0], s[2]];
                let taken = self.avoid.iter().any(|a| dist2(p, *a).sqrt() < PASSING_DISTANCE - SPOT_MARGIN);
                let d = dist2(p, near).sqrt();
                if !taken && best.is_none_or(|(b, _)| d < b) {
                    best = Some((d, o));
                }
            }
        }
        best.map(|b| b.1)
    }

    /// Whether every seat contact of object `o` is taken by an earlier character.
    pub(crate) fn seats_taken(&self, o: usize) -> bool {
        let seats = contacts_of(self.ctx.scene, self.ctx.cat, o, ContactKind::Seat);
        !seats.is_empty()
            && seats
                .iter()
                .all(|s| self.avoid.iter().any(|a| dist2([s[0], s[2]], *a).sqrt() < PASSING_DISTANCE - SPOT_MARGIN))
    }
}
