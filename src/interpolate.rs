//! Data-sampling interpolation (seed 004): the schedule turned into every axis's setpoint at a
//! fixed interpolation period T, what a controller's servo loops consume.
//!
//! # Motion between stations
//!
//! The schedule fixes b = u̇² at its stations (and ü, for a jerk-limited profile); between
//! them the motion follows the laws of [`crate::motion`] — for an acceleration-limited profile
//! b linear in u, ü constant (eq. 40–43) — through [`Interval::at`] (and its inverse,
//! [`Interval::time_to_x`], for the G-code writer): exactly the motion [`crate::verify`]
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
//! **CSV** ([`setpoints_csv`]): a header naming each column with its unit,
//! `t_s,s_mm,feed_mm_s,X_mm,Y_mm,Z_mm,C_deg,A_deg` (a joint-space path: `t_s,s,feed,<axis>_mm|
//! _deg…`, s in the file's own unit), then one row per sample.
//!
//! **Binary** ([`setpoints_bin`], read back by [`read_setpoints_bin`]), all little-endian:
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `FOSETPT\0` |
//! | 4 | u32 version = 1 |
//! | 4 | u32 flags: bit 0 set = joint-space path (s and feed in the path's own units) |
//! | 4 | u32 axis count n |
//! | 8 | f64 period T, s |
//! | 8 | u64 sample count m |
//! | per axis | u8 name length, the name (UTF-8), u8 unit: 0 = mm, 1 = degrees |
//! | m × (3 + n) × 8 | records of f64: t (s), s (mm), feed (mm/s), q₁ … qₙ (mm or °) |

use std::path::Path;

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

fn unit_name(kind: AxisKind) -> &'static str {
    match kind {
        AxisKind::Linear => "mm",
        AxisKind::Rotary => "deg",
    }
}

/// The setpoints as CSV: header `t_s,s_mm,feed_mm_s,<axis>_<unit>…`, one row per sample.
pub fn setpoints_csv(sp: &Setpoints) -> String {
    use std::fmt::Write as _;
    let na = sp.axes.len();
    let mut out = String::with_capacity(sp.samples.len() * (24 * (3 + na)));
    out.push_str(if sp.joint {
        "t_s,s,feed"
    } else {
        "t_s,s_mm,feed_mm_s"
    });
    for (name, kind) in sp.axes.iter().zip(&sp.kinds) {
        let _ = write!(out, ",{name}_{}", unit_name(*kind));
    }
    out.push('\n');
    for s in &sp.samples {
        let _ = write!(out, "{},{},{}", s.t, s.s, s.feed);
        for q in &s.q[..na] {
            let _ = write!(out, ",{q}");
        }
        out.push('\n');
    }
    out
}

/// Magic bytes of the binary setpoint file.
pub const MAGIC: &[u8; 8] = b"FOSETPT\0";
/// Version of the binary layout.
pub const VERSION: u32 = 1;

/// The setpoints in the binary layout of the module doc.
pub fn setpoints_bin(sp: &Setpoints) -> Result<Vec<u8>> {
    let na = sp.axes.len();
    let mut out = Vec::with_capacity(64 + sp.samples.len() * 8 * (3 + na));
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&u32::from(sp.joint).to_le_bytes());
    out.extend_from_slice(&(na as u32).to_le_bytes());
    out.extend_from_slice(&sp.period.to_le_bytes());
    out.extend_from_slice(&(sp.samples.len() as u64).to_le_bytes());
    for (name, kind) in sp.axes.iter().zip(&sp.kinds) {
        let len = u8::try_from(name.len())
            .map_err(|_| Error::Usage(format!("axis name `{name}` is too long")))?;
        out.push(len);
        out.extend_from_slice(name.as_bytes());
        out.push(u8::from(*kind == AxisKind::Rotary));
    }
    for s in &sp.samples {
        for x in [s.t, s.s, s.feed].iter().chain(&s.q[..na]) {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    Ok(out)
}

/// Reads the binary layout back (positions only: [`Sample::qd`], [`Sample::qdd`] are 0).
/// `source` names the file in errors.
pub fn read_setpoints_bin(source: &Path, bytes: &[u8]) -> Result<Setpoints> {
    let bad = |what: &str| {
        Error::io(
            source,
            std::io::Error::new(std::io::ErrorKind::InvalidData, what.to_string()),
        )
    };
    let mut at = 0usize;
    let mut take = |n: usize| -> Result<&[u8]> {
        let slice = bytes
            .get(at..at + n)
            .ok_or_else(|| bad("truncated setpoint file"))?;
        at += n;
        Ok(slice)
    };
    if take(8)? != MAGIC {
        return Err(bad("not a feedopt setpoint file (bad magic bytes)"));
    }
    let u32_of = |b: &[u8]| u32::from_le_bytes(b.try_into().unwrap_or([0; 4]));
    let f64_of = |b: &[u8]| f64::from_le_bytes(b.try_into().unwrap_or([0; 8]));
    let version = u32_of(take(4)?);
    if version != VERSION {
        return Err(bad(&format!(
            "setpoint file version {version} (expected 1)"
        )));
    }
    let joint = u32_of(take(4)?) & 1 == 1;
    let na = u32_of(take(4)?) as usize;
    if na > MAX_AXES {
        return Err(bad(&format!("{na} axes (at most {MAX_AXES})")));
    }
    let period = f64_of(take(8)?);
    let m = u64::from_le_bytes(take(8)?.try_into().unwrap_or([0; 8]));
    let mut axes = Vec::with_capacity(na);
    let mut kinds = Vec::with_capacity(na);
    for _ in 0..na {
        let len = take(1)?[0] as usize;
        let name = std::str::from_utf8(take(len)?).map_err(|_| bad("axis name is not UTF-8"))?;
        axes.push(name.to_string());
        kinds.push(match take(1)?[0] {
            0 => AxisKind::Linear,
            1 => AxisKind::Rotary,
            u => return Err(bad(&format!("unknown axis unit code {u}"))),
        });
    }
    let record = 8 * (3 + na);
    let rest = bytes.len() - at;
    if (rest as u64) != m.saturating_mul(record as u64) {
        return Err(bad(&format!(
            "{m} records of {record} bytes announced, {rest} bytes present"
        )));
    }
    let samples = bytes[at..]
        .chunks_exact(record)
        .map(|r| {
            let x = |k: usize| f64_of(&r[8 * k..8 * k + 8]);
            let mut q = [0.0; MAX_AXES];
            for (j, qj) in q.iter_mut().enumerate().take(na) {
                *qj = x(3 + j);
            }
            Sample {
                t: x(0),
                s: x(1),
                feed: x(2),
                q,
                qd: [0.0; MAX_AXES],
                qdd: [0.0; MAX_AXES],
            }
        })
        .collect();
    Ok(Setpoints {
        axes,
        kinds,
        joint,
        period,
        samples,
    })
}

/// Output formats of the setpoints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetpointFormat {
    /// Comma-separated text.
    Csv,
    /// The compact binary layout of the module doc.
    Bin,
}

/// The format of an output path by its extension (`.csv` or `.bin`).
pub fn setpoint_format(path: &Path) -> Result<SetpointFormat> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("csv") => Ok(SetpointFormat::Csv),
        Some("bin") => Ok(SetpointFormat::Bin),
        _ => Err(Error::Usage(format!(
            "{}: unknown setpoint format (use .csv or .bin)",
            path.display()
        ))),
    }
}

/// Writes the setpoints to `path` (format by extension), atomically.
pub fn write_setpoints(path: &Path, sp: &Setpoints) -> Result<()> {
    let bytes = match setpoint_format(path)? {
        SetpointFormat::Csv => setpoints_csv(sp).into_bytes(),
        SetpointFormat::Bin => setpoints_bin(sp)?,
    };
    crate::writers::write_atomically(path, &bytes)
}
