//! The version 4 runtime layout on every take of the corpus at ACL's protocol (skipped when the
//! corpus is absent): the runtime sampler returns exactly the encoder's values on every frame,
//! the bound holds on the decoded clip, and damaged files are refused with a message.

use inbetween_io::data::with_shared_data;
use inbetween_mocap::bench::acl::{takes, AclConfig};
use inbetween_mocap::codec::v3_encode::{compress_in, vertex_errors, Format, Options};
use inbetween_mocap::codec::{read, v4};

#[test]
fn every_take_samples_the_encoders_values_on_every_frame_within_the_bound() {
    with_shared_data("codec v4 real-data test", |dir| {
        let corpus = inbetween_mocap::corpus::load(&dir, None).unwrap();
        let all = takes(&corpus.clips, &corpus.units, AclConfig::default().fps).unwrap();
        assert!(!all.is_empty());
        for t in &all {
            let name = &t.name;
            let c = compress_in(&t.motion, t.unit.clone(), &Options::with_format(0.05, Format::V4)).unwrap();
            assert!(c.max_error_cm <= 0.05, "{name}: {} cm", c.max_error_cm);
            let clip = v4::Clip::open(&c.bytes).unwrap();
            let n = clip.num_joints();
            let mut ctx = v4::Context::new(&clip);
            let (mut rot, mut tr) = (vec![[0f32; 4]; n], vec![[0f32; 3]; n]);
            let mut vals = Vec::new();
            for f in 0..clip.num_frames() {
                // The frame's values: bit for bit the encoder's.
                let want = v4::encoder_frame(&c.quantised, f);
                clip.frame_values(f, &mut vals);
                assert_eq!(vals, want, "{name} frame {f}");
                // Sampled at the frame's time: within 1e-6 (the time may land a hair before it).
                clip.sample(&mut ctx, f as f64 * clip.frame_time(), &mut rot, &mut tr).unwrap();
                for j in 0..n {
                    let q = v4::exp_map([want[6 * j], want[6 * j + 1], want[6 * j + 2]]);
                    // q and −q are the same rotation (the slerp's shortest path may flip it).
                    let d = [1.0f32, -1.0]
                        .map(|s| (0..4).map(|k| (rot[j][k] - s * q[k]).abs()).fold(0.0, f32::max))
                        .into_iter()
                        .fold(f32::INFINITY, f32::min);
                    assert!(d < 1e-6, "{name} frame {f} joint {j}: {:?} vs {q:?}", rot[j]);
                    let scale = 1.0 + want[6 * j + 3..6 * j + 6].iter().map(|x| x.abs()).fold(0.0, f32::max);
                    for k in 0..3 {
                        assert!((tr[j][k] - want[6 * j + 3 + k]).abs() <= 1e-6 * scale, "{name} frame {f} joint {j}");
                    }
                }
            }
            // Oracle: the core's forward kinematics on the decoded BVH channels.
            let decoded = read(&c.bytes).unwrap().motion().unwrap();
            let cm = t.unit.cm_per_unit();
            let max = vertex_errors(&t.motion, &decoded, cm, 3.0).into_iter().fold(0.0, f64::max) * cm;
            assert!(max <= 0.05 * (1.0 + 1e-6), "{name}: {max} cm");
        }
    });
}
