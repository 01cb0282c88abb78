//! A progress bar over simulated time, drawn only when stderr is a terminal.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

/// Progress of a run in simulated seconds.
#[derive(Debug)]
pub struct SimProgress {
    bar: Option<ProgressBar>,
}

impl SimProgress {
    /// A bar for `total_s` simulated seconds, labelled `label`; hidden unless stderr is a
    /// terminal and `enabled`.
    pub fn new(label: &str, total_s: f64, enabled: bool) -> Self {
        if !enabled || !std::io::stderr().is_terminal() {
            return Self { bar: None };
        }
        let bar = ProgressBar::new((total_s * 1000.0).max(1.0) as u64);
        if let Ok(style) = ProgressStyle::with_template("{prefix} [{bar:40}] {msg} (eta {eta})") {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_prefix(label.to_owned());
        Self { bar: Some(bar) }
    }

    /// Reports simulated time `t_s`.
    pub fn set(&self, t_s: f64) {
        if let Some(bar) = &self.bar {
            bar.set_position((t_s * 1000.0) as u64);
            bar.set_message(format!("{t_s:.1} s"));
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
