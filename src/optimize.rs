//! The pipeline, end to end: machine + toolpath in, time-optimal [`Solution`] out.
//!
//! toolpath → kinematics (rotary angles on one branch) → geometry (spans, splines) →
//! constraints (rows on b = u̇² at stations) → solver (Clarabel) → schedule (eq. 43).
//!
//! Every CL point is a station, and each CL segment is divided further (see
//! [`constraints::stations`](crate::constraints::stations)). Unless a station count is given,
//! the stations are refined adaptively (`Plan::solve_adaptive`): each round compares every
//! span's grid with its bisection by the O(N) reach pass, halves only the intervals whose time
//! changes most, and puts a station where a ramp ends inside an interval, until the change
//! summed over the path is below [`Options::convergence`] (1e-4) of the cycle time; that sum
//! is returned as [`Solution::error_estimate`]. The final grid is then solved exactly
//! ([`solver::optimal`]: the lattice relaxation where it is exact, Clarabel on the windows
//! where it is not). Jerk-limited solves refine the same way with the SCP as the solver of
//! both grids (`Plan::solve_adaptive_jerk`), to 1e-3 (10 × the SCP's own tolerance).
//!
//! Every schedule is then re-simulated at the servo period ([`crate::verify`]); one that exceeds
//! any limit by more than the tolerance (0.1 %) between stations is not returned: the
//! intervals where the check failed are split (their midpoints become stations) and the spans
//! concerned solved again, until it verifies; on a grid the user fixed, that grid stays and
//! only those stations are added.

use crate::constraints::{Bound, Grid, SpanProblem};
use crate::error::{Error, Result};
use crate::geometry::{GeometryOptions, Path, Span, SpanKind};
use crate::kinematics::Kinematics;
use crate::machine::{KinematicsSpec, Machine};
use crate::schedule::Schedule;
use crate::solver::interval_times;
use crate::solver::jerk::{JerkData, JerkOptions, MidBounds, Warm};
use crate::solver::{self, SolverKind, SolverSettings, SpanSolution, Status};
use crate::toolpath::joint_csv::JointPath;
use crate::toolpath::{Input, Toolpath};
use crate::verify::{Quantity, Verification, VerifyOptions, Violation, verify_marked};

mod checks;
mod reuse;
pub(crate) use checks::inputs as check_inputs;

/// Options of a solve.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    pub geometry: GeometryOptions,
    /// Station intervals over the whole path (at least; every CL point is also a station);
    /// `None`: choose automatically.
    pub stations: Option<usize>,
    pub solver: SolverSettings,
    /// Which solver computes the profile.
    pub solver_kind: SolverKind,
    /// Tool-tip feed at the start of the path and at its end, mm/s (0: at rest). Inner span
    /// boundaries are exact stops.
    pub start_feed: f64,
    pub end_feed: f64,
    /// Relative change of the cycle time under doubling the stations that counts as converged.
    /// 1e-4 by default: at 1e-3 the refinement can stop where the cycle time only pauses, e.g.
    /// on p2, where below about three stations per CL segment in its tight corners the reach
    /// pass lags the optimum by 8e-4 and both pass a 1e-3 test before converging for real.
    pub convergence: f64,
    /// Stations to start the automatic refinement from.
    pub initial_stations: usize,
    /// Refinement stops with an error beyond this many stations.
    pub max_stations: usize,
    /// Re-simulation of the schedule (servo period, tolerance).
    pub verify: VerifyOptions,
    /// Add stations until the re-simulation verifies (default). When false, the schedule of the
    /// first converged (or the fixed) grid is returned as it is, with its verification: for
    /// like-for-like comparisons with other solvers on their grid. The CLI always refines.
    pub refine_until_verified: bool,
    /// Rounds of local refinement before the spans still over a limit are slowed down
    /// instead ([`Solution::slowed_down`]); default 12.
    pub local_rounds: usize,
    /// Honour the machine's jerk limits (when it has any; issue 6). When false, the jerk limits
    /// are dropped from the machine for the whole solve (an acceleration-limited schedule).
    pub jerk_limited: bool,
    /// The sequential convex programme of a jerk-limited solve.
    pub jerk: JerkOptions,
    /// Process feed caps from the material stage ([`crate::material::FeedLimits`], computed
    /// on the same toolpath): attached to the spans before the constraints are built.
    pub process: Option<std::sync::Arc<crate::material::FeedLimits>>,
    /// How ü varies between stations of an acceleration-limited profile: linearly (the
    /// default, second order in Δu) or constant per interval, the discretisation of seed 000
    /// that COPP's solvers state (for like-for-like comparisons with them on their grid).
    pub ramp: crate::constraints::Ramp,
    /// Solve each distinct span problem once and give its answer to every span that poses
    /// the same one (a drilling cycle's moves at every hole): the same schedule, bit for bit,
    /// as solving each (see `reuse`). Default on.
    pub reuse_spans: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            geometry: GeometryOptions::default(),
            stations: None,
            solver: SolverSettings::default(),
            solver_kind: SolverKind::default(),
            start_feed: 0.0,
            end_feed: 0.0,
            convergence: 1e-4,
            initial_stations: 1000,
            max_stations: 4_000_000,
            verify: VerifyOptions::default(),
            refine_until_verified: true,
            local_rounds: MAX_LOCAL_ROUNDS,
            jerk_limited: true,
            jerk: JerkOptions::default(),
            process: None,
            reuse_spans: true,
            ramp: Default::default(),
        }
    }
}

/// Where a long solve is, for a front end that shows it (the CLI draws a progress bar). Every
/// method has an empty default; calls come from the thread that runs the solve.
pub trait Progress: Sync {
    /// A new stage begins (`"refining stations"`, `"solving"`, `"verifying at 1 ms"`, …).
    fn stage(&self, _what: &str) {}
    /// A refinement round ended: `stations` in all, the estimated relative error `estimate`,
    /// and the `target` it must reach.
    fn round(&self, _stations: usize, _estimate: f64, _target: f64) {}
}

/// Reports nothing.
pub struct Silent;

impl Progress for Silent {}

/// One step of the automatic refinement.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Refinement {
    pub stations: usize,
    pub cycle_time_s: f64,
}

/// Everything a solve produced.
#[derive(Debug, Clone)]
pub struct Solution {
    pub path: Path,
    pub kinematics: Kinematics,
    pub problems: Vec<SpanProblem>,
    pub solutions: Vec<SpanSolution>,
    pub schedule: Schedule,
    /// The worst status over all spans.
    pub status: Status,
    /// Interior-point iterations, summed over spans (final station count).
    pub iterations: u32,
    /// Solver time, summed over spans (final station count), s.
    pub solve_time: f64,
    /// Station counts tried and their cycle times.
    pub refinement: Vec<Refinement>,
    /// Estimated relative error of the cycle time against the continuous optimum (automatic
    /// refinement only; `None` on a fixed grid). Acceleration-limited: the change of the time,
    /// summed over intervals, when every interval of the returned grid's parent is halved,
    /// which bounds the returned grid's remaining error wherever the error falls at least
    /// linearly with the interval length (Richardson). Jerk-limited: the relative change of
    /// the time from the last uniform level to the returned one.
    pub error_estimate: Option<f64>,
    /// The relative error the automatic refinement aimed at (`None` on a fixed grid).
    pub error_target: Option<f64>,
    /// Why the automatic refinement stopped with its estimate above [`Self::error_target`],
    /// if it did. The schedule is verified all the same; the estimate says how far its cycle
    /// time may be from the continuous optimum.
    pub unconverged: Option<String>,
    /// Where the local refinement did not settle within its rounds and the spans still over
    /// a limit were slowed down instead (each by the least factor that keeps every limit):
    /// how many, by how much, and the time it cost. The schedule keeps every limit; its time
    /// is that much above what the stations would give, which the error estimate includes.
    pub slowed_down: Option<String>,
    /// The re-simulation of the returned schedule at the servo period.
    pub verification: Verification,
    /// Its servo period, s.
    pub verify_period: f64,
    /// Corners blended within [`GeometryOptions::corner_tolerance_mm`] instead of stopped at.
    pub corners_blended: usize,
    /// Span solves answered by an earlier solve of the same problem ([`Options::reuse_spans`]),
    /// over every round of the refinement.
    pub reused_solves: usize,
}

impl Solution {
    /// Total number of stations.
    pub fn stations(&self) -> usize {
        self.schedule.stations.len()
    }
}

/// Computes the time-optimal schedule of `toolpath` on `machine`.
pub fn optimize(machine: &Machine, toolpath: &Toolpath, options: &Options) -> Result<Solution> {
    optimize_observed(machine, toolpath, options, &Silent)
}

/// [`optimize`], telling `progress` where it is.
pub fn optimize_observed(
    machine: &Machine,
    toolpath: &Toolpath,
    options: &Options,
    progress: &dyn Progress,
) -> Result<Solution> {
    checks::inputs(machine, options)?;
    if machine.kinematics == KinematicsSpec::Joint {
        return Err(Error::Usage(format!(
            "{}: a CL toolpath needs a machine with kinematics (xyz, head_head), not a \
             joint-space machine",
            toolpath.source.display()
        )));
    }
    if options.geometry.corner_tolerance_mm > 0.0 && options.jerk_limited && machine.has_jerk() {
        // The jerk-limited SCP is ill-conditioned on the short, tightly curved blends next to
        // long moves: on seeded random polylines its subproblems ran into Clarabel's iteration
        // cap (1,200+ interior-point iterations a window) and a 20-move path took minutes,
        // where exact stops take 0.2 s. And a blend gains little under jerk limits: it is
        // passed at V ~ (j ε²)^(1/3).
        return Err(Error::Usage(
            "--corner-tolerance with jerk limits is not supported yet (the jerk-limited solve \
             is ill-conditioned on the blends' short, tight curves): drop the jerk limits with \
             --no-jerk, or the corner tolerance"
                .into(),
        ));
    }
    let kin = Kinematics::new(machine);
    // Corners blended within the contour tolerance, when one is given.
    let (blended, corners_blended) = crate::geometry::blend::blend_corners(
        toolpath,
        options.geometry.corner_tolerance_mm,
        options.geometry.corner_angle_deg,
    );
    let toolpath: &Toolpath = &blended;
    let angles = kin.rotary_angles(&toolpath.points, &machine.axes)?;
    checks::travel(machine, &kin, toolpath, &angles)?;
    let mut path = Path::build(
        toolpath,
        &angles,
        machine.feed_max,
        kin.uses_orientation(),
        matches!(kin, Kinematics::Dresser(_)),
        machine.kinematics.machine_coordinates(),
        &options.geometry,
    )?;
    if path.spans.is_empty() {
        return Err(Error::parse(
            &toolpath.source,
            toolpath.points.first().map_or(1, |p| p.line),
            "no motion: every CL point is at the same position",
        ));
    }
    if let Some(limits) = &options.process {
        limits.attach(&mut path, toolpath, machine.feed_max)?;
    }
    let mut solution = optimize_path(machine, path, options, progress)?;
    solution.corners_blended = corners_blended;
    Ok(solution)
}

/// Computes the time-optimal schedule of a joint-space path (axis positions along s) on a
/// machine of kinematics `joint`. The feed options are path speeds ds/dt there.
pub fn optimize_joint(machine: &Machine, path: &JointPath, options: &Options) -> Result<Solution> {
    optimize_joint_observed(machine, path, options, &Silent)
}

/// [`optimize_joint`], telling `progress` where it is.
pub fn optimize_joint_observed(
    machine: &Machine,
    path: &JointPath,
    options: &Options,
    progress: &dyn Progress,
) -> Result<Solution> {
    checks::inputs(machine, options)?;
    if machine.kinematics != KinematicsSpec::Joint {
        return Err(Error::Usage(format!(
            "{}: a joint-space path needs a machine file with \"kinematics\": {{\"type\": \"joint\"}}",
            path.source.display()
        )));
    }
    optimize_path(machine, Path::from_joint(path, machine)?, options, progress)
}

/// Computes the time-optimal schedule of any input.
pub fn optimize_input(machine: &Machine, input: &Input, options: &Options) -> Result<Solution> {
    optimize_input_observed(machine, input, options, &Silent)
}

/// [`optimize_input`], telling `progress` where it is.
pub fn optimize_input_observed(
    machine: &Machine,
    input: &Input,
    options: &Options,
    progress: &dyn Progress,
) -> Result<Solution> {
    match input {
        Input::Cl(t) => optimize_observed(machine, t, options, progress),
        Input::Joint(j) => optimize_joint_observed(machine, j, options, progress),
    }
}

/// The refinement loop over a built path.
fn optimize_path(
    machine: &Machine,
    path: Path,
    options: &Options,
    progress: &dyn Progress,
) -> Result<Solution> {
    let unlimited;
    let machine = if options.jerk_limited || !machine.has_jerk() {
        machine
    } else {
        unlimited = machine.without_jerk();
        &unlimited
    };
    // A path of one span has no other span to share an answer with (each refinement solves it
    // on other stations): its keys, every input's bits, would only be built and dropped (2.5 %
    // of a COPP path's jerk-limited solve).
    let reuse = reuse::Reuse::new(options.reuse_spans && path.spans.len() > 1);
    let mid_bounds = (0..path.spans.len()).map(|_| Default::default()).collect();
    let plan = Plan {
        machine,
        weights: span_weights(&path),
        axes: machine.axes.iter().map(|a| a.name.clone()).collect(),
        kin: Kinematics::new(machine),
        path,
        progress,
        reuse,
        mid_bounds,
    };
    let (mut unconverged, mut error_target) = (None, None);
    let (mut lv, mut refinement, error_estimate) = match options.stations {
        Some(total) => {
            let lv = plan.solve_at(total, options)?;
            let r = Refinement {
                stations: lv.schedule.stations.len(),
                cycle_time_s: lv.schedule.cycle_time,
            };
            (lv, vec![r], None)
        }
        None => {
            let a = if plan.machine.has_jerk() {
                plan.solve_adaptive_jerk(options)?
            } else {
                plan.solve_adaptive(options)?
            };
            unconverged = a.unconverged;
            error_target = Some(a.target);
            (a.level, a.refinement, Some(a.estimate))
        }
    };
    plan.progress.stage(&format!(
        "verifying {} stations at {} ms",
        lv.schedule.stations.len(),
        options.verify.period * 1e3
    ));
    // Intervals within LOCAL_MARK of the tolerance are divided with the violating ones.
    let mark = LOCAL_MARK * options.verify.tolerance;
    let (mut v, mut marks) = plan.verify_marked(&lv, options, mark)?;
    let mut round = 0;
    let n_spans = lv.problems.len();
    // Per span, its worst excess over a limit in the last verifications ([`diverging`]).
    let mut excess: Vec<Vec<f64>> = vec![Vec::new(); n_spans];
    record_excess(&mut excess, &v);
    // Spans slowed down instead of refined, each one's slow-down factor so far, and the time
    // the slow-downs cost.
    let mut frozen = vec![false; n_spans];
    let mut slowed: Vec<f64> = vec![1.0; n_spans];
    let mut slow_cost = 0.0;
    // A span whose refinement diverged that cannot be slowed down on its own.
    let mut stuck = false;
    // Per span refined, its profile with the least excess so far (excess, problem, solution):
    // a span whose refinement diverges runs slower from that one, not from its worst.
    let mut least: std::collections::HashMap<usize, (f64, SpanProblem, SpanSolution)> =
        std::collections::HashMap::new();
    while !v.verified && options.refine_until_verified && round < options.local_rounds {
        // A span whose excess grows round after round as its intervals are divided runs
        // slower instead, and the others go on being refined. (Stopping the whole refinement
        // there left the other spans' small excesses to the slow-down below, whose every try
        // moved the clock and found new ones: the Röders finishing program with jerk limits
        // failed so, after one span's excess went 0.7 %, 15 %, 220 % on intervals of 1e-7 mm
        // at a rest end.)
        let runaway: Vec<bool> = (0..n_spans)
            .map(|s| {
                excess[s].last().is_some_and(|&e| e > 0.0) && (frozen[s] || diverging(&excess[s]))
            })
            .collect();
        if runaway.contains(&true) {
            // Back to each diverging span's profile of least excess, re-simulated on the
            // path's clock (the Spinner U5 program: a span's excess went 6 %, 16 %, 34,240 %;
            // slowed from its last profile it ran 7 times slower, from its first 2 %).
            let mut restored = 0;
            for (si, _) in runaway.iter().enumerate().filter(|(_, r)| **r) {
                let now = excess[si].last().copied().unwrap_or(0.0);
                if let Some((e, p, sol)) = least.remove(&si).filter(|(e, ..)| *e < now) {
                    tracing::trace!("  span {si}: back to its profile of excess {e:.3e}");
                    lv.problems[si] = p;
                    lv.solutions[si] = sol;
                    restored += 1;
                }
            }
            if restored > 0 {
                v = plan.verify_marked(&lv, options, mark)?.0;
            }
            let Some(factors) =
                slow_down_factors(&v.violations, n_spans, |s| runaway[s], |s| at_rest(&lv, s))
            else {
                stuck = true;
                break;
            };
            tracing::debug!(
                "local refinement round {round}: {} span(s) slowed down (their excess grew \
                 round after round, or the solver failed on their finer grid), by up to {:.4}",
                factors.iter().filter(|&&f| f > 1.0).count(),
                factors.iter().copied().fold(1.0, f64::max)
            );
            for (si, &f) in factors.iter().enumerate().filter(|(_, f)| **f > 1.0) {
                tracing::trace!("  span {si}: × {f:.6}, excess {:?}", excess[si]);
            }
            slow_cost += slow_spans(&mut lv, &factors, &mut slowed)?;
            for (si, &f) in factors.iter().enumerate() {
                frozen[si] |= f > 1.0;
            }
            lv.rebuild_schedule(&plan)?;
            (v, marks) = plan.verify_marked(&lv, options, mark)?;
            round += 1;
            record_excess(&mut excess, &v);
            continue;
        }
        marks.retain(|m| !frozen[m.span]);
        tracing::debug!(
            "verify: {} intervals ({} marked), worst {:?}",
            v.violating_intervals,
            marks.len(),
            v.violations.first()
        );
        let t0 = std::time::Instant::now();
        plan.progress
            .stage("adding stations where the re-simulation found a limit exceeded");
        let mut all = marks_of(&marks);
        all.extend(
            predicted_marks(&lv.problems, &lv.solutions, &options.verify, mark)?
                .into_iter()
                .filter(|m| !frozen[m.0]),
        );
        let (touched, failed, replaced) = plan.refine_where_violated(&mut lv, &all, options)?;
        for (si, p, sol) in replaced {
            let e = excess[si].last().copied().unwrap_or(0.0);
            if least.get(&si).is_none_or(|(l, ..)| e < *l) {
                least.insert(si, (e, p, sol));
            }
        }
        let solved = t0.elapsed().as_secs_f64();
        // The spans solved again first, on their own (the others passed and have not changed),
        // with those the solver failed on, which are slowed down in the next round where they
        // exceed a limit; the whole path once they pass (its clock samples each span at other
        // instants).
        let mut check = touched.clone();
        for &si in &failed {
            frozen[si] = true;
            check.push(si);
        }
        check.sort_unstable();
        check.dedup();
        (v, marks) = plan.verify_spans(&lv, &check, options, mark)?;
        if v.verified {
            lv.rebuild_schedule(&plan)?;
            // Every span checked, in order, is the whole path on its clock: verified already
            // (a one-span path, as each COPP path, saves a re-simulation per solve).
            if check.len() < n_spans {
                (v, marks) = plan.verify_marked(&lv, options, mark)?;
            }
        }
        tracing::debug!(
            "local refinement round {round}: {} spans solved in {solved:.2} s, verified in {:.2} s",
            touched.len(),
            t0.elapsed().as_secs_f64() - solved
        );
        round += 1;
        record_excess(&mut excess, &v);
    }
    if stuck {
        tracing::debug!(
            "local refinement stopped: a span's worst excess grew round after round, and it \
             does not start and end at rest"
        );
    }
    if round > 0 && !v.verified {
        lv.rebuild_schedule(&plan)?;
    }
    // The local refinement did not settle (each round's re-simulation found the excess in
    // other intervals): the spans still over a limit run slower instead, each by the least
    // factor that brings its worst excess within the limit ([`slow_down_factors`]), so that
    // the schedule returned keeps every limit; the time that costs is added to the error
    // estimate and said.
    let mut tries = 0;
    while !v.verified
        && options.refine_until_verified
        && (round >= options.local_rounds || stuck)
        && tries < SLOW_DOWN_TRIES
    {
        let Some(factors) =
            slow_down_factors(&v.violations, n_spans, |_| true, |s| at_rest(&lv, s))
        else {
            tracing::debug!("slow-down: a span over a limit cannot be slowed on its own");
            break;
        };
        slow_cost += slow_spans(&mut lv, &factors, &mut slowed)?;
        lv.rebuild_schedule(&plan)?;
        v = plan.verify_marked(&lv, options, mark)?.0;
        tries += 1;
        tracing::debug!(
            "slow-down try {tries}: {} span(s) slowed; {} interval(s) still over a limit",
            factors.iter().filter(|&&f| f > 1.0).count(),
            v.violating_intervals
        );
    }
    let mut error_estimate = error_estimate;
    let mut slowed_down = None;
    let spans_slowed = slowed.iter().filter(|&&f| f > 1.0).count();
    if spans_slowed > 0 && v.verified {
        let largest = slowed.iter().copied().fold(1.0, f64::max);
        let cost = slow_cost;
        let added = cost / lv.schedule.cycle_time;
        error_estimate = error_estimate.map(|e| e + added);
        let why = format!(
            "the re-simulation still found limits exceeded between stations after \
             {round} rounds of local refinement: {} span(s) run up to {:.3} % \
             slower instead, which keeps every limit ({:.4} s, {added:.1e} of the cycle \
             time{})",
            spans_slowed,
            (largest - 1.0) * 100.0,
            cost,
            if error_estimate.is_some() {
                ", added to the error estimate"
            } else {
                ""
            }
        );
        if error_target.is_some_and(|t| error_estimate.is_some_and(|e| e > t)) {
            unconverged = Some(unconverged.map_or(why.clone(), |u| format!("{u}; {why}")));
        }
        slowed_down = Some(why);
    }
    if round > 0 {
        refinement.push(Refinement {
            stations: lv.schedule.stations.len(),
            cycle_time_s: lv.schedule.cycle_time,
        });
    }
    if !v.verified && options.refine_until_verified {
        let worst = v.violations.first();
        return Err(Error::Solver(format!(
            "the schedule still exceeds a limit between stations after {round} rounds \
             of local refinement ({} intervals{}); try a finer --period or report the program",
            v.violating_intervals,
            worst.map_or(String::new(), |w| format!(
                ", worst {:.4}× at span {} u = {:.6}, nearest CL line {}",
                w.ratio,
                w.span,
                w.u,
                plan.path.spans[w.span].nearest_line(w.u)
            ))
        )));
    }
    Ok(Solution {
        path: plan.path,
        kinematics: plan.kin,
        problems: lv.problems,
        solutions: lv.solutions,
        schedule: lv.schedule,
        status: lv.status,
        iterations: lv.iterations,
        solve_time: lv.solve_time,
        refinement,
        error_estimate,
        error_target,
        unconverged,
        slowed_down,
        verification: v,
        verify_period: options.verify.period,
        corners_blended: 0,
        reused_solves: plan.reuse.hits(),
    })
}

/// How close to the jerk bound of its inner station a rest end's constant-jerk interval must
/// run to be kept whole ([`Plan::rest_split`]).
const REST_HOLDS: f64 = 0.9;

/// The SCP convergence of the first coarse grid G of a jerk-limited refinement (relative
/// change of its cycle time; every other grid takes [`JerkOptions::convergence`]). G's profile
/// is only F's first linearisation point (F's SCP converges as every other), and its times
/// enter only round 0's ε: an unconverged G is slower, so those ε are, summed, too large
/// rather than too small (an estimate that ends the refinement at round 0 stays an upper
/// one). G's cold SCP (from the reach profile, 4–7 subproblems a window) is the costliest
/// part of the rounds: 3 % less time on the jerk-limited impeller, its cycle time within
/// 1e-5 of before.
const COARSE_SCP: f64 = 3e-3;

/// Geometric grading of the stations into a rest end of a jerk-limited span (levels).
const GRADING: usize = 4;

/// Where a full-rate ramp inside interval `k` meets the plateau the interval ends on (or
/// starts from), if it does so inside the interval.
///
/// With b linear between stations, an interval from an acceleration-limited ramp onto a
/// velocity bound (or off it) spreads the change of b over its whole length, at a lower ü
/// than the limits allow: the lost time is of the order of the interval's time, the first-order
/// term of the discretisation error (at a rest end below a low feed cap the whole ramp lies in
/// the first interval). The ramp at the rate allowed at its start (ü_max at u_k and b_k, or
/// ü_min at u_{k+1} and b_{k+1} for a braking one) reaches the plateau at
/// u* = u_k + (b_{k+1} − b_k)/(2 ü_max); a station there makes the piecewise-linear b follow
/// the ramp and the plateau exactly on a straight path (and to second order on a curved one).
fn ramp_end(p: &SpanProblem, b: &[f64], k: usize) -> Option<f64> {
    let (u0, u1) = (p.u[k], p.u[k + 1]);
    let du = u1 - u0;
    let slope = (b[k + 1] - b[k]) / (2.0 * du);
    let on_bound = |i: usize| b[i] >= p.b_max[i] * (1.0 - 1e-9);
    let at = if slope > 0.0 && on_bound(k + 1) {
        let hi = p.udd_range(k, b[k]).1;
        (hi > slope * (1.0 + 1e-6)).then(|| u0 + (b[k + 1] - b[k]) / (2.0 * hi))
    } else if slope < 0.0 && on_bound(k) {
        let lo = p.udd_range(k + 1, b[k + 1]).0;
        (lo < slope * (1.0 + 1e-6)).then(|| u1 - (b[k] - b[k + 1]) / (2.0 * -lo))
    } else {
        None
    }?;
    (at > u0 + 1e-3 * du && at < u1 - 1e-3 * du).then_some(at)
}

/// An interval a local refinement divides: (span, interval, the ratio to a limit found or
/// predicted there).
pub(crate) type Mark = (usize, usize, f64);

/// The marks of re-simulated violations.
pub(crate) fn marks_of<'a>(v: impl IntoIterator<Item = &'a Violation>) -> Vec<Mark> {
    v.into_iter()
        .map(|w| (w.span, w.interval, w.ratio))
        .collect()
}

/// The intervals of acceleration-limited profiles with ü linear between stations whose
/// estimated excess over a limit between stations ([`SpanProblem::overshoot`]) is above
/// `mark` (relative), with 1 + that excess. Where the re-simulation has found some limit
/// exceeded, these are divided with the intervals it found: its servo instants fall at other
/// places of an interval each time the clock before it moves, so a round that divided only
/// what they found left excesses they had missed for the next round to find (the bear's
/// machine-limits run: 712, 77, 18, 1, then 26 intervals as earlier spans' times changed).
/// Intervals too short for an instant to be likely inside are left (as in the adaptive
/// rounds, [`OVERSHOOT_MARK`]).
pub(crate) fn predicted_marks(
    problems: &[SpanProblem],
    solutions: &[SpanSolution],
    verify: &VerifyOptions,
    mark: f64,
) -> Result<Vec<Mark>> {
    let brief = verify.period * BRIEF_SHARE;
    let mut out = Vec::new();
    for (si, (p, s)) in problems.iter().zip(solutions).enumerate() {
        let Some(ends) = s.ends.as_deref() else {
            continue;
        };
        let dt = interval_times(p, s)?;
        for (k, &t) in dt.iter().enumerate() {
            if t > brief {
                let o = p.overshoot(&s.b, ends, k);
                if o > mark {
                    out.push((si, k, 1.0 + o));
                }
            }
        }
    }
    Ok(out)
}

/// Per span (of `spans`), the intervals `marks` name and into how many parts each is divided
/// ([`local_parts`]): sorted, one entry per interval (its worst violation's, the most parts),
/// as [`divide`] takes them.
pub(crate) fn marked_parts(
    marks: impl IntoIterator<Item = Mark>,
    spans: usize,
    tolerance: f64,
) -> Vec<Vec<(usize, usize)>> {
    let mut split: Vec<Vec<(usize, usize)>> = vec![Vec::new(); spans];
    for (span, interval, ratio) in marks {
        split[span].push((interval, local_parts(ratio, tolerance)));
    }
    for ks in &mut split {
        ks.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(b.1.cmp(&a.1)));
        ks.dedup_by_key(|k| k.0);
    }
    split
}

/// Into how many equal parts a local refinement divides an interval whose re-simulation
/// exceeded a limit by the factor `ratio` (> 1 + `tolerance`): the excess between stations falls
/// as Δu² (b, ü and the jerk are smooth inside an interval, and their deviation from what the
/// rows see at its stations and collocation points is of second order), so m parts take an
/// excess e to about e/m². m is chosen to bring e to a quarter of the tolerance, at least 2,
/// at most [`MAX_LOCAL_SPLIT`]: one round usually suffices where halving took three or four
/// (the jerk-limited impeller: excess 3.6 % at first).
fn local_parts(ratio: f64, tolerance: f64) -> usize {
    let excess = (ratio - 1.0).max(0.0);
    let m = (excess / (0.25 * tolerance.max(1e-12))).sqrt().ceil();
    if m.is_finite() {
        (m as usize).clamp(2, MAX_LOCAL_SPLIT)
    } else {
        MAX_LOCAL_SPLIT
    }
}

/// The share of the verification tolerance above which an interval is divided in a round of
/// local refinement (once the re-simulation has found a limit exceeded). The jerk-limited
/// impeller with the tolerance itself: four rounds, each finding over the tolerance intervals
/// that were just under it (1.0011–1.0016 of a limit) on the clock of the round before.
pub(crate) const LOCAL_MARK: f64 = 0.5;

/// The most parts one round of local refinement divides an interval into.
const MAX_LOCAL_SPLIT: usize = 8;

/// Rounds of local refinement where the re-simulation failed before giving up (each round
/// divides the excess between stations by four or more).
const MAX_LOCAL_ROUNDS: usize = 12;

/// Appends each span's worst excess over a limit in `v` (its worst ratio less one, 0 where it
/// has none) to that span's history, of which the last three are kept ([`diverging`]).
fn record_excess(excess: &mut [Vec<f64>], v: &Verification) {
    let mut worst = vec![0.0_f64; excess.len()];
    for w in &v.violations {
        worst[w.span] = worst[w.span].max(w.ratio - 1.0);
    }
    for (h, w) in excess.iter_mut().zip(worst) {
        if h.len() == 3 {
            h.remove(0);
        }
        h.push(w);
    }
}

/// What [`Plan::refine_where_violated`] did: the spans solved again, those the solver failed
/// on, and each replaced span's former problem and profile.
type RefineOutcome = (
    Vec<usize>,
    Vec<usize>,
    Vec<(usize, SpanProblem, SpanSolution)>,
);

/// Whether span `si` of `lv` starts and ends at rest (so that it can run slower on its own).
fn at_rest(lv: &Level, si: usize) -> bool {
    let p = &lv.problems[si];
    p.b_start == 0.0 && p.b_end == 0.0
}

/// Runs each span `si` of `lv` slower by `factors[si]` where that is above 1 (its time then
/// grows by that factor: b and ü scale by 1/f²), multiplying `slowed[si]`; returns the time
/// added.
fn slow_spans(lv: &mut Level, factors: &[f64], slowed: &mut [f64]) -> Result<f64> {
    let mut cost = 0.0;
    for (si, &f) in factors.iter().enumerate().filter(|(_, f)| **f > 1.0) {
        let t: f64 = interval_times(&lv.problems[si], &lv.solutions[si])?
            .iter()
            .sum();
        lv.solutions[si].slow_down(f);
        slowed[si] *= f;
        cost += (f - 1.0) * t;
    }
    Ok(cost)
}

/// Per span, the least factor by which running it slower brings the worst of its violations
/// in `v` within the limit, with [`SLOW_DOWN_MARGIN`] (velocity and feed fall as 1/f,
/// acceleration and chord error as 1/f², jerk as 1/f³), for the spans `which` selects, 1 for
/// the others (of `n`); `None` where such a span cannot be slowed down on its own (it does not
/// start and end at rest: `at_rest`) or an excess is not finite.
fn slow_down_factors(
    violations: &[Violation],
    n: usize,
    which: impl Fn(usize) -> bool,
    at_rest: impl Fn(usize) -> bool,
) -> Option<Vec<f64>> {
    let mut factors = vec![1.0_f64; n];
    for w in violations.iter().filter(|w| which(w.span)) {
        let k = match w.kind {
            Quantity::Velocity | Quantity::Feed => 1.0,
            Quantity::Acceleration | Quantity::Chord => 2.0,
            Quantity::Jerk => 3.0,
        };
        if !w.ratio.is_finite() || !at_rest(w.span) {
            return None;
        }
        let f = w.ratio.powf(1.0 / k) * (1.0 + SLOW_DOWN_MARGIN);
        factors[w.span] = factors[w.span].max(f);
    }
    Some(factors)
}

/// Whether the local refinement is making things worse: the worst excess over a limit at
/// least doubled in each of the last two rounds, to [`DIVERGED_EXCESS`] or more. Dividing
/// intervals where the re-simulation found a limit exceeded shrinks the excess as Δu²
/// wherever the profile converges; where it grows instead (a bulge of jerk between the sites
/// near a rest end: 1.002, 1.011, 2.4, 21, … of the limit), each round's stations multiply by
/// up to eight, and twelve rounds would take minutes and gigabytes before the spans are
/// slowed down. Then they are slowed down at once. Excesses of a few per cent wander from
/// interval to interval as rounds move the clock and are left to the rounds: CAMotics bear
/// with jerk limits went 4.2, 6.8, 1.1, 3.4, 8.0 % and then settled.
fn diverging(excess: &[f64]) -> bool {
    match excess {
        [.., a, b, c] => *b >= 2.0 * a && *c >= 2.0 * b && *c >= DIVERGED_EXCESS,
        _ => false,
    }
}

/// The excess over a limit (25 %) below which the local refinement is not judged diverging
/// (the runaways seen reached 40 % and 140 % in their third round, the wandering 8 %).
const DIVERGED_EXCESS: f64 = 0.25;

/// Times the spans still over a limit after the local refinement are slowed down: each try
/// moves the clock of every span after the ones it slows, and the re-simulation then finds
/// excesses of a per cent or so at other instants (the NX bottle opener on the Spinner U5 with
/// jerk limits: 11, 8, 12, 10 intervals over after four tries, which failed the solve; none
/// after eight, 42 spans slowed by up to 3.2 %, 0.065 s of 242 s).
const SLOW_DOWN_TRIES: usize = 16;

/// How far below its limit a slowed-down span's worst excess is brought (relative).
const SLOW_DOWN_MARGIN: f64 = 1e-6;

/// Rounds of the adaptive refinement of one span at most (each halves the intervals marked).
const MAX_ADAPTIVE_ROUNDS: usize = 60;

/// One round of the adaptive refinement of one span: its fine grid F solved by the reach
/// pass, F's time, and the change e_k of each coarse interval's time under halving (and
/// their sum).
struct Round {
    fine: SpanProblem,
    greedy: SpanSolution,
    time: f64,
    e: Vec<f64>,
    estimate: f64,
    /// Per interval of G: whether F exceeds an acceleration limit between its stations there
    /// by more than [`OVERSHOOT_MARK`] of the re-simulation's tolerance
    /// ([`SpanProblem::overshoot`]): halved whatever its e_k.
    over: Vec<bool>,
}

/// The share of the re-simulation's tolerance above which an interval's estimated excess
/// between stations ([`SpanProblem::overshoot`]) has the adaptive refinement halve it.
const OVERSHOOT_MARK: f64 = 0.25;

/// Intervals shorter than this share of the servo period are not halved for their estimated
/// excess ([`OVERSHOOT_MARK`], [`predicted_marks`]): no servo instant is likely inside.
const BRIEF_SHARE: f64 = 1.0 / 64.0;

/// One round of the jerk-limited adaptive refinement of one span: G and F both solved by the
/// SCP.
struct JerkRound {
    /// F, its profile and its intervals' times.
    fine: SpanProblem,
    fine_solution: SpanSolution,
    fine_times: Vec<f64>,
    /// The times of G's intervals, and into how many parts F divides each.
    coarse_times: Vec<f64>,
    split: Vec<usize>,
    /// T(F), and ε_k, the estimated error of F on each interval of G.
    time: f64,
    eps: Vec<f64>,
}

/// One span's state between the rounds of an adaptive refinement ([`Plan::refine_rounds`]).
trait AdaptiveRound: Send + Sync {
    /// The cycle time on its finest grid F, s.
    fn time(&self) -> f64;
    /// F's stations.
    fn stations(&self) -> usize;
    /// The error each interval of its grid G carries (e_k or ε_k), s: what the threshold
    /// marks for refinement.
    fn errors(&self) -> &[f64];
    /// Intervals of G to refine whatever their error (empty: none).
    fn forced(&self) -> &[bool] {
        &[]
    }
}

impl AdaptiveRound for Round {
    fn time(&self) -> f64 {
        self.time
    }
    fn stations(&self) -> usize {
        self.fine.u.len()
    }
    fn errors(&self) -> &[f64] {
        &self.e
    }
    fn forced(&self) -> &[bool] {
        &self.over
    }
}

impl AdaptiveRound for JerkRound {
    fn time(&self) -> f64 {
        self.time
    }
    fn stations(&self) -> usize {
        self.fine.u.len()
    }
    fn errors(&self) -> &[f64] {
        &self.eps
    }
}

/// The range of ρ, the ratio of successive changes of the jerk-limited cycle time, that the
/// error estimate takes ([`Plan::solve_adaptive_jerk`]). 0.25 is a uniform halving under the
/// cubic law's second order (there ρ/(1 − ρ) = 1/3 is Richardson's factor for p = 2); the
/// rounds refine only part of the intervals and show more (0.31–0.47 on the jerk-limited
/// impeller). 0.9 bounds the tail's factor at 9.
const RHO_MIN: f64 = 0.25;
const RHO_MAX: f64 = 0.9;

/// Before ρ is observed (the first two rounds) the jerk-limited estimate assumes p = 1
/// (ρ = 0.5, itself twice Richardson's factor for the cubic law's p = 2) and ends the
/// refinement only when this multiple of it is within tolerance: ρ up to 2/3 would still be
/// covered.
const UNSEEN_RHO_MARGIN: f64 = 2.0;

/// The most parts one round divides an interval of the jerk-limited refinement into. Halving
/// (2) is the cheapest measured: on the jerk-limited impeller, up to 4 parts as a first-order
/// prediction asks takes one round less but 106k stations instead of 88k and 1.3× the CPU
/// time (up to 16: 146k stations).
const MAX_SPLIT: usize = 2;

/// The refinement threshold of a round: the smallest e_k, summing to half the `allowance`
/// (tol · T), stay; every interval above it is halved. Errors equal to the first one that
/// passes half the allowance are all above it: a program repeating one pattern has many equal
/// e_k, and a threshold equal to them marked none (a Fusion post for Marlin stopped at an
/// estimate of 1.24e-4 for a target of 1e-4, with nothing refined).
fn threshold(e: impl Iterator<Item = f64>, allowance: f64) -> f64 {
    let mut all: Vec<f64> = e.collect();
    all.sort_unstable_by(f64::total_cmp);
    let mut acc = 0.0;
    for (i, &e) in all.iter().enumerate() {
        acc += e;
        if acc > 0.5 * allowance {
            // The largest error below this one (0: every positive error is marked).
            return all[..i]
                .iter()
                .rev()
                .find(|&&x| x < e)
                .copied()
                .unwrap_or(0.0);
        }
    }
    all.last().copied().unwrap_or(0.0)
}

/// What [`Plan::refine_rounds`] ends with: the last rounds, the refinement history, the
/// last estimate (s) and, where that estimate is above the target, why the rounds stopped.
struct Refined<R> {
    rounds: Vec<R>,
    refinement: Vec<Refinement>,
    estimate_s: f64,
    unconverged: Option<String>,
}

/// An adaptive refinement's answer: the final level, the history, the relative estimate and
/// the target it aimed at, and why it stopped short of that target, if it did.
struct Adaptive {
    level: Level,
    refinement: Vec<Refinement>,
    estimate: f64,
    target: f64,
    unconverged: Option<String>,
}

/// The solve of every span at one refinement level.
struct Level {
    problems: Vec<SpanProblem>,
    solutions: Vec<SpanSolution>,
    schedule: Schedule,
    status: Status,
    iterations: u32,
    solve_time: f64,
}

impl Level {
    /// The schedule of the level's problems and solutions again (after spans were solved
    /// again). The old one is dropped first: built beside it, two schedules at once were the
    /// peak of a 1.07 M-station 5-axis solve (360 of 577 MB).
    fn rebuild_schedule(&mut self, plan: &Plan) -> Result<()> {
        self.schedule = Schedule::default();
        self.schedule = Schedule::build(
            &plan.axes,
            &plan.path.spans,
            &self.problems,
            &self.solutions,
        )?;
        Ok(())
    }
}

/// Each span's share of the stations: half by its share of CL moves, half by its share of
/// the path parameter among spans of its kind.
fn span_weights(path: &Path) -> Vec<f64> {
    let segs: f64 = path.spans.iter().map(|s| s.feed_caps.len() as f64).sum();
    let len_of = |kind| -> f64 {
        path.spans
            .iter()
            .filter(|s| s.kind == kind)
            .map(|s| s.length())
            .sum()
    };
    let (lm, lr) = (
        len_of(SpanKind::Moving) + len_of(SpanKind::Joint),
        len_of(SpanKind::Reorientation),
    );
    let share_kind = |kind| {
        path.spans
            .iter()
            .filter(|s| s.kind == kind)
            .map(|s| s.feed_caps.len() as f64)
            .sum::<f64>()
            / segs
    };
    let (sm, sr) = (
        share_kind(SpanKind::Moving) + share_kind(SpanKind::Joint),
        share_kind(SpanKind::Reorientation),
    );
    path.spans
        .iter()
        .map(|s| {
            let by_len = match s.kind {
                SpanKind::Moving | SpanKind::Joint => sm * s.length() / lm,
                SpanKind::Reorientation => sr * s.length() / lr,
            };
            0.5 * s.feed_caps.len() as f64 / segs + 0.5 * by_len
        })
        .collect()
}

/// b at an end station for a tool-tip feed (mm/s); an error where the tip cannot move.
fn end_speed(span: &Span, p: &SpanProblem, i: usize, feed: f64, which: &str) -> Result<f64> {
    if !(feed.is_finite() && (0.0..=1e6).contains(&feed)) {
        return Err(Error::Usage(format!(
            "the {which} feed must be between 0 and 1e6 mm/s, got {} mm/s",
            crate::error::number(feed)
        )));
    }
    if feed == 0.0 {
        return Ok(0.0);
    }
    if span.kind == SpanKind::Joint {
        return Ok(feed * feed); // u̇ = ds/dt itself
    }
    let speed = p.tip_speed[i];
    if speed <= 0.0 {
        return Err(Error::Infeasible(format!(
            "the path's {which} is a pure reorientation (the tool tip stands still): the {which} \
             feed must be 0, got {feed} mm/s"
        )));
    }
    let b = (feed / speed).powi(2);
    if !b.is_finite() {
        return Err(Error::Infeasible(format!(
            "the path's {which} barely moves the tool tip ({speed:.3e} mm per unit of path): a \
             {which} feed of {feed} mm/s there is out of reach; give 0"
        )));
    }
    Ok(b)
}

/// What stays fixed while the stations are refined.
struct Plan<'a> {
    machine: &'a Machine,
    kin: Kinematics,
    path: Path,
    axes: Vec<String>,
    /// Each span's share of the stations.
    weights: Vec<f64>,
    progress: &'a dyn Progress,
    /// The answers of the span problems solved so far.
    reuse: reuse::Reuse,
    /// Per span, its last jerk-limited solve's collocation bounds, which the next one (a
    /// local refinement's) takes where its intervals are the same ([`JerkData::new`]).
    mid_bounds: Vec<std::sync::Mutex<Option<MidBounds>>>,
}

impl Plan<'_> {
    /// Every axis within its travel at every station, or an error naming where.
    fn check_travel(&self, si: usize, p: &SpanProblem) -> Result<()> {
        for (j, axis) in self.machine.axes.iter().enumerate() {
            if axis.travel.is_none() {
                continue;
            }
            if let Some((i, (lo, hi))) =
                (0..p.u.len()).find_map(|i| axis.travel_exceeded(p.jets.q(i)[j]).map(|t| (i, t)))
            {
                return Err(Error::Infeasible(format!(
                    "span {si}, u = {:.6}, nearest CL line {}: axis {} would be at {:.4}, outside \
                     its travel [{lo}, {hi}]",
                    p.u[i],
                    self.path.spans[si].nearest_line(p.u[i]),
                    axis.name,
                    p.jets.q(i)[j]
                )));
            }
        }
        Ok(())
    }

    /// The interval times of one span's profile (eq. 43); where the feed is zero over a whole
    /// interval, an error naming span, u, the nearest CL line and the limit that allows no
    /// motion there.
    fn times(&self, si: usize, p: &SpanProblem, s: &SpanSolution) -> Result<Vec<f64>> {
        interval_times(p, s).map_err(|e| {
            let Some(k) = (0..p.intervals()).find(|&k| s.b[k] <= 0.0 && s.b[k + 1] <= 0.0) else {
                return e;
            };
            let i = if p.b_max[k] <= p.b_max[k + 1] {
                k
            } else {
                k + 1
            };
            let limit = match p.b_max_by[i] {
                Bound::AxisVelocity(j) => format!("the {} velocity limit", self.axes[j]),
                Bound::AxisAcceleration(j) => format!("the {} acceleration limit", self.axes[j]),
                Bound::AxisJerk(j) => format!("the {} jerk limit", self.axes[j]),
                Bound::Feed => "the programmed feed".to_string(),
                Bound::Chord => "the chord tolerance".to_string(),
                Bound::Process(l) => format!("the {} limit", l.label()),
                Bound::None => "the limits".to_string(),
            };
            Error::Infeasible(format!(
                "span {si}, u = {:.6}, nearest CL line {}: {limit} leaves the tool no speed \
                 here (at most {:.3e} mm/s), so the path cannot be traversed; check that value \
                 in the program or the machine file",
                p.u[k],
                self.path.spans[si].nearest_line(p.u[k]),
                p.b_max[i].max(0.0).sqrt() * p.tip_speed[i].max(1.0)
            ))
        })
    }

    /// The reach pass on one span, its infeasibility in words.
    ///
    /// Where its profile stands still on an interval inside the span (b = 0 at both ends, no
    /// motion), the optimum of the same stations instead ([`solver::optimal`]): on rows that
    /// are not max-closed the pass's pointwise-largest b at one station can leave the next
    /// nothing but 0. The 20 COPP paths end with q' falling to 0 over their last interval,
    /// where the stations' bounds on ü are steep lines in b; under the linear-ü law the
    /// largest b one station before the end left the next none, and every path failed (the
    /// cone program's optimum has b = 0.0039 there). The convex program never stands still
    /// where motion is possible: its objective, the time, would be infinite.
    fn reach(&self, si: usize, p: &SpanProblem, settings: &SolverSettings) -> Result<SpanSolution> {
        let g = solver::reach::solve(p).map_err(|inf| self.infeasible(si, p, &inf))?;
        // (A scan of b, not the interval times: this runs on every grid of every round, and
        // the times are computed next by the caller that needs them.)
        if !g.b.windows(2).any(|w| w[0] <= 0.0 && w[1] <= 0.0) {
            return Ok(g);
        }
        tracing::debug!("span {si}: the reach profile stands still on an interval; its optimum");
        match solver::optimal(p, &g, settings) {
            Ok(o) if interval_times(p, &o).is_ok() => Ok(o),
            _ => Ok(g),
        }
    }

    /// Span `si` on a uniform grid (every CL knot, each segment divided so the spans share
    /// about `total` stations), with its end speeds: the start of the adaptive refinements and
    /// the fixed grid of `--stations`.
    fn uniform_problem(&self, si: usize, total: usize, options: &Options) -> Result<SpanProblem> {
        let spans = &self.path.spans;
        let span = &spans[si];
        let grid = Grid {
            spacing: span.length() / (total as f64 * self.weights[si]).max(8.0),
            min_parts: 1,
        };
        let mut p = SpanProblem::build(span, &self.kin, self.machine, grid);
        p.ramp = options.ramp;
        if let Some(c) = &options.verify.chord {
            p.apply_chord(span, c);
        }
        self.check_travel(si, &p)?;
        if si == 0 {
            p.b_start = end_speed(span, &p, 0, options.start_feed, "start")?;
        }
        if si + 1 == spans.len() {
            p.b_end = end_speed(span, &p, p.intervals(), options.end_feed, "end")?;
        }
        Ok(p)
    }

    /// One span's grid G and its bisection F (every interval halved), both solved by the reach
    /// pass, and e_k = |t_k(G) − t_{2k}(F) − t_{2k+1}(F)| for every interval k of G: the change
    /// of its time under halving.
    fn bisect(&self, si: usize, options: &Options, p: SpanProblem) -> Result<Round> {
        let span = &self.path.spans[si];
        let chord = options.verify.chord.as_ref();
        let g = self.reach(si, &p, &options.solver)?;
        let t = self.times(si, &p, &g)?;
        let n = p.intervals();
        let all: Vec<usize> = (0..n).collect();
        let pf = p.with_inserted(span, &self.kin, self.machine, chord, &all, |k| {
            0.5 * (p.u[k] + p.u[k + 1])
        });
        self.check_travel(si, &pf)?;
        let gf = self.reach(si, &pf, &options.solver)?;
        let tf = self.times(si, &pf, &gf)?;
        let time = tf.iter().sum();
        let e: Vec<f64> = (0..n)
            .map(|k| (t[k] - tf[2 * k] - tf[2 * k + 1]).abs())
            .collect();
        // Intervals so short that no servo instant is likely to fall inside are left alone (a
        // rotary axis reversing on a reorientation span of NX's Mori program drove them to
        // 1e-10° with the estimate unchanged: there ü is huge and the jets' terms cancel).
        let (mark, brief) = (
            OVERSHOOT_MARK * options.verify.tolerance,
            options.verify.period * BRIEF_SHARE,
        );
        let over = match gf.ends.as_deref() {
            Some(ends) => (0..n)
                .map(|k| {
                    (2 * k..2 * k + 2).any(|i| tf[i] > brief && pf.overshoot(&gf.b, ends, i) > mark)
                })
                .collect(),
            None => Vec::new(),
        };
        Ok(Round {
            fine: pf,
            greedy: gf,
            time,
            estimate: e.iter().sum(),
            e,
            over,
        })
    }

    /// The next grid of a span: G with every interval whose e_k exceeds `threshold` halved
    /// (the stations of F in it), and a station where a ramp inside it ends ([`ramp_end`]).
    fn refined_grid(&self, si: usize, options: &Options, r: &Round, threshold: f64) -> SpanProblem {
        let span = &self.path.spans[si];
        let chord = options.verify.chord.as_ref();
        let pf = &r.fine;
        let mut keep: Vec<bool> = (0..pf.u.len()).map(|i| i % 2 == 0).collect();
        for (k, &e) in r.e.iter().enumerate() {
            if e > threshold || r.over.get(k) == Some(&true) {
                keep[2 * k + 1] = true;
            }
        }
        // Where a marked interval of F ramps onto (or off) a plateau more slowly than the
        // limits allow, the ramp really ends inside it: a station goes where it does.
        let kinks: Vec<f64> = (0..r.e.len())
            .filter(|&k| keep[2 * k + 1])
            .flat_map(|k| [2 * k, 2 * k + 1])
            .filter_map(|f| ramp_end(pf, &r.greedy.b, f))
            .collect();
        let p = pf.select(&keep);
        if kinks.is_empty() {
            return p;
        }
        let mut at: Vec<(usize, f64)> = kinks
            .into_iter()
            .map(|x| (p.u.partition_point(|&v| v <= x) - 1, x))
            .collect();
        at.sort_unstable_by_key(|a| a.0);
        at.dedup_by_key(|a| a.0);
        let ks: Vec<usize> = at.iter().map(|a| a.0).collect();
        p.with_inserted(span, &self.kin, self.machine, chord, &ks, |k| {
            at[ks.partition_point(|&x| x < k)].1
        })
    }

    /// Every span refined adaptively, then solved on its final grid by the chosen solver.
    /// Spans run in parallel; where several fail, the first along the path is reported (the
    /// same error whatever the threads).
    ///
    /// Each round takes every span's grid G and its bisection F ([`Plan::bisect`], spans in
    /// parallel: rest stops decouple them exactly). When Σ e_k over the whole path is at most
    /// `convergence` × T(F), the grids F are final and Σ e_k / T(F) is the error estimate:
    /// under an error ∝ h^p (p ≥ 1), F's remaining error is at most Σ e_k / (2^p − 1) ≤ Σ e_k
    /// (Richardson). Otherwise every interval whose e_k exceeds one threshold for the whole
    /// path — all but the smallest e_k that sum to half the allowance — is halved, a station
    /// goes where a ramp ends inside it, and the spans with such intervals run the next round
    /// (the others keep theirs). Plateaus (feed cap, velocity bound) have e_k = 0 and are never
    /// refined: the stations go to ramps, rest ends, corners and curvature peaks.
    fn solve_adaptive(&self, options: &Options) -> Result<Adaptive> {
        use rayon::prelude::*;
        self.progress.stage("refining stations");
        let Refined {
            rounds,
            refinement,
            estimate_s,
            unconverged,
        } = self.refine_rounds(
            options,
            options.convergence,
            |si| {
                self.bisect(
                    si,
                    options,
                    self.uniform_problem(si, options.initial_stations, options)?,
                )
            },
            // Richardson's bound holds from the first round on.
            |rounds: &[Round], _: &[Refinement], _| (rounds.iter().map(|r| r.estimate).sum(), true),
            |si, r, threshold| {
                self.bisect(si, options, self.refined_grid(si, options, r, threshold))
            },
        )?;
        self.progress.stage(&format!(
            "solving {} stations",
            rounds.iter().map(|r| r.fine.u.len()).sum::<usize>()
        ));
        let solved: Vec<(SpanProblem, SpanSolution)> = rounds
            .into_par_iter()
            .enumerate()
            .map(|(si, r)| {
                // (Acceleration-limited only: jerk-limited solves take `solve_adaptive_jerk`.)
                let s = self.solve_span(si, &r.fine, options, None, Some(r.greedy), false)?;
                Ok((r.fine, s))
            })
            .collect::<Vec<Result<_>>>()
            .into_iter()
            .collect::<Result<_>>()?;
        let (problems, solutions): (Vec<_>, Vec<_>) = solved.into_iter().unzip();
        let (level, estimate) = self.estimated_level(problems, solutions, estimate_s)?;
        Ok(Adaptive {
            level,
            refinement,
            estimate,
            target: options.convergence,
            unconverged,
        })
    }

    /// Jerk-limited solves, refined adaptively as [`Plan::solve_adaptive`] refines the
    /// acceleration-limited ones, with the SCP itself as the solver.
    ///
    /// Every span has a grid G and a refinement F of it, each interval k of G divided into s_k
    /// equal parts (s_k a power of two, 2 to [`MAX_SPLIT`]); e_k is the change of interval k's
    /// time between G and F. Under an error ∝ h^p with p ≥ 1, F's error on interval k is at
    /// most ε_k = e_k / (s_k − 1) (Richardson with p = 1). Near a rest end the profile grows as
    /// b ∝ u^(4/3), which quadratic pieces fit with the same relative misfit at every scale (an
    /// error of order h^(1/3), which halving hardly shows: on a rest-to-rest line the estimate
    /// was 6.3e-4 for a true 1.6e-3). So the first (last) interval of a span from (to) rest
    /// ends where the full-jerk phase does ([`solver::jerk::rest_phase_length`], in
    /// [`Self::final_grid`]), where its constant-jerk law is the profile's own, and it stays
    /// whole while its jerk bound holds ([`Self::rest_split`]); its time still moves with its
    /// neighbours' refinement, and that change is counted in ε. The estimate takes the order the
    /// rounds show: with ρ the ratio of successive changes of T (clamped to
    /// [`RHO_MIN`]…[`RHO_MAX`], 0.25…0.9; the larger of the last two such ratios, as one alone
    /// fluctuates: 0.48, 0.31, 0.29 on the jerk-limited impeller, where the last alone gave an
    /// estimate of 5.6e-4 for a true error of 5.7e-4), F's error is at most Σ ε_k · ρ / (1 − ρ) (the
    /// geometric tail; ρ = 0.5 is Richardson's p = 1, ρ = 0.25 its p = 2, the cubic law's
    /// order). ρ is observed from the third round on; before, ρ = 0.5, and a round ends the
    /// refinement only if [`UNSEEN_RHO_MARGIN`] times that estimate is within tolerance; a
    /// round within tolerance but not by that margin halves every interval of F (a uniform
    /// halving, whose changes show the order).
    /// Rounds stop when the bound is ≤ tol · T(F) (tol: the larger of the convergence and 10 ×
    /// the SCP's own);
    /// F is the answer and that bound / T(F) the estimate. Otherwise every interval whose ε_k exceeds one path-wide
    /// threshold (the smallest ε_k summing to half the allowance stay) is replaced by its s_k
    /// parts in the next G, each part divided in the next F by as many as its share of ε_k
    /// says it needs to come under the threshold (a first-order prediction, so most intervals
    /// need one round).
    ///
    /// Why it pays: the error sits where the jerk limit holds a ramp (a' follows a bound that
    /// varies along each interval; under the cubic law of [`crate::motion::Law::Cubic`] the
    /// time lost there is of second order in Δu), at rest ends and at corners. Halving every
    /// interval (the uniform doubling) spends most stations on plateaus that are already
    /// exact.
    ///
    /// Only F is solved after the first round: the next G's intervals are intervals of G or
    /// of F, whose times are known, and the next F contains the last F. Its SCP starts from
    /// the last F ([`Warm`]); a window with no new station keeps its profile, so a round costs
    /// what it refines.
    fn solve_adaptive_jerk(&self, options: &Options) -> Result<Adaptive> {
        self.progress.stage("refining stations (jerk-limited)");
        let mut rho = 0.5;
        let mut seen: Option<f64> = None;
        let tol = options.convergence.max(10.0 * options.jerk.convergence);
        let Refined {
            rounds,
            refinement,
            estimate_s,
            unconverged,
        } = self.refine_rounds(
            options,
            tol,
            |si| {
                let p = self.uniform_problem(si, options.initial_stations, options)?;
                if let Some(round) = self.straight_round(si, options, &p)? {
                    return Ok(round);
                }
                let p = self.final_grid(si, p, options);
                // G's SCP stops at COARSE_SCP: its profile only starts F's SCP (which
                // converges as every other), and its times enter only round 0's ε.
                let mut coarse_options = options.clone();
                coarse_options.jerk.convergence = options.jerk.convergence.max(COARSE_SCP);
                let s = self.solve_span(si, &p, &coarse_options, None, None, false)?;
                let coarse = self.times(si, &p, &s)?;
                let split = self.rest_split(si, &p, &s);
                self.refine_jerk(si, options, &p, split, coarse, (&p, &s))
            },
            |rounds: &[JerkRound], refinement: &[Refinement], time| {
                // The order the rounds show: ρ, the ratio of successive changes of T.
                if let [.., a, b] = refinement {
                    let (d0, d1) = (a.cycle_time_s - b.cycle_time_s, b.cycle_time_s - time);
                    if d0 > 0.0 && d1 > 0.0 {
                        let r = (d1 / d0).clamp(RHO_MIN, RHO_MAX);
                        // The larger of the last two ratios: one alone fluctuates.
                        rho = seen.map_or(r, |p: f64| p.max(r));
                        seen = Some(r);
                    }
                }
                let raw: f64 = rounds.iter().map(|r| r.eps.iter().sum::<f64>()).sum();
                // ρ is observed from the third round on; before, the estimate assumes p = 1
                // (ρ = 0.5), and it ends the refinement only with a margin of UNSEEN_RHO_MARGIN
                // for an order it has not seen yet. No finer than the SCP resolves: its windows
                // stop when T changes by less than `jerk.convergence` (the cubic law's
                // discretisation error can fall below that, e.g. 2.8e-7 on a rest-to-rest line).
                let tail = raw * rho / (1.0 - rho);
                let observed = refinement.len() >= 2;
                (
                    tail.max(options.jerk.convergence * time),
                    observed || UNSEEN_RHO_MARGIN * tail <= tol * time,
                )
            },
            |si, r, threshold| self.next_jerk_round(si, options, r, threshold),
        )?;
        let (problems, solutions): (Vec<_>, Vec<_>) = rounds
            .into_iter()
            .map(|r| (r.fine, r.fine_solution))
            .unzip();
        let (level, estimate) = self.estimated_level(problems, solutions, estimate_s)?;
        Ok(Adaptive {
            level,
            refinement,
            estimate,
            target: tol,
            unconverged,
        })
    }

    /// The rounds both adaptive refinements share. Every span's first round comes from
    /// `first` (spans in parallel: rest stops decouple them exactly); then, per round, T and the
    /// error estimate of the whole path (`estimate(rounds, refinement so far, T)`: the
    /// estimate, s, and whether it may end the refinement yet) are recorded as a
    /// [`Refinement`] and reported. The rounds end when a settled estimate is within
    /// `tol` · T; they also end, with the reason in [`Refined::unconverged`], after
    /// [`MAX_ADAPTIVE_ROUNDS`], before a round that would pass `options.max_stations`, or
    /// when no interval can be refined. Otherwise every interval whose error exceeds one
    /// path-wide [`threshold`] (the smallest errors summing to half the allowance stay; 0,
    /// every interval, while an estimate within `tol` is not settled yet) is refined:
    /// `next(span, its round, threshold)` for the spans that have such intervals, the others
    /// keep theirs.
    fn refine_rounds<R: AdaptiveRound>(
        &self,
        options: &Options,
        tol: f64,
        first: impl Fn(usize) -> Result<R> + Sync,
        mut estimate: impl FnMut(&[R], &[Refinement], f64) -> (f64, bool),
        next: impl Fn(usize, &R, f64) -> Result<R> + Sync,
    ) -> Result<Refined<R>> {
        use rayon::prelude::*;
        let t0 = std::time::Instant::now();
        let mut rounds: Vec<R> = (0..self.path.spans.len())
            .into_par_iter()
            .map(&first)
            .collect::<Vec<Result<_>>>()
            .into_iter()
            .collect::<Result<_>>()?;
        let mut refinement: Vec<Refinement> = Vec::new();
        loop {
            let time: f64 = rounds.iter().map(|r| r.time()).sum();
            let stations: usize = rounds.iter().map(|r| r.stations()).sum();
            let (estimate_s, settled) = estimate(&rounds, &refinement, time);
            tracing::debug!(
                "adaptive round {}: {stations} stations, T = {time:.6}, estimate {:.2e}, {:.2} s",
                refinement.len(),
                estimate_s / time,
                t0.elapsed().as_secs_f64()
            );
            refinement.push(Refinement {
                stations,
                cycle_time_s: time,
            });
            self.progress.round(stations, estimate_s / time, tol);
            let within = estimate_s <= tol * time;
            let done = |rounds, refinement, why: Option<String>| {
                Ok(Refined {
                    rounds,
                    refinement,
                    estimate_s,
                    unconverged: why.filter(|_| !within),
                })
            };
            let forced = rounds.iter().any(|r| r.forced().contains(&true));
            if settled && within && !forced {
                return done(rounds, refinement, None);
            }
            if refinement.len() >= MAX_ADAPTIVE_ROUNDS {
                let why = format!("the refinement stopped after {MAX_ADAPTIVE_ROUNDS} rounds");
                return done(rounds, refinement, Some(why));
            }
            if 2 * stations > options.max_stations {
                // The last round is solved (and is verified next): returned with its estimate,
                // not refused (a 64,698-line hyperMILL finish stopped at 1.1e-4 with 2.7 M
                // stations, its T settled to 1e-4 over the last rounds, and the user got
                // nothing).
                let why = format!(
                    "another round would pass the limit of {} stations (--max-stations)",
                    options.max_stations
                );
                return done(rounds, refinement, Some(why));
            }
            // Within tol but not settled: refine every interval, so that the next changes of
            // T are those of uniform halvings and show the order the estimate assumes.
            // The errors' own allowance: where the estimate is a multiple of their sum (the
            // jerk-limited geometric tail, Σε·ρ/(1 − ρ), up to 9 Σε), the sum must come under
            // tol·T divided by that multiple. (With tol·T itself, the flower mould with jerk
            // limits marked nothing at an estimate of 2.5e-3 and ran its 60 rounds unchanged.)
            let sum: f64 = rounds.iter().flat_map(|r| r.errors().iter()).sum();
            let share = if estimate_s > sum * (1.0 + 1e-9) && estimate_s > 0.0 {
                sum / estimate_s
            } else {
                1.0
            };
            let threshold = if within && settled {
                // Only the intervals that exceed a limit between stations.
                f64::INFINITY
            } else if within {
                0.0
            } else {
                threshold(
                    rounds.iter().flat_map(|r| r.errors().iter().copied()),
                    tol * time * share,
                )
            };
            let next: Vec<Option<R>> = rounds
                .par_iter()
                .enumerate()
                .map(|(si, r)| {
                    if r.errors().iter().all(|&e| e <= threshold) && !r.forced().contains(&true) {
                        return Ok(None);
                    }
                    next(si, r, threshold).map(Some)
                })
                .collect::<Vec<Result<_>>>()
                .into_iter()
                .collect::<Result<_>>()?;
            if next.iter().all(Option::is_none) {
                // Nothing to refine (every marked interval is one a round keeps whole): a
                // further round would repeat this one. The estimate stands as it is.
                let why = "the intervals that carry the error are ones the refinement keeps whole \
                           (a jerk-limited ramp from rest)"
                    .to_string();
                return done(rounds, refinement, Some(why));
            }
            for (r, n) in rounds.iter_mut().zip(next) {
                if let Some(n) = n {
                    *r = n;
                }
            }
        }
    }

    /// A straight span from rest to rest with the same limits everywhere (`p`: its problem on
    /// any grid): the double-S profile in closed form ([`solver::double_s`]) as a finished
    /// round. Its stations carry the profile under the motion laws within that module's
    /// tolerances (time within 1e-7, jerk within 5e-4), so its intervals carry no error for
    /// the refinement to mark; the re-simulation checks it as every other. `None`: not such a
    /// span (or the option is off), the programme takes it.
    fn straight_round(
        &self,
        si: usize,
        options: &Options,
        p: &SpanProblem,
    ) -> Result<Option<JerkRound>> {
        use solver::double_s::{DoubleS, PathLimits, profile_stations};
        if !options.jerk.closed_form {
            return Ok(None);
        }
        let Some(limits) = PathLimits::of_straight(p, self.machine) else {
            return Ok(None);
        };
        let n = p.intervals();
        let profile = DoubleS::new(p.u[n] - p.u[0], limits);
        let Some((u, solution)) = profile_stations(&profile, p.u[0]) else {
            return Ok(None);
        };
        let span = &self.path.spans[si];
        let fine = SpanProblem::at_stations_within(
            span,
            &self.kin,
            self.machine,
            u,
            options.verify.chord.as_ref(),
        );
        self.check_travel(si, &fine)?;
        let times = self.times(si, &fine, &solution)?;
        let k = times.len();
        Ok(Some(JerkRound {
            fine,
            fine_solution: solution,
            coarse_times: times.clone(),
            split: vec![1; k],
            time: times.iter().sum(),
            fine_times: times,
            eps: vec![0.0; k],
        }))
    }

    /// The next jerk-limited round of span `si`: its next G is F with the parts of the
    /// unmarked intervals (ε_k ≤ `threshold`) merged again, each marked interval's parts
    /// divided as their share of ε_k asks ([`Plan::solve_adaptive_jerk`]); a rest end's
    /// interval kept whole stays whole.
    fn next_jerk_round(
        &self,
        si: usize,
        options: &Options,
        r: &JerkRound,
        threshold: f64,
    ) -> Result<JerkRound> {
        let mut keep = vec![false; r.fine.u.len()];
        let (mut coarse, mut split) = (Vec::new(), Vec::new());
        let mut at = 0;
        for (k, &eps) in r.eps.iter().enumerate() {
            let s = r.split[k];
            keep[at] = true;
            if s == 1 {
                // A rest end's interval kept whole: its time is F's.
                coarse.push(r.fine_times[at]);
                split.push(1);
            } else if eps > threshold {
                let part = eps / s as f64;
                let more = (part / threshold).ceil().max(2.0).min(MAX_SPLIT as f64);
                for j in 0..s {
                    keep[at + j] = true;
                    coarse.push(r.fine_times[at + j]);
                    split.push((more as usize).next_power_of_two().min(MAX_SPLIT));
                }
            } else {
                coarse.push(r.coarse_times[k]);
                split.push(s);
            }
            at += s;
        }
        keep[at] = true;
        let g = r.fine.select(&keep);
        self.refine_jerk(si, options, &g, split, coarse, (&r.fine, &r.fine_solution))
    }

    /// Round 0's division of every interval of a jerk-limited span's grid `p` (solved: `s`):
    /// halves, but a constant-jerk interval from or to rest whose jerk bound holds its inner
    /// station ([`solver::jerk::rest_bounds`]) stays whole in every round. Its law is then the
    /// profile's own (the full-jerk phase has not ended inside it), and halving it would only
    /// put a quadratic piece where b ∝ u^(4/3) — the same relative misfit at every scale, an
    /// error that halving hardly reduces and the estimate cannot see. Where the bound does not
    /// hold (the interval runs past the phase's end), it is refined like any other.
    fn rest_split(&self, si: usize, p: &SpanProblem, s: &SpanSolution) -> Vec<usize> {
        let n = p.intervals();
        let mut split = vec![2; n];
        if n < 3 {
            return split;
        }
        let bounds = solver::jerk::rest_bounds(&self.path.spans[si], &self.kin, self.machine, p);
        // Within REST_HOLDS of the bound: the interval runs near full jerk to its end (the next
        // intervals' own first-order misfit keeps b₁ a little below it: 0.6 % on the closed-form
        // line), where one that runs past the phase's end stays well below it.
        let holds = |b: f64, bound: f64| bound.is_finite() && b >= bound * REST_HOLDS;
        if p.b_start == 0.0 && holds(s.b[1], bounds.0) {
            split[0] = 1;
        }
        if p.b_end == 0.0 && holds(s.b[n - 1], bounds.1) {
            split[n - 1] = 1;
        }
        split
    }

    /// F: every interval k of a span's grid `g` (whose intervals' times are `coarse`) divided
    /// into `split[k]` equal parts, solved by the SCP from `warm` (a profile on stations that
    /// F contains), and ε_k = |t_k(G) − Σ t(F's parts)| / (s_k − 1) for every interval of G.
    fn refine_jerk(
        &self,
        si: usize,
        options: &Options,
        g: &SpanProblem,
        split: Vec<usize>,
        coarse: Vec<f64>,
        warm: (&SpanProblem, &SpanSolution),
    ) -> Result<JerkRound> {
        let span = &self.path.spans[si];
        let chord = options.verify.chord.as_ref();
        debug_assert_eq!(coarse.len(), g.intervals());
        debug_assert_eq!(split.len(), g.intervals());
        // Halve repeatedly: pass m halves the parts of every interval with s_k > 2^m.
        let mut pf = g.clone();
        let mut parts = vec![1usize; g.intervals()];
        while parts.iter().zip(&split).any(|(p, s)| p < s) {
            let mut ks = Vec::new();
            let mut at = 0;
            for (k, p) in parts.iter_mut().enumerate() {
                if *p < split[k] {
                    ks.extend(at..at + *p);
                    at += *p;
                    *p *= 2;
                } else {
                    at += *p;
                }
            }
            let u = pf.u.clone();
            pf = pf.with_inserted(span, &self.kin, self.machine, chord, &ks, |k| {
                0.5 * (u[k] + u[k + 1])
            });
        }
        self.check_travel(si, &pf)?;
        let sf = self.solve_span(si, &pf, options, Some(warm), None, false)?;
        let tf = self.times(si, &pf, &sf)?;
        let mut at = 0;
        let eps: Vec<f64> = split
            .iter()
            .zip(&coarse)
            .map(|(&s, &c)| {
                let fine: f64 = tf[at..at + s].iter().sum();
                at += s;
                // An interval kept whole (a rest end's, [`Self::rest_split`]) has no
                // discretisation error of its own, but its time moves with b at its inner
                // station as its neighbours are refined: that change is theirs, counted here
                // as one halving's (p = 1).
                (c - fine).abs() / (s.max(2) - 1) as f64
            })
            .collect();
        Ok(JerkRound {
            fine: pf,
            fine_solution: sf,
            time: tf.iter().sum(),
            fine_times: tf,
            coarse_times: coarse,
            split,
            eps,
        })
    }

    /// The final level of an adaptive refinement, and its error estimate `estimate_s` (s)
    /// relative to its cycle time.
    fn estimated_level(
        &self,
        problems: Vec<SpanProblem>,
        solutions: Vec<SpanSolution>,
        estimate_s: f64,
    ) -> Result<(Level, f64)> {
        let lv = self.level(problems, solutions)?;
        let estimate = if lv.schedule.cycle_time > 0.0 {
            estimate_s / lv.schedule.cycle_time
        } else {
            0.0
        };
        Ok((lv, estimate))
    }

    /// Assembles a level from every span's problem and solution.
    fn level(&self, problems: Vec<SpanProblem>, solutions: Vec<SpanSolution>) -> Result<Level> {
        let (mut status, mut iterations, mut solve_time) = (Status::Optimal, 0, 0.0);
        for s in &solutions {
            status = status.worst(s.status);
            iterations += s.iterations;
            solve_time += s.solve_time;
        }
        let schedule = match Schedule::build(&self.axes, &self.path.spans, &problems, &solutions) {
            Ok(s) => s,
            Err(e) => {
                // Name where (a zero feed over an interval), if that is the failure.
                for (si, (p, s)) in problems.iter().zip(&solutions).enumerate() {
                    self.times(si, p, s)?;
                }
                return Err(e);
            }
        };
        Ok(Level {
            problems,
            solutions,
            schedule,
            status,
            iterations,
            solve_time,
        })
    }

    /// The grid a span is finally solved on: for a jerk-limited solve, graded into its rest
    /// ends (from rest the jerk-limited profile grows as b ∝ u^(4/3), which evenly spaced
    /// quadratic pieces follow badly: L/2, L/4, … L/2^GRADING of the first three intervals' L).
    fn final_grid(&self, si: usize, p: SpanProblem, options: &Options) -> SpanProblem {
        if !self.machine.has_jerk() || p.intervals() < 6 {
            return p;
        }
        let n = p.intervals();
        let (u0, un) = (p.u[0], p.u[n]);
        let mut u = p.u.clone();
        // The end of the full-jerk phase from rest, where one can be estimated: the first
        // (last) interval ends there, so its constant-jerk law is the profile's own
        // ([`solver::jerk::rest_phase_length`]); the geometric grading continues beyond it.
        let phase = |end: bool| {
            (if end { p.b_end } else { p.b_start } == 0.0)
                .then(|| solver::jerk::rest_phase_length(&p, self.machine, end))
                .flatten()
        };
        let (first, last) = (phase(false), phase(true));
        if p.b_start == 0.0 {
            let l = p.u[3] - u0;
            u.extend((1..=GRADING).map(|k| u0 + l / f64::powi(2.0, k as i32)));
        }
        if p.b_end == 0.0 {
            let l = un - p.u[n - 3];
            u.extend((1..=GRADING).map(|k| un - l / f64::powi(2.0, k as i32)));
        }
        // The stations inside the phase go: the profile there stays below a quarter of the
        // lowest velocity bound on that half (V in [`solver::jerk::rest_phase_length`]), and
        // its jerk is bounded along the whole interval ([`solver::jerk::rest_bounds`]); the
        // re-simulation checks the rest, as everywhere.
        if let Some(d) = first {
            u.retain(|&x| x == u0 || x > u0 + d * (1.0 + 1e-9));
            u.push(u0 + d);
        }
        if let Some(d) = last {
            u.retain(|&x| x == un || x < un - d * (1.0 + 1e-9));
            u.push(un - d);
        }
        if u.len() == p.u.len() && first.is_none() && last.is_none() {
            return p;
        }
        u.sort_by(f64::total_cmp);
        u.dedup();
        let span = &self.path.spans[si];
        let mut q = SpanProblem::at_stations_within(
            span,
            &self.kin,
            self.machine,
            u,
            options.verify.chord.as_ref(),
        );
        (q.b_start, q.b_end, q.ramp) = (p.b_start, p.b_end, p.ramp);
        q
    }

    /// Re-simulates one level's schedule.
    /// The re-simulation of a level, and the intervals above `1 + mark` ([`verify_marked`]).
    fn verify_marked(
        &self,
        lv: &Level,
        options: &Options,
        mark: f64,
    ) -> Result<(Verification, Vec<Violation>)> {
        verify_marked(
            self.machine,
            &self.kin,
            &self.path.spans,
            &lv.problems,
            &lv.solutions,
            &options.verify,
            mark,
        )
    }

    /// Divides every interval of `marks` (where the re-simulation found a limit exceeded, or
    /// nearly: [`LOCAL_MARK`]) into equal parts (as many as its excess asks, [`local_parts`])
    /// and solves the spans concerned again, in parallel: the excess between stations falls as
    /// Δu², so a round or two suffice, and only where the path needs it. Returns the spans
    /// solved again, those from rest to rest the solver failed on, which keep their profiles,
    /// and the problems and profiles the new ones replaced; the level's schedule is left for
    /// the caller to rebuild.
    fn refine_where_violated(
        &self,
        lv: &mut Level,
        marks: &[Mark],
        options: &Options,
    ) -> Result<RefineOutcome> {
        use rayon::prelude::*;
        let split = marked_parts(
            marks.iter().copied(),
            lv.problems.len(),
            options.verify.tolerance,
        );
        // The spans concerned in parallel (each span's windows join the same pool).
        let jobs: Vec<(usize, Vec<(usize, usize)>)> = split
            .into_iter()
            .enumerate()
            .filter(|(_, ks)| !ks.is_empty())
            .collect();
        let solved: Vec<(usize, Option<(SpanProblem, SpanSolution)>)> = jobs
            .into_par_iter()
            .map(|(si, ks)| {
                let old = &lv.problems[si];
                let mut p = old.with_divided(
                    &self.path.spans[si],
                    &self.kin,
                    self.machine,
                    options.verify.chord.as_ref(),
                    &ks,
                );
                self.check_travel(si, &p)?;
                (p.b_start, p.b_end, p.ramp) = (old.b_start, old.b_end, old.ramp);
                match self.solve_span(si, &p, options, Some((old, &lv.solutions[si])), None, true) {
                    Ok(s) => Ok((si, Some((p, s)))),
                    // A span from rest to rest whose finer grid the solver fails on keeps its
                    // profile, to be slowed down where it exceeds a limit (the caller's
                    // `failed`): one such span failed the whole Röders finishing program with
                    // jerk limits (Clarabel's InsufficientProgress on intervals of 1e-6 mm
                    // at a curvature peak).
                    Err(Error::Solver(e)) if old.b_start == 0.0 && old.b_end == 0.0 => {
                        tracing::debug!("span {si}: {e}; its profile is kept");
                        Ok((si, None))
                    }
                    Err(e) => Err(e),
                }
            })
            .collect::<Vec<Result<_>>>()
            .into_iter()
            .collect::<Result<_>>()?;
        let (mut touched, mut failed) = (Vec::with_capacity(solved.len()), Vec::new());
        let mut replaced = Vec::with_capacity(solved.len());
        for (si, solved) in solved {
            let Some((p, s)) = solved else {
                failed.push(si);
                continue;
            };
            lv.iterations += s.iterations;
            lv.solve_time += s.solve_time;
            lv.status = lv.status.worst(s.status);
            replaced.push((
                si,
                std::mem::replace(&mut lv.problems[si], p),
                std::mem::replace(&mut lv.solutions[si], s),
            ));
            touched.push(si);
        }
        Ok((touched, failed, replaced))
    }

    /// Re-simulates spans `which` of a level on their own (each on its own clock, from 0), with
    /// the violations' span indices those of the path.
    fn verify_spans(
        &self,
        lv: &Level,
        which: &[usize],
        options: &Options,
        mark: f64,
    ) -> Result<(Verification, Vec<Violation>)> {
        let spans: Vec<Span> = which
            .iter()
            .map(|&si| self.path.spans[si].clone())
            .collect();
        let problems: Vec<SpanProblem> = which.iter().map(|&si| lv.problems[si].clone()).collect();
        let solutions: Vec<SpanSolution> =
            which.iter().map(|&si| lv.solutions[si].clone()).collect();
        let (mut v, mut marks) = verify_marked(
            self.machine,
            &self.kin,
            &spans,
            &problems,
            &solutions,
            &options.verify,
            mark,
        )?;
        for w in v.violations.iter_mut().chain(&mut marks) {
            w.span = which[w.span];
        }
        Ok((v, marks))
    }

    /// Solves one span's problem with the chosen solver, after the reach pass has checked that a
    /// schedule exists (and said where not). `previous`: a profile on stations that `p`
    /// contains, the jerk-limited SCP's start; `local`: solve again only about the stations
    /// `p` adds to it ([`Warm::local`]).
    fn solve_span(
        &self,
        si: usize,
        p: &SpanProblem,
        options: &Options,
        previous: Option<(&SpanProblem, &SpanSolution)>,
        greedy: Option<SpanSolution>,
        local: bool,
    ) -> Result<SpanSolution> {
        // The O(N) pass runs first whatever the solver (unless the caller has its profile on
        // these stations already): it finds an impossible request and says where, which a
        // convex solver's infeasibility certificate cannot.
        let greedy = match greedy {
            Some(g) => g,
            None => self.reach(si, p, &options.solver)?,
        };
        if self.machine.has_jerk() {
            if options.solver_kind == SolverKind::Reach {
                return Err(Error::Usage(
                    "the machine has jerk limits: only the clarabel solver honours them (or \
                     drop them with --no-jerk)"
                        .into(),
                ));
            }
            let kept = self.mid_bounds[si]
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .take();
            let jd = JerkData::new(
                &self.path.spans[si],
                &self.kin,
                self.machine,
                p,
                options.verify.chord.as_ref(),
                options.solver.worker_threads(),
                kept.as_ref(),
            );
            *self.mid_bounds[si]
                .lock()
                .unwrap_or_else(|e| e.into_inner()) = Some(jd.bounds(p));
            let warm = previous
                .and_then(|(op, os)| Warm::resample(op, os, p))
                .map(|w| Warm { local, ..w });
            let key = self.reuse.key(
                p,
                &options.solver,
                Some(&options.jerk),
                &greedy,
                warm.as_ref(),
                |out| jd.fingerprint(out),
            );
            // Where, and what to try: a bare solver status named neither.
            let named = |e: Error| match e {
                Error::Solver(why) => {
                    let span = &self.path.spans[si];
                    let (a, b) = (
                        span.nearest_line(p.u[0]),
                        span.nearest_line(p.u[p.intervals()]),
                    );
                    Error::Solver(format!(
                        "span {si} (CL lines {a}–{b}): the jerk-limited solve failed ({why}): \
                         drop the jerk limits with --no-jerk, or report the program"
                    ))
                }
                other => other,
            };
            return self.reuse.answer(key, || {
                solver::jerk::solve(p, &jd, &greedy, warm, &options.solver, &options.jerk)
                    .map_err(named)
            });
        }
        if options.solver_kind == SolverKind::Reach {
            return Ok(greedy);
        }
        let key = self
            .reuse
            .key(p, &options.solver, None, &greedy, None, |_| ());
        self.reuse
            .answer(key, || solver::optimal(p, &greedy, &options.solver))
    }

    /// Turns the reach pass's finding into an error naming span, station, u, CL line and axes.
    fn infeasible(&self, si: usize, p: &SpanProblem, inf: &solver::reach::Infeasible) -> Error {
        let span = &self.path.spans[si];
        let u = p.u[inf.station];
        let names: Vec<String> = inf
            .binding
            .iter()
            .filter_map(|b| match *b {
                Bound::AxisVelocity(j) => Some(format!("{} velocity", self.axes[j])),
                Bound::AxisAcceleration(j) => Some(format!("{} acceleration", self.axes[j])),
                Bound::AxisJerk(j) => Some(format!("{} jerk", self.axes[j])),
                Bound::Feed => Some("the feed cap".to_string()),
                Bound::Chord => Some("the chord tolerance".to_string()),
                Bound::Process(l) => Some(format!("the {} limit", l.label())),
                Bound::None => None,
            })
            .collect();
        let binding = if names.is_empty() {
            String::new()
        } else {
            format!("; binding: {}", names.join(", "))
        };
        Error::Infeasible(format!(
            "span {si}, station {} of {}, u = {u:.6}, nearest CL line {}: {}{binding}",
            inf.station,
            p.intervals(),
            span.nearest_line(u),
            inf.what
        ))
    }

    /// Solves every span on a fixed grid of about `total` stations (`--stations`).
    fn solve_at(&self, total: usize, options: &Options) -> Result<Level> {
        let mut problems = Vec::with_capacity(self.path.spans.len());
        let mut solutions = Vec::with_capacity(self.path.spans.len());
        for si in 0..self.path.spans.len() {
            let p = self.final_grid(si, self.uniform_problem(si, total, options)?, options);
            solutions.push(self.solve_span(si, &p, options, None, None, false)?);
            problems.push(p);
        }
        self.level(problems, solutions)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The smallest errors summing to half the allowance stay; the rest are marked (above the
    /// threshold), ties with the first error that passes half the allowance included.
    #[test]
    fn the_threshold_marks_every_error_tied_with_the_first_one_over_the_allowance() {
        let marked = |e: &[f64], allowance: f64| -> Vec<f64> {
            let t = threshold(e.iter().copied(), allowance);
            e.iter().copied().filter(|&x| x > t).collect()
        };
        // A repeated pattern: equal errors (a threshold equal to them marked none).
        assert_eq!(marked(&[1.0; 4], 2.0), vec![1.0; 4]);
        assert_eq!(marked(&[0.2, 1.0, 0.1, 1.0, 1.0], 0.8), vec![1.0; 3]);
        assert_eq!(marked(&[0.1, 0.2, 0.3, 2.0], 1.3), vec![2.0]);
        // Within half the allowance: nothing to mark.
        assert!(marked(&[0.1, 0.2], 1.0).is_empty());
        assert!(marked(&[0.0, 0.0], 0.0).is_empty());
    }

    #[test]
    fn divide_splits_the_listed_intervals_into_equal_parts() {
        use crate::constraints::divide;
        let u = [0.0, 1.0, 3.0, 4.0];
        let out = divide(&u, &[(1, 4), (2, 2)]);
        assert_eq!(out, vec![0.0, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0]);
        assert_eq!(divide(&u, &[]), u.to_vec());
    }

    /// The local refinement gives up on an excess that doubles twice in a row, not on one
    /// that wanders or shrinks.
    #[test]
    fn a_refinement_whose_excess_keeps_doubling_is_diverging() {
        assert!(!diverging(&[0.019]));
        assert!(!diverging(&[0.019, 0.0028]));
        assert!(!diverging(&[0.019, 0.0028, 0.0011]));
        assert!(!diverging(&[0.002, 0.003, 0.004]));
        assert!(diverging(&[0.002, 0.011, 1.4]));
        assert!(diverging(&[0.5, 0.002, 0.011, 1.4]));
        assert!(!diverging(&[0.002, 0.011, 0.015]));
        assert!(!diverging(&[0.0, 0.0, 0.0]));
        // Small excesses that wander: left to the rounds.
        assert!(!diverging(&[0.0005, 0.0012, 0.0073]));
        assert!(diverging(&[0.0028, 0.0276, 0.395]));
        assert!(!diverging(&[0.042, 0.068, 0.011, 0.0335, 0.0798]));
    }

    /// Each span's history holds its last three worst excesses, 0 where it had none; a span
    /// whose excess keeps doubling is told apart from one that converges beside it.
    #[test]
    fn each_span_keeps_its_own_excess_history() {
        let violation = |span: usize, ratio: f64| Violation {
            span,
            interval: 0,
            u: 0.0,
            t: 0.0,
            axis: Some(0),
            kind: Quantity::Jerk,
            value: ratio,
            limit: 1.0,
            ratio,
        };
        let verification = |violations: Vec<Violation>| Verification {
            verified: violations.is_empty(),
            violating_intervals: violations.len(),
            violations,
            ..Verification::default()
        };
        let mut excess = vec![Vec::new(); 3];
        for round in [
            vec![
                violation(0, 1.003),
                violation(1, 1.004),
                violation(1, 1.002),
            ],
            vec![violation(0, 1.02), violation(1, 1.001)],
            vec![violation(0, 1.3)],
            vec![violation(0, 1.9), violation(2, 1.01)],
        ] {
            record_excess(&mut excess, &verification(round));
        }
        let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        assert!(close(&excess[0], &[0.02, 0.3, 0.9]), "{:?}", excess[0]);
        assert!(close(&excess[1], &[0.001, 0.0, 0.0]), "{:?}", excess[1]);
        assert!(close(&excess[2], &[0.0, 0.0, 0.01]), "{:?}", excess[2]);
        assert!(excess.iter().all(|h| h.len() == 3));
        assert!(!diverging(&excess[1]) && !diverging(&excess[2]));
        // 0.003, 0.02, 0.3 doubled twice to over a quarter.
        let mut first = vec![Vec::new(); 1];
        for r in [1.003, 1.02, 1.3] {
            record_excess(&mut first, &verification(vec![violation(0, r)]));
        }
        assert!(diverging(&first[0]));
    }

    /// A span is slowed by the least factor that brings its worst excess within the limit:
    /// velocity falls as 1/f, acceleration as 1/f², jerk as 1/f³; a span that does not start
    /// and end at rest cannot be slowed on its own.
    #[test]
    fn slow_down_factors_follow_the_powers_of_each_quantity() {
        let violation = |span: usize, kind: Quantity, ratio: f64| Violation {
            span,
            interval: 0,
            u: 0.0,
            t: 0.0,
            axis: Some(0),
            kind,
            value: ratio,
            limit: 1.0,
            ratio,
        };
        let vs = [
            violation(0, Quantity::Jerk, 1.331),
            violation(0, Quantity::Velocity, 1.05),
            violation(1, Quantity::Acceleration, 1.21),
            violation(2, Quantity::Feed, 1.5),
        ];
        let m = 1.0 + SLOW_DOWN_MARGIN;
        let f = slow_down_factors(&vs, 4, |s| s < 2, |_| true).expect("at rest");
        assert!((f[0] - 1.1 * m).abs() < 1e-12, "{f:?}");
        assert!((f[1] - 1.1 * m).abs() < 1e-12, "{f:?}");
        assert_eq!((f[2], f[3]), (1.0, 1.0));
        // After slowing by f, each excess is within its limit: r / f^k ≤ 1.
        assert!(1.331 / f[0].powi(3) <= 1.0 && 1.05 / f[0] <= 1.0 && 1.21 / f[1].powi(2) <= 1.0);
        assert!(slow_down_factors(&vs, 4, |_| true, |s| s != 2).is_none());
        assert!(slow_down_factors(&vs, 4, |s| s < 2, |s| s != 2).is_some());
        let bad = [violation(0, Quantity::Jerk, f64::INFINITY)];
        assert!(slow_down_factors(&bad, 1, |_| true, |_| true).is_none());
    }

    /// m parts take an excess e (∝ Δu²) to e/m²: at most a quarter of the tolerance when m is
    /// not capped; at least a halving; at most MAX_LOCAL_SPLIT.
    #[test]
    fn local_parts_bring_a_second_order_excess_under_the_tolerance() {
        let tol = 1e-3;
        for ratio in [1.0011, 1.0015, 1.003, 1.01, 1.012, 1.0155] {
            let m = local_parts(ratio, tol);
            let excess = ratio - 1.0;
            assert!((2..=MAX_LOCAL_SPLIT).contains(&m), "{ratio}: {m}");
            assert!(
                excess / (m * m) as f64 <= 0.25 * tol,
                "{ratio}: {m} parts leave {}",
                excess / (m * m) as f64
            );
            // No more parts than needed: one fewer would not do (or the floor of 2 holds).
            let fewer = m - 1;
            assert!(
                m == 2 || excess / (fewer * fewer) as f64 > 0.25 * tol,
                "{ratio}: {m}"
            );
        }
        assert_eq!(local_parts(1.036, tol), MAX_LOCAL_SPLIT);
        assert_eq!(local_parts(f64::INFINITY, tol), MAX_LOCAL_SPLIT);
        assert_eq!(local_parts(1.0005, tol), 2);
    }
}
