//! The race against the real ACL (the Animation Compression Library, v2.1.0): when its sources
//! and a small decoder/timer are found beside the data (`../shared/peers/acl-race`, outside the
//! repository; nothing of it is copied here) and `g++` exists, the bench builds its own
//! `acl_compressor` and `acl_decode` into the target folder, writes each take as ACL's raw clip
//! text (`.acl.sjson` version 5: local quaternions and translations in cm, bind translation =
//! the skeleton offset, 3 cm virtual vertices), compresses it with ACL at the same bounds as ours,
//! decodes every sample with ACL and scores ACL's output with **our** error metric
//! ([`crate::codec::v3_encode::vertex_errors`]), beside our version 3 and version 4 files of the same
//! takes. Without them the table holds our rows and the report says `skipped: ACL not built`.

use crate::codec::v3_encode::{self, Format, Options};
use crate::codec::{v3, v4, RAW_BYTES_PER_BONE};
use crate::corpus::Take;
use crate::{MocapError, Result};
use glam::{DQuat, DVec3};
use inbetween_core::{Motion, Pose};
use inbetween_io::report::{num, Table};
use rand::{Rng, SeedableRng};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Where the ACL race's sources are looked for: `$INBETWEEN_ACL_RACE`, else `peers/acl-race`
/// beside the data folder (`../shared/peers/acl-race` from the repository).
pub fn acl_sources(data_dir: &Path) -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("INBETWEEN_ACL_RACE") {
        return Some(PathBuf::from(p)).filter(|p| p.join("build.sh").exists());
    }
    let p = data_dir.ancestors().find_map(|a| {
        let c = a.join("peers/acl-race");
        c.join("build.sh").exists().then_some(c)
    });
    p.or_else(|| Some(PathBuf::from("../shared/peers/acl-race")).filter(|p| p.join("build.sh").exists()))
}

/// Builds ACL's compressor and decoder into `out` (kept between runs); None with the reason
/// when the sources or g++ are missing.
pub fn build_acl(sources: Option<&Path>, out: &Path) -> std::result::Result<PathBuf, String> {
    let Some(src) = sources else { return Err("no ACL sources (../shared/peers/acl-race)".into()) };
    if out.join("acl_compressor").exists() && out.join("acl_decode").exists() {
        return Ok(out.to_path_buf());
    }
    let gxx = Command::new("g++").arg("--version").output().map(|o| o.status.success()).unwrap_or(false);
    if !gxx {
        return Err("no g++".into());
    }
    std::fs::create_dir_all(out).map_err(|e| format!("creating {}: {e}", out.display()))?;
    let o = Command::new("bash")
        .arg(src.join("build.sh"))
        .arg(out)
        .output()
        .map_err(|e| format!("running {}: {e}", src.join("build.sh").display()))?;
    if !o.status.success() {
        return Err(format!("building ACL failed: {}", String::from_utf8_lossy(&o.stderr)));
    }
    Ok(out.to_path_buf())
}

/// The target folder ACL is built into: `$CARGO_TARGET_DIR/acl-race` or `target/acl-race`.
pub fn default_build_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|| PathBuf::from("target")).join("acl-race")
}

/// ACL's raw clip text of a take (lengths in cm).
pub fn acl_sjson(t: &Take, threshold_cm: f64, shell_cm: f64) -> String {
    let m = &t.motion;
    let cm = t.unit.cm_per_unit();
    let sk = &m.skeleton;
    let poses = m.poses();
    let mut s = String::new();
    let _ = write!(
        s,
        "version = 5\n\nclip =\n{{\n\tname = \"{}\"\n\tnum_samples = {}\n\tsample_rate = {:?}\n\tis_binary_exact = false\n\tadditive_format = \"none\"\n}}\n\n",
        t.name,
        m.num_frames(),
        1.0 / m.frame_time
    );
    let _ = write!(s, "settings =\n{{\n\terror_threshold = {threshold_cm:?}\n}}\n\nbones =\n[\n");
    for (j, jt) in sk.joints().iter().enumerate() {
        let parent = sk.parent(j).map(|p| sk.joints()[p].name.as_str()).unwrap_or("");
        let _ = write!(
            s,
            "\t{{\n\t\tname = \"{}\"\n\t\tparent = \"{parent}\"\n\t\tvertex_distance = {shell_cm:?}\n",
            jt.name
        );
        if sk.parent(j).is_some() {
            let o = jt.offset * cm;
            let _ = writeln!(s, "\t\tbind_translation = [ {:?}, {:?}, {:?} ]", o.x, o.y, o.z);
        }
        s.push_str("\t}\n");
    }
    s.push_str("]\n\ntracks =\n[\n");
    for (j, jt) in sk.joints().iter().enumerate() {
        let _ = write!(s, "\t{{\n\t\tname = \"{}\"\n\t\trotations =\n\t\t[\n", jt.name);
        for p in &poses {
            let q = p.rotations[j];
            let _ = writeln!(s, "\t\t\t[ {:?}, {:?}, {:?}, {:?} ]", q.x, q.y, q.z, q.w);
        }
        s.push_str("\t\t]\n\t\ttranslations =\n\t\t[\n");
        for p in &poses {
            let v = p.translations[j] * cm;
            let _ = writeln!(s, "\t\t\t[ {:?}, {:?}, {:?} ]", v.x, v.y, v.z);
        }
        s.push_str("\t\t]\n\t}\n");
    }
    s.push_str("]\n");
    s
}

/// `key = value` of ACL's stats text.
fn stat(text: &str, key: &str) -> Option<f64> {
    text.lines().find_map(|l| {
        let l = l.trim();
        let rest = l.strip_prefix(key)?.trim_start().strip_prefix('=')?;
        rest.trim().trim_end_matches(',').parse().ok()
    })
}

/// One codec on a group of takes at one bound.
#[derive(Clone, Debug, PartialEq)]
pub struct RaceRow {
    pub codec: String,
    pub bound_cm: f64,
    pub raw_bytes: usize,
    pub bytes: usize,
    pub max_cm: f64,
    pub p99_cm: f64,
    pub compress_mb_s: f64,
    /// µs per pose at a random time, and per pose in playback (60 Hz forwards); NaN: not measured.
    pub pose_us: f64,
    pub playback_us: f64,
}

impl RaceRow {
    pub fn ratio(&self) -> f64 {
        self.raw_bytes as f64 / self.bytes.max(1) as f64
    }
}

/// What ACL did with one take at one bound.
struct AclTake {
    bytes: usize,
    errors: Vec<f64>,
    compress_s: f64,
    pose_us: f64,
}

fn run_acl(bin: &Path, work: &Path, t: &Take, bound_cm: f64) -> Result<AclTake> {
    let io = |e: std::io::Error, p: &Path| MocapError::Io { path: p.display().to_string(), source: e };
    let stem = format!("{}_{bound_cm}", t.name.replace('/', "_"));
    let (src, out, stats, dump) = (
        work.join(format!("{stem}.acl.sjson")),
        work.join(format!("{stem}.acl")),
        work.join(format!("{stem}.stats.sjson")),
        work.join(format!("{stem}.f32")),
    );
    std::fs::write(&src, acl_sjson(t, bound_cm, v3_encode::SHELL_CM)).map_err(|e| io(e, &src))?;
    let o = Command::new(bin.join("acl_compressor"))
        .arg(format!("-acl={}", src.display()))
        .arg(format!("-out={}", out.display()))
        .arg(format!("-stats={}", stats.display()))
        .output()
        .map_err(|e| io(e, &bin.join("acl_compressor")))?;
    if !o.status.success() {
        return Err(MocapError::Invalid(format!(
            "acl_compressor on {}: {}",
            src.display(),
            String::from_utf8_lossy(&o.stderr)
        )));
    }
    let st = std::fs::read_to_string(&stats).map_err(|e| io(e, &stats))?;
    let file_bytes = std::fs::metadata(&out).map_err(|e| io(e, &out))?.len() as usize;
    let bytes = stat(&st, "compressed_size").map(|b| b as usize).unwrap_or(file_bytes);
    let compress_s = stat(&st, "compression_time").unwrap_or(f64::NAN);
    let o = Command::new(bin.join("acl_decode"))
        .arg(&out)
        .arg(&dump)
        .output()
        .map_err(|e| io(e, &bin.join("acl_decode")))?;
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    if !o.status.success() {
        return Err(MocapError::Invalid(format!(
            "acl_decode on {}: {}",
            out.display(),
            String::from_utf8_lossy(&o.stderr)
        )));
    }
    let pose_us = text
        .lines()
        .find_map(|l| l.strip_prefix("us_per_pose_random ").and_then(|v| v.trim().parse().ok()))
        .unwrap_or(f64::NAN);
    let raw = std::fs::read(&dump).map_err(|e| io(e, &dump))?;
    let m = &t.motion;
    let nj = m.skeleton.len();
    if raw.len() != m.num_frames() * nj * 28 {
        return Err(MocapError::Invalid(format!(
            "{}: {} bytes, expected {} frames × {nj} bones × 28",
            dump.display(),
            raw.len(),
            m.num_frames()
        )));
    }
    let cm = t.unit.cm_per_unit();
    let f = |i: usize| f32::from_le_bytes(raw[4 * i..4 * i + 4].try_into().expect("4 bytes")) as f64;
    let poses: Vec<Pose> = (0..m.num_frames())
        .map(|s| {
            let mut p = Pose { rotations: Vec::with_capacity(nj), translations: Vec::with_capacity(nj) };
            for j in 0..nj {
                let b = 7 * (s * nj + j);
                p.rotations.push(DQuat::from_xyzw(f(b), f(b + 1), f(b + 2), f(b + 3)).normalize());
                p.translations.push(DVec3::new(f(b + 4), f(b + 5), f(b + 6)) / cm);
            }
            p
        })
        .collect();
    let decoded = Motion::from_poses(m.skeleton.clone(), m.frame_time, &poses)?;
    let errors: Vec<f64> =
        v3_encode::vertex_errors(m, &decoded, cm, v3_encode::SHELL_CM).into_iter().map(|e| e * cm).collect();
    Ok(AclTake { bytes, errors, compress_s, pose_us })
}

/// The race on `takes` (one group) at `bounds`: ACL when `acl_bin` is given, our version 3 and
/// version 4 always (version 4 timed through the runtime sampler, version 3 through
/// `File::pose_at`).
pub fn race(
    takes: &[&Take],
    bounds: &[f64],
    acl_bin: Option<&Path>,
    seek_poses: usize,
    seed: u64,
) -> Result<Vec<RaceRow>> {
    let raw: usize = takes.iter().map(|t| t.raw_bytes()).sum();
    let mb = raw as f64 / 1e6;
    let mut rows = Vec::new();
    let work = std::env::temp_dir().join(format!("inbetween-acl-race-{}", std::process::id()));
    for &b in bounds {
        if let Some(bin) = acl_bin {
            std::fs::create_dir_all(&work)
                .map_err(|e| MocapError::Io { path: work.display().to_string(), source: e })?;
            let rs = takes.iter().map(|t| run_acl(bin, &work, t, b)).collect::<Result<Vec<_>>>()?;
            let mut errors: Vec<f64> = rs.iter().flat_map(|r| r.errors.iter().copied()).collect();
            rows.push(RaceRow {
                codec: "ACL 2.1 (defaults)".into(),
                bound_cm: b,
                raw_bytes: raw,
                bytes: rs.iter().map(|r| r.bytes).sum(),
                max_cm: errors.iter().copied().fold(0.0, f64::max),
                p99_cm: inbetween_core::stats::percentile(&mut errors, 0.99),
                compress_mb_s: mb / rs.iter().map(|r| r.compress_s).sum::<f64>(),
                pose_us: rs.iter().map(|r| r.pose_us).sum::<f64>() / rs.len() as f64,
                playback_us: f64::NAN,
            });
        }
        for format in [Format::V3, Format::V4] {
            let mut errors = Vec::new();
            let (mut bytes, mut secs, mut pose, mut play) = (0, 0.0, 0.0, 0.0);
            for t in takes {
                let r = run_format(t, b, format, seek_poses, seed)?;
                bytes += r.bytes;
                secs += r.compress_s;
                pose += r.pose_s;
                play += r.playback_s;
                errors.extend(r.errors);
            }
            let n = takes.len() as f64;
            rows.push(RaceRow {
                codec: format!("ours, .ibk version {}", format.version()),
                bound_cm: b,
                raw_bytes: raw,
                bytes,
                max_cm: errors.iter().copied().fold(0.0, f64::max),
                p99_cm: inbetween_core::stats::percentile(&mut errors, 0.99),
                compress_mb_s: mb / secs,
                pose_us: pose / n * 1e6,
                playback_us: play / n * 1e6,
            });
        }
    }
    let _ = std::fs::remove_dir_all(&work);
    Ok(rows)
}

/// The race table.
pub fn table(group: &str, rows: &[RaceRow], acl_note: &str) -> Table {
    let mut t = Table::new(
        "acl_race",
        &format!("Race against ACL on {group} at 24 fps: same takes, same bounds, one error metric (ours)"),
        &[
            "codec",
            "bound cm",
            "bytes",
            "ratio (40-byte raw)",
            "max error cm",
            "p99 error cm",
            "compress MB/s",
            "µs per random pose",
            "µs per playback pose",
        ],
    );
    for r in rows {
        let opt = |x: f64| if x.is_finite() { num(x, 2) } else { String::new() };
        t.row([
            r.codec.clone(),
            num(r.bound_cm, 2),
            r.bytes.to_string(),
            num(r.ratio(), 2),
            num(r.max_cm, 4),
            num(r.p99_cm, 4),
            opt(r.compress_mb_s),
            opt(r.pose_us),
            opt(r.playback_us),
        ]);
    }
    t.note(format!("raw = {RAW_BYTES_PER_BONE} bytes per bone per sample (quaternion, translation, scale as f32); bytes: whole files (ours: header, skeleton with joint names, checksum; ACL: the compressed_size of its stats)"));
    t.note("errors: each joint's largest of three vertices 3 cm along its local axes, object space, every frame of the decoded clip against the source (ACL's output read back from acl_decode's f32 dump); ACL's bound column is its error_threshold (a target), ours a bound on every frame".to_string());
    t.note("speeds on one core: compress MB/s of raw (ACL: its own compression_time); random pose: two samples interpolated, context made once (ACL: acl_decode's best of 5 rounds of 2000 poses; ours: the same count, best of 3 rounds); playback: every 1/60 s from the start with one context (acl_decode does not time playback)".to_string());
    t.note(acl_note.to_string());
    t
}

/// One take compressed in `format` at `bound_cm` (the format's default segment length), with
/// its timings on this thread: what the race against ACL runs.
pub struct FormatResult {
    pub bytes: usize,
    pub errors: Vec<f64>,
    pub compress_s: f64,
    /// Seconds per pose at a random time and per playback pose (best of 5 rounds).
    pub pose_s: f64,
    pub playback_s: f64,
}

/// Best of `rounds` timings of `f`, seconds.
fn best_of(rounds: usize, mut f: impl FnMut()) -> f64 {
    f();
    (0..rounds)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

pub fn run_format(t: &Take, bound_cm: f64, format: Format, seek_poses: usize, seed: u64) -> Result<FormatResult> {
    let opts = Options::with_format(bound_cm, format);
    let start = Instant::now();
    let c = v3_encode::compress_in(&t.motion, t.unit.clone(), &opts)?;
    let compress_s = start.elapsed().as_secs_f64();
    let mut rng =
        rand_chacha::ChaCha8Rng::seed_from_u64(inbetween_core::seed::derive(seed, t.motion.num_frames() as u64));
    let duration = (t.motion.num_frames() - 1) as f64 * t.motion.frame_time;
    let times: Vec<f64> = (0..seek_poses.max(1)).map(|_| rng.random::<f64>() * duration).collect();
    let ticks: Vec<f64> = (0..).map(|k| k as f64 / 60.0).take_while(|&t| t <= duration).collect();
    let (pose_s, playback_s) = match format {
        Format::V3 => {
            let file = v3::File::open(&c.bytes)?;
            let (mut pose, mut sc) = (inbetween_core::Pose::rest(&t.motion.skeleton), v3::Scratch::default());
            let mut timed = |ts: &[f64]| {
                best_of(5, || {
                    for &time in ts {
                        file.pose_at(time, &mut pose, &mut sc).expect("a valid file seeks");
                    }
                    std::hint::black_box(&pose);
                }) / ts.len() as f64
            };
            (timed(&times), timed(&ticks))
        }
        Format::V4 => {
            let clip = v4::Clip::open(&c.bytes).map_err(|e| MocapError::Codec(e.to_string()))?;
            let mut ctx = v4::Context::new(&clip);
            let n = clip.num_joints();
            let (mut rot, mut tr) = (vec![[0f32; 4]; n], vec![[0f32; 3]; n]);
            let mut timed = |ts: &[f64]| {
                best_of(5, || {
                    for &time in ts {
                        clip.sample(&mut ctx, time, &mut rot, &mut tr).expect("buffers fit");
                    }
                    std::hint::black_box((&rot, &tr));
                }) / ts.len() as f64
            };
            (timed(&times), timed(&ticks))
        }
    };
    Ok(FormatResult { bytes: c.bytes.len(), errors: c.errors_cm, compress_s, pose_s, playback_s })
}
