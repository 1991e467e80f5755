//! Toolpath readers: files in, plain [`Toolpath`] data out.
//!
//! A toolpath is a list of cutter-location (CL) points in workpiece coordinates: tool-tip
//! position **P** (mm), unit tool orientation **O**, and the feed programmed for the move that
//! arrives at the point. Readers never interpolate or judge geometry; that is
//! [`crate::geometry`]'s job.

pub mod apt;
pub mod gcode;
pub mod joint_csv;
pub mod nurbs;

use nalgebra::Vector3;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::machine::{KinematicsSpec, Machine, References};

/// The number of chords an arc of `sweep` radians and radius `radius` (mm) is cut into, so that
/// every chord's sagitta is at most [`gcode::MAX_CHORD_ERROR_MM`]: ⌈sweep / (2 acos(1 − e/r))⌉
/// (G2/G3 and APT arcs alike); an error past [`gcode::MAX_ARC_CHORDS`].
pub fn arc_chords(sweep: f64, radius: f64) -> std::result::Result<usize, String> {
    let step = 2.0 * (1.0 - gcode::MAX_CHORD_ERROR_MM / radius).max(-1.0).acos();
    let n = (sweep.abs() / step).ceil();
    if n.is_nan() || n > gcode::MAX_ARC_CHORDS as f64 {
        return Err(format!(
            "the arc (radius {radius:.6} mm, {:.1} turns) needs more than {} chords within {} mm",
            sweep.abs() / std::f64::consts::TAU,
            gcode::MAX_ARC_CHORDS,
            gcode::MAX_CHORD_ERROR_MM
        ));
    }
    Ok((n as usize).max(1))
}

/// Most CL points a reader makes from one program: 4 million, the default station limit
/// ([`crate::optimize::Options::max_stations`]; a station sits on every CL point, so a longer
/// path could not be solved at the default anyway). It bounds the work that grows with what a
/// program asks for rather than with its length: arcs with many turns, cycles, repeats,
/// subprogram calls and jumps, which a few lines can multiply into any number of points.
/// Every reader checks it *before* it makes a run of points (`check_room`), so the error
/// comes before the work and the memory, never after.
pub const MAX_POINTS: usize = 4_000_000;

/// Checks that `more` CL points made at `line` of `source` by `what` (an arc's chords, a
/// cycle's moves, a curve's samples), after the `have` made so far, stay within
/// [`MAX_POINTS`]; `more = 0` checks what was made (a block's single points). The error names
/// the file and line, the counts, and what to do.
pub(crate) fn check_room(
    source: &Path,
    line: usize,
    what: &str,
    have: usize,
    more: usize,
) -> Result<()> {
    if have.saturating_add(more) <= MAX_POINTS {
        return Ok(());
    }
    let made = if more == 0 {
        format!("the program has made {have} CL points by {what}")
    } else {
        format!("{what} makes {more} CL points after {have}")
    };
    Err(Error::parse(
        source,
        line,
        format!(
            "{made}: more than the {MAX_POINTS} a toolpath may have (a loop, repeat counts or \
             arc turns that multiply the moves, or a program too long to solve at once): check \
             the jumps and repeat counts, or split the program"
        ),
    ))
}

/// Millimetres per inch.
pub const MM_PER_INCH: f64 = 25.4;

/// Length units of a program (APT `UNITS`, G-code G20/G21).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    Mm,
    Inch,
}

impl Units {
    /// Millimetres per program unit.
    pub fn mm_per_unit(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Inch => MM_PER_INCH,
        }
    }
}

/// How fast the move that arrives at a CL point may run, as the program says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Feed {
    /// A programmed feed in mm/s (already converted from the file's per-minute unit).
    Programmed(f64),
    /// A rapid move: the machine's maximum feed applies.
    Rapid,
    /// G-code inverse-time feed (G93): the block is programmed to take this long, seconds.
    BlockTime(f64),
    /// No feed was programmed before this move (APT: a `GOTO` before the first `FEDRAT`; a
    /// G-code feed move without a feed is an error): the machine's maximum feed applies.
    Unspecified,
}

/// One cutter-location point.
#[derive(Debug, Clone, PartialEq)]
pub struct ClPoint {
    /// Tool-tip position in workpiece coordinates, mm.
    pub p: Vector3<f64>,
    /// Unit tool orientation (from tip towards the spindle), normalised by the reader.
    pub o: Vector3<f64>,
    /// Feed of the move that ends at this point (the first point's feed is unused).
    pub feed: Feed,
    /// Rotary axis positions programmed for this point, degrees, as `[A, B, C]` (G-code in
    /// tool-tip mode gives them; `None` where the input gives a tool vector instead).
    pub rotary: Option<[f64; 3]>,
    /// 1-based line in the source file where the record starts.
    pub line: usize,
}

/// A toolpath as read from a file: CL points in program order. (`Default`: no points, no
/// source, nothing else; struct literals take the fields they set and `..Default::default()`.)
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Toolpath {
    /// The file it came from (for error messages).
    pub source: PathBuf,
    pub points: Vec<ClPoint>,
    /// Things the reader skipped or doubted, with their lines (never silently dropped).
    pub warnings: Vec<Warning>,
    /// Dwells (G4, a cycle's dwell at the bottom of a hole): the tool stands still at a CL
    /// point for a programmed time, which is part of the cycle time.
    pub dwells: Vec<Dwell>,
    /// The tools the program selects, in the order it runs (APT `CUTTER/`, `TLDATA/MILL`;
    /// G-code `T… M6`, `M61 Q…`, Sinumerik `T="name"`; Klartext `TOOL CALL`). Read by the
    /// material model ([`crate::material`]); the motion does not depend on them.
    pub tool_changes: Vec<ToolChange>,
    /// The spindle speeds the program sets, in the order it runs (G-code `S`, Klartext
    /// `TOOL CALL … S`, APT `SPINDL/`). Read by the material model's chip load.
    pub spindle_changes: Vec<SpindleChange>,
    /// The spindle and coolant switches the program makes, in the order it runs (G-code M3,
    /// M4, M5, M7, M8, M9, Klartext M13/M14; APT `SPINDL/…CLW`, `COOLNT/`). The motion does
    /// not depend on them; `feedopt gcode` writes them back where the program has them.
    pub switches: Vec<MachineSwitch>,
    /// The work offset the points are in, as the program names it before its first move
    /// (G-code `G55`, `G54.1 P3`); `None` where it names none (the control's default, an APT
    /// or Klartext program). `feedopt gcode` selects it.
    pub work_offset: Option<String>,
    /// The work offsets the program selects after its first move, in program order.
    pub offset_changes: Vec<OffsetChange>,
    /// The CL points the program places in machine coordinates (`G53`, `SUPA`, `M91`, the
    /// `G28`/`G30` reference points), in program order.
    pub machine_points: Vec<MachinePoint>,
    /// The tool length offsets the program switches, in program order, where its language
    /// has them (LinuxCNC and Fanuc G-code: `G43 H…`, `G44`, `G49`, and the `H` of tool-tip
    /// mode `G43.4`/`G43.5`/`G234`); `None` where it has none (APT, Sinumerik, Klartext: the
    /// control applies the tool's length with the tool). The motion does not depend on them
    /// (a 3-axis program without `G43` is the same path with Z shifted by the tool's
    /// length); `feedopt gcode` writes them back as the program has them, so that the
    /// written Z means what the program's meant.
    pub length_offsets: Option<Vec<LengthOffsetChange>>,
    /// The tapping cycles the program runs, one per hole, in program order. Their moves are
    /// timed as feeds at the tap's pitch × spindle speed, but on the control the cycle
    /// synchronises the spindle with the feed and reverses it at the bottom: `feedopt gcode`
    /// writes each back as the output control's tapping cycle, never as feed moves.
    pub taps: Vec<TapCycle>,
    /// The files the program's subprogram calls read, in the order read (empty: every line is
    /// the main program's). Every `line` of the toolpath (points, warnings, dwells, changes)
    /// counts in one sequence: the main program's lines 1 to n, then each of these files'
    /// lines after the lines of the files before it; [`Toolpath::place`] maps one back to
    /// its file and line there, [`Toolpath::line_name`] and [`Toolpath::file_line`] say it.
    pub files: Vec<SourceFile>,
}

/// A file a program's subprogram call read ([`Toolpath::files`]): its line n is line
/// `offset + n` of the toolpath.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceFile {
    pub path: PathBuf,
    /// The lines (of the main program and the files read before it) numbered before its own.
    pub offset: usize,
    /// Its line count.
    pub lines: usize,
}

impl Toolpath {
    /// A toolpath without warnings or dwells.
    pub fn new(source: PathBuf, points: Vec<ClPoint>) -> Self {
        Toolpath {
            source,
            points,
            ..Default::default()
        }
    }

    /// The file and its line of toolpath line `line` ([`Toolpath::files`]): the main
    /// program's (`source`) unless a subprogram's file holds it.
    pub fn place(&self, line: usize) -> (&Path, usize) {
        match self.files.iter().rev().find(|f| line > f.offset) {
            Some(f) => (&f.path, line - f.offset),
            None => (&self.source, line),
        }
    }

    /// `line 12`, or `line 12 of subs/O1002.nc` where a subprogram's file holds it.
    pub fn line_name(&self, line: usize) -> String {
        match self.place(line) {
            (_, local) if local == line => format!("line {line}"),
            (path, local) => format!("line {local} of {}", path.display()),
        }
    }

    /// `file:line` of toolpath line `line`, as a message about it starts
    /// (`prog.nc:12`, `subs/O1002.nc:3`).
    pub fn file_line(&self, line: usize) -> String {
        let (path, local) = self.place(line);
        format!("{}:{local}", path.display())
    }

    /// The line count of the main program where calls read other files (their lines come
    /// after it), else `None`: every line is the main program's.
    fn main_lines(&self) -> Option<usize> {
        self.files.first().map(|f| f.offset)
    }

    /// `text` with each `line N` whose N is a line of a file a call read ([`Toolpath::files`])
    /// as `line n of FILE` (one already so named is left as it is) (for messages of the stages after the reader, which number lines
    /// in the toolpath's sequence: `nearest CL line 1234`, `the last at line 1240`).
    pub fn name_lines(&self, text: &str) -> String {
        let Some(main) = self.main_lines() else {
            return text.to_string();
        };
        let mut out = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(at) = rest.find("line ") {
            let before = &rest[..at];
            let after = &rest[at + 5..];
            let digits = after.len() - after.trim_start_matches(|c: char| c.is_ascii_digit()).len();
            out.push_str(before);
            let word_start = !before.ends_with(|c: char| c.is_alphanumeric() || c == '_');
            // `line 3 of subs/O1002.nc` is named already.
            let named = after[digits..].starts_with(" of ");
            match after[..digits].parse::<usize>() {
                Ok(n) if word_start && !named && n > main => {
                    out.push_str(&self.line_name(n));
                }
                _ => {
                    out.push_str("line ");
                    out.push_str(&after[..digits]);
                }
            }
            rest = &after[digits..];
        }
        out.push_str(rest);
        out
    }

    /// An error of a stage after the reader about this toolpath, its lines named in their
    /// files: a parse error at a line of a file a call read names that file and line, and
    /// every `line N` in a message is named so ([`Toolpath::name_lines`]).
    pub fn in_files(&self, e: Error) -> Error {
        if self.files.is_empty() {
            return e;
        }
        match e {
            Error::Parse {
                file,
                line,
                message,
            } if file == self.source => {
                let (path, local) = self.place(line);
                Error::Parse {
                    file: path.to_path_buf(),
                    line: local,
                    message: self.name_lines(&message),
                }
            }
            Error::Infeasible(m) => Error::Infeasible(self.name_lines(&m)),
            Error::Solver(m) => Error::Solver(self.name_lines(&m)),
            Error::Usage(m) => Error::Usage(self.name_lines(&m)),
            e => e,
        }
    }

    /// A JSON value (a report about this toolpath) with each line of a file a call read
    /// named in its file: an object's `line` (and `first_move_line`, `last_line`) past the
    /// main program's lines becomes the line in that file, and a key beside it (`file`,
    /// `first_move_file`, `last_file`) names the file. Objects about the main program's lines
    /// are left as they are.
    pub fn name_json_lines(&self, value: &mut serde_json::Value) {
        let Some(main) = self.main_lines() else {
            return;
        };
        match value {
            serde_json::Value::Array(items) => {
                items.iter_mut().for_each(|v| self.name_json_lines(v));
            }
            serde_json::Value::Object(map) => {
                for (key, file_key) in [
                    ("line", "file"),
                    ("first_move_line", "first_move_file"),
                    ("last_line", "last_file"),
                ] {
                    let Some(n) = map.get(key).and_then(|v| v.as_u64()) else {
                        continue;
                    };
                    let n = n as usize;
                    if n > main {
                        let (path, local) = self.place(n);
                        let path = path.display().to_string();
                        map.insert(key.into(), local.into());
                        map.insert(file_key.into(), path.into());
                    }
                }
                for (_, v) in map.iter_mut() {
                    self.name_json_lines(v);
                }
            }
            _ => {}
        }
    }

    /// A parse error at toolpath line `line`, naming its file and its line there.
    pub fn error_at(&self, line: usize, message: impl Into<String>) -> Error {
        let (path, local) = self.place(line);
        Error::parse(path, local, message)
    }

    /// Total dwell time, seconds.
    pub fn dwell_time(&self) -> f64 {
        self.dwells.iter().fold(0.0, |sum, d| sum + d.seconds)
    }

    /// Whether the tool dwells at CL point `index` (the path must stop there).
    pub fn dwells_at(&self, index: usize) -> bool {
        self.dwells
            .iter()
            .any(|d| d.point == index && d.seconds > 0.0)
    }
}

/// One hole of a tapping cycle the program runs (Fanuc/LinuxCNC `G84`/`G74`, LinuxCNC
/// `G33.1`, Sinumerik `CYCLE84`, Klartext cycles 207/209, APT `CYCLE/TAP`): what `feedopt
/// gcode` needs to write it back as a cycle. `line` is the block that runs it (a hole of a
/// modal cycle, an `M99`, a `CYCL CALL`), `name` the cycle as the program writes it.
#[derive(Debug, Clone, PartialEq)]
pub struct TapCycle {
    pub line: usize,
    pub name: String,
    /// The CL points the cycle's feed into the hole and back out made (indices into
    /// [`Toolpath::points`]): the first is the hole's bottom, the last where the feed out
    /// ends; the point before them is where the feed in starts (the R plane, RFP + SDIS,
    /// the set-up clearance). More than two: the cycle breaks chips on the way.
    pub points: std::ops::Range<usize>,
    /// The feed into the hole and out of it, mm/min, as the reader timed them (pitch ×
    /// spindle speed where the program gives both).
    pub feed_in: f64,
    pub feed_out: f64,
    /// The thread's pitch, mm per revolution, where the program gives it (Sinumerik PIT or
    /// MPIT, Klartext Q239, LinuxCNC K); `None`: the feed and the speed give it.
    pub pitch: Option<f64>,
    /// The spindle speed the tap runs at, rpm (Sinumerik SST, else the speed in force), where
    /// the program gives one.
    pub rpm: Option<f64>,
    /// A left-hand thread (`G74`, a negative pitch, a spindle turning M4).
    pub left_hand: bool,
    /// The dwell at the bottom, s.
    pub dwell: f64,
    /// The direction the cycle feeds out of the hole in workpiece coordinates: +Z of the
    /// working plane in force (a tilted plane's, a frame's), or the tool axis (APT).
    pub axis: Vector3<f64>,
}

/// The tool stands still at CL point `point` (an index into [`Toolpath::points`]) for
/// `seconds` before the next move; `line` is the block or record that programs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dwell {
    pub point: usize,
    pub seconds: f64,
    pub line: usize,
}

/// A tool the program selects: by number (G-code `T5`, Klartext `TOOL CALL 5`, looked up in
/// a tool table), by name (Sinumerik `T="MILL_D10"`, Klartext `TOOL CALL "MILL_D10"`), or by
/// its geometry (APT `CUTTER/d, r`, NX `TLDATA/MILL, d, r, …`, in mm).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolSelect {
    /// A tool number.
    Number(u32),
    /// A tool name (as written, upper case in Sinumerik programs).
    Name(String),
    /// Diameter and corner radius, mm.
    Cutter {
        /// D, mm.
        diameter: f64,
        /// Corner radius, mm.
        corner_radius: f64,
    },
}

impl std::fmt::Display for ToolSelect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ToolSelect::Number(n) => write!(f, "T{n}"),
            ToolSelect::Name(s) => write!(f, "T=\"{s}\""),
            ToolSelect::Cutter {
                diameter,
                corner_radius,
            } => write!(f, "CUTTER/{diameter},{corner_radius}"),
        }
    }
}

/// The program puts `tool` in the spindle at `line`: the move ending at CL point `point` (an
/// index into [`Toolpath::points`], the number of points made before the change) and every
/// later one, up to the next change, cut with it.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolChange {
    pub point: usize,
    pub line: usize,
    pub tool: ToolSelect,
}

/// The program sets the spindle speed to `rpm` at `line`: the move ending at CL point `point`
/// (the number of points made before the change) and every later one, up to the next change,
/// run at it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpindleChange {
    pub point: usize,
    pub line: usize,
    pub rpm: f64,
}

impl SpindleChange {
    /// Appends the speed `rpm` (its magnitude) to `changes` from CL point `point` on; a speed
    /// that is not positive and finite, or the same as the last, changes nothing.
    pub(crate) fn record(changes: &mut Vec<SpindleChange>, point: usize, line: usize, rpm: f64) {
        let rpm = rpm.abs();
        if rpm.is_finite() && rpm > 0.0 && changes.last().is_none_or(|c| c.rpm != rpm) {
            changes.push(SpindleChange { point, line, rpm });
        }
    }
}

/// A machine function that does not move the tool: the spindle's or the coolant's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Switch {
    /// The spindle turns clockwise (M3, `SPINDL/…,CLW`).
    SpindleClockwise,
    /// The spindle turns counter-clockwise (M4, `SPINDL/…,CCLW`).
    SpindleCounterClockwise,
    /// The spindle stops (M5, `SPINDL/OFF`).
    SpindleStop,
    /// Mist coolant on (M7, `COOLNT/MIST`).
    CoolantMist,
    /// Flood coolant on (M8, `COOLNT/ON`, `COOLNT/FLOOD`).
    CoolantFlood,
    /// Coolant off (M9, `COOLNT/OFF`).
    CoolantOff,
}

/// The program makes `switch` at `line`. A switch that starts something (the spindle, the
/// coolant) comes before the move ending at CL point `point`; one that stops something comes
/// after the moves of its own block, so that `point` is the number of points made by then (a
/// control runs `G0 Z50 M5` as the retract, then the stop: the spindle does not stop in the
/// cut).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineSwitch {
    pub point: usize,
    pub line: usize,
    pub switch: Switch,
}

impl Switch {
    /// Whether it stops something (M5, M9): it takes effect after its block's motion.
    pub fn stops(self) -> bool {
        matches!(self, Switch::SpindleStop | Switch::CoolantOff)
    }
}

/// The program selects work offset `name` (`G55`, `G54.1 P3`) at `line`, before the move
/// ending at CL point `point`. `origin`: where the reader takes its origin to lie, X Y Z in
/// the toolpath's coordinates (those of [`Toolpath::work_offset`]): where the program sets it
/// (`G10`), there; otherwise equal to the offset before it, as the reader assumes (and says).
/// The points after it are the program's coordinates plus `origin` (and any `G52` or `G92`
/// shift).
#[derive(Debug, Clone, PartialEq)]
pub struct OffsetChange {
    pub point: usize,
    pub line: usize,
    pub name: String,
    pub origin: [f64; 3],
    /// The program gave this offset's origin (`G10 L2`, `L20`) rather than the reader taking
    /// it as equal to the one before: the control's stored offset is then not the one the
    /// program ran in, and `feedopt gcode`, which writes no `G10`, writes the points on in the
    /// offset in force, their coordinates carrying the difference.
    pub given: bool,
}

/// A tool length offset switched by the program ([`Toolpath::length_offsets`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthOffset {
    /// `G43` (and tool-tip mode's `G43.4`, `G43.5`, Haas `G234`) with offset number H
    /// (`None`: no H in the block and none the control would take: LinuxCNC takes the tool
    /// in the spindle, a Fanuc the last H given).
    Plus(Option<u32>),
    /// `G44 H…`: the offset subtracted.
    Minus(Option<u32>),
    /// `G49`: no length offset.
    Cancel,
}

/// The program switches `offset` at `line`, before the move ending at CL point `point` (a
/// control applies it with the block's own motion).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LengthOffsetChange {
    pub point: usize,
    pub line: usize,
    pub offset: LengthOffset,
}

/// CL point `point` is where a block in machine coordinates goes (the reader places it
/// through the machine file: its work offset, its reference points). `feedopt gcode` writes
/// such a block in machine coordinates, as the program does, not as the tip position the
/// machine file's values give.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachinePoint {
    pub point: usize,
    pub line: usize,
    pub kind: MachineMove,
}

/// How a block in machine coordinates names its target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MachineMove {
    /// `G53`, `SUPA`, `M91`: the axes X Y Z A B C it names (`None`: not named) to these
    /// machine coordinates, mm and degrees.
    Coordinates([Option<f64>; 6]),
    /// `G28` (`k` = 1) or `G30` (`k` = 2, or `P3`, `P4`): the named axes to reference point
    /// `k`, the control's own; `at`: the machine coordinates the reader took for it (the
    /// machine file's reference, else machine zero), for a dialect without the code.
    Reference {
        k: u8,
        axes: [bool; 6],
        at: [f64; 6],
    },
}

/// A reader's warning: a line and what about it. The message is shared (`Arc<str>`): a
/// reader that says the same thing of many blocks keeps one copy of its text, not one per
/// block (the Fanuc combined-feed rule's 390 characters on every block of a 51k-line
/// four-axis program: 20 MB).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    pub line: usize,
    pub message: std::sync::Arc<str>,
}

/// A reader's warnings with the same message, told once: the first, and how many more.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WarningGroup {
    /// The first occurrence (its line is the one to show).
    pub first: Warning,
    /// How many more warnings have the same message.
    pub more: usize,
    /// The line of the last of them (the first's when there is none).
    pub last_line: usize,
}

impl WarningGroup {
    /// Groups `warnings` by message, in the order of each message's first occurrence: a post
    /// that writes `K0.` on every G17 arc gives one group, not one warning per arc.
    pub fn group(warnings: &[Warning]) -> Vec<WarningGroup> {
        let mut groups: Vec<WarningGroup> = Vec::new();
        let mut index: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
        for w in warnings {
            match index.get(&*w.message) {
                Some(&k) => {
                    groups[k].more += 1;
                    groups[k].last_line = w.line;
                }
                None => {
                    index.insert(&*w.message, groups.len());
                    groups.push(WarningGroup {
                        first: w.clone(),
                        more: 0,
                        last_line: w.line,
                    });
                }
            }
        }
        groups
    }

    /// The message, with `(and N more like it, the last at line L)` when there are more.
    pub fn message(&self) -> String {
        match self.more {
            0 => self.first.message.to_string(),
            n => format!(
                "{} (and {n} more like it, the last at line {})",
                self.first.message, self.last_line
            ),
        }
    }

    /// [`Self::message`], the last line named in `toolpath`'s files ([`Toolpath::line_name`]).
    pub fn message_in(&self, toolpath: &Toolpath) -> String {
        match self.more {
            0 => self.first.message.to_string(),
            n => format!(
                "{} (and {n} more like it, the last at {})",
                self.first.message,
                toolpath.line_name(self.last_line)
            ),
        }
    }
}

/// What a reader needs to know about the machine the program runs on: which axes it has (an
/// axis word for any other is an error naming it), its reference positions (`G28`/`G30`) and
/// how machine coordinates (`G53`, `SUPA`, the reference points) map to program coordinates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MachineContext {
    /// The machine file, for messages that name a field to add.
    pub file: PathBuf,
    /// Axis letters the machine has; `None`: any of X Y Z A B C is accepted.
    pub axes: Option<Vec<char>>,
    /// Reference positions per axis X Y Z A B C, machine coordinates (mm, degrees): the first
    /// is `G28`'s, the second `G30`'s, … (empty: the file gives none).
    pub reference: [Vec<f64>; 6],
    /// Machine coordinates minus program coordinates, X Y Z, mm (the trunnion kinematics'
    /// `work-offset`, else the machine file's `work_offset`; zero where neither is given).
    pub work_offset: [f64; 3],
    /// The machine file gives the work offset (a trunnion's `kinematics.work-offset`, which
    /// defaults to zero, counts as given; else the file's `work_offset`).
    pub work_offset_given: bool,
    /// A `G28`/`G30` without axis words returns every axis (the machine file's
    /// `"g28_without_axes": "all"`, a Haas), in every dialect.
    pub g28_all_axes: bool,
    /// Travel `(min, max)` per axis X Y Z A B C, machine coordinates (mm, degrees), where the
    /// machine file gives it (Heidenhain `M140 MB MAX` retracts Z to its max).
    pub travel: [Option<(f64, f64)>; 6],
    /// Heidenhain's M92 datum per axis X Y Z, machine coordinates (mm), where the machine file
    /// gives it (`axes.Z.m92`).
    pub m92: [Option<f64>; 3],
    /// The unit the control reads a program that selects none in (`program_units`), where the
    /// machine file gives it.
    pub program_units: Option<crate::machine::LengthUnit>,
    /// How the control reads a Fanuc number without a decimal point (`decimal_point_input`),
    /// where the machine file gives it.
    pub decimal_point_input: Option<crate::machine::DecimalPointInput>,
    /// The diameter (mm) at which the control turns a G94 feed into degrees, per rotary axis
    /// A B C, where the machine file gives it (`axes.C.feed_diameter`; Haas settings 34/79).
    pub feed_diameter: [Option<f64>; 3],
    /// Per rotary axis A B C: whether it reaches an absolute position the shorter way,
    /// modulo 360° (`axes.A.shortest_way`: a modulo rotary axis set so), rather than by the
    /// sign of the difference.
    pub shortest_way: [bool; 3],
    /// The machine is programmed in machine coordinates (a four-axis machine,
    /// [`KinematicsSpec::FourthAxis`]): X Y Z and the angle are the axes' positions, not a tool
    /// tip, and it has no tool-tip mode.
    pub machine_coordinates: bool,
    /// The program's G41/G42 (Klartext RL/RR) offset only the tool's wear: its path is the
    /// tool centre's, and a reader takes it as programmed (the command line's
    /// `--wear-compensation`). Otherwise such a block is an error: the control moves the tool
    /// off the programmed path by the tool's radius, which feedopt does not model.
    pub wear_compensation: bool,
    /// The machine's kinematics, where the reader computes what a control computes from it
    /// (Klartext `PLANE … SEQ±`: which of the rotary axes' two solutions, Q120–Q122); `None`:
    /// the reader leaves that to the kinematics' own choice.
    pub kinematics: Option<crate::kinematics::Kinematics>,
}

impl MachineContext {
    /// The context of a machine and its reference positions.
    pub fn new(machine: &Machine, references: &References) -> Self {
        const NAMES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
        let axes = (machine.kinematics != KinematicsSpec::Joint).then(|| {
            machine
                .axes
                .iter()
                .filter_map(|a| a.name.chars().next().filter(|_| a.name.len() == 1))
                .collect()
        });
        let reference = std::array::from_fn(|i| {
            references
                .axes
                .iter()
                .find(|(n, _)| n == NAMES[i])
                .map(|(_, r)| r.clone())
                .unwrap_or_default()
        });
        let (work_offset, work_offset_given) = match &machine.kinematics {
            KinematicsSpec::TableTable { params, .. } => (params.work_offset, true),
            _ => match references.work_offset {
                Some(w) => (w, true),
                None => ([0.0; 3], false),
            },
        };
        let travel = std::array::from_fn(|i| {
            machine
                .axes
                .iter()
                .find(|a| a.name == NAMES[i])
                .and_then(|a| a.travel)
        });
        MachineContext {
            file: references.file.clone(),
            axes,
            reference,
            work_offset,
            work_offset_given,
            g28_all_axes: references.g28_all_axes,
            travel,
            m92: std::array::from_fn(|i| {
                references
                    .m92
                    .iter()
                    .find(|(n, _)| n == NAMES[i])
                    .map(|(_, d)| *d)
            }),
            program_units: references.program_units,
            decimal_point_input: references.decimal_point_input,
            machine_coordinates: machine.kinematics.machine_coordinates(),
            wear_compensation: false,
            feed_diameter: std::array::from_fn(|i| {
                references
                    .feed_diameter
                    .iter()
                    .find(|(n, _)| n == NAMES[3 + i])
                    .map(|(_, d)| *d)
            }),
            shortest_way: std::array::from_fn(|i| {
                references.shortest_way.iter().any(|n| n == NAMES[3 + i])
            }),
            kinematics: Some(crate::kinematics::Kinematics::new(machine)),
        }
    }

    /// Whether the machine has axis `letter` (always, when the machine is unknown).
    pub fn has_axis(&self, letter: char) -> bool {
        self.axes.as_ref().is_none_or(|a| a.contains(&letter))
    }
}

/// How to read an input: the format and G-code dialect (detected when `None`) and the machine.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    pub format: Option<Format>,
    pub dialect: Option<gcode::Dialect>,
    pub machine: Option<MachineContext>,
    /// Cycles read under another name ([`gcode::parse_cycle_alias`]: `("CYCLE76",
    /// "CYCLE86")` reads a machine builder's CYCLE76 as the standard CYCLE86).
    pub cycle_aliases: Vec<(String, String)>,
    /// The block-skip switch ([`gcode::Settings::block_delete`]): skip the blocks that start
    /// with `/` (default: run them).
    pub block_delete: bool,
    /// The tool's diameter, mm ([`gcode::Settings::tool_diameter`]).
    pub tool_diameter: Option<f64>,
    /// How a Fanuc number without a decimal point is read
    /// ([`gcode::Settings::decimal_point_input`]; `None`: the machine file's, else increments).
    pub decimal_point_input: Option<crate::machine::DecimalPointInput>,
    /// The dialect of a G-code input whose content and extension name none (`None`: the
    /// default, LinuxCNC); [`Self::dialect`] overrides detection altogether.
    pub fallback_dialect: Option<gcode::Dialect>,
    /// Where subprogram calls look for files ([`gcode::Settings::subprogram_dirs`]).
    pub subprogram_dirs: Vec<PathBuf>,
}

/// What a reader was used, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Detected {
    pub format: Format,
    /// The G-code dialect (G-code inputs only).
    pub dialect: Option<gcode::Dialect>,
    /// How the format and dialect were chosen: `"option"`, `"extension"`, `"content"` or
    /// `"default"` (for the dialect when nothing in the file tells).
    pub format_by: &'static str,
    pub dialect_by: &'static str,
    /// What the reader assumed where the machine file is silent ([`read_with`] fills it;
    /// [`detect`] leaves it empty).
    pub assumed: Assumed,
}

/// What a reader assumed where the program and the machine file leave something open.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Assumed {
    /// Axes X Y Z A B C that a `G28`/`G30` sent to a reference point the machine file does
    /// not give (`axes.Z.reference`): machine zero, machine coordinate 0, was used — the
    /// controls' default.
    pub reference_at_machine_zero: [bool; 6],
    /// A Fanuc, Sinumerik or LinuxCNC program selected no unit (G20/G21, G70/G71, G700/G710) and the
    /// machine file gives no `program_units`: it was read in mm, as a metric control does.
    pub units_mm: bool,
}

impl Assumed {
    /// One line saying what was assumed of the program's unit, or `None` when nothing was.
    pub fn units_note(&self) -> Option<String> {
        self.units_mm.then(|| {
            "the program selects no unit: read in mm, as a metric control does; set \
             program_units (\"mm\" or \"inch\") in the machine file"
                .to_string()
        })
    }

    /// One line saying what was assumed, or `None` when nothing was.
    pub fn reference_note(&self) -> Option<String> {
        const NAMES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
        let axes: Vec<&str> = NAMES
            .iter()
            .zip(self.reference_at_machine_zero)
            .filter(|(_, d)| *d)
            .map(|(n, _)| *n)
            .collect();
        (!axes.is_empty()).then(|| {
            let fields: Vec<String> = axes.iter().map(|a| format!("axes.{a}.reference")).collect();
            format!(
                "G28/G30 reference of {}: machine zero, the controls' default; set {} in the \
                 machine file",
                axes.join(", "),
                fields.join(", ")
            )
        })
    }
}

impl Format {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Format::Apt => "apt",
            Format::Gcode => "gcode",
            Format::Csv => "csv",
        }
    }
}

/// Extensions read as APT CL.
pub const APT_EXTENSIONS: &[&str] = &["cls", "clsf", "apt", "cl", "aptsource"];
/// Extensions read as G-code (`.mpf`/`.spf`: Sinumerik main program / subprogram; `.ptp`: NX
/// post output; `.h`: Heidenhain Klartext; `.txt`: by content).
pub const GCODE_EXTENSIONS: &[&str] = &[
    "ngc", "nc", "gcode", "tap", "mpf", "spf", "ptp", "eia", "min", "iso", "h", "txt",
];

/// Chooses the reader and dialect: the options first, then the file's content (a `GOTO/`
/// record is APT; a first block `BEGIN PGM` is Heidenhain Klartext; `TRAORI`, `MCALL`,
/// `CYCLE8…(`, `DEF REAL`, `SUPA`, `G710`/`G700` are Sinumerik; `G43.4`, `G43.5`, `G68.2`,
/// `G05.1`, `M98` or an `O1234` program number are Fanuc; `M428`–`M430`, `O<…>` or an O-word
/// keyword after an `O` number, `o100 sub`, are LinuxCNC), then the extension (`.mpf`, `.spf`: Sinumerik; `.h`: Heidenhain), else LinuxCNC.
pub fn detect(path: &Path, text: &str, options: &ReadOptions) -> Result<Detected> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let sample: String = text.lines().take(5000).collect::<Vec<_>>().join("\n");
    let upper = sample.to_ascii_uppercase();
    let apt_content = upper.lines().any(|l| {
        let l: String = l.chars().filter(|c| !c.is_whitespace()).collect();
        l.starts_with("GOTO/") || l.starts_with("FEDRAT/") || l.starts_with("MULTAX")
    });
    let (format, format_by) = if let Some(f) = options.format {
        (f, "option")
    } else if ext == "csv" {
        (Format::Csv, "extension")
    } else if apt_content {
        (Format::Apt, "content")
    } else if APT_EXTENSIONS.contains(&ext.as_str()) {
        (Format::Apt, "extension")
    } else if GCODE_EXTENSIONS.contains(&ext.as_str()) {
        (Format::Gcode, "extension")
    } else if gcode::is_klartext(&upper)
        || (upper.contains('G')
            && upper
                .lines()
                .any(|l| l.trim_start().starts_with(['G', 'N', 'X', 'Y', 'Z'])))
    {
        (Format::Gcode, "content")
    } else {
        return Err(Error::Usage(format!(
            "{}: cannot tell the toolpath format (extension `.{ext}`, and the content has \
             neither APT GOTO/ records nor G-code blocks); give --format apt|gcode|csv",
            path.display()
        )));
    };
    let (dialect, dialect_by) = if format != Format::Gcode {
        (None, "")
    } else if let Some(d) = options.dialect {
        (Some(d), "option")
    } else if let Some(d) = gcode::detect_dialect(&upper) {
        (Some(d), "content")
    } else if matches!(ext.as_str(), "mpf" | "spf") {
        (Some(gcode::Dialect::Sinumerik), "extension")
    } else if ext == "h" {
        (Some(gcode::Dialect::Heidenhain), "extension")
    } else {
        (
            Some(options.fallback_dialect.unwrap_or_default()),
            "default",
        )
    };
    Ok(Detected {
        format,
        dialect,
        format_by,
        dialect_by,
        assumed: Assumed::default(),
    })
}

/// Reads any input with `options`, detecting what they leave open; says what was used.
pub fn read_with(path: &Path, options: &ReadOptions) -> Result<(Input, Detected)> {
    let bytes = read_bytes(path)?;
    let text = String::from_utf8_lossy(&bytes);
    let mut detected = detect(path, &text, options)?;
    let input = match detected.format {
        Format::Csv => Input::Joint(joint_csv::parse(
            path,
            &crate::files::utf8(path, bytes.clone())?,
        )?),
        // The CL readers replace bytes that are not UTF-8 (Latin-1 comments).
        Format::Apt => Input::Cl(plausible(apt::parse_for(
            path,
            &text,
            options.machine.as_ref(),
        )?)?),
        Format::Gcode => {
            let settings = gcode::Settings {
                cycle_aliases: options.cycle_aliases.clone(),
                block_delete: options.block_delete,
                tool_diameter: options.tool_diameter,
                decimal_point_input: options.decimal_point_input,
                subprogram_dirs: options.subprogram_dirs.clone(),
                // Read in a dialect chosen for it (`feedopt gcode`'s output's), not the
                // default one `solve` reads it in.
                dialect_unnamed: detected.dialect_by == "default"
                    && options
                        .fallback_dialect
                        .is_some_and(|d| d != gcode::Dialect::default()),
                // (`.ngc` is LinuxCNC's own extension, though `detect` does not choose by it:
                // it is the default dialect.)
                dialect_defaulted: detected.dialect_by == "default"
                    && !path
                        .extension()
                        .is_some_and(|e| e.eq_ignore_ascii_case("ngc")),
            };
            let (toolpath, assumed) = gcode::parse_configured(
                path,
                &text,
                detected.dialect.unwrap_or_default().spec(),
                options.machine.as_ref(),
                &settings,
            )?;
            detected.assumed = assumed;
            Input::Cl(plausible(toolpath)?)
        }
    };
    Ok((input, detected))
}

/// The largest tool-tip coordinate a toolpath may give, mm (1 km): beyond it a number is a
/// typo or a wrong unit, and the path's length sets the work of every later stage.
pub const MAX_COORDINATE_MM: f64 = 1e6;

/// The smallest programmed feed, mm/s (1e-3 mm/min): below it the cycle time, and the work of
/// the re-simulation, grow without bound.
pub const MIN_FEED_MM_S: f64 = 1e-3 / 60.0;

/// A CL toolpath as read, checked for implausible magnitudes at the entry point (whatever the
/// reader): every tool-tip coordinate finite and within ±[`MAX_COORDINATE_MM`], every tool
/// vector finite, every programmed feed at least [`MIN_FEED_MM_S`] (the first point's feed is
/// unused). Errors name the line.
pub fn plausible(t: Toolpath) -> Result<Toolpath> {
    for (k, p) in t.points.iter().enumerate() {
        for (axis, x) in ["X", "Y", "Z"].iter().zip(p.p.iter()) {
            if !(x.is_finite() && x.abs() <= MAX_COORDINATE_MM) {
                return Err(crate::error::Error::parse(
                    &t.source,
                    p.line,
                    format!(
                        "tool tip {axis} = {} mm is beyond ±{MAX_COORDINATE_MM:e} mm (1 km): \
                         check the number and the units",
                        crate::error::number(*x)
                    ),
                ));
            }
        }
        if !p.o.iter().all(|x| x.is_finite()) {
            return Err(crate::error::Error::parse(
                &t.source,
                p.line,
                "the tool vector is not finite: give i, j, k as ordinary numbers",
            ));
        }
        if let (Feed::Programmed(f), true) = (p.feed, k > 0) {
            if !(f.is_finite() && f >= MIN_FEED_MM_S) {
                return Err(crate::error::Error::parse(
                    &t.source,
                    p.line,
                    format!(
                        "a feed of {} mm/min is below 1e-3 mm/min: check the number and the \
                         units",
                        crate::error::number(f * 60.0)
                    ),
                ));
            }
        }
    }
    Ok(t)
}

/// A toolpath file's bytes, at most [`crate::files::MAX_TOOLPATH_BYTES`] of them: a larger
/// file, or a device that never ends (`/dev/zero`), is refused before it is read.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    crate::files::read_bounded(path, crate::files::MAX_TOOLPATH_BYTES, "toolpath")
}

/// A tool vector shorter than this (after scaling) has no direction.
const MIN_TOOL_VECTOR_NORM: f64 = 1e-12;

/// The unit tool vector along `v`, or `None` when `v` has no direction (zero length). Scaled
/// by its largest component first, so that huge components cannot overflow and tiny ones
/// cannot underflow; the one normalisation of every reader.
pub fn unit_tool_vector(v: nalgebra::Vector3<f64>) -> Option<nalgebra::Vector3<f64>> {
    let largest = v.amax();
    let scaled_norm = if largest > 0.0 {
        (v / largest).norm()
    } else {
        0.0
    };
    (largest * scaled_norm >= MIN_TOOL_VECTOR_NORM).then(|| v / largest / scaled_norm)
}

/// Any input path: cutter locations or joint positions.
#[derive(Debug, Clone, PartialEq)]
pub enum Input {
    Cl(Toolpath),
    Joint(joint_csv::JointPath),
}

/// Reads any input path, detecting its format and dialect ([`detect`]).
pub fn read_input(path: &Path) -> Result<Input> {
    read_with(path, &ReadOptions::default()).map(|(input, _)| input)
}

/// An input format, to override the choice by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Apt,
    Gcode,
    Csv,
}

/// Reads any input path: in `format` if given, else detected; G-code in `dialect`.
pub fn read_as(path: &Path, format: Option<Format>, dialect: gcode::Dialect) -> Result<Input> {
    let options = ReadOptions {
        format,
        dialect: Some(dialect),
        ..Default::default()
    };
    read_with(path, &options).map(|(input, _)| input)
}

/// Reads a CL toolpath file (APT or G-code), detecting its format and dialect ([`detect`]).
pub fn read(path: &Path) -> Result<Toolpath> {
    match read_with(path, &ReadOptions::default())? {
        (Input::Cl(t), _) => Ok(t),
        (Input::Joint(_), _) => Err(Error::Usage(format!(
            "{}: a joint-space path, not a CL toolpath",
            path.display()
        ))),
    }
}

impl crate::kinematics::CutterLocation for ClPoint {
    fn tip(&self) -> Vector3<f64> {
        self.p
    }

    fn tool_axis(&self) -> Vector3<f64> {
        self.o
    }

    fn rotary(&self) -> Option<[f64; 3]> {
        self.rotary
    }

    fn line(&self) -> usize {
        self.line
    }
}
