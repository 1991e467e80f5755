//! Re-simulation: an independent check of a schedule at the servo period of a controller.
//!
//! The solver bounds the axis accelerations and the feed only at its stations. A controller
//! runs the motion at a fixed interpolation period (seed 004: data-sampling interpolation), so
//! what matters is whether every axis stays within its limits *at every servo instant*. This
//! module replays the schedule on that clock and checks every limit from scratch:
//!
//! - time comes from eq. 43 per interval ([`crate::motion::interval_times`]); within an
//!   interval b = u̇² is linear in u, so ü is constant and the motion integrates exactly:
//!   `√b(t) = √b_i + ü (t − t_i)`, `u(t) = u_i + (t − t_i)(√b_i + √b(t))/2`
//!   (the second form stays exact and finite for ü → 0 and from rest);
//! - the geometry is evaluated from the path spline at each sampled u (not taken from the
//!   solver's station data), then through the kinematics to every axis:
//!   `q̇ = q' u̇`, `q̈ = q'' b + q' ü`, and on a moving span `V = |P'| u̇`;
//! - every quantity is compared with its limit as a ratio ([`Limit::ratio`]); a ratio above
//!   `1 + tolerance` is a [`Violation`].
//!
//! Samples are the instants `t = j · period` of one global clock (time accumulates over the
//! spans, run one after the other) plus the last instant of each span; inside an interval that
//! lasts more than [`MAX_INTERVAL_SAMPLES`] periods, every k-th of them, evenly spread, so the
//! work is bounded by the stations, not by cycle time ÷ period. In addition, both ends
//! of every station interval are checked with that interval's own ü (q̈ jumps at stations), so
//! the check is at least as strict as the solver's own rows.

use crate::constraints::{Chord, SpanProblem};
use crate::error::number;
use crate::error::{Error, Result};
use crate::geometry::{Span, SpanKind};
use crate::kinematics::{AxisJets, Kinematics, MAX_AXES};
use crate::machine::{Limit, Machine};
use crate::motion::{Interval, Law, State};
use crate::solver::SpanSolution;
use crate::solver::interval_times;
use crate::validate::{MIN_CHORD_TOLERANCE_MM, non_negative, period};

/// Most servo instants a re-simulation checks (2e9: about 23 days of motion at 1 ms; on two
/// cores about 10 min). A schedule that would need more is refused before the check starts.
pub const MAX_SAMPLES: f64 = 2e9;

/// Most servo instants checked inside one station interval. An interval lasting longer (a slow
/// feed over a long CL move) is checked at this many of its instants, every k-th, evenly
/// spread: within an interval the motion follows a closed-form law on one cubic piece of the
/// path spline, which 4,096 samples resolve far below the tolerance, so the work grows with
/// the stations rather than with cycle time ÷ period.
pub const MAX_INTERVAL_SAMPLES: u64 = 4096;

/// The first instant `j · period` of the global clock at or after `t`.
pub(crate) fn first_instant(t: f64, period: f64) -> u64 {
    let mut j = (t / period).ceil().max(0.0) as u64;
    while j > 0 && (j - 1) as f64 * period >= t {
        j -= 1;
    }
    while (j as f64) * period < t {
        j += 1;
    }
    j
}

/// Walks the servo instants `j · period` of the global clock inside one station interval,
/// from instant `j` (the first at or after its start `ta`) to before its end `ta + dt`:
/// calls `f(t, state, u)` at each, with the motion of [`Interval::at`] and the path
/// parameter `u` (kept within `[ua, ub]`). With `max`, an interval holding more instants is
/// walked at `max` of them, every k-th, evenly spread. Returns the first instant at or after
/// the interval's end, where the next interval's walk starts.
///
/// The one sampler of a schedule on the servo clock: [`verify`] checks every limit at these
/// instants, and `compare` takes its finite-difference jerk from them (every instant).
pub(crate) fn servo_instants(
    iv: &Interval,
    (ua, ub): (f64, f64),
    (ta, dt): (f64, f64),
    mut j: u64,
    period: f64,
    max: Option<u64>,
    mut f: impl FnMut(f64, &State, f64),
) -> u64 {
    let tb = ta + dt;
    let inside = ((tb / period).ceil() - j as f64).max(0.0);
    let stride = max.map_or(1, |m| (inside / m as f64).ceil().max(1.0) as u64);
    let mut march = iv.marcher(dt);
    loop {
        let t = j as f64 * period;
        if t >= tb {
            break;
        }
        let st = march.at(t - ta);
        f(t, &st, (ua + st.x).min(ub));
        j += stride;
    }
    if stride > 1 {
        j = first_instant(tb, period);
    }
    j
}

/// A duration in the unit a person reads it in.
fn human_duration(t: f64) -> String {
    if !t.is_finite() {
        "of unbounded length".to_string()
    } else if t < 120.0 {
        format!("{t:.3} s")
    } else if t < 2.0 * 3600.0 {
        format!("{:.1} min", t / 60.0)
    } else if t < 2.0 * 86400.0 {
        format!("{:.1} h", t / 3600.0)
    } else {
        format!("{:.3e} days", t / 86400.0)
    }
}

/// Most violations kept in [`Verification::violations`] (the worst ones).
pub const MAX_VIOLATIONS: usize = 1000;

/// Options of a re-simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerifyOptions {
    /// Servo (interpolation) period, s.
    pub period: f64,
    /// Allowed relative excess over a limit: a ratio above `1 + tolerance` is a violation.
    pub tolerance: f64,
    /// The chord error of each interpolation period to check (and, in the pipeline, to bound:
    /// [`crate::constraints::Chord`]); `None`: not checked.
    pub chord: Option<Chord>,
    /// Threads checking chunks of the schedule in parallel (0: as many as the machine has);
    /// the result does not depend on it.
    pub threads: usize,
}

impl Default for VerifyOptions {
    fn default() -> Self {
        VerifyOptions {
            period: 1e-3,
            tolerance: 1e-3,
            chord: None,
            threads: 0,
        }
    }
}

/// Which limit a check concerns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// An axis velocity q̇.
    Velocity,
    /// An axis acceleration q̈.
    Acceleration,
    /// The tool-tip feed V against the programmed or maximum feed.
    Feed,
    /// An axis jerk q⃛ (only where the machine file gives jerk limits).
    Jerk,
    /// The chord error of one interpolation period (only with a chord tolerance).
    Chord,
}

/// The worst use of one axis's limits over all samples.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct AxisWorst {
    /// Axis name, as in the machine file.
    pub name: String,
    /// Largest q̇ / limit on its side (≥ 0).
    pub velocity: f64,
    /// Largest q̈ / limit on its side (≥ 0).
    pub acceleration: f64,
    /// Largest q⃛ / limit on its side (≥ 0; 0 where the axis has no jerk limit).
    pub jerk: f64,
}

/// A limit exceeded by more than the tolerance: the worst excess within one station interval.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Violation {
    /// Index of the span (a rest-to-rest piece of the path).
    pub span: usize,
    /// Station interval k within the span (between stations k and k+1).
    pub interval: usize,
    /// Path parameter of the worst sample.
    pub u: f64,
    /// Time of the worst sample from the start of the path, s.
    pub t: f64,
    /// The axis (index into the machine's axes); `None` for the feed.
    pub axis: Option<usize>,
    /// What exceeds its limit.
    pub kind: Quantity,
    /// The value (mm/s, mm/s², °/s, °/s²; a reorientation's rate of turn against its feed cap in °/s).
    pub value: f64,
    /// The limit on the value's side (`min` for a negative value).
    pub limit: f64,
    /// `value / limit` (> 1 + tolerance; infinite if the value could not be evaluated).
    pub ratio: f64,
}

/// The outcome of a re-simulation.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Verification {
    /// No sample exceeds any limit by more than the tolerance.
    pub verified: bool,
    /// Servo instants checked: every `j · period` within the schedule (every k-th inside an
    /// interval longer than [`MAX_INTERVAL_SAMPLES`] periods) and the last instant of each span.
    pub samples: usize,
    /// Additional checks at station instants: both ends of every station interval, each with
    /// that interval's ü (the last instant of a span is among them and among `samples`).
    pub station_checks: usize,
    /// Per machine axis, in the machine's order.
    pub worst: Vec<AxisWorst>,
    /// Largest V / feed cap (0 where no cap applies).
    pub worst_feed: f64,
    /// Largest chord error / chord tolerance (0 without a chord tolerance).
    pub worst_chord: f64,
    /// Station intervals with a violation, before [`MAX_VIOLATIONS`] truncation.
    pub violating_intervals: usize,
    /// The worst violation of each offending (span, interval), worst first, at most
    /// [`MAX_VIOLATIONS`].
    pub violations: Vec<Violation>,
}

impl Verification {
    /// The largest ratio over every axis, quantity and the feed.
    pub fn worst_ratio(&self) -> f64 {
        self.worst
            .iter()
            .flat_map(|w| [w.velocity, w.acceleration, w.jerk])
            .fold(self.worst_feed.max(self.worst_chord), f64::max)
    }
}

/// Re-simulates the schedule given by `solutions` (b = u̇² at the stations of `problems`, one
/// per span of `spans`, in order) at `options.period` and checks every axis limit of `machine`
/// and every feed cap at every sample.
///
/// Errors: a non-positive or non-finite period, a negative or non-finite tolerance, inputs of
/// mismatched lengths, and a schedule that stalls (b = 0 over a whole interval).
///
/// Cost: O((samples + stations) × axes), no allocation per sample.
pub fn verify(
    machine: &Machine,
    kin: &Kinematics,
    spans: &[Span],
    problems: &[SpanProblem],
    solutions: &[SpanSolution],
    options: &VerifyOptions,
) -> Result<Verification> {
    verify_marked(
        machine,
        kin,
        spans,
        problems,
        solutions,
        options,
        options.tolerance,
    )
    .map(|(v, _)| v)
}

/// [`verify`], and besides the verdict every interval whose worst ratio exceeds `1 + mark`
/// (`mark` ≤ the tolerance: those near a violation too), in the order checked. The local
/// refinement divides these, so that a sample on another clock (a span's times change when it
/// is solved again, and with them every later span's sample instants) does not find the ones
/// just under the tolerance over it a round later.
pub(crate) fn verify_marked(
    machine: &Machine,
    kin: &Kinematics,
    spans: &[Span],
    problems: &[SpanProblem],
    solutions: &[SpanSolution],
    options: &VerifyOptions,
    mark: f64,
) -> Result<(Verification, Vec<Violation>)> {
    let period = options.period;
    if !(period.is_finite() && period > 0.0) {
        return Err(Error::Usage(format!(
            "the verification period must be a positive number of seconds, found {period}"
        )));
    }
    if !(options.tolerance.is_finite() && options.tolerance >= 0.0) {
        return Err(Error::Usage(format!(
            "the verification tolerance must be a non-negative number, found {}",
            options.tolerance
        )));
    }
    if spans.len() != problems.len() || spans.len() != solutions.len() {
        return Err(Error::Usage(format!(
            "verify: {} spans, {} problems and {} solutions",
            spans.len(),
            problems.len(),
            solutions.len()
        )));
    }
    let na = kin.n_axes().min(machine.axes.len());
    let jerk = machine.axes.iter().take(na).any(|a| a.jerk.is_some());
    let limits: Vec<(Limit, Limit, Option<Limit>)> = machine
        .axes
        .iter()
        .take(na)
        .map(|a| (a.velocity, a.acceleration, a.jerk))
        .collect();
    // Every span's interval times, and each span's start on the global clock.
    let mut times = Vec::with_capacity(spans.len());
    let mut t0 = 0.0f64;
    for (si, (p, sol)) in problems.iter().zip(solutions).enumerate() {
        if sol.b.len() != p.u.len() || p.u.len() < 2 {
            return Err(Error::Usage(format!(
                "verify: span {si} has {} stations but {} values of b",
                p.u.len(),
                sol.b.len()
            )));
        }
        let dt = interval_times(p, sol)?;
        let span_start = t0;
        t0 = dt.iter().fold(t0, |t, d| t + d);
        times.push((span_start, dt));
    }
    // The work is the number of samples: refuse before starting where it is out of reach.
    let samples = t0 / period;
    if samples.is_nan() || samples > MAX_SAMPLES {
        // Where the time goes: the longest interval.
        let (si, k, dt) = times
            .iter()
            .enumerate()
            .flat_map(|(si, (_, dt))| dt.iter().enumerate().map(move |(k, &d)| (si, k, d)))
            .fold(
                (0, 0, f64::NEG_INFINITY),
                |m, x| if x.2 > m.2 { x } else { m },
            );
        return Err(Error::Usage(format!(
            "re-simulating the schedule ({}) every {} ms would take {samples:.3e} servo \
             instants, more than the {MAX_SAMPLES:.0e} feedopt checks; the slowest stretch \
             ({}) is near CL line {}: a feed or a limit there (program or machine file) is far \
             too small, or the period (--period) too short",
            human_duration(t0),
            period * 1e3,
            human_duration(dt),
            spans[si].nearest_line(problems[si].u[k])
        )));
    }
    // Chunks of CHUNK intervals, checked independently (in parallel) and merged in order: the
    // same samples, the same result, whatever the number of threads.
    let mut chunks = Vec::new();
    for (si, p) in problems.iter().enumerate() {
        let n = p.intervals();
        chunks.extend(
            (0..n)
                .step_by(CHUNK)
                .map(|i0| (si, i0, (i0 + CHUNK).min(n))),
        );
    }
    let threads = crate::parallel::resolve_threads(options.threads);
    let parts = crate::parallel::par_map(&chunks, threads, |&(si, i0, i1)| {
        let mut acc = Accumulator {
            limits: limits.clone(),
            threshold: 1.0 + mark.min(options.tolerance),
            worst: vec![[0.0; 3]; na],
            worst_feed: 0.0,
            worst_chord: 0.0,
            chord: options.chord,
            current: None,
            violations: Vec::new(),
        };
        let counts = check_intervals(
            &mut acc,
            kin,
            &spans[si],
            &problems[si],
            &solutions[si],
            (si, i0, i1),
            &times[si],
            period,
            jerk,
        );
        (acc, counts)
    });
    // Each span's last instant is a sample too (checked as its last interval's end).
    let (mut samples, mut station_checks) = (problems.len(), 0usize);
    let mut worst = vec![[0.0f64; 3]; na];
    let (mut worst_feed, mut worst_chord) = (0.0f64, 0.0f64);
    let mut violations = Vec::new();
    for (acc, (s, c)) in parts {
        samples += s;
        station_checks += c;
        for (w, aw) in worst.iter_mut().zip(&acc.worst) {
            for (x, y) in w.iter_mut().zip(aw) {
                *x = x.max(*y);
            }
        }
        worst_feed = worst_feed.max(acc.worst_feed);
        worst_chord = worst_chord.max(acc.worst_chord);
        violations.extend(acc.violations);
    }
    let marks = violations.clone();
    let threshold = 1.0 + options.tolerance;
    violations.retain(|v| v.ratio > threshold);
    let violating_intervals = violations.len();
    violations.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    violations.truncate(MAX_VIOLATIONS);
    let v = Verification {
        verified: violating_intervals == 0,
        samples,
        station_checks,
        worst: machine
            .axes
            .iter()
            .take(na)
            .zip(&worst)
            .map(|(a, w)| AxisWorst {
                name: a.name.clone(),
                velocity: w[0],
                acceleration: w[1],
                jerk: w[2],
            })
            .collect(),
        worst_feed,
        worst_chord,
        violating_intervals,
        violations,
    };
    Ok((v, marks))
}

/// Station intervals checked per task of the re-simulation.
const CHUNK: usize = 512;

/// Checks intervals `i0..i1` of span `si` (`at` = (si, i0, i1)) into `acc`: every servo
/// instant `j · period` of the global clock within them and both ends of every interval.
/// `times`: the span's start on the global clock and its interval times. Returns the number of
/// samples and of station checks.
#[allow(clippy::too_many_arguments)]
fn check_intervals(
    acc: &mut Accumulator,
    kin: &Kinematics,
    span: &Span,
    p: &SpanProblem,
    sol: &SpanSolution,
    at: (usize, usize, usize),
    times: &(f64, Vec<f64>),
    period: f64,
    jerk: bool,
) -> (usize, usize) {
    let (si, i0, i1) = at;
    let (span_start, dt) = times;
    let b = &sol.b;
    let knots = span.spline.knots();
    let last_seg = knots.len() - 2;
    let moving = span.kind == SpanKind::Moving;
    let (mut samples, mut station_checks) = (0usize, 0usize);
    // The chunk's start on the global clock, summed as when walking the span from its start.
    let mut ta = dt[..i0].iter().fold(*span_start, |t, d| t + d);
    // The first instant of the global clock at or after ta (an interval's samples lie in
    // [ta, tb): its end belongs to the next interval; a span's last instant is counted apart).
    let mut j = first_instant(ta, period);
    // The spline segment at the chunk's first station: at a span's start the one starting
    // there (a station on a knot starts the next segment), else the one the previous interval
    // ended in (the left side of a knot), as when walking the span from its start.
    let mut seg = 0usize;
    while seg < last_seg && (knots[seg + 1] < p.u[i0] || (i0 == 0 && knots[seg + 1] <= p.u[i0])) {
        seg += 1;
    }
    // Geometry at the interval's start station (shared with the previous interval's end).
    let mut at_start = Point::new(span, kin, seg, p.u[i0], moving, jerk);
    // ü just before the current station (at rest before a span that starts at rest).
    let mut udd_before = if i0 == 0 {
        0.0
    } else {
        Interval::of(&p.u, b, sol.shape(), i0 - 1).ends().1.udd
    };
    for i in i0..i1 {
        let (ua, ub) = (p.u[i], p.u[i + 1]);
        let iv = Interval::of(&p.u, b, sol.shape(), i);
        let (s0, s1) = iv.ends();
        let tb = ta + dt[i];
        // The segment of the spline this interval starts in (a station at a knot starts
        // the next segment: its feed cap applies from there on).
        let seg_before = seg;
        while seg < last_seg && knots[seg + 1] <= ua {
            seg += 1;
        }
        if jerk && seg != seg_before {
            // On a knot q''' jumps: the interval starts with its own segment's.
            at_start = Point::new(span, kin, seg, ua, moving, jerk);
        }
        let cap = span.feed_cap(seg, ua);
        acc.check(&at_start, &s0, cap, ua, ta, si, i);
        if jerk && iv.law == Law::Linear && (i > 0 || s0.b == 0.0) {
            // ü jumps at the station: a controller sampling at the period sees the step
            // of q̈ within one period.
            acc.check_step(&at_start, (s0.udd - udd_before) / period, ua, ta, si, i);
        }
        udd_before = s1.udd;
        station_checks += 1;
        // Servo instants strictly inside the interval (and at its start); past
        // MAX_INTERVAL_SAMPLES of them, every k-th, evenly spread.
        j = servo_instants(
            &iv,
            (ua, ub),
            (ta, dt[i]),
            j,
            period,
            Some(MAX_INTERVAL_SAMPLES),
            |t, st, u| {
                // Stay in the left segment at a knot: the interval's own side.
                while seg < last_seg && knots[seg + 1] < u {
                    seg += 1;
                }
                let cap = span.feed_cap(seg, u);
                let pt = Point::new(span, kin, seg, u, moving, jerk);
                acc.check(&pt, st, cap, u, t, si, i);
                samples += 1;
            },
        );
        // The interval's end, with this interval's ü.
        while seg < last_seg && knots[seg + 1] < ub {
            seg += 1;
        }
        let cap = span.feed_cap(seg, ub);
        let at_end = Point::new(span, kin, seg, ub, moving, jerk);
        acc.check(&at_end, &s1, cap, ub, tb, si, i);
        station_checks += 1;
        acc.close_interval();
        at_start = at_end;
        ta = tb;
    }
    (samples, station_checks)
}

/// The path geometry at one sample: every axis's u-derivatives and |P'|.
struct Point {
    jets: AxisJets,
    /// |P'(u)| on a moving span, 0 on a reorientation.
    speed: f64,
    /// Every axis's q''' (on the segment's side of a knot), when jerk is checked.
    dddq: Option<[f64; MAX_AXES]>,
    /// κ |P'|² of the tool tip on a moving span ([`Chord::curvature_term`]), else 0.
    bend: f64,
    /// On a reorientation: the feed cap is on u̇, the rate of turn ([`Span::feed_caps`]).
    turn: bool,
}

impl Point {
    fn new(span: &Span, kin: &Kinematics, seg: usize, u: f64, moving: bool, jerk: bool) -> Point {
        let w = span.spline.eval_in(seg, u);
        let dddq = jerk.then(|| kin.axis_third_derivatives(&w, &span.spline.d3_in(seg, u)));
        let speed = if moving {
            (w.d1[0] * w.d1[0] + w.d1[1] * w.d1[1] + w.d1[2] * w.d1[2]).sqrt()
        } else {
            0.0
        };
        Point {
            jets: kin.axis_jets(&w),
            speed,
            dddq,
            bend: if moving {
                Chord::curvature_term(&w)
            } else {
                0.0
            },
            turn: span.kind == SpanKind::Reorientation,
        }
    }
}

/// Worst ratios so far and the violations found.
struct Accumulator {
    /// (velocity, acceleration, jerk) limits per axis.
    limits: Vec<(Limit, Limit, Option<Limit>)>,
    threshold: f64,
    /// [velocity, acceleration, jerk] worst ratio per axis.
    worst: Vec<[f64; 3]>,
    worst_feed: f64,
    worst_chord: f64,
    chord: Option<Chord>,
    /// The worst violation of the interval being checked.
    current: Option<Violation>,
    violations: Vec<Violation>,
}

/// A ratio that is never NaN: a value that cannot be evaluated counts as an infinite excess.
fn ratio(limit: f64, value: f64) -> f64 {
    let r = value / limit;
    if r.is_nan() { f64::INFINITY } else { r }
}

impl Accumulator {
    /// Checks every limit at one sample: the geometry `pt`, the motion `st`, feed cap `cap`.
    #[allow(clippy::too_many_arguments)]
    fn check(
        &mut self,
        pt: &Point,
        st: &State,
        cap: f64,
        u: f64,
        t: f64,
        span: usize,
        interval: usize,
    ) {
        let (jets, speed, r) = (&pt.jets, pt.speed, st.ud);
        for j in 0..self.limits.len() {
            let qd = jets.dq[j] * r;
            let qdd = jets.ddq[j] * st.b + jets.dq[j] * st.udd;
            self.compare(j, 0, Quantity::Velocity, qd, (span, interval, u, t));
            self.compare(j, 1, Quantity::Acceleration, qdd, (span, interval, u, t));
            if let Some(d3) = &pt.dddq {
                let q3 = st.jerk(jets.dq[j], jets.ddq[j], d3[j]);
                self.compare(j, 2, Quantity::Jerk, q3, (span, interval, u, t));
            }
        }
        if let Some(c) = self.chord.filter(|_| pt.bend > 0.0) {
            let e = pt.bend * st.b * c.period * c.period / 8.0;
            let x = ratio(c.tolerance, e);
            self.worst_chord = self.worst_chord.max(x);
            self.note(
                None,
                Quantity::Chord,
                e,
                c.tolerance,
                x,
                (span, interval, u, t),
            );
        }
        if cap.is_finite() && (speed > 0.0 || pt.turn) {
            // A reorientation's rate of turn u̇ against its cap, both in °/s.
            let (v, cap) = if pt.turn {
                (r.to_degrees(), cap.to_degrees())
            } else {
                (speed * r, cap)
            };
            let x = if v > 0.0 { ratio(cap, v) } else { 0.0 };
            self.worst_feed = self.worst_feed.max(x);
            self.note(None, Quantity::Feed, v, cap, x, (span, interval, u, t));
        }
    }

    /// A step of ü at a station (`rate` = Δü / period): the jerk a controller sees there.
    fn check_step(&mut self, pt: &Point, rate: f64, u: f64, t: f64, span: usize, interval: usize) {
        for j in 0..self.limits.len() {
            self.compare(
                j,
                2,
                Quantity::Jerk,
                pt.jets.dq[j] * rate,
                (span, interval, u, t),
            );
        }
    }

    /// One value of axis `j`'s quantity `k` (0 velocity, 1 acceleration, 2 jerk) against its
    /// limit; `at` = (span, interval, u, t).
    fn compare(
        &mut self,
        j: usize,
        k: usize,
        kind: Quantity,
        value: f64,
        at: (usize, usize, f64, f64),
    ) {
        let (vl, al, jl) = &self.limits[j];
        let lim = match k {
            0 => vl,
            1 => al,
            _ => match jl {
                Some(l) => l,
                None => return,
            },
        };
        let limit = if value >= 0.0 { lim.max } else { lim.min };
        let x = ratio(limit, value);
        if x > self.worst[j][k] {
            self.worst[j][k] = x;
        }
        self.note(Some(j), kind, value, limit, x, at);
    }

    /// Keeps ratio `x` of `value` to `limit` as the interval's worst violation when it is one
    /// (above the threshold) and worse than the one kept; `at` = (span, interval, u, t).
    fn note(
        &mut self,
        axis: Option<usize>,
        kind: Quantity,
        value: f64,
        limit: f64,
        x: f64,
        at: (usize, usize, f64, f64),
    ) {
        if x > self.threshold && self.current.as_ref().is_none_or(|c| x > c.ratio) {
            let (span, interval, u, t) = at;
            self.current = Some(Violation {
                span,
                interval,
                u,
                t,
                axis,
                kind,
                value: if value.is_nan() { f64::INFINITY } else { value },
                limit,
                ratio: x,
            });
        }
    }

    /// Ends an interval: keeps its worst violation, if any.
    fn close_interval(&mut self) {
        if let Some(v) = self.current.take() {
            self.violations.push(v);
        }
    }
}

impl VerifyOptions {
    /// Checks every field's range ([`crate::validate`]); the error names the field.
    pub fn validate(&self) -> Result<()> {
        period("period", self.period)?;
        non_negative("tolerance", self.tolerance, "(relative)")?;
        if let Some(chord) = &self.chord {
            let d = chord.tolerance;
            if !(d.is_finite() && d >= MIN_CHORD_TOLERANCE_MM) {
                return Err(Error::option(
                    "chord.tolerance",
                    format!(
                        "{} mm: give a chord tolerance of at least {MIN_CHORD_TOLERANCE_MM:e} mm \
                         (1 nm; smaller ones only slow the feed to a crawl)",
                        number(d)
                    ),
                ));
            }
            period("chord.period", chord.period)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::Grid;
    use crate::geometry::spline::CubicSpline;
    use crate::kinematics::PATH_DIM;
    use crate::machine::{Axis, AxisKind, KinematicsSpec};
    use crate::solver::Status;

    fn xyz(a: f64, v: f64, feed: Option<f64>) -> Machine {
        let axis = |name: &str| Axis {
            name: name.to_string(),
            kind: AxisKind::Linear,
            velocity: Limit::symmetric(v),
            acceleration: Limit::symmetric(a),
            jerk: None,
            travel: None,
        };
        Machine {
            name: "xyz".into(),
            kinematics: KinematicsSpec::Xyz,
            axes: vec![axis("X"), axis("Y"), axis("Z")],
            feed_max: feed,
        }
    }

    /// A straight line along X of length `len`, one CL segment.
    fn line(len: f64, cap: f64) -> Span {
        let mut end = [0.0; PATH_DIM];
        end[0] = len;
        Span {
            deviation: (0.0, 0.0),
            kind: SpanKind::Moving,
            spline: CubicSpline::new(&[0.0, len], &[[0.0; PATH_DIM], end]),
            feed_caps: vec![cap],
            lines: vec![1, 2],
            points: vec![0, 1],
            process: None,
        }
    }

    fn solution(b: Vec<f64>) -> SpanSolution {
        SpanSolution {
            ends: None,
            a: None,
            slopes: None,
            b,
            status: Status::Optimal,
            iterations: 0,
            solve_time: 0.0,
            scp_iterations: 0,
        }
    }

    #[test]
    fn exact_integration_with_constant_path_acceleration() {
        let lin = |ua: f64, ub: f64, ba: f64, bb: f64| {
            Interval::of(&[ua, ub], &[ba * ba, bb * bb], Default::default(), 0)
        };
        // From rest with ü = 3 (√b 0 → 6 over u 0 → 6, 2 s): √b = 3τ, u = 1.5 τ².
        let iv = lin(0.0, 6.0, 0.0, 6.0);
        let st = iv.at(1.5, iv.duration().unwrap());
        assert!((st.ud - 4.5).abs() < 1e-15 && (st.x - 1.5 * 2.25).abs() < 1e-15);
        // ü = 0: uniform motion, no division anywhere.
        let iv = lin(1.0, 5.0, 2.0, 2.0);
        let st = iv.at(0.5, 2.0);
        assert_eq!((st.ud, st.x + 1.0), (2.0, 2.0));
        // Braking to rest ends exactly at the interval's end.
        let iv = lin(0.0, 4.0, 4.0, 0.0);
        let st = iv.at(2.0, iv.duration().unwrap());
        assert_eq!((st.ud, st.x), (0.0, 4.0));
    }

    #[test]
    fn a_triangular_profile_at_the_acceleration_limit_is_exact() {
        // b = 2 a u up to mid-line, then symmetric: X accelerates at exactly ±a throughout.
        let (len, a) = (2.0, 2000.0);
        let m = xyz(a, 1e4, None);
        let kin = Kinematics::new(&m);
        let span = line(len, f64::INFINITY);
        let p = SpanProblem::build(
            &span,
            &kin,
            &m,
            Grid {
                spacing: len / 8.0,
                min_parts: 1,
            },
        );
        let b: Vec<f64> = p.u.iter().map(|&u| 2.0 * a * u.min(len - u)).collect();
        let options = VerifyOptions::default();
        let v = verify(&m, &kin, &[span], &[p], &[solution(b)], &options).unwrap();
        assert!(v.verified, "{v:?}");
        assert!((v.worst[0].acceleration - 1.0).abs() < 1e-12, "{v:?}");
        let vpeak = (a * len).sqrt();
        assert!((v.worst[0].velocity - vpeak / 1e4).abs() < 1e-12);
        assert_eq!(v.worst_feed, 0.0);
        // T = 2√(L/a) = 63.2 ms: instants 0 … 63 ms and the end.
        assert_eq!(v.samples, 65);
        assert_eq!(v.station_checks, 16);
    }

    /// Intervals above `1 + mark` but within the tolerance are marked and do not fail the
    /// verdict; those above the tolerance do both.
    #[test]
    fn marks_reach_below_the_tolerance_and_the_verdict_does_not() {
        let (len, a) = (2.0, 2000.0);
        let m = xyz(a, 1e4, None);
        let kin = Kinematics::new(&m);
        let span = line(len, f64::INFINITY);
        let p = SpanProblem::build(
            &span,
            &kin,
            &m,
            Grid {
                spacing: len / 8.0,
                min_parts: 1,
            },
        );
        let options = VerifyOptions::default();
        let run = |excess: f64| {
            // The triangular profile at (1 + excess) a: every interval exceeds by that much.
            let b: Vec<f64> = (p.u.iter())
                .map(|&u| 2.0 * a * (1.0 + excess) * u.min(len - u))
                .collect();
            let (spans, problems) = (std::slice::from_ref(&span), std::slice::from_ref(&p));
            verify_marked(&m, &kin, spans, problems, &[solution(b)], &options, 5e-4).unwrap()
        };
        let (v, marks) = run(7e-4);
        assert!(
            v.verified && v.violations.is_empty() && v.violating_intervals == 0,
            "{v:?}"
        );
        assert_eq!(marks.len(), 8, "{marks:?}");
        assert!(
            marks.iter().all(|x| (x.ratio - 1.0007).abs() < 1e-9),
            "{marks:?}"
        );
        let (v, marks) = run(2e-3);
        assert!(!v.verified && v.violating_intervals == 8, "{v:?}");
        assert_eq!(marks.len(), 8);
        let (v, marks) = run(0.0);
        assert!(v.verified && marks.is_empty());
    }

    #[test]
    fn a_long_slow_interval_costs_a_bounded_number_of_samples_and_is_still_checked() {
        // 1 m at about 0.11 mm/s: some 9,000 s, 9 million instants at 1 ms, on 4 intervals.
        let (len, a) = (1000.0, 2000.0);
        let m = xyz(a, 1e4, None);
        let kin = Kinematics::new(&m);
        let span = line(len, 0.1);
        let grid = Grid {
            spacing: len / 4.0,
            min_parts: 1,
        };
        let p = SpanProblem::build(&span, &kin, &m, grid);
        let n = p.intervals();
        let b: Vec<f64> = (0..=n)
            .map(|i| {
                if i == 0 || i == n {
                    0.0
                } else {
                    0.11f64.powi(2)
                }
            })
            .collect();
        let v = verify(&m, &kin, &[span], &[p], &[solution(b)], &Default::default()).unwrap();
        assert!(
            v.samples <= n * MAX_INTERVAL_SAMPLES as usize + 1,
            "{}",
            v.samples
        );
        assert!(v.samples >= n * (MAX_INTERVAL_SAMPLES as usize - 1));
        // The feed 10 % over its cap is found inside the long intervals.
        assert!(!v.verified);
        assert!((v.worst_feed - 1.1).abs() < 1e-9, "{}", v.worst_feed);
        assert!(v.violations.iter().any(|x| x.kind == Quantity::Feed));
    }

    #[test]
    fn an_excess_names_the_axis_the_quantity_and_the_cap() {
        let (len, a) = (2.0, 2000.0);
        let m = xyz(a, 1e4, None);
        let kin = Kinematics::new(&m);
        let span = line(len, 65.0);
        let grid = Grid {
            spacing: len / 8.0,
            min_parts: 1,
        };
        let p = SpanProblem::build(&span, &kin, &m, grid);
        let b: Vec<f64> =
            p.u.iter()
                .map(|&u| 1.1 * 2.0 * a * u.min(len - u))
                .collect();
        let v = verify(&m, &kin, &[span], &[p], &[solution(b)], &Default::default()).unwrap();
        assert!(!v.verified);
        let w = &v.violations[0];
        assert_eq!((w.axis, w.kind), (Some(0), Quantity::Acceleration));
        assert!((w.ratio - 1.1).abs() < 1e-9);
        assert!((v.worst_feed - (1.1 * a * len).sqrt() / 65.0).abs() < 1e-9);
        assert!(
            v.violations
                .iter()
                .all(|x| x.ratio.is_finite() && x.u.is_finite() && x.t.is_finite())
        );
        assert_eq!(v.violating_intervals, v.violations.len());
    }

    #[test]
    fn bad_options_and_stalls_are_errors() {
        let m = xyz(2000.0, 1e4, None);
        let kin = Kinematics::new(&m);
        let span = line(1.0, f64::INFINITY);
        let grid = Grid {
            spacing: 0.25,
            min_parts: 1,
        };
        let p = SpanProblem::build(&span, &kin, &m, grid);
        let sol = solution(vec![0.0; p.u.len()]);
        let (spans, ps, ss) = ([span], [p], [sol]);
        for period in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let o = VerifyOptions {
                period,
                ..Default::default()
            };
            assert!(verify(&m, &kin, &spans, &ps, &ss, &o).is_err());
        }
        // b = 0 everywhere: the path is never traversed.
        assert!(verify(&m, &kin, &spans, &ps, &ss, &Default::default()).is_err());
    }
}
