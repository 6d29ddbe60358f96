//! Previews of an edit a person can look at: the schematic 2-D face of `inbetween_render::face`
//! driven by the 52 ARKit weights (original and edited side by side, as a GIF), and a PNG of the
//! curves that changed most, before and after, with the mask and the keyframe constraints marked.
//!
//! The face renderer knows nothing about ARKit; [`pose_from_arkit`] is the mapping, documented
//! shape by shape.

use std::path::Path;

use inbetween_io::Progress;
use inbetween_render::curves::{EditCurve, EditPlot};
use inbetween_render::face::{FaceGifOptions, FacePose};
use inbetween_render::RenderError;

use crate::data::{ARKIT_NAMES, NUM_ARKIT, NUM_HEAD_EYE};
use crate::edit::{Frame, Segment};

/// Index of an ARKit shape, checked at compile time.
const fn shape(name: &str) -> usize {
    let mut i = 0;
    while i < NUM_ARKIT {
        let (a, b) = (ARKIT_NAMES[i].as_bytes(), name.as_bytes());
        if a.len() == b.len() {
            let mut k = 0;
            while k < a.len() && a[k] == b[k] {
                k += 1;
            }
            if k == a.len() {
                return i;
            }
        }
        i += 1;
    }
    panic!("not an ARKit shape name")
}

const EYE_BLINK_L: usize = shape("EyeBlinkLeft");
const EYE_LOOK_DOWN_L: usize = shape("EyeLookDownLeft");
const EYE_LOOK_IN_L: usize = shape("EyeLookInLeft");
const EYE_LOOK_OUT_L: usize = shape("EyeLookOutLeft");
const EYE_LOOK_UP_L: usize = shape("EyeLookUpLeft");
const EYE_SQUINT_L: usize = shape("EyeSquintLeft");
const EYE_WIDE_L: usize = shape("EyeWideLeft");
const EYE_BLINK_R: usize = shape("EyeBlinkRight");
const EYE_LOOK_DOWN_R: usize = shape("EyeLookDownRight");
const EYE_LOOK_IN_R: usize = shape("EyeLookInRight");
const EYE_LOOK_OUT_R: usize = shape("EyeLookOutRight");
const EYE_LOOK_UP_R: usize = shape("EyeLookUpRight");
const EYE_SQUINT_R: usize = shape("EyeSquintRight");
const EYE_WIDE_R: usize = shape("EyeWideRight");
const JAW_RIGHT: usize = shape("JawRight");
const JAW_LEFT: usize = shape("JawLeft");
const JAW_OPEN: usize = shape("JawOpen");
const MOUTH_CLOSE: usize = shape("MouthClose");
const MOUTH_FUNNEL: usize = shape("MouthFunnel");
const MOUTH_PUCKER: usize = shape("MouthPucker");
const MOUTH_RIGHT: usize = shape("MouthRight");
const MOUTH_LEFT: usize = shape("MouthLeft");
const SMILE_L: usize = shape("MouthSmileLeft");
const SMILE_R: usize = shape("MouthSmileRight");
const FROWN_L: usize = shape("MouthFrownLeft");
const FROWN_R: usize = shape("MouthFrownRight");
const DIMPLE_L: usize = shape("MouthDimpleLeft");
const DIMPLE_R: usize = shape("MouthDimpleRight");
const STRETCH_L: usize = shape("MouthStretchLeft");
const STRETCH_R: usize = shape("MouthStretchRight");
const ROLL_LOWER: usize = shape("MouthRollLower");
const ROLL_UPPER: usize = shape("MouthRollUpper");
const SHRUG_LOWER: usize = shape("MouthShrugLower");
const SHRUG_UPPER: usize = shape("MouthShrugUpper");
const PRESS_L: usize = shape("MouthPressLeft");
const PRESS_R: usize = shape("MouthPressRight");
const LOWER_DOWN_L: usize = shape("MouthLowerDownLeft");
const LOWER_DOWN_R: usize = shape("MouthLowerDownRight");
const UPPER_UP_L: usize = shape("MouthUpperUpLeft");
const UPPER_UP_R: usize = shape("MouthUpperUpRight");
const BROW_DOWN_L: usize = shape("BrowDownLeft");
const BROW_DOWN_R: usize = shape("BrowDownRight");
const BROW_INNER_UP: usize = shape("BrowInnerUp");
const BROW_OUTER_UP_L: usize = shape("BrowOuterUpLeft");
const BROW_OUTER_UP_R: usize = shape("BrowOuterUpRight");
const CHEEK_PUFF: usize = shape("CheekPuff");
const CHEEK_SQUINT_L: usize = shape("CheekSquintLeft");
const CHEEK_SQUINT_R: usize = shape("CheekSquintRight");
const SNEER_L: usize = shape("NoseSneerLeft");
const SNEER_R: usize = shape("NoseSneerRight");
const TONGUE_OUT: usize = shape("TongueOut");

/// Eye rotation (radians) drawn as a full gaze (the real captures reach about ±0.55).
pub const EYE_GAZE_RANGE_RAD: f32 = 0.5;

/// The schematic face pose of one frame. `frame` holds the 52 ARKit weights in
/// [`ARKIT_NAMES`] order (missing trailing values read as 0); `head_eye` the 9 head/eye rotations in
/// [`crate::data::HEAD_EYE_NAMES`] order (radians), when the clip has them.
///
/// ARKit's `Left`/`Right` are the subject's sides, and so are [`FacePose`]'s. The mapping:
/// - jaw: `jaw_open` = JawOpen; `jaw_shift` = JawLeft − JawRight; `lip_close` = MouthClose.
/// - lips: `upper_lip_raise_*` = MouthUpperUp* + ½ MouthShrugUpper; `lower_lip_drop_*` =
///   MouthLowerDown*; `chin_raise` = MouthShrugLower; `lip_press` = mean of MouthPress*;
///   `lip_roll` = mean of MouthRollUpper/Lower; `pucker` = MouthPucker; `funnel` = MouthFunnel;
///   `mouth_shift` = MouthLeft − MouthRight.
/// - corners: `smile_*` = MouthSmile*; `frown_*` = MouthFrown*; `stretch_*` = MouthStretch* +
///   ½ MouthDimple*.
/// - brows: `brow_inner_up` = BrowInnerUp; `brow_outer_up_*` = BrowOuterUp*; `brow_down_*` = BrowDown*.
/// - lids: `eyelid_open_*` = 1 − EyeBlink* + 0.4 EyeWide*; `squint_*` = EyeSquint* + ½ CheekSquint*.
/// - gaze: from the eye rotations when present and not all zero (generated files carry zeros):
///   x = −EyeYaw / [`EYE_GAZE_RANGE_RAD`], y = EyePitch / the same (in the captures a positive
///   `LeftEyeYaw` goes with `EyeLookInLeft`, i.e. towards the image left, and a positive pitch with
///   `EyeLookDown*`). Otherwise from the EyeLook shapes: left eye x = EyeLookOutLeft −
///   EyeLookInLeft, right eye x = EyeLookInRight − EyeLookOutRight (both positive towards the
///   image right), y = EyeLookDown* − EyeLookUp*.
/// - rest: `cheek_puff` = CheekPuff; `sneer_*` = NoseSneer*; `tongue_out` = TongueOut.
/// - head: `head_yaw` = −HeadYaw (taken to follow the eye yaw's sign), `head_pitch` = HeadPitch,
///   `head_roll` = HeadRoll. The captures at hand hold no head rotation, so these signs are unchecked.
///
/// JawForward has no 2-D picture and is not drawn. Values are clamped to the pose's ranges when drawn.
pub fn pose_from_arkit(frame: &[f32], head_eye: Option<&[f32]>) -> FacePose {
    let w = |i: usize| frame.get(i).copied().filter(|v| v.is_finite()).unwrap_or(0.0);
    let he = |i: usize| head_eye.and_then(|h| h.get(i).copied()).filter(|v| v.is_finite()).unwrap_or(0.0);
    let mut p = FacePose {
        jaw_open: w(JAW_OPEN),
        jaw_shift: w(JAW_LEFT) - w(JAW_RIGHT),
        mouth_shift: w(MOUTH_LEFT) - w(MOUTH_RIGHT),
        upper_lip_raise_left: w(UPPER_UP_L) + 0.5 * w(SHRUG_UPPER),
        upper_lip_raise_right: w(UPPER_UP_R) + 0.5 * w(SHRUG_UPPER),
        lower_lip_drop_left: w(LOWER_DOWN_L),
        lower_lip_drop_right: w(LOWER_DOWN_R),
        lip_close: w(MOUTH_CLOSE),
        smile_left: w(SMILE_L),
        smile_right: w(SMILE_R),
        frown_left: w(FROWN_L),
        frown_right: w(FROWN_R),
        stretch_left: w(STRETCH_L) + 0.5 * w(DIMPLE_L),
        stretch_right: w(STRETCH_R) + 0.5 * w(DIMPLE_R),
        pucker: w(MOUTH_PUCKER),
        funnel: w(MOUTH_FUNNEL),
        lip_press: 0.5 * (w(PRESS_L) + w(PRESS_R)),
        lip_roll: 0.5 * (w(ROLL_UPPER) + w(ROLL_LOWER)),
        chin_raise: w(SHRUG_LOWER),
        brow_inner_up: w(BROW_INNER_UP),
        brow_outer_up_left: w(BROW_OUTER_UP_L),
        brow_outer_up_right: w(BROW_OUTER_UP_R),
        brow_down_left: w(BROW_DOWN_L),
        brow_down_right: w(BROW_DOWN_R),
        eyelid_open_left: 1.0 - w(EYE_BLINK_L) + 0.4 * w(EYE_WIDE_L),
        eyelid_open_right: 1.0 - w(EYE_BLINK_R) + 0.4 * w(EYE_WIDE_R),
        squint_left: w(EYE_SQUINT_L) + 0.5 * w(CHEEK_SQUINT_L),
        squint_right: w(EYE_SQUINT_R) + 0.5 * w(CHEEK_SQUINT_R),
        gaze_left_x: w(EYE_LOOK_OUT_L) - w(EYE_LOOK_IN_L),
        gaze_left_y: w(EYE_LOOK_DOWN_L) - w(EYE_LOOK_UP_L),
        gaze_right_x: w(EYE_LOOK_IN_R) - w(EYE_LOOK_OUT_R),
        gaze_right_y: w(EYE_LOOK_DOWN_R) - w(EYE_LOOK_UP_R),
        cheek_puff: w(CHEEK_PUFF),
        sneer_left: w(SNEER_L),
        sneer_right: w(SNEER_R),
        tongue_out: w(TONGUE_OUT),
        head_yaw: -he(0),
        head_pitch: he(1),
        head_roll: he(2),
    };
    // HEAD_EYE_NAMES: LeftEyeYaw 3, LeftEyePitch 4, RightEyeYaw 6, RightEyePitch 7.
    let eyes = [he(3), he(4), he(6), he(7)];
    if eyes.iter().any(|&v| v != 0.0) {
        p.gaze_left_x = -eyes[0] / EYE_GAZE_RANGE_RAD;
        p.gaze_left_y = eyes[1] / EYE_GAZE_RANGE_RAD;
        p.gaze_right_x = -eyes[2] / EYE_GAZE_RANGE_RAD;
        p.gaze_right_y = eyes[3] / EYE_GAZE_RANGE_RAD;
    }
    p
}

/// One flag per frame: whether it lies in any of `spans` (for [`write_edit_gif`]'s highlight).
pub fn span_flags(frames: usize, spans: &[Segment]) -> Vec<bool> {
    (0..frames).map(|f| spans.iter().any(|s| s.contains(f))).collect()
}

fn invalid(message: String) -> RenderError {
    RenderError::InvalidInput(message)
}

/// Writes a GIF of the schematic face, one column per animation (e.g. `("original", before)`,
/// `("edited", after)`), 240-pixel panels at `fps`, atomically. All columns need one length;
/// `head_eye` (the clip's head/eye rotations, shared by every column) is None or has that length
/// too; `highlight` is empty or one flag per frame (e.g. [`span_flags`] of the edited segments),
/// flagged frames carrying an orange frame and "edited span".
pub fn write_edit_gif(
    path: &Path,
    fps: f64,
    columns: &[(&str, &[Frame])],
    head_eye: Option<&[[f32; NUM_HEAD_EYE]]>,
    highlight: &[bool],
    progress: &Progress,
) -> Result<(), RenderError> {
    let n = columns.first().map_or(0, |c| c.1.len());
    if let Some(he) = head_eye {
        if he.len() != n {
            return Err(invalid(format!("{} head/eye frames for {n} blendshape frames", he.len())));
        }
    }
    let poses: Vec<(String, Vec<FacePose>)> = columns
        .iter()
        .map(|(name, frames)| {
            let poses =
                frames.iter().enumerate().map(|(f, w)| pose_from_arkit(w, head_eye.map(|h| &h[f][..]))).collect();
            (name.to_string(), poses)
        })
        .collect();
    let opts = FaceGifOptions { fps, ..FaceGifOptions::default() };
    inbetween_render::face::write_face_gif(path, &poses, highlight, &opts, &mut |done, total| {
        progress.set_length(total as u64);
        progress.set_position(done as u64);
    })
}

/// What [`write_edit_png`] plots.
#[derive(Clone, Copy, Debug)]
pub struct CurvePreview<'a> {
    pub title: &'a str,
    /// Frame rate of the curves (for the time axis).
    pub fps: f64,
    pub before: &'a [Frame],
    pub after: &'a [Frame],
    /// Edited frames, shaded.
    pub spans: &'a [Segment],
    /// Keyframe constraints (frame, weights), drawn as dots on every plotted curve.
    pub keys: &'a [(usize, Frame)],
    /// A third animation drawn dashed (e.g. ("linear", baseline) or ("guide", noisy input)).
    pub extra: Option<(&'a str, &'a [Frame])>,
    /// How many curves to plot (1..=24).
    pub n_curves: usize,
}

/// Below this largest change a curve counts as unchanged when choosing what to plot.
pub const CHANGED_THRESHOLD: f32 = 0.02;

/// The `n` channels whose largest |after − before| is biggest (at least [`CHANGED_THRESHOLD`]),
/// biggest first; when fewer changed, JawOpen and then EyeBlinkLeft fill up the list.
pub fn changed_channels(before: &[Frame], after: &[Frame], n: usize) -> Vec<usize> {
    let mut score: Vec<(usize, f32)> = (0..NUM_ARKIT)
        .map(|c| {
            (
                c,
                before
                    .iter()
                    .zip(after)
                    .map(|(b, a)| (a[c] - b[c]).abs())
                    .filter(|d| d.is_finite())
                    .fold(0.0, f32::max),
            )
        })
        .filter(|&(_, s)| s >= CHANGED_THRESHOLD)
        .collect();
    score.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut out: Vec<usize> = score.into_iter().take(n).map(|(c, _)| c).collect();
    for fill in [JAW_OPEN, EYE_BLINK_L] {
        if out.len() < n && !out.contains(&fill) {
            out.push(fill);
        }
    }
    out
}

/// The curve plot of an edit as an [`EditPlot`], choosing the curves with [`changed_channels`].
pub fn edit_plot(p: &CurvePreview<'_>) -> Result<EditPlot, RenderError> {
    let n = p.before.len();
    if n == 0 || p.after.len() != n {
        return Err(invalid(format!(
            "curve preview needs equal, non-empty before ({n}) and after ({}) frames",
            p.after.len()
        )));
    }
    if !(p.fps.is_finite() && p.fps > 0.0) {
        return Err(invalid(format!("curve preview frame rate {} must be a positive number", p.fps)));
    }
    if p.n_curves == 0 || p.n_curves > inbetween_render::curves::MAX_EDIT_CURVES {
        return Err(invalid(format!(
            "{} curves requested; 1 to {} fit",
            p.n_curves,
            inbetween_render::curves::MAX_EDIT_CURVES
        )));
    }
    if let Some((name, extra)) = p.extra {
        if extra.len() != n {
            return Err(invalid(format!("'{name}' has {} frames for {n} edited frames", extra.len())));
        }
    }
    if let Some((f, _)) = p.keys.iter().find(|k| k.0 >= n) {
        return Err(invalid(format!("key at frame {f} lies past the clip's {n} frames")));
    }
    let times: Vec<f64> = (0..n).map(|f| f as f64 / p.fps).collect();
    let mut plot = EditPlot::new(p.title, times);
    let channel = |frames: &[Frame], c: usize| frames.iter().map(|w| w[c]).collect::<Vec<f32>>();
    for c in changed_channels(p.before, p.after, p.n_curves) {
        plot.curves.push(EditCurve {
            name: ARKIT_NAMES[c].to_string(),
            before: channel(p.before, c),
            after: channel(p.after, c),
            extra: p.extra.map(|(name, frames)| (name.to_string(), channel(frames, c))),
        });
        plot.markers.extend(p.keys.iter().map(|(f, w)| (ARKIT_NAMES[c].to_string(), *f as f64 / p.fps, w[c])));
    }
    // Shade half a frame either side of the erased frames, so that one erased frame shows too.
    plot.spans = p
        .spans
        .iter()
        .filter(|s| !s.is_empty())
        .map(|s| ((s.start as f64 - 0.5) / p.fps, (s.end as f64 - 0.5) / p.fps))
        .collect();
    Ok(plot)
}

/// Writes the PNG of an edit's curves (see [`CurvePreview`]) atomically; returns the ARKit channels
/// it plotted.
pub fn write_edit_png(path: &Path, preview: &CurvePreview<'_>) -> Result<Vec<usize>, RenderError> {
    let plot = edit_plot(preview)?;
    inbetween_render::curves::write_edit_plot(path, &plot)?;
    Ok(plot.curves.iter().filter_map(|c| crate::data::arkit_index(&c.name)).collect())
}

/// Frames shown before and after the spans in an edit's GIF (1 s at the model rate).
pub const GIF_MARGIN_FRAMES: usize = 25;

/// An edit's curve plot at `path` ([`write_edit_png`]): the six most-changed curves at the model
/// rate, the spans shaded, the keys dotted, under `title`.
pub fn write_outcome_png(path: &Path, out: &crate::infer::EditOutcome, title: &str) -> Result<(), RenderError> {
    let segs = out.mask.segments();
    let preview = CurvePreview {
        title,
        fps: crate::data::MODEL_FPS,
        before: &out.before,
        after: &out.after,
        spans: &segs,
        keys: &out.keys,
        extra: None,
        n_curves: 6,
    };
    write_edit_png(path, &preview).map(|_| ())
}

/// An edit's schematic face at `path` ([`write_edit_gif`]), original beside edited, over its spans
/// and [`GIF_MARGIN_FRAMES`] either side; `progress` counts the frames.
pub fn write_outcome_gif(path: &Path, out: &crate::infer::EditOutcome, progress: &Progress) -> Result<(), RenderError> {
    let segs = out.mask.segments();
    let first = segs.iter().map(|s| s.start).min().unwrap_or(0).saturating_sub(GIF_MARGIN_FRAMES);
    let last = (segs.iter().map(|s| s.end).max().unwrap_or(0) + GIF_MARGIN_FRAMES).min(out.before.len());
    let local: Vec<Segment> = segs.iter().map(|s| Segment { start: s.start - first, end: s.end - first }).collect();
    progress.set_length((last - first) as u64);
    write_edit_gif(
        path,
        crate::data::MODEL_FPS,
        &[("original", &out.before[first..last]), ("edited", &out.after[first..last])],
        None,
        &span_flags(last - first, &local),
        progress,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::HEAD_EYE_NAMES;

    fn frame(pairs: &[(&str, f32)]) -> Frame {
        let mut f = [0.0; NUM_ARKIT];
        for (name, v) in pairs {
            f[crate::data::arkit_index(name).unwrap()] = *v;
        }
        f
    }

    #[test]
    fn arkit_shapes_map_to_their_pose_fields() {
        let p = pose_from_arkit(
            &frame(&[("JawOpen", 0.7), ("EyeBlinkLeft", 1.0), ("MouthSmileRight", 0.5), ("EyeWideRight", 1.0)]),
            None,
        );
        assert_eq!(p.jaw_open, 0.7);
        assert_eq!(p.eyelid_open_left, 0.0);
        assert!((p.eyelid_open_right - 1.4).abs() < 1e-6);
        assert_eq!((p.smile_right, p.smile_left), (0.5, 0.0));
        assert_eq!(pose_from_arkit(&[0.0; NUM_ARKIT], None), FacePose::default());
        // Short or broken frames read as zeros, never panic.
        assert_eq!(pose_from_arkit(&[f32::NAN], None).eyelid_open_left, 1.0);
    }

    #[test]
    fn gaze_comes_from_eye_rotations_or_else_from_eye_look_shapes() {
        let look = frame(&[("EyeLookOutLeft", 1.0), ("EyeLookInRight", 1.0), ("EyeLookUpLeft", 0.5)]);
        let p = pose_from_arkit(&look, None);
        assert!(p.gaze_left_x > 0.9 && p.gaze_right_x > 0.9, "both eyes look to the subject's left = image right");
        assert_eq!(p.gaze_left_y, -0.5);
        // Zeroed rotation columns (as in generated files) fall back to the shapes.
        assert_eq!(pose_from_arkit(&look, Some(&[0.0; NUM_HEAD_EYE])).gaze_left_x, p.gaze_left_x);
        let mut he = [0.0f32; NUM_HEAD_EYE];
        assert_eq!(HEAD_EYE_NAMES[3], "LeftEyeYaw");
        he[3] = 0.25; // towards the nose for the left eye (EyeLookInLeft): image left
        he[7] = 0.25; // RightEyePitch: down
        let q = pose_from_arkit(&look, Some(&he));
        assert!((q.gaze_left_x + 0.5).abs() < 1e-6 && (q.gaze_right_y - 0.5).abs() < 1e-6, "{q:?}");
    }

    #[test]
    fn changed_channels_pick_the_biggest_edits_or_fall_back() {
        let before = vec![[0.0; NUM_ARKIT]; 10];
        let mut after = before.clone();
        after[4][shape("MouthPucker")] = 0.5;
        after[5][shape("BrowInnerUp")] = 0.2;
        after[6][shape("CheekPuff")] = 0.01; // below the threshold
        assert_eq!(changed_channels(&before, &after, 2), vec![shape("MouthPucker"), shape("BrowInnerUp")]);
        assert_eq!(changed_channels(&before, &after, 3), vec![shape("MouthPucker"), shape("BrowInnerUp"), JAW_OPEN]);
        assert_eq!(changed_channels(&before, &before, 4), vec![JAW_OPEN, EYE_BLINK_L]);
    }

    fn talking(n: usize, speed: f32) -> Vec<Frame> {
        (0..n)
            .map(|i| {
                let t = i as f32 * speed;
                frame(&[
                    ("JawOpen", 0.4 + 0.4 * t.sin()),
                    ("EyeBlinkLeft", if i % 40 < 4 { 1.0 } else { 0.0 }),
                    ("MouthSmileLeft", 0.3),
                ])
            })
            .collect()
    }

    #[test]
    fn edit_png_plots_the_changed_curves_with_keys_and_span() {
        let before = talking(100, 0.2);
        let mut after = before.clone();
        for f in after.iter_mut().take(60).skip(40) {
            f[JAW_OPEN] = 0.1;
        }
        let keys = [(50usize, after[50])];
        let spans = [Segment { start: 40, end: 60 }];
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("curves.png");
        let preview = CurvePreview {
            title: "test edit",
            fps: 25.0,
            before: &before,
            after: &after,
            spans: &spans,
            keys: &keys,
            extra: Some(("linear", &before)),
            n_curves: 3,
        };
        let chosen = write_edit_png(&path, &preview).unwrap();
        assert_eq!(chosen, vec![JAW_OPEN, EYE_BLINK_L]);
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!(
            img.dimensions(),
            (inbetween_render::curves::EDIT_PLOT_WIDTH, inbetween_render::curves::edit_plot_height(2))
        );
        assert!(img.pixels().any(|p| p.0 == inbetween_render::curves::SPAN_COLOR));
        let plot = edit_plot(&preview).unwrap();
        assert_eq!(plot.markers.len(), 2, "one key on each of the two curves");
        assert_eq!(plot.spans, vec![(39.5 / 25.0, 59.5 / 25.0)]);
        // Bad input: mismatched lengths, keys past the end, nothing written.
        let bad = CurvePreview { after: &after[..10], ..preview };
        assert!(write_edit_png(&dir.path().join("bad.png"), &bad).is_err());
        let late = [(100usize, after[0])];
        assert!(edit_plot(&CurvePreview { keys: &late, ..preview }).unwrap_err().to_string().contains("frame 100"));
        assert!(!dir.path().join("bad.png").exists());
    }

    #[test]
    fn edit_gif_has_a_frame_per_pose() {
        use image::AnimationDecoder;
        let before = talking(12, 0.5);
        let after = talking(12, 0.3);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("face.gif");
        let flags = span_flags(12, &[Segment { start: 3, end: 7 }]);
        assert_eq!(flags.iter().filter(|&&f| f).count(), 4);
        let progress = Progress::hidden();
        let he = vec![[0.0f32; NUM_HEAD_EYE]; 12];
        write_edit_gif(&path, 25.0, &[("original", &before), ("edited", &after)], Some(&he), &flags, &progress)
            .unwrap();
        assert_eq!(progress.position(), 12);
        let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
        let frames = image::codecs::gif::GifDecoder::new(file).unwrap().into_frames().collect_frames().unwrap();
        assert_eq!(frames.len(), 12);
        assert_eq!(frames[0].buffer().width(), 2 * FaceGifOptions::default().panel_size);
        let short = vec![[0.0f32; NUM_HEAD_EYE]; 5];
        let err = write_edit_gif(&path, 25.0, &[("original", &before)], Some(&short), &[], &progress).unwrap_err();
        assert!(err.to_string().contains("5 head/eye frames"), "{err}");
    }
}
