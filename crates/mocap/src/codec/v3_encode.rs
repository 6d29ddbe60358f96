//! The version 3 encoder: step sizes chosen per track and per segment so that the decoded clip
//! keeps every virtual vertex within the error bound (ACL's error metric: three vertices
//! `shell_cm` from each joint along its local axes, in object space, through the hierarchy).
//!
//! Per segment (32 frames by default, in parallel):
//! 1. a starting step per track that is safe by construction: a rotation error δ of joint j moves
//!    a vertex of a descendant by at most δ × (its distance from j), a translation error moves it
//!    by the error itself, and errors add along a chain. Each track gets an equal share of the
//!    bound along its longest chain: `step = (2/√3) · bound / (reach × tracks on the chain)`
//!    (a rotation vector component rounded by step/2 turns a joint by at most (√3/2) · step);
//! 2. every step is coarsened together (quarter octaves) while the measured error of the
//!    segment's decoded frames stays within the bound (the worst-case sum is far from the
//!    typical one);
//! 3. then each track alone, in sweeps, while its subtree's vertices stay within the bound: the
//!    joint whose error dominates keeps its fine steps, the others get coarser.
//!
//! Every check quantises exactly as the decoder dequantises, so the bound holds for the file.

use super::v3::{self, step, Header, Quantised, Track, TrackKind, MAX_Q, STEP_BIAS};
use super::v4;
use crate::{MocapError, Result};
use glam::{DMat3, DQuat, DVec3};
use inbetween_core::rotation::{quat_to_rotvec, rotvec_to_quat};
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::{Motion, Skeleton};
use rayon::prelude::*;

/// ACL's virtual vertex distance (its CMU protocol).
pub const SHELL_CM: f64 = 3.0;

/// Version 3 compression settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Largest virtual-vertex error of the decoded clip, cm.
    pub bound_cm: f64,
    /// Distance of the virtual vertices from each joint, cm.
    pub shell_cm: f64,
    pub segment_len: usize,
    /// The file version written (and whose decoded values the search checks).
    pub format: Format,
}

/// Which sampled version [`compress_in`] writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Version 3: f64 values, Rice-coded prediction residuals (smallest files).
    V3,
    /// Version 4: f32 values at fixed widths per segment (fast sampling, [`v4`]).
    V4,
}

impl Format {
    /// The version number it writes.
    pub fn version(self) -> u16 {
        match self {
            Format::V3 => v3::VERSION,
            Format::V4 => v4::VERSION,
        }
    }

    /// Frames per segment written by default.
    pub fn default_segment_len(self) -> usize {
        match self {
            Format::V3 => v3::DEFAULT_SEGMENT_LEN,
            Format::V4 => v4::DEFAULT_SEGMENT_LEN,
        }
    }
}

impl Options {
    /// ACL's protocol at `bound_cm`: vertices 3 cm away, version 3 with 32-frame segments.
    pub fn bound(bound_cm: f64) -> Options {
        Options { bound_cm, shell_cm: SHELL_CM, segment_len: v3::DEFAULT_SEGMENT_LEN, format: Format::V3 }
    }

    /// ACL's protocol at `bound_cm` in `format`, with its default segment length.
    pub fn with_format(bound_cm: f64, format: Format) -> Options {
        Options { segment_len: format.default_segment_len(), format, ..Options::bound(bound_cm) }
    }
}

/// A compressed clip and the error of its decoded file.
#[derive(Clone, Debug)]
pub struct Compressed {
    pub bytes: Vec<u8>,
    pub quantised: Quantised,
    /// Virtual-vertex errors of the decoded file, cm: the largest, and the 99th percentile over
    /// every joint of every frame (each joint's error is the largest of its three vertices).
    pub max_error_cm: f64,
    pub p99_error_cm: f64,
    /// Every joint's error at every frame (frame-major), cm.
    pub errors_cm: Vec<f64>,
    pub unit: UnitChoice,
}

/// [`compress_in`] with the length unit inferred from the skeleton.
pub fn compress(motion: &Motion, opts: &Options) -> Result<Compressed> {
    compress_in(motion, LengthUnit::infer(&motion.skeleton), opts)
}

/// Compresses every frame of `motion` (lengths in `unit`) so that no virtual vertex of the
/// decoded clip is more than `opts.bound_cm` from the source's.
pub fn compress_in(motion: &Motion, unit: UnitChoice, opts: &Options) -> Result<Compressed> {
    let cm = unit.cm_per_unit();
    if !(opts.bound_cm.is_finite() && opts.bound_cm > 0.0) {
        return Err(MocapError::Invalid(format!("max error {} cm must be a positive number", opts.bound_cm)));
    }
    if !(opts.shell_cm.is_finite() && opts.shell_cm >= 0.0) {
        return Err(MocapError::Invalid(format!("virtual vertex distance {} cm must be non-negative", opts.shell_cm)));
    }
    if !(1..=v3::MAX_SEGMENT_LEN).contains(&opts.segment_len) {
        return Err(MocapError::Invalid(format!(
            "segment length {} must be 1 to {}",
            opts.segment_len,
            v3::MAX_SEGMENT_LEN
        )));
    }
    if motion.num_frames() == 0 {
        return Err(MocapError::Invalid("a clip of 0 frames has nothing to compress".into()));
    }
    let ctx = Context::new(motion, opts.shell_cm / cm, opts.bound_cm / cm, opts.format);
    let n = motion.num_frames();
    let nt = ctx.tracks.len();
    let segments = n.div_ceil(opts.segment_len);
    let chosen: Vec<SegmentChoice> = (0..segments)
        .into_par_iter()
        .map(|s| {
            let start = s * opts.segment_len;
            ctx.segment(start, (start + opts.segment_len).min(n))
        })
        .collect();
    let mut q = Vec::with_capacity(n * nt);
    let mut codes = Vec::with_capacity(segments * nt);
    for c in chosen {
        q.extend(c.q);
        codes.extend(c.codes);
    }
    let quantised = Quantised { header: ctx.header(motion, opts.segment_len, cm, opts.bound_cm), codes, q };
    // Measure the file, not the encoder's state.
    let (bytes, decoded, mut errors) = match opts.format {
        Format::V3 => {
            let bytes = v3::encode(&quantised);
            let decoded = v3::decode(&bytes)?;
            let errors = ctx.errors(|f| decoded.pose(f));
            (bytes, decoded, errors)
        }
        Format::V4 => {
            let bytes = v4::encode(&quantised);
            let d = v4::decode(&bytes)?;
            let errors = ctx.errors(|f| d.poses[f].clone());
            (bytes, quantised, errors)
        }
    };
    for e in &mut errors {
        *e *= cm;
    }
    let max_error_cm = errors.iter().copied().fold(0.0, f64::max);
    if max_error_cm > opts.bound_cm {
        return Err(MocapError::Invalid(format!(
            "the decoded file exceeds the bound: {max_error_cm} cm > {} cm",
            opts.bound_cm
        )));
    }
    let p99_error_cm = inbetween_core::stats::percentile(&mut errors.clone(), 0.99);
    Ok(Compressed { bytes, quantised: decoded, max_error_cm, p99_error_cm, errors_cm: errors, unit })
}

/// Virtual-vertex errors (file units) of `decoded` against `source`, one per joint and frame:
/// the largest of each joint's three vertices `shell_cm` away (ACL's metric).
pub fn vertex_errors(source: &Motion, decoded: &Motion, cm_per_unit: f64, shell_cm: f64) -> Vec<f64> {
    let ctx = Context::new(source, shell_cm / cm_per_unit, f64::INFINITY, Format::V3);
    let nj = source.skeleton.len();
    let mut out = Vec::with_capacity(source.num_frames() * nj);
    for f in 0..source.num_frames().min(decoded.num_frames()) {
        let g = inbetween_core::forward(&decoded.skeleton, &decoded.pose(f));
        for j in 0..nj {
            out.push(ctx.vertex_error(f, j, g.positions[j], g.rotations[j]));
        }
    }
    out
}

/// The clip as the encoder sees it.
struct Context {
    skeleton: Skeleton,
    tracks: Vec<Track>,
    /// Per track: its value when constant over the whole clip.
    constants: Vec<Option<[f32; 3]>>,
    /// Source values, frames × tracks.
    values: Vec<DVec3>,
    /// Per joint: its rotation and translation track.
    joint_tracks: Vec<(Option<usize>, Option<usize>)>,
    /// Source vertices, frames × joints: the joint and its three shell vertices (object space).
    raw: Vec<[DVec3; 4]>,
    /// Per joint: itself and every descendant, in order.
    subtree: Vec<Vec<usize>>,
    /// Per track: the starting step code.
    start_codes: Vec<u8>,
    shell: f64,
    bound: f64,
    format: Format,
    /// What the search compares squared errors with: the bound less a little, squared.
    bound_sq: f64,
}

/// A segment's chosen step codes and quantised values.
struct SegmentChoice {
    codes: Vec<u8>,
    q: Vec<[i64; 3]>,
}

impl Context {
    fn new(motion: &Motion, shell: f64, bound: f64, format: Format) -> Context {
        let sk = &motion.skeleton;
        let (n, nj) = (motion.num_frames(), sk.len());
        let tracks = v3::tracks(sk);
        let poses = motion.poses();
        let mut values = Vec::with_capacity(n * tracks.len());
        let mut raw = Vec::with_capacity(n * nj);
        for p in &poses {
            values.extend(tracks.iter().map(|t| match t.kind {
                TrackKind::Rotation => quat_to_rotvec(p.rotations[t.joint]),
                TrackKind::Translation => p.translations[t.joint],
            }));
            let g = inbetween_core::forward(sk, p);
            raw.extend((0..nj).map(|j| shell_vertices(g.positions[j], g.rotations[j], shell)));
        }
        let nt = tracks.len();
        let constants: Vec<Option<[f32; 3]>> = (0..nt)
            .map(|t| {
                let v0 = values[t];
                let constant = (0..n).all(|f| (values[f * nt + t] - v0).abs().max_element() <= 1e-9);
                constant.then(|| v0.to_array().map(|x| x as f32))
            })
            .collect();
        let mut joint_tracks = vec![(None, None); nj];
        for (i, t) in tracks.iter().enumerate() {
            match t.kind {
                TrackKind::Rotation => joint_tracks[t.joint].0 = Some(i),
                TrackKind::Translation => joint_tracks[t.joint].1 = Some(i),
            }
        }
        let mut subtree: Vec<Vec<usize>> = (0..nj).map(|j| vec![j]).collect();
        for k in (1..nj).rev() {
            let mut a = sk.parent(k);
            while let Some(p) = a {
                subtree[p].push(k);
                a = sk.parent(p);
            }
        }
        for s in &mut subtree {
            s.sort_unstable();
        }
        let mut ctx = Context {
            skeleton: sk.clone(),
            tracks,
            constants,
            values,
            joint_tracks,
            raw,
            subtree,
            start_codes: Vec::new(),
            shell,
            bound,
            format,
            bound_sq: (bound * (1.0 - 1e-9)).powi(2),
        };
        ctx.start_codes = ctx.safe_codes();
        ctx
    }

    /// Step codes that keep the bound by the worst-case sum (module doc, step 1).
    fn safe_codes(&self) -> Vec<u8> {
        let sk = &self.skeleton;
        let (nj, nt) = (sk.len(), self.tracks.len());
        let n = self.raw.len() / nj.max(1);
        // Reach of each joint: the farthest vertex of its subtree over the clip.
        let mut reach = vec![self.shell; nj];
        for f in 0..n {
            for (j, r) in reach.iter_mut().enumerate() {
                let p = self.raw[f * nj + j][0];
                for &k in &self.subtree[j] {
                    *r = r.max((self.raw[f * nj + k][0] - p).length() + self.shell);
                }
            }
        }
        // Animated tracks on the longest chain through each joint.
        let own: Vec<usize> = (0..nj)
            .map(|j| {
                let (r, t) = self.joint_tracks[j];
                [r, t].iter().flatten().filter(|&&i| self.constants[i].is_none()).count()
            })
            .collect();
        let mut up = own.clone();
        for j in 1..nj {
            up[j] += up[sk.parent(j).expect("non-root joints have parents")];
        }
        let mut down = own.clone();
        for j in (1..nj).rev() {
            let p = sk.parent(j).expect("non-root joints have parents");
            down[p] = down[p].max(own[p] + down[j]);
        }
        let max_abs: Vec<f64> =
            (0..nt).map(|t| (0..n).map(|f| self.values[f * nt + t].abs().max_element()).fold(0.0, f64::max)).collect();
        (0..nt)
            .map(|t| {
                let j = self.tracks[t].joint;
                let chain = (up[j] + down[j] - own[j]).max(1) as f64;
                let lever = match self.tracks[t].kind {
                    TrackKind::Rotation => reach[j],
                    TrackKind::Translation => 1.0,
                };
                let s = 2.0 / 3f64.sqrt() * self.bound / (lever.max(1e-12) * chain);
                let code = (4.0 * s.log2()).floor() + STEP_BIAS as f64;
                // Coarse enough that |q| ≤ MAX_Q.
                let least = (4.0 * (max_abs[t] / MAX_Q as f64).log2()).ceil() + STEP_BIAS as f64;
                code.max(least).clamp(0.0, 255.0) as u8
            })
            .collect()
    }

    /// Virtual-vertex error (file units) of joint `j` at frame `f` placed at `pos`, `rot`.
    fn vertex_error(&self, f: usize, j: usize, pos: DVec3, rot: DQuat) -> f64 {
        let raw = &self.raw[f * self.skeleton.len() + j];
        let v = shell_vertices(pos, rot, self.shell);
        (1..4).map(|a| (v[a] - raw[a]).length()).fold(0.0, f64::max)
    }

    /// The square of [`Context::vertex_error`] (what the search compares, without roots).
    fn vertex_error_sq(&self, f: usize, j: usize, pos: DVec3, rot: DQuat) -> f64 {
        let raw = &self.raw[f * self.skeleton.len() + j];
        let v = shell_vertices(pos, rot, self.shell);
        (1..4).map(|a| (v[a] - raw[a]).length_squared()).fold(0.0, f64::max)
    }

    /// The file header of `motion` (the clip this context was made from) with these settings.
    fn header(&self, motion: &Motion, segment_len: usize, cm_per_unit: f64, bound_cm: f64) -> Header {
        Header {
            skeleton: self.skeleton.clone(),
            frame_time: motion.frame_time,
            num_frames: motion.num_frames(),
            segment_len,
            cm_per_unit,
            bound_cm,
            tracks: self.tracks.clone(),
            constants: self.constants.clone(),
        }
    }

    /// Errors of every joint of every frame of a decoded clip (`pose(f)`: its frame `f`).
    fn errors(&self, pose: impl Fn(usize) -> inbetween_core::Pose) -> Vec<f64> {
        let nj = self.skeleton.len();
        let n = self.raw.len() / nj.max(1);
        let mut out = Vec::with_capacity(n * nj);
        let (mut pos, mut rot) = (vec![DVec3::ZERO; nj], vec![DQuat::IDENTITY; nj]);
        for f in 0..n {
            let p = pose(f);
            crate::rotations::forward_into(&self.skeleton, &p.rotations, &p.translations, &mut pos, &mut rot);
            out.extend((0..nj).map(|j| self.vertex_error(f, j, pos[j], rot[j])));
        }
        out
    }

    /// Chooses the step codes of frames `start..end` (module doc, steps 2–3).
    fn segment(&self, start: usize, end: usize) -> SegmentChoice {
        let mut s = Segment::new(self, start, end);
        // Step 2: all tracks coarser together, by doubling then bisection of the shift.
        let animated: Vec<usize> = (0..self.tracks.len()).filter(|&t| self.constants[t].is_none()).collect();
        let base = s.codes.clone();
        let shifted = |d: i64| -> Vec<u8> {
            base.iter()
                .enumerate()
                .map(|(t, &c)| if self.constants[t].is_none() { (c as i64 + d).clamp(0, 255) as u8 } else { c })
                .collect()
        };
        // The starting codes hold by construction; should rounding say otherwise, go finer.
        let mut lo = 0i64;
        while !s.try_all(&shifted(lo)) {
            if lo < -256 {
                // Not even the finest steps fit: the caller's check of the file reports it.
                return SegmentChoice { codes: s.codes, q: s.q };
            }
            lo -= 4;
        }
        let mut stride = 4;
        let mut hi = lo + stride;
        while stride <= 128 && s.try_all(&shifted(hi)) {
            lo = hi;
            stride *= 2;
            hi = lo + stride;
        }
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if s.try_all(&shifted(mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        s.try_all(&shifted(lo));
        // Step 3: each track on its own, coarser while its subtree stays within the bound.
        for _sweep in 0..2 {
            let mut changed = false;
            for &t in &animated {
                for inc in [4u8, 2, 1] {
                    while s.codes[t] as u16 + inc as u16 <= 255 && s.try_track(t, s.codes[t] + inc) {
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        SegmentChoice { codes: s.codes, q: s.q }
    }
}

/// A joint's position and its three shell vertices along its local axes.
fn shell_vertices(pos: DVec3, rot: DQuat, shell: f64) -> [DVec3; 4] {
    let m = DMat3::from_quat(rot);
    [pos, pos + m.x_axis * shell, pos + m.y_axis * shell, pos + m.z_axis * shell]
}

/// The search state of one segment: current codes, quantised values, local and object-space
/// transforms of its frames.
struct Segment<'a> {
    ctx: &'a Context,
    start: usize,
    len: usize,
    codes: Vec<u8>,
    /// len × tracks
    q: Vec<[i64; 3]>,
    /// len × joints: local rotation and translation as decoded.
    lrot: Vec<DQuat>,
    ltr: Vec<DVec3>,
    /// len × joints: object-space transforms.
    orot: Vec<DQuat>,
    opos: Vec<DVec3>,
    /// The frame where the last try failed.
    hot: usize,
}

impl<'a> Segment<'a> {
    fn new(ctx: &'a Context, start: usize, end: usize) -> Segment<'a> {
        let (nj, nt, len) = (ctx.skeleton.len(), ctx.tracks.len(), end - start);
        let mut s = Segment {
            ctx,
            start,
            len,
            codes: ctx.start_codes.clone(),
            q: vec![[0; 3]; len * nt],
            lrot: vec![DQuat::IDENTITY; len * nj],
            // Version 4 decodes rest offsets as f32.
            ltr: (0..len)
                .flat_map(|_| {
                    ctx.skeleton.joints().iter().map(|j| match ctx.format {
                        Format::V3 => j.offset,
                        Format::V4 => j.offset.as_vec3().as_dvec3(),
                    })
                })
                .collect(),
            orot: vec![DQuat::IDENTITY; len * nj],
            opos: vec![DVec3::ZERO; len * nj],
            hot: 0,
        };
        for t in 0..nt {
            let (mut q, mut v) = (vec![[0; 3]; len], vec![DVec3::ZERO; len]);
            s.quantise(t, s.codes[t], &mut q, &mut v);
            s.store(t, &q, &v);
        }
        s
    }

    /// Quantised values and decoded values of track `t` at step code `code`.
    fn quantise(&self, t: usize, code: u8, q: &mut [[i64; 3]], v: &mut [DVec3]) {
        let nt = self.ctx.tracks.len();
        if let Some(c) = self.ctx.constants[t] {
            v.fill(DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64));
            q.fill([0; 3]);
            return;
        }
        let st = match self.ctx.format {
            Format::V3 => step(code),
            Format::V4 => v4::step(code) as f64,
        };
        for i in 0..self.len {
            let x = self.ctx.values[(self.start + i) * nt + t];
            let qi = [x.x, x.y, x.z].map(|c| ((c / st).round() as i64).clamp(-MAX_Q, MAX_Q));
            q[i] = qi;
            v[i] = DVec3::new(qi[0] as f64 * st, qi[1] as f64 * st, qi[2] as f64 * st);
        }
        if self.ctx.format == Format::V4 {
            // The runtime's f32 values: (q_min × scale) + (q − q_min) × scale per component.
            let (mut comp, mut out) = (vec![0i64; self.len], vec![0f32; self.len]);
            for c in 0..3 {
                comp.iter_mut().zip(q.iter()).for_each(|(x, qi)| *x = qi[c]);
                v4::dequantise(&comp, code, &mut out);
                for (vi, &o) in v.iter_mut().zip(&out) {
                    vi[c] = o as f64;
                }
            }
        }
    }

    /// The local rotation the decoder gives for a decoded rotation vector.
    fn rotation(&self, v: DVec3) -> DQuat {
        match self.ctx.format {
            Format::V3 => rotvec_to_quat(v),
            Format::V4 => v4::rotation([v.x as f32, v.y as f32, v.z as f32]),
        }
    }

    fn store(&mut self, t: usize, q: &[[i64; 3]], v: &[DVec3]) {
        let (nj, nt) = (self.ctx.skeleton.len(), self.ctx.tracks.len());
        let tr = self.ctx.tracks[t];
        for i in 0..self.len {
            self.q[i * nt + t] = q[i];
            match tr.kind {
                TrackKind::Rotation => self.lrot[i * nj + tr.joint] = self.rotation(v[i]),
                TrackKind::Translation => self.ltr[i * nj + tr.joint] = v[i],
            }
        }
    }

    /// Object-space transforms of `joints` (a subtree, in order) at frame `i` into `pos`/`rot`
    /// (indexed like `joints`), with the local rotation of `over` replaced; false as soon as a
    /// vertex leaves the bound.
    fn fk_check(
        &self,
        i: usize,
        joints: &[usize],
        over: Option<(usize, DQuat)>,
        pos: &mut [DVec3],
        rot: &mut [DQuat],
    ) -> bool {
        let nj = self.ctx.skeleton.len();
        for (a, &j) in joints.iter().enumerate() {
            let lr = match over {
                Some((oj, q)) if oj == j => q,
                _ => self.lrot[i * nj + j],
            };
            let lt = self.ltr[i * nj + j];
            let (p, r) = match self.ctx.skeleton.parent(j) {
                None => (lt, lr),
                Some(par) => {
                    // The parent is earlier in `joints` when inside the subtree, else committed.
                    let (pp, pr) = match joints[..a].binary_search(&par) {
                        Ok(b) => (pos[b], rot[b]),
                        Err(_) => (self.opos[i * nj + par], self.orot[i * nj + par]),
                    };
                    (pp + pr * lt, pr * lr)
                }
            };
            pos[a] = p;
            rot[a] = r;
            if self.ctx.vertex_error_sq(self.start + i, j, p, r) > self.ctx.bound_sq {
                return false;
            }
        }
        true
    }

    /// Tries every code at once; keeps them when every vertex of every frame fits.
    fn try_all(&mut self, codes: &[u8]) -> bool {
        let (nj, nt) = (self.ctx.skeleton.len(), self.ctx.tracks.len());
        let saved = (self.codes.clone(), self.q.clone(), self.lrot.clone(), self.ltr.clone());
        let (mut q, mut v) = (vec![[0; 3]; self.len], vec![DVec3::ZERO; self.len]);
        for (t, &code) in codes.iter().enumerate().take(nt) {
            self.quantise(t, code, &mut q, &mut v);
            self.store(t, &q, &v);
        }
        let all: Vec<usize> = (0..nj).collect();
        let (mut pos, mut rot) = (vec![DVec3::ZERO; nj], vec![DQuat::IDENTITY; nj]);
        let mut new_pos = Vec::with_capacity(self.len * nj);
        let mut new_rot = Vec::with_capacity(self.len * nj);
        for i in 0..self.len {
            if !self.fk_check(i, &all, None, &mut pos, &mut rot) {
                (self.codes, self.q, self.lrot, self.ltr) = saved;
                return false;
            }
            new_pos.extend_from_slice(&pos);
            new_rot.extend_from_slice(&rot);
        }
        self.codes = codes.to_vec();
        self.opos = new_pos;
        self.orot = new_rot;
        true
    }

    /// Tries code `code` for track `t` alone; keeps it when its subtree fits on every frame.
    fn try_track(&mut self, t: usize, code: u8) -> bool {
        let ctx = self.ctx;
        let nj = ctx.skeleton.len();
        let tr = ctx.tracks[t];
        let joints = &ctx.subtree[tr.joint];
        let (mut q, mut v) = (vec![[0; 3]; self.len], vec![DVec3::ZERO; self.len]);
        self.quantise(t, code, &mut q, &mut v);
        let saved_tr: Vec<DVec3> = (0..self.len).map(|i| self.ltr[i * nj + tr.joint]).collect();
        if tr.kind == TrackKind::Translation {
            for (i, x) in v.iter().enumerate() {
                self.ltr[i * nj + tr.joint] = *x;
            }
        }
        let m = joints.len();
        let (mut pos, mut rot) = (vec![DVec3::ZERO; self.len * m], vec![DQuat::IDENTITY; self.len * m]);
        // The frame that failed last is checked first: most tries that fail, fail there.
        for i in (self.hot..self.len).chain(0..self.hot) {
            let over = (tr.kind == TrackKind::Rotation).then(|| (tr.joint, self.rotation(v[i])));
            let (p, r) = (&mut pos[i * m..(i + 1) * m], &mut rot[i * m..(i + 1) * m]);
            if !self.fk_check(i, joints, over, p, r) {
                for (i, x) in saved_tr.iter().enumerate() {
                    self.ltr[i * nj + tr.joint] = *x;
                }
                self.hot = i;
                return false;
            }
        }
        self.codes[t] = code;
        self.store(t, &q, &v);
        for i in 0..self.len {
            for (a, &j) in joints.iter().enumerate() {
                self.opos[i * nj + j] = pos[i * m + a];
                self.orot[i * nj + j] = rot[i * m + a];
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::procedural::{gait, GaitParams, CM_PER_CMU_UNIT};
    use inbetween_core::units::{scale_motion, LengthUnit};

    fn clips() -> Vec<Motion> {
        let mut walk = GaitParams::walk();
        walk.frames = 50;
        walk.fps = 24.0;
        let mut run = GaitParams::run();
        run.frames = 70;
        run.fps = 60.0;
        let mut turn = GaitParams::walk();
        turn.frames = 45;
        turn.fps = 24.0;
        turn.turn_rate = 2.5;
        vec![gait(&walk), gait(&run), gait(&turn)]
    }

    /// Oracle: the virtual-vertex error computed from scratch with the core's forward kinematics
    /// on the decoded file's BVH channels (through Euler angles, so within rounding).
    fn oracle_max_cm(source: &Motion, decoded: &Motion, cm: f64) -> f64 {
        let mut max = 0.0f64;
        for f in 0..source.num_frames() {
            let (a, b) = (
                inbetween_core::forward(&source.skeleton, &source.pose(f)),
                inbetween_core::forward(&decoded.skeleton, &decoded.pose(f)),
            );
            for j in 0..source.skeleton.len() {
                for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                    let v = axis * (SHELL_CM / cm);
                    let d = (a.positions[j] + a.rotations[j] * v) - (b.positions[j] + b.rotations[j] * v);
                    max = max.max(d.length() * cm);
                }
            }
        }
        max
    }

    #[test]
    fn the_decoded_file_keeps_every_bound_and_looser_bounds_compress_more() {
        for (i, m) in clips().iter().enumerate() {
            let mut last_bytes = usize::MAX;
            for bound in [0.01, 0.05, 0.2, 1.0] {
                let c = compress(m, &Options::bound(bound)).unwrap();
                assert_eq!(c.unit.unit, LengthUnit::Cmu);
                let file = crate::codec::read(&c.bytes).unwrap();
                let decoded = file.motion().unwrap();
                assert_eq!(decoded.num_frames(), m.num_frames());
                let oracle = oracle_max_cm(m, &decoded, CM_PER_CMU_UNIT);
                assert!(c.max_error_cm <= bound, "clip {i}, {bound} cm: {}", c.max_error_cm);
                assert!(oracle <= bound * (1.0 + 1e-6), "clip {i}, {bound} cm: oracle {oracle}");
                assert!((oracle - c.max_error_cm).abs() < 1e-6 * bound.max(1.0), "{oracle} vs {}", c.max_error_cm);
                // Tight: the search spends the bound rather than bits.
                assert!(c.max_error_cm > 0.5 * bound, "clip {i}, {bound} cm: only {} cm", c.max_error_cm);
                assert!(c.p99_error_cm <= c.max_error_cm && c.p99_error_cm > 0.0);
                assert!(c.bytes.len() < last_bytes, "clip {i}: {bound} cm takes {} bytes", c.bytes.len());
                last_bytes = c.bytes.len();
            }
            // 0.05 cm on a 24-60 fps clip: well over ACL's 40-byte raw ratio of 5.
            let c = compress(m, &Options::bound(0.05)).unwrap();
            let raw = 40 * m.skeleton.len() * m.num_frames();
            assert!(raw as f64 / c.bytes.len() as f64 > 5.0, "clip {i}: {} of {raw}", c.bytes.len());
        }
    }

    /// The starting steps keep the bound by the worst-case argument alone (module doc, step 1):
    /// a file written with them, before any search, is within the bound.
    #[test]
    fn the_safe_starting_steps_keep_the_bound_without_search() {
        for m in clips() {
            let ctx = Context::new(&m, SHELL_CM / CM_PER_CMU_UNIT, 0.05 / CM_PER_CMU_UNIT, Format::V3);
            let (n, nt) = (m.num_frames(), ctx.tracks.len());
            let seg = Segment::new(&ctx, 0, n);
            let header = ctx.header(&m, n, CM_PER_CMU_UNIT, 0.05);
            let qz = Quantised { header, codes: ctx.start_codes.clone(), q: seg.q.clone() };
            assert_eq!(qz.codes.len(), nt);
            let max = ctx.errors(|f| qz.pose(f)).into_iter().fold(0.0, f64::max) * CM_PER_CMU_UNIT;
            assert!(max <= 0.05, "{max}");
            // ... and are far from tight: the search has room to coarsen.
            assert!(max < 0.025, "{max}");
        }
    }

    #[test]
    fn the_same_clip_in_any_unit_gives_the_same_errors_in_cm() {
        let m = &clips()[1];
        let reference = compress(m, &Options::bound(0.05)).unwrap();
        for unit in [LengthUnit::Centimetre, LengthUnit::Metre, LengthUnit::Inch] {
            let scaled = scale_motion(m, CM_PER_CMU_UNIT / unit.cm_per_unit());
            let c = compress_in(&scaled, UnitChoice::given(unit), &Options::bound(0.05)).unwrap();
            assert!(c.max_error_cm <= 0.05 && c.max_error_cm > 0.025, "{unit}: {}", c.max_error_cm);
            let rel = c.bytes.len() as f64 / reference.bytes.len() as f64;
            assert!((0.9..1.1).contains(&rel), "{unit}: {} vs {} bytes", c.bytes.len(), reference.bytes.len());
        }
    }

    #[test]
    fn static_joints_become_constant_tracks_and_bad_options_are_refused() {
        let m = &clips()[0];
        let c = compress(m, &Options::bound(0.05)).unwrap();
        let constant = c.quantised.header.constants.iter().filter(|x| x.is_some()).count();
        let static_joints = (0..v3::tracks(&m.skeleton).len())
            .filter(|&t| {
                let tr = v3::tracks(&m.skeleton)[t];
                tr.kind == TrackKind::Rotation
                    && (0..m.num_frames()).all(|f| m.pose(f).rotations[tr.joint] == m.pose(0).rotations[tr.joint])
            })
            .count();
        assert!(
            static_joints > 0 && constant >= static_joints,
            "{constant} constant tracks, {static_joints} static joints"
        );
        for bad in [0.0, -1.0, f64::NAN] {
            let e = compress(m, &Options::bound(bad)).unwrap_err().to_string();
            assert!(e.contains("must be a positive number"), "{e}");
        }
        let e = compress(m, &Options { segment_len: 0, ..Options::bound(0.05) }).unwrap_err().to_string();
        assert!(e.contains("segment length"), "{e}");
    }

    /// What the fuzz target (`fuzz/fuzz_targets/ibk.rs`) does to version 3 files, on seeded
    /// random changes behind a valid checksum: reading returns, never panics.
    #[test]
    fn reading_damaged_version_3_files_never_panics() {
        use rand::{Rng, SeedableRng};
        let m = &clips()[2];
        let good = compress(m, &Options::bound(0.1)).unwrap().bytes;
        let body = &good[..good.len() - 4];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for case in 0..1500 {
            let mut b = body.to_vec();
            match case % 3 {
                0 => {
                    for _ in 0..rng.random_range(1..6) {
                        let i = rng.random_range(6..b.len());
                        b[i] = rng.random();
                    }
                }
                1 => b.truncate(rng.random_range(0..b.len())),
                _ => {
                    let at = rng.random_range(8..b.len() - 4);
                    b[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
                }
            }
            let crc = crc32fast::hash(&b);
            b.extend_from_slice(&crc.to_le_bytes());
            if let Ok(f) = crate::codec::read(&b) {
                if f.num_frames() * f.skeleton().len() <= 100_000 {
                    let _ = f.motion();
                }
            }
            if let Ok(f) = v3::File::open(&b) {
                let (mut pose, mut sc) = (inbetween_core::Pose::rest(&f.header.skeleton), v3::Scratch::default());
                let _ = f.pose_at(rng.random::<f64>() * 3.0, &mut pose, &mut sc);
            }
        }
    }
}
