//! A caption's simple emphasis, read once for the app's band and the handout's HTML: `*words*`
//! (or `**words**`) emphasised and `` `words` `` as code, as Markdown writes them; everything else
//! is plain text. A marker with no partner is plain text too (`2 * 3 = 6` stays as typed).

/// A run of a caption's text and how it is shown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Span {
    Plain(String),
    Emphasis(String),
    Code(String),
}

/// `text` cut into runs. Code is literal (no emphasis inside it); an emphasis needs a partner
/// marker on the same line and may not start or end with a space (`a * b * c` is plain).
pub fn spans(text: &str) -> Vec<Span> {
    let mut out: Vec<Span> = Vec::new();
    let mut plain = String::new();
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        let taken = match c {
            '`' => closed(rest, "`").map(|(inner, len)| (Span::Code(inner.to_string()), len)),
            '*' => {
                let marker = if rest.starts_with("**") { "**" } else { "*" };
                closed(rest, marker)
                    .filter(|(inner, _)| !inner.starts_with(' ') && !inner.ends_with(' '))
                    .map(|(inner, len)| (Span::Emphasis(inner.to_string()), len))
            }
            _ => None,
        };
        match taken {
            Some((span, len)) => {
                if !plain.is_empty() {
                    out.push(Span::Plain(std::mem::take(&mut plain)));
                }
                out.push(span);
                rest = &rest[len..];
            }
            None => {
                plain.push(c);
                rest = &rest[c.len_utf8()..];
            }
        }
    }
    if !plain.is_empty() {
        out.push(Span::Plain(plain));
    }
    out
}

/// When `s` starts with `marker`, the text up to the same marker on the same line (not empty)
/// and the length of the whole run, markers included.
fn closed<'a>(s: &'a str, marker: &str) -> Option<(&'a str, usize)> {
    let body = &s[marker.len()..];
    let end = body.find(marker)?;
    let inner = &body[..end];
    (!inner.is_empty() && !inner.contains('\n')).then_some((inner, marker.len() * 2 + inner.len()))
}

#[cfg(test)]
mod tests {
    use super::{spans, Span::*};

    #[test]
    fn emphasis_and_code_as_markdown_writes_them_and_stray_markers_as_typed() {
        let s = |t: &str| t.to_string();
        assert_eq!(
            spans("cut at the *centroids*, with `midpoint` and **SAH**"),
            [
                Plain(s("cut at the ")),
                Emphasis(s("centroids")),
                Plain(s(", with ")),
                Code(s("midpoint")),
                Plain(s(" and ")),
                Emphasis(s("SAH"))
            ]
        );
        assert_eq!(spans("2 * 3 * 4 = 24"), [Plain(s("2 * 3 * 4 = 24"))]);
        assert_eq!(spans("`a*b*c` and *x*"), [Code(s("a*b*c")), Plain(s(" and ")), Emphasis(s("x"))]);
        assert_eq!(spans("an open ` and *a\nb*"), [Plain(s("an open ` and *a\nb*"))]);
        assert_eq!(spans("n·0.5 + 0.5 ×"), [Plain(s("n·0.5 + 0.5 ×"))]);
        assert_eq!(spans(""), []);
    }
}
