//! The checks [`optimize`](super::optimize) makes before any work: the options' ranges (the
//! table in [`crate::validate`]) and the machine. Beside `optimize.rs` so that the library's
//! lower modules can share the range checks of [`crate::validate`] without a loop.

use crate::base::{MAX_AXES, PATH_DIM};
use crate::error::{Error, Result, number};
use crate::kinematics::Kinematics;
use crate::machine::Machine;
use crate::toolpath::Toolpath;
use crate::validate::{MAX_END_FEED, at_least};

use super::Options;

impl Options {
    /// Checks every option's range ([`crate::validate`]); the error names the field, e.g.
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

/// Every CL point within every axis's travel (`angles`: the rotary angles the kinematics chose
/// for the points, radians), or an error naming the program line and the axis: checked before
/// the path is fitted, so that a point off the machine fails at once rather than after the
/// smoothing and the solve (the stations are checked again, [`super::Plan`]).
pub fn travel(
    machine: &Machine,
    kin: &Kinematics,
    toolpath: &Toolpath,
    angles: &[[f64; 2]],
) -> Result<()> {
    if machine.axes.iter().all(|a| a.travel.is_none()) {
        return Ok(());
    }
    for (p, a) in toolpath.points.iter().zip(angles) {
        let mut w = [0.0; PATH_DIM];
        w[..5].copy_from_slice(&[p.p.x, p.p.y, p.p.z, a[0], a[1]]);
        let mut q = [0.0; MAX_AXES];
        kin.axis_positions(w, &mut q);
        for (j, axis) in machine.axes.iter().enumerate() {
            if let Some((lo, hi)) = axis.travel_exceeded(q[j]) {
                return Err(Error::Infeasible(format!(
                    "{}:{}: axis {} would be at {:.4} here, outside its travel [{lo}, {hi}]; \
                     check the program's work offset and units, or the travel in the machine \
                     file",
                    toolpath.source.display(),
                    p.line,
                    axis.name,
                    q[j]
                )));
            }
        }
    }
    Ok(())
}
