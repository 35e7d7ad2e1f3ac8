//! A progress bar on standard error, shown only when it is a terminal.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Progress of a long loop; invisible when standard error is not a terminal.
pub struct Progress {
    bar: ProgressBar,
    every: u64,
}

impl Progress {
    /// A bar for `total` units named `unit`.
    pub fn new(total: u64, unit: &str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr_with_hz(4));
        let template = format!("{{bar:40}} {{pos}}/{{len}} {unit} ({{per_sec}}, eta {{eta}})");
        if let Ok(style) = ProgressStyle::with_template(&template) {
            bar.set_style(style);
        }
        Progress {
            bar,
            every: (total / 1000).max(1),
        }
    }

    /// Records that `done` units are finished (cheap: updates the bar every 0.1 % only).
    pub fn tick(&self, done: u64) {
        if done.is_multiple_of(self.every) {
            self.bar.set_position(done);
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
