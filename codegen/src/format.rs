//! Formatting of emitted tokens (`syn` + `prettyplease`, deterministic and
//! independent of any installed rustfmt) and the `//` comments that tokens
//! cannot carry.

use proc_macro2::TokenStream;

use crate::error::EmitError;
use crate::float::MACRO_FLOAT;

/// Formats items as a Rust file body.
pub fn format_items(tokens: TokenStream) -> Result<String, EmitError> {
    let file: syn::File = syn::parse2(tokens).map_err(|e| EmitError::Syntax(e.to_string()))?;
    Ok(prettyplease::unparse(&file))
}

/// Puts `// doc` above the first `let name = ` of function `function`, for
/// each (name, doc).
pub(crate) fn comment_lets(text: &str, function: &str, comments: &[(&str, &str)]) -> String {
    let header = format!("fn {function}(");
    let mut out = String::with_capacity(text.len() + 64 * comments.len());
    let mut in_function = false;
    let mut pending: Vec<(&str, &str)> = comments
        .iter()
        .copied()
        .filter(|c| !c.1.is_empty())
        .collect();
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if trimmed.starts_with("pub fn ") || trimmed.starts_with("fn ") {
            in_function = trimmed.contains(&header);
        }
        if in_function {
            if let Some(k) = pending
                .iter()
                .position(|(name, _)| trimmed.starts_with(&format!("let {name} = ")))
            {
                let (_, doc) = pending.remove(k);
                let indent = &line[..line.len() - trimmed.len()];
                for d in doc.lines() {
                    out.push_str(indent);
                    out.push_str("// ");
                    out.push_str(d);
                    out.push('\n');
                }
            }
        }
        out.push_str(line);
    }
    out
}

/// A blank line between consecutive items of the same block (prettyplease
/// writes none): before a line opening an item (`///`, `#[`, `pub `, `fn `,
/// `impl `) that follows a line closing one (`;` or `}`) at the same or a
/// deeper indent (an item may end on a continuation line, e.g. a long const).
pub(crate) fn space_items(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + text.len() / 16);
    let mut prev: Option<&str> = None;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        let indent = line.len() - trimmed.len();
        let opens = ["///", "#[", "pub ", "fn ", "impl "]
            .iter()
            .any(|p| trimmed.starts_with(p));
        if let Some(p) = prev {
            let p_trimmed = p.trim_start();
            let p_indent = p.len() - p_trimmed.len();
            let closes = p_trimmed.trim_end().ends_with(';') || p_trimmed.trim_end().ends_with('}');
            let comment = p_trimmed.starts_with("//") || p_trimmed.starts_with("#[");
            if opens && closes && !comment && p_indent >= indent {
                out.push('\n');
            }
        }
        out.push_str(line);
        prev = Some(line);
    }
    out
}

/// `macro_rules! name { ($f:ty) => { … } }` around formatted items, preceded
/// by `doc` as `///` lines: the items' [`MACRO_FLOAT`] placeholders become
/// `$f` (whole words only) and every non-empty line is indented into the
/// macro (the items hold no multi-line literals).
pub(crate) fn macro_rules(name: &str, doc: &str, items: &str) -> String {
    let mut out = String::with_capacity(items.len() + items.len() / 8 + 128);
    for line in doc.lines() {
        out.push_str("///");
        if !line.is_empty() {
            out.push(' ');
            out.push_str(line);
        }
        out.push('\n');
    }
    out.push_str(&format!("macro_rules! {name} {{\n    ($f:ty) => {{\n"));
    for line in items.lines() {
        if !line.is_empty() {
            out.push_str("        ");
            out.push_str(&replace_word(line, MACRO_FLOAT, "$f"));
        }
        out.push('\n');
    }
    out.push_str("    };\n}\n");
    out
}

/// `text` with every occurrence of the identifier `word` (not a part of a
/// longer identifier) replaced by `by`.
fn replace_word(text: &str, word: &str, by: &str) -> String {
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(k) = rest.find(word) {
        let (before, after) = (&rest[..k], &rest[k + word.len()..]);
        let whole = !before.chars().next_back().is_some_and(is_ident)
            && !after.chars().next().is_some_and(is_ident);
        out.push_str(before);
        out.push_str(if whole { by } else { word });
        rest = after;
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_macro_body_has_its_placeholder_replaced_as_a_word_and_is_indented() {
        let items = format!(
            "pub const X: {f} = 1.0;\n\nfn g({f}x: {f}) -> {f}Output {{}}\n",
            f = MACRO_FLOAT
        );
        let text = macro_rules("m", "Doc.\n\nMore.", &items);
        let want = format!(
            "/// Doc.\n///\n/// More.\nmacro_rules! m {{\n    ($f:ty) => {{\n        pub const X: $f = 1.0;\n\n        fn g({f}x: $f) -> {f}Output {{}}\n    }};\n}}\n",
            f = MACRO_FLOAT
        );
        assert_eq!(text, want);
    }
}
