//! The limits of a script job (issue 29), checked before any composition or animation: the work a
//! story asks for grows with its sentences, words, characters, objects and actions, so each is
//! capped, and the animation's length is checked again before any output is written. Each limit
//! is a field the error names ([`LimitExceeded::field`]); the CLI maps it to its flag.

use inbetween_io::LimitExceeded;

use crate::catalogue::Catalogue;
use crate::parse::parse_script;
use crate::sentences::SentenceKind;

/// The limits of a story job. The defaults let every built-in story and far longer ones through.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScriptLimits {
    /// Most sentences (scene sentences, directions and camera commands). Default 200.
    pub max_sentences: usize,
    /// Most words in the whole script. Default 5 000.
    pub max_words: usize,
    /// Most characters named. Default 20.
    pub max_characters: usize,
    /// Most objects the scene sentences ask for (every mention's count, "two chairs" = 2).
    /// Default 300.
    pub max_objects: usize,
    /// Most character actions (verbs): each one is a clip of animation. Default 150, about ten
    /// minutes of animation at the built-in stories' pace.
    pub max_actions: usize,
    /// Longest animation, seconds, checked after animating and before writing. Default 600.
    pub max_animation_s: f64,
}

impl Default for ScriptLimits {
    fn default() -> Self {
        ScriptLimits {
            max_sentences: 200,
            max_words: 5_000,
            max_characters: 20,
            max_objects: 300,
            max_actions: 150,
            max_animation_s: 600.0,
        }
    }
}

impl ScriptLimits {
    /// Checks what the text asks for against the limits before any work: sentences and words
    /// first (no parsing), then characters, objects and actions from the parse. `source` names the
    /// script in the error.
    pub fn check_text(&self, text: &str, source: &str, cat: &Catalogue) -> Result<(), LimitExceeded> {
        self.check_and_parse(text, source, cat).map(|_| ())
    }

    /// [`ScriptLimits::check_text`] that gives the parse it made, for a caller that needs it
    /// next (one parse instead of two).
    pub fn check_and_parse(
        &self,
        text: &str,
        source: &str,
        cat: &Catalogue,
    ) -> Result<crate::parse::ParsedScript, LimitExceeded> {
        let words = text.split_whitespace().count();
        LimitExceeded::check_count(source, words, self.max_words, "words", "max_words")?;
        let sentences = crate::sentences::split(text).len();
        LimitExceeded::check_count(source, sentences, self.max_sentences, "sentences", "max_sentences")?;
        let parsed = parse_script(text, cat);
        let mut names: Vec<String> = Vec::new();
        let (mut objects, mut actions) = (0usize, 0usize);
        for s in &parsed.sentences {
            // Objects placed in the room come from scene sentences; directions only refer to them.
            if s.raw.kind == SentenceKind::Scene {
                objects += s.ssg.objects.iter().map(|o| o.count).sum::<usize>();
            }
            for c in &s.ssg.characters {
                actions += c.actions.len();
                let key = c.name.to_lowercase();
                if !names.contains(&key) {
                    names.push(key);
                }
            }
        }
        LimitExceeded::check_count(source, names.len(), self.max_characters, "characters", "max_characters")?;
        LimitExceeded::check_count(source, objects, self.max_objects, "objects", "max_objects")?;
        LimitExceeded::check_count(source, actions, self.max_actions, "character actions", "max_actions")?;
        Ok(parsed)
    }

    /// Checks the animation's length (`frames` at `fps`) before its outputs are written.
    pub fn check_animation(&self, source: &str, frames: usize, fps: f64) -> Result<(), LimitExceeded> {
        let seconds = if fps > 0.0 { frames as f64 / fps } else { 0.0 };
        LimitExceeded::check_seconds(
            format!("{source}: the animation"),
            seconds,
            self.max_animation_s,
            "max_animation_s",
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn cat() -> Catalogue {
        crate::catalogue::builtin::builtin()
    }

    #[test]
    fn every_builtin_story_is_within_the_default_limits() {
        let cat = cat();
        for (name, text) in crate::builtin_scripts::all() {
            ScriptLimits::default().check_text(text, name, &cat).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }

    #[test]
    fn each_limit_is_named_in_its_error() {
        let cat = cat();
        let text = "In the office, two chairs are near a desk$\nEve walks to the desk. Tom sits on a chair.\n";
        let l = ScriptLimits::default();
        let field = |l: ScriptLimits| l.check_text(text, "s.txt", &cat).unwrap_err().field;
        assert_eq!(field(ScriptLimits { max_words: 5, ..l }), "max_words");
        assert_eq!(field(ScriptLimits { max_sentences: 2, ..l }), "max_sentences");
        assert_eq!(field(ScriptLimits { max_characters: 1, ..l }), "max_characters");
        assert_eq!(field(ScriptLimits { max_objects: 2, ..l }), "max_objects");
        assert_eq!(field(ScriptLimits { max_actions: 1, ..l }), "max_actions");
        let e = ScriptLimits { max_sentences: 2, ..l }.check_text(text, "s.txt", &cat).unwrap_err();
        assert!(e.to_string().contains("s.txt") && e.to_string().contains("3 sentences"), "{e}");
        assert!(l.check_text(text, "s.txt", &cat).is_ok());
        let e = l.check_animation("s.txt", 30 * 700, 30.0).unwrap_err();
        assert_eq!(e.field, "max_animation_s");
        assert!(l.check_animation("s.txt", 30 * 60, 30.0).is_ok());
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]
        /// Oversized stories (thousands of sentences, or one endless sentence) are refused at
        /// once, naming the limit, long before any composition.
        #[test]
        fn oversized_stories_are_refused_quickly(n in 250usize..3000, one_line in any::<bool>()) {
            let cat = cat();
            let sep = if one_line { " and " } else { ".\n" };
            let text = std::iter::repeat_n("Eve walks to the desk", n).collect::<Vec<_>>().join(sep);
            let t = std::time::Instant::now();
            let e = ScriptLimits::default().check_text(&text, "big.txt", &cat).unwrap_err();
            prop_assert!(["max_words", "max_sentences", "max_actions"].contains(&e.field), "{}", e);
            prop_assert!(t.elapsed().as_secs_f64() < 1.0, "took {:?}", t.elapsed());
        }
    }
}
