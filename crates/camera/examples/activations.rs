//! Activation statistics of the generator along one rollout: `-- WEIGHTS.bpk|committed`.
//! Prints H's (h, c) ranges, then per step the LSTM's |h|, |c| maxima, the share of active ReLUs
//! in enc1/enc2/dec1 and the size of the predicted correction.
use inbetween_camera::dataset::{Dataset, DOWNSAMPLE};
use inbetween_camera::infer::{key_vector, FastModel, Rollout};
use inbetween_camera::model::{MAP_FRAMES, STYLE_STEPS};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a = std::env::args().nth(1).unwrap_or_else(|| "committed".into());
    let m = if a == "committed" { FastModel::committed()? } else { FastModel::load(std::path::Path::new(&a))? };
    let data = Dataset::generate(9001, 1, 1500);
    let mx = |v: &[f32]| v.iter().map(|x| x.abs()).fold(0.0f32, f32::max);
    let active = |v: &[f32]| v.iter().filter(|v| **v > 0.0).count();
    for s in data.sequences.iter().step_by(3).take(3) {
        let (c, x) = s.encoded(DOWNSAMPLE);
        let z = m.extract_style(&c[..STYLE_STEPS], &x[..STYLE_STEPS]);
        let frames: [[f32; 6]; MAP_FRAMES] = std::array::from_fn(|i| x[10 + i]);
        let mut r = Rollout::mapped(&m, &z, &frames);
        println!("{:?}: z {z:.3?}  H: max|h| {:.2} max|c| {:.2}", s.behaviour, mx(&r.state().h), mx(&r.state().c));
        let hd = m.config.hidden;
        let key_t = 14 + 20;
        let key = key_vector(&x[key_t], &c[key_t]);
        for t in 15..=key_t {
            let next = r.step(&c[t], &key, (key_t - t) * DOWNSAMPLE);
            // A leaky ReLU keeps the sign, so counting positives after it counts active units.
            let (e1, e2, d1, delta) = r.scratch().layers(&m);
            if t % 4 == 3 || t == key_t {
                let norm = delta.iter().map(|v| v * v).sum::<f32>().sqrt();
                println!(
                    "  t{t}: |h|max {:.2} |c|max {:.2} active enc1 {} enc2 {} dec1 {} /{hd}  |Δ| {norm:.4}  θ {:.2} gt {:.2}",
                    mx(&r.state().h),
                    mx(&r.state().c),
                    active(e1),
                    active(e2),
                    active(d1),
                    next[4],
                    x[t][4]
                );
            }
        }
    }
    Ok(())
}
