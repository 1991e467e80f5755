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
//! Variables b_i and a_i at every station; between stations b is the cubic with b and
//! b' = 2a given at both ends (Hermite: [`crate::motion::Law::Cubic`]), so a is quadratic and
//! a' linear there, its end values σ⁰_k, σ¹_k linear in (b_k, b_{k+1}, a_k, a_{k+1}); q̈ is
//! continuous, q⃛ bounded and free to jump at a station. The jerk rows are stated at both ends
//! e of every interval k, with that interval's a' at e and q''' on its side of a knot. (With
//! a' constant per interval — b quadratic, `b_{k+1} − b_k = Δu_k (a_k + a_{k+1})` — a jerk
//! limit that holds a ramp is met at one end of each interval only, and the time lost is of
//! first order in Δu; a linear a' follows the bound to second order. The first subproblem
//! from the reach profile is solved with those equalities, "tied", which tie ü to b from the
//! span's ends; later ones free the slopes.) A rest-to-rest span starts and ends with a constant-jerk interval
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
//! b_reach (ü at a station: the mean of its two intervals'). The tangent at *any* b̄ is an
//! inner approximation, so even this first subproblem's solution is jerk-feasible, however far
//! from jerk-feasible b_reach is. Iterations stop when the cycle time (eq. 43 under the motion
//! laws) changes by less than [`JerkOptions::convergence`].
//!
//! Each subproblem is an LP (the linearised time, [`Objective::Linearised`]) or a second-order
//! cone program (the time itself, [`Objective::Cones`]) in the scaled variables x = b/B,
//! y = a/B (B: the median of the first linearisation point); the rows that are far from their
//! bounds are left out until a solution violates them (an active set). The linearised time can
//! overshoot: where the time of a new iterate exceeds the previous one's, the step between
//! them is halved until it does not (both satisfy the convex subproblem, so every point
//! between them is jerk-feasible) — without it the iteration cycled on a LinuxCNC program.
//! Either objective sees b only at the stations, so b is also kept above half its chord at
//! every collocation point ([`DIP`]).
//!
//! ## Windows, in parallel
//!
//! Where the reach profile runs along the velocity bound for a few stations (set by one axis),
//! the jerk-limited optimum does too: its acceleration ramps at the jerk limit, so it leaves
//! and rejoins such a plateau a few stations from its ends. Fixing b and ü at the middle of a
//! plateau therefore cuts the span into independent pieces; each piece runs its own SCP with
//! its ends fixed, on as many threads as [`SolverSettings::threads`] allows, and stops at its
//! own 1e-4 (so the whole does too). A refinement that only adds stations inside some windows
//! solves only those. On the 20 COPP paths the windowed cycle times are 1e-5 to 3e-5 above the
//! one-piece ones, within the SCP's own tolerance (test `windows_agree_with_one_piece`).
//!
//! The cone form: c_i ≤ √x_i and d_k (c_k + c_{k+1}) ≥ 1 as in
//! [`super::clarabel`], minimising `Σ 2Δu_k d_k/√B` (`3 Δu_k d_k/√B` on a constant-jerk end
//! interval).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, SolverStatus, SupportedConeT};

use super::{Rows, SolverSettings, SpanSolution, Status};
use crate::constraints::{Chord, SpanProblem, point_bound};
use crate::error::{Error, Result};
use crate::geometry::Span;
use crate::kinematics::{AxisJets, Kinematics, MAX_AXES};
use crate::machine::{Limit, Machine};
use crate::motion::{Interval, Shape};
use crate::solver::interval_times;

/// Settings of the sequential convex programme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JerkOptions {
    /// Stop when the cycle time changes by less than this, relative.
    pub convergence: f64,
    /// At most this many convex subproblems.
    pub max_iterations: usize,
    /// The subproblems' objective.
    pub objective: Objective,
    /// Stations per window: a longer span is cut into windows of about this many stations,
    /// solved independently and in parallel (see [`solve`]); `usize::MAX`: one piece. 50 (as
    /// [`MIN_WINDOW`]) rather than 150: a window at a rest end, whose SCP takes twice the
    /// iterations of the others and whose dense collocation doubles its rows, is then
    /// smaller, and converges closer. On the 20 COPP paths with jerk limits (one core, the
    /// CLI, alternating runs): 150 → 100 stations 2.54 → 2.46 s of CPU for the twenty, 100 →
    /// 50 2.52–2.58 → 2.35–2.37 s; paths 1 and 11 3.3e-5 and 3.9e-5 shorter, the others within
    /// 5e-6; the windowed times 3e-5…8e-5 below the one-piece SCP's, which stops further from
    /// the optimum at its rest ends. The jerk-limited impeller: 9.5–9.9 (150) and 9.4–9.5 (100)
    /// → 8.9 s (50) of CPU, 1193.6237 → 1193.6214 s.
    pub window: usize,
    /// A straight span from rest to rest with the same limits everywhere takes the double-S
    /// profile in closed form ([`super::double_s`]) instead of the programme (an adaptive
    /// refinement only; a grid the user fixes is always solved by the programme).
    pub closed_form: bool,
    /// Who solves the linear subproblems ([`Objective::Linearised`]).
    pub lp_solver: LpSolver,
}

/// The solver of the SCP's linear subproblems.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LpSolver {
    /// The banded interior-point method (`solver::banded`), with Clarabel where it does not
    /// answer (a subproblem it cannot solve within its iteration cap, e.g. an infeasible one).
    #[default]
    Banded,
    /// Clarabel for every subproblem.
    Clarabel,
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
            window: 50,
            closed_form: true,
            lp_solver: LpSolver::default(),
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
    /// The [`collocation`] points of every interval, interval by interval.
    pub mid: Vec<Midpoint>,
    /// Interval k's collocation points are `mid[mid_start[k]..mid_start[k + 1]]`.
    pub mid_start: Vec<usize>,
}

impl JerkData {
    /// Appends to `out` the exact bits of everything the programme reads of this data beyond
    /// its [`SpanProblem`] (see [`SpanProblem::fingerprint`]; the axis positions q at the
    /// collocation points are left out as there).
    pub fn fingerprint(&self, out: &mut Vec<u64>) {
        let JerkData {
            right,
            left,
            limits,
            rest_bound,
            mid,
            mid_start,
        } = self;
        for side in [right, left] {
            out.push(side.len() as u64);
            out.extend(side.iter().flatten().map(|x| x.to_bits()));
        }
        out.extend(limits.iter().flat_map(|l| match l {
            Some(l) => [1, l.min.to_bits(), l.max.to_bits()],
            None => [0, 0, 0],
        }));
        out.extend([
            rest_bound.0.to_bits(),
            rest_bound.1.to_bits(),
            mid.len() as u64,
        ]);
        for m in mid {
            let Midpoint {
                theta,
                jets,
                d3,
                b_max,
                essential,
                velocity_only,
                eager,
            } = m;
            out.extend([theta.to_bits(), b_max.to_bits(), u64::from(*essential)]);
            out.push(u64::from(*velocity_only) | (u64::from(*eager) << 1));
            out.extend(
                jets.dq
                    .iter()
                    .chain(&jets.ddq)
                    .chain(d3)
                    .map(|x| x.to_bits()),
            );
        }
        out.extend(mid_start.iter().map(|&k| k as u64));
    }
}

/// Where inside each interval velocity, acceleration and jerk are also bounded (as fractions
/// of the interval): b is cubic between stations and may bulge above both ends, and the
/// geometry's curvature varies in between. Only the rows at [`EAGER`] and the velocity bounds
/// at [`VELOCITY_ONLY`] are stated from the start; the others are *lazy*: they join a
/// subproblem where its solution breaks them ([`Program::solve`]), so that they cost an LP
/// rows only where they bind.
///
/// With rows at ¼, ½, ¾ alone, the jerk of the SCP's answer bulged between them: on the 20 COPP
/// paths with jerk limits (1,000 stations) the first 1 ms re-simulation found it over its
/// limit by 0.1–0.5 % in 115–124 intervals of every path, all at θ ≈ 0.36–0.39 and 0.61–0.64,
/// and the local refinement that divided them, solved their windows again and re-simulated
/// the path twice more was 41 % of the twenty's CPU time (2.31 s; 1.36 s stopped after the
/// first re-simulation). Each point added moved the bulge: with ⅜ and ⅝, 17–23 intervals per
/// path, between 0.1 and ¼ (velocity only there then); with acceleration and jerk at 0.1 and
/// 0.9, 2–3, at 0.43–0.45 and 0.55–0.57; with 7/16 and 9/16, 13 in all twenty, at 0.16–0.19
/// and 0.82–0.84; with 0.175 and 0.825, none: every path verified at its first re-simulation.
/// Stated from the start, those rows made every LP twice as costly (the first pass's LPs
/// 0.75 → 1.49 s of CPU; the twenty 2.22 s against 2.34); lazy (with [`Program::values`]
/// reading only the rows an LP left out), the twenty took 1.73–1.77 s against 2.36–2.39
/// (2026-11-27, alternating runs). The cycle times came out 0.8e-4–1.2e-4 longer at 1,000
/// stations, where the bulges had let the jerk exceed its limit between points (1,000 and
/// 4,000 stations differ by 9e-4; at 4,000 both builds give the same times to 3e-6).
pub const COLLOCATION: [f64; 11] = [
    0.1, 0.175, 0.25, 0.375, 0.4375, 0.5, 0.5625, 0.625, 0.75, 0.825, 0.9,
];

/// The points of [`COLLOCATION`] whose rows are stated in every subproblem from the start
/// (those within [`ACTIVE_AT`] of their bound); the other points' rows are lazy. At a point
/// all of whose rows are lazy, no velocity bound is stated (the eager points' and
/// [`VELOCITY_ONLY`]'s hold b there) and every acceleration row is a candidate: the polygon's
/// presolve that picks the few that are edges of it ([`point_bound`]) cost more than
/// evaluating the others (the twenty 1.92 → 1.81 s without it).
pub const EAGER: [f64; 3] = [0.25, 0.5, 0.75];

/// The points of [`COLLOCATION`] where the velocity bound (axes and feed cap) is stated from
/// the start, and the other rows are lazy ([`EAGER`]): on a feed plateau b sits on its cap at
/// both stations while ü there is free (nothing else binds it), and the cubic through them
/// then bulged over the cap just inside a station,
/// where ¼, ½, ¾ did not look (θ ≈ 0.1 or 0.9 in every feed excess the re-simulation found on
/// the jerk-limited impeller, up to 0.6 %; each interval solved again found the next, for
/// 10–12 rounds of local refinement; with these, 5–6). Acceleration and jerk rows there from
/// the start cost the 20 COPP jerk paths 20 % more time (before [`EAGER`]).
pub const VELOCITY_ONLY: [f64; 2] = [0.1, 0.9];

/// The collocation points of the intervals next to a rest end ([`NEAR_REST`]): there b grows
/// as u^(4/3) from 0, which the quadratic pieces follow with a jerk that curves strongly
/// inside each interval (on COPP path 3 it peaked 1.7 % above the limit between ¼ and ½ of
/// the interval after the constant-jerk start).
pub const COLLOCATION_NEAR_REST: [f64; 15] = [
    0.0625, 0.125, 0.1875, 0.25, 0.3125, 0.375, 0.4375, 0.5, 0.5625, 0.625, 0.6875, 0.75, 0.8125,
    0.875, 0.9375,
];

/// The collocation points of the two intervals after a rest end's constant-jerk interval
/// ([`AT_REST`]): every 32nd of the interval. With 16ths the jerk there still peaked 0.2 %
/// over its limit between points (the aamorim programs with jerk limits, where such excesses,
/// caught by the 1 ms re-simulation only at some clock phases, kept local refinement going
/// for twelve rounds).
pub const COLLOCATION_AT_REST: [f64; 31] = {
    let mut t = [0.0; 31];
    let mut i = 0;
    while i < 31 {
        t[i] = (i + 1) as f64 / 32.0;
        i += 1;
    }
    t
};

/// The points of [`COLLOCATION_AT_REST`] whose rows are stated from the start, every fourth;
/// the others' are lazy, as are those of [`COLLOCATION_NEAR_REST`] but [`EAGER`]'s. All
/// stated from the start, a window at a rest end took twice the rows of another and two or
/// three times its subproblems; lazy, the 20 COPP paths with jerk limits took 4.5–5.6 % fewer
/// instructions (paths 3, 10, 15, 18), the same cycle times. (With only [`EAGER`] here too,
/// 0.2–3.6 % fewer again, but path 10 came out 2.6e-5 longer.)
pub const EAGER_AT_REST: [f64; 7] = [0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875];

/// Intervals counted from a rest end (the constant-jerk interval is the first) that take
/// [`COLLOCATION_AT_REST`].
pub const AT_REST: usize = 3;

/// Intervals counted from a rest end that take [`COLLOCATION_NEAR_REST`]: the constant-jerk
/// interval and the stations graded into it (see [`crate::optimize`]) lie within the first
/// seven, and the jerk still bulged 0.1 % over its limit with ¼-spaced points in the ninth and
/// tenth.
pub const NEAR_REST: usize = 12;

/// An interval's collocation points (fractions of it) and those of them where only the
/// velocity bound is stated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collocation {
    /// Every point.
    pub points: &'static [f64],
    /// The points (of `points`) with only the velocity bound ([`VELOCITY_ONLY`]; none next to
    /// a rest end, where the jerk is what bulges between points).
    pub velocity_only: &'static [f64],
    /// The points (of `points`) whose rows are all stated from the start ([`EAGER`],
    /// [`EAGER_AT_REST`]).
    pub eager: &'static [f64],
}

/// The collocation points of interval `k` of `n`.
pub fn collocation(k: usize, n: usize, rest_start: bool, rest_end: bool) -> Collocation {
    let from_rest = |m: usize| (rest_start && k < m) || (rest_end && k + m >= n);
    let (points, velocity_only, eager): (&'static [f64], &'static [f64], &'static [f64]) =
        if from_rest(AT_REST) {
            (&COLLOCATION_AT_REST, &[], &EAGER_AT_REST)
        } else if from_rest(NEAR_REST) {
            (&COLLOCATION_NEAR_REST, &[], &EAGER)
        } else {
            (&COLLOCATION, &VELOCITY_ONLY, &EAGER)
        };
    Collocation {
        points,
        velocity_only,
        eager,
    }
}

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
    /// Its velocity bound is stated from the start, its other rows are lazy
    /// ([`VELOCITY_ONLY`]).
    pub velocity_only: bool,
    /// Every row of it is stated from the start ([`EAGER`]); otherwise all but the velocity
    /// bound of a [`VELOCITY_ONLY`] point are lazy.
    pub eager: bool,
}

/// Inside an interval b may not dip below this share of the chord between its stations: the
/// objective sees b only at the stations (the interval's time as if b were linear in u), so
/// without it a subproblem could bend b down to 0 between two stations where nothing else
/// binds (found on a long interval of a LinuxCNC boat program, where the quadratic reached
/// −3.5 between b = 16 and 13 and the schedule stalled).
pub const DIP: f64 = 0.5;

/// A row joins the active set when its value reaches this fraction of its bound (see
/// [`subproblem`]).
const ACTIVE_AT: f64 = 0.85;

/// Once a subproblem's solution breaks a row it left out, the lazy rows ([`COLLOCATION`])
/// within this fraction of their bound join with it (the others', [`ACTIVE_AT`]). Taking only
/// the broken ones took three LPs per subproblem where two did (the 20 COPP paths with jerk
/// limits 2.11 s against 1.94 s); 0.85 and 0.99 did as well as 0.95.
const LAZY_AT: f64 = 0.95;
const _: () = assert!(LAZY_AT > ACTIVE_AT);

/// The first active set of a subproblem started from a warm profile also takes the rows within
/// this share of their bound at the sites next to a fresh station (one a refinement inserted,
/// where the warm profile is interpolated): the refined profile moves most there, and at
/// [`ACTIVE_AT`] most of those rows were left out, found violated and added for a second LP
/// (the jerk-limited impeller: 2.3 LPs per first subproblem; with 0.6, 2.0 and 8 % less wall
/// time; 0.4 or 0.7 gained less).
const ACTIVE_NEAR_FRESH: f64 = 0.6;

/// The lowest linearisation point b̄ of a subproblem, as a share of its scale B (the median
/// b̄). The jerk row is the tangent of 1/√b at b̄, which lies below the curve at any b̄ > 0, so
/// raising a smaller b̄ to this keeps every iterate jerk-feasible; it only stops the LP from
/// degenerating where an iterate reached b ≈ 0. Without it, the LinuxCNC boats with jerk limits
/// and `--tolerance 0` (a cubic through every point: q''' up to 10⁴ times the median) reached
/// iterates with b ≈ 1e-12 B, objective weights of 1e149 and Clarabel's DualInfeasible, and
/// the solve failed; with it they solve and verify (boat-xyzbc 441.59 s, boat-xyzac
/// 621.45 s, the same to 2e-6 with a floor of 1e-4).
const BBAR_FLOOR: f64 = 1e-6;

/// Solves with part of the rows before all are taken (see [`subproblem`]).
const ACTIVE_ROUNDS: usize = 6;

/// The most a provisional answer ([`Program::solve`]) may exceed a row's bound, relative. The
/// tied subproblem's first answer, where it exceeded any: on the 20 COPP paths with jerk limits
/// 1.12 times the bound (median over their windows), 1.78 (9 in 10), 5.5 at most; on the
/// CAMotics bear's short spans 5.9 (median), up to 320. Linearised far above the jerk-feasible
/// profiles, the free subproblem moves far: without this bound the jerk-limited LinuxCNC
/// impeller took 90 SCP iterations more (2,971 → 3,061) and 5 % more time; with it 18 more,
/// and 3 % fewer interior-point iterations (83,749 → 81,084).
const PROVISIONAL_EXCESS: f64 = 2.0;

/// Samples of a constant-jerk end interval at which the jerk is bounded.
const REST_SAMPLES: usize = 8;

/// The velocity bounds and acceleration rows ([`point_bound`]) of a [`JerkData`]'s collocation
/// points, with where they lie: what a later build of the same span on other stations takes
/// instead of evaluating them again ([`JerkData::new`]).
///
/// A local refinement divides some intervals and keeps the others whole: their collocation
/// points are the same points, and the acceleration polygon's presolve there was 7 % of a
/// jerk-limited COPP path's solve, each round. Kept per span between rounds: 10 bytes a
/// collocation point (the velocity bound, the row mask) and 13 an interval (its first
/// station, where its points start, how many: [`collocation`]'s three sets differ in length).
#[derive(Debug, Clone, Default)]
pub struct MidBounds {
    u: Vec<f64>,
    mid_start: Vec<u32>,
    points: Vec<u8>,
    b_max: Vec<f64>,
    essential: Vec<u16>,
}

// An interval's collocation set is told by its length ([`MidBounds`]).
const _: () = assert!(
    COLLOCATION.len() != COLLOCATION_NEAR_REST.len()
        && COLLOCATION.len() != COLLOCATION_AT_REST.len()
        && COLLOCATION_NEAR_REST.len() != COLLOCATION_AT_REST.len()
);

impl MidBounds {
    /// Per interval k of `u`, the interval of `self.u` with the same ends, if any.
    fn matches(&self, u: &[f64]) -> Vec<Option<usize>> {
        let mut j = 0;
        (0..u.len().saturating_sub(1))
            .map(|k| {
                while j + 1 < self.u.len() && self.u[j] < u[k] {
                    j += 1;
                }
                (j + 1 < self.u.len() && self.u[j] == u[k] && self.u[j + 1] == u[k + 1])
                    .then_some(j)
            })
            .collect()
    }
}

impl JerkData {
    /// Evaluates q''' at the stations of `p`, the geometry at the collocation points and the
    /// end-interval bounds (on `threads` threads, 0: as many as the machine has). `previous`:
    /// the bounds of an earlier build of the same span ([`JerkData::bounds`]), taken where an
    /// interval and its collocation points are the same (the same values, bit for bit).
    pub fn new(
        span: &Span,
        kin: &Kinematics,
        machine: &Machine,
        p: &SpanProblem,
        chord: Option<&Chord>,
        threads: usize,
        previous: Option<&MidBounds>,
    ) -> JerkData {
        let knots = span.spline.knots();
        let last_seg = knots.len() - 2;
        let d3 = |seg: usize, u: f64| {
            let w = span.spline.eval_in(seg, u);
            kin.axis_third_derivatives(&w, &span.spline.d3_in(seg, u))
        };
        // q''' on both sides of station u (they differ on a knot: a station there belongs to
        // the segment before it on its left side).
        let sides = |u: f64| {
            let seg_r = span.spline.segment(u);
            let seg_l = if seg_r > 0 && u <= knots[seg_r] {
                seg_r - 1
            } else {
                seg_r
            };
            let right = d3(seg_r.min(last_seg), u);
            let left = if seg_l == seg_r { right } else { d3(seg_l, u) };
            (right, left)
        };
        let na = p.n_axes();
        // Both acceleration rows of every axis ([`crate::constraints::essential_rows`]' mask).
        let every_row = u16::try_from((1u32 << (2 * na)) - 1).unwrap_or(u16::MAX);
        let limits: Vec<Option<Limit>> = machine.axes.iter().take(na).map(|a| a.jerk).collect();
        let n = p.intervals();
        let rest = rest_bounds(span, kin, machine, p);
        let (rs, re) = (p.b_start == 0.0, p.b_end == 0.0);
        let mut mid_start = Vec::with_capacity(n + 1);
        mid_start.push(0);
        for k in 0..n {
            mid_start.push(mid_start[k] + collocation(k, n, rs, re).points.len());
        }
        // Per interval, where `previous` has its collocation points' bounds.
        let kept: Vec<Option<usize>> = match previous {
            Some(prev) => prev
                .matches(&p.u)
                .into_iter()
                .enumerate()
                .map(|(k, m)| {
                    let points = collocation(k, n, rs, re).points.len();
                    m.filter(|&j| usize::from(prev.points[j]) == points)
                        .map(|j| prev.mid_start[j] as usize)
                })
                .collect(),
            None => vec![None; n],
        };
        let midpoint = |(k, i, th, velocity_only, eager): (usize, usize, f64, bool, bool)| {
            let um = p.u[k] + th * (p.u[k + 1] - p.u[k]);
            let seg = span.spline.segment(um);
            let w = span.spline.eval_in(seg, um);
            let jets = kin.axis_jets(&w);
            let (b_max, essential) = match (previous, kept[k]) {
                (Some(prev), Some(at)) => (prev.b_max[at + i], prev.essential[at + i]),
                // Every row lazy: no velocity bound, every acceleration row ([`EAGER`]).
                _ if !eager && !velocity_only => (f64::INFINITY, every_row),
                _ => {
                    let cap = span.feed_cap(seg, um);
                    let pb = point_bound(
                        machine,
                        &p.acceleration,
                        &jets,
                        &w,
                        span.kind,
                        (cap, None),
                        chord,
                    );
                    (pb.b_max, pb.essential)
                }
            };
            Midpoint {
                theta: th,
                d3: kin.axis_third_derivatives(&w, &span.spline.d3_in(seg, um)),
                jets,
                b_max,
                essential,
                velocity_only,
                eager,
            }
        };
        // Chunks of intervals (their first stations and collocation points) in parallel.
        const CHUNK: usize = 128;
        let chunks: Vec<(usize, usize)> = (0..=n)
            .step_by(CHUNK)
            .map(|k0| (k0, (k0 + CHUNK).min(n + 1)))
            .collect();
        let parts = super::par_map(&chunks, threads, |&(k0, k1)| {
            let stations: Vec<_> = (k0..k1).map(|i| sides(p.u[i])).collect();
            let mids: Vec<Midpoint> = (k0..k1.min(n))
                .flat_map(|k| {
                    let set = collocation(k, n, rs, re);
                    set.points.iter().enumerate().map(move |(i, &th)| {
                        let velocity_only = set.velocity_only.contains(&th);
                        (k, i, th, velocity_only, set.eager.contains(&th))
                    })
                })
                .map(midpoint)
                .collect();
            (stations, mids)
        });
        let (mut right, mut left) = (Vec::with_capacity(n + 1), Vec::with_capacity(n + 1));
        let mut mid = Vec::with_capacity(mid_start[n]);
        for (stations, mids) in parts {
            for (r, l) in stations {
                right.push(r);
                left.push(l);
            }
            mid.extend(mids);
        }
        JerkData {
            right,
            left,
            limits,
            rest_bound: rest,
            mid,
            mid_start,
        }
    }
}

impl JerkData {
    /// Its collocation points' bounds, for a later build of the same span on stations `p.u`
    /// ([`JerkData::new`]).
    pub fn bounds(&self, p: &SpanProblem) -> MidBounds {
        MidBounds {
            u: p.u.clone(),
            mid_start: self.mid_start.iter().map(|&m| m as u32).collect(),
            points: self
                .mid_start
                .windows(2)
                .map(|w| (w[1] - w[0]) as u8)
                .collect(),
            b_max: self.mid.iter().map(|m| m.b_max).collect(),
            essential: self.mid.iter().map(|m| m.essential).collect(),
        }
    }

    /// The longest time an axis takes to ramp its acceleration from 0 to its limit at its jerk
    /// limit, max_j a_j / j_j (s; 0 without jerk limits): about how early a jerk-limited
    /// profile leaves a velocity plateau of the acceleration-limited one.
    pub fn ramp_time(&self, p: &SpanProblem) -> f64 {
        self.limits
            .iter()
            .zip(&p.acceleration)
            .filter_map(|(j, a)| {
                let j = (*j)?;
                let jm = j.max.abs().min(j.min.abs());
                (jm > 0.0).then(|| a.max.abs().max(a.min.abs()) / jm)
            })
            .fold(0.0, f64::max)
    }

    /// The data of stations `a..=b` (intervals a..b), as [`SpanProblem::window`].
    pub fn window(&self, a: usize, b: usize) -> JerkData {
        let n = self.right.len() - 1;
        let (m0, m1) = (self.mid_start[a], self.mid_start[b]);
        JerkData {
            right: self.right[a..=b].to_vec(),
            left: self.left[a..=b].to_vec(),
            limits: self.limits.clone(),
            rest_bound: (
                if a == 0 {
                    self.rest_bound.0
                } else {
                    f64::INFINITY
                },
                if b == n {
                    self.rest_bound.1
                } else {
                    f64::INFINITY
                },
            ),
            mid: self.mid[m0..m1].to_vec(),
            mid_start: self.mid_start[a..=b].iter().map(|&m| m - m0).collect(),
        }
    }
}

/// The bounds on b at station 1 and N−1 that the constant-jerk end intervals of `p` put there
/// ([`JerkData::rest_bound`], without the rest of the jerk data): infinite at an end not at rest.
pub fn rest_bounds(
    span: &Span,
    kin: &Kinematics,
    machine: &Machine,
    p: &SpanProblem,
) -> (f64, f64) {
    let limits: Vec<Option<Limit>> = machine
        .axes
        .iter()
        .take(p.n_axes())
        .map(|a| a.jerk)
        .collect();
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
    rest
}

/// Where the jerk-limited profile from rest at station `i` (0, or N when `end`) should stop
/// growing at full jerk, u measured from that end, estimated from the limits there.
///
/// From rest, every axis moves as `q⃛ = q' u⃛` at first, so the path jerk is at most
/// `J = min_j j_j/|q'_j|` and the path acceleration at most `A` (the acceleration limits at
/// b = 0). At full jerk `u = J t³/6`; the phase lasts until ü reaches A (`t = A/J`), or until
/// the speed V the profile may rise to is half reached (`t = √(V/J)`: +J then −J), or until
/// half the span is used (`J t³ ≤ L/2`). V is taken as the lowest velocity bound on the near
/// half of the span, so the estimate errs short: a constant-jerk interval that ends before
/// the switch is exact, one that ends after it is not.
///
/// An axis whose q' is rounding (`STILL_AXIS` of the largest |q'|) does not move along the
/// path there and bounds no path jerk: its 1e-16 would make J 1e20 and the phase 1e-35 long,
/// a first interval no solver can scale (the fuzz corpus's hand-made APT program on a B-head
/// machine with jerk limits on Z only: every subproblem of that span stopped Clarabel).
pub fn rest_phase_length(p: &SpanProblem, machine: &Machine, end: bool) -> Option<f64> {
    let n = p.intervals();
    let i = if end { n } else { 0 };
    let (up, down) = path_jerk_bounds(machine, &p.jets.dq(i)[..p.n_axes()]);
    let jerk = up.min(down);
    let (lo, hi) = p.udd_range(i, 0.0);
    let acc = if end { -lo } else { hi };
    let half = if end { n / 2..n + 1 } else { 0..n / 2 + 1 };
    let b_max = p.b_max[half].iter().copied().fold(f64::INFINITY, f64::min);
    let len = p.u[n] - p.u[0];
    if !(jerk.is_finite() && jerk > 0.0 && acc > 0.0 && len > 0.0) {
        return None;
    }
    let t = (acc / jerk)
        .min((b_max.sqrt() / jerk).sqrt())
        .min((len / (2.0 * jerk)).cbrt());
    let at = jerk * t * t * t / 6.0;
    (at.is_finite() && at > 0.0 && at < 0.5 * len).then_some(at)
}

/// An axis whose |q'| is at most this share of the largest axis's does not move along the path
/// ([`path_jerk_bounds`]).
const STILL_AXIS: f64 = 1e-9;

/// The jerk bounds on the path that the axes' jerk limits give along the direction `dq` (q'
/// per axis) where the path is straight (q'' = 0, so q⃛ = q' u⃛): the largest u⃛ ≥ 0 and the
/// largest −u⃛ (each infinite where no moving axis has a jerk limit). An axis with |q'| at most
/// [`STILL_AXIS`] of the largest does not move and bounds nothing.
pub(crate) fn path_jerk_bounds(machine: &Machine, dq: &[f64]) -> (f64, f64) {
    let moving = dq.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let (mut up, mut down) = (f64::INFINITY, f64::INFINITY);
    for (axis, &d) in machine.axes.iter().zip(dq) {
        let Some(lim) = axis.jerk else { continue };
        if d.abs() <= STILL_AXIS * moving {
            continue;
        }
        // u⃛ > 0 moves axis j by q'·u⃛: its jerk's positive side bounds it where q' > 0.
        let (plus, minus) = if d > 0.0 {
            (lim.max / d, -lim.min / d)
        } else {
            (-lim.min / -d, lim.max / -d)
        };
        up = up.min(plus);
        down = down.min(minus);
    }
    (up, down)
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
    /// a' at both ends of every interval.
    pub slopes: Vec<[f64; 2]>,
    /// Stations that were not stations of the previous profile.
    pub fresh: Vec<bool>,
    /// Solve only windows about the fresh stations, cut a few stations from them where the
    /// previous profile is kept (a local refinement), besides the plateau cuts ([`solve`]).
    pub local: bool,
}

impl Warm {
    /// `old`'s profile (b, ü and a' under its motion laws) at the stations of `p`; `None` if
    /// `old` is not jerk-limited. Where every new interval lies inside an old one (a
    /// refinement), the cubic law carries the profile over exactly.
    pub fn resample(old_p: &SpanProblem, old: &SpanSolution, p: &SpanProblem) -> Option<Warm> {
        let a_old = old.a.as_deref()?;
        let s_old = old.slopes.as_deref();
        let n = p.u.len();
        let last = old_p.intervals() - 1;
        let shape = Shape {
            a: Some(a_old),
            slopes: s_old,
            ends: None,
        };
        let mut slopes = Vec::with_capacity(n.saturating_sub(1));
        let mut k = 0;
        for j in 0..n.saturating_sub(1) {
            let mid = 0.5 * (p.u[j] + p.u[j + 1]);
            while k < last && old_p.u[k + 1] <= mid {
                k += 1;
            }
            let iv = Interval::of(&old_p.u, &old.b, shape, k);
            slopes.push([
                iv.slope_at_x(p.u[j] - old_p.u[k]),
                iv.slope_at_x(p.u[j + 1] - old_p.u[k]),
            ]);
        }
        let (mut b, mut a, mut fresh) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        let mut k = 0;
        let last = old_p.intervals() - 1;
        for &u in &p.u {
            while k < last && old_p.u[k + 1] <= u {
                k += 1;
            }
            let iv = Interval::of(&old_p.u, &old.b, shape, k);
            let (bu, au) = iv.at_x(u - old_p.u[k]);
            b.push(bu);
            a.push(au);
            fresh.push(u != old_p.u[k] && u != old_p.u[k + 1]);
        }
        Some(Warm {
            b,
            a,
            slopes,
            fresh,
            local: false,
        })
    }
}

/// The jerk-limited optimum of one span: sequential convex programming from the
/// acceleration-limited reach profile `greedy` (same stations), or from `warm`.
///
/// A long span is cut into windows at stations where the starting profile runs along the
/// velocity bound ([`PLATEAU`] stations each side): b and ü are fixed there, and each window
/// runs its own SCP, the windows in parallel (`settings.threads`). Where the profile sits on
/// its velocity bound over several stations, the optimum does too, so the cut costs almost
/// nothing (1e-5…3e-5 of the cycle time on the COPP paths); a window that cannot
/// be solved with its ends fixed sends the span back to one piece.
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
    let warm = warm.filter(|w| w.b.len() == p.u.len() && w.b[1..n].iter().all(|&b| b > 0.0));
    let start = match &warm {
        Some(w) => Start {
            b: &w.b,
            a: Some(&w.a),
            slopes: Some(&w.slopes),
            fresh: Some(&w.fresh),
        },
        None => Start {
            b: &greedy.b,
            a: None,
            slopes: None,
            fresh: None,
        },
    };
    let threads = settings.worker_threads();
    let mut cuts = cuts(p, jd, &start, threads, options.window);
    if let Some(w) = warm.as_ref().filter(|w| w.local) {
        // The plateau cuts as well: where the fresh stations lie close together, their
        // windows merge into one as long as the span (a COPP path: 470 and 660 stations).
        cuts.extend(local_cuts(&w.fresh));
        cuts.sort_unstable();
        cuts.dedup();
    }
    if cuts.len() <= 2 {
        return solve_piece(p, jd, &start, (0.0, 0.0), settings, options);
    }
    let t0 = std::time::Instant::now();
    // Solved windows, by their ends. A window that fails (its fixed ends can be out of reach:
    // a plateau the jerk-limited profile leaves earlier than PLATEAU stations before the cut,
    // or a kink of the bound at the cut) is merged with its neighbours and solved again; the
    // others keep their profiles (their ends do not move). At worst the span is one piece.
    let mut solved: Vec<((usize, usize), SpanSolution)> = Vec::new();
    loop {
        let windows: Vec<(usize, usize)> = cuts.windows(2).map(|c| (c[0], c[1])).collect();
        // The windows at the span's ends first: their dense collocation and their start from
        // rest make them the slowest, and a slow window taken last leaves the other threads
        // idle.
        let last = windows.len() - 1;
        let mut queue: Vec<usize> = if last == 0 { vec![0] } else { vec![0, last] };
        queue.extend(1..last);
        queue.retain(|&w| !solved.iter().any(|(ab, _)| *ab == windows[w]));
        let results = super::par_map(&queue, threads, |&w| {
            let (a, b) = windows[w];
            if let Some(w) = warm.as_ref().filter(|w| !w.fresh[a..=b].contains(&true)) {
                // No new station in this window: the previous profile is its solution still
                // (its ends are fixed at that profile's values).
                return Ok(SpanSolution {
                    ends: None,
                    b: w.b[a..=b].to_vec(),
                    a: Some(w.a[a..=b].to_vec()),
                    slopes: Some(w.slopes[a..b].to_vec()),
                    status: Status::Optimal,
                    iterations: 0,
                    solve_time: 0.0,
                    scp_iterations: 0,
                });
            }
            let (ba, aa) = start.at(p, a);
            let (bb, ab) = start.at(p, b);
            let wp = p.window(a, b, ba, bb);
            let wjd = jd.window(a, b);
            let ws = Start {
                b: &start.b[a..=b],
                a: start.a.map(|x| &x[a..=b]),
                slopes: start.slopes.map(|x| &x[a..b]),
                fresh: start.fresh.map(|x| &x[a..=b]),
            };
            solve_piece(&wp, &wjd, &ws, (aa, ab), settings, options)
        });
        let mut failed: Vec<(usize, usize)> = Vec::new();
        let mut error = None;
        for (w, r) in queue.into_iter().zip(results) {
            match r {
                Ok(sol) => solved.push((windows[w], sol)),
                Err(e) => {
                    failed.push(windows[w]);
                    error = Some(e);
                }
            }
        }
        if let Some(e) = error {
            if windows.len() == 1 {
                return Err(e);
            }
            tracing::debug!("SCP windows {failed:?} failed ({e}); merged with their neighbours");
            cuts.retain(|&c| c == 0 || c == n || !failed.iter().any(|&(a, b)| c == a || c == b));
            solved.retain(|((a, b), _)| cuts.contains(a) && cuts.contains(b));
            continue;
        }
        solved.sort_by_key(|(ab, _)| ab.0);
        let (windows, results): (Vec<_>, Vec<_>) =
            solved.into_iter().map(|(ab, sol)| (ab, Ok(sol))).unzip();
        let mut sol = stitch(&windows, results)?;
        sol.solve_time = t0.elapsed().as_secs_f64();
        tracing::debug!("SCP in {} windows: {:?}", windows.len(), windows);
        return Ok(sol);
    }
}

/// The first linearisation point: b at every station, and ü (a jerk-limited profile) or none
/// (the reach profile).
struct Start<'a> {
    b: &'a [f64],
    a: Option<&'a [f64]>,
    /// a' at both ends of every interval (with `a`).
    slopes: Option<&'a [[f64; 2]]>,
    /// Stations where a warm start's profile is interpolated, not solved: no window ends
    /// there (its b and ü need not be feasible on the new stations).
    fresh: Option<&'a [bool]>,
}

impl Start<'_> {
    /// (b, ü) at station i: ü as given, or for the reach profile on a velocity plateau the
    /// slope of the bound, ½ db_max/du (the optimum follows the bound there).
    fn at(&self, p: &SpanProblem, i: usize) -> (f64, f64) {
        if i == 0 || i == p.intervals() {
            // The span's own ends: ü = 0 there.
            return (self.b[i], 0.0);
        }
        let a = match self.a {
            Some(a) => a[i],
            None => {
                // A flat plateau (the bound varies by less than FLAT around the cut, e.g. a feed
                // cap): b at the lowest bound there and ü = 0, which stay feasible on both
                // sides. The bound's central slope is noise there, and where its one-sided
                // slopes differ (a kink) no ü keeps b under it on both sides: the windows of
                // the bundled pocket with jerk limits were infeasible so, and the span fell
                // back to one piece.
                let near = &p.b_max[i.saturating_sub(PLATEAU)..=(i + PLATEAU).min(p.intervals())];
                let lo = near.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = near.iter().copied().fold(0.0, f64::max);
                if hi <= lo * (1.0 + FLAT) {
                    return (self.b[i].min(lo), 0.0);
                }
                0.5 * (p.b_max[i + 1] - p.b_max[i - 1]) / (p.u[i + 1] - p.u[i - 1])
            }
        };
        (self.b[i], a)
    }
}

/// A plateau of the reach profile whose bound varies by less than this (relative) around a
/// cut is taken as flat there ([`Start::at`]).
const FLAT: f64 = 1e-4;

/// How many times a piece whose first subproblem fails is linearised again at b̄/4
/// ([`solve_piece`]).
const MAX_RESCALES: usize = 3;

/// Stations fewer than this apart are not cut (100 until 2026-11-27; see
/// [`JerkOptions::window`]).
const MIN_WINDOW: usize = 50;

/// A cut needs the starting profile on the velocity bound, set by the same limit, from
/// `PLATEAU` stations before it to `PLATEAU` after: a jerk-limited profile leaves a plateau
/// of the acceleration-limited one a few stations early and rejoins it a few late (its
/// acceleration ramps at the jerk limit), so the middle of a long plateau is on the bound in
/// both.
pub const PLATEAU: usize = 5;

/// Window boundaries `0 = c_0 < c_1 < … = N`: about `max(threads, N/window)` windows of similar
/// length (none shorter than [`MIN_WINDOW`]), each cut at the plateau station nearest its
/// target (within ±40 % of a window); targets without one are skipped.
fn cuts(
    p: &SpanProblem,
    jd: &JerkData,
    start: &Start,
    threads: usize,
    window: usize,
) -> Vec<usize> {
    let n = p.intervals();
    if window == usize::MAX {
        return vec![0, n];
    }
    let windows = threads
        .max(n.div_ceil(window.max(1)))
        .min(n / MIN_WINDOW)
        .max(1);
    let mut cuts = vec![0usize];
    if windows > 1 {
        // A jerk-limited start is on the bound wherever the optimum is (up to the refinement
        // that follows): its neighbours on the bound suffice.
        // From the reach profile, the plateau must also reach a jerk ramp's length past the
        // cut on both sides: the jerk-limited profile leaves it about that early (on the
        // bundled pocket, 15 mm of a 150 mm/s feed cap with a/j = 0.1 s: ten stations, where
        // PLATEAU = 5 made the windows infeasible).
        let half = if start.a.is_some() { 1 } else { PLATEAU };
        let ramp = if start.a.is_some() {
            0.0
        } else {
            jd.ramp_time(p)
        };
        let on_plateau = |m: usize| {
            if m <= half || m + half >= n || !p.b_max[m].is_finite() {
                return false;
            }
            let reach = 2.0 * ramp * p.b_max[m].sqrt();
            let mut lo = m - half;
            while lo > 1 && p.u[m] - p.u[lo] < reach {
                lo -= 1;
            }
            let mut hi = m + half;
            while hi + 1 < n && p.u[hi] - p.u[m] < reach {
                hi += 1;
            }
            (lo..=hi).all(|i| {
                p.b_max[i].is_finite()
                    && p.b_max_by[i] == p.b_max_by[m]
                    && start.b[i] >= (1.0 - 1e-4) * p.b_max[i]
                    && !start.fresh.is_some_and(|f| f[i])
            })
        };
        let len = n / windows;
        for w in 1..windows {
            let target = w * n / windows;
            let reach = 2 * len / 5;
            let found = (0..=reach)
                .flat_map(|d| [target.saturating_sub(d), target + d])
                .find(|&m| on_plateau(m));
            if let Some(m) = found.filter(|&m| m >= cuts[cuts.len() - 1] + MIN_WINDOW / 2) {
                cuts.push(m);
            }
        }
    }
    if n - cuts[cuts.len() - 1] < MIN_WINDOW / 2 {
        cuts.pop();
    }
    cuts.push(n);
    cuts
}

/// Stations kept between a fresh station and the end of its window in a local refinement
/// ([`local_cuts`]).
const LOCAL_REACH: usize = 12;

/// Window boundaries `0 = c_0 < c_1 < … = N` of a local refinement (added to the plateau cuts
/// of [`cuts`]): every run of fresh stations gets a window reaching [`LOCAL_REACH`] stations
/// past its first and last (windows that would overlap are one); the stretches between them
/// hold no fresh station, so their profile is kept ([`solve`]). A window cut anywhere else than on a plateau fixes b and ü at
/// the previous profile's values there; where that leaves no feasible profile inside (the
/// fresh stations too close to a cut for the profile to slow down in time), the window fails
/// and is merged with its neighbours, as any window.
///
/// Why: a local refinement divides the intervals where the re-simulation found a limit
/// exceeded. Solving their whole windows again moved the profile everywhere in them, and the
/// re-simulation then found new small excesses (1.001–1.01) in other intervals of those windows:
/// on the jerk-limited impeller 993 violating intervals were followed by 177, 43, 14, … in
/// other intervals of the same spans, each a round of re-solving and re-simulating.
fn local_cuts(fresh: &[bool]) -> Vec<usize> {
    let n = fresh.len() - 1;
    let mut cuts = vec![0usize];
    let mut i = 0;
    while i <= n {
        if !fresh[i] {
            i += 1;
            continue;
        }
        let mut j = i;
        while j < n && fresh[j + 1] {
            j += 1;
        }
        let (a, b) = (
            i.saturating_sub(LOCAL_REACH + 1),
            (j + LOCAL_REACH + 1).min(n),
        );
        // Overlapping or touching the previous window: extend it.
        let last = cuts.len() - 1;
        if cuts.len() >= 2 && a <= cuts[last] {
            cuts[last] = b;
        } else {
            if a > cuts[last] {
                cuts.push(a);
            }
            cuts.push(b);
        }
        i = j + 1;
    }
    if cuts[cuts.len() - 1] != n {
        cuts.push(n);
    }
    cuts
}

/// The windows' profiles joined (each shares its first station with the previous one's last).
fn stitch(windows: &[(usize, usize)], results: Vec<Result<SpanSolution>>) -> Result<SpanSolution> {
    let mut b = Vec::new();
    let mut a = Vec::new();
    let mut slopes = Vec::new();
    let (mut status, mut iterations, mut scp) = (Status::Optimal, 0, 0);
    for (w, r) in results.into_iter().enumerate() {
        let s = r?;
        scp = scp.max(s.scp_iterations);
        let from = if w == 0 { 0 } else { 1 };
        debug_assert_eq!(s.b.len(), windows[w].1 - windows[w].0 + 1);
        b.extend_from_slice(&s.b[from..]);
        a.extend_from_slice(&s.a.as_deref().unwrap_or_default()[from..]);
        slopes.extend_from_slice(s.slopes.as_deref().unwrap_or_default());
        status = status.worst(s.status);
        iterations += s.iterations;
    }
    Ok(SpanSolution {
        ends: None,
        b,
        a: Some(a),
        slopes: Some(slopes),
        status,
        iterations,
        solve_time: 0.0,
        scp_iterations: scp,
    })
}

/// The SCP on one piece of a span (the whole span, or a window whose ends are fixed at b =
/// `p.b_start`, `p.b_end` and ü = `a_ends`).
///
/// Its first subproblem may be provisional ([`Program::solve`]); where the iteration then
/// fails, it is run again without, so the answer never depends on that shortcut (the CAMotics
/// bear with jerk limits: a free subproblem linearised at a provisional answer far above the
/// jerk-feasible profiles stood still on an interval).
fn solve_piece(
    p: &SpanProblem,
    jd: &JerkData,
    start: &Start,
    a_ends: (f64, f64),
    settings: &SolverSettings,
    options: &JerkOptions,
) -> Result<SpanSolution> {
    let mut provisional = false;
    match scp(
        p,
        jd,
        start,
        a_ends,
        settings,
        options,
        Some(&mut provisional),
    ) {
        Err(e) if provisional => {
            tracing::debug!("SCP: {e}; again without a provisional first subproblem");
            scp(p, jd, start, a_ends, settings, options, None)
        }
        answer => answer,
    }
}

/// [`solve_piece`]'s iteration; `provisional`: whether the first subproblem may be provisional,
/// set where one was taken.
fn scp(
    p: &SpanProblem,
    jd: &JerkData,
    start: &Start,
    a_ends: (f64, f64),
    settings: &SolverSettings,
    options: &JerkOptions,
    mut provisional_taken: Option<&mut bool>,
) -> Result<SpanSolution> {
    let mut bbar = start.b.to_vec();
    let mut abar: Option<Vec<f64>> = start.a.map(<[f64]>::to_vec);
    let mut sbar: Option<Vec<[f64; 2]>> = start.slopes.map(<[[f64; 2]]>::to_vec);
    // The time of the previous profile, for the stopping test.
    let mut last_time: Option<f64> = match &abar {
        Some(a) => Some(
            interval_times(
                p,
                &SpanSolution {
                    ends: None,
                    b: bbar.clone(),
                    a: Some(a.clone()),
                    slopes: sbar.clone(),
                    status: Status::Optimal,
                    iterations: 0,
                    solve_time: 0.0,
                    scp_iterations: 0,
                },
            )?
            .iter()
            .sum(),
        ),
        None => None,
    };
    let mut best: Option<(SpanSolution, f64)> = None;
    let (mut status, mut iterations, mut solve_time) = (Status::Optimal, 0, 0.0);
    let mut carried = Carried::default();
    let program = Program::new(p, jd, &bbar, a_ends, options, start.fresh);
    // Whether (bbar, abar) is an iterate of this SCP (feasible), not the start.
    let mut from_iterate = false;
    let mut subproblems = 0;
    let mut rescaled = 0;
    for it in 0..options.max_iterations.max(1) {
        // From the reach profile (no slopes yet) the first subproblem keeps a' constant per
        // interval (the quadratic law), which ties ü to b from the span's ends on; later ones
        // free both ends of every interval. Where Clarabel fails on one form, the other is
        // tried: the free form failed on short rest-to-rest spans whose rows are nearly all
        // active; the tied form is infeasible on a window whose ends fix both b and ü (the
        // equalities then determine ü at both ends from b, which need not agree: the bundled
        // pocket with jerk limits fell back to one piece, at 100–300 ms a subproblem).
        let tie = sbar.is_none();
        // The tied subproblem from the reach profile only sets the point the free ones start
        // linearising at: where its solution violates rows it left out, they join the next
        // subproblem's active set rather than being solved for again here (as any later
        // subproblem's are). It then is no iterate (it breaks those rows), so a free
        // subproblem must follow. On the 20 COPP paths with jerk limits: 13 % fewer
        // interior-point iterations (15,000 → 13,023), the same cycle times to 5e-6 but on
        // paths 1 and 11, 3.1e-5 and 3.5e-5 longer: a window at a rest end stopped one
        // iteration earlier, as the stopping test allows.
        let provisional = provisional_taken.is_some() && tie && it + 1 < options.max_iterations;
        let solved = program
            .solve(
                &bbar,
                abar.as_deref(),
                sbar.as_deref(),
                match (tie, provisional) {
                    (false, _) => Form::Free,
                    (true, false) => Form::Tied,
                    (true, true) => Form::Provisional,
                },
                settings,
                &mut carried,
            )
            .or_else(|e| {
                let form = if tie { "free" } else { "constant" };
                tracing::debug!("SCP {it}: {e}; again with a' {form} per interval");
                program.solve(
                    &bbar,
                    abar.as_deref(),
                    sbar.as_deref(),
                    if tie { Form::Free } else { Form::Tied },
                    settings,
                    &mut carried,
                )
            })
            .or_else(|e| {
                // Both forms stalled (InsufficientProgress or NumericalError: seen on the
                // CAMotics bear with jerk limits, where the whole solve then failed): once more
                // with iterative refinement of every KKT solve, which Clarabel's default
                // leaves on and ours turns off for speed.
                if settings.iterative_refinement {
                    return Err(e);
                }
                tracing::debug!("SCP {it}: {e}; again with iterative refinement");
                let refined = SolverSettings {
                    iterative_refinement: true,
                    ..*settings
                };
                program.solve(
                    &bbar,
                    abar.as_deref(),
                    sbar.as_deref(),
                    if tie { Form::Tied } else { Form::Free },
                    &refined,
                    &mut carried,
                )
            });
        let (mut sol, holds) = match solved {
            Ok(Subsolution { sol, holds }) => {
                if !holds && let Some(taken) = provisional_taken.as_deref_mut() {
                    *taken = true;
                }
                (sol, holds)
            }
            // A provisional answer led here: [`solve_piece`] runs the iteration again without.
            Err(e) if best.is_none() && provisional_taken.as_deref().is_some_and(|t| *t) => {
                return Err(e);
            }
            // Every iterate is jerk-feasible: when a later subproblem fails (a time limit,
            // a numerical stall), the best iterate so far is a valid answer, not yet
            // converged; say so through the status (issue 14: solver failure is not the
            // user's problem).
            Err(e) if best.is_some() => {
                tracing::debug!("SCP {it}: {e}; keeping the best iterate");
                status = status.worst(Status::AlmostOptimal);
                break;
            }
            // No iterate yet: linearise at a quarter of b̄ (the tangent rows of a point far
            // above the jerk-feasible profiles leave a sliver that Clarabel could not
            // solve: a 2.5 mm rest-to-rest span of the CAMotics bear with jerk limits, b̄ up
            // to 50 times the jerk-limited b). The tangent at any b̄ is an inner
            // approximation, so every iterate stays jerk-feasible.
            Err(e) if rescaled < MAX_RESCALES => {
                rescaled += 1;
                tracing::debug!("SCP {it}: {e}; again linearised at b̄/4");
                for b in &mut bbar[1..p.intervals()] {
                    *b *= 0.25;
                }
                (abar, sbar, last_time) = (None, None, None);
                carried = Carried::default();
                continue;
            }
            Err(e) => return Err(e),
        };
        subproblems += 1;
        status = status.worst(sol.status);
        iterations += sol.iterations;
        solve_time += sol.solve_time;
        let mut time: f64 = interval_times(p, &sol)?.iter().sum();
        let mut step = 1.0;
        if let (true, Some(t0), Some(a0)) = (from_iterate, last_time, abar.as_deref()) {
            // The linearised objective can overshoot: the time then rises from one iterate to
            // the next, and the iteration may cycle. Both the previous iterate and this
            // solution satisfy the (convex) subproblem, so every point between them does, and
            // is jerk-feasible: halve the step until the time does not rise.
            while time > t0 && step > 1.0 / 64.0 {
                step *= 0.5;
                let mix = |old: &[f64], new: &[f64]| -> Vec<f64> {
                    old.iter()
                        .zip(new)
                        .map(|(o, n)| o + step * (n - o))
                        .collect()
                };
                let trial = SpanSolution {
                    ends: None,
                    b: mix(&bbar, &sol.b),
                    a: sol.a.as_deref().map(|a| mix(a0, a)),
                    slopes: match (sbar.as_deref(), sol.slopes.as_deref()) {
                        (Some(old), Some(new)) => Some(
                            old.iter()
                                .zip(new)
                                .map(|(o, n)| {
                                    [o[0] + step * (n[0] - o[0]), o[1] + step * (n[1] - o[1])]
                                })
                                .collect(),
                        ),
                        _ => sol.slopes.clone(),
                    },
                    ..sol.clone()
                };
                let t = interval_times(p, &trial)?.iter().sum();
                if t < time {
                    (sol, time) = (trial, t);
                }
            }
        }
        let moved = relative_move(p, &bbar, &sol.b);
        tracing::debug!(
            "SCP {it}: T = {time:.6}, {} IP iterations, {:.1} ms, {:?}, step {step}, moved {moved:.1e}",
            sol.iterations,
            sol.solve_time * 1e3,
            sol.status
        );
        // (A provisional answer that breaks rows is no iterate: neither a point to step back
        // to, nor a candidate answer, nor the end.)
        from_iterate = holds;
        // Converged when the time has settled, or when a subproblem of the free form (as the
        // next one is) taken whole moved the profile so little that the next one, linearised
        // here, is this one to second order ([`relative_move`]).
        let settled = !tie && step == 1.0 && moved <= options.convergence;
        let done = holds
            && (settled
                || last_time.is_some_and(|t| (t - time).abs() <= options.convergence * time));
        last_time = Some(time);
        bbar.clone_from(&sol.b);
        abar.clone_from(&sol.a);
        sbar.clone_from(&sol.slopes);
        if holds && best.as_ref().is_none_or(|(_, t)| time <= *t) {
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
    sol.scp_iterations = subproblems;
    Ok(sol)
}

/// How far a subproblem moved the profile from its linearisation point `bbar` to `b`: the
/// time-weighted mean of (Δb/b)² over the interior stations (each weighted by Δu/√b about it,
/// its share of the time; b below 1e-3 of the largest counted as that).
///
/// The jerk rows are tangents of 1/√b at b̄ and the objective is T linearised at b̄: linearised
/// again at b, a row moves by (3/8)(Δb/b)² of its bound, and the objective's error by a
/// like amount, so the next subproblem differs from this one by about this mean and its
/// solution's time by less. When it is below the SCP's convergence, the next subproblem is not
/// solved: on the jerk-limited impeller, over 2,095 windows, a move below 3e-4 was followed by
/// a change of the time of at most 4.2e-5 (median 1e-6), and a fifth of the subproblems (mostly
/// the confirming second one after a warm start) were spared.
fn relative_move(p: &SpanProblem, bbar: &[f64], b: &[f64]) -> f64 {
    let top = bbar.iter().chain(b).fold(0.0f64, |m, &x| m.max(x));
    let (mut num, mut den) = (0.0, 0.0);
    for i in 1..p.intervals() {
        let big = bbar[i].max(b[i]).max(1e-3 * top);
        if big <= 0.0 {
            continue;
        }
        let w = (p.u[i + 1] - p.u[i - 1]) / big.sqrt();
        let r = (b[i] - bbar[i]) / big;
        num += w * r * r;
        den += w;
    }
    if den > 0.0 { num / den } else { 0.0 }
}

/// A linear expression in the scaled variables with at most five terms (a dip row inside an
/// interval: x_k, x_{k+1}, y_k and both slopes), and a constant.
#[derive(Debug, Clone, Copy, Default)]
struct Lin {
    terms: [(usize, f64); 5],
    len: usize,
    constant: f64,
}

impl Lin {
    fn var(col: usize) -> Lin {
        Lin::default().plus(col, 1.0)
    }
    fn constant(c: f64) -> Lin {
        Lin {
            constant: c,
            ..Lin::default()
        }
    }
    /// `self + w·col` (merged with a term of the same column).
    fn plus(mut self, col: usize, w: f64) -> Lin {
        self.plus_in_place(col, w);
        self
    }
    fn plus_in_place(&mut self, col: usize, w: f64) {
        if let Some(t) = self.terms[..self.len].iter_mut().find(|t| t.0 == col) {
            t.1 += w;
        } else {
            self.terms[self.len] = (col, w);
            self.len += 1;
        }
    }
    /// `self + w·other`.
    #[inline]
    fn add(mut self, other: &Lin, w: f64) -> Lin {
        for &(c, v) in &other.terms[..other.len] {
            self.plus_in_place(c, v * w);
        }
        self.constant += other.constant * w;
        self
    }
    fn eval(&self, z: &[f64]) -> f64 {
        self.terms[..self.len]
            .iter()
            .fold(self.constant, |acc, &(c, v)| acc + v * z[c])
    }
}

/// Where the linearisation point's b̄ at a site comes from.
#[derive(Debug, Clone, Copy)]
enum BbarAt {
    Station(usize),
    /// Inside interval k at x = θΔu: `b_k + 2 a_k x + w0 σ⁰_k + w1 σ¹_k` under the previous
    /// profile's cubic law, or `(1 − θ) b_k + θ b_{k+1}` for the reach profile (no ü).
    Inside {
        k: usize,
        theta: f64,
        x: f64,
        w0: f64,
        w1: f64,
    },
}

/// A point of the path where rows are stated: a station (acceleration), an end of an interval
/// (jerk, with that interval's a'), or a collocation point (velocity, acceleration, jerk).
struct Site<'a> {
    /// b/B, ü/B and (for jerk) a'/B there (the cubic law's, linear in the stations' x, y).
    xb: Lin,
    ya: Lin,
    slope: Lin,
    /// At a collocation point: the chord (1 − θ) x_k + θ x_{k+1} of its interval.
    chord: Lin,
    jets: crate::constraints::JetRef<'a>,
    /// q''' there (jerk rows), on the interval's side of a knot.
    d3: Option<&'a [f64; MAX_AXES]>,
    /// Acceleration rows to state ([`crate::constraints::essential_rows`] mask).
    essential: u16,
    /// The velocity bound (infinite: none; the stations' bounds are always stated).
    b_max: f64,
    /// Its rows but the velocity bound are lazy ([`EAGER`]).
    lazy: bool,
    at: BbarAt,
}

/// Whether interval k is a constant-jerk interval from or to rest (the span's first or last,
/// at an end with b = 0).
fn is_rest_interval(p: &SpanProblem, k: usize) -> bool {
    (k == 0 && p.b_start == 0.0) || (k + 1 == p.intervals() && p.b_end == 0.0)
}

/// Which row of a site a candidate is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Velocity,
    /// b at a collocation point at least half its interval's chord (see [`DIP`]).
    Dip,
    /// Axis, and the upper (`false`) or lower (`true`) limit.
    Acceleration(u8, bool),
    Jerk(u8, bool),
}

/// What a site's jerk rows `(2/3)√b̄ L/j + b/(3 b̄) ≤ 1` share ([`Program::jerk_weights`]):
/// `w` = (2/3)√b̄ B (times L/j) and `x` = B x/(3 b̄) (b = B x).
#[derive(Clone, Copy, Default)]
struct JerkFactors {
    w: f64,
    x: f64,
}

impl JerkFactors {
    /// At b̄ (> 0; none otherwise) and the site's x, with the scale B.
    fn at(scale: f64, bbar: f64, x: f64) -> JerkFactors {
        if bbar > 0.0 {
            JerkFactors {
                w: 2.0 * bbar.sqrt() * scale / 3.0,
                x: scale * x / (3.0 * bbar),
            }
        } else {
            JerkFactors::default()
        }
    }
}

/// The values at one site of the expressions its rows are built from.
#[derive(Clone, Copy, Default)]
struct SiteValues {
    x: f64,
    y: f64,
    slope: f64,
    chord: f64,
}

/// The convex subproblems of one span: everything that stays fixed from one SCP iterate to the
/// next (stations, geometry, the equalities, the cones, every candidate row's site), built once.
///
/// The inequality rows are not built until they join the active set: each is evaluated at its
/// site from three expression values (b, ü, a' there) and the site's jets, so testing all of
/// them (≈ 90k on a 1,000-interval 7-axis path) costs a few multiplications each.
struct Program<'a> {
    p: &'a SpanProblem,
    jd: &'a JerkData,
    lay: Layout,
    /// B: the median of the first linearisation point (the profile stays near it; the
    /// velocity bounds can be orders of magnitude above where jerk holds the feed down, which
    /// would leave x tiny and the solver badly scaled).
    scale: f64,
    sites: Vec<Site<'a>>,
    /// Candidate rows: site index and kind, in site order.
    cands: Vec<(u32, Kind)>,
    eq: Rows,
    /// The equalities of a tied subproblem (a' constant per interval).
    tied: Rows,
    /// The velocity bounds at the stations (always stated: they keep the LP bounded).
    lin: Rows,
    /// ü at the first and last station.
    a_ends: (f64, f64),
    soc: Rows,
    n_soc: usize,
    /// Per site: at or inside an interval next to a fresh station of a warm start (see
    /// [`ACTIVE_NEAR_FRESH`]); `None` from the reach profile.
    hot: Option<Vec<bool>>,
    /// Who solves a linear subproblem.
    lp_solver: LpSolver,
    /// Per candidate, its value's weights on its site's x, y and a' ([`Program::values`]):
    /// of the value itself (velocity, acceleration; relative to the bound), or, for a jerk
    /// row, of what the site's factors ([`JerkFactors`]) then scale.
    weights: Vec<[f64; 3]>,
}

/// What one subproblem of an SCP leaves the next: its active rows (by candidate) and its last
/// LP's solution.
#[derive(Default)]
struct Carried {
    active: Vec<bool>,
    lp: Option<WarmLp>,
}

/// The last linear subproblem's solution, kept to start the next one from (the same
/// subproblem with more rows, or the next SCP iterate's): its primal and each row's multiplier,
/// by the row's identity (equalities, velocity rows, candidates; NaN where a candidate was not
/// stated).
struct WarmLp {
    x: Vec<f64>,
    eq: Vec<f64>,
    tied: Vec<f64>,
    lin: Vec<f64>,
    cands: Vec<f64>,
}

impl WarmLp {
    fn of(
        program: &Program,
        sol: &super::banded::LpSolution,
        active: &[bool],
        tie: bool,
    ) -> WarmLp {
        let mut d = sol.duals.iter().copied();
        let eq = d.by_ref().take(program.eq.len()).collect();
        let tied = if tie {
            d.by_ref().take(program.tied.len()).collect()
        } else {
            vec![f64::NAN; program.tied.len()]
        };
        let lin = d.by_ref().take(program.lin.len()).collect();
        let cands = active
            .iter()
            .map(|&a| {
                if a {
                    d.next().unwrap_or(f64::NAN)
                } else {
                    f64::NAN
                }
            })
            .collect();
        WarmLp {
            x: sol.x.clone(),
            eq,
            tied,
            lin,
            cands,
        }
    }

    /// A start at `x` with every multiplier unknown.
    fn at(program: &Program, x: Vec<f64>) -> WarmLp {
        let unknown = |rows: usize| vec![f64::NAN; rows];
        WarmLp {
            x,
            eq: unknown(program.eq.len()),
            tied: unknown(program.tied.len()),
            lin: unknown(program.lin.len()),
            cands: unknown(program.cands.len()),
        }
    }

    /// The multipliers in the row order of a subproblem with `active` candidates.
    fn duals(&self, active: &[bool], tie: bool) -> Vec<f64> {
        let mut d = self.eq.clone();
        if tie {
            d.extend_from_slice(&self.tied);
        }
        d.extend_from_slice(&self.lin);
        d.extend(
            active
                .iter()
                .zip(&self.cands)
                .filter(|(a, _)| **a)
                .map(|(_, v)| *v),
        );
        d
    }
}

/// What Clarabel returned for one subproblem ([`Program::clarabel`]).
struct ClarabelAnswer {
    x: Vec<f64>,
    status: Status,
    iterations: u32,
    solve_time: f64,
}

impl<'a> Program<'a> {
    fn new(
        p: &'a SpanProblem,
        jd: &'a JerkData,
        bbar: &[f64],
        a_ends: (f64, f64),
        options: &JerkOptions,
        fresh: Option<&[bool]>,
    ) -> Self {
        let n = p.intervals();
        let lay = Layout {
            n,
            lp: options.objective == Objective::Linearised,
        };
        let scale = super::median_scale(bbar);
        let (rest_start, rest_end) = (p.b_start == 0.0, p.b_end == 0.0);
        let is_rest = |k: usize| is_rest_interval(p, k);
        let interior = |i: usize| i > 0 && i < n;
        let xconst = |i: usize| {
            if i == 0 {
                p.b_start / scale
            } else {
                p.b_end / scale
            }
        };
        // x_i = b_i/B and y_i = a_i/B (constants at the end stations).
        let x = |i: usize| {
            if interior(i) {
                Lin::var(lay.x(i))
            } else {
                Lin::constant(xconst(i))
            }
        };
        let y = |i: usize| {
            if interior(i) {
                Lin::var(lay.y(i))
            } else if i == 0 {
                Lin::constant(a_ends.0 / scale)
            } else {
                Lin::constant(a_ends.1 / scale)
            }
        };

        // The slopes σ⁰_k, σ¹_k (a'/B at the start and end of interval k) of the cubic law
        // ([`crate::motion::Law::Cubic`]): b is the cubic with b and b' = 2ü given at both
        // stations (Hermite): linear in x_k, x_{k+1}, y_k, y_{k+1}
        // ([`crate::motion::hermite_slope_weights`]).
        let sv = |k: usize, end: usize| {
            let w = crate::motion::hermite_slope_weights(p.du(k))[end];
            Lin::default()
                .add(&x(k), w[0])
                .add(&x(k + 1), w[1])
                .add(&y(k), w[2])
                .add(&y(k + 1), w[3])
        };
        // Equalities (zero cone): the constant-jerk ends, a_1 = 2 b_1/(3Δu_0) and
        // a_{N−1} = −2 b_{N−1}/(3Δu_{N−1}). (A tied subproblem adds
        // b_{k+1} − b_k = Δu (a_k + a_{k+1}) on every other interval: σ⁰ = σ¹.)
        let mut eq = Rows::default();
        for k in 0..n {
            let du = p.du(k);
            let e = if k == 0 && rest_start {
                y(1).add(&x(1), -2.0 / (3.0 * du))
            } else if k + 1 == n && rest_end {
                y(n - 1).add(&x(n - 1), 2.0 / (3.0 * du))
            } else {
                continue;
            };
            eq.push(&e.terms[..e.len], -e.constant);
        }
        let mut tied = Rows::default();
        for k in (0..n).filter(|&k| !is_rest(k)) {
            let du = p.du(k);
            let e = x(k + 1)
                .add(&x(k), -1.0)
                .add(&y(k), -du)
                .add(&y(k + 1), -du);
            tied.push(&e.terms[..e.len], -e.constant);
        }

        // The sites: stations (velocity in `lin`, acceleration), both ends of every quadratic
        // interval (jerk with the interval's a' and q''' on its side of a knot), collocation
        // points (all three).
        let mut lin = Rows::default();
        let mut sites = Vec::with_capacity(4 * n + jd.mid.len());
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
            sites.push(Site {
                xb: x(i),
                ya: y(i),
                slope: Lin::default(),
                chord: Lin::default(),
                jets: p.jets.view(i),
                d3: None,
                essential: p.essential[i],
                b_max: f64::INFINITY,
                lazy: false,
                at: BbarAt::Station(i),
            });
        }
        for k in (0..n).filter(|&k| !is_rest(k)) {
            let du = p.du(k);
            for (end, e, d3) in [(0, k, &jd.right[k]), (1, k + 1, &jd.left[k + 1])] {
                sites.push(Site {
                    xb: x(e),
                    ya: y(e),
                    slope: sv(k, end),
                    chord: Lin::default(),
                    jets: p.jets.view(e),
                    d3: Some(d3),
                    essential: 0,
                    b_max: f64::INFINITY,
                    lazy: false,
                    at: BbarAt::Station(e),
                });
            }
            // At x = θΔu: b(x) = b_k + 2x a_k + (x² − x³/(3Δu)) σ⁰ + (x³/(3Δu)) σ¹,
            // a(x) = a_k + (x − x²/(2Δu)) σ⁰ + (x²/(2Δu)) σ¹, a'(x) = (1 − θ) σ⁰ + θ σ¹.
            // (The interval's expressions once, not per point: with the lazy points, eleven.)
            let (xk, yk, xk1) = (x(k), y(k), x(k + 1));
            let (s0, s1) = (sv(k, 0), sv(k, 1));
            for m in &jd.mid[jd.mid_start[k]..jd.mid_start[k + 1]] {
                let (th, xx) = (m.theta, m.theta * du);
                let (w0, w1) = (xx * xx - xx.powi(3) / (3.0 * du), xx.powi(3) / (3.0 * du));
                let (v0, v1) = (xx - xx * xx / (2.0 * du), xx * xx / (2.0 * du));
                sites.push(Site {
                    xb: xk.add(&yk, 2.0 * xx).add(&s0, w0).add(&s1, w1),
                    ya: yk.add(&s0, v0).add(&s1, v1),
                    slope: Lin::default().add(&s0, 1.0 - th).add(&s1, th),
                    chord: Lin::default().add(&xk, 1.0 - th).add(&xk1, th),
                    jets: (&m.jets).into(),
                    d3: Some(&m.d3),
                    essential: m.essential,
                    b_max: m.b_max,
                    lazy: !m.eager,
                    at: BbarAt::Inside {
                        k,
                        theta: th,
                        x: xx,
                        w0,
                        w1,
                    },
                });
            }
        }
        // A site at station i or inside interval i is near a fresh station within i − 1 … i + 2.
        let hot = fresh.map(|f| {
            sites
                .iter()
                .map(|site| {
                    let i = match site.at {
                        BbarAt::Station(i) => i,
                        BbarAt::Inside { k, .. } => k,
                    };
                    f[i.saturating_sub(1)..(i + 3).min(f.len())].contains(&true)
                })
                .collect()
        });
        let mut cands = Vec::new();
        for (s, site) in sites.iter().enumerate() {
            let s = s as u32;
            if site.b_max.is_finite() {
                cands.push((s, Kind::Velocity));
            }
            if site.chord.len > 0 {
                cands.push((s, Kind::Dip));
            }
            for j in 0..p.n_axes() {
                let (dq, ddq) = (site.jets.dq[j], site.jets.ddq[j]);
                let mask = site.essential >> (2 * j);
                if dq == 0.0 && ddq == 0.0 {
                    continue;
                }
                for (bit, lower) in [(1, false), (2, true)] {
                    if mask & bit != 0 {
                        cands.push((s, Kind::Acceleration(j as u8, lower)));
                    }
                }
            }
            if let Some(d3) = site.d3 {
                for (j, lim) in jd.limits.iter().enumerate() {
                    let moves = site.jets.dq[j] != 0.0 || site.jets.ddq[j] != 0.0 || d3[j] != 0.0;
                    if lim.is_some() && moves {
                        cands.push((s, Kind::Jerk(j as u8, false)));
                        cands.push((s, Kind::Jerk(j as u8, true)));
                    }
                }
            }
        }

        let mut inv_jerk = [[0.0; 2]; MAX_AXES];
        for (inv, lim) in inv_jerk.iter_mut().zip(&jd.limits) {
            if let Some(l) = lim {
                *inv = [1.0 / l.max, 1.0 / l.min];
            }
        }
        let weights = cands
            .iter()
            .map(|&(s, kind)| {
                let site = &sites[s as usize];
                match kind {
                    Kind::Velocity => [scale / site.b_max, 0.0, 0.0],
                    Kind::Dip => [0.0; 3],
                    Kind::Acceleration(j, lower) => {
                        let j = j as usize;
                        let lim = &p.acceleration[j];
                        let a = if lower { lim.min } else { lim.max };
                        [
                            scale * site.jets.ddq[j] / a,
                            scale * site.jets.dq[j] / a,
                            0.0,
                        ]
                    }
                    Kind::Jerk(j, lower) => {
                        let j = j as usize;
                        let d3 = site.d3.expect("a jerk site has q'''");
                        let inv = inv_jerk[j][usize::from(lower)];
                        [
                            d3[j] * inv,
                            3.0 * site.jets.ddq[j] * inv,
                            site.jets.dq[j] * inv,
                        ]
                    }
                }
            })
            .collect();

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
        Program {
            p,
            jd,
            lay,
            scale,
            sites,
            cands,
            weights,
            eq,
            tied,
            lin,
            a_ends,
            soc,
            n_soc,
            hot,
            lp_solver: options.lp_solver,
        }
    }

    /// Whether candidate `c` is lazy ([`COLLOCATION`]): it joins a subproblem only where its
    /// solution breaks it (or, once one is broken, comes within [`LAZY_AT`] of its bound). A
    /// site's velocity bound never is.
    fn is_lazy(&self, c: (u32, Kind)) -> bool {
        c.1 != Kind::Velocity && self.sites[c.0 as usize].lazy
    }

    fn is_rest(&self, k: usize) -> bool {
        is_rest_interval(self.p, k)
    }

    /// b̄ at every site under the linearisation point.
    fn bbar_at_sites(
        &self,
        bbar: &[f64],
        abar: Option<&[f64]>,
        sbar: Option<&[[f64; 2]]>,
    ) -> Vec<f64> {
        self.sites
            .iter()
            .map(|s| match s.at {
                BbarAt::Station(i) => bbar[i],
                BbarAt::Inside {
                    k,
                    theta,
                    x,
                    w0,
                    w1,
                } => match abar {
                    Some(a) => {
                        let [s0, s1] = match sbar {
                            Some(sl) => sl[k],
                            None => {
                                let g = (a[k + 1] - a[k]) / self.p.du(k);
                                [g, g]
                            }
                        };
                        bbar[k] + 2.0 * a[k] * x + w0 * s0 + w1 * s1
                    }
                    None => (1.0 - theta) * bbar[k] + theta * bbar[k + 1],
                },
            })
            .collect()
    }

    /// The jerk row `(2/3)√b̄ L/j + b/(3 b̄) ≤ 1` with `L = B (q''' x + 3 q'' y + q' a'/B)`
    /// as coefficients on (x, y, a'/B).
    fn jerk_weights(&self, site: &Site, j: usize, lower: bool, bbar: f64) -> (f64, f64, f64) {
        let lim = self.jd.limits[j].expect("a jerk candidate has a limit");
        let jl = if lower { lim.min } else { lim.max };
        let d3 = site.d3.expect("a jerk site has q'''");
        let b = self.scale;
        let w = 2.0 * bbar.sqrt() * b / (3.0 * jl);
        (
            w * d3[j] + b / (3.0 * bbar),
            3.0 * w * site.jets.ddq[j],
            w * site.jets.dq[j],
        )
    }

    /// Every candidate's value at z (the site expressions, and what the jerk rows share, once
    /// per site: a square root and a division per site rather than per row; the candidates'
    /// values are 6 % of a jerk-limited solve on the COPP paths). Those `skip` marks are not
    /// evaluated (0 in `out`).
    fn values(&self, z: &[f64], bbar_sites: &[f64], skip: Option<&[bool]>, out: &mut Vec<f64>) {
        out.clear();
        let mut last = u32::MAX;
        let mut sv = SiteValues::default();
        let mut f = JerkFactors::default();
        for (r, &c) in self.cands.iter().enumerate() {
            if skip.is_some_and(|s| s[r]) {
                out.push(0.0);
                continue;
            }
            let bbar = bbar_sites[c.0 as usize];
            if c.0 != last {
                let s = &self.sites[c.0 as usize];
                sv = SiteValues {
                    x: s.xb.eval(z),
                    y: s.ya.eval(z),
                    slope: s.slope.eval(z),
                    chord: s.chord.eval(z),
                };
                f = JerkFactors::at(self.scale, bbar, sv.x);
                last = c.0;
            }
            let w = &self.weights[r];
            let l = w[0] * sv.x + w[1] * sv.y + w[2] * sv.slope;
            out.push(match c.1 {
                // jerk_weights' row, its factors common to the site's rows taken out.
                Kind::Jerk(..) => f.w * l + f.x,
                // 1 + (DIP·chord − b)/b̄: above 1 where b dips below its share of the chord.
                Kind::Dip => {
                    1.0 + (DIP * sv.chord - sv.x) * self.scale / bbar.max(f64::MIN_POSITIVE)
                }
                Kind::Velocity | Kind::Acceleration(..) => l,
            });
        }
    }

    /// Appends candidate `c` as a row `A z ≤ h` in the scaled variables: velocity
    /// `x ≤ b_max/B`; acceleration `a_min ≤ B (q'' x + q' y) ≤ a_max`; jerk
    /// `L/j ≤ (3/2)/√b̄ − b/(2 b̄^{3/2})` (the tangent of 1/√b at b̄), i.e.
    /// `(2/3)√b̄ L/j + b/(3 b̄) ≤ 1`.
    fn push_row(&self, rows: &mut Rows, c: (u32, Kind), bbar: f64) {
        let site = &self.sites[c.0 as usize];
        let b = self.scale;
        let (e, h) = match c.1 {
            Kind::Velocity => (site.xb, site.b_max / b),
            Kind::Dip => (
                Lin::default().add(&site.chord, DIP).add(&site.xb, -1.0),
                0.0,
            ),
            Kind::Acceleration(j, lower) => {
                let j = j as usize;
                let lim = &self.p.acceleration[j];
                let a = if lower { lim.min } else { lim.max };
                let e = Lin::default()
                    .add(&site.xb, b * site.jets.ddq[j] / a)
                    .add(&site.ya, b * site.jets.dq[j] / a);
                (e, 1.0)
            }
            Kind::Jerk(j, lower) => {
                let (k_x, k_y, k_s) = self.jerk_weights(site, j as usize, lower, bbar);
                let e = Lin::default()
                    .add(&site.xb, k_x)
                    .add(&site.ya, k_y)
                    .add(&site.slope, k_s);
                (e, 1.0)
            }
        };
        rows.push(&e.terms[..e.len], h - e.constant);
    }

    /// One convex subproblem, the jerk rows linearised at the profile (`bbar`, `abar`; without
    /// `abar`, the acceleration-limited reach profile, whose b̄ inside an interval is
    /// interpolated linearly). `carried`: what the previous subproblem left, updated.
    /// One subproblem by Clarabel: `all`'s first `n_eq` rows equalities, then the velocity
    /// bounds and `n_rows` active rows (non-negative cone), then the cones.
    fn clarabel(
        &self,
        all: Rows,
        n_eq: usize,
        n_rows: usize,
        q: &[f64],
        settings: &SolverSettings,
        gap: f64,
    ) -> Result<ClarabelAnswer> {
        let (m, nv) = (all.h.len(), self.lay.len());
        let a = CscMatrix::new_from_triplets(m, nv, all.i, all.j, all.v);
        let pmat = CscMatrix::zeros((nv, nv));
        let mut cones = Vec::with_capacity(2 + self.n_soc);
        cones.push(SupportedConeT::ZeroConeT(n_eq));
        if self.lin.len() + n_rows > 0 {
            cones.push(SupportedConeT::NonnegativeConeT(self.lin.len() + n_rows));
        }
        cones.extend(std::iter::repeat_n(
            SupportedConeT::SecondOrderConeT(3),
            self.n_soc,
        ));
        let s = settings.clarabel(gap)?;
        let mut solver = DefaultSolver::new(&pmat, q, &a, &all.h, &cones, s)
            .map_err(|e| Error::Solver(format!("problem setup: {e:?}")))?;
        super::run_clarabel(&mut solver);
        let sol = &mut solver.solution;
        let status = match sol.status {
            SolverStatus::Solved => Status::Optimal,
            SolverStatus::AlmostSolved => Status::AlmostOptimal,
            other => {
                return Err(Error::Solver(format!(
                    "jerk-limited subproblem: Clarabel stopped with status {other:?}"
                )));
            }
        };
        Ok(ClarabelAnswer {
            x: std::mem::take(&mut sol.x),
            status,
            iterations: sol.iterations,
            solve_time: sol.solve_time,
        })
    }

    /// The subproblem linearised at (`bbar`, `abar`, `sbar`), in the given form, solved over
    /// an active set of its rows grown until no omitted row is violated.
    ///
    /// [`Form::Provisional`]: the solution only sets the next subproblem's linearisation point
    /// (the first, tied subproblem from the reach profile): where it violates omitted rows,
    /// they join the active set for the next subproblem instead of being solved for again here,
    /// and the answer says so ([`Subsolution::holds`]).
    fn solve(
        &self,
        bbar: &[f64],
        abar: Option<&[f64]>,
        sbar: Option<&[[f64; 2]]>,
        form: Form,
        settings: &SolverSettings,
        carried: &mut Carried,
    ) -> Result<Subsolution> {
        let (tie, provisional) = (form != Form::Free, form == Form::Provisional);
        let (p, lay, scale) = (self.p, &self.lay, self.scale);
        let n = p.intervals();
        let interior = |i: usize| i > 0 && i < n;
        // b̄ no lower than B·BBAR_FLOOR (any b̄ > 0 keeps the jerk rows an inner approximation;
        // at b̄ → 0 the objective's gradient and the tangent's slope 1/(3b̄) blow up).
        let floor = BBAR_FLOOR * scale;
        let floored: Vec<f64> = bbar
            .iter()
            .enumerate()
            .map(|(i, &b)| if interior(i) { b.max(floor) } else { b })
            .collect();
        let bbar = &floored[..];
        let nv = lay.len();
        let mut q = vec![0.0; nv];
        if lay.lp {
            // The gradient of T = Σ 2Δu/(√b_k + √b_{k+1}) (3Δu/√b on a constant-jerk end) at b̄.
            let root = |i: usize| bbar[i].max(1e-300).sqrt();
            for k in 0..n {
                let du = p.du(k);
                if self.is_rest(k) {
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
                q[lay.d(k)] = if self.is_rest(k) { 3.0 } else { 2.0 } * p.du(k) / scale.sqrt();
            }
        }
        let mut bbar_sites = self.bbar_at_sites(bbar, abar, sbar);
        for b in &mut bbar_sites {
            *b = b.max(floor);
        }

        // Active set over every row but the equalities and the velocity bounds at the stations:
        // most are far from binding. Start with those within ACTIVE_AT of their bound at the
        // linearisation point (but the lazy ones, [`COLLOCATION`]) and the previous
        // subproblem's, solve, add every omitted row the solution violates (with those near
        // it), and solve again until none is: the result is the optimum of the full
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
        let mut vals = Vec::with_capacity(self.cands.len());
        self.values(&zbar, &bbar_sites, None, &mut vals);
        let keep = carried.active.len() == self.cands.len();
        let warm = &mut carried.lp;
        // A subproblem from a warm profile (abar given) without an LP solution to start from
        // starts its LP at that profile, multipliers unknown.
        if warm.is_none() && abar.is_some() {
            *warm = Some(WarmLp::at(self, zbar.clone()));
        }
        // With free slopes, b and ü at a station are independent: the stations' acceleration
        // rows (the first N − 1 sites) are always stated, as what bounds ü where no other row
        // binds it.
        let n_station_sites = (n - 1) as u32;
        let mut active: Vec<bool> = self
            .cands
            .iter()
            .enumerate()
            .map(|(r, c)| {
                (keep && carried.active[r])
                    || ((vals[r] >= ACTIVE_AT
                        || (!keep
                            && self.hot.as_ref().is_some_and(|h| h[c.0 as usize])
                            && vals[r] >= ACTIVE_NEAR_FRESH)
                        || (!tie
                            && c.0 < n_station_sites
                            && matches!(c.1, Kind::Acceleration(..))))
                        && !self.is_lazy(*c))
            })
            .collect();
        // The duality gap of a subproblem only moves the next linearisation point; 1e-5 of the
        // cycle time is a tenth of what the iteration's own stopping test resolves.
        let gap = settings.tol_gap.max(1e-5);
        let (mut iterations, mut solve_time, mut rounds) = (0, 0.0, 0);
        let (x, status, holds) = loop {
            // Sized once: appending grew it, row by row, through a few reallocations per LP.
            let tied: &[&Rows] = if tie { &[&self.tied] } else { &[] };
            let fixed = [&self.eq, &self.lin, &self.soc]
                .into_iter()
                .chain(tied.iter().copied());
            let n_active = active.iter().filter(|a| **a).count();
            let (rows, entries) = fixed.fold((n_active, 4 * n_active), |(r, e), b| {
                (r + b.len(), e + b.v.len())
            });
            let mut all = Rows::with_capacity(rows, entries);
            all.append(&self.eq);
            // `tie`: a' constant per interval (σ⁰ = σ¹, the quadratic law).
            let mut n_eq = self.eq.len();
            if tie {
                all.append(&self.tied);
                n_eq += self.tied.len();
            }
            all.append(&self.lin);
            let mut n_rows = 0;
            for (r, _) in active.iter().enumerate().filter(|(_, a)| **a) {
                let c = self.cands[r];
                self.push_row(&mut all, c, bbar_sites[c.0 as usize]);
                n_rows += 1;
            }
            all.append(&self.soc);
            // A linear subproblem is banded: the banded interior-point method first; Clarabel
            // where it does not answer (it then also tells infeasibility apart). Its gap is a
            // hundredth of Clarabel's: at Clarabel's, ü at stations on a velocity plateau (where
            // it barely moves the objective) was still 5e-5 of B from its settled value, and on
            // the bundled problem's rest end the jerk between the LP's sites, which the 1 ms
            // re-simulation checks, came out 0.2 % over its limit; two or three iterations more
            // settle it (the COPP paths: the same cycle times to 5e-7).
            let banded = if self.n_soc == 0 && self.lp_solver == LpSolver::Banded {
                let started = std::time::Instant::now();
                let duals = warm.as_ref().map(|w| w.duals(&active, tie));
                let start = warm
                    .as_ref()
                    .zip(duals.as_ref())
                    .map(|(w, d)| super::banded::WarmStart { x: &w.x, duals: d });
                // The tied subproblem starts the iteration from the reach profile, and a free
                // one follows from its solution (only where the free form fails is a tied
                // solution an iterate, still within the iteration's tolerance): its LPs stop
                // at the SCP's own gap. 2 % fewer interior-point iterations on the 20 COPP
                // paths with jerk limits (15,328 → 14,997), the same cycle times.
                let lp_gap = if tie { gap } else { 1e-2 * gap };
                let r =
                    super::banded::solve(&q, &all, n_eq, settings.tol_feas, lp_gap, start.as_ref());
                solve_time += started.elapsed().as_secs_f64();
                r.map_err(|e| tracing::debug!("  banded LP: {e:?}; Clarabel instead"))
                    .ok()
            } else {
                None
            };
            let (x_new, status, by_banded) = match banded {
                Some(sol) => {
                    iterations += sol.iterations;
                    *warm = Some(WarmLp::of(self, &sol, &active, tie));
                    (sol.x, Status::Optimal, true)
                }
                None => {
                    let sol = self.clarabel(all, n_eq, n_rows, &q, settings, gap)?;
                    iterations += sol.iterations;
                    solve_time += sol.solve_time;
                    (sol.x, sol.status, false)
                }
            };
            // Any omitted row violated: add it, and with it every omitted row near its bound
            // at this solution (the next solution is likely to lean on them too); after
            // [`ACTIVE_ROUNDS`] rounds, every row (a start far from the optimum can otherwise
            // uncover a few rows per round for many rounds).
            rounds += 1;
            // (The rows it had hold at its solution: only the others are read.)
            self.values(&x_new, &bbar_sites, Some(&active), &mut vals);
            let violated = active.iter().zip(&vals).any(|(a, &v)| !a && v > 1.0 + 1e-9);
            let every = rounds >= ACTIVE_ROUNDS;
            let mut added = 0;
            if violated {
                // (LAZY_AT is above ACTIVE_AT: a row's laziness is looked up only between.)
                for ((act, &v), &c) in active.iter_mut().zip(&vals).zip(&self.cands) {
                    let near = v > LAZY_AT || (v > ACTIVE_AT && !self.is_lazy(c));
                    if !*act && (every || near) {
                        *act = true;
                        added += 1;
                    }
                }
            }
            // A provisional answer is taken only where it is a fair point to linearise at: the
            // banded solver's (where it needed Clarabel the problem is a hard one: the bundled
            // pocket with jerk limits on one 23,758-station piece, whose first LP's answer
            // broke 36,494 rows more and stood still at a station), above no row's bound by
            // more than [`PROVISIONAL_EXCESS`].
            let plausible =
                provisional && by_banded && vals.iter().all(|&v| v <= PROVISIONAL_EXCESS);
            tracing::debug!(
                "  active rows {n_rows} of {} candidates, {added} added{}",
                self.cands.len(),
                if plausible && added > 0 {
                    " (provisional: not solved again)"
                } else {
                    ""
                }
            );
            if added == 0 || plausible {
                carried.active = active;
                break (x_new, status, added == 0);
            }
        };
        let mut b = Vec::with_capacity(n + 1);
        let mut acc = Vec::with_capacity(n + 1);
        b.push(p.b_start);
        acc.push(self.a_ends.0);
        for i in 1..n {
            b.push((x[lay.x(i)] * scale).max(0.0));
            acc.push(x[lay.y(i)] * scale);
        }
        b.push(p.b_end);
        acc.push(self.a_ends.1);
        // The slopes of the cubic law (the same weights as the rows').
        let slopes = (0..n)
            .map(|k| {
                let v = [b[k], b[k + 1], acc[k], acc[k + 1]];
                crate::motion::hermite_slope_weights(p.du(k))
                    .map(|w| w.iter().zip(&v).map(|(w, v)| w * v).sum())
            })
            .collect();
        Ok(Subsolution {
            sol: SpanSolution {
                ends: None,
                a: Some(acc),
                slopes: Some(slopes),
                b,
                status,
                iterations,
                solve_time,
                scp_iterations: 0,
            },
            holds,
        })
    }
}

/// The form of a subproblem ([`Program::solve`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Form {
    /// Both end slopes a' of every interval free.
    Free,
    /// a' constant per interval (the quadratic law).
    Tied,
    /// Tied, its answer only the next subproblem's linearisation point.
    Provisional,
}

/// A subproblem's answer ([`Program::solve`]).
struct Subsolution {
    sol: SpanSolution,
    /// Every candidate row holds at `sol`: it is an iterate of the SCP (jerk-feasible). Not so
    /// for a provisional answer that left violated rows to the next subproblem: that one is a
    /// linearisation point only.
    holds: bool,
}

#[cfg(test)]
mod tests {
    use super::{
        AT_REST, COLLOCATION, EAGER, EAGER_AT_REST, LOCAL_REACH, NEAR_REST, VELOCITY_ONLY,
        collocation, local_cuts,
    };

    /// Away from rest ends the velocity-only points are [`VELOCITY_ONLY`], each one of the
    /// interval's points; next to a rest end there are none (whatever the sets' sizes).
    #[test]
    fn velocity_only_points_are_the_regular_sets_own() {
        let n = 40;
        for k in 0..n {
            for (rs, re) in [(false, false), (true, false), (false, true), (true, true)] {
                let c = collocation(k, n, rs, re);
                assert!(c.velocity_only.iter().all(|t| c.points.contains(t)));
                assert!(c.eager.iter().all(|t| c.points.contains(t)));
                assert!(c.eager.iter().all(|t| !c.velocity_only.contains(t)));
                let near = (rs && k < NEAR_REST) || (re && k + NEAR_REST >= n);
                if near {
                    assert!(c.velocity_only.is_empty(), "k {k} ({rs}, {re})");
                    let at = (rs && k < AT_REST) || (re && k + AT_REST >= n);
                    let eager: &[f64] = if at { &EAGER_AT_REST } else { &EAGER };
                    assert_eq!(c.eager, eager, "k {k} ({rs}, {re})");
                } else {
                    assert_eq!(c.points, &COLLOCATION[..]);
                    assert_eq!(c.velocity_only, &VELOCITY_ONLY[..]);
                    assert_eq!(c.eager, &EAGER[..]);
                }
            }
        }
    }

    /// `n + 1` stations with the listed ones fresh.
    fn fresh(n: usize, at: &[usize]) -> Vec<bool> {
        (0..=n).map(|i| at.contains(&i)).collect()
    }

    #[test]
    fn local_windows_reach_past_each_run_of_fresh_stations_and_merge_when_they_meet() {
        let r = LOCAL_REACH;
        // One run in the middle: a window from r + 1 before it to r + 1 after it, the rest kept.
        assert_eq!(
            local_cuts(&fresh(200, &[100, 101])),
            vec![0, 100 - r - 1, 101 + r + 1, 200]
        );
        // Two runs closer than two reaches: one window.
        assert_eq!(
            local_cuts(&fresh(200, &[50, 60])),
            vec![0, 50 - r - 1, 60 + r + 1, 200]
        );
        // Two runs far apart: two windows, the stretch between them kept.
        assert_eq!(
            local_cuts(&fresh(300, &[50, 250])),
            vec![0, 50 - r - 1, 50 + r + 1, 250 - r - 1, 250 + r + 1, 300]
        );
        // Near the span's ends: the windows stop there.
        assert_eq!(
            local_cuts(&fresh(100, &[2, 98])),
            vec![0, 2 + r + 1, 98 - r - 1, 100]
        );
        // Nothing fresh: one window, which the solve keeps as it is.
        assert_eq!(local_cuts(&fresh(50, &[])), vec![0, 50]);
        // Every window end is a station that is not fresh (the previous profile is kept there).
        let f = fresh(400, &[10, 11, 12, 40, 90, 91, 200, 231, 399]);
        let cuts = local_cuts(&f);
        assert!(cuts.windows(2).all(|w| w[0] < w[1]));
        assert!(cuts.iter().all(|&c| c == 0 || c == 400 || !f[c]));
    }
}
