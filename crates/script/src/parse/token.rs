//! Tokenising a sentence into words and punctuation (§3.2, the first step before tagging).

/// One word or punctuation mark of a sentence.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Token {
    /// As written.
    pub text: String,
    /// Lower case, for look-ups.
    pub lower: String,
}

impl Token {
    fn new(text: &str) -> Token {
        Token { text: text.to_string(), lower: text.to_lowercase() }
    }

    /// Whether this is punctuation rather than a word.
    pub fn is_punct(&self) -> bool {
        !self.text.chars().any(char::is_alphanumeric)
    }
}

/// Splits text into words (letters, digits, inner `'`, `-` and `.` in numbers) and punctuation.
/// A possessive `'s` becomes its own token ("Eve's" → "Eve", "'s").
pub fn tokenize(text: &str) -> Vec<Token> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut Vec<Token>| {
        if word.is_empty() {
            return;
        }
        let lower = word.to_lowercase();
        if lower.len() > 2 && (lower.ends_with("'s") || lower.ends_with("\u{2019}s")) {
            let cut = word.len() - if word.ends_with("'s") || word.ends_with("'S") { 2 } else { "\u{2019}s".len() };
            out.push(Token::new(&word[..cut]));
            out.push(Token::new("'s"));
        } else {
            out.push(Token::new(word));
        }
        word.clear();
    };
    for (k, &c) in chars.iter().enumerate() {
        let prev_alnum = k > 0 && chars[k - 1].is_alphanumeric();
        let next_alnum = chars.get(k + 1).is_some_and(|c| c.is_alphanumeric());
        let next_digit = chars.get(k + 1).is_some_and(|c| c.is_ascii_digit());
        let inner = (c == '\'' || c == '\u{2019}' || c == '-') && prev_alnum && next_alnum;
        let decimal = c == '.' && k > 0 && chars[k - 1].is_ascii_digit() && next_digit;
        if c.is_alphanumeric() || inner || decimal {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            if !c.is_whitespace() && c != '"' && c != '\\' {
                out.push(Token::new(&c.to_string()));
            }
        }
    }
    flush(&mut word, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_punctuation() {
        let t: Vec<String> = tokenize("In the room, Eve's 2.5 m-wide desk!").into_iter().map(|t| t.text).collect();
        assert_eq!(t, ["In", "the", "room", ",", "Eve", "'s", "2.5", "m-wide", "desk", "!"]);
    }
}
