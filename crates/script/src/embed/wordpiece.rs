//! BERT's uncased WordPiece tokeniser, written out so the `embeddings` feature needs no `tokenizers`
//! crate. It reproduces what `BertTokenizer` (do_lower_case, tokenize_chinese_chars) does for
//! all-MiniLM-L6-v2:
//!
//! 1. clean: drop NUL, U+FFFD and control characters; every whitespace character becomes a space;
//! 2. put spaces around CJK ideographs;
//! 3. split on whitespace; lower-case each piece and strip accents ("Café" → "cafe"; Latin letters
//!    through a table, since std has no Unicode decomposition);
//! 4. split off every punctuation character as its own token (ASCII punctuation and the common
//!    Unicode punctuation blocks);
//! 5. WordPiece: greedy longest-match-first against the vocabulary, continuation pieces carry the
//!    `##` prefix; a word that cannot be covered, or is longer than 100 characters, becomes `[UNK]`.
//!
//! [`WordPiece::encode`] wraps the ids as `[CLS] … [SEP]`. Encoding is pad-free: each text is
//! encoded alone, so there are no `[PAD]` tokens and the attention mask is all ones.

use std::collections::HashMap;
use std::path::Path;

use crate::error::ScriptError;

/// Longest word WordPiece tries to split (BERT's `max_input_chars_per_word`).
pub const MAX_CHARS_PER_WORD: usize = 100;

/// A WordPiece vocabulary with BERT's special tokens.
#[derive(Debug, Clone)]
pub struct WordPiece {
    vocab: HashMap<String, u32>,
    unk: u32,
    cls: u32,
    sep: u32,
}

impl WordPiece {
    /// A vocabulary from `vocab.txt` text: one token a line, the id is the 0-based line number.
    /// `[UNK]`, `[CLS]` and `[SEP]` must be present.
    pub fn from_vocab_text(text: &str) -> Result<WordPiece, ScriptError> {
        let vocab = text
            .lines()
            .enumerate()
            .map(|(i, t)| (t.trim_end_matches('\r').to_string(), i as u32))
            .collect::<HashMap<_, _>>();
        WordPiece::from_map(vocab)
    }

    /// A vocabulary from a token → id map (as in `tokenizer.json`'s `model.vocab`).
    pub fn from_map(vocab: HashMap<String, u32>) -> Result<WordPiece, ScriptError> {
        let special = |t: &str| {
            vocab.get(t).copied().ok_or_else(|| ScriptError::Invalid(format!("WordPiece vocabulary has no {t} token")))
        };
        Ok(WordPiece { unk: special("[UNK]")?, cls: special("[CLS]")?, sep: special("[SEP]")?, vocab })
    }

    /// Reads `vocab.txt`.
    pub fn from_vocab_file(path: &Path) -> Result<WordPiece, ScriptError> {
        let text = std::fs::read_to_string(path).map_err(|e| ScriptError::io(path, e))?;
        WordPiece::from_vocab_text(&text)
            .map_err(|e| ScriptError::Asset { path: path.to_path_buf(), message: e.to_string() })
    }

    /// Reads the vocabulary out of a Hugging Face `tokenizer.json` (`model.vocab`).
    pub fn from_tokenizer_json(path: &Path) -> Result<WordPiece, ScriptError> {
        let text = std::fs::read_to_string(path).map_err(|e| ScriptError::io(path, e))?;
        let asset = |message: String| ScriptError::Asset { path: path.to_path_buf(), message };
        let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| asset(format!("not JSON: {e}")))?;
        let map = json
            .pointer("/model/vocab")
            .and_then(|v| v.as_object())
            .ok_or_else(|| asset("no model.vocab object".to_string()))?;
        let vocab =
            map.iter().filter_map(|(k, v)| v.as_u64().map(|id| (k.clone(), id as u32))).collect::<HashMap<_, _>>();
        WordPiece::from_map(vocab).map_err(|e| asset(e.to_string()))
    }

    pub fn len(&self) -> usize {
        self.vocab.len()
    }

    pub fn is_empty(&self) -> bool {
        self.vocab.is_empty()
    }

    /// The id of a token, when the vocabulary has it.
    pub fn id(&self, token: &str) -> Option<u32> {
        self.vocab.get(token).copied()
    }

    pub fn cls_id(&self) -> u32 {
        self.cls
    }

    pub fn sep_id(&self) -> u32 {
        self.sep
    }

    pub fn unk_id(&self) -> u32 {
        self.unk
    }

    /// Steps 1–4: the basic tokeniser's words and punctuation marks, lower-cased, accents stripped.
    pub fn basic_tokens(text: &str) -> Vec<String> {
        let mut cleaned = String::with_capacity(text.len() + 8);
        for c in text.chars() {
            if c == '\0' || c == '\u{fffd}' || is_control(c) {
                continue;
            }
            if is_cjk(c) {
                cleaned.push(' ');
                cleaned.push(c);
                cleaned.push(' ');
            } else if c.is_whitespace() {
                cleaned.push(' ');
            } else {
                cleaned.push(c);
            }
        }
        let mut out = Vec::new();
        for word in cleaned.split_whitespace() {
            let mut current = String::new();
            for c in word.chars().flat_map(char::to_lowercase) {
                let Some(c) = strip_accent(c) else { continue };
                if is_punctuation(c) {
                    if !current.is_empty() {
                        out.push(std::mem::take(&mut current));
                    }
                    out.push(c.to_string());
                } else {
                    current.push(c);
                }
            }
            if !current.is_empty() {
                out.push(current);
            }
        }
        out
    }

    /// Step 5 for one basic token: greedy longest-match-first pieces (`##` on continuations), or
    /// `["[UNK]"]` when the word cannot be covered.
    pub fn word_pieces(&self, word: &str) -> Vec<String> {
        let chars: Vec<char> = word.chars().collect();
        if chars.len() > MAX_CHARS_PER_WORD {
            return vec!["[UNK]".to_string()];
        }
        let mut pieces = Vec::new();
        let mut start = 0;
        while start < chars.len() {
            let mut end = chars.len();
            let mut found = None;
            while start < end {
                let mut sub: String = chars[start..end].iter().collect();
                if start > 0 {
                    sub.insert_str(0, "##");
                }
                if self.vocab.contains_key(&sub) {
                    found = Some(sub);
                    break;
                }
                end -= 1;
            }
            match found {
                Some(sub) => pieces.push(sub),
                None => return vec!["[UNK]".to_string()],
            }
            start = end;
        }
        pieces
    }

    /// All WordPiece tokens of a text, without `[CLS]`/`[SEP]`.
    pub fn tokenize(&self, text: &str) -> Vec<String> {
        WordPiece::basic_tokens(text).iter().flat_map(|w| self.word_pieces(w)).collect()
    }

    /// `[CLS] pieces… [SEP]` as ids, at most `max_len` ids in all (the pieces are truncated, as
    /// sentence-transformers does at `max_seq_length`); `max_len` below 2 counts as 2.
    pub fn encode(&self, text: &str, max_len: usize) -> Vec<u32> {
        let mut ids = vec![self.cls];
        let room = max_len.max(2) - 2;
        ids.extend(self.tokenize(text).iter().map(|t| self.vocab.get(t).copied().unwrap_or(self.unk)).take(room));
        ids.push(self.sep);
        ids
    }

    /// Splits a glued compound the vocabulary does not hold as one word into two (or three) whole
    /// words it does ("officechair" → "office chair", "bedsidetable" → "bedside table"), so the
    /// catalogue's glued names embed like the phrases they stand for. Words the vocabulary has,
    /// and words with no such split, come back unchanged.
    pub fn split_compound(&self, word: &str) -> String {
        if word.contains(char::is_whitespace) || self.vocab.contains_key(word) {
            return word.to_string();
        }
        self.split_parts(word, 3).map(|p| p.join(" ")).unwrap_or_else(|| word.to_string())
    }

    /// The split into at most `parts` vocabulary words (each ≥ 2 characters) whose shortest part is
    /// longest; ties go to the longer first part.
    fn split_parts<'a>(&self, word: &'a str, parts: usize) -> Option<Vec<&'a str>> {
        if self.vocab.contains_key(word) {
            return Some(vec![word]);
        }
        if parts < 2 {
            return None;
        }
        let mut best: Option<Vec<&'a str>> = None;
        let score = |p: &Vec<&str>| (std::cmp::Reverse(p.len()), p.iter().map(|s| s.len()).min().unwrap_or(0));
        for (i, _) in word.char_indices().skip(2) {
            let (left, right) = word.split_at(i);
            if right.chars().count() < 2 || !self.vocab.contains_key(left) {
                continue;
            }
            if let Some(mut rest) = self.split_parts(right, parts - 1) {
                rest.insert(0, left);
                if best.as_ref().is_none_or(|b| score(&rest) > score(b)) {
                    best = Some(rest);
                }
            }
        }
        best
    }
}

/// Control characters BERT drops (Unicode Cc/Cf), except tab, newline and carriage return, which
/// count as whitespace.
fn is_control(c: char) -> bool {
    if c == '\t' || c == '\n' || c == '\r' {
        return false;
    }
    c.is_control()
        || matches!(c, '\u{00ad}' | '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2060}'..='\u{2064}' | '\u{feff}')
}

/// BERT's "Chinese character" ranges (CJK unified ideographs and their extensions).
fn is_cjk(c: char) -> bool {
    matches!(c as u32,
        0x4E00..=0x9FFF | 0x3400..=0x4DBF | 0x20000..=0x2A6DF | 0x2A700..=0x2B73F
        | 0x2B740..=0x2B81F | 0x2B820..=0x2CEAF | 0xF900..=0xFAFF | 0x2F800..=0x2FA1F)
}

/// BERT's punctuation: every non-alphanumeric ASCII printable character, plus Unicode punctuation
/// (the Latin-1 marks, General Punctuation, CJK symbols and punctuation, full-width forms).
fn is_punctuation(c: char) -> bool {
    c.is_ascii_punctuation()
        || matches!(c,
            '¡' | '§' | '«' | '¶' | '·' | '»' | '¿' | '\u{2010}'..='\u{2027}' | '\u{2030}'..='\u{205e}'
            | '\u{3001}'..='\u{3003}' | '\u{3008}'..='\u{3011}' | '\u{3014}'..='\u{301f}'
            | '\u{ff01}'..='\u{ff0f}' | '\u{ff1a}'..='\u{ff20}' | '\u{ff3b}'..='\u{ff40}'
            | '\u{ff5b}'..='\u{ff65}')
}

/// Accent stripping (NFD, then drop combining marks) for lower-case Latin letters; combining marks
/// themselves vanish (`None`). Other characters pass unchanged.
fn strip_accent(c: char) -> Option<char> {
    if ('\u{0300}'..='\u{036f}').contains(&c) {
        return None;
    }
    let base = match c {
        'à' | 'á' | 'â' | 'ã' | 'ä' | 'å' | 'ā' | 'ă' | 'ą' | 'ǎ' => 'a',
        'ç' | 'ć' | 'ĉ' | 'ċ' | 'č' => 'c',
        'ď' => 'd',
        'è' | 'é' | 'ê' | 'ë' | 'ē' | 'ĕ' | 'ė' | 'ę' | 'ě' => 'e',
        'ĝ' | 'ğ' | 'ġ' | 'ģ' => 'g',
        'ĥ' => 'h',
        'ì' | 'í' | 'î' | 'ï' | 'ĩ' | 'ī' | 'ĭ' | 'į' | 'ǐ' => 'i',
        'ĵ' => 'j',
        'ķ' => 'k',
        'ĺ' | 'ļ' | 'ľ' => 'l',
        'ñ' | 'ń' | 'ņ' | 'ň' => 'n',
        'ò' | 'ó' | 'ô' | 'õ' | 'ö' | 'ō' | 'ŏ' | 'ő' | 'ǒ' => 'o',
        'ŕ' | 'ŗ' | 'ř' => 'r',
        'ś' | 'ŝ' | 'ş' | 'š' | 'ș' => 's',
        'ţ' | 'ť' | 'ț' => 't',
        'ù' | 'ú' | 'û' | 'ü' | 'ũ' | 'ū' | 'ŭ' | 'ů' | 'ű' | 'ų' | 'ǔ' => 'u',
        'ŵ' => 'w',
        'ý' | 'ÿ' | 'ŷ' => 'y',
        'ź' | 'ż' | 'ž' => 'z',
        other => other,
    };
    Some(base)
}
