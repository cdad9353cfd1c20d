//! `design!("valve.toml")`: the reldesign controller of an actuator
//! description, generated while your crate compiles — no build script, no
//! checked-in generated file.
//!
//! The macro runs the same pipeline as `reldesign build` and
//! `reldesign_build::compile` (description → model → feedback linearization →
//! references → feasibility → reference tables → emitted Rust) and splices
//! the emitted module into your crate. All three ways produce the same code,
//! byte for byte.
//!
//! # Usage
//!
//! ```toml
//! # Cargo.toml of the firmware crate
//! [dependencies]
//! reldesign-macros = { path = "…/macros" }
//! reldesign-runtime = { path = "…/runtime" }   # the generated code calls it
//! ```
//!
//! ```ignore
//! #![no_std]
//!
//! // Path relative to this crate's Cargo.toml (its CARGO_MANIFEST_DIR).
//! reldesign_macros::design!("../perfect-tracking-valve.toml");
//! // expands to
//! // pub mod perfect_tracking_valve { macro_rules! params {…} pub mod f32 {…} pub mod f64 {…} }
//!
//! use perfect_tracking_valve::f32::{Controller, Operation};
//!
//! let mut controller = Controller::new(Operation::Closing);
//! controller.start(t_now);
//! // every SAMPLE_PERIOD:
//! let volts = controller.step(t, z, v, phi);
//! ```
//!
//! The module is named after the description's `name` and is `pub`; it
//! holds one submodule per `float` of the `[controller]` section. The
//! emitted code depends only on `reldesign_runtime`, so the calling crate
//! needs that dependency (and can be `#![no_std]`).
//!
//! # Errors
//!
//! Problems are compile errors pointing at the macro's argument:
//!
//! * a file that cannot be read (with the directory the path was resolved
//!   against),
//! * an invalid description, as `valve.toml:LINE:COL: key: what was expected`,
//! * a description without `[trajectory]` and `[controller]` sections,
//! * an infeasible design, with the feasibility report saying which
//!   condition of the paper fails, where, and what to try.
//!
//! # Rebuilds
//!
//! Editing the TOML file re-runs the design on the next `cargo build` (see
//! the `include_bytes!` in the expansion). Designing takes about a second in
//! an unoptimized build; the macro runs whenever the calling crate compiles.
//! If that matters, prefer the `build.rs` route (`reldesign_build::compile`), whose
//! output cargo caches until the description changes.
//!
//! # Choosing between the three ways
//!
//! * `design!` — least ceremony; code is never seen (use `cargo expand` or
//!   `reldesign build` to read it).
//! * `build.rs` + `reldesign_build::compile` + `include!(concat!(env!("OUT_DIR"), "/<name>.rs"))`
//!   — prost-build style, cached by cargo.
//! * `reldesign build --out src/<name>.rs` and commit the file — reviewable,
//!   no generator in the firmware's dependency tree at all.

use std::path::{Path, PathBuf};

use proc_macro2::TokenStream;
use quote::quote;
use syn::{Ident, LitStr};

/// Designs the controller of the actuator description at the given path
/// (relative to the calling crate's `CARGO_MANIFEST_DIR`, or absolute) and
/// expands to `pub mod <name> { … }` with the emitted code. See the
/// [crate documentation](crate).
#[proc_macro]
pub fn design(input: proc_macro::TokenStream) -> proc_macro::TokenStream {
    // Read at expansion time: the manifest directory of the crate being
    // compiled (cargo sets it for rustc), not of this macro crate.
    let manifest_dir = std::env::var_os("CARGO_MANIFEST_DIR").map(PathBuf::from);
    expand(input.into(), manifest_dir.as_deref()).into()
}

/// The expansion of `design!(input)` for a crate rooted at `manifest_dir`;
/// failures become a `compile_error!` spanned at the argument.
fn expand(input: TokenStream, manifest_dir: Option<&Path>) -> TokenStream {
    try_expand(input, manifest_dir).unwrap_or_else(|e| e.to_compile_error())
}

fn try_expand(input: TokenStream, manifest_dir: Option<&Path>) -> syn::Result<TokenStream> {
    let lit: LitStr = syn::parse2(input).map_err(|e| {
        syn::Error::new(
            e.span(),
            "design! expects one string literal: the path of the actuator description, \
             e.g. design!(\"valve.toml\")",
        )
    })?;
    let span = lit.span();
    let relative = lit.value();
    let error = |message: String| syn::Error::new(span, format!("design!: {message}"));

    let base = match manifest_dir {
        Some(dir) => dir,
        None if Path::new(&relative).is_absolute() => Path::new(""),
        None => {
            return Err(error(
                "CARGO_MANIFEST_DIR is not set, so a relative path cannot be resolved: \
                 build with cargo or give an absolute path"
                    .into(),
            ))
        }
    };
    let path = resolve(base, &relative);
    if let Err(e) = std::fs::metadata(&path) {
        let note = if Path::new(&relative).is_absolute() {
            String::new()
        } else {
            format!(
                " (the path `{relative}` is relative to the crate's directory `{}`)",
                base.display()
            )
        };
        return Err(error(format!(
            "cannot read the actuator description `{}`: {e}{note}",
            path.display()
        )));
    }

    let (design, code) = reldesign_build::build_file(&path)
        .map_err(|e| error(e.to_string().trim_end().to_string()))?;

    let name = &design.description.name;
    let module: Ident = syn::parse_str(name).map_err(|_| {
        error(format!(
            "the description's name `{name}` is not a Rust identifier, so it cannot name the module"
        ))
    })?;
    // Tokens parsed from a string carry the call-site span: the code behaves
    // as if written where `design!` is invoked.
    let body: TokenStream = code.parse().map_err(|e| {
        error(format!(
            "the emitted code does not tokenize (a codegen bug): {e}"
        ))
    })?;

    let tracked = path.to_str().ok_or_else(|| {
        error(format!(
            "the path `{}` is not valid UTF-8, which include_bytes! needs",
            path.display()
        ))
    })?;
    let doc = format!(
        " Controller generated at compile time by `reldesign_macros::design!` from `{relative}`."
    );

    Ok(quote! {
        #[doc = #doc]
        pub mod #module {
            #body

            // Rebuild tracking. A proc macro cannot tell cargo which files it
            // read: `proc_macro::tracked_path` is unstable and there is no
            // `cargo:rerun-if-changed` for macros. `include_bytes!` makes rustc
            // record the description in the crate's dep-info, so cargo
            // recompiles (and this macro re-designs) when the TOML changes.
            // The constant is unnamed and unused: nothing reaches the binary.
            const _: &[u8] = ::core::include_bytes!(#tracked);
        }
    })
}

/// `relative` resolved against `base` (an absolute `relative` stays as is);
/// canonical when the file exists, so messages and dep-info show a clean path.
fn resolve(base: &Path, relative: &str) -> PathBuf {
    let joined = base.join(relative);
    if cfg!(windows) {
        // canonicalize() yields `\\?\` paths there; the joined path works as is.
        return joined;
    }
    std::fs::canonicalize(&joined).unwrap_or(joined)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn workspace() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
    }

    /// The expansion's `compile_error!` message, if it is one.
    fn error_of(out: &TokenStream) -> Option<String> {
        let text = out.to_string();
        text.contains("compile_error").then_some(text)
    }

    /// A description file in a fresh temporary directory.
    fn temp_description(name: &str, text: &str) -> (PathBuf, PathBuf) {
        let dir =
            std::env::temp_dir().join(format!("reldesign-macros-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join(format!("{name}.toml"));
        std::fs::write(&file, text).unwrap();
        (dir, file)
    }

    fn example() -> String {
        std::fs::read_to_string(workspace().join("examples/perfect-tracking-valve.toml")).unwrap()
    }

    #[test]
    fn expands_the_example_to_its_module() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
        let out = expand(quote!("../examples/perfect-tracking-valve.toml"), Some(dir));
        assert!(error_of(&out).is_none(), "{out}");
        let text = out.to_string();
        // One public module named after the description, holding the
        // emitted code verbatim and the tracked absolute path.
        assert!(text.contains("pub mod perfect_tracking_valve {"), "{text}");
        // (Byte-identity with `reldesign build` is tested by
        // examples/firmware/tests/agree.rs; designing twice here would double
        // this test's time in the unoptimized host build.)
        for item in ["macro_rules ! params", "pub mod f32 {", "pub mod f64 {"] {
            assert!(text.contains(item), "{item} missing from {text}");
        }
        let tracked =
            std::fs::canonicalize(workspace().join("examples/perfect-tracking-valve.toml"))
                .unwrap();
        let tracked = tracked.to_str().unwrap();
        let include = quote!(::core::include_bytes!(#tracked)).to_string();
        assert!(text.contains(&include), "{text}");
    }

    /// The sliding-mode law goes the same way in: its module, the runtime's
    /// `sliding::SlidingMode` as `Controller`.
    #[test]
    fn expands_the_sliding_mode_example() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
        let out = expand(quote!("../examples/sliding-mode-valve.toml"), Some(dir));
        assert!(error_of(&out).is_none(), "{out}");
        let text = out.to_string();
        assert!(text.contains("pub mod sliding_mode_valve {"), "{text}");
        for item in [
            "pub const LAMBDA1",
            "sliding :: SlidingMode < Design , f32 >",
        ] {
            assert!(text.contains(item), "{item} missing from {text}");
        }
    }

    #[test]
    fn a_missing_file_names_the_resolved_path() {
        let out = expand(
            quote!("no/such/valve.toml"),
            Some(Path::new("/nonexistent-crate")),
        );
        let message = error_of(&out).expect("a compile error");
        assert!(
            message.contains("cannot read the actuator description"),
            "{message}"
        );
        assert!(
            message.contains("/nonexistent-crate/no/such/valve.toml"),
            "{message}"
        );
    }

    #[test]
    fn an_invalid_description_reports_file_line_and_column() {
        let text = example().replace("mass = 2e-3", "mass = -1.0");
        let line = text
            .lines()
            .position(|l| l.starts_with("mass = -1.0"))
            .unwrap()
            + 1;
        let (dir, _) = temp_description("bad_mass", &text);
        let out = expand(quote!("bad_mass.toml"), Some(&dir));
        let message = error_of(&out).expect("a compile error");
        assert!(
            message.contains(&format!("bad_mass.toml:{line}:")),
            "{message}"
        );
        assert!(message.contains("mechanics.mass"), "{message}");
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn an_infeasible_design_is_a_compile_error_with_the_report() {
        let text = example()
            .replace("landing = 6e-3", "landing = 1.2e-3")
            .replace("shape = \"energy-optimal\"", "shape = \"polynomial\"");
        let (dir, _) = temp_description("too_fast", &text);
        let out = expand(quote!("too_fast.toml"), Some(&dir));
        let message = error_of(&out).expect("a compile error");
        assert!(message.contains("infeasible"), "{message}");
        assert!(message.contains("FAIL"), "{message}");
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn a_description_without_design_sections_says_what_to_add() {
        let text = example();
        let text = &text[..text.find("[trajectory]").unwrap()];
        let (dir, _) = temp_description("no_design", text);
        let out = expand(quote!("no_design.toml"), Some(&dir));
        let message = error_of(&out).expect("a compile error");
        assert!(message.contains("nothing to build"), "{message}");
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn the_argument_must_be_one_string_literal() {
        for input in [
            quote!(),
            quote!(valve),
            quote!("a.toml", "b.toml"),
            quote!(42),
        ] {
            let message = error_of(&expand(input, Some(&workspace()))).expect("a compile error");
            assert!(message.contains("one string literal"), "{message}");
        }
    }
}
