//! `feedopt compare`: several schedules of one toolpath on one machine, side by side, each
//! checked by the same re-simulation.
//!
//! The schedules ([`SCHEDULES`], in table order):
//!
//! - **programmed** — the program's feeds run as they are, constant per block, every change of
//!   feed taken within one servo period ([`baseline::programmed_feed`]);
//! - **controller** — a controller's look-ahead planner: per-block trapezoids with the axes'
//!   limits applied along each block, junction speeds by grbl's junction deviation, backward
//!   and forward passes ([`baseline::plan_controller`]);
//! - **feedopt** — the time-optimal schedule ([`crate::optimize::optimize_input`]),
//!   acceleration-limited;
//! - **feedopt_jerk** — the jerk-limited time-optimal schedule (issue 6), when the machine file
//!   gives jerk limits.
//!
//! **One evaluation for all.** Every schedule is expressed the way feedopt expresses its own:
//! b = u̇² at stations of the same path (feedopt's fitted spans, so every schedule runs on the
//! same geometry), linear in u between stations, so ü is constant there and time follows from
//! eq. 43 exactly. Then:
//!
//! - velocity, acceleration and feed are checked by [`crate::verify::verify`] at the servo
//!   period (1 ms) and at both ends of every interval, the geometry evaluated from the path's
//!   splines — the same check `feedopt solve` passes;
//! - where a schedule passes a corner between two spans at speed (the baselines do; feedopt
//!   stops there), the axes' velocities jump: a servo executes the jump within one period, an
//!   acceleration Δq̇ / T, counted with the accelerations (and a jerk of that pulse);
//! - jerk is the finite difference of the accelerations sampled every period,
//!   (q̈(t + T) − q̈(t)) / T, against the machine's jerk limits where the machine file gives
//!   them.
//!
//! A schedule is *verified* when no ratio exceeds 1.001 (the tolerance of [`crate::verify`]).

pub mod baseline;

use std::fmt;

use crate::constraints::SpanProblem;
use crate::error::{Error, Result};
use crate::kinematics::MAX_AXES;
use crate::machine::Machine;
use crate::motion::Interval;
use crate::optimize::{self, Options, Solution};
use crate::schedule::Schedule;
use crate::solver::interval_times;
use crate::solver::{SpanSolution, Status};
use crate::toolpath::Input;
use crate::verify;

use crate::validate::non_negative;
use baseline::Profile;

/// Options of a comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareOptions {
    /// Options of feedopt's own solve (also: geometry, feed caps, and the servo period and
    /// tolerance of the common re-simulation, `solve.verify`).
    pub solve: Options,
    /// Junction deviation δ of the controller baseline, mm.
    pub junction_deviation: f64,
}

impl Default for CompareOptions {
    fn default() -> Self {
        CompareOptions {
            solve: Options::default(),
            junction_deviation: baseline::DEFAULT_JUNCTION_DEVIATION_MM,
        }
    }
}

/// What every planner sees: the inputs and feedopt's solution (whose path is the common
/// geometry).
pub struct Context<'a> {
    /// The machine.
    pub machine: &'a Machine,
    /// The toolpath or joint-space path.
    pub input: &'a Input,
    /// The comparison's options.
    pub options: &'a CompareOptions,
    /// feedopt's acceleration-limited solution, whose path is the common geometry.
    pub reference: &'a Solution,
}

/// A schedule to evaluate: b = u̇² at the stations of every span of the reference path.
#[derive(Debug, Clone)]
pub struct Candidate {
    /// The reference path's span problems (stations) the schedule is given on.
    pub problems: Vec<SpanProblem>,
    /// b (and ü) at those stations, per span.
    pub solutions: Vec<SpanSolution>,
    /// Figures of the planner worth printing (e.g. a closed-form time).
    pub notes: Vec<String>,
}

/// A planner: the schedule, or the reason it does not apply to this input.
pub type Planner = fn(&Context) -> Result<std::result::Result<Candidate, String>>;

/// One schedule of the comparison.
pub struct Entry {
    /// Short key (JSON, column heading).
    pub key: &'static str,
    /// What it is.
    pub label: &'static str,
    /// Computes the schedule.
    pub plan: Planner,
}

/// The schedules compared, in table order: adding one is adding a line here.
pub const SCHEDULES: &[Entry] = &[
    Entry {
        key: "programmed",
        label: "(a) programmed feed, constant per block",
        plan: programmed,
    },
    Entry {
        key: "controller",
        label: "(b) controller: per-block trapezoids, junction deviation",
        plan: controller,
    },
    Entry {
        key: "feedopt",
        label: "(c) feedopt time-optimal (acceleration-limited)",
        plan: time_optimal,
    },
    Entry {
        key: "feedopt_jerk",
        label: "(d) feedopt time-optimal, jerk-limited",
        plan: jerk_limited,
    },
];

fn programmed(ctx: &Context) -> Result<std::result::Result<Candidate, String>> {
    if let Input::Joint(_) = ctx.input {
        return Ok(Err("a joint-space path has no programmed feed".into()));
    }
    let profile = baseline::programmed_feed(
        ctx.machine,
        &ctx.reference.path,
        &ctx.reference.kinematics,
        ctx.options.solve.verify.period,
    )?;
    Ok(profile.map(|p| realize(ctx, &p, Vec::new())))
}

fn controller(ctx: &Context) -> Result<std::result::Result<Candidate, String>> {
    let plan = baseline::plan_controller(
        ctx.machine,
        &ctx.reference.path,
        &ctx.reference.kinematics,
        ctx.options.junction_deviation,
    )?;
    let at_speed = plan
        .blocks
        .windows(2)
        .filter(|w| w[0].block.span != w[1].block.span && w[1].entry > 0.0)
        .count();
    let notes = vec![
        format!(
            "planned time {:.4} s (closed form), junction deviation {} mm",
            plan.time(),
            plan.junction_deviation
        ),
        format!("{at_speed} corner(s) between spans passed at speed"),
    ];
    Ok(Ok(realize(ctx, &plan.profile(&ctx.reference.path), notes)))
}

fn time_optimal(ctx: &Context) -> Result<std::result::Result<Candidate, String>> {
    let r = ctx.reference;
    let solver = match r.status {
        Status::Greedy => "reachability pass",
        _ => "Clarabel",
    };
    Ok(Ok(Candidate {
        problems: r.problems.clone(),
        solutions: r.solutions.clone(),
        notes: vec![format!("{} stations, {solver}", r.stations())],
    }))
}

/// (d): the jerk-limited optimum on the same path (issue 6), when the machine file gives jerk
/// limits.
fn jerk_limited(ctx: &Context) -> Result<std::result::Result<Candidate, String>> {
    if !ctx.machine.has_jerk() {
        return Ok(Err("the machine file gives no jerk limits".into()));
    }
    let options = Options {
        jerk_limited: true,
        solver_kind: crate::solver::SolverKind::Clarabel,
        ..ctx.options.solve.clone()
    };
    let r = optimize::optimize_input(ctx.machine, ctx.input, &options)?;
    Ok(Ok(Candidate {
        problems: r.problems,
        solutions: r.solutions,
        notes: vec![format!(
            "{} stations, Clarabel SCP, {} interior-point iterations",
            r.schedule.stations.len(),
            r.iterations
        )],
    }))
}

/// A profile as stations of the reference path: every breakpoint, and each breakpoint
/// interval divided in four (so plots show √b's curve; b stays exactly linear).
fn realize(ctx: &Context, profile: &Profile, notes: Vec<String>) -> Candidate {
    const PARTS: usize = 4;
    let path = &ctx.reference.path;
    let kin = &ctx.reference.kinematics;
    let mut problems = Vec::with_capacity(path.spans.len());
    let mut solutions = Vec::with_capacity(path.spans.len());
    for (span, pts) in path.spans.iter().zip(&profile.spans) {
        // Merge breakpoints closer than rounding (the later one wins).
        let gap = 1e-12 * (1.0 + span.length());
        let mut bp: Vec<(f64, f64)> = Vec::with_capacity(pts.len());
        for &(u, b) in pts {
            match bp.last_mut() {
                Some(last) if u <= last.0 + gap => last.1 = b,
                _ => bp.push((u, b)),
            }
        }
        if let Some(last) = bp.last_mut() {
            last.0 = span.length();
        }
        let mut u = Vec::with_capacity(PARTS * bp.len());
        let mut b = Vec::with_capacity(PARTS * bp.len());
        for w in bp.windows(2) {
            for p in 0..PARTS {
                let f = p as f64 / PARTS as f64;
                u.push(w[0].0 + f * (w[1].0 - w[0].0));
                b.push((w[0].1 + f * (w[1].1 - w[0].1)).max(0.0));
            }
        }
        if let Some(&(ul, bl)) = bp.last() {
            u.push(ul);
            b.push(bl.max(0.0));
        }
        problems.push(SpanProblem::at_stations(span, kin, ctx.machine, u));
        solutions.push(SpanSolution {
            ends: None,
            a: None,
            slopes: None,
            b,
            status: Status::Greedy,
            iterations: 0,
            solve_time: 0.0,
            scp_iterations: 0,
        });
    }
    Candidate {
        problems,
        solutions,
        notes,
    }
}

/// One axis's worst use of its limits in one schedule.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct AxisRow {
    /// Axis name.
    pub name: String,
    /// Worst |q̇| / limit.
    pub velocity: f64,
    /// Worst |q̈| / limit (velocity jumps at corners counted as Δq̇ / T).
    pub acceleration: f64,
    /// Worst |jerk| / limit; `None` when the machine file gives no jerk limit for the axis.
    pub jerk: Option<f64>,
    /// Largest |jerk| (mm/s³ or °/s³), by finite differences of the sampled accelerations.
    pub peak_jerk: f64,
}

/// One schedule's figures.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Short key (JSON, column heading).
    pub key: String,
    /// What the schedule is.
    pub label: String,
    /// Cycle time, s, the program's dwells included (the same in every row), as `solve`
    /// reports it.
    pub cycle_time_s: f64,
    /// Every ratio ≤ 1 + tolerance (1.001).
    pub verified: bool,
    /// The largest ratio to any limit, and which limit.
    pub worst_ratio: f64,
    /// The limit of `worst_ratio` (e.g. `X acceleration`).
    pub worst_limit: String,
    /// Largest V / feed cap.
    pub worst_feed_ratio: f64,
    /// Every axis's worst use of its limits.
    pub axes: Vec<AxisRow>,
    /// Corners between spans passed at speed (velocity jumps executed in one servo period).
    pub corners_at_speed: usize,
    /// The largest ratio of such a jump's acceleration Δq̇ / T to an axis's limit (0: none).
    pub worst_corner_ratio: f64,
    /// Figures of the planner worth printing.
    pub notes: Vec<String>,
    /// The schedule itself (stations with s, t, V, every axis's motion).
    #[serde(skip)]
    pub schedule: Schedule,
}

/// A schedule that does not apply to the input, and why.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Omitted {
    /// The schedule's key.
    pub key: String,
    /// Why it does not apply.
    pub reason: String,
}

/// The comparison: what `feedopt compare` prints.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Comparison {
    /// The machine's name.
    pub machine: String,
    /// The toolpath as named on the command line.
    pub toolpath: String,
    /// Servo period of the re-simulation, s.
    pub period_s: f64,
    /// Junction deviation δ of the controller baseline, mm.
    pub junction_deviation_mm: f64,
    /// Whether lengths and feeds are in the joint-space path's parameter s.
    pub joint_space: bool,
    /// The program's dwells (G4, cycle dwells), s: part of every row's cycle time.
    pub dwell_time_s: f64,
    /// The schedules compared, in table order.
    pub schedules: Vec<Row>,
    /// The schedules that do not apply to this input.
    pub omitted: Vec<Omitted>,
}

impl Comparison {
    /// The row of schedule `key`.
    pub fn row(&self, key: &str) -> Option<&Row> {
        self.schedules.iter().find(|r| r.key == key)
    }
}

/// Runs every schedule of [`SCHEDULES`] on `input` and evaluates each by the common
/// re-simulation.
pub fn compare(
    machine: &Machine,
    input: &Input,
    toolpath_name: &str,
    options: &CompareOptions,
) -> Result<Comparison> {
    options.validate()?;
    optimize::check_inputs(machine, &options.solve).map_err(|e| e.within("solve"))?;
    // The reference (c) is acceleration-limited; (d) adds the jerk limits.
    let accel_only = Options {
        jerk_limited: false,
        ..options.solve.clone()
    };
    let reference = optimize::optimize_input(machine, input, &accel_only)?;
    let ctx = Context {
        machine,
        input,
        options,
        reference: &reference,
    };
    let mut schedules = Vec::new();
    let mut omitted = Vec::new();
    for entry in SCHEDULES {
        match (entry.plan)(&ctx)? {
            Ok(c) => schedules.push(evaluate(&ctx, entry, c)?),
            Err(reason) => omitted.push(Omitted {
                key: entry.key.to_string(),
                reason,
            }),
        }
    }
    Ok(Comparison {
        machine: machine.name.clone(),
        toolpath: toolpath_name.to_string(),
        period_s: options.solve.verify.period,
        junction_deviation_mm: options.junction_deviation,
        joint_space: machine.kinematics == crate::machine::KinematicsSpec::Joint,
        dwell_time_s: dwell_time(input),
        schedules,
        omitted,
    })
}

/// The program's dwell time, s (none on a joint-space path).
fn dwell_time(input: &Input) -> f64 {
    match input {
        Input::Cl(t) => t.dwell_time(),
        Input::Joint(_) => 0.0,
    }
}

/// The common evaluation of one schedule.
fn evaluate(ctx: &Context, entry: &Entry, c: Candidate) -> Result<Row> {
    let path = &ctx.reference.path;
    let kin = &ctx.reference.kinematics;
    let vopt = ctx.options.solve.verify;
    let v = verify::verify(
        ctx.machine,
        kin,
        &path.spans,
        &c.problems,
        &c.solutions,
        &vopt,
    )?;
    let d = dynamics(ctx, &c)?;
    let names: Vec<String> = ctx.machine.axes.iter().map(|a| a.name.clone()).collect();
    let schedule = Schedule::build(&names, &path.spans, &c.problems, &c.solutions)?;
    let mut worst = (v.worst_feed, "feed".to_string());
    let axes: Vec<AxisRow> = v
        .worst
        .iter()
        .enumerate()
        .map(|(j, w)| {
            let acceleration = w.acceleration.max(d.junction_acceleration[j]);
            let jerk = ctx.machine.axes[j].jerk.map(|_| d.jerk_ratio[j]);
            for (x, what) in [
                (w.velocity, "velocity"),
                (acceleration, "acceleration"),
                (jerk.unwrap_or(0.0), "jerk"),
            ] {
                if x > worst.0 {
                    worst = (x, format!("{} {what}", w.name));
                }
            }
            AxisRow {
                name: w.name.clone(),
                velocity: w.velocity,
                acceleration,
                jerk,
                peak_jerk: d.peak_jerk[j],
            }
        })
        .collect();
    Ok(Row {
        key: entry.key.to_string(),
        label: entry.label.to_string(),
        cycle_time_s: schedule.cycle_time + dwell_time(ctx.input),
        verified: worst.0 <= 1.0 + vopt.tolerance,
        worst_ratio: worst.0,
        worst_limit: worst.1,
        worst_feed_ratio: v.worst_feed,
        axes,
        corners_at_speed: d.corners_at_speed,
        worst_corner_ratio: d.junction_acceleration.iter().copied().fold(0.0, f64::max),
        notes: c.notes,
        schedule,
    })
}

/// What the sampled accelerations show beyond [`verify::verify`]'s check.
struct Dynamics {
    /// Per axis: largest |jerk| and its largest ratio to the jerk limit (0 without one).
    peak_jerk: Vec<f64>,
    jerk_ratio: Vec<f64>,
    /// Per axis: largest ratio of a corner's velocity jump, executed in one period, to the
    /// acceleration limit.
    junction_acceleration: Vec<f64>,
    corners_at_speed: usize,
}

/// Samples every axis's acceleration at the servo instants of one global clock (as
/// [`verify::verify`] does: within an interval ü is constant, `√b(t) = √b_i + ü (t − t_i)`,
/// the geometry evaluated from the span's spline at each sample), and takes jerk as the
/// difference of successive samples over the period. At a corner between spans passed at
/// speed, the axes' velocity jump Δq̇ becomes one period's acceleration pulse Δq̇ / T.
///
/// The instants and the motion at each come from verify's own sampler
/// (`verify::servo_instants`), here at every instant (the differences need successive ones);
/// eq. 43's interval times ([`interval_times`]) and the kinematics
/// ([`crate::kinematics::Kinematics::axis_jets`]) are the ones every other check uses.
fn dynamics(ctx: &Context, c: &Candidate) -> Result<Dynamics> {
    let (machine, kin) = (ctx.machine, &ctx.reference.kinematics);
    let (spans, problems, solutions) = (&ctx.reference.path.spans, &c.problems, &c.solutions);
    let period = ctx.options.solve.verify.period;
    let na = kin.n_axes().min(machine.axes.len());
    let mut d = Dynamics {
        peak_jerk: vec![0.0; na],
        jerk_ratio: vec![0.0; na],
        junction_acceleration: vec![0.0; na],
        corners_at_speed: 0,
    };
    let mut prev: Option<[f64; MAX_AXES]> = None;
    let jerk = |d: &mut Dynamics, prev: &Option<[f64; MAX_AXES]>, qdd: &[f64; MAX_AXES]| {
        if let Some(p) = prev {
            for j in 0..na {
                let x = (qdd[j] - p[j]) / period;
                d.peak_jerk[j] = d.peak_jerk[j].max(x.abs());
                if let Some(lim) = machine.axes[j].jerk {
                    d.jerk_ratio[j] = d.jerk_ratio[j].max(lim.ratio(x));
                }
            }
        }
    };
    let mut qd_end: Option<[f64; MAX_AXES]> = None; // axis velocities where the last span ended
    let mut t0 = 0.0f64;
    for (span, (p, sol)) in spans.iter().zip(problems.iter().zip(solutions)) {
        let b = &sol.b;
        if b.len() != p.u.len() || b.len() < 2 {
            return Err(Error::Usage(
                "compare: stations and b differ in length".into(),
            ));
        }
        let dt = interval_times(p, sol)?;
        let jets_at = |u: f64| kin.axis_jets(&span.eval(u));
        // A corner passed at speed: the velocity jump as one period's acceleration.
        if let Some(before) = qd_end {
            let start = p.jets.view(0);
            let r = b[0].max(0.0).sqrt();
            let mut pulse = [0.0; MAX_AXES];
            let mut jump = false;
            for j in 0..na {
                let dv = start.dq[j] * r - before[j];
                jump |= dv != 0.0;
                pulse[j] = dv / period;
                let x = machine.axes[j].acceleration.ratio(pulse[j]);
                d.junction_acceleration[j] = d.junction_acceleration[j].max(x);
            }
            if jump {
                d.corners_at_speed += 1;
                jerk(&mut d, &prev, &pulse);
                prev = Some(pulse);
            }
        }
        let mut jj = verify::first_instant(t0, period);
        let mut ta = t0;
        for i in 0..p.intervals() {
            let iv = Interval::of(&p.u, b, sol.shape(), i);
            jj = verify::servo_instants(
                &iv,
                (p.u[i], p.u[i + 1]),
                (ta, dt[i]),
                jj,
                period,
                None,
                |_, st, u| {
                    let w = jets_at(u);
                    let mut qdd = [0.0; MAX_AXES];
                    for j in 0..na {
                        qdd[j] = w.ddq[j] * st.b + w.dq[j] * st.udd;
                    }
                    jerk(&mut d, &prev, &qdd);
                    prev = Some(qdd);
                },
            );
            ta += dt[i];
        }
        let n = p.intervals();
        let r = b[n].max(0.0).sqrt();
        let mut end = [0.0; MAX_AXES];
        for j in 0..na {
            end[j] = p.jets.dq(n)[j] * r;
        }
        qd_end = Some(end);
        t0 = ta;
    }
    Ok(d)
}

impl fmt::Display for Comparison {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "toolpath      {}", self.toolpath)?;
        writeln!(f, "machine       {}", self.machine)?;
        writeln!(
            f,
            "re-simulated  every {} ms on the fitted path (verified: every ratio ≤ 1.001)",
            self.period_s * 1e3
        )?;
        writeln!(f)?;
        for r in &self.schedules {
            writeln!(f, "{:<11} {}", r.key, r.label)?;
            for n in &r.notes {
                writeln!(f, "{:<11}   {n}", "")?;
            }
        }
        for o in &self.omitted {
            writeln!(f, "{:<11} omitted: {}", o.key, o.reason)?;
        }
        writeln!(f)?;
        const W: usize = 16;
        let head = |f: &mut fmt::Formatter<'_>, name: &str| write!(f, "{name:<24}");
        head(f, "")?;
        for r in &self.schedules {
            write!(f, "{:>W$}", r.key)?;
        }
        writeln!(f)?;
        let line = |f: &mut fmt::Formatter<'_>, name: &str, cells: Vec<String>| {
            head(f, name)?;
            for c in cells {
                write!(f, "{c:>W$}")?;
            }
            writeln!(f)
        };
        let rows = &self.schedules;
        line(
            f,
            "cycle time (s)",
            rows.iter()
                .map(|r| format!("{:.4}", r.cycle_time_s))
                .collect(),
        )?;
        line(
            f,
            "verified",
            rows.iter()
                .map(|r| if r.verified { "yes" } else { "NO" }.to_string())
                .collect(),
        )?;
        line(
            f,
            "worst ratio",
            rows.iter().map(|r| ratio(r.worst_ratio)).collect(),
        )?;
        line(
            f,
            "  at",
            rows.iter().map(|r| r.worst_limit.clone()).collect(),
        )?;
        line(
            f,
            "feed / cap",
            rows.iter().map(|r| ratio(r.worst_feed_ratio)).collect(),
        )?;
        line(
            f,
            "corners at speed",
            rows.iter()
                .map(|r| r.corners_at_speed.to_string())
                .collect(),
        )?;
        line(
            f,
            "  worst jump Δq̇/T / a",
            rows.iter().map(|r| ratio(r.worst_corner_ratio)).collect(),
        )?;
        let na = rows.first().map_or(0, |r| r.axes.len());
        for j in 0..na {
            let name = &rows[0].axes[j].name;
            line(
                f,
                &format!("{name} velocity / limit"),
                rows.iter().map(|r| ratio(r.axes[j].velocity)).collect(),
            )?;
            line(
                f,
                &format!("{name} accel. / limit"),
                rows.iter().map(|r| ratio(r.axes[j].acceleration)).collect(),
            )?;
            line(
                f,
                &format!("{name} jerk / limit"),
                rows.iter()
                    .map(|r| r.axes[j].jerk.map_or("–".to_string(), ratio))
                    .collect(),
            )?;
        }
        Ok(())
    }
}

/// A ratio to print: four significant digits near 1, fewer for large excesses.
fn ratio(x: f64) -> String {
    if !x.is_finite() {
        "∞".to_string()
    } else if x < 10.0 {
        format!("{x:.4}")
    } else if x < 1000.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.3e}")
    }
}

impl CompareOptions {
    /// Checks the solve options (fields under `solve.`) and the junction deviation
    /// ([`crate::validate`]). [`compare`] calls it before any work.
    pub fn validate(&self) -> Result<()> {
        self.solve.validate().map_err(|e| e.within("solve"))?;
        non_negative("junction_deviation", self.junction_deviation, "mm")
    }
}
