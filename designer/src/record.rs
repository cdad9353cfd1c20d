//! Recorded signals in the measured-data CSV format
//! (`shared/spec/measured-data.md`): one header row naming the columns, `#`
//! comment lines anywhere, comma-separated numbers, column order free. Read
//! as oscilloscope and DAQ software writes it: a UTF-8 byte-order mark,
//! quoted names or cells, CRLF line ends; a file separated by semicolons (or
//! tabs) throughout is read as such, and a decimal comma is named as such.
//!
//! Errors name the file, the line (1-based, as an editor shows it) and the
//! column, and say what was expected.

use std::path::Path;

/// A table of named numeric columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    pub columns: Vec<String>,
    /// rows[k][j] is the value of column j in data row k.
    pub rows: Vec<Vec<f64>>,
    /// Source line of each data row (for error messages).
    pub lines: Vec<usize>,
    pub file_name: String,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RecordError {
    #[error("{file}: cannot read: {message}")]
    Io { file: String, message: String },
    #[error("{file}: no header row (expected a line of column names such as `t,v,i`)")]
    NoHeader { file: String },
    #[error("{file}:{line}: duplicate column `{column}` in the header")]
    DuplicateColumn {
        file: String,
        line: usize,
        column: String,
    },
    #[error("{file}: missing column `{column}` (the header has: {present})")]
    MissingColumn {
        file: String,
        column: String,
        present: String,
    },
    #[error("{file}:{line}: expected {expected} values (one per header column), found {found}")]
    RowLength {
        file: String,
        line: usize,
        expected: usize,
        found: usize,
    },
    #[error("{file}:{line}: column `{column}`: expected a finite number, found `{found}`")]
    NotANumber {
        file: String,
        line: usize,
        column: String,
        found: String,
    },
    #[error("{file}:{line}: column `t`: time must increase strictly, but {t} follows {previous}")]
    NotIncreasing {
        file: String,
        line: usize,
        t: f64,
        previous: f64,
    },
    #[error("{file}:{line}: column `t`: sampling is not uniform within 1 % (step {step:e} s, median {median:e} s)")]
    NotUniform {
        file: String,
        line: usize,
        step: f64,
        median: f64,
    },
    #[error("{file}: at least {needed} data rows are needed, found {found}")]
    TooShort {
        file: String,
        needed: usize,
        found: usize,
    },
}

impl Record {
    pub fn read(path: &Path) -> Result<Record, RecordError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| RecordError::Io {
            file: file.clone(),
            message: e.to_string(),
        })?;
        Record::parse(&text, &file)
    }

    pub fn parse(text: &str, file: &str) -> Result<Record, RecordError> {
        let err_file = || file.to_owned();
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let delimiter = delimiter(text);
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(delimiter)
            .comment(Some(b'#'))
            .trim(csv::Trim::All)
            .has_headers(false)
            .flexible(true)
            .from_reader(text.as_bytes());
        // one record per line (numbers never hold a newline): the k-th
        // record is the k-th line that is neither blank nor a comment
        let mut numbers = content_lines(text);
        let mut lines = reader.records().filter_map(|r| match r {
            Ok(r) if r.iter().all(str::is_empty) => None,
            Ok(r) => Some(Ok((numbers.next().unwrap_or(0), r))),
            Err(e) => Some(Err(RecordError::Io {
                file: err_file(),
                message: e.to_string(),
            })),
        });
        let (header_line, header) = lines
            .next()
            .ok_or(RecordError::NoHeader { file: err_file() })??;
        let columns: Vec<String> = header.iter().map(str::to_owned).collect();
        for (k, c) in columns.iter().enumerate() {
            if columns[..k].contains(c) {
                return Err(RecordError::DuplicateColumn {
                    file: err_file(),
                    line: header_line,
                    column: c.clone(),
                });
            }
        }
        let mut rows = Vec::new();
        let mut row_lines = Vec::new();
        for entry in lines {
            let (line, cells) = entry?;
            if cells.len() != columns.len() {
                return Err(RecordError::RowLength {
                    file: err_file(),
                    line,
                    expected: columns.len(),
                    found: cells.len(),
                });
            }
            let row = cells
                .iter()
                .zip(&columns)
                .map(|(cell, column)| {
                    number(cell, delimiter).map_err(|found| RecordError::NotANumber {
                        file: err_file(),
                        line,
                        column: column.clone(),
                        found,
                    })
                })
                .collect::<Result<Vec<f64>, _>>()?;
            rows.push(row);
            row_lines.push(line);
        }
        Ok(Record {
            columns,
            rows,
            lines: row_lines,
            file_name: file.to_owned(),
        })
    }

    /// Index of a column, or a clear error naming what is there.
    pub fn column_index(&self, name: &str) -> Result<usize, RecordError> {
        self.columns
            .iter()
            .position(|c| c == name)
            .ok_or_else(|| RecordError::MissingColumn {
                file: self.file_name.clone(),
                column: name.to_owned(),
                present: self.columns.join(", "),
            })
    }

    pub fn column(&self, name: &str) -> Result<Vec<f64>, RecordError> {
        let j = self.column_index(name)?;
        Ok(self.rows.iter().map(|r| r[j]).collect())
    }

    /// The time column, checked to increase strictly, with ≥ `min_rows` rows.
    pub fn time(&self, min_rows: usize) -> Result<Vec<f64>, RecordError> {
        let t = self.column("t")?;
        if t.len() < min_rows {
            return Err(RecordError::TooShort {
                file: self.file_name.clone(),
                needed: min_rows,
                found: t.len(),
            });
        }
        for k in 1..t.len() {
            if t[k] <= t[k - 1] {
                return Err(RecordError::NotIncreasing {
                    file: self.file_name.clone(),
                    line: self.lines[k],
                    t: t[k],
                    previous: t[k - 1],
                });
            }
        }
        Ok(t)
    }

    /// Checks that the sampling is uniform within 1 % (measured data).
    pub fn check_uniform(&self, t: &[f64]) -> Result<f64, RecordError> {
        let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_by(f64::total_cmp);
        let median = steps.get(steps.len() / 2).copied().unwrap_or(0.0);
        for k in 1..t.len() {
            let step = t[k] - t[k - 1];
            if (step - median).abs() > 0.01 * median {
                return Err(RecordError::NotUniform {
                    file: self.file_name.clone(),
                    line: self.lines[k],
                    step,
                    median,
                });
            }
        }
        Ok(median)
    }
}

/// The 1-based numbers (as an editor counts) of the lines that hold records.
fn content_lines(text: &str) -> impl Iterator<Item = usize> + '_ {
    text.lines()
        .enumerate()
        .filter(|(_, l)| {
            let l = l.trim();
            !l.is_empty()
                && !l.starts_with('#')
                && !l.split([',', ';', '\t']).all(|c| c.trim().is_empty())
        })
        .map(|(k, _)| k + 1)
}

/// The separator of the header row: a comma where it has one, else a
/// semicolon or a tab where it has one (European and DAQ exports), else a
/// comma (a single column).
fn delimiter(text: &str) -> u8 {
    let header = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
        .unwrap_or("");
    [b',', b';', b'\t']
        .into_iter()
        .find(|&d| header.as_bytes().contains(&d))
        .unwrap_or(b',')
}

/// A finite number, or what was found instead (naming a decimal comma).
fn number(cell: &str, delimiter: u8) -> Result<f64, String> {
    match cell.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ if delimiter != b','
            && cell.contains(',')
            && cell.replace(',', ".").parse::<f64>().is_ok() =>
        {
            Err(format!(
                "{cell}` (a decimal comma: export with a decimal point"
            ))
        }
        _ => Err(cell.to_owned()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_comments_free_column_order_and_extra_columns() {
        let r = Record::parse(
            "# bench export\nv, t ,i\n1,0,0.5\n# mid comment\n2,1e-3,0.25\n",
            "a.csv",
        )
        .unwrap();
        assert_eq!(r.column("t").unwrap(), vec![0.0, 1e-3]);
        assert_eq!(r.column("v").unwrap(), vec![1.0, 2.0]);
        assert_eq!(r.lines, vec![3, 5]);
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = Record::parse("t,v\n0,1\n1e-3,abc\n", "in.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("in.csv:3") && e.contains("`v`") && e.contains("abc"),
            "{e}"
        );
        let e = Record::parse("t,v\n0,1\n0,2\n", "in.csv")
            .unwrap()
            .time(2)
            .unwrap_err()
            .to_string();
        assert!(e.contains("in.csv:3") && e.contains("increase"), "{e}");
        let e = Record::parse("t,x\n0,1\n", "in.csv")
            .unwrap()
            .column("v")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("missing column `v`") && e.contains("t, x"),
            "{e}"
        );
        let e = Record::parse("t,v\n0,nan\n", "in.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("finite"), "{e}");
        let e = Record::parse("t,v\n0,1,2\n", "in.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected 2 values"), "{e}");
        let r = Record::parse("t,v\n0,0\n1,0\n2,0\n3.5,0\n", "in.csv").unwrap();
        let t = r.time(2).unwrap();
        assert!(r
            .check_uniform(&t)
            .unwrap_err()
            .to_string()
            .contains("in.csv:5"));
    }

    /// Issue 12 §4: the forms DAQ and oscilloscope software write.
    #[test]
    fn reads_records_as_daq_software_writes_them() {
        let plain = Record::parse("t,v,i\n0,1,0.5\n1e-3,2,0.25\n", "p.csv").unwrap();
        let forms = [
            ("byte-order mark", "\u{feff}t,v,i\n0,1,0.5\n1e-3,2,0.25\n"),
            ("quoted header", "\"t\",\"v\",\"i\"\n0,1,0.5\n1e-3,2,0.25\n"),
            (
                "quoted cells",
                "\"t\",\"v\",\"i\"\n\"0\",\"1\",\"0.5\"\n\"1e-3\",\"2\",\"0.25\"\n",
            ),
            ("CRLF", "t,v,i\r\n0,1,0.5\r\n1e-3,2,0.25\r\n"),
            (
                "BOM, quotes and CRLF",
                "\u{feff}\"t\",\"v\",\"i\"\r\n0,1,0.5\r\n1e-3,2,0.25\r\n",
            ),
            ("semicolons", "t;v;i\n0;1;0.5\n1e-3;2;0.25\n"),
            ("tabs", "t\tv\ti\n0\t1\t0.5\n1e-3\t2\t0.25\n"),
        ];
        for (what, text) in forms {
            let r = Record::parse(text, "daq.csv").unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_eq!(r.columns, plain.columns, "{what}");
            assert_eq!(r.rows, plain.rows, "{what}");
            assert_eq!(r.lines, vec![2, 3], "{what}");
        }
        let e = Record::parse("t;v;i\n0;1,5;0,5\n", "eu.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("eu.csv:2") && e.contains("decimal comma"), "{e}");
    }
}
