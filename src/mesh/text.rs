//! The line structure shared by the text formats (OBJ, MTL): bytes, not UTF-8, so
//! one Latin-1 comment does not reject a file; any line ending (LF, CR LF, CR
//! alone); a UTF-8 byte-order mark skipped; `\` at the end of a line joining the
//! next; `#` starting a comment anywhere on a line.

use std::borrow::Cow;

/// The logical lines of `bytes`: (1-based number of the first physical line, the
/// text without its comment), empty ones included.
pub fn lines(bytes: &[u8]) -> Lines<'_> {
    let rest = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    Lines { rest, next: 1 }
}

pub struct Lines<'a> {
    rest: &'a [u8],
    next: usize,
}

impl<'a> Lines<'a> {
    /// One physical line and whatever ends it.
    fn physical(&mut self) -> Option<&'a [u8]> {
        if self.rest.is_empty() {
            return None;
        }
        let end = self
            .rest
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .unwrap_or(self.rest.len());
        let line = &self.rest[..end];
        let skip = match self.rest.get(end..end + 2) {
            Some(b"\r\n") => 2,
            Some(_) => 1,
            None => usize::from(end < self.rest.len()),
        };
        self.rest = &self.rest[end + skip..];
        self.next += 1;
        Some(line)
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, Cow<'a, [u8]>);

    fn next(&mut self) -> Option<Self::Item> {
        let number = self.next;
        let mut line: Cow<'a, [u8]> = Cow::Borrowed(self.physical()?);
        // A comment ends the line, continuation marks included.
        loop {
            let body = strip_comment(&line);
            let trimmed = body.trim_ascii_end();
            let Some(joined) = trimmed.strip_suffix(b"\\") else {
                if body.len() != line.len() {
                    line = Cow::Owned(body.to_vec());
                }
                return Some((number, line));
            };
            let mut owned = joined.to_vec();
            owned.push(b' ');
            match self.physical() {
                Some(more) => owned.extend_from_slice(more),
                None => return Some((number, Cow::Owned(owned))),
            }
            line = Cow::Owned(owned);
        }
    }
}

fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// The whitespace-separated words of a line.
pub fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(u8::is_ascii_whitespace)
        .filter(|w| !w.is_empty())
}

/// A number word; `None` for anything that is not one.
pub fn number(word: &[u8]) -> Option<f64> {
    std::str::from_utf8(word).ok()?.parse().ok()
}

/// The rest of a line after its keyword, trimmed, decoded lossily (names, paths).
pub fn rest_after_keyword(line: &[u8]) -> String {
    let line = line.trim_ascii_start();
    let end = line
        .iter()
        .position(u8::is_ascii_whitespace)
        .unwrap_or(line.len());
    String::from_utf8_lossy(line[end..].trim_ascii()).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(bytes: &[u8]) -> Vec<(usize, String)> {
        lines(bytes)
            .map(|(n, l)| (n, String::from_utf8_lossy(&l).into_owned()))
            .collect()
    }

    #[test]
    fn every_line_ending_and_the_bom() {
        let want = [(1, "a".to_string()), (2, "b".into()), (3, "c".into())];
        for text in [
            &b"a\nb\nc"[..],
            b"a\r\nb\r\nc\r\n",
            b"a\rb\rc\r",
            b"\xEF\xBB\xBFa\nb\rc",
        ] {
            assert_eq!(all(text), want, "{text:?}");
        }
        assert_eq!(all(b"a\n\nb").len(), 3);
    }

    #[test]
    fn comments_and_continuations() {
        assert_eq!(
            all(b"f 1 2 \\\n3 # last\nv 1 # \\\nv 2"),
            [
                (1, "f 1 2  3 ".into()),
                (3, "v 1 ".into()),
                (4, "v 2".into())
            ]
        );
        assert_eq!(all(b"f 1 \\"), [(1, "f 1  ".into())]);
    }

    #[test]
    fn words_and_names() {
        let w: Vec<_> = words(b"  f\t1  2 ").collect();
        assert_eq!(w, [&b"f"[..], b"1", b"2"]);
        assert_eq!(
            rest_after_keyword(b"newmtl  caf\xe9 red "),
            "caf\u{fffd} red"
        );
        assert_eq!(rest_after_keyword(b"newmtl"), "");
        assert_eq!(number(b"-1.5e3"), Some(-1500.0));
        assert_eq!(number(b"1,5"), None);
    }
}
