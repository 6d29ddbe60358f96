//! Standing up from a seat: the stand-up clip placed at the stand point in front of the seat,
//! the root lowered onto the seat's height at first and eased to standing height (legs re-solved).

use crate::animate::builder::placed;
use crate::animate::builder::{smooth, Builder};
use crate::motion::procedural::SEAT_HEIGHT;

impl Builder<'_> {
    /// Stands up from a seat (if seated): a "stand_up" segment touching the seat.
    pub fn stand_up(&mut self) {
        self.get_up_from_lying();
        let start = self.frames.len();
        // On a chair scooted in at a table: scoot it out again first.
        if let (Some(p), Some((_, _, o))) = (self.st.pulled, self.st.seated) {
            if p.chair == o && p.inside != p.out {
                self.scoot(p.chair, p.inside, p.out);
            }
        }
        let Some((at, seat, obj)) = self.st.seated.take() else { return };
        let clip = self.named("procedural stand up");
        let mut poses = placed(&clip, at, self.st.heading);
        let n = poses.len().max(2);
        let dy = seat[1] as f64 - SEAT_HEIGHT;
        self.lift(&mut poses, |k| dy * (1.0 - smooth(k as f64 / (n - 1) as f64)));
        self.append(poses);
        self.push_segment("stand_up", start, Some(obj), vec![obj], Vec::new());
        self.st.pos = at;
        // A chair pulled out from under a table: a step to its side, then pushed back in.
        if let Some(crate::animate::builder::Pulled { chair, side, out: offset, .. }) = self.st.pulled.take() {
            let from = self.frames.len();
            self.step_to(side, self.st.heading, None);
            self.slide_seat(chair, offset, [0.0, 0.0]);
            self.push_segment("push in", from, Some(chair), vec![chair], Vec::new());
        }
    }
}
