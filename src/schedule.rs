//! Schedule: the optimal b = u̇² turned into time (seed 000, eq. 40–43) and into every axis's
//! motion at every station.
//!
//! Between stations the motion follows the profile's law ([`crate::motion`]): for an
//! acceleration-limited profile b is linear in u, so ü is constant there (the paper's "A
//! constant between stations"), and eq. 43 integrates in closed form:
//!
//! `t_{k+1} − t_k = ∫ du / √b(u) = 2 Δu_k / (√b_k + √b_{k+1})`;
//!
//! for a jerk-limited one ü is continuous and piecewise linear in u (issue 6).

use crate::constraints::SpanProblem;
use crate::error::{Error, Result};
use crate::geometry::Span;
use crate::kinematics::MAX_AXES;
use crate::motion::Interval;
use crate::solver::SpanSolution;

/// One station of the schedule.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Station {
    /// Index of the span (rest-to-rest piece) the station belongs to.
    pub span: usize,
    /// Path parameter within the span (mm of chord, or radians on a reorientation span).
    pub u: f64,
    /// Tool-tip arc length from the start of the path, mm (for a joint-space path: its
    /// parameter s).
    pub s: f64,
    /// Time from the start of the path, s.
    pub t: f64,
    /// Tool-tip feed V = |P'| u̇, mm/s (joint-space path: the path speed ds/dt).
    pub v: f64,
    /// Tangential acceleration A = dV/dt, mm/s² (of the interval that starts here; joint-space
    /// path: d²s/dt²).
    pub a: f64,
    /// Axis positions (mm or degrees).
    pub q: [f64; MAX_AXES],
    /// Axis velocities q̇ = q' u̇.
    pub qd: [f64; MAX_AXES],
    /// Axis accelerations q̈ = q'' b + q' ü (of the interval that starts here).
    pub qdd: [f64; MAX_AXES],
}

/// The time-optimal motion along the whole path.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Schedule {
    /// Names of the axes, in the order of `Station::q`.
    pub axes: Vec<String>,
    /// Every station of every span, in path order.
    pub stations: Vec<Station>,
    /// Total time, s.
    pub cycle_time: f64,
}

/// Time taken by each interval of one span (eq. 43 under the profile's law, see
/// [`crate::motion`]).
pub fn interval_times(problem: &SpanProblem, sol: &SpanSolution) -> Result<Vec<f64>> {
    (0..problem.intervals())
        .map(|k| {
            Interval::of(&problem.u, &sol.b, sol.a.as_deref(), k)
                .duration()
                .map_err(|_| {
                    Error::Infeasible(format!(
                        "the feed is zero on a whole interval (station {k}): the path cannot be \
                         traversed"
                    ))
                })
        })
        .collect()
}

/// ü at station `i` (on the interval that starts there; the last station: the one ending
/// there), under the profile's law.
pub fn station_udd(problem: &SpanProblem, sol: &SpanSolution, i: usize) -> f64 {
    match &sol.a {
        Some(a) => a[i],
        None => problem.path_acceleration(&sol.b, i.min(problem.intervals() - 1)),
    }
}

impl Schedule {
    /// Assembles the schedule of every span, in order.
    pub fn build(
        axes: &[String],
        spans: &[Span],
        problems: &[SpanProblem],
        solutions: &[SpanSolution],
    ) -> Result<Schedule> {
        let na = axes.len();
        let mut stations = Vec::with_capacity(problems.iter().map(|p| p.u.len()).sum());
        let (mut t0, mut s0) = (0.0, 0.0);
        for (si, ((span, p), sol)) in spans.iter().zip(problems).zip(solutions).enumerate() {
            let b = &sol.b;
            let dt = interval_times(p, sol)?;
            let n = p.intervals();
            let (mut t, mut s) = (t0, s0);
            for i in 0..=n {
                let udd = station_udd(p, sol, i);
                let ud = b[i].sqrt();
                let jet = &p.jets[i];
                let w = span.eval(p.u[i]);
                let speed = p.tip_speed[i];
                let along = if speed > 0.0 {
                    (w.d1[0] * w.d2[0] + w.d1[1] * w.d2[1] + w.d1[2] * w.d2[2]) / speed
                } else {
                    0.0
                };
                let joint = span.kind == crate::geometry::SpanKind::Joint;
                let mut st = Station {
                    span: si,
                    u: p.u[i],
                    s,
                    t,
                    v: if joint { ud } else { speed * ud },
                    a: if joint {
                        udd
                    } else {
                        along * b[i] + speed * udd
                    },
                    q: [0.0; MAX_AXES],
                    qd: [0.0; MAX_AXES],
                    qdd: [0.0; MAX_AXES],
                };
                for j in 0..na {
                    st.q[j] = jet.q[j];
                    st.qd[j] = jet.dq[j] * ud;
                    st.qdd[j] = jet.ddq[j] * b[i] + jet.dq[j] * udd;
                }
                stations.push(st);
                if i < n {
                    t += dt[i];
                    // Arc length by Simpson's rule on |P'(u)|.
                    let du = p.du(i);
                    if span.kind == crate::geometry::SpanKind::Joint {
                        s += du; // a joint path's s is its own parameter
                    } else if speed > 0.0 || p.tip_speed[i + 1] > 0.0 {
                        let mid = span.eval(p.u[i] + 0.5 * du);
                        let sm = (mid.d1[0].powi(2) + mid.d1[1].powi(2) + mid.d1[2].powi(2)).sqrt();
                        s += du / 6.0 * (speed + 4.0 * sm + p.tip_speed[i + 1]);
                    }
                }
            }
            t0 = t;
            s0 = s;
        }
        Ok(Schedule {
            axes: axes.to_vec(),
            stations,
            cycle_time: t0,
        })
    }
}
