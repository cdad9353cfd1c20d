//! The checked-in generated code is what `reldesign build` emits today
//! (rust-analyzer style): regenerates every module from its example and fails
//! when one is stale. `UPDATE_GENERATED=1` rewrites stale files instead.

use std::path::PathBuf;

use support::{example_paths, root};

/// Examples with design sections (controller or observer), and the module
/// each one generates.
fn designed_examples() -> Vec<(PathBuf, String)> {
    let mut out = Vec::new();
    for path in example_paths() {
        let d = designer::description::parse_file(&path).unwrap_or_else(|e| panic!("{e}"));
        if d.controller.is_some() || d.observer.is_some() {
            out.push((path, d.name));
        }
    }
    out
}

#[test]
fn generated_code_is_fresh() {
    let update = std::env::var_os("UPDATE_GENERATED").is_some_and(|v| v == "1");
    let lib = std::fs::read_to_string(root().join("generated/src/lib.rs")).expect("lib.rs");
    let mut stale = Vec::new();
    let designed = designed_examples();
    assert!(!designed.is_empty(), "no example carries design sections");
    for (example, name) in designed {
        let (_, code) = reldesign_build::build_file(&example).unwrap_or_else(|e| panic!("{e}"));
        let target = root().join("generated/src").join(format!("{name}.rs"));
        if std::fs::read_to_string(&target).ok().as_deref() != Some(code.as_str()) {
            if update {
                reldesign_build::write_if_changed(&target, &code).unwrap_or_else(|e| panic!("{e}"));
                eprintln!("updated {}", target.display());
            } else {
                stale.push(target.display().to_string());
            }
        }
        assert!(
            lib.contains(&format!("pub mod {name};")),
            "generated/src/lib.rs does not declare `pub mod {name};`"
        );
    }
    assert!(stale.is_empty(), "stale generated code: {stale:?}\nrun `UPDATE_GENERATED=1 cargo test -p reldesign-generated` and commit the result");
}
