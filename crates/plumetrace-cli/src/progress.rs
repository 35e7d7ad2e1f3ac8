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

/// A progress callback `(done, total)` for a loop whose total only the loop knows: the bar is
/// made at the first call and removed at the call with `done >= total`.
pub fn reporter(unit: &'static str) -> impl FnMut(u64, u64) {
    let mut bar: Option<Progress> = None;
    move |done, total| {
        let b = bar.get_or_insert_with(|| Progress::new(total, unit));
        b.tick(done);
        if done >= total {
            b.finish();
        }
    }
}
