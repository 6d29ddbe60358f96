//! The editing loop (§3.2: "the user can iteratively write and edit texts"): a [`Session`] keeps the
//! last composition, and a new version of the script re-solves only what changed. Objects of
//! unchanged sentences keep their places exactly (they are pinned); objects of new or edited
//! sentences are laid out around them.
//!
//! Objects are recognised by category and instance ("the second chair"), not by sentence number,
//! so inserting a line above does not move anything; an object whose relations changed is placed
//! anew, and so is everything resting on it.

use std::collections::HashMap;
use std::time::Instant;

use crate::catalogue::Catalogue;
use crate::compose::{compose, ComposeConfig, ComposeInput, Composition, ObjectKey, Pin};
use crate::database::SceneDatabase;
use crate::parse::{parse_script, ParsedScript};

/// What one update did.
#[derive(Debug, Clone)]
pub struct Update {
    pub composition: Composition,
    pub parsed: ParsedScript,
    /// Sentences whose text is new since the previous version (1-based numbers).
    pub changed_sentences: Vec<usize>,
    /// Objects kept exactly in place from the previous version.
    pub kept: usize,
    /// Objects placed anew.
    pub placed: usize,
    /// Wall-clock seconds of the whole update (parse + match + layout).
    pub seconds: f64,
}

/// An editing session over one script.
pub struct Session {
    catalogue: Catalogue,
    database: SceneDatabase,
    config: ComposeConfig,
    pins: HashMap<ObjectKey, Pin>,
    sentences: Vec<String>,
}

impl Session {
    pub fn new(catalogue: Catalogue, database: SceneDatabase, config: ComposeConfig) -> Session {
        Session { catalogue, database, config, pins: HashMap::new(), sentences: Vec::new() }
    }

    pub fn catalogue(&self) -> &Catalogue {
        &self.catalogue
    }

    pub fn database(&self) -> &SceneDatabase {
        &self.database
    }

    /// What [`Session::update`] changes (pins and sentences), to put back with
    /// [`Session::restore`] when a caller abandons the update it started.
    pub(crate) fn checkpoint(&self) -> (HashMap<ObjectKey, Pin>, Vec<String>) {
        (self.pins.clone(), self.sentences.clone())
    }

    /// Puts back a [`Session::checkpoint`].
    pub(crate) fn restore(&mut self, (pins, sentences): (HashMap<ObjectKey, Pin>, Vec<String>)) {
        (self.pins, self.sentences) = (pins, sentences);
    }

    /// Composes `text`, keeping every object of an unchanged sentence where it was.
    pub fn update(&mut self, text: &str) -> Update {
        let start = Instant::now();
        let parsed = parse_script(text, &self.catalogue);
        let changed_sentences = parsed
            .sentences
            .iter()
            .filter(|s| !self.sentences.contains(&s.raw.at.text))
            .map(|s| s.raw.at.sentence)
            .collect();
        let input =
            ComposeInput { parsed: &parsed, catalogue: &self.catalogue, database: &self.database, pins: &self.pins };
        let composition = compose(&input, &self.config);
        let mut pins = HashMap::new();
        let (mut kept, mut placed) = (0, 0);
        for (o, (key, signature)) in composition.scene.objects.iter().zip(&composition.keys) {
            match self.pins.get(key) {
                Some(p) if p.position == o.position && p.yaw == o.yaw => kept += 1,
                _ => placed += 1,
            }
            pins.insert(key.clone(), Pin { position: o.position, yaw: o.yaw, signature: signature.clone() });
        }
        self.pins = pins;
        self.sentences = parsed.sentences.iter().map(|s| s.raw.at.text.clone()).collect();
        Update { composition, parsed, changed_sentences, kept, placed, seconds: start.elapsed().as_secs_f64() }
    }
}
