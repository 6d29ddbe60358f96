//! Locomotion along a route (§3.2, §4.3: the paper's NSM is replaced by cycle-based walking):
//! the route comes from A* on the scene's occupancy grid (`layout::grid::Grid::astar`), the
//! root follows it with arc-length timing at the cycle's speed, heading follows the path tangent
//! at a limited turn rate (slowing down for sharp turns), the character accelerates from idle
//! and decelerates to a stop followed by a settle step into the idle stance, and stance feet are
//! locked to the floor with two-bone leg IK ([`lock_feet`]; skate measured by [`foot_skate`]).

use super::ik::{flat_of, solve_limb, Limb};
use super::library::MotionLibrary;
use super::rig::{clip, heading_of, local_from_global, wrap, yaw, Rig, FPS};
use crate::error::ScriptError;
use glam::{DQuat, DVec3};
use inbetween_core::clip::Clip;
use inbetween_core::fk::{forward, GlobalPose};
use inbetween_core::motion::interpolate_pose;
use inbetween_core::Pose;

/// How to walk a route.
#[derive(Clone, Debug, PartialEq)]
pub struct WalkParams {
    /// Locomotion verb whose cycle is used ("walk", "run").
    pub verb: String,
    /// Cruise speed in m/s; None: the cycle's own speed.
    pub speed: Option<f64>,
    /// Largest heading change, rad/s.
    pub max_turn_rate: f64,
    /// Seconds to speed up from rest to cruise speed (and to slow down to a stop).
    pub ease: f64,
    /// Idle seconds before starting and after stopping.
    pub hold_start: f64,
    pub hold_end: f64,
    /// Heading at the start (None: along the route); the character turns on the spot first.
    pub initial_heading: Option<f64>,
    /// Heading to turn to after stopping (e.g. to face a chair), None: keep.
    pub final_heading: Option<f64>,
    /// Pin stance feet to the floor ([`lock_feet`]).
    pub lock_feet: bool,
}

impl Default for WalkParams {
    fn default() -> WalkParams {
        WalkParams {
            verb: "walk".into(),
            speed: None,
            max_turn_rate: 2.5,
            ease: 0.8,
            hold_start: 0.3,
            hold_end: 0.3,
            initial_heading: None,
            final_heading: None,
            lock_feet: true,
        }
    }
}

/// What [`walk_route_stats`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct WalkStats {
    /// Route length, metres.
    pub length: f64,
    /// Frames and seconds of the clip.
    pub frames: usize,
    pub seconds: f64,
    /// [`foot_skate`] before and after foot locking, cm/s.
    pub skate_before: f64,
    pub skate_after: f64,
    /// Largest distance from the root (on the floor) to the route, metres.
    pub max_route_error: f64,
}

/// A polyline with arc-length parameterisation.
struct Path {
    pts: Vec<DVec3>,
    cum: Vec<f64>,
}

impl Path {
    fn new(route: &[[f32; 2]]) -> Path {
        let mut pts: Vec<DVec3> = Vec::new();
        for p in route {
            let q = DVec3::new(p[0] as f64, 0.0, p[1] as f64);
            if pts.last().is_none_or(|l: &DVec3| (*l - q).length() > 1e-6) {
                pts.push(q);
            }
        }
        let mut cum = vec![0.0];
        for w in pts.windows(2) {
            cum.push(cum.last().unwrap() + (w[1] - w[0]).length());
        }
        Path { pts, cum }
    }

    fn len(&self) -> f64 {
        *self.cum.last().unwrap_or(&0.0)
    }

    fn at(&self, s: f64) -> DVec3 {
        if self.pts.len() == 1 {
            return self.pts[0];
        }
        let s = s.clamp(0.0, self.len());
        let i = self.cum.partition_point(|&c| c <= s).clamp(1, self.pts.len() - 1);
        let seg = self.cum[i] - self.cum[i - 1];
        let u = if seg > 0.0 { (s - self.cum[i - 1]) / seg } else { 0.0 };
        self.pts[i - 1].lerp(self.pts[i], u)
    }

    /// Heading of the path around `s`, looking `ahead` metres forward.
    fn heading(&self, s: f64, ahead: f64) -> Option<f64> {
        let (a, b) = if s + ahead <= self.len() {
            (self.at(s), self.at(s + ahead))
        } else {
            (self.at(self.len() - ahead), self.at(self.len()))
        };
        let d = b - a;
        (d.length() > 1e-6).then(|| d.x.atan2(d.z))
    }
}

/// A looping cycle: local poses with the forward progression removed from the root.
struct Cycle {
    poses: Vec<Pose>,
    /// Ankle positions of each frame in the cycle's own (progression-free) frame.
    ankles: Vec<[DVec3; 2]>,
    /// Metres travelled per loop of the clip.
    stride: f64,
    speed: f64,
}

impl Cycle {
    fn new(m: &Clip, rig: &Rig) -> Cycle {
        let n = m.num_frames().max(1);
        let mut poses = m.poses();
        let r0 = poses[0].translations[rig.hips];
        let r1 = poses[n - 1].translations[rig.hips];
        let trend = if n > 1 { (r1 - r0) / (n - 1) as f64 } else { DVec3::ZERO };
        let trend = DVec3::new(trend.x, 0.0, trend.z);
        for (f, p) in poses.iter_mut().enumerate() {
            let r = p.translations[rig.hips] - trend * f as f64;
            p.translations[rig.hips] = DVec3::new(r.x - r0.x, r.y, r.z - r0.z);
        }
        let speed = trend.length() / m.frame_time();
        let ankles: Vec<[DVec3; 2]> = poses
            .iter()
            .map(|p| {
                let g = forward(&rig.skeleton, p);
                [g.positions[rig.legs[0][2]], g.positions[rig.legs[1][2]]]
            })
            .collect();
        Cycle { poses, ankles, stride: trend.length() * n as f64, speed }
    }

    /// Pose at loop phase `u` (cycles, any real). Between two frames the joint rotations are
    /// slerped and the legs re-solved so the ankles follow the straight line between the frames'
    /// ankle positions (slerped legs alone let a planted foot dip or slide).
    fn sample(&self, u: f64, rig: &Rig) -> Pose {
        let n = self.poses.len();
        let x = u.rem_euclid(1.0) * n as f64;
        let f0 = (x.floor() as usize).min(n - 1);
        let f1 = (f0 + 1) % n;
        let w = x - f0 as f64;
        let mut p = interpolate_pose(&self.poses[f0], &self.poses[f1], w);
        if w > 1e-9 && self.stride > 0.0 {
            for (k, limb) in [Limb::LeftLeg, Limb::RightLeg].into_iter().enumerate() {
                let target = self.ankles[f0][k].lerp(self.ankles[f1][k], w);
                solve_limb(rig, &mut p, limb, target, None);
            }
        }
        p
    }
}

fn idle_cycle(lib: &MotionLibrary, rig: &Rig) -> Cycle {
    match lib.retrieve("idle").filter(|c| c.clip.skeleton() == &rig.skeleton) {
        Some(c) => {
            let mut cyc = Cycle::new(&c.clip, rig);
            // An idle has no progression: keep the root where it stands.
            for (p, q) in cyc.poses.iter_mut().zip(c.clip.poses()) {
                p.translations[rig.hips] = q.translations[rig.hips];
            }
            cyc
        }
        None => Cycle { poses: vec![rig.standing()], ankles: vec![[DVec3::ZERO; 2]], stride: 0.0, speed: 0.0 },
    }
}

/// Places a local (character-frame) pose at floor point `at` with heading `h`.
fn place(rig: &Rig, mut p: Pose, at: DVec3, h: f64) -> Pose {
    let q = yaw(h);
    let r = p.translations[rig.hips];
    p.translations[rig.hips] = DVec3::new(at.x, 0.0, at.z) + q * r;
    p.rotations[rig.hips] = (q * p.rotations[rig.hips]).normalize();
    p
}

/// Walks `route` (points on the floor, metres, `[x, z]`) with the library's cycle for
/// `params.verb`: see the module comment. Returns a 30 fps clip on the common skeleton in world
/// metres. A route of one point (or of zero length) gives an idle at that point.
pub fn walk_route(route: &[[f32; 2]], library: &MotionLibrary, params: &WalkParams) -> Clip {
    walk_route_stats(route, library, params).0
}

/// [`walk_route`] plus measurements (foot skate before/after locking, route error).
pub fn walk_route_stats(route: &[[f32; 2]], library: &MotionLibrary, params: &WalkParams) -> (Clip, WalkStats) {
    let rig = Rig::standard();
    let path = Path::new(if route.is_empty() { &[[0.0, 0.0]] } else { route });
    // The library's cycle for the verb, else its walk, else the built-in procedural walk.
    let cycle = Some(
        library
            .cycle(&params.verb)
            .or_else(|| library.cycle("walk"))
            .filter(|c| c.clip.skeleton() == &rig.skeleton)
            .map(|c| Cycle::new(&c.clip, &rig))
            .unwrap_or_else(|| {
                let walk = inbetween_core::procedural::GaitParams {
                    cycle_hz: super::procedural::WALK_CYCLE_HZ,
                    ..inbetween_core::procedural::GaitParams::walk()
                };
                let m = super::procedural::gait_cycle(walk, 2, 0.6, 0.08);
                Cycle::new(&m, &rig)
            }),
    );
    let idle = idle_cycle(library, &rig);
    let dt = 1.0 / FPS;
    let len = path.len();
    let mut frames: Vec<Pose> = Vec::new();
    let mut t = 0.0;
    let mut h = params.initial_heading.or_else(|| path.heading(0.0, 0.3)).unwrap_or(0.0);
    let push = |frames: &mut Vec<Pose>, t: &mut f64, local: Pose, at: DVec3, h: f64| {
        frames.push(place(&rig, local, at, h));
        *t += dt;
    };
    let idle_at = |t: f64| idle.sample(t * FPS / idle.poses.len() as f64, &rig);
    for _ in 0..(params.hold_start * FPS).round() as usize {
        let l = idle_at(t);
        push(&mut frames, &mut t, l, path.at(0.0), h);
    }
    let mut route_err: f64 = 0.0;
    if let (Some(cycle), true) = (&cycle, len > 1e-3) {
        let vmax = params.speed.unwrap_or(cycle.speed).max(0.05);
        let acc = vmax / params.ease.max(dt);
        let turn = params.max_turn_rate.max(0.1) * dt;
        let rate = 1.0 / cycle.stride.max(1e-9);
        let (mut s, mut v, mut phase) = (0.0f64, 0.0f64, 0.0f64);
        let cap = ((len / vmax + 10.0 + 2.0 * params.ease) * FPS * 4.0) as usize;
        for _ in 0..cap {
            let desired = path.heading(s, 0.3).unwrap_or(h);
            let err = wrap(desired - h);
            h = wrap(h + err.clamp(-turn, turn));
            let rem = len - s;
            // Slow down for sharp turns (turn on the spot beyond 90°) and before the end.
            let align = wrap(desired - h).cos().max(0.0).powi(2);
            let vcap = (vmax * align).min((2.0 * acc * rem).sqrt());
            v = (v + acc * dt).min(vcap).max(0.0);
            let step = (v * dt).min(rem);
            s += step;
            phase += step * rate;
            // Phase follows distance, so the cycle keeps its foot plants at any speed; the idle
            // stance blends in over the first `blend_dist` metres (the stop is a settle step).
            let blend_dist = 0.3;
            let w = smooth01(s / blend_dist);
            let local = interpolate_pose(&idle_at(t), &cycle.sample(phase, &rig), w);
            let at = path.at(s);
            push(&mut frames, &mut t, local, at, h);
            if len - s < 1e-4 {
                break;
            }
        }
        // Stop: the stride frozen at arrival settles into the idle stance with one small step per
        // foot (the foot farther from its idle place first), lifted in an arc, the hips blending
        // to the idle pose meanwhile.
        let last = cycle.sample(phase, &rig);
        let end = path.at(len);
        let settle = (0.9 * FPS).round() as usize;
        let feet = |p: &Pose| {
            let g = forward(&rig.skeleton, p);
            [g.positions[rig.legs[0][2]], g.positions[rig.legs[1][2]]]
        };
        let from = feet(&place(&rig, last.clone(), end, h));
        let to = feet(&place(&rig, idle_at(t + settle as f64 * dt), end, h));
        let first = if (from[0] - to[0]).length() >= (from[1] - to[1]).length() { 0 } else { 1 };
        for i in 1..=settle {
            let u = i as f64 / settle as f64;
            let mut p = place(&rig, interpolate_pose(&last, &idle_at(t), smooth01(u)), end, h);
            for (k, limb) in [Limb::LeftLeg, Limb::RightLeg].into_iter().enumerate() {
                // Foot `first` steps in the first half, the other in the second.
                let v = if k == first { (2.0 * u).min(1.0) } else { (2.0 * u - 1.0).max(0.0) };
                let a = DVec3::new(from[k].x, 0.0, from[k].z).lerp(DVec3::new(to[k].x, 0.0, to[k].z), smooth01(v));
                let dist = DVec3::new(to[k].x - from[k].x, 0.0, to[k].z - from[k].z).length();
                let lift = (0.5 * dist).min(0.06) * (std::f64::consts::PI * v).sin();
                let y = from[k].y + (to[k].y - from[k].y) * smooth01(v) + lift;
                solve_limb(&rig, &mut p, limb, DVec3::new(a.x, y, a.z), None);
            }
            frames.push(p);
            t += dt;
        }
        for p in &frames {
            let r = p.translations[rig.hips];
            let d = (0..=100)
                .map(|k| (path.at(len * k as f64 / 100.0) - DVec3::new(r.x, 0.0, r.z)).length())
                .fold(f64::INFINITY, f64::min);
            route_err = route_err.max(d);
        }
    }
    if let Some(fh) = params.final_heading {
        // A step-turn on the spot: the body turns at most `max_turn_rate` while each foot stays
        // planted, then steps (lifted in an arc) to where the idle stance puts it at the final
        // heading, one foot in the first half of the turn, the other in the second.
        let turn = params.max_turn_rate.max(0.1) * dt;
        let mut headings = Vec::new();
        let mut hh = h;
        while wrap(fh - hh).abs() > 1e-6 {
            hh = wrap(hh + wrap(fh - hh).clamp(-turn, turn));
            headings.push(hh);
        }
        let at = path.at(len);
        let feet = |p: &Pose| {
            let g = forward(&rig.skeleton, p);
            [g.positions[rig.legs[0][2]], g.positions[rig.legs[1][2]]]
        };
        let m = headings.len();
        let (start, end) = (place(&rig, idle_at(t), at, h), place(&rig, idle_at(t + m as f64 * dt), at, fh));
        let (from, to) = (feet(&start), feet(&end));
        // The feet keep their world orientation while planted and turn with the step.
        let foot_turn = |p: &Pose| {
            let g = forward(&rig.skeleton, p);
            [g.rotations[rig.legs[0][2]], g.rotations[rig.legs[1][2]]]
        };
        let (turn_from, turn_to) = (foot_turn(&start), foot_turn(&end));
        for (i, &hi) in headings.iter().enumerate() {
            let u = (i + 1) as f64 / m as f64;
            let mut p = place(&rig, idle_at(t), at, hi);
            for (k, limb) in [Limb::LeftLeg, Limb::RightLeg].into_iter().enumerate() {
                let v = if k == 0 { (2.0 * u).min(1.0) } else { (2.0 * u - 1.0).max(0.0) };
                let a = DVec3::new(from[k].x, 0.0, from[k].z).lerp(DVec3::new(to[k].x, 0.0, to[k].z), smooth01(v));
                let dist = DVec3::new(to[k].x - from[k].x, 0.0, to[k].z - from[k].z).length();
                // A foot that moves at all is lifted clear of the floor (3 to 6 cm at the top).
                let top = if dist > 0.01 { (0.5 * dist).clamp(0.03, 0.06) } else { 0.0 };
                let lift = top * (std::f64::consts::PI * v).sin();
                let y = from[k].y + (to[k].y - from[k].y) * smooth01(v) + lift;
                solve_limb(&rig, &mut p, limb, DVec3::new(a.x, y, a.z), None);
                let [_, knee, foot, _] = rig.legs[k];
                let knee_global = forward(&rig.skeleton, &p).rotations[knee];
                let want = turn_from[k].slerp(turn_to[k], smooth01(v)).normalize();
                p.rotations[foot] = local_from_global(knee_global, want);
            }
            frames.push(p);
            t += dt;
        }
        h = hh;
    }
    for _ in 0..(params.hold_end * FPS).round().max(1.0) as usize {
        let l = idle_at(t);
        push(&mut frames, &mut t, l, path.at(len), h);
    }
    let raw = clip(&rig, &frames);
    let on_rig = "a walk is on the common rig";
    let before = foot_skate(&raw).expect(on_rig);
    let out = if params.lock_feet { lock_feet(&raw, &LockParams::default()).expect(on_rig) } else { raw };
    let stats = WalkStats {
        length: len,
        frames: out.num_frames(),
        seconds: out.duration(),
        skate_before: before,
        skate_after: foot_skate(&out).expect(on_rig),
        max_route_error: route_err,
    };
    (out, stats)
}

use inbetween_core::interp::smoothstep as smooth01;

/// Thresholds of foot-contact detection and locking.
#[derive(Clone, Debug, PartialEq)]
pub struct LockParams {
    /// A foot is in contact when its ankle is at most this far above its rest height (m) …
    pub height_tol: f64,
    /// … and moves horizontally slower than this (m/s).
    pub speed_tol: f64,
    /// Contacts shorter than this many frames are ignored.
    pub min_frames: usize,
    /// Frames over which the lock fades in and out at a contact's ends.
    pub blend_frames: usize,
    /// A locked foot whose unlocked position drifts further than this (m) is re-locked.
    pub max_drift: f64,
    /// In a fade, a foot lower than this above rest (m) keeps its lock horizontally.
    pub release_height: f64,
}

impl Default for LockParams {
    fn default() -> LockParams {
        LockParams {
            height_tol: 0.06,
            speed_tol: 1.2,
            min_frames: 3,
            blend_frames: 6,
            max_drift: 0.3,
            release_height: 0.04,
        }
    }
}

fn ankles(globals: &[GlobalPose], rig: &Rig) -> Vec<[DVec3; 2]> {
    globals.iter().map(|g| [g.positions[rig.legs[0][2]], g.positions[rig.legs[1][2]]]).collect()
}

fn hspeed(a: DVec3, b: DVec3, dt: f64) -> f64 {
    DVec3::new(b.x - a.x, 0.0, b.z - a.z).length() / dt
}

/// Foot contacts (left, right) per frame by ankle height and horizontal speed, with runs
/// shorter than `min_frames` removed.
/// An error names the joint missing when `m` is not on the common rig.
pub fn detect_contacts(m: &Clip, p: &LockParams) -> Result<[Vec<bool>; 2], ScriptError> {
    let rig = &Rig::for_clip(m, "foot-contact detection")?;
    Ok(contacts_of(&ankles(&m.globals(), rig), rig, m.frame_time(), p))
}

/// [`detect_contacts`] from the ankles' global positions per frame.
fn contacts_of(a: &[[DVec3; 2]], rig: &Rig, dt: f64, p: &LockParams) -> [Vec<bool>; 2] {
    let n = a.len();
    [0, 1].map(|k| {
        let mut c: Vec<bool> = (0..n)
            .map(|f| {
                let (f0, f1) = (f.saturating_sub(1), (f + 1).min(n - 1));
                let v = if f1 > f0 { hspeed(a[f0][k], a[f1][k], dt * (f1 - f0) as f64) } else { 0.0 };
                a[f][k].y <= rig.ankle_height + p.height_tol && v <= p.speed_tol
            })
            .collect();
        let mut f = 0;
        while f < n {
            if c[f] {
                let start = f;
                while f < n && c[f] {
                    f += 1;
                }
                if f - start < p.min_frames {
                    c[start..f].iter_mut().for_each(|x| *x = false);
                }
            } else {
                f += 1;
            }
        }
        c
    })
}

/// Foot locking: each detected contact pins the toe base at its mean floor position (the ankle
/// moved with it, at least at rest ankle height; faded in/out over `blend_frames`), the heel
/// rises about the toes and then the root is lowered where a leg could not reach, and both legs
/// are re-solved with two-bone IK (ankles keep their global orientation unless the heel rose).
/// An error names the joint missing when `m` is not on the common rig.
pub fn lock_feet(m: &Clip, p: &LockParams) -> Result<Clip, ScriptError> {
    let rig = &Rig::for_clip(m, "foot locking")?;
    let n = m.num_frames();
    let globals = m.globals();
    let a = ankles(&globals, rig);
    let contacts = contacts_of(&a, rig, m.frame_time(), p);
    // Each contact pins the toe base (the point a foot rolls over from heel-off on) where the foot
    // lands; the ankle is moved with it, so a heel rolling up over the toes keeps its
    // own rise and the foot only stops sliding. `pins[f][k]`: (pin, weight) per frame and foot.
    let toes: Vec<[DVec3; 2]> =
        globals.iter().map(|g| [g.positions[rig.legs[0][3]], g.positions[rig.legs[1][3]]]).collect();
    let flat = |v: DVec3| DVec3::new(v.x, 0.0, v.z);
    let mut pins: Vec<[Option<(DVec3, f64)>; 2]> = vec![[None, None]; n];
    for k in 0..2 {
        let c = &contacts[k];
        let mut f = 0;
        while f < n {
            if !c[f] {
                f += 1;
                continue;
            }
            // A contact whose foot drifts further than `max_drift` is split into several locks.
            let start = f;
            while f < n && c[f] && (flat(a[f][k]) - flat(a[start][k])).length() <= p.max_drift {
                f += 1;
            }
            let end = f; // exclusive
            let b = p.blend_frames;
            let lock = (start..end).map(|i| flat(toes[i][k])).sum::<DVec3>() / (end - start) as f64;
            // After a split, or a contact broken for a frame or two, glide from the previous
            // lock instead of jumping.
            let from =
                (1..=3).filter(|&d| start >= d).find(|&d| c[start - d]).and_then(|d| pins[start - d][k].map(|q| q.0));
            for (j, pin) in pins[start..end].iter_mut().enumerate() {
                let t = match from {
                    Some(q) if j < b => q.lerp(lock, smooth01((j + 1) as f64 / (b + 1) as f64)),
                    _ => lock,
                };
                pin[k] = Some((t, 1.0));
            }
            // Fades: the foot keeps its lock horizontally while it is low (it lifts before it
            // swings, and lands where it will be locked), weighted by time and by height.
            let fade = |i: usize, j: usize| -> (DVec3, f64) {
                let wt = smooth01(1.0 - j as f64 / (b + 1) as f64);
                let wh = smooth01(1.0 - (a[i][k].y - rig.ankle_height) / p.release_height);
                (lock, wt.max(wh) * smooth01(1.0 - (j as f64 - 1.0) / b as f64).max(wt))
            };
            for j in 1..=b {
                if start >= j && pins[start - j][k].is_none() {
                    pins[start - j][k] = Some(fade(start - j, j));
                }
                if end - 1 + j < n && !c[end - 1 + j] {
                    pins[end - 1 + j][k] = Some(fade(end - 1 + j, j));
                }
            }
        }
    }
    let mut targets: Vec<[Option<DVec3>; 2]> = (0..n)
        .map(|f| {
            [0, 1].map(|k| {
                pins[f][k].map(|(pin, w)| {
                    let t = a[f][k] + (pin - flat(toes[f][k])) * w;
                    DVec3::new(t.x, a[f][k].y.max(rig.ankle_height), t.z)
                })
            })
        })
        .collect();
    let mut poses = m.poses();
    // The unlocked poses' global transforms (the raise and drop passes and each frame's own
    // orientations before it is re-solved).
    let unlocked: Vec<GlobalPose> = poses.iter().map(|q| forward(&rig.skeleton, q)).collect();
    let leg_len = {
        let s = &rig.skeleton;
        (s.joint(rig.legs[0][1]).offset.length() + s.joint(rig.legs[0][2]).offset.length()) * 0.999
    };
    // Where a locked leg cannot reach its ankle target, the heel rises first, the foot turning
    // about its pinned toe base (as a walker's back foot does), up to MAX_HEEL_RAISE.
    let mut raises: Vec<[Option<(DVec3, f64)>; 2]> = vec![[None, None]; n];
    for f in 0..n {
        let g = &unlocked[f];
        for k in 0..2 {
            let Some(t) = targets[f][k] else { continue };
            let hip = g.positions[rig.legs[k][0]];
            if (t - hip).length() <= leg_len {
                continue;
            }
            let toe = t + (toes[f][k] - a[f][k]);
            let back = t - toe;
            let axis = flat(back).cross(DVec3::Y).normalize_or_zero();
            if axis == DVec3::ZERO {
                continue;
            }
            let lifted = |ang: f64| toe + DQuat::from_axis_angle(axis, ang) * back;
            let mut ang = MAX_HEEL_RAISE;
            if (lifted(ang) - hip).length() <= leg_len {
                let (mut lo, mut hi) = (0.0, MAX_HEEL_RAISE);
                for _ in 0..14 {
                    let mid = 0.5 * (lo + hi);
                    if (lifted(mid) - hip).length() <= leg_len {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                ang = hi;
            }
            targets[f][k] = Some(lifted(ang));
            raises[f][k] = Some((axis, ang));
        }
    }
    // Lower the root where a locked leg still cannot reach, smoothed over a few frames.
    let mut drop = vec![0.0f64; n];
    for f in 0..n {
        let g = &unlocked[f];
        for (k, t) in targets[f].iter().enumerate() {
            if let Some(t) = *t {
                let hip = g.positions[rig.legs[k][0]];
                let r = DVec3::new(t.x - hip.x, 0.0, t.z - hip.z).length();
                if r < leg_len {
                    let dy = hip.y - t.y;
                    drop[f] = drop[f].max(dy - (leg_len * leg_len - r * r).sqrt());
                }
            }
        }
    }
    let w = 3usize;
    let grown: Vec<f64> =
        (0..n).map(|f| drop[f.saturating_sub(w)..(f + w + 1).min(n)].iter().cloned().fold(0.0, f64::max)).collect();
    let smooth: Vec<f64> = (0..n)
        .map(|f| {
            let s = &grown[f.saturating_sub(w)..(f + w + 1).min(n)];
            s.iter().sum::<f64>() / s.len() as f64
        })
        .collect();
    for f in 0..n {
        let g0 = &unlocked[f];
        poses[f].translations[rig.hips].y -= smooth[f].max(0.0);
        for (k, limb) in [Limb::LeftLeg, Limb::RightLeg].into_iter().enumerate() {
            if let Some(t) = targets[f][k] {
                solve_limb(rig, &mut poses[f], limb, t, None);
            }
            if raises[f][k].is_none() && contacts[k][f] {
                // A foot standing on its heel with the toes up settles flat once it has landed
                // (a stride frozen at a stop or blended at a start would keep them up).
                let [_, knee, foot, _] = rig.legs[k];
                let own = g0.rotations[foot];
                let since = (0..=f).rev().take_while(|&i| contacts[k][i]).count();
                let w = smooth01(since as f64 / SETTLE_FRAMES);
                if (own * DVec3::Z).y > 0.0 && w > 0.0 {
                    let foot_global = own.slerp(flat_of(own), w).normalize();
                    let knee_global = forward(&rig.skeleton, &poses[f]).rotations[knee];
                    poses[f].rotations[foot] = local_from_global(knee_global, foot_global);
                }
            }
            if let Some((axis, ang)) = raises[f][k] {
                // The foot turned with its heel, the toes kept on the floor.
                let [_, knee, foot, toe] = rig.legs[k];
                let foot_global = (DQuat::from_axis_angle(axis, ang) * g0.rotations[foot]).normalize();
                let knee_global = forward(&rig.skeleton, &poses[f]).rotations[knee];
                poses[f].rotations[foot] = local_from_global(knee_global, foot_global);
                poses[f].rotations[toe] = local_from_global(foot_global, g0.rotations[toe]);
            }
        }
    }
    Ok(Clip::from_poses(m.skeleton().clone(), m.frame_time(), &poses).expect("locked poses fit the skeleton"))
}

/// Frames over which a planted foot with its toes up settles flat.
const SETTLE_FRAMES: f64 = 2.0;

/// Largest heel raise (radians of foot pitch about the toe base) foot locking uses before it
/// lowers the hips.
const MAX_HEEL_RAISE: f64 = 0.7;

/// Ankle height above rest at or below which [`foot_skate`] counts a foot as on the floor (m).
pub const SKATE_HEIGHT: f64 = 0.02;

/// Foot skate in **cm/s**: mean horizontal speed of the toe base (the point a foot stands on
/// from flat to toe off; the ankle itself moves when the heel rolls up) over the frames where
/// the foot is on the floor, its ankle within [`SKATE_HEIGHT`] of its rest height (both feet
/// pooled; 0 when no foot touches the floor).
/// Contact is judged by height alone, so locking cannot hide skate by changing the detection.
/// An error names the joint missing when `m` is not on the common rig.
pub fn foot_skate(m: &Clip) -> Result<f64, ScriptError> {
    let rig = &Rig::for_clip(m, "foot skate")?;
    // (ankle, toe base) per frame and foot.
    let a: Vec<[(DVec3, DVec3); 2]> =
        m.globals().into_iter().map(|g| rig.legs.map(|l| (g.positions[l[2]], g.positions[l[3]]))).collect();
    let on = |(ankle, _): (DVec3, DVec3)| ankle.y <= rig.ankle_height + SKATE_HEIGHT;
    let (mut sum, mut count) = (0.0, 0usize);
    for f in 1..a.len() {
        for (&now, &before) in a[f].iter().zip(&a[f - 1]) {
            if on(now) && on(before) {
                sum += hspeed(before.1, now.1, m.frame_time());
                count += 1;
            }
        }
    }
    Ok(if count == 0 { 0.0 } else { 100.0 * sum / count as f64 })
}

/// A library clip placed in the world: its first frame's root moved to floor point `at` and
/// turned to heading `heading` (the clip starts facing +Z at the origin).
/// An error names the joint missing when `m` is not on the common rig.
pub fn place_clip(m: &Clip, at: [f32; 2], heading: f64) -> Result<Clip, ScriptError> {
    let rig = Rig::for_clip(m, "placing a clip")?;
    let q = yaw(heading);
    let off = DVec3::new(at[0] as f64, 0.0, at[1] as f64);
    let poses: Vec<Pose> = m
        .poses()
        .into_iter()
        .map(|mut p| {
            p.translations[rig.hips] = off + q * p.translations[rig.hips];
            p.rotations[rig.hips] = (q * p.rotations[rig.hips]).normalize();
            p
        })
        .collect();
    Ok(Clip::from_poses(m.skeleton().clone(), m.frame_time(), &poses).expect("placed poses fit the skeleton"))
}

/// Heading (yaw, 0 = +Z) of a clip's root at frame `f`.
pub fn heading_at(m: &Clip, f: usize) -> f64 {
    heading_of(m.pose(f).rotations[0])
}
