//! MP4 out: openh264 encoder (H.264 Baseline: no B-frames, so any player and our own reader decode
//! it) and the `mp4` crate's muxer.
//!
//! openh264 emits Annex-B NAL units; MP4 wants the SPS/PPS in the `avcC` box and each frame as
//! length-prefixed (AVCC) NAL units, so the encoder output is split and rewritten. The track
//! timescale is the frame rate × 1000 with a duration of 1000 ticks per frame, which represents
//! 25, 30 and 29.97 fps exactly.

use super::Clip;
use crate::VideoError;
use image::RgbImage;
use openh264::encoder::{
    BitRate, Encoder, EncoderConfig, FrameRate, FrameType, IntraFramePeriod, Profile, RateControlMode,
};
use openh264::formats::{RgbSliceU8, YUVBuffer};
use openh264::OpenH264API;
use std::path::Path;

/// Ticks per frame in the track timescale.
const FRAME_TICKS: u32 = 1000;

/// Bits per pixel per frame for the nominal bitrate. Rate control is off: every frame must be
/// written, and with frame skipping disabled openh264's rate control cannot hold a bitrate anyway
/// (it warns on every encoder start). Frames are then coded at openh264's constant base QP (26),
/// about 32 dB PSNR on the textured procedural clips.
const BITS_PER_PIXEL: f64 = 0.5;

/// A key frame at least every this many seconds, so players can seek.
const KEY_INTERVAL_S: f64 = 2.0;

/// H.264 4:2:0 needs even sizes: an odd width or height loses its last column or row (cropping keeps
/// every written pixel a real one; padding would invent a border).
pub(crate) fn even_size(w: u32, h: u32) -> (u32, u32) {
    (w & !1, h & !1)
}

/// The top-left `w`×`h` of `img`, as tightly packed RGB bytes.
fn cropped_rgb(img: &RgbImage, w: u32, h: u32) -> Vec<u8> {
    if img.dimensions() == (w, h) {
        return img.as_raw().clone();
    }
    let row = img.width() as usize * 3;
    img.as_raw().chunks(row).take(h as usize).flat_map(|r| &r[..w as usize * 3]).copied().collect()
}

/// Splits Annex-B bytes into NAL units (start codes removed).
fn split_annexb(bytes: &[u8]) -> Vec<&[u8]> {
    let mut starts = Vec::new();
    let mut i = 0;
    while i + 3 <= bytes.len() {
        if bytes[i] == 0 && bytes[i + 1] == 0 && bytes[i + 2] == 1 {
            starts.push(i + 3);
            i += 3;
        } else {
            i += 1;
        }
    }
    let mut nals = Vec::with_capacity(starts.len());
    for (k, &s) in starts.iter().enumerate() {
        let mut end = starts.get(k + 1).map_or(bytes.len(), |&n| n - 3);
        // A 4-byte start code leaves its leading zero on the previous unit.
        while end > s && k + 1 < starts.len() && bytes[end - 1] == 0 {
            end -= 1;
        }
        nals.push(&bytes[s..end]);
    }
    nals
}

/// One encoded frame: AVCC sample bytes, whether it is an IDR, and the SPS/PPS it carried.
struct EncodedFrame {
    sample: Vec<u8>,
    idr: bool,
    sps: Option<Vec<u8>>,
    pps: Option<Vec<u8>>,
}

/// Separates parameter sets from picture NAL units and length-prefixes the latter.
fn to_avcc(annexb: &[u8], idr: bool) -> EncodedFrame {
    let mut f = EncodedFrame { sample: Vec::new(), idr, sps: None, pps: None };
    for nal in split_annexb(annexb).into_iter().filter(|n| !n.is_empty()) {
        match nal[0] & 0x1F {
            7 => f.sps = Some(nal.to_vec()),
            8 => f.pps = Some(nal.to_vec()),
            _ => {
                f.sample.extend_from_slice(&(nal.len() as u32).to_be_bytes());
                f.sample.extend_from_slice(nal);
            }
        }
    }
    f
}

/// The openh264 encoder for `w`×`h` at `fps`.
fn encoder(w: u32, h: u32, fps: f64) -> Result<Encoder, String> {
    let bps = (w as f64 * h as f64 * fps * BITS_PER_PIXEL).clamp(100_000.0, 50_000_000.0) as u32;
    let key = ((fps * KEY_INTERVAL_S).round() as u32).max(1);
    let config = EncoderConfig::new()
        .profile(Profile::Baseline)
        .bitrate(BitRate::from_bps(bps))
        .max_frame_rate(FrameRate::from_hz(fps as f32))
        .rate_control_mode(RateControlMode::Off)
        .skip_frames(false)
        .intra_frame_period(IntraFramePeriod::from_num_frames(key));
    Encoder::with_api_config(OpenH264API::from_source(), config).map_err(|e| format!("openh264 encoder: {e}"))
}

/// Encodes every frame (cropped to `w`×`h`).
fn encode_frames(clip: &Clip, w: u32, h: u32) -> Result<Vec<EncodedFrame>, String> {
    let mut enc = encoder(w, h, clip.fps)?;
    let mut out = Vec::with_capacity(clip.len());
    for (i, img) in clip.frames.iter().enumerate() {
        let rgb = cropped_rgb(img, w, h);
        let yuv = YUVBuffer::from_rgb8_source(RgbSliceU8::new(&rgb, (w as usize, h as usize)));
        let ms = (i as f64 * 1000.0 / clip.fps).round() as u64;
        let bits = enc.encode_at(&yuv, openh264::Timestamp::from_millis(ms)).map_err(|e| format!("frame {i}: {e}"))?;
        let frame = to_avcc(&bits.to_vec(), bits.frame_type() == FrameType::IDR);
        if frame.sample.is_empty() {
            return Err(format!("frame {i}: the encoder produced no picture"));
        }
        out.push(frame);
    }
    Ok(out)
}

/// Muxes the encoded frames into MP4 bytes.
fn mux(frames: &[EncodedFrame], w: u32, h: u32, fps: f64) -> Result<Vec<u8>, String> {
    let sps = frames.iter().find_map(|f| f.sps.clone()).ok_or("the encoder gave no SPS")?;
    let pps = frames.iter().find_map(|f| f.pps.clone()).ok_or("the encoder gave no PPS")?;
    let brand = |s: &str| s.parse::<mp4::FourCC>().expect("four ASCII letters");
    let config = mp4::Mp4Config {
        major_brand: brand("isom"),
        minor_version: 512,
        compatible_brands: ["isom", "iso2", "avc1", "mp41"].iter().map(|b| brand(b)).collect(),
        timescale: 1000,
    };
    let mut writer =
        mp4::Mp4Writer::write_start(std::io::Cursor::new(Vec::new()), &config).map_err(|e| e.to_string())?;
    let avc = mp4::AvcConfig { width: w as u16, height: h as u16, seq_param_set: sps, pic_param_set: pps };
    let track = mp4::TrackConfig {
        track_type: mp4::TrackType::Video,
        timescale: (fps * FRAME_TICKS as f64).round() as u32,
        language: "und".into(),
        media_conf: mp4::MediaConfig::AvcConfig(avc),
    };
    writer.add_track(&track).map_err(|e| e.to_string())?;
    for (i, f) in frames.iter().enumerate() {
        let sample = mp4::Mp4Sample {
            start_time: i as u64 * FRAME_TICKS as u64,
            duration: FRAME_TICKS,
            rendering_offset: 0,
            is_sync: f.idr,
            bytes: mp4::Bytes::from(f.sample.clone()),
        };
        writer.write_sample(1, &sample).map_err(|e| e.to_string())?;
    }
    writer.write_end().map_err(|e| e.to_string())?;
    Ok(writer.into_writer().into_inner())
}

/// Writes the clip as an H.264 Baseline MP4, atomically. Frames with an odd width or height are
/// cropped by one column/row (H.264 4:2:0 needs even sizes); sizes must be 2…65535 after that.
pub(crate) fn write_mp4(path: &Path, clip: &Clip) -> Result<(), VideoError> {
    let fail = |message: String| VideoError::Encode { path: path.to_path_buf(), message };
    let (w, h) = even_size(clip.width(), clip.height());
    if w < 2 || h < 2 || w > u16::MAX as u32 || h > u16::MAX as u32 {
        return Err(fail(format!("frames are {}x{}; MP4 needs 2…65535 pixels a side", clip.width(), clip.height())));
    }
    let encoded = encode_frames(clip, w, h).map_err(fail)?;
    let bytes = mux(&encoded, w, h, clip.fps).map_err(fail)?;
    inbetween_io::write_atomic(path, &bytes).map_err(|e| VideoError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn annexb_split_handles_3_and_4_byte_start_codes() {
        let bytes = [0, 0, 0, 1, 0x67, 1, 2, 0, 0, 1, 0x68, 3, 0, 0, 0, 1, 0x65, 4, 0];
        let nals = split_annexb(&bytes);
        assert_eq!(nals, vec![&[0x67, 1, 2][..], &[0x68, 3][..], &[0x65, 4, 0][..]]);
        let f = to_avcc(&bytes, true);
        assert_eq!(f.sps.as_deref(), Some(&[0x67, 1, 2][..]));
        assert_eq!(f.pps.as_deref(), Some(&[0x68, 3][..]));
        assert_eq!(f.sample, vec![0, 0, 0, 3, 0x65, 4, 0]);
    }

    #[test]
    fn odd_sizes_are_cropped_to_even() {
        assert_eq!(even_size(175, 144), (174, 144));
        assert_eq!(even_size(3, 3), (2, 2));
        let img = RgbImage::from_fn(3, 3, |x, y| image::Rgb([x as u8, y as u8, 0]));
        assert_eq!(cropped_rgb(&img, 2, 2), vec![0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0]);
    }
}
