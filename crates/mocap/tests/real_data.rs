//! Checks on the real CMU clips of the shared corpus (skipped when it is absent).

use inbetween_io::data::with_shared_data;
use inbetween_mocap::bench::{clip_windows, evaluate, Method, Protocol};
use inbetween_mocap::codec::{compress, decode, Budget};

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

#[test]
fn cmu_clip_compresses_within_its_bound() {
    with_shared_data("mocap codec real-data test", |dir| {
        let m = inbetween_io::read_bvh(&dir.join("mocap/cmu/cgspeed/131_03.bvh")).unwrap();
        let m = m.crop(1, 241).unwrap(); // two seconds after the T-pose keep the test fast
        let c = compress(&m, Budget::MaxErrorCm(1.0), 60).unwrap();
        assert!(c.planned.max_cm <= 1.0 + 1e-9);
        assert!(c.decoded_max_cm < 1.1, "{}", c.decoded_max_cm);
        assert!(c.bytes.len() * 3 < inbetween_mocap::codec::raw_bytes(&m), "{} bytes", c.bytes.len());
        assert_eq!(decode(&c.bytes).unwrap().reconstruct().unwrap().num_frames(), 240);
    });
}
