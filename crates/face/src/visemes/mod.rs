//! Visemes from phonemes (§3.1, Table 1): the 18 classes, and per-frame viseme tracks from a
//! forced alignment (TextGrid), a phoneme-timing CSV/JSON, or English text spread over a time span.
//!
//! * [`classes`](Viseme): the 18 classes of Table 1 and the ARPAbet map; [`phoneme_viseme`] adds the
//!   IPA labels of Montreal Forced Aligner's `english_mfa` model.
//! * [`PhonemeSpan`]: a phoneme over `[start_s, end_s)`; every source is checked the same way
//!   ([`validate_spans`]).
//! * Sources: [`read_textgrid`] (Praat TextGrid, long or short layout, UTF-8/UTF-16),
//!   [`read_phoneme_timing`] (CSV/JSON), [`read_viseme_source`] (either, by extension), and
//!   [`text_to_phonemes`] (English text over a time span: CMUdict, embedded at build time, plus our
//!   letter-to-sound rules).
//! * Tracks: [`viseme_frames`] (one class per frame) and [`one_hot`] (the network's constraint
//!   channels, §3.1).
//!
//! No reader panics on any input (property tests in `robustness.rs`, `fuzz/fuzz_targets/face_textgrid.rs`).

mod classes;
pub mod g2p;
mod labels;
mod source;
mod spans;
pub mod textgrid;
pub mod timing;
mod track;

pub use classes::{Viseme, ARPABET, NUM_VISEMES};
pub use g2p::{letter_to_sound, pronounce, text_to_phonemes, Pronunciation, TextPhonemes};
pub use labels::{ipa_viseme, phoneme_viseme, SILENCE};
pub use source::read_viseme_source;
pub use spans::{decode_text, validate_spans, PhonemeSpan, OVERLAP_TOLERANCE_S};
pub use textgrid::{parse_textgrid, read_textgrid, PHONE_TIER_NAMES};
pub use timing::{
    parse_phoneme_csv, parse_phoneme_json, read_phoneme_timing, to_phoneme_csv_string, to_phoneme_json_string,
    write_phoneme_timing,
};
pub use track::{one_hot, viseme_frames};

#[cfg(test)]
mod robustness;
