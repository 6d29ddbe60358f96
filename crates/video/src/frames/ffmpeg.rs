//! Decoding through an `ffmpeg` subprocess, for the streams openh264 cannot read (High profile,
//! B-frames, other codecs).
//!
//! A subprocess keeps the build pure Rust (bindings to libavcodec would need clang and system
//! headers at build time). ffmpeg writes raw `rgb24` frames to a pipe; we cut the byte stream into
//! frames of the size we were told. Auto-rotation is turned off so that the frame size stays the
//! stream's coded display size that the caller knows.

use super::decode_err;
use crate::VideoError;
use image::RgbImage;
use std::ffi::OsStr;
use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};

/// True when an `ffmpeg` that runs is on `PATH`.
pub fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Width, height and frame rate of the first video stream, asked of `ffprobe` (installed with
/// ffmpeg); `None` when ffprobe is missing or says nothing usable.
pub(crate) fn ffprobe_video(path: &Path) -> Option<(u32, u32, Option<f64>)> {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-select_streams", "v:0", "-show_entries", "stream=width,height,avg_frame_rate"])
        .args(["-of", "csv=p=0"])
        .arg(path)
        .stdin(Stdio::null())
        .output()
        .ok()?;
    parse_probe(&String::from_utf8_lossy(&out.stdout))
}

/// Parses ffprobe's `width,height,num/den` line.
fn parse_probe(text: &str) -> Option<(u32, u32, Option<f64>)> {
    let mut parts = text.lines().next()?.trim().split(',');
    let w: u32 = parts.next()?.parse().ok()?;
    let h: u32 = parts.next()?.parse().ok()?;
    let fps = parts.next().and_then(|r| {
        let (n, d) = r.split_once('/')?;
        let (n, d): (f64, f64) = (n.parse().ok()?, d.parse().ok()?);
        (n > 0.0 && d > 0.0).then_some(n / d)
    });
    (w > 0 && h > 0).then_some((w, h, fps))
}

/// Reads up to `max_frames` frames of `width`×`height` from `path` with the ffmpeg at `program`.
/// stderr is drained on a thread so a chatty ffmpeg cannot block on a full pipe.
pub(crate) fn decode_with(
    program: &OsStr,
    path: &Path,
    (width, height): (u32, u32),
    max_frames: Option<usize>,
) -> Result<Vec<RgbImage>, VideoError> {
    let mut cmd = Command::new(program);
    cmd.args(["-nostdin", "-v", "error", "-noautorotate", "-i"]).arg(path);
    cmd.args(["-map", "0:v:0", "-f", "rawvideo", "-pix_fmt", "rgb24"]);
    if let Some(m) = max_frames {
        cmd.args(["-frames:v", &m.to_string()]);
    }
    cmd.arg("-").stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped());
    let mut child =
        cmd.spawn().map_err(|e| decode_err(path, None, format!("cannot run {}: {e}", program.to_string_lossy())))?;
    let mut stderr = child.stderr.take().expect("stderr is piped");
    let errors = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let mut stdout = child.stdout.take().expect("stdout is piped");
    let frames = read_frames(&mut stdout, width, height, max_frames);
    let status = child.wait().map_err(|e| VideoError::io(path, e))?;
    let errors = errors.join().unwrap_or_default();
    finish(path, frames, status.success(), errors.trim(), width, height)
}

/// Turns the pipe's outcome into frames or an error carrying ffmpeg's own message.
fn finish(
    path: &Path,
    frames: std::io::Result<(Vec<RgbImage>, usize)>,
    ok: bool,
    errors: &str,
    width: u32,
    height: u32,
) -> Result<Vec<RgbImage>, VideoError> {
    let (frames, leftover) = frames.map_err(|e| VideoError::io(path, e))?;
    let said = if errors.is_empty() { String::new() } else { format!(": {errors}") };
    if !ok {
        return Err(decode_err(path, Some(frames.len()), format!("ffmpeg failed{said}")));
    }
    if frames.is_empty() {
        return Err(decode_err(path, None, format!("ffmpeg produced no {width}x{height} frame{said}")));
    }
    if leftover != 0 {
        return Err(decode_err(
            path,
            Some(frames.len()),
            format!("ffmpeg output ends in a partial frame ({leftover} bytes): frame size is not {width}x{height}"),
        ));
    }
    Ok(frames)
}

/// Cuts a raw rgb24 byte stream into frames; also returns the bytes of a trailing partial frame.
fn read_frames(
    r: &mut impl Read,
    width: u32,
    height: u32,
    max_frames: Option<usize>,
) -> std::io::Result<(Vec<RgbImage>, usize)> {
    let size = width as usize * height as usize * 3;
    let mut frames = Vec::new();
    loop {
        if max_frames.is_some_and(|m| frames.len() >= m) {
            // Drain the rest so ffmpeg exits cleanly instead of on a broken pipe.
            std::io::copy(r, &mut std::io::sink())?;
            return Ok((frames, 0));
        }
        let mut buf = vec![0u8; size];
        let got = read_full(r, &mut buf)?;
        if got < size {
            return Ok((frames, got));
        }
        frames.push(RgbImage::from_raw(width, height, buf).expect("buffer has the frame's size"));
    }
}

/// Reads until `buf` is full or the stream ends; returns the bytes read.
fn read_full(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probe_line_parses() {
        assert_eq!(parse_probe("176,144,30000/1001\n"), Some((176, 144, Some(30000.0 / 1001.0))));
        assert_eq!(parse_probe("1280,720,0/0"), Some((1280, 720, None)));
        assert_eq!(parse_probe(""), None);
        assert_eq!(parse_probe("N/A,N/A,N/A"), None);
    }

    #[test]
    fn raw_stream_is_cut_into_frames() {
        let bytes: Vec<u8> = (0..2 * 2 * 3 * 2 + 5).map(|i| i as u8).collect();
        let (frames, leftover) = read_frames(&mut bytes.as_slice(), 2, 2, None).unwrap();
        assert_eq!(frames.len(), 2);
        assert_eq!(leftover, 5);
        assert_eq!(frames[1].get_pixel(0, 0).0, [12, 13, 14]);
        let (frames, leftover) = read_frames(&mut bytes.as_slice(), 2, 2, Some(1)).unwrap();
        assert_eq!((frames.len(), leftover), (1, 0));
    }

    /// A stand-in ffmpeg (a shell script) checks the pipe handling and error reporting without a real
    /// ffmpeg installed.
    #[cfg(unix)]
    #[test]
    fn fake_ffmpeg_frames_and_failures() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let script = |name: &str, body: &str| {
            let p = dir.path().join(name);
            std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
            std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
            p
        };
        let clip = Path::new("clip.mp4");
        let good = script("good", "head -c 36 /dev/zero");
        let frames = decode_with(good.as_os_str(), clip, (2, 2), None).unwrap();
        assert_eq!(frames.len(), 3);
        let bad = script("bad", "echo 'Invalid data found' >&2; exit 1");
        let err = decode_with(bad.as_os_str(), clip, (2, 2), None).unwrap_err().to_string();
        assert!(err.contains("clip.mp4") && err.contains("Invalid data found"), "{err}");
        let partial = script("partial", "head -c 20 /dev/zero");
        let err = decode_with(partial.as_os_str(), clip, (2, 2), None).unwrap_err().to_string();
        assert!(err.contains("partial frame") && err.contains("frame 1"), "{err}");
        let missing = dir.path().join("no-such-ffmpeg");
        assert!(decode_with(missing.as_os_str(), clip, (2, 2), None).is_err());
    }
}
