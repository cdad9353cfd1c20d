//! A test, not a command: every `reldesign …` line in a shell fence of
//! README.md and `docs/**/*.md` (```sh, ```console, ```bash; also `cargo
//! run … -p reldesign -- …`) must parse with this binary's clap definitions,
//! so no documented command falls behind a renamed or removed option. A
//! synopsis (with `[optional]` parts, `a|b` or `…`) is checked for its
//! subcommand and option names only.

use std::path::{Path, PathBuf};

use clap::{CommandFactory, Parser};

use super::Cli;

/// One documented command: where, and its words after `reldesign`.
struct Line {
    place: String,
    text: String,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for path in entries.flatten().map(|e| e.path()) {
        if path.is_dir() {
            markdown_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "md") {
            out.push(path);
        }
    }
}

/// The shell fences' lines of `text`, `\` continuations joined, each with
/// its first line's number.
fn shell_lines(text: &str) -> Vec<(usize, String)> {
    let mut out: Vec<(usize, String)> = Vec::new();
    let (mut fence, mut continued) = (None::<bool>, false);
    for (k, line) in text.lines().enumerate() {
        let trimmed = line.trim();
        if let Some(lang) = trimmed.strip_prefix("```") {
            fence = match fence {
                Some(_) => None,
                None => Some(matches!(lang.trim(), "sh" | "console" | "bash")),
            };
            continued = false;
            continue;
        }
        if fence != Some(true) {
            continue;
        }
        let body = trimmed.strip_suffix('\\').map(str::trim_end);
        let words = body.unwrap_or(trimmed);
        match out.last_mut() {
            Some((_, last)) if continued => *last = format!("{last} {words}"),
            _ => out.push((k + 1, words.strip_prefix("$ ").unwrap_or(words).to_owned())),
        }
        continued = body.is_some();
    }
    out
}

/// The line without a trailing `# comment`.
fn uncommented(line: &str) -> &str {
    match line.find(" #") {
        Some(i) => line[..i].trim_end(),
        None => line,
    }
}

/// The arguments after the program name, if `line` runs reldesign.
fn reldesign_args(line: &str) -> Option<&str> {
    let line = uncommented(line);
    if let Some(rest) = line.strip_prefix("reldesign ") {
        return Some(rest);
    }
    let runs_cli = line.starts_with("cargo run") && line.contains("-p reldesign ");
    runs_cli.then(|| line.split_once(" -- ").map(|(_, args)| args))?
}

fn documented_lines() -> Vec<Line> {
    let mut files = vec![root().join("README.md")];
    markdown_files(&root().join("docs"), &mut files);
    files.sort();
    let mut out = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).expect("readable markdown");
        let name = file
            .strip_prefix(root())
            .unwrap_or(&file)
            .display()
            .to_string();
        for (number, line) in shell_lines(&text) {
            if let Some(args) = reldesign_args(&line) {
                let place = format!("{}:{number}", name.trim_start_matches("../"));
                out.push(Line {
                    place,
                    text: args.to_owned(),
                });
            }
        }
    }
    out
}

/// Words as a shell splits them (single and double quotes, no escapes).
fn words(text: &str) -> Vec<String> {
    let (mut out, mut word, mut quote) = (Vec::new(), None::<String>, None);
    for c in text.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.get_or_insert_with(String::new).push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                word.get_or_insert_with(String::new);
            }
            (None, c) if c.is_whitespace() => out.extend(word.take()),
            (None, c) => word.get_or_insert_with(String::new).push(c),
        }
    }
    out.extend(word);
    out
}

fn is_synopsis(text: &str) -> bool {
    text.contains('[') || text.contains('…') || text.contains('|')
}

/// Why a synopsis is stale: its subcommand or one of its `--options` is unknown.
fn synopsis_problem(text: &str) -> Option<String> {
    let words = words(text);
    let name = words.first()?;
    let cli = Cli::command();
    let Some(sub) = cli.find_subcommand(name) else {
        return Some(format!("no subcommand `{name}`"));
    };
    let known: Vec<String> = sub
        .get_arguments()
        .filter_map(|a| a.get_long().map(str::to_owned))
        .chain(["help".to_owned()])
        .collect();
    words
        .iter()
        .map(|w| w.trim_start_matches('['))
        .filter_map(|w| w.strip_prefix("--"))
        .map(|w| w.split(['=', ']']).next().unwrap_or(w))
        .find(|option| !known.iter().any(|k| k == option))
        .map(|option| format!("`{name}` has no option `--{option}`"))
}

/// Why a command does not parse, if it does not.
fn problem(text: &str) -> Option<String> {
    if is_synopsis(text) {
        return synopsis_problem(text);
    }
    let argv = std::iter::once("reldesign".to_owned()).chain(words(text));
    match Cli::try_parse_from(argv) {
        Ok(_) => None,
        Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelp => None,
        Err(e) => Some(e.to_string().lines().next().unwrap_or_default().to_owned()),
    }
}

#[test]
fn every_documented_command_parses() {
    let lines = documented_lines();
    assert!(lines.len() > 20, "found only {} commands", lines.len());
    let stale: Vec<String> = lines
        .iter()
        .filter_map(|l| {
            problem(&l.text).map(|p| format!("{}: reldesign {}\n  {p}", l.place, l.text))
        })
        .collect();
    assert!(stale.is_empty(), "stale commands:\n{}", stale.join("\n"));
}

#[test]
fn a_stale_command_is_caught() {
    assert!(problem("loop valve.toml --out a.csv --plot a.svg").is_none());
    assert!(problem("loop valve.toml --no-such-option").is_some());
    assert!(problem("fit M.toml D.csv [--no-such-option N]").is_some());
    assert!(problem("nonsense").is_some());
    assert_eq!(
        reldesign_args("cargo run --release -p reldesign -- build v.toml  # why"),
        Some("build v.toml")
    );
}
