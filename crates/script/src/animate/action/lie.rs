//! Lying down (issue 27: "lie down", "sleep"): on a bed or sofa the character walks to it, sits
//! on its edge and lies back along its length, head towards the bed's head end (a sofa's left
//! end); without anything to lie on it lies down on the floor where it stands, head forward. It
//! stays lying until it gets up: back to sitting first on a seat, straight up from the floor.

use glam::{DQuat, DVec3};
use inbetween_core::motion::interpolate_pose;
use inbetween_core::Pose;

use super::Step;
use crate::animate::builder::{smooth, Builder};
use crate::animate::contacts_of;
use crate::catalogue::ContactKind;
use crate::motion::rig::yaw;

/// Frames of the move between sitting (or standing) and lying.
const LIE_FRAMES: usize = 40;
/// Height of the hips joint above the surface a body lies on, metres.
const HIPS_ABOVE_SURFACE: f64 = 0.12;
/// The hips lie this far from the middle of the surface, towards the feet, metres.
const HIPS_FROM_MIDDLE: f64 = 0.15;

impl Builder<'_> {
    /// "lie (down) (on X)": a "lie" segment, lying on X when it has a seat, else on the floor.
    pub fn lie(&mut self, step: &Step) {
        if self.st.lying {
            let start = self.frames.len();
            let poses = self.in_place(self.min_action_frames());
            self.append(poses);
            self.push_segment(
                "lie",
                start,
                step.object,
                self.st.seated.map(|s| vec![s.2]).unwrap_or_default(),
                Vec::new(),
            );
            return;
        }
        let (scene, cat) = (self.ctx.scene, self.ctx.cat);
        let bed = step.object.and_then(|o| contacts_of(scene, cat, o, ContactKind::Seat).first().map(|s| (o, *s)));
        let lying = match bed {
            Some((o, s)) => {
                if self.st.seated.is_none_or(|(_, _, so)| so != o) {
                    self.stand_up();
                    self.sit_on(o, s, 10, step.speed);
                }
                let b = &scene.objects[o];
                let bed_yaw = b.yaw as f64;
                // Head towards the far end of the longer side: a bed's head (−z), a sofa's left (−x).
                let head = if b.size[2] >= b.size[0] {
                    DVec3::new(-bed_yaw.sin(), 0.0, -bed_yaw.cos())
                } else {
                    DVec3::new(-bed_yaw.cos(), 0.0, bed_yaw.sin())
                };
                let mid = DVec3::new(b.position[0] as f64, b.top() as f64, b.position[2] as f64);
                self.lying_pose(mid - head * HIPS_FROM_MIDDLE, head)
            }
            None => {
                self.stand_up();
                let h = self.st.heading;
                let at = DVec3::new(self.st.pos[0] as f64, 0.0, self.st.pos[1] as f64);
                self.lying_pose(at, DVec3::new(h.sin(), 0.0, h.cos()))
            }
        };
        let start = self.frames.len();
        let from = self.frames.last().cloned().unwrap_or_else(|| self.ctx.rig.standing());
        let poses: Vec<Pose> =
            (1..=LIE_FRAMES).map(|k| interpolate_pose(&from, &lying, smooth(k as f64 / LIE_FRAMES as f64))).collect();
        self.append(poses);
        self.st.lying = true;
        let hold = vec![lying; self.min_action_frames()];
        self.append(hold);
        let touching = self.st.seated.map(|s| vec![s.2]).unwrap_or_default();
        self.push_segment("lie", start, step.object, touching, Vec::new());
    }

    /// Gets up from lying: back onto the seat's edge (then [`Builder::stand_up`] as from sitting),
    /// or from the floor straight to standing where the character lies.
    pub fn get_up_from_lying(&mut self) {
        if !self.st.lying {
            return;
        }
        self.st.lying = false;
        let from = self.frames.last().cloned().unwrap_or_else(|| self.ctx.rig.standing());
        let to = self.in_place(1).remove(0);
        let start = self.frames.len();
        let poses: Vec<Pose> =
            (1..=LIE_FRAMES).map(|k| interpolate_pose(&from, &to, smooth(k as f64 / LIE_FRAMES as f64))).collect();
        self.append(poses);
        let touching = self.st.seated.map(|s| vec![s.2]).unwrap_or_default();
        self.push_segment("get_up", start, None, touching, Vec::new());
    }

    /// The idle pose laid on its back, hips at `surface` (raised by [`HIPS_ABOVE_SURFACE`]), head
    /// towards `head` (a horizontal unit direction).
    fn lying_pose(&mut self, surface: DVec3, head: DVec3) -> Pose {
        let idle = self.idle_clip();
        let rig = &self.ctx.rig;
        let mut p = if idle.num_frames() > 0 { idle.pose(0) } else { rig.standing() };
        // Standing faces +z with the head up; turned a quarter back about x the head points to −z
        // and the face up, then turned about y so the head points along `head`.
        let turn = yaw((-head.x).atan2(-head.z)) * DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2);
        p.rotations[rig.hips] = (turn * p.rotations[rig.hips]).normalize();
        p.translations[rig.hips] = surface + DVec3::Y * HIPS_ABOVE_SURFACE;
        p
    }
}
