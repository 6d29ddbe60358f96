//! Phoneme labels → viseme classes (Table 1), for the two label sets forced aligners write.
//!
//! * **ARPAbet** (CMUdict, Montreal Forced Aligner's `english_us_arpa` model, our text front end):
//!   [`Viseme::from_arpabet`] from `classes.rs`.
//! * **IPA** (Montreal Forced Aligner's default `english_mfa` model writes phones such as `tʃ`, `ɹ`,
//!   `aj`, `ow`, `ɾ`, `tʰ`, `ɚ`): Table 1's IPA column, read here. Diacritics, length and stress marks
//!   are dropped first (`tʰ` → `t`, `iː` → `i`, `ɾ̃` → `ɾ`). Two readings are ours: the palatal stops
//!   `c`/`ɟ` that `english_mfa` writes for /k/ and /g/ before front vowels join G+K+H, and the flap `ɾ`
//!   joins L+N+T+D (it is an allophone of /t/ and /d/).

use super::Viseme;

/// Label that our readers and the text front end write for silence (empty TextGrid intervals, pauses).
pub const SILENCE: &str = "sil";

/// The viseme class of a phoneme label: ARPAbet first (stress digits and case ignored, silence
/// labels `""`, `sil`, `sp`, `spn`, `<eps>` → [`Viseme::Sil`]), then IPA. `None` for unknown labels.
pub fn phoneme_viseme(label: &str) -> Option<Viseme> {
    Viseme::from_arpabet(label).or_else(|| ipa_viseme(label))
}

/// Modifier letters and marks that do not change the viseme class.
fn is_modifier(c: char) -> bool {
    matches!(c, '\u{0300}'..='\u{036F}' | 'ʰ' | 'ʷ' | 'ʲ' | 'ˠ' | 'ˤ' | 'ː' | 'ˑ' | '˞' | 'ʼ' | 'ˈ' | 'ˌ' | '.')
}

/// The class of an IPA phone, or `None`.
pub fn ipa_viseme(label: &str) -> Option<Viseme> {
    let base: String = label.trim().chars().filter(|c| !is_modifier(*c)).collect();
    Some(match base.as_str() {
        "ɔ" | "ɔj" | "ɔɪ" | "ɔi" | "ɒ" => Viseme::AoOy,
        "ɑ" | "a" | "æ" | "aj" | "aɪ" | "ai" | "ɑj" | "ɑɪ" => Viseme::AaAeAy,
        "ɛ" | "e" | "ej" | "eɪ" | "ei" => Viseme::EhEy,
        "i" | "ɪ" | "ɨ" => Viseme::IhIy,
        "o" | "ow" | "oʊ" | "ou" | "əʊ" | "əw" => Viseme::OhOw,
        "ə" | "ʌ" | "ɚ" | "ɝ" | "ɜ" | "ɐ" | "ɘ" | "ɵ" => Viseme::AhEr,
        "u" | "ʊ" | "ʉ" | "ɯ" | "aʊ" | "au" | "ɑw" | "ɑʊ" => Viseme::UwAwUh,
        "dʒ" | "ʤ" | "j" => Viseme::Jh,
        "k" | "ɡ" | "g" | "h" | "ɦ" | "ŋ" | "ʔ" | "c" | "ɟ" | "x" | "ɣ" => Viseme::GKH,
        "l" | "ɫ" | "n" | "t" | "d" | "ɾ" | "ɲ" | "ʎ" | "ɬ" => Viseme::LNTD,
        "s" | "z" => Viseme::SZ,
        "ʃ" | "ʒ" | "tʃ" | "ʧ" | "ɕ" | "ʑ" => Viseme::ShChZh,
        "θ" | "ð" => Viseme::ThDh,
        "f" | "v" | "ʋ" => Viseme::FV,
        "m" | "b" | "p" | "ɱ" => Viseme::MBP,
        "w" | "ʍ" => Viseme::W,
        "ɹ" | "r" | "ɻ" => Viseme::R,
        _ => return None,
    })
}

/// What a phoneme label must be, for error messages.
pub(crate) const EXPECTED_LABEL: &str =
    "an ARPAbet phoneme (CMUdict, e.g. 'AH1', 'B'), an IPA phone (e.g. 'ə', 'tʃ'), or silence ('', 'sil', 'sp', 'spn')";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arpabet_and_ipa_labels_map_to_table_1() {
        assert_eq!(phoneme_viseme("B"), Some(Viseme::MBP));
        assert_eq!(phoneme_viseme("ah1"), Some(Viseme::AhEr));
        assert_eq!(phoneme_viseme(""), Some(Viseme::Sil));
        assert_eq!(phoneme_viseme(SILENCE), Some(Viseme::Sil));
        assert_eq!(phoneme_viseme("spn"), Some(Viseme::Sil));
        // IPA as english_mfa writes it.
        assert_eq!(phoneme_viseme("tʃ"), Some(Viseme::ShChZh));
        assert_eq!(phoneme_viseme("tʰ"), Some(Viseme::LNTD));
        assert_eq!(phoneme_viseme("ɹ"), Some(Viseme::R));
        assert_eq!(phoneme_viseme("ð"), Some(Viseme::ThDh));
        assert_eq!(phoneme_viseme("iː"), Some(Viseme::IhIy));
        assert_eq!(phoneme_viseme("ɾ̃"), Some(Viseme::LNTD));
        assert_eq!(phoneme_viseme("aj"), Some(Viseme::AaAeAy));
        assert_eq!(phoneme_viseme("ɚ"), Some(Viseme::AhEr));
        assert_eq!(phoneme_viseme("ʊ"), Some(Viseme::UwAwUh));
        assert_eq!(phoneme_viseme("cʰ"), Some(Viseme::GKH));
        assert_eq!(phoneme_viseme("m̩"), Some(Viseme::MBP));
        assert_eq!(phoneme_viseme("XYZ"), None);
        assert_eq!(phoneme_viseme("ʘ"), None);
    }

    #[test]
    fn every_class_has_an_ipa_phone() {
        let phones = ["ɔ", "æ", "ɛ", "ɪ", "ow", "ə", "u", "dʒ", "k", "l", "s", "ʃ", "θ", "f", "m", "w", "ɹ"];
        let mut seen = [false; super::super::NUM_VISEMES];
        seen[Viseme::Sil.index()] = true;
        for p in phones {
            seen[ipa_viseme(p).unwrap_or_else(|| panic!("{p} unmapped")).index()] = true;
        }
        assert!(seen.iter().all(|s| *s), "{seen:?}");
    }
}
