//! Activation statistics of the generator along one rollout: `-- WEIGHTS.bpk|committed`.
//! Prints H's (h, c) ranges, then per step the LSTM's |h|, |c| maxima, the share of active ReLUs
//! in enc1/enc2/dec1 and the size of the predicted correction.
use inbetween_camera::dataset::{Dataset, DOWNSAMPLE};
use inbetween_camera::infer::FastModel;
use inbetween_camera::model::{MAP_FRAMES, STYLE_STEPS};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a = std::env::args().nth(1).unwrap_or_else(|| "committed".into());
    let m = if a == "committed" { FastModel::committed()? } else { FastModel::load(std::path::Path::new(&a))? };
    let data = Dataset::generate(9001, 1, 1500);
    for s in data.sequences.iter().step_by(3).take(3) {
        let (c, x) = s.encoded(DOWNSAMPLE);
        let z = m.extract_style(&c[..STYLE_STEPS], &x[..STYLE_STEPS]);
        let frames: [[f32; 6]; MAP_FRAMES] = std::array::from_fn(|i| x[10 + i]);
        let mut st = m.map_state(&z, &frames);
        let mx = |v: &[f32]| v.iter().map(|x| x.abs()).fold(0.0f32, f32::max);
        println!("{:?}: z {z:.3?}  H: max|h| {:.2} max|c| {:.2}", s.behaviour, mx(&st.h), mx(&st.c));
        let hd = m.config.hidden;
        let mut prev = x[14];
        let key_t = 14 + 20;
        for t in 15..=key_t {
            let mut inp = z.clone();
            inp.extend_from_slice(&prev);
            inp.extend_from_slice(&c[t]);
            inp.extend_from_slice(&x[key_t]);
            inp.extend_from_slice(&c[key_t]);
            let tta = (key_t - t) * DOWNSAMPLE;
            inp.extend_from_slice(&m.config.tta().values(tta as f32));
            let mut e1 = vec![0.0; hd];
            m.enc1.forward(&inp, &mut e1, 1);
            let a1 = e1.iter().filter(|v| **v > 0.0).count();
            e1.iter_mut().for_each(|v| if *v < 0.0 { *v *= m.config.leaky_slope });
            let mut e2 = vec![0.0; hd];
            m.enc2.forward(&e1, &mut e2, 1);
            let a2 = e2.iter().filter(|v| **v > 0.0).count();
            e2.iter_mut().for_each(|v| if *v < 0.0 { *v *= m.config.leaky_slope });
            m.gen_lstm.step(&e2, &mut st, 1);
            let mut d1 = vec![0.0; hd];
            m.dec1.forward(&st.h, &mut d1, 1);
            let a3 = d1.iter().filter(|v| **v > 0.0).count();
            d1.iter_mut().for_each(|v| if *v < 0.0 { *v *= m.config.leaky_slope });
            let mut d2 = vec![0.0; 6];
            m.dec2.forward(&d1, &mut d2, 1);
            let w = m.config.arrival_weight(tta as f32);
            let next: [f32; 6] = std::array::from_fn(|k| prev[k] + w * (x[key_t][k] - prev[k]) + d2[k]);
            if t % 4 == 3 || t == key_t {
                println!("  t{t}: |h|max {:.2} |c|max {:.2} active enc1 {a1} enc2 {a2} dec1 {a3} /{hd}  |Δ| {:.4}  θ {:.2} gt {:.2}", mx(&st.h), mx(&st.c), d2.iter().map(|v| v * v).sum::<f32>().sqrt(), next[4], x[t][4]);
            }
            prev = next;
        }
    }
    Ok(())
}
