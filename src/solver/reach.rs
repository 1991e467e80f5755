//! The exact O(N) reachability solver: a backward pass of controllable sets and a forward greedy
//! pass (the maximum-velocity-profile idea of TOPP-RA, Pham & Pham 2018; COPP's TOPP2-RA).
//!
//! It solves the same discretisation as [`super::clarabel`]: b = u̇² at stations, each axis's
//! acceleration bounded at both ends of every interval (under the problem's
//! [`Ramp`](crate::constraints::Ramp): with that interval's one ü, or with ü linear between its
//! ends and the ends' ü eliminated, [`SpanProblem::interval_rows`]), and every velocity limit
//! merged into `b_k ≤ b_max_k`.
//!
//! On interval k every row is linear in (x, y) = (b_k, b_{k+1}). Solved for y, a row is a line
//! y ≤ α + βx (an *upper* line) or y ≥ α + βx (a *lower* line), or a bound on x alone. Some y
//! exists for a given x iff every lower line lies below every upper line there; each (upper,
//! lower) pair is one linear inequality in x, so the x that can continue form an interval found
//! in O(pairs) arithmetic, without sorting or an LP:
//!
//! - backward pass: the controllable set C_k = {b_k : some b_{k+1} ∈ C_{k+1} meets interval k's
//!   rows}, from C_N = {b_end};
//! - forward pass: from b_0 = b_start, take the largest b_{k+1} ∈ C_{k+1} that interval k's rows
//!   allow.
//!
//! The profile is pointwise maximal among the feasible ones of the discretisation when the rows
//! keep the feasible set a lattice; where a row puts same-sign coefficients on b_k and b_{k+1}
//! it is not, and the profile can be slower than the true optimum of the same discretisation by
//! O(Δu²): measured at most 1.2e-4 on the 20 COPP paths and 7.9e-5 on 1,000 random paths at
//! 1,000 stations (the issue quotes up to 0.3 % on coarser grids). It is therefore the fast
//! path and the cross-check of the convex solve, not its replacement.

use super::{SpanSolution, Status};
use crate::constraints::{Bound, LineCache, SpanProblem};

/// A line in (x, y) = (b_k, b_{k+1}): y ≤ α + βx (upper) or y ≥ α + βx (lower), and the limit
/// it comes from.
#[derive(Debug, Clone, Copy)]
struct Line {
    alpha: f64,
    beta: f64,
    src: Bound,
}

/// The rows of one interval, sorted into upper lines, lower lines and bounds on x.
#[derive(Debug, Default)]
struct IntervalRows {
    upper: Vec<Line>,
    lower: Vec<Line>,
    /// x ≤ value / x ≥ value (rows with no b_{k+1} term), and the limit each comes from.
    x_max: (f64, Bound),
    x_min: (f64, Bound),
    /// The stations' bounds on ü (one problem's: an `IntervalRows` serves one pass).
    cache: LineCache,
}

impl IntervalRows {
    /// Adds `cx x + cy y ≤ d` for a row of axis `axis`'s acceleration.
    fn le(&mut self, cx: f64, cy: f64, d: f64, axis: usize) {
        let src = Bound::AxisAcceleration(axis);
        let line = Line {
            alpha: d / cy,
            beta: -cx / cy,
            src,
        };
        if cy > 0.0 {
            self.upper.push(line);
        } else if cy < 0.0 {
            self.lower.push(line);
        } else if cx > 0.0 {
            if d / cx < self.x_max.0 {
                self.x_max = (d / cx, src);
            }
        } else if cx < 0.0 && d / cx > self.x_min.0 {
            self.x_min = (d / cx, src);
        }
    }

    /// Builds interval k's rows ([`SpanProblem::interval_rows`]), with b_{k+1} restricted to
    /// the set `next`; with `lattice_only`, without the rows that are not max-closed (see
    /// [`is_lattice_row`]).
    fn build(&mut self, p: &SpanProblem, k: usize, next: &Set, lattice_only: bool) {
        self.upper.clear();
        self.lower.clear();
        self.x_max = (p.b_max[k], p.b_max_by[k]);
        self.x_min = (0.0, Bound::None);
        self.upper.push(Line {
            alpha: next.hi,
            beta: 0.0,
            src: next.hi_by,
        });
        self.lower.push(Line {
            alpha: next.lo,
            beta: 0.0,
            src: next.lo_by,
        });
        let mut cache = std::mem::take(&mut self.cache);
        p.interval_rows(k, &mut cache, |r| {
            if lattice_only && !is_lattice_row(r.cx, r.cy) {
                return;
            }
            let axis = r.limits[0].map_or(0, |l| l.0);
            self.le(r.cx, r.cy, r.d, axis);
        });
        self.cache = cache;
    }

    /// The x in `[x_min, x_max]` for which some y meets every row (with the limits that set
    /// its ends), or the limits that leave none.
    fn x_range(&self) -> Result<Set, Vec<Bound>> {
        // Of the two lines that meet, the acceleration row is the limit worth naming.
        let pick = |u: &Line, l: &Line| match u.src {
            Bound::AxisAcceleration(_) => u.src,
            _ => l.src,
        };
        let (mut lo, mut hi) = (self.x_min, self.x_max);
        for u in &self.upper {
            for l in &self.lower {
                // u(x) − l(x) = a + s x ≥ 0
                let (a, s) = (u.alpha - l.alpha, u.beta - l.beta);
                if s > 0.0 {
                    let r = -a / s;
                    if r > lo.0 {
                        lo = (r, pick(u, l));
                    }
                } else if s < 0.0 {
                    let r = -a / s;
                    if r < hi.0 {
                        hi = (r, pick(u, l));
                    }
                } else if a < -1e-12 * (u.alpha.abs() + l.alpha.abs()) {
                    return Err(vec![u.src, l.src]);
                }
            }
        }
        let tol = 1e-12 * (hi.0.abs() + lo.0.abs()) + f64::MIN_POSITIVE;
        if lo.0 > hi.0 + tol {
            return Err(vec![lo.1, hi.1]);
        }
        Ok(Set {
            lo: lo.0.max(0.0),
            hi: hi.0.max(lo.0).max(0.0),
            lo_by: lo.1,
            hi_by: hi.1,
        })
    }

    /// The largest y allowed at `x`.
    fn y_max(&self, x: f64) -> f64 {
        let up = self
            .upper
            .iter()
            .map(|l| l.alpha + l.beta * x)
            .fold(f64::INFINITY, f64::min);
        let lo = self
            .lower
            .iter()
            .map(|l| l.alpha + l.beta * x)
            .fold(0.0, f64::max);
        up.max(lo)
    }
}

/// A controllable set [lo, hi] of b at one station, and the limits that set its ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Set {
    /// The least b reachable at the station.
    pub lo: f64,
    /// The greatest b at the station from which the span can still be completed.
    pub hi: f64,
    /// The limit that sets `lo`.
    pub lo_by: Bound,
    /// The limit that sets `hi`.
    pub hi_by: Bound,
}

/// Where and why no schedule exists.
#[derive(Debug, Clone, PartialEq)]
pub struct Infeasible {
    /// Station index within the span where the request fails.
    pub station: usize,
    /// The limits that clash there (an axis's velocity or acceleration, or the feed cap).
    pub binding: Vec<Bound>,
    /// What cannot be met, in the user's units.
    pub what: String,
}

/// b at station `i` as a speed a person reads: the feed in mm/s where the tool tip moves, the
/// path speed du/dt elsewhere.
fn speed(p: &SpanProblem, i: usize, b: f64) -> String {
    let v = b.max(0.0).sqrt();
    if p.tip_speed[i] > 0.0 {
        format!("{:.3} mm/s", v * p.tip_speed[i])
    } else {
        format!("a path speed of {v:.6} per second")
    }
}

/// Whether the row `cx b_k + cy b_{k+1} ≤ d` (or `≥ d`) keeps the feasible set closed under
/// the componentwise maximum: its two coefficients must not have the same sign (Topkis,
/// Veinott). If every row of a problem is such, the feasible profiles form a lattice, its
/// largest element exists, and because the time decreases in every b it is the optimum.
pub fn is_lattice_row(cx: f64, cy: f64) -> bool {
    cx * cy <= 0.0
}

/// The controllable sets C_k = [lo_k, hi_k] of the backward pass.
pub fn controllable_sets(p: &SpanProblem) -> Result<Vec<Set>, Infeasible> {
    sets_of(p, false)
}

fn sets_of(p: &SpanProblem, lattice_only: bool) -> Result<Vec<Set>, Infeasible> {
    let n = p.intervals();
    if p.b_end > p.b_max[n] * (1.0 + 1e-9) {
        return Err(Infeasible {
            station: n,
            binding: vec![p.b_max_by[n]],
            what: format!(
                "the end feed ({}) is more than the limits allow there ({})",
                speed(p, n, p.b_end),
                speed(p, n, p.b_max[n])
            ),
        });
    }
    let end = Set {
        lo: p.b_end,
        hi: p.b_end,
        lo_by: Bound::None,
        hi_by: Bound::None,
    };
    let mut sets = vec![end; n + 1];
    let mut rows = IntervalRows::default();
    for k in (0..n).rev() {
        rows.build(p, k, &sets[k + 1], lattice_only);
        sets[k] = rows.x_range().map_err(|binding| Infeasible {
            station: k,
            binding,
            what: "no speed here can reach the end of the span within the limits".to_string(),
        })?;
    }
    Ok(sets)
}

/// Solves one span by the backward and forward passes.
pub fn solve(p: &SpanProblem) -> Result<SpanSolution, Infeasible> {
    passes(p, false)
}

/// The largest profile of the *lattice relaxation*: every row that is not max-closed
/// ([`is_lattice_row`]) left out. The relaxation's feasible set contains the problem's, so this
/// profile is at least as fast as any feasible one; where it also meets the rows left out
/// ([`lattice_violations`] finds none) it is the exact optimum of the discretisation. Errors
/// as [`solve`] (a relaxation infeasible means the problem is too).
pub fn solve_lattice(p: &SpanProblem) -> Result<SpanSolution, Infeasible> {
    passes(p, true)
}

/// The intervals (sorted) where profile `b` breaks one of the rows [`solve_lattice`] leaves
/// out by more than a relative `tol` of its limit.
pub fn lattice_violations(p: &SpanProblem, b: &[f64], tol: f64) -> Vec<usize> {
    let mut out = Vec::new();
    let mut cache = LineCache::default();
    for k in 0..p.intervals() {
        let mut broken = false;
        p.interval_rows(k, &mut cache, |r| {
            broken |=
                !is_lattice_row(r.cx, r.cy) && r.cx * b[k] + r.cy * b[k + 1] > r.d + tol * r.scale;
        });
        if broken {
            out.push(k);
        }
    }
    out
}

fn passes(p: &SpanProblem, lattice_only: bool) -> Result<SpanSolution, Infeasible> {
    let t0 = std::time::Instant::now();
    let sets = sets_of(p, lattice_only)?;
    let n = p.intervals();
    let c0 = sets[0];
    if p.b_start > c0.hi * (1.0 + 1e-9) {
        return Err(Infeasible {
            station: 0,
            binding: vec![c0.hi_by],
            what: format!(
                "the start feed ({}) is too fast to go on within the limits (at most {})",
                speed(p, 0, p.b_start),
                speed(p, 0, c0.hi)
            ),
        });
    }
    if p.b_start < c0.lo * (1.0 - 1e-9) {
        return Err(Infeasible {
            station: 0,
            binding: vec![c0.lo_by],
            what: format!(
                "the end feed ({}) cannot be reached within the limits: it needs at least {} \
                 at the start",
                speed(p, n, p.b_end),
                speed(p, 0, c0.lo)
            ),
        });
    }
    let mut b = Vec::with_capacity(n + 1);
    b.push(p.b_start);
    let mut rows = IntervalRows::default();
    for k in 0..n {
        let next = sets[k + 1];
        rows.build(p, k, &next, lattice_only);
        b.push(rows.y_max(b[k]).clamp(next.lo, next.hi));
    }
    Ok(SpanSolution::acceleration_limited(
        p,
        b,
        Status::Greedy,
        0,
        t0.elapsed().as_secs_f64(),
    ))
}
