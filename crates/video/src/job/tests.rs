use std::sync::Arc;

use inbetween_core::cancel::Cancel;
use inbetween_io::Progress;

use super::*;
use crate::frames::{procedural_clip, read_clip, write_clip, ProceduralKind, ReadOptions};
use crate::sdpf::{stability_md, SdpfParams};
use crate::VideoError;

use crate::pipeline::tests::quick_config as quick;

#[test]
fn resequence_job_reads_analyses_walks_measures_explains_and_writes() {
    let dir = tempfile::tempdir().unwrap();
    let clip = procedural_clip(ProceduralKind::Mixed, 32, 64, 48, 3);
    let input = dir.path().join("mixed.gif");
    write_clip(&input, &clip).unwrap();
    let mut analyse = AnalyseJob::for_file(&input);
    analyse.config = quick(&dir.path().join("cache"));
    let job = ResequenceJob {
        source: ResequenceSource::Analyse(Box::new(analyse)),
        start: 3,
        params: SdpfParams { seed: 2, length: Some(40), ..SdpfParams::default() },
        count: 2,
        out: Some(dir.path().join("new.gif")),
        explain: true,
        ..ResequenceJob::default()
    };
    let report = job.run(&Cancel::new(), &Progress::hidden()).unwrap();
    assert_eq!(report.analysis.frames, 32);
    assert_eq!(report.analysis.decoder.as_deref(), Some("gif"));
    assert!(!report.sequences.is_empty());
    let (written, _) = read_clip(&input, &ReadOptions::default()).unwrap();
    for (i, s) in report.sequences.iter().enumerate() {
        assert_eq!(s.order[0], 3);
        assert_eq!(s.order.len(), 40);
        assert_eq!(s.backward_steps, 0, "{:?}", s.order);
        // The engine's M_D equals Eq. 21 on the clip as read.
        assert_eq!(s.md, stability_md(&written.frames, &s.order));
        // Every step off the source order is explained, and only those.
        let off: Vec<usize> = (1..s.order.len()).filter(|&p| s.order[p] != s.order[p - 1] + 1).collect();
        assert_eq!(s.jumps.iter().map(|j| j.position).collect::<Vec<_>>(), off);
        assert!(s.jumps.iter().all(|j| !j.text.is_empty()));
        assert!(s.explain.starts_with("SDPF path of 40 frames from frame 3"), "{}", s.explain);
        let file = s.file.clone().unwrap();
        assert_eq!(file, numbered(&dir.path().join("new.gif"), i, 2));
        let (out, _) = read_clip(&file, &ReadOptions::default()).unwrap();
        assert_eq!(out.len(), 40);
        assert!(s.sheet.as_ref().unwrap().is_file());
    }
    // It prints itself: the clip, the metric, one line per order with the walk, the stages.
    let text = report.to_string();
    assert!(text.contains("32 frames 64x48") && text.contains("decoded by gif"), "{text}");
    assert!(text.contains("new-1.gif: 40 frames") && text.contains("SDPF path of 40 frames"), "{text}");
    assert!(text.contains("motion judged") && text.contains("SDPF walks:"), "{text}");
    // And serialises: the order, cuts, loops and jumps are there for Python.
    let json = serde_json::to_value(&report).unwrap();
    assert_eq!(json["sequences"][0]["order"][0], 3);
    assert!(json["sequences"][0]["jumps"].is_array() && json["sequences"][0]["cuts"].is_array());
    assert_eq!(json["analysis"]["frames"], 32);
}

#[test]
fn a_kept_analysis_serves_later_orders_with_the_same_result() {
    let dir = tempfile::tempdir().unwrap();
    let mut analyse = AnalyseJob::for_clip(procedural_clip(ProceduralKind::Pendulum, 24, 64, 48, 3));
    analyse.config = quick(dir.path());
    let a = Arc::new(analyse.run(&Cancel::new(), &Progress::hidden()).unwrap());
    assert_eq!(a.decoder, None);
    assert!(a.to_string().contains("given in memory"), "{a}");
    assert_eq!(a.source_md, stability_md(&a.clip.frames, &(0..24).collect::<Vec<_>>()));
    let job = ResequenceJob {
        start: 5,
        params: SdpfParams { seed: 4, ..SdpfParams::default() },
        ..ResequenceJob::on(a.clone())
    };
    let one = job.run(&Cancel::new(), &Progress::hidden()).unwrap();
    let two = job.run(&Cancel::new(), &Progress::hidden()).unwrap();
    assert_eq!(one.sequences[0].order, two.sequences[0].order);
    assert_eq!(one.sequences[0].order.len(), 24);
    assert!(one.sequences[0].file.is_none(), "no output asked for");
    // A cancelled token stops the walk.
    let c = Cancel::new();
    c.cancel();
    assert!(matches!(job.run(&c, &Progress::hidden()), Err(VideoError::Cancelled(_))));
}

#[test]
fn bad_requests_are_refused_before_the_work() {
    let job = ResequenceJob { out: Some("new.avi".into()), ..ResequenceJob::for_file("clip.mp4") };
    assert!(job.validate().unwrap_err().to_string().contains("must end in .mp4 or .gif"));
    let job = ResequenceJob { count: 0, ..ResequenceJob::for_file("clip.mp4") };
    assert!(job.validate().unwrap_err().to_string().contains("0 sequences"));
    let job = ResequenceJob { count: 99, ..ResequenceJob::for_file("clip.mp4") };
    assert!(matches!(job.validate(), Err(VideoError::Limit(l)) if l.field == "max_count"));
    let job = ResequenceJob {
        params: SdpfParams { length: Some(0), ..SdpfParams::default() },
        ..ResequenceJob::for_file("clip.mp4")
    };
    assert!(job.validate().unwrap_err().to_string().contains("0 frames"));
    assert!(AnalyseJob::default().validate().unwrap_err().to_string().contains("no input"));
    // A start past the clip's end is refused once the clip is read, before the analysis: a
    // cache folder that cannot exist would fail the analysis, not this check.
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("drift.gif");
    write_clip(&input, &procedural_clip(ProceduralKind::Drift, 12, 64, 48, 3)).unwrap();
    let mut analyse = AnalyseJob::for_file(&input);
    analyse.config.cache_dir = input.join("not-a-folder");
    let job = ResequenceJob {
        start: 12,
        source: ResequenceSource::Analyse(Box::new(analyse.clone())),
        ..ResequenceJob::default()
    };
    let e = job.run(&Cancel::new(), &Progress::hidden()).unwrap_err().to_string();
    assert!(e.contains("start frame 12 is outside the clip (frames 0..11)"), "{e}");
    // Over the frame limit: refused after reading one frame past it.
    analyse.config.limits.max_frames = 10;
    let e = analyse.run(&Cancel::new(), &Progress::hidden()).unwrap_err();
    assert!(matches!(&e, VideoError::TooManyFrames(l) if l.field == "max_frames"), "{e}");
    let said = "drift.gif: 11 frames or more, more than the limit of 10 frames (max_frames); or read only the first";
    assert!(e.to_string().ends_with(&format!("{said} frames with `read.max_frames`")), "{e}");
}

#[test]
fn a_blend_cross_fades_the_written_jumps_and_is_measured_on_the_written_frames() {
    let dir = tempfile::tempdir().unwrap();
    let mut analyse = AnalyseJob::for_clip(procedural_clip(ProceduralKind::Pendulum, 40, 64, 48, 3));
    analyse.config = quick(dir.path());
    let a = Arc::new(analyse.run(&Cancel::new(), &Progress::hidden()).unwrap());
    let params = SdpfParams { seed: 1, length: Some(80), ..SdpfParams::default() };
    let plain = ResequenceJob { params: params.clone(), ..ResequenceJob::on(a.clone()) };
    let plain = plain.run(&Cancel::new(), &Progress::hidden()).unwrap();
    let out = dir.path().join("blend.gif");
    let job = ResequenceJob { params, blend: 2, out: Some(out.clone()), ..ResequenceJob::on(a.clone()) };
    let blended = job.run(&Cancel::new(), &Progress::hidden()).unwrap();
    let (p, b) = (&plain.sequences[0], &blended.sequences[0]);
    assert_eq!(p.order, b.order, "the blend changes frames, not the order");
    assert!(p.blended.is_empty());
    // An order twice the source's length must jump back, so something is blended.
    assert!(!b.blended.is_empty(), "{:?}", b.order);
    let (written, _) = read_clip(&out, &ReadOptions::default()).unwrap();
    assert_eq!(written.len(), 80);
    assert_ne!(p.md, b.md);
}
