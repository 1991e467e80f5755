//! The exact O(N) reachability solver: a backward pass of controllable sets and a forward greedy
//! pass (the maximum-velocity-profile idea of TOPP-RA, Pham & Pham 2018; COPP's TOPP2-RA).
//!
//! It solves the same discretisation as [`super::clarabel`]: b = u̇² at stations, linear in u
//! between them, each axis's acceleration bounded at both ends of every interval with that
//! interval's ü = (b_{k+1} − b_k)/(2Δu_k), and every velocity limit merged into `b_k ≤ b_max_k`.
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
//! O(Δu²) (about 0.3 % at 1,000 stations on random 5-axis paths). It is therefore the fast path
//! and the cross-check of the convex solve, not its replacement.

use super::{SpanSolution, Status};
use crate::constraints::SpanProblem;

/// A line in (x, y) = (b_k, b_{k+1}): y ≤ α + βx (upper) or y ≥ α + βx (lower), from a row of
/// axis `axis` (or a station bound when `axis` is `None`).
#[derive(Debug, Clone, Copy)]
struct Line {
    alpha: f64,
    beta: f64,
    axis: Option<usize>,
}

/// The rows of one interval, sorted into upper lines, lower lines and bounds on x.
#[derive(Debug, Default)]
struct IntervalRows {
    upper: Vec<Line>,
    lower: Vec<Line>,
    /// x ≤ value / x ≥ value (rows with no b_{k+1} term).
    x_max: (f64, Option<usize>),
    x_min: (f64, Option<usize>),
}

impl IntervalRows {
    fn clear(&mut self, x_max: f64) {
        self.upper.clear();
        self.lower.clear();
        self.x_max = (x_max, None);
        self.x_min = (0.0, None);
    }

    /// Adds `cx x + cy y ≤ d` for the row of `axis`.
    fn le(&mut self, cx: f64, cy: f64, d: f64, axis: usize) {
        if cy > 0.0 {
            self.upper.push(Line {
                alpha: d / cy,
                beta: -cx / cy,
                axis: Some(axis),
            });
        } else if cy < 0.0 {
            self.lower.push(Line {
                alpha: d / cy,
                beta: -cx / cy,
                axis: Some(axis),
            });
        } else if cx > 0.0 {
            if d / cx < self.x_max.0 {
                self.x_max = (d / cx, Some(axis));
            }
        } else if cx < 0.0 && d / cx > self.x_min.0 {
            self.x_min = (d / cx, Some(axis));
        }
    }

    /// Builds interval k's rows, with b_{k+1} restricted to `[y_lo, y_hi]`.
    fn build(&mut self, p: &SpanProblem, k: usize, y_lo: f64, y_hi: f64) {
        self.clear(p.b_max[k]);
        self.upper.push(Line {
            alpha: y_hi,
            beta: 0.0,
            axis: None,
        });
        self.lower.push(Line {
            alpha: y_lo,
            beta: 0.0,
            axis: None,
        });
        let inv = 1.0 / (2.0 * p.du(k));
        for (e, at_end) in [(k, false), (k + 1, true)] {
            let jet = &p.jets[e];
            for (j, lim) in p.acceleration.iter().enumerate() {
                let rows = p.essential[e] >> (2 * j) & 3;
                if rows == 0 {
                    continue;
                }
                let (dq, ddq) = (jet.dq[j], jet.ddq[j]);
                // ddq b_e + dq (y − x)/(2Δu) as cx x + cy y.
                let (mut cx, mut cy) = (-dq * inv, dq * inv);
                if at_end {
                    cy += ddq;
                } else {
                    cx += ddq;
                }
                if rows & 1 != 0 {
                    self.le(cx, cy, lim.max, j);
                }
                if rows & 2 != 0 {
                    self.le(-cx, -cy, -lim.min, j);
                }
            }
        }
    }

    /// The x in `[x_min, x_max]` for which some y meets every row, or the pair of limits that
    /// leaves none.
    fn x_range(&self) -> Result<(f64, f64), (Option<usize>, Option<usize>)> {
        let (mut lo, mut hi) = (self.x_min, self.x_max);
        for u in &self.upper {
            for l in &self.lower {
                // u(x) − l(x) = a + s x ≥ 0
                let (a, s) = (u.alpha - l.alpha, u.beta - l.beta);
                if s > 0.0 {
                    let r = -a / s;
                    if r > lo.0 {
                        lo = (r, u.axis.or(l.axis));
                    }
                } else if s < 0.0 {
                    let r = -a / s;
                    if r < hi.0 {
                        hi = (r, u.axis.or(l.axis));
                    }
                } else if a < -1e-12 * (u.alpha.abs() + l.alpha.abs()) {
                    return Err((u.axis, l.axis));
                }
            }
        }
        let tol = 1e-12 * (hi.0.abs() + lo.0.abs()) + f64::MIN_POSITIVE;
        if lo.0 > hi.0 + tol {
            return Err((lo.1, hi.1));
        }
        Ok((lo.0.max(0.0), hi.0.max(lo.0).max(0.0)))
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

/// Where and why no schedule exists.
#[derive(Debug, Clone, PartialEq)]
pub struct Infeasible {
    /// Station index within the span where the request fails.
    pub station: usize,
    /// The axes whose limits clash there (`None`: a velocity bound or the end condition).
    pub axes: Vec<usize>,
    /// What cannot be met.
    pub what: String,
}

/// The controllable sets C_k = [lo_k, hi_k] of the backward pass.
pub fn controllable_sets(p: &SpanProblem) -> Result<Vec<(f64, f64)>, Infeasible> {
    let n = p.intervals();
    if p.b_end > p.b_max[n] * (1.0 + 1e-9) {
        return Err(Infeasible {
            station: n,
            axes: bound_axis(p, n),
            what: format!(
                "the end speed (b = {:.6e}) exceeds what the limits allow there (b ≤ {:.6e})",
                p.b_end, p.b_max[n]
            ),
        });
    }
    let mut sets = vec![(0.0, 0.0); n + 1];
    sets[n] = (p.b_end, p.b_end);
    let mut rows = IntervalRows::default();
    for k in (0..n).rev() {
        rows.build(p, k, sets[k + 1].0, sets[k + 1].1);
        sets[k] = rows.x_range().map_err(|(a, b)| Infeasible {
            station: k,
            axes: [a, b].into_iter().flatten().collect(),
            what: "no speed here can reach the end of the span within the limits".to_string(),
        })?;
    }
    Ok(sets)
}

/// Solves one span by the backward and forward passes.
pub fn solve(p: &SpanProblem) -> Result<SpanSolution, Infeasible> {
    let t0 = std::time::Instant::now();
    let sets = controllable_sets(p)?;
    let n = p.intervals();
    if p.b_start > sets[0].1 * (1.0 + 1e-9) || p.b_start < sets[0].0 * (1.0 - 1e-9) {
        let mut rows = IntervalRows::default();
        rows.build(p, 0, sets[1].0, sets[1].1);
        return Err(Infeasible {
            station: 0,
            axes: bound_axis(p, 0),
            what: format!(
                "the start speed (b = {:.6e}) is outside what can continue along the span \
                 (b in [{:.6e}, {:.6e}])",
                p.b_start, sets[0].0, sets[0].1
            ),
        });
    }
    let mut b = Vec::with_capacity(n + 1);
    b.push(p.b_start);
    let mut rows = IntervalRows::default();
    for k in 0..n {
        let (lo, hi) = sets[k + 1];
        rows.build(p, k, lo, hi);
        b.push(rows.y_max(b[k]).clamp(lo, hi));
    }
    Ok(SpanSolution {
        b,
        status: Status::Greedy,
        iterations: 0,
        solve_time: t0.elapsed().as_secs_f64(),
    })
}

/// The axis whose velocity bound gives `b_max` at station `i`, if any.
fn bound_axis(p: &SpanProblem, i: usize) -> Vec<usize> {
    use crate::constraints::Bound;
    match p.b_max_by[i] {
        Bound::AxisVelocity(j) | Bound::AxisAcceleration(j) => vec![j],
        _ => vec![],
    }
}
