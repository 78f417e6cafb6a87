//! The pbrt tokenizer: words (directives, `true`/`false`), quoted strings, numbers,
//! brackets and `#` comments. Every token carries the `file:line:column` of its first
//! character (1-based; columns count Unicode characters, a tab counts as one).

use std::sync::Arc;

use super::error::{FileLoc, SceneError};

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub enum TokenKind {
    /// A bare word: a directive name, or `true` / `false`.
    Word(String),
    /// A quoted string with its escapes resolved.
    Str(String),
    /// A number. `integer` is set when it was written as an integer literal
    /// (optional sign and decimal digits only).
    Num {
        value: f64,
        integer: Option<i64>,
    },
    Open,
    Close,
}

impl TokenKind {
    /// A short description for error messages.
    pub fn describe(&self) -> String {
        match self {
            TokenKind::Word(w) => format!("'{}'", excerpt(w)),
            TokenKind::Str(s) => format!("string \"{}\"", excerpt(s)),
            TokenKind::Num { value, .. } => format!("number {value}"),
            TokenKind::Open => "'['".into(),
            TokenKind::Close => "']'".into(),
        }
    }
}

/// One token and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    pub kind: TokenKind,
    pub loc: FileLoc,
}

/// Splits one file's text into tokens, on demand.
#[derive(Debug)]
pub struct Lexer {
    text: String,
    file: Arc<str>,
    pos: usize,
    line: u32,
    column: u32,
}

/// The longest token (word, number or string) read, in bytes: file names and names of
/// things are far shorter; a longer one is a broken file (a missing quote, binary data).
pub const MAX_TOKEN_BYTES: usize = 64 * 1024;

/// At most the first 80 characters of `text` for a message, with the length when cut.
pub fn excerpt(text: &str) -> String {
    const SHOWN: usize = 80;
    if text.chars().count() <= SHOWN {
        return text.to_string();
    }
    let head: String = text.chars().take(SHOWN - 1).collect();
    format!("{head}… ({} bytes)", text.len())
}

fn ends_word(b: u8) -> bool {
    b.is_ascii_whitespace() || matches!(b, b'"' | b'[' | b']' | b'#')
}

/// Words that parse as numbers although they do not start like one: pbrt files written
/// by other programs occasionally contain `nan` or `inf`, and those must reach the
/// validation that reports them with a location rather than fail as "unknown directive".
fn is_special_number(word: &str) -> bool {
    ["nan", "inf", "infinity"]
        .iter()
        .any(|w| word.eq_ignore_ascii_case(w))
}

impl Lexer {
    /// A lexer over `text`, naming `file` in every location.
    pub fn new(text: String, file: impl Into<Arc<str>>) -> Lexer {
        Lexer {
            text,
            file: file.into(),
            pos: 0,
            line: 1,
            column: 1,
        }
    }

    /// The file name used in locations.
    pub fn file(&self) -> &Arc<str> {
        &self.file
    }

    fn loc(&self) -> FileLoc {
        FileLoc {
            file: self.file.clone(),
            line: self.line,
            column: self.column,
        }
    }

    fn peek_byte(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    /// Advances over one byte, keeping line and column (continuation bytes of a UTF-8
    /// sequence do not start a new column).
    fn bump(&mut self) -> Option<u8> {
        let b = self.peek_byte()?;
        self.pos += 1;
        if b == b'\n' {
            self.line += 1;
            self.column = 1;
        } else if b & 0xC0 != 0x80 {
            self.column += 1;
        }
        Some(b)
    }

    fn skip_space_and_comments(&mut self) {
        while let Some(b) = self.peek_byte() {
            if b.is_ascii_whitespace() {
                self.bump();
            } else if b == b'#' {
                while let Some(c) = self.peek_byte() {
                    if c == b'\n' {
                        break;
                    }
                    self.bump();
                }
            } else {
                break;
            }
        }
    }

    /// The next token, `None` at the end of the file.
    pub fn next_token(&mut self) -> Result<Option<Token>, SceneError> {
        self.skip_space_and_comments();
        let loc = self.loc();
        let Some(b) = self.peek_byte() else {
            return Ok(None);
        };
        let kind = match b {
            b'[' => {
                self.bump();
                TokenKind::Open
            }
            b']' => {
                self.bump();
                TokenKind::Close
            }
            b'"' => TokenKind::Str(self.string(&loc)?),
            _ => {
                let start = self.pos;
                while self.peek_byte().is_some_and(|c| !ends_word(c)) {
                    self.bump();
                }
                let word = &self.text[start..self.pos];
                check_length(word, &loc)?;
                number_or_word(word, &loc)?
            }
        };
        Ok(Some(Token { kind, loc }))
    }

    /// A quoted string starting at the opening quote at `open`.
    fn string(&mut self, open: &FileLoc) -> Result<String, SceneError> {
        self.bump();
        let mut out = String::new();
        loop {
            let start = self.pos;
            while self
                .peek_byte()
                .is_some_and(|c| !matches!(c, b'"' | b'\\' | b'\n'))
            {
                self.bump();
            }
            out.push_str(&self.text[start..self.pos]);
            check_length(&out, open)?;
            match self.peek_byte() {
                Some(b'"') => {
                    self.bump();
                    return Ok(out);
                }
                Some(b'\\') => {
                    let esc_loc = self.loc();
                    self.bump();
                    let c = match self.bump() {
                        Some(b'n') => '\n',
                        Some(b't') => '\t',
                        Some(b'r') => '\r',
                        Some(b'b') => '\u{8}',
                        Some(b'f') => '\u{c}',
                        Some(b'\\') => '\\',
                        Some(b'\'') => '\'',
                        Some(b'"') => '"',
                        // A newline or the end of the file: the string never closes.
                        None | Some(b'\n') => {
                            return Err(SceneError::at(open, "unterminated string"));
                        }
                        Some(_) => {
                            return Err(SceneError::at(
                                &esc_loc,
                                "unknown escape sequence in string",
                            ));
                        }
                    };
                    out.push(c);
                }
                // A string may not span lines (pbrt's rule): an unclosed quote is
                // reported where it opened, not at the end of the file.
                _ => return Err(SceneError::at(open, "unterminated string")),
            }
        }
    }
}

fn check_length(token: &str, loc: &FileLoc) -> Result<(), SceneError> {
    if token.len() > MAX_TOKEN_BYTES {
        return Err(SceneError::at(
            loc,
            format!(
                "token longer than {} KiB: '{}'",
                MAX_TOKEN_BYTES / 1024,
                excerpt(token)
            ),
        ));
    }
    Ok(())
}

fn number_or_word(word: &str, loc: &FileLoc) -> Result<TokenKind, SceneError> {
    let first = word.as_bytes()[0];
    let numeric = first.is_ascii_digit() || matches!(first, b'+' | b'-' | b'.');
    if !numeric && !is_special_number(word) {
        return Ok(TokenKind::Word(word.to_string()));
    }
    let value: f64 = word
        .parse()
        .map_err(|_| SceneError::at(loc, format!("bad number '{}'", excerpt(word))))?;
    let digits = word.strip_prefix(['+', '-']).unwrap_or(word);
    let integer = if !digits.is_empty() && digits.bytes().all(|c| c.is_ascii_digit()) {
        Some(word.parse::<i64>().map_err(|_| {
            SceneError::at(loc, format!("integer '{}' is too large", excerpt(word)))
        })?)
    } else {
        None
    };
    Ok(TokenKind::Num { value, integer })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lex(text: &str) -> Result<Vec<Token>, SceneError> {
        let mut lx = Lexer::new(text.to_string(), "t.pbrt");
        let mut out = Vec::new();
        while let Some(t) = lx.next_token()? {
            out.push(t);
        }
        Ok(out)
    }

    #[test]
    fn tokens_carry_line_and_column() {
        let toks = lex("Shape \"sphere\" # comment\n  \"float radius\" [ 2.5 ]\n").unwrap();
        let got: Vec<(TokenKind, u32, u32)> = toks
            .into_iter()
            .map(|t| (t.kind, t.loc.line, t.loc.column))
            .collect();
        assert_eq!(
            got,
            vec![
                (TokenKind::Word("Shape".into()), 1, 1),
                (TokenKind::Str("sphere".into()), 1, 7),
                (TokenKind::Str("float radius".into()), 2, 3),
                (TokenKind::Open, 2, 18),
                (
                    TokenKind::Num {
                        value: 2.5,
                        integer: None
                    },
                    2,
                    20
                ),
                (TokenKind::Close, 2, 24),
            ]
        );
    }

    #[test]
    fn numbers_integers_and_specials() {
        let toks = lex("-3 +7 1e3 .5 nan -inf").unwrap();
        let ints: Vec<Option<i64>> = toks
            .iter()
            .map(|t| match t.kind {
                TokenKind::Num { integer, .. } => integer,
                _ => panic!("not a number"),
            })
            .collect();
        assert_eq!(ints, vec![Some(-3), Some(7), None, None, None, None]);
        assert!(matches!(toks[4].kind, TokenKind::Num { value, .. } if value.is_nan()));
    }

    #[test]
    fn escapes_and_errors() {
        let toks = lex(r#""a\"b\\c\n""#).unwrap();
        assert_eq!(toks[0].kind, TokenKind::Str("a\"b\\c\n".into()));
        let e = lex("Film \"rgb\n\"x\"").unwrap_err().to_string();
        assert!(
            e.starts_with("t.pbrt:1:6: error: unterminated string"),
            "{e}"
        );
        let e = lex("\n  1.2.3").unwrap_err().to_string();
        assert!(e.starts_with("t.pbrt:2:3: error: bad number"), "{e}");
        let e = lex("\"é\" \"abc").unwrap_err().to_string();
        assert!(e.starts_with("t.pbrt:1:5:"), "{e}");
    }
}
