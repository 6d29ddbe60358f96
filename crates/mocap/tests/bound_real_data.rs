//! The error-bounded search's bound holds on what is played back (skipped when the corpus is
//! absent): on every CMU take at 1 cm, the clip rebuilt along the engine's Hermite curve and along
//! a DCC's quaternion and Euler Bezier curves stays within 1 cm on every joint of every frame, and the keys
//! this costs beside the spherical model's plan (which bounds the model, not the rebuild) are
//! printed.

use inbetween_core::cancel::Cancel;
use inbetween_io::data::with_shared_data;
use inbetween_io::Progress;
use inbetween_mocap::metrics::{ErrorMeasure, SegmentTable};
use inbetween_mocap::select::error_bounded;
use inbetween_mocap::select::job::max_gap_frames;
use inbetween_mocap::{PreparedClip, ReconstructJob, RotationCurve, SelectJob, Selector};

#[test]
fn a_bound_in_cm_holds_on_the_rebuilt_clip_along_either_curve_on_every_take() {
    with_shared_data("error-bound real-data test", |dir| {
        let corpus = inbetween_mocap::corpus::load(&dir, None).unwrap();
        assert!(!corpus.clips.is_empty());
        for (clip, unit) in corpus.clips.iter().zip(&corpus.units) {
            // Two seconds of each take keep the test short on two cores.
            let n = clip.motion.num_frames().min((2.0 / clip.motion.frame_time) as usize);
            let motion = clip.motion.crop(0, n).unwrap();
            let prepared = PreparedClip::new(motion, unit.clone()).unwrap();
            let gap = max_gap_frames(0.5, prepared.motion.frame_time).min(n - 1);
            let planned =
                error_bounded(&SegmentTable::bounded(&prepared.rep, gap, 1.0), 1.0, ErrorMeasure::Angle).unwrap();
            let planned_rebuilt = ReconstructJob { keys: planned.frames().to_vec(), ..ReconstructJob::default() }
                .run(&prepared, &Cancel::new(), &Progress::hidden())
                .unwrap();
            let mut line = format!(
                "{}: {n} frames; spherical plan {} keys, rebuilt max {:.3} cm",
                clip.name,
                planned.len(),
                planned_rebuilt.error.max_cm
            );
            for curve in [RotationCurve::Hermite, RotationCurve::QuaternionBezier, RotationCurve::EulerBezier] {
                let job =
                    SelectJob { method: Selector::ErrorBounded, bound_cm: Some(1.0), curve, ..SelectJob::default() };
                let r = job.run(&prepared, &Cancel::new(), &Progress::hidden()).unwrap();
                let max = r.reconstruction.error.max_cm;
                assert!(max <= 1.0 + 1e-9, "{} along {}: {max} cm", clip.name, curve.name());
                line += &format!("; {} {} keys, max {max:.3} cm", curve.name(), r.keys().len());
            }
            println!("{line}");
        }
    });
}
