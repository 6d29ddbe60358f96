//! Picking a small prop up (beyond the paper): walked to unless its grip is within
//! [`PICK_REACH`] (a seated character stands up first and sits down again afterwards), the reach
//! clip's upper body over the idle or seated lower body, the right wrist brought onto the grip by
//! IK peaking at the clip's middle frame (knees bent and back leant for a prop low down); from
//! that frame the prop follows the hand ([`CarriedProp`]).

use glam::{DQuat, DVec3};
use inbetween_core::fk::forward;
use inbetween_core::Pose;

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

/// A wrist further than this (metres) from its target at the reach's peak did not reach it.
pub(crate) const REACH_SLACK: f64 = 0.03;

/// Horizontal distance (metres) from a target a character steps up to when its arm fell short.
const STEP_TO: f32 = 0.3;

impl<'a> Builder<'a> {
    /// Picks up prop `o` with the right hand: from where the character is when the grip is within
    /// [`PICK_REACH`], else (standing up first if seated) after walking to the prop, and back to
    /// the seat afterwards. The reach clip plays with the wrist brought onto the grip by IK (the
    /// root lowered, legs bent, for a prop low down); at the frame the hand is there the prop is
    /// taken ([`CarriedProp`]), and a "pick_up" segment measures the wrist on the grip.
    pub fn pick_up(&mut self, o: usize, speed: Option<f64>) {
        let ctx = self.ctx;
        let cat = ctx.cat;
        // Where the prop is now: its scene pose, or where this character put it down.
        let scene = self.scene_now(o);
        let Some(grip) = contacts_of(&scene, cat, o, ContactKind::Grip).into_iter().next() else { return };
        let gxz = [grip[0], grip[2]];
        let seat_before = self.st.seated;
        let target = DVec3::new(grip[0] as f64, grip[1] as f64, grip[2] as f64);
        if dist2(gxz, self.st.pos) > PICK_REACH * PICK_REACH {
            self.walk_to_use(&scene, o, gxz, speed);
        }
        let (mut m, mut grab) = self.reach_to(target);
        // Still out of the right arm's reach (a prop across a wide table, or on the floor past a
        // stand point the grid moved away): step up to it and reach again.
        if self.wrist_gap(&m, grab, target) > REACH_SLACK && self.step_closer(o, gxz, speed) {
            (m, grab) = self.reach_to(target);
        }
        // The prop's grip goes to the hand joint; its rotation relative to the hand stays as it
        // was at the grab.
        let rig = &ctx.rig;
        let hand = rig.arms[1][3];
        let gp = forward(&rig.skeleton, &m.pose(grab));
        let wq = gp.rotations[hand];
        let obj = &scene.objects[o];
        let q_obj = DQuat::from_rotation_y(obj.yaw as f64);
        let base_point = DVec3::new(obj.position[0] as f64, obj.position[1] as f64, obj.position[2] as f64);
        let rotation = (wq.inverse() * q_obj).normalize();
        let grip_from_base = q_obj.inverse() * (target - base_point);
        let offset = -(rotation * grip_from_base);
        let start = self.hand_action("pick_up", o, &m, grab, grip, None);
        self.props.push(CarriedProp { object: o, joint: hand, from: start + grab, offset, rotation, put_down: None });
        self.back_to_seat(seat_before, speed);
    }

    /// Appends a hand action `m` on prop `o` whose wrist is on `grip` at frame `peak`: a `verb`
    /// segment touching `o` (and `also`, and the seat when seated) with the wrist's grip contact
    /// around that frame. Returns the action's first frame.
    pub(crate) fn hand_action(
        &mut self,
        verb: &str,
        o: usize,
        m: &inbetween_core::clip::Clip,
        peak: usize,
        grip: [f32; 3],
        also: Option<usize>,
    ) -> usize {
        let start = self.frames.len();
        self.append(m.poses());
        let contact = JointContact {
            joint: ContactJoint::RightWrist,
            kind: ContactKind::Grip,
            point: grip,
            start: start + peak.saturating_sub(2),
            end: start + peak + 3,
        };
        let mut touching = vec![o];
        touching.extend(also);
        touching.extend(self.st.seated.map(|s| s.2));
        self.push_segment(verb, start, Some(o), touching, vec![contact]);
        start
    }

    /// Sits down again on the seat `seat_before` names when an action made the character leave it.
    pub(crate) fn back_to_seat(&mut self, seat_before: Option<([f32; 2], [f32; 3], usize)>, speed: Option<f64>) {
        if let (Some((_, s, so)), None) = (seat_before, self.st.seated) {
            self.sit_on(so, s, 10, speed);
        }
    }
    /// The right hand brought to `target` (world metres) and back: the reach clip's upper body
    /// over the idle or seated lower body (knees bent and back leant for a target low down), the
    /// wrist on the target by IK peaking at the clip's middle frame, facing it when standing.
    /// Returns the motion (not yet appended) and that frame.
    pub(crate) fn reach_to(&mut self, target: DVec3) -> (inbetween_core::clip::Clip, usize) {
        let rig = &self.ctx.rig;
        if self.st.seated.is_none() {
            self.st.heading = heading_to(self.st.pos, [target.x as f32, target.z as f32], self.st.heading);
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
        // The hand is on the target at frame `grab`: IK weight rises to 1 there and falls after.
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
            // For a target below the hands' reach (a microphone on the floor) bend the knees and
            // lean the back forward, about the character's left axis; for one beyond the arm's
            // length (across a table) lean until the shoulder is within reach.
            let low = ((0.75 - target.y) / 0.6).clamp(0.0, 1.0);
            self.lift(&mut poses, |k| -0.5 * low * bump(k));
            let left = DVec3::new(self.st.heading.cos(), 0.0, -self.st.heading.sin());
            let leaned = |p: &Pose, lean: f64| -> Pose {
                let mut p = p.clone();
                let gl = forward(&rig.skeleton, &p);
                let parent = rig.skeleton.parent(rig.lower_back).map_or(DQuat::IDENTITY, |j| gl.rotations[j]);
                let want = DQuat::from_axis_angle(left, lean) * gl.rotations[rig.lower_back];
                p.rotations[rig.lower_back] = crate::motion::rig::local_from_global(parent, want);
                p
            };
            let [_, shoulder, elbow, wrist] = rig.arms[1];
            let arm = rig.skeleton.joint(elbow).offset.length() + rig.skeleton.joint(wrist).offset.length();
            let far = (0..=18)
                .map(|i| i as f64 * 0.05)
                .find(|&lean| {
                    let s = forward(&rig.skeleton, &leaned(&poses[grab], lean)).positions[shoulder];
                    (s - target).length() <= 0.95 * arm
                })
                .unwrap_or(0.9);
            let lean_peak = (0.9 * low).max(far);
            for (k, p) in poses.iter_mut().enumerate() {
                let lean = lean_peak * bump(k);
                if lean > 1e-4 {
                    *p = leaned(p, lean);
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
        let m = reach_contacts(&m, &[Contact { limb: Limb::RightArm, target, window }]).expect(ON_RIG).0;
        (m, grab)
    }

    /// Stands up if seated and walks to where `o` is used in `scene` (its stand point), facing
    /// `at`, with a "walk" segment.
    pub(crate) fn walk_to_use(&mut self, scene: &crate::scene::Scene, o: usize, at: [f32; 2], speed: Option<f64>) {
        self.stand_up();
        let to = stand_point(scene, self.ctx.cat, self.grid, o, self.st.pos, self.avoid);
        if dist2(to, self.st.pos) <= 1e-4 {
            return;
        }
        let start = self.frames.len();
        let h = heading_to(to, at, self.st.heading);
        self.walk(to, h, "walk", speed);
        self.push_segment("walk", start, Some(o), vec![o], Vec::new());
    }

    /// Walks (standing up first) to the free spot nearest [`STEP_TO`] from `at` on the way from
    /// where the character is, when that is a step away or more; whether it moved.
    pub(crate) fn step_closer(&mut self, o: usize, at: [f32; 2], speed: Option<f64>) -> bool {
        let (dx, dz) = (self.st.pos[0] - at[0], self.st.pos[1] - at[1]);
        let len = (dx * dx + dz * dz).sqrt();
        if len <= STEP_TO {
            return false;
        }
        let want = [at[0] + dx / len * STEP_TO, at[1] + dz / len * STEP_TO];
        let to = if self.grid.is_free_at(want) {
            want
        } else {
            match self.grid.nearest_free(want) {
                Some(c) => self.grid.center(c),
                None => return false,
            }
        };
        if dist2(to, self.st.pos) <= 0.05 * 0.05 || dist2(to, at) >= dist2(self.st.pos, at) {
            return false;
        }
        self.stand_up();
        let start = self.frames.len();
        let h = heading_to(to, at, self.st.heading);
        self.walk(to, h, "walk", speed);
        self.push_segment("walk", start, Some(o), vec![o], Vec::new());
        true
    }

    /// How far (metres) the right wrist of motion `m` is from `target` at frame `at`.
    pub(crate) fn wrist_gap(&self, m: &inbetween_core::clip::Clip, at: usize, target: DVec3) -> f64 {
        let rig = &self.ctx.rig;
        (forward(&rig.skeleton, &m.pose(at)).positions[rig.arms[1][3]] - target).length()
    }

    /// The scene with prop `o` where this character last put it down (the scene itself when it
    /// never did).
    pub(crate) fn scene_now(&self, o: usize) -> std::borrow::Cow<'a, crate::scene::Scene> {
        let scene = self.ctx.scene;
        match self.props.iter().rev().find(|p| p.object == o).and_then(|p| p.put_down.as_ref()) {
            Some(d) => {
                let mut moved = scene.clone();
                let obj = &mut moved.objects[o];
                obj.position = [d.position.x as f32, d.position.y as f32, d.position.z as f32];
                obj.yaw = crate::motion::rig::heading_of(d.rotation) as f32;
                obj.support = d.support;
                std::borrow::Cow::Owned(moved)
            }
            None => std::borrow::Cow::Borrowed(scene),
        }
    }
}
