//! Round trips, bad inputs and the shared real clips.

use super::*;
use crate::VideoError;
use image::{GrayImage, Rgb, RgbImage};
use inbetween_io::data::with_shared_data;
use std::path::PathBuf;

/// PSNR in dB of two same-size RGB images (infinite when equal).
fn psnr(a: &RgbImage, b: &RgbImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let se: f64 = a.as_raw().iter().zip(b.as_raw()).map(|(&x, &y)| (x as f64 - y as f64).powi(2)).sum();
    let mse = se / a.as_raw().len() as f64;
    10.0 * (255.0f64 * 255.0 / mse).log10()
}

fn psnr_gray(a: &GrayImage, b: &GrayImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let se: f64 = a.as_raw().iter().zip(b.as_raw()).map(|(&x, &y)| (x as f64 - y as f64).powi(2)).sum();
    10.0 * (255.0f64 * 255.0 / (se / a.as_raw().len() as f64)).log10()
}

fn read(path: &Path) -> Result<(Clip, DecodeReport), VideoError> {
    read_clip(path, &ReadOptions::default())
}

fn read_with(path: &Path, decoder: Decoder) -> Result<(Clip, DecodeReport), VideoError> {
    read_clip(path, &ReadOptions { decoder, max_frames: None })
}

/// Moving flat rectangles on a flat background: few colours, no anti-aliasing.
fn flat_clip(frames: usize) -> Clip {
    let imgs = (0..frames)
        .map(|i| {
            let mut c = inbetween_render::Canvas::new(40, 30, [240, 230, 200]);
            c.rect(2.0 + 3.0 * i as f32, 5.0, 8.0, 8.0, [200, 30, 30]);
            c.rect(30.0, 2.0 + 2.0 * i as f32, 5.0, 6.0, [20, 60, 160]);
            c.into_image()
        })
        .collect();
    Clip { frames: imgs, fps: 20.0, source: "flat".into() }
}

#[test]
fn gif_round_trip_is_exact_for_few_colours() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flat.gif");
    let clip = flat_clip(6);
    write_clip(&path, &clip).unwrap();
    let (back, report) = read(&path).unwrap();
    assert_eq!(back.frames, clip.frames);
    assert!((back.fps - 20.0).abs() < 1e-9, "{}", back.fps);
    assert_eq!((report.decoder.as_str(), report.frames), ("gif", 6));
}

#[test]
fn gif_round_trip_of_a_procedural_clip_keeps_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.gif");
    let clip = procedural_clip(ProceduralKind::Mixed, 12, 64, 48, 11);
    write_clip(&path, &clip).unwrap();
    let (back, _) = read(&path).unwrap();
    assert_eq!((back.len(), back.width(), back.height()), (12, 64, 48));
    assert!((back.fps - 25.0).abs() < 1e-9);
    for (i, (a, b)) in clip.frames.iter().zip(&back.frames).enumerate() {
        let p = psnr(a, b);
        assert!(p > 35.0, "frame {i}: {p:.1} dB");
    }
}

#[test]
fn mp4_round_trip_decodes_with_openh264_above_30_db() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.mp4");
    let clip = procedural_clip(ProceduralKind::Mixed, 20, 96, 64, 4);
    write_clip(&path, &clip).unwrap();
    let (back, report) = read_with(&path, Decoder::OpenH264).unwrap();
    assert_eq!((back.len(), back.width(), back.height()), (20, 96, 64));
    assert!((back.fps - 25.0).abs() < 1e-6, "{}", back.fps);
    assert_eq!(report.decoder, "openh264 (bundled)");
    let worst = clip.frames.iter().zip(&back.frames).map(|(a, b)| psnr(a, b)).fold(f64::INFINITY, f64::min);
    println!("mp4 round trip: worst frame PSNR {worst:.1} dB");
    assert!(worst > 30.0, "worst frame {worst:.1} dB");
    // Auto takes openh264 for our own Baseline files, and the frame order survives: each decoded
    // frame is closest to its own source frame.
    let (auto, report) = read(&path).unwrap();
    assert_eq!(report.decoder, "openh264 (bundled)");
    for (i, b) in auto.frames.iter().enumerate().take(16) {
        let best =
            (0..clip.len()).max_by(|&x, &y| psnr(&clip.frames[x], b).total_cmp(&psnr(&clip.frames[y], b))).unwrap();
        assert_eq!(best, i);
    }
}

#[test]
fn mp4_keeps_a_29_97_frame_rate_and_crops_odd_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odd.mp4");
    let mut clip = procedural_clip(ProceduralKind::Pendulum, 5, 35, 23, 1);
    clip.fps = 30000.0 / 1001.0;
    write_clip(&path, &clip).unwrap();
    let (back, _) = read(&path).unwrap();
    assert_eq!((back.len(), back.width(), back.height()), (5, 34, 22));
    assert!((back.fps - 30000.0 / 1001.0).abs() < 1e-3, "{}", back.fps);
    let cropped = image::imageops::crop_imm(&clip.frames[2], 0, 0, 34, 22).to_image();
    assert!(psnr(&cropped, &back.frames[2]) > 30.0);
}

#[test]
fn max_frames_stops_early_for_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let clip = procedural_clip(ProceduralKind::Slider, 8, 32, 24, 2);
    let opts = ReadOptions { decoder: Decoder::Auto, max_frames: Some(3) };
    for name in ["c.gif", "c.mp4"] {
        let path = dir.path().join(name);
        write_clip(&path, &clip).unwrap();
        assert_eq!(read_clip(&path, &opts).unwrap().0.len(), 3, "{name}");
    }
    let folder = dir.path().join("seq");
    for (i, f) in clip.frames.iter().enumerate() {
        inbetween_render::write_png(&folder.join(format!("{i}.png")), f).unwrap();
    }
    let (c, _) = read_clip(&folder, &opts).unwrap();
    assert_eq!(c.frames, clip.frames[..3].to_vec());
}

#[test]
fn folder_frames_come_in_natural_order_and_other_files_are_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let colour = |i: u8| RgbImage::from_pixel(4, 2, Rgb([i * 20, 0, 0]));
    for i in [1u8, 2, 10, 9] {
        inbetween_render::write_png(&dir.path().join(format!("f{i}.png")), &colour(i)).unwrap();
    }
    colour(3).save(dir.path().join("f3.jpg")).unwrap();
    std::fs::write(dir.path().join("notes.txt"), "not a frame").unwrap();
    let (clip, report) = read(dir.path()).unwrap();
    let reds: Vec<u8> = clip.frames.iter().map(|f| f.get_pixel(0, 0).0[0]).collect();
    assert_eq!(reds.len(), 5);
    assert_eq!([reds[0], reds[1], reds[3], reds[4]], [20, 40, 180, 200]);
    assert!(reds[2].abs_diff(60) < 8, "jpeg frame {}", reds[2]);
    assert_eq!(clip.fps, DEFAULT_FPS);
    assert!(report.notes.iter().any(|n| n.contains("assumed")));
}

/// Asserts that `r` is an error whose message names `needle` and all of `words`.
fn assert_err<T: std::fmt::Debug>(r: Result<T, VideoError>, needle: &str, words: &[&str]) -> VideoError {
    let e = r.unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains(needle), "message does not name {needle}: {msg}");
    for w in words {
        assert!(msg.contains(w), "message lacks '{w}': {msg}");
    }
    e
}

#[test]
fn bad_folders_give_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    assert_err(read(&empty), "empty", &["no .png"]);

    let broken = dir.path().join("broken");
    inbetween_render::write_png(&broken.join("a1.png"), &RgbImage::new(4, 4)).unwrap();
    std::fs::write(broken.join("a2.png"), b"this is text, not a PNG").unwrap();
    let e = assert_err(read(&broken), "a2.png", &["frame 1"]);
    assert!(matches!(e, VideoError::Decode { frame: Some(1), .. }));

    let mixed = dir.path().join("mixed");
    inbetween_render::write_png(&mixed.join("a1.png"), &RgbImage::new(4, 4)).unwrap();
    inbetween_render::write_png(&mixed.join("a2.png"), &RgbImage::new(4, 4)).unwrap();
    inbetween_render::write_png(&mixed.join("a3.png"), &RgbImage::new(6, 4)).unwrap();
    assert_err(read(&mixed), "a3.png", &["6x4", "4x4", "frame 2", "a1.png"]);
}

#[test]
fn bad_files_give_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.mp4");
    assert!(matches!(read(&missing), Err(VideoError::Io { .. })));

    let text = dir.path().join("notes.txt");
    std::fs::write(&text, "hello").unwrap();
    assert_err(read(&text), "notes.txt", &["not a clip"]);

    let garbage = dir.path().join("garbage.mp4");
    std::fs::write(&garbage, vec![7u8; 500]).unwrap();
    for decoder in [Decoder::Auto, Decoder::OpenH264] {
        assert!(read_with(&garbage, decoder).unwrap_err().to_string().contains("garbage.mp4"));
    }

    let gif = dir.path().join("bad.gif");
    std::fs::write(&gif, b"GIF89a\x10\x00").unwrap();
    assert_err(read(&gif), "bad.gif", &[]);

    let empty = dir.path().join("empty.mp4");
    std::fs::write(&empty, b"").unwrap();
    assert_err(read(&empty), "empty.mp4", &[]);
}

#[test]
fn truncated_mp4s_give_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.mp4");
    write_clip(&good, &procedural_clip(ProceduralKind::Pendulum, 10, 48, 32, 9)).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    // Our muxer writes mdat first and moov last: cutting anywhere loses the index or samples.
    for keep in [8, 40, bytes.len() / 3, bytes.len() / 2, bytes.len() - 30, bytes.len() - 1] {
        let cut = dir.path().join(format!("cut{keep}.mp4"));
        std::fs::write(&cut, &bytes[..keep]).unwrap();
        for decoder in [Decoder::Auto, Decoder::OpenH264] {
            let r = read_with(&cut, decoder);
            let e = r.expect_err("a truncated file must not read as a clip");
            assert!(e.to_string().contains(&format!("cut{keep}.mp4")), "{e}");
        }
    }
    // A sample whose bytes are corrupted (moov intact): an error or frames, never a panic.
    let mut bad = bytes.clone();
    for b in bad.iter_mut().skip(60).take(200) {
        *b ^= 0x5A;
    }
    let corrupt = dir.path().join("corrupt.mp4");
    std::fs::write(&corrupt, &bad).unwrap();
    if let Err(e) = read_with(&corrupt, Decoder::OpenH264) {
        assert!(e.to_string().contains("corrupt.mp4"), "{e}");
    }
}

#[test]
fn unwritable_clips_give_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let empty = Clip { frames: vec![], fps: 25.0, source: String::new() };
    assert_err(write_clip(&p("e.mp4"), &empty), "e.mp4", &["no frames"]);
    let mixed = Clip { frames: vec![RgbImage::new(4, 4), RgbImage::new(6, 4)], fps: 25.0, source: String::new() };
    assert_err(write_clip(&p("m.gif"), &mixed), "m.gif", &["frame 1"]);
    let slow = Clip { frames: vec![RgbImage::new(4, 4)], fps: 0.0, source: String::new() };
    assert_err(write_clip(&p("s.mp4"), &slow), "s.mp4", &["frame rate"]);
    let ok = flat_clip(2);
    assert_err(write_clip(&p("x.avi"), &ok), "x.avi", &[".mp4 or .gif"]);
    let thin = Clip { frames: vec![RgbImage::new(1, 8)], fps: 25.0, source: String::new() };
    assert_err(write_clip(&p("t.mp4"), &thin), "t.mp4", &["2…65535"]);
    // Nothing half-written was left behind.
    let left: Vec<PathBuf> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn gray_downscaled_bounds_the_longer_side() {
    let clip = procedural_clip(ProceduralKind::Walker, 3, 100, 60, 1);
    let g = clip.gray_downscaled(50);
    assert_eq!(g.len(), 3);
    assert_eq!(g[0].dimensions(), (50, 30));
    assert_eq!(clip.gray_downscaled(500)[0].dimensions(), (100, 60));
}

#[test]
fn real_bigbuckbunny_decodes_132_frames_with_openh264_matching_ffmpegs_frames() {
    with_shared_data("bigbuckbunny.mp4", |data| {
        let video = data.join("video");
        let path = video.join("bigbuckbunny.mp4");
        let t = std::time::Instant::now();
        let (clip, report) = read(&path).unwrap();
        println!(
            "bigbuckbunny: {} frames in {:.2} s via {} {:?}",
            clip.len(),
            t.elapsed().as_secs_f64(),
            report.decoder,
            report.notes
        );
        assert_eq!((clip.len(), clip.width(), clip.height()), (132, 1280, 720));
        assert_eq!(report.decoder, "openh264 (bundled)");
        assert!((clip.fps - 25.0).abs() < 0.01, "{}", clip.fps);
        // bbb_png_seq holds frames 24..47 decoded by ffmpeg and scaled to 320x180: our frames,
        // downscaled the same way (area average, a different filter), must match them, and match
        // the right index better than the neighbours.
        let (seq, _) = read(&video.join("bbb_png_seq")).unwrap();
        let ours = Clip { frames: clip.frames[16..60].to_vec(), fps: 25.0, source: String::new() }.gray_downscaled(320);
        let theirs = seq.gray_downscaled(320);
        for k in [0usize, 10, 23] {
            let own = psnr_gray(&ours[k + 8], &theirs[k]);
            println!("bbb frame {}: {own:.1} dB against ffmpeg's", k + 24);
            assert!(own > 28.0, "frame {}: {own:.1} dB", k + 24);
            for off in [1usize, 3, 7] {
                assert!(own > psnr_gray(&ours[k + 8 + off], &theirs[k]), "frame {} off by {off}", k + 24);
                assert!(own > psnr_gray(&ours[k + 8 - off], &theirs[k]), "frame {} off by -{off}", k + 24);
            }
        }
    });
}

#[test]
fn real_png_sequence_reads_24_frames() {
    with_shared_data("bbb_png_seq", |data| {
        let (clip, report) = read(&data.join("video/bbb_png_seq")).unwrap();
        assert_eq!((clip.len(), clip.width(), clip.height(), report.frames), (24, 320, 180, 24));
        assert!(clip.source.ends_with("bbb_png_seq"));
    });
}

/// Display order of an MP4's samples: the decode-order indices sorted by presentation time
/// (decode time + `ctts` offset).
fn display_order(path: &Path) -> Vec<usize> {
    let bytes = std::fs::read(path).unwrap();
    let mut r = mp4::Mp4Reader::read_header(std::io::Cursor::new(&bytes[..]), bytes.len() as u64).unwrap();
    let n = r.sample_count(1).unwrap();
    let pts: Vec<i64> = (1..=n)
        .map(|i| r.read_sample(1, i).unwrap().map(|s| s.start_time as i64 + s.rendering_offset as i64).unwrap())
        .collect();
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by_key(|&i| pts[i]);
    order
}

/// Mean PSNR of consecutive frames taken in `order`: real display order is the smoothest.
fn smoothness(frames: &[RgbImage], order: &[usize]) -> f64 {
    order.windows(2).map(|w| psnr(&frames[w[0]], &frames[w[1]])).sum::<f64>() / (order.len() - 1) as f64
}

#[test]
fn real_carphone_openh264_measurement_and_auto_path() {
    with_shared_data("carphone_pristine.mp4", |data| {
        let path = data.join("video/carphone_pristine.mp4");
        let probe = probe_openh264(&path).unwrap();
        println!("carphone_pristine, bundled openh264 (no flush per packet), per sample: {}", probe.summary());
        assert_eq!(probe.samples.len(), 120);
        assert_eq!(probe.profile, 100);
        assert!(probe.has_b_frames, "carphone stores B-frames (reordering ctts)");
        assert_eq!((probe.frames(), probe.errors()), (120, 0), "{}", probe.summary());

        let (clip, report) = read(&path).unwrap();
        println!("Auto: {} {:?}", report.decoder, report.notes);
        assert_eq!((clip.len(), clip.width(), clip.height()), (120, 176, 144));
        assert!((clip.fps - 29.97).abs() < 0.01, "{}", clip.fps);
        if ffmpeg_available() {
            assert_eq!(report.decoder, "ffmpeg (subprocess)");
        } else {
            assert_eq!(report.decoder, "openh264 (bundled)");
            assert!(
                report.notes.iter().any(|n| n.contains("B-frames") && n.contains("no ffmpeg")),
                "{:?}",
                report.notes
            );
        }
        // The pictures come out in display order, not decode order: taken in display order they are
        // smoother than if they were still in decode order, and no swap of neighbours helps.
        let shown = smoothness(&clip.frames, &(0..120).collect::<Vec<_>>());
        let as_if_decode_order = smoothness(&clip.frames, &display_order(&path));
        println!("consecutive-frame PSNR: {shown:.2} dB as returned, {as_if_decode_order:.2} dB if in decode order");
        assert!(shown > as_if_decode_order + 1.0);
        let d = |a: usize, b: usize| psnr(&clip.frames[a], &clip.frames[b]);
        let better_swaps =
            (1..117).filter(|&i| d(i - 1, i + 1) + d(i, i + 2) > d(i - 1, i) + d(i + 1, i + 2) + 0.5).count();
        assert_eq!(better_swaps, 0);
    });
}

#[test]
fn openh264_failure_without_ffmpeg_is_unsupported_and_names_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken_sample.mp4");
    write_clip(&path, &procedural_clip(ProceduralKind::Pendulum, 4, 32, 32, 1)).unwrap();
    // Overwrite the first sample's NAL length prefix with a length past the sample's end.
    let mut bytes = std::fs::read(&path).unwrap();
    let r = mp4::Mp4Reader::read_header(std::io::Cursor::new(&bytes[..]), bytes.len() as u64).unwrap();
    let stbl = &r.tracks()[&1].trak.mdia.minf.stbl;
    let first = match (&stbl.co64, &stbl.stco) {
        (Some(c), _) => c.entries[0] as usize,
        (None, Some(c)) => c.entries[0] as usize,
        (None, None) => panic!("no chunk offsets"),
    };
    bytes[first..first + 4].copy_from_slice(&[0x7F, 0xFF, 0xFF, 0xFF]);
    std::fs::write(&path, &bytes).unwrap();
    let e = read_with(&path, Decoder::OpenH264).unwrap_err();
    assert!(matches!(e, VideoError::Decode { frame: Some(0), .. }), "{e:?}");
    assert!(e.to_string().contains("broken_sample.mp4"), "{e}");
    match read(&path) {
        Err(e @ VideoError::Unsupported { .. }) => {
            assert!(!ffmpeg_available());
            let m = e.to_string();
            for w in ["broken_sample.mp4", "frame 0", "apt-get install ffmpeg", "-bf 0"] {
                assert!(m.contains(w), "missing '{w}' in: {m}");
            }
        }
        // ffmpeg cannot read the broken sample either: a decode error naming the file.
        Err(e) => assert!(ffmpeg_available() && e.to_string().contains("broken_sample.mp4"), "{e:?}"),
        Ok(_) => panic!("a broken sample must not decode"),
    }
}

#[test]
fn real_truncated_bigbuckbunny_is_a_decode_error_naming_the_file() {
    with_shared_data("bigbuckbunny.mp4", |data| {
        let bytes = std::fs::read(data.join("video/bigbuckbunny.mp4")).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bbb_cut.mp4");
        std::fs::write(&path, &bytes[..bytes.len() * 3 / 5]).unwrap();
        let e = read_with(&path, Decoder::OpenH264).unwrap_err();
        println!("truncated bigbuckbunny: {e}");
        assert!(matches!(e, VideoError::Decode { .. }), "{e:?}");
        assert!(e.to_string().contains("bbb_cut.mp4"), "{e}");
    });
}

#[test]
fn synth_writes_its_clip_and_a_probe_prints_every_sample() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.gif");
    let job = SynthJob { frames: 6, width: 40, height: 30, ..SynthJob::default() };
    let line = job.write(&out).unwrap();
    assert_eq!(line, format!("wrote {} (6 frames, 40x30, 25 fps)", out.display()));
    let (clip, _) = read(&out).unwrap();
    assert_eq!((clip.len(), clip.width(), clip.height()), (6, 40, 30));
    let probe = OpenH264Probe {
        profile: 66,
        has_b_frames: false,
        samples: vec![SampleOutcome::NoOutput, SampleOutcome::Frame, SampleOutcome::Error("bad".into())],
        flushed: 1,
    };
    assert_eq!(
        probe.to_string(),
        "H.264 profile 66, B-frames no, 3 samples, openh264 decoded 2 pictures\n  sample 0: NoOutput\n  sample 1: \
         Frame\n  sample 2: Error(\"bad\")"
    );
}
