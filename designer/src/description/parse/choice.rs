//! The values that are not numbers: one string among the schema's values of
//! a key (a model, a law), a non-empty array of distinct ones (operations,
//! estimators, float types), and booleans.

use toml::de::DeValue;

use super::sect::{Res, Sect};
use crate::description::schema;

impl Sect<'_> {
    /// A required string among the schema's values.
    pub(super) fn choice(&self, key: &str, what: &str) -> Res<&'static str> {
        let list = quoted_list(schema::values(&self.full_key(key)));
        self.opt_choice(key, what)?
            .ok_or_else(|| self.missing(key, &format!("one of {list}")))
    }

    /// An optional string among the schema's values; `what` names one in
    /// messages ("gap model").
    pub(super) fn opt_choice(&self, key: &str, what: &str) -> Res<Option<&'static str>> {
        let allowed = schema::values(&self.full_key(key));
        let list = quoted_list(allowed);
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        let Some(text) = value.get_ref().as_str() else {
            let msg = format!(
                "expected a string, one of {list}, found {}",
                self.ctx.found(value)
            );
            return Err(self.err(key, msg, "expected a string"));
        };
        match allowed.iter().find(|a| **a == text) {
            Some(a) => Ok(Some(a)),
            None => {
                let msg = format!("unknown {what} \"{text}\"; expected one of {list}");
                Err(self.err(key, msg, &format!("unknown {what}")))
            }
        }
    }

    /// An optional, non-empty array of distinct strings among the schema's
    /// values, in the order given.
    pub(super) fn names(
        &self,
        key: &str,
        what: &str,
        at_least: &str,
    ) -> Res<Option<Vec<&'static str>>> {
        let allowed = schema::values(&self.full_key(key));
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        let list = quoted_list(allowed);
        let Some(items) = value.get_ref().as_array() else {
            let msg = format!(
                "expected an array of strings among {list}, found {}",
                self.ctx.found(value)
            );
            return Err(self.err(key, msg, "expected an array"));
        };
        if items.is_empty() {
            let msg = format!("expected a non-empty array ({at_least}) among {list}, found []");
            return Err(self.err(key, msg, "empty"));
        }
        let full = self.full_key(key);
        let mut out: Vec<&'static str> = Vec::with_capacity(items.len());
        for (i, item) in items.iter().enumerate() {
            let elem = |msg: String, label: &str| {
                self.ctx
                    .err(format!("{full}[{i}]"), item.span(), msg, label)
            };
            let Some(text) = item.get_ref().as_str() else {
                let msg = format!(
                    "expected a string, one of {list}, found {}",
                    self.ctx.found(item)
                );
                return Err(elem(msg, "expected a string"));
            };
            let Some(name) = allowed.iter().find(|a| **a == text) else {
                let msg = format!("unknown {what} \"{text}\"; expected one of {list}");
                return Err(elem(msg, &format!("unknown {what}")));
            };
            if let Some(first) = out.iter().position(|o| o == name) {
                let msg = format!(
                    "duplicate {what} \"{text}\" (already given as {full}[{first}]); each may \
                     appear once"
                );
                return Err(elem(msg, "duplicate"));
            }
            out.push(name);
        }
        Ok(Some(out))
    }

    /// An optional boolean.
    pub(super) fn opt_bool(&self, key: &str) -> Res<Option<bool>> {
        let Some((_, value)) = self.entry(key) else {
            return Ok(None);
        };
        match value.get_ref() {
            DeValue::Boolean(b) => Ok(Some(*b)),
            _ => {
                let msg = format!("expected a boolean, found {}", self.ctx.found(value));
                Err(self.err(key, msg, "expected true or false"))
            }
        }
    }
}

/// `"a", "b", "c"`.
fn quoted_list(allowed: &[&str]) -> String {
    allowed
        .iter()
        .map(|a| format!("\"{a}\""))
        .collect::<Vec<_>>()
        .join(", ")
}
