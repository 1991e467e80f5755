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
//! and one at the cycle time itself (so the last period may be shorter). The program's dwells
//! ([`crate::geometry::Path::holds`]) are part of the time: where the tool dwells between two
//! spans, the setpoints hold its position, at rest, for the dwell's duration, and the cycle
//! time counts them, as `solve` reports it. At each sample the
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

/// The most setpoints [`sample`] or [`for_each`] takes, checked before sampling: 11 hours of
/// motion at 1 ms. [`for_each`] keeps one setpoint at a time (`feedopt interpolate` writes
/// them as they come: a binary file of 8 (3 + n) bytes a setpoint, 2.6 GB for 5 axes at the
/// limit); [`sample`] keeps them all (216 bytes each).
pub const MAX_SAMPLES: usize = 40_000_000;

/// What the setpoints of [`for_each`] are: their axes and how many there are.
#[derive(Debug, Clone, PartialEq)]
pub struct SetpointsHeader {
    /// Axis names in the order of [`Sample::q`].
    pub axes: Vec<String>,
    /// Unit of each axis: linear (mm) or rotary (degrees).
    pub kinds: Vec<AxisKind>,
    /// A joint-space path: s and feed are in the path's own units.
    pub joint: bool,
    /// Interpolation period T, s.
    pub period: f64,
    /// How many setpoints there are.
    pub count: usize,
}

/// Samples the solution's motion at period `period` (s), all setpoints at once: see the module
/// doc and [`for_each`].
pub fn sample(machine: &Machine, solution: &Solution, period: f64) -> Result<Setpoints> {
    let samples = std::cell::RefCell::new(Vec::new());
    let h = for_each(
        machine,
        solution,
        period,
        |head| {
            samples.borrow_mut().reserve_exact(head.count);
            Ok(())
        },
        |s| {
            samples.borrow_mut().push(*s);
            Ok(())
        },
    )?;
    Ok(Setpoints {
        axes: h.axes,
        kinds: h.kinds,
        joint: h.joint,
        period,
        samples: samples.into_inner(),
    })
}

/// Samples the solution's motion at period `period` (s) one setpoint at a time: `start` gets
/// the header (the count known before the first setpoint), then `each` every setpoint in time
/// order. A setpoint that is not finite stops it with an error (whatever `each` did with the
/// ones before is the caller's to undo). Errors: a bad period, more than [`MAX_SAMPLES`]
/// setpoints, and what `start` and `each` return.
pub fn for_each(
    machine: &Machine,
    solution: &Solution,
    period: f64,
    start: impl FnOnce(&SetpointsHeader) -> Result<()>,
    mut each: impl FnMut(&Sample) -> Result<()>,
) -> Result<SetpointsHeader> {
    crate::validate::period("period", period)?;
    let timeline = Timeline::new(&solution.schedule, &solution.problems, &solution.solutions)?;
    let holds = &solution.path.holds;
    let hold = |s: usize| holds.get(s).copied().unwrap_or(0.0);
    let cycle = timeline.cycle_time + holds.iter().sum::<f64>();
    let estimate = (cycle / period).ceil();
    if !(estimate.is_finite() && estimate < MAX_SAMPLES as f64) {
        return Err(Error::Usage(format!(
            "the schedule takes {} s: at a period of {} s that is more than {MAX_SAMPLES} \
             setpoints: give a period of at least {} s",
            crate::error::number(cycle),
            crate::error::number(period),
            crate::error::number(cycle / MAX_SAMPLES as f64)
        )));
    }
    let kin = &solution.kinematics;
    let na = kin.n_axes().min(machine.axes.len());
    let spans = &solution.path.spans;
    // The instants, as the sampling loop below takes them: the count first. `offset`: the
    // dwells so far, by which the clock runs ahead of the schedule's.
    let instants = |visit: &mut Visit| {
        let mut k: u64 = 0;
        let mut offset = 0.0;
        let mut stand = |k: &mut u64, end: f64, span, tl, at: At| -> Result<()> {
            loop {
                let t = *k as f64 * period;
                if t >= end {
                    return Ok(());
                }
                visit(span, tl, at, t)?;
                *k += 1;
            }
        };
        for (si, (span, tl)) in spans.iter().zip(&timeline.spans).enumerate() {
            if si == 0 && hold(0) > 0.0 {
                stand(&mut k, tl.t[0] + hold(0), span, tl, At::Start)?;
                offset += hold(0);
            }
            for i in 0..tl.u.len() - 1 {
                stand(&mut k, tl.t[i + 1] + offset, span, tl, At::Move(i, offset))?;
            }
            let h = hold(si + 1);
            if h > 0.0 {
                stand(&mut k, tl.t[tl.t.len() - 1] + offset + h, span, tl, At::End)?;
                offset += h;
            }
        }
        Ok::<(), Error>(())
    };
    let mut count = 0usize;
    instants(&mut |_, _, _, _| {
        count += 1;
        Ok(())
    })?;
    let last = spans.last().zip(timeline.spans.last());
    if last.is_some() {
        count += 1;
    }
    let header = SetpointsHeader {
        axes: machine
            .axes
            .iter()
            .take(na)
            .map(|a| a.name.clone())
            .collect(),
        kinds: machine.axes.iter().take(na).map(|a| a.kind).collect(),
        joint: spans.iter().any(|s| s.kind == SpanKind::Joint),
        period,
        count,
    };
    start(&header)?;
    let mut emit = |s: Sample| -> Result<()> {
        if !(s.t.is_finite() && s.s.is_finite() && s.feed.is_finite())
            || s.q[..na].iter().any(|x| !x.is_finite())
        {
            return Err(Error::Solver(format!(
                "the setpoint at t = {} s is not finite",
                s.t
            )));
        }
        each(&s)
    };
    instants(&mut |span, tl, at, t| {
        let last = tl.u.len() - 2;
        match at {
            At::Move(i, offset) => {
                let dur = tl.t[i + 1] - tl.t[i];
                let iv = tl.interval(i);
                emit(point(
                    span,
                    kin,
                    na,
                    tl,
                    i,
                    iv.at(t - offset - tl.t[i], dur),
                    t,
                ))
            }
            At::Start => emit(point(span, kin, na, tl, 0, tl.interval(0).ends().0, t)),
            At::End => emit(point(
                span,
                kin,
                na,
                tl,
                last,
                tl.interval(last).ends().1,
                t,
            )),
        }
    })?;
    // The final instant: the end of the last span.
    if let Some((span, tl)) = last {
        let i = tl.u.len() - 2;
        let st = tl.interval(i).ends().1;
        emit(point(span, kin, na, tl, i, st, cycle))?;
    }
    Ok(header)
}

/// Where a sampling instant falls: in interval i of a span's motion (with the dwells before
/// it, by which the clock is ahead of the schedule's), or in a dwell at the span's start or end.
#[derive(Debug, Clone, Copy)]
enum At {
    Move(usize, f64),
    Start,
    End,
}

/// What [`for_each`] does at one sampling instant: span, its timeline, where and t.
type Visit<'a> = dyn FnMut(&Span, &SpanTimeline, At, f64) -> Result<()> + 'a;

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
