//! Every option's range, checked where it enters the library.
//!
//! [`optimize`](crate::optimize::optimize) (and every other entry point: [`compare`],
//! [`sweep`], [`interpolate::sample`], [`write_gcode`]) checks its options and its machine
//! before any work starts, so a library caller gets the same answer the command line gives: an
//! [`Error::InvalidOption`] naming the option's field and what to give instead, or an
//! [`Error::InvalidMachine`] ([`Machine::validate`]). The command line only parses; it names
//! its own flag (`--period`) where the library names the field (`verify.period`).
//!
//! The bounds are here, in one place, with the reasons for them:
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

use crate::compare::CompareOptions;
use crate::error::{Error, Result, number};
use crate::geometry::GeometryOptions;
use crate::machine::Machine;
use crate::optimize::Options;
use crate::solver::SolverSettings;
use crate::solver::jerk::JerkOptions;
use crate::sweep::{MAX_STEPS, SweepOptions};
use crate::verify::VerifyOptions;
use crate::writers::gcode::GcodeOptions;

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
fn non_negative(field: &str, x: f64, unit: &str) -> Result<()> {
    if x.is_finite() && x >= 0.0 {
        return Ok(());
    }
    Err(Error::option(
        field,
        format!("must be a finite number ≥ 0 {unit}, got {}", number(x)),
    ))
}

/// `x` is a finite number > 0.
fn positive(field: &str, x: f64) -> Result<()> {
    if x.is_finite() && x > 0.0 {
        return Ok(());
    }
    Err(Error::option(
        field,
        format!("must be a finite number > 0, got {}", number(x)),
    ))
}

/// A count of at least `min`.
fn at_least(field: &str, n: usize, min: usize, what: &str) -> Result<()> {
    if n >= min {
        return Ok(());
    }
    Err(Error::option(
        field,
        format!("must be at least {min} ({what}), got {n}"),
    ))
}

impl GeometryOptions {
    /// Checks every field's range (module doc); the error names the field.
    pub fn validate(&self) -> Result<()> {
        let a = self.corner_angle_deg;
        if !(a.is_finite() && a > 0.0 && a < 180.0) {
            return Err(Error::option(
                "corner_angle_deg",
                format!(
                    "must be between 0 and 180 degrees (exclusive), got {}",
                    number(a)
                ),
            ));
        }
        non_negative("tolerance_mm", self.tolerance_mm, "mm")?;
        non_negative("tolerance_deg", self.tolerance_deg, "degrees")?;
        if !(MIN_FEED_OVERRIDE..=MAX_FEED_OVERRIDE).contains(&self.feed_override) {
            return Err(Error::option(
                "feed_override",
                format!(
                    "{}: give a factor from {MIN_FEED_OVERRIDE} to {MAX_FEED_OVERRIDE} (1: the \
                     programmed feeds)",
                    number(self.feed_override)
                ),
            ));
        }
        Ok(())
    }
}

impl VerifyOptions {
    /// Checks every field's range (module doc); the error names the field.
    pub fn validate(&self) -> Result<()> {
        period("period", self.period)?;
        non_negative("tolerance", self.tolerance, "(relative)")?;
        if let Some(chord) = &self.chord {
            let d = chord.tolerance;
            if !(d.is_finite() && d >= MIN_CHORD_TOLERANCE_MM) {
                return Err(Error::option(
                    "chord.tolerance",
                    format!(
                        "{} mm: give a chord tolerance of at least {MIN_CHORD_TOLERANCE_MM:e} mm \
                         (1 nm; smaller ones only slow the feed to a crawl)",
                        number(d)
                    ),
                ));
            }
            period("chord.period", chord.period)?;
        }
        Ok(())
    }
}

impl SolverSettings {
    /// Checks every field's range (module doc); the error names the field.
    pub fn validate(&self) -> Result<()> {
        at_least("max_iter", self.max_iter as usize, 1, "iterations")?;
        positive("tol_gap", self.tol_gap)?;
        positive("tol_feas", self.tol_feas)?;
        at_least("window", self.window, 2, "stations per window")?;
        // 0 is allowed: Clarabel stops at once and every window keeps the reach profile.
        if self.time_limit.is_nan() || self.time_limit < 0.0 {
            return Err(Error::option(
                "time_limit",
                format!(
                    "must be 0 s or more (0: the reach profile; infinite: no limit), got {}",
                    number(self.time_limit)
                ),
            ));
        }
        Ok(())
    }
}

impl JerkOptions {
    /// Checks every field's range (module doc); the error names the field.
    pub fn validate(&self) -> Result<()> {
        positive("convergence", self.convergence)?;
        at_least("max_iterations", self.max_iterations, 1, "subproblems")?;
        at_least("window", self.window, 2, "stations per window")
    }
}

impl Options {
    /// Checks every option's range (module doc); the error names the field, e.g.
    /// `verify.period`. [`optimize`](crate::optimize::optimize) calls it (and
    /// [`Options::validate_for`]) before any work.
    pub fn validate(&self) -> Result<()> {
        self.geometry.validate().map_err(|e| e.within("geometry"))?;
        at_least("initial_stations", self.initial_stations, 2, "stations")?;
        at_least("max_stations", self.max_stations, 2, "stations")?;
        if let Some(n) = self.stations {
            at_least("stations", n, 2, "stations")?;
            if n > self.max_stations {
                let max = self.max_stations;
                return Err(Error::option(
                    "stations",
                    format!(
                        "{n} is more than the limit of {max} (memory and time grow with it): \
                         give at most {max}, or none to refine automatically"
                    ),
                ));
            }
        }
        self.solver.validate().map_err(|e| e.within("solver"))?;
        for (field, feed) in [("start_feed", self.start_feed), ("end_feed", self.end_feed)] {
            if !(feed.is_finite() && (0.0..=MAX_END_FEED).contains(&feed)) {
                return Err(Error::option(
                    field,
                    format!(
                        "{} mm/s is outside 0 to {MAX_END_FEED:e} mm/s: give the tool-tip feed in \
                         mm/s (0: at rest)",
                        number(feed)
                    ),
                ));
            }
        }
        let c = self.convergence;
        if !(c > 0.0 && c < 1.0) {
            return Err(Error::option(
                "convergence",
                format!(
                    "must be a relative change between 0 and 1 (exclusive), got {}",
                    number(c)
                ),
            ));
        }
        self.verify.validate().map_err(|e| e.within("verify"))?;
        self.jerk.validate().map_err(|e| e.within("jerk"))
    }

    /// [`Options::validate`], and the options against `machine`: the start and end feeds at
    /// most its maximum feed (no schedule can start or end faster).
    pub fn validate_for(&self, machine: &Machine) -> Result<()> {
        self.validate()?;
        let Some(max) = machine.feed_max else {
            return Ok(());
        };
        for (field, feed) in [("start_feed", self.start_feed), ("end_feed", self.end_feed)] {
            if feed > max {
                return Err(Error::option(
                    field,
                    format!(
                        "{} mm/s is more than the machine's maximum feed (feed.max = {max} mm/s): \
                         give at most {max} mm/s",
                        number(feed)
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// What every solve checks first: `machine` ([`Machine::validate`]) and `options` against it
/// ([`Options::validate_for`]).
pub fn inputs(machine: &Machine, options: &Options) -> Result<()> {
    machine.validate()?;
    options.validate_for(machine)
}

impl CompareOptions {
    /// Checks the solve options (fields under `solve.`) and the junction deviation (module
    /// doc). [`compare`](crate::compare::compare) calls it before any work.
    pub fn validate(&self) -> Result<()> {
        self.solve.validate().map_err(|e| e.within("solve"))?;
        non_negative("junction_deviation", self.junction_deviation, "mm")
    }
}

impl SweepOptions {
    /// Checks the range and steps of the study and its solve options (fields under `solve.`;
    /// module doc). [`sweep`](crate::sweep::sweep) calls it, and checks the axis and the range
    /// against the machine, before any work.
    pub fn validate(&self) -> Result<()> {
        for (field, v) in [("from", self.from), ("to", self.to)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::option(
                    field,
                    format!("must be a positive limit, got {}", number(v)),
                ));
            }
        }
        if self.steps == 0 {
            return Err(Error::option("steps", "must be at least 1"));
        }
        if self.steps > MAX_STEPS {
            return Err(Error::option(
                "steps",
                format!(
                    "{} is more than {MAX_STEPS} (each step is three solves): give at most \
                     {MAX_STEPS}",
                    self.steps
                ),
            ));
        }
        if self.steps > 1 && self.to <= self.from {
            return Err(Error::option(
                "to",
                format!(
                    "({}) must be greater than from ({}) for more than one step",
                    number(self.to),
                    number(self.from)
                ),
            ));
        }
        let h = self.fd_step;
        if !(h > 0.0 && h < 0.5) {
            return Err(Error::option(
                "fd_step",
                format!("must be a relative step in (0, 0.5), got {}", number(h)),
            ));
        }
        self.solve.validate().map_err(|e| e.within("solve"))
    }
}

impl GcodeOptions {
    /// Checks the largest rotation per block (module doc).
    /// [`write_gcode`](crate::writers::gcode::write_gcode) calls it before any work.
    pub fn validate(&self) -> Result<()> {
        match self.max_rotation_deg {
            Some(d) if !(d.is_finite() && d >= MIN_ROTATION_DEG) => Err(Error::option(
                "max_rotation_deg",
                format!(
                    "{}: give at least {MIN_ROTATION_DEG}° (a rotary axis's resolution; smaller \
                     steps only multiply the blocks)",
                    number(d)
                ),
            )),
            _ => Ok(()),
        }
    }
}
