//! The glossary (docs/glossary.md) on the report page, so that a reader of
//! the table has the words' meanings beside it without the repository.

use super::esc;

const GLOSSARY: &str = include_str!("../../docs/glossary.md");

/// The glossary's table as a folded section of the page.
pub fn section() -> String {
    let mut h = String::from(
        "<details class=\"terms\"><summary>What the words in this report mean</summary>\n<table>\n",
    );
    for (word, meaning) in entries() {
        h.push_str(&format!(
            "<tr><td>{}</td><td>{}</td></tr>\n",
            inline(&word),
            inline(&meaning)
        ));
    }
    h.push_str("</table>\n<p>The definitions, and the facts the designs rest on, are in catflip's <code>docs/model.md</code>.</p></details>\n");
    h
}

/// The table's rows as (word, meaning), in the markdown's text.
fn entries() -> Vec<(String, String)> {
    GLOSSARY
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| word ") && !l.starts_with("| ---"))
        .filter_map(|l| {
            // cells split at `|` that is not escaped as `\|`
            let cells: Vec<String> = l
                .replace("\\|", "\u{0}")
                .split('|')
                .map(|c| c.trim().replace('\u{0}', "|"))
                .collect();
            Some((cells.get(1)?.clone(), cells.get(2)?.clone()))
        })
        .collect()
}

/// One cell's markdown as HTML: code spans, and links as their text.
fn inline(md: &str) -> String {
    let mut out = String::new();
    for (i, part) in md.split('`').enumerate() {
        if i % 2 == 1 {
            out.push_str(&format!("<code>{}</code>", esc(part)));
        } else {
            out.push_str(&esc(&link_texts(part)));
        }
    }
    out
}

/// `[text](target)` as `text`; a link to another of catflip's documents
/// as `catflip's docs/text`, which the page's reader can find.
fn link_texts(s: &str) -> String {
    let mut out = String::new();
    let mut rest = s;
    while let Some(open) = rest.find('[') {
        let Some(close) = rest[open..].find("](").map(|c| open + c) else {
            break;
        };
        let Some(end) = rest[close..].find(')').map(|e| close + e) else {
            break;
        };
        out.push_str(&rest[..open]);
        let (text, target) = (&rest[open + 1..close], &rest[close + 2..end]);
        if target.split('#').next().is_some_and(|f| f.ends_with(".md")) {
            out.push_str("catflip's docs/");
        }
        out.push_str(text);
        rest = &rest[end + 1..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every row of the glossary, escaped pipes inside a cell kept, code
    /// spans and links rendered, nothing of the markdown left.
    #[test]
    fn the_section_holds_every_word_of_the_glossary() {
        let rows = entries();
        let table_rows = GLOSSARY.lines().filter(|l| l.starts_with("| ")).count();
        assert_eq!(rows.len(), table_rows - 2, "{rows:?}");
        let bend = rows.iter().find(|(w, _)| w == "bend").unwrap();
        assert!(bend.1.starts_with("`|q|`, how far"), "{}", bend.1);
        let h = section();
        for (word, _) in &rows {
            assert!(h.contains(&inline(word)), "{word}");
        }
        assert!(h.contains("<code>|q|</code>, how far"));
        assert!(!h.contains("\\|") && !h.contains("]("), "{h}");
        assert!(
            h.contains(
                "<code>min_envelope_margin</code> in the JSON; catflip's docs/configuration.md)"
            ),
            "{h}"
        );
    }

    #[test]
    fn links_read_as_their_text() {
        assert_eq!(
            link_texts("see [model.md](model.md#f4) and [a](https://b#c)."),
            "see catflip's docs/model.md and a."
        );
        assert_eq!(link_texts("no [link here"), "no [link here");
    }
}
