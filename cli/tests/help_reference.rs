//! The documentation stays true to the code (rust-analyzer's
//! `ensure_file_contents` pattern, as `generated/tests/fresh.rs` does for the
//! generated code):
//!
//! - `docs/reference/cli.md` holds the `--help` text of the built binary, for
//!   the top level and for every subcommand, each in a fenced `console` block
//!   whose first line is `$ reldesign … --help`. A stale or missing block
//!   fails; `UPDATE_DOCS=1 cargo test -p reldesign --test help_reference`
//!   rewrites the file (a missing subcommand gets a new section at the end)
//!   and still fails, so that a rewritten file is looked at and committed.
//! - Every relative link in `README.md` and `docs/**/*.md` resolves to a file
//!   of the repository (and its `#anchor` to a heading of that file), and
//!   every repository path quoted in backticks exists.
//! - Every complete description in a `toml` block of those files (one with
//!   `name` and `[coil]`) passes `reldesign check`.

use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};

use support::{rd, root, Cli, TempDir};

const CLI: Cli = Cli::new(env!("CARGO_BIN_EXE_reldesign"));

/// `reldesign ARGS --help` as the binary prints it, without colour and
/// without trailing spaces on its lines.
fn help(args: &[&str]) -> Result<String, String> {
    let run = CLI.run(&[args, &["--help"]].concat());
    if !run.succeeded() {
        return Err(run.stderr);
    }
    let text = String::from_utf8(run.stdout).map_err(|e| e.to_string())?;
    Ok(text
        .lines()
        .map(str::trim_end)
        .collect::<Vec<_>>()
        .join("\n"))
}

/// The subcommands the top-level help lists (without `help`).
fn subcommands(top: &str) -> Vec<String> {
    top.lines()
        .skip_while(|line| *line != "Commands:")
        .skip(1)
        .take_while(|line| !line.is_empty())
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_owned)
        .collect()
}

/// A `console` block of cli.md: the arguments of its `$ reldesign … --help`
/// line and the range of its content lines.
struct Block {
    args: Vec<String>,
    content: std::ops::Range<usize>,
}

fn help_blocks(lines: &[&str]) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let command = lines.get(i + 1).and_then(|l| l.strip_prefix("$ reldesign"));
        if lines[i] == "```console" {
            if let Some(args) = command.and_then(|c| c.trim().strip_suffix("--help")) {
                let start = i + 1;
                let end = (start..lines.len())
                    .find(|&j| lines[j].starts_with("```"))
                    .unwrap_or(lines.len());
                blocks.push(Block {
                    args: args.split_whitespace().map(str::to_owned).collect(),
                    content: start..end,
                });
                i = end;
            }
        }
        i += 1;
    }
    blocks
}

/// `$ reldesign ARGS --help`, the first line of a block.
fn command_line(args: &[&str]) -> String {
    let mut words = vec!["$", "reldesign"];
    words.extend(args);
    words.push("--help");
    words.join(" ")
}

#[test]
fn cli_reference_is_the_binarys_help() {
    let path = root().join("docs/reference/cli.md");
    let old = std::fs::read_to_string(&path).expect("docs/reference/cli.md");
    let lines: Vec<&str> = old.lines().collect();
    let blocks = help_blocks(&lines);
    let top = help(&[]).expect("reldesign --help");
    let mut problems = Vec::new();

    // Every block, refreshed from the binary.
    let mut new = String::new();
    let mut next = 0;
    for block in &blocks {
        let args: Vec<&str> = block.args.iter().map(String::as_str).collect();
        for line in &lines[next..block.content.start] {
            new.push_str(line);
            new.push('\n');
        }
        new.push_str(&command_line(&args));
        new.push('\n');
        match help(&args) {
            Ok(text) => {
                new.push_str(&text);
                new.push('\n');
            }
            Err(error) => {
                problems.push(format!(
                    "`reldesign {} --help` fails (a command the binary no longer has? \
                     remove its section): {}",
                    args.join(" "),
                    error.trim()
                ));
                for line in &lines[block.content.start + 1..block.content.end] {
                    new.push_str(line);
                    new.push('\n');
                }
            }
        }
        next = block.content.end;
    }
    for line in &lines[next..] {
        new.push_str(line);
        new.push('\n');
    }

    // Every subcommand (and the top level) has a block.
    let documented: BTreeSet<Vec<String>> = blocks.iter().map(|b| b.args.clone()).collect();
    let mut wanted = vec![Vec::new()];
    wanted.extend(subcommands(&top).into_iter().map(|name| vec![name]));
    for args in wanted.iter().filter(|a| !documented.contains(*a)) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let text = help(&args).expect("the help of a listed subcommand");
        let title = ["reldesign"]
            .iter()
            .chain(&args)
            .copied()
            .collect::<Vec<_>>()
            .join(" ");
        let first = command_line(&args);
        new.push_str(&format!(
            "\n## `{title}`\n\n```console\n{first}\n{text}\n```\n"
        ));
    }

    if new != old {
        let update = std::env::var_os("UPDATE_DOCS").is_some_and(|v| v == "1");
        if update {
            std::fs::write(&path, &new).expect("write docs/reference/cli.md");
        }
        let first = old
            .lines()
            .zip(new.lines())
            .position(|(a, b)| a != b)
            .map_or_else(
                || "at the end".to_owned(),
                |i| format!("from line {}", i + 1),
            );
        problems.push(if update {
            format!("docs/reference/cli.md was stale ({first}) and has been rewritten: review and commit it")
        } else {
            format!(
                "docs/reference/cli.md differs from the binary's --help ({first}): run \
                 `UPDATE_DOCS=1 cargo test -p reldesign --test help_reference`"
            )
        });
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// README.md and every Markdown file under docs/.
fn markdown_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .expect("docs/")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|x| x == "md") {
                out.push(path);
            }
        }
    }
    let mut files = vec![root().join("README.md")];
    walk(&root().join("docs"), &mut files);
    files
}

/// The text outside fenced code blocks, line by line (fenced lines empty).
fn prose_lines(text: &str) -> Vec<&str> {
    let mut fenced = false;
    text.lines()
        .map(|line| {
            let fence =
                line.trim_start().starts_with("```") || line.trim_start().starts_with("~~~");
            if fence {
                fenced = !fenced;
                ""
            } else if fenced {
                ""
            } else {
                line
            }
        })
        .collect()
}

/// A line split into its inline code spans and the rest.
fn split_code(line: &str) -> (Vec<&str>, String) {
    let mut spans = Vec::new();
    let mut rest = String::new();
    let mut parts = line.split('`');
    if let Some(first) = parts.next() {
        rest.push_str(first);
    }
    let mut in_code = true;
    for part in parts {
        if in_code {
            spans.push(part);
        } else {
            rest.push_str(part);
        }
        in_code = !in_code;
    }
    (spans, rest)
}

/// Link targets of `[text](target)`, `![alt](target)` and `[label]: target`.
fn link_targets(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        let end = after.find(')').unwrap_or(after.len());
        let target = after[..end].split_whitespace().next().unwrap_or("");
        targets.push(target.trim_matches(|c| c == '<' || c == '>').to_owned());
        rest = &after[end..];
    }
    let trimmed = text.trim_start();
    if trimmed.starts_with('[') {
        if let Some(at) = trimmed.find("]: ") {
            if !trimmed[..at].contains("](") {
                targets.push(trimmed[at + 3..].trim().to_owned());
            }
        }
    }
    targets
}

/// GitHub's (and mdBook's) anchor of a heading: the text without code
/// marks and link targets, lower case, letters, digits, `-` and `_` kept,
/// spaces to `-`, everything else dropped.
fn slug(heading: &str) -> String {
    let mut text = heading.replace('`', "");
    // [text](target) → text
    while let Some(mid) = text.find("](") {
        let open = text[..mid].rfind('[').unwrap_or(mid);
        let close = text[mid..].find(')').map_or(text.len(), |c| mid + c + 1);
        text = format!(
            "{}{}{}",
            &text[..open],
            &text[(open + 1).min(mid)..mid],
            &text[close..]
        );
    }
    text.trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

fn anchors(path: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let mut seen = BTreeSet::new();
    let mut out = BTreeSet::new();
    for line in prose_lines(&text) {
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if hashes == 0 || hashes > 6 || !line[hashes..].starts_with(' ') {
            continue;
        }
        let base = slug(&line[hashes..]);
        let mut anchor = base.clone();
        let mut n = 0;
        while seen.contains(&anchor) {
            n += 1;
            anchor = format!("{base}-{n}");
        }
        seen.insert(anchor.clone());
        out.insert(anchor);
    }
    out
}

/// `base/target` with `.` and `..` resolved lexically; `None` if it leaves the
/// repository.
fn resolve(base: &Path, target: &str) -> Option<PathBuf> {
    let root = root();
    let joined = base.join(target);
    let mut parts: Vec<Component> = Vec::new();
    for component in joined.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                parts.pop();
            }
            other => parts.push(other),
        }
    }
    let path: PathBuf = parts.iter().collect();
    path.starts_with(&root).then_some(path)
}

/// A code span that names a path of the repository: starts with a top-level
/// directory, only path characters, no placeholder or wildcard.
fn repository_path(span: &str, top: &BTreeSet<String>) -> bool {
    let Some((first, _)) = span.split_once('/') else {
        return false;
    };
    top.contains(first)
        && span
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-./".contains(c))
        && !span.contains("..")
}

#[test]
fn relative_links_and_quoted_paths_resolve() {
    let root = root();
    let top: BTreeSet<String> = std::fs::read_dir(&root)
        .expect("the repository")
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| !name.starts_with('.') && name != "target")
        .collect();
    let mut broken = Vec::new();
    let files = markdown_files();
    assert!(files.len() > 1, "no Markdown under docs/");
    for file in &files {
        let text = std::fs::read_to_string(file).expect("a Markdown file");
        let shown = file
            .strip_prefix(&root)
            .unwrap_or(file)
            .display()
            .to_string();
        let dir = file.parent().expect("a file has a directory");
        for (n, line) in prose_lines(&text).iter().enumerate() {
            let (spans, rest) = split_code(line);
            for span in spans.iter().filter(|s| repository_path(s, &top)) {
                if !root.join(span).exists() {
                    broken.push(format!("{shown}:{}: `{span}` does not exist", n + 1));
                }
            }
            for target in link_targets(&rest) {
                if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let (path, anchor) = match target.split_once('#') {
                    Some((path, anchor)) => (path, Some(anchor)),
                    None => (target.as_str(), None),
                };
                let resolved = if path.is_empty() {
                    Some(file.clone())
                } else {
                    resolve(dir, path)
                };
                let Some(resolved) = resolved else {
                    broken.push(format!("{shown}:{}: {target} leaves the repository", n + 1));
                    continue;
                };
                if !resolved.exists() {
                    broken.push(format!("{shown}:{}: {target} does not exist", n + 1));
                } else if let Some(anchor) = anchor {
                    let is_md = resolved.extension().is_some_and(|x| x == "md");
                    if is_md && !anchors(&resolved).contains(anchor) {
                        broken.push(format!(
                            "{shown}:{}: no heading for #{anchor} in {path}",
                            n + 1
                        ));
                    }
                }
            }
        }
    }
    assert!(
        broken.is_empty(),
        "broken references:\n{}",
        broken.join("\n")
    );
}

/// The `toml` blocks of a Markdown text, with the line each starts on.
fn toml_blocks(text: &str) -> Vec<(usize, String)> {
    let mut blocks = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (n, line) in text.lines().enumerate() {
        let fence = line.trim_start().starts_with("```");
        match (&mut current, fence) {
            (None, true) if line.trim() == "```toml" => current = Some((n + 1, String::new())),
            (Some(_), true) => blocks.extend(current.take()),
            (Some((_, body)), false) => {
                body.push_str(line);
                body.push('\n');
            }
            _ => {}
        }
    }
    blocks
}

#[test]
fn descriptions_in_the_docs_are_valid() {
    let root = root();
    let dir = TempDir::new("docs-descriptions");
    let mut checked = 0;
    let mut invalid = Vec::new();
    for file in markdown_files() {
        let text = std::fs::read_to_string(&file).expect("a Markdown file");
        let shown = file
            .strip_prefix(&root)
            .unwrap_or(&file)
            .display()
            .to_string();
        for (line, body) in toml_blocks(&text) {
            let complete = body.lines().any(|l| l.starts_with("name ="))
                && body.lines().any(|l| l.starts_with("[coil]"));
            if !complete {
                continue;
            }
            let path = dir.join(format!("{}-{line}.toml", shown.replace('/', "-")));
            std::fs::write(&path, &body).expect("write a description");
            let run = rd!("check", path);
            checked += 1;
            if !run.succeeded() {
                invalid.push(format!("{shown}:{line}: {}", run.stderr.trim()));
            }
        }
    }
    assert!(
        checked >= 2,
        "only {checked} complete descriptions found in the docs"
    );
    assert!(
        invalid.is_empty(),
        "invalid descriptions:\n{}",
        invalid.join("\n")
    );
}

#[test]
fn the_checks_see_what_they_check() {
    // The parsers above on small inputs, so that a check cannot pass by
    // seeing nothing.
    assert_eq!(
        link_targets("see [a](guide/x.md#y) and ![p](img/p.svg \"t\")"),
        ["guide/x.md#y", "img/p.svg"]
    );
    assert_eq!(link_targets("[label]: ../README.md"), ["../README.md"]);
    assert_eq!(
        slug(" `reldesign check`: validate"),
        "reldesign-check-validate"
    );
    assert_eq!(slug(" Closed loop (f64 / f32)"), "closed-loop-f64--f32");
    let (spans, rest) = split_code("run `cli/src/main.rs` [x](y)");
    assert_eq!(
        (spans, rest.as_str()),
        (vec!["cli/src/main.rs"], "run  [x](y)")
    );
    assert_eq!(
        prose_lines("a\n```\n[x](y)\n```\nb"),
        ["a", "", "", "", "b"]
    );
    let top: BTreeSet<String> = ["cli".to_owned()].into();
    assert!(repository_path("cli/src/main.rs", &top));
    assert!(!repository_path("cli/src/*.rs", &top));
    assert!(!repository_path("out/x.rs", &top));
    let blocks = toml_blocks("a\n```toml\nname = 1\n```\n```sh\nx\n```");
    assert_eq!(blocks, [(2, "name = 1\n".to_owned())]);
    assert_eq!(
        subcommands("Commands:\n  check  x\n  help  y\n\nOptions:"),
        ["check"]
    );
    let lines = ["```console", "$ reldesign fit --help", "old", "```"];
    let blocks = help_blocks(&lines);
    assert_eq!(blocks.len(), 1);
    assert_eq!(
        (blocks[0].args.clone(), blocks[0].content.clone()),
        (vec!["fit".to_owned()], 1..3)
    );
}
