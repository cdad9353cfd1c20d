//! No import circles: within a folder, no two modules use each other,
//! directly or through a chain (A uses B, B uses A). What both need lives
//! in a lower module. A module's dependencies are its plain `use`
//! statements and the `super::…`, `self::…`, `crate::…` paths of its code,
//! before its `#[cfg(test)]` part; a re-export (`pub use`) is not one.
//! A module and its own children are one unit (the parent declares them and
//! may call them, a child may read the parent's items), so circles are
//! sought among modules that are not each other's ancestor.

use std::collections::BTreeMap;
use std::path::Path;

/// A module's path from its crate root, e.g. `design::law::hold`.
type Module = Vec<String>;

/// The module of `rel` (a path under `src/`): `a/b.rs` and `a/b/mod.rs` are `a::b`.
fn module_of(rel: &str) -> Module {
    let rel = rel.trim_end_matches(".rs");
    let mut parts: Module = rel.split('/').map(str::to_owned).collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// The code before the tests, without comment lines.
fn code(text: &str) -> String {
    text.lines()
        .take_while(|l| !l.trim_start().starts_with("#[cfg(test)]"))
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths of a use tree such as `a::{b, c::{d, e}}` (`self` as the prefix).
fn expand(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        return vec![tree.to_owned()];
    };
    let (prefix, inner) = (&tree[..open], &tree[open + 1..tree.len() - 1]);
    let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .filter(|p| !p.trim().is_empty())
        .flat_map(expand)
        .map(|p| match p.as_str() {
            "self" => prefix.trim_end_matches("::").to_owned(),
            _ => format!("{prefix}{p}"),
        })
        .collect()
}

/// The paths a module's code names: its plain `use` trees expanded, and the
/// `super::`, `self::`, `crate::` paths elsewhere.
fn named_paths(code: &str) -> Vec<String> {
    let (mut paths, mut outside, mut rest) = (Vec::new(), String::new(), code);
    while let Some(i) = use_statement(rest) {
        let Some(end) = rest[i..].find(';').map(|e| i + e) else {
            break;
        };
        let head = rest[..i].trim_end();
        let reexport = head.ends_with("pub")
            || head
                .rfind("pub(")
                .is_some_and(|k| head.ends_with(')') && !head[k..].contains([';', '{', '}']));
        if !reexport {
            paths.extend(expand(&rest[i + 4..end].replace(char::is_whitespace, "")));
        }
        outside.push_str(&rest[..i]);
        rest = &rest[end + 1..];
    }
    outside.push_str(rest);
    inline_paths(&outside, &mut paths);
    paths
}

/// Where the next `use` statement of `text` starts.
fn use_statement(text: &str) -> Option<usize> {
    text.match_indices("use ").map(|(i, _)| i).find(|&i| {
        let head = text[..i].trim_end();
        let word_start = !text[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_');
        word_start
            && (head.is_empty()
                || head.ends_with([';', '{', '}', ']'])
                || head.ends_with("pub")
                || head.ends_with(')'))
    })
}

fn inline_paths(text: &str, out: &mut Vec<String>) {
    for start in ["super::", "self::", "crate::"] {
        for (i, _) in text.match_indices(start) {
            let before = text[..i].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let path: String = text[i..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            out.push(path);
        }
    }
}

/// The module `path` names from `from`, among `known`: its longest known
/// prefix, resolved from `crate`, `super` and `self`, or a child's name.
fn resolve(from: &Module, path: &str, known: &[Module]) -> Option<Module> {
    let mut words = path.split("::").filter(|w| !w.is_empty()).peekable();
    let bare = !["crate", "super", "self"]
        .iter()
        .any(|k| path.starts_with(k));
    let mut at = from.clone();
    if words.peek() == Some(&"crate") {
        words.next();
        at.clear();
    }
    while let Some(&w) = words.peek() {
        match w {
            "super" => {
                at.pop()?;
            }
            "self" => {}
            _ => break,
        }
        words.next();
    }
    let mut best = (!bare && known.contains(&at)).then(|| at.clone());
    for w in words {
        at.push(w.to_owned());
        if known.contains(&at) {
            best = Some(at.clone());
        }
    }
    best
}

/// The circles among the modules of `src/<folder>` (each as its members).
pub fn circles(src: &Path, folder: &str) -> Vec<Vec<String>> {
    let mut files = Vec::new();
    super::rust_files(&src.join(folder), &mut files);
    let modules: BTreeMap<Module, String> = files
        .iter()
        .map(|f| {
            let rel = f
                .strip_prefix(src)
                .expect("under src")
                .to_string_lossy()
                .replace('\\', "/");
            (
                module_of(&rel),
                std::fs::read_to_string(f).expect("readable source"),
            )
        })
        .collect();
    let known: Vec<Module> = modules.keys().cloned().collect();
    let edges: BTreeMap<&Module, Vec<Module>> = modules
        .iter()
        .map(|(m, text)| {
            let mut to: Vec<Module> = named_paths(&code(text))
                .iter()
                .filter_map(|p| resolve(m, p, &known))
                .filter(|t| !t.starts_with(m) && !m.starts_with(t))
                .collect();
            to.sort();
            to.dedup();
            (m, to)
        })
        .collect();
    strongly_connected(&known, &edges)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| c.iter().map(|m| m.join("::")).collect())
        .collect()
}

/// Tarjan's strongly connected components.
fn strongly_connected(
    nodes: &[Module],
    edges: &BTreeMap<&Module, Vec<Module>>,
) -> Vec<Vec<Module>> {
    struct State<'a> {
        edges: &'a BTreeMap<&'a Module, Vec<Module>>,
        index: BTreeMap<Module, (usize, usize)>,
        stack: Vec<Module>,
        out: Vec<Vec<Module>>,
    }
    fn visit(s: &mut State, v: &Module) {
        let n = s.index.len();
        s.index.insert(v.clone(), (n, n));
        s.stack.push(v.clone());
        for w in s.edges.get(v).cloned().unwrap_or_default() {
            if !s.index.contains_key(&w) {
                visit(s, &w);
                let low = s.index[&w].1.min(s.index[v].1);
                s.index.get_mut(v).expect("visited").1 = low;
            } else if s.stack.contains(&w) {
                let low = s.index[&w].0.min(s.index[v].1);
                s.index.get_mut(v).expect("visited").1 = low;
            }
        }
        let (i, low) = s.index[v];
        if i == low {
            let at = s.stack.iter().rposition(|m| m == v).expect("on the stack");
            s.out.push(s.stack.split_off(at));
        }
    }
    let mut s = State {
        edges,
        index: BTreeMap::new(),
        stack: Vec::new(),
        out: Vec::new(),
    };
    for v in nodes {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

#[test]
fn a_circle_is_found() {
    let known: Vec<Module> = vec![
        vec!["a".into()],
        vec!["a".into(), "b".into()],
        vec!["c".into()],
    ];
    let b = vec!["a".to_owned(), "b".to_owned()];
    assert_eq!(resolve(&b, "super::Item", &known), Some(vec!["a".into()]));
    assert_eq!(
        resolve(&b, "crate::c::Item", &known),
        Some(vec!["c".into()])
    );
    assert_eq!(
        resolve(&vec!["a".into()], "b::Item", &known),
        Some(b.clone())
    );
    assert_eq!(resolve(&b, "std::fmt", &known), None);
    assert_eq!(
        named_paths("use super::x::{A, y::{B, C}};\npub use z::D;\nfn f() { crate::w::e(); }"),
        [
            "super::x::A",
            "super::x::y::B",
            "super::x::y::C",
            "crate::w::e"
        ]
    );
    let edges: BTreeMap<&Module, Vec<Module>> = [
        (&known[0], vec![known[1].clone()]),
        (&known[1], vec![known[0].clone()]),
    ]
    .into_iter()
    .collect();
    let found: Vec<_> = strongly_connected(&known, &edges)
        .into_iter()
        .filter(|c| c.len() > 1)
        .collect();
    assert_eq!(found.len(), 1);
}
