//! A schematic 2-D face: head outline, brows, eyes with lids and gaze, nose, lips, jaw and tongue,
//! drawn from a [`FacePose`] of plain expression weights. It knows nothing about any rig or blendshape
//! set: an engine maps its own channels onto a pose (the face engine maps the 52 ARKit blendshapes in
//! `inbetween_face::preview`). People judge facial animation by looking at faces, so edits are shown
//! as side-by-side GIFs ([`write_face_gif`]) or still panels ([`render_face_panels`]).
//!
//! Conventions: "left" and "right" are the *subject's* sides, as in ARKit (`MouthSmileLeft` is the
//! subject's left corner), so with the subject facing the viewer, `_left` features are drawn on the
//! image's right. Face geometry lives in face units (the head's half-height is 1, x right, y down);
//! each feature also has a depth in front of the head's centre plane, so head yaw and pitch shift
//! near features (nose, mouth) more than far ones (the outline).

use crate::canvas::{text_width, Canvas};
use crate::RenderError;
use image::RgbImage;
use rayon::prelude::*;
use std::path::Path;

/// Expression weights of the schematic face. Weights are 0 (neutral) to 1 (full) unless noted;
/// values outside the documented range are clamped and non-finite ones read as neutral
/// ([`FacePose::sanitized`]), so any input draws without panicking. [`Default`] is the neutral face
/// with open eyes looking ahead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacePose {
    /// Lower jaw drops (chin and lower lip move down): 0..1.
    pub jaw_open: f32,
    /// Jaw slides sideways: -1 (subject's right, image left) .. 1 (subject's left, image right).
    pub jaw_shift: f32,
    /// Whole mouth slides sideways, same sign as `jaw_shift`: -1..1.
    pub mouth_shift: f32,
    /// Upper lip lifts on the subject's left / right: 0..1.
    pub upper_lip_raise_left: f32,
    pub upper_lip_raise_right: f32,
    /// Lower lip drops on the subject's left / right: 0..1.
    pub lower_lip_drop_left: f32,
    pub lower_lip_drop_right: f32,
    /// Lips close despite an open jaw (cancels up to `jaw_open` of the lip opening): 0..1.
    pub lip_close: f32,
    /// Mouth corners rise and widen: 0..1 each side.
    pub smile_left: f32,
    pub smile_right: f32,
    /// Mouth corners drop: 0..1 each side.
    pub frown_left: f32,
    pub frown_right: f32,
    /// Mouth corners pull outwards (and slightly down): 0..1 each side.
    pub stretch_left: f32,
    pub stretch_right: f32,
    /// Lips push forward into a narrow, thick kiss shape: 0..1.
    pub pucker: f32,
    /// Lips form a narrow, open funnel: 0..1.
    pub funnel: f32,
    /// Lips press together and thin out: 0..1.
    pub lip_press: f32,
    /// Lips roll inwards (less red shows): 0..1.
    pub lip_roll: f32,
    /// Chin pushes the lower lip up (closes the lip opening from below): 0..1.
    pub chin_raise: f32,
    /// Inner ends of both brows rise: 0..1.
    pub brow_inner_up: f32,
    /// Outer end of the brow rises: 0..1 each side.
    pub brow_outer_up_left: f32,
    pub brow_outer_up_right: f32,
    /// Brow lowers and furrows towards the nose: 0..1 each side.
    pub brow_down_left: f32,
    pub brow_down_right: f32,
    /// Upper lid opening: 0 closed, 1 relaxed open, up to 1.4 wide open (1.5 at most).
    pub eyelid_open_left: f32,
    pub eyelid_open_right: f32,
    /// Lower lid rises, upper lid lowers a little: 0..1 each side.
    pub squint_left: f32,
    pub squint_right: f32,
    /// Gaze of the subject's left eye: x -1 (image left) .. 1 (image right), y -1 (up) .. 1 (down).
    pub gaze_left_x: f32,
    pub gaze_left_y: f32,
    /// Gaze of the subject's right eye, same axes.
    pub gaze_right_x: f32,
    pub gaze_right_y: f32,
    /// Cheeks bulge out: 0..1.
    pub cheek_puff: f32,
    /// Nostril wing rises and the nose wrinkles: 0..1 each side.
    pub sneer_left: f32,
    pub sneer_right: f32,
    /// Tongue sticks out over the lower lip: 0..1.
    pub tongue_out: f32,
    /// Head turn in radians, positive turns the face towards the image right: -0.8..0.8.
    pub head_yaw: f32,
    /// Head nod in radians, positive tips the chin down: -0.8..0.8.
    pub head_pitch: f32,
    /// Head tilt in radians, positive rotates clockwise on screen: -0.8..0.8.
    pub head_roll: f32,
}

impl Default for FacePose {
    fn default() -> Self {
        FacePose {
            jaw_open: 0.0,
            jaw_shift: 0.0,
            mouth_shift: 0.0,
            upper_lip_raise_left: 0.0,
            upper_lip_raise_right: 0.0,
            lower_lip_drop_left: 0.0,
            lower_lip_drop_right: 0.0,
            lip_close: 0.0,
            smile_left: 0.0,
            smile_right: 0.0,
            frown_left: 0.0,
            frown_right: 0.0,
            stretch_left: 0.0,
            stretch_right: 0.0,
            pucker: 0.0,
            funnel: 0.0,
            lip_press: 0.0,
            lip_roll: 0.0,
            chin_raise: 0.0,
            brow_inner_up: 0.0,
            brow_outer_up_left: 0.0,
            brow_outer_up_right: 0.0,
            brow_down_left: 0.0,
            brow_down_right: 0.0,
            eyelid_open_left: 1.0,
            eyelid_open_right: 1.0,
            squint_left: 0.0,
            squint_right: 0.0,
            gaze_left_x: 0.0,
            gaze_left_y: 0.0,
            gaze_right_x: 0.0,
            gaze_right_y: 0.0,
            cheek_puff: 0.0,
            sneer_left: 0.0,
            sneer_right: 0.0,
            tongue_out: 0.0,
            head_yaw: 0.0,
            head_pitch: 0.0,
            head_roll: 0.0,
        }
    }
}

/// `v` clamped to `lo..=hi`, or `neutral` when it is not finite.
fn fit(v: f32, lo: f32, hi: f32, neutral: f32) -> f32 {
    if v.is_finite() {
        v.clamp(lo, hi)
    } else {
        neutral
    }
}

/// Largest head rotation drawn, radians.
const MAX_HEAD_ANGLE: f32 = 0.8;

impl FacePose {
    /// The pose with every field clamped to its documented range and non-finite values replaced by
    /// the neutral ones.
    pub fn sanitized(&self) -> FacePose {
        let w = |v: f32| fit(v, 0.0, 1.0, 0.0);
        let s = |v: f32| fit(v, -1.0, 1.0, 0.0);
        let a = |v: f32| fit(v, -MAX_HEAD_ANGLE, MAX_HEAD_ANGLE, 0.0);
        let lid = |v: f32| fit(v, 0.0, 1.5, 1.0);
        FacePose {
            jaw_open: w(self.jaw_open),
            jaw_shift: s(self.jaw_shift),
            mouth_shift: s(self.mouth_shift),
            upper_lip_raise_left: w(self.upper_lip_raise_left),
            upper_lip_raise_right: w(self.upper_lip_raise_right),
            lower_lip_drop_left: w(self.lower_lip_drop_left),
            lower_lip_drop_right: w(self.lower_lip_drop_right),
            lip_close: w(self.lip_close),
            smile_left: w(self.smile_left),
            smile_right: w(self.smile_right),
            frown_left: w(self.frown_left),
            frown_right: w(self.frown_right),
            stretch_left: w(self.stretch_left),
            stretch_right: w(self.stretch_right),
            pucker: w(self.pucker),
            funnel: w(self.funnel),
            lip_press: w(self.lip_press),
            lip_roll: w(self.lip_roll),
            chin_raise: w(self.chin_raise),
            brow_inner_up: w(self.brow_inner_up),
            brow_outer_up_left: w(self.brow_outer_up_left),
            brow_outer_up_right: w(self.brow_outer_up_right),
            brow_down_left: w(self.brow_down_left),
            brow_down_right: w(self.brow_down_right),
            eyelid_open_left: lid(self.eyelid_open_left),
            eyelid_open_right: lid(self.eyelid_open_right),
            squint_left: w(self.squint_left),
            squint_right: w(self.squint_right),
            gaze_left_x: s(self.gaze_left_x),
            gaze_left_y: s(self.gaze_left_y),
            gaze_right_x: s(self.gaze_right_x),
            gaze_right_y: s(self.gaze_right_y),
            cheek_puff: w(self.cheek_puff),
            sneer_left: w(self.sneer_left),
            sneer_right: w(self.sneer_right),
            tongue_out: w(self.tongue_out),
            head_yaw: a(self.head_yaw),
            head_pitch: a(self.head_pitch),
            head_roll: a(self.head_roll),
        }
    }

    /// The value of a sided field for image side `side` (+1 image right = subject's left).
    fn sided(side: f32, left: f32, right: f32) -> f32 {
        if side > 0.0 {
            left
        } else {
            right
        }
    }
}

// ---- colours ---------------------------------------------------------------------------------------

const BACKGROUND: [u8; 3] = [250, 250, 247];
const SKIN: [u8; 3] = [246, 222, 198];
const OUTLINE: [u8; 3] = [120, 88, 72];
const BROW: [u8; 3] = [92, 64, 48];
const EYE_WHITE: [u8; 3] = [255, 255, 255];
/// Iris colour (tests look for it).
pub const IRIS: [u8; 3] = [64, 118, 170];
const PUPIL: [u8; 3] = [24, 24, 30];
const LID: [u8; 3] = [70, 46, 40];
const LOWER_LID: [u8; 3] = [176, 136, 118];
const LIP: [u8; 3] = [200, 98, 98];
const LIP_LINE: [u8; 3] = [128, 52, 56];
/// Inside of the open mouth (tests look for dark pixels of it).
pub const MOUTH_CAVITY: [u8; 3] = [72, 22, 32];
const TEETH: [u8; 3] = [243, 241, 232];
const TONGUE: [u8; 3] = [222, 104, 124];
const CHEEK: [u8; 3] = [238, 150, 140];
const HIGHLIGHT: [u8; 3] = [230, 120, 20];
const TEXT: [u8; 3] = [40, 40, 40];
const SEPARATOR: [u8; 3] = [200, 200, 196];

// ---- geometry in face units (head half-height 1, y down) -------------------------------------------

const HEAD_RX: f32 = 0.80;
/// Chin travel at full `jaw_open`.
const JAW_DROP: f32 = 0.20;
const EYE_X: f32 = 0.33;
const EYE_Y: f32 = -0.12;
const EYE_HALF_W: f32 = 0.16;
/// Upper and lower lid heights above and below the eye line at the eye's middle.
const EYE_UPPER: f32 = 0.085;
const EYE_LOWER: f32 = 0.055;
const IRIS_R: f32 = 0.066;
const PUPIL_R: f32 = 0.03;
const MOUTH_Y: f32 = 0.50;
const MOUTH_HALF_W: f32 = 0.25;
/// Depths in front of the head's centre plane (how far yaw and pitch shift a feature).
const DEPTH_EYE: f32 = 0.55;
const DEPTH_BROW: f32 = 0.6;
const DEPTH_NOSE_BRIDGE: f32 = 0.8;
const DEPTH_NOSE_TIP: f32 = 0.95;
const DEPTH_MOUTH: f32 = 0.72;
/// The outline barely moves with yaw and pitch (a sphere's silhouette).
const DEPTH_OUTLINE: f32 = 0.08;
/// Head roll pivots about this point (the neck), face units.
const ROLL_PIVOT: (f32, f32) = (0.0, 0.6);

/// Face units to pixels for one face drawn in one rectangle, with the head pose applied.
struct View {
    cx: f32,
    cy: f32,
    scale: f32,
    yaw: (f32, f32),
    pitch: (f32, f32),
    roll: (f32, f32),
}

impl View {
    fn new(rect: (f32, f32, f32, f32), pose: &FacePose) -> View {
        let (x, y, w, h) = rect;
        View {
            cx: x + w * 0.5,
            cy: y + h * 0.45,
            scale: (w / 1.9).min(h / 2.45).max(0.0),
            yaw: pose.head_yaw.sin_cos(),
            pitch: pose.head_pitch.sin_cos(),
            roll: pose.head_roll.sin_cos(),
        }
    }

    /// Pixel position of the face point (x, y) lying `depth` in front of the head's centre plane.
    fn at(&self, x: f32, y: f32, depth: f32) -> (f32, f32) {
        let x1 = x * self.yaw.1 + depth * self.yaw.0;
        let y1 = y * self.pitch.1 + depth * self.pitch.0;
        self.place(x1, y1)
    }

    /// Pixel position of an outline point (not foreshortened, only shifted a little).
    fn outline(&self, x: f32, y: f32) -> (f32, f32) {
        self.place(x + DEPTH_OUTLINE * self.yaw.0, y + DEPTH_OUTLINE * self.pitch.0)
    }

    fn place(&self, x: f32, y: f32) -> (f32, f32) {
        let (dx, dy) = (x - ROLL_PIVOT.0, y - ROLL_PIVOT.1);
        let (s, c) = self.roll;
        let (xr, yr) = (ROLL_PIVOT.0 + dx * c - dy * s, ROLL_PIVOT.1 + dx * s + dy * c);
        (self.cx + self.scale * xr, self.cy + self.scale * yr)
    }

    /// A stroke width of `units` face units in pixels (at least one pixel).
    fn width(&self, units: f32) -> f32 {
        (units * self.scale).max(1.0)
    }
}

/// Strokes a polyline with round joins.
fn polyline(cv: &mut Canvas, pts: &[(f32, f32)], color: [u8; 3], width: f32) {
    for w in pts.windows(2) {
        cv.line(w[0], w[1], color, width);
    }
}

/// `n + 1` points of the quadratic Bézier from `a` to `b` that passes through `mid` at its middle.
fn curve_through(a: (f32, f32), mid: (f32, f32), b: (f32, f32), n: usize) -> Vec<(f32, f32)> {
    let c = (2.0 * mid.0 - 0.5 * (a.0 + b.0), 2.0 * mid.1 - 0.5 * (a.1 + b.1));
    (0..=n)
        .map(|i| {
            let t = i as f32 / n as f32;
            let (u, v, w) = ((1.0 - t) * (1.0 - t), 2.0 * t * (1.0 - t), t * t);
            (u * a.0 + v * c.0 + w * b.0, u * a.1 + v * c.1 + w * b.1)
        })
        .collect()
}

/// `n` points around an ellipse in face units, mapped by `map`.
fn ellipse(center: (f32, f32), r: (f32, f32), n: usize, map: impl Fn(f32, f32) -> (f32, f32)) -> Vec<(f32, f32)> {
    (0..n)
        .map(|i| {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            map(center.0 + r.0 * a.cos(), center.1 + r.1 * a.sin())
        })
        .collect()
}

/// Mixes `a` towards `b` by `t` (0..1).
fn mix(a: [u8; 3], b: [u8; 3], t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    [0, 1, 2].map(|i| (a[i] as f32 + (b[i] as f32 - a[i] as f32) * t).round() as u8)
}

/// Lid and lip profile across a feature: 1 in the middle (`u` = 0), 0 at the corners (`u` = ±1).
fn bump(u: f32, power: f32) -> f32 {
    (1.0 - u * u).max(0.0).powf(power)
}

/// Parameter values from -1 to 1.
fn params(n: usize) -> impl Iterator<Item = f32> + Clone {
    (0..=n).map(move |i| -1.0 + 2.0 * i as f32 / n as f32)
}

// ---- the face -------------------------------------------------------------------------------------

/// Draws the schematic face for `pose` into `rect` = (left, top, width, height) pixels of `canvas`
/// (the rectangle's background is left as it is; the head fills most of it). Sided fields follow the
/// subject's sides: `_left` features appear on the image right.
pub fn draw_face(canvas: &mut Canvas, rect: (f32, f32, f32, f32), pose: &FacePose) {
    let p = pose.sanitized();
    let v = View::new(rect, &p);
    if v.scale < 4.0 {
        return;
    }
    draw_head(canvas, &v, &p);
    for side in [-1.0f32, 1.0] {
        draw_brow(canvas, &v, &p, side);
        draw_eye(canvas, &v, &p, side);
    }
    draw_nose(canvas, &v, &p);
    draw_mouth(canvas, &v, &p);
}

/// Head outline: an ellipse whose lower half follows the jaw (drop and sideways shift) and bulges at
/// the cheeks with `cheek_puff`.
fn draw_head(cv: &mut Canvas, v: &View, p: &FacePose) {
    let n = 72;
    let outline: Vec<(f32, f32)> = (0..n)
        .map(|i| {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            let (s, c) = a.sin_cos();
            let (mut x, mut y) = (HEAD_RX * c, s);
            if s > 0.0 {
                let low = s * s;
                y += JAW_DROP * p.jaw_open * low;
                x += 0.08 * p.jaw_shift * low;
            }
            x *= 1.0 + 0.09 * p.cheek_puff * (-((y - 0.3) / 0.45).powi(2)).exp();
            v.outline(x, y)
        })
        .collect();
    cv.fill_polygons(&[&outline], SKIN, 1.0);
    let mut closed = outline.clone();
    closed.push(outline[0]);
    polyline(cv, &closed, OUTLINE, v.width(0.022));
    if p.cheek_puff > 0.01 {
        for side in [-1.0f32, 1.0] {
            let r = 0.09 + 0.05 * p.cheek_puff;
            let blush = ellipse((side * 0.5, 0.32), (r, r * 0.8), 24, |x, y| v.at(x, y, DEPTH_EYE));
            cv.fill_polygons(&[&blush], CHEEK, 0.45 * p.cheek_puff);
        }
    }
}

/// A brow: a thick curve over the eye whose inner end rises with `brow_inner_up`, outer end with
/// `brow_outer_up_*`, and which lowers and slides towards the nose with `brow_down_*`.
fn draw_brow(cv: &mut Canvas, v: &View, p: &FacePose, side: f32) {
    let outer_up = FacePose::sided(side, p.brow_outer_up_left, p.brow_outer_up_right);
    let down = FacePose::sided(side, p.brow_down_left, p.brow_down_right);
    let inner_up = p.brow_inner_up;
    let inner = (side * (0.13 - 0.03 * down), -0.34 - 0.11 * inner_up + 0.09 * down);
    let mid = (side * 0.30, -0.40 - 0.05 * inner_up - 0.05 * outer_up + 0.06 * down);
    let outer = (side * 0.47, -0.35 - 0.10 * outer_up + 0.05 * down);
    let pts: Vec<(f32, f32)> =
        curve_through(inner, mid, outer, 10).into_iter().map(|(x, y)| v.at(x, y, DEPTH_BROW)).collect();
    polyline(cv, &pts, BROW, v.width(0.036));
}

/// An eye: the white between the lids, the iris and pupil (moved by gaze) clipped to that opening,
/// then the upper lid line (thick) and the lower lid line (thin). `eyelid_open` 0 brings the upper lid
/// down onto the lower one, hiding the iris; squint raises the lower lid.
fn draw_eye(cv: &mut Canvas, v: &View, p: &FacePose, side: f32) {
    let open = FacePose::sided(side, p.eyelid_open_left, p.eyelid_open_right);
    let squint = FacePose::sided(side, p.squint_left, p.squint_right);
    let gaze = if side > 0.0 { (p.gaze_left_x, p.gaze_left_y) } else { (p.gaze_right_x, p.gaze_right_y) };
    let (ex, ey) = (side * EYE_X, EYE_Y);
    let open = open * (1.0 - 0.25 * squint);
    let lower_y = |u: f32| ey + EYE_LOWER * bump(u, 0.75) * (1.0 - 0.55 * squint);
    let upper_y = |u: f32| {
        let low = lower_y(u);
        (low + (ey - EYE_UPPER * bump(u, 0.75) - low) * open).min(low)
    };
    let map = |u: f32, y: f32| v.at(ex + u * EYE_HALF_W, y, DEPTH_EYE);
    let upper: Vec<(f32, f32)> = params(16).map(|u| map(u, upper_y(u))).collect();
    let lower: Vec<(f32, f32)> = params(16).map(|u| map(u, lower_y(u))).collect();
    let opening: Vec<(f32, f32)> = upper.iter().chain(lower.iter().rev()).copied().collect();
    cv.fill_polygons(&[&opening], EYE_WHITE, 1.0);
    let iris_c = (ex + gaze.0 * 0.08, ey - 0.004 + gaze.1 * 0.045);
    let iris = ellipse(iris_c, (IRIS_R, IRIS_R), 28, |x, y| v.at(x, y, DEPTH_EYE));
    cv.fill_polygons(&[&iris, &opening], IRIS, 1.0);
    let pupil = ellipse(iris_c, (PUPIL_R, PUPIL_R), 20, |x, y| v.at(x, y, DEPTH_EYE));
    cv.fill_polygons(&[&pupil, &opening], PUPIL, 1.0);
    polyline(cv, &lower, LOWER_LID, v.width(0.009));
    polyline(cv, &upper, LID, v.width(0.024));
}

/// Nose: a bridge line and a base curve whose nostril ends rise with `sneer_*`, plus wrinkle lines
/// that darken with the sneer.
fn draw_nose(cv: &mut Canvas, v: &View, p: &FacePose) {
    let bridge = [v.at(0.015, -0.07, DEPTH_NOSE_BRIDGE), v.at(0.04, 0.15, DEPTH_NOSE_TIP)];
    polyline(cv, &bridge, OUTLINE, v.width(0.014));
    let (sl, sr) = (p.sneer_left, p.sneer_right);
    let base = curve_through((-0.085, 0.17 - 0.045 * sr), (0.0, 0.215), (0.085, 0.17 - 0.045 * sl), 10);
    let base: Vec<(f32, f32)> = base.into_iter().map(|(x, y)| v.at(x, y, DEPTH_NOSE_TIP)).collect();
    polyline(cv, &base, OUTLINE, v.width(0.016));
    for (side, s) in [(-1.0f32, sr), (1.0, sl)] {
        if s > 0.05 {
            let c = mix(SKIN, OUTLINE, s);
            let a = v.at(side * 0.05, 0.0, DEPTH_NOSE_BRIDGE);
            let b = v.at(side * 0.095, 0.07, DEPTH_NOSE_BRIDGE);
            cv.line(a, b, c, v.width(0.01));
        }
    }
}

/// The mouth's shape in face units: the lip contours sampled from the subject's right corner
/// (image left, `u` = -1) to the left corner (`u` = 1).
struct MouthShape {
    upper_outer: Vec<(f32, f32)>,
    upper_inner: Vec<(f32, f32)>,
    lower_inner: Vec<(f32, f32)>,
    lower_outer: Vec<(f32, f32)>,
    /// Middle of the lower inner lip edge (where the tongue comes out).
    lower_mid: (f32, f32),
}

/// Mouth corners follow smile (up, out), frown (down), stretch (out), pucker and funnel (in); the
/// lip opening follows the jaw (less what `lip_close` and `chin_raise` cancel), the lip raise/drop
/// shapes and the funnel; lips thin with press and roll and thicken with pucker.
fn mouth_shape(p: &FacePose) -> MouthShape {
    let mx = 0.06 * p.mouth_shift;
    let side_w = |side: f32| {
        let smile = FacePose::sided(side, p.smile_left, p.smile_right);
        let stretch = FacePose::sided(side, p.stretch_left, p.stretch_right);
        (MOUTH_HALF_W * (1.0 + 0.22 * smile + 0.30 * stretch - 0.40 * p.pucker - 0.30 * p.funnel)).max(0.06)
    };
    let jaw_lips = (p.jaw_open - p.lip_close).max(0.0) * JAW_DROP;
    let corner_y = |side: f32| {
        let smile = FacePose::sided(side, p.smile_left, p.smile_right);
        let frown = FacePose::sided(side, p.frown_left, p.frown_right);
        let stretch = FacePose::sided(side, p.stretch_left, p.stretch_right);
        MOUTH_Y - 0.07 * smile + 0.07 * frown + 0.02 * stretch + 0.4 * JAW_DROP * p.jaw_open
    };
    let (w_r, w_l) = (side_w(-1.0), side_w(1.0));
    let (cy_r, cy_l) = (corner_y(-1.0), corner_y(1.0));
    let open_up =
        |side: f32| 0.05 * FacePose::sided(side, p.upper_lip_raise_left, p.upper_lip_raise_right) + 0.02 * p.funnel;
    let open_lo = |side: f32| {
        let drop = FacePose::sided(side, p.lower_lip_drop_left, p.lower_lip_drop_right);
        (jaw_lips + 0.06 * drop + 0.03 * p.funnel - 0.04 * p.chin_raise).max(0.0)
    };
    let thin = (1.0 - 0.7 * p.lip_roll) * (1.0 - 0.4 * p.lip_press);
    let (t_up, t_lo) = (0.045 * thin + 0.02 * p.pucker, 0.055 * thin + 0.025 * p.pucker);
    let jaw_x = 0.06 * p.jaw_shift;
    let mut m = MouthShape {
        upper_outer: Vec::new(),
        upper_inner: Vec::new(),
        lower_inner: Vec::new(),
        lower_outer: Vec::new(),
        lower_mid: (0.0, 0.0),
    };
    for u in params(24) {
        let s = (u + 1.0) * 0.5; // 0 at the image-left corner, 1 at the image-right one
        let x = mx + if u < 0.0 { u * w_r } else { u * w_l };
        let line = (cy_r + (cy_l - cy_r) * s) * u * u + MOUTH_Y * (1.0 - u * u);
        let b = bump(u, 0.6);
        let up = open_up(-1.0) + (open_up(1.0) - open_up(-1.0)) * s;
        let lo = open_lo(-1.0) + (open_lo(1.0) - open_lo(-1.0)) * s;
        let ui = line - up * b;
        let li = line + lo * b;
        let bow = 0.012 * (-(u / 0.12).powi(2)).exp();
        let xl = x + jaw_x * b;
        m.upper_inner.push((x, ui));
        m.upper_outer.push((x, ui - t_up * (0.3 + 0.7 * b) + bow));
        m.lower_inner.push((xl, li));
        m.lower_outer.push((xl, li + t_lo * (0.3 + 0.7 * b)));
    }
    m.lower_mid = m.lower_inner[m.lower_inner.len() / 2];
    m
}

/// Mouth: dark cavity with upper and lower teeth when open, the two lips, the line where they meet,
/// and the tongue when it is out.
fn draw_mouth(cv: &mut Canvas, v: &View, p: &FacePose) {
    let m = mouth_shape(p);
    let px = |pts: &[(f32, f32)]| -> Vec<(f32, f32)> { pts.iter().map(|&(x, y)| v.at(x, y, DEPTH_MOUTH)).collect() };
    let offset = |pts: &[(f32, f32)], dy: f32| -> Vec<(f32, f32)> { pts.iter().map(|&(x, y)| (x, y + dy)).collect() };
    let join = |a: Vec<(f32, f32)>, b: Vec<(f32, f32)>| -> Vec<(f32, f32)> {
        a.into_iter().chain(b.into_iter().rev()).collect()
    };
    let cavity = join(px(&m.upper_inner), px(&m.lower_inner));
    cv.fill_polygons(&[&cavity], MOUTH_CAVITY, 1.0);
    let upper_teeth = join(px(&offset(&m.upper_inner, -0.01)), px(&offset(&m.upper_inner, 0.032)));
    cv.fill_polygons(&[&upper_teeth, &cavity], TEETH, 1.0);
    let lower_teeth = join(px(&offset(&m.lower_inner, -0.022)), px(&offset(&m.lower_inner, 0.01)));
    cv.fill_polygons(&[&lower_teeth, &cavity], TEETH, 1.0);
    cv.fill_polygons(&[&join(px(&m.upper_outer), px(&m.upper_inner))], LIP, 1.0);
    cv.fill_polygons(&[&join(px(&m.lower_inner), px(&m.lower_outer))], LIP, 1.0);
    polyline(cv, &px(&m.upper_inner), LIP_LINE, v.width(0.012));
    if p.tongue_out > 0.02 {
        let t = p.tongue_out;
        let c = (m.lower_mid.0, m.lower_mid.1 + 0.01 + 0.06 * t);
        let tongue = ellipse(c, (0.085, 0.025 + 0.07 * t), 28, |x, y| v.at(x, y, DEPTH_MOUTH + 0.05));
        cv.fill_polygons(&[&tongue], TONGUE, 1.0);
        let mid = [v.at(c.0, c.1 - 0.01, DEPTH_MOUTH + 0.05), v.at(c.0, c.1 + 0.04 * t, DEPTH_MOUTH + 0.05)];
        polyline(cv, &mid, mix(TONGUE, LIP_LINE, 0.5), v.width(0.008));
    }
}

// ---- panels and GIFs ------------------------------------------------------------------------------

/// Smallest and largest panel edge accepted, pixels.
const PANEL_RANGE: (u32, u32) = (48, 2048);

fn check_panel_size(panel_size: u32) -> Result<(), RenderError> {
    if panel_size < PANEL_RANGE.0 || panel_size > PANEL_RANGE.1 {
        return Err(RenderError::InvalidInput(format!(
            "face panel size {panel_size} must be between {} and {} pixels",
            PANEL_RANGE.0, PANEL_RANGE.1
        )));
    }
    Ok(())
}

/// Text height for labels on panels of `panel_size` pixels.
fn label_size(panel_size: u32) -> f32 {
    (panel_size as f32 / 14.0).clamp(11.0, 28.0)
}

/// Height of a strip holding one line of text of `size`.
fn strip_height(size: f32) -> u32 {
    (size * 1.6).ceil() as u32
}

/// Draws `text` centred horizontally in the `width`-pixel column starting at `x`.
fn centred_text(cv: &mut Canvas, x: f32, width: f32, y: f32, text: &str, size: f32, color: [u8; 3]) {
    let w = text_width(text, size);
    cv.text((x + (width - w).max(0.0) * 0.5, y), text, size, color);
}

/// Faces side by side, each in a `panel_size`-pixel square under its label.
pub fn render_face_panels(panels: &[(&str, &FacePose)], panel_size: u32) -> Result<RgbImage, RenderError> {
    check_panel_size(panel_size)?;
    if panels.is_empty() {
        return Err(RenderError::InvalidInput("no face panels to draw".into()));
    }
    let labels: Vec<&str> = panels.iter().map(|p| p.0).collect();
    let mut cv = header(&labels, None, panel_size, 0);
    let top = strip_height(label_size(panel_size)) as f32;
    for (i, (_, pose)) in panels.iter().enumerate() {
        draw_face(&mut cv, ((i as u32 * panel_size) as f32, top, panel_size as f32, panel_size as f32), pose);
    }
    separators(&mut cv, panels.len(), panel_size);
    Ok(cv.into_image())
}

/// A canvas for `labels.len()` panels: the optional title line and the label line on top, the
/// panels, and `footer` pixels below them.
fn header(labels: &[&str], title: Option<&str>, panel_size: u32, footer: u32) -> Canvas {
    let size = label_size(panel_size);
    let line = strip_height(size);
    let title_h = if title.is_some() { line } else { 0 };
    let width = labels.len() as u32 * panel_size;
    let mut cv = Canvas::new(width, title_h + line + panel_size + footer, BACKGROUND);
    if let Some(t) = title {
        centred_text(&mut cv, 0.0, width as f32, size * 0.3, t, size, TEXT);
    }
    for (i, l) in labels.iter().enumerate() {
        centred_text(
            &mut cv,
            (i as u32 * panel_size) as f32,
            panel_size as f32,
            title_h as f32 + size * 0.3,
            l,
            size,
            TEXT,
        );
    }
    cv
}

/// One-pixel lines between neighbouring panels.
fn separators(cv: &mut Canvas, panels: usize, panel_size: u32) {
    for i in 1..panels {
        cv.rect((i as u32 * panel_size) as f32, 0.0, 1.0, cv.height() as f32, SEPARATOR);
    }
}

/// How [`write_face_gif`] lays out its frames.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceGifOptions {
    /// Playback rate, frames per second (one GIF frame per pose).
    pub fps: f64,
    /// Edge of each face's square panel, pixels.
    pub panel_size: u32,
    /// A line above the column labels.
    pub title: Option<String>,
    /// Caption shown (and the frame tinted) on highlighted frames.
    pub highlight_caption: String,
}

impl Default for FaceGifOptions {
    fn default() -> Self {
        FaceGifOptions { fps: 25.0, panel_size: 240, title: None, highlight_caption: "edited span".into() }
    }
}

/// Checks columns and highlight flags; returns the number of frames.
fn check_columns(columns: &[(String, Vec<FacePose>)], highlight: &[bool]) -> Result<usize, RenderError> {
    let first = columns.first().ok_or_else(|| RenderError::InvalidInput("no face columns to draw".into()))?;
    let n = first.1.len();
    if n == 0 {
        return Err(RenderError::InvalidInput(format!("face column '{}' has no frames", first.0)));
    }
    if let Some((name, poses)) = columns.iter().find(|c| c.1.len() != n) {
        return Err(RenderError::InvalidInput(format!(
            "face column '{name}' has {} frames but '{}' has {n}; all columns must have one length",
            poses.len(),
            first.0
        )));
    }
    if !highlight.is_empty() && highlight.len() != n {
        return Err(RenderError::InvalidInput(format!(
            "{} highlight flags for {n} frames (give one per frame, or none)",
            highlight.len()
        )));
    }
    Ok(n)
}

/// The frames of [`write_face_gif`]: one image per pose index, columns side by side under their
/// labels, a footer with the time, and on highlighted frames an orange frame and the caption.
pub fn render_face_frames(
    columns: &[(String, Vec<FacePose>)],
    highlight: &[bool],
    opts: &FaceGifOptions,
) -> Result<Vec<RgbImage>, RenderError> {
    check_panel_size(opts.panel_size)?;
    let n = check_columns(columns, highlight)?;
    if !(opts.fps.is_finite() && opts.fps > 0.0) {
        return Err(RenderError::InvalidInput(format!("face GIF frame rate {} must be a positive number", opts.fps)));
    }
    let size = label_size(opts.panel_size);
    let footer = strip_height(size);
    let labels: Vec<&str> = columns.iter().map(|c| c.0.as_str()).collect();
    let base = header(&labels, opts.title.as_deref(), opts.panel_size, footer);
    let top = (base.height() - footer - opts.panel_size) as f32;
    let frames = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut cv = base.clone();
            let ps = opts.panel_size as f32;
            for (c, (_, poses)) in columns.iter().enumerate() {
                draw_face(&mut cv, (c as f32 * ps, top, ps, ps), &poses[i]);
            }
            separators(&mut cv, columns.len(), opts.panel_size);
            let y = top + ps + size * 0.3;
            cv.text((size * 0.5, y), &format!("{:.2} s", i as f64 / opts.fps), size, TEXT);
            if highlight.get(i).copied().unwrap_or(false) {
                let border = (opts.panel_size as f32 / 80.0).max(2.0).round();
                let (w, h) = (cv.width() as f32, ps);
                for k in 0..border as u32 {
                    let k = k as f32;
                    cv.rect_outline(k, top + k, w - 2.0 * k, h - 2.0 * k, HIGHLIGHT);
                }
                let tw = text_width(&opts.highlight_caption, size);
                cv.text((w - tw - size * 0.5, y), &opts.highlight_caption, size, HIGHLIGHT);
            }
            cv.into_image()
        })
        .collect();
    Ok(frames)
}

/// Writes an animated GIF of several face animations side by side (e.g. original, edited), one
/// frame per pose at `opts.fps`, atomically. `highlight` is empty or one flag per frame: flagged
/// frames get an orange frame and `opts.highlight_caption` (e.g. while inside the edited span).
/// `progress(done, total)` is called as frames are encoded.
pub fn write_face_gif(
    path: &Path,
    columns: &[(String, Vec<FacePose>)],
    highlight: &[bool],
    opts: &FaceGifOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(), RenderError> {
    let frames = render_face_frames(columns, highlight, opts)?;
    crate::write_gif_with_progress(path, &frames, opts.fps, progress)
}

#[cfg(test)]
mod tests;
