//! Progress on a terminal (cargo feature `progress`, on by default): a spinner for a solve and
//! a bar for a sweep's steps, both drawn on stderr with `indicatif`. A build without the
//! feature (`--no-default-features`) draws nothing and does not link `indicatif`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::optimize::Progress;

/// A spinner on stderr with the solve's stage and refinement rounds: drawn only when stderr is
/// a terminal, and only once the solve has run for a second (short solves print nothing).
/// Pass it to [`optimize_input_observed`](crate::optimize::optimize_input_observed); it clears
/// itself when dropped.
pub struct Spinner {
    bar: indicatif::ProgressBar,
    start: Instant,
    shown: AtomicBool,
}

impl Spinner {
    /// A spinner, hidden until the solve has run for a second.
    pub fn new() -> Spinner {
        let bar = indicatif::ProgressBar::hidden();
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {elapsed:>4} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
        );
        Spinner {
            bar,
            start: Instant::now(),
            shown: AtomicBool::new(false),
        }
    }

    fn show(&self, msg: String) {
        use std::io::IsTerminal;
        self.bar.set_message(msg);
        if self.start.elapsed().as_secs_f64() >= 1.0
            && std::io::stderr().is_terminal()
            && !self.shown.swap(true, Ordering::Relaxed)
        {
            self.bar
                .set_draw_target(indicatif::ProgressDrawTarget::stderr());
            self.bar.enable_steady_tick(Duration::from_millis(120));
        }
    }
}

impl Default for Spinner {
    fn default() -> Self {
        Spinner::new()
    }
}

impl Progress for Spinner {
    fn stage(&self, what: &str) {
        self.show(what.to_string());
    }
    fn round(&self, stations: usize, estimate: f64, target: f64) {
        self.show(format!(
            "refining stations: {stations}, estimated error {estimate:.1e} (target {target:.0e})"
        ));
    }
}

impl Drop for Spinner {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// A bar on stderr counting `len` jobs (a sweep's solves), labelled `message`; cleared when
/// dropped. Safe to advance from several threads.
pub struct Counter {
    bar: indicatif::ProgressBar,
}

impl Counter {
    /// A bar of `len` jobs on stderr.
    pub fn new(len: usize, message: String) -> Counter {
        let bar = indicatif::ProgressBar::with_draw_target(
            Some(len as u64),
            indicatif::ProgressDrawTarget::stderr(),
        );
        bar.set_message(message);
        Counter { bar }
    }

    /// One more job done.
    pub fn inc(&self) {
        self.bar.inc(1);
    }
}

impl Drop for Counter {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
