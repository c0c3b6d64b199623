//! A small, strict CSV table reader for the workflow inputs (planar point
//! pairs, per-height matrices, XY-table positions).
//!
//! Format: the first non-blank, non-comment line is the header; fields are
//! separated by commas and trimmed; lines starting with `#` and blank lines
//! are ignored; no quoting (none of our files need it). Every error names the
//! 1-based line and column.

use crate::error::{Error, Result};

/// One data row with the line it came from.
#[derive(Debug, Clone, PartialEq)]
struct Row {
    line: usize,
    fields: Vec<String>,
}

/// A parsed CSV file: header names and data rows.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvTable {
    /// Column names from the header, trimmed, in file order.
    pub header: Vec<String>,
    header_line: usize,
    rows: Vec<Row>,
}

impl CsvTable {
    /// Parse `text`. Fails on an empty file, duplicate header names or rows
    /// whose field count differs from the header's.
    pub fn parse(text: &str) -> Result<CsvTable> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let (header_line, header_text) = lines
            .next()
            .ok_or_else(|| Error::parse(0, 0, "the file is empty: expected a CSV header line"))?;
        let header: Vec<String> = split(header_text);
        for (i, name) in header.iter().enumerate() {
            if name.is_empty() {
                return Err(Error::parse(
                    header_line,
                    i + 1,
                    "empty column name in the header",
                ));
            }
            if header[..i].contains(name) {
                return Err(Error::parse(
                    header_line,
                    i + 1,
                    format!("column '{name}' appears twice in the header"),
                ));
            }
        }
        let mut rows = Vec::new();
        for (line, l) in lines {
            let fields = split(l);
            if fields.len() != header.len() {
                return Err(Error::parse(
                    line,
                    0,
                    format!(
                        "expected {} comma-separated fields like the header, got {}",
                        header.len(),
                        fields.len()
                    ),
                ));
            }
            rows.push(Row { line, fields });
        }
        Ok(CsvTable {
            header,
            header_line,
            rows,
        })
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there are no data rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Index of column `name`, if present.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// Indices of all `names`; the error lists the missing ones and the header.
    pub fn require_columns(&self, names: &[&str]) -> Result<Vec<usize>> {
        let missing: Vec<&str> = names
            .iter()
            .copied()
            .filter(|n| self.column(n).is_none())
            .collect();
        if !missing.is_empty() {
            return Err(Error::parse(
                self.header_line,
                0,
                format!(
                    "missing column(s) {} (expected header {}, got {})",
                    missing.join(", "),
                    names.join(","),
                    self.header.join(",")
                ),
            ));
        }
        Ok(names.iter().filter_map(|n| self.column(n)).collect())
    }

    /// The 1-based file line of data row `row`.
    pub fn line_of(&self, row: usize) -> usize {
        self.rows.get(row).map_or(0, |r| r.line)
    }

    /// The trimmed text of row `row`, column `col` (empty when out of range).
    pub fn text(&self, row: usize, col: usize) -> &str {
        self.rows
            .get(row)
            .and_then(|r| r.fields.get(col))
            .map_or("", |s| s.as_str())
    }

    /// Row `row`, column `col` as a finite number.
    pub fn number(&self, row: usize, col: usize) -> Result<f64> {
        let text = self.text(row, col);
        let name = self.header.get(col).map_or("?", |s| s.as_str());
        match text.parse::<f64>().ok() {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(Error::parse(
                self.line_of(row),
                col + 1,
                format!("{name}: expected a finite number, got '{text}'"),
            )),
        }
    }

    /// The numbers of `cols` for every row, in row order.
    pub fn numbers(&self, cols: &[usize]) -> Result<Vec<Vec<f64>>> {
        (0..self.len())
            .map(|r| cols.iter().map(|&c| self.number(r, c)).collect())
            .collect()
    }
}

fn split(line: &str) -> Vec<String> {
    line.split(',').map(|f| f.trim().to_string()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn parses_numbers_and_skips_comments() {
        let t = CsvTable::parse("# comment\nh, a ,b\n\n1,2.5,-3e2\n4,5,6\n").unwrap();
        assert_eq!(t.header, vec!["h", "a", "b"]);
        assert_eq!(t.len(), 2);
        let cols = t.require_columns(&["b", "h"]).unwrap();
        assert_eq!(
            t.numbers(&cols).unwrap(),
            vec![vec![-300.0, 1.0], vec![6.0, 4.0]]
        );
        assert_eq!(t.line_of(1), 5);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn errors_name_line_and_column() {
        let t = CsvTable::parse("x,y\n1,2\n3,abc\n").unwrap();
        assert_eq!(
            t.number(1, 1).unwrap_err().to_string(),
            "line 3, column 2: y: expected a finite number, got 'abc'"
        );
        assert_eq!(
            CsvTable::parse("x,y\n1,2,3\n").unwrap_err().to_string(),
            "line 2: expected 2 comma-separated fields like the header, got 3"
        );
        assert_eq!(
            t.require_columns(&["x", "z"]).unwrap_err().to_string(),
            "line 1: missing column(s) z (expected header x,z, got x,y)"
        );
        assert_eq!(
            CsvTable::parse("\n# only\n").unwrap_err().to_string(),
            "the file is empty: expected a CSV header line"
        );
        assert_eq!(
            CsvTable::parse("a,a\n").unwrap_err().to_string(),
            "line 1, column 2: column 'a' appears twice in the header"
        );
    }
}
