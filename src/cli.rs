//! The command line: argument parsing into options, and one function per subcommand.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::error::{Error, Result};
use crate::machine::Machine;
use crate::optimize::{self, Options};
use crate::report::Summary;
use crate::solver::SolverKind;
use crate::{toolpath, writers};

/// feedopt: time-optimal feedrate along CNC toolpaths.
#[derive(Debug, Parser)]
#[command(version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Compute the time-optimal feed profile of a toolpath on a machine.
    Solve(SolveArgs),
    /// Solve, then write the toolpath back as G-code with the optimised feed per block.
    Gcode(GcodeArgs),
    /// Solve, then sample every axis's setpoint at a fixed interpolation period.
    Interpolate(InterpolateArgs),
    /// Compare schedules on one toolpath: the programmed feed, a controller's planner and
    /// feedopt's time-optimal schedule, all re-simulated alike.
    Compare(CompareArgs),
    /// Constraint study: cycle time and its sensitivity against one axis limit.
    Sweep(SweepArgs),
}

#[derive(Debug, Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub solve: SolveArgs,
    /// Junction deviation δ of the controller baseline, mm (grbl's `$11`): how far the
    /// virtual arc through a corner may pass from the corner point.
    #[arg(long, default_value_t = crate::compare::baseline::DEFAULT_JUNCTION_DEVIATION_MM, value_name = "MM")]
    pub junction_deviation: f64,
}

#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Machine, toolpath, --json, -o (here: the sweep table as FILE.csv or FILE.json) and the
    /// solve options. `--stations N` fixes the stations of every step; without it they are
    /// refined once at the machine's own limits (with the reachability pass) and then fixed.
    #[command(flatten)]
    pub solve: SolveArgs,
    /// Axis whose limit is swept, as named in the machine file (e.g. C).
    #[arg(long)]
    pub axis: String,
    /// Which limit: velocity or acceleration. An asymmetric limit is scaled proportionally so
    /// that its max is the value.
    #[arg(long, value_enum)]
    pub limit: crate::sweep::SweptLimit,
    /// First limit value (mm/s, mm/s², deg/s or deg/s²), within 1/1000 to 1000 times the
    /// machine's own.
    #[arg(long)]
    pub from: f64,
    /// Last limit value.
    #[arg(long)]
    pub to: f64,
    /// Number of values from --from to --to, evenly spaced (at most 10,000).
    #[arg(long, default_value_t = 20)]
    pub steps: usize,
    /// Relative step of the central finite differences of the cycle time.
    #[arg(long, default_value_t = 0.01)]
    pub fd_step: f64,
}

#[derive(Debug, Args)]
pub struct SolveArgs {
    /// Machine file (JSON: kinematics, axis limits, maximum feed).
    #[arg(long, short)]
    pub machine: PathBuf,
    /// Toolpath file (APT CL: .cls, .apt; joint-space CSV: .csv).
    pub toolpath: PathBuf,
    /// Print one JSON object with the summary instead of the readable report.
    #[arg(long)]
    pub json: bool,
    /// Write the full schedule (per station: u, s, t, V, A and every axis's q, q̇, q̈) to
    /// FILE.json or FILE.csv (sweep: the sweep table).
    #[arg(long, short, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Plot the schedule to FILE.svg: feed against path length, coloured by the limit holding
    /// it down, with the limits; every axis's velocity and acceleration over its limit against
    /// time (`compare`: every schedule's feed against path length; `sweep`: cycle time and
    /// sensitivity against the limit).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Total station count, 2 to 4,000,000 (default: refined automatically until doubling
    /// changes the cycle time by less than 0.01 %).
    #[arg(long)]
    pub stations: Option<usize>,
    /// Turning angle between CL moves (degrees) above which the path stops exactly.
    #[arg(long, default_value_t = 10.0)]
    pub corner_angle: f64,
    /// How far the fitted path may stray from the programmed tool-tip positions, mm (0: through
    /// every point exactly).
    #[arg(long, default_value_t = 0.005, value_name = "MM")]
    pub tolerance: f64,
    /// How far the fitted rotary angles may stray from the programmed ones, degrees.
    #[arg(long, default_value_t = 0.01, value_name = "DEG")]
    pub tolerance_deg: f64,
    /// Cap every programmed feed at this multiple of it (a feed override), 0.001 to 1000.
    #[arg(long, default_value_t = 1.0, value_name = "FACTOR")]
    pub feed_override: f64,
    /// Ignore the program's feeds: what do the machine's limits alone allow?
    #[arg(long)]
    pub ignore_programmed_feed: bool,
    /// Input format instead of the file's extension: apt, gcode or csv.
    #[arg(long, value_enum)]
    pub format: Option<FormatChoice>,
    /// G-code dialect: linuxcnc, fanuc, sinumerik or heidenhain (default: detected from the
    /// program).
    #[arg(long)]
    pub dialect: Option<crate::toolpath::gcode::Dialect>,
    /// Read a machine builder's (or a post's) Sinumerik cycle as the standard one it works
    /// like: `--cycle-alias CYCLE76=CYCLE86` (repeatable; the target one of CYCLE81–CYCLE89).
    #[arg(long = "cycle-alias", value_name = "FROM=TO")]
    pub cycle_alias: Vec<String>,
    /// Solver: `clarabel` (convex, the optimum of the discretisation) or `reach` (the O(N)
    /// reachability pass: within O(Δu²) of it, much faster).
    #[arg(long, value_enum, default_value_t = SolverChoice::Clarabel)]
    pub solver: SolverChoice,
    /// Tool-tip feed at the start of the path, mm/s (default: at rest); at most feed.max.
    #[arg(long, default_value_t = 0.0, value_name = "MM_PER_S")]
    pub start_feed: f64,
    /// Tool-tip feed at the end of the path, mm/s (default: at rest); at most feed.max.
    #[arg(long, default_value_t = 0.0, value_name = "MM_PER_S")]
    pub end_feed: f64,
    /// Bound the chord error of each interpolation period (`--period`) by this, mm (seed 004:
    /// V² ≤ 8δ/(κT²) on a path of curvature κ), checked by the re-simulation; ≥ 1e-6 mm.
    #[arg(long, value_name = "MM")]
    pub chord_tolerance: Option<f64>,
    /// Ignore the machine file's jerk limits: an acceleration-limited schedule.
    #[arg(long)]
    pub no_jerk: bool,
    /// Servo period of the re-simulation that checks every schedule: `1ms`, `500us`, `0.002`
    /// (seconds); 1 µs to 1 s.
    #[arg(long, default_value = "1ms", value_parser = parse_period)]
    pub period: f64,
}

/// A duration: a number of seconds, or with unit `s`, `ms` or `us`.
fn parse_period(text: &str) -> std::result::Result<f64, String> {
    let t = text.trim();
    let (num, scale) = if let Some(n) = t.strip_suffix("us") {
        (n, 1e-6)
    } else if let Some(n) = t.strip_suffix("ms") {
        (n, 1e-3)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1.0)
    } else {
        (t, 1.0)
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * scale),
        _ => Err(format!(
            "`{text}` is not a positive duration (e.g. 1ms, 500us, 0.002)"
        )),
    }
}

/// `--format` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FormatChoice {
    Apt,
    Gcode,
    Csv,
}

/// `--solver` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SolverChoice {
    Clarabel,
    Reach,
}

/// The shortest servo period (`--period`) feedopt re-simulates at: 1 µs. The re-simulation's
/// work is the cycle time divided by the period.
pub const MIN_PERIOD_S: f64 = 1e-6;

/// The longest servo period: 1 s.
pub const MAX_PERIOD_S: f64 = 1.0;

/// The smallest chord tolerance (`--chord-tolerance`): 1 nm, below any machine's resolution.
pub const MIN_CHORD_TOLERANCE_MM: f64 = 1e-6;

/// The largest start or end feed (`--start-feed`, `--end-feed`): 1e6 mm/s (1 km/s).
pub const MAX_END_FEED: f64 = 1e6;

/// The range of `--feed-override`: a factor below 0.001 slows the feed to a crawl (and the
/// re-simulation's work grows with the cycle time); above 1000 it caps nothing.
pub const MIN_FEED_OVERRIDE: f64 = 1e-3;
pub const MAX_FEED_OVERRIDE: f64 = 1e3;

/// The smallest rotation per block (`gcode --max-rotation-deg`): 0.001°, a rotary axis's
/// resolution; smaller steps only multiply the program's blocks.
pub const MIN_ROTATION_DEG: f64 = 1e-3;

impl SolveArgs {
    /// The inputs an output must not overwrite.
    fn inputs(&self) -> [(&'static str, &std::path::Path); 2] {
        [
            ("machine file", self.machine.as_path()),
            ("toolpath", self.toolpath.as_path()),
        ]
    }

    fn options(&self) -> Result<Options> {
        if !(self.corner_angle.is_finite() && self.corner_angle > 0.0 && self.corner_angle < 180.0)
        {
            return Err(Error::Usage(format!(
                "--corner-angle must be between 0 and 180 degrees, got {}",
                self.corner_angle
            )));
        }
        let max_stations = Options::default().max_stations;
        match self.stations {
            Some(n) if n < 2 => {
                return Err(Error::Usage("--stations must be at least 2".into()));
            }
            Some(n) if n > max_stations => {
                return Err(Error::Usage(format!(
                    "--stations {n} is more than the limit of {max_stations} (memory and time \
                     grow with it): give at most {max_stations}, or leave it out to refine \
                     automatically"
                )));
            }
            _ => {}
        }
        if !(MIN_PERIOD_S..=MAX_PERIOD_S).contains(&self.period) {
            return Err(Error::Usage(format!(
                "--period {} s is outside {MIN_PERIOD_S:e} s to {MAX_PERIOD_S} s (1 µs to 1 s; \
                 the re-simulation takes cycle time ÷ period steps): give e.g. 1ms or 250us",
                crate::error::number(self.period)
            )));
        }
        for (option, feed) in [
            ("--start-feed", self.start_feed),
            ("--end-feed", self.end_feed),
        ] {
            if !(feed.is_finite() && (0.0..=MAX_END_FEED).contains(&feed)) {
                return Err(Error::Usage(format!(
                    "{option} {} mm/s is outside 0 to {MAX_END_FEED:e} mm/s: give the \
                     tool-tip feed in mm/s (0: at rest)",
                    crate::error::number(feed)
                )));
            }
        }
        if let Some(out) = &self.output {
            writers::schedule_format(out)?;
            writers::check_output("-o", out, &self.inputs())?;
        }
        if let Some(plot) = &self.plot {
            writers::plot::plot_format(plot)?;
            writers::check_output("--plot", plot, &self.inputs())?;
        }
        let mut o = Options {
            stations: self.stations,
            solver_kind: match self.solver {
                SolverChoice::Clarabel => SolverKind::Clarabel,
                SolverChoice::Reach => SolverKind::Reach,
            },
            start_feed: self.start_feed,
            end_feed: self.end_feed,
            verify: crate::verify::VerifyOptions {
                period: self.period,
                chord: match self.chord_tolerance {
                    None => None,
                    Some(d) if d.is_finite() && d >= MIN_CHORD_TOLERANCE_MM => {
                        Some(crate::constraints::Chord {
                            tolerance: d,
                            period: self.period,
                        })
                    }
                    Some(d) => {
                        return Err(Error::Usage(format!(
                            "--chord-tolerance {} mm: give a chord tolerance of at least \
                             {MIN_CHORD_TOLERANCE_MM:e} mm (1 nm; smaller ones only slow the \
                             feed to a crawl)",
                            crate::error::number(d)
                        )));
                    }
                },
                ..Default::default()
            },
            jerk_limited: !self.no_jerk,
            ..Options::default()
        };
        o.geometry.corner_angle_deg = self.corner_angle;
        if !(self.tolerance >= 0.0 && self.tolerance_deg >= 0.0) {
            return Err(Error::Usage(
                "--tolerance and --tolerance-deg must be ≥ 0".into(),
            ));
        }
        if !(MIN_FEED_OVERRIDE..=MAX_FEED_OVERRIDE).contains(&self.feed_override) {
            return Err(Error::Usage(format!(
                "--feed-override {}: give a factor from {MIN_FEED_OVERRIDE} to \
                 {MAX_FEED_OVERRIDE} (1: the programmed feeds)",
                crate::error::number(self.feed_override)
            )));
        }
        o.geometry.feed_override = self.feed_override;
        o.geometry.ignore_programmed_feed = self.ignore_programmed_feed;
        o.geometry.tolerance_mm = self.tolerance;
        o.geometry.tolerance_deg = self.tolerance_deg;
        Ok(o)
    }

    /// The start and end feeds against the machine's maximum feed (checked before solving).
    fn check_feeds(&self, machine: &Machine) -> Result<()> {
        let Some(max) = machine.feed_max else {
            return Ok(());
        };
        for (option, feed) in [
            ("--start-feed", self.start_feed),
            ("--end-feed", self.end_feed),
        ] {
            if feed > max {
                return Err(Error::Usage(format!(
                    "{option} {} mm/s is more than the machine's maximum feed (feed.max = \
                     {max} mm/s in {}): give at most {max} mm/s",
                    crate::error::number(feed),
                    self.machine.display()
                )));
            }
        }
        Ok(())
    }

    /// The machine file, read and checked against these options.
    fn machine(&self) -> Result<Machine> {
        let machine = Machine::from_file(&self.machine)?;
        self.check_feeds(&machine)?;
        Ok(machine)
    }
}

/// A spinner on stderr with the solve's stage and refinement rounds: drawn only when stderr is
/// a terminal, and only once the solve has run for a second (short solves print nothing).
struct Bar {
    bar: indicatif::ProgressBar,
    start: std::time::Instant,
    shown: std::sync::atomic::AtomicBool,
}

impl Bar {
    fn new() -> Bar {
        let bar = indicatif::ProgressBar::hidden();
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {elapsed:>4} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
        );
        Bar {
            bar,
            start: std::time::Instant::now(),
            shown: std::sync::atomic::AtomicBool::new(false),
        }
    }

    fn show(&self, msg: String) {
        use std::io::IsTerminal;
        self.bar.set_message(msg);
        if self.start.elapsed().as_secs_f64() >= 1.0
            && std::io::stderr().is_terminal()
            && !self.shown.swap(true, std::sync::atomic::Ordering::Relaxed)
        {
            self.bar
                .set_draw_target(indicatif::ProgressDrawTarget::stderr());
            self.bar
                .enable_steady_tick(std::time::Duration::from_millis(120));
        }
    }
}

impl optimize::Progress for Bar {
    fn stage(&self, what: &str) {
        self.show(what.to_string());
    }
    fn round(&self, stations: usize, estimate: f64, target: f64) {
        self.show(format!(
            "refining stations: {stations}, estimated error {estimate:.1e} (target {target:.0e})"
        ));
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// Solves with a progress bar on a terminal.
fn solve_with_progress(
    machine: &Machine,
    input: &toolpath::Input,
    options: &Options,
) -> Result<optimize::Solution> {
    let bar = Bar::new();
    optimize::optimize_input_observed(machine, input, options, &bar)
}

/// `feedopt solve`: returns what to print on stdout.
pub fn solve(args: &SolveArgs) -> Result<String> {
    let options = args.options()?;
    let machine = args.machine()?;
    let (input, warnings, detected) = read_input(args)?;
    let solution = solve_with_progress(&machine, &input, &options)?;
    let dwell = match &input {
        toolpath::Input::Cl(t) => t.dwell_time(),
        toolpath::Input::Joint(_) => 0.0,
    };
    if let Some(out) = &args.output {
        writers::write_schedule(out, &solution.schedule)?;
    }
    if let Some(plot) = &args.plot {
        writers::plot::write_solution_plot(
            plot,
            &args.toolpath.display().to_string(),
            &machine,
            &solution,
        )?;
    }
    let mut summary = Summary::new(&machine, &args.toolpath.display().to_string(), &solution);
    summary.warnings = warnings;
    summary.set_reader(&detected, dwell);
    Ok(if args.json {
        let mut s = serde_json::to_string_pretty(&summary)
            .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
        s.push('\n');
        s
    } else {
        summary.to_string()
    })
}

/// Reads the toolpath of `args`; its reader's warnings are printed on stderr and returned, with
/// what reader was used and what it assumed.
fn read_input(args: &SolveArgs) -> Result<(toolpath::Input, Vec<String>, toolpath::Detected)> {
    let format = args.format.map(|f| match f {
        FormatChoice::Apt => toolpath::Format::Apt,
        FormatChoice::Gcode => toolpath::Format::Gcode,
        FormatChoice::Csv => toolpath::Format::Csv,
    });
    let (_, references) = Machine::references_from_file(&args.machine)?;
    let machine = Machine::from_file(&args.machine)?;
    let cycle_aliases = args
        .cycle_alias
        .iter()
        .map(|a| toolpath::gcode::parse_cycle_alias(a))
        .collect::<Result<Vec<_>>>()?;
    let options = toolpath::ReadOptions {
        format,
        dialect: args.dialect,
        machine: Some(toolpath::MachineContext::new(&machine, &references)),
        cycle_aliases,
    };
    let (input, detected) = toolpath::read_with(&args.toolpath, &options)?;
    // What the reader skipped or doubted: one line each on stderr, and in the summary.
    let warnings: Vec<String> = match &input {
        toolpath::Input::Cl(t) => t
            .warnings
            .iter()
            .map(|w| {
                let text = format!("{}:{}: {}", args.toolpath.display(), w.line, w.message);
                crate::files::escape_control(&text)
            })
            .collect(),
        toolpath::Input::Joint(_) => Vec::new(),
    };
    for w in &warnings {
        eprintln!("feedopt: warning: {w}");
    }
    Ok((input, warnings, detected))
}

/// `feedopt compare`: returns what to print on stdout.
pub fn compare(args: &CompareArgs) -> Result<String> {
    let a = &args.solve;
    if a.output.is_some() {
        return Err(Error::Usage(
            "compare writes no schedule file (-o): use `feedopt solve -o` for feedopt's".into(),
        ));
    }
    let options = crate::compare::CompareOptions {
        solve: a.options()?,
        junction_deviation: args.junction_deviation,
    };
    if !(options.junction_deviation.is_finite() && options.junction_deviation >= 0.0) {
        return Err(Error::Usage(format!(
            "--junction-deviation must be ≥ 0 mm, got {}",
            options.junction_deviation
        )));
    }
    let machine = a.machine()?;
    let (input, _, _) = read_input(a)?;
    let name = a.toolpath.display().to_string();
    let cmp = crate::compare::compare(&machine, &input, &name, &options)?;
    if let Some(plot) = &a.plot {
        let curves: Vec<writers::plot::ProfileCurve> = cmp
            .schedules
            .iter()
            .map(|r| writers::plot::ProfileCurve {
                label: format!(
                    "{}: {:.4} s{}",
                    r.label,
                    r.cycle_time_s,
                    if r.verified { "" } else { " (exceeds limits)" }
                ),
                schedule: &r.schedule,
            })
            .collect();
        let title = format!("{name} on {}: feed profiles", machine.name);
        writers::plot::write_profiles_plot(plot, &title, cmp.joint_space, &curves)?;
    }
    Ok(if a.json {
        let mut s = serde_json::to_string_pretty(&cmp)
            .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
        s.push('\n');
        s
    } else {
        cmp.to_string()
    })
}

/// `feedopt sweep`: returns what to print on stdout.
pub fn sweep(args: &SweepArgs) -> Result<String> {
    use std::io::IsTerminal;
    let solve = &args.solve;
    let options = solve.options()?;
    // `options()` has checked --plot (and -o) already.
    let machine = solve.machine()?;
    let (input, _, _) = read_input(solve)?;
    let mut o =
        crate::sweep::SweepOptions::new(&args.axis, args.limit, args.from, args.to, args.steps);
    o.fd_step = args.fd_step;
    o.solve = options;
    o.progress = !solve.json && std::io::stderr().is_terminal();
    let result = crate::sweep::sweep(&machine, &input, &solve.toolpath.display().to_string(), &o)?;
    if let Some(out) = &solve.output {
        result.write(out)?;
    }
    if let Some(plot) = &args.solve.plot {
        result.write_plot(plot)?;
    }
    if solve.json {
        result.to_json()
    } else {
        Ok(result.to_string())
    }
}

/// Runs a parsed command line; returns what to print on stdout.
pub fn run(cli: &Cli) -> Result<String> {
    match &cli.command {
        Command::Solve(args) => solve(args),
        Command::Gcode(args) => gcode(args),
        Command::Interpolate(args) => interpolate(args),
        Command::Compare(args) => compare(args),
        Command::Sweep(args) => sweep(args),
    }
}

/// The solve options of `feedopt gcode` and `feedopt interpolate` (as `feedopt solve`'s).
#[derive(Debug, Clone, Args)]
pub struct PlanArgs {
    /// Machine file (JSON: kinematics, axis limits, maximum feed).
    #[arg(long, short)]
    pub machine: PathBuf,
    /// Toolpath file (APT CL: .cls, .apt; G-code: .ngc, .nc, .gcode, .tap).
    pub toolpath: PathBuf,
    /// Total station count, 2 to 4,000,000 (default: refined automatically).
    #[arg(long)]
    pub stations: Option<usize>,
    /// Turning angle between CL moves (degrees) above which the path stops exactly.
    #[arg(long, default_value_t = 10.0)]
    pub corner_angle: f64,
    /// How far the fitted path may stray from the programmed tool-tip positions, mm.
    #[arg(long, default_value_t = 0.005, value_name = "MM")]
    pub tolerance: f64,
    /// How far the fitted rotary angles may stray from the programmed ones, degrees.
    #[arg(long, default_value_t = 0.01, value_name = "DEG")]
    pub tolerance_deg: f64,
    /// Cap every programmed feed at this multiple of it (a feed override), 0.001 to 1000.
    #[arg(long, default_value_t = 1.0, value_name = "FACTOR")]
    pub feed_override: f64,
    /// Ignore the program's feeds: only the machine's limits apply.
    #[arg(long)]
    pub ignore_programmed_feed: bool,
    /// Input format instead of the file's extension: apt, gcode or csv.
    #[arg(long, value_enum)]
    pub format: Option<FormatChoice>,
    /// Read a machine builder's (or a post's) Sinumerik cycle as the standard one it works
    /// like: `--cycle-alias CYCLE76=CYCLE86` (repeatable).
    #[arg(long = "cycle-alias", value_name = "FROM=TO")]
    pub cycle_alias: Vec<String>,
    /// Solver: `clarabel` or `reach`.
    #[arg(long, value_enum, default_value_t = SolverChoice::Clarabel)]
    pub solver: SolverChoice,
    /// Tool-tip feed at the start of the path, mm/s (default: at rest); at most feed.max.
    #[arg(long, default_value_t = 0.0, value_name = "MM_PER_S")]
    pub start_feed: f64,
    /// Tool-tip feed at the end of the path, mm/s (default: at rest); at most feed.max.
    #[arg(long, default_value_t = 0.0, value_name = "MM_PER_S")]
    pub end_feed: f64,
    /// Bound the chord error of each interpolation period (`--period`) by this, mm (seed 004:
    /// V² ≤ 8δ/(κT²) on a path of curvature κ), checked by the re-simulation.
    #[arg(long, value_name = "MM")]
    pub chord_tolerance: Option<f64>,
    /// Ignore the machine file's jerk limits: an acceleration-limited schedule.
    #[arg(long)]
    pub no_jerk: bool,
}

impl PlanArgs {
    /// The inputs an output must not overwrite.
    fn inputs(&self) -> [(&'static str, &std::path::Path); 2] {
        [
            ("machine file", self.machine.as_path()),
            ("toolpath", self.toolpath.as_path()),
        ]
    }

    /// The same solve as `feedopt solve` with these options (G-code input in `dialect`).
    fn solve_args(&self, dialect: crate::toolpath::gcode::Dialect, period: f64) -> SolveArgs {
        SolveArgs {
            machine: self.machine.clone(),
            toolpath: self.toolpath.clone(),
            json: false,
            output: None,
            stations: self.stations,
            corner_angle: self.corner_angle,
            tolerance: self.tolerance,
            tolerance_deg: self.tolerance_deg,
            feed_override: self.feed_override,
            ignore_programmed_feed: self.ignore_programmed_feed,
            format: self.format,
            dialect: Some(dialect),
            cycle_alias: self.cycle_alias.clone(),
            solver: self.solver,
            start_feed: self.start_feed,
            end_feed: self.end_feed,
            period,
            plot: None,
            chord_tolerance: self.chord_tolerance,
            no_jerk: self.no_jerk,
        }
    }
}

/// Reads, solves; reader warnings go to stderr.
fn plan(args: &SolveArgs) -> Result<(Machine, toolpath::Input, Options, optimize::Solution)> {
    let options = args.options()?;
    let machine = args.machine()?;
    let (input, _, _) = read_input(args)?;
    let solution = solve_with_progress(&machine, &input, &options)?;
    Ok((machine, input, options, solution))
}

#[derive(Debug, Args)]
pub struct GcodeArgs {
    #[command(flatten)]
    pub plan: PlanArgs,
    /// The G-code program to write (.ngc, .nc, …).
    #[arg(long, short, value_name = "FILE")]
    pub output: PathBuf,
    /// Dialect of the written program (and of a G-code input unless --input-dialect):
    /// linuxcnc, fanuc or sinumerik.
    #[arg(long, default_value = "linuxcnc")]
    pub dialect: crate::toolpath::gcode::Dialect,
    /// Dialect of a G-code input, when it differs from the output's.
    #[arg(long)]
    pub input_dialect: Option<crate::toolpath::gcode::Dialect>,
    /// Largest turn of a rotary axis within one block (Δθ, degrees, seed 001): longer turns are
    /// split by bisection (default: no limit; at least 0.001°).
    #[arg(long, value_name = "DEG")]
    pub max_rotation_deg: Option<f64>,
}

/// `feedopt gcode`: returns what to print on stdout.
pub fn gcode(args: &GcodeArgs) -> Result<String> {
    writers::check_output("-o", &args.output, &args.plan.inputs())?;
    if let Some(d) = args.max_rotation_deg {
        if !(d.is_finite() && d >= MIN_ROTATION_DEG) {
            return Err(Error::Usage(format!(
                "--max-rotation-deg {}: give at least {MIN_ROTATION_DEG}° (a rotary axis's \
                 resolution; smaller steps only multiply the blocks)",
                crate::error::number(d)
            )));
        }
    }
    let solve_args = args.plan.solve_args(
        args.input_dialect.unwrap_or(args.dialect),
        crate::verify::VerifyOptions::default().period,
    );
    let (machine, input, options, solution) = plan(&solve_args)?;
    let toolpath::Input::Cl(path) = &input else {
        return Err(Error::Usage(format!(
            "{}: a joint-space path has no tool tip to write as G-code",
            args.plan.toolpath.display()
        )));
    };
    let prog = writers::gcode::write_gcode(
        &args.output,
        &machine,
        path,
        &solution,
        &options.geometry,
        &writers::gcode::GcodeOptions {
            dialect: args.dialect,
            max_rotation_deg: args.max_rotation_deg,
        },
    )?;
    Ok(format!(
        "wrote {} ({} dialect): {} blocks ({} under G93), {} merged, {} added by Δθ\n\
         schedule cycle time {:.4} s, program time {:.4} s\n",
        args.output.display(),
        args.dialect,
        prog.blocks,
        prog.inverse_time_blocks,
        prog.merged,
        prog.split,
        solution.schedule.cycle_time,
        prog.time
    ))
}

#[derive(Debug, Args)]
pub struct InterpolateArgs {
    #[command(flatten)]
    pub plan: PlanArgs,
    /// Interpolation period: `1ms`, `500us`, `0.002` (seconds); 1 µs to 1 s. Also the servo
    /// period of the schedule's verification.
    #[arg(long, default_value = "1ms", value_parser = parse_period)]
    pub period: f64,
    /// The setpoints to write: FILE.csv or FILE.bin (layout in `feedopt::interpolate`).
    #[arg(long, short, value_name = "FILE")]
    pub output: PathBuf,
    /// Dialect of a G-code input.
    #[arg(long, default_value = "linuxcnc")]
    pub dialect: crate::toolpath::gcode::Dialect,
}

/// `feedopt interpolate`: returns what to print on stdout.
pub fn interpolate(args: &InterpolateArgs) -> Result<String> {
    crate::interpolate::setpoint_format(&args.output)?;
    writers::check_output("-o", &args.output, &args.plan.inputs())?;
    let (machine, _, _, solution) = plan(&args.plan.solve_args(args.dialect, args.period))?;
    let sp = crate::interpolate::sample(&machine, &solution, args.period)?;
    crate::interpolate::write_setpoints(&args.output, &sp)?;
    Ok(format!(
        "wrote {}: {} setpoints every {} s over {:.4} s, axes {}\n",
        args.output.display(),
        sp.samples.len(),
        args.period,
        solution.schedule.cycle_time,
        sp.axes.join(" ")
    ))
}
