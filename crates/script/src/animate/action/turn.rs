//! Turning on the spot ("turns left"): the walk generator with a one-point route, from the
//! current heading to the new one.

use crate::animate::builder::Builder;
use crate::motion::WalkParams;

impl Builder<'_> {
    /// Turns by `dh` radians where the character stands: a "turn" segment.
    pub fn turn(&mut self, dh: f64, object: Option<usize>) {
        let start = self.frames.len();
        let to = self.st.heading + dh;
        let m = self.cache.walk(
            &[self.st.pos],
            self.ctx.lib,
            &WalkParams {
                initial_heading: Some(self.st.heading),
                final_heading: Some(to),
                lock_feet: self.ctx.cfg.lock_feet,
                ..WalkParams::default()
            },
        );
        self.append(m.poses());
        self.st.heading = to;
        self.push_segment("turn", start, object, Vec::new(), Vec::new());
    }
}
