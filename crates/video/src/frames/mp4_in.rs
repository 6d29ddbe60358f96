//! MP4 (H.264) in: demux with the `mp4` crate, decode with the bundled openh264, fall back to an
//! `ffmpeg` subprocess.
//!
//! MP4 stores H.264 in AVCC form: each sample is a list of length-prefixed NAL units, and the
//! parameter sets (SPS/PPS) live once in the track's `avcC` box. openh264 reads Annex-B byte streams
//! (NAL units behind `00 00 00 01` start codes, parameter sets in-band), so each sample is rewritten
//! and the parameter sets are put before every sync sample.
//!
//! openh264 decodes Baseline and Main streams. A `ctts` box whose offsets are not all equal means
//! frames are stored out of display order, i.e. B-frames. openh264 has long failed on those; the
//! bundled version reorders them correctly as long as it is not flushed after every packet (see
//! [`probe_openh264`] and the carphone test), but ffmpeg, when installed, stays the first choice for
//! them as the reference decoder. Anything openh264 cannot finish goes to ffmpeg, or gives
//! [`VideoError::Unsupported`] saying what to install.

use super::ffmpeg::{decode_with, ffmpeg_available, ffprobe_video};
use super::{decode_err, DecodeReport, Decoder, ReadOptions, DEFAULT_FPS};
use crate::VideoError;
use image::RgbImage;
use openh264::decoder::{DecodedYUV, Decoder as H264Decoder, DecoderConfig, Flush};
use openh264::formats::YUVSource;
use std::path::Path;

/// The first H.264 video track of an MP4, demuxed.
pub(crate) struct Demuxed {
    pub width: u32,
    pub height: u32,
    /// `None` when the timing tables give no usable rate.
    pub fps: Option<f64>,
    /// `profile_idc` from the `avcC` box (66 Baseline, 77 Main, 100 High).
    pub profile: u8,
    /// True when a `ctts` box reorders frames (B-frames).
    pub reorder: bool,
    /// Bytes of the NAL length prefix in samples (1, 2 or 4).
    length_size: usize,
    /// SPS and PPS NAL units from `avcC`.
    params: Vec<Vec<u8>>,
    /// Samples in decode order: AVCC bytes and whether it is a sync (IDR) sample.
    samples: Vec<(Vec<u8>, bool)>,
}

/// Why demuxing failed: a broken file, or a valid MP4 without an H.264 video track.
pub(crate) enum DemuxError {
    Broken(String),
    NoH264(String),
}

/// Name of an H.264 profile_idc.
fn profile_name(idc: u8) -> &'static str {
    match idc {
        66 => "Baseline",
        77 => "Main",
        88 => "Extended",
        100 => "High",
        110 => "High 10",
        122 => "High 4:2:2",
        244 => "High 4:4:4",
        _ => "unknown",
    }
}

/// Demuxes the file's bytes. The `mp4` crate has panics on some malformed tables (`unwrap`s in
/// its sample lookup), so it runs under `catch_unwind` and a panic becomes an error.
pub(crate) fn demux(bytes: &[u8]) -> Result<Demuxed, DemuxError> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| demux_inner(bytes))) {
        Ok(r) => r,
        Err(_) => Err(DemuxError::Broken("the MP4 tables are inconsistent (demuxer gave up)".into())),
    }
}

fn demux_inner(bytes: &[u8]) -> Result<Demuxed, DemuxError> {
    let size = bytes.len() as u64;
    let mut reader = mp4::Mp4Reader::read_header(std::io::Cursor::new(bytes), size)
        .map_err(|e| DemuxError::Broken(format!("not a readable MP4: {e}")))?;
    let mut ids: Vec<u32> = reader.tracks().keys().copied().collect();
    ids.sort_unstable();
    let id = ids
        .iter()
        .copied()
        .find(|id| reader.tracks()[id].trak.mdia.minf.stbl.stsd.avc1.is_some())
        .ok_or_else(|| DemuxError::NoH264(describe_tracks(&reader)))?;
    let track = &reader.tracks()[&id];
    let stbl = &track.trak.mdia.minf.stbl;
    let avcc = &stbl.stsd.avc1.as_ref().expect("found above").avcc;
    let mut params: Vec<Vec<u8>> = avcc.sequence_parameter_sets.iter().map(|n| n.bytes.clone()).collect();
    params.extend(avcc.picture_parameter_sets.iter().map(|n| n.bytes.clone()));
    let mut d = Demuxed {
        width: track.width() as u32,
        height: track.height() as u32,
        fps: fps_of(track),
        profile: avcc.avc_profile_indication,
        reorder: stbl
            .ctts
            .as_ref()
            .is_some_and(|c| c.entries.windows(2).any(|w| w[0].sample_offset != w[1].sample_offset)),
        length_size: avcc.length_size_minus_one as usize % 4 + 1,
        params,
        samples: Vec::new(),
    };
    check_sample_sizes(track, size)?;
    let count = track.sample_count();
    for i in 1..=count {
        let s = reader
            .read_sample(id, i)
            .map_err(|e| DemuxError::Broken(format!("sample {} cannot be read: {e}", i - 1)))?
            .ok_or_else(|| DemuxError::Broken(format!("sample {} is missing from the tables", i - 1)))?;
        d.samples.push((s.bytes.to_vec(), s.is_sync));
    }
    if d.samples.is_empty() {
        return Err(DemuxError::Broken("the H.264 track has no samples".into()));
    }
    Ok(d)
}

/// Refuses sample sizes larger than the file before anything allocates them.
fn check_sample_sizes(track: &mp4::Mp4Track, file_size: u64) -> Result<(), DemuxError> {
    let stsz = &track.trak.mdia.minf.stbl.stsz;
    let largest = stsz.sample_sizes.iter().copied().max().unwrap_or(0).max(stsz.sample_size);
    if largest as u64 > file_size {
        return Err(DemuxError::Broken(format!("a sample claims {largest} bytes but the file has {file_size}")));
    }
    Ok(())
}

/// Frames per second from the time-to-sample table: samples ÷ (sum of deltas ÷ timescale).
fn fps_of(track: &mp4::Mp4Track) -> Option<f64> {
    let timescale = track.trak.mdia.mdhd.timescale as f64;
    let stts = &track.trak.mdia.minf.stbl.stts.entries;
    let samples: f64 = stts.iter().map(|e| e.sample_count as f64).sum();
    let ticks: f64 = stts.iter().map(|e| e.sample_count as f64 * e.sample_delta as f64).sum();
    let fps = samples * timescale / ticks;
    (fps.is_finite() && fps > 0.0 && fps < 1000.0).then_some(fps)
}

/// The tracks an MP4 has, for the "no H.264 track" message.
fn describe_tracks<R: std::io::Read + std::io::Seek>(reader: &mp4::Mp4Reader<R>) -> String {
    let kinds: Vec<String> = reader
        .tracks()
        .values()
        .map(|t| t.media_type().map(|m| m.to_string()).unwrap_or_else(|_| "unknown".into()))
        .collect();
    format!("no H.264 video track (tracks: {})", if kinds.is_empty() { "none".into() } else { kinds.join(", ") })
}

/// Rewrites one AVCC sample as Annex-B into `out`.
fn avcc_to_annexb(sample: &[u8], length_size: usize, out: &mut Vec<u8>) -> Result<(), String> {
    let mut rest = sample;
    while !rest.is_empty() {
        if rest.len() < length_size {
            return Err(format!("{} stray bytes after the last NAL unit", rest.len()));
        }
        let len = rest[..length_size].iter().fold(0usize, |a, &b| a << 8 | b as usize);
        rest = &rest[length_size..];
        if len > rest.len() {
            return Err(format!("a NAL unit claims {len} bytes but the sample has {} left", rest.len()));
        }
        out.extend_from_slice(&[0, 0, 0, 1]);
        out.extend_from_slice(&rest[..len]);
        rest = &rest[len..];
    }
    Ok(())
}

/// What openh264 did with one sample.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SampleOutcome {
    /// A picture came out.
    Frame,
    /// Accepted, no picture yet (buffered, or parameter sets only).
    NoOutput,
    /// openh264 (or the AVCC rewrite) reported an error.
    Error(String),
}

/// Sample-by-sample result of running the bundled openh264 over a whole MP4 (see
/// [`probe_openh264`]).
#[derive(Clone, Debug)]
pub struct OpenH264Probe {
    /// H.264 `profile_idc` (66 Baseline, 77 Main, 100 High).
    pub profile: u8,
    /// The track has a reordering `ctts` box (B-frames).
    pub has_b_frames: bool,
    /// One outcome per sample, in decode order.
    pub samples: Vec<SampleOutcome>,
    /// Pictures returned by the final flush.
    pub flushed: usize,
}

impl std::fmt::Display for OpenH264Probe {
    /// `video probe`'s text: profile, B-frames, samples and pictures, then one line per sample.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let b_frames = if self.has_b_frames { "yes (ctts box)" } else { "no" };
        let (profile, samples, pictures) = (self.profile, self.samples.len(), self.frames());
        write!(
            f,
            "H.264 profile {profile}, B-frames {b_frames}, {samples} samples, openh264 decoded {pictures} pictures"
        )?;
        self.samples.iter().enumerate().try_for_each(|(i, s)| write!(f, "\n  sample {i}: {s:?}"))
    }
}

impl OpenH264Probe {
    /// Pictures decoded, flushed ones included.
    pub fn frames(&self) -> usize {
        self.samples.iter().filter(|o| **o == SampleOutcome::Frame).count() + self.flushed
    }

    /// Samples that gave an error.
    pub fn errors(&self) -> usize {
        self.samples.iter().filter(|o| matches!(o, SampleOutcome::Error(_))).count()
    }

    /// Index of the first sample that gave an error.
    pub fn first_error(&self) -> Option<usize> {
        self.samples.iter().position(|o| matches!(o, SampleOutcome::Error(_)))
    }

    /// Runs of equal outcomes, e.g. `0-9 frame, 10-119 error`.
    pub fn summary(&self) -> String {
        let tag = |o: &SampleOutcome| match o {
            SampleOutcome::Frame => "frame",
            SampleOutcome::NoOutput => "no output",
            SampleOutcome::Error(_) => "error",
        };
        let mut parts: Vec<String> = Vec::new();
        let mut start = 0;
        for i in 1..=self.samples.len() {
            if i == self.samples.len() || tag(&self.samples[i]) != tag(&self.samples[start]) {
                parts.push(format!("{}-{} {}", start, i - 1, tag(&self.samples[start])));
                start = i;
            }
        }
        format!("{} ({} frames, {} errors, {} flushed)", parts.join(", "), self.frames(), self.errors(), self.flushed)
    }
}

/// Result of running openh264 over the samples.
struct H264Run {
    frames: Vec<RgbImage>,
    outcomes: Vec<SampleOutcome>,
    flushed: usize,
}

/// A YUV picture from openh264 as RGB, checking it has the size of the earlier pictures.
fn to_rgb(yuv: &DecodedYUV<'_>, size: &mut Option<(u32, u32)>) -> Result<RgbImage, String> {
    let (w, h) = yuv.dimensions();
    let dims = (w as u32, h as u32);
    if size.is_some_and(|s| s != dims) {
        let (pw, ph) = size.expect("checked");
        return Err(format!("picture size changed from {pw}x{ph} to {w}x{h}"));
    }
    *size = Some(dims);
    let mut buf = vec![0u8; w * h * 3];
    yuv.write_rgb8(&mut buf);
    RgbImage::from_raw(dims.0, dims.1, buf).ok_or_else(|| "bad picture buffer".to_string())
}

/// Feeds the samples to openh264 in decode order. Stops at the first error unless `keep_going`,
/// and once `max_frames` pictures are out; keeps pictures only when `keep_frames`.
fn run_openh264(
    d: &Demuxed,
    max_frames: Option<usize>,
    keep_going: bool,
    keep_frames: bool,
) -> Result<H264Run, String> {
    let config = DecoderConfig::new().flush_after_decode(Flush::NoFlush);
    let mut dec = H264Decoder::with_api_config(openh264::OpenH264API::from_source(), config)
        .map_err(|e| format!("openh264 does not start: {e}"))?;
    let mut run = H264Run { frames: Vec::new(), outcomes: Vec::new(), flushed: 0 };
    let mut size = None;
    let mut packet = Vec::new();
    let max = max_frames.unwrap_or(usize::MAX);
    let mut pictures = 0;
    for (i, (sample, sync)) in d.samples.iter().enumerate() {
        if pictures >= max {
            break;
        }
        packet.clear();
        if i == 0 || *sync {
            for p in &d.params {
                packet.extend_from_slice(&[0, 0, 0, 1]);
                packet.extend_from_slice(p);
            }
        }
        let outcome = avcc_to_annexb(sample, d.length_size, &mut packet).and_then(|()| match dec.decode(&packet) {
            Ok(Some(yuv)) => to_rgb(&yuv, &mut size).map(Some),
            Ok(None) => Ok(None),
            Err(e) => Err(format!("openh264: {e}")),
        });
        match outcome {
            Ok(Some(img)) => {
                pictures += 1;
                run.outcomes.push(SampleOutcome::Frame);
                if keep_frames {
                    run.frames.push(img);
                }
            }
            Ok(None) => run.outcomes.push(SampleOutcome::NoOutput),
            Err(e) => {
                run.outcomes.push(SampleOutcome::Error(e));
                if !keep_going {
                    return Ok(run);
                }
            }
        }
    }
    if pictures < max {
        let rest = dec.flush_remaining().map_err(|e| format!("openh264 flush: {e}"))?;
        for yuv in rest.iter().take(max - pictures) {
            let img = to_rgb(yuv, &mut size)?;
            run.flushed += 1;
            if keep_frames {
                run.frames.push(img);
            }
        }
    }
    Ok(run)
}

/// Runs the bundled openh264 over every sample of an MP4's H.264 track, not stopping at errors, and
/// records what happened to each sample: the measurement behind the decoder choice in [`read_clip`].
///
/// [`read_clip`]: super::read_clip
pub fn probe_openh264(path: &Path) -> Result<OpenH264Probe, VideoError> {
    let bytes = std::fs::read(path).map_err(|e| VideoError::io(path, e))?;
    let d = demux(&bytes).map_err(|e| match e {
        DemuxError::Broken(m) | DemuxError::NoH264(m) => decode_err(path, None, m),
    })?;
    let run = run_openh264(&d, None, true, false).map_err(|m| decode_err(path, None, m))?;
    Ok(OpenH264Probe { profile: d.profile, has_b_frames: d.reorder, samples: run.outcomes, flushed: run.flushed })
}

/// The error when neither decoder can be used: what failed, what to install, how to convert.
fn unsupported(path: &Path, reason: &str) -> VideoError {
    VideoError::Unsupported {
        path: path.to_path_buf(),
        message: format!(
            "{reason}. The bundled openh264 cannot decode this stream and no ffmpeg is on PATH. Install ffmpeg (e.g. `apt-get install ffmpeg`) and it is used automatically, or convert \
             the clip first: ffmpeg -i in.mp4 -profile:v main -bf 0 out.mp4"
        ),
    }
}

type Read = (Vec<RgbImage>, f64, DecodeReport);

/// Reads an MP4 with the decoder the options ask for (see the module docs for `Auto`).
pub(crate) fn read_mp4(path: &Path, opts: &ReadOptions) -> Result<Read, VideoError> {
    let bytes = std::fs::read(path).map_err(|e| VideoError::io(path, e))?;
    let demuxed = demux(&bytes);
    match opts.decoder {
        Decoder::Ffmpeg => via_ffmpeg(path, demuxed.ok().as_ref(), opts.max_frames, Vec::new()),
        Decoder::OpenH264 => {
            let d = demuxed_or_err(path, demuxed)?;
            via_openh264(&d, opts.max_frames).map_err(|(frame, m)| decode_err(path, frame, m))
        }
        Decoder::Auto => read_auto(path, demuxed, opts.max_frames),
    }
}

/// The demuxed track, or a decode error naming the file.
fn demuxed_or_err(path: &Path, demuxed: Result<Demuxed, DemuxError>) -> Result<Demuxed, VideoError> {
    demuxed.map_err(|e| match e {
        DemuxError::Broken(m) => decode_err(path, None, m),
        DemuxError::NoH264(m) => unsupported(path, &m),
    })
}

/// Auto: openh264 when the stream suits it; ffmpeg for B-frames, other codecs or openh264 errors;
/// a clear error when ffmpeg is missing.
fn read_auto(path: &Path, demuxed: Result<Demuxed, DemuxError>, max_frames: Option<usize>) -> Result<Read, VideoError> {
    let d = match demuxed {
        Ok(d) => d,
        Err(DemuxError::Broken(m)) if !ffmpeg_available() => return Err(decode_err(path, None, m)),
        Err(DemuxError::NoH264(m)) if !ffmpeg_available() => return Err(unsupported(path, &m)),
        Err(DemuxError::Broken(m) | DemuxError::NoH264(m)) => {
            return via_ffmpeg(path, None, max_frames, vec![format!("mp4 demuxer: {m}; used ffmpeg")]);
        }
    };
    if d.reorder {
        return read_b_frames(path, &d, max_frames);
    }
    match via_openh264(&d, max_frames) {
        Ok(read) => Ok(read),
        Err((frame, m)) => {
            let at = frame.map(|f| format!(" at frame {f}")).unwrap_or_default();
            let why = format!("openh264 failed{at} of this H.264 {} stream: {m}", profile_name(d.profile));
            if !ffmpeg_available() {
                return Err(unsupported(path, &why));
            }
            via_ffmpeg(path, Some(&d), max_frames, vec![format!("{why}; fell back to ffmpeg")])
        }
    }
}

/// A stream with B-frames: ffmpeg (the reference decoder) when installed; otherwise openh264, which
/// reorders pictures to display order by POC when it is not flushed after every packet (measured on
/// `carphone_pristine.mp4`: all 120 samples decode; flushing after each packet, the crate's
/// default, fails from sample 10 on), accepted only when every sample gave a picture.
fn read_b_frames(path: &Path, d: &Demuxed, max_frames: Option<usize>) -> Result<Read, VideoError> {
    let why = format!("H.264 {} stream with B-frames (reordering ctts box)", profile_name(d.profile));
    if ffmpeg_available() {
        return via_ffmpeg(path, Some(d), max_frames, vec![format!("{why}: used ffmpeg")]);
    }
    match via_openh264(d, max_frames) {
        Ok(mut read) => {
            read.2.notes.push(format!("{why}: no ffmpeg on PATH, decoded by openh264 (display order by POC)"));
            Ok(read)
        }
        Err((frame, m)) => {
            let at = frame.map(|f| format!(" at frame {f}")).unwrap_or_default();
            Err(unsupported(path, &format!("{why}: openh264 failed{at}: {m}")))
        }
    }
}

/// Decodes with openh264, stopping at the first error: `Err((frame index, message))`.
fn via_openh264(d: &Demuxed, max_frames: Option<usize>) -> Result<Read, (Option<usize>, String)> {
    let run = run_openh264(d, max_frames, false, true).map_err(|m| (None, m))?;
    if let Some(i) = run.outcomes.iter().position(|o| matches!(o, SampleOutcome::Error(_))) {
        let SampleOutcome::Error(m) = &run.outcomes[i] else { unreachable!() };
        return Err((Some(i), m.clone()));
    }
    let expected = d.samples.len().min(max_frames.unwrap_or(usize::MAX));
    if run.frames.len() < expected {
        let got = run.frames.len();
        return Err((Some(got), format!("openh264 gave {got} pictures for {expected} samples")));
    }
    let mut notes = vec![format!("H.264 {} profile ({})", profile_name(d.profile), d.profile)];
    let fps = d.fps.unwrap_or_else(|| {
        notes.push(format!("no usable timing in the MP4: assumed {DEFAULT_FPS} fps"));
        DEFAULT_FPS
    });
    let report = DecodeReport { decoder: "openh264 (bundled)".into(), frames: run.frames.len(), notes };
    Ok((run.frames, fps, report))
}

/// Decodes with an ffmpeg subprocess; the frame size comes from ffprobe, else from the MP4 header.
fn via_ffmpeg(
    path: &Path,
    d: Option<&Demuxed>,
    max_frames: Option<usize>,
    mut notes: Vec<String>,
) -> Result<Read, VideoError> {
    if !ffmpeg_available() {
        return Err(VideoError::Unsupported {
            path: path.to_path_buf(),
            message: "the ffmpeg decoder was asked for but no ffmpeg is on PATH; install it (e.g. `apt-get install \
                      ffmpeg`)"
                .into(),
        });
    }
    let probe = ffprobe_video(path);
    let size = probe.map(|p| (p.0, p.1)).or(d.map(|d| (d.width, d.height)));
    let (w, h) = size
        .ok_or_else(|| decode_err(path, None, "cannot tell the frame size: no ffprobe and no readable MP4 header"))?;
    let fps = probe.and_then(|p| p.2).or(d.and_then(|d| d.fps)).unwrap_or_else(|| {
        notes.push(format!("no frame rate found: assumed {DEFAULT_FPS} fps"));
        DEFAULT_FPS
    });
    let frames = decode_with(std::ffi::OsStr::new("ffmpeg"), path, (w, h), max_frames)?;
    let report = DecodeReport { decoder: "ffmpeg (subprocess)".into(), frames: frames.len(), notes };
    Ok((frames, fps, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn avcc_becomes_annexb() {
        let mut out = Vec::new();
        avcc_to_annexb(&[0, 0, 0, 2, 0x65, 0xAA, 0, 0, 0, 1, 0x41], 4, &mut out).unwrap();
        assert_eq!(out, vec![0, 0, 0, 1, 0x65, 0xAA, 0, 0, 0, 1, 0x41]);
        assert!(avcc_to_annexb(&[0, 0, 0, 9, 1], 4, &mut out).unwrap_err().contains("claims 9 bytes"));
        assert!(avcc_to_annexb(&[0, 0], 4, &mut out).unwrap_err().contains("stray"));
    }

    #[test]
    fn probe_summary_groups_runs() {
        let p = OpenH264Probe {
            profile: 100,
            has_b_frames: true,
            samples: vec![
                SampleOutcome::Frame,
                SampleOutcome::Frame,
                SampleOutcome::Error("x".into()),
                SampleOutcome::NoOutput,
            ],
            flushed: 1,
        };
        assert_eq!(p.summary(), "0-1 frame, 2-2 error, 3-3 no output (3 frames, 1 errors, 1 flushed)");
        assert_eq!(p.first_error(), Some(2));
    }
}
