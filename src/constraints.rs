//! Constraints on V²: one span's axis and feed limits as linear rows on b = u̇² at stations.
//!
//! With b = u̇² and ü = ½ db/du (constant between stations, b linear in u), every axis moves as
//! (eq. 28–39 written in u)
//!
//! - q̇ = q' u̇, so the velocity limit v_min ≤ q̇ ≤ v_max is `q'² b ≤ v²` (the side of q'),
//! - q̈ = q'' b + q' ü, so the acceleration limit is `a_min ≤ q'' b + q' ü ≤ a_max`,
//!
//! and the tool-tip feed is V = |P'| u̇, so `|P'|² b ≤ F²`. On a moving span u is close to arc
//! length and q', q'' are close to the effective tangent t_q and curvature K_q.
//!
//! Discretisation: stations u_0 … u_N at every CL knot of the span, each CL segment divided
//! evenly (the spline's q'' is linear between knots, so its extremes are at stations); the
//! velocity rows of all axes and the feed
//! are merged into the single tightest bound `b_i ≤ b_max_i`; the acceleration of every axis is
//! bounded at *both ends* of every interval with that interval's ü = (b_{k+1} − b_k)/(2Δu),
//! so the piecewise-linear b respects the limits at every station from either side.

use crate::geometry::{Span, SpanKind};
use crate::kinematics::{AxisJets, Kinematics};
use crate::machine::{Limit, Machine};

/// Which limit gives a station's velocity bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Bound {
    /// The velocity limit of axis `j`.
    AxisVelocity(usize),
    /// The acceleration limit of axis `j`.
    AxisAcceleration(usize),
    /// The programmed feed or the machine's maximum feed.
    Feed,
    /// Nothing binds (no finite bound).
    None,
}

/// The discretised problem of one span, ready for a solver.
#[derive(Debug, Clone)]
pub struct SpanProblem {
    /// Stations u_0 … u_N (every knot of the span, and even subdivisions).
    pub u: Vec<f64>,
    /// Tightest velocity bound on b at each station (`f64::INFINITY`: none).
    pub b_max: Vec<f64>,
    /// The limit that gives `b_max`.
    pub b_max_by: Vec<Bound>,
    /// |P'(u)| at each station (0 on a reorientation span).
    pub tip_speed: Vec<f64>,
    /// Axis positions and u-derivatives at each station.
    pub jets: Vec<AxisJets>,
    /// Acceleration limit of each axis.
    pub acceleration: Vec<Limit>,
    /// b at the first and last station (0: at rest).
    pub b_start: f64,
    pub b_end: f64,
}

impl SpanProblem {
    /// Discretises `span` at the stations of [`stations`].
    pub fn build(span: &Span, kin: &Kinematics, machine: &Machine, grid: Grid) -> Self {
        let u = stations(span, grid);
        let n = u.len() - 1;
        let na = kin.n_axes();
        let mut jets = Vec::with_capacity(n + 1);
        let mut tip_speed = Vec::with_capacity(n + 1);
        for &ui in &u {
            let w = span.eval(ui);
            jets.push(kin.axis_jets(&w));
            tip_speed.push(match span.kind {
                SpanKind::Moving => (w.d1[0].powi(2) + w.d1[1].powi(2) + w.d1[2].powi(2)).sqrt(),
                SpanKind::Reorientation => 0.0,
            });
        }
        let feed = station_feed_caps(span, &u);
        let mut b_max = Vec::with_capacity(n + 1);
        let mut b_max_by = Vec::with_capacity(n + 1);
        for i in 0..=n {
            let mut best = (f64::INFINITY, Bound::None);
            for (j, axis) in machine.axes.iter().enumerate().take(na) {
                let d = jets[i].dq[j];
                if d != 0.0 {
                    let v = if d > 0.0 {
                        axis.velocity.max
                    } else {
                        axis.velocity.min
                    };
                    let b = (v / d).powi(2);
                    if b < best.0 {
                        best = (b, Bound::AxisVelocity(j));
                    }
                }
            }
            if tip_speed[i] > 0.0 && feed[i].is_finite() {
                let b = (feed[i] / tip_speed[i]).powi(2);
                if b < best.0 {
                    best = (b, Bound::Feed);
                }
            }
            b_max.push(best.0);
            b_max_by.push(best.1);
        }
        SpanProblem {
            u,
            b_max,
            b_max_by,
            tip_speed,
            jets,
            acceleration: machine
                .axes
                .iter()
                .take(na)
                .map(|a| a.acceleration)
                .collect(),
            b_start: 0.0,
            b_end: 0.0,
        }
    }

    /// Number of intervals N.
    pub fn intervals(&self) -> usize {
        self.u.len() - 1
    }

    /// Number of axes.
    pub fn n_axes(&self) -> usize {
        self.acceleration.len()
    }

    /// Length Δu_k of interval k.
    pub fn du(&self, k: usize) -> f64 {
        self.u[k + 1] - self.u[k]
    }

    /// ü on interval k: (b_{k+1} − b_k) / (2Δu_k).
    pub fn path_acceleration(&self, b: &[f64], k: usize) -> f64 {
        (b[k + 1] - b[k]) / (2.0 * self.du(k))
    }

    /// Acceleration q̈ = q'' b + q' ü of axis `j` at station `i`, with interval `k`'s ü
    /// (`k` is `i − 1` or `i`).
    pub fn axis_acceleration(&self, b: &[f64], k: usize, i: usize, j: usize) -> f64 {
        self.jets[i].ddq[j] * b[i] + self.jets[i].dq[j] * self.path_acceleration(b, k)
    }
}

/// How finely to place stations on a span.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Largest distance between stations (in u).
    pub spacing: f64,
    /// Fewest intervals per CL segment.
    pub min_parts: usize,
}

/// Stations of a span: every knot, and each knot segment divided into equal parts, at least
/// `grid.min_parts` and none longer than `grid.spacing`; at least two intervals in all.
pub fn stations(span: &Span, grid: Grid) -> Vec<f64> {
    let knots = span.spline.knots();
    let min_parts = grid.min_parts.max(if knots.len() == 2 { 2 } else { 1 });
    let spacing = grid.spacing;
    let mut u = Vec::with_capacity(knots.len());
    u.push(knots[0]);
    for w in knots.windows(2) {
        let len = w[1] - w[0];
        let parts = ((len / spacing).ceil() as usize).max(min_parts);
        for p in 1..parts {
            u.push(w[0] + len * p as f64 / parts as f64);
        }
        u.push(w[1]);
    }
    u
}

/// Feed cap at each station: the lowest cap of every CL move that the station's neighbouring
/// intervals overlap, so the feed respects a lower cap ahead before reaching it.
fn station_feed_caps(span: &Span, u: &[f64]) -> Vec<f64> {
    let n = u.len() - 1;
    let seg = |x: f64| span.spline.segment(x);
    let caps = &span.feed_caps;
    (0..=n)
        .map(|i| {
            let a = seg(u[i.saturating_sub(1)]);
            let b = seg(u[(i + 1).min(n)]).max(a);
            caps[a..=b.min(caps.len() - 1)]
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}
