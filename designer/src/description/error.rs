//! [`DescriptionError`]: why a description was rejected, and where.
//!
//! One line of `Display` says everything a terminal or a test needs:
//!
//! ```text
//! valve.toml:12:1: mechanics.mass: expected a number > 0 [kg], found -1
//! ```
//!
//! As a [`miette::Diagnostic`] it also carries the whole file (a
//! [`NamedSource`]) and a labelled span, so a graphical report shows the
//! offending line with a caret under the key and its value.

use std::fmt;
use std::ops::Range;

use miette::{Diagnostic, LabeledSpan, NamedSource, SourceCode, SourceSpan};

/// A rejected actuator description: file, key, 1-based line/column, and
/// what was expected.
#[derive(Debug, thiserror::Error)]
#[error("{}", self.summary())]
pub struct DescriptionError(Box<Details>);

/// Boxed so that `Result<_, DescriptionError>` stays small.
#[derive(Debug)]
struct Details {
    file_name: String,
    key: String,
    line: usize,
    column: usize,
    message: String,
    label: String,
    help: Option<String>,
    span: Option<SourceSpan>,
    source_code: NamedSource<String>,
}

impl DescriptionError {
    /// An error about `key` (full dotted key, e.g. `mechanics.mass`; empty for
    /// errors that concern no key) at the byte range `span` of `text`.
    pub(crate) fn at(
        file_name: &str,
        text: &str,
        key: impl Into<String>,
        span: Range<usize>,
        message: impl Into<String>,
        label: impl Into<String>,
    ) -> Self {
        let start = floor_char_boundary(text, span.start);
        let end = floor_char_boundary(text, span.end.max(start));
        let (line, column) = line_column(text, start);
        DescriptionError(Box::new(Details {
            file_name: file_name.to_string(),
            key: key.into(),
            line,
            column,
            message: message.into(),
            label: label.into(),
            help: None,
            span: Some((start, end - start).into()),
            source_code: NamedSource::new(file_name, text.to_string()).with_language("toml"),
        }))
    }

    /// A TOML syntax error reported by the `toml` parser.
    pub(crate) fn syntax(file_name: &str, text: &str, err: &toml::de::Error) -> Self {
        let span = err.span().unwrap_or(0..0);
        let message = err.message().trim_end().replace('\n', " ");
        Self::at(
            file_name,
            text,
            "",
            span,
            format!("TOML syntax error: {message}"),
            "invalid TOML here",
        )
    }

    /// The file could not be read.
    pub(crate) fn io(file_name: &str, err: &std::io::Error) -> Self {
        DescriptionError(Box::new(Details {
            file_name: file_name.to_string(),
            key: String::new(),
            line: 0,
            column: 0,
            message: format!("cannot read the actuator description: {err}"),
            label: String::new(),
            help: None,
            span: None,
            source_code: NamedSource::new(file_name, String::new()),
        }))
    }

    /// Adds a hint shown by graphical reports (not part of `Display`).
    pub(crate) fn with_help(mut self, help: impl Into<String>) -> Self {
        self.0.help = Some(help.into());
        self
    }

    /// The file name as given to the parser.
    pub fn file_name(&self) -> &str {
        &self.0.file_name
    }

    /// The full dotted key (`mechanics.mass`, `gap.z[3]`); empty for syntax
    /// and I/O errors.
    pub fn key(&self) -> &str {
        &self.0.key
    }

    /// 1-based line of the offending key or value; 0 when there is no
    /// position (the file could not be read).
    pub fn line(&self) -> usize {
        self.0.line
    }

    /// 1-based column (in characters); 0 when there is no position.
    pub fn column(&self) -> usize {
        self.0.column
    }

    /// What was wrong and what was expected, without file/position/key.
    pub fn message(&self) -> &str {
        &self.0.message
    }

    /// Byte range of the offending text, when there is one.
    pub fn span(&self) -> Option<Range<usize>> {
        self.0.span.map(|s| s.offset()..s.offset() + s.len())
    }

    fn summary(&self) -> String {
        let mut out = self.0.file_name.clone();
        if self.0.line > 0 {
            out.push_str(&format!(":{}:{}", self.0.line, self.0.column));
        }
        out.push_str(": ");
        if !self.0.key.is_empty() {
            out.push_str(&self.0.key);
            out.push_str(": ");
        }
        out.push_str(&self.0.message);
        out
    }
}

impl Diagnostic for DescriptionError {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new("reldesign::description"))
    }

    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.0
            .help
            .as_ref()
            .map(|h| Box::new(h) as Box<dyn fmt::Display + 'a>)
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        self.0.span.map(|_| &self.0.source_code as &dyn SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let span = self.0.span?;
        let label = LabeledSpan::new_primary_with_span(Some(self.0.label.clone()), span);
        Some(Box::new(std::iter::once(label)))
    }
}

/// 1-based (line, column) of byte `offset`; the column counts characters.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

fn floor_char_boundary(text: &str, offset: usize) -> usize {
    let mut i = offset.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_characters_and_lines_start_at_one() {
        let text = "aµb\ncµd";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, text.find('b').unwrap()), (1, 3));
        assert_eq!(line_column(text, text.find('d').unwrap()), (2, 3));
        assert_eq!(line_column(text, text.len()), (2, 4));
    }

    #[test]
    fn spans_inside_a_character_are_moved_to_its_start() {
        let text = "µ = 1";
        let err = DescriptionError::at("f.toml", text, "k", 1..4, "m", "l");
        assert_eq!(err.span(), Some(0..4));
        assert_eq!(err.to_string(), "f.toml:1:1: k: m");
    }
}
