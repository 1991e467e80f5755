//! Jerk-limited time-optimal profiles: sequential convex programming with Clarabel (issue 6).
//!
//! ## The jerk along the path
//!
//! With b = u̇² and a = ü = ½ b' (′ = d/du), every axis moves as `q̇ = q' √b`,
//! `q̈ = q'' b + q' a`, and, differentiating once more in time (d/dt = √b d/du, a' = ½ b''),
//!
//! ```text
//! q⃛ = q''' u̇³ + 3 q'' u̇ ü + q' u⃛ = √b · (q''' b + 3 q'' a + q' a')
//!    = √b · (q''' b + (3/2) q'' b' + (1/2) q' b'').
//! ```
//!
//! The bracket L is linear in (b, a, a'); the factor √b makes `j_min ≤ √b L ≤ j_max` non-convex.
//!
//! ## Discretisation (see [`crate::motion`])
//!
//! Variables b_i and a_i at every station; a is linear in u between stations, so b is
//! quadratic there and `b_{k+1} − b_k = Δu_k (a_k + a_{k+1})` (an equality per interval), a'
//! is constant per interval, q̈ is continuous and q⃛ is bounded. The jerk rows are stated at
//! both ends e of every interval k, with that interval's a' = (a_{k+1} − a_k)/Δu_k and q''' on
//! its side of a knot. A rest-to-rest span starts and ends with a constant-jerk interval
//! (`u = j t³/6`: b ∝ u^{4/3}, which no quadratic reaches in finite time): there
//! `a_1 = 2 b_1 / (3 Δu_0)`, its time is `3 Δu_0 / √b_1`, and every axis's jerk is
//! `c(t) · b_1^{3/2}` with c known along the interval — a plain upper bound on b_1.
//!
//! ## Sequential convex programming, every iterate feasible
//!
//! `√b L ≤ j_max` ⇔ `L ≤ j_max / √b` (b > 0). 1/√b is convex, so it lies above its tangent at
//! any b̄: `1/√b ≥ (3/2)/√b̄ − b / (2 b̄^{3/2})`. Replacing 1/√b by the tangent at the previous
//! profile b̄ gives linear rows whose feasible set lies *inside* the true one (the same for
//! `j_min < 0`), so every solution of the convex subproblem is jerk-feasible, and b̄ itself is
//! feasible for the next subproblem (the tangent is exact at b̄): the cycle time never increases
//! from one iterate to the next (a convex–concave procedure). The tangent turns negative at
//! b = 3 b̄, a built-in trust region.
//!
//! The first linearisation point is the acceleration-limited optimum from the O(N) pass, b̄ =
//! b_reach, with 1/√b̄ itself as the bound and b ≤ b̄ added (then `L ≤ j/√b̄ ≤ j/√b`): feasible
//! by construction, however far from jerk-feasible b_reach is. Iterations stop when the cycle
//! time (eq. 43 under the motion laws) changes by less than [`JerkOptions::convergence`].
//!
//! Each subproblem is a second-order cone program in the scaled variables x = b/B, y = a/B
//! (B: the median velocity bound), with c_i ≤ √x_i and d_k (c_k + c_{k+1}) ≥ 1 as in
//! [`super::clarabel`], minimising `Σ 2Δu_k d_k/√B` (`3 Δu_k d_k/√B` on a constant-jerk end
//! interval).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

use super::{SolverSettings, SpanSolution, Status};
use crate::constraints::SpanProblem;
use crate::error::{Error, Result};
use crate::geometry::Span;
use crate::kinematics::{Kinematics, MAX_AXES};
use crate::machine::{Limit, Machine};
use crate::schedule::interval_times;

/// Settings of the sequential convex programme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JerkOptions {
    /// Stop when the cycle time changes by less than this, relative.
    pub convergence: f64,
    /// At most this many convex subproblems.
    pub max_iterations: usize,
}

impl Default for JerkOptions {
    fn default() -> Self {
        JerkOptions {
            convergence: 1e-4,
            max_iterations: 30,
        }
    }
}

/// What the jerk rows need beyond a [`SpanProblem`]: every axis's q''' at every station on both
/// sides (they differ at a knot of a cubic), the jerk limits, and the bound on b that the
/// constant-jerk end intervals put on their inner station.
#[derive(Debug, Clone)]
pub struct JerkData {
    /// q''' on the segment to the right of station i (the interval starting there).
    pub right: Vec<[f64; MAX_AXES]>,
    /// q''' on the segment to the left of station i (the interval ending there).
    pub left: Vec<[f64; MAX_AXES]>,
    pub limits: Vec<Option<Limit>>,
    /// Largest b at station 1 (N−1) for the first (last) interval's constant jerk to stay
    /// within every limit; infinite where the span does not start (end) at rest.
    pub rest_bound: (f64, f64),
}

/// Samples of a constant-jerk end interval at which the jerk is bounded.
const REST_SAMPLES: usize = 8;

impl JerkData {
    /// Evaluates q''' at the stations of `p` and the end-interval bounds.
    pub fn new(span: &Span, kin: &Kinematics, machine: &Machine, p: &SpanProblem) -> JerkData {
        let knots = span.spline.knots();
        let last_seg = knots.len() - 2;
        let d3 = |seg: usize, u: f64| {
            let w = span.spline.eval_in(seg, u);
            kin.axis_third_derivatives(&w, &span.spline.d3_in(seg, u))
        };
        let (mut right, mut left) = (Vec::with_capacity(p.u.len()), Vec::with_capacity(p.u.len()));
        for &u in &p.u {
            let seg_r = span.spline.segment(u);
            // A station on a knot belongs to the segment before it on its left side.
            let seg_l = if seg_r > 0 && u <= knots[seg_r] {
                seg_r - 1
            } else {
                seg_r
            };
            right.push(d3(seg_r.min(last_seg), u));
            left.push(if seg_l == seg_r {
                *right.last().unwrap_or(&[0.0; MAX_AXES])
            } else {
                d3(seg_l, u)
            });
        }
        let na = p.n_axes();
        let limits: Vec<Option<Limit>> = machine.axes.iter().take(na).map(|a| a.jerk).collect();
        let n = p.intervals();
        let mut rest = (f64::INFINITY, f64::INFINITY);
        if n >= 2 {
            if p.b_start == 0.0 {
                rest.0 = rest_bound(span, kin, &limits, p.u[0], p.u[1], false);
            }
            if p.b_end == 0.0 {
                rest.1 = rest_bound(span, kin, &limits, p.u[n], p.u[n - 1], true);
            }
        }
        JerkData {
            right,
            left,
            limits,
            rest_bound: rest,
        }
    }
}

/// The largest b at the inner station of a constant-jerk interval from rest at `u_rest` to
/// `u_in` (mirrored when `end`): with s = t/τ ∈ [0, 1], `u − u_rest = ±Δu s³`, `u̇ = 3Δu s²/τ`,
/// `ü = ±6Δu s/τ²` (− into the end), `u⃛ = 6Δu/τ³`, τ = 3Δu/√b, so each axis's jerk is
/// `c(s) · b^{3/2}` with `c(s) = q''' s⁶ ± 2 q'' s³/Δu + 2 q'/(9 Δu²)`.
fn rest_bound(
    span: &Span,
    kin: &Kinematics,
    limits: &[Option<Limit>],
    u_rest: f64,
    u_in: f64,
    end: bool,
) -> f64 {
    let du = (u_in - u_rest).abs();
    let dir = if end { -1.0 } else { 1.0 };
    let mut bound = f64::INFINITY;
    for k in 0..=REST_SAMPLES {
        let s = k as f64 / REST_SAMPLES as f64;
        let u = u_rest + dir * du * s.powi(3);
        // The segment on the interval's side of u.
        let mut seg = span.spline.segment(u);
        let knots = span.spline.knots();
        if end && seg > 0 && u <= knots[seg] {
            seg -= 1;
        }
        let w = span.spline.eval_in(seg, u);
        let jets = kin.axis_jets(&w);
        let d3 = kin.axis_third_derivatives(&w, &span.spline.d3_in(seg, u));
        for (j, lim) in limits.iter().enumerate() {
            let Some(lim) = lim else { continue };
            // Into the end, time reversed: ü changes sign, u̇ and u⃛ do not.
            let c = d3[j] * s.powi(6)
                + dir * 2.0 * jets.ddq[j] * s.powi(3) / du
                + 2.0 * jets.dq[j] / (9.0 * du * du);
            let side = if c > 0.0 { lim.max } else { lim.min };
            if c != 0.0 {
                bound = bound.min((side / c).powf(2.0 / 3.0));
            }
        }
    }
    bound
}

/// A sparse row block under construction (triplets), with its right-hand side.
#[derive(Default)]
struct Rows {
    i: Vec<usize>,
    j: Vec<usize>,
    v: Vec<f64>,
    h: Vec<f64>,
}

impl Rows {
    fn push(&mut self, coefs: &[(usize, f64)], h: f64) {
        let r = self.h.len();
        for &(j, v) in coefs {
            if v != 0.0 {
                self.i.push(r);
                self.j.push(j);
                self.v.push(v);
            }
        }
        self.h.push(h);
    }

    fn append(&mut self, other: Rows) {
        let off = self.h.len();
        self.i.extend(other.i.iter().map(|r| r + off));
        self.j.extend(other.j);
        self.v.extend(other.v);
        self.h.extend(other.h);
    }
}

/// Column indices: x_i, y_i, c_i for interior stations 1 ≤ i ≤ N−1, d_k per interval.
struct Layout {
    n: usize,
}

impl Layout {
    fn x(&self, i: usize) -> usize {
        4 * (i - 1)
    }
    fn y(&self, i: usize) -> usize {
        4 * (i - 1) + 1
    }
    fn c(&self, i: usize) -> usize {
        4 * (i - 1) + 2
    }
    fn d(&self, k: usize) -> usize {
        if k + 1 < self.n {
            4 * k + 3
        } else {
            4 * (self.n - 1)
        }
    }
    fn len(&self) -> usize {
        4 * (self.n - 1) + 1
    }
}

/// The jerk-limited optimum of one span: sequential convex programming from the
/// acceleration-limited reach profile `greedy` (same stations).
pub fn solve(
    p: &SpanProblem,
    jd: &JerkData,
    greedy: &SpanSolution,
    settings: &SolverSettings,
    options: &JerkOptions,
) -> Result<SpanSolution> {
    let n = p.intervals();
    if n < 3 {
        return Err(Error::Solver(format!(
            "a jerk-limited span needs at least 3 station intervals, found {n}"
        )));
    }
    let mut bbar = greedy.b.clone();
    let mut best: Option<(SpanSolution, f64)> = None;
    let (mut status, mut iterations, mut solve_time) = (Status::Optimal, 0, 0.0);
    for it in 0..options.max_iterations.max(1) {
        let sol = subproblem(p, jd, &bbar, it == 0, settings)?;
        status = status.worst(sol.status);
        iterations += sol.iterations;
        solve_time += sol.solve_time;
        let time: f64 = interval_times(p, &sol)?.iter().sum();
        if std::env::var_os("FEEDOPT_JERK_TRACE").is_some() {
            let (mut c5, mut c9, mut c99, mut tot) = (0, 0, 0, 0);
            let acc = sol.a.as_ref().unwrap();
            for k in 1..n - 1 {
                for e in [k, k + 1] {
                    let d3 = if e == k { &jd.right[e] } else { &jd.left[e] };
                    for (j, lim) in jd.limits.iter().enumerate() {
                        let Some(lim) = lim else { continue };
                        let jets = &p.jets[e];
                        let l = d3[j] * sol.b[e] + 3.0 * jets.ddq[j] * acc[e]
                            + jets.dq[j] * (acc[k + 1] - acc[k]) / p.du(k);
                        let v = sol.b[e].sqrt() * l;
                        let r = lim.ratio(v);
                        tot += 2;
                        if r > 0.5 { c5 += 1; }
                        if r > 0.9 { c9 += 1; }
                        if r > 0.99 { c99 += 1; }
                    }
                }
            }
            eprintln!("jerk rows {tot}: >0.5 {c5}, >0.9 {c9}, >0.99 {c99}");
            eprintln!(
                "SCP {it}: T = {time:.6}, {} IP iterations, {:.1} ms, {:?}",
                sol.iterations,
                sol.solve_time * 1e3,
                sol.status
            );
        }
        let done = best
            .as_ref()
            .is_some_and(|(_, t)| (t - time).abs() <= options.convergence * time);
        bbar.clone_from(&sol.b);
        if best.as_ref().is_none_or(|(_, t)| time <= *t) {
            best = Some((sol, time));
        }
        if done {
            break;
        }
    }
    let (mut sol, _) = best.ok_or_else(|| Error::Solver("no SCP iterate".into()))?;
    sol.status = status;
    sol.iterations = iterations;
    sol.solve_time = solve_time;
    Ok(sol)
}

/// One convex subproblem, linearised at `bbar`; `first`: bound 1/√b by 1/√b̄ and add b ≤ b̄.
fn subproblem(
    p: &SpanProblem,
    jd: &JerkData,
    bbar: &[f64],
    first: bool,
    settings: &SolverSettings,
) -> Result<SpanSolution> {
    let n = p.intervals();
    let lay = Layout { n };
    let scale = {
        let mut finite: Vec<f64> = p
            .b_max
            .iter()
            .copied()
            .filter(|b| b.is_finite() && *b > 0.0)
            .collect();
        if finite.is_empty() {
            1.0
        } else {
            let mid = finite.len() / 2;
            *finite.select_nth_unstable_by(mid, f64::total_cmp).1
        }
    };
    let rest_start = p.b_start == 0.0;
    let rest_end = p.b_end == 0.0;
    let xconst = |i: usize| {
        if i == 0 {
            p.b_start / scale
        } else {
            p.b_end / scale
        }
    };
    let interior = |i: usize| i > 0 && i < n;
    // Coefficients of x_i and y_i in a row, or their constant contribution (y = 0 at the ends).
    let term = |coefs: &mut Vec<(usize, f64)>, constant: &mut f64, i: usize, cx: f64, cy: f64| {
        if interior(i) {
            coefs.push((lay.x(i), cx));
            coefs.push((lay.y(i), cy));
        } else {
            *constant += cx * xconst(i);
        }
    };

    // Equalities (zero cone): b_{k+1} − b_k = Δu (a_k + a_{k+1}) on quadratic intervals; the
    // constant-jerk ends: a_1 = 2 b_1/(3Δu_0), a_{N−1} = −2 b_{N−1}/(3Δu_{N−1}).
    let mut eq = Rows::default();
    for k in 0..n {
        let du = p.du(k);
        let (mut coefs, mut constant) = (Vec::with_capacity(4), 0.0);
        if k == 0 && rest_start {
            term(&mut coefs, &mut constant, 1, -2.0 / (3.0 * du), 1.0);
        } else if k + 1 == n && rest_end {
            term(&mut coefs, &mut constant, n - 1, 2.0 / (3.0 * du), 1.0);
        } else {
            term(&mut coefs, &mut constant, k + 1, 1.0, -du);
            term(&mut coefs, &mut constant, k, -1.0, -du);
        }
        eq.push(&coefs, -constant);
    }

    // Inequalities (nonnegative cone): A z ≤ h.
    let mut lin = Rows::default();
    for i in 1..n {
        let mut bmax = p.b_max[i];
        if i == 1 {
            bmax = bmax.min(jd.rest_bound.0);
        }
        if i == n - 1 {
            bmax = bmax.min(jd.rest_bound.1);
        }
        if first {
            bmax = bmax.min(bbar[i]);
        }
        if bmax.is_finite() {
            lin.push(&[(lay.x(i), 1.0)], bmax / scale);
        }
        // Acceleration at the station: a_min ≤ q'' b + q' a ≤ a_max (the rows that are edges
        // of the station's (b, a) polygon).
        for (j, lim) in p.acceleration.iter().enumerate() {
            let (dq, ddq) = (p.jets[i].dq[j], p.jets[i].ddq[j]);
            let rows = p.essential[i] >> (2 * j);
            if (dq == 0.0 && ddq == 0.0) || rows & 3 == 0 {
                continue;
            }
            for (bit, a) in [(1, lim.max), (2, lim.min)] {
                if rows & bit != 0 {
                    lin.push(
                        &[(lay.x(i), scale * ddq / a), (lay.y(i), scale * dq / a)],
                        1.0,
                    );
                }
            }
        }
    }
    // Jerk at both ends e of every quadratic interval k:
    // L = B (q''' x_e + 3 q'' y_e + q' (y_{k+1} − y_k)/Δu_k), L/j ≤ g(x_e) for j = j_max, j_min,
    // g the tangent of 1/√b at b̄_e (or 1/√b̄_e itself on the first iterate).
    let skip = std::env::var_os("FEEDOPT_JERK_NOROWS").is_some();
    for k in 0..n {
        if (k == 0 && rest_start) || (k + 1 == n && rest_end) || skip {
            continue;
        }
        let du = p.du(k);
        for e in [k, k + 1] {
            let be = if interior(e) { bbar[e] } else { xconst(e) * scale };
            if be <= 0.0 {
                continue;
            }
            let d3 = if e == k { &jd.right[e] } else { &jd.left[e] };
            let (jets, sq) = (&p.jets[e], (be).sqrt());
            for (j, lim) in jd.limits.iter().enumerate() {
                let Some(lim) = lim else { continue };
                let (dq, ddq, dddq) = (jets.dq[j], jets.ddq[j], d3[j]);
                if dq == 0.0 && ddq == 0.0 && dddq == 0.0 {
                    continue;
                }
                // L as coefficients (of x_e, y_e, y_k, y_{k+1}) and constant.
                let mut coefs: Vec<(usize, f64)> = Vec::with_capacity(5);
                let mut constant = 0.0;
                if interior(e) {
                    coefs.push((lay.x(e), scale * dddq));
                    coefs.push((lay.y(e), scale * 3.0 * ddq));
                } else {
                    constant += scale * dddq * xconst(e);
                }
                for (i, sgn) in [(k + 1, 1.0), (k, -1.0)] {
                    if interior(i) {
                        coefs.push((lay.y(i), scale * sgn * dq / du));
                    }
                }
                merge_duplicates(&mut coefs);
                for jl in [lim.max, lim.min] {
                    // Exact bound where b_e is a constant; first iterate: L/j ≤ 1/√b̄;
                    // later: (2/3)√b̄ L/j + x_e/(3 x̄_e) ≤ 1.
                    let (w, tangent) = if !interior(e) || first {
                        (sq / jl, false)
                    } else {
                        (2.0 * sq / (3.0 * jl), true)
                    };
                    let mut row: Vec<(usize, f64)> =
                        coefs.iter().map(|&(c, v)| (c, v * w)).collect();
                    if tangent {
                        row.push((lay.x(e), scale / (3.0 * be)));
                        merge_duplicates(&mut row);
                    }
                    lin.push(&row, 1.0 - constant * w);
                }
            }
        }
    }
    let n_eq = eq.h.len();
    let n_lin = lin.h.len();

    // Cones: c_i² ≤ x_i, and d_k (c_k + c_{k+1}) ≥ 1 (turned by 45° as in super::clarabel).
    let mut soc = Rows::default();
    for i in 1..n {
        soc.push(&[(lay.x(i), -1.0)], 1.0);
        soc.push(&[(lay.x(i), -1.0)], -1.0);
        soc.push(&[(lay.c(i), -2.0)], 0.0);
    }
    let r = std::f64::consts::FRAC_1_SQRT_2;
    for k in 0..n {
        let mut e_const = 0.0;
        let mut row0 = vec![(lay.d(k), -1.0)];
        let mut row1 = vec![(lay.d(k), -r)];
        let mut row2 = vec![(lay.d(k), -r)];
        for i in [k, k + 1] {
            if interior(i) {
                row0.push((lay.c(i), -1.0));
                row1.push((lay.c(i), r));
                row2.push((lay.c(i), r));
            } else {
                e_const += xconst(i).sqrt();
            }
        }
        soc.push(&row0, e_const);
        soc.push(&row1, r * (-e_const - 2.0));
        soc.push(&row2, r * (-e_const + 2.0));
    }
    let n_soc = soc.h.len() / 3;

    let mut all = eq;
    all.append(lin);
    all.append(soc);
    let nv = lay.len();
    let m = all.h.len();
    let a = CscMatrix::new_from_triplets(m, nv, all.i, all.j, all.v);
    let pmat = CscMatrix::zeros((nv, nv));
    let mut q = vec![0.0; nv];
    for k in 0..n {
        let rest = (k == 0 && rest_start) || (k + 1 == n && rest_end);
        q[lay.d(k)] = if rest { 3.0 } else { 2.0 } * p.du(k) / scale.sqrt();
    }
    let mut cones = Vec::with_capacity(2 + n_soc);
    cones.push(SupportedConeT::ZeroConeT(n_eq));
    if n_lin > 0 {
        cones.push(SupportedConeT::NonnegativeConeT(n_lin));
    }
    cones.extend(std::iter::repeat_n(
        SupportedConeT::SecondOrderConeT(3),
        n_soc,
    ));
    let s = DefaultSettingsBuilder::default()
        .verbose(std::env::var_os("FEEDOPT_SOLVER_VERBOSE").is_some())
        .max_iter(settings.max_iter)
        .tol_gap_rel(settings.tol_gap)
        .tol_gap_abs(settings.tol_gap)
        .tol_feas(settings.tol_feas)
        .iterative_refinement_enable(settings.iterative_refinement)
        .build()
        .map_err(|e| Error::Solver(format!("settings: {e:?}")))?;
    let mut solver = DefaultSolver::new(&pmat, &q, &a, &all.h, &cones, s)
        .map_err(|e| Error::Solver(format!("problem setup: {e:?}")))?;
    solver.solve();
    let sol = &solver.solution;
    let status = match sol.status {
        SolverStatus::Solved => Status::Optimal,
        SolverStatus::AlmostSolved => Status::AlmostOptimal,
        other => {
            return Err(Error::Solver(format!(
                "jerk-limited subproblem: Clarabel stopped with status {other:?}"
            )));
        }
    };
    let mut b = Vec::with_capacity(n + 1);
    let mut acc = Vec::with_capacity(n + 1);
    b.push(p.b_start);
    acc.push(0.0);
    for i in 1..n {
        b.push((sol.x[lay.x(i)] * scale).max(0.0));
        acc.push(sol.x[lay.y(i)] * scale);
    }
    b.push(p.b_end);
    acc.push(0.0);
    Ok(SpanSolution {
        a: Some(acc),
        b,
        status,
        iterations: sol.iterations,
        solve_time: sol.solve_time,
    })
}

/// Sums coefficients that share a column.
fn merge_duplicates(coefs: &mut Vec<(usize, f64)>) {
    coefs.sort_by_key(|c| c.0);
    coefs.dedup_by(|later, first| {
        if later.0 == first.0 {
            first.1 += later.1;
            true
        } else {
            false
        }
    });
}
