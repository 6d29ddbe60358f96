//! Issue 41 on the corpus (real-data test, skipped without `../shared/data`): the default order of
//! each clip, from frames 0, 40 and 100 and the bench's four evenly spread starts, at the source's
//! length, plays nothing backwards, repeats no loop under a second more than twice in a row, shows
//! most of the source, cuts no more than the source changes shot, and is about as smooth as the
//! source (M_D, Eq. 21, within 20 % of the source's). The same on a clip of four shots cut from the
//! corpus MP4s, made here (bigbuckbunny 70–131, carphone 0–59, bigbuckbunny 0–59, the distorted
//! carphone 60–119, at 256×144).

use std::sync::Arc;

use inbetween_core::cancel::Cancel;
use inbetween_io::data::with_shared_data;
use inbetween_io::Progress;
use inbetween_video::frames::{read_clip, Clip, ReadOptions};
use inbetween_video::job::{AnalyseJob, ResequenceJob};
use inbetween_video::sdpf::{longest_repeated_cycle, short_cycle_repeats, shot_changes, SdpfParams};

/// Frames `range` of `clip`, resized to 256×144.
fn part(clip: &Clip, range: std::ops::Range<usize>) -> Vec<image::RgbImage> {
    clip.frames[range]
        .iter()
        .map(|f| image::imageops::resize(f, 256, 144, image::imageops::FilterType::Triangle))
        .collect()
}

#[test]
fn corpus_orders_are_long_smooth_and_never_backwards() {
    with_shared_data("video corpus", |data| {
        let cache = tempfile::tempdir().unwrap();
        let dir = data.join("video");
        let mut clips: Vec<(String, Clip)> = Vec::new();
        for name in ["carphone_pristine.mp4", "bigbuckbunny.mp4", "bbb_png_seq"] {
            let path = dir.join(name);
            if !path.exists() {
                println!("skipped: no {}", path.display());
                continue;
            }
            clips.push((name.to_string(), read_clip(&path, &ReadOptions::default()).unwrap().0));
        }
        let read = |name: &str| read_clip(&dir.join(name), &ReadOptions::default()).ok().map(|c| c.0);
        if let (Some(bunny), Some(car), Some(distorted)) =
            (read("bigbuckbunny.mp4"), read("carphone_pristine.mp4"), read("carphone_distorted.mp4"))
        {
            let frames =
                [part(&bunny, 70..132), part(&car, 0..60), part(&bunny, 0..60), part(&distorted, 60..120)].concat();
            clips.push(("four shots".into(), Clip { frames, fps: 25.0, source: "four shots of the corpus".into() }));
        }
        let mut failures = Vec::new();
        for (name, clip) in clips {
            let mut job = AnalyseJob::for_clip(clip);
            job.config.cache_dir = cache.path().to_path_buf();
            let a = Arc::new(job.run(&Cancel::new(), &Progress::hidden()).unwrap());
            let n = a.frames;
            let source: Vec<usize> = (0..n).collect();
            let source_changes = shot_changes(&source, &a.shot);
            let second = a.analysis.info.min_loop_frames(1.0);
            let mut starts: Vec<usize> = (0..4).map(|i| i * n / 4).chain([40, 100]).filter(|&s| s < n).collect();
            starts.sort_unstable();
            starts.dedup();
            for start in starts {
                let run = ResequenceJob {
                    start,
                    params: SdpfParams { seed: 1, ..SdpfParams::default() },
                    ..ResequenceJob::on(a.clone())
                };
                let s = run.run(&Cancel::new(), &Progress::hidden()).unwrap().sequences.remove(0);
                let o = &s.order;
                let md = s.md / a.source_md;
                let short = short_cycle_repeats(o, second);
                let cuts = shot_changes(o, &a.shot);
                let cycle = longest_repeated_cycle(o).map(|c| format!("{}x{}", c.period, c.repeats));
                println!(
                    "{name} from {start}: {} frames, distinct {:.2}, longest cycle {cycle:?}, short loops played {short}x, cuts {cuts} (source {source_changes}), jump cuts {}, M_D {md:.3}x",
                    o.len(),
                    s.distinct,
                    s.cuts.len().saturating_sub(cuts),
                );
                assert_eq!(o.len(), n);
                assert_eq!(s.backward_steps, 0, "{name} from {start}: {o:?}");
                let checks = [
                    (short <= 2, format!("a loop under {second} frames played {short} times")),
                    (s.distinct >= 0.6, format!("{:.2} of the frames shown", s.distinct)),
                    (cuts <= source_changes, format!("{cuts} cuts")),
                    ((0.8..=1.2).contains(&md), format!("M_D {md:.3}x the source's")),
                ];
                failures.extend(checks.into_iter().filter(|c| !c.0).map(|c| format!("{name} from {start}: {}", c.1)));
            }
        }
        assert!(failures.is_empty(), "{failures:#?}");
    });
}
