use super::*;
use inbetween_core::procedural::{gait, GaitParams, CM_PER_CMU_UNIT};
use inbetween_core::units::{scale_motion, CANDIDATES};

fn clips() -> Vec<Motion> {
    let mut walk = GaitParams::walk();
    walk.frames = 60;
    let mut run = GaitParams::run();
    run.frames = 90;
    run.fps = 60.0;
    let mut turn = GaitParams::walk();
    turn.frames = 80;
    turn.turn_rate = 2.5;
    vec![gait(&walk), gait(&run), gait(&turn)]
}

#[test]
fn the_decoded_file_keeps_every_bound_and_k_mode_uses_k_keys() {
    for (i, m) in clips().iter().enumerate() {
        let mut last_keys = 0;
        for bound in [2.0, 1.0, 0.5, 0.1, 0.05] {
            let c = compress(m, Budget::MaxErrorCm(bound), 30).unwrap();
            assert!(c.decoded_max_cm <= bound, "clip {i}, {bound} cm: decoded max {} cm", c.decoded_max_cm);
            assert!(c.planned.max_cm <= bound);
            // Tight enough to matter: the bound is approached, not met by keying everything.
            assert!(c.decoded_max_cm > 0.3 * bound, "clip {i}, {bound} cm: only {} cm", c.decoded_max_cm);
            assert!(c.keys.len() < m.num_frames() / 2 || bound < 0.1, "clip {i}, {bound} cm: {} keys", c.keys.len());
            assert!(c.keys.len() >= last_keys, "a tighter bound never needs fewer keys");
            last_keys = c.keys.len();
            assert_eq!(c.unit.unit, LengthUnit::Cmu, "{}", c.unit.reason);
        }
    }
    let m = &clips()[0];
    let k = compress(m, Budget::Keys(6), 10).unwrap();
    assert_eq!(k.keys.len(), 6);
    assert_eq!(decode(&k.bytes).unwrap().key_frames, k.keys.frames());
    let k10 = compress(m, Budget::Keys(10), 10).unwrap();
    assert!(k10.decoded_mean_cm < k.decoded_mean_cm, "{} vs {}", k10.decoded_mean_cm, k.decoded_mean_cm);
    assert!(compress(m, Budget::MaxErrorCm(f64::NAN), 10).is_err());
    let e = compress(m, Budget::MaxErrorCm(1e-6), 10).unwrap_err().to_string();
    assert!(e.contains("below what the .ibk format stores"), "{e}");
}

#[test]
fn the_same_clip_in_any_unit_gives_the_same_keys_and_cm_errors() {
    let m = &clips()[1];
    let reference = compress(m, Budget::MaxErrorCm(0.5), 30).unwrap();
    for unit in CANDIDATES.into_iter().chain([LengthUnit::CmPerUnit(0.37)]) {
        let scaled = scale_motion(m, CM_PER_CMU_UNIT / unit.cm_per_unit());
        let guess = LengthUnit::infer(&scaled.skeleton);
        let c = match unit {
            LengthUnit::CmPerUnit(_) => compress_in(&scaled, UnitChoice::given(unit), Budget::MaxErrorCm(0.5), 30),
            _ => {
                assert_eq!(guess.unit, unit, "{}", guess.reason);
                compress(&scaled, Budget::MaxErrorCm(0.5), 30)
            }
        }
        .unwrap();
        assert_eq!(c.keys, reference.keys, "{unit}");
        let rel = |a: f64, b: f64| (a - b).abs() / b;
        assert!(
            rel(c.decoded_max_cm, reference.decoded_max_cm) < 1e-4,
            "{unit}: {} vs {}",
            c.decoded_max_cm,
            reference.decoded_max_cm
        );
        assert!(rel(c.decoded_mean_cm, reference.decoded_mean_cm) < 1e-4, "{unit}");
    }
    // Read in the wrong unit, the same clip would be held to a bound 5.6 times too loose.
    let as_cm = compress_in(m, UnitChoice::given(LengthUnit::Centimetre), Budget::MaxErrorCm(0.5), 30).unwrap();
    assert!(as_cm.keys.len() < reference.keys.len());
}

#[test]
fn lengths_parse_with_units() {
    assert_eq!(parse_length_cm("10mm").unwrap(), 1.0);
    assert_eq!(parse_length_cm("0.5 cm").unwrap(), 0.5);
    assert_eq!(parse_length_cm("0.01m").unwrap(), 1.0);
    assert!(parse_length_cm("fast").is_err());
    assert!(parse_length_cm("-1cm").is_err());
    // A number without a unit is refused, naming the units it could have meant.
    let e = parse_length_cm("1e9").unwrap_err().to_string();
    assert!(e.contains("'1e9' has no length unit") && e.contains("1e9cm"), "{e}");
}

#[test]
fn decompress_job_rebuilds_every_frame_and_counts_what_the_file_stores() {
    use crate::codec::job::{CompressJob, DecompressJob};
    use inbetween_core::cancel::Cancel;
    use inbetween_io::Progress;
    let m = inbetween_core::procedural::gait(&inbetween_core::procedural::GaitParams {
        frames: 40,
        ..inbetween_core::procedural::GaitParams::walk()
    });
    let unit = inbetween_core::units::LengthUnit::infer(&m.skeleton);
    for (budget, stored) in [(Budget::Keys(6), 6), (Budget::MaxErrorCm(1.0), 40)] {
        let job = CompressJob { budget, version: None, segment_len: None, max_gap: 15, unit: unit.clone() };
        let bytes = job.run(&m).unwrap().bytes().to_vec();
        let r = DecompressJob.run(&bytes, &Cancel::new(), &Progress::hidden()).unwrap();
        assert_eq!((r.stored_poses, r.frames, r.joints), (stored, 40, m.skeleton.len()), "{budget:?}");
        assert_eq!(r.motion.num_frames(), 40);
        assert!(r.to_string().contains("→ 40 frames at 30.0 fps"), "{r}");
    }
    let err = DecompressJob.run(b"not an ibk file", &Cancel::new(), &Progress::hidden()).unwrap_err();
    assert!(!err.to_string().is_empty());
}

#[test]
fn preview_job_draws_from_keys_or_a_matching_file_and_refuses_another_clips_file() {
    use crate::codec::job::{CompressJob, DecompressJob, PreviewJob, Rebuilt};
    use inbetween_core::cancel::Cancel;
    use inbetween_io::Progress;
    let walk = |frames| gait(&GaitParams { frames, ..GaitParams::walk() });
    let (m, dir) = (walk(40), tempfile::tempdir().unwrap());
    let (name, out) = (std::path::Path::new("walk.bvh"), dir.path().join("p.gif"));
    let keys = CompressJob::for_motion(&m, Budget::Keys(6));
    let unit = keys.unit.clone();
    let job = |rebuilt| PreviewJob { original: &m, name, unit: unit.clone(), rebuilt, out: &out };
    let r6 = job(Rebuilt::Keys(keys)).run().unwrap();
    let r = &r6;
    assert_eq!(r.keys, 6);
    assert!(r.error.max_cm > 0.0 && r.error.mean_cm <= r.error.max_cm, "{r}");
    assert!(out.is_file() && r.to_string().ends_with(&format!("; wrote {}", out.display())), "{r}");
    // A file of this clip (every frame within 1 cm) draws its own reconstruction.
    let file = |m: &Motion| {
        let bytes = CompressJob::for_motion(m, Budget::MaxErrorCm(1.0)).run(m).unwrap().bytes().to_vec();
        DecompressJob.run(&bytes, &Cancel::new(), &Progress::hidden()).unwrap()
    };
    let ibk = std::path::Path::new("walk.ibk");
    let r = job(Rebuilt::File(ibk, Box::new(file(&m)))).run().unwrap();
    assert_eq!(r.keys, 40);
    // The file bounds the virtual vertices at 1 cm; a joint may move a little more (0.95 cm measured).
    assert!(r.error.max_cm < 1.5 && r.error.max_cm != r6.error.max_cm, "{r} vs {r6}");
    // Another clip's file is refused, naming both files.
    let e = job(Rebuilt::File(ibk, Box::new(file(&walk(30))))).run().unwrap_err().to_string();
    assert!(e.contains("walk.ibk does not match walk.bvh"), "{e}");
}
