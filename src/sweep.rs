//! Constraint study (`feedopt sweep`): how the cycle time T depends on one axis limit.
//!
//! For each of `steps` values v of one axis's velocity or acceleration limit the path is
//! solved again and reported: T(v), which limit holds the feed down over what share of the
//! path and of the time (the classification of [`crate::report::Summary`]), the 1 ms
//! re-simulation of the step's schedule, and the sensitivity dT/dv (s per mm/s, mm/s², °/s or
//! °/s²) twice: from the solver's dual variables and by central finite differences.
//!
//! **Scaling the limit.** A symmetric limit becomes ±v. An asymmetric one `[min, max]` is
//! scaled proportionally so that its max is v: `[min·v/max, v]` (both sides move together, so
//! the study changes one number, not the asymmetry). Every step is therefore the nominal
//! machine with that axis's limit multiplied by μ = v / max₀.
//!
//! **A common station set.** The automatic refinement of [`crate::optimize`] picks its
//! station count from the limits; letting it run at every step would change the
//! discretisation from step to step, so T(v) would carry discretisation jumps (spoiling
//! monotonicity) and a finite difference would mix two discretisations. The sweep therefore
//! solves once, at the nominal limits, with the steps' own solver and the user's station
//! options (`--stations N` or automatic), and starts from that solve's stations — including
//! those added where its re-simulation failed. (The stations came from a reachability solve
//! until round 11: its profile verified on them, but the cone program's optimum on the same
//! stations, which rides other limits between stations, did not, so the step at the machine's
//! own limit was unverified on four of twelve real programs, NX's Mori NMV5000 program by
//! 20.6 %, while `solve` verified there.)
//!
//! Other limits need stations elsewhere: a step whose ramps or curvature-held stretches move
//! exceeds its limits between the nominal stations (the LinuxCNC impeller's C acceleration at
//! 40 °/s², 3.3 % over at 31,267 stations, 3.3 times over at 8,887; a test's smooth joint path
//! 40 % over at a tenth of its velocity limit). Each step's schedule is re-simulated at the
//! servo period, and where one exceeds a limit, the intervals it marks are divided as `solve`'s
//! local refinement divides them (`optimize::marked_parts`) — *for every step* — and the steps
//! are solved again, up to [`SWEEP_ROUNDS`] times and [`MAX_STATION_GROWTH`] times the
//! baseline's stations: one station set, fine enough for every step. While the stations
//! change only some steps run (the two ends of the range first, then those a run of all found
//! over a limit); all run again on the final set. A step still over
//! a limit after the last round reports `verified: false` and its worst ratio. The finite
//! differences' solves, 1 % from their step's limit, are timed but not re-simulated.
//! (`refine_until_verified: false` keeps the baseline's stations.)
//!
//! **The sensitivity from the duals.** Scale the swept limit by μ around a step (μ = 1 there);
//! then dT/dv = (1/v)·dT/dμ. Per span, with the multipliers of
//! [`crate::solver::clarabel::solve_with_sensitivity`]
//! (dT/db_max_i = −y_i/B, dT/da = −Σ y_r/a over an axis's acceleration rows of one side):
//!
//! ```text
//! velocity:      dT/dμ = Σ_i dT/db_max_i · 2 b_max_i          over stations whose b_max is this
//!                                                              axis's velocity bound (v/q')²
//! acceleration:  dT/dμ = dT/da_max · a_max + dT/da_min · a_min
//!                      + Σ_i dT/db_max_i · ∂b*_i/∂μ           over stations whose b_max is the
//!                                                              acceleration-limited b*_i
//! ```
//!
//! so for an acceleration limit the row part alone is dT/dv = −(1/v) Σ y_r over every row of
//! the axis (both sides alike: each limit is μ times its nominal value). The second term is
//! needed because b*_i, the largest b the acceleration rows allow at station i, is stated as
//! the station's bound `b ≤ b_max` and the interior-point method shares the multiplier between
//! that bound and the rows it is implied by. ∂b*_i/∂μ is the derivative of
//! [`essential_rows`]' b* (a closed-form vertex of the station's (b, ü) polygon), taken by a
//! central difference of relative step 1e-6 (exact to rounding except exactly at a vertex
//! switch, where T is not differentiable either).
//!
//! **Lattice spans: no cone program.** Where the largest profile of the lattice relaxation
//! ([`solver::reach::solve_lattice`]) meets every row the relaxation leaves out, it is the
//! exact optimum of the span's discretisation ([`solver::optimal`]), and dT/dμ is the
//! derivative of that optimum's time. It is taken by a central difference of relative step
//! ε = [`LATTICE_EPS`]: the span solved again at μ = 1 ± ε, both times still lattice-exact
//! (else the span is a cone program). This is the quantity the multipliers give (the
//! derivative of the optimal value), found another way: exact to O(ε²) and rounding (about
//! 1e-10 of T over 2ε) wherever T is smooth, the mean of its one-sided slopes at a kink, where
//! the multipliers give one subgradient. The two ways agree to 3e-5 on the test paths (test
//! `the_lattice_derivative_equals_clarabels_duals`). Only the other spans are solved as cone
//! programs: on the CAMotics bear (481k stations, 3,209 spans) 1 to 3 spans a step, and a
//! 20-step sweep of X's acceleration took 54 s instead of 958 s (the same 20 minutes, the
//! machine shared with another job). [`SweepPoint::cone_spans`] says how many a step solved.
//!
//! **One window.** The clarabel solver splits long spans into windows stitched at stations
//! whose b is fixed to the reachability profile's value. Those stitch values are constants of
//! each window's problem but move with the limits (a stitch sits where the profile meets a
//! velocity or acceleration-limited bound), so the windows' duals alone would miss the terms
//! (∂T_left/∂b_s + ∂T_right/∂b_s)·db_s/dv of every stitch s, and the reach profile's choice of
//! stitch makes db_s/dv discontinuous. The sweep therefore solves every span as one cone
//! program (cost and memory still linear in the stations; one span per thread) and gets its
//! parallelism from running steps in parallel (rayon), with the solver's and the
//! re-simulation's own thread counts at 1.
//!
//! **Finite differences.** T(v(1+h)) and T(v(1−h)) at the same stations, h = `fd_step`
//! (default 1 %): dT/dv ≈ (T₊ − T₋)/(2hv). The value function T(v) of the discretised problem
//! is only piecewise smooth: its derivative jumps where the set of active rows changes. The
//! sweep calls a step *smooth* when the dual sensitivity at v(1−h), v and v(1+h) lies on one
//! line within 5 % (|s₋ + s₊ − 2s| ≤ 0.05 |s|, and s₋, s, s₊ of one sign) *and* the same limits
//! hold the feed down somewhere (the labels with a share of the path in the report's binding
//! table) at all three. Then the active set changes over the bracket only by rows whose
//! multipliers are small, so the central difference, which averages dT/dv over the bracket,
//! must agree with the dual at v to O(h²). On a fine discretisation the active set always
//! shifts by a station or two, each moving dT/dv by O(1/N): that is what the 5 % allows. Where
//! a limit starts or stops binding inside the bracket, dT/dv jumps and the two estimates may
//! legitimately differ. Where the swept limit binds nowhere (`binds: false`), dT/dv = 0 and
//! both estimates are solver noise (|dT/dv|·v/T of order the gap tolerance).

use std::collections::BTreeMap;
use std::fmt;

use rayon::prelude::*;
use serde::Serialize;

use crate::constraints::{Bound, SpanProblem, essential_rows};
use crate::error::number;
use crate::error::{Error, Result};
use crate::machine::{AxisKind, KinematicsSpec, Limit, Machine};
use crate::optimize::{self, Options, Solution, optimize_input};
use crate::report::{BindingShare, Summary};
use crate::schedule::Schedule;
use crate::solver::clarabel::{Sensitivity, solve_with_sensitivity};
use crate::solver::{self, SolverKind, Status};
use crate::toolpath::Input;
use crate::verify::verify_marked;

/// Which limit of the axis is swept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum SweptLimit {
    /// The velocity limit.
    Velocity,
    /// The acceleration limit.
    Acceleration,
}

impl fmt::Display for SweptLimit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SweptLimit::Velocity => "velocity",
            SweptLimit::Acceleration => "acceleration",
        })
    }
}

/// What to sweep and how to solve each step.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Axis name, as in the machine file (e.g. `"C"`).
    pub axis: String,
    /// Which of its limits.
    pub limit: SweptLimit,
    /// First limit value (the max side; mm/s, mm/s², °/s or °/s²).
    pub from: f64,
    /// The last value.
    pub to: f64,
    /// Number of values, evenly spaced from `from` to `to` (1: `from` only).
    pub steps: usize,
    /// Relative step h of the central finite differences, v(1 ± h).
    pub fd_step: f64,
    /// Solve options: geometry, stations, solver, verification. The solver's windows and
    /// threads and the re-simulation's threads are overridden (one window, one thread: see
    /// the module doc).
    pub solve: Options,
    /// Draw a progress bar on stderr (with the cargo feature `progress`; without it, nothing
    /// is drawn).
    pub progress: bool,
    /// With the Clarabel solver: take a span's optimum and dT/dμ from the lattice relaxation
    /// where its largest profile is the exact optimum (module doc), and solve a cone program
    /// only for the other spans (default). `false`: a cone program for every span (its duals
    /// give every span's dT/dμ), as a check of the other way.
    pub lattice: bool,
}

impl SweepOptions {
    /// Options for `steps` values of `axis`'s `limit` from `from` to `to`, otherwise defaults.
    pub fn new(axis: &str, limit: SweptLimit, from: f64, to: f64, steps: usize) -> Self {
        SweepOptions {
            axis: axis.to_string(),
            limit,
            from,
            to,
            steps,
            fd_step: 0.01,
            solve: Options::default(),
            progress: false,
            lattice: true,
        }
    }

    /// The limit values of the steps.
    pub fn values(&self) -> Vec<f64> {
        if self.steps <= 1 {
            return vec![self.from];
        }
        let n = self.steps - 1;
        (0..=n)
            .map(|k| self.from + (self.to - self.from) * k as f64 / n as f64)
            .collect()
    }
}

/// The most steps a sweep takes (each is three solves: the value and its finite differences).
pub const MAX_STEPS: usize = 10_000;

/// How far from the machine's own limit a sweep may go: from 1/`MAX_SWEEP_FACTOR` to
/// `MAX_SWEEP_FACTOR` times it. The cycle time, and with it the re-simulation's work, grows as
/// the limit shrinks; a study beyond this range is no longer about that machine.
pub const MAX_SWEEP_FACTOR: f64 = 1e3;

/// One step of the sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepPoint {
    /// The swept limit's max side at this step.
    pub limit: f64,
    /// Cycle time T at `limit`, s (the program's dwells included, as `solve` reports it).
    pub cycle_time_s: f64,
    /// dT/dv, the derivative of the discretised optimum, s per unit of the limit: from the
    /// dual variables on the spans solved as cone programs, from the lattice optimum's central
    /// difference on the others (module doc; `None` with the reach solver).
    pub sensitivity_dual: Option<f64>,
    /// dT/dv by central differences (T₊ − T₋)/(2hv).
    pub sensitivity_fd: f64,
    /// T at v(1 − h), s.
    pub cycle_time_minus_s: f64,
    /// T at v(1 + h), s.
    pub cycle_time_plus_s: f64,
    /// The dual sensitivity at v(1 − h).
    pub sensitivity_dual_minus: Option<f64>,
    /// The dual sensitivity at v(1 + h).
    pub sensitivity_dual_plus: Option<f64>,
    /// The swept limit holds the feed down somewhere at this step (its share of the path in
    /// [`binding`](Self::binding) is not 0). Where it does not, dT/dv = 0 and both estimates
    /// are solver noise.
    pub binds: bool,
    /// The binding set does not change over the finite-difference bracket (module doc), so the
    /// two sensitivities must agree.
    pub smooth: bool,
    /// |dual − FD| / |dual| (`None` without duals or where the dual is 0).
    pub relative_difference: Option<f64>,
    /// Which limit holds the feed down over what share of the path and of the time.
    pub binding: Vec<BindingShare>,
    /// The worst status over the step's spans.
    pub status: Status,
    /// The step's schedule re-simulated at the servo period keeps every limit.
    pub verified: bool,
    /// Its worst ratio to any limit.
    pub worst_ratio: f64,
    /// Solver time of the step (the centre solve), s.
    pub solve_time_s: f64,
    /// Spans of the centre solve solved as cone programs (Clarabel's multipliers give their
    /// dT/dμ); the others' optimum is the lattice relaxation's largest profile (module doc).
    pub cone_spans: usize,
}

/// A whole sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sweep {
    /// The machine's name.
    pub machine: String,
    /// The toolpath as named by the caller.
    pub toolpath: String,
    /// The swept axis.
    pub axis: String,
    /// Which of its limits.
    pub limit: SweptLimit,
    /// Unit of the limit values (`mm/s²`, `deg/s`, …); sensitivities are in s per this unit.
    pub unit: String,
    /// The machine's own limit (min, max) before scaling.
    pub nominal_min: f64,
    /// The machine's own limit, max side.
    pub nominal_max: f64,
    /// Stations (the same for every step) and spans.
    pub stations: usize,
    /// Rounds in which the stations were divided where a step exceeded a limit between them
    /// (0: the baseline's stations verified every step; module doc).
    pub refinement_rounds: usize,
    /// Rest-to-rest spans.
    pub spans: usize,
    /// Relative finite-difference step h.
    pub fd_step: f64,
    /// The solver of the steps: `"clarabel"` or `"reach"`.
    pub solver: String,
    /// The steps, in order of the limit.
    pub points: Vec<SweepPoint>,
}

/// `limit` scaled so its max side is `value`: ±value if symmetric, `[min·value/max, value]`
/// otherwise.
pub fn scaled_limit(limit: Limit, value: f64) -> Limit {
    Limit {
        min: limit.min * (value / limit.max),
        max: value,
    }
}

/// `machine` with the `which` limit of axis `axis` scaled to `value` ([`scaled_limit`]).
pub fn with_limit(machine: &Machine, axis: usize, which: SweptLimit, value: f64) -> Machine {
    let mut m = machine.clone();
    let a = &mut m.axes[axis];
    match which {
        SweptLimit::Velocity => a.velocity = scaled_limit(a.velocity, value),
        SweptLimit::Acceleration => a.acceleration = scaled_limit(a.acceleration, value),
    }
    m
}

/// What every step shares: the path and its kinematics (from the baseline solve), the
/// stations (the baseline's, divided where a step needed it), and the options.
struct Study<'a> {
    machine: &'a Machine,
    axis: usize,
    which: SweptLimit,
    base: Solution,
    /// Per span, the stations every step is solved at: the baseline's, with the intervals
    /// divided where a step's re-simulation found a limit exceeded (module doc).
    grid: Vec<Vec<f64>>,
    options: Options,
    toolpath: String,
    lattice: bool,
}

/// One solve at one limit value.
struct Eval {
    cycle_time: f64,
    /// dT/dv from the duals.
    sensitivity: Option<f64>,
    summary: Summary,
    /// Spans solved as cone programs (the others: the lattice relaxation's exact optimum).
    cone_spans: usize,
    /// Where its re-simulation found a limit exceeded (or nearly, [`optimize::LOCAL_MARK`]),
    /// with the intervals the motion's model predicts so ([`optimize::predicted_marks`]);
    /// empty where it verified.
    marks: Vec<optimize::Mark>,
}

impl Study<'_> {
    /// Solves the whole path with the swept limit at `value`, at the study's stations, and
    /// re-simulates the schedule where `check` (a step's centre; a finite difference's solve
    /// is only timed).
    fn evaluate(&self, value: f64, check: bool) -> Result<Eval> {
        let machine = with_limit(self.machine, self.axis, self.which, value);
        let kin = &self.base.kinematics;
        let spans = &self.base.path.spans;
        let axes: Vec<String> = machine.axes.iter().map(|a| a.name.clone()).collect();
        let mut problems = Vec::with_capacity(spans.len());
        let mut solutions = Vec::with_capacity(spans.len());
        let (mut status, mut iterations, mut solve_time) = (Status::Optimal, 0, 0.0);
        let mut dt_dmu = 0.0;
        let mut cone_spans = 0;
        for (si, span) in spans.iter().enumerate() {
            let p = self.problem(si, &machine);
            // The reachability pass, for its profile (`--solver reach`) or to name where the
            // limits leave no feasible profile. A lattice-exact span needs neither: its
            // profile meets every row, so the span is feasible.
            let greedy = |p: &SpanProblem| {
                solver::reach::solve(p).map_err(|inf| {
                    Error::Infeasible(format!(
                        "with the {} {} limit at {value}: span {si}, station {}, nearest CL line {}: {}",
                        self.machine.axes[self.axis].name,
                        self.which,
                        inf.station,
                        span.nearest_line(p.u[inf.station]),
                        inf.what
                    ))
                })
            };
            let s = match self.options.solver_kind {
                SolverKind::Reach => greedy(&p)?,
                SolverKind::Clarabel => {
                    let exact = if self.lattice {
                        self.lattice_optimum(&p, si, value)?
                    } else {
                        None
                    };
                    match exact {
                        Some((s, d)) => {
                            dt_dmu += d;
                            s
                        }
                        None => {
                            greedy(&p)?;
                            let (s, sens) = solve_with_sensitivity(&p, &self.options.solver)?;
                            dt_dmu += span_dt_dmu(&p, &sens, self.axis, self.which);
                            cone_spans += 1;
                            s
                        }
                    }
                }
            };
            status = status.worst(s.status);
            iterations += s.iterations;
            solve_time += s.solve_time;
            problems.push(p);
            solutions.push(s);
        }
        let schedule = Schedule::build(&axes, spans, &problems, &solutions)?;
        let (verification, mut marks) = if check {
            verify_marked(
                &machine,
                kin,
                spans,
                &problems,
                &solutions,
                &self.options.verify,
                optimize::LOCAL_MARK * self.options.verify.tolerance,
            )?
        } else {
            Default::default()
        };
        if verification.verified {
            marks.clear();
        }
        let mut marks = optimize::marks_of(&marks);
        if !marks.is_empty() {
            // What the model of the motion between stations predicts too (`solve`'s local
            // refinement does the same).
            marks.extend(optimize::predicted_marks(
                &problems,
                &solutions,
                &self.options.verify,
                optimize::LOCAL_MARK * self.options.verify.tolerance,
            )?);
        }
        let cycle_time = schedule.cycle_time;
        let sol = Solution {
            path: self.base.path.clone(),
            kinematics: kin.clone(),
            problems,
            solutions,
            schedule,
            status,
            iterations,
            solve_time,
            refinement: Vec::new(),
            error_estimate: None,
            error_target: None,
            unconverged: None,
            slowed_down: None,
            verification,
            verify_period: self.options.verify.period,
            corners_blended: self.base.corners_blended,
            reused_solves: 0,
        };
        let summary = Summary::new(&machine, &self.toolpath, &sol);
        Ok(Eval {
            cycle_time,
            sensitivity: (self.options.solver_kind == SolverKind::Clarabel)
                .then(|| dt_dmu / machine_limit(&machine, self.axis, self.which).max),
            summary,
            cone_spans,
            marks,
        })
    }

    /// Stations over all spans.
    fn stations(&self) -> usize {
        self.grid.iter().map(Vec::len).sum()
    }

    /// The study's stations with every interval some step marked divided as the local
    /// refinement of `solve` divides it (the most parts any step asks for); `None` where that
    /// would pass `max_stations` stations.
    fn divided(&self, evals: &[Eval], max_stations: usize) -> Option<Vec<Vec<f64>>> {
        let split = optimize::marked_parts(
            evals.iter().flat_map(|e| e.marks.iter().copied()),
            self.grid.len(),
            self.options.verify.tolerance,
        );
        let mut grid = self.grid.clone();
        for (u, ks) in grid.iter_mut().zip(&split) {
            if !ks.is_empty() {
                *u = crate::constraints::divide(u, ks);
            }
        }
        (grid.iter().map(Vec::len).sum::<usize>() <= max_stations).then_some(grid)
    }

    /// Span `si`'s problem on the study's stations with `machine`'s limits, its end speeds
    /// and chord bound as the baseline's.
    fn problem(&self, si: usize, machine: &Machine) -> SpanProblem {
        let (span, old) = (&self.base.path.spans[si], &self.base.problems[si]);
        let mut p = SpanProblem::at_stations_within(
            span,
            &self.base.kinematics,
            machine,
            self.grid[si].clone(),
            self.options.verify.chord.as_ref(),
        );
        (p.b_start, p.b_end, p.ramp) = (old.b_start, old.b_end, old.ramp);
        p
    }

    /// Where the lattice relaxation's largest profile is the exact optimum of span `p` (the
    /// swept limit at `value`) and stays so at `value·(1 ± ε)`: that profile and dT/dμ, the
    /// central difference (T(1 + ε) − T(1 − ε)) / 2ε of the span's optimal time with ε =
    /// [`LATTICE_EPS`] (module doc). `None` where a cone program is needed.
    fn lattice_optimum(
        &self,
        p: &SpanProblem,
        si: usize,
        value: f64,
    ) -> Result<Option<(solver::SpanSolution, f64)>> {
        let exact = |p: &SpanProblem| -> Option<solver::SpanSolution> {
            let s = solver::reach::solve_lattice(p).ok()?;
            solver::reach::lattice_violations(p, &s.b, 1e-9)
                .is_empty()
                .then_some(s)
        };
        let Some(mut s) = exact(p) else {
            return Ok(None);
        };
        // The exact optimum of the discretisation, as `solver::optimal` calls it (the passes
        // label their profile greedy: in general it is only feasible).
        s.status = Status::Optimal;
        let mut times = [0.0; 2];
        for (t, mu) in times.iter_mut().zip([1.0 - LATTICE_EPS, 1.0 + LATTICE_EPS]) {
            let machine = with_limit(self.machine, self.axis, self.which, value * mu);
            let q = self.problem(si, &machine);
            match exact(&q) {
                Some(sq) => *t = solver::interval_times(&q, &sq)?.iter().sum(),
                None => return Ok(None),
            }
        }
        Ok(Some((s, (times[1] - times[0]) / (2.0 * LATTICE_EPS))))
    }
}

/// Rounds of dividing the study's stations where a step exceeds a limit between them (module
/// doc): each divides the excess by four or more, as `solve`'s local refinement; most run only
/// the steps still over a limit. (The LinuxCNC impeller's C-acceleration study on 8,887
/// requested stations took 6, to 10,000 stations; `solve` allows 12.)
pub const SWEEP_ROUNDS: usize = 8;

/// The most the sweep's rounds may multiply the baseline's stations by (module doc): a step
/// whose excess does not fall as its intervals are divided (where `solve` would slow a span
/// down instead) stops the rounds there, not at `max_stations`. (The LinuxCNC impeller's
/// studies grew them by 1 % and 12 %.)
pub const MAX_STATION_GROWTH: usize = 4;

/// Relative step ε of the lattice optimum's central difference (module doc).
pub const LATTICE_EPS: f64 = 1e-6;

fn machine_limit(machine: &Machine, axis: usize, which: SweptLimit) -> Limit {
    match which {
        SweptLimit::Velocity => machine.axes[axis].velocity,
        SweptLimit::Acceleration => machine.axes[axis].acceleration,
    }
}

/// dT/dμ of one span when the swept limit of axis `j` is multiplied by μ (module doc).
pub fn span_dt_dmu(p: &SpanProblem, sens: &Sensitivity, j: usize, which: SweptLimit) -> f64 {
    match which {
        SweptLimit::Velocity => (0..p.u.len())
            .filter(|&i| p.b_max_by[i] == Bound::AxisVelocity(j))
            .map(|i| sens.b_max[i] * 2.0 * p.b_max[i])
            .sum(),
        SweptLimit::Acceleration => {
            let (lim, s) = (p.acceleration[j], sens.acceleration[j]);
            let rows = s.max * lim.max + s.min * lim.min;
            let stations: f64 = (0..p.u.len())
                .filter(|&i| {
                    sens.b_max[i] != 0.0 && matches!(p.b_max_by[i], Bound::AxisAcceleration(_))
                })
                .map(|i| sens.b_max[i] * db_star_dmu(p, i, j))
                .sum();
            rows + stations
        }
    }
}

/// ∂b*_i/∂μ: how the acceleration-limited bound at station `i` moves when both acceleration
/// limits of axis `j` are multiplied by μ (central difference of [`essential_rows`]' b*).
fn db_star_dmu(p: &SpanProblem, i: usize, j: usize) -> f64 {
    const EPS: f64 = 1e-6;
    // Headroom above the current b*, so that the cap does not clip the perturbed vertex.
    let cap = 2.0 * p.b_max[i];
    let at = |mu: f64| {
        let mut lim = p.acceleration.clone();
        lim[j] = Limit {
            min: lim[j].min * mu,
            max: lim[j].max * mu,
        };
        essential_rows(&p.jets.get(i), &lim, cap).1
    };
    (at(1.0 + EPS) - at(1.0 - EPS)) / (2.0 * EPS)
}

/// Three dual sensitivities lie on one line within 5 % of the middle one, all of one sign.
fn smooth(minus: f64, mid: f64, plus: f64) -> bool {
    let same_sign =
        (minus <= 0.0 && mid <= 0.0 && plus <= 0.0) || (minus >= 0.0 && mid >= 0.0 && plus >= 0.0);
    same_sign && (minus + plus - 2.0 * mid).abs() <= 0.05 * mid.abs()
}

/// Runs the sweep (module doc).
pub fn sweep(
    machine: &Machine,
    input: &Input,
    toolpath: &str,
    options: &SweepOptions,
) -> Result<Sweep> {
    options.validate()?;
    optimize::check_inputs(machine, &options.solve).map_err(|e| e.within("solve"))?;
    // The steps are the convex problem of velocity and acceleration limits (its optimum and
    // its derivative): a jerk-limited schedule is not, so the study refuses jerk limits rather
    // than re-simulate acceleration-limited steps against them; with `jerk_limited` off
    // (`--no-jerk`) they are dropped from the machine, for the steps and their check alike.
    let unlimited;
    let machine = if !machine.has_jerk() {
        machine
    } else if options.solve.jerk_limited {
        return Err(Error::option(
            "solve.jerk_limited",
            format!(
                "the machine {} has jerk limits, and the sweep studies the velocity and \
                 acceleration limits only: drop the jerk limits (--no-jerk) to sweep without them",
                machine.name
            ),
        ));
    } else {
        unlimited = machine.without_jerk();
        &unlimited
    };
    // The program's dwells: part of every step's cycle time, as `solve` reports it (they do
    // not depend on the limit).
    let dwells = match input {
        Input::Cl(t) => t.dwell_time(),
        Input::Joint(_) => 0.0,
    };
    let axis = machine
        .axes
        .iter()
        .position(|a| a.name.eq_ignore_ascii_case(&options.axis))
        .ok_or_else(|| {
            let names: Vec<&str> = machine.axes.iter().map(|a| a.name.as_str()).collect();
            Error::option(
                "axis",
                format!(
                    "{}: the machine {} has no such axis (axes: {})",
                    options.axis,
                    machine.name,
                    names.join(", ")
                ),
            )
        })?;
    let which = options.limit;
    let nominal = machine_limit(machine, axis, which);
    let (lo, hi) = (
        nominal.max / MAX_SWEEP_FACTOR,
        nominal.max * MAX_SWEEP_FACTOR,
    );
    for (field, v) in [("from", options.from), ("to", options.to)] {
        if !(lo..=hi).contains(&v) {
            return Err(Error::option(
                field,
                format!(
                    "{} is outside {} to {}, 1/{MAX_SWEEP_FACTOR} to {MAX_SWEEP_FACTOR} times the \
                     machine's {} {which} limit ({}): sweep within that range",
                    crate::error::number(v),
                    crate::error::number(lo),
                    crate::error::number(hi),
                    machine.axes[axis].name,
                    nominal.max
                ),
            ));
        }
    }
    // The stations: one solve at the nominal limits with the steps' solver, as `solve` would
    // refine them (its verification adds the stations that solver's profile needs).
    let base = optimize_input(machine, input, &options.solve)?;
    let mut solve_options = options.solve.clone();
    solve_options.solver.window = usize::MAX;
    solve_options.solver.threads = 1;
    solve_options.verify.threads = 1;
    let grid = base.problems.iter().map(|p| p.u.clone()).collect();
    let mut study = Study {
        machine,
        axis,
        which,
        base,
        grid,
        options: solve_options,
        toolpath: toolpath.to_string(),
        lattice: options.lattice,
    };
    let values = options.values();
    let h = options.fd_step;
    let jobs: Vec<(usize, usize, f64)> = values
        .iter()
        .enumerate()
        .flat_map(|(k, &v)| [(k, 0, v * (1.0 - h)), (k, 1, v), (k, 2, v * (1.0 + h))])
        .collect();
    // Every step at the study's stations; where a step's re-simulation finds a limit exceeded
    // between them, its marked intervals are divided for every step and the steps are solved
    // again (module doc, "A common station set"). While the stations change only some steps
    // run (probes): first the two ends of the range, whose limits are furthest from those the
    // baseline's stations were refined for, then the steps a run of every solve found over a
    // limit, each set until it verifies; every solve then runs again on the final stations.
    // (The finite differences' solves, 1 % from their step's, are timed, not re-simulated.)
    let mut round = 0;
    let refine = options.solve.refine_until_verified;
    let mut probes: Vec<(usize, usize, f64)> = if refine && values.len() > 1 {
        vec![jobs[1], jobs[jobs.len() - 2]]
    } else {
        Vec::new()
    };
    let evals = loop {
        let run: Vec<(usize, usize, f64)> = if probes.is_empty() {
            jobs.clone()
        } else {
            probes.clone()
        };
        #[cfg(feature = "progress")]
        let bar = options.progress.then(|| {
            crate::progress::Counter::new(
                run.len(),
                if round == 0 {
                    format!("{} {} sweep", machine.axes[axis].name, which)
                } else {
                    format!(
                        "{} {} sweep, {} stations (round {round} of refinement)",
                        machine.axes[axis].name,
                        which,
                        study.stations()
                    )
                },
            )
        });
        let evals: Vec<Result<Eval>> = run
            .par_iter()
            .map(|&(_, which, v)| {
                let e = study.evaluate(v, which == 1);
                #[cfg(feature = "progress")]
                if let Some(b) = &bar {
                    b.inc();
                }
                e
            })
            .collect();
        #[cfg(feature = "progress")]
        drop(bar);
        let evals = evals.into_iter().collect::<Result<Vec<Eval>>>()?;
        tracing::debug!(
            "sweep: {} of {} solves at {} stations, {} over a limit",
            run.len(),
            jobs.len(),
            study.stations(),
            evals.iter().filter(|e| !e.marks.is_empty()).count()
        );
        let grid = (refine && round < SWEEP_ROUNDS && evals.iter().any(|e| !e.marks.is_empty()))
            .then(|| {
                let cap = options
                    .solve
                    .max_stations
                    .min(MAX_STATION_GROWTH * study.base.stations());
                study.divided(&evals, cap)
            })
            .flatten();
        match grid {
            Some(grid) => {
                study.grid = grid;
                round += 1;
                if probes.is_empty() {
                    probes = run
                        .iter()
                        .zip(&evals)
                        .filter(|(_, e)| !e.marks.is_empty())
                        .map(|(j, _)| *j)
                        .collect();
                }
            }
            None if !probes.is_empty() => probes.clear(),
            None => break evals,
        }
    };
    let mut evals = evals.into_iter();
    let mut points = Vec::with_capacity(values.len());
    for &v in &values {
        let (minus, mid, plus) = match (evals.next(), evals.next(), evals.next()) {
            (Some(a), Some(b), Some(c)) => (a, b, c),
            _ => return Err(Error::Solver("a sweep step was lost".into())),
        };
        let fd = (plus.cycle_time - minus.cycle_time) / (2.0 * h * v);
        let swept = match which {
            SweptLimit::Velocity => Bound::AxisVelocity(axis),
            SweptLimit::Acceleration => Bound::AxisAcceleration(axis),
        };
        let binding_set = |e: &Eval| -> Vec<Bound> {
            let mut l: Vec<Bound> = e
                .summary
                .binding
                .iter()
                .filter(|b| b.share_of_path > 0.0 && b.limit != Bound::None)
                .map(|b| b.limit)
                .collect();
            l.sort();
            l
        };
        let same_set =
            binding_set(&minus) == binding_set(&mid) && binding_set(&plus) == binding_set(&mid);
        let binds = binding_set(&mid).contains(&swept);
        let is_smooth = same_set
            && match (minus.sensitivity, mid.sensitivity, plus.sensitivity) {
                (Some(a), Some(b), Some(c)) => smooth(a, b, c),
                _ => false,
            };
        let relative_difference = mid
            .sensitivity
            .filter(|d| *d != 0.0)
            .map(|d| (d - fd).abs() / d.abs());
        points.push(SweepPoint {
            limit: v,
            cycle_time_s: mid.cycle_time + dwells,
            sensitivity_dual: mid.sensitivity,
            sensitivity_fd: fd,
            cycle_time_minus_s: minus.cycle_time + dwells,
            cycle_time_plus_s: plus.cycle_time + dwells,
            sensitivity_dual_minus: minus.sensitivity,
            sensitivity_dual_plus: plus.sensitivity,
            binds,
            smooth: is_smooth,
            relative_difference,
            binding: mid.summary.binding.clone(),
            status: mid.summary.status,
            verified: mid.summary.verified,
            worst_ratio: mid
                .summary
                .worst_ratio
                .iter()
                .map(|(_, w)| w.velocity.max(w.acceleration))
                .fold(mid.summary.worst_feed_ratio, f64::max),
            solve_time_s: mid.summary.solve_time_s,
            cone_spans: mid.cone_spans,
        });
    }
    let rotary =
        machine.axes[axis].kind == AxisKind::Rotary && machine.kinematics != KinematicsSpec::Joint;
    let unit = match (rotary, which) {
        (false, SweptLimit::Velocity) => "mm/s",
        (false, SweptLimit::Acceleration) => "mm/s²",
        (true, SweptLimit::Velocity) => "deg/s",
        (true, SweptLimit::Acceleration) => "deg/s²",
    };
    Ok(Sweep {
        machine: machine.name.clone(),
        toolpath: toolpath.to_string(),
        axis: machine.axes[axis].name.clone(),
        limit: which,
        unit: unit.to_string(),
        nominal_min: nominal.min,
        nominal_max: nominal.max,
        stations: study.stations(),
        refinement_rounds: round,
        spans: study.base.problems.len(),
        fd_step: h,
        solver: match study.options.solver_kind {
            SolverKind::Clarabel => "clarabel",
            SolverKind::Reach => "reach",
        }
        .to_string(),
        points,
    })
}

impl Sweep {
    /// Binding limits over all steps, the most time-consuming first.
    pub(crate) fn binding_labels(&self) -> Vec<String> {
        let mut most: BTreeMap<&str, f64> = BTreeMap::new();
        for p in &self.points {
            for b in &p.binding {
                let e = most.entry(b.name.as_str()).or_insert(0.0);
                *e = e.max(b.share_of_time);
            }
        }
        let mut labels: Vec<(&str, f64)> = most.into_iter().collect();
        labels.sort_by(|a, b| b.1.total_cmp(&a.1));
        labels.into_iter().map(|(l, _)| l.to_string()).collect()
    }
}

impl fmt::Display for Sweep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "toolpath      {}", self.toolpath)?;
        writeln!(f, "machine       {}", self.machine)?;
        writeln!(
            f,
            "swept         {} {} limit (nominal [{}, {}] {}), scaled so its max is the value",
            self.axis, self.limit, self.nominal_min, self.nominal_max, self.unit
        )?;
        writeln!(
            f,
            "stations      {} in {} span(s), the same for every step{}; solver {}; finite differences at ±{} %",
            self.stations,
            self.spans,
            match self.refinement_rounds {
                0 => String::new(),
                1 => " (divided once where a step exceeded a limit)".to_string(),
                n => format!(" (divided {n} times where a step exceeded a limit)"),
            },
            self.solver,
            100.0 * self.fd_step
        )?;
        writeln!(f)?;
        let labels = self.binding_labels();
        let unit = format!("[s per {}]", self.unit);
        write!(
            f,
            "{:>12} {:>12} {:>14} {:>14} {:>7} {:>6} {:>8}",
            format!("[{}]", self.unit),
            "T [s]",
            "dT/dv dual",
            "dT/dv FD",
            "diff",
            "smooth",
            "verified"
        )?;
        for l in &labels {
            write!(f, " {:>15}", truncate(l, 15))?;
        }
        writeln!(f)?;
        write!(
            f,
            "{:>12} {:>12} {:>14} {:>14} {:>7} {:>6} {:>8}",
            "limit", "", unit, unit, "", "", "(worst)"
        )?;
        for _ in &labels {
            write!(f, " {:>15}", "% time")?;
        }
        writeln!(f)?;
        for p in &self.points {
            write!(
                f,
                "{:>12.6} {:>12.5} {:>14} {:>14.5e} {:>7} {:>6} {:>8}",
                p.limit,
                p.cycle_time_s,
                p.sensitivity_dual
                    .map_or("–".to_string(), |s| format!("{s:.5e}")),
                p.sensitivity_fd,
                p.relative_difference
                    .map_or("–".to_string(), |d| format!("{:.2}%", 100.0 * d)),
                if !p.binds {
                    "–"
                } else if p.smooth {
                    "yes"
                } else {
                    "no"
                },
                format!(
                    "{} {:.3}",
                    if p.verified { "y" } else { "N" },
                    p.worst_ratio
                )
            )?;
            for l in &labels {
                let share = p
                    .binding
                    .iter()
                    .find(|b| &b.name == l)
                    .map_or(0.0, |b| b.share_of_time);
                write!(f, " {:>15.1}", 100.0 * share)?;
            }
            writeln!(f)?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "dual: the derivative of the optimum at v (Clarabel's multipliers where a span is a \
             cone program, ±1e-6 of the exact lattice optimum elsewhere); FD: central \
             differences at ±h; diff: |dual − FD|/|dual|;"
        )?;
        writeln!(
            f,
            "smooth: the same limits bind over v(1 ± h) and the dual sensitivity is linear there \
             (the two must agree); –: the {} {} limit binds nowhere (dT/dv = 0 up to solver noise)",
            self.axis, self.limit
        )?;
        Ok(())
    }
}

fn truncate(s: &str, n: usize) -> String {
    s.chars().take(n).collect()
}

impl SweepOptions {
    /// Checks the range and steps of the study and its solve options (fields under `solve.`;
    /// [`crate::validate`]). [`sweep`] calls it, and checks the axis and the range
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::AxisJets;

    #[test]
    fn the_vertex_bound_moves_with_the_limits_that_make_it() {
        // Axis 0 (q' = 1, q'' = 1, ±2) and axis 1 (q' = −1, q'' = 1, ±1): in the (b, ü) plane
        // the rows are ü ≤ 2 − b, ü ≥ −2 − b, ü ≥ b − 1, ü ≤ b + 1; the polygon closes where
        // 2 − b = b − 1, so b* = (a₀ + a₁)/2 = 1.5: ∂b*/∂μ is a₀/2 = 1 for axis 0, a₁/2 = 0.5
        // for axis 1.
        let mut jet = AxisJets::default();
        (jet.dq[0], jet.ddq[0], jet.dq[1], jet.ddq[1]) = (1.0, 1.0, -1.0, 1.0);
        let acceleration = vec![Limit::symmetric(2.0), Limit::symmetric(1.0)];
        let (_, b_star, _) = essential_rows(&jet, &acceleration, 10.0);
        assert!((b_star - 1.5).abs() < 1e-12);
        let p = SpanProblem {
            u: vec![0.0, 1.0],
            b_max: vec![b_star; 2],
            b_max_by: vec![Bound::AxisAcceleration(0); 2],
            tip_speed: vec![0.0; 2],
            jets: crate::constraints::StationJets::from_jets(2, &[jet; 2]),
            acceleration,
            essential: vec![u16::MAX; 2],
            b_start: 0.0,
            b_end: 0.0,
            ramp: Default::default(),
        };
        assert!((db_star_dmu(&p, 0, 0) - 1.0).abs() < 1e-8);
        assert!((db_star_dmu(&p, 0, 1) - 0.5).abs() < 1e-8);
    }

    #[test]
    fn smoothness_needs_a_line_and_one_sign() {
        assert!(smooth(-1.0, -0.9, -0.8));
        assert!(!smooth(-1.0, -0.5, -0.8)); // a kink
        assert!(!smooth(-0.01, 0.0, 0.01)); // noise around zero
    }
}
