//! The two layouts of the terminal tables: labelled rows (one quantity a
//! line) and right-aligned columns (one method or point a line).

use std::path::PathBuf;

/// A table of labelled rows under a title: `  label  value`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rows {
    lines: Vec<String>,
}

impl Rows {
    /// A table that starts with `title` on its own line.
    pub fn titled(title: impl Into<String>) -> Rows {
        Rows {
            lines: vec![title.into()],
        }
    }

    /// One labelled row.
    pub fn row(&mut self, label: &str, value: impl Into<String>) -> &mut Rows {
        self.lines.push(format!("  {label:<34} {}", value.into()));
        self
    }

    /// A line as it is.
    pub fn line(&mut self, line: impl Into<String>) -> &mut Rows {
        self.lines.push(line.into());
        self
    }

    /// A `wrote` row for each file written.
    pub fn wrote(&mut self, written: &[PathBuf]) -> &mut Rows {
        for w in written {
            self.row("wrote", w.display().to_string());
        }
        self
    }

    /// The rows of another table (its title included).
    pub fn extend(&mut self, other: Rows) -> &mut Rows {
        self.lines.extend(other.lines);
        self
    }

    pub fn lines(&self) -> &[String] {
        &self.lines
    }

    pub fn into_lines(self) -> Vec<String> {
        self.lines
    }
}

/// Columns right-aligned to their widest cell, two spaces apart; the last
/// column is left as it is (it holds free text: the verdict's reasons).
#[derive(Debug, Clone, PartialEq)]
pub struct Columns {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Columns {
    pub fn new(header: &[&str], rows: Vec<Vec<String>>) -> Columns {
        Columns {
            header: header.iter().map(|h| h.to_string()).collect(),
            rows,
        }
    }

    /// The header line and a line per row, each indented by two spaces.
    pub fn lines(&self) -> Vec<String> {
        let n = self.header.len();
        let widths: Vec<usize> = (0..n.saturating_sub(1))
            .map(|j| {
                self.rows
                    .iter()
                    .filter_map(|r| r.get(j).map(String::len))
                    .chain([self.header[j].len()])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        std::iter::once(&self.header)
            .chain(&self.rows)
            .map(|cells| {
                let parts: Vec<String> = cells
                    .iter()
                    .enumerate()
                    .map(|(j, c)| match widths.get(j) {
                        Some(w) => format!("{c:>w$}"),
                        None => c.to_string(),
                    })
                    .collect();
                format!("  {}", parts.join("  "))
            })
            .collect()
    }
}

/// A number that may be absent, to `digits` decimals, else `-`.
pub fn maybe(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "-".into(), |v| format!("{v:.digits$}"))
}

/// The name serde gives a unit enum value (`criticality`), for display only.
pub fn shown<T: serde::Serialize>(v: &T) -> String {
    match serde_json::to_value(v) {
        Ok(serde_json::Value::String(s)) => s,
        other => format!("{other:?}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_align_right_but_leave_the_last_one_free() {
        let c = Columns::new(
            &["a", "bb", "verdict"],
            vec![
                vec!["xyz".into(), "1".into(), "ok".into()],
                vec!["w".into(), "2345".into(), "FLAGGED: why".into()],
            ],
        );
        assert_eq!(
            c.lines(),
            [
                "    a    bb  verdict",
                "  xyz     1  ok",
                "    w  2345  FLAGGED: why"
            ]
        );
    }

    #[test]
    fn rows_pad_the_label_to_one_column() {
        let mut r = Rows::titled("t");
        r.row("flip", "1 deg");
        assert_eq!(r.lines()[1], format!("  flip{} 1 deg", " ".repeat(30)));
    }
}
