//! Solvers: a [`SpanProblem`](crate::constraints::SpanProblem) in, the optimal b = u̇² at every
//! station out.
//!
//! [`clarabel`] states the minimum-time problem as a second-order cone program (Verscheure et
//! al. 2009; Lipp & Boyd 2014) and solves it with the Clarabel interior-point solver.
//! [`reach`] is the exact O(N) reachability pass on the same discretisation: the fast path, the
//! cross-check, and the source of precise infeasibility errors.

pub(crate) mod banded;
pub mod clarabel;
pub mod double_s;
// Being edited on the jerk-limited refinement's branch: documented once that lands.
#[allow(missing_docs)]
pub mod jerk;
pub mod reach;

use crate::error::{Error, Result, number};
// The windows' workers (`super::par_map` in the solvers).
pub(crate) use crate::parallel::par_map;
use crate::parallel::resolve_threads;
use crate::validate::{at_least, positive};

/// Which solver computes the profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SolverKind {
    /// The convex solve (second-order cone program, Clarabel): the optimum of the discretisation.
    #[default]
    Clarabel,
    /// The O(N) reachability pass: the maximal reachable profile, within O(Δu²) of the optimum.
    Reach,
}

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Solved to the solver's full tolerances.
    Optimal,
    /// Solved to the solver's reduced tolerances.
    AlmostOptimal,
    /// The reachability pass's maximal profile (feasible; within O(Δu²) of the optimum).
    Greedy,
}

impl Status {
    /// The worse of two statuses.
    pub fn worst(self, other: Status) -> Status {
        match (self, other) {
            (Status::AlmostOptimal, _) | (_, Status::AlmostOptimal) => Status::AlmostOptimal,
            (Status::Greedy, _) | (_, Status::Greedy) => Status::Greedy,
            _ => Status::Optimal,
        }
    }
}

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Interior-point iteration cap.
    pub max_iter: u32,
    /// Duality-gap tolerance (absolute and relative) on the cycle time. 1e-6 is a thousand times
    /// below the discretisation error the station refinement accepts (1e-3). On degenerate
    /// profiles (long plateaus where every cone is active) Clarabel's gap floors near 2e-7 and
    /// it would report reduced accuracy at a tighter setting, with the same answer.
    pub tol_gap: f64,
    /// Primal and dual feasibility tolerance (relative): how far a row may be violated.
    pub tol_feas: f64,
    /// Iterative refinement of each KKT solve. Off by default: on these problems it cost a third
    /// to almost half of the solve time without changing the answer or the status, and
    /// Clarabel's termination test uses the true residuals either way.
    pub iterative_refinement: bool,
    /// Longest window (stations) solved as one cone program; longer spans are split (see
    /// [`clarabel::solve_windowed`]).
    pub window: usize,
    /// Threads for windows solved in parallel (0: as many as the machine has).
    pub threads: usize,
    /// Longest a single cone program may run, s. Past it Clarabel stops (status MaxTime) and the
    /// window keeps the feasible reach profile ([`optimal`]): a solve never hangs.
    pub time_limit: f64,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            max_iter: 200,
            tol_gap: 1e-6,
            tol_feas: 1e-8,
            iterative_refinement: false,
            window: 2000,
            threads: 0,
            time_limit: 60.0,
        }
    }
}

impl SolverSettings {
    /// Threads for parallel windows: `threads`, or as many as the machine has when 0.
    pub fn worker_threads(&self) -> usize {
        resolve_threads(self.threads)
    }

    /// Clarabel's settings for these, with duality-gap tolerance `gap`. Verbose when `tracing`
    /// events of level TRACE from `feedopt::solver` are wanted (`RUST_LOG=feedopt::solver=trace`
    /// or `feedopt -vv`): [`run_clarabel`] then passes Clarabel's log on as such an event.
    pub(crate) fn clarabel(
        &self,
        gap: f64,
    ) -> crate::error::Result<::clarabel::solver::DefaultSettings<f64>> {
        ::clarabel::solver::DefaultSettingsBuilder::default()
            .verbose(tracing::enabled!(tracing::Level::TRACE))
            .max_iter(self.max_iter)
            .tol_gap_rel(gap)
            .tol_gap_abs(gap)
            .tol_feas(self.tol_feas)
            .iterative_refinement_enable(self.iterative_refinement)
            .time_limit(self.time_limit)
            .build()
            .map_err(|e| crate::error::Error::Solver(format!("settings: {e:?}")))
    }
}

/// Runs `solver`; with verbose settings ([`SolverSettings::clarabel`]) its log is collected
/// and passed on as one TRACE event (to stderr through the binary's subscriber, never to
/// stdout, where the CLI's output goes).
pub(crate) fn run_clarabel(solver: &mut ::clarabel::solver::DefaultSolver<f64>) {
    use ::clarabel::io::ConfigurablePrintTarget;
    // The same question `SolverSettings::clarabel` asked when it made the settings.
    let verbose = tracing::enabled!(tracing::Level::TRACE);
    if verbose {
        solver.print_to_buffer();
    }
    ::clarabel::solver::IPSolver::solve(solver);
    if verbose {
        if let Ok(log) = solver.get_print_buffer() {
            tracing::trace!("Clarabel:\n{log}");
        }
    }
}

/// The scale B of a cone program's variables (x = b/B): the median of the finite positive
/// `values` (robust against stations where an axis barely moves), 1 if there are none.
pub(crate) fn median_scale(values: &[f64]) -> f64 {
    let mut finite: Vec<f64> = values
        .iter()
        .copied()
        .filter(|b| b.is_finite() && *b > 0.0)
        .collect();
    if finite.is_empty() {
        return 1.0;
    }
    let mid = finite.len() / 2;
    *finite.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The optimal profile of one span.
#[derive(Debug, Clone)]
pub struct SpanSolution {
    /// b = u̇² at every station.
    pub b: Vec<f64>,
    /// ü at every station for a jerk-limited profile (ü continuous; b quadratic in u between
    /// stations, or cubic with `slopes`; see [`crate::motion`]); `None`: b linear in u between
    /// stations, ü constant per interval.
    pub a: Option<Vec<f64>>,
    /// a' = dü/du at the start and end of every interval, for a jerk-limited profile whose ü
    /// is quadratic between stations ([`crate::motion::Law::Cubic`]); `None` with `a`: ü
    /// linear between stations.
    pub slopes: Option<Vec<[f64; 2]>>,
    /// ü at the start and end of every interval of an acceleration-limited profile whose ü
    /// is linear between stations ([`crate::constraints::Ramp::Linear`], from
    /// [`crate::constraints::SpanProblem::ramp_ends`]); `None` without `a`: ü constant on
    /// each interval.
    pub ends: Option<Vec<[f64; 2]>>,
    /// How the solve ended.
    pub status: Status,
    /// Interior-point iterations (0 for the reach pass).
    pub iterations: u32,
    /// Wall time of the solver proper (s), excluding problem build.
    pub solve_time: f64,
    /// Convex subproblems of a jerk-limited solve (the most any window of the span took); 0
    /// for the other solvers.
    pub scp_iterations: u32,
}

impl SpanSolution {
    /// An acceleration-limited profile `b` of problem `p`: ü at the intervals' ends as the
    /// problem's [`Ramp`](crate::constraints::Ramp) says ([`SpanProblem::ramp_ends`]).
    ///
    /// [`SpanProblem::ramp_ends`]: crate::constraints::SpanProblem::ramp_ends
    pub fn acceleration_limited(
        p: &crate::constraints::SpanProblem,
        b: Vec<f64>,
        status: Status,
        iterations: u32,
        solve_time: f64,
    ) -> SpanSolution {
        SpanSolution {
            a: None,
            slopes: None,
            ends: p.ramp_ends(&b),
            b,
            status,
            iterations,
            solve_time,
            scp_iterations: 0,
        }
    }

    /// Everything but b that decides the motion between stations.
    pub fn shape(&self) -> crate::motion::Shape<'_> {
        crate::motion::Shape {
            a: self.a.as_deref(),
            slopes: self.slopes.as_deref(),
            ends: self.ends.as_deref(),
        }
    }

    /// The same motion `factor` (≥ 1) times slower: u̇ → u̇/f, so b, ü and a' = dü/du all
    /// divide by f². Every motion law is homogeneous in them, so each interval takes f times
    /// as long, and every axis's velocity, acceleration and jerk along the path divide by f,
    /// f² and f³ (the path, its stations and the laws unchanged).
    pub fn slow_down(&mut self, factor: f64) {
        let k = 1.0 / (factor * factor);
        self.b.iter_mut().for_each(|x| *x *= k);
        if let Some(a) = &mut self.a {
            a.iter_mut().for_each(|x| *x *= k);
        }
        for s in [&mut self.slopes, &mut self.ends].into_iter().flatten() {
            s.iter_mut().for_each(|x| {
                x[0] *= k;
                x[1] *= k;
            });
        }
    }
}

/// Time taken by each interval of one span's profile: [`crate::motion::interval_times`] at
/// the problem's stations.
pub fn interval_times(
    problem: &crate::constraints::SpanProblem,
    sol: &SpanSolution,
) -> crate::error::Result<Vec<f64>> {
    crate::motion::interval_times(&problem.u, &sol.b, sol.shape())
}

/// A sparse row block under construction (triplets in row order), with its right-hand side.
#[derive(Default)]
pub(crate) struct Rows {
    pub(crate) i: Vec<usize>,
    pub(crate) j: Vec<usize>,
    pub(crate) v: Vec<f64>,
    pub(crate) h: Vec<f64>,
    /// Index of each row's first triplet.
    pub(crate) start: Vec<usize>,
}

impl Rows {
    /// Empty, with room for `rows` rows of `entries` entries in all.
    pub(crate) fn with_capacity(rows: usize, entries: usize) -> Rows {
        Rows {
            i: Vec::with_capacity(entries),
            j: Vec::with_capacity(entries),
            v: Vec::with_capacity(entries),
            h: Vec::with_capacity(rows),
            start: Vec::with_capacity(rows + 1),
        }
    }

    pub(crate) fn push(&mut self, coefs: &[(usize, f64)], h: f64) {
        let r = self.h.len();
        self.start.push(self.v.len());
        for &(j, v) in coefs {
            if v != 0.0 {
                self.i.push(r);
                self.j.push(j);
                self.v.push(v);
            }
        }
        self.h.push(h);
    }

    pub(crate) fn len(&self) -> usize {
        self.h.len()
    }

    pub(crate) fn triplets(&self, r: usize) -> std::ops::Range<usize> {
        self.start[r]..self.start.get(r + 1).copied().unwrap_or(self.v.len())
    }

    /// Row `r` of `other` appended.
    pub(crate) fn copy_row(&mut self, other: &Rows, r: usize) {
        let row = self.h.len();
        self.start.push(self.v.len());
        for t in other.triplets(r) {
            self.i.push(row);
            self.j.push(other.j[t]);
            self.v.push(other.v[t]);
        }
        self.h.push(other.h[r]);
    }

    pub(crate) fn append(&mut self, other: &Rows) {
        for r in 0..other.len() {
            self.copy_row(other, r);
        }
    }
}

/// b_i / b_max_i where station i's bound is a velocity limit or the feed cap, 0 where it is the
/// acceleration-limited maximum b* (or none). A profile on such a bound cannot be faster there,
/// so a stitch there is safe; b* is where rows that are not max-closed live, and the optimum
/// can leave it.
pub(crate) fn on_velocity_bound(p: &crate::constraints::SpanProblem, b: &[f64], i: usize) -> f64 {
    use crate::constraints::Bound;
    match p.b_max_by[i] {
        Bound::AxisVelocity(_) | Bound::Feed | Bound::Chord | Bound::Process(_)
            if p.b_max[i].is_finite() && p.b_max[i] > 0.0 =>
        {
            b[i] / p.b_max[i]
        }
        _ => 0.0,
    }
}

/// The optimum of one span's discretisation, with Clarabel only where it is needed.
///
/// The largest profile of the lattice relaxation ([`reach::solve_lattice`]) is at least as fast
/// as every feasible profile; wherever it also meets the rows the relaxation left out it is the
/// exact optimum, and no cone program is solved. Otherwise each interval where it breaks such a
/// row is covered by a window reaching out to the nearest *stitch* on either side — a span end,
/// or a station inside a plateau of the feasible profile `greedy` (it and both neighbours on
/// their velocity bound: no feasible profile is faster there, so the relaxation's profile is on
/// the bound too) — and the windows are solved by Clarabel ([`clarabel::solve_windowed`]) with b
/// fixed at their ends, except where a certificate makes that needless: the relaxation's time
/// over the window bounds its optimum from below and `greedy`'s from above, so where the two
/// are within Clarabel's own relative gap (`tol_gap`) `greedy` is kept, as good an answer as
/// the cone program's. On the first 12k lines of a hyperMILL finish, 83 of 149 windows (57 % of
/// their stations) end that way and the solve takes 9 s instead of 23 s. Between windows the relaxation's profile meets every row with the same
/// ends, so it is the optimum there. The stitched profile equals the all-Clarabel windowed
/// solve of the same stations up to the solvers' tolerances (tested). If Clarabel fails on a
/// window (a status other than Solved or AlmostSolved), that window keeps `greedy` (feasible),
/// and the status says [`Status::Greedy`].
pub fn optimal(
    p: &crate::constraints::SpanProblem,
    greedy: &SpanSolution,
    settings: &SolverSettings,
) -> crate::error::Result<SpanSolution> {
    let t0 = std::time::Instant::now();
    let n = p.intervals();
    let mut b = match reach::solve_lattice(p) {
        Ok(m) => m.b,
        // (cannot happen when `greedy` exists: the relaxation's feasible set is larger)
        Err(_) => greedy.b.clone(),
    };
    let bad = reach::lattice_violations(p, &b, 1e-9);
    let (mut status, mut iterations, mut certified) = (Status::Optimal, 0, 0);
    if !bad.is_empty() {
        let on_bound =
            |i: usize| p.b_max[i].is_finite() && greedy.b[i] >= p.b_max[i] * (1.0 - 1e-9);
        let stitch =
            |i: usize| i == 0 || i == n || (on_bound(i - 1) && on_bound(i) && on_bound(i + 1));
        let mut windows: Vec<(usize, usize)> = Vec::new();
        for &k in &bad {
            if windows.last().is_some_and(|w| k < w.1) {
                continue; // inside the previous window
            }
            let a = (0..=k).rev().find(|&i| stitch(i)).unwrap_or(0);
            let c = (k + 1..=n).find(|&i| stitch(i)).unwrap_or(n);
            match windows.last_mut() {
                Some(w) if a <= w.1 => w.1 = c,
                _ => windows.push((a, c)),
            }
        }
        // A window's time (s) under profile `x` (`None`: not finite).
        let window_time = |a: usize, c: usize, x: &[f64]| {
            crate::motion::interval_times(&p.u[a..=c], &x[a..=c], Default::default())
                .ok()
                .map(|t| t.iter().sum::<f64>())
        };
        let count = windows.len();
        for (a, c) in windows {
            // The relaxation's time bounds the window's optimum from below and the feasible
            // profile's from above: within Clarabel's own relative gap, that profile is as good
            // an answer as the cone program's.
            if let (Some(upper), Some(lower)) =
                (window_time(a, c, &greedy.b), window_time(a, c, &b))
            {
                if upper - lower <= settings.tol_gap * upper {
                    b[a..=c].copy_from_slice(&greedy.b[a..=c]);
                    certified += 1;
                    continue;
                }
            }
            let w = p.window(a, c, b[a], b[c]);
            let solved = if c - a <= settings.window {
                clarabel::solve(&w, settings)
            } else {
                clarabel::solve_windowed(&w, &greedy.b[a..=c], settings)
            };
            match solved {
                Ok(s) => {
                    status = status.worst(s.status);
                    iterations += s.iterations;
                    b[a..=c].copy_from_slice(&s.b);
                }
                Err(crate::error::Error::Solver(_)) => {
                    status = status.worst(Status::Greedy);
                    b[a..=c].copy_from_slice(&greedy.b[a..=c]);
                }
                Err(e) => return Err(e),
            }
        }
        tracing::debug!(
            "{count} windows, {certified} within the gap on the feasible profile, {iterations} \
             interior-point iterations"
        );
    }
    Ok(SpanSolution::acceleration_limited(
        p,
        b,
        status,
        iterations,
        t0.elapsed().as_secs_f64(),
    ))
}

impl SolverSettings {
    /// Checks every field's range ([`crate::validate`]); the error names the field.
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

impl jerk::JerkOptions {
    /// Checks every field's range ([`crate::validate`]); the error names the field.
    pub fn validate(&self) -> Result<()> {
        positive("convergence", self.convergence)?;
        at_least("max_iterations", self.max_iterations, 1, "subproblems")?;
        at_least("window", self.window, 2, "stations per window")
    }
}
