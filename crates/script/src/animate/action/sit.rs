//! Sitting (§4.2 "hips to the seat"): the target's seat contact nearest the character and clear
//! of where earlier characters stand or sit, walked up to, then the sit-down clip placed so the
//! pelvis lands on the seat (the root lifted by the seat's height over the clip's, legs
//! re-solved), then the seated loop. The "sit" segment carries the hips contact of Eq. 2.

use super::Step;
use crate::animate::builder::placed;
use crate::animate::builder::{smooth, Builder};
use crate::animate::spots::{dist2, heading_to, SPOT_MARGIN};
use crate::animate::{contacts_of, ContactJoint, JointContact, PASSING_DISTANCE};
use crate::catalogue::ContactKind;
use crate::motion::ik::PELVIS_ABOVE_SEAT;
use crate::motion::procedural::{seat_point, SEAT_HEIGHT};

/// How far the stand point in front of a seat tucked at a table keeps from the table's edge once
/// the seat is pulled out, metres. (A seat merely near a table is sat on where it stands: pulled
/// out, a character seated at a desk would not reach it to type, as seated characters do not
/// scoot in; tried on the demo, its contact cost after the annealing rose 0.05 → 0.055–0.18 m.)
pub const CLEAR: f32 = 0.22;
/// Least pull worth the walk round.
const MIN_PULL: f32 = 0.05;
/// Where a character seated on a pulled-out chair scoots it back to: its seat's centre this far
/// from the table's front edge, metres (knees under the top).
const SEATED_FROM_TABLE: f32 = 0.30;
/// Frames a seated character takes to scoot a chair in or out.
const SCOOT_FRAMES: usize = 20;
/// Frames over which each foot (left, right) steps along during a scoot.
const FOOT_STEPS: [(f64, f64); 2] = [(3.0, 9.0), (9.0, 15.0)];
/// Height a foot is lifted to when it steps along during a scoot, metres.
const STEP_LIFT: f64 = 0.06;
/// How far the wrist of the hand holding a sliding seat is above the grip, metres.
pub const GRIP_ABOVE: f64 = 0.04;
/// Frames a chair takes to be pulled out or pushed back.
const PULL_FRAMES: usize = 18;
/// Sideways distance from a pulled-out chair's stand point to where the character pulls it from,
/// metres (beside the chair, clear of it).
const BESIDE: f32 = 0.6;

impl Builder<'_> {
    /// "sit (on X)": sits on X's best seat unless already seated there; otherwise (already
    /// seated, or nothing to sit on) holds the seat or stands, a "sit" segment either way.
    pub fn sit(&mut self, step: &Step) {
        let scene = self.ctx.scene;
        let standing = self.st.seated.is_none() && !self.st.lying;
        // "sits down" (no seat named): the nearest free seat; a seat someone already sits on:
        // another free one of the same kind ("Ben sits on the other chair").
        let obj = match step.object {
            Some(o) if standing && self.seats_taken(o) => {
                let category = &scene.objects[o].category;
                self.free_seat_near(self.st.pos, |k| &scene.objects[k].category == category).or(Some(o))
            }
            None if standing => self.free_seat_near(self.sit_toward.unwrap_or(self.st.pos), |_| true),
            other => other,
        };
        let seat = obj.and_then(|o| {
            let seats = contacts_of(scene, self.ctx.cat, o, ContactKind::Seat);
            // The nearest seat, away from where earlier characters stand or sit.
            let crowd = |p: &[f32; 3]| {
                self.avoid
                    .iter()
                    .map(|a| (PASSING_DISTANCE + SPOT_MARGIN - dist2([p[0], p[2]], *a).sqrt()).max(0.0))
                    .sum::<f32>()
            };
            let near = self.sit_toward.unwrap_or(self.st.pos);
            let cost = |p: &[f32; 3]| 10.0 * crowd(p) + dist2([p[0], p[2]], near).sqrt();
            seats.into_iter().min_by(|p, q| cost(p).total_cmp(&cost(q))).map(|s| (o, s))
        });
        match (seat, self.st.seated) {
            (Some((o, s)), seated) if seated.is_none_or(|(_, _, so)| so != o) => {
                self.stand_up();
                let hold = self.min_action_frames();
                self.sit_on(o, s, hold, step.speed);
            }
            _ => {
                if let (None, Some(o)) = (seat, obj) {
                    self.notes.push(format!("{}: nothing to sit on in {}", self.name, scene.objects[o].label));
                }
                // Already seated (or no seat): hold.
                let start = self.frames.len();
                let n = self.min_action_frames();
                let poses = self.in_place(n);
                self.append(poses);
                let touching = self.st.seated.map(|s| vec![s.2]).unwrap_or_default();
                self.push_segment("sit", start, obj, touching, Vec::new());
            }
        }
    }

    /// Walks to the point in front of seat `s` of object `o`, sits down (pelvis onto the seat) and
    /// stays seated `hold` frames: a "walk" and a "sit" segment, the latter with the hips contact.
    pub fn sit_on(&mut self, o: usize, s: [f32; 3], hold: usize, speed: Option<f64>) {
        let yaw = self.ctx.scene.objects[o].yaw as f64;
        let sp = seat_point();
        let f = [yaw.sin(), yaw.cos()];
        // The sit-down clip's seat lies `-sp.z` behind where it starts.
        let stand_of = |s: [f32; 3]| [s[0] + (-sp.z * f[0]) as f32, s[2] + (-sp.z * f[1]) as f32];
        let start = self.frames.len();
        // A chair tucked under a table is pulled out first: from beside it, then a step in front.
        let pull = self.pull_spot(o, s, f, stand_of);
        let s = match pull {
            Some((side, offset, pulled)) => {
                // Arrive turned to where the chair will stand (the chair before it, a little
                // towards the table), so the step in is a walk forwards.
                let stand = stand_of(pulled);
                self.walk(side, heading_to(side, stand, yaw), "walk", speed);
                self.push_segment("walk", start, Some(o), vec![o], Vec::new());
                let from = self.frames.len();
                self.slide_seat(o, [0.0, 0.0], offset);
                self.step_to(stand_of(pulled), yaw, speed);
                self.push_segment("pull out", from, Some(o), vec![o], Vec::new());
                pulled
            }
            None => {
                self.walk(stand_of(s), yaw, "walk", speed);
                self.push_segment("walk", start, Some(o), vec![o], Vec::new());
                s
            }
        };
        let start = self.frames.len();
        let clip = self.named("procedural sit down");
        let mut poses = placed(&clip, self.st.pos, yaw);
        let n = poses.len().max(2);
        let dy = s[1] as f64 - SEAT_HEIGHT;
        self.lift(&mut poses, |k| dy * smooth(k as f64 / (n - 1) as f64));
        self.append(poses);
        self.st.seated = Some((self.st.pos, s, o));
        // Seated on a pulled-out chair: scoot it back in towards the table.
        self.st.pulled = pull.map(|(side, offset, _)| {
            let scoot = CLEAR + (-seat_point().z) as f32 - SEATED_FROM_TABLE;
            let inside = [offset[0] + scoot * f[0] as f32, offset[1] + scoot * f[1] as f32];
            self.scoot(o, offset, inside);
            crate::animate::builder::Pulled { chair: o, side, out: offset, inside }
        });
        let (at, s) = self.st.seated.map(|(at, s, _)| (at, s)).expect("seated above");
        let seated_from = self.frames.len();
        let poses = self.seated(at, s, yaw, hold.max(1));
        self.append(poses);
        self.seats.push([s[0], s[2]]);
        let hips = JointContact {
            joint: ContactJoint::Hips,
            kind: ContactKind::Seat,
            point: [s[0], s[1] + PELVIS_ABOVE_SEAT as f32, s[2]],
            start: seated_from,
            end: self.frames.len(),
        };
        self.push_segment("sit", start, Some(o), vec![o], vec![hips]);
    }

    /// Stands still over [`PULL_FRAMES`] while seat `o` slides from offset `from` to `to` (x, z
    /// metres from its place).
    pub(crate) fn slide_seat(&mut self, o: usize, from: [f32; 2], to: [f32; 2]) {
        let start = self.frames.len();
        let slide = crate::animate::Slide { object: o, start, end: start + PULL_FRAMES, from, to };
        let mut poses = self.in_place(PULL_FRAMES);
        self.hold_seat(&slide, &mut poses);
        self.append(poses);
        debug_assert_eq!(self.frames.len(), slide.end);
        self.slides.push(slide);
    }

    /// Seated on chair `o`, slides it from offset `from` to `to` (x, z metres from its place) with
    /// the character on it over [`SCOOT_FRAMES`] (the seated loop carried along, the feet planted
    /// and stepping along one after the other, [`FOOT_STEPS`]); the seat and stand point move with
    /// it.
    pub(crate) fn scoot(&mut self, o: usize, from: [f32; 2], to: [f32; 2]) {
        let Some((at, seat, so)) = self.st.seated else { return };
        let start = self.frames.len();
        let slide = crate::animate::Slide { object: o, start, end: start + SCOOT_FRAMES, from, to };
        let yaw = self.ctx.scene.objects[o].yaw as f64;
        let mut poses = self.seated(at, seat, yaw, SCOOT_FRAMES);
        let rig = &self.ctx.rig;
        let d = glam::DVec3::new((to[0] - from[0]) as f64, 0.0, (to[1] - from[1]) as f64);
        for (k, p) in poses.iter_mut().enumerate() {
            // The feet stay planted, then step along one after the other, lifted on an arc.
            let g = inbetween_core::fk::forward(&rig.skeleton, p);
            let feet = [0, 1].map(|i| g.positions[rig.legs[i][2]]);
            let [x, z] = slide.offset_at(start + k);
            p.translations[rig.hips].x += (x - from[0]) as f64;
            p.translations[rig.hips].z += (z - from[1]) as f64;
            for (i, (limb, foot)) in
                [crate::motion::Limb::LeftLeg, crate::motion::Limb::RightLeg].into_iter().zip(feet).enumerate()
            {
                let (a, b) = FOOT_STEPS[i];
                let t = ((k as f64 - a) / (b - a)).clamp(0.0, 1.0);
                let arc = glam::DVec3::Y * STEP_LIFT * (std::f64::consts::PI * t).sin();
                crate::motion::solve_limb(rig, p, limb, foot + d * smooth(t) + arc, None);
            }
        }
        self.append(poses);
        self.slides.push(slide);
        let d = [d.x as f32, d.z as f32];
        let at = [at[0] + d[0], at[1] + d[1]];
        self.st.seated = Some((at, [seat[0] + d[0], seat[1], seat[2] + d[1]], so));
        self.st.pos = at;
    }

    /// The hand nearer the sliding seat holds it while it moves: the top of a chair's backrest, or
    /// the rim of a stool's seat, at the point nearest that shoulder halfway through; two-bone
    /// IK each frame (§4.2 contacts), the wrist [`GRIP_ABOVE`] over the grip, in over the first
    /// frames and out over the last (the seat barely moves then: the slide eases in and out).
    fn hold_seat(&self, slide: &crate::animate::Slide, poses: &mut [inbetween_core::Pose]) {
        use crate::motion::{solve_limb, Limb};
        use glam::DVec3;
        use inbetween_core::fk::forward;
        let (rig, obj) = (&self.ctx.rig, &self.ctx.scene.objects[slide.object]);
        let n = poses.len();
        if n < 2 {
            return;
        }
        let yaw = obj.yaw as f64;
        // The seat's facing and its left-right axis; the grip in that frame (metres from its centre).
        let (fw, side) = (DVec3::new(yaw.sin(), 0.0, yaw.cos()), DVec3::new(yaw.cos(), 0.0, -yaw.sin()));
        let (hw, hd) = (obj.size[0] as f64 / 2.0 - 0.04, obj.size[2] as f64 / 2.0 - 0.03);
        let stool = obj.category.contains("stool");
        // The middle of the seat's top (a chair's: of its whole box, backrest included) at a frame.
        let top = |frame: usize| {
            let [dx, dz] = slide.offset_at(frame);
            DVec3::new(
                (obj.position[0] + dx) as f64,
                obj.position[1] as f64 + obj.size[1] as f64,
                (obj.position[2] + dz) as f64,
            )
        };
        // Nearest the shoulder halfway through the slide, so the hand reaches it at both ends.
        let mid = slide.start + n / 2;
        let grip_of = |shoulder: DVec3| {
            let d = shoulder - top(mid);
            let x = d.dot(side).clamp(-hw.max(0.0), hw.max(0.0));
            let z = if stool { d.dot(fw).clamp(-hd.max(0.0), hd.max(0.0)) } else { -hd.max(0.0) };
            (x, z)
        };
        let g0 = forward(&rig.skeleton, &poses[0]);
        let (limb, (gx, gz)) = [(Limb::LeftArm, rig.arms[0][1]), (Limb::RightArm, rig.arms[1][1])]
            .into_iter()
            .map(|(limb, shoulder)| (limb, grip_of(g0.positions[shoulder]), g0.positions[shoulder]))
            .min_by(|a, b| {
                let at = |(x, z): (f64, f64), s: DVec3| (top(mid) + side * x + fw * z - s).length();
                at(a.1, a.2).total_cmp(&at(b.1, b.2))
            })
            .map(|(limb, grip, _)| (limb, grip))
            .expect("two arms");
        let [_, upper, elbow, wrist] = rig.arms[if limb == Limb::LeftArm { 0 } else { 1 }];
        let arm = rig.skeleton.joint(elbow).offset.length() + rig.skeleton.joint(wrist).offset.length();
        let weight = |k: usize| smooth((k as f64 / 7.0).min((n - 1 - k) as f64 / 4.0).min(1.0));
        let target = |k: usize| top(slide.start + k) + side * gx + fw * gz + DVec3::Y * GRIP_ABOVE;
        // For a grip low down (a stool's seat) the knees bend: the hips drop up to 0.4 m for a grip
        // 0.5 m or more below a backrest's usual height.
        let low = ((0.95 - target(0).y) / 0.5).clamp(0.0, 1.0);
        if low > 0.0 {
            self.lift(poses, |k| -0.4 * low * weight(k));
        }
        // The back leans towards the grip (about the lower back) when the shoulder is out of reach.
        let leaned = |p: &inbetween_core::Pose, t: DVec3, lean: f64| {
            let mut p = p.clone();
            let g = forward(&rig.skeleton, &p);
            let to = t - g.positions[rig.lower_back];
            let dir = DVec3::new(to.x, 0.0, to.z).normalize_or_zero();
            let parent = rig.skeleton.parent(rig.lower_back).map_or(glam::DQuat::IDENTITY, |j| g.rotations[j]);
            let want = glam::DQuat::from_axis_angle(DVec3::Y.cross(dir).normalize_or(DVec3::X), lean)
                * g.rotations[rig.lower_back];
            p.rotations[rig.lower_back] = crate::motion::rig::local_from_global(parent, want);
            p
        };
        let lean = (0..n)
            .filter(|&k| weight(k) >= 1.0)
            .map(|k| {
                (0..=10)
                    .map(|i| i as f64 * 0.05)
                    .find(|&l| {
                        let s = forward(&rig.skeleton, &leaned(&poses[k], target(k), l)).positions[upper];
                        (s - target(k)).length() <= 0.97 * arm
                    })
                    .unwrap_or(0.5)
            })
            .fold(0.0, f64::max);
        for (k, p) in poses.iter_mut().enumerate() {
            let w = weight(k);
            if w <= 0.0 {
                continue;
            }
            if lean > 0.0 {
                *p = leaned(p, target(k), lean * w);
            }
            let now = forward(&rig.skeleton, p).positions[wrist];
            solve_limb(rig, p, limb, now.lerp(target(k), w), None);
        }
    }

    /// For a chair tucked under a table with leg room (centred in front of it, facing it, its
    /// front edge under the top): the spot
    /// beside it to pull it from (free on the grid, the side nearer the character first, else the
    /// free cell nearest it within 0.5 m), its offset once pulled out (back from the table until
    /// the stand point keeps [`CLEAR`]) and its seat point there. None for any other seat, or when
    /// nothing beside it is free.
    fn pull_spot(
        &self,
        o: usize,
        s: [f32; 3],
        f: [f64; 2],
        stand_of: impl Fn([f32; 3]) -> [f32; 2],
    ) -> Option<([f32; 2], [f32; 2], [f32; 3])> {
        let objs = &self.ctx.scene.objects;
        let chair = &objs[o];
        // How far the seat's centre stands from the front of a table with leg room it faces and
        // stands in front of (negative reach: under it).
        let from_table = objs
            .iter()
            .enumerate()
            .filter(|&(j, t)| {
                j != o
                    && crate::catalogue::builtin::tucks_under(&chair.category, &t.category)
                    && crate::layout::geom::facing_angle(chair, t) <= crate::layout::geom::FACING_TOLERANCE_DEG
            })
            .filter_map(|(_, t)| {
                // Tucked: centred in front of it, its front edge in under the top.
                let (c, h) = crate::layout::geom::local_box(chair, t);
                let (aw, ad) = (t.size[0] / 2.0, t.size[2] / 2.0);
                (c[1] > 0.0 && c[0].abs() <= aw && c[1] - h[1] < ad).then_some(c[1] - ad)
            })
            .fold(f32::INFINITY, f32::min);
        // Out far enough that the stand point in front of the seat keeps CLEAR from the table.
        let pull = CLEAR + (-seat_point().z) as f32 - from_table;
        if pull.is_nan() || pull < MIN_PULL {
            return None;
        }
        let offset = [-pull * f[0] as f32, -pull * f[1] as f32];
        let pulled = [s[0] + offset[0], s[1], s[2] + offset[1]];
        let stand = stand_of(pulled);
        let (fw, right) = ([f[0] as f32, f[1] as f32], [f[1] as f32, -f[0] as f32]);
        // Beside the pulled-out chair, a little back from the stand point (the table's edge is
        // within a walker's radius of the stand point itself), either side, nearer first.
        let at = |back: f32, side: f32| {
            [stand[0] - back * fw[0] + side * BESIDE * right[0], stand[1] - back * fw[1] + side * BESIDE * right[1]]
        };
        let mut spots: Vec<[f32; 2]> = [0.25f32, 0.4].iter().flat_map(|&b| [1.0f32, -1.0].map(|k| at(b, k))).collect();
        let here = self.st.pos;
        spots.sort_by(|a, b| dist2(*a, here).total_cmp(&dist2(*b, here)));
        let side = match spots.iter().copied().find(|&p| self.grid.is_free_at(p)) {
            Some(p) => p,
            // Else the free cell nearest the nearer spot, if it is close to it.
            None => {
                let c = self.grid.nearest_free(spots[0]).map(|c| self.grid.center(c))?;
                if dist2(c, spots[0]) > 0.5 * 0.5 {
                    return None;
                }
                c
            }
        };
        Some((side, offset, pulled))
    }
}
