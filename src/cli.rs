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
    /// The subcommand and its arguments.
    #[command(subcommand)]
    pub command: Command,
    /// Diagnostics on stderr: `-v` each solver stage's details (refinement rounds, SCP
    /// iterates), `-vv` also Clarabel's own log. `RUST_LOG` (e.g. `feedopt=debug`), when set,
    /// decides instead.
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    pub verbose: u8,
}

/// Installs the diagnostics subscriber: the library's `tracing` events on stderr, filtered by
/// `RUST_LOG` when it is set, else by `verbose` (0: warnings, 1: `feedopt=debug`, 2 or more:
/// `feedopt=trace`). Call once, before [`run`].
pub fn init_logging(verbose: u8) {
    use tracing_subscriber::EnvFilter;
    let filter = match std::env::var("RUST_LOG") {
        Ok(spec) if !spec.trim().is_empty() => EnvFilter::new(spec),
        _ => EnvFilter::new(match verbose {
            0 => "warn",
            1 => "warn,feedopt=debug",
            _ => "warn,feedopt=trace",
        }),
    };
    // A second call (in a test, say) keeps the first subscriber.
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .without_time()
        .try_init();
}

#[derive(Debug, Subcommand)]
/// The subcommands.
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
    /// Overload check (needs a stock): cut the stock along the program and list every move
    /// whose programmed feed exceeds a process limit, every rapid through material and every
    /// move that takes the shank into it.
    Check(CheckArgs),
}

/// The material model's options (`solve`, `gcode`, `interpolate`, `compare`, `sweep`,
/// `check`): they apply when the machine file has a `stock` (see `feedopt::material`).
#[derive(Debug, Clone, Default, Args)]
pub struct MaterialArgs {
    /// Dexel cell size of the material model, mm (default: tool diameter / 50).
    #[arg(long, value_name = "MM")]
    pub cell: Option<f64>,
    /// Sample step of the engagement along the path, mm (default: the larger of 5 cells and
    /// D/8).
    #[arg(long, value_name = "MM")]
    pub sample_step: Option<f64>,
    /// Spindle speed, rpm (instead of the program's S / SPINDL/ or the machine file's
    /// `process.spindle_speed`).
    #[arg(long, value_name = "RPM")]
    pub spindle_speed: Option<f64>,
    /// Tool diameter, mm (for every tool, instead of the program's CUTTER/, the tool table or
    /// the machine file's `tool`). Also
    /// what a Klartext bore-milling cycle (CYCL DEF 208) mills with, which the control takes
    /// from its tool table; alone (without a stock) it asks for no material stage.
    #[arg(long, value_name = "MM")]
    pub tool_diameter: Option<f64>,
    /// Tool corner radius, mm (0: flat, D/2: ball-nose).
    #[arg(long, value_name = "MM")]
    pub tool_corner_radius: Option<f64>,
    /// Tool flute length, mm (default 2 D).
    #[arg(long, value_name = "MM")]
    pub tool_flute_length: Option<f64>,
    /// Number of flutes (teeth).
    #[arg(long, value_name = "N")]
    pub tool_flutes: Option<u32>,
    /// Tool table: what the program's tool numbers and names (`T5 M6`, `T="MILL"`, `TOOL CALL
    /// 5`) stand for; LinuxCNC `.tbl` (`T5 P5 D6.35`) or JSON (`{"5": {"diameter": 6.35,
    /// "flutes": 3}}`), instead of the machine file's `tools`.
    #[arg(long, value_name = "FILE")]
    pub tool_table: Option<PathBuf>,
    /// Ignore the machine file's stock, tool and process sections: axis limits and programmed
    /// feeds only.
    #[arg(long)]
    pub no_material: bool,
}

#[derive(Debug, Args)]
/// Arguments of `feedopt check`: the overload check of seed 003.
pub struct CheckArgs {
    /// Machine file with `stock`, `tool` and `process` sections.
    #[arg(long, short)]
    pub machine: PathBuf,
    /// Toolpath file: APT CL (.cls, .apt) or G-code (.ngc, .nc, .gcode, .tap, Sinumerik .mpf,
    /// Heidenhain .h, …; the dialect is detected from the content).
    pub toolpath: PathBuf,
    /// Print one JSON object (the material report with its `findings`).
    #[arg(long)]
    pub json: bool,
    /// Input format instead of the file's extension: apt or gcode.
    #[arg(long, value_enum)]
    pub format: Option<FormatChoice>,
    /// G-code dialect (default: detected from the program).
    #[arg(long)]
    pub dialect: Option<crate::toolpath::gcode::Dialect>,
    /// How a Fanuc number without a decimal point is read: `increment` (`X100` is 0.1 mm,
    /// parameter 3401#0 DPI = 0) or `calculator` (100 mm, DPI = 1); default: the machine
    /// file's `decimal_point_input`, else increment with a warning.
    #[arg(long, value_name = "increment|calculator")]
    pub decimal_point_input: Option<crate::machine::DecimalPointInput>,
    /// Factor on every programmed feed, as the machine would run it (0.001 to 1000).
    #[arg(long, default_value_t = 1.0, value_name = "FACTOR")]
    pub feed_override: f64,
    /// Skip the G-code blocks that start with `/` (the control's block-skip switch on;
    /// default: run them).
    #[arg(long)]
    pub block_delete: bool,
    /// The program's G41/G42 (Klartext RL/RR) offset only the tool's wear: its path is the
    /// tool centre's (CAM wear compensation). Without it such a block is an error.
    #[arg(long)]
    pub wear_compensation: bool,
    /// A directory that holds the program's subprograms' files (repeatable; searched after the
    /// program's own directory, in the order given): Fanuc `M98 P1002` and `G65 P1002` read
    /// `O1002`, `O1002.nc`, `1002.nc`, …; LinuxCNC `o<name> call` reads `name.ngc`; Sinumerik
    /// `NAME`, `L1234`, `EXTCALL "NAME"` read `NAME.SPF` or `NAME.MPF`; Heidenhain `CALL PGM
    /// name` reads `name.h`.
    #[arg(long = "subprogram-dir", value_name = "DIR")]
    pub subprogram_dir: Vec<PathBuf>,
    #[command(flatten)]
    /// Stock, tool and process limits beyond the machine file.
    pub material: MaterialArgs,
}

#[derive(Debug, Args)]
/// Arguments of `feedopt compare`.
pub struct CompareArgs {
    #[command(flatten)]
    /// Machine, toolpath, --json, --plot and the solve options.
    pub solve: SolveArgs,
    /// Junction deviation δ of the controller baseline, mm (grbl's `$11`): how far the
    /// virtual arc through a corner may pass from the corner point.
    #[arg(long, default_value_t = crate::compare::baseline::DEFAULT_JUNCTION_DEVIATION_MM, value_name = "MM")]
    pub junction_deviation: f64,
}

#[derive(Debug, Args)]
/// Arguments of `feedopt sweep`.
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
/// Arguments of `feedopt solve` (also `compare` and `sweep`).
pub struct SolveArgs {
    /// Machine file (JSON: kinematics, axis limits, maximum feed).
    #[arg(long, short)]
    pub machine: PathBuf,
    /// Toolpath file: APT CL (.cls, .apt), G-code (.ngc, .nc, .gcode, .tap, Sinumerik .mpf,
    /// Heidenhain .h, …; the dialect is detected from the content) or a joint-space CSV (.csv).
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
    /// G-code dialect: linuxcnc, fanuc, sinumerik or heidenhain (default: detected from the
    /// program).
    #[arg(long)]
    pub dialect: Option<crate::toolpath::gcode::Dialect>,
    /// The dialect of a G-code input whose content and extension name none (`gcode`: the
    /// output's); `None`: LinuxCNC.
    #[arg(skip)]
    pub fallback_dialect: Option<crate::toolpath::gcode::Dialect>,
    /// Servo period of the re-simulation that checks every schedule: `1ms`, `500us`, `0.002`
    /// (seconds); 1 µs to 1 s.
    #[arg(long, default_value = "1ms", value_parser = parse_period)]
    pub period: f64,
    #[command(flatten)]
    /// The solve options every subcommand shares.
    pub opts: SolveOptions,
}

#[derive(Debug, Clone, Args)]
/// The solve options every subcommand that solves shares (`solve`, `compare`, `sweep`,
/// `gcode`, `interpolate`): one declaration, flattened into each.
pub struct SolveOptions {
    /// Total station count, 2 to 4,000,000 (default: refined automatically where it changes
    /// the cycle time, interval by interval, until the estimated error of the cycle time is
    /// below 0.01 % of it).
    #[arg(long)]
    pub stations: Option<usize>,
    /// Most stations the automatic refinement may use (it stops before a round that would
    /// pass them, with its estimate and a warning); memory grows by about 0.5–1 kB a station.
    #[arg(long, default_value_t = 4_000_000, value_name = "N")]
    pub max_stations: usize,
    /// Turning angle between CL moves (degrees) above which the path stops exactly.
    #[arg(long, default_value_t = 10.0)]
    pub corner_angle: f64,
    /// Blend such corners between feed moves instead of stopping: a curve whose middle lies
    /// this far from the corner, mm, as a control does under a contour tolerance (G64 P,
    /// CYCLE832, CYCL DEF 32). 0: exact stops. Not with jerk limits (--no-jerk).
    #[arg(long, default_value_t = 0.0, value_name = "MM")]
    pub corner_tolerance: f64,
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
    /// Read a machine builder's (or a post's) Sinumerik cycle as the standard one it works
    /// like: `--cycle-alias CYCLE76=CYCLE86` (repeatable; the target one of CYCLE81–CYCLE89).
    #[arg(long = "cycle-alias", value_name = "FROM=TO")]
    pub cycle_alias: Vec<String>,
    /// Skip the G-code blocks that start with `/`, as a control with its block-skip (block
    /// delete) switch on does (default: run them, the program as posted).
    #[arg(long)]
    pub block_delete: bool,
    /// The program's G41/G42 (Klartext RL/RR) offset only the tool's wear: its path is the
    /// tool centre's (CAM wear compensation), read as programmed. Without it such a block is
    /// an error: the control offsets the path by the tool's radius, which feedopt does not
    /// model.
    #[arg(long)]
    pub wear_compensation: bool,
    /// A directory that holds the program's subprograms' files (repeatable; searched after the
    /// program's own directory, in the order given): Fanuc `M98 P1002` and `G65 P1002` read
    /// `O1002`, `O1002.nc`, `1002.nc`, …; LinuxCNC `o<name> call` reads `name.ngc`; Sinumerik
    /// `NAME`, `L1234`, `EXTCALL "NAME"` read `NAME.SPF` or `NAME.MPF`; Heidenhain `CALL PGM
    /// name` reads `name.h`.
    #[arg(long = "subprogram-dir", value_name = "DIR")]
    pub subprogram_dir: Vec<PathBuf>,
    /// How a Fanuc number without a decimal point is read: `increment` (`X100` is 0.1 mm,
    /// parameter 3401#0 DPI = 0) or `calculator` (100 mm, DPI = 1); default: the machine
    /// file's `decimal_point_input`, else increment with a warning.
    #[arg(long, value_name = "increment|calculator")]
    pub decimal_point_input: Option<crate::machine::DecimalPointInput>,
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
    #[command(flatten)]
    /// Stock, tool and process limits beyond the machine file.
    pub material: MaterialArgs,
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
    /// APT CL (`.cls`, `.apt`).
    Apt,
    /// G-code (`.ngc`, `.nc`, `.gcode`, `.tap`).
    Gcode,
    /// A joint-space CSV (`s,q_<axis>,…`).
    Csv,
}

/// `--solver` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SolverChoice {
    /// The convex solve (Clarabel).
    Clarabel,
    /// The O(N) reachability pass.
    Reach,
}

/// The command-line flag of each option field the library names in an
/// [`Error::InvalidOption`] (a nested struct's prefix `solve.` dropped).
const FLAGS: &[(&str, &str)] = &[
    ("geometry.corner_angle_deg", "--corner-angle"),
    ("geometry.corner_tolerance_mm", "--corner-tolerance"),
    ("geometry.tolerance_mm", "--tolerance"),
    ("geometry.tolerance_deg", "--tolerance-deg"),
    ("geometry.feed_override", "--feed-override"),
    ("stations", "--stations"),
    ("max_stations", "--max-stations"),
    ("start_feed", "--start-feed"),
    ("end_feed", "--end-feed"),
    ("verify.period", "--period"),
    ("verify.chord.tolerance", "--chord-tolerance"),
    ("verify.chord.period", "--period"),
    ("period", "--period"),
    ("junction_deviation", "--junction-deviation"),
    ("axis", "--axis"),
    ("from", "--from"),
    ("to", "--to"),
    ("steps", "--steps"),
    ("fd_step", "--fd-step"),
    ("max_rotation_deg", "--max-rotation-deg"),
];

/// The library's [`Error::InvalidOption`] as the command line says it: naming the flag
/// (`--period 1e-12 s is outside …`) instead of the field; every other error unchanged.
pub fn name_flag(e: Error) -> Error {
    match e {
        Error::InvalidOption { field, reason } => {
            let key = field.strip_prefix("solve.").unwrap_or(&field);
            match FLAGS.iter().find(|(f, _)| *f == key) {
                Some((_, flag)) => Error::Usage(format!("{flag} {reason}")),
                None => Error::InvalidOption { field, reason },
            }
        }
        e => e,
    }
}

impl SolveArgs {
    /// The inputs an output must not overwrite.
    fn inputs(&self) -> [(&'static str, &std::path::Path); 2] {
        [
            ("machine file", self.machine.as_path()),
            ("toolpath", self.toolpath.as_path()),
        ]
    }

    /// The options these arguments give, checked by the library ([`Options::validate`]), and
    /// the outputs checked before any work.
    fn options(&self) -> Result<Options> {
        let mut o = Options {
            stations: self.opts.stations,
            max_stations: self.opts.max_stations,
            solver_kind: match self.opts.solver {
                SolverChoice::Clarabel => SolverKind::Clarabel,
                SolverChoice::Reach => SolverKind::Reach,
            },
            start_feed: self.opts.start_feed,
            end_feed: self.opts.end_feed,
            verify: crate::verify::VerifyOptions {
                period: self.period,
                chord: self
                    .opts
                    .chord_tolerance
                    .map(|d| crate::constraints::Chord {
                        tolerance: d,
                        period: self.period,
                    }),
                ..Default::default()
            },
            jerk_limited: !self.opts.no_jerk,
            ..Options::default()
        };
        o.geometry.corner_angle_deg = self.opts.corner_angle;
        o.geometry.corner_tolerance_mm = self.opts.corner_tolerance;
        o.geometry.feed_override = self.opts.feed_override;
        o.geometry.ignore_programmed_feed = self.opts.ignore_programmed_feed;
        o.geometry.tolerance_mm = self.opts.tolerance;
        o.geometry.tolerance_deg = self.opts.tolerance_deg;
        o.validate()?;
        if let Some(out) = &self.output {
            writers::output_format(out, writers::SCHEDULE)?;
            writers::check_output("-o", out, &self.inputs())?;
        }
        if let Some(plot) = &self.plot {
            writers::output_format(plot, writers::PLOT)?;
            writers::check_output("--plot", plot, &self.inputs())?;
        }
        Ok(o)
    }

    /// The machine file, read and checked against `options` ([`Options::validate_for`]).
    fn machine(&self, options: &Options) -> Result<Machine> {
        let machine = Machine::from_file(&self.machine)?;
        options.validate_for(&machine)?;
        Ok(machine)
    }
}

/// Solves with a progress bar on a terminal.
fn solve_with_progress(
    machine: &Machine,
    input: &toolpath::Input,
    options: &Options,
) -> Result<optimize::Solution> {
    #[cfg(feature = "progress")]
    let bar = crate::progress::Spinner::new();
    #[cfg(not(feature = "progress"))]
    let bar = optimize::Silent;
    let solution = optimize::optimize_input_observed(machine, input, options, &bar)?;
    if let (Some(why), Some(e)) = (&solution.unconverged, solution.error_estimate) {
        eprintln!(
            "feedopt: warning: the cycle time is estimated within {e:.1e} of the continuous \
             optimum, not within the {:.0e} aimed at: {why}",
            solution.error_target.unwrap_or(f64::NAN)
        );
    }
    if let Some(why) = &solution.slowed_down {
        eprintln!("feedopt: warning: {why}");
    }
    Ok(solution)
}

/// `feedopt solve`: returns what to print on stdout.
pub fn solve(args: &SolveArgs) -> Result<String> {
    let mut options = args.options()?;
    let machine = args.machine(&options)?;
    let (input, warnings, detected) = read_input(args)?;
    let run = || -> Result<String> {
        let (material, solution) = cut_and_solve(args, &machine, &input, &mut options)?;
        let dwell = match &input {
            toolpath::Input::Cl(t) => t.dwell_time(),
            toolpath::Input::Joint(_) => 0.0,
        };
        if let Some(out) = &args.output {
            writers::write_schedule(out, &solution.schedule, &solution.path.holds)?;
        }
        #[cfg(feature = "plot")]
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
            let mut value = serde_json::to_value(&summary)
                .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
            if let (Some(m), Some(obj)) = (&material, value.as_object_mut()) {
                let m = serde_json::to_value(m)
                    .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
                obj.insert("material".into(), m);
            }
            name_json_lines(&input, &mut value);
            let mut s = serde_json::to_string_pretty(&value)
                .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
            s.push('\n');
            s
        } else {
            let mut s = summary.to_string();
            if let Some(m) = &material {
                s.push('\n');
                s.push_str(&m.to_string());
                for f in &m.findings {
                    s.push_str(&format!("check         line {}: {f}\n", f.line));
                }
            }
            name_lines(&input, &s)
        })
    };
    in_files(&input, run())
}

/// The material stage ([`apply_material`]) and the solve under the feed caps it sets.
fn cut_and_solve(
    args: &SolveArgs,
    machine: &Machine,
    input: &toolpath::Input,
    options: &mut Options,
) -> Result<(Option<crate::material::MaterialReport>, optimize::Solution)> {
    let material = apply_material(
        &args.machine,
        &args.toolpath,
        &args.opts.material,
        input,
        options,
    )?;
    Ok((material, solve_with_progress(machine, input, options)?))
}

/// Runs the material stage when the machine file has a stock (and `--no-material` is not
/// given): cuts the stock along the toolpath, checks the programmed feeds against the process
/// limits, and, where any process limit is given, puts its feed caps into `options`.
fn apply_material(
    machine_file: &std::path::Path,
    toolpath_file: &std::path::Path,
    args: &MaterialArgs,
    input: &toolpath::Input,
    options: &mut Options,
) -> Result<Option<crate::material::MaterialReport>> {
    use crate::material;
    let given = args.cell.is_some()
        || args.sample_step.is_some()
        || args.spindle_speed.is_some()
        || args.tool_corner_radius.is_some()
        || args.tool_flute_length.is_some()
        || args.tool_flutes.is_some()
        || args.tool_table.is_some();
    if args.no_material {
        return Ok(None);
    }
    let spec = material::from_machine_file(machine_file)?;
    if !given && spec.as_ref().is_none_or(|s| s.stock.is_none()) {
        // No stock, no material stage: the program is not scanned for tools (a program with
        // several cutters solves as before).
        return Ok(None);
    }
    let toolpath::Input::Cl(tp) = input else {
        if spec.as_ref().is_some_and(|s| s.stock.is_some()) || given {
            return Err(Error::Usage(format!(
                "{}: a joint-space path has no tool tip to cut a stock with: remove the \
                 machine file's `stock` or give --no-material",
                toolpath_file.display()
            )));
        }
        return Ok(None);
    };
    let program = material::program::ProgramProcess::from_toolpath(tp);
    let overrides = material::Overrides {
        tool_table: args
            .tool_table
            .as_deref()
            .map(material::tooltable::read)
            .transpose()?,
        tool: material::ToolSpec {
            diameter: args.tool_diameter,
            corner_radius: args.tool_corner_radius,
            flute_length: args.tool_flute_length,
            flutes: args.tool_flutes,
        },
        spindle_speed: args.spindle_speed,
        options: material::CutOptions {
            cell: args.cell,
            step: args.sample_step,
        },
    };
    let Some(m) = material::Material::resolve(machine_file, spec, &program, &overrides)? else {
        if given {
            return Err(Error::Usage(format!(
                "{}: the material options need a stock: add the machine file's `stock` section",
                machine_file.display()
            )));
        }
        return Ok(None);
    };
    let machine = Machine::from_file(machine_file)?;
    let tp = material::tool_axes(tp, &machine)?;
    let sim = material::simulate(&tp, &m)?;
    let findings = material::check::overloads(&sim, &m, options.geometry.feed_override);
    if m.process.any() {
        let limits = material::FeedLimits::new(&sim, &m, tp.points.len());
        options.process = Some(std::sync::Arc::new(limits));
    }
    Ok(Some(material::MaterialReport::new(
        &m, &sim, &program, findings,
    )))
}

/// `feedopt check`: returns what to print on stdout.
pub fn check(args: &CheckArgs) -> Result<String> {
    let mut options = Options::default();
    options.geometry.feed_override = args.feed_override;
    options.geometry.validate()?;
    let (input, _, _) = read_input_from(
        &args.machine,
        &args.toolpath,
        Reading {
            format: args.format,
            dialect: args.dialect,
            fallback_dialect: None,
            cycle_alias: &[],
            block_delete: args.block_delete,
            wear_compensation: args.wear_compensation,
            subprogram_dirs: &args.subprogram_dir,
            tool_diameter: args.material.tool_diameter,
            decimal_point_input: args.decimal_point_input,
        },
    )?;
    let material = apply_material(
        &args.machine,
        &args.toolpath,
        &args.material,
        &input,
        &mut options,
    );
    let Some(report) = in_files(&input, material)? else {
        return Err(Error::Usage(format!(
            "{}: the overload check needs a stock: add the machine file's `stock` section \
             (and `tool`, `process`)",
            args.machine.display()
        )));
    };
    if args.json {
        let mut value = serde_json::to_value(&report)
            .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
        name_json_lines(&input, &mut value);
        let mut s = serde_json::to_string_pretty(&value)
            .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
        s.push('\n');
        return Ok(s);
    }
    let mut s = format!("toolpath      {}\n", args.toolpath.display());
    s.push_str(&report.to_string());
    let errors = report
        .findings
        .iter()
        .filter(|f| f.severity == crate::material::check::Severity::Error)
        .count();
    s.push_str(&format!(
        "findings      {} ({errors} error{}, {} warning{})\n",
        report.findings.len(),
        if errors == 1 { "" } else { "s" },
        report.findings.len() - errors,
        if report.findings.len() - errors == 1 {
            ""
        } else {
            "s"
        }
    ));
    // The shank findings once, with how many moves follow (a deep relief with too short a
    // flute length makes every move one); `--json` lists each.
    use crate::material::check::FindingKind;
    let shank: Vec<_> = report
        .findings
        .iter()
        .filter(|f| f.kind == FindingKind::Shank)
        .collect();
    let mut shank_said = false;
    for f in &report.findings {
        if f.kind == FindingKind::Shank {
            if shank_said {
                continue;
            }
            shank_said = true;
            let more = if shank.len() > 1 {
                let deepest = shank.iter().map(|x| x.shank_depth).fold(0.0, f64::max);
                format!(
                    " (and {} more moves like it, up to {deepest:.3} mm, the last at line {})",
                    shank.len() - 1,
                    shank[shank.len() - 1].line
                )
            } else {
                String::new()
            };
            s.push_str(&format!(
                "{}: {f}{more}\n",
                file_line(&input, &args.toolpath, f.line)
            ));
            continue;
        }
        s.push_str(&format!(
            "{}: {f}\n",
            file_line(&input, &args.toolpath, f.line)
        ));
    }
    Ok(name_lines(&input, &s))
}

/// Reads the toolpath of `args`; its reader's warnings are printed on stderr and returned.
fn read_input(args: &SolveArgs) -> Result<(toolpath::Input, Vec<String>, toolpath::Detected)> {
    read_input_from(
        &args.machine,
        &args.toolpath,
        Reading {
            format: args.opts.format,
            dialect: args.dialect,
            fallback_dialect: args.fallback_dialect,
            cycle_alias: &args.opts.cycle_alias,
            block_delete: args.opts.block_delete,
            wear_compensation: args.opts.wear_compensation,
            subprogram_dirs: &args.opts.subprogram_dir,
            tool_diameter: args.opts.material.tool_diameter,
            decimal_point_input: args.opts.decimal_point_input,
        },
    )
}

/// How the command line asks for a toolpath to be read (the machine file adds its part).
struct Reading<'a> {
    format: Option<FormatChoice>,
    dialect: Option<crate::toolpath::gcode::Dialect>,
    fallback_dialect: Option<crate::toolpath::gcode::Dialect>,
    cycle_alias: &'a [String],
    block_delete: bool,
    wear_compensation: bool,
    subprogram_dirs: &'a [PathBuf],
    tool_diameter: Option<f64>,
    decimal_point_input: Option<crate::machine::DecimalPointInput>,
}

/// Reads `toolpath_file` for the machine of `machine_file`; its reader's warnings are printed
/// on stderr and returned.
fn read_input_from(
    machine_file: &std::path::Path,
    toolpath_file: &std::path::Path,
    reading: Reading,
) -> Result<(toolpath::Input, Vec<String>, toolpath::Detected)> {
    let Reading {
        format,
        dialect,
        fallback_dialect,
        cycle_alias,
        block_delete,
        wear_compensation,
        subprogram_dirs,
        tool_diameter,
        decimal_point_input,
    } = reading;
    for dir in subprogram_dirs {
        if !dir.is_dir() {
            return Err(Error::Usage(format!(
                "--subprogram-dir {}: not a directory",
                crate::files::escape_control(&dir.display().to_string())
            )));
        }
    }
    let format = format.map(|f| match f {
        FormatChoice::Apt => toolpath::Format::Apt,
        FormatChoice::Gcode => toolpath::Format::Gcode,
        FormatChoice::Csv => toolpath::Format::Csv,
    });
    // The machine file once: the machine, its reference positions and its tool.
    let text = crate::files::utf8(
        machine_file,
        crate::files::read_bounded(
            machine_file,
            crate::files::MAX_MACHINE_FILE_BYTES,
            "machine file",
        )?,
    )?;
    let machine = Machine::from_json(machine_file, &text)?;
    let references = crate::machine::references_from_json(machine_file, &text, &machine)?;
    let cycle_aliases = cycle_alias
        .iter()
        .map(|a| toolpath::gcode::parse_cycle_alias(a))
        .collect::<Result<Vec<_>>>()?;
    let options = toolpath::ReadOptions {
        format,
        dialect,
        machine: Some(toolpath::MachineContext {
            wear_compensation,
            ..toolpath::MachineContext::new(&machine, &references)
        }),
        cycle_aliases,
        block_delete,
        // The tool's diameter for the cycles whose path needs it: the option, else the machine
        // file's `tool` (its errors are the material stage's to report).
        tool_diameter: tool_diameter.or_else(|| {
            crate::material::MaterialSpec::from_json(machine_file, &text)
                .ok()
                .flatten()
                .and_then(|s| s.tool.diameter)
        }),
        fallback_dialect,
        decimal_point_input,
        subprogram_dirs: subprogram_dirs.to_vec(),
    };
    let (input, detected) = toolpath::read_with(toolpath_file, &options)?;
    // What the reader skipped or doubted: one line each on stderr, and in the summary; a
    // message repeated on many lines once, at its first line, with the count of the others.
    let warnings: Vec<String> = match &input {
        toolpath::Input::Cl(t) => toolpath::WarningGroup::group(&t.warnings)
            .iter()
            .map(|g| {
                let text = format!(
                    "{}: {}",
                    t.file_line(g.first.line),
                    t.name_lines(&g.message())
                );
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
    let mut options = crate::compare::CompareOptions {
        solve: a.options()?,
        junction_deviation: args.junction_deviation,
    };
    options.validate()?;
    let machine = a.machine(&options.solve)?;
    let (input, _, _) = read_input(a)?;
    let mut run = || -> Result<String> {
        apply_material(
            &a.machine,
            &a.toolpath,
            &a.opts.material,
            &input,
            &mut options.solve,
        )?;
        let name = a.toolpath.display().to_string();
        let cmp = crate::compare::compare(&machine, &input, &name, &options)?;
        #[cfg(feature = "plot")]
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
    };
    in_files(&input, run())
}

/// `feedopt sweep`: returns what to print on stdout.
pub fn sweep(args: &SweepArgs) -> Result<String> {
    use std::io::IsTerminal;
    let solve = &args.solve;
    let options = solve.options()?;
    // `options()` has checked --plot (and -o) already.
    let mut o =
        crate::sweep::SweepOptions::new(&args.axis, args.limit, args.from, args.to, args.steps);
    o.fd_step = args.fd_step;
    o.solve = options;
    o.progress = !solve.json && std::io::stderr().is_terminal();
    o.validate()?;
    let machine = solve.machine(&o.solve)?;
    let (input, _, _) = read_input(solve)?;
    let mut run = || -> Result<String> {
        apply_material(
            &solve.machine,
            &solve.toolpath,
            &solve.opts.material,
            &input,
            &mut o.solve,
        )?;
        let result =
            crate::sweep::sweep(&machine, &input, &solve.toolpath.display().to_string(), &o)?;
        if let Some(out) = &solve.output {
            result.write(out)?;
        }
        #[cfg(feature = "plot")]
        if let Some(plot) = &args.solve.plot {
            result.write_plot(plot)?;
        }
        if solve.json {
            result.to_json()
        } else {
            Ok(result.to_string())
        }
    };
    in_files(&input, run())
}

/// Runs a parsed command line; returns what to print on stdout. An option the library refuses
/// is named by its flag ([`name_flag`]).
pub fn run(cli: &Cli) -> Result<String> {
    match &cli.command {
        Command::Solve(args) => solve(args),
        Command::Gcode(args) => gcode(args),
        Command::Interpolate(args) => interpolate(args),
        Command::Compare(args) => compare(args),
        Command::Sweep(args) => sweep(args),
        Command::Check(args) => check(args),
    }
    .map_err(name_flag)
}

/// Machine, toolpath and the solve options of `feedopt gcode` and `feedopt interpolate` (as
/// `feedopt solve`'s).
#[derive(Debug, Clone, Args)]
pub struct PlanArgs {
    /// Machine file (JSON: kinematics, axis limits, maximum feed).
    #[arg(long, short)]
    pub machine: PathBuf,
    /// Toolpath file: APT CL (.cls, .apt) or G-code (.ngc, .nc, .gcode, .tap, Sinumerik .mpf,
    /// Heidenhain .h, …; the dialect is detected from the content).
    pub toolpath: PathBuf,
    #[command(flatten)]
    /// The solve options every subcommand shares.
    pub opts: SolveOptions,
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
    /// The solve's arguments, with a G-code input read in `dialect` (`None`: detected as
    /// `feedopt solve` detects it).
    fn solve_args(
        &self,
        dialect: Option<crate::toolpath::gcode::Dialect>,
        fallback_dialect: Option<crate::toolpath::gcode::Dialect>,
        period: f64,
    ) -> SolveArgs {
        SolveArgs {
            machine: self.machine.clone(),
            toolpath: self.toolpath.clone(),
            json: false,
            output: None,
            plot: None,
            dialect,
            fallback_dialect,
            period,
            opts: self.opts.clone(),
        }
    }
}

/// Reads, solves; reader warnings go to stderr.
fn plan(args: &SolveArgs) -> Result<(Machine, toolpath::Input, Options, optimize::Solution)> {
    let mut options = args.options()?;
    let machine = args.machine(&options)?;
    let (input, _, _) = read_input(args)?;
    let mut run = || cut_and_solve(args, &machine, &input, &mut options).map(|(_, s)| s);
    let solution = in_files(&input, run())?;
    Ok((machine, input, options, solution))
}

/// An error of the stages after the reader with the toolpath's lines named in their files
/// ([`toolpath::Toolpath::in_files`]: a line of a subprogram's file a call read).
fn in_files<T>(input: &toolpath::Input, result: Result<T>) -> Result<T> {
    result.map_err(|e| match input {
        toolpath::Input::Cl(t) => t.in_files(e),
        toolpath::Input::Joint(_) => e,
    })
}

/// Text about the toolpath with its lines named in their files
/// ([`toolpath::Toolpath::name_lines`]).
fn name_lines(input: &toolpath::Input, text: &str) -> String {
    match input {
        toolpath::Input::Cl(t) => t.name_lines(text),
        toolpath::Input::Joint(_) => text.to_string(),
    }
}

/// A JSON report with the toolpath's lines named in their files
/// ([`toolpath::Toolpath::name_json_lines`]).
fn name_json_lines(input: &toolpath::Input, value: &mut serde_json::Value) {
    if let toolpath::Input::Cl(t) = input {
        t.name_json_lines(value);
    }
}

/// `file:line` of toolpath line `line` (the toolpath's file otherwise).
fn file_line(input: &toolpath::Input, file: &std::path::Path, line: usize) -> String {
    match input {
        toolpath::Input::Cl(t) => t.file_line(line),
        toolpath::Input::Joint(_) => format!("{}:{line}", file.display()),
    }
}

#[derive(Debug, Args)]
/// Arguments of `feedopt gcode`.
pub struct GcodeArgs {
    #[command(flatten)]
    /// Machine, toolpath and the solve options.
    pub plan: PlanArgs,
    /// The G-code program to write (.ngc, .nc, …).
    #[arg(long, short, value_name = "FILE")]
    pub output: PathBuf,
    /// Dialect of the written program: linuxcnc, fanuc or sinumerik (and of a G-code input
    /// whose content and extension name none, unless --input-dialect).
    #[arg(long, default_value = "linuxcnc")]
    pub dialect: crate::toolpath::gcode::Dialect,
    /// Dialect of a G-code input (default: detected from the program, as `solve` does; where
    /// nothing in it tells, the output's).
    #[arg(long)]
    pub input_dialect: Option<crate::toolpath::gcode::Dialect>,
    /// Largest turn of a rotary axis within one block (Δθ, degrees, seed 001): longer turns are
    /// split by bisection (default: no limit; at least 0.001°).
    #[arg(long, value_name = "DEG")]
    pub max_rotation_deg: Option<f64>,
    /// What each block's F states: `peak` (default), the fastest feed the schedule reaches
    /// along the block, so that a control, which accelerates between the blocks' feeds within
    /// the machine's limits, runs the schedule's time; or `average`, the block's chord over
    /// its time in the schedule, whose times at F add up to the cycle time but which a control
    /// that accelerates runs slower (every block that starts or ends at rest: NX programs
    /// solved again from such a program took 0.8 % to 7 % longer)
    #[arg(long, default_value = "peak", value_name = "peak|average")]
    pub block_feed: writers::gcode::BlockFeed,
}

/// `feedopt gcode`: returns what to print on stdout.
pub fn gcode(args: &GcodeArgs) -> Result<String> {
    writers::check_output("-o", &args.output, &args.plan.inputs())?;
    let gcode_options = writers::gcode::GcodeOptions {
        dialect: args.dialect,
        max_rotation_deg: args.max_rotation_deg,
        block_feed: args.block_feed,
    };
    gcode_options.validate()?;
    // The input's dialect as `solve` detects it (a Klartext `.h`, a Sinumerik program); a
    // program nothing in which names one is read in the output's.
    let solve_args = args.plan.solve_args(
        args.input_dialect,
        Some(args.dialect),
        crate::verify::VerifyOptions::default().period,
    );
    let (machine, input, options, solution) = plan(&solve_args)?;
    let toolpath::Input::Cl(path) = &input else {
        return Err(Error::Usage(format!(
            "{}: a joint-space path has no tool tip to write as G-code",
            args.plan.toolpath.display()
        )));
    };
    let prog = in_files(
        &input,
        writers::gcode::write_gcode(
            &args.output,
            &machine,
            path,
            &solution,
            &options.geometry,
            &gcode_options,
        ),
    )?;
    let time = match args.block_feed {
        writers::gcode::BlockFeed::Average => format!(
            "program time {:.4} s (its blocks at their average feeds, dwells included)",
            prog.time
        ),
        writers::gcode::BlockFeed::Peak => format!(
            "F at each block's peak feed: a control that accelerates within the machine's \
             limits runs the schedule's time (the blocks at F without accelerating: {:.4} s)",
            prog.time
        ),
    };
    Ok(format!(
        "wrote {} ({} dialect): {} blocks ({} under G93), {} merged, {} added by Δθ, {} where \
         a process limit changes\n\
         schedule cycle time {:.4} s (dwells included); {time}\n",
        args.output.display(),
        args.dialect,
        prog.blocks,
        prog.inverse_time_blocks,
        prog.merged,
        prog.split,
        prog.process_split,
        solution.schedule.cycle_time + path.dwell_time(),
    ))
}

#[derive(Debug, Args)]
/// Arguments of `feedopt interpolate`.
pub struct InterpolateArgs {
    #[command(flatten)]
    /// Machine, toolpath and the solve options.
    pub plan: PlanArgs,
    /// Interpolation period: `1ms`, `500us`, `0.002` (seconds); 1 µs to 1 s. Also the servo
    /// period of the schedule's verification.
    #[arg(long, default_value = "1ms", value_parser = parse_period)]
    pub period: f64,
    /// The setpoints to write: FILE.csv or FILE.bin (layout in `feedopt::interpolate`).
    #[arg(long, short, value_name = "FILE")]
    pub output: PathBuf,
    /// G-code dialect of the input: linuxcnc, fanuc, sinumerik or heidenhain (default:
    /// detected from the program, as `solve` does).
    #[arg(long)]
    pub dialect: Option<crate::toolpath::gcode::Dialect>,
}

/// `feedopt interpolate`: returns what to print on stdout.
pub fn interpolate(args: &InterpolateArgs) -> Result<String> {
    writers::output_format(&args.output, writers::setpoints::SETPOINTS)?;
    writers::check_output("-o", &args.output, &args.plan.inputs())?;
    let (machine, _, _, solution) = plan(&args.plan.solve_args(args.dialect, None, args.period))?;
    // Straight to the file, one setpoint at a time: hours of motion at 1 ms in bounded memory.
    let sp = writers::setpoints::write_sampled(&args.output, &machine, &solution, args.period)?;
    Ok(format!(
        "wrote {}: {} setpoints every {} s over {:.4} s, axes {}\n",
        args.output.display(),
        sp.count,
        args.period,
        solution.schedule.cycle_time + solution.path.holds.iter().sum::<f64>(),
        sp.axes.join(" ")
    ))
}
