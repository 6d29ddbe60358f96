use super::*;

const SIZE: u32 = 240;

fn face(pose: &FacePose) -> Canvas {
    let mut cv = Canvas::new(SIZE, SIZE, BACKGROUND);
    draw_face(&mut cv, (0.0, 0.0, SIZE as f32, SIZE as f32), pose);
    cv
}

/// Pixels in the region (pixel rectangle) that satisfy `pred`.
fn count(cv: &Canvas, region: (u32, u32, u32, u32), pred: impl Fn([u8; 3]) -> bool) -> Vec<(u32, u32)> {
    let (x0, y0, x1, y1) = region;
    (y0..y1.min(cv.height()))
        .flat_map(|y| (x0..x1.min(cv.width())).map(move |x| (x, y)))
        .filter(|&(x, y)| pred(cv.pixel(x, y)))
        .collect()
}

fn whole() -> (u32, u32, u32, u32) {
    (0, 0, SIZE, SIZE)
}

fn is_dark(c: [u8; 3]) -> bool {
    c.iter().all(|&v| v < 110)
}

fn is_iris(c: [u8; 3]) -> bool {
    c == IRIS
}

/// Pixel box of the mouth region in the neutral framing (face units 0.2..1.0 down, ±0.5 across).
fn mouth_region() -> (u32, u32, u32, u32) {
    let v = View::new((0.0, 0.0, SIZE as f32, SIZE as f32), &FacePose::default());
    let (a, b) = (v.at(-0.5, 0.25, 0.0), v.at(0.5, 1.0, 0.0));
    (a.0 as u32, a.1 as u32, b.0 as u32, b.1 as u32)
}

fn centroid_x(pts: &[(u32, u32)]) -> f32 {
    pts.iter().map(|p| p.0 as f32).sum::<f32>() / pts.len().max(1) as f32
}

#[test]
fn an_open_jaw_shows_more_dark_mouth_than_a_closed_one() {
    let closed = count(&face(&FacePose::default()), mouth_region(), is_dark).len();
    let open = count(&face(&FacePose { jaw_open: 0.8, ..FacePose::default() }), mouth_region(), is_dark).len();
    assert!(open > closed + 150, "open mouth {open} dark pixels, closed {closed}");
    // MouthClose cancels the lip opening the jaw would give.
    let sealed = FacePose { jaw_open: 0.8, lip_close: 0.8, ..FacePose::default() };
    let sealed = count(&face(&sealed), mouth_region(), is_dark).len();
    assert!(sealed < open / 3, "lips closed over an open jaw: {sealed} dark pixels vs {open}");
}

#[test]
fn closed_lids_hide_the_iris_and_wide_lids_show_more() {
    let open = count(&face(&FacePose::default()), whole(), is_iris).len();
    assert!(open > 100, "open eyes show {open} iris pixels");
    let shut = FacePose { eyelid_open_left: 0.0, eyelid_open_right: 0.0, ..FacePose::default() };
    assert_eq!(count(&face(&shut), whole(), is_iris).len(), 0, "closed lids must hide the iris");
    let half = FacePose { eyelid_open_left: 0.5, eyelid_open_right: 0.5, ..FacePose::default() };
    let half = count(&face(&half), whole(), is_iris).len();
    assert!(half > 0 && half < open, "half-closed {half} vs open {open}");
    // One lid only: the iris remains on the other side of the image.
    let wink = FacePose { eyelid_open_left: 0.0, ..FacePose::default() };
    let wink = count(&face(&wink), whole(), is_iris);
    assert!(!wink.is_empty() && wink.iter().all(|p| p.0 < SIZE / 2), "the subject's left eye is on the image right");
}

#[test]
fn gaze_moves_the_iris() {
    let ahead = centroid_x(&count(&face(&FacePose::default()), whole(), is_iris));
    let right = FacePose { gaze_left_x: 1.0, gaze_right_x: 1.0, ..FacePose::default() };
    let right = centroid_x(&count(&face(&right), whole(), is_iris));
    assert!(right > ahead + 4.0, "looking right moves the iris right: {ahead} -> {right}");
    let up = FacePose {
        gaze_left_y: -1.0,
        gaze_right_y: -1.0,
        eyelid_open_left: 1.4,
        eyelid_open_right: 1.4,
        ..FacePose::default()
    };
    let wide = FacePose { eyelid_open_left: 1.4, eyelid_open_right: 1.4, ..FacePose::default() };
    let cy = |pose: &FacePose| {
        let pts = count(&face(pose), whole(), is_iris);
        pts.iter().map(|p| p.1 as f32).sum::<f32>() / pts.len() as f32
    };
    assert!(cy(&up) < cy(&wide) - 1.0, "looking up moves the iris up");
}

/// Leftmost and rightmost lip pixels of the mouth.
fn mouth_extent(pose: &FacePose) -> (u32, u32) {
    let pts = count(&face(pose), mouth_region(), |c| c == LIP || c == LIP_LINE);
    (pts.iter().map(|p| p.0).min().unwrap(), pts.iter().map(|p| p.0).max().unwrap())
}

#[test]
fn a_smile_moves_the_corners_outwards_and_a_pucker_inwards() {
    let (l0, r0) = mouth_extent(&FacePose::default());
    let (l1, r1) = mouth_extent(&FacePose { smile_left: 1.0, smile_right: 1.0, ..FacePose::default() });
    assert!(l1 + 3 < l0 && r1 > r0 + 3, "smile widens the mouth: {l0}..{r0} -> {l1}..{r1}");
    let (l2, r2) = mouth_extent(&FacePose { pucker: 1.0, ..FacePose::default() });
    assert!(l2 > l0 + 5 && r2 + 5 < r0, "pucker narrows the mouth: {l0}..{r0} -> {l2}..{r2}");
    // A one-sided smile moves only the subject's left corner (image right).
    let (l3, r3) = mouth_extent(&FacePose { smile_left: 1.0, ..FacePose::default() });
    assert!(l3.abs_diff(l0) <= 1 && r3 > r0 + 3, "{l0}..{r0} -> {l3}..{r3}");
}

#[test]
fn tongue_brows_and_head_pose_change_the_picture() {
    let neutral = face(&FacePose::default());
    let tongue = face(&FacePose { tongue_out: 1.0, jaw_open: 0.4, ..FacePose::default() });
    assert!(!count(&tongue, mouth_region(), |c| c == TONGUE).is_empty());
    assert!(count(&neutral, whole(), |c| c == TONGUE).is_empty());
    // Raised brows move brow pixels up.
    let brow_y = |cv: &Canvas| {
        let pts = count(cv, (0, 0, SIZE, SIZE / 2), |c| c == BROW);
        pts.iter().map(|p| p.1 as f32).sum::<f32>() / pts.len() as f32
    };
    let raised = face(&FacePose {
        brow_inner_up: 1.0,
        brow_outer_up_left: 1.0,
        brow_outer_up_right: 1.0,
        ..FacePose::default()
    });
    assert!(brow_y(&raised) < brow_y(&neutral) - 3.0);
    // Yaw shifts the features (iris) more than nothing.
    let turned = face(&FacePose { head_yaw: 0.5, ..FacePose::default() });
    let shift = centroid_x(&count(&turned, whole(), is_iris)) - centroid_x(&count(&neutral, whole(), is_iris));
    assert!(shift > 10.0, "a head turn to the right moves the eyes right by {shift} px");
}

#[test]
fn bad_values_draw_without_panicking() {
    let wild = FacePose {
        jaw_open: f32::NAN,
        head_yaw: f32::INFINITY,
        eyelid_open_left: -5.0,
        smile_left: 1e9,
        ..FacePose::default()
    };
    assert_eq!(wild.sanitized().jaw_open, 0.0);
    assert_eq!(wild.sanitized().eyelid_open_left, 0.0);
    let cv = face(&wild);
    assert!(count(&cv, whole(), |c| c == SKIN).len() > 1000);
    // A tiny rectangle draws nothing rather than failing.
    let mut small = Canvas::new(4, 4, BACKGROUND);
    draw_face(&mut small, (0.0, 0.0, 4.0, 4.0), &FacePose::default());
    assert_eq!(small.pixel(2, 2), BACKGROUND);
}

#[test]
fn panels_sit_side_by_side_under_labels() {
    let smile = FacePose { smile_left: 1.0, smile_right: 1.0, ..FacePose::default() };
    let img = render_face_panels(&[("neutral", &FacePose::default()), ("smile", &smile)], 120).unwrap();
    let top = strip_height(label_size(120));
    assert_eq!(img.dimensions(), (240, 120 + top));
    let cv = Canvas::from_image(img);
    assert!(!count(&cv, (0, 0, 120, top), |c| c[0] < 100).is_empty(), "label text");
    assert!(count(&cv, (0, top, 120, top + 120), |c| c == SKIN).len() > 1000);
    assert!(count(&cv, (120, top, 240, top + 120), |c| c == SKIN).len() > 1000);
    assert!(render_face_panels(&[], 120).is_err());
    assert!(render_face_panels(&[("x", &smile)], 8).is_err());
}

#[test]
fn gif_has_one_frame_per_pose_and_highlights_flagged_frames() {
    use image::AnimationDecoder;
    let n = 6;
    let talk: Vec<FacePose> =
        (0..n).map(|i| FacePose { jaw_open: i as f32 / n as f32, ..FacePose::default() }).collect();
    let still = vec![FacePose::default(); n];
    let columns = vec![("original".to_string(), still), ("edited".to_string(), talk)];
    let highlight: Vec<bool> = (0..n).map(|i| (2..4).contains(&i)).collect();
    let opts = FaceGifOptions { panel_size: 96, title: Some("test".into()), ..FaceGifOptions::default() };
    let frames = render_face_frames(&columns, &highlight, &opts).unwrap();
    let orange = |img: &RgbImage| img.pixels().filter(|p| p.0 == HIGHLIGHT).count();
    assert_eq!(orange(&frames[1]), 0);
    assert!(orange(&frames[2]) > 300, "highlighted frame has an orange frame: {}", orange(&frames[2]));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("face.gif");
    let mut calls = 0;
    write_face_gif(&path, &columns, &highlight, &opts, &mut |_, _| calls += 1).unwrap();
    assert_eq!(calls, n);
    let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
    let decoded = image::codecs::gif::GifDecoder::new(file).unwrap().into_frames().collect_frames().unwrap();
    assert_eq!(decoded.len(), n);
    assert_eq!(decoded[0].buffer().dimensions(), frames[0].dimensions());
    assert_eq!(frames[0].width(), 2 * 96);
    // Mismatched inputs are errors and write nothing.
    let bad = vec![("a".to_string(), vec![FacePose::default(); 3]), ("b".to_string(), vec![FacePose::default(); 2])];
    let bad_path = dir.path().join("bad.gif");
    let err = write_face_gif(&bad_path, &bad, &[], &opts, &mut |_, _| {}).unwrap_err().to_string();
    assert!(err.contains("'b' has 2 frames"), "{err}");
    assert!(write_face_gif(&bad_path, &columns, &[true], &opts, &mut |_, _| {}).is_err());
    assert!(!bad_path.exists());
}
