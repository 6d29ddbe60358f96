//! A zero-allocation whitespace tokenizer that tracks 1-based line numbers, shared by the BVH and
//! ASF/AMC readers. Accepts LF, CRLF and mixtures (a `\r` is just whitespace).

/// One whitespace-separated word and the line it starts on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Token<'a> {
    pub text: &'a str,
    pub line: usize,
}

#[derive(Clone)]
pub(crate) struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    line: usize,
}

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

impl<'a> Lexer<'a> {
    pub fn new(text: &'a str) -> Lexer<'a> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        Lexer { text, pos: 0, line: 1 }
    }

    /// Line of the next unread character.
    pub fn line(&self) -> usize {
        self.line
    }

    fn skip_space(&mut self) {
        let bytes = self.text.as_bytes();
        while self.pos < bytes.len() && is_space(bytes[self.pos]) {
            if bytes[self.pos] == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
    }

    /// The next word, or `None` at the end of the text.
    pub fn next_token(&mut self) -> Option<Token<'a>> {
        self.skip_space();
        let bytes = self.text.as_bytes();
        if self.pos >= bytes.len() {
            return None;
        }
        let start = self.pos;
        while self.pos < bytes.len() && !is_space(bytes[self.pos]) {
            self.pos += 1;
        }
        Some(Token { text: &self.text[start..self.pos], line: self.line })
    }

    /// The rest of the current line (trimmed), consuming it but not the newline.
    pub fn rest_of_line(&mut self) -> &'a str {
        let bytes = self.text.as_bytes();
        let start = self.pos;
        while self.pos < bytes.len() && bytes[self.pos] != b'\n' {
            self.pos += 1;
        }
        self.text[start..self.pos].trim()
    }

    /// Splits off the remaining text as lines: `(line number, line without its end-of-line)`.
    pub fn remaining_lines(self) -> impl Iterator<Item = (usize, &'a str)> {
        let first = self.line;
        let rest = &self.text[self.pos..];
        rest.split('\n').enumerate().map(move |(i, l)| (first + i, l.strip_suffix('\r').unwrap_or(l)))
    }
}

/// How a token appears in an error message: quoted and cut to a readable length.
pub(crate) fn describe(token: Option<Token<'_>>) -> String {
    match token {
        None => "end of file".into(),
        Some(t) => quote(t.text),
    }
}

pub(crate) fn quote(text: &str) -> String {
    const MAX: usize = 40;
    if text.chars().count() <= MAX {
        format!("'{text}'")
    } else {
        let cut: String = text.chars().take(MAX).collect();
        format!("'{cut}…'")
    }
}

/// Parses a finite decimal number (`nan`/`inf` are rejected: motion data must be finite).
pub(crate) fn parse_finite(text: &str) -> Option<f64> {
    text.parse::<f64>().ok().filter(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_lines_across_crlf_lf_and_tabs() {
        let mut lx = Lexer::new("a\r\n\tb  c\n\r\nd");
        let toks: Vec<(&str, usize)> = std::iter::from_fn(|| lx.next_token()).map(|t| (t.text, t.line)).collect();
        assert_eq!(toks, vec![("a", 1), ("b", 2), ("c", 2), ("d", 4)]);
    }

    #[test]
    fn rejects_non_finite_numbers() {
        assert_eq!(parse_finite("1.5e2"), Some(150.0));
        assert_eq!(parse_finite(".25"), Some(0.25));
        assert_eq!(parse_finite("nan"), None);
        assert_eq!(parse_finite("inf"), None);
        assert_eq!(parse_finite("1e400"), None);
        assert_eq!(parse_finite("x"), None);
    }
}
