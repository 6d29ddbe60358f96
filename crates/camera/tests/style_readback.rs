//! Which named style a reference camera reads as (§4.1's extractor on a camera's motion): a camera
//! filmed by each behaviour over a scene (the dataset's own filming, no keys) and turned into a
//! reference clip through its world poses, as Blender's and Python's reference cameras are. Its
//! style code is nearest its own behaviour's for direct, side and orbit on three unseen scenes;
//! relative reads as side on two of them (their codes lie about 1.0 apart, against 4 to 8 for the
//! other pairs).

use inbetween_camera::dataset::{film, Behaviour, BehaviourParams, Scene, BEHAVIOURS};
use inbetween_camera::infer::ReferenceClip;
use inbetween_camera::toric::{to_pose, Lens};
use inbetween_camera::weights;
use rand::SeedableRng;
use std::path::Path;

#[test]
fn a_reference_camera_reads_as_the_behaviour_that_filmed_it() {
    let w = weights::committed().unwrap();
    let lens = Lens::default();
    let dist = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>().sqrt();
    let mut relative_right = 0;
    for seed in [21u64, 22, 23] {
        let scene = Scene::procedural(seed, 301, 30.0);
        let params = BehaviourParams::sample(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
        for &b in BEHAVIOURS.iter() {
            let poses: Vec<_> = film(&scene, 0, 1, true, b, &params, &lens)
                .iter()
                .enumerate()
                .map(|(f, t)| {
                    let (a, c) = (scene.characters[0].frame(f), scene.characters[1].frame(f));
                    to_pose(t, a.target(), c.target(), &lens).unwrap()
                })
                .collect();
            let code =
                ReferenceClip::from_poses(&scene, &poses, &lens).unwrap().style(&w.model, Path::new("r")).unwrap();
            let d: Vec<(Behaviour, f64)> =
                BEHAVIOURS.iter().map(|&o| (o, dist(&code, &w.style(o).unwrap().code))).collect();
            let nearest = d.iter().min_by(|x, y| x.1.total_cmp(&y.1)).unwrap().0;
            println!("scene {seed}, filmed {}: nearest {} ({d:.2?})", b.name(), nearest.name());
            match b {
                Behaviour::Relative => relative_right += usize::from(nearest == b),
                _ => assert_eq!(nearest, b, "scene {seed}: {d:?}"),
            }
        }
    }
    // Relative and side are the two codes the extractor barely separates.
    assert!(relative_right >= 1, "relative never read as relative");
}
