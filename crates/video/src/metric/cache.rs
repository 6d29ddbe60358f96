//! Per-clip cache of a trained RSFNet and its frame embeddings, so a clip is trained once.
//!
//! The key hashes the images the network sees (every frame resized to `input_side`, so two clips
//! that the network cannot tell apart share an entry and any pixel change that reaches the network
//! makes a new one), the architecture and the training options (seed included). One file per key,
//! `rsfnet-<key>.bin` in the caller's folder, holds the network (burnpack) as well as the embeddings,
//! because the motion distance of Eq. 15 embeds pseudo-images on demand:
//!
//! ```text
//! b"INBRSF01" | JSON length (u64 LE) | JSON {format, key, frames, config, options, summary, embeddings} | burnpack
//! ```
//!
//! The file is written atomically ([`inbetween_io::write_atomic`]). A file that cannot be read, is
//! truncated or corrupt, or describes another clip is ignored (with a note on the progress handle)
//! and rebuilt; it never causes a panic or an error.

use std::path::{Path, PathBuf};

use image::RgbImage;
use inbetween_core::cancel::Cancel;
use inbetween_io::{write_atomic, Progress};
use inbetween_nn::{backend, checkpoint};
use serde::{Deserialize, Serialize};

use super::embed::Embedder;
use super::input::Planes;
use super::model::RsfConfig;
use super::train::{clip_planes, TrainOptions, TrainSummary};
use crate::VideoError;

const MAGIC: &[u8; 8] = b"INBRSF01";
/// Version of the cached content; bump it when training or the network change meaning.
pub const CACHE_FORMAT: u32 = 2;

/// A trained metric for one clip: the network, every frame's latent vector and how it was made.
#[derive(Debug, Clone)]
pub struct ClipMetric {
    pub embedder: Embedder,
    /// `R(x_i)` of every frame (Eq. 7), in frame order.
    pub embeddings: Vec<Vec<f32>>,
    pub summary: TrainSummary,
    /// The cache key of this clip, config and options.
    pub key: u64,
    /// The cache file.
    pub path: PathBuf,
    /// Read from the cache (no training happened).
    pub from_cache: bool,
    /// Why an existing cache file was not used, if one was there but unusable.
    pub rejected_cache: Option<String>,
    /// Why the cache file could not be written, if it could not (the result is still good).
    pub write_error: Option<String>,
}

#[derive(Serialize, Deserialize)]
struct CacheMeta {
    format: u32,
    key: u64,
    frames: usize,
    config: RsfConfig,
    options: TrainOptions,
    summary: TrainSummary,
    embeddings: Vec<Vec<f32>>,
}

/// 64-bit FNV-1a, finished with SplitMix: a stable hash (unlike `std`'s, which may change between
/// Rust releases) for cache keys.
struct KeyHasher(u64);

impl KeyHasher {
    fn new() -> KeyHasher {
        KeyHasher(0xcbf2_9ce4_8422_2325)
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn finish(&self) -> u64 {
        inbetween_core::seed::mix(self.0)
    }
}

/// The cache key of a clip (already resized by [`clip_planes`]) under a config and options.
pub fn cache_key(planes: &[Planes], cfg: &RsfConfig, opts: &TrainOptions) -> u64 {
    let mut h = KeyHasher::new();
    h.bytes(&CACHE_FORMAT.to_le_bytes());
    h.bytes(&(planes.len() as u64).to_le_bytes());
    for p in planes {
        for v in p {
            h.bytes(&v.to_bits().to_le_bytes());
        }
    }
    h.bytes(serde_json::to_string(cfg).unwrap_or_default().as_bytes());
    h.bytes(serde_json::to_string(opts).unwrap_or_default().as_bytes());
    h.finish()
}

/// The cache file of `key` in `cache_dir`.
pub fn cache_path(cache_dir: &Path, key: u64) -> PathBuf {
    cache_dir.join(format!("rsfnet-{key:016x}.bin"))
}

/// The trained metric of a clip: read from `cache_dir` when a valid entry exists, otherwise
/// trained ([`super::train_rsfnet`]), embedded and written there.
pub fn embeddings_cached(
    cache_dir: &Path,
    frames: &[RgbImage],
    cfg: &RsfConfig,
    opts: &TrainOptions,
    progress: &Progress,
) -> Result<ClipMetric, VideoError> {
    embeddings_cached_with(cache_dir, frames, cfg, opts, progress, &Cancel::new())
}

/// [`embeddings_cached`] whose training stops with [`VideoError::Cancelled`] once `cancel` is
/// cancelled (nothing is written to the cache then).
pub fn embeddings_cached_with(
    cache_dir: &Path,
    frames: &[RgbImage],
    cfg: &RsfConfig,
    opts: &TrainOptions,
    progress: &Progress,
    cancel: &Cancel,
) -> Result<ClipMetric, VideoError> {
    cfg.validate()?;
    opts.validate()?;
    let planes = clip_planes(frames, cfg.input_side);
    let key = cache_key(&planes, cfg, opts);
    let path = cache_path(cache_dir, key);
    let rejected_cache = match read_entry(&path, key, planes.len(), cfg, opts) {
        Ok(Some((embedder, embeddings, summary))) => {
            return Ok(ClipMetric {
                embedder,
                embeddings,
                summary,
                key,
                path,
                from_cache: true,
                rejected_cache: None,
                write_error: None,
            });
        }
        Ok(None) => None,
        Err(reason) => {
            progress.println(format!("{}: ignoring the RSFNet cache ({reason}); training again", path.display()));
            Some(reason)
        }
    };
    let (embedder, summary) = super::train::train_on_planes_with(&planes, cfg, opts, progress, cancel)?;
    let embeddings = embedder.embed_planes(&planes);
    cancel.check()?;
    let write_error = write_entry(&path, key, cfg, opts, &summary, &embeddings, &embedder).err();
    if let Some(e) = &write_error {
        progress.println(format!("{}: could not write the RSFNet cache: {e}", path.display()));
    }
    Ok(ClipMetric { embedder, embeddings, summary, key, path, from_cache: false, rejected_cache, write_error })
}

type Entry = (Embedder, Vec<Vec<f32>>, TrainSummary);

/// `Ok(None)`: no file. `Err`: a file that cannot be used, and why.
fn read_entry(
    path: &Path,
    key: u64,
    frames: usize,
    cfg: &RsfConfig,
    opts: &TrainOptions,
) -> Result<Option<Entry>, String> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("cannot read it: {e}")),
    };
    if bytes.len() < 16 || &bytes[..8] != MAGIC {
        return Err("not an RSFNet cache file".into());
    }
    let json_len = u64::from_le_bytes(bytes[8..16].try_into().expect("8 bytes"));
    let json_end = usize::try_from(json_len)
        .ok()
        .and_then(|l| l.checked_add(16))
        .filter(|&e| e <= bytes.len())
        .ok_or("truncated")?;
    let meta: CacheMeta = serde_json::from_slice(&bytes[16..json_end]).map_err(|e| format!("bad header: {e}"))?;
    if meta.format != CACHE_FORMAT
        || meta.key != key
        || meta.frames != frames
        || &meta.config != cfg
        || &meta.options != opts
    {
        return Err("written for another clip, config or format".into());
    }
    if meta.embeddings.len() != frames || meta.embeddings.iter().any(|e| e.len() != cfg.latent) {
        return Err("embeddings of the wrong shape".into());
    }
    let device = backend::cpu();
    let net = checkpoint::load_module_bytes(cfg.init(&device), bytes[json_end..].to_vec(), path)
        .map_err(|e| e.to_string())?;
    Ok(Some((Embedder::new(net, cfg.clone()), meta.embeddings, meta.summary)))
}

fn write_entry(
    path: &Path,
    key: u64,
    cfg: &RsfConfig,
    opts: &TrainOptions,
    summary: &TrainSummary,
    embeddings: &[Vec<f32>],
    embedder: &Embedder,
) -> Result<(), String> {
    let meta = CacheMeta {
        format: CACHE_FORMAT,
        key,
        frames: embeddings.len(),
        config: cfg.clone(),
        options: opts.clone(),
        summary: summary.clone(),
        embeddings: embeddings.to_vec(),
    };
    let json = serde_json::to_vec(&meta).map_err(|e| e.to_string())?;
    let net = checkpoint::module_bytes(&embedder.net, path).map_err(|e| e.to_string())?;
    let mut bytes = Vec::with_capacity(16 + json.len() + net.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&(json.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&json);
    bytes.extend_from_slice(&net);
    write_atomic(path, &bytes).map_err(|e| e.to_string())
}
