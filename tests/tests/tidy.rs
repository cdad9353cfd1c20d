//! House rules checked by test (rust-analyzer's `tidy.rs`): every source file
//! says what it is in a `//!` module doc, and ARCHITECTURE.md's module maps
//! list every source file, so the map cannot fall behind the code.

use std::path::{Path, PathBuf};

/// The crates whose `src/` the module maps cover.
const CRATES: [&str; 9] = [
    "sym", "designer", "identify", "codegen", "runtime", "cli", "macros", "tests", "python",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// (crate, path relative to its `src/`) of every source file.
fn sources() -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    for krate in CRATES {
        let src = root().join(krate).join("src");
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        files.sort();
        for f in files {
            let rel = f
                .strip_prefix(&src)
                .expect("under src")
                .to_string_lossy()
                .replace('\\', "/");
            out.push((krate, rel));
        }
    }
    out
}

#[test]
fn every_source_file_starts_with_a_module_doc() {
    let missing: Vec<String> = sources()
        .into_iter()
        .filter(|(krate, rel)| {
            let text = std::fs::read_to_string(root().join(krate).join("src").join(rel))
                .expect("readable source");
            !text.trim_start().starts_with("//!")
        })
        .map(|(krate, rel)| format!("{krate}/src/{rel}"))
        .collect();
    assert!(missing.is_empty(), "no `//!` module doc: {missing:?}");
}

#[test]
fn architecture_lists_every_source_file() {
    let map = std::fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let missing: Vec<String> = sources()
        .into_iter()
        .filter(|(_, rel)| rel != "lib.rs" && rel != "main.rs")
        .filter(|(krate, rel)| {
            let full = format!("`{krate}/src/{rel}`");
            let short = format!("`{rel}`");
            !map.contains(&full) && !map.contains(&short)
        })
        .map(|(krate, rel)| format!("{krate}/src/{rel}"))
        .collect();
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md's module maps do not list: {missing:#?}"
    );
}

/// The paper keys of equation tags such as `[JA 84a]` (ARCHITECTURE.md).
const PAPER_KEYS: [&str; 5] = ["PT", "JA", "SE", "SM", "SB"];

/// The rows of ARCHITECTURE.md's "Where the equations live" table.
fn equation_rows(map: &str) -> Vec<String> {
    map.split("## Where the equations live")
        .nth(1)
        .expect("the equation table's section")
        .lines()
        .take_while(|l| !l.starts_with("## "))
        .filter(|l| l.starts_with("| ["))
        .map(str::to_owned)
        .collect()
}

/// The tags `[KEY …]` in `text`, e.g. `[JA 84–87]`.
fn tags(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (i, _) in text.match_indices('[') {
        let rest = &text[i..];
        let Some(end) = rest.find(']') else { continue };
        let tag = &rest[..=end];
        if PAPER_KEYS
            .iter()
            .any(|k| tag[1..].starts_with(&format!("{k} ")))
        {
            out.push(tag.to_owned());
        }
    }
    out
}

/// Whether `text` holds `tag`; a range `[JA 84–87]` is found by `[JA 84`
/// followed by anything but a digit (`[JA 84]`, `[JA 84a]`, `[JA 84–85]`).
fn holds_tag(text: &str, tag: &str) -> bool {
    let Some((first, _)) = tag.split_once('–') else {
        return text.contains(tag);
    };
    text.match_indices(first).any(|(i, _)| {
        !text[i + first.len()..]
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_digit())
    })
}

/// The text of a table cell's files: a directory stands for its `*.rs`.
fn cell_files_text(cell: &str) -> Result<String, String> {
    let mut text = String::new();
    for path in cell.split('`').skip(1).step_by(2) {
        let full = root().join(path);
        if path.ends_with('/') {
            let mut files = Vec::new();
            rust_files(&full, &mut files);
            if files.is_empty() {
                return Err(format!("`{path}` holds no Rust file"));
            }
            for f in files {
                text += &std::fs::read_to_string(f).expect("readable source");
            }
        } else {
            text +=
                &std::fs::read_to_string(&full).map_err(|_| format!("`{path}` does not exist"))?;
        }
    }
    Ok(text)
}

#[test]
fn equation_table_tags_are_found_in_their_files() {
    let map = std::fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let rows = equation_rows(&map);
    assert!(rows.len() > 10, "equation table not found: {rows:?}");
    let mut problems = Vec::new();
    for row in rows {
        let cells: Vec<&str> = row.split(" | ").collect();
        let (Some(equations), Some(files)) = (cells.first(), cells.last()) else {
            continue;
        };
        match cell_files_text(files) {
            Err(e) => problems.push(e),
            Ok(text) => problems.extend(
                tags(equations)
                    .into_iter()
                    .filter(|t| !holds_tag(&text, t))
                    .map(|t| format!("{t} not in {}", files.trim_end_matches(" |"))),
            ),
        }
    }
    assert!(problems.is_empty(), "equation table: {problems:#?}");
}

/// The comment of a source line (after `//` outside a string), without its
/// quoted `"…"` and code `` `…` `` spans (emitted text and identifiers).
fn comment_prose(line: &str) -> Option<String> {
    let mut in_string = false;
    let mut escaped = false;
    let mut start = None;
    let bytes = line.as_bytes();
    for (i, &b) in bytes.iter().enumerate() {
        if in_string {
            in_string = !(b == b'"' && !escaped);
            escaped = b == b'\\' && !escaped;
        } else if b == b'"' {
            in_string = true;
        } else if b == b'/' && bytes.get(i + 1) == Some(&b'/') {
            start = Some(i);
            break;
        }
    }
    let comment = &line[start?..];
    let mut prose = String::new();
    let mut quote = None;
    for c in comment.chars() {
        match (quote, c) {
            (None, '"' | '`') => quote = Some(c),
            (Some(q), _) if q == c => quote = None,
            (None, _) => prose.push(c),
            _ => {}
        }
    }
    Some(prose)
}

/// Untagged citations in a comment: `(84a)`, `eq. 50`, `eqs. 41–42`,
/// `Algorithm 1`, `Table 2`, `§6.1` without a paper key in front.
fn untagged_citations(prose: &str) -> Vec<String> {
    let chars: Vec<char> = prose.chars().collect();
    let mut found = Vec::new();
    for (i, &c) in chars.iter().enumerate() {
        let before = if i == 0 { ' ' } else { chars[i - 1] };
        let rest: String = chars[i..].iter().take(12).collect();
        let digits: String = chars[i + 1..]
            .iter()
            .take_while(|d| d.is_ascii_digit())
            .collect();
        let after = chars.get(i + 1 + digits.len()).copied();
        let after2 = chars.get(i + 2 + digits.len()).copied();
        let paren = c == '('
            && !(before.is_alphanumeric() || "_'′)]^/".contains(before))
            && !digits.is_empty()
            && digits != "0"
            && (after == Some(')')
                || (after.is_some_and(|a| a.is_ascii_lowercase()) && after2 == Some(')')));
        let keyed = i >= 4
            && PAPER_KEYS.iter().any(|k| {
                prose[..prose.char_indices().nth(i).map_or(prose.len(), |(b, _)| b)]
                    .ends_with(&format!("[{k} "))
            });
        let word = ["eq. ", "eqs. ", "Algorithm ", "Table "]
            .iter()
            .any(|w| rest.starts_with(w) && !before.is_alphanumeric());
        let section = c == '§' && !keyed && !prose.to_lowercase().contains("issue");
        if paren || (word && !keyed) || section {
            found.push(rest);
        }
    }
    found
}

#[test]
fn equation_citations_carry_their_paper() {
    // Hairer–Nørsett–Wanner's book, not one of the papers.
    const BOOK: &str = "designer/src/sim/rk.rs";
    let mut files: Vec<String> = sources()
        .into_iter()
        .map(|(krate, rel)| format!("{krate}/src/{rel}"))
        .collect();
    let mut tests = Vec::new();
    rust_files(&root().join("tests/tests"), &mut tests);
    files.extend(tests.iter().map(|f| {
        f.strip_prefix(root())
            .expect("under the root")
            .to_string_lossy()
            .replace('\\', "/")
    }));
    let mut untagged = Vec::new();
    for file in files.iter().filter(|f| f.as_str() != BOOK) {
        let text = std::fs::read_to_string(root().join(file)).expect("readable source");
        for (n, line) in text.lines().enumerate() {
            let Some(prose) = comment_prose(line) else {
                continue;
            };
            for cite in untagged_citations(&prose) {
                untagged.push(format!("{file}:{}: {cite}", n + 1));
            }
        }
    }
    assert!(
        untagged.is_empty(),
        "citations without a paper key ([PT 50], [JA 84a], [SE Alg. 1]): {untagged:#?}"
    );
}

#[path = "tidy/circles.rs"]
mod circles;

/// No crate's modules use each other in a circle (issue 34 found four:
/// `design/{plan, decisions, hold, backstepping_design}`, `design/{optimal,
/// optimal_guess, optimal_search}`, `codegen/{controller, operations}`,
/// `diagnose/localise/{drift, report}`); what two modules share lives in a
/// lower one.
#[test]
fn no_module_uses_itself_through_another() {
    let found: Vec<String> = CRATES
        .iter()
        .flat_map(|krate| {
            circles::circles(&root().join(krate).join("src"), "")
                .into_iter()
                .map(move |c| format!("{krate}: {}", c.join(" → ")))
        })
        .collect();
    assert!(found.is_empty(), "import circles: {found:#?}");
}
