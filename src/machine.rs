//! Machine files: the kinematics and every axis's limits (JSON; mm, degrees, seconds).
//!
//! ```json
//! {"name": "seed double swivel head",
//!  "kinematics": {"type": "head_head", "tool_length": 200.0},
//!  "axes": {"X": {"velocity": 400, "acceleration": 2000}, "Y": {...}, "Z": {...},
//!           "C": {"velocity": 120, "acceleration": 600}, "A": {"velocity": 60, "acceleration": 400}},
//!  "feed": {"max": 150}}
//! ```
//!
//! A limit is a number (symmetric, `> 0`) or `[min, max]` with `min < 0 < max`. Linear axes are
//! in mm/s and mm/s², rotary axes in °/s and °/s². An optional `"jerk"` (number or `[min, max]`,
//! mm/s³ or °/s³) makes the schedule jerk-limited. An axis may also give its travel, `"min"` and
//! `"max"` (mm or degrees, both or neither, `min < max`). `feed.max` (mm/s) caps the tool-tip
//! feed V; the `feed` section is optional. The optional `stock`, `tool`, `tools` and `process` sections
//! belong to the material model and are read by [`crate::material::from_machine_file`].
//! Unknown fields, missing axes or limits,
//! non-positive limits and keys given twice in one object are errors that name the field; so
//! are implausible magnitudes: limits outside [`MIN_LIMIT`]…[`MAX_LIMIT`] of their unit (jerk
//! up to [`MAX_JERK_LIMIT`]) and lengths beyond ±[`MAX_LENGTH`] mm.
//!
//! An axis may give its **reference position**, `"reference": 0.0` (mm or degrees, machine
//! coordinates), or several, `"reference": [0.0, -250.0]`: the first is the point `G28`
//! (Fanuc, LinuxCNC) returns to, the second the one `G30` goes to (`G30 P3`: the third, …).
//! Only the toolpath readers use it ([`References`], read by [`Machine::references_from_file`]).
//! Where a program needs a reference the file lacks, the readers use machine zero (machine
//! coordinate 0), the controls' default: Fanuc's reference positions (parameters 1240–1243)
//! and LinuxCNC's G28/G30 positions (parameters 5161–5169, 5181–5189) are 0 in machine
//! coordinates until set, and a Fanuc's machine zero is set at its reference position; they
//! say so (a warning naming `axes.Z.reference`, the summary's `reference` line). Machine
//! coordinates (`G28`, `G53`, Sinumerik `SUPA`, Heidenhain `M91`) are program coordinates plus
//! the kinematics' `work-offset` (trunnion tables) or, for every other kinematics, the file's
//! top-level `"work_offset": [x, y, z]` (mm: the machine coordinates of the program's origin,
//! the G54 offset; [`References::work_offset`]); where a program moves in machine coordinates
//! and the file gives neither, they are the program coordinates themselves, with a warning
//! naming `work_offset` (`G53 Z0`, the top of Z's travel, is otherwise the part's Z0). X, Y and Z may give Heidenhain's **M92 datum**, `"m92": 180.0`
//! (machine coordinates, mm), the machine builder's: an `M92` block's coordinates are relative
//! to it (machine zero, with a warning, where the file gives none). A rotary axis may give the
//! **diameter its feed is taken at**, `"feed_diameter": 50.0` (mm; Haas settings 34 and 79, the
//! "4th/5th axis diameter"): a Fanuc-family program's G94 feed then counts a degree of that axis
//! as π·D/360 mm of the block's distance instead of one unit of length (only the readers use it,
//! as [`References::feed_diameter`]). A rotary axis may be a modulo axis that reaches an
//! absolute position **the shorter way**, `"shortest_way": true` (Sinumerik MD30455 bit 2,
//! Fanuc 1008 RAB = 0, LinuxCNC `WRAPPED_ROTARY`; [`References::shortest_way`]).
//!
//! Kinematics types and their parameters (see [`crate::kinematics`] for the maths):
//!
//! | `type` | axes | parameters |
//! |---|---|---|
//! | `xyz` | X Y Z | – |
//! | `xyza`, `xyzb`, `xyzc` | X Y Z and A, B or C | – (programmed in machine coordinates: X Y Z and the angle are the axes' positions, [`KinematicsSpec::FourthAxis`]) |
//! | `head_head` | X Y Z C A | `tool_length` (> 0) |
//! | `table_table_ac` | X Y Z A C | LinuxCNC xyzac-trt: `x-rot-point`, `y-rot-point`, `z-rot-point`, `y-offset`, `z-offset` (required); `tool-offset` (0), `conventional-directions` (false), `work-offset` ([0, 0, 0]) |
//! | `table_table_bc` | X Y Z B C | LinuxCNC xyzbc-trt: the same with `x-offset` instead of `y-offset` |
//! | `table_table_ab` | X Y Z A B | a Haas TR-series A/B trunnion: A tilts about X, B turns the platter (machine +Z at A = 0); `table_table_ac`'s parameters, the rot-point being B's centre |
//! | `head_table` | X Y Z B C, or X Y Z A B with `"table": "A"` | `pivot_length` (≥ 0); `table` (`"C"`, the default: a rotary table about Z; `"A"`: a rotary axis about X, as on a blade mill's A axis between centres) |
//! | `dresser` | X Z B | `tool_length` (≥ 0) |
//! | `joint` | as the file names them | – |

use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// A two-sided limit on an axis quantity: `min < 0 < max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit {
    /// The negative side.
    pub min: f64,
    /// The positive side.
    pub max: f64,
}

impl Limit {
    /// A symmetric limit `[-v, v]`.
    pub fn symmetric(v: f64) -> Self {
        Limit { min: -v, max: v }
    }

    /// Ratio of `value` to the bound on its side (`value/max` or `value/min`), always ≥ 0.
    pub fn ratio(&self, value: f64) -> f64 {
        if value >= 0.0 {
            value / self.max
        } else {
            value / self.min
        }
    }
}

/// Linear (mm) or rotary (degrees) axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisKind {
    /// Millimetres.
    Linear,
    /// Degrees.
    Rotary,
}

/// One machine axis with its velocity and acceleration limits (file units).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Axis name (`X`, `C`, or a joint-space machine's own).
    pub name: String,
    /// Linear or rotary.
    pub kind: AxisKind,
    /// Velocity limit, mm/s or °/s.
    pub velocity: Limit,
    /// Acceleration limit, mm/s² or °/s².
    pub acceleration: Limit,
    /// Jerk limit (mm/s³ or °/s³), `None` when the file gives none: the schedule is then
    /// acceleration-limited (issue 6).
    pub jerk: Option<Limit>,
    /// Travel `(min, max)` of the axis position (mm or degrees), `None` when the file gives
    /// none.
    pub travel: Option<(f64, f64)>,
}

impl Axis {
    /// Whether position `x` (mm or degrees) lies within the axis's travel (always, without
    /// travel).
    pub fn within_travel(&self, x: f64) -> bool {
        self.travel.is_none_or(|(lo, hi)| x >= lo && x <= hi)
    }

    /// The travel `(min, max)` that position `x` leaves by more than rounding (1e-9 of the
    /// travel's larger end, plus 1e-9), if it does: what the solve checks at CL points and
    /// stations.
    pub fn travel_exceeded(&self, x: f64) -> Option<(f64, f64)> {
        let (lo, hi) = self.travel?;
        let tol = 1e-9 * (1.0 + lo.abs().max(hi.abs()));
        (!(lo - tol..=hi + tol).contains(&x)).then_some((lo, hi))
    }
}

/// The rotary axis of a four-axis machine ([`KinematicsSpec::FourthAxis`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FourthAxis {
    /// A, about X (a rotary table or indexer on a mill's or router's table).
    A,
    /// B, about Y (a horizontal machining centre's table).
    B,
    /// C, about Z.
    C,
}

impl FourthAxis {
    /// The axis letter.
    pub fn letter(self) -> &'static str {
        match self {
            FourthAxis::A => "A",
            FourthAxis::B => "B",
            FourthAxis::C => "C",
        }
    }

    /// Its index in a program's `[A, B, C]` rotary words.
    pub fn index(self) -> usize {
        match self {
            FourthAxis::A => 0,
            FourthAxis::B => 1,
            FourthAxis::C => 2,
        }
    }
}

/// The rotary axis that carries the workpiece on a head–table machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RotaryTable {
    /// A rotary table C about Z.
    #[default]
    C,
    /// A rotary axis A about X (a blade mill's workpiece between centres).
    A,
}

/// Which table tilts in a trunnion ("table-rotary-tilting") machine, and the platter's letter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrunnionTilt {
    /// xyzac-trt: the tilt axis A is parallel to X; the platter is C.
    A,
    /// xyzbc-trt: the tilt axis B is parallel to Y; the platter is C.
    B,
    /// `table_table_ab`, a Haas TR-series table: the tilt axis A is parallel to X as in
    /// xyzac-trt, and the platter, which turns about the table's normal (machine +Z at A = 0),
    /// is lettered B (Haas names a trunnion's fifth axis B, not by ISO's about-Y rule).
    AB,
}

impl TrunnionTilt {
    /// Whether the tilt axis is parallel to X (A) rather than Y (B).
    pub fn about_x(self) -> bool {
        matches!(self, TrunnionTilt::A | TrunnionTilt::AB)
    }

    /// The letters of the tilt and the platter axes.
    pub fn letters(self) -> [&'static str; 2] {
        match self {
            TrunnionTilt::A => ["A", "C"],
            TrunnionTilt::B => ["B", "C"],
            TrunnionTilt::AB => ["A", "B"],
        }
    }
}

/// The parameters of LinuxCNC's xyzac-trt / xyzbc-trt kinematics (HAL pin names in the
/// machine file), plus the work offset (G54) added to the program coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrunnionParams {
    /// `x-rot-point`, `y-rot-point`, `z-rot-point`: the platter's (C, or B for AB) centre in
    /// machine coordinates, mm.
    pub rot_point: [f64; 3],
    /// The tilt axis's offset from the platter centre across it: `y-offset` for AC and AB,
    /// `x-offset` for BC, mm.
    pub tilt_offset: f64,
    /// `z-offset`: the tilt axis's height above the C centre, mm.
    pub z_offset: f64,
    /// `tool-offset`: the tool length L in force, mm (default 0).
    pub tool_offset: f64,
    /// `conventional-directions` (default false): `true` turns both rotary axes the other way
    /// (σ = −1).
    pub conventional_directions: bool,
    /// `work-offset` [x, y, z]: the work offset added to the program coordinates, mm
    /// (default 0).
    pub work_offset: [f64; 3],
}

/// The machine's kinematic structure.
#[derive(Debug, Clone, PartialEq)]
pub enum KinematicsSpec {
    /// Three linear axes X, Y, Z follow the tool tip; orientation is ignored.
    Xyz,
    /// Seed 000's fixed-bed double swivel head: θ1 = axis C about z, θ2 = axis A,
    /// `tool_length` = d2 (pivot to tool tip, mm). Eq. 15–16 and 27.
    HeadHead {
        /// Pivot to tool tip (d2), mm.
        tool_length: f64,
    },
    /// LinuxCNC's xyzac-trt (`tilt` A, axes X Y Z A C) or xyzbc-trt (`tilt` B, axes
    /// X Y Z B C) table-rotary-tilting machine, or a Haas TR-series A/B table (`tilt` AB, axes
    /// X Y Z A B: xyzac-trt with the platter lettered B).
    TableTable {
        /// Which table tilts.
        tilt: TrunnionTilt,
        /// The LinuxCNC parameters.
        params: TrunnionParams,
    },
    /// A tilting head B (about Y) with a rotary table C (about Z; axes X Y Z B C) or a rotary
    /// axis A (about X, a blade mill's workpiece between centres; axes X Y Z A B);
    /// `pivot_length` (mm) from the B pivot to the tool tip.
    HeadTable {
        /// B pivot to tool tip, mm.
        pivot_length: f64,
        /// The rotary axis that carries the workpiece.
        table: RotaryTable,
    },
    /// Seed 001's dresser: planar X–Z slides and a rotary axis B that keeps the dressing tool
    /// on the profile normal; `tool_length` (mm) from the B axis to the tool tip. Axes X Z B.
    Dresser {
        /// B axis to tool tip, mm.
        tool_length: f64,
    },
    /// A joint-space path (CSV of axis positions along a parameter s): any axes, named as in
    /// the CSV's `q_<axis>` columns, in the file's order; no feed limit applies.
    Joint,
    /// Three linear axes and a fourth, rotary one (`xyza`, `xyzb`, `xyzc`: a rotary table or
    /// indexer), programmed in machine coordinates: a program's X Y Z and angle are the axes'
    /// positions, each block a straight move of all four (no tool-tip mode). The path is the
    /// axes' own, so the feed cap applies to X Y Z's speed and the rotary axis follows.
    FourthAxis(FourthAxis),
}

impl KinematicsSpec {
    /// Axis names in the order the kinematics produces them (empty for `Joint`: the machine
    /// file names its axes).
    pub fn axis_names(&self) -> &'static [&'static str] {
        match self {
            KinematicsSpec::Xyz => &["X", "Y", "Z"],
            KinematicsSpec::HeadHead { .. } => &["X", "Y", "Z", "C", "A"],
            KinematicsSpec::TableTable { tilt, .. } => match tilt {
                TrunnionTilt::A => &["X", "Y", "Z", "A", "C"],
                TrunnionTilt::B => &["X", "Y", "Z", "B", "C"],
                TrunnionTilt::AB => &["X", "Y", "Z", "A", "B"],
            },
            KinematicsSpec::HeadTable {
                table: RotaryTable::C,
                ..
            } => &["X", "Y", "Z", "B", "C"],
            KinematicsSpec::HeadTable {
                table: RotaryTable::A,
                ..
            } => &["X", "Y", "Z", "A", "B"],
            KinematicsSpec::Dresser { .. } => &["X", "Z", "B"],
            KinematicsSpec::FourthAxis(FourthAxis::A) => &["X", "Y", "Z", "A"],
            KinematicsSpec::FourthAxis(FourthAxis::B) => &["X", "Y", "Z", "B"],
            KinematicsSpec::FourthAxis(FourthAxis::C) => &["X", "Y", "Z", "C"],
            KinematicsSpec::Joint => &[],
        }
    }

    /// Whether the machine is programmed in machine coordinates (a four-axis machine): a
    /// program's X Y Z and angles are the axes' positions, not a tool tip, and it has no
    /// tool-tip mode.
    pub fn machine_coordinates(&self) -> bool {
        matches!(self, KinematicsSpec::FourthAxis(_))
    }

    /// Whether an axis of this name is rotary (A, B, C: degrees) or linear (mm) in a machine
    /// with kinematics (a joint-space machine's axes are all treated as linear).
    pub fn axis_kind(name: &str) -> AxisKind {
        match name {
            "A" | "B" | "C" => AxisKind::Rotary,
            _ => AxisKind::Linear,
        }
    }
}

/// A machine: kinematics, axes (in the kinematics' order) and the feed cap.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// The machine's name (for reports).
    pub name: String,
    /// The kinematic structure.
    pub kinematics: KinematicsSpec,
    /// The axes, in the kinematics' order.
    pub axes: Vec<Axis>,
    /// Maximum tool-tip feed, mm/s (`None`: only the axes limit the feed).
    pub feed_max: Option<f64>,
}

impl Machine {
    /// The same machine without jerk limits (for an acceleration-limited schedule).
    pub fn without_jerk(&self) -> Machine {
        let mut m = self.clone();
        for a in &mut m.axes {
            a.jerk = None;
        }
        m
    }

    /// Whether any axis has a jerk limit (the schedule is then jerk-limited).
    pub fn has_jerk(&self) -> bool {
        self.axes.iter().any(|a| a.jerk.is_some())
    }

    /// Reads and validates a machine file.
    pub fn from_file(path: &Path) -> Result<Machine> {
        let bytes =
            crate::files::read_bounded(path, crate::files::MAX_MACHINE_FILE_BYTES, "machine file")?;
        Machine::from_json(path, &crate::files::utf8(path, bytes)?)
    }

    /// Parses and validates machine JSON; `source` names the file in errors.
    pub fn from_json(source: &Path, text: &str) -> Result<Machine> {
        let value: Value = serde_json::from_str(text).map_err(|e| Error::Parse {
            file: source.to_path_buf(),
            line: e.line(),
            message: format!("invalid JSON: {e}"),
        })?;
        // A JSON object keeps only one value per key (the last); a key given twice is a
        // mistake feedopt does not guess about.
        if let Some((field, line)) = duplicate_key(text) {
            return Err(Error::field(
                source,
                field,
                format!(
                    "given twice in one object (the second time on line {line}): remove one of them"
                ),
            ));
        }
        Parser {
            file: source.to_path_buf(),
        }
        .machine(&value)
    }
}

/// Every axis's reference positions (machine coordinates, mm or degrees), in the machine's
/// axis order: `axes[k]` is `(name, [first, second, …])`, empty where the file gives none.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct References {
    /// The machine file (for messages naming the field to add).
    pub file: PathBuf,
    /// Per axis: its name and reference positions.
    pub axes: Vec<(String, Vec<f64>)>,
    /// The axes that give Heidenhain's M92 datum (`"m92"`, machine coordinates, mm): name and
    /// datum.
    pub m92: Vec<(String, f64)>,
    /// `"program_units"`: the unit the control reads a program in that selects none (Fanuc
    /// and Sinumerik set it by a parameter or machine datum, LinuxCNC in its INI file, not in
    /// the program); `None`: the file does not say.
    pub program_units: Option<LengthUnit>,
    /// `"decimal_point_input"`: how the control reads a number written without a decimal
    /// point (Fanuc parameter 3401#0, DPI); `None`: the file does not say.
    pub decimal_point_input: Option<DecimalPointInput>,
    /// The rotary axes that give `"feed_diameter"` (mm): name and diameter D, at which a
    /// Fanuc-family control (Haas settings 34/79) turns a G94 feed into degrees, a degree
    /// counting as π·D/360 mm.
    pub feed_diameter: Vec<(String, f64)>,
    /// The rotary axes that give `"shortest_way": true`: a modulo ("roll-over") rotary axis
    /// that reaches an absolute position the shorter way, modulo 360° (Sinumerik MD30455 bit
    /// 2, Fanuc parameter 1008 ROA with RAB = 0, LinuxCNC `WRAPPED_ROTARY`).
    pub shortest_way: Vec<String>,
    /// `"work_offset"` [x, y, z]: where the program's origin lies in machine coordinates, mm
    /// (the work offset in force, G54's: machine coordinates minus program coordinates), for
    /// the kinematics that have no `work-offset` of their own; `None`: the file does not say.
    /// The readers need it where a program moves in machine coordinates (`G53`, `G28`/`G30`
    /// to the reference point, `SUPA`, `M91`).
    pub work_offset: Option<[f64; 3]>,
    /// `"g28_without_axes": "all"`: a `G28`/`G30` without axis words returns every axis to its
    /// reference point, as a Haas does (a Fanuc returns none); without it such a block is an
    /// error in the dialects that do not say (Fanuc).
    pub g28_all_axes: bool,
}

/// How a Fanuc control reads an axis word written without a decimal point (`X100`):
/// parameter 3401#0, DPI.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecimalPointInput {
    /// DPI = 0, Fanuc's default: the number counts least input increments (`X100` is 0.1 mm
    /// under G21, 0.01 inch under G20, 0.1° on a rotary axis).
    Increment,
    /// DPI = 1, "calculator-type" input: the number is in mm, inch or degrees (`X100` is
    /// 100 mm), as LinuxCNC, grbl and Mach3 read it.
    Calculator,
}

impl DecimalPointInput {
    /// The name in machine files and on the command line (`increment`, `calculator`).
    pub fn name(self) -> &'static str {
        match self {
            DecimalPointInput::Increment => "increment",
            DecimalPointInput::Calculator => "calculator",
        }
    }
}

impl std::str::FromStr for DecimalPointInput {
    type Err = Error;

    /// `increment` or `calculator`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "increment" => Ok(DecimalPointInput::Increment),
            "calculator" => Ok(DecimalPointInput::Calculator),
            other => Err(Error::Usage(format!(
                "unknown decimal-point input `{other}`: expected increment (a Fanuc control \
                 with parameter 3401#0 DPI = 0: X100 is 0.1 mm) or calculator (DPI = 1: X100 \
                 is 100 mm)"
            ))),
        }
    }
}

/// A program's length unit (F in that unit per minute).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// Millimetres.
    Mm,
    /// Inches.
    Inch,
}

impl Machine {
    /// Reads a machine file and the axes' optional `reference` positions.
    pub fn references_from_file(path: &Path) -> Result<(Machine, References)> {
        let bytes =
            crate::files::read_bounded(path, crate::files::MAX_MACHINE_FILE_BYTES, "machine file")?;
        let text = crate::files::utf8(path, bytes)?;
        let machine = Machine::from_json(path, &text)?;
        let references = references_from_json(path, &text, &machine)?;
        Ok((machine, references))
    }
}

/// The axes' `reference` positions of a machine file already read as `machine`.
pub fn references_from_json(source: &Path, text: &str, machine: &Machine) -> Result<References> {
    let value: Value = serde_json::from_str(text).map_err(|e| Error::Parse {
        file: source.to_path_buf(),
        line: e.line(),
        message: format!("invalid JSON: {e}"),
    })?;
    let parser = Parser {
        file: source.to_path_buf(),
    };
    let mut axes = Vec::new();
    let mut m92 = Vec::new();
    let mut feed_diameter = Vec::new();
    let mut shortest_way = Vec::new();
    for axis in &machine.axes {
        // The axis object's field `name`, if given.
        let given = |name: &str| {
            value
                .get("axes")
                .and_then(|a| a.get(&axis.name))
                .and_then(|a| a.get(name))
        };
        let field = format!("axes.{}.feed_diameter", axis.name);
        if let Some(v) = given("feed_diameter") {
            if axis.kind != AxisKind::Rotary {
                return Err(parser.err(
                    &field,
                    "only a rotary axis (A, B, C) has a feed diameter: leave it out",
                ));
            }
            let d = parser.number(Some(v), &field)?;
            if !(d > 0.0 && d <= MAX_LENGTH) {
                return Err(parser.err(
                    &field,
                    format!(
                        "must be a diameter in mm, above 0 and at most {MAX_LENGTH:e}, found {}",
                        crate::error::number(d)
                    ),
                ));
            }
            feed_diameter.push((axis.name.clone(), d));
        }
        let field = format!("axes.{}.shortest_way", axis.name);
        if let Some(v) = given("shortest_way") {
            if axis.kind != AxisKind::Rotary {
                return Err(parser.err(
                    &field,
                    "only a rotary axis (A, B, C) turns the shorter way: leave it out",
                ));
            }
            match v.as_bool() {
                Some(true) => shortest_way.push(axis.name.clone()),
                Some(false) => {}
                None => {
                    return Err(parser.err(
                        &field,
                        format!(
                            "must be true (an absolute position is reached the shorter way, \
                             modulo 360°) or false (by the sign of the difference), found {v}"
                        ),
                    ));
                }
            }
        }
        let field = format!("axes.{}.m92", axis.name);
        if let Some(v) = given("m92") {
            if !matches!(axis.name.as_str(), "X" | "Y" | "Z") {
                return Err(parser.err(&field, "only X, Y and Z have an M92 datum"));
            }
            let d = parser.coordinate(v, &field)?;
            m92.push((axis.name.clone(), d));
        }
        let field = format!("axes.{}.reference", axis.name);
        let list = match given("reference") {
            None => Vec::new(),
            Some(Value::Array(items)) if !items.is_empty() => items
                .iter()
                .map(|v| parser.number(Some(v), &field))
                .collect::<Result<Vec<f64>>>()?,
            Some(v @ Value::Number(_)) => vec![parser.number(Some(v), &field)?],
            Some(v) => {
                return Err(parser.err(
                    &field,
                    format!("expected a number or a list of numbers (mm or °), found {v}"),
                ));
            }
        };
        axes.push((axis.name.clone(), list));
    }
    let program_units = match value.get("program_units") {
        None => None,
        Some(Value::String(u)) if u == "mm" => Some(LengthUnit::Mm),
        Some(Value::String(u)) if u == "inch" => Some(LengthUnit::Inch),
        Some(v) => {
            return Err(parser.err(
                "program_units",
                format!(
                    "expected \"mm\" or \"inch\" (the unit the control reads a program that \
                     selects none in), found {v}"
                ),
            ));
        }
    };
    let decimal_point_input = match value.get("decimal_point_input") {
        None => None,
        Some(Value::String(u)) if u == "increment" => Some(DecimalPointInput::Increment),
        Some(Value::String(u)) if u == "calculator" => Some(DecimalPointInput::Calculator),
        Some(v) => {
            return Err(parser.err(
                "decimal_point_input",
                format!(
                    "expected \"increment\" (a Fanuc control with parameter 3401#0 DPI = 0: \
                     X100 is 0.1 mm) or \"calculator\" (DPI = 1: X100 is 100 mm), found {v}"
                ),
            ));
        }
    };
    let work_offset = match value.get("work_offset") {
        None => None,
        Some(_) if matches!(machine.kinematics, KinematicsSpec::TableTable { .. }) => {
            return Err(parser.err(
                "work_offset",
                "a trunnion table gives its work offset as kinematics.work-offset: give it there",
            ));
        }
        Some(_) if machine.kinematics == KinematicsSpec::Joint => {
            return Err(parser.err(
                "work_offset",
                "a joint-space path has no program coordinates: remove it",
            ));
        }
        Some(Value::Array(items)) if items.len() == 3 => {
            let mut w = [0.0; 3];
            for (k, v) in items.iter().enumerate() {
                let field = format!("work_offset[{k}]");
                w[k] = parser.coordinate(v, &field)?;
            }
            Some(w)
        }
        Some(v) => {
            return Err(parser.err(
                "work_offset",
                format!(
                    "expected [x, y, z]: the machine coordinates of the program's origin (the \
                     G54 offset), mm, found {v}"
                ),
            ));
        }
    };
    let g28_all_axes = match value.get("g28_without_axes") {
        None => false,
        Some(Value::String(u)) if u == "all" => true,
        Some(v) => {
            return Err(parser.err(
                "g28_without_axes",
                format!(
                    "expected \"all\" (a G28 or G30 without axis words returns every axis to \
                     its reference point, as a Haas does), found {v}"
                ),
            ));
        }
    };
    Ok(References {
        file: source.to_path_buf(),
        axes,
        m92,
        program_units,
        decimal_point_input,
        feed_diameter,
        shortest_way,
        work_offset,
        g28_all_axes,
    })
}

/// The smallest limit a machine file may give, in its unit (mm/s, mm/s², mm/s³, °/s, …, or
/// mm/s for `feed.max`): below it a schedule would take ages, and the value is more likely a
/// wrong unit than a machine.
pub const MIN_LIMIT: f64 = 1e-6;

/// The largest velocity or acceleration limit (and `feed.max`) a machine file may give.
pub const MAX_LIMIT: f64 = 1e9;

/// The largest jerk limit a machine file may give.
pub const MAX_JERK_LIMIT: f64 = 1e12;

/// The largest length a machine file may give (tool and pivot lengths, trunnion offsets, work
/// offsets, travel), in mm or degrees: 1 km.
pub const MAX_LENGTH: f64 = 1e6;

/// The dotted path and line of the first key that appears twice in one JSON object of `text`
/// (already known to be valid JSON), if any.
fn duplicate_key(text: &str) -> Option<(String, usize)> {
    use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
    use std::cell::RefCell;
    use std::collections::HashSet;

    /// Walks any JSON value; `found` receives the path of a repeated key.
    struct Walk<'a> {
        path: String,
        found: &'a RefCell<Option<String>>,
    }

    impl<'de> DeserializeSeed<'de> for Walk<'_> {
        type Value = ();
        fn deserialize<D: Deserializer<'de>>(self, d: D) -> std::result::Result<(), D::Error> {
            d.deserialize_any(self)
        }
    }

    impl<'de> Visitor<'de> for Walk<'_> {
        type Value = ();
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("any JSON value")
        }
        fn visit_bool<E>(self, _: bool) -> std::result::Result<(), E> {
            Ok(())
        }
        fn visit_i64<E>(self, _: i64) -> std::result::Result<(), E> {
            Ok(())
        }
        fn visit_u64<E>(self, _: u64) -> std::result::Result<(), E> {
            Ok(())
        }
        fn visit_f64<E>(self, _: f64) -> std::result::Result<(), E> {
            Ok(())
        }
        fn visit_str<E>(self, _: &str) -> std::result::Result<(), E> {
            Ok(())
        }
        fn visit_unit<E>(self) -> std::result::Result<(), E> {
            Ok(())
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<(), A::Error> {
            let mut i = 0;
            while seq
                .next_element_seed(Walk {
                    path: format!("{}[{i}]", self.path),
                    found: self.found,
                })?
                .is_some()
            {
                i += 1;
            }
            Ok(())
        }
        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> std::result::Result<(), A::Error> {
            let mut seen = HashSet::new();
            while let Some(key) = map.next_key::<String>()? {
                let path = if self.path.is_empty() {
                    key.clone()
                } else {
                    format!("{}.{key}", self.path)
                };
                if !seen.insert(key) {
                    *self.found.borrow_mut() = Some(path);
                    return Err(de::Error::custom("duplicate key"));
                }
                map.next_value_seed(Walk {
                    path,
                    found: self.found,
                })?;
            }
            Ok(())
        }
    }

    let found = RefCell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    let result = Walk {
        path: String::new(),
        found: &found,
    }
    .deserialize(&mut de);
    match (result, found.into_inner()) {
        (Err(e), Some(path)) => Some((path, e.line())),
        _ => None,
    }
}

struct Parser {
    file: PathBuf,
}

impl Parser {
    fn err(&self, field: &str, message: impl Into<String>) -> Error {
        Error::field(&self.file, field, message)
    }

    fn object<'a>(&self, v: &'a Value, field: &str) -> Result<&'a Map<String, Value>> {
        v.as_object()
            .ok_or_else(|| self.err(field, "expected a JSON object"))
    }

    fn only_known(&self, obj: &Map<String, Value>, field: &str, known: &[&str]) -> Result<()> {
        for key in obj.keys() {
            if !known.contains(&key.as_str()) {
                let at = if field.is_empty() {
                    key.clone()
                } else {
                    format!("{field}.{key}")
                };
                return Err(self.err(
                    &at,
                    format!("unknown field (expected one of: {})", known.join(", ")),
                ));
            }
        }
        Ok(())
    }

    fn positive(&self, v: Option<&Value>, field: &str) -> Result<f64> {
        let v = v.ok_or_else(|| self.err(field, "missing"))?;
        let x = v
            .as_f64()
            .ok_or_else(|| self.err(field, format!("expected a number, found {v}")))?;
        if !(x.is_finite() && x > 0.0) {
            return Err(self.err(field, format!("must be a positive number, found {x}")));
        }
        Ok(x)
    }

    fn number(&self, v: Option<&Value>, field: &str) -> Result<f64> {
        let v = v.ok_or_else(|| self.err(field, "missing"))?;
        let x = v
            .as_f64()
            .ok_or_else(|| self.err(field, format!("expected a number, found {v}")))?;
        if !x.is_finite() {
            return Err(self.err(field, format!("must be a finite number, found {x}")));
        }
        Ok(x)
    }

    fn non_negative(&self, v: Option<&Value>, field: &str) -> Result<f64> {
        let x = self.number(v, field)?;
        if x < 0.0 {
            return Err(self.err(field, format!("must be zero or positive, found {x}")));
        }
        Ok(x)
    }

    /// A limit's size `x` (> 0) must lie within [[`MIN_LIMIT`], `max`] of its `unit`.
    fn plausible_limit(&self, x: f64, field: &str, unit: &str, max: f64) -> Result<()> {
        plausible_limit(x, unit, max).map_err(|reason| self.err(field, reason))
    }

    /// A machine coordinate (mm) within ±[`MAX_LENGTH`] (an M92 datum, a work offset).
    fn coordinate(&self, v: &Value, field: &str) -> Result<f64> {
        let d = self.number(Some(v), field)?;
        if d.abs() > MAX_LENGTH {
            return Err(self.err(
                field,
                format!(
                    "{} mm is beyond ±{MAX_LENGTH:e} mm",
                    crate::error::number(d)
                ),
            ));
        }
        Ok(d)
    }

    /// A length (mm, or degrees for a rotary travel) within ±[`MAX_LENGTH`].
    fn plausible_length(&self, x: f64, field: &str) -> Result<f64> {
        plausible_length(x).map_err(|reason| self.err(field, reason))?;
        Ok(x)
    }

    /// A limit in `unit`, each side's size within [[`MIN_LIMIT`], `max`].
    fn limit(&self, v: Option<&Value>, field: &str, unit: &str, max: f64) -> Result<Limit> {
        match v {
            Some(Value::Array(items)) => {
                let nums: Vec<f64> = items.iter().filter_map(Value::as_f64).collect();
                if items.len() != 2 || nums.len() != 2 {
                    return Err(self.err(field, "expected a number or [min, max]"));
                }
                let limit = Limit {
                    min: nums[0],
                    max: nums[1],
                };
                check_limit(limit, unit, max).map_err(|reason| self.err(field, reason))?;
                Ok(limit)
            }
            other => {
                let x = self.positive(other, field)?;
                self.plausible_limit(x, field, unit, max)?;
                Ok(Limit::symmetric(x))
            }
        }
    }

    fn machine(&self, root: &Value) -> Result<Machine> {
        let obj = self.object(root, "(top level)")?;
        self.only_known(
            obj,
            "",
            &[
                "name",
                "kinematics",
                "axes",
                "feed",
                "stock",
                "tool",
                "tools",
                "process",
                "program_units",
                "decimal_point_input",
                "work_offset",
                "g28_without_axes",
            ],
        )?;
        let name = match obj.get("name") {
            None => String::new(),
            Some(Value::String(s)) => s.clone(),
            Some(_) => return Err(self.err("name", "expected a string")),
        };
        let kinematics = self.kinematics(obj.get("kinematics"))?;
        let axes = self.axes(obj.get("axes"), &kinematics)?;
        let feed_max = match obj.get("feed") {
            None => None,
            Some(_) if kinematics == KinematicsSpec::Joint => {
                return Err(self.err(
                    "feed",
                    "a joint-space machine has no tool-tip feed limit; remove the section",
                ));
            }
            Some(f) => {
                let f = self.object(f, "feed")?;
                self.only_known(f, "feed", &["max"])?;
                let max = self.positive(f.get("max"), "feed.max")?;
                self.plausible_limit(max, "feed.max", "mm/s", MAX_LIMIT)?;
                Some(max)
            }
        };
        Ok(Machine {
            name,
            kinematics,
            axes,
            feed_max,
        })
    }

    fn kinematics(&self, v: Option<&Value>) -> Result<KinematicsSpec> {
        let v = v.ok_or_else(|| self.err("kinematics", "missing"))?;
        let obj = self.object(v, "kinematics")?;
        let ty = obj
            .get("type")
            .ok_or_else(|| self.err("kinematics.type", "missing"))?;
        match ty.as_str() {
            Some("xyz") => {
                self.only_known(obj, "kinematics", &["type"])?;
                Ok(KinematicsSpec::Xyz)
            }
            Some("joint") => {
                self.only_known(obj, "kinematics", &["type"])?;
                Ok(KinematicsSpec::Joint)
            }
            Some(t @ ("xyza" | "xyzb" | "xyzc")) => {
                self.only_known(obj, "kinematics", &["type"])?;
                Ok(KinematicsSpec::FourthAxis(match t {
                    "xyza" => FourthAxis::A,
                    "xyzb" => FourthAxis::B,
                    _ => FourthAxis::C,
                }))
            }
            Some("head_head") => {
                self.only_known(obj, "kinematics", &["type", "tool_length"])?;
                let tool_length =
                    self.positive(obj.get("tool_length"), "kinematics.tool_length")?;
                self.plausible_length(tool_length, "kinematics.tool_length")?;
                Ok(KinematicsSpec::HeadHead { tool_length })
            }
            Some("table_table_ac") => self.trunnion(obj, TrunnionTilt::A),
            Some("table_table_bc") => self.trunnion(obj, TrunnionTilt::B),
            Some("table_table_ab") => self.trunnion(obj, TrunnionTilt::AB),
            Some("head_table") => {
                self.only_known(obj, "kinematics", &["type", "pivot_length", "table"])?;
                let pivot_length =
                    self.non_negative(obj.get("pivot_length"), "kinematics.pivot_length")?;
                self.plausible_length(pivot_length, "kinematics.pivot_length")?;
                let table = match obj.get("table") {
                    None => RotaryTable::C,
                    Some(v) => match v.as_str() {
                        Some("C") => RotaryTable::C,
                        Some("A") => RotaryTable::A,
                        _ => {
                            return Err(self.err(
                                "kinematics.table",
                                format!(
                                    "must be \"C\" (a rotary table about Z) or \"A\" (a rotary \
                                     axis about X), found {v}"
                                ),
                            ));
                        }
                    },
                };
                Ok(KinematicsSpec::HeadTable {
                    pivot_length,
                    table,
                })
            }
            Some("dresser") => {
                self.only_known(obj, "kinematics", &["type", "tool_length"])?;
                let tool_length =
                    self.non_negative(obj.get("tool_length"), "kinematics.tool_length")?;
                self.plausible_length(tool_length, "kinematics.tool_length")?;
                Ok(KinematicsSpec::Dresser { tool_length })
            }
            _ => Err(self.err(
                "kinematics.type",
                format!(
                    "unknown kinematics {ty} (expected \"xyz\", \"xyza\", \"xyzb\", \"xyzc\", \
                     \"head_head\", \"table_table_ac\", \"table_table_bc\", \
                     \"table_table_ab\", \"head_table\", \"dresser\" or \"joint\")"
                ),
            )),
        }
    }

    /// The parameters of LinuxCNC's xyzac-trt / xyzbc-trt under their HAL pin names (the A/B
    /// table takes xyzac-trt's).
    fn trunnion(&self, obj: &Map<String, Value>, tilt: TrunnionTilt) -> Result<KinematicsSpec> {
        let (offset, other, module) = match tilt {
            TrunnionTilt::A => ("y-offset", "x-offset", "xyzac-trt"),
            TrunnionTilt::B => ("x-offset", "y-offset", "xyzbc-trt"),
            TrunnionTilt::AB => ("y-offset", "x-offset", "table_table_ab"),
        };
        if obj.contains_key(other) {
            return Err(self.err(
                &format!("kinematics.{other}"),
                format!(
                    "unknown field: {module} does not use {other} (its tilt axis is placed by \
                     {offset} and z-offset)"
                ),
            ));
        }
        self.only_known(
            obj,
            "kinematics",
            &[
                "type",
                "x-rot-point",
                "y-rot-point",
                "z-rot-point",
                offset,
                "z-offset",
                "tool-offset",
                "conventional-directions",
                "work-offset",
            ],
        )?;
        let num = |name: &str| {
            let field = format!("kinematics.{name}");
            self.plausible_length(self.number(obj.get(name), &field)?, &field)
        };
        let rot_point = [
            num("x-rot-point")?,
            num("y-rot-point")?,
            num("z-rot-point")?,
        ];
        let tilt_offset = num(offset)?;
        let z_offset = num("z-offset")?;
        let tool_offset = match obj.get("tool-offset") {
            None => 0.0,
            Some(_) => num("tool-offset")?,
        };
        let conventional_directions = match obj.get("conventional-directions") {
            None => false,
            Some(Value::Bool(b)) => *b,
            Some(v) => {
                return Err(self.err(
                    "kinematics.conventional-directions",
                    format!("expected true or false, found {v}"),
                ));
            }
        };
        let work_offset = match obj.get("work-offset") {
            None => [0.0; 3],
            Some(Value::Array(items))
                if items.len() == 3
                    && items
                        .iter()
                        .all(|x| x.as_f64().is_some_and(|x| x.abs() <= MAX_LENGTH)) =>
            {
                std::array::from_fn(|i| items[i].as_f64().unwrap_or(0.0))
            }
            Some(v) => {
                return Err(self.err(
                    "kinematics.work-offset",
                    format!(
                        "expected [x, y, z] (three numbers, mm, each within ±{MAX_LENGTH:e}), \
                         found {v}"
                    ),
                ));
            }
        };
        Ok(KinematicsSpec::TableTable {
            tilt,
            params: TrunnionParams {
                rot_point,
                tilt_offset,
                z_offset,
                tool_offset,
                conventional_directions,
                work_offset,
            },
        })
    }

    /// The optional travel `min`, `max` of an axis object: both or neither, `min < max`.
    fn travel(&self, a: &Map<String, Value>, field: &str) -> Result<Option<(f64, f64)>> {
        let (min_f, max_f) = (format!("{field}.min"), format!("{field}.max"));
        match (a.get("min"), a.get("max")) {
            (None, None) => Ok(None),
            (Some(_), None) => Err(self.err(&max_f, "missing (travel needs both min and max)")),
            (None, Some(_)) => Err(self.err(&min_f, "missing (travel needs both min and max)")),
            (lo, hi) => {
                let min = self.plausible_length(self.number(lo, &min_f)?, &min_f)?;
                let max = self.plausible_length(self.number(hi, &max_f)?, &max_f)?;
                if min >= max {
                    return Err(self.err(
                        &min_f,
                        format!("travel min must be less than max, found min {min}, max {max}"),
                    ));
                }
                Ok(Some((min, max)))
            }
        }
    }

    fn axes(&self, v: Option<&Value>, kin: &KinematicsSpec) -> Result<Vec<Axis>> {
        let v = v.ok_or_else(|| self.err("axes", "missing"))?;
        let obj = self.object(v, "axes")?;
        let file_names: Vec<&str> = obj.keys().map(String::as_str).collect();
        let names: &[&str] = match kin {
            KinematicsSpec::Joint => {
                if file_names.is_empty() || file_names.len() > crate::base::MAX_AXES {
                    return Err(self.err(
                        "axes",
                        format!(
                            "a joint-space machine needs 1 to {} axes, found {}",
                            crate::base::MAX_AXES,
                            file_names.len()
                        ),
                    ));
                }
                &file_names
            }
            _ => kin.axis_names(),
        };
        self.only_known(obj, "axes", names)?;
        names
            .iter()
            .map(|&name| {
                let field = format!("axes.{name}");
                let a = obj.get(name).ok_or_else(|| {
                    self.err(
                        &field,
                        "missing (this kinematics needs every one of its axes)",
                    )
                })?;
                let a = self.object(a, &field)?;
                self.only_known(
                    a,
                    &field,
                    &[
                        "velocity",
                        "acceleration",
                        "jerk",
                        "min",
                        "max",
                        "reference",
                        "m92",
                        "feed_diameter",
                        "shortest_way",
                    ],
                )?;
                let kind = if *kin == KinematicsSpec::Joint {
                    AxisKind::Linear
                } else {
                    KinematicsSpec::axis_kind(name)
                };
                let unit = velocity_unit(kin, kind);
                Ok(Axis {
                    name: name.to_string(),
                    kind,
                    velocity: self.limit(
                        a.get("velocity"),
                        &format!("{field}.velocity"),
                        unit,
                        MAX_LIMIT,
                    )?,
                    acceleration: self.limit(
                        a.get("acceleration"),
                        &format!("{field}.acceleration"),
                        &format!("{unit}²"),
                        MAX_LIMIT,
                    )?,
                    jerk: match a.get("jerk") {
                        None => None,
                        Some(j) => Some(self.limit(
                            Some(j),
                            &format!("{field}.jerk"),
                            &format!("{unit}³"),
                            MAX_JERK_LIMIT,
                        )?),
                    },
                    travel: self.travel(a, &field)?,
                })
            })
            .collect()
    }
}

/// The velocity unit of an axis of kind `kind` under kinematics `kin`, for messages.
fn velocity_unit(kin: &KinematicsSpec, kind: AxisKind) -> &'static str {
    match (kin, kind) {
        (KinematicsSpec::Joint, _) => "units/s",
        (_, AxisKind::Linear) => "mm/s",
        (_, AxisKind::Rotary) => "°/s",
    }
}

/// A limit's size `x` (> 0) lies within [[`MIN_LIMIT`], `max`] of its `unit`; else what to do.
fn plausible_limit(x: f64, unit: &str, max: f64) -> std::result::Result<(), String> {
    if x < MIN_LIMIT {
        return Err(format!(
            "{x} {unit} is implausibly small (at least {MIN_LIMIT:e} {unit}): check the unit \
             (mm, degrees, seconds)"
        ));
    }
    if x > max {
        return Err(format!(
            "{x} {unit} is implausibly large (at most {max:e} {unit}): check the unit (mm, \
             degrees, seconds)"
        ));
    }
    Ok(())
}

/// A two-sided limit: finite, `min < 0 < max`, each side's size plausible
/// ([`plausible_limit`]); else what to do.
fn check_limit(limit: Limit, unit: &str, max: f64) -> std::result::Result<(), String> {
    let Limit { min: lo, max: hi } = limit;
    if !(lo.is_finite() && hi.is_finite() && lo < 0.0 && hi > 0.0) {
        return Err(format!(
            "[min, max] must have min < 0 < max, found [{lo}, {hi}]"
        ));
    }
    plausible_limit(-lo, unit, max)?;
    plausible_limit(hi, unit, max)
}

/// A length (mm, or degrees for a rotary travel) is finite and within ±[`MAX_LENGTH`]; else
/// what to do.
fn plausible_length(x: f64) -> std::result::Result<(), String> {
    if !x.is_finite() {
        return Err(format!("must be a finite number, found {x}"));
    }
    if x.abs() > MAX_LENGTH {
        return Err(format!(
            "{x} is implausibly large (at most {MAX_LENGTH:e} mm or degrees in size): check the \
             unit (mm)"
        ));
    }
    Ok(())
}

impl Machine {
    /// Checks what [`Machine::from_json`] checks of a file, for a machine built in code: the
    /// kinematics' parameters (finite, plausible lengths; `tool_length` > 0 on a double swivel
    /// head, ≥ 0 on a head-table or dresser), the axes the kinematics needs in its order (a
    /// joint-space machine: 1 to [`MAX_AXES`](crate::base::MAX_AXES) axes with distinct,
    /// non-empty names), every limit finite with `min < 0 < max` and each side within
    /// [`MIN_LIMIT`]…[`MAX_LIMIT`] ([`MAX_JERK_LIMIT`] for jerk), travel `min < max` within
    /// ±[`MAX_LENGTH`], and `feed_max` a plausible limit (none on a joint-space machine).
    /// [`optimize`](crate::optimize::optimize) calls it before any work. The error
    /// ([`Error::InvalidMachine`]) names the field as a machine file would (`axes.C.velocity`).
    pub fn validate(&self) -> Result<()> {
        let bad = |field: &str, reason: String| Error::InvalidMachine {
            field: field.to_string(),
            reason,
        };
        let length = |field: &str, x: f64| plausible_length(x).map_err(|r| bad(field, r));
        let kin = &self.kinematics;
        match kin {
            KinematicsSpec::Xyz | KinematicsSpec::Joint | KinematicsSpec::FourthAxis(_) => {}
            KinematicsSpec::HeadHead { tool_length } => {
                length("kinematics.tool_length", *tool_length)?;
                if *tool_length <= 0.0 {
                    return Err(bad(
                        "kinematics.tool_length",
                        format!("must be a positive number, found {tool_length}"),
                    ));
                }
            }
            KinematicsSpec::HeadTable {
                pivot_length: x, ..
            }
            | KinematicsSpec::Dresser { tool_length: x } => {
                let field = match kin {
                    KinematicsSpec::HeadTable { .. } => "kinematics.pivot_length",
                    _ => "kinematics.tool_length",
                };
                length(field, *x)?;
                if *x < 0.0 {
                    return Err(bad(field, format!("must be zero or positive, found {x}")));
                }
            }
            KinematicsSpec::TableTable { tilt, params } => {
                let offset = if *tilt == TrunnionTilt::B {
                    "kinematics.x-offset"
                } else {
                    "kinematics.y-offset"
                };
                let [x, y, z] = params.rot_point;
                let [wx, wy, wz] = params.work_offset;
                for (field, v) in [
                    ("kinematics.x-rot-point", x),
                    ("kinematics.y-rot-point", y),
                    ("kinematics.z-rot-point", z),
                    (offset, params.tilt_offset),
                    ("kinematics.z-offset", params.z_offset),
                    ("kinematics.tool-offset", params.tool_offset),
                    ("kinematics.work-offset[0]", wx),
                    ("kinematics.work-offset[1]", wy),
                    ("kinematics.work-offset[2]", wz),
                ] {
                    length(field, v)?;
                }
            }
        }
        if *kin == KinematicsSpec::Joint {
            let max = crate::base::MAX_AXES;
            if self.axes.is_empty() || self.axes.len() > max {
                return Err(bad(
                    "axes",
                    format!(
                        "a joint-space machine needs 1 to {max} axes, found {}",
                        self.axes.len()
                    ),
                ));
            }
            for (k, a) in self.axes.iter().enumerate() {
                if a.name.is_empty() || self.axes[..k].iter().any(|b| b.name == a.name) {
                    return Err(bad(
                        &format!("axes[{k}].name"),
                        format!(
                            "`{}`: every axis needs a name of its own (not empty, not repeated)",
                            a.name
                        ),
                    ));
                }
            }
        } else {
            let names: Vec<&str> = self.axes.iter().map(|a| a.name.as_str()).collect();
            if names != kin.axis_names() {
                return Err(bad(
                    "axes",
                    format!(
                        "this kinematics needs the axes {} in that order, found {}",
                        kin.axis_names().join(" "),
                        if names.is_empty() {
                            "none".to_string()
                        } else {
                            names.join(" ")
                        }
                    ),
                ));
            }
            for a in &self.axes {
                let kind = KinematicsSpec::axis_kind(&a.name);
                if a.kind != kind {
                    return Err(bad(
                        &format!("axes.{}.kind", a.name),
                        format!(
                            "axis {} is {kind:?} in this kinematics, not {:?}",
                            a.name, a.kind
                        ),
                    ));
                }
            }
        }
        for a in &self.axes {
            let field = format!("axes.{}", a.name);
            let unit = velocity_unit(kin, a.kind);
            let limit = |which: &str, limit: Limit, unit: &str, max: f64| {
                check_limit(limit, unit, max).map_err(|r| bad(&format!("{field}.{which}"), r))
            };
            limit("velocity", a.velocity, unit, MAX_LIMIT)?;
            limit(
                "acceleration",
                a.acceleration,
                &format!("{unit}²"),
                MAX_LIMIT,
            )?;
            if let Some(j) = a.jerk {
                limit("jerk", j, &format!("{unit}³"), MAX_JERK_LIMIT)?;
            }
            if let Some((min, max)) = a.travel {
                length(&format!("{field}.min"), min)?;
                length(&format!("{field}.max"), max)?;
                if min >= max {
                    return Err(bad(
                        &format!("{field}.min"),
                        format!("travel min must be less than max, found min {min}, max {max}"),
                    ));
                }
            }
        }
        match self.feed_max {
            None => Ok(()),
            Some(_) if *kin == KinematicsSpec::Joint => Err(bad(
                "feed.max",
                "a joint-space machine has no tool-tip feed limit: leave it out (None)".into(),
            )),
            Some(max) if !(max.is_finite() && max > 0.0) => Err(bad(
                "feed.max",
                format!("must be a positive number, found {max}"),
            )),
            Some(max) => plausible_limit(max, "mm/s", MAX_LIMIT).map_err(|r| bad("feed.max", r)),
        }
    }
}
