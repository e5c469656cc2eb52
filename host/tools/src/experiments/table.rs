//! A result table: printed as Markdown (so it can be pasted into `docs/RESULTS.md` as is) and
//! written as CSV (so a script can read the same numbers).

use std::fmt::Write as _;
use std::io::Write;

/// One table of an experiment's results.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// File stem of the CSV (`results` → `results.csv`).
    pub stem: &'static str,
    /// One line saying what the table shows.
    pub caption: String,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new(stem: &'static str, caption: impl Into<String>, header: &[&str]) -> Self {
        Self {
            stem,
            caption: caption.into(),
            header: header.iter().map(|h| (*h).to_owned()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row; it must have one cell per column (a programming error otherwise).
    pub fn push(&mut self, row: Vec<String>) {
        assert_eq!(
            row.len(),
            self.header.len(),
            "table `{}`: row {row:?} does not fit the header",
            self.stem
        );
        self.rows.push(row);
    }

    /// The cell in the row whose first cell is `key`, column `column`.
    pub fn cell(&self, key: &str, column: usize) -> Option<&str> {
        self.rows
            .iter()
            .find(|r| r[0] == key)
            .and_then(|r| r.get(column))
            .map(String::as_str)
    }

    /// A GitHub-flavoured Markdown table with padded columns: numbers right-aligned, text
    /// left-aligned.
    pub fn markdown(&self) -> String {
        let numeric: Vec<bool> = (0..self.header.len())
            .map(|c| self.rows.iter().all(|r| is_number(&r[c])))
            .collect();
        let widths: Vec<usize> = (0..self.header.len())
            .map(|c| {
                std::iter::once(&self.header[c])
                    .chain(self.rows.iter().map(|r| &r[c]))
                    .map(|s| s.chars().count().max(3))
                    .max()
                    .unwrap_or(3)
            })
            .collect();
        let line = |cells: &[String]| {
            let mut out = String::from("|");
            for (c, (cell, &w)) in cells.iter().zip(&widths).enumerate() {
                // Writing to a String cannot fail.
                let _ = if numeric[c] {
                    write!(out, " {cell:>w$} |")
                } else {
                    write!(out, " {cell:<w$} |")
                };
            }
            out.push('\n');
            out
        };
        let mut out = line(&self.header);
        out.push('|');
        for (c, &w) in widths.iter().enumerate() {
            let dashes = "-".repeat(w - 1);
            out.push_str(&if numeric[c] {
                format!(" {dashes}: |")
            } else {
                format!(" :{dashes} |")
            });
        }
        out.push('\n');
        for row in &self.rows {
            out.push_str(&line(row));
        }
        out
    }

    /// The header and rows as CSV.
    pub fn write_csv<W: Write>(&self, out: W) -> Result<(), csv::Error> {
        let mut w = csv::Writer::from_writer(out);
        w.write_record(&self.header)?;
        for row in &self.rows {
            w.write_record(row)?;
        }
        w.flush()?;
        Ok(())
    }
}

/// A cell that reads as a number: a value, optionally with a unit, or `-` for none.
fn is_number(cell: &str) -> bool {
    let value = cell.trim_end_matches(" %");
    value == "-" || value.parse::<f64>().is_ok()
}

/// `v` with `decimals` decimals, `-` when there is no value.
pub fn fixed(v: Option<f64>, decimals: usize) -> String {
    v.map_or_else(|| "-".to_owned(), |v| format!("{v:.decimals$}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_and_csv_hold_the_same_cells() {
        let mut t = Table::new("results", "test", &["quantity", "ours"]);
        t.push(vec!["span (deg)".into(), fixed(Some(0.123456), 4)]);
        t.push(vec!["missing".into(), fixed(None, 4)]);
        assert_eq!(
            t.markdown(),
            "| quantity   |   ours |\n| :--------- | -----: |\n| span (deg) | 0.1235 |\n| missing    |      - |\n"
        );
        let mut csv = Vec::new();
        t.write_csv(&mut csv).unwrap();
        assert_eq!(
            String::from_utf8(csv).unwrap(),
            "quantity,ours\nspan (deg),0.1235\nmissing,-\n"
        );
        assert_eq!(t.cell("span (deg)", 1), Some("0.1235"));
    }
}
