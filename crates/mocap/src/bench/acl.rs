//! The codec on ACL's protocol (the Animation Compression Library's CMU figures): every take
//! resampled to 24 fps; raw = 10 f32 per bone per sample (rotation quaternion, translation,
//! scale: 40 bytes); error = the largest distance of three virtual vertices 3 cm from each bone,
//! in object space through the hierarchy; compression and decompression speed in MB/s of raw.
//! Beside it: seekable single-pose decoding in µs, general-purpose compressors (gzip, zstd, xz)
//! on the BVH text and on the raw floats, and the rate–error curve as a PNG.

use crate::codec::v3_encode::{self, Options};
use crate::codec::{v3, RAW_BYTES_PER_BONE};
pub use crate::corpus::{takes, Take};
use crate::{MocapError, Result};
use inbetween_core::units::LengthUnit;
use inbetween_core::Motion;
use inbetween_io::report::{num, seconds_per_call, BenchOptions, Report, Table};
use inbetween_io::Progress;
use rand::{Rng, SeedableRng};
use std::io::{Read, Write};
use std::path::PathBuf;
use std::time::Instant;

/// ACL 2.1's published CMU figures (2534 clips at 24 fps): compression ratio, max and 99th
/// percentile virtual-vertex error (cm), compression speed (MB/s).
pub const ACL_RATIO: f64 = 21.77;
pub const ACL_MAX_CM: f64 = 0.0495;
pub const ACL_P99_CM: f64 = 0.0089;
pub const ACL_COMPRESS_MB_S: f64 = 14.0;

/// What the ACL-protocol bench runs.
#[derive(Clone, Debug)]
pub struct AclConfig {
    /// Data folder (as `mocap bench --data`); None: the shared corpus.
    pub data: Option<PathBuf>,
    pub unit: Option<LengthUnit>,
    pub fps: f64,
    /// Error bounds of the rate–error curve (cm); the table's headline row is `headline_cm`.
    pub bounds_cm: Vec<f64>,
    pub headline_cm: f64,
    /// Frames per segment of the files (a pose decodes from its segment alone).
    pub segment_len: usize,
    /// Random poses timed per clip for the seek benchmark.
    pub seek_poses: usize,
    pub seed: u64,
    /// Bounds (cm) of the race against the real ACL on the CMU takes (empty: no race).
    pub race_bounds: Vec<f64>,
    /// Where ACL is built for the race (None: `$CARGO_TARGET_DIR/acl-race` or `target/acl-race`).
    pub acl_build_dir: Option<PathBuf>,
}

impl Default for AclConfig {
    fn default() -> AclConfig {
        AclConfig {
            data: None,
            unit: None,
            fps: 24.0,
            bounds_cm: vec![0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0],
            headline_cm: 0.05,
            segment_len: v3::DEFAULT_SEGMENT_LEN,
            seek_poses: 2000,
            seed: 0,
            race_bounds: vec![0.01, 0.05],
            acl_build_dir: None,
        }
    }
}

/// A group of takes at one bound.
#[derive(Clone, Debug, PartialEq)]
pub struct CodecRow {
    pub group: String,
    pub bound_cm: f64,
    pub takes: usize,
    pub frames: usize,
    /// Bones × samples.
    pub bone_samples: usize,
    pub raw_bytes: usize,
    pub bytes: usize,
    pub max_error_cm: f64,
    pub p99_error_cm: f64,
    /// Raw MB per second of compression on one core, and of decoding every pose.
    pub compress_mb_s: f64,
    pub decompress_mb_s: f64,
    /// Mean µs to decode one pose at a random time (file opened once).
    pub pose_us: f64,
    /// Mean µs per pose when playing the clip forwards at 60 Hz (one scratch, as an engine does).
    pub playback_us: f64,
}

impl CodecRow {
    pub fn ratio(&self) -> f64 {
        self.raw_bytes as f64 / self.bytes.max(1) as f64
    }
}

/// A general-purpose compressor on one input.
#[derive(Clone, Debug, PartialEq)]
pub struct BaselineRow {
    pub group: String,
    pub input: &'static str,
    pub compressor: &'static str,
    pub input_bytes: usize,
    pub bytes: usize,
    pub raw_bytes: usize,
}

impl BaselineRow {
    pub fn ratio(&self) -> f64 {
        self.raw_bytes as f64 / self.bytes.max(1) as f64
    }
}

/// Everything the ACL-protocol bench measured.
#[derive(Clone, Debug, PartialEq)]
pub struct AclResults {
    pub fps: f64,
    pub headline_cm: f64,
    pub rows: Vec<CodecRow>,
    pub baselines: Vec<BaselineRow>,
    pub unit_notes: Vec<String>,
    /// The race against the real ACL: its group, rows and whether/where ACL was built.
    pub race_group: String,
    pub race: Vec<super::acl_race::RaceRow>,
    pub race_note: String,
}

/// The groups of takes: the CMU skeletons (cgspeed, ASF/AMC, or a plain folder) and the
/// Character Creator retargets, each on its own and all together.
fn groups(takes: &[Take]) -> Vec<(String, Vec<&Take>)> {
    let cmu: Vec<&Take> = takes.iter().filter(|t| t.source != "iclone_cc").collect();
    let cc: Vec<&Take> = takes.iter().filter(|t| t.source == "iclone_cc").collect();
    let mut out = Vec::new();
    if !cmu.is_empty() {
        let bones: std::collections::BTreeSet<usize> = cmu.iter().map(|t| t.motion.skeleton.len()).collect();
        out.push((format!("CMU skeletons ({} takes, {bones:?} bones)", cmu.len()), cmu.clone()));
    }
    if !cc.is_empty() {
        let bones: std::collections::BTreeSet<usize> = cc.iter().map(|t| t.motion.skeleton.len()).collect();
        out.push((format!("iClone retargets ({} takes, {bones:?} bones)", cc.len()), cc.clone()));
        if !cmu.is_empty() {
            out.push((format!("all {} takes", takes.len()), takes.iter().collect()));
        }
    }
    out
}

/// One take compressed at one bound, with its timings.
struct TakeResult {
    bytes: usize,
    errors_max: f64,
    errors: Vec<f64>,
    compress_s: f64,
    decompress_s: f64,
    pose_s: f64,
    playback_s: f64,
}

fn run_take(t: &Take, bound_cm: f64, cfg: &AclConfig, timed: bool) -> Result<TakeResult> {
    let opts = Options { segment_len: cfg.segment_len, ..Options::bound(bound_cm) };
    let start = Instant::now();
    let c = v3_encode::compress_in(&t.motion, t.unit.clone(), &opts)?;
    let compress_s = start.elapsed().as_secs_f64();
    let errors = c.errors_cm.clone();
    let (mut decompress_s, mut pose_s, mut playback_s) = (0.0, 0.0, 0.0);
    if timed {
        decompress_s = seconds_per_call(1, 3, || {
            let f = v3::File::open(&c.bytes).expect("a file just written opens");
            std::hint::black_box(f.decode_all().expect("and decodes").poses());
        });
        let file = v3::File::open(&c.bytes)?;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(inbetween_core::seed::derive(
            cfg.seed,
            t.motion.num_frames() as u64,
        ));
        let duration = (t.motion.num_frames() - 1) as f64 * t.motion.frame_time;
        let times: Vec<f64> = (0..cfg.seek_poses.max(1)).map(|_| rng.random::<f64>() * duration).collect();
        let (mut pose, mut sc) = (inbetween_core::Pose::rest(&t.motion.skeleton), v3::Scratch::default());
        let per_round = seconds_per_call(1, 3, || {
            for &time in &times {
                file.pose_at(time, &mut pose, &mut sc).expect("a valid file seeks");
            }
            std::hint::black_box(&pose);
        });
        pose_s = per_round / times.len() as f64;
        let ticks: Vec<f64> = (0..).map(|k| k as f64 / 60.0).take_while(|&t| t <= duration).collect();
        let per_play = seconds_per_call(1, 3, || {
            for &time in &ticks {
                file.pose_at(time, &mut pose, &mut sc).expect("a valid file seeks");
            }
            std::hint::black_box(&pose);
        });
        playback_s = per_play / ticks.len() as f64;
    }
    Ok(TakeResult {
        bytes: c.bytes.len(),
        errors_max: c.max_error_cm,
        errors,
        compress_s,
        decompress_s,
        pose_s,
        playback_s,
    })
}

/// Runs the protocol: every group at every bound (timings single-threaded, so MB/s is per core).
pub fn measure(cfg: &AclConfig, progress: &Progress) -> Result<AclResults> {
    let dir = super::run::data_dir(cfg.data.as_deref())?;
    let corpus = crate::corpus::load(&dir, cfg.unit)?;
    let takes = takes(&corpus.clips, &corpus.units, cfg.fps)?;
    let mut bounds = cfg.bounds_cm.clone();
    if !bounds.contains(&cfg.headline_cm) {
        bounds.push(cfg.headline_cm);
    }
    bounds.sort_by(f64::total_cmp);
    progress.phase((takes.len() * bounds.len()) as u64, "codec (ACL protocol)");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| MocapError::Invalid(format!("thread pool: {e}")))?;
    // results[bound][take]
    let mut results: Vec<Vec<TakeResult>> = Vec::new();
    for &b in &bounds {
        let mut per = Vec::new();
        for t in &takes {
            progress.set_message(format!("{} at {b} cm", t.name));
            let timed = b == cfg.headline_cm;
            per.push(pool.install(|| run_take(t, b, cfg, timed))?);
            progress.inc(1);
        }
        results.push(per);
    }
    let mut rows = Vec::new();
    for (group, members) in groups(&takes) {
        for (bi, &b) in bounds.iter().enumerate() {
            let idx: Vec<usize> =
                members.iter().map(|m| takes.iter().position(|t| std::ptr::eq(t, *m)).expect("member")).collect();
            let rs: Vec<&TakeResult> = idx.iter().map(|&i| &results[bi][i]).collect();
            let raw: usize = idx.iter().map(|&i| takes[i].raw_bytes()).sum();
            let mut errors: Vec<f64> = rs.iter().flat_map(|r| r.errors.iter().copied()).collect();
            let secs = |f: fn(&TakeResult) -> f64| rs.iter().map(|r| f(r)).sum::<f64>();
            let mb = raw as f64 / 1e6;
            let timed = b == cfg.headline_cm;
            let seeks: f64 = rs.iter().map(|r| r.pose_s).sum::<f64>() / rs.len().max(1) as f64;
            let plays: f64 = rs.iter().map(|r| r.playback_s).sum::<f64>() / rs.len().max(1) as f64;
            rows.push(CodecRow {
                group: group.clone(),
                bound_cm: b,
                takes: idx.len(),
                frames: idx.iter().map(|&i| takes[i].motion.num_frames()).sum(),
                bone_samples: idx.iter().map(|&i| takes[i].motion.num_frames() * takes[i].motion.skeleton.len()).sum(),
                raw_bytes: raw,
                bytes: rs.iter().map(|r| r.bytes).sum(),
                max_error_cm: rs.iter().map(|r| r.errors_max).fold(0.0, f64::max),
                p99_error_cm: inbetween_core::stats::percentile(&mut errors, 0.99),
                compress_mb_s: mb / secs(|r| r.compress_s).max(1e-12),
                decompress_mb_s: if timed { mb / secs(|r| r.decompress_s).max(1e-12) } else { f64::NAN },
                pose_us: if timed { seeks * 1e6 } else { f64::NAN },
                playback_us: if timed { plays * 1e6 } else { f64::NAN },
            });
        }
    }
    let baselines = baselines(&takes)?;
    let (race_group, race, race_note) = match groups(&takes).into_iter().next() {
        Some((group, members)) if !cfg.race_bounds.is_empty() => {
            let out = cfg.acl_build_dir.clone().unwrap_or_else(super::acl_race::default_build_dir);
            progress.set_message("building ACL for the race".to_string());
            let built = super::acl_race::build_acl(super::acl_race::acl_sources(&dir).as_deref(), &out);
            let note = match &built {
                Ok(p) => {
                    format!("ACL v2.1.0 built from ../shared/peers/acl-race into {} (g++ -O3 -msse4.1)", p.display())
                }
                Err(why) => format!("skipped: ACL not built ({why}); our rows only"),
            };
            progress.set_message(format!("race on {group}"));
            let rows = pool.install(|| {
                super::acl_race::race(&members, &cfg.race_bounds, built.as_deref().ok(), cfg.seek_poses, cfg.seed)
            })?;
            (group, rows, note)
        }
        _ => (String::new(), Vec::new(), String::new()),
    };
    Ok(AclResults {
        fps: cfg.fps,
        headline_cm: cfg.headline_cm,
        rows,
        baselines,
        unit_notes: corpus.unit_notes(),
        race_group,
        race,
        race_note,
    })
}

/// The raw 40-byte buffer of a take: per sample, per bone, quaternion xyzw, translation, scale.
pub fn raw_floats(m: &Motion) -> Vec<u8> {
    let mut out = Vec::with_capacity(RAW_BYTES_PER_BONE * m.skeleton.len() * m.num_frames());
    for f in 0..m.num_frames() {
        let p = m.pose(f);
        for (r, t) in p.rotations.iter().zip(&p.translations) {
            for v in [r.x, r.y, r.z, r.w, t.x, t.y, t.z, 1.0, 1.0, 1.0] {
                out.extend_from_slice(&(v as f32).to_le_bytes());
            }
        }
    }
    out
}

fn gzip(data: &[u8]) -> Result<usize> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(data)
        .and_then(|_| e.finish())
        .map(|v| v.len())
        .map_err(|source| MocapError::Io { path: "gzip".into(), source })
}

fn zstd19(data: &[u8]) -> Result<usize> {
    zstd::bulk::compress(data, 19).map(|v| v.len()).map_err(|source| MocapError::Io { path: "zstd".into(), source })
}

fn xz9(data: &[u8]) -> Result<usize> {
    let mut out = Vec::new();
    liblzma::read::XzEncoder::new(data, 9)
        .read_to_end(&mut out)
        .map(|_| out.len())
        .map_err(|source| MocapError::Io { path: "xz".into(), source })
}

/// gzip -9, zstd -19 and xz -9 on the BVH text and on the raw floats of every group (lossless).
pub fn baselines(takes: &[Take]) -> Result<Vec<BaselineRow>> {
    let mut rows = Vec::new();
    for (group, members) in groups(takes) {
        let raw: usize = members.iter().map(|t| t.raw_bytes()).sum();
        let bvh: Vec<Vec<u8>> =
            members.iter().map(|t| inbetween_io::bvh::to_bvh_string(&t.motion).into_bytes()).collect();
        let floats: Vec<Vec<u8>> = members.iter().map(|t| raw_floats(&t.motion)).collect();
        for (input, data) in [("BVH text", &bvh), ("raw f32 (40 B per bone)", &floats)] {
            type Compressor = fn(&[u8]) -> Result<usize>;
            let compressors: [(&'static str, Compressor); 3] =
                [("gzip -9", gzip), ("zstd -19", zstd19), ("xz -9", xz9)];
            for (name, c) in compressors {
                let mut bytes = 0;
                for d in data.iter() {
                    bytes += c(d)?;
                }
                rows.push(BaselineRow {
                    group: group.clone(),
                    input,
                    compressor: name,
                    input_bytes: data.iter().map(|d| d.len()).sum(),
                    bytes,
                    raw_bytes: raw,
                });
            }
        }
    }
    Ok(rows)
}

impl AclResults {
    /// The codec table: every group at every bound, ACL's published row first.
    pub fn codec_table(&self) -> Table {
        let mut t = Table::new(
            "acl_codec",
            &format!("Codec (.ibk version 3) on ACL's protocol: {} fps, raw = 40 bytes per bone per sample, virtual vertices 3 cm from each bone", self.fps),
            &[
                "takes", "bound cm", "frames", "bone samples", "raw bytes", "bytes", "ratio", "max error cm", "p99 error cm",
                "compress MB/s", "decompress MB/s", "µs per pose", "µs per pose, playback",
            ],
        );
        t.row([
            "ACL 2.1, published (2534 CMU clips)".to_string(),
            "0.01".into(),
            String::new(),
            String::new(),
            String::new(),
            String::new(),
            format!("{ACL_RATIO:.2}"),
            format!("{ACL_MAX_CM}"),
            format!("{ACL_P99_CM}"),
            format!("~{ACL_COMPRESS_MB_S}"),
            String::new(),
            String::new(),
            String::new(),
        ]);
        for r in &self.rows {
            let opt = |v: f64, d: usize| if v.is_finite() { num(v, d) } else { String::new() };
            t.row([
                r.group.clone(),
                format!("{}", r.bound_cm),
                r.frames.to_string(),
                r.bone_samples.to_string(),
                r.raw_bytes.to_string(),
                r.bytes.to_string(),
                format!("{:.2}", r.ratio()),
                format!("{:.4}", r.max_error_cm),
                format!("{:.4}", r.p99_error_cm),
                num(r.compress_mb_s, 1),
                opt(r.decompress_mb_s, 1),
                opt(r.pose_us, 2),
                opt(r.playback_us, 2),
            ]);
        }
        t.note("ratio: 40 bytes × bones × samples / .ibk bytes (the whole file: header, skeleton with joint names, offsets, checksum)");
        t.note("errors: each joint's largest of three vertices 3 cm along its local axes, object space, decoded file vs source; p99 over every joint of every frame");
        t.note(format!(
            "speeds: raw MB per second on one core; decompress = open + decode every pose; µs per pose = one pose at a random time (two frames, slerp), file opened once; playback = every 1/60 s from the start with one scratch (each frame decoded once); timed at {} cm only",
            self.headline_cm
        ));
        t.note(
            "ACL's bound column: its threshold setting; its errors are measured, ours are bounded by the bound column",
        );
        t
    }

    /// The general-purpose compressors.
    pub fn baseline_table(&self) -> Table {
        let mut t = Table::new(
            "acl_baselines",
            "Sanity baselines: lossless general-purpose compressors, ratio against the same 40-byte raw",
            &["takes", "input", "compressor", "input bytes", "bytes", "ratio"],
        );
        for b in &self.baselines {
            t.row([
                b.group.clone(),
                b.input.to_string(),
                b.compressor.to_string(),
                b.input_bytes.to_string(),
                b.bytes.to_string(),
                format!("{:.2}", b.ratio()),
            ]);
        }
        t.note("BVH text: the 24 fps clip written by our BVH writer; raw f32: quaternion xyzw, translation, scale (1, 1, 1) per bone per sample");
        t
    }

    /// The rate–error curve, written to `path`: ratio against the measured max error, one line
    /// per group, and ACL's published point.
    pub fn plot(&self, path: &std::path::Path) -> Result<()> {
        use inbetween_render::plot::{line_plot, Series};
        let mut series: Vec<Series> = Vec::new();
        let mut groups: Vec<&str> = Vec::new();
        for r in &self.rows {
            if !groups.contains(&r.group.as_str()) {
                groups.push(&r.group);
            }
        }
        for g in groups {
            let pts = self.rows.iter().filter(|r| r.group == g).map(|r| (r.max_error_cm, r.ratio())).collect();
            series.push(Series::new(format!("ours: {g}"), pts));
        }
        // ACL's single published point, drawn as a small cross of two segments.
        let (x, y) = (ACL_MAX_CM, ACL_RATIO);
        series.push(Series {
            color: Some([0, 0, 0]),
            ..Series::new("ACL 2.1 (published)", vec![(x * 0.7, y), (x * 1.3, y)])
        });
        series.push(Series { color: Some([0, 0, 0]), ..Series::new("", vec![(x, y * 0.93), (x, y * 1.07)]) });
        line_plot(
            path,
            "Rate-error curve (ACL protocol, 24 fps)",
            "max virtual-vertex error (cm)",
            "compression ratio (40-byte raw)",
            &series,
        )
        .map_err(|e| MocapError::Invalid(format!("plot {}: {e}", path.display())))
    }

    /// The report: both tables and the unit notes.
    pub fn report(&self) -> Report {
        let mut r = Report::new("acl_codec", "The codec on ACL's protocol (CMU takes at 24 fps)");
        if !self.race.is_empty() {
            r.table(super::acl_race::table(&self.race_group, &self.race, &self.race_note));
        }
        r.table(self.codec_table());
        r.table(self.baseline_table());
        r.text(format!("units: {}", self.unit_notes.join("; ")));
        r
    }
}

/// `inbetween mocap bench`'s codec table on ACL's protocol: [`measure`] (`data` and `seed` of the
/// options replacing the configuration's) and the report (`acl_codec.txt/.md`, `acl_codec.csv`,
/// `acl_baselines.csv`), with the chart `acl_rate_error.png` when it will be written to a folder.
pub fn run(opts: &BenchOptions<AclConfig>) -> Result<Report> {
    let cfg = AclConfig {
        data: opts.data.clone().or_else(|| opts.engine.data.clone()),
        seed: opts.seed.unwrap_or(opts.engine.seed),
        ..opts.engine.clone()
    };
    let results = measure(&cfg, &opts.progress)?;
    let mut report = results.report();
    if opts.out.is_some() {
        let png = inbetween_render::rendered_bytes("acl_rate_error.png", |p| {
            results.plot(p).map_err(|e| inbetween_render::RenderError::InvalidInput(e.to_string()))
        })
        .map_err(|e| MocapError::Invalid(format!("acl_rate_error.png: {e}")))?;
        report.file("acl_rate_error.png", png);
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two procedural walks in a plain folder: every group row, the baselines and the files.
    #[test]
    fn the_acl_table_runs_on_a_folder_and_writes_its_files() {
        let dir = tempfile::tempdir().unwrap();
        let data = dir.path().join("clips");
        std::fs::create_dir_all(&data).unwrap();
        for (i, frames) in [(0, 90), (1, 70)] {
            let mut p = inbetween_core::procedural::GaitParams::walk();
            p.frames = frames;
            p.speed *= 1.0 + 0.2 * i as f64;
            inbetween_io::write_bvh(&data.join(format!("walk{i}.bvh")), &inbetween_core::procedural::gait(&p)).unwrap();
        }
        let cfg = AclConfig { data: Some(data), bounds_cm: vec![0.5, 0.05], seek_poses: 50, ..Default::default() };
        let out = dir.path().join("out");
        let r = measure(&cfg, &Progress::hidden()).unwrap();
        let opts = BenchOptions { out: Some(out.clone()), ..BenchOptions::new(cfg.clone()) };
        let report = run(&opts).unwrap();
        let written = opts.write(&report).unwrap();
        assert!(run(&BenchOptions::new(cfg.clone())).unwrap().file_bytes("acl_rate_error.png").is_none());
        assert_eq!(r.rows.len(), 2, "one group (plain folder), two bounds");
        let (fine, coarse) = (&r.rows[0], &r.rows[1]);
        assert_eq!((fine.bound_cm, coarse.bound_cm), (0.05, 0.5));
        assert!(fine.max_error_cm <= 0.05 && coarse.max_error_cm <= 0.5);
        assert!(coarse.ratio() > fine.ratio() && fine.ratio() > 5.0, "{r:?}");
        assert!(fine.pose_us > 0.0 && fine.decompress_mb_s > 0.0 && coarse.pose_us.is_nan());
        assert!(fine.playback_us > 0.0 && coarse.playback_us.is_nan());
        assert_eq!(fine.takes, 2);
        assert_eq!(fine.raw_bytes, 40 * 31 * fine.frames);
        assert_eq!(r.baselines.len(), 6);
        assert!(r.baselines.iter().all(|b| b.ratio() > 1.0), "{:?}", r.baselines);
        let names: Vec<String> =
            written.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
        assert_eq!(
            names,
            [
                "acl_codec.txt",
                "acl_codec.md",
                "acl_race.csv",
                "acl_codec.csv",
                "acl_baselines.csv",
                "acl_rate_error.png"
            ]
        );
        // The race: without ACL's sources beside this folder, our rows only (versions 3 and 4 at
        // each race bound), and the report says why.
        assert!(r.race_note.starts_with("skipped: ACL not built"), "{}", r.race_note);
        assert_eq!(r.race.len(), 2 * cfg.race_bounds.len());
        for row in &r.race {
            assert!(row.max_cm <= row.bound_cm && row.ratio() > 5.0, "{row:?}");
            assert!(row.pose_us > 0.0 && row.playback_us > 0.0, "{row:?}");
        }
        assert!(report.to_text().contains("skipped: ACL not built"));
        let text = report.to_text();
        assert!(text.contains("ACL 2.1, published") && text.contains("21.77"), "{text}");
        let csv = std::fs::read_to_string(out.join("acl_codec.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 1 + 2, "header, ACL's row, ours");
    }

    #[test]
    fn raw_floats_are_40_bytes_per_bone_and_sample() {
        let m = inbetween_core::procedural::gait(&inbetween_core::procedural::GaitParams::walk());
        let raw = raw_floats(&m);
        assert_eq!(raw.len(), 40 * m.skeleton.len() * m.num_frames());
        // The first bone's scale of the first sample is (1, 1, 1).
        assert_eq!(&raw[28..32], &1.0f32.to_le_bytes());
    }
}
