//! Sitting (§4.2 "hips to the seat"): the target's seat contact nearest the character and clear
//! of where earlier characters stand or sit, walked up to, then the sit-down clip placed so the
//! pelvis lands on the seat (the root lifted by the seat's height over the clip's, legs
//! re-solved), then the seated loop. The "sit" segment carries the hips contact of Eq. 2.

use super::Step;
use crate::animate::builder::placed;
use crate::animate::builder::{smooth, Builder};
use crate::animate::spots::{dist2, SPOT_MARGIN};
use crate::animate::{contacts_of, ContactJoint, JointContact, PASSING_DISTANCE};
use crate::catalogue::ContactKind;
use crate::motion::ik::PELVIS_ABOVE_SEAT;
use crate::motion::procedural::{seat_point, SEAT_HEIGHT};

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
        let at = [s[0] + (-sp.z * f[0]) as f32, s[2] + (-sp.z * f[1]) as f32];
        let start = self.frames.len();
        self.walk(at, yaw, "walk", speed);
        self.push_segment("walk", start, Some(o), vec![o], Vec::new());
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
}
