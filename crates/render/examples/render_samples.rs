//! Writes sample previews of procedural motion to a folder (default `out/render_samples`) and
//! prints how long each took: `cargo run -p inbetween-render --example render_samples [DIR]`.

use inbetween_core::procedural::{gait, GaitParams};
use inbetween_render::plot::{grouped_bar_chart, line_plot, scatter_plot, Series};
use inbetween_render::stick::{render_motion_gif, render_motion_png, StickOptions};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "out/render_samples".into()));
    std::fs::create_dir_all(&dir)?;
    let walk = gait(&GaitParams::walk());
    let run = gait(&GaitParams { turn_rate: 0.5, ..GaitParams::run() });
    let other = gait(&GaitParams::walk().jittered(7, 0.3));
    let timed = |name: &str,
                 f: &mut dyn FnMut() -> Result<(), inbetween_render::RenderError>|
     -> Result<(), inbetween_render::RenderError> {
        let t = Instant::now();
        f()?;
        let kib = std::fs::metadata(dir.join(name)).map(|m| m.len() as f64 / 1024.0).unwrap_or(0.0);
        println!("{name:<22} {:>8.3} s {:>9.1} KiB", t.elapsed().as_secs_f64(), kib);
        Ok(())
    };
    let titled = StickOptions { title: Some("procedural walk".into()), ..StickOptions::default() };
    timed("walk_frame.png", &mut || render_motion_png(&dir.join("walk_frame.png"), &[&walk], 40, &titled))?;
    timed("walk.gif", &mut || render_motion_gif(&dir.join("walk.gif"), &[&walk], &titled))?;
    let compare = StickOptions { labels: vec!["walk".into(), "jittered walk".into()], ..StickOptions::default() };
    timed("compare_frame.png", &mut || {
        render_motion_png(&dir.join("compare_frame.png"), &[&walk, &other], 60, &compare)
    })?;
    timed("compare.gif", &mut || render_motion_gif(&dir.join("compare.gif"), &[&walk, &other], &compare))?;
    let long_title = StickOptions {
        labels: vec!["original".into(), "from 12 keys".into()],
        title: Some("mocap codec: 12 keys, max 0.53 cm, mean 0.21 cm".into()),
        ..StickOptions::default()
    };
    timed("long_title.png", &mut || render_motion_png(&dir.join("long_title.png"), &[&walk, &other], 0, &long_title))?;
    timed("run_turning.png", &mut || {
        render_motion_png(&dir.join("run_turning.png"), &[&run], 100, &StickOptions::default())
    })?;
    let curve = |f: fn(f64) -> f64| (0..200).map(|i| (i as f64 / 30.0, f(i as f64 / 30.0))).collect::<Vec<_>>();
    timed("line.png", &mut || {
        line_plot(
            &dir.join("line.png"),
            "Position error per frame",
            "time (s)",
            "error (cm)",
            &[
                Series::new("uniform keys", curve(|t| 2.0 + (t * 3.0).sin().abs() * 3.0)),
                Series::new("SIDQL keys", curve(|t| 1.0 + (t * 3.0).sin().abs())),
            ],
        )
    })?;
    timed("scatter.png", &mut || {
        let pts = (0..80).map(|i| (i as f64, ((i * 37) % 23) as f64 * 0.3 + i as f64 * 0.05)).collect();
        scatter_plot(&dir.join("scatter.png"), "Keys vs error", "keyframes", "error (cm)", &[Series::new("clips", pts)])
    })?;
    timed("bars.png", &mut || {
        // Illustrative values to show the chart layout; they are not measurements.
        let groups: Vec<String> = ["group 1", "group 2", "group 3", "group 4"].iter().map(|s| s.to_string()).collect();
        grouped_bar_chart(
            &dir.join("bars.png"),
            "Sample bar chart (illustrative values)",
            "value",
            &groups,
            &[
                ("series a".into(), vec![3.1, 5.2, 4.4, 6.0]),
                ("series b".into(), vec![2.0, 3.1, 2.9, 3.8]),
                ("series c".into(), vec![1.4, 2.2, 2.0, 2.9]),
            ],
        )
    })?;
    Ok(())
}
