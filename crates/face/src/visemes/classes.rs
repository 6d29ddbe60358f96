//! The 18 viseme classes of the paper's Table 1 and the ARPAbet → viseme map.
//!
//! Table 1 groups phonemes by their visual signature. Its IPA column is partly lost in our copy of the
//! paper; where a symbol is missing we read the class name (which lists ARPAbet-like labels). Two
//! readings are ours and documented here: `Y` (IPA /j/, listed under "JH: j") maps to [`Viseme::Jh`]
//! together with `JH` (/dʒ/), and `NG` (velar, like g/k) maps to [`Viseme::GKH`].

use serde::{Deserialize, Serialize};

/// Number of viseme classes (Table 1).
pub const NUM_VISEMES: usize = 18;

/// One viseme class of Table 1. `index()` is the position of its one-hot channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Viseme {
    /// Silence and pauses.
    Sil,
    /// AO + OY (/ɔ/, /ɔɪ/).
    AoOy,
    /// AA + AE + AY (/ɑ/, /æ/, /aɪ/).
    AaAeAy,
    /// EH + EY (/ɛ/, /eɪ/).
    EhEy,
    /// IH + IY + EE + IX (/ɪ/, /i/).
    IhIy,
    /// OH + OW (/oʊ/).
    OhOw,
    /// AH + ER (/ʌ/, /ə/, /ɝ/).
    AhEr,
    /// UW + AW + UH (/u/, /aʊ/, /ʊ/).
    UwAwUh,
    /// JH (/dʒ/, and /j/ as Table 1 lists it).
    Jh,
    /// G + K + H (/g/, /k/, /h/, and /ŋ/).
    GKH,
    /// L + N + T + D.
    LNTD,
    /// S + Z.
    SZ,
    /// Sh + Ch + Zh (/ʃ/, /tʃ/, /ʒ/).
    ShChZh,
    /// TH + DH (/θ/, /ð/).
    ThDh,
    /// F + V.
    FV,
    /// M + B + P (bilabials: the mouth closes).
    MBP,
    /// W.
    W,
    /// R.
    R,
}

impl Viseme {
    /// Every class in channel order.
    pub const ALL: [Viseme; NUM_VISEMES] = [
        Viseme::Sil,
        Viseme::AoOy,
        Viseme::AaAeAy,
        Viseme::EhEy,
        Viseme::IhIy,
        Viseme::OhOw,
        Viseme::AhEr,
        Viseme::UwAwUh,
        Viseme::Jh,
        Viseme::GKH,
        Viseme::LNTD,
        Viseme::SZ,
        Viseme::ShChZh,
        Viseme::ThDh,
        Viseme::FV,
        Viseme::MBP,
        Viseme::W,
        Viseme::R,
    ];

    /// Channel of this class in a one-hot viseme vector.
    pub fn index(self) -> usize {
        Viseme::ALL.iter().position(|v| *v == self).expect("every viseme is in ALL")
    }

    /// The class at one-hot channel `i`, if any.
    pub fn from_index(i: usize) -> Option<Viseme> {
        Viseme::ALL.get(i).copied()
    }

    /// Short name as Table 1 writes it (`"M+B+P"`), used in files and plots.
    pub fn name(self) -> &'static str {
        match self {
            Viseme::Sil => "sil",
            Viseme::AoOy => "AO+OY",
            Viseme::AaAeAy => "AA+AE+AY",
            Viseme::EhEy => "EH+EY",
            Viseme::IhIy => "IH+IY",
            Viseme::OhOw => "OH+OW",
            Viseme::AhEr => "AH+ER",
            Viseme::UwAwUh => "UW+AW+UH",
            Viseme::Jh => "JH",
            Viseme::GKH => "G+K+H",
            Viseme::LNTD => "L+N+T+D",
            Viseme::SZ => "S+Z",
            Viseme::ShChZh => "SH+CH+ZH",
            Viseme::ThDh => "TH+DH",
            Viseme::FV => "F+V",
            Viseme::MBP => "M+B+P",
            Viseme::W => "W",
            Viseme::R => "R",
        }
    }

    /// The class of a viseme name as [`Self::name`] writes it (case-insensitive).
    pub fn from_name(name: &str) -> Option<Viseme> {
        Viseme::ALL.iter().copied().find(|v| v.name().eq_ignore_ascii_case(name.trim()))
    }

    /// The class of an ARPAbet phoneme (CMUdict, Montreal Forced Aligner's English models).
    /// Stress digits are ignored and case does not matter; silence labels (`""`, `sil`, `sp`, `spn`,
    /// `<eps>`) give [`Viseme::Sil`]. Unknown labels give `None`.
    pub fn from_arpabet(phoneme: &str) -> Option<Viseme> {
        let p = phoneme.trim().trim_end_matches(['0', '1', '2']).to_ascii_uppercase();
        Some(match p.as_str() {
            "" | "SIL" | "SP" | "SPN" | "<EPS>" | "PAU" => Viseme::Sil,
            "AO" | "OY" => Viseme::AoOy,
            "AA" | "AE" | "AY" => Viseme::AaAeAy,
            "EH" | "EY" => Viseme::EhEy,
            "IH" | "IY" | "IX" | "EE" => Viseme::IhIy,
            "OW" | "OH" => Viseme::OhOw,
            "AH" | "ER" | "AX" | "AXR" => Viseme::AhEr,
            "UW" | "AW" | "UH" => Viseme::UwAwUh,
            "JH" | "Y" => Viseme::Jh,
            "G" | "K" | "HH" | "H" | "NG" | "Q" => Viseme::GKH,
            "L" | "N" | "T" | "D" | "DX" | "EL" | "EN" => Viseme::LNTD,
            "S" | "Z" => Viseme::SZ,
            "SH" | "CH" | "ZH" => Viseme::ShChZh,
            "TH" | "DH" => Viseme::ThDh,
            "F" | "V" => Viseme::FV,
            "M" | "B" | "P" | "EM" => Viseme::MBP,
            "W" | "WH" => Viseme::W,
            "R" => Viseme::R,
            _ => return None,
        })
    }

    /// Whether the mouth closes for this class (bilabials).
    pub fn closes_mouth(self) -> bool {
        self == Viseme::MBP
    }
}

/// The 39 ARPAbet phonemes of CMUdict (no stress digits).
pub const ARPABET: [&str; 39] = [
    "AA", "AE", "AH", "AO", "AW", "AY", "B", "CH", "D", "DH", "EH", "ER", "EY", "F", "G", "HH", "IH", "IY", "JH", "K",
    "L", "M", "N", "NG", "OW", "OY", "P", "R", "S", "SH", "T", "TH", "UH", "UW", "V", "W", "Y", "Z", "ZH",
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_arpabet_phoneme_has_a_class_and_every_class_a_phoneme() {
        let mut seen = [false; NUM_VISEMES];
        seen[Viseme::Sil.index()] = true;
        for p in ARPABET {
            let v = Viseme::from_arpabet(p).unwrap_or_else(|| panic!("{p} has no viseme"));
            seen[v.index()] = true;
            assert_eq!(Viseme::from_arpabet(&format!("{}1", p.to_lowercase())), Some(v));
        }
        assert!(seen.iter().all(|s| *s), "classes without a phoneme: {seen:?}");
    }

    #[test]
    fn names_and_indices_round_trip() {
        for (i, v) in Viseme::ALL.iter().enumerate() {
            assert_eq!(v.index(), i);
            assert_eq!(Viseme::from_index(i), Some(*v));
            assert_eq!(Viseme::from_name(v.name()), Some(*v));
        }
        assert_eq!(Viseme::from_arpabet("XYZ"), None);
        assert_eq!(Viseme::from_arpabet("sp"), Some(Viseme::Sil));
        assert!(Viseme::MBP.closes_mouth() && !Viseme::FV.closes_mouth());
    }
}
