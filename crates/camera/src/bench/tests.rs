use super::*;
use crate::infer::Cam;

#[test]
fn report_writes_the_committed_csv_layout_json_and_charts() {
    let progress = Progress::hidden();
    let r = measure(&tiny_model(), &tiny_config(), &progress);
    assert_eq!(progress.position(), 1, "the last phase (speed) is done");
    let dir = tempfile::tempdir().unwrap();
    let files = r.write(dir.path()).unwrap();
    let names: Vec<String> = files.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    let expected = [
        "report.txt",
        "report.md",
        "table1.csv",
        "table2.csv",
        "rails.csv",
        "speed.csv",
        "report.json",
        "table1.png",
        "table2_td.png",
        "table2_sd.png",
        "style_pca.png",
    ];
    assert_eq!(names, expected);
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap();
    let t1 = read("table1.csv");
    let t1: Vec<&str> = t1.lines().collect();
    assert_eq!(
        t1[0],
        "behaviour,zero,gaussian,warm_start,mapped,toric_lerp,paper_zero,paper_gaussian,paper_warm_start,paper_mapped"
    );
    let direct = &r.table1[0];
    assert_eq!(
        t1[1],
        format!(
            "direct,{:.4},{:.4},{:.4},{:.4},{:.4},0.162,0.146,0.173,0.107",
            direct.zero, direct.gaussian, direct.warm_start, direct.mapped, direct.lerp
        )
    );
    let t2 = read("table2.csv");
    assert_eq!(
        t2.lines().next(),
        Some("displacement,sd_ours,sd_only_style,sd_interpolation,td_ours,td_only_style,td_interpolation,kd_ours")
    );
    assert!(t2.lines().nth(1).unwrap().starts_with("0,") && t2.lines().nth(2).unwrap().starts_with("1,"), "{t2}");
    assert!(read("rails.csv").starts_with("behaviour,ours_error,spline_keys,capped\ndirect,"));
    let back: BenchReport = serde_json::from_str(&read("report.json")).unwrap();
    // serde_json parses floats to within an ulp, not bit for bit.
    assert_eq!((back.sequences, back.table2.len(), back.styles.len()), (r.sequences, r.table2.len(), r.styles.len()));
    for (a, b) in back.table1.iter().zip(&r.table1) {
        assert!(
            a.behaviour == b.behaviour && (a.mapped - b.mapped).abs() < 1e-12 && (a.lerp - b.lerp).abs() < 1e-12,
            "{a:?} vs {b:?}"
        );
    }
    let text = read("report.txt");
    assert!(
        text.starts_with("camera bench: 8 held-out sequences (seed 9001)\n") && text.contains("style effect:"),
        "{text}"
    );
    assert!(std::fs::read(dir.path().join("style_pca.png")).unwrap().starts_with(b"\x89PNG"));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), expected.len(), "no temporary files left");
}

#[test]
fn pca_finds_the_dominant_axis() {
    let codes: Vec<Vec<f32>> =
        (0..20).map(|i| vec![i as f32, 0.5 * i as f32, 0.01 * ((i * 7) % 3) as f32, 0.0]).collect();
    let p = pca2(&codes);
    let spread1 = p.iter().map(|x| x.0.abs()).fold(0.0, f64::max);
    let spread2 = p.iter().map(|x| x.1.abs()).fold(0.0, f64::max);
    assert!(spread1 > 10.0 && spread2 < 0.1, "{spread1} {spread2}");
}

#[test]
fn displaced_keys_stay_valid_and_move_by_delta() {
    let lens = Lens::default();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let key: Cam = [-0.3, 0.1, 0.3, 0.1, 2.0, 0.2];
    for delta in [0.0, 0.5, 1.0] {
        let d = displaced(&key, delta, &lens, &mut rng);
        assert!(((d[4] - key[4]).abs() as f64 - delta).abs() < 1e-6);
        assert!((d[4] as f64) < crate::features::decode_camera(&key).theta_max(&lens));
    }
}

#[test]
fn committed_weights_beat_toric_interpolation() {
    // Held-out seed: the trained generator with mapped H must do clearly better than the
    // straight line to the key, overall and on orbit tracks (which a line cannot follow).
    let model = FastModel::committed().unwrap();
    let cfg = BenchConfig { seed: 4242, scenes: 1, windows_per_sequence: 2, ..BenchConfig::quick() };
    let seqs = eval_sequences(cfg.seed, cfg.scenes);
    let rows = table1(&model, &seqs, &cfg, &mut ChaCha8Rng::seed_from_u64(1), &Progress::hidden());
    let mapped = rows.iter().map(|r| r.mapped).sum::<f64>() / rows.len() as f64;
    let lerp = rows.iter().map(|r| r.lerp).sum::<f64>() / rows.len() as f64;
    let orbit = rows.iter().find(|r| r.behaviour == "orbit").unwrap();
    assert!(mapped < 0.8 * lerp, "mapped {mapped} vs lerp {lerp}");
    assert!(orbit.mapped < 0.6 * orbit.lerp, "orbit: mapped {} vs lerp {}", orbit.mapped, orbit.lerp);
}

fn tiny_model() -> FastModel {
    let device = inbetween_nn::backend::cpu();
    let cfg = crate::model::ModelConfig { hidden: 8, tta_dim: 8, ..Default::default() };
    FastModel::from_burn(&inbetween_nn::backend::seeded_module(&device, 8, |d| cfg.init(d)), cfg)
}

fn tiny_config() -> BenchConfig {
    BenchConfig {
        scenes: 1,
        displacements: vec![0.0, 1.0],
        max_spline_keys: 6,
        speed_seconds: 0.05,
        ..BenchConfig::quick()
    }
}

#[test]
fn a_generator_that_predicts_no_correction_scores_exactly_as_toric_interpolation() {
    // With the arrival base and a zero decoder output, every step is one step of the straight
    // Toric line to the key (within the tta cap), whatever the state or style: each Table 1
    // column (40 steps = 200 frames) must equal the lerp column, the network must land on
    // displaced keys (KD 0) and the style must have no effect. Any misaligned window, key,
    // tta or restart in the bench's bookkeeping breaks these equalities.
    let mut model = tiny_model();
    model.dec2.w.iter_mut().for_each(|w| *w = 0.0);
    model.dec2.b.iter_mut().for_each(|b| *b = 0.0);
    let r = measure(&model, &tiny_config(), &Progress::hidden());
    for row in &r.table1 {
        for (name, v) in
            [("zero", row.zero), ("gaussian", row.gaussian), ("warm", row.warm_start), ("mapped", row.mapped)]
        {
            assert!((v - row.lerp).abs() < 1e-5, "{} {name}: {v} vs lerp {}", row.behaviour, row.lerp);
        }
    }
    assert!(r.table1.iter().any(|row| row.lerp > 0.01), "the windows move: the check is not 0 = 0");
    // Table 2's 60-step segments start beyond the 200-frame tta cap, where one step of the
    // arrival base is shorter than the line's: only the landing (KD) is exact there, and the
    // style, having no effect, cannot separate ours from only-style.
    for row in &r.table2 {
        assert!(row.kd_ours < 1e-5, "δ {}: KD {}", row.displacement, row.kd_ours);
        assert_eq!(row.td_ours, row.td_only_style, "{row:?}");
    }
    assert!(r.style_spread < 1e-6, "style spread {}", r.style_spread);
    // The same tiny model with its (random) decoder departs from the line and styles differ.
    let r = measure(&tiny_model(), &tiny_config(), &Progress::hidden());
    let departs = r.table1.iter().map(|row| (row.mapped - row.lerp).abs()).fold(0.0, f64::max);
    assert!(departs > 1e-4 && r.style_spread > 1e-5, "departure {departs}, style spread {}", r.style_spread);
    assert!(r.speed.single_frames_per_s > 0.0 && r.speed.batched_frames_per_s > 0.0);
}

#[test]
fn the_bench_entry_names_weights_it_cannot_load() {
    let opts =
        BenchOptions { quick: true, ..BenchOptions::new(CameraBench { weights: Some("no/such/camera.bpk".into()) }) };
    let e = run(&opts).unwrap_err().to_string();
    assert!(e.starts_with("loading camera weights no/such/camera.bpk: ") && e.contains("no/such/camera"), "{e}");
}
