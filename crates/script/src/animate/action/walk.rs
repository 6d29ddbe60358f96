//! Walking (§4.3 route + locomotion, NSM's role in the paper): an A* route on the character's
//! grid to where it is going, walked with foot locking ([`crate::motion::walk_route`]) after
//! waiting as the crowd repair says ([`crate::animate::routes::WalkChoice`]); walks already made come
//! from the [`crate::animate::routes::WalkCache`].

use super::Step;
use crate::animate::builder::Builder;
use crate::animate::routes::{route, WalkInfo};
use crate::animate::spots::{heading_to, stand_point};
use crate::layout::geom;
use crate::motion::WalkParams;

impl Builder<'_> {
    /// A locomotion verb ("walks to the desk", "runs"): stands up if seated, then walks to the
    /// target's stand point, ending turned towards it, or two metres ahead without a target.
    pub fn walk_to(&mut self, step: &Step) {
        self.stand_up();
        let (scene, grid) = (self.ctx.scene, self.grid);
        let start = self.frames.len();
        let (to, h) = match step.object {
            Some(o) => {
                let to = stand_point(scene, self.ctx.cat, grid, o, self.st.pos, self.avoid);
                (to, heading_to(to, geom::center(&scene.objects[o]), self.st.heading))
            }
            // "walks out": to the door, facing out.
            None if step.action.manner.iter().any(|m| m == "out")
                || matches!(step.action.verb.as_str(), "leave" | "exit") =>
            {
                let door = crate::layout::door(&scene.room);
                let to = grid.nearest_free([door[0], door[1] - 0.3]).map(|c| grid.center(c)).unwrap_or(self.st.pos);
                (to, 0.0)
            }
            None => {
                let f = [self.st.heading.sin() as f32, self.st.heading.cos() as f32];
                let p = [self.st.pos[0] + 2.0 * f[0], self.st.pos[1] + 2.0 * f[1]];
                let to = grid.nearest_free(p).map(|c| grid.center(c)).unwrap_or(self.st.pos);
                (to, self.st.heading)
            }
        };
        self.walk(to, h, &step.verb, step.speed);
        self.push_segment(&step.verb, start, step.object, step.object.into_iter().collect(), Vec::new());
    }

    /// Walks along a route to `to`, turning to `final_heading`, after waiting in place as this
    /// walk's [`crate::animate::routes::WalkChoice`] says.
    pub fn walk(&mut self, to: [f32; 2], final_heading: f64, verb: &str, speed: Option<f64>) {
        self.walk_on(to, final_heading, verb, speed, false);
    }

    /// [`Builder::walk`] in a straight line (a step beside furniture the grid does not know
    /// has moved), unless this walk's choice gives a route.
    pub fn step_to(&mut self, to: [f32; 2], final_heading: f64, speed: Option<f64>) {
        self.walk_on(to, final_heading, "walk", speed, true);
    }

    fn walk_on(&mut self, to: [f32; 2], final_heading: f64, verb: &str, speed: Option<f64>, straight: bool) {
        let choice = self.choices.get(self.walks.len()).cloned().unwrap_or_default();
        let route = match choice.route {
            Some(r) => r,
            None if straight => vec![self.st.pos, to],
            None => route(self.grid, self.st.pos, to).unwrap_or_else(|| {
                self.notes.push(format!(
                    "{}: no route from ({:.2}, {:.2}) to ({:.2}, {:.2}); walking straight",
                    self.name, self.st.pos[0], self.st.pos[1], to[0], to[1]
                ));
                vec![self.st.pos, to]
            }),
        };
        let lib = self.ctx.lib;
        let params = WalkParams {
            verb: if lib.cycle(verb).is_some() { verb.to_string() } else { "walk".into() },
            speed,
            initial_heading: Some(self.st.heading),
            final_heading: Some(final_heading),
            lock_feet: self.ctx.cfg.lock_feet,
            ..WalkParams::default()
        };
        let m = self.cache.walk(&route, lib, &params);
        let wait_start = self.frames.len();
        if choice.wait > 0 {
            let idle = self.idle_clip();
            let wait = self.looped(&idle, self.st.pos, self.st.heading, choice.wait);
            self.append(wait);
        }
        let poses = m.poses();
        if let Some(last) = poses.last() {
            let r = last.translations[self.ctx.rig.hips];
            self.st.pos = [r.x as f32, r.z as f32];
        }
        let walk_start = self.frames.len();
        self.append(poses);
        self.walks.push(WalkInfo { wait_start, walk_start, end: self.frames.len(), route, params });
        self.st.heading = final_heading;
    }
}
