//! Every option's range, checked where it enters the library.
//!
//! [`optimize`](crate::optimize::optimize) (and every other entry point: [`compare`],
//! [`sweep`], [`interpolate::sample`], [`write_gcode`]) checks its options and its machine
//! before any work starts, so a library caller gets the same answer the command line gives: an
//! [`Error::InvalidOption`] naming the option's field and what to give instead, or an
//! [`Error::InvalidMachine`] ([`Machine::validate`]). The command line only parses; it names
//! its own flag (`--period`) where the library names the field (`verify.period`).
//!
//! The bounds are here, in one place, with the reasons for them, and the checks they share
//! ([`period`] and the crate's own range checks); each options type's `validate` stands beside
//! the type and calls them, so this module sits below every stage that has options (issue 15:
//! no loop between modules):
//!
//! | option | range |
//! |---|---|
//! | `geometry.corner_angle_deg` | between 0 and 180 degrees, exclusive |
//! | `geometry.tolerance_mm`, `geometry.tolerance_deg` | finite, ≥ 0 |
//! | `geometry.feed_override` | [`MIN_FEED_OVERRIDE`] to [`MAX_FEED_OVERRIDE`] |
//! | `stations` | 2 to `max_stations` |
//! | `start_feed`, `end_feed` | 0 to [`MAX_END_FEED`] mm/s, and at most the machine's `feed.max` |
//! | `convergence` | between 0 and 1, exclusive |
//! | `initial_stations`, `max_stations` | at least 2 |
//! | `verify.period` (and `chord.period`) | [`MIN_PERIOD_S`] to [`MAX_PERIOD_S`] |
//! | `verify.tolerance` | finite, ≥ 0 |
//! | `verify.chord.tolerance` | at least [`MIN_CHORD_TOLERANCE_MM`] |
//! | `solver.max_iter` | at least 1 |
//! | `solver.tol_gap`, `solver.tol_feas` | finite, > 0 |
//! | `solver.window`, `jerk.window` | at least 2 stations |
//! | `solver.time_limit` | ≥ 0 s (may be infinite) |
//! | `jerk.convergence` | finite, > 0 |
//! | `jerk.max_iterations` | at least 1 |
//! | compare: `junction_deviation` | finite, ≥ 0 mm |
//! | sweep: `from`, `to` | finite, > 0, `to > from` for more than one step; within 1/[`MAX_SWEEP_FACTOR`] to [`MAX_SWEEP_FACTOR`] times the machine's limit |
//! | sweep: `steps` | 1 to [`MAX_STEPS`] |
//! | sweep: `fd_step` | between 0 and 0.5, exclusive |
//! | sweep: `axis` | an axis of the machine |
//! | G-code: `max_rotation_deg` | at least [`MIN_ROTATION_DEG`] |
//! | interpolation `period` | [`MIN_PERIOD_S`] to [`MAX_PERIOD_S`] |
//!
//! [`compare`]: crate::compare::compare
//! [`sweep`]: crate::sweep::sweep
//! [`interpolate::sample`]: crate::interpolate::sample
//! [`write_gcode`]: crate::writers::gcode::write_gcode
//! [`Machine::validate`]: crate::machine::Machine::validate
//! [`MAX_SWEEP_FACTOR`]: crate::sweep::MAX_SWEEP_FACTOR
//! [`MAX_STEPS`]: crate::sweep::MAX_STEPS

use crate::error::{Error, Result, number};

/// The shortest servo period feedopt re-simulates (and interpolates) at: 1 µs. The
/// re-simulation's work is the cycle time divided by the period.
pub const MIN_PERIOD_S: f64 = 1e-6;

/// The longest servo period: 1 s.
pub const MAX_PERIOD_S: f64 = 1.0;

/// The smallest chord tolerance: 1 nm, below any machine's resolution (smaller ones only slow
/// the feed to a crawl).
pub const MIN_CHORD_TOLERANCE_MM: f64 = 1e-6;

/// The largest start or end feed: 1e6 mm/s (1 km/s).
pub const MAX_END_FEED: f64 = 1e6;

/// The smallest feed override: a factor below 0.001 slows the feed to a crawl (and the
/// re-simulation's work grows with the cycle time).
pub const MIN_FEED_OVERRIDE: f64 = 1e-3;

/// The largest feed override: above 1000 it caps nothing.
pub const MAX_FEED_OVERRIDE: f64 = 1e3;

/// The smallest rotation per G-code block: 0.001°, a rotary axis's resolution; smaller steps
/// only multiply the program's blocks.
pub const MIN_ROTATION_DEG: f64 = 1e-3;

/// A servo or interpolation period `period` (s) named `field`, within [`MIN_PERIOD_S`] to
/// [`MAX_PERIOD_S`].
pub fn period(field: &str, period: f64) -> Result<()> {
    if (MIN_PERIOD_S..=MAX_PERIOD_S).contains(&period) {
        return Ok(());
    }
    Err(Error::option(
        field,
        format!(
            "{} s is outside {MIN_PERIOD_S:e} s to {MAX_PERIOD_S} s (1 µs to 1 s; the \
             re-simulation takes cycle time ÷ period steps): give e.g. 0.001 s (1 ms) or \
             0.00025 s",
            number(period)
        ),
    ))
}

/// `x` is a finite number ≥ 0.
pub(crate) fn non_negative(field: &str, x: f64, unit: &str) -> Result<()> {
    if x.is_finite() && x >= 0.0 {
        return Ok(());
    }
    Err(Error::option(
        field,
        format!("must be a finite number ≥ 0 {unit}, got {}", number(x)),
    ))
}

/// `x` is a finite number > 0.
pub(crate) fn positive(field: &str, x: f64) -> Result<()> {
    if x.is_finite() && x > 0.0 {
        return Ok(());
    }
    Err(Error::option(
        field,
        format!("must be a finite number > 0, got {}", number(x)),
    ))
}

/// A count of at least `min`.
pub(crate) fn at_least(field: &str, n: usize, min: usize, what: &str) -> Result<()> {
    if n >= min {
        return Ok(());
    }
    Err(Error::option(
        field,
        format!("must be at least {min} ({what}), got {n}"),
    ))
}
