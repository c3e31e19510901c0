//! A plain-text table with aligned columns, as `mbrl list` prints it.

use std::fmt;

pub struct Table {
    header: Vec<&'static str>,
    rows: Vec<Vec<String>>,
    /// Lines printed under the table.
    notes: Vec<String>,
}

impl Table {
    pub fn new(header: &[&'static str]) -> Self {
        Table { header: header.to_vec(), rows: Vec::new(), notes: Vec::new() }
    }

    pub fn row(&mut self, cells: Vec<String>) {
        debug_assert_eq!(cells.len(), self.header.len());
        self.rows.push(cells);
    }

    pub fn note(&mut self, line: impl Into<String>) {
        self.notes.push(line.into());
    }

    /// The first column: the names listed.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.rows.iter().map(|r| r[0].as_str())
    }

    pub fn rows(&self) -> &[Vec<String>] {
        &self.rows
    }
}

impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let width = |i: usize| {
            let cells = self.rows.iter().map(|r| r[i].chars().count());
            cells.chain([self.header[i].len()]).max().unwrap_or(0)
        };
        let widths: Vec<usize> = (0..self.header.len()).map(width).collect();
        let line = |f: &mut fmt::Formatter<'_>, cells: &[&str]| {
            let last = cells.len() - 1;
            let mut text = String::new();
            for (i, cell) in cells.iter().enumerate() {
                text.push_str(cell);
                if i < last {
                    text.extend(std::iter::repeat_n(' ', widths[i] - cell.chars().count() + 2));
                }
            }
            writeln!(f, "{}", text.trim_end())
        };
        line(f, &self.header)?;
        for row in &self.rows {
            line(f, &row.iter().map(String::as_str).collect::<Vec<_>>())?;
        }
        for note in &self.notes {
            writeln!(f, "{note}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_line_up_whatever_the_cell_widths() {
        let mut t = Table::new(&["NAME", "DT", "WHAT"]);
        t.row(vec!["pendulum:heavy".into(), "0.05".into(), "a".into()]);
        t.row(vec!["toy".into(), "—".into(), "b c".into()]);
        let text = t.to_string();
        let lines: Vec<&str> = text.lines().collect();
        let column =
            |line: &str, word: &str| line.chars().collect::<String>().find(word).map(|b| line[..b].chars().count());
        assert_eq!(column(lines[0], "DT"), column(lines[1], "0.05"));
        assert_eq!(column(lines[0], "DT"), column(lines[2], "—"));
        assert_eq!(column(lines[0], "WHAT"), column(lines[2], "b c"));
    }
}
