//! Report: what a person reads after a solve — cycle time, solver figures, how close each axis
//! comes to its limits, and which limit holds the feed down over what share of the path.

use std::collections::BTreeMap;
use std::fmt;

use crate::constraints::{Bound, SpanProblem};
use crate::geometry::Span;
use crate::kinematics::Kinematics;
use crate::machine::Machine;
use crate::motion::Interval;
use crate::optimize::{Refinement, Solution};
use crate::solver::SpanSolution;
use crate::solver::Status;

/// A constraint counts as binding when used to within this fraction of its limit.
pub const BINDING_TOLERANCE: f64 = 1e-3;

/// The limit holding the feed down on interval k of a span's schedule: the one used most at
/// either end of the interval (velocity and feed through `b_max`, which names its limit; every
/// axis's acceleration with the profile's ü there; and, for a jerk-limited profile, the
/// interval's largest jerk ratio from [`jerk_ratios`]), if used to within
/// [`BINDING_TOLERANCE`]; else [`Bound::None`].
pub fn interval_binding(
    p: &SpanProblem,
    sol: &SpanSolution,
    k: usize,
    jerk: Option<&[(f64, usize)]>,
) -> Bound {
    let b = &sol.b;
    let mut best = (0.0, Bound::None);
    for e in [k, k + 1] {
        if p.b_max[e].is_finite() && p.b_max[e] > 0.0 {
            let r = b[e] / p.b_max[e];
            if r > best.0 {
                best = (r, p.b_max_by[e]);
            }
        }
        for (j, lim) in p.acceleration.iter().enumerate() {
            let r = lim.ratio(axis_acceleration(p, sol, k, e, j));
            if r > best.0 {
                best = (r, Bound::AxisAcceleration(j));
            }
        }
    }
    if let Some(&(r, j)) = jerk.and_then(|v| v.get(k)) {
        if r > best.0 {
            best = (r, Bound::AxisJerk(j));
        }
    }
    if best.0 >= 1.0 - BINDING_TOLERANCE {
        best.1
    } else {
        Bound::None
    }
}

/// Axis `j`'s q̈ at station `e` (an end of interval k) under the profile's law.
fn axis_acceleration(p: &SpanProblem, sol: &SpanSolution, k: usize, e: usize, j: usize) -> f64 {
    match &sol.a {
        Some(a) => p.jets.ddq(e)[j] * sol.b[e] + p.jets.dq(e)[j] * a[e],
        None => p.axis_acceleration(&sol.b, sol.ends.as_deref(), k, e, j),
    }
}

/// Per interval of a jerk-limited profile, the largest |q⃛|/limit at its two ends over the axes
/// with a jerk limit, and that axis (`q⃛ = q''' u̇³ + 3 q'' u̇ ü + q' u⃛` under the motion laws
/// of [`crate::motion`]); `None` for an acceleration-limited profile or a machine without jerk
/// limits.
pub fn jerk_ratios(
    machine: &Machine,
    span: &Span,
    kin: &Kinematics,
    p: &SpanProblem,
    sol: &SpanSolution,
) -> Option<Vec<(f64, usize)>> {
    sol.a.as_ref()?;
    if !machine.has_jerk() {
        return None;
    }
    let knots = span.spline.knots();
    let last = knots.len() - 2;
    let mut out = Vec::with_capacity(p.intervals());
    for k in 0..p.intervals() {
        let iv = Interval::of(&p.u, &sol.b, sol.shape(), k);
        let (s0, s1) = iv.ends();
        let mut best = (0.0, 0);
        for (e, st) in [(k, s0), (k + 1, s1)] {
            let u = p.u[e];
            let mut seg = span.spline.segment(u).min(last);
            if e == k + 1 && seg > 0 && u <= knots[seg] {
                seg -= 1;
            }
            let w = span.spline.eval_in(seg, u);
            let d3 = kin.axis_third_derivatives(&w, &span.spline.d3_in(seg, u));
            let jets = p.jets.view(e);
            for (j, axis) in machine.axes.iter().enumerate().take(kin.n_axes()) {
                let Some(lim) = axis.jerk else { continue };
                let q3 = st.jerk(jets.dq[j], jets.ddq[j], d3[j]);
                let r = lim.ratio(q3);
                if r > best.0 {
                    best = (r, j);
                }
            }
        }
        out.push(best);
    }
    Some(out)
}

/// How a limit is named in reports and plots: `"X velocity"`, `"C acceleration"`, `"feed"`,
/// `"none"`.
pub fn binding_label(bound: Bound, axes: &[&str]) -> String {
    match bound {
        Bound::AxisVelocity(j) => format!("{} velocity", axes[j]),
        Bound::AxisAcceleration(j) => format!("{} acceleration", axes[j]),
        Bound::AxisJerk(j) => format!("{} jerk", axes[j]),
        Bound::Feed => "feed".to_string(),
        Bound::Chord => "chord error".to_string(),
        Bound::Process(l) => l.label().to_string(),
        Bound::None => "none".to_string(),
    }
}

/// Peak use of an axis's limits.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct AxisPeaks {
    /// max |q̇| / v over the schedule (on the side of the sign of q̇).
    pub peak_velocity_ratio: f64,
    /// max |q̈| / a over the schedule, at both ends of every interval.
    pub peak_acceleration_ratio: f64,
}

/// Share of the path over which one limit holds the feed down.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BindingShare {
    /// The limit ([`Bound::None`]: nothing binds). Not in the JSON, which names it (`name`).
    #[serde(skip)]
    pub limit: Bound,
    /// Its name in reports ([`binding_label`]), e.g. `"feed"`, `"C velocity"`,
    /// `"A acceleration"`, `"none"`: the JSON's `limit`.
    #[serde(rename = "limit")]
    pub name: String,
    /// Share of the tool-tip path length (0–1).
    pub share_of_path: f64,
    /// Share of the cycle time (0–1).
    pub share_of_time: f64,
}

/// The summary of a solve (what `feedopt solve --json` prints).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Summary {
    /// The machine's name.
    pub machine: String,
    /// The toolpath as named by the caller.
    pub toolpath: String,
    /// Cycle time, s (dwells included).
    pub cycle_time_s: f64,
    /// Stations in all.
    pub stations: usize,
    /// Rest-to-rest spans.
    pub spans: usize,
    /// The worst status over all spans.
    pub status: Status,
    /// Interior-point iterations, summed over spans.
    pub iterations: u32,
    /// Solver time, summed over spans, s.
    pub solve_time_s: f64,
    /// Tool-tip path length, mm (joint-space path: the length of its parameter s).
    pub path_length_mm: f64,
    /// Whether the input was a joint-space path (so lengths and feeds are in s, not mm).
    pub joint_space: bool,
    /// Largest distance of the fitted path from the programmed path, at its points (smoothing
    /// within `--tolerance`) and between them (the programmed chords): tool tip, mm; rotary
    /// angles, degrees.
    pub max_deviation_mm: f64,
    /// The same for the rotary angles, degrees.
    pub max_deviation_deg: f64,
    /// Corners blended within the corner tolerance (`--corner-tolerance`) instead of stopped
    /// at; the deviations above are from the path with those blends.
    pub corners_blended: usize,
    /// Per axis, in the machine's order (a JSON object keyed by axis name).
    #[serde(serialize_with = "as_map")]
    pub axes: Vec<(String, AxisPeaks)>,
    /// Which limit holds the feed down over what share of the path and of the time.
    pub binding: Vec<BindingShare>,
    /// Station counts tried and their cycle times.
    pub refinement: Vec<Refinement>,
    /// Estimated relative error of `cycle_time_s` against the continuous optimum (automatic
    /// refinement; `null` on a fixed grid): see [`Solution::error_estimate`].
    pub error_estimate: Option<f64>,
    /// The relative error the automatic refinement aimed at (`null` on a fixed grid).
    pub error_target: Option<f64>,
    /// Why the refinement stopped with `error_estimate` above `error_target` (`null`: it did
    /// not): see [`Solution::unconverged`].
    pub unconverged: Option<String>,
    /// Where spans were slowed down after the local refinement did not settle (`null`: none
    /// were): see [`Solution::slowed_down`].
    pub slowed_down: Option<String>,
    /// Span solves answered by an earlier solve of the same problem (a drilling cycle's
    /// moves at every hole): see [`Solution::reused_solves`].
    pub reused_solves: usize,
    /// The re-simulation at the servo period found every limit kept (within its tolerance).
    pub verified: bool,
    /// Servo period of the re-simulation, s.
    pub verify_period_s: f64,
    /// Worst ratio to each axis's limits over the re-simulated motion (between stations too).
    #[serde(serialize_with = "worst_as_map")]
    pub worst_ratio: Vec<(String, WorstRatio)>,
    /// Worst ratio of the tool-tip feed to its cap (0 without a cap).
    pub worst_feed_ratio: f64,
    /// Worst chord error of an interpolation period over `--chord-tolerance` (0 without).
    pub worst_chord_ratio: f64,
    /// Whether the schedule honours jerk limits (the machine file gives some).
    pub jerk_limited: bool,
    /// The reader's warnings (`file:line: message`), each message once at its first line,
    /// with `(and N more like it, the last at line L)` where it repeats.
    pub warnings: Vec<String>,
    /// The input format read (`apt`, `gcode`, `csv`) and how it was chosen (`option`,
    /// `extension`, `content`).
    pub format: String,
    /// How the format was chosen.
    pub format_by: String,
    /// The G-code dialect read (G-code only) and how it was chosen (`option`, `content`,
    /// `extension`, `default`).
    pub dialect: Option<String>,
    /// How the dialect was chosen.
    pub dialect_by: Option<String>,
    /// Dwells of the program (G4, cycle dwells), s: part of `cycle_time_s`.
    pub dwell_time_s: f64,
    /// What the reader assumed for `G28`/`G30` where the machine file gives no reference
    /// point (machine zero, the controls' default; the fields to set), else `null`.
    pub reference: Option<String>,
    /// What the reader assumed of the unit of a Fanuc, Sinumerik or LinuxCNC program that selects none
    /// where the machine file gives no `program_units` (mm), else `null`.
    pub units: Option<String>,
}

/// Worst use of one axis's limits in the re-simulation.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct WorstRatio {
    /// Worst |q̇| / limit.
    pub velocity: f64,
    /// Worst |q̈| / limit.
    pub acceleration: f64,
    /// 0 where the axis has no jerk limit.
    pub jerk: f64,
}

fn worst_as_map<S: serde::Serializer>(v: &[(String, WorstRatio)], s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(v.iter().map(|(k, p)| (k, p)))
}

impl Summary {
    /// The summary of `sol`, a solve of `toolpath` (as named in reports) on `machine`.
    pub fn new(machine: &Machine, toolpath: &str, sol: &Solution) -> Summary {
        let names: Vec<&str> = machine.axes.iter().map(|a| a.name.as_str()).collect();
        let na = names.len();
        let mut vel = vec![0.0f64; na];
        let mut acc = vec![0.0f64; na];
        let mut by_bound: BTreeMap<Bound, (f64, f64)> = BTreeMap::new();
        let st = &sol.schedule.stations;
        let mut offset = 0;
        for ((p, s), span) in sol.problems.iter().zip(&sol.solutions).zip(&sol.path.spans) {
            let b = &s.b;
            let jerk = jerk_ratios(machine, span, &sol.kinematics, p, s);
            for i in 0..p.u.len() {
                for (j, axis) in machine.axes.iter().enumerate() {
                    let qd = p.jets.dq(i)[j] * b[i].sqrt();
                    vel[j] = vel[j].max(axis.velocity.ratio(qd));
                }
            }
            for k in 0..p.intervals() {
                for e in [k, k + 1] {
                    for (j, lim) in p.acceleration.iter().enumerate() {
                        acc[j] = acc[j].max(lim.ratio(axis_acceleration(p, s, k, e, j)));
                    }
                }
                let bound = interval_binding(p, s, k, jerk.as_deref());
                let (a, z) = (&st[offset + k], &st[offset + k + 1]);
                let e = by_bound.entry(bound).or_insert((0.0, 0.0));
                e.0 += z.s - a.s;
                e.1 += z.t - a.t;
            }
            offset += p.u.len();
        }
        let length = st.last().map_or(0.0, |s| s.s);
        let deviation = sol.path.deviation();
        let time = sol.schedule.cycle_time;
        let label = |b: Bound| binding_label(b, &names);
        let mut binding: Vec<BindingShare> = by_bound
            .into_iter()
            .map(|(b, (ds, dt))| BindingShare {
                limit: b,
                name: label(b),
                share_of_path: if length > 0.0 { ds / length } else { 0.0 },
                share_of_time: if time > 0.0 { dt / time } else { 0.0 },
            })
            .collect();
        binding.sort_by(|a, b| b.share_of_time.total_cmp(&a.share_of_time));
        Summary {
            machine: machine.name.clone(),
            toolpath: toolpath.to_string(),
            cycle_time_s: time,
            stations: sol.stations(),
            spans: sol.problems.len(),
            status: sol.status,
            iterations: sol.iterations,
            solve_time_s: sol.solve_time,
            path_length_mm: length,
            joint_space: machine.kinematics == crate::machine::KinematicsSpec::Joint,
            max_deviation_mm: deviation.0,
            max_deviation_deg: deviation.1.to_degrees(),
            axes: names
                .iter()
                .enumerate()
                .map(|(j, n)| {
                    (
                        n.to_string(),
                        AxisPeaks {
                            peak_velocity_ratio: vel[j],
                            peak_acceleration_ratio: acc[j],
                        },
                    )
                })
                .collect(),
            binding,
            refinement: sol.refinement.clone(),
            corners_blended: sol.corners_blended,
            error_estimate: sol.error_estimate,
            error_target: sol.error_target,
            unconverged: sol.unconverged.clone(),
            slowed_down: sol.slowed_down.clone(),
            reused_solves: sol.reused_solves,
            verified: sol.verification.verified,
            verify_period_s: sol.verify_period,
            worst_ratio: sol
                .verification
                .worst
                .iter()
                .map(|w| {
                    (
                        w.name.clone(),
                        WorstRatio {
                            velocity: w.velocity,
                            acceleration: w.acceleration,
                            jerk: w.jerk,
                        },
                    )
                })
                .collect(),
            worst_feed_ratio: sol.verification.worst_feed,
            worst_chord_ratio: sol.verification.worst_chord,
            jerk_limited: sol.solutions.iter().any(|s| s.a.is_some()),
            warnings: Vec::new(),
            format: String::new(),
            format_by: String::new(),
            dialect: None,
            dialect_by: None,
            dwell_time_s: 0.0,
            reference: None,
            units: None,
        }
    }

    /// Records the reader used and adds the program's dwells to the cycle time.
    pub fn set_reader(&mut self, detected: &crate::toolpath::Detected, dwell_time_s: f64) {
        self.format = detected.format.name().to_string();
        self.format_by = detected.format_by.to_string();
        self.dialect = detected.dialect.map(|d| d.name().to_string());
        self.dialect_by = detected.dialect.map(|_| detected.dialect_by.to_string());
        self.cycle_time_s += dwell_time_s - self.dwell_time_s;
        self.dwell_time_s = dwell_time_s;
        self.reference = detected.assumed.reference_note();
        self.units = detected.assumed.units_note();
    }
}

fn as_map<S: serde::Serializer>(v: &[(String, AxisPeaks)], s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(v.iter().map(|(k, p)| (k, p)))
}

impl Summary {
    /// Peaks of the axis called `name`.
    pub fn axis(&self, name: &str) -> Option<&AxisPeaks> {
        self.axes.iter().find(|(n, _)| n == name).map(|(_, p)| p)
    }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "toolpath      {}", self.toolpath)?;
        writeln!(f, "machine       {}", self.machine)?;
        if !self.format.is_empty() {
            match &self.dialect {
                Some(d) => writeln!(
                    f,
                    "read as       {} ({}), dialect {d} ({})",
                    self.format,
                    self.format_by,
                    self.dialect_by.as_deref().unwrap_or("")
                )?,
                None => writeln!(f, "read as       {} ({})", self.format, self.format_by)?,
            }
        }
        if let Some(units) = &self.units {
            writeln!(f, "units         {units}")?;
        }
        if let Some(reference) = &self.reference {
            writeln!(f, "reference     {reference}")?;
        }
        if self.dwell_time_s > 0.0 {
            writeln!(
                f,
                "cycle time    {:.4} s (motion {:.4} s + dwells {:.4} s)",
                self.cycle_time_s,
                self.cycle_time_s - self.dwell_time_s,
                self.dwell_time_s
            )?;
        } else {
            writeln!(f, "cycle time    {:.4} s", self.cycle_time_s)?;
        }
        if self.max_deviation_mm > 0.0 || self.max_deviation_deg > 0.0 {
            writeln!(
                f,
                "fitted path   within {:.4} mm and {:.4}° of the programmed path (at and between its points{})",
                self.max_deviation_mm,
                self.max_deviation_deg,
                if self.corners_blended > 0 {
                    "; blended corners apart"
                } else {
                    ""
                }
            )?;
        }
        if self.corners_blended > 0 {
            writeln!(
                f,
                "corners       {} blended within the corner tolerance instead of stopped at",
                self.corners_blended
            )?;
        }
        if self.joint_space {
            writeln!(
                f,
                "path length   {:.6} (the file's parameter s)",
                self.path_length_mm
            )?;
        } else {
            writeln!(f, "path length   {:.3} mm", self.path_length_mm)?;
        }
        let steps: Vec<String> = self
            .refinement
            .iter()
            .map(|r| r.stations.to_string())
            .collect();
        writeln!(
            f,
            "stations      {} in {} span(s) (tried {})",
            self.stations,
            self.spans,
            steps.join(" → ")
        )?;
        match (self.error_estimate, &self.unconverged) {
            (Some(e), Some(why)) => writeln!(
                f,
                "NOT converged estimated within {e:.1e} of the continuous optimum, above the \
                 {:.0e} aimed at: {why}",
                self.error_target.unwrap_or(f64::NAN)
            )?,
            (Some(e), None) => writeln!(
                f,
                "converged     within {e:.1e} of the continuous optimum (estimated from how \
                 each interval's time changed when it was halved)"
            )?,
            (None, _) => {}
        }
        let status = match self.status {
            Status::Optimal => "optimal",
            Status::AlmostOptimal => "almost optimal (reduced accuracy)",
            Status::Greedy => "maximal reachable profile",
        };
        if self.status == Status::Greedy {
            writeln!(
                f,
                "solver        reachability pass: {status}, {:.4} s",
                self.solve_time_s
            )?;
        } else {
            // Jerk limits: the SCP's linear subproblems go to the banded interior-point
            // method, with Clarabel where it does not answer (`solver::jerk::LpSolver`).
            let name = if self.jerk_limited {
                "SCP, banded LP and Clarabel"
            } else {
                "Clarabel"
            };
            writeln!(
                f,
                "solver        {name}: {status}, {} iterations, {:.3} s",
                self.iterations, self.solve_time_s
            )?;
        }
        writeln!(
            f,
            "verified      {} (re-simulated every {} ms: worst ratio to a limit {:.5})",
            if self.verified { "yes" } else { "NO" },
            self.verify_period_s * 1e3,
            self.worst_ratio
                .iter()
                .map(|(_, w)| w.velocity.max(w.acceleration).max(w.jerk))
                .fold(self.worst_feed_ratio.max(self.worst_chord_ratio), f64::max)
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "axis   peak |q̇|/v   peak |q̈|/a   (at stations; re-simulated: |q̇|/v  |q̈|/a{})",
            if self.jerk_limited { "  |q⃛|/j" } else { "" }
        )?;
        for ((name, p), (_, w)) in self.axes.iter().zip(&self.worst_ratio) {
            write!(
                f,
                "{name:<6} {:>10.3}   {:>10.3}                   {:>10.4} {:>7.4}",
                p.peak_velocity_ratio, p.peak_acceleration_ratio, w.velocity, w.acceleration
            )?;
            if self.jerk_limited {
                write!(f, " {:>7.4}", w.jerk)?;
            }
            writeln!(f)?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "limit holding the feed down   share of path   share of time"
        )?;
        for b in &self.binding {
            writeln!(
                f,
                "{:<29} {:>12.1} %  {:>12.1} %",
                b.name,
                100.0 * b.share_of_path,
                100.0 * b.share_of_time
            )?;
        }
        Ok(())
    }
}
