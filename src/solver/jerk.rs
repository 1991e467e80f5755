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
use clarabel::solver::{DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

use super::{Rows, SolverSettings, SpanSolution, Status};
use crate::constraints::{Chord, SpanProblem, essential_rows};
use crate::error::{Error, Result};
use crate::geometry::{Span, SpanKind};
use crate::kinematics::{AxisJets, Kinematics, MAX_AXES};
use crate::machine::{Limit, Machine};
use crate::motion::Interval;
use crate::schedule::interval_times;

/// Settings of the sequential convex programme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JerkOptions {
    /// Stop when the cycle time changes by less than this, relative.
    pub convergence: f64,
    /// At most this many convex subproblems.
    pub max_iterations: usize,
    /// The subproblems' objective.
    pub objective: Objective,
}

/// The objective of each convex subproblem.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Objective {
    /// The cycle time linearised at the previous profile, `Σ ∂T/∂b_i · b_i`: a linear program
    /// (no cones), 2–3× faster per subproblem. Where the limits make the feasible set a lattice
    /// every positive weighting has the same optimum (the pointwise-largest profile), and at a
    /// fixed point of the iteration the first-order optimality conditions of the true problem
    /// hold; on the COPP paths it reaches the cone objective's time to 1e-7.
    #[default]
    Linearised,
    /// The cycle time itself, `Σ 2Δu/(√b_k + √b_{k+1})`, through second-order cones (as
    /// [`super::clarabel`]): every subproblem's optimum is exact and the time never increases
    /// from one iterate to the next.
    Cones,
}

impl Default for JerkOptions {
    fn default() -> Self {
        JerkOptions {
            convergence: 1e-4,
            max_iterations: 30,
            objective: Objective::default(),
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
    /// The [`COLLOCATION`] points of every interval, interval by interval.
    pub mid: Vec<Midpoint>,
}

/// Where inside each interval velocity, acceleration and jerk are also bounded (as fractions
/// of the interval): b is quadratic between stations and may bulge above both ends, and the
/// geometry's curvature varies in between.
pub const COLLOCATION: [f64; 3] = [0.25, 0.5, 0.75];

/// The geometry at a collocation point inside an interval.
#[derive(Debug, Clone)]
pub struct Midpoint {
    /// Its place in the interval, 0 < θ < 1.
    pub theta: f64,
    pub jets: AxisJets,
    pub d3: [f64; MAX_AXES],
    /// The velocity bound on b there (axes and feed cap, and the acceleration polygon's b*).
    pub b_max: f64,
    /// The acceleration rows that are edges of the polygon there
    /// ([`crate::constraints::essential_rows`]).
    pub essential: u16,
}

/// A row joins the active set when its value reaches this fraction of its bound (see
/// [`subproblem`]).
const ACTIVE_AT: f64 = 0.85;

/// Solves with part of the rows before all are taken (see [`subproblem`]).
const ACTIVE_ROUNDS: usize = 6;

/// Samples of a constant-jerk end interval at which the jerk is bounded.
const REST_SAMPLES: usize = 8;

impl JerkData {
    /// Evaluates q''' at the stations of `p` and the end-interval bounds.
    pub fn new(
        span: &Span,
        kin: &Kinematics,
        machine: &Machine,
        p: &SpanProblem,
        chord: Option<&Chord>,
    ) -> JerkData {
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
        let moving = span.kind == SpanKind::Moving;
        let mid = (0..n)
            .flat_map(|k| COLLOCATION.iter().map(move |&th| (k, th)))
            .map(|(k, th)| {
                let um = p.u[k] + th * (p.u[k + 1] - p.u[k]);
                let seg = span.spline.segment(um);
                let w = span.spline.eval_in(seg, um);
                let jets = kin.axis_jets(&w);
                let mut b_max = f64::INFINITY;
                for (j, axis) in machine.axes.iter().enumerate().take(na) {
                    let d = jets.dq[j];
                    if d != 0.0 {
                        let v = if d > 0.0 {
                            axis.velocity.max
                        } else {
                            axis.velocity.min
                        };
                        b_max = b_max.min((v / d).powi(2));
                    }
                }
                if let (true, Some(c)) = (moving, chord) {
                    b_max = b_max.min(c.b_max(&w));
                }
                let cap = span.feed_caps.get(seg).copied().unwrap_or(f64::INFINITY);
                if moving && cap.is_finite() {
                    let speed = (w.d1[0].powi(2) + w.d1[1].powi(2) + w.d1[2].powi(2)).sqrt();
                    if speed > 0.0 {
                        b_max = b_max.min((cap / speed).powi(2));
                    }
                }
                let (essential, b_star, _) = essential_rows(&jets, &p.acceleration, b_max);
                Midpoint {
                    theta: th,
                    d3: kin.axis_third_derivatives(&w, &span.spline.d3_in(seg, um)),
                    jets,
                    b_max: b_max.min(b_star),
                    essential,
                }
            })
            .collect();
        JerkData {
            right,
            left,
            limits,
            rest_bound: rest,
            mid,
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

/// Column indices: x_i, y_i, c_i for interior stations 1 ≤ i ≤ N−1, d_k per interval.
struct Layout {
    n: usize,
    /// Without the cone variables c, d (linearised objective).
    lp: bool,
}

impl Layout {
    fn stride(&self) -> usize {
        if self.lp { 2 } else { 4 }
    }
    fn x(&self, i: usize) -> usize {
        self.stride() * (i - 1)
    }
    fn y(&self, i: usize) -> usize {
        self.stride() * (i - 1) + 1
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
        if self.lp {
            2 * (self.n - 1)
        } else {
            4 * (self.n - 1) + 1
        }
    }
}

/// A previous jerk-limited profile carried over to new stations (a refinement of the same
/// span): the first linearisation point instead of the reach profile.
#[derive(Debug, Clone)]
pub struct Warm {
    pub b: Vec<f64>,
    pub a: Vec<f64>,
    /// Its cycle time on its own stations.
    pub time: f64,
}

impl Warm {
    /// `old`'s profile (b and ü under its motion laws) at the stations of `p`; `None` if `old`
    /// is not jerk-limited.
    pub fn resample(old_p: &SpanProblem, old: &SpanSolution, p: &SpanProblem) -> Option<Warm> {
        let a_old = old.a.as_deref()?;
        let time = interval_times(old_p, old).ok()?.iter().sum();
        let (mut b, mut a) = (Vec::with_capacity(p.u.len()), Vec::with_capacity(p.u.len()));
        let mut k = 0;
        let last = old_p.intervals() - 1;
        for &u in &p.u {
            while k < last && old_p.u[k + 1] <= u {
                k += 1;
            }
            let iv = Interval::of(&old_p.u, &old.b, Some(a_old), k);
            let (bu, au) = iv.at_x(u - old_p.u[k]);
            b.push(bu);
            a.push(au);
        }
        Some(Warm { b, a, time })
    }
}

/// The jerk-limited optimum of one span: sequential convex programming from the
/// acceleration-limited reach profile `greedy` (same stations), or from `warm`.
pub fn solve(
    p: &SpanProblem,
    jd: &JerkData,
    greedy: &SpanSolution,
    warm: Option<Warm>,
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
    let mut abar: Option<Vec<f64>> = None;
    // The time of the previous profile, for the stopping test.
    let mut last_time: Option<f64> = None;
    if let Some(w) = warm.filter(|w| w.b.len() == p.u.len() && w.b[1..n].iter().all(|&b| b > 0.0)) {
        bbar = w.b;
        abar = Some(w.a);
        last_time = Some(w.time);
    }
    let mut best: Option<(SpanSolution, f64)> = None;
    let (mut status, mut iterations, mut solve_time) = (Status::Optimal, 0, 0.0);
    let mut carried: Vec<bool> = Vec::new();
    for it in 0..options.max_iterations.max(1) {
        let sol = subproblem(
            p,
            jd,
            &bbar,
            abar.as_deref(),
            settings,
            options.objective,
            &mut carried,
        )?;
        status = status.worst(sol.status);
        iterations += sol.iterations;
        solve_time += sol.solve_time;
        let time: f64 = interval_times(p, &sol)?.iter().sum();
        if std::env::var_os("FEEDOPT_JERK_TRACE").is_some() {
            eprintln!(
                "SCP {it}: T = {time:.6}, {} IP iterations, {:.1} ms, {:?}",
                sol.iterations,
                sol.solve_time * 1e3,
                sol.status
            );
        }
        let done = last_time.is_some_and(|t| (t - time).abs() <= options.convergence * time);
        last_time = Some(time);
        bbar.clone_from(&sol.b);
        abar.clone_from(&sol.a);
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

/// Most terms an [`Expr`] holds before duplicates are merged.
const EXPR_CAP: usize = 16;

/// A linear expression in the scaled variables: coefficients by column, and a constant (a
/// fixed-size buffer: rows are built by the hundred thousand, without allocating).
#[derive(Clone, Copy)]
struct Expr {
    terms: [(usize, f64); EXPR_CAP],
    len: usize,
    constant: f64,
}

impl Default for Expr {
    fn default() -> Self {
        Expr {
            terms: [(0, 0.0); EXPR_CAP],
            len: 0,
            constant: 0.0,
        }
    }
}

impl Expr {
    fn var(col: usize) -> Expr {
        let mut e = Expr::default();
        e.terms[0] = (col, 1.0);
        e.len = 1;
        e
    }
    fn constant(c: f64) -> Expr {
        Expr {
            constant: c,
            ..Expr::default()
        }
    }
    fn coefs(&self) -> &[(usize, f64)] {
        &self.terms[..self.len]
    }
    fn scaled(&self, w: f64) -> Expr {
        let mut e = *self;
        for t in &mut e.terms[..e.len] {
            t.1 *= w;
        }
        e.constant *= w;
        e
    }
    fn add(&mut self, other: &Expr, w: f64) {
        for &(c, v) in other.coefs() {
            self.terms[self.len] = (c, v * w);
            self.len += 1;
        }
        self.constant += other.constant * w;
    }
    /// Sums the coefficients that share a column.
    fn merge(&mut self) {
        let t = &mut self.terms[..self.len];
        t.sort_unstable_by_key(|c| c.0);
        let mut n = 0;
        for i in 0..t.len() {
            if n > 0 && t[n - 1].0 == t[i].0 {
                t[n - 1].1 += t[i].1;
            } else {
                t[n] = t[i];
                n += 1;
            }
        }
        self.len = n;
    }
}

/// Σ w·e, duplicates merged.
fn sum(terms: &[(&Expr, f64)]) -> Expr {
    let mut e = Expr::default();
    for (t, w) in terms {
        e.add(t, *w);
    }
    e.merge();
    e
}

/// `e ≤ h` as a row.
fn le(rows: &mut Rows, e: &Expr, h: f64) {
    rows.push(e.coefs(), h - e.constant);
}

/// The rows at one point of the path, in scaled variables (b = B·xb, a = B·ya):
/// acceleration `a_min ≤ B (q'' xb + q' ya) ≤ a_max` (the rows of `essential`), and, given
/// q''' and the interval's slope a' = B·slope, jerk `L/j ≤ (3/2)/√b̄ − b/(2 b̄^{3/2})` with
/// `L = B (q''' xb + 3 q'' ya + q' slope)`, i.e. `(2/3)√b̄ L/j + b/(3 b̄) ≤ 1`.
#[allow(clippy::too_many_arguments)]
fn point_rows(
    rows: &mut Rows,
    p: &SpanProblem,
    jd: &JerkData,
    scale: f64,
    jets: &AxisJets,
    essential: u16,
    xb: &Expr,
    ya: &Expr,
    jerk: Option<(&[f64; MAX_AXES], &Expr, f64)>,
) {
    for (j, lim) in p.acceleration.iter().enumerate() {
        let (dq, ddq) = (jets.dq[j], jets.ddq[j]);
        let mask = essential >> (2 * j);
        if (dq == 0.0 && ddq == 0.0) || mask & 3 == 0 {
            continue;
        }
        let e = sum(&[(xb, scale * ddq), (ya, scale * dq)]);
        for (bit, a) in [(1, lim.max), (2, lim.min)] {
            if mask & bit != 0 {
                le(rows, &e.scaled(1.0 / a), 1.0);
            }
        }
    }
    let Some((d3, slope, bbar)) = jerk else {
        return;
    };
    if bbar <= 0.0 {
        return;
    }
    let sq = bbar.sqrt();
    for (j, lim) in jd.limits.iter().enumerate() {
        let Some(lim) = lim else { continue };
        let (dq, ddq, dddq) = (jets.dq[j], jets.ddq[j], d3[j]);
        if dq == 0.0 && ddq == 0.0 && dddq == 0.0 {
            continue;
        }
        let l = sum(&[
            (xb, scale * dddq),
            (ya, 3.0 * scale * ddq),
            (slope, scale * dq),
        ]);
        for jl in [lim.max, lim.min] {
            let mut row = l.scaled(2.0 * sq / (3.0 * jl));
            row.add(xb, scale / (3.0 * bbar));
            row.merge();
            le(rows, &row, 1.0);
        }
    }
}

/// One convex subproblem, the jerk rows linearised at the profile (`bbar`, `abar`; without
/// `abar`, the acceleration-limited reach profile, whose b̄ at interval midpoints is taken as
/// the mean of its ends).
fn subproblem(
    p: &SpanProblem,
    jd: &JerkData,
    bbar: &[f64],
    abar: Option<&[f64]>,
    settings: &SolverSettings,
    objective: Objective,
    carried: &mut Vec<bool>,
) -> Result<SpanSolution> {
    let n = p.intervals();
    let lay = Layout {
        n,
        lp: objective == Objective::Linearised,
    };
    // B: the median of the linearisation point (the profile is near it; the velocity bounds
    // can be orders of magnitude above where jerk holds the feed down, which would leave x tiny
    // and the solver badly scaled).
    let scale = {
        let mut finite: Vec<f64> = bbar
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
    let is_rest = |k: usize| (k == 0 && rest_start) || (k + 1 == n && rest_end);
    let interior = |i: usize| i > 0 && i < n;
    let xconst = |i: usize| {
        if i == 0 {
            p.b_start / scale
        } else {
            p.b_end / scale
        }
    };
    // x_i = b_i/B and y_i = a_i/B as expressions (constants at the end stations, a = 0 there).
    let x = |i: usize| {
        if interior(i) {
            Expr::var(lay.x(i))
        } else {
            Expr::constant(xconst(i))
        }
    };
    let y = |i: usize| {
        if interior(i) {
            Expr::var(lay.y(i))
        } else {
            Expr::default()
        }
    };

    // Equalities (zero cone): b_{k+1} − b_k = Δu (a_k + a_{k+1}) on quadratic intervals; the
    // constant-jerk ends: a_1 = 2 b_1/(3Δu_0), a_{N−1} = −2 b_{N−1}/(3Δu_{N−1}).
    let mut eq = Rows::default();
    for k in 0..n {
        let du = p.du(k);
        let e = if k == 0 && rest_start {
            sum(&[(&y(1), 1.0), (&x(1), -2.0 / (3.0 * du))])
        } else if k + 1 == n && rest_end {
            sum(&[(&y(n - 1), 1.0), (&x(n - 1), 2.0 / (3.0 * du))])
        } else {
            sum(&[
                (&x(k + 1), 1.0),
                (&x(k), -1.0),
                (&y(k), -du),
                (&y(k + 1), -du),
            ])
        };
        le(&mut eq, &e, 0.0);
    }

    let mut lin = Rows::default();
    let mut cand = Rows::default();
    // At the stations: velocity (and the constant-jerk ends' bound) and acceleration.
    for i in 1..n {
        let mut bmax = p.b_max[i];
        if i == 1 {
            bmax = bmax.min(jd.rest_bound.0);
        }
        if i == n - 1 {
            bmax = bmax.min(jd.rest_bound.1);
        }
        if bmax.is_finite() {
            lin.push(&[(lay.x(i), 1.0)], bmax / scale);
        }
        point_rows(
            &mut cand,
            p,
            jd,
            scale,
            &p.jets[i],
            p.essential[i],
            &x(i),
            &y(i),
            None,
        );
    }
    for k in 0..n {
        if is_rest(k) {
            continue;
        }
        let du = p.du(k);
        let slope = sum(&[(&y(k + 1), 1.0 / du), (&y(k), -1.0 / du)]);
        // Jerk at both ends, with this interval's a' and q''' on its side of a knot.
        for e in [k, k + 1] {
            let d3 = if e == k { &jd.right[e] } else { &jd.left[e] };
            let be = if interior(e) {
                bbar[e]
            } else {
                xconst(e) * scale
            };
            let jet = &p.jets[e];
            point_rows(
                &mut cand,
                p,
                jd,
                scale,
                jet,
                0,
                &x(e),
                &y(e),
                Some((d3, &slope, be)),
            );
        }
        // At the collocation points x = θΔu: b(x) = b_k + (2x − x²/Δu) a_k + (x²/Δu) a_{k+1},
        // a(x) = (1 − θ) a_k + θ a_{k+1} — velocity, acceleration and jerk.
        let nc = COLLOCATION.len();
        for m in &jd.mid[nc * k..nc * (k + 1)] {
            let (th, xx) = (m.theta, m.theta * du);
            let (wa, wb) = (2.0 * xx - xx * xx / du, xx * xx / du);
            let xm = sum(&[(&x(k), 1.0), (&y(k), wa), (&y(k + 1), wb)]);
            let ym = sum(&[(&y(k), 1.0 - th), (&y(k + 1), th)]);
            if m.b_max.is_finite() {
                le(&mut cand, &xm, m.b_max / scale);
            }
            let bbar_m = match abar {
                Some(a) => bbar[k] + wa * a[k] + wb * a[k + 1],
                None => (1.0 - th) * bbar[k] + th * bbar[k + 1],
            };
            point_rows(
                &mut cand,
                p,
                jd,
                scale,
                &m.jets,
                m.essential,
                &xm,
                &ym,
                Some((&m.d3, &slope, bbar_m)),
            );
        }
    }
    let n_eq = eq.h.len();
    let n_lin = lin.h.len();

    // Cones: c_i² ≤ x_i, and d_k (c_k + c_{k+1}) ≥ 1 (turned by 45° as in super::clarabel).
    let mut soc = Rows::default();
    for i in (1..n).filter(|_| !lay.lp) {
        soc.push(&[(lay.x(i), -1.0)], 1.0);
        soc.push(&[(lay.x(i), -1.0)], -1.0);
        soc.push(&[(lay.c(i), -2.0)], 0.0);
    }
    let r = std::f64::consts::FRAC_1_SQRT_2;
    for k in (0..n).filter(|_| !lay.lp) {
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
    let nv = lay.len();
    let mut q = vec![0.0; nv];
    if lay.lp {
        // The gradient of T = Σ 2Δu/(√b_k + √b_{k+1}) (3Δu/√b on a constant-jerk end) at b̄.
        let root = |i: usize| bbar[i].max(1e-300).sqrt();
        for k in 0..n {
            let du = p.du(k);
            if is_rest(k) {
                let i = if k == 0 { 1 } else { n - 1 };
                q[lay.x(i)] -= 1.5 * du * scale / (bbar[i].max(1e-300) * root(i));
            } else {
                let sum = root(k) + root(k + 1);
                for i in [k, k + 1] {
                    if interior(i) {
                        q[lay.x(i)] -= du * scale / (sum * sum * root(i));
                    }
                }
            }
        }
    } else {
        for k in 0..n {
            q[lay.d(k)] = if is_rest(k) { 3.0 } else { 2.0 } * p.du(k) / scale.sqrt();
        }
    }

    // Active set over every row but the equalities and the velocity bounds at the stations
    // (which keep the linear program bounded): most are far from binding (typically a tenth of
    // the jerk rows come within half of their limit). Start with those within half of it at
    // the linearisation point, solve, add every omitted row the solution violates (with those
    // near it), and solve again until none is: the result is the optimum of the full
    // subproblem (the omitted rows hold at it).
    let mut zbar = vec![0.0; nv];
    for i in 1..n {
        zbar[lay.x(i)] = bbar[i] / scale;
        zbar[lay.y(i)] = match abar {
            Some(a) => a[i],
            // The reach profile's ü at the station: the mean of its neighbouring intervals'.
            None => (bbar[i + 1] - bbar[i - 1]) / (2.0 * (p.u[i + 1] - p.u[i - 1])),
        } / scale;
    }
    // The previous subproblem's active rows stay (same rows, same order, when their count
    // agrees): the active set changes little from one iterate to the next.
    let keep = carried.len() == cand.len();
    let threshold = ACTIVE_AT;
    let mut active: Vec<bool> = (0..cand.len())
        .map(|r| (keep && carried[r]) || cand.value(r, &zbar) >= threshold)
        .collect();
    // The duality gap of a subproblem only moves the next linearisation point; 1e-5 of the
    // cycle time is a tenth of what the iteration's own stopping test resolves.
    let gap = settings.tol_gap.max(1e-5);
    let (mut iterations, mut solve_time, mut rounds) = (0, 0.0, 0);
    let (x, status) = loop {
        let mut all = Rows::default();
        all.append(&eq);
        all.append(&lin);
        let mut n_jerk = 0;
        for (r, _) in active.iter().enumerate().filter(|(_, a)| **a) {
            all.copy_row(&cand, r);
            n_jerk += 1;
        }
        all.append(&soc);
        let m = all.h.len();
        let a = CscMatrix::new_from_triplets(m, nv, all.i, all.j, all.v);
        let pmat = CscMatrix::zeros((nv, nv));
        let mut cones = Vec::with_capacity(2 + n_soc);
        cones.push(SupportedConeT::ZeroConeT(n_eq));
        if n_lin + n_jerk > 0 {
            cones.push(SupportedConeT::NonnegativeConeT(n_lin + n_jerk));
        }
        cones.extend(std::iter::repeat_n(
            SupportedConeT::SecondOrderConeT(3),
            n_soc,
        ));
        let s = settings.clarabel(gap)?;
        let mut solver = DefaultSolver::new(&pmat, &q, &a, &all.h, &cones, s)
            .map_err(|e| Error::Solver(format!("problem setup: {e:?}")))?;
        solver.solve();
        let sol = &solver.solution;
        iterations += sol.iterations;
        solve_time += sol.solve_time;
        let status = match sol.status {
            SolverStatus::Solved => Status::Optimal,
            SolverStatus::AlmostSolved => Status::AlmostOptimal,
            other => {
                return Err(Error::Solver(format!(
                    "jerk-limited subproblem: Clarabel stopped with status {other:?}"
                )));
            }
        };
        // Any omitted row violated: add it, and with it every omitted row near its bound at
        // this solution (the next solution is likely to lean on them too); after
        // [`ACTIVE_ROUNDS`] rounds, every row (a start far from the optimum can otherwise
        // uncover a few rows per round for many rounds).
        rounds += 1;
        let violated = (0..cand.len()).any(|r| !active[r] && cand.value(r, &sol.x) > 1.0 + 1e-9);
        let all = rounds >= ACTIVE_ROUNDS;
        let mut added = 0;
        if violated {
            for (r, act) in active.iter_mut().enumerate() {
                if !*act && (all || cand.value(r, &sol.x) > ACTIVE_AT) {
                    *act = true;
                    added += 1;
                }
            }
        }
        if std::env::var_os("FEEDOPT_JERK_TRACE").is_some() {
            eprintln!(
                "  active rows {n_jerk} of {} candidates, {added} added",
                cand.len()
            );
        }
        if added == 0 {
            *carried = std::mem::take(&mut active);
            break (sol.x.clone(), status);
        }
    };
    let mut b = Vec::with_capacity(n + 1);
    let mut acc = Vec::with_capacity(n + 1);
    b.push(p.b_start);
    acc.push(0.0);
    for i in 1..n {
        b.push((x[lay.x(i)] * scale).max(0.0));
        acc.push(x[lay.y(i)] * scale);
    }
    b.push(p.b_end);
    acc.push(0.0);
    Ok(SpanSolution {
        a: Some(acc),
        b,
        status,
        iterations,
        solve_time,
    })
}
