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
use crate::motion::Interval;
use crate::solver::{SpanSolution, interval_times};

/// One station of the schedule (its axes' motion: [`Schedule::q`], [`Schedule::qd`],
/// [`Schedule::qdd`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Station {
    /// Index of the span (rest-to-rest piece) the station belongs to.
    pub span: usize,
    /// Path parameter within the span (mm of chord, in joint space on a four-axis machine,
    /// or radians on a reorientation span).
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
}

/// The time-optimal motion along the whole path.
///
/// The axes' positions, velocities and accelerations are kept per station for the machine's
/// axes only (a station of a 3-axis machine takes 48 + 72 bytes, where arrays of every
/// possible axis took 240).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Schedule {
    /// Names of the axes, in the order of [`Schedule::q`].
    pub axes: Vec<String>,
    /// Every station of every span, in path order.
    pub stations: Vec<Station>,
    /// Total time, s.
    pub cycle_time: f64,
    /// Per station, per axis: q, q̇ = q' u̇ and q̈ = q'' b + q' ü.
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
}

/// ü at station `i` (on the interval that starts there; the last station: the one ending
/// there), under the profile's law.
pub fn station_udd(problem: &SpanProblem, sol: &SpanSolution, i: usize) -> f64 {
    match &sol.a {
        Some(a) => a[i],
        None => {
            let k = i.min(problem.intervals() - 1);
            problem.path_acceleration(&sol.b, sol.ends.as_deref(), k, i)
        }
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
        let total: usize = problems.iter().map(|p| p.u.len()).sum();
        let mut stations = Vec::with_capacity(total);
        let (mut q, mut qd, mut qdd) = (
            Vec::with_capacity(na * total),
            Vec::with_capacity(na * total),
            Vec::with_capacity(na * total),
        );
        let (mut t0, mut s0) = (0.0, 0.0);
        for (si, ((span, p), sol)) in spans.iter().zip(problems).zip(solutions).enumerate() {
            let b = &sol.b;
            let dt = interval_times(p, sol)?;
            let n = p.intervals();
            let (mut t, mut s) = (t0, s0);
            for i in 0..=n {
                let udd = station_udd(p, sol, i);
                let ud = b[i].sqrt();
                let jet = p.jets.view(i);
                let w = span.eval(p.u[i]);
                let speed = p.tip_speed[i];
                let along = if speed > 0.0 {
                    (w.d1[0] * w.d2[0] + w.d1[1] * w.d2[1] + w.d1[2] * w.d2[2]) / speed
                } else {
                    0.0
                };
                let joint = span.kind == crate::geometry::SpanKind::Joint;
                let st = Station {
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
                };
                for j in 0..na {
                    q.push(jet.q[j]);
                    qd.push(jet.dq[j] * ud);
                    qdd.push(jet.ddq[j] * b[i] + jet.dq[j] * udd);
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
            q,
            qd,
            qdd,
        })
    }

    fn at(&self, i: usize) -> std::ops::Range<usize> {
        let na = self.axes.len();
        i * na..(i + 1) * na
    }

    /// Axis positions at station `i` (mm or degrees), in the order of [`Schedule::axes`].
    pub fn q(&self, i: usize) -> &[f64] {
        &self.q[self.at(i)]
    }

    /// Axis velocities q̇ = q' u̇ at station `i`.
    pub fn qd(&self, i: usize) -> &[f64] {
        &self.qd[self.at(i)]
    }

    /// Axis accelerations q̈ = q'' b + q' ü at station `i` (of the interval that starts there).
    pub fn qdd(&self, i: usize) -> &[f64] {
        &self.qdd[self.at(i)]
    }
}

/// The schedule's motion as intervals, span by span, with each interval's start time and the
/// station's arc length there: what the sampler and the G-code writer walk along.
#[derive(Debug, Clone)]
pub struct Timeline {
    /// Per span: its stations' u, start times t (s) and arc lengths s, and b.
    pub spans: Vec<SpanTimeline>,
    /// The schedule's cycle time, s.
    pub cycle_time: f64,
}

/// One span's stations on the global clock.
#[derive(Debug, Clone)]
pub struct SpanTimeline {
    /// The stations' u.
    pub u: Vec<f64>,
    /// b = u̇² at the stations.
    pub b: Vec<f64>,
    /// ü at the stations of a jerk-limited profile.
    pub a: Option<Vec<f64>>,
    /// a' at both ends of every interval of a jerk-limited profile with quadratic ü
    /// ([`crate::motion::Law::Cubic`]).
    pub slopes: Option<Vec<[f64; 2]>>,
    /// ü at both ends of every interval of an acceleration-limited profile with linear ü
    /// ([`crate::solver::SpanSolution::ends`]).
    pub ends: Option<Vec<[f64; 2]>>,
    /// Time at each station, s (the schedule's).
    pub t: Vec<f64>,
    /// Arc length at each station, mm (the schedule's).
    pub s: Vec<f64>,
}

impl SpanTimeline {
    /// Interval `i` (stations i, i + 1).
    pub fn interval(&self, i: usize) -> Interval {
        let shape = crate::motion::Shape {
            a: self.a.as_deref(),
            slopes: self.slopes.as_deref(),
            ends: self.ends.as_deref(),
        };
        Interval::of(&self.u, &self.b, shape, i)
    }

    /// The interval containing `u` (the last one at the span's end).
    pub fn interval_of(&self, u: f64) -> usize {
        let n = self.u.len() - 1;
        self.u
            .partition_point(|&x| x <= u)
            .saturating_sub(1)
            .min(n - 1)
    }

    /// The time (s, global clock) at which the motion passes `u` on this span.
    pub fn time_at(&self, u: f64) -> f64 {
        let i = self.interval_of(u);
        let dt = self.t[i + 1] - self.t[i];
        self.t[i]
            + self
                .interval(i)
                .time_to_x(u - self.u[i])
                .unwrap_or(dt)
                .min(dt)
    }
}

impl Timeline {
    /// The timeline of `schedule`, built from the span `problems` and their `solutions`.
    /// Station times are the schedule's own.
    pub fn new(
        schedule: &Schedule,
        problems: &[SpanProblem],
        solutions: &[SpanSolution],
    ) -> Result<Timeline> {
        let stations = &schedule.stations;
        let mut spans = Vec::with_capacity(problems.len());
        let mut offset = 0;
        for (p, sol) in problems.iter().zip(solutions) {
            let n = p.u.len();
            if sol.b.len() != n || offset + n > stations.len() || n < 2 {
                return Err(Error::Solver(format!(
                    "the schedule does not match its span problems ({} stations, span of {n})",
                    stations.len()
                )));
            }
            // Checks that the schedule's intervals are traversable (never zero speed).
            interval_times(p, sol)?;
            let st = &stations[offset..offset + n];
            spans.push(SpanTimeline {
                u: p.u.clone(),
                b: sol.b.clone(),
                a: sol.a.clone(),
                slopes: sol.slopes.clone(),
                ends: sol.ends.clone(),
                t: st.iter().map(|s| s.t).collect(),
                s: st.iter().map(|s| s.s).collect(),
            });
            offset += n;
        }
        Ok(Timeline {
            spans,
            cycle_time: schedule.cycle_time,
        })
    }
}
