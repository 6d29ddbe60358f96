//! Live keyframe stream (the paper's motivation: avatars over a network). The sender reads a clip as
//! if it were being captured, chooses keys online with a bounded look-ahead and sends them over TCP;
//! the receiver rebuilds and emits the frames between each pair of keys as soon as the second
//! arrives.
//!
//! Online choice: with the last key at `a` and frames up to `t` captured, a key's velocity needs the
//! frame after it, so candidates are `b ≤ t − 1`. While segment `(a, t−1)` keeps every joint within
//! the error bound and is shorter than the look-ahead, the sender waits; otherwise it sends the
//! farthest feasible `b` (at least `a + 1`). A frame therefore waits at most `lookahead + 1` frames.
//! Segments are judged on the keys as the receiver decodes them ([`quantised_model`]), so the bound
//! holds for the frames the receiver rebuilds, and errors are in cm in the clip's length unit
//! (inferred from the skeleton, or given).
//!
//! Wire format: messages `type u8 | length u32 | payload | crc32(type, length, payload) u32`.
//! Hello (1): magic "IBS1", frame time f64, frame count u32, skeleton (as in the `.ibk` codec).
//! Key (2): frame u32, angular velocity scale f32, key values (as in the codec). End (3): empty.
//! A sender whose connection breaks reconnects and resends Hello and its last key; a receiver whose
//! peer vanishes keeps the frames it has and waits for the peer to come back. A receiver that joins
//! mid-stream (a new process after the old one died) starts at the first key it gets: every key
//! carries its frame index, so [`Received::start_frame`] says where its frames belong in the clip.

use crate::codec::{quantised_model, read_scaled_key, read_skeleton, write_scaled_key, write_skeleton, Reader};
use crate::metrics::SegmentModel;
use crate::rotations::{interpolate_pose_into, KeyPose, RotationCurve, RotationMotion};
use crate::{MocapError, Result};
use glam::{DQuat, DVec3};
use inbetween_core::units::{LengthUnit, UnitChoice};
use inbetween_core::{Motion, Pose, Skeleton};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream, ToSocketAddrs};
use std::path::PathBuf;
use std::time::{Duration, Instant};

const HELLO: u8 = 1;
const KEY: u8 = 2;
const END: u8 = 3;
const STREAM_MAGIC: &[u8; 4] = b"IBS1";
/// Upper bound on one message, so a corrupt length cannot make the receiver allocate gigabytes.
const MAX_MESSAGE: usize = 16 << 20;

/// A key decision: key frame `key` is sent once frame `at` has been captured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KeyEvent {
    pub key: usize,
    pub at: usize,
}

/// Chooses keys online (see the module doc). The first key (frame 0) is sent at frame 0 and the
/// last frame is always a key.
pub fn online_keys(model: &dyn SegmentModel, max_cm: f64, lookahead: usize) -> Vec<KeyEvent> {
    let n = model.num_frames();
    let lookahead = lookahead.max(1);
    let mut scratch = model.scratch();
    let mut events = vec![KeyEvent { key: 0, at: 0 }];
    let mut a = 0;
    for t in 2..n {
        // Candidates end at t − 1 (its velocity needs frame t).
        let newest = t - 1;
        if newest <= a {
            continue;
        }
        let fits = |b: usize, s: &mut crate::metrics::Scratch| model.segment_cost_within(a, b, max_cm, s).is_some();
        if newest - a < lookahead && fits(newest, &mut scratch) {
            continue;
        }
        let b = (a + 1..=newest).rev().find(|&b| b == a + 1 || fits(b, &mut scratch)).expect("a + 1 always fits");
        events.push(KeyEvent { key: b, at: t });
        a = b;
    }
    // End of the clip: the last frame is known (one-sided velocity); close with feasible keys.
    while a != n - 1 {
        let b = (a + 1..n)
            .rev()
            .find(|&b| b == a + 1 || model.segment_cost_within(a, b, max_cm, &mut scratch).is_some())
            .expect("a + 1 always fits");
        events.push(KeyEvent { key: b, at: n - 1 });
        a = b;
    }
    events
}

/// Latency each frame waits beyond its capture, in frames: until the key closing its segment is sent.
pub fn added_latency_frames(events: &[KeyEvent]) -> Vec<usize> {
    let mut lat = vec![0usize];
    for w in events.windows(2) {
        for f in w[0].key + 1..=w[1].key {
            lat.push(w[1].at.saturating_sub(f));
        }
    }
    lat
}

fn frame_message(kind: u8, payload: &[u8]) -> Vec<u8> {
    let mut m = Vec::with_capacity(payload.len() + 9);
    m.push(kind);
    m.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    m.extend_from_slice(payload);
    let crc = crc32fast::hash(&m);
    m.extend_from_slice(&crc.to_le_bytes());
    m
}

fn hello_payload(skeleton: &Skeleton, frame_time: f64, frames: usize) -> Vec<u8> {
    let mut p = STREAM_MAGIC.to_vec();
    p.extend_from_slice(&frame_time.to_le_bytes());
    p.extend_from_slice(&(frames as u32).to_le_bytes());
    write_skeleton(&mut p, skeleton);
    p
}

fn key_payload(skeleton: &Skeleton, frame: usize, key: &KeyPose) -> Vec<u8> {
    let mut p = (frame as u32).to_le_bytes().to_vec();
    write_scaled_key(&mut p, skeleton, key);
    p
}

/// Where `mocap stream` sends to and listens on by default.
pub const DEFAULT_ADDR: &str = "127.0.0.1:7878";

/// Sender settings.
#[derive(Clone, Debug)]
pub struct SendOptions {
    pub max_cm: f64,
    pub lookahead: usize,
    /// Pace messages at the clip's frame rate (off in tests).
    pub realtime: bool,
    /// Reconnection attempts after a broken connection, 200 ms apart.
    pub retries: usize,
    /// The clip's length unit; `None` infers it from the skeleton.
    pub unit: Option<LengthUnit>,
}

impl Default for SendOptions {
    /// Keys within 1 cm, a look-ahead of 15 frames (half a second at 30 fps), paced in real time,
    /// 10 reconnection attempts, the unit inferred.
    fn default() -> SendOptions {
        SendOptions { max_cm: 1.0, lookahead: 15, realtime: true, retries: 10, unit: None }
    }
}

/// What a sender did.
#[derive(Clone, Debug)]
pub struct SendReport {
    /// The unit the error bound was applied in, and why.
    pub unit: UnitChoice,
    pub frames: usize,
    pub keys: usize,
    pub bytes_sent: usize,
    /// Bytes of the same frames as raw f32 channels.
    pub raw_bytes: usize,
    pub seconds: f64,
    pub mean_latency_ms: f64,
    pub max_latency_ms: f64,
    pub reconnects: usize,
    /// Length of the clip sent, seconds (the rates are per second of clip).
    pub clip_seconds: f64,
}

impl std::fmt::Display for SendReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let secs = self.clip_seconds.max(1e-9);
        write!(
            f,
            "sent {} keys for {} frames in {:.2} s: {} bytes ({:.0} B/s) vs {} raw bytes ({:.0} B/s), {:.1}x less; added latency mean {:.0} ms, max {:.0} ms; {} reconnects",
            self.keys,
            self.frames,
            self.seconds,
            self.bytes_sent,
            self.bytes_sent as f64 / secs,
            self.raw_bytes,
            self.raw_bytes as f64 / secs,
            self.raw_bytes as f64 / self.bytes_sent as f64,
            self.mean_latency_ms,
            self.max_latency_ms,
            self.reconnects
        )
    }
}

fn connect(addr: &str, retries: usize) -> Result<TcpStream> {
    let mut last = None;
    for attempt in 0..=retries {
        if attempt > 0 {
            std::thread::sleep(Duration::from_millis(200));
        }
        let addrs = addr.to_socket_addrs().map_err(|e| MocapError::Stream(format!("bad address {addr}: {e}")))?;
        for a in addrs {
            match TcpStream::connect_timeout(&a, Duration::from_secs(2)) {
                Ok(s) => {
                    let _ = s.set_nodelay(true);
                    return Ok(s);
                }
                Err(e) => last = Some(e),
            }
        }
    }
    Err(MocapError::Stream(format!(
        "cannot connect to {addr} after {} attempts: {}",
        retries + 1,
        last.map(|e| e.to_string()).unwrap_or_default()
    )))
}

/// Streams `motion` to a receiver at `addr`.
pub fn send(addr: &str, motion: &Motion, opts: &SendOptions) -> Result<SendReport> {
    let unit = UnitChoice::resolve(opts.unit, &motion.skeleton);
    let model = RotationMotion::from_motion_in(motion, unit.cm_per_unit())?;
    let events = online_keys(&quantised_model(&model), opts.max_cm, opts.lookahead);
    let sk = &model.skeleton;
    let hello = frame_message(HELLO, &hello_payload(sk, model.frame_time, model.num_frames()));
    let mut report = SendReport {
        unit,
        frames: model.num_frames(),
        keys: events.len(),
        bytes_sent: 0,
        raw_bytes: inbetween_core::Motion::num_channels(motion) * 4 * model.num_frames(),
        seconds: 0.0,
        mean_latency_ms: 0.0,
        max_latency_ms: 0.0,
        reconnects: 0,
        clip_seconds: motion.duration(),
    };
    let start = Instant::now();
    let mut conn = connect(addr, opts.retries)?;
    conn.write_all(&hello).map_err(|e| MocapError::Stream(format!("sending hello: {e}")))?;
    report.bytes_sent += hello.len();
    let mut last_key: Option<Vec<u8>> = None;
    for ev in &events {
        if opts.realtime {
            let due = Duration::from_secs_f64(ev.at as f64 * model.frame_time);
            if let Some(wait) = due.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        let msg = frame_message(KEY, &key_payload(sk, ev.key, &model.frames[ev.key]));
        if conn.write_all(&msg).is_err() {
            // The receiver went away: reconnect, say hello again and resend the previous key so
            // it can rebuild the segment this key closes.
            conn = connect(addr, opts.retries)?;
            report.reconnects += 1;
            let mut resume = hello.clone();
            if let Some(prev) = &last_key {
                resume.extend_from_slice(prev);
            }
            resume.extend_from_slice(&msg);
            conn.write_all(&resume).map_err(|e| MocapError::Stream(format!("resending after reconnect: {e}")))?;
            report.bytes_sent += resume.len() - msg.len();
        }
        report.bytes_sent += msg.len();
        last_key = Some(msg);
    }
    let end = frame_message(END, &[]);
    let _ = conn.write_all(&end);
    let _ = conn.flush();
    report.bytes_sent += end.len();
    report.seconds = start.elapsed().as_secs_f64();
    let lat = added_latency_frames(&events);
    report.mean_latency_ms = lat.iter().sum::<usize>() as f64 / lat.len() as f64 * model.frame_time * 1000.0;
    report.max_latency_ms = lat.iter().copied().max().unwrap_or(0) as f64 * model.frame_time * 1000.0;
    Ok(report)
}

/// One message of the stream.
#[derive(Clone, Debug)]
pub enum Message {
    /// The clip's skeleton, frame time and frame count.
    Hello {
        skeleton: Skeleton,
        frame_time: f64,
        frames: usize,
    },
    Key {
        frame: usize,
        key: KeyPose,
    },
    End,
}

/// Decodes the messages of a byte stream (what a receiver reads from its connection): untrusted
/// input, checked message by message, never a panic. Keys need a Hello before them.
pub fn decode_messages(mut bytes: &[u8]) -> Result<Vec<Message>> {
    let mut out = Vec::new();
    let mut skeleton: Option<Skeleton> = None;
    while !bytes.is_empty() {
        let (msg, _) = read_message(&mut bytes, skeleton.as_ref())?;
        if let Message::Hello { skeleton: s, .. } = &msg {
            skeleton = Some(s.clone());
        }
        out.push(msg);
    }
    Ok(out)
}

fn read_message(conn: &mut impl Read, skeleton: Option<&Skeleton>) -> Result<(Message, usize)> {
    let mut head = [0u8; 5];
    conn.read_exact(&mut head)
        .map_err(|e| MocapError::Stream(format!("connection closed while waiting for a message: {e}")))?;
    let len = u32::from_le_bytes(head[1..5].try_into().expect("4 bytes")) as usize;
    if len > MAX_MESSAGE {
        return Err(MocapError::Stream(format!("message of {len} bytes exceeds the {MAX_MESSAGE}-byte limit")));
    }
    let mut body = vec![0u8; len + 4];
    conn.read_exact(&mut body)
        .map_err(|e| MocapError::Stream(format!("connection closed inside a {len}-byte message: {e}")))?;
    let mut check = head.to_vec();
    check.extend_from_slice(&body[..len]);
    if crc32fast::hash(&check).to_le_bytes() != body[len..] {
        return Err(MocapError::Stream("message checksum mismatch".into()));
    }
    let mut r = Reader::new(&body[..len]);
    let msg = match head[0] {
        HELLO => {
            let magic = [r.u8("magic")?, r.u8("magic")?, r.u8("magic")?, r.u8("magic")?];
            if &magic != STREAM_MAGIC {
                return Err(MocapError::Stream("hello without the IBS1 magic".into()));
            }
            let frame_time = r.f64("frame time")?;
            let frames = r.u32("frame count")? as usize;
            if !(frame_time.is_finite() && frame_time > 0.0) || frames < 2 {
                return Err(MocapError::Stream(format!("hello with frame time {frame_time} and {frames} frames")));
            }
            Message::Hello { skeleton: read_skeleton(&mut r)?, frame_time, frames }
        }
        KEY => {
            let sk = skeleton.ok_or_else(|| MocapError::Stream("key before hello".into()))?;
            let frame = r.u32("key frame")? as usize;
            Message::Key { frame, key: read_scaled_key(&mut r, sk)? }
        }
        END => Message::End,
        other => return Err(MocapError::Stream(format!("unknown message type {other}"))),
    };
    if r.remaining() != 0 {
        return Err(MocapError::Stream(format!("{} stray bytes at the end of a message", r.remaining())));
    }
    Ok((msg, len + 9))
}

/// Receiver settings.
#[derive(Clone, Debug)]
pub struct RecvOptions {
    /// Sessions (connections) to accept before giving up on an unfinished stream.
    pub max_sessions: usize,
    /// How long to wait for a (re)connection.
    pub accept_timeout: Duration,
}

impl Default for RecvOptions {
    /// 8 sessions, 30 s for each (re)connection (`mocap stream recv`'s defaults).
    fn default() -> Self {
        RecvOptions { max_sessions: 8, accept_timeout: Duration::from_secs(30) }
    }
}

/// What a receiver rebuilt.
#[derive(Clone, Debug)]
pub struct Received {
    /// The frames rebuilt, from [`Received::start_frame`] of the sender's clip on.
    pub motion: Motion,
    /// Frame of the sender's clip that `motion` starts at: 0, or later for a receiver that joined
    /// mid-stream (its first key's frame).
    pub start_frame: usize,
    /// Frames of the sender's whole clip (from its Hello).
    pub clip_frames: usize,
    pub keys: usize,
    pub bytes: usize,
    /// True when the sender's End arrived.
    pub complete: bool,
    pub sessions: usize,
    /// Problems met on the way (broken connections, bad messages), for the log.
    pub warnings: Vec<String>,
}

impl std::fmt::Display for Received {
    /// What arrived and what was rebuilt, and where in the sender's clip it starts.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "received {} keys ({} bytes, {} sessions, {}), emitted {} frames (frames {}..{} of the sender's {}-frame clip)",
            self.keys,
            self.bytes,
            self.sessions,
            if self.complete { "complete" } else { "incomplete" },
            self.motion.num_frames(),
            self.start_frame,
            self.start_frame + self.motion.num_frames(),
            self.clip_frames
        )
    }
}

struct Rebuild {
    skeleton: Skeleton,
    frame_time: f64,
    clip_frames: usize,
    poses: Vec<Pose>,
    /// Frame of the first key received.
    start: Option<usize>,
    last: Option<(usize, KeyPose)>,
    keys: usize,
}

impl Rebuild {
    fn new(skeleton: Skeleton, frame_time: f64, clip_frames: usize) -> Rebuild {
        Rebuild { skeleton, frame_time, clip_frames, poses: Vec::new(), start: None, last: None, keys: 0 }
    }

    /// Adds a key; emits the frames after the previous key up to this one. A key outside the
    /// clip announced by Hello is refused (it would make the receiver emit frames without end).
    fn key(&mut self, frame: usize, key: KeyPose) -> Result<()> {
        if frame >= self.clip_frames {
            return Err(MocapError::Stream(format!(
                "key at frame {frame} is outside the announced clip of {} frames; ignored",
                self.clip_frames
            )));
        }
        let nj = self.skeleton.len();
        match &self.last {
            Some((a, k0)) if frame > *a => {
                let (a, h) = (*a, (frame - a) as f64 * self.frame_time);
                for f in a + 1..frame {
                    let mut p = Pose { rotations: vec![DQuat::IDENTITY; nj], translations: vec![DVec3::ZERO; nj] };
                    interpolate_pose_into(
                        k0,
                        &key,
                        h,
                        (f - a) as f64 / (frame - a) as f64,
                        RotationCurve::Hermite,
                        None,
                        &mut p.rotations,
                        &mut p.translations,
                    );
                    self.poses.push(p);
                }
            }
            Some(_) => return Ok(()), // a repeated (resent) or stale key
            None => self.start = Some(frame),
        }
        self.poses.push(Pose { rotations: key.rotations.clone(), translations: key.translations.clone() });
        self.last = Some((frame, key));
        self.keys += 1;
        Ok(())
    }
}

/// Receives one stream on `listener`, surviving dropped connections (up to `max_sessions`).
pub fn recv(listener: &TcpListener, opts: &RecvOptions) -> Result<Received> {
    listener.set_nonblocking(false).ok();
    let mut state: Option<Rebuild> = None;
    let (mut bytes, mut sessions, mut warnings, mut complete) = (0usize, 0usize, Vec::new(), false);
    while sessions < opts.max_sessions && !complete {
        let mut conn = match accept_with_timeout(listener, opts.accept_timeout) {
            Ok(c) => c,
            Err(e) => {
                warnings.push(e.to_string());
                break;
            }
        };
        sessions += 1;
        loop {
            let sk = state.as_ref().map(|s| s.skeleton.clone());
            match read_message(&mut conn, sk.as_ref()) {
                Ok((Message::Hello { skeleton, frame_time, frames }, size)) => {
                    bytes += size;
                    match &state {
                        Some(s) if s.skeleton != skeleton => {
                            warnings.push("a reconnecting sender sent a different skeleton; ignoring it".into());
                            break;
                        }
                        Some(_) => {}
                        None => state = Some(Rebuild::new(skeleton, frame_time, frames)),
                    }
                }
                Ok((Message::Key { frame, key }, size)) => {
                    bytes += size;
                    if let Some(Err(e)) = state.as_mut().map(|s| s.key(frame, key)) {
                        warnings.push(e.to_string());
                    }
                }
                Ok((Message::End, size)) => {
                    bytes += size;
                    complete = true;
                    break;
                }
                Err(e) => {
                    warnings.push(e.to_string());
                    break;
                }
            }
        }
    }
    let s = state.ok_or_else(|| MocapError::Stream(format!("no stream received ({})", warnings.join("; "))))?;
    let motion = Motion::from_poses(s.skeleton.clone(), s.frame_time, &s.poses)?;
    Ok(Received {
        motion,
        start_frame: s.start.unwrap_or(0),
        clip_frames: s.clip_frames,
        keys: s.keys,
        bytes,
        complete,
        sessions,
        warnings,
    })
}

impl Received {
    /// Frames of the sender's clip that did not arrive: those before the first key (a receiver
    /// that joined late) are not counted, those after the last frame rebuilt are.
    pub fn frames_lost(&self) -> usize {
        self.clip_frames.saturating_sub(self.start_frame + self.motion.num_frames())
    }

    /// An error saying what was lost and why when the sender's End never arrived.
    pub fn check_complete(&self) -> Result<()> {
        if self.complete {
            return Ok(());
        }
        Err(MocapError::Stream(format!(
            "the stream ended without the sender's End: {} of the clip's {} frames were rebuilt (frames {}..{}), {} lost after them; {}",
            self.motion.num_frames(),
            self.clip_frames,
            self.start_frame,
            self.start_frame + self.motion.num_frames(),
            self.frames_lost(),
            if self.warnings.is_empty() { "no reason given".to_string() } else { self.warnings.join("; ") }
        )))
    }
}

/// Position error of received frames against the sender's clip, at the right offset.
#[derive(Clone, Debug, PartialEq)]
pub struct StreamError {
    /// First frame of the reference compared (the receiver's start frame).
    pub start_frame: usize,
    /// Frames compared.
    pub frames: usize,
    pub mean_cm: f64,
    pub max_cm: f64,
}

impl std::fmt::Display for StreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "frames {}..{}: mean {:.3} cm, max {:.3} cm over {} frames",
            self.start_frame,
            self.start_frame + self.frames,
            self.mean_cm,
            self.max_cm,
            self.frames
        )
    }
}

/// Compares `received` with the sender's clip `reference` (same skeleton), frame
/// `received.start_frame + i` against received frame `i`, in cm at `cm_per_unit`.
pub fn compare(received: &Received, reference: &Motion, cm_per_unit: f64) -> Result<StreamError> {
    if reference.skeleton.len() != received.motion.skeleton.len() {
        return Err(MocapError::Invalid(format!(
            "the reference has {} joints, the stream {}",
            reference.skeleton.len(),
            received.motion.skeleton.len()
        )));
    }
    let start = received.start_frame;
    let frames = received.motion.num_frames().min(reference.num_frames().saturating_sub(start));
    if frames == 0 {
        return Err(MocapError::Invalid(format!(
            "the stream starts at frame {start}, past the reference's {} frames",
            reference.num_frames()
        )));
    }
    let e = inbetween_core::position_error(
        &inbetween_core::positions_clip(&reference.crop(start, start + frames)?),
        &inbetween_core::positions_clip(&received.motion.crop(0, frames)?),
    );
    Ok(StreamError { start_frame: start, frames, mean_cm: e.mean * cm_per_unit, max_cm: e.max * cm_per_unit })
}

/// `mocap stream recv` as one job: receive one stream on `addr` ([`recv`]), write the frames
/// rebuilt to `output` as BVH (nothing when no frame was rebuilt), and compare them with the
/// sender's clip when one is given. [`RecvReport::check`] then says what an unfinished stream lost.
#[derive(Clone, Debug)]
pub struct RecvJob {
    pub addr: String,
    pub output: PathBuf,
    pub options: RecvOptions,
    /// The sender's clip (its path and motion) to compare the frames rebuilt with.
    pub reference: Option<(PathBuf, Motion)>,
    /// The reference's length unit, for errors in cm; `None` infers it from its skeleton.
    pub unit: Option<LengthUnit>,
}

/// What a [`RecvJob`] received, wrote and measured.
#[derive(Debug)]
pub struct RecvReport {
    pub received: Received,
    /// The BVH written; `None` when no frame was rebuilt from an unfinished stream.
    pub output: Option<PathBuf>,
    /// The reference's unit and path, and the frames' error against it (or why it could not be measured).
    pub compared: Option<(UnitChoice, PathBuf, Result<StreamError>)>,
}

impl RecvJob {
    /// Listens on `addr`, then [`RecvJob::run_on`].
    pub fn run(&self) -> Result<RecvReport> {
        let listener = TcpListener::bind(&self.addr)
            .map_err(|e| MocapError::Context { context: format!("listening on {}", self.addr), source: e.into() })?;
        self.run_on(&listener)
    }

    /// Receives one stream on `listener`, writes and compares what it rebuilt.
    pub fn run_on(&self, listener: &TcpListener) -> Result<RecvReport> {
        let received = recv(listener, &self.options)?;
        if received.motion.num_frames() == 0 && !received.complete {
            return Ok(RecvReport { received, output: None, compared: None });
        }
        inbetween_io::write_bvh(&self.output, &received.motion)?;
        let compared = self.reference.as_ref().map(|(path, m)| {
            let unit = UnitChoice::resolve(self.unit, &m.skeleton);
            let e = compare(&received, m, unit.cm_per_unit());
            (unit, path.clone(), e)
        });
        Ok(RecvReport { received, output: Some(self.output.clone()), compared })
    }
}

impl RecvReport {
    /// `Err` when nothing was written (no frame rebuilt), the comparison failed, or the sender's
    /// End never arrived (the frames rebuilt were kept); each says what became of the frames.
    pub fn check(self) -> Result<()> {
        let within = |context: String, e: MocapError| MocapError::Context { context, source: e.into() };
        let Some(output) = &self.output else {
            let nothing = "no frame was rebuilt, so nothing was written".to_string();
            return self.received.check_complete().map_err(|e| within(nothing, e));
        };
        if let Some((_, path, Err(e))) = self.compared {
            return Err(within(format!("comparing with {}", path.display()), e));
        }
        let kept =
            format!("the {} frames received were kept in {}", self.received.motion.num_frames(), output.display());
        self.received.check_complete().map_err(|e| within(kept, e))
    }
}

impl std::fmt::Display for RecvReport {
    /// What arrived and where it was written, where it starts in the sender's clip when it joined
    /// mid-stream, and its error against the reference.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let output = self.output.as_ref().map_or("nothing".into(), |o| o.display().to_string());
        write!(f, "{}; wrote {output}", self.received)?;
        if self.received.start_frame > 0 {
            let start = self.received.start_frame;
            write!(f, "\njoined mid-stream: the output's frame 0 is frame {start} of the sender's clip")?;
        }
        if let Some((unit, path, Ok(e))) = &self.compared {
            write!(f, "\n{unit}\nerror vs {} {e}", path.display())?;
        }
        Ok(())
    }
}

fn accept_with_timeout(listener: &TcpListener, timeout: Duration) -> Result<TcpStream> {
    listener.set_nonblocking(true).map_err(|e| MocapError::Stream(e.to_string()))?;
    let start = Instant::now();
    loop {
        match listener.accept() {
            Ok((c, _)) => {
                c.set_nonblocking(false).map_err(|e| MocapError::Stream(e.to_string()))?;
                c.set_read_timeout(Some(timeout)).ok();
                return Ok(c);
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                if start.elapsed() > timeout {
                    return Err(MocapError::Stream(format!(
                        "no sender connected within {:.1} s",
                        timeout.as_secs_f64()
                    )));
                }
                std::thread::sleep(Duration::from_millis(10));
            }
            Err(e) => return Err(MocapError::Stream(format!("accept failed: {e}"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use inbetween_core::positions_clip;
    use inbetween_core::procedural::{gait, GaitParams, CM_PER_CMU_UNIT};
    use rand::{Rng, SeedableRng};

    fn walk() -> Motion {
        let mut p = GaitParams::walk();
        p.frames = 90;
        gait(&p)
    }

    fn recv_opts() -> RecvOptions {
        RecvOptions { max_sessions: 3, accept_timeout: Duration::from_secs(5) }
    }

    fn fast(max_cm: f64, retries: usize) -> SendOptions {
        SendOptions { max_cm, lookahead: 15, realtime: false, retries, unit: None }
    }

    #[test]
    fn online_keys_respect_bound_and_lookahead() {
        let m = RotationMotion::from_motion(&walk()).unwrap();
        let ev = online_keys(&m, 1.0, 12);
        assert_eq!(ev.last().unwrap().key, 89);
        for w in ev.windows(2) {
            assert!(w[1].key > w[0].key && w[1].key - w[0].key <= 12);
            assert!(w[1].at >= w[0].at);
            assert!(w[1].at > w[1].key || w[1].key == 89, "a key's velocity needs the next frame");
            let c = m.segment_cost(w[0].key, w[1].key, &mut m.scratch());
            assert!(c.cm_max <= 1.0 + 1e-9);
        }
        assert!(added_latency_frames(&ev).iter().all(|&l| l <= 13));
    }

    #[test]
    fn loopback_stream_rebuilds_the_clip_within_the_bound() {
        let m = walk();
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let rx = std::thread::spawn(move || recv(&listener, &recv_opts()));
        let sent = send(&addr, &m, &fast(1.0, 3)).unwrap();
        assert_eq!(sent.unit.unit, LengthUnit::Cmu, "{}", sent.unit.reason);
        let got = rx.join().unwrap().unwrap();
        assert!(got.complete);
        assert_eq!((got.start_frame, got.clip_frames, got.motion.num_frames()), (0, 90, 90));
        assert_eq!(got.keys, sent.keys);
        assert!(sent.bytes_sent < sent.raw_bytes);
        // Keys are chosen on what the receiver decodes: the bound holds for the rebuilt frames.
        let e = compare(&got, &m, CM_PER_CMU_UNIT).unwrap();
        assert!(e.max_cm <= 1.0 && e.max_cm > 0.3, "max {} cm", e.max_cm);
        let direct = inbetween_core::position_error(&positions_clip(&m), &positions_clip(&got.motion));
        assert!((direct.max * CM_PER_CMU_UNIT - e.max_cm).abs() < 1e-9);
    }

    #[test]
    fn a_dropped_peer_crashes_neither_side() {
        // Nobody listening: the sender gives up with an error.
        let probe = TcpListener::bind("127.0.0.1:0").unwrap();
        let dead = probe.local_addr().unwrap().to_string();
        drop(probe);
        assert!(send(&dead, &walk(), &fast(1.0, 1)).is_err());
        // A peer that says hello, sends half a key and vanishes; then a real sender connects.
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let rx = std::thread::spawn(move || recv(&listener, &recv_opts()));
        let m = walk();
        {
            let mut c = TcpStream::connect(&addr).unwrap();
            let model = RotationMotion::from_motion(&m).unwrap();
            c.write_all(&frame_message(HELLO, &hello_payload(&model.skeleton, model.frame_time, 90))).unwrap();
            let key = frame_message(KEY, &key_payload(&model.skeleton, 0, &model.frames[0]));
            c.write_all(&key[..key.len() / 2]).unwrap();
        }
        send(&addr, &m, &fast(1.0, 3)).unwrap();
        let got = rx.join().unwrap().unwrap();
        assert!(got.complete && got.sessions == 2, "{:?}", got.warnings);
        assert!(!got.warnings.is_empty());
        assert_eq!(got.motion.num_frames(), 90);
    }

    /// The recv job writes what arrived and measures it against the sender's clip; a sender gone
    /// after its Hello leaves no file, and the error says so and why.
    #[test]
    fn the_recv_job_writes_and_compares_or_says_why_nothing_was_written() {
        let (m, dir) = (walk(), tempfile::tempdir().unwrap());
        let output = dir.path().join("got.bvh");
        let reference = Some((PathBuf::from("walk.bvh"), m.clone()));
        let job = RecvJob { addr: String::new(), output, options: recv_opts(), reference, unit: None };
        let run = |job: &RecvJob| {
            let listener = TcpListener::bind("127.0.0.1:0").unwrap();
            let addr = listener.local_addr().unwrap().to_string();
            let job = job.clone();
            (addr, std::thread::spawn(move || job.run_on(&listener)))
        };
        let (addr, rx) = run(&job);
        send(&addr, &m, &fast(1.0, 3)).unwrap();
        let report = rx.join().unwrap().unwrap();
        let text = report.to_string();
        assert!(text.contains("emitted 90 frames") && text.contains(&format!("wrote {}", job.output.display())));
        assert!(text.contains("error vs walk.bvh frames 0..90: mean"), "{text}");
        assert!(matches!(&report.compared, Some((_, _, Ok(e))) if e.max_cm <= 1.0), "{text}");
        report.check().unwrap();
        assert_eq!(inbetween_io::read_bvh(&job.output).unwrap().num_frames(), 90);
        let gone = RecvJob {
            output: dir.path().join("none.bvh"),
            options: RecvOptions { max_sessions: 1, accept_timeout: Duration::from_millis(500) },
            ..job
        };
        let (addr, rx) = run(&gone);
        let model = RotationMotion::from_motion(&m).unwrap();
        let hello = frame_message(HELLO, &hello_payload(&model.skeleton, model.frame_time, 90));
        TcpStream::connect(&addr).unwrap().write_all(&hello).unwrap();
        let report = rx.join().unwrap().unwrap();
        assert!(report.output.is_none() && !gone.output.exists());
        let e = report.check().unwrap_err();
        assert_eq!(e.to_string(), "no frame was rebuilt, so nothing was written");
        let why = std::error::Error::source(&e).unwrap().to_string();
        assert!(why.contains("ended without the sender's End: 0 of the clip's 90 frames"), "{why}");
    }

    /// A sender that says hello, sends two keys and is cut off inside the third (or sends
    /// garbage after hello): the receiver keeps the frames it rebuilt and says what it lost.
    #[test]
    fn a_sender_cut_mid_message_leaves_an_incomplete_stream_that_says_what_was_lost() {
        let m = walk();
        let model = RotationMotion::from_motion(&m).unwrap();
        for garbage in [false, true] {
            let listener = TcpListener::bind("127.0.0.1:0").unwrap();
            let addr = listener.local_addr().unwrap().to_string();
            let opts = RecvOptions { max_sessions: 3, accept_timeout: Duration::from_millis(500) };
            let rx = std::thread::spawn(move || recv(&listener, &opts));
            {
                let mut c = TcpStream::connect(&addr).unwrap();
                c.write_all(&frame_message(HELLO, &hello_payload(&model.skeleton, model.frame_time, 90))).unwrap();
                if garbage {
                    c.write_all(&[0x5a; 64]).unwrap();
                } else {
                    for f in [0, 10] {
                        c.write_all(&frame_message(KEY, &key_payload(&model.skeleton, f, &model.frames[f]))).unwrap();
                    }
                    let key = frame_message(KEY, &key_payload(&model.skeleton, 20, &model.frames[20]));
                    c.write_all(&key[..key.len() / 2]).unwrap();
                }
            }
            let got = rx.join().unwrap().unwrap();
            assert!(!got.complete);
            let e = got.check_complete().unwrap_err().to_string();
            if garbage {
                assert_eq!(got.motion.num_frames(), 0);
                assert!(e.contains("0 of the clip's 90 frames") && e.contains("90 lost"), "{e}");
            } else {
                assert_eq!(got.motion.num_frames(), 11, "frames 0..=10 rebuilt");
                assert_eq!(got.frames_lost(), 79);
                assert!(e.contains("11 of the clip's 90 frames") && e.contains("inside a"), "{e}");
            }
        }
    }

    /// A receiver dies after a few keys and a new one takes its place: the sender reconnects, the
    /// new receiver's frames start where its first key is, and compared at that offset they match
    /// the clip within the bound (compared from frame 0 they would not).
    #[test]
    fn a_receiver_joining_mid_stream_knows_where_its_frames_belong() {
        let mut p = GaitParams::walk();
        p.frames = 120;
        p.fps = 60.0;
        let m = gait(&p);
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        let rx = std::thread::spawn(move || {
            // The first receiver: reads Hello and three keys, then dies.
            let mut first = accept_with_timeout(&listener, Duration::from_secs(5)).unwrap();
            let mut skeleton = None;
            let mut keys = 0;
            while keys < 3 {
                match read_message(&mut first, skeleton.as_ref()).unwrap().0 {
                    Message::Hello { skeleton: s, .. } => skeleton = Some(s),
                    Message::Key { .. } => keys += 1,
                    Message::End => panic!("the stream ended before the receiver died"),
                }
            }
            drop(first);
            recv(&listener, &recv_opts())
        });
        let opts = SendOptions { realtime: true, ..fast(1.0, 10) };
        let sent = send(&addr, &m, &opts).unwrap();
        assert_eq!(sent.reconnects, 1);
        let got = rx.join().unwrap().unwrap();
        assert!(got.complete, "{:?}", got.warnings);
        assert!(got.start_frame > 0, "the new receiver joined mid-stream");
        assert_eq!(got.start_frame + got.motion.num_frames(), 120);
        let e = compare(&got, &m, CM_PER_CMU_UNIT).unwrap();
        assert_eq!((e.start_frame, e.frames), (got.start_frame, 120 - got.start_frame));
        assert!(e.max_cm <= 1.0, "at the right offset: max {} cm", e.max_cm);
        let from_zero = inbetween_core::position_error(
            &positions_clip(&m.crop(0, got.motion.num_frames()).unwrap()),
            &positions_clip(&got.motion),
        );
        assert!(from_zero.max * CM_PER_CMU_UNIT > 5.0, "from frame 0 the walk is elsewhere");
    }

    /// What the fuzz target (`fuzz/fuzz_targets/stream_message.rs`) does, on seeded random inputs so
    /// that CI runs it: random bytes, and a valid stream with bytes changed or cut, with and without
    /// valid checksums. Decoding returns an error or messages, never panics.
    #[test]
    fn decoding_arbitrary_messages_never_panics() {
        let model = RotationMotion::from_motion(&walk()).unwrap();
        let mut good = frame_message(HELLO, &hello_payload(&model.skeleton, model.frame_time, 90));
        for f in [0, 10, 89] {
            good.extend(frame_message(KEY, &key_payload(&model.skeleton, f, &model.frames[f])));
        }
        good.extend(frame_message(END, &[]));
        assert_eq!(decode_messages(&good).unwrap().len(), 5);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for case in 0..3000 {
            let bytes: Vec<u8> = match case % 3 {
                0 => (0..rng.random_range(0..300)).map(|_| rng.random()).collect(),
                1 => {
                    let mut b = good.clone();
                    for _ in 0..rng.random_range(1..4) {
                        let i = rng.random_range(0..b.len());
                        b[i] = rng.random();
                    }
                    b
                }
                _ => good[..rng.random_range(0..good.len())].to_vec(),
            };
            let _ = decode_messages(&bytes);
            // The same payload behind a valid frame and checksum reaches the payload checks.
            if bytes.len() > 1 {
                let _ = decode_messages(&frame_message(bytes[0] % 4, &bytes[1..]));
            }
        }
        // A key beyond the announced clip is refused, not rebuilt into billions of frames.
        let mut r = Rebuild::new(model.skeleton.clone(), model.frame_time, 90);
        r.key(0, model.frames[0].clone()).unwrap();
        assert!(r.key(u32::MAX as usize, model.frames[1].clone()).is_err());
        assert_eq!(r.poses.len(), 1);
    }
}
