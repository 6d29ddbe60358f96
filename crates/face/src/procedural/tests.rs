//! Tests of the generator: determinism, ranges, labels, bilabial closure, blinks, gaze consistency.

use super::*;
use crate::edit::distances::distances;

fn minute(seed: u64) -> ProceduralClip {
    generate(&ProceduralConfig::with_duration(60.0), seed)
}

#[test]
fn same_seed_same_clip_other_seed_other_clip() {
    let a = generate(&ProceduralConfig::default(), 7);
    let b = generate(&ProceduralConfig::default(), 7);
    let c = generate(&ProceduralConfig::default(), 8);
    assert_eq!(a, b);
    assert_ne!(a.clip.values(), c.clip.values());
    assert_ne!(a.phonemes, c.phonemes);
    let corpus = generate_corpus(3, 4.0, 1);
    assert_eq!(corpus, generate_corpus(3, 4.0, 1));
    assert_eq!(corpus.len(), 3);
    assert_ne!(corpus[0].clip.values(), corpus[1].clip.values());
}

#[test]
fn layout_times_and_ranges() {
    let p = minute(1);
    let clip = &p.clip;
    assert_eq!(clip.num_frames(), 1500);
    assert!(clip.has_head_eye() && clip.extra_names().is_empty());
    assert_eq!(clip.fps(), 25.0);
    for (i, t) in clip.times().iter().enumerate() {
        assert!((t - i as f64 / 25.0).abs() < 1e-12);
    }
    for f in 0..clip.num_frames() {
        assert!(clip.arkit(f).iter().all(|x| (0.0..=1.0).contains(x)), "frame {f}: {:?}", clip.arkit(f));
        assert!(clip.head_eye(f).unwrap().iter().all(|x| x.abs() < 0.6), "frame {f}");
    }
    // Every channel the generator drives moves.
    for name in ["JawOpen", "MouthClose", "EyeBlinkLeft", "MouthFunnel", "BrowInnerUp", "EyeLookInLeft"] {
        let c = clip.channel(arkit_index(name).unwrap());
        let (lo, hi) = c.iter().fold((1.0f32, 0.0f32), |(l, h), x| (l.min(*x), h.max(*x)));
        assert!(hi - lo > 0.05, "{name} spans only {lo}..{hi}");
    }
}

#[test]
fn viseme_labels_cover_every_frame_and_match_the_phonemes() {
    let p = minute(2);
    assert_eq!(p.visemes.len(), p.clip.num_frames());
    assert_eq!(p.phonemes[0].0, 0.0);
    assert!((p.phonemes.last().unwrap().1 - 60.0).abs() < 1e-9);
    for w in p.phonemes.windows(2) {
        assert_eq!(w[0].1, w[1].0, "phonemes are contiguous");
    }
    for (f, v) in p.visemes.iter().enumerate() {
        let t = f as f64 / 25.0;
        let ph = p.phonemes.iter().find(|(s, e, _)| *s <= t && t < *e).expect("a phoneme holds every frame");
        assert_eq!(Viseme::from_arpabet(ph.2), Some(*v), "frame {f} at {t} s: {}", ph.2);
    }
    // Speech and silence both present.
    assert!(p.visemes.contains(&Viseme::Sil) && p.visemes.contains(&Viseme::MBP));
}

#[test]
fn bilabials_close_the_lips_and_vowels_open_them() {
    let (mut mbp, mut open) = (Vec::new(), Vec::new());
    for seed in 0..3 {
        let p = minute(seed);
        for (f, v) in p.visemes.iter().enumerate() {
            let gap = distances(p.clip.arkit(f))[1];
            match v {
                Viseme::MBP => mbp.push(gap),
                Viseme::AaAeAy | Viseme::AoOy | Viseme::EhEy => open.push(gap),
                _ => {}
            }
        }
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    let max_mbp = mbp.iter().fold(f32::MIN, |m, x| m.max(*x));
    println!(
        "centre lip gap: M/B/P mean {:.3} max {max_mbp:.3} ({} frames); open vowels mean {:.3} ({} frames)",
        mean(&mbp),
        mbp.len(),
        mean(&open),
        open.len()
    );
    assert!(mbp.len() > 50 && open.len() > 100);
    // Closed: about 0 (slightly negative where rolled or pressed lips close them further).
    assert!(mean(&mbp).abs() < 0.04, "M/B/P mean gap {}", mean(&mbp));
    assert!(max_mbp < 0.05, "some M/B/P frame opens the lips by {max_mbp}");
    assert!(mean(&open) > 0.25, "open vowels gap {}", mean(&open));
}

#[test]
fn blinks_in_a_minute_are_plausible_and_symmetric() {
    for seed in 0..3 {
        let p = minute(seed);
        let s = calibrate::measure(&p.clip).unwrap();
        assert!((8..=40).contains(&s.blinks), "seed {seed}: {} blinks in 60 s", s.blinks);
        assert!((0.06..0.25).contains(&s.blink_duration_s), "seed {seed}: blinks last {} s", s.blink_duration_s);
        assert!(s.correlation("EyeBlinkLeft", "EyeBlinkRight").unwrap() > 0.8);
    }
    let calm = generate(&ProceduralConfig { blink_rate_per_min: 0.0, ..ProceduralConfig::with_duration(60.0) }, 1);
    assert_eq!(calibrate::measure(&calm.clip).unwrap().blinks, 0, "no blinks asked, none measured");
}

#[test]
fn eye_look_shapes_agree_with_the_eye_angles() {
    let p = minute(4);
    let c = &p.clip;
    let yaw_l = c.channel(c.channel_index("LeftEyeYaw").unwrap());
    let yaw_r = c.channel(c.channel_index("RightEyeYaw").unwrap());
    let pitch = c.channel(c.channel_index("LeftEyePitch").unwrap());
    let corr = |a: &[f32], b: &[f32]| {
        let n = a.len() as f64;
        let (ma, mb) = (a.iter().map(|x| *x as f64).sum::<f64>() / n, b.iter().map(|x| *x as f64).sum::<f64>() / n);
        let cov: f64 = a.iter().zip(b).map(|(x, y)| (*x as f64 - ma) * (*y as f64 - mb)).sum();
        let va: f64 = a.iter().map(|x| (*x as f64 - ma).powi(2)).sum();
        let vb: f64 = b.iter().map(|y| (*y as f64 - mb).powi(2)).sum();
        cov / (va * vb).sqrt()
    };
    let ch = |n: &str| c.channel(arkit_index(n).unwrap());
    // Same signs as on the real captures (yaw > 0: left eye in, right eye out; pitch > 0: down).
    assert!(corr(&yaw_l, &ch("EyeLookInLeft")) > 0.5);
    assert!(corr(&yaw_l, &ch("EyeLookOutLeft")) < -0.3);
    assert!(corr(&yaw_r, &ch("EyeLookOutRight")) > 0.5);
    assert!(corr(&pitch, &ch("EyeLookUpLeft")) < -0.5);
    assert!(corr(&pitch, &ch("EyeLookDownLeft")) > 0.3);
}

#[test]
fn bad_settings_are_reported_by_validate_and_clamped_by_generate() {
    assert!(ProceduralConfig::default().validate().is_ok());
    let bad = ProceduralConfig {
        duration_s: f64::NAN,
        fps: -1.0,
        speech_fraction: 3.0,
        micro_noise: f64::INFINITY,
        ..Default::default()
    };
    let e = bad.validate().unwrap_err().to_string();
    assert!(e.contains("duration_s"), "{e}");
    let p = generate(&bad, 1);
    assert_eq!(p.clip.num_frames(), 250, "NaN duration → default 10 s at default 25 fps");
    let tiny = generate(&ProceduralConfig { duration_s: 1e-6, ..Default::default() }, 1);
    assert_eq!(tiny.clip.num_frames(), 1);
    assert_eq!(tiny.visemes.len(), 1);
    let quiet = generate(&ProceduralConfig { speech_fraction: 0.0, ..Default::default() }, 3);
    assert!(quiet.visemes.iter().all(|v| *v == Viseme::Sil));
    assert_eq!(quiet.phonemes.len(), 1);
    let fast = generate(&ProceduralConfig { fps: 60.0, ..Default::default() }, 3);
    assert_eq!(fast.clip.num_frames(), 600);
}

#[test]
fn a_written_clip_reads_back_with_its_phoneme_timing_beside_it() {
    let p = generate(&ProceduralConfig { duration_s: 3.0, ..Default::default() }, 5);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("take.csv");
    let line = p.write(&out, true).unwrap();
    let timing = dir.path().join("take.phonemes.csv");
    assert_eq!(
        line,
        format!("wrote {} (75 frames at 25 fps) and its phoneme timing {}", out.display(), timing.display())
    );
    let back = crate::data::read_clip(&out).unwrap();
    assert_eq!(back.num_frames(), p.clip.num_frames());
    let spans = crate::visemes::read_phoneme_timing(&timing).unwrap();
    assert_eq!(spans.len(), p.phonemes.len());
    assert_eq!(spans[0].phoneme, p.phonemes[0].2);
    // A folder that cannot be made leaves neither file.
    let blocked = dir.path().join("take.csv").join("x.csv");
    assert!(p.write(&blocked, false).is_err());
}
