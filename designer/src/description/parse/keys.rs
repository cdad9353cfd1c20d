//! Unknown keys: a section may hold only the keys the schema lists for it
//! (for its `model` or `law`); the first other one, in document order, is
//! refused with the allowed list and, when one is near, a "did you mean".

use super::sect::{Res, Sect};
use crate::description::schema;

impl Sect<'_> {
    /// Rejects keys the schema does not allow in this section (with its
    /// `model` = `variant`), reporting the first in document order.
    pub(super) fn check_keys(&self, variant: Option<&str>, context: &str) -> Res<()> {
        self.reject_unknown(&schema::keys_of(self.name, variant), context)
    }

    /// Unknown keys, against the keys of every variant of the section.
    pub(super) fn check_keys_any_variant(&self, context: &str) -> Res<()> {
        let allowed: Vec<&str> = schema::KEYS
            .iter()
            .filter(|k| k.section() == self.name)
            .map(schema::Key::name)
            .collect();
        self.reject_unknown(&allowed, context)
    }

    fn reject_unknown(&self, allowed: &[&str], context: &str) -> Res<()> {
        let unknown = self
            .table
            .iter()
            .filter(|(k, _)| !allowed.contains(&k.get_ref().as_ref()))
            .min_by_key(|(k, _)| k.span().start);
        let Some((key, _)) = unknown else {
            return Ok(());
        };
        let msg = format!(
            "unknown key; allowed keys {context}: {}",
            allowed.join(", ")
        );
        let full = self.full_key(key.get_ref());
        let err = self.ctx.err(full, key.span(), msg, "unknown key");
        match closest(key.get_ref(), allowed) {
            Some(near) => Err(err.with_help(format!("did you mean `{near}`?"))),
            None => Err(err),
        }
    }
}

/// The allowed key nearest to a misspelt one (at most 2 edits away).
fn closest<'k>(key: &str, allowed: &[&'k str]) -> Option<&'k str> {
    allowed
        .iter()
        .map(|a| (edit_distance(key, a), *a))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
        .map(|(_, a)| a)
}

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != *cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            diagonal = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn misspelt_keys_get_a_suggestion() {
        assert_eq!(edit_distance("resistence", "resistance"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(
            closest("stifness", &["mass", "stiffness"]),
            Some("stiffness")
        );
        assert_eq!(closest("inductance", &["turns", "resistance"]), None);
    }
}
