//! The Penn Treebank tag set the tagger ([`super::tag`]) assigns and the lemmatiser
//! ([`super::lemma`]) reads (§3.2: CoreNLP's tags in the paper, Fig. 3).

/// Penn Treebank tags (the names are the standard ones, hence upper case).
#[allow(clippy::upper_case_acronyms)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Tag {
    /// Determiner ("a", "the").
    DT,
    /// Number ("two", "3").
    CD,
    /// Singular noun.
    NN,
    /// Plural noun.
    NNS,
    /// Proper noun ("Eve").
    NNP,
    /// Personal pronoun.
    PRP,
    /// Possessive pronoun ("his").
    PRPS,
    /// Verb, base form.
    VB,
    /// Verb, 3rd person singular present ("sits").
    VBZ,
    /// Verb, non-3rd person present ("are").
    VBP,
    /// Verb, past tense ("sat").
    VBD,
    /// Verb, gerund ("sitting").
    VBG,
    /// Verb, past participle ("seen").
    VBN,
    /// Modal ("can").
    MD,
    /// Preposition.
    IN,
    /// "to".
    TO,
    /// Adjective.
    JJ,
    /// Adverb or particle ("madly", "right").
    RB,
    /// Coordinating conjunction.
    CC,
    /// Existential "there".
    EX,
    /// Wh-determiner ("which").
    WDT,
    /// Possessive ending "'s".
    POS,
    /// Punctuation.
    Punct,
}

impl Tag {
    pub fn is_verb(self) -> bool {
        matches!(self, Tag::VB | Tag::VBZ | Tag::VBP | Tag::VBD | Tag::VBG | Tag::VBN)
    }

    pub fn is_noun(self) -> bool {
        matches!(self, Tag::NN | Tag::NNS | Tag::NNP)
    }

    /// The Penn name ("PRP$" for [`Tag::PRPS`]).
    pub fn name(self) -> &'static str {
        match self {
            Tag::DT => "DT",
            Tag::CD => "CD",
            Tag::NN => "NN",
            Tag::NNS => "NNS",
            Tag::NNP => "NNP",
            Tag::PRP => "PRP",
            Tag::PRPS => "PRP$",
            Tag::VB => "VB",
            Tag::VBZ => "VBZ",
            Tag::VBP => "VBP",
            Tag::VBD => "VBD",
            Tag::VBG => "VBG",
            Tag::VBN => "VBN",
            Tag::MD => "MD",
            Tag::IN => "IN",
            Tag::TO => "TO",
            Tag::JJ => "JJ",
            Tag::RB => "RB",
            Tag::CC => "CC",
            Tag::EX => "EX",
            Tag::WDT => "WDT",
            Tag::POS => "POS",
            Tag::Punct => ".",
        }
    }
}
