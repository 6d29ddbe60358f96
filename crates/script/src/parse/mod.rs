//! Text → semantic scene graph (§3.2 "Text Parsing", §4.1). The paper runs CoreNLP's tagger and
//! dependency parser; we tokenise ([`token`]), tag with rules ([`tag`], Penn tags in [`penn`]),
//! lemmatise ([`lemma`]) and turn tag patterns into the SSG ([`rules`]). No model files,
//! deterministic.

pub mod lemma;
pub mod lexicon;
pub mod penn;
pub mod rules;
pub mod suggest;
pub mod tag;
pub mod token;

pub use lemma::{lemmatize, lemmatize_noun, lemmatize_verb};
pub use lexicon::number_value;
pub use rules::ParseState;
pub use suggest::{edit_distance, suggestions};
pub use tag::{tag, Tag, Tagged};
pub use token::{tokenize, Token};

use crate::catalogue::Catalogue;
use crate::error::Diagnostic;
use crate::sentences::{split, RawSentence, SentenceKind};
use crate::ssg::Ssg;

/// One sentence and its graph. Nodes carry `sentence = raw.at.sentence - 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParsedSentence {
    pub raw: RawSentence,
    pub ssg: Ssg,
}

/// A whole script: every sentence's graph plus the problems found, in script order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParsedScript {
    pub sentences: Vec<ParsedSentence>,
    pub diagnostics: Vec<Diagnostic>,
}

impl ParsedScript {
    /// All sentences' graphs merged into one (node ids renumbered).
    pub fn merged(&self) -> Ssg {
        let mut all = Ssg::default();
        for s in &self.sentences {
            all.merge(s.ssg.clone());
        }
        all
    }
}

/// Parses one sentence on its own (no "it"/"he" from earlier sentences).
pub fn parse_sentence(raw: &RawSentence, cat: &Catalogue) -> (Ssg, Vec<Diagnostic>) {
    rules::parse_with(raw, cat, &mut ParseState::default())
}

/// Splits and parses a script. A direction that describes only objects ("There is a bottle",
/// written without `$` in Fig. 5) is read as a scene description and its kind set to
/// [`SentenceKind::Scene`]; a diagnostic says so.
pub fn parse_script(text: &str, cat: &Catalogue) -> ParsedScript {
    let mut state = ParseState::default();
    let mut out = ParsedScript::default();
    for mut raw in split(text) {
        let (ssg, diags) = rules::parse_with(&raw, cat, &mut state);
        if raw.kind == SentenceKind::Direction
            && ssg.characters.is_empty()
            && ssg.commands.is_empty()
            && (!ssg.objects.is_empty() || ssg.room.is_some())
        {
            raw.kind = SentenceKind::Scene;
        }
        out.diagnostics.extend(diags);
        out.sentences.push(ParsedSentence { raw, ssg });
    }
    out
}
