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

/// How far a tucked chair is pulled out from under its table to sit on, metres: the stand point
/// in front of its seat then keeps about 0.2 m from the table's edge.
pub const PULL: f32 = 0.5;
/// Frames a chair takes to be pulled out or pushed back.
pub(crate) const PULL_FRAMES: usize = 18;
/// Sideways distance from a pulled-out chair's stand point to where the character pulls it from,
/// metres (beside the chair, clear of it).
const BESIDE: f32 = 0.6;

impl Builder<'_> {
    /// "sit (on X)": sits on X's best seat unless already seated there; otherwise (already
    /// seated, or nothing to sit on) holds the seat or stands, a "sit" segment either way.
    pub fn sit(&mut self, step: &Step) {
        let (scene, obj) = (self.ctx.scene, step.object);
        let seat = obj.and_then(|o| {
            let seats = contacts_of(scene, self.ctx.cat, o, ContactKind::Seat);
            // The nearest seat, away from where earlier characters stand or sit.
            let crowd = |p: &[f32; 3]| {
                self.avoid
                    .iter()
                    .map(|a| (PASSING_DISTANCE + SPOT_MARGIN - dist2([p[0], p[2]], *a).sqrt()).max(0.0))
                    .sum::<f32>()
            };
            let cost = |p: &[f32; 3]| 10.0 * crowd(p) + dist2([p[0], p[2]], self.st.pos).sqrt();
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
                let poses = self.in_place(PULL_FRAMES);
                self.append(poses);
                self.slides.push(crate::animate::Slide {
                    object: o,
                    start: from,
                    end: self.frames.len(),
                    from: [0.0, 0.0],
                    to: offset,
                });
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
        let seated_from = self.frames.len();
        let poses = self.seated(self.st.pos, s, yaw, hold.max(1));
        self.append(poses);
        self.st.seated = Some((self.st.pos, s, o));
        self.st.pulled = pull.map(|(side, offset, _)| (o, side, offset));
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

    /// For a chair tucked under a table with leg room (its footprint reaching under the table
    /// it faces): the spot beside it to pull it from (free on the grid, the side nearer the
    /// character first), its offset once pulled out ([`PULL`] back from the table) and its seat
    /// point there. None for any other seat, or when neither side is free.
    fn pull_spot(
        &self,
        o: usize,
        s: [f32; 3],
        f: [f64; 2],
        stand_of: impl Fn([f32; 3]) -> [f32; 2],
    ) -> Option<([f32; 2], [f32; 2], [f32; 3])> {
        let objs = &self.ctx.scene.objects;
        let chair = &objs[o];
        let tucked = objs.iter().enumerate().any(|(j, t)| {
            j != o
                && crate::catalogue::builtin::tucks_under(&chair.category, &t.category)
                && crate::layout::interpenetrate(chair, t)
                && crate::layout::geom::facing_angle(chair, t) <= crate::layout::geom::FACING_TOLERANCE_DEG
        });
        if !tucked {
            return None;
        }
        let offset = [-PULL * f[0] as f32, -PULL * f[1] as f32];
        let pulled = [s[0] + offset[0], s[1], s[2] + offset[1]];
        let stand = stand_of(pulled);
        let right = [f[1] as f32, -f[0] as f32];
        let mut sides: Vec<[f32; 2]> = [1.0f32, -1.0]
            .iter()
            .map(|k| [stand[0] + k * BESIDE * right[0], stand[1] + k * BESIDE * right[1]])
            .collect();
        let here = self.st.pos;
        sides.sort_by(|a, b| dist2(*a, here).total_cmp(&dist2(*b, here)));
        let side = sides.into_iter().find(|&p| self.grid.is_free_at(p))?;
        Some((side, offset, pulled))
    }
}
