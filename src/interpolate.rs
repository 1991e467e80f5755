//! Data-sampling interpolation (seed 004): the schedule turned into every axis's setpoint at a
//! fixed interpolation period T, what a controller's servo loops consume.
//!
//! # Motion between stations
//!
//! The schedule fixes b = u̇² at its stations (and ü, for a jerk-limited profile); between
//! them the motion follows the laws of [`crate::motion`] — for an acceleration-limited profile
//! b linear in u, ü constant (eq. 40–43) — through [`Interval::at`](crate::motion::Interval::at) (and its inverse,
//! [`Interval::time_to_x`](crate::motion::Interval::time_to_x), for the G-code writer): exactly the motion [`crate::verify`]
//! re-simulates.
//!
//! # Samples
//!
//! [`sample`] gives one [`Sample`] at every t = kT from 0 while kT is before the cycle time,
//! and one at the cycle time itself (so the last period may be shorter). At each sample the
//! path is evaluated from the span's spline at u(t) and pushed through the kinematics — never
//! interpolated between stations: q, and the analytic q̇ = q′ u̇, q̈ = q″ b + q′ ü. The arc length
//! s is the interval's start station's s plus Simpson's rule on |P′| over [u_i, u]; the feed
//! is |P′| u̇ (on a joint-space path u is s itself: s = u, feed = u̇).
//!
//! # Files
//!
//! The setpoints are written as CSV or in a compact binary layout by
//! [`crate::writers::setpoints`].

use crate::error::{Error, Result};
use crate::geometry::{Span, SpanKind};
use crate::kinematics::{Kinematics, MAX_AXES};
use crate::machine::{AxisKind, Machine};
use crate::motion::State;
use crate::optimize::Solution;
use crate::schedule::{SpanTimeline, Timeline};

/// One setpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// Tool-tip arc length from the start, mm (joint-space path: its parameter s).
    pub s: f64,
    /// Tool-tip feed, mm/s (joint-space path: ds/dt).
    pub feed: f64,
    /// Axis positions, mm or degrees (the machine's axis order; unused entries 0).
    pub q: [f64; MAX_AXES],
    /// Axis velocities q̇ = q′ u̇ (analytic; not written to the files).
    pub qd: [f64; MAX_AXES],
    /// Axis accelerations q̈ = q″ b + q′ ü (analytic; not written to the files).
    pub qdd: [f64; MAX_AXES],
}

/// Setpoints at a fixed period.
#[derive(Debug, Clone, PartialEq)]
pub struct Setpoints {
    /// Axis names in the order of [`Sample::q`].
    pub axes: Vec<String>,
    /// Unit of each axis: linear (mm) or rotary (degrees).
    pub kinds: Vec<AxisKind>,
    /// A joint-space path: s and feed are in the path's own units.
    pub joint: bool,
    /// Interpolation period T, s.
    pub period: f64,
    /// The setpoints, at t = 0, T, 2T, … and at the cycle time.
    pub samples: Vec<Sample>,
}

/// The most setpoints [`sample`] takes (216 bytes each in memory, about 1 GB; 66 minutes of
/// motion at 1 ms), checked before sampling.
pub const MAX_SAMPLES: usize = 4_000_000;

/// Samples the solution's motion at period `period` (s): see the module doc.
pub fn sample(machine: &Machine, solution: &Solution, period: f64) -> Result<Setpoints> {
    crate::validate::period("period", period)?;
    let timeline = Timeline::new(&solution.schedule, &solution.problems, &solution.solutions)?;
    let cycle = timeline.cycle_time;
    let count = (cycle / period).ceil();
    if !(count.is_finite() && count < MAX_SAMPLES as f64) {
        return Err(Error::Usage(format!(
            "the schedule takes {} s: at a period of {} s that is more than {MAX_SAMPLES} \
             setpoints (about 1 GB): give a period of at least {} s",
            crate::error::number(cycle),
            crate::error::number(period),
            crate::error::number(cycle / MAX_SAMPLES as f64)
        )));
    }
    let kin = &solution.kinematics;
    let na = kin.n_axes().min(machine.axes.len());
    let spans = &solution.path.spans;
    let mut samples = Vec::with_capacity(count as usize + 2);
    let mut k: u64 = 0;
    for (span, tl) in spans.iter().zip(&timeline.spans) {
        for i in 0..tl.u.len() - 1 {
            let iv = tl.interval(i);
            let t_end = tl.t[i + 1];
            let dur = t_end - tl.t[i];
            loop {
                let t = k as f64 * period;
                if t >= t_end {
                    break;
                }
                samples.push(point(span, kin, na, tl, i, iv.at(t - tl.t[i], dur), t));
                k += 1;
            }
        }
    }
    // The final instant: the end of the last span.
    if let (Some(span), Some(tl)) = (spans.last(), timeline.spans.last()) {
        let i = tl.u.len() - 2;
        let st = tl.interval(i).ends().1;
        samples.push(point(span, kin, na, tl, i, st, cycle));
    }
    if let Some(bad) = samples.iter().find(|s| {
        !(s.t.is_finite() && s.s.is_finite() && s.feed.is_finite())
            || s.q[..na].iter().any(|x| !x.is_finite())
    }) {
        return Err(Error::Solver(format!(
            "the setpoint at t = {} s is not finite",
            bad.t
        )));
    }
    Ok(Setpoints {
        axes: machine
            .axes
            .iter()
            .take(na)
            .map(|a| a.name.clone())
            .collect(),
        kinds: machine.axes.iter().take(na).map(|a| a.kind).collect(),
        joint: spans.iter().any(|s| s.kind == SpanKind::Joint),
        period,
        samples,
    })
}

/// The setpoint at state `st` within interval `i` of a span.
fn point(
    span: &Span,
    kin: &Kinematics,
    na: usize,
    tl: &SpanTimeline,
    i: usize,
    st: State,
    t: f64,
) -> Sample {
    let u = (tl.u[i] + st.x).min(tl.u[i + 1]);
    let w = span.eval(u);
    let jets = kin.axis_jets(&w);
    let tip = |u: f64| {
        let d = span.eval(u).d1;
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    };
    let (s, feed) = match span.kind {
        SpanKind::Joint => (tl.s[i] + (u - tl.u[i]), st.ud),
        SpanKind::Reorientation => (tl.s[i], 0.0),
        SpanKind::Moving => {
            let (ua, du) = (tl.u[i], u - tl.u[i]);
            let s = if du > 0.0 {
                du / 6.0 * (tip(ua) + 4.0 * tip(ua + 0.5 * du) + tip(u))
            } else {
                0.0
            };
            (tl.s[i] + s, tip(u) * st.ud)
        }
    };
    let mut out = Sample {
        t,
        s,
        feed,
        q: [0.0; MAX_AXES],
        qd: [0.0; MAX_AXES],
        qdd: [0.0; MAX_AXES],
    };
    for j in 0..na {
        out.q[j] = jets.q[j];
        out.qd[j] = jets.dq[j] * st.ud;
        out.qdd[j] = jets.ddq[j] * st.ud * st.ud + jets.dq[j] * st.udd;
    }
    out
}
