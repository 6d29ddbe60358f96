//! Checks on the real CMU clips of the shared corpus (skipped when it is absent).

use inbetween_io::data::with_shared_data;
use inbetween_mocap::bench::{clip_windows, evaluate, Method, Protocol};
use inbetween_mocap::codec::{compress_in, decode, raw_bytes, Budget};

#[test]
fn every_cmu_take_filters_to_the_major_joints_and_optimal_never_loses() {
    with_shared_data("mocap real-data test", |dir| {
        let clips = inbetween_mocap::corpus::cmu_corpus(&dir).unwrap();
        for clip in &clips {
            let windows = clip_windows(clip, &Protocol::paper()).unwrap();
            // 23 joints on CMU skeletons (and CC rigs under an RL_BoneRoot), 22 on plain CC rigs.
            assert!(windows.iter().all(|w| w.rep.num_joints == 22 || w.rep.num_joints == 23), "{}", clip.name);
        }
        for name in ["01_01", "11_01", "05_02"] {
            let clip = clips.iter().find(|c| c.name == name).unwrap();
            let windows = clip_windows(clip, &Protocol::paper()).unwrap();
            assert!(!windows.is_empty(), "{name}");
            let few = &windows[..windows.len().min(2)];
            let rows = evaluate("t", few, &[Method::Uc, Method::Greedy, Method::Optimal], &[5], 0, None).unwrap();
            let opt = rows.iter().find(|r| r.method == Method::Optimal).unwrap().mean_angle_error;
            for r in &rows {
                assert!(
                    opt <= r.mean_angle_error + 1e-12,
                    "{name}: optimal {opt} vs {:?} {}",
                    r.method,
                    r.mean_angle_error
                );
            }
        }
    });
}

/// Every 60-frame window of the corpus (the bench's 116): the fast optimum picks the keys of the
/// programme over the full segment table, with the same total to the bit.
#[test]
fn fast_optimum_equals_the_full_table_programme_on_every_cmu_window() {
    use inbetween_mocap::select::optimal;
    use inbetween_mocap::select::optimal::optimal_spherical_with_total;
    use inbetween_mocap::{ErrorMeasure, SegmentTable};
    with_shared_data("mocap fast-optimum real-data test", |dir| {
        let corpus = inbetween_mocap::corpus::load(&dir, None).unwrap();
        let mut windows = 0;
        for clip in &corpus.clips {
            for w in clip_windows(clip, &Protocol::paper()).unwrap() {
                let table = SegmentTable::full_serial(&w.rep);
                for k in [5, 10, 15] {
                    let want = optimal(&table, k, ErrorMeasure::Angle).unwrap();
                    let (got, total) = optimal_spherical_with_total(&w.rep, k, ErrorMeasure::Angle).unwrap();
                    assert_eq!(got, want, "{} window at {}, K={k}", w.clip, w.start);
                    assert_eq!(total.to_bits(), table.total(&want).unwrap().angle_sum.to_bits(), "{} K={k}", w.clip);
                }
                windows += 1;
            }
        }
        assert!(windows >= 100, "{windows} windows");
    });
}

/// Every take of the corpus (its first 2 s after the T-pose frame, to keep CI fast), at 1 cm and
/// 0.1 cm: the decoded file keeps the bound, quantisation included, in each clip's own unit.
#[test]
fn every_cmu_take_compresses_within_its_bound_after_decoding() {
    with_shared_data("mocap codec real-data test", |dir| {
        let corpus = inbetween_mocap::corpus::load(&dir, None).unwrap();
        let mut worst = [0.0f64; 2];
        for (clip, unit) in corpus.clips.iter().zip(&corpus.units) {
            let n = clip.motion.num_frames();
            let two_s = (2.0 / clip.motion.frame_time).round() as usize;
            let m = clip.motion.crop(1, n.min(1 + two_s)).unwrap();
            let gap = ((0.5 / m.frame_time).round() as usize).max(1);
            for (i, bound) in [1.0, 0.1].into_iter().enumerate() {
                let c = compress_in(&m, unit.clone(), Budget::MaxErrorCm(bound), gap).unwrap();
                assert!(c.decoded_max_cm <= bound, "{} at {bound} cm: decoded max {} cm", clip.name, c.decoded_max_cm);
                assert_eq!(decode(&c.bytes).unwrap().reconstruct().unwrap().num_frames(), m.num_frames());
                if bound == 1.0 {
                    assert!(c.bytes.len() < raw_bytes(&m), "{}: {} bytes", clip.name, c.bytes.len());
                }
                worst[i] = worst[i].max(c.decoded_max_cm);
            }
        }
        println!(
            "{} takes: decoded max error {:.4} cm at 1 cm, {:.4} cm at 0.1 cm",
            corpus.clips.len(),
            worst[0],
            worst[1]
        );
    });
}
