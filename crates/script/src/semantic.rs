//! Words outside the synonym tables, read through sentence embeddings (feature `embeddings`,
//! model installed by `scripts/fetch-minilm.sh`). Every replacement is reported, never silent:
//! "loveseat" read as sofa (cosine 0.77).

use crate::catalogue::Catalogue;
use crate::error::Diagnostic;
use crate::parse::parse_script;
use crate::ScriptError;

/// The words the parser did not know and the catalogue entries the embedding model maps them to.
/// Returns the catalogue taught those words and one note per replacement.
#[cfg(feature = "embeddings")]
pub fn teach_unknown_words(
    text: &str,
    cat: &Catalogue,
    model_dir: Option<&std::path::Path>,
) -> Result<(Catalogue, Vec<Diagnostic>), ScriptError> {
    use crate::embed::{Embedder, SemanticResolver};
    let parsed = parse_script(text, cat);
    let unknown: Vec<&Diagnostic> =
        parsed.diagnostics.iter().filter(|d| d.word.is_some() && d.message.starts_with("unknown object")).collect();
    if unknown.is_empty() {
        return Ok((cat.clone(), Vec::new()));
    }
    let embedder = match model_dir {
        Some(dir) => Embedder::load(dir)?,
        None => Embedder::load_default()?,
    };
    let resolver = SemanticResolver::new(embedder, cat)?;
    let mut taught = cat.clone();
    let mut notes = Vec::new();
    for d in unknown {
        let Some(word) = d.word.as_deref() else { continue };
        let lower = word.to_lowercase();
        if let Some((category, cosine)) = resolver.nearest(&lower)? {
            if taught.add_synonym(&lower, &category) {
                notes.push(Diagnostic {
                    message: format!("'{word}' read as {category} (embedding cosine {cosine:.2})"),
                    suggestions: Vec::new(),
                    ..d.clone()
                });
            }
        } else if let Some((room, cosine)) = resolver.nearest_room(&lower)? {
            if taught.add_room_synonym(&lower, &room) {
                notes.push(Diagnostic {
                    message: format!("'{word}' read as the room kind {room} (embedding cosine {cosine:.2})"),
                    suggestions: Vec::new(),
                    ..d.clone()
                });
            }
        }
    }
    Ok((taught, notes))
}

/// Without the `embeddings` feature: a clear error saying how to get it.
#[cfg(not(feature = "embeddings"))]
pub fn teach_unknown_words(
    _text: &str,
    _cat: &Catalogue,
    _model_dir: Option<&std::path::Path>,
) -> Result<(Catalogue, Vec<Diagnostic>), ScriptError> {
    let _ = parse_script;
    Err(ScriptError::Invalid(
        "semantic matching needs the `embeddings` feature: build with `cargo build --release -p inbetween-cli --features embeddings` and install the model with scripts/fetch-minilm.sh".into(),
    ))
}
