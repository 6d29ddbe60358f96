//! Picking a small prop up (beyond the paper): walked to unless its grip is within
//! [`PICK_REACH`] (a seated character stands up first and sits down again afterwards), the reach
//! clip's upper body over the idle or seated lower body, the right wrist brought onto the grip by
//! IK peaking at the clip's middle frame (knees bent and back leant for a prop low down); from
//! that frame the prop follows the hand ([`CarriedProp`]).

use glam::{DQuat, DVec3};
use inbetween_core::fk::forward;

use crate::animate::builder::ON_RIG;
use crate::animate::builder::{smooth, Builder};
use crate::animate::spots::{dist2, heading_to, stand_point};
use crate::animate::{contacts_of, CarriedProp, ContactJoint, JointContact};
use crate::catalogue::ContactKind;
use crate::motion::blend::{blend_upper, reach_contacts};
use crate::motion::ik::Limb;
use crate::motion::{BlendParams, Contact};

/// Horizontal distance (metres) from the root within which a hand picks a prop up without walking.
const PICK_REACH: f32 = 0.55;

impl Builder<'_> {
    /// Picks up prop `o` with the right hand: from where the character is when the grip is within
    /// [`PICK_REACH`], else (standing up first if seated) after walking to the prop, and back to
    /// the seat afterwards. The reach clip plays with the wrist brought onto the grip by IK (the
    /// root lowered, legs bent, for a prop low down); at the frame the hand is there the prop is
    /// taken ([`CarriedProp`]), and a "pick_up" segment measures the wrist on the grip.
    pub fn pick_up(&mut self, o: usize, speed: Option<f64>) {
        let ctx = self.ctx;
        let (scene, cat, rig) = (ctx.scene, ctx.cat, &ctx.rig);
        let Some(grip) = contacts_of(scene, cat, o, ContactKind::Grip).into_iter().next() else { return };
        let gxz = [grip[0], grip[2]];
        let seat_before = self.st.seated;
        if dist2(gxz, self.st.pos) > PICK_REACH * PICK_REACH {
            self.stand_up();
            let to = stand_point(scene, cat, self.grid, o, self.st.pos, self.avoid);
            let start = self.frames.len();
            let h = heading_to(to, gxz, self.st.heading);
            self.walk(to, h, "walk", speed);
            self.push_segment("walk", start, Some(o), vec![o], Vec::new());
        }
        if self.st.seated.is_none() {
            self.st.heading = heading_to(self.st.pos, gxz, self.st.heading);
        }
        let clip = self.retrieved_or("reach", "procedural reach");
        let n = clip.num_frames().max(30);
        let base = self.in_place(n);
        let base = crate::motion::rig::clip(rig, &base);
        let m = blend_upper(
            &base,
            &clip,
            &BlendParams { start: 0, end: None, blend_in: 8, blend_out: 0, looping: false, action_offset: 0 },
        )
        .expect(ON_RIG);
        // The hand closes at frame `grab`: IK weight rises to 1 there and falls after.
        let grab = n / 2;
        let bump = |k: usize| {
            if k <= grab {
                smooth(k as f64 / grab as f64)
            } else {
                smooth((n - 1 - k) as f64 / (n - 1 - grab) as f64)
            }
        };
        let mut poses = m.poses();
        if self.st.seated.is_none() {
            // For a prop below the hands' reach (a microphone on the floor) bend the knees and
            // lean the back forward, about the character's left axis.
            let low = ((0.75 - grip[1] as f64) / 0.6).clamp(0.0, 1.0);
            self.lift(&mut poses, |k| -0.5 * low * bump(k));
            let left = DVec3::new(self.st.heading.cos(), 0.0, -self.st.heading.sin());
            for (k, p) in poses.iter_mut().enumerate() {
                let lean = 0.9 * low * bump(k);
                if lean > 1e-4 {
                    let gl = forward(&rig.skeleton, p);
                    let parent = rig.skeleton.parent(rig.lower_back).map_or(DQuat::IDENTITY, |j| gl.rotations[j]);
                    let want = DQuat::from_axis_angle(left, lean) * gl.rotations[rig.lower_back];
                    p.rotations[rig.lower_back] = crate::motion::rig::local_from_global(parent, want);
                }
            }
        }
        let m = crate::motion::rig::clip(rig, &poses);
        let window = BlendParams {
            start: 0,
            end: Some(n),
            blend_in: grab,
            blend_out: n - grab,
            looping: false,
            action_offset: 0,
        };
        let target = DVec3::new(grip[0] as f64, grip[1] as f64, grip[2] as f64);
        let m = reach_contacts(&m, &[Contact { limb: Limb::RightArm, target, window }]).expect(ON_RIG).0;
        // The prop's grip goes to the hand joint; its rotation relative to the hand stays as it
        // was at the grab.
        let hand = rig.arms[1][3];
        let gp = forward(&rig.skeleton, &m.pose(grab));
        let wq = gp.rotations[hand];
        let obj = &scene.objects[o];
        let q_obj = DQuat::from_rotation_y(obj.yaw as f64);
        let base_point = DVec3::new(obj.position[0] as f64, obj.position[1] as f64, obj.position[2] as f64);
        let rotation = (wq.inverse() * q_obj).normalize();
        let grip_from_base = q_obj.inverse() * (target - base_point);
        let offset = -(rotation * grip_from_base);
        let start = self.frames.len();
        self.append(m.poses());
        self.props.push(CarriedProp { object: o, joint: hand, from: start + grab, offset, rotation });
        let contact = JointContact {
            joint: ContactJoint::RightWrist,
            kind: ContactKind::Grip,
            point: grip,
            start: start + grab.saturating_sub(2),
            end: start + grab + 3,
        };
        let mut touching = vec![o];
        touching.extend(self.st.seated.map(|s| s.2));
        self.push_segment("pick_up", start, Some(o), touching, vec![contact]);
        // Back to the seat it left.
        if let (Some((_, s, so)), None) = (seat_before, self.st.seated) {
            self.sit_on(so, s, 10, speed);
        }
    }
}
