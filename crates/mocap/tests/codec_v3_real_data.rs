//! The version 3 codec on real CMU takes at ACL's protocol (skipped when the corpus is absent).

use inbetween_io::data::with_shared_data;
use inbetween_mocap::bench::acl::{takes, AclConfig};
use inbetween_mocap::codec::v3_encode::{compress_in, vertex_errors, Options};
use inbetween_mocap::codec::{read, v3};

#[test]
fn cmu_takes_at_24_fps_keep_the_bound_in_the_decoded_file_and_seek() {
    with_shared_data("codec v3 real-data test", |dir| {
        let corpus = inbetween_mocap::corpus::load(&dir, None).unwrap();
        let all = takes(&corpus.clips, &corpus.units, AclConfig::default().fps).unwrap();
        for name in ["131_03", "11_01", "02_03"] {
            let Some(t) = all.iter().find(|t| t.name == name) else {
                println!("skipped: no take {name} in {}", dir.display());
                continue;
            };
            let c = compress_in(&t.motion, t.unit.clone(), &Options::bound(0.05)).unwrap();
            let decoded = read(&c.bytes).unwrap().motion().unwrap();
            let cm = t.unit.cm_per_unit();
            // Oracle: the core's forward kinematics on the decoded BVH channels.
            let max = vertex_errors(&t.motion, &decoded, cm, 3.0).into_iter().fold(0.0, f64::max) * cm;
            assert!(max <= 0.05 * (1.0 + 1e-6), "{name}: {max} cm");
            assert!(c.max_error_cm > 0.03, "{name}: the bound is spent, {} cm", c.max_error_cm);
            let ratio = t.raw_bytes() as f64 / c.bytes.len() as f64;
            assert!(ratio > 5.0, "{name}: ratio {ratio}");
            // One pose at a time from the file equals the whole decode at frame times.
            let file = v3::File::open(&c.bytes).unwrap();
            let (mut pose, mut sc) = (inbetween_core::Pose::rest(&file.header.skeleton), v3::Scratch::default());
            for f in [0, 17, t.motion.num_frames() / 2, t.motion.num_frames() - 1] {
                file.pose_at(f as f64 * file.header.frame_time, &mut pose, &mut sc).unwrap();
                let want = c.quantised.pose(f);
                for j in 0..pose.rotations.len() {
                    assert!(
                        inbetween_core::rotation::angle_between(pose.rotations[j], want.rotations[j]) < 1e-9,
                        "{name} frame {f} joint {j}"
                    );
                }
            }
        }
    });
}

/// Absent data is a skip, not a failure.
#[test]
fn absent_data_is_reported_as_a_skip() {
    let dir = std::path::Path::new("/tmp/no-such-data-xyz");
    let e = inbetween_mocap::bench::acl::measure(
        &AclConfig { data: Some(dir.to_path_buf()), ..Default::default() },
        &inbetween_io::Progress::hidden(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("/tmp/no-such-data-xyz"), "{e}");
}
