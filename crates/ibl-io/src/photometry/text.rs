//! The text layer shared by both photometric readers: bytes to text, numbered lines, numbers with
//! the line they came from, and a cursor over whitespace-separated values whose every error names
//! its line and the field it was reading.

use std::borrow::Cow;

use crate::error::DecodeError;

/// The file as text: UTF-8 when it is valid UTF-8, otherwise ISO 8859-1 (Latin-1, one character
/// per byte), which both formats' writers commonly use for names and degree signs.
pub(crate) fn decode(bytes: &[u8]) -> Cow<'_, str> {
    match std::str::from_utf8(bytes) {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(bytes.iter().map(|&b| char::from(b)).collect()),
    }
}

/// The lines of `text` with their 1-based numbers, split at `\r\n`, `\n` or a lone `\r`.
pub(crate) fn lines(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut rest = text;
    while !rest.is_empty() {
        let end = rest.find(['\n', '\r']).unwrap_or(rest.len());
        out.push((out.len() + 1, &rest[..end]));
        let skip = if rest[end..].starts_with("\r\n") {
            2
        } else {
            usize::from(end < rest.len())
        };
        rest = &rest[end + skip..];
    }
    out
}

/// A finite number from `text` (surrounding blanks ignored), or `None`.
pub(crate) fn number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// One value of a numeric section: its text and its line.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Token<'a> {
    /// The value as written.
    pub text: &'a str,
    /// 1-based line number.
    pub line: usize,
}

/// A cursor over the values of numbered lines, split at blanks and at every character in a set of
/// separators (IES allows commas between values; EULUMDAT uses the comma as a decimal point).
pub(crate) struct Values<'a> {
    tokens: Vec<Token<'a>>,
    next: usize,
    last_line: usize,
}

impl<'a> Values<'a> {
    /// The values of `lines`, split at whitespace and at each of `separators`.
    pub fn new(lines: &[(usize, &'a str)], separators: &[char]) -> Values<'a> {
        let tokens = lines
            .iter()
            .flat_map(|&(line, text)| {
                text.split(|c: char| c.is_whitespace() || separators.contains(&c))
                    .filter(|t| !t.is_empty())
                    .map(move |text| Token { text, line })
            })
            .collect();
        Values {
            tokens,
            next: 0,
            last_line: lines.last().map_or(0, |l| l.0),
        }
    }

    /// How many values are left.
    pub fn remaining(&self) -> usize {
        self.tokens.len() - self.next
    }

    /// The values not read yet.
    pub fn rest(&self) -> &[Token<'a>] {
        &self.tokens[self.next..]
    }

    /// The next value as a finite number and its line; `what` names the field in the error;
    /// `decimal_comma` reads `0,5` as `0.5`.
    pub fn number(&mut self, what: &str, decimal_comma: bool) -> Result<(f64, usize), DecodeError> {
        let Some(token) = self.tokens.get(self.next).copied() else {
            return Err(DecodeError::invalid(format!(
                "the file ends (after line {}) before {what}",
                self.last_line
            )));
        };
        self.next += 1;
        let parsed = if decimal_comma {
            number(&token.text.replace(',', "."))
        } else {
            number(token.text)
        };
        parsed.map(|v| (v, token.line)).ok_or_else(|| {
            DecodeError::invalid(format!(
                "line {}: {what} is {:?}, not a finite number",
                token.line, token.text
            ))
        })
    }

    /// The next `n` values as angles, degrees, increasing within `0..=max`; `axis` names them.
    pub fn angles(
        &mut self,
        axis: &str,
        n: usize,
        max: f64,
        decimal_comma: bool,
    ) -> Result<Vec<f64>, DecodeError> {
        let mut out: Vec<f64> = Vec::with_capacity(n);
        for k in 0..n {
            let what = format!("{axis} angle {} of {n}", k + 1);
            let (a, line) = self.number(&what, decimal_comma)?;
            if !(0.0..=max).contains(&a) || out.last().is_some_and(|&prev| a <= prev) {
                return Err(DecodeError::invalid(format!(
                    "line {line}: {what} is {a} (angles increase within 0..={max} degrees)"
                )));
            }
            out.push(a);
        }
        Ok(out)
    }

    /// The next value as a whole number in `min..=max`; over `max` is a [`DecodeError::Limits`]
    /// error, so that no count from a file is ever allocated unchecked.
    pub fn count(&mut self, what: &str, min: usize, max: usize) -> Result<usize, DecodeError> {
        let (v, line) = self.number(what, false)?;
        whole(v, line, what, min, max)
    }
}

/// `v` (read on `line` as `what`) as a whole number in `min..=max`.
pub(crate) fn whole(
    v: f64,
    line: usize,
    what: &str,
    min: usize,
    max: usize,
) -> Result<usize, DecodeError> {
    if v.fract() != 0.0 || v < min as f64 {
        return Err(DecodeError::invalid(format!(
            "line {line}: {what} is {v}, not a whole number of at least {min}"
        )));
    }
    if v > max as f64 {
        return Err(DecodeError::Limits(format!(
            "line {line}: {what} is {v}, over the limit of {max}"
        )));
    }
    Ok(v as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_split_at_every_ending() {
        let l = lines("a\r\nb\nc\rd");
        assert_eq!(l, vec![(1, "a"), (2, "b"), (3, "c"), (4, "d")]);
        assert_eq!(lines("a\n\nb\n"), vec![(1, "a"), (2, ""), (3, "b")]);
        assert!(lines("").is_empty());
    }

    #[test]
    fn latin1_falls_back() {
        assert_eq!(decode(b"30\xb0"), "30\u{b0}");
        assert_eq!(decode("30°".as_bytes()), "30°");
    }

    #[test]
    fn values_name_their_line_and_field() {
        let l = lines("1 2,3\n4 x\n");
        let mut v = Values::new(&l, &[',']);
        assert_eq!(v.count("the lamp count", 1, 10).unwrap(), 1);
        assert_eq!(v.number("a", false).unwrap(), (2.0, 1));
        assert_eq!(v.remaining(), 3);
        v.number("b", false).unwrap();
        v.number("c", false).unwrap();
        let e = v.number("the multiplier", false).unwrap_err().to_string();
        assert!(
            e.contains("line 2") && e.contains("the multiplier") && e.contains("\"x\""),
            "{e}"
        );
        let e = v.number("the width", false).unwrap_err().to_string();
        assert!(e.contains("ends") && e.contains("the width"), "{e}");
        let mut v = Values::new(&lines("1e9 2.5 inf"), &[]);
        assert!(matches!(v.count("n", 1, 100), Err(DecodeError::Limits(_))));
        assert!(matches!(v.count("n", 1, 100), Err(DecodeError::Invalid(_))));
        assert!(matches!(v.number("n", false), Err(DecodeError::Invalid(_))));
        let mut v = Values::new(&lines("0,25"), &[]);
        assert_eq!(v.number("n", true).unwrap().0, 0.25);
        let mut v = Values::new(&lines("0 5\n5"), &[]);
        let e = v
            .angles("vertical", 3, 180.0, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2: vertical angle 3 of 3 is 5"), "{e}");
    }
}
