//! Table 3's CPU time of an edit: the generator in plain Rust ([`GeneratorRuntime`]) on seeded weights,
//! with the directions on two threads and on one.

use inbetween_io::report::seconds_per_call;
use inbetween_nn::bench::BenchRow;

use crate::edit::ConstraintKind;
use crate::model::generator::GeneratorConfig;
use crate::model::runtime::GeneratorRuntime;

/// Milliseconds per generator run of a `frames`-frame edit (keyframe network, `d_hidden` units,
/// `layers` layers, seeded weights), one row with the directions on two threads and one on one:
/// the rows for a `bench` table (Table 3's CPU time of an edit covers this plus assembling the input).
pub fn edit_time_rows(d_hidden: usize, layers: usize, frames: usize, repeats: usize) -> Vec<BenchRow> {
    let config = GeneratorConfig { kind: ConstraintKind::Keyframes, d_hidden, layers, dropout: 0.0 };
    let device = inbetween_nn::backend::cpu();
    let g = inbetween_nn::backend::seeded_module(&device, 0, |d| config.init(d));
    let mut rt = GeneratorRuntime::from_generator(&g);
    let d = rt.d_input();
    let input: Vec<f32> = (0..frames * d).map(|i| ((i as f32) * 0.37).sin().max(0.0)).collect();
    [true, false]
        .into_iter()
        .map(|parallel| {
            rt.parallel = parallel;
            let secs = seconds_per_call(1, repeats, || {
                std::hint::black_box(rt.run(&input, frames));
            });
            BenchRow {
                name: format!("face generator runtime, {frames}-frame edit"),
                value: secs * 1e3,
                unit: "ms".into(),
                detail: format!(
                    "{layers}×BiLSTM {d_hidden} + dense, input {d}, plain Rust, {}",
                    if parallel { "directions on 2 threads" } else { "1 thread" }
                ),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_time_rows_are_measured() {
        let rows = edit_time_rows(8, 2, 12, 1);
        assert_eq!(rows.len(), 2);
        assert!(rows.iter().all(|r| r.value.is_finite() && r.value > 0.0 && r.unit == "ms"), "{rows:?}");
    }

    #[test]
    #[ignore = "measurement, run by hand"]
    fn edit_time_full_size() {
        for row in edit_time_rows(128, 2, 100, 50) {
            println!("{}: {:.3} {} ({})", row.name, row.value, row.unit, row.detail);
        }
    }
}
