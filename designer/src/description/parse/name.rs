//! The top-level `name`: it becomes the generated module's and types' name,
//! so it must be a Rust identifier once its `-` are `_`, and no keyword.

use super::sect::{Res, Sect};

/// The `name` of the root table.
pub(super) fn parse_name(root: &Sect) -> Res<String> {
    const WHAT: &str = "an identifier usable as a Rust module name ([A-Za-z_][A-Za-z0-9_-]*)";
    let Some((_, value)) = root.entry("name") else {
        return Err(root.missing("name", WHAT));
    };
    let Some(name) = value.get_ref().as_str() else {
        let msg = format!("expected a string, {WHAT}, found {}", root.ctx.found(value));
        return Err(root.err("name", msg, "expected a string"));
    };
    if let Some(why) = identifier_problem(name) {
        let msg = format!("expected {WHAT}, found {name:?} ({why})");
        return Err(root.err("name", msg, "not a valid identifier"));
    }
    Ok(name.to_string())
}

/// Why `name` cannot be used as a module/type name, if it cannot.
fn identifier_problem(name: &str) -> Option<&'static str> {
    let mut chars = name.chars();
    let Some(first) = chars.next() else {
        return Some("it is empty");
    };
    if !(first.is_ascii_alphabetic() || first == '_') {
        return Some("it must start with a letter or '_'");
    }
    if !chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Some("only letters, digits, '_' and '-' are allowed");
    }
    let ident = name.replace('-', "_");
    if ident.chars().all(|c| c == '_') {
        return Some("it needs a letter or digit");
    }
    if RUST_KEYWORDS.contains(&ident.as_str()) {
        return Some("it is a Rust keyword");
    }
    None
}

const RUST_KEYWORDS: [&str; 51] = [
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe", "use", "where",
    "while", "async", "await", "dyn", "abstract", "become", "box", "do", "final", "macro",
    "override", "priv", "typeof", "unsized", "virtual", "yield", "try",
];
