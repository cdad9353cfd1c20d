//! The walker: a [`Sect`] is one table of the document (the root or a
//! section) with its name and span, so that every error it makes names the
//! full dotted key and points at the key, its value or the section header.
//! The typed readers (`number.rs`, `choice.rs`) and the unknown-key check
//! (`keys.rs`) are further `impl Sect` blocks.

use std::ops::Range;

use toml::de::{DeString, DeTable, DeValue};
use toml::Spanned;

use crate::description::schema;
use crate::description::DescriptionError;

pub(super) type Res<T> = Result<T, DescriptionError>;

/// The file being parsed: its name and text, for messages and spans.
pub(super) struct Ctx<'a> {
    pub(super) file: &'a str,
    pub(super) text: &'a str,
}

impl Ctx<'_> {
    pub(super) fn err(
        &self,
        key: String,
        span: Range<usize>,
        msg: impl Into<String>,
        label: &str,
    ) -> DescriptionError {
        DescriptionError::at(self.file, self.text, key, span, msg, label)
    }

    /// How a value reads in a message: numbers as written, others by type.
    pub(super) fn found(&self, value: &Spanned<DeValue>) -> String {
        match value.get_ref() {
            DeValue::Integer(_) | DeValue::Float(_) => self
                .text
                .get(value.span())
                .unwrap_or("?")
                .trim()
                .to_string(),
            DeValue::String(s) => format!("the string {s:?}"),
            DeValue::Boolean(b) => format!("the boolean {b}"),
            DeValue::Datetime(d) => format!("the datetime {d}"),
            DeValue::Array(_) => "an array".into(),
            DeValue::Table(_) => "a table".into(),
        }
    }
}

pub(super) type Entry<'a> = (&'a Spanned<DeString<'a>>, &'a Spanned<DeValue<'a>>);

/// A table of the document (the root or a section) and where it is.
pub(super) struct Sect<'a> {
    pub(super) ctx: &'a Ctx<'a>,
    /// "" for the root.
    pub(super) name: &'a str,
    pub(super) table: &'a DeTable<'a>,
    /// The section header (or inline table); 0..0 for the root.
    pub(super) span: Range<usize>,
}

impl<'a> Sect<'a> {
    /// The document's top level.
    pub(super) fn root(ctx: &'a Ctx<'a>, table: &'a DeTable<'a>) -> Sect<'a> {
        Sect {
            ctx,
            name: "",
            table,
            span: 0..0,
        }
    }

    pub(super) fn full_key(&self, key: &str) -> String {
        if self.name.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.name)
        }
    }

    pub(super) fn entry(&self, key: &str) -> Option<Entry<'a>> {
        self.table.get_key_value(key)
    }

    /// The schema's entry for `key` of this section.
    pub(super) fn spec(&self, key: &str) -> &'static schema::Key {
        schema::key(&self.full_key(key))
    }

    /// The key and, when on the same line, its value.
    pub(super) fn key_span(&self, key: &str) -> Range<usize> {
        let Some((k, v)) = self.entry(key) else {
            return self.span.clone();
        };
        let (k, v) = (k.span(), v.span());
        let (start, end) = (k.start.min(v.start), k.end.max(v.end));
        match self.ctx.text.get(start..end) {
            Some(t) if !t.contains('\n') => start..end,
            _ => k,
        }
    }

    /// `key`'s value as the file writes it (for "found …" in a message), or
    /// `value` where the key is absent (a default).
    pub(super) fn found(&self, key: &str, value: f64) -> String {
        self.entry(key)
            .map_or_else(|| value.to_string(), |(_, v)| self.ctx.found(v))
    }

    pub(super) fn err(&self, key: &str, msg: impl Into<String>, label: &str) -> DescriptionError {
        self.ctx
            .err(self.full_key(key), self.key_span(key), msg, label)
    }

    /// An error about element `index` of the array `key`.
    pub(super) fn elem_err(
        &self,
        key: &str,
        index: usize,
        msg: impl Into<String>,
        label: &str,
    ) -> DescriptionError {
        let span = self
            .entry(key)
            .and_then(|(_, v)| v.get_ref().as_array()?.get(index).map(|e| e.span()))
            .unwrap_or_else(|| self.key_span(key));
        self.ctx
            .err(format!("{}[{index}]", self.full_key(key)), span, msg, label)
    }

    /// The required `key` is absent; `what` says what it must be.
    pub(super) fn missing(&self, key: &str, what: &str) -> DescriptionError {
        let place = if self.name.is_empty() {
            "at the top level".to_string()
        } else {
            format!("in section [{}]", self.name)
        };
        let msg = format!("missing required key {place}: expected {what}");
        self.ctx.err(
            self.full_key(key),
            self.span.clone(),
            msg,
            &format!("`{key}` is missing"),
        )
    }

    /// The required sub-table `name` of the root.
    pub(super) fn section(&self, name: &'a str) -> Res<Sect<'a>> {
        let Some((_, value)) = self.entry(name) else {
            let msg = format!(
                "missing required section [{name}] (required sections: [coil], [gap], [core], \
                 [mechanics], [supply])"
            );
            return Err(self.ctx.err(name.to_string(), 0..0, msg, "section missing"));
        };
        let Some(table) = value.get_ref().as_table() else {
            let msg = format!("expected a table [{name}], found {}", self.ctx.found(value));
            return Err(self.err(name, msg, "expected a table"));
        };
        Ok(Sect {
            ctx: self.ctx,
            name,
            table,
            span: value.span(),
        })
    }

    /// The optional sub-table `name` of the root.
    pub(super) fn opt_section(&self, name: &'a str) -> Res<Option<Sect<'a>>> {
        if self.entry(name).is_none() {
            return Ok(None);
        }
        self.section(name).map(Some)
    }

    /// The sub-table `key` of this section, named `full` in messages, which
    /// must be present iff `required` (`needed_by` says which entries of
    /// `estimators` ask for it).
    pub(super) fn sub_section(
        &self,
        key: &str,
        full: &'static str,
        required: bool,
        needed_by: &str,
    ) -> Res<Option<Sect<'a>>> {
        let Some((_, value)) = self.entry(key) else {
            if !required {
                return Ok(None);
            }
            let msg = format!(
                "missing required section [{full}]: {}.estimators lists {needed_by}, which \
                 needs its parameters (see docs/reference/description.md)",
                self.name
            );
            return Err(self
                .ctx
                .err(full.to_string(), self.span.clone(), msg, "section missing"));
        };
        let Some(table) = value.get_ref().as_table() else {
            let msg = format!("expected a table [{full}], found {}", self.ctx.found(value));
            return Err(self.err(key, msg, "expected a table"));
        };
        if !required {
            let msg = format!(
                "section [{full}] is given but {}.estimators does not list {needed_by}: \
                 add it there or remove the section",
                self.name
            );
            return Err(self.err(key, msg, "not used by any estimator"));
        }
        Ok(Some(Sect {
            ctx: self.ctx,
            name: full,
            table,
            span: value.span(),
        }))
    }
}
