//! The `reldesign` binary run as a user runs it: without colour, its exit
//! code and both streams kept, with the assertions every command test makes
//! (success; a clean rejection that names what was wrong and panics never).
//!
//! The binary's path is the caller's: `CARGO_BIN_EXE_reldesign` exists only
//! in the cli crate's tests, where [`rd!`](crate::rd) reads it.

use std::ffi::OsStr;
use std::process::Command;

/// A binary to run.
#[derive(Clone, Copy, Debug)]
pub struct Cli {
    bin: &'static str,
}

impl Cli {
    pub const fn new(bin: &'static str) -> Cli {
        Cli { bin }
    }

    /// Runs the binary with `args`, `NO_COLOR=1` and no forced colour.
    pub fn run<S: AsRef<OsStr>>(&self, args: &[S]) -> Run {
        let out = Command::new(self.bin)
            .args(args)
            .env("NO_COLOR", "1")
            .env_remove("CLICOLOR_FORCE")
            .output()
            .unwrap_or_else(|e| panic!("cannot run {}: {e}", self.bin));
        Run {
            args: args
                .iter()
                .map(|a| a.as_ref().to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join(" "),
            code: out.status.code(),
            stdout: out.stdout,
            stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        }
    }
}

/// Runs `reldesign` with any mix of `&str`, `String`, `Path` and `PathBuf`
/// arguments: `rd!("check", path)`. Only in the cli crate's tests, where
/// cargo sets `CARGO_BIN_EXE_reldesign`.
#[macro_export]
macro_rules! rd {
    ($($arg:expr),* $(,)?) => {
        $crate::Cli::new(env!("CARGO_BIN_EXE_reldesign"))
            .run::<&::std::ffi::OsStr>(&[$(::std::ffi::OsStr::new(&$arg)),*])
    };
}

/// One finished run.
#[derive(Debug)]
pub struct Run {
    /// The arguments, joined by spaces (for messages).
    pub args: String,
    /// The exit code; `None` when a signal ended the process.
    pub code: Option<i32>,
    /// stdout as written (byte-compared with files by some tests).
    pub stdout: Vec<u8>,
    pub stderr: String,
}

impl Run {
    /// Exit code 0.
    pub fn succeeded(&self) -> bool {
        self.code == Some(0)
    }

    /// stdout as text; panics unless it is UTF-8.
    pub fn stdout(&self) -> String {
        String::from_utf8(self.stdout.clone())
            .unwrap_or_else(|_| panic!("stdout is not UTF-8\n{}", self.context()))
    }

    /// The command, its exit code and both streams, for failure messages.
    pub fn context(&self) -> String {
        format!(
            "`reldesign {}` exited with {:?}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.args,
            self.code,
            String::from_utf8_lossy(&self.stdout),
            self.stderr
        )
    }

    /// Exit 0 and no panic text. Returns stdout.
    #[track_caller]
    pub fn ok(&self) -> String {
        assert!(self.succeeded(), "expected success\n{}", self.context());
        assert_no_panic(&self.stderr, &self.context());
        self.stdout()
    }

    /// A clean rejection: a non-zero exit (not a signal), nothing on stdout,
    /// a message and no panic text on stderr, and every needle in it. Needles
    /// are compared [`squeeze`]d, so that a message wrapped by the error
    /// renderer still matches.
    #[track_caller]
    pub fn rejected(&self, needles: &[&str]) {
        self.rejected_in("", needles);
    }

    /// As [`Run::rejected`], with `case` describing the input in the message.
    #[track_caller]
    pub fn rejected_in(&self, case: &str, needles: &[&str]) {
        let ctx = format!("{case}\n{}", self.context());
        match self.code {
            Some(0) => panic!("expected a failure\n{ctx}"),
            None => panic!("killed by a signal\n{ctx}"),
            Some(_) => {}
        }
        assert_no_panic(&self.stderr, &ctx);
        assert!(self.stdout.is_empty(), "stdout must stay empty\n{ctx}");
        assert!(
            !self.stderr.trim().is_empty(),
            "no message on stderr\n{ctx}"
        );
        let stderr = squeeze(&self.stderr);
        for needle in needles {
            assert!(
                stderr.contains(&squeeze(needle)),
                "stderr does not mention {needle:?}\n{ctx}"
            );
        }
    }
}

/// Fails when `stderr` carries a panic message or a backtrace.
#[track_caller]
pub fn assert_no_panic(stderr: &str, ctx: &str) {
    for bad in ["panicked", "RUST_BACKTRACE", "stack backtrace"] {
        assert!(!stderr.contains(bad), "panic text {bad:?} on stderr\n{ctx}");
    }
}

/// `s` without whitespace and without the `│` margin of the error report.
pub fn squeeze(s: &str) -> String {
    s.chars()
        .filter(|c| !c.is_whitespace() && *c != '│')
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn squeeze_drops_whitespace_and_the_report_margin() {
        let wrapped = "  × bad.toml: coil.resistance must\n  │ be positive (Ω)\n";
        assert_eq!(
            squeeze(wrapped),
            "×bad.toml:coil.resistancemustbepositive(Ω)"
        );
        assert!(squeeze(wrapped).contains(&squeeze("must be positive")));
    }

    #[test]
    #[should_panic(expected = "panic text \"panicked\"")]
    fn a_panic_message_fails() {
        assert_no_panic("thread 'main' panicked at src/main.rs:1:1", "ctx");
    }

    fn run(code: Option<i32>, stdout: &str, stderr: &str) -> Run {
        Run {
            args: "check x.toml".into(),
            code,
            stdout: stdout.into(),
            stderr: stderr.into(),
        }
    }

    #[test]
    fn a_clean_rejection_names_every_needle() {
        run(
            Some(1),
            "",
            "error: x.toml: coil.resistance\n  │ must be positive\n",
        )
        .rejected(&["x.toml", "must be positive"]);
    }

    #[test]
    #[should_panic(expected = "stdout must stay empty")]
    fn a_rejection_with_output_fails() {
        run(Some(1), "partial", "error: x.toml").rejected(&[]);
    }

    #[test]
    #[should_panic(expected = "killed by a signal")]
    fn a_signal_is_not_a_rejection() {
        run(None, "", "").rejected(&[]);
    }

    #[test]
    #[should_panic(expected = "does not mention \"y.toml\"")]
    fn a_missing_needle_fails() {
        run(Some(2), "", "error: x.toml").rejected(&["y.toml"]);
    }

    #[test]
    fn a_real_process_is_run_and_its_streams_kept() {
        let cargo = Cli::new(env!("CARGO"));
        let run = cargo.run(&["--version"]);
        assert!(run.ok().starts_with("cargo "), "{}", run.context());
        let bad = cargo.run(&["--no-such-flag"]);
        assert!(
            !bad.succeeded() && !bad.stderr.is_empty(),
            "{}",
            bad.context()
        );
    }
}
