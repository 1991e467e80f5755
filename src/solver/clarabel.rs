//! The minimum-time profile as a second-order cone program, solved by Clarabel.
//!
//! Variables, with b scaled by a constant B so they are of order one (x = b/B): at every
//! interior station x_i and c_i, and on every interval d_k. The problem is
//!
//! ```text
//! minimise   Σ_k 2Δu_k/√B · d_k                   (= Σ 2Δu_k/(√b_k + √b_{k+1}), eq. 43)
//! subject to c_i² ≤ x_i                              (rotated cone: c_i ≤ √x_i)
//!            d_k (c_k + c_{k+1}) ≥ 1                 (rotated cone)
//!            x_i ≤ b_max_i / B                       (all velocity limits and the feed)
//!            cx x_k + cy x_{k+1} ≤ d / B              interval k's acceleration rows
//! ```
//!
//! The acceleration rows are [`SpanProblem::interval_rows`]: under
//! [`Ramp::Constant`](crate::constraints::Ramp::Constant)
//! `a_min ≤ B (q''_e x_e + q'_e (x_{k+1} − x_k)/(2Δu_k)) ≤ a_max` at both ends e of k; under
//! [`Ramp::Linear`](crate::constraints::Ramp::Linear) (the default) the pairs of an end's
//! bound on its own ü, with ü linear between the ends and the ends' ü eliminated. Each row is
//! divided by its scale. The objective is eq. 43 with b linear between stations under either
//! law (under the linear-ü law the motion's own time differs from it by O(Δu³) an interval).
//!
//! The end stations are not variables: b_0 and b_N (and c = √b there) are constants, so no
//! cone is left without interior (a cone `c_0² ≤ b_0` with b_0 fixed to 0 has none and makes
//! Clarabel stop at AlmostSolved). Rows whose coefficients all vanish (an axis that does not
//! move) are dropped, and so are acceleration rows implied by the others at their station
//! ([`essential_rows`](crate::constraints::essential_rows)).
//!
//! **Constraint generation.** Of the linear rows few hold with equality at the optimum: on
//! the 20 COPP paths about 560 of the 6,100 acceleration rows lie within a tenth of their
//! limit at the reachability profile ([`crate::solver::reach`], feasible and close to the
//! optimum), and the optimum breaks none of the others. So the first program has only the
//! rows within [`NEAR`] of their bound there; a row left out that its solution breaks (by more
//! than [`BROKEN`]) joins, with the rows then near their bound, and the program is solved
//! again. A solution of fewer rows that meets every row is the optimum of the whole program
//! (its feasible set is smaller, its objective the same), and its dual variables, with zeros
//! for the rows left out, are the whole program's (they meet the same conditions). The
//! program is smaller by about half, each iteration cheaper: 36–39 ms → 22–23 ms of Clarabel
//! per COPP path, one round on each of the twenty.
//!//! **Stations on their velocity bound.** Where a program's rows hold x_i only in its velocity
//! row x_i ≤ h_i (on the COPP paths, about 63 % of the stations in the first program), c_i is
//! bounded by c_i ≤ √h_i alone and enters nothing but the cones of its two intervals, whose
//! time falls as c_i grows: the program's optimum has x_i = h_i. Such a station is a constant,
//! not a variable (`Layout`), and an interval between two of them has a constant time and no
//! cone. The program is the same, with fewer variables and cones (on the COPP paths 1,137
//! variables and 773 cones, where every station's would be 2,998 and 1,999) and solves in
//! half the time (22 → 10.7 ms per COPP path). The velocity row's multiplier, which the
//! sensitivities need, is then dT/dc_i through the two intervals' cones (`program`). A row
//! that the solution breaks brings its stations back as variables in the next round.
//!

//! **Windows.** [`solve_windowed`] splits a long span into windows at stations where the O(N)
//! reachability profile sits on the velocity bound (b = b_max: there the optimum almost surely
//! does too), fixes b there to that value, and solves the windows in parallel. Each window is
//! solved to optimality; the stitched profile is feasible by construction and, within the
//! solver's gap tolerance, never slower than the reachability profile (which is feasible for
//! every window). Cost and memory then grow
//! linearly with the stations, and both cores work on one span.
//!
//! **Sensitivities from the dual variables.** Clarabel solves min qᵀz s.t. Az + s = h,
//! s ∈ K, and returns the dual y ∈ K* with q + Aᵀy = 0. The objective here is the cycle time
//! T itself (s), so by the envelope theorem the optimal T moves with any parameter θ of the
//! rows as dT/dθ = ∂/∂θ [yᵀ(Az − h)] at the optimum. For the rows that carry a limit:
//!
//! - velocity and feed, x_i ≤ b_max_i / B: dT/db_max_i = −y_i / B (s per unit of b = u̇²);
//! - acceleration, g·z ≤ h with h = d/s − c (d the row's right-hand side in the limits, s its
//!   scale, c the fixed stations' part): dT/da = −y_r ∂h/∂a = −y_r (∂d/∂a)/s; for a row of one
//!   limit (the constant-ü law) d = a_max, s = |a_max| (or d = −a_min, s = |a_min|), so
//!   dT/da = −y_r / a on both sides (positive for a_min: a more negative a_min is looser); a
//!   linear-ü row joins two ends' bounds, α = a/q' each, and gives each limit its share.
//!   Summed over every row of the axis and side: [`Sensitivity::acceleration`].
//!
//! Dropped rows (implied by the others, [`essential_rows`](crate::constraints::essential_rows))
//! carry no multiplier; the implied bound b* they give is stated as `b_max` instead, so part of
//! the multiplier of an acceleration-limited station can sit on its `b_max` row: a caller who
//! changes an acceleration limit must add dT/db_max_i · ∂b*_i/∂a there (see
//! [`crate::sweep`]). The end stations (fixed b) have no rows. A windowed solve
//! ([`solve_windowed`]) fixes b at its stitches to values that themselves depend on the limits,
//! so only [`solve_with_sensitivity`] (one window) returns sensitivities.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, SolverStatus, SupportedConeT};

use super::{Rows, SolverSettings, SpanSolution, Status};
use crate::constraints::SpanProblem;
use crate::error::{Error, Result};

/// Column indices of one program's variables. A station whose x_i is in no kept row but its
/// velocity row x_i ≤ h_i (h_i > 0) is *fixed* at x_i = h_i, c_i = √h_i: there c_i is bounded
/// by c_i ≤ √h_i alone and enters only the cones of its two intervals, whose time falls as c_i
/// grows, so the program's optimum has c_i = √h_i. An interval between two fixed stations
/// then has a constant time and no cone (module doc).
struct Layout {
    /// x_i's column; `None` where fixed (and at the end stations, constants).
    x: Vec<Option<usize>>,
    /// d_k's column; `None` on an interval between fixed stations.
    d: Vec<Option<usize>>,
    /// Columns in all.
    len: usize,
}

impl Layout {
    /// The columns of span `p`'s program with x fixed where `fixed` says (indexed by station,
    /// the two end stations always fixed).
    fn new(p: &SpanProblem, fixed: &[Option<f64>]) -> Layout {
        let n = p.intervals();
        let mut x = vec![None; n + 1];
        let mut next = 0;
        for i in 1..n {
            if fixed[i].is_none() {
                x[i] = Some(next);
                next += 2;
            }
        }
        // An interval between fixed stations keeps its d (and cone) when its time is not
        // finite (b = 0 at both ends): Clarabel then says the program is infeasible.
        let mut d = vec![None; n];
        for k in 0..n {
            let both = fixed[k].zip(fixed[k + 1]);
            if !both.is_some_and(|(a, b)| a.sqrt() + b.sqrt() > 0.0) {
                d[k] = Some(next);
                next += 1;
            }
        }
        Layout { x, d, len: next }
    }

    /// c_i's column (next to x_i's); `None` where fixed.
    fn c(&self, i: usize) -> Option<usize> {
        self.x[i].map(|x| x + 1)
    }
}

/// What a linear row bounds (for the sensitivities).
#[derive(Debug, Clone, Copy)]
enum RowTag {
    /// x_i ≤ b_max_i / B.
    BMax(usize),
    /// An acceleration row divided by its scale: the limits in its right-hand side, each
    /// with ∂h/∂limit (axis, a_max's (else a_min's), derivative).
    Acceleration([Option<(usize, bool, f64)>; 2]),
}

/// First-order sensitivities of one span's optimal time T to its bounds, from the dual
/// variables (module doc: dT/db_max_i = −y_i/B, dT/da = −Σ y_r/a).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sensitivity {
    /// dT/db_max_i at every station, s per unit of b = u̇² (0 where the station has no row: the
    /// two end stations and stations without a finite bound).
    pub b_max: Vec<f64>,
    /// Per axis, dT/da for its two acceleration limits: s per mm/s² (or °/s²).
    pub acceleration: Vec<SideSensitivity>,
}

/// dT/d(limit) for the lower and the upper limit of one axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SideSensitivity {
    /// dT/da_min (≥ 0: lowering a_min < 0 loosens it).
    pub min: f64,
    /// dT/da_max (≤ 0).
    pub max: f64,
}

/// Solves one span's problem.
pub fn solve(p: &SpanProblem, settings: &SolverSettings) -> Result<SpanSolution> {
    solve_with_sensitivity(p, settings).map(|(s, _)| s)
}

/// Solves one span's problem as one cone program (no windows) and returns, with the profile,
/// the sensitivities of its time to every bound (see the module doc for the derivation).
///
/// The linear rows enter by constraint generation (module doc): first those within [`NEAR`]
/// of their bound at the reachability profile, then every row the solution breaks, until it
/// breaks none (at most [`MAX_ROUNDS`] programs; the last has every row).
pub fn solve_with_sensitivity(
    p: &SpanProblem,
    settings: &SolverSettings,
) -> Result<(SpanSolution, Sensitivity)> {
    solve_rows(p, settings, Rows0::NearReach)
}

/// Which linear rows a cone program starts with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rows0 {
    /// Those within [`NEAR`] of their bound at the reachability profile (the default; module
    /// doc).
    NearReach,
    /// Only the velocity rows (x_i ≤ b_max_i/B): more rounds (tests).
    Velocity,
    /// Every row: one program, no generation.
    Every,
}

/// [`solve_with_sensitivity`] with the first program's rows `first`.
pub fn solve_rows(
    p: &SpanProblem,
    settings: &SolverSettings,
    first: Rows0,
) -> Result<(SpanSolution, Sensitivity)> {
    // The median finite bound.
    let scale = super::median_scale(&p.b_max);
    let rows = linear_rows(p, scale);
    let every = vec![true; rows.len()];
    let mut keep: Vec<bool> = match first {
        Rows0::NearReach => match super::reach::solve(p) {
            Ok(seed) => {
                let x = |i: usize| seed.b[i] / scale;
                rows.iter().map(|r| r.slack(x) <= NEAR * r.unit()).collect()
            }
            // No feasible profile: let Clarabel say why on the whole program.
            Err(_) => every,
        },
        Rows0::Velocity => rows
            .iter()
            .map(|r| matches!(r.tag, RowTag::BMax(_)))
            .collect(),
        Rows0::Every => every,
    };
    let (mut iterations, mut solve_time) = (0, 0.0);
    for round in 1.. {
        if round == MAX_ROUNDS {
            keep.fill(true);
        }
        let (mut solution, sens, x) = match program(p, scale, &rows, &keep, settings) {
            Ok(s) => s,
            // A program with rows left out that Clarabel cannot solve (one left unbounded,
            // say): every row in the next, which then speaks for the whole problem.
            Err(Error::Solver(_)) if keep.iter().any(|k| !k) => {
                keep.fill(true);
                continue;
            }
            Err(e) => return Err(e),
        };
        iterations += solution.iterations;
        solve_time += solution.solve_time;
        let at = |i: usize| x[i];
        let mut broken = false;
        for (r, k) in rows.iter().zip(keep.iter_mut()) {
            if !*k {
                let slack = r.slack(at);
                broken |= slack < -BROKEN * r.unit();
                // The rows near their bound join too, so that the next program is the last.
                *k = slack <= NEAR * r.unit();
            }
        }
        if !broken {
            solution.iterations = iterations;
            solution.solve_time = solve_time;
            return Ok((solution, sens));
        }
    }
    unreachable!("the last round has every row")
}

/// Rows within this much of their bound (h − row(x) ≤ NEAR, in units of the bound, at
/// least one) at the seed profile, or at a round's solution, are in the next program.
pub const NEAR: f64 = 0.1;

/// A row left out that the solution breaks by more than this (in units of its bound, at
/// least one) starts another round; below it, the solution counts as meeting it (Clarabel's
/// own feasibility tolerance on the rows it has is 1e-8).
pub const BROKEN: f64 = 1e-7;

/// The most programs a solve runs; the last has every row.
pub const MAX_ROUNDS: usize = 4;

/// One linear row `coefs · x ≤ h`, its coefficients by station (x_i for station i).
struct LinearRow {
    coefs: Vec<(usize, f64)>,
    h: f64,
    tag: RowTag,
}

impl LinearRow {
    /// h − coefs·x: ≥ 0 where `x` meets the row.
    fn slack(&self, x: impl Fn(usize) -> f64) -> f64 {
        self.h - self.coefs.iter().map(|&(c, v)| v * x(c)).sum::<f64>()
    }

    /// The row's scale: |h|, at least 1 (acceleration rows are normalised by their limit, so
    /// h is about 1; velocity rows are in units of the median bound).
    fn unit(&self) -> f64 {
        self.h.abs().max(1.0)
    }
}

/// Every linear row of the program: x_i ≤ b_max_i / B and the acceleration rows (module doc).
fn linear_rows(p: &SpanProblem, scale: f64) -> Vec<LinearRow> {
    let n = p.intervals();
    let (x0, xn) = (p.b_start / scale, p.b_end / scale);
    // A variable or a constant: Some(station) for interior stations.
    let xvar = |i: usize| (i > 0 && i < n).then_some(i);
    let xconst = |i: usize| if i == 0 { x0 } else { xn };
    let mut rows = Vec::new();
    for i in 1..n {
        if p.b_max[i].is_finite() {
            rows.push(LinearRow {
                coefs: vec![(i, 1.0)],
                h: p.b_max[i] / scale,
                tag: RowTag::BMax(i),
            });
        }
    }
    let mut cache = crate::constraints::LineCache::default();
    for k in 0..n {
        p.interval_rows(k, &mut cache, |r| {
            // cx x_k + cy x_{k+1} ≤ d/B, divided by the row's scale (so h is about 1).
            let norm = scale / r.scale;
            let mut coefs: Vec<(usize, f64)> = Vec::with_capacity(2);
            let mut constant = 0.0;
            for (i, c) in [(k, r.cx), (k + 1, r.cy)] {
                match xvar(i) {
                    Some(col) => coefs.push((col, c * norm)),
                    None => constant += c * norm * xconst(i),
                }
            }
            if coefs.iter().all(|c| c.1 == 0.0) && constant == 0.0 {
                return;
            }
            rows.push(LinearRow {
                coefs,
                h: r.d / r.scale - constant,
                tag: RowTag::Acceleration(
                    r.limits
                        .map(|l| l.map(|(j, upper, dd)| (j, upper, dd / r.scale))),
                ),
            });
        });
    }
    rows
}

/// The cone program with the linear rows `keep` picks: its solution, the sensitivities
/// (zero for the rows left out) and x = b/B at every station.
fn program(
    p: &SpanProblem,
    scale: f64,
    rows: &[LinearRow],
    keep: &[bool],
    settings: &SolverSettings,
) -> Result<(SpanSolution, Sensitivity, Vec<f64>)> {
    let n = p.intervals();
    let (x0, xn) = (p.b_start / scale, p.b_end / scale);
    // The stations on their velocity bound (`Layout`): the kept rows' x_i is in none but
    // its velocity row, of positive bound h_i (x_i = h_i there).
    let mut bound = vec![None; n + 1];
    let mut other = vec![false; n + 1];
    for (r, _) in rows.iter().zip(keep).filter(|(_, k)| **k) {
        match r.tag {
            RowTag::BMax(i) if r.h > 0.0 => bound[i] = Some(r.h),
            _ => r.coefs.iter().for_each(|&(i, _)| other[i] = true),
        }
    }
    let mut fixed: Vec<Option<f64>> = (0..=n).map(|i| bound[i].filter(|_| !other[i])).collect();
    fixed[0] = Some(x0);
    fixed[n] = Some(xn);
    let lay = Layout::new(p, &fixed);
    // c = √x where x is fixed.
    let c_at = |i: usize| fixed[i].map(f64::sqrt);

    // Nonnegative rows: A x + s = h, s ≥ 0, i.e. A x ≤ h.
    let mut lin = Rows::default();
    let mut tags: Vec<RowTag> = Vec::new();
    let mut coefs: Vec<(usize, f64)> = Vec::with_capacity(3);
    for (r, _) in rows.iter().zip(keep).filter(|(_, k)| **k) {
        if let RowTag::BMax(i) = r.tag {
            if fixed[i].is_some() {
                continue; // x_i = h_i: met, its multiplier from the cones (below)
            }
        }
        coefs.clear();
        coefs.extend(
            r.coefs
                .iter()
                .map(|&(i, v)| (lay.x[i].expect("a station in a kept row is free"), v)),
        );
        lin.push(&coefs, r.h);
        tags.push(r.tag);
    }
    let n_lin = lin.h.len();

    // Second-order cones (3 rows each), appended after the linear rows.
    let mut soc = Rows::default();
    for i in 1..n {
        if let (Some(x), Some(c)) = (lay.x[i], lay.c(i)) {
            // (x + 1, x − 1, 2c) ∈ SOC  ⇔  c² ≤ x.
            soc.push(&[(x, -1.0)], 1.0);
            soc.push(&[(x, -1.0)], -1.0);
            soc.push(&[(c, -2.0)], 0.0);
        }
    }
    let r = std::f64::consts::FRAC_1_SQRT_2;
    // The row (in z) of the first of interval k's cone rows, where it has a cone.
    let mut cone_row: Vec<Option<usize>> = vec![None; n];
    for k in 0..n {
        let Some(dcol) = lay.d[k] else {
            continue;
        };
        // d e ≥ 1 with e = c_k + c_{k+1}  ⇔  (d + e, d − e, 2) ∈ SOC. The last two coordinates
        // are turned by 45° (which maps the cone onto itself) to (d − e − 2, d − e + 2)/√2, so
        // that no row is a bare constant: Clarabel scales all rows of a cone alike, and a row
        // without variables distorts that scale and stalls the solver at a 2e-7 gap.
        let mut e_const = 0.0;
        let mut cs: Vec<usize> = Vec::with_capacity(2);
        for i in [k, k + 1] {
            match (c_at(i), lay.c(i)) {
                (Some(c), _) => e_const += c,
                (None, col) => cs.push(col.expect("a station is fixed or has a column")),
            }
        }
        // Rows of s = h − A z: s0 = d + e, s1 = (d − e − 2)/√2, s2 = (d − e + 2)/√2.
        let mut row0 = vec![(dcol, -1.0)];
        let mut row1 = vec![(dcol, -r)];
        let mut row2 = vec![(dcol, -r)];
        for &c in &cs {
            row0.push((c, -1.0));
            row1.push((c, r));
            row2.push((c, r));
        }
        cone_row[k] = Some(n_lin + soc.h.len());
        soc.push(&row0, e_const);
        soc.push(&row1, r * (-e_const - 2.0));
        soc.push(&row2, r * (-e_const + 2.0));
    }
    let n_soc = soc.h.len() / 3;
    // The weight of d_k in the objective: T = Σ w_k d_k.
    let w = |k: usize| 2.0 * p.du(k) / scale.sqrt();

    let mut x: Vec<f64> = fixed.iter().map(|f| f.unwrap_or(0.0)).collect();
    let (status, iterations, solve_time, z) = if lay.len == 0 {
        // Every station fixed: nothing to solve, but rows on the end stations alone to check.
        if lin.h.iter().any(|&h| h < -settings.tol_feas) {
            return Err(Error::Infeasible(
                "no feed profile meets every limit on this span (a row on its end stations alone)"
                    .into(),
            ));
        }
        (Status::Optimal, 0, 0.0, vec![0.0; n_lin])
    } else {
        // Assemble A = [lin; soc].
        let m = n_lin + soc.h.len();
        let mut ri = lin.i;
        ri.extend(soc.i.iter().map(|r| r + n_lin));
        let mut cj = lin.j;
        cj.extend(soc.j);
        let mut vv = lin.v;
        vv.extend(soc.v);
        let mut h = lin.h;
        h.extend(soc.h);
        let nv = lay.len;
        let a = CscMatrix::new_from_triplets(m, nv, ri, cj, vv);
        let pmat = CscMatrix::zeros((nv, nv));
        let mut q = vec![0.0; nv];
        for k in 0..n {
            if let Some(d) = lay.d[k] {
                q[d] = w(k);
            }
        }
        let mut cones = Vec::with_capacity(1 + n_soc);
        if n_lin > 0 {
            cones.push(SupportedConeT::NonnegativeConeT(n_lin));
        }
        cones.extend(std::iter::repeat_n(
            SupportedConeT::SecondOrderConeT(3),
            n_soc,
        ));

        let mut s = settings.clarabel(settings.tol_gap)?;
        // No Ruiz equilibration: the program is scaled already (x = b/B, every row divided by
        // its limit), and equilibrating it cost iterations. The first 12,000 lines of a
        // hyperMILL finish (1.08 M stations, 332 windows of 1.5–3k stations whose Δu spans
        // 2e-5…0.15 mm): 8,305 IP iterations and 17.7 s without, 11,394 and 23.4 s with; the
        // 20 COPP paths 247 against 263 ms; the whole program (64,698 lines, 2.7 M stations)
        // 34.6 against 39.6 s (2026-11-26). (The jerk-limited LPs keep it: the impeller took
        // 31.7 s without, 19.0 s with.)
        s.equilibrate_enable = false;
        let mut solver = DefaultSolver::new(&pmat, &q, &a, &h, &cones, s)
            .map_err(|e| Error::Solver(format!("problem setup: {e:?}")))?;
        super::run_clarabel(&mut solver);
        let sol = &solver.solution;
        let status = match sol.status {
            SolverStatus::Solved => Status::Optimal,
            SolverStatus::AlmostSolved => Status::AlmostOptimal,
            other => {
                return Err(match other {
                    SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                        Error::Infeasible(
                            "no feed profile meets every limit on this span (Clarabel: primal infeasible)"
                                .into(),
                        )
                    }
                    _ => Error::Solver(format!("Clarabel stopped with status {other:?}")),
                });
            }
        };
        for i in 1..n {
            if let Some(col) = lay.x[i] {
                x[i] = sol.x[col];
            }
        }
        (status, sol.iterations, sol.solve_time, sol.z.clone())
    };
    let b: Vec<f64> = x.iter().map(|x| (x * scale).max(0.0)).collect();

    // The duals of the linear rows come first in z, in the order of `tags`.
    let mut sens = Sensitivity {
        b_max: vec![0.0; n + 1],
        acceleration: vec![SideSensitivity::default(); p.n_axes()],
    };
    for (tag, &y) in tags.iter().zip(&z) {
        let y = y.max(0.0); // y ∈ K*: nonnegative up to the solver's tolerance
        match *tag {
            RowTag::BMax(i) => sens.b_max[i] = -y / scale,
            RowTag::Acceleration(limits) => {
                // dT/dh = −y, and h moves with a limit by ∂h/∂limit.
                for (j, upper, dh) in limits.into_iter().flatten() {
                    let side = &mut sens.acceleration[j];
                    if upper {
                        side.max -= y * dh;
                    } else {
                        side.min -= y * dh;
                    }
                }
            }
        }
    }
    // A fixed interior station: dT/dc_i through the cones (or the constant times) of its two
    // intervals, then dc/dx = 1/(2c), and x = b/B. Interval k's cone holds e = c_k + c_{k+1}
    // in its constants h = (e, −(e + 2)/√2, −(e − 2)/√2), and dT/dh = −y, so
    // dT/de = −y₀ + (y₁ + y₂)/√2; an interval without a cone takes w_k/e: dT/de = −w_k/e².
    for i in 1..n {
        let Some(xi) = fixed[i] else {
            continue;
        };
        let mut dt_dc = 0.0;
        for k in [i - 1, i] {
            dt_dc += match cone_row[k] {
                Some(r0) => -z[r0] + r * (z[r0 + 1] + z[r0 + 2]),
                None => {
                    let e = c_at(k).unwrap_or(0.0) + c_at(k + 1).unwrap_or(0.0);
                    -w(k) / (e * e)
                }
            };
        }
        sens.b_max[i] = dt_dc / (2.0 * xi.sqrt()) / scale;
    }
    Ok((
        SpanSolution::acceleration_limited(p, b, status, iterations, solve_time),
        sens,
        x,
    ))
}

/// Solves one span in windows of at most `settings.window` stations (at least one per thread
/// when the span is long enough), stitched at stations of the reachability profile `greedy`
/// (b at every station, feasible). Falls back to one window when no stitch is worth it.
pub fn solve_windowed(
    p: &SpanProblem,
    greedy: &[f64],
    settings: &SolverSettings,
) -> Result<SpanSolution> {
    let n = p.intervals();
    let threads = settings.worker_threads();
    const MIN_WINDOW: usize = 200;
    let windows = n
        .div_ceil(settings.window.max(MIN_WINDOW))
        .max(threads.min(n / MIN_WINDOW))
        .max(1);
    if windows == 1 {
        return solve(p, settings);
    }
    // Cut near every k·n/windows, within ±40 % of a window, at a station in the interior of a
    // plateau of the reach profile (it and both neighbours at their velocity bound: there the
    // optimum sits on the bound too, so fixing b there loses nothing); nearest the target
    // first. Without such a station in range, the station closest to its bound.
    let len = n / windows;
    let on_bound = |i: usize| super::on_velocity_bound(p, greedy, i);
    let plateau = |i: usize| (i - 1..=i + 1).all(|k| on_bound(k) >= 1.0 - 1e-9);
    let mut cuts = vec![0usize];
    for w in 1..windows {
        let target = w * n / windows;
        let reach = (2 * len / 5).max(1);
        let (lo, hi) = (
            target.saturating_sub(reach).max(cuts[w - 1] + 2),
            (target + reach).min(n - 2),
        );
        let score = |i: usize| {
            (
                plateau(i),
                on_bound(i),
                std::cmp::Reverse(i.abs_diff(target)),
            )
        };
        let best = (lo..=hi.max(lo)).max_by(|&a, &b| {
            score(a)
                .partial_cmp(&score(b))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        cuts.push(best.unwrap_or(target));
    }
    cuts.push(n);
    let parts: Vec<SpanProblem> = cuts
        .windows(2)
        .map(|c| {
            let bs = if c[0] == 0 { p.b_start } else { greedy[c[0]] };
            let be = if c[1] == n { p.b_end } else { greedy[c[1]] };
            p.window(c[0], c[1], bs, be)
        })
        .collect();
    // Solve the windows on `threads` workers.
    let t0 = std::time::Instant::now();
    let results = super::par_map(&parts, threads, |part| solve(part, settings));
    let mut b = Vec::with_capacity(n + 1);
    let (mut status, mut iterations) = (Status::Optimal, 0);
    for (i, r) in results.into_iter().enumerate() {
        let s = r?;
        status = status.worst(s.status);
        iterations += s.iterations;
        b.extend_from_slice(if i == 0 { &s.b[..] } else { &s.b[1..] });
    }
    Ok(SpanSolution::acceleration_limited(
        p,
        b,
        status,
        iterations,
        t0.elapsed().as_secs_f64(),
    ))
}
