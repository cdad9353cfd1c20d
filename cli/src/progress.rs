//! Progress of the long commands (`fit`, `robustness`'s Monte Carlo,
//! `diagnose --batch`) on stderr, written once: an indicatif bar with the
//! rate and the time left, drawn only when stderr is a terminal. Pipes and
//! files get no redraws, only the lines meant to stay (a batch's one line per
//! record).

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar of `len` steps, counted in `unit` (e.g. "draws"), from any thread.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar of `len` steps of `unit`: hidden unless stderr is a terminal.
    pub fn new(len: u64, unit: &str) -> Progress {
        let bar = ProgressBar::new(len);
        if !std::io::stderr().is_terminal() {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        let template = format!(
            "[{{elapsed_precise}}] {{bar:30}} {{pos}}/{{len}} {unit} \
             ({{per_sec}}, {{eta}} left) {{msg}}"
        );
        if let Ok(style) = ProgressStyle::with_template(&template) {
            bar.set_style(style.progress_chars("=> "));
        }
        Progress { bar }
    }

    /// One more step done.
    pub fn inc(&self) {
        self.bar.inc(1);
    }

    /// The text after the counts (e.g. the current objective).
    pub fn message(&self, text: String) {
        self.bar.set_message(text);
    }

    /// A line that stays: above the bar on a terminal, on stderr otherwise.
    pub fn println(&self, line: &str) {
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    /// The bar removed, its lines kept.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
