//! Putting a carried prop down (beyond the paper, whose scene is static): "puts the cup on the
//! counter" sets it on the counter's top, "puts the cup next to the sofa" on the floor beside the
//! sofa, "puts down the cup" on the nearest free surface within [`NEAR_SURFACE`] (else the floor in
//! front), "drops the cup" on the floor. The character walks there when the spot is out of reach
//! (standing up first if seated), the reach clip brings the right wrist onto the grip the prop will
//! have at rest, and from that frame the prop rests there ([`PutDown`]), upright, on its support.

use glam::{DQuat, DVec3};

use super::pick_up::REACH_SLACK;
use super::Step;
use crate::animate::builder::Builder;
use crate::animate::spots::{dist2, heading_to, stand_point};
use crate::animate::{contacts_of, PutDown};
use crate::catalogue::ContactKind;
use crate::layout::geom;
use crate::scene::{PlacedObject, Scene};

/// Verb lemmas that put a held prop down.
pub(crate) const PUT_VERBS: &[&str] = &["put", "place", "set", "drop", "lay", "leave", "release"];

/// Farthest surface (metres from the character) "puts down the cup" walks to.
const NEAR_SURFACE: f32 = 2.5;

/// Horizontal reach (metres from the root) within which the hand sets a prop down without walking.
const PLACE_REACH: f32 = 0.55;

/// Surfaces a standing character sets things on: tops between these heights (metres).
const SURFACE_HEIGHTS: (f32, f32) = (0.3, 1.4);

/// Gap (metres) kept between a prop set down and other things on the same top.
const CLEARANCE: f32 = 0.03;

/// Frames over which a prop goes from the hand's pose onto its rest.
const SETTLE: usize = 6;

/// Prepositions that set a prop on its destination's top.
fn onto(prep: &str) -> bool {
    matches!(prep, "on" | "onto" | "upon" | "atop" | "on top of" | "in" | "inside" | "into" | "within")
}

impl Builder<'_> {
    /// Puts down prop `o`, which this character holds (see the module doc); false when it holds
    /// no such prop.
    pub fn put_down(&mut self, o: usize, step: &Step) -> bool {
        let Some(k) = self.props.iter().rposition(|p| p.object == o && p.put_down.is_none()) else { return false };
        let ctx = self.ctx;
        let (scene, cat) = (ctx.scene, ctx.cat);
        let drop = step.verb == "drop" || step.action.verb == "drop";
        // Where: a destination's top, beside a destination, the nearest free surface, or the floor.
        let support = match &step.destination {
            Some((prep, d)) if onto(prep) && self.can_hold(*d, o) => Some(*d),
            Some(_) => None,
            None if drop => None,
            None => self.nearest_surface(o),
        };
        let beside = step.destination.as_ref().filter(|_| support.is_none()).map(|(_, d)| *d);
        // Walk up to it when out of reach.
        let seat_before = self.st.seated;
        let spot = |b: &Builder| b.spot(o, support, beside);
        let (mut at, mut on) = spot(self);
        if dist2([at[0], at[2]], self.st.pos) > PLACE_REACH * PLACE_REACH {
            self.stand_up();
            let to = match (support, beside) {
                (Some(s), _) | (None, Some(s)) => stand_point(scene, cat, self.grid, s, self.st.pos, self.avoid),
                (None, None) => self.st.pos,
            };
            if dist2(to, self.st.pos) > 0.01 {
                let start = self.frames.len();
                let h = heading_to(to, [at[0], at[2]], self.st.heading);
                self.walk(to, h, "walk", step.speed);
                self.push_segment("walk", start, support.or(beside), support.or(beside).into_iter().collect(), vec![]);
            }
            (at, on) = spot(self);
        }
        let support = on;
        // The prop at rest there, upright, with the yaw it had in the scene; its grip then.
        let obj = &scene.objects[o];
        let rotation = DQuat::from_rotation_y(obj.yaw as f64);
        let position = DVec3::new(at[0] as f64, at[1] as f64, at[2] as f64);
        let mut rested = scene.clone();
        rested.objects[o].position = at;
        rested.objects[o].support = support;
        let Some(grip) = contacts_of(&rested, cat, o, ContactKind::Grip).into_iter().next() else { return false };
        let target = DVec3::new(grip[0] as f64, grip[1] as f64, grip[2] as f64);
        let (mut m, mut release) = self.reach_to(target);
        // Out of the arm's reach (a spot low on the floor): step up to it and reach again.
        if self.wrist_gap(&m, release, target) > REACH_SLACK && self.step_closer(o, [grip[0], grip[2]], step.speed) {
            (m, release) = self.reach_to(target);
        }
        let start = self.hand_action("put_down", o, &m, release, grip, support);
        self.props[k].put_down =
            Some(PutDown { frame: start + release, position, rotation, support, blend: SETTLE.min(release) });
        self.back_to_seat(seat_before, step.speed);
        true
    }

    /// Whether `s` can take prop `o` on its top: a surface at a height a hand sets things on,
    /// other than the prop itself.
    fn can_hold(&self, s: usize, o: usize) -> bool {
        let (scene, cat) = (self.ctx.scene, self.ctx.cat);
        let sup = &scene.objects[s];
        s != o
            && cat.get(&sup.category).is_some_and(|c| c.surface)
            && (SURFACE_HEIGHTS.0..=SURFACE_HEIGHTS.1).contains(&sup.top())
            && sup.support != Some(o)
    }

    /// The surface nearest the character that can take prop `o` and has room for it, within
    /// [`NEAR_SURFACE`].
    fn nearest_surface(&self, o: usize) -> Option<usize> {
        let scene = self.ctx.scene;
        (0..scene.objects.len())
            .filter(|&s| self.can_hold(s, o))
            .filter(|&s| free_spot(scene, o, s, self.st.pos).is_some())
            .map(|s| (s, dist2(geom::center(&scene.objects[s]), self.st.pos)))
            .filter(|&(_, d)| d <= NEAR_SURFACE * NEAR_SURFACE)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(s, _)| s)
    }

    /// Where prop `o`'s base goes (world metres) and what it rests on: `support`'s top nearest
    /// the character, else (no room there) the floor beside it or beside `beside`, else the floor
    /// in front of the character.
    fn spot(&self, o: usize, support: Option<usize>, beside: Option<usize>) -> ([f32; 3], Option<usize>) {
        let scene = self.ctx.scene;
        if let Some((s, p)) = support.and_then(|s| free_spot(scene, o, s, self.st.pos).map(|p| (s, p))) {
            return (p, Some(s));
        }
        let half = scene.objects[o].half_extents_xz();
        let r = half[0].max(half[1]);
        let ahead_at = |d: f32, turn: f32| {
            let h = self.st.heading as f32 + turn;
            [self.st.pos[0] + h.sin() * d, self.st.pos[1] + h.cos() * d]
        };
        let ahead = |d: f32| ahead_at(d, 0.0);
        let floor = match beside.or(support) {
            Some(b) => {
                // The side of `b` facing the character, just off its footprint.
                let bo = &scene.objects[b];
                let c = geom::center(bo);
                let (dx, dz) = (self.st.pos[0] - c[0], self.st.pos[1] - c[1]);
                let len = (dx * dx + dz * dz).sqrt().max(1e-6);
                let he = bo.half_extents_xz();
                let out = (he[0] * (dx / len).abs() + he[1] * (dz / len).abs()) + r + CLEARANCE;
                [c[0] + dx / len * out, c[1] + dz / len * out]
            }
            None => ahead(0.45),
        };

        // That spot, else ahead of the character, turning further to the sides until clear.
        let p = std::iter::once(floor)
            .chain([0.0f32, -0.5, 0.5, -1.0, 1.0, -1.6, 1.6].map(|t| ahead_at(0.45, t)))
            .find(|&p| floor_clear(scene, o, p, r))
            .unwrap_or_else(|| ahead(0.45));
        ([p[0], 0.0, p[1]], None)
    }
}

/// Whether prop `o` (radius `r`, metres) can stand on the floor at `p`: inside the room and off
/// every other floor object's footprint.
fn floor_clear(scene: &Scene, o: usize, p: [f32; 2], r: f32) -> bool {
    let room = &scene.room;
    let inside = p[0] > r && p[1] > r && p[0] < room.width - r && p[1] < room.depth - r;
    inside
        && scene.objects.iter().enumerate().filter(|&(i, x)| i != o && x.support.is_none()).all(|(_, x)| {
            let l = geom::to_local(geom::center(x), x.yaw, p);
            l[0].abs() >= x.size[0] / 2.0 + r || l[1].abs() >= x.size[2] / 2.0 + r
        })
}

/// A spot (base point, world metres) on `s`'s top where prop `o` fits inside the footprint and
/// clear of what already rests there, nearest to `near`; None when there is none.
fn free_spot(scene: &Scene, o: usize, s: usize, near: [f32; 2]) -> Option<[f32; 3]> {
    let sup = &scene.objects[s];
    let prop = &scene.objects[o];
    let (hw, hd) = (sup.size[0] / 2.0, sup.size[2] / 2.0);
    // The prop's half extents in the support's frame (its yaw relative to the support's).
    let rel = prop.yaw - sup.yaw;
    let (rs, rc) = rel.sin_cos();
    let (pw, pd) = (prop.size[0] / 2.0, prop.size[2] / 2.0);
    let (ex, ez) = (pw * rc.abs() + pd * rs.abs(), pw * rs.abs() + pd * rc.abs());
    let (mx, mz) = (hw - ex - CLEARANCE, hd - ez - CLEARANCE);
    if mx < 0.0 || mz < 0.0 {
        return None;
    }
    let others: Vec<&PlacedObject> =
        scene.objects.iter().enumerate().filter(|&(i, x)| i != o && x.support == Some(s)).map(|(_, x)| x).collect();
    let steps = 8;
    let [ax, az] = prop.half_extents_xz();
    let mut best: Option<(f32, [f32; 2])> = None;
    for i in 0..=steps {
        for j in 0..=steps {
            let local = [-mx + 2.0 * mx * i as f32 / steps as f32, -mz + 2.0 * mz * j as f32 / steps as f32];
            let w = geom::to_world(geom::center(sup), sup.yaw, local);
            let clear = others.iter().all(|x| {
                let [bx, bz] = x.half_extents_xz();
                let c = geom::center(x);
                (w[0] - c[0]).abs() >= ax + bx + CLEARANCE || (w[1] - c[1]).abs() >= az + bz + CLEARANCE
            });
            let d = dist2(w, near);
            if clear && best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, w));
            }
        }
    }
    best.map(|(_, w)| [w[0], sup.top(), w[1]])
}
