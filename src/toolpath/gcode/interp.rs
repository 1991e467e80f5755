//! Interpreting: the modal state and the moves each block makes.

use nalgebra::Vector3;
use std::path::Path;

mod axes;
mod cycle_axis;
mod heidenhain;
pub(super) use heidenhain::KlartextWords;

use super::cycles::{self, Step};
use super::dialect::*;
use super::expr::Variables;
use super::frames::{self, Frame};
use super::lexer::{Item, Num};
use super::offsets::{self, WorkOffsets};
use super::*;
use crate::error::{Error, Result};
use crate::machine::DecimalPointInput;
use crate::toolpath::{
    Assumed, ClPoint, Dwell, Feed, LengthOffset, LengthOffsetChange, MM_PER_INCH, MachineContext,
    MachineMove, MachinePoint, MachineSwitch, OffsetChange, SpindleChange, Switch, ToolChange,
    ToolSelect, Toolpath, Warning,
};

/// The words of one block, sorted by meaning.
#[derive(Debug, Default)]
struct Block {
    axes: [Option<Num>; 6],
    centre: [Option<Num>; 3],
    /// Per centre word, `I=AC(…)` (Some(true)) or `I=IC(…)` (Some(false)): absolute or from
    /// the start whatever the modal arc-centre mode.
    centre_as: [Option<bool>; 3],
    vector: [Option<f64>; 3],
    radius: Option<Num>,
    turns: Option<f64>,
    extra_turns: Option<f64>,
    feed: Option<f64>,
    /// F was written with a decimal point (or computed).
    feed_point: Option<bool>,
    /// Every single-letter word's value as written (cycle and dwell parameters P Q R K L).
    letters: [Option<Num>; 26],
    /// Codes and keywords in the order written, with their text and `( … )` arguments.
    actions: Vec<(String, Action, Option<String>)>,
    /// Klartext: the axis word is incremental (`IX+5`, this word only); Sinumerik `X=IC(5)`.
    incremental: [bool; 6],
    /// Sinumerik `X=AC(5)`: the axis word is absolute whatever G90/G91.
    absolute: [bool; 6],
    /// Sinumerik `C=DC(v)` (0), `C=ACP(v)` (+1), `C=ACN(v)` (−1): the way a rotary axis
    /// turns to its absolute position.
    rotary_way: [Option<i8>; 6],
    /// Klartext `DR±`: +1 counter-clockwise, −1 clockwise.
    direction: Option<f64>,
    /// Klartext `PA`/`IPA` (degrees) and `PR`/`IPR` (mm), `true` when incremental.
    polar_angle: Option<(f64, bool)>,
    polar_radius: Option<(f64, bool)>,
    /// Klartext `MB`: the retract distance, mm.
    retract: Option<f64>,
    /// Klartext `A+Q120`, `B+Q121`, `C+Q122`: the rotary axis goes to the active PLANE's
    /// solution.
    plane_rotary: [bool; 3],
    /// Set by the interpreter for Klartext arcs: the arc's plane (else the modal plane), its
    /// centre (else R or I J K) and its signed sweep, radians (else from the end point).
    arc_plane: Option<Plane>,
    arc_centre: Option<ArcCentre>,
    arc_sweep: Option<f64>,
    /// Sinumerik `T="name"`.
    tool_name: Option<String>,
    /// A corner word (Fanuc `,R5` / `,C3`, Sinumerik `RND=5`, `CHF=`, `CHR=`) as written.
    corner: Option<(String, CornerWord, Num)>,
}

/// A chamfer or rounding asked for at the end of a straight move, made when the next move is
/// read ([`Interpreter::corner_to`]).
#[derive(Debug, Clone)]
pub(super) struct PendingCorner {
    line: usize,
    text: String,
    word: CornerWord,
    /// Its size, mm (a radius, a chamfer's leg or its length).
    size: f64,
    /// The corner's index in the points, and the dwell, tool and spindle counts then: nothing
    /// may come between the two moves.
    at: usize,
    counts: [usize; 3],
    /// The corner's own feed, mm/s (Klartext `RND R5 F300`); `None`: the first move's.
    feed: Option<f64>,
}

/// Where a Klartext arc's centre comes from.
#[derive(Debug, Clone, Copy)]
enum ArcCentre {
    /// The pole `CC`: the arc plane's first and second coordinate, program coordinates, mm.
    At([f64; 2]),
    /// `CT`: tangent to this unit direction (in the arc plane) at the start.
    Tangent([f64; 2]),
}

impl Block {
    fn letter(&self, c: char) -> Option<Num> {
        self.letters[(c as u8 - b'A') as usize]
    }
}

/// The modal F: under G94 per minute; under G95 per revolution (see
/// [`Interpreter::modal_feed`] for the feed at a move).
#[derive(Debug, Clone, Copy)]
struct ModalFeed {
    /// Linear feed, mm/min (G95: mm per revolution).
    mm_per_min: f64,
    /// F as written (degrees per minute on rotary-only moves; G95: per revolution).
    raw: f64,
}

/// A Fanuc/LinuxCNC canned cycle in force (modal until G80 or a motion code).
#[derive(Debug, Clone, Copy)]
struct CycleMode {
    kind: cycles::Kind,
    /// The G code (81 …), for messages.
    code: u32,
    /// R and Z (absolute, mm) and Q (mm) and P (s), modal within the cycle.
    r: Option<f64>,
    z: Option<f64>,
    q: Option<f64>,
    dwell: f64,
    /// The Z where the cycle mode began (the G98 return level).
    initial: f64,
}

/// A Sinumerik `MCALL CYCLE8x(...)` in force: the cycle runs after every positioning block.
#[derive(Debug, Clone)]
struct ModalCall {
    number: u32,
    /// Its moves along the drilling axis, which depend on its arguments only.
    steps: Vec<cycles::Step>,
    /// CYCLE84's pitch, speed and hand ([`Interpreter::sinumerik_tap`]).
    tap: Option<Tap>,
}

/// What a tapping cycle's call gives besides its moves: the pitch (mm), the speed (rpm) and
/// whether the thread is left-hand ([`crate::toolpath::TapCycle`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Tap {
    pub pitch: Option<f64>,
    pub rpm: Option<f64>,
    pub left_hand: bool,
}

/// A subprogram call a block makes, run after the block's own words.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Call {
    /// The call as written (`M98 P2000 L3`, `L123 P2`, `MYSUB`), for messages.
    pub(super) text: String,
    /// The subprogram's name and the repeat count, in order of preference: the first whose
    /// name is in the file is called (Fanuc's packed `M98 P32000`: O32000 once, else
    /// O2000 three times).
    pub(super) targets: Vec<(String, u64)>,
}

const AXIS_NAMES: [char; 6] = ['X', 'Y', 'Z', 'A', 'B', 'C'];

/// A code as written (`G054`, `g55`) in its canonical form (`G54`, `G55`), so that offsets
/// written differently compare equal.
fn code_name(text: &str) -> String {
    let mut chars = text.chars();
    let letter = chars.next().map_or('G', |c| c.to_ascii_uppercase());
    match chars.as_str().parse::<f64>() {
        Ok(v) if v.fract() == 0.0 => format!("{letter}{}", v as u64),
        Ok(v) => format!("{letter}{v}"),
        Err(_) => text.to_ascii_uppercase(),
    }
}

/// Largest coordinate a program may use, mm (and degrees of rotary travel, ×1000): past it a
/// word is an error naming it, so that arc chord counts and cycle pecks stay bounded. The
/// same bound as every reader's ([`crate::toolpath::MAX_COORDINATE_MM`]).
pub use crate::toolpath::MAX_COORDINATE_MM;
/// Most chords one arc block may become (full turns included).
pub const MAX_ARC_CHORDS: usize = 1_000_000;

pub(super) struct Interpreter<'a> {
    spec: &'a DialectSpec,
    source: &'a Path,
    machine: Option<&'a MachineContext>,
    pub(super) vars: Variables,
    units: Units,
    feed_units: Units,
    /// The basic system F is read in is known (Sinumerik: G70/G71 change lengths only): the
    /// machine file's `program_units`, else the program's first unit word.
    basic_system_set: bool,
    /// The program has selected its unit (G20/G21, G70/G71, G700/G710).
    units_selected: bool,
    distance: Distance,
    arc_distance: Distance,
    plane: Plane,
    feed_mode: FeedMode,
    feed: Option<ModalFeed>,
    /// The spindle speed S last programmed, rpm (`None`: none yet, or S under G96 is a
    /// cutting speed); G95 feeds are F × this.
    rpm: Option<f64>,
    /// G96 (constant surface speed) is on: S is a cutting speed, not rpm.
    surface_speed: bool,
    motion: Option<Motion>,
    tcp: Tcp,
    /// The code that switched tool-tip mode on last (`G43.4`, `TRAORI`, `M128`), for messages.
    tcp_code: String,
    /// Modal position in program (frame) coordinates: X Y Z in mm, A B C in degrees.
    pos: [f64; 6],
    /// X Y Z set by an absolute word.
    known: [bool; 3],
    /// LinuxCNC's parameters 5211–5219 (the `G52`/`G92` shift kept for `G92.3`), toolpath
    /// coordinates: `None` until the program sets them (at the start they are the control's).
    g92_params: Option<[f64; 6]>,
    unknown_warned: [bool; 3],
    /// The machine file's feed diameters were said not to apply to this dialect's feed.
    feed_diameter_warned: bool,
    vector: Vector3<f64>,
    saw_rotary: bool,
    /// A warning about motion outside TCP mode was given for the current stretch.
    non_tcp_warned: bool,
    cycle: Option<CycleMode>,
    /// G99: return to R (else G98: to the initial level).
    return_to_r: bool,
    mcall: Option<ModalCall>,
    programmable: Frame,
    swivel: Option<Frame>,
    /// A program end or subprogram return was read; `end_of_program`: it ends the whole
    /// program (M2, M30), not just a subprogram (M99, M17, RET).
    pub(super) ended: bool,
    pub(super) end_of_program: bool,
    /// The call the last block made, taken by the driver.
    pub(super) call: Option<Call>,
    /// Names of the file's named subprograms (Sinumerik `PROC NAME`): a bare word with one of
    /// these names is a call.
    pub(super) procs: Vec<String>,
    /// Where the files of subprograms the program does not hold are looked for (Sinumerik: a
    /// bare name that a file `NAME.SPF` there holds calls it).
    pub(super) subprogram_search: Vec<std::path::PathBuf>,
    /// Names looked for as files there and not found (each is looked for once: a program
    /// with an unknown word on every block lists the directories once).
    not_files: std::collections::HashSet<String>,
    pub(super) points: Vec<ClPoint>,
    warnings: Vec<Warning>,
    /// Every warning text said so far, once ([`Interpreter::warn`]).
    warning_texts: std::collections::HashSet<std::sync::Arc<str>>,
    dwells: Vec<Dwell>,
    /// The tangent (plane, unit direction in its two axes) at the end of the last straight
    /// line or arc, and the point count right after it (Klartext `CT` must follow directly).
    tangent: Option<(Plane, [f64; 2], usize)>,
    /// Klartext `M126`: rotary axes take the shorter way to an absolute position.
    shortest_path: bool,
    /// A corner the last straight move asked to chamfer or round, made by the next move.
    pub(super) corner: Option<PendingCorner>,
    /// Where the last straight feed move of X Y Z ended (the point count then) and the dwell,
    /// tool and spindle counts: a Klartext `RND`/`CHF` must follow it directly.
    pub(super) straight_end: Option<(usize, [usize; 3])>,
    /// The Klartext state ([`heidenhain`]).
    klartext: heidenhain::State,
    /// What the reader assumed where the machine file is silent.
    pub(super) assumed: Assumed,
    /// Cycle aliases (`CYCLE76` read as `CYCLE86`), and those a warning has named.
    pub(super) cycle_aliases: Vec<(String, String)>,
    aliases_used: Vec<String>,
    /// The block-skip switch ([`super::Settings::block_delete`]).
    pub(super) block_delete: bool,
    /// The tool's diameter, mm ([`super::Settings::tool_diameter`]).
    pub(super) tool_diameter: Option<f64>,
    /// How a number without a decimal point is read: least input increments (the dialect's,
    /// Fanuc), or `None` (as written: calculator-type input, and every other dialect).
    increments: Option<IntegerIncrements>,
    /// Whether the settings or the machine file chose `increments` (else it is the dialect's
    /// default, and the first integer word read as increments is a warning); and whether that
    /// warning was given.
    increments_chosen: bool,
    increments_warned: bool,
    /// That warning's word and line, `Z15` read as 0.015 mm: named again by an arc that does
    /// not close, where the reading is the likely cause (warnings are not shown with an error).
    increments_first: Option<(usize, String, String, String)>,
    /// [`super::Settings::dialect_unnamed`].
    pub(super) dialect_unnamed: bool,
    /// [`super::Settings::dialect_defaulted`]; cleared once its warning is given.
    pub(super) dialect_defaulted: bool,
    /// The tool the last `T` word selected (`M6` puts it in the spindle).
    prepared_tool: Option<ToolSelect>,
    /// The work offsets, `G10` and `G52` ([`offsets`]).
    offsets: WorkOffsets,
    /// The point being made is in machine coordinates (`G53`, a reference point): outside the
    /// work offsets' check.
    machine_point: bool,
    /// A point made across offsets on different bases ([`offsets::Mismatch`]): the error the
    /// block returns.
    offset_error: Option<Error>,
    /// The tool changes so far.
    pub(super) tool_changes: Vec<ToolChange>,
    /// The spindle speed changes so far.
    pub(super) spindle_changes: Vec<SpindleChange>,
    /// The spindle and coolant switches so far.
    pub(super) switches: Vec<MachineSwitch>,
    /// This block's switches that stop something (M5, M9): recorded after its motion.
    stops: Vec<Switch>,
    /// The work offsets selected after the first point.
    offset_changes: Vec<OffsetChange>,
    /// The points placed in machine coordinates.
    machine_points: Vec<MachinePoint>,
    /// The tool length offsets switched so far.
    length_offsets: Vec<LengthOffsetChange>,
    /// The last H word given with a length offset code (a Fanuc's H is modal).
    last_h: Option<u32>,
    /// The tapping cycles run so far.
    pub(super) taps: Vec<crate::toolpath::TapCycle>,
    /// This block's machine coordinates are M92's (relative to the builder's datum).
    m92: bool,
    /// Axes X Y Z whose missing M92 datum a warning has named.
    m92_warned: [bool; 3],
}

impl<'a> Interpreter<'a> {
    pub(super) fn new(
        spec: &'a DialectSpec,
        source: &'a Path,
        machine: Option<&'a MachineContext>,
    ) -> Self {
        // A program that selects no unit is read in the machine file's `program_units`.
        let units = match machine.and_then(|m| m.program_units) {
            Some(crate::machine::LengthUnit::Inch) => Units::Inch,
            _ => Units::Mm,
        };
        Interpreter {
            spec,
            source,
            machine,
            vars: Variables::default(),
            units,
            feed_units: units,
            basic_system_set: machine.is_some_and(|m| m.program_units.is_some()),
            units_selected: false,
            distance: Distance::Absolute,
            arc_distance: Distance::Incremental,
            plane: Plane::Xy,
            feed_mode: FeedMode::PerMinute,
            feed: None,
            rpm: None,
            surface_speed: false,
            motion: spec.initial_motion,
            tcp: Tcp::Off,
            tcp_code: String::new(),
            pos: [0.0; 6],
            known: [false; 3],
            g92_params: None,
            unknown_warned: [false; 3],
            feed_diameter_warned: false,
            vector: Vector3::new(0.0, 0.0, 1.0),
            saw_rotary: false,
            non_tcp_warned: false,
            cycle: None,
            return_to_r: false,
            mcall: None,
            programmable: Frame::IDENTITY,
            swivel: None,
            ended: false,
            end_of_program: false,
            call: None,
            procs: Vec::new(),
            subprogram_search: Vec::new(),
            not_files: Default::default(),
            points: Vec::new(),
            warnings: Vec::new(),
            warning_texts: std::collections::HashSet::new(),
            dwells: Vec::new(),
            taps: Vec::new(),
            tangent: None,
            shortest_path: false,
            corner: None,
            straight_end: None,
            klartext: heidenhain::State::default(),
            assumed: Assumed::default(),
            cycle_aliases: Vec::new(),
            aliases_used: Vec::new(),
            block_delete: false,
            tool_diameter: None,
            increments: spec.integer_increments,
            increments_chosen: false,
            increments_warned: false,
            increments_first: None,
            dialect_unnamed: false,
            dialect_defaulted: false,
            prepared_tool: None,
            offsets: WorkOffsets::new("G54"),
            machine_point: false,
            offset_error: None,
            tool_changes: Vec::new(),
            spindle_changes: Vec::new(),
            switches: Vec::new(),
            stops: Vec::new(),
            offset_changes: Vec::new(),
            machine_points: Vec::new(),
            length_offsets: Vec::new(),
            last_h: None,
            m92: false,
            m92_warned: [false; 3],
        }
    }

    /// How numbers without a decimal point are read ([`super::Settings::decimal_point_input`]),
    /// else the machine file's `decimal_point_input`, else the dialect's default.
    pub(super) fn set_decimal_point_input(&mut self, setting: Option<DecimalPointInput>) {
        let chosen = setting.or(self.machine.and_then(|m| m.decimal_point_input));
        self.increments_chosen = chosen.is_some();
        self.increments = match chosen {
            Some(DecimalPointInput::Calculator) => None,
            _ => self.spec.integer_increments,
        };
    }

    /// The first axis word (or I J K R Q) without a decimal point that is read as least input
    /// increments, when no setting chose that reading: one warning saying what it was read as
    /// and how to choose the other reading.
    fn note_increments(&mut self, line: usize, block: &Block, text: &str, num: Num, degrees: bool) {
        let Some(inc) = self.increments else { return };
        if self.increments_chosen || self.increments_warned || num.point || num.value == 0.0 {
            return;
        }
        self.increments_warned = true;
        // The unit in force, or the one this block selects (`G20 G0 X1000`).
        let units = block
            .actions
            .iter()
            .rev()
            .find_map(|(_, a, _)| match a {
                Action::Units { units, .. } => Some(*units),
                _ => None,
            })
            .unwrap_or(self.units);
        let (step, unit) = match (degrees, units) {
            (true, _) => (inc.deg, "°"),
            (false, Units::Mm) => (inc.mm, " mm"),
            (false, Units::Inch) => (inc.inch, " inch"),
        };
        // 117 × 0.001 is 0.11700000000000001 in binary: shown to the nanometre.
        let read = crate::error::number((num.value * step * 1e9).round() / 1e9);
        let written = crate::error::number(num.value);
        self.increments_first = Some((
            line,
            text.to_string(),
            format!("{read}{unit}"),
            format!("{written}{unit}"),
        ));
        let name = self.spec.name;
        self.warn(
            line,
            format!(
                "`{text}`: a number without a decimal point counts least input increments of \
                 {step}{unit}, as a {name} control reads it by default (parameter 3401#0 DPI = \
                 0): read as {read}{unit}, and so is every such word after it; a control set \
                 for calculator-type input (DPI = 1) reads it as {written}{unit}: then set \
                 \"decimal_point_input\": \"calculator\" in the machine file or pass \
                 --decimal-point-input calculator (\"increment\" keeps this reading without \
                 this warning)"
            ),
        );
    }

    /// The error for a program whose dialect nothing named
    /// ([`super::Settings::dialect_unnamed`]) and in which a number without a decimal point
    /// was read as least input increments by this dialect's default: the word, both readings
    /// and how to choose one.
    pub(super) fn increments_unnamed_dialect(&self) -> Option<Error> {
        let (line, text, read, written) = self.increments_first.as_ref()?;
        let name = self.spec.name;
        Some(self.error(
            *line,
            format!(
                "`{text}`: nothing in the program names its dialect, so it is read as a {name} \
                 program (the written program's dialect), where a number without a decimal \
                 point counts least input increments: {read}; read as LinuxCNC, as `feedopt \
                 solve` reads this file, it is {written}. Say which the program means: \
                 --input-dialect linuxcnc (as written), or --input-dialect {dialect} \
                 (increments; --decimal-point-input calculator reads {name} numbers as \
                 written)",
                dialect = name.to_ascii_lowercase()
            ),
        ))
    }

    /// Tool-tip mode on a machine programmed in machine coordinates (a four-axis machine) is
    /// an error: its X Y Z are read as the axes' positions, which a tool-tip program's are not.
    pub(super) fn no_tcp_on_machine_coordinates(&self, line: usize) -> Result<()> {
        match self.machine {
            Some(m) if m.machine_coordinates => Err(self.error(
                line,
                format!(
                    "tool-tip mode (TCP) on a four-axis machine, whose programs feedopt reads \
                     in machine coordinates (X Y Z and the angle as the axes' positions): give \
                     a five-axis kinematics in {} for a tool-tip program",
                    m.file.display()
                ),
            )),
            _ => Ok(()),
        }
    }

    /// Selects the work offset `name` (`G55`, Fadal `E2`): see [`offsets`].
    fn select_work_offset(&mut self, line: usize, name: String) {
        let before = self.offsets.shift();
        let used = if self.saw_rotary { 0..6 } else { 0..3 };
        if let Some(warning) = self.offsets.select(&name, used) {
            self.warn(line, warning);
        }
        if !self.points.is_empty() {
            self.offset_changes.push(OffsetChange {
                point: self.points.len(),
                line,
                name,
                origin: self.offsets.origin(),
                given: self.offsets.origin_given(),
            });
        }
        self.shift_changed(before);
    }

    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::parse(self.source, line, message)
    }

    pub(super) fn warn(&mut self, line: usize, message: impl Into<String>) {
        // One copy of each text ([`Warning`]): a message said before shares its first copy.
        let message: String = message.into();
        let shared = match self.warning_texts.get(message.as_str()) {
            Some(text) => text.clone(),
            None => {
                let text: std::sync::Arc<str> = message.into();
                self.warning_texts.insert(text.clone());
                text
            }
        };
        self.warnings.push(Warning {
            line,
            message: shared,
        });
    }

    /// After the program: a Fanuc, Sinumerik or LinuxCNC program that selected no unit, on a machine
    /// whose file does not say which unit its control reads such a program in, was read in mm;
    /// a warning at its first move and [`Assumed::units_mm`] say so.
    pub(super) fn note_units(&mut self) {
        let given = self.machine.is_some_and(|m| m.program_units.is_some());
        if self.spec.units_by_setting
            && !self.units_selected
            && !given
            && let Some(first) = self.points.first().map(|p| p.line)
        {
            self.assumed.units_mm = true;
            self.warn(
                first,
                "the program selects no unit (G20/G21, G70/G71 or G700/G710): read in mm and \
                 mm/min, as a control set for metric reads it; a control set for inch reads it \
                 in inch (set program_units in the machine file)",
            );
        }
    }

    /// After the program: every Sinumerik R parameter it read before setting it, at the line
    /// of the first such read. Taken as 0, as after the control's reset; but R parameters keep
    /// their values between programs (a main program or the operator may have set them), and
    /// the value can move the tool (`TRANS X=R24-243.6`).
    pub(super) fn note_assumed_parameters(&mut self) {
        for (name, line) in self.vars.take_assumed_zero() {
            self.warn(
                line,
                format!(
                    "`{name}` is read before the program sets it: taken as 0, its value after \
                     the control's reset (R parameters keep their values between programs: if \
                     another program or the operator sets it, set it at the start of this one)"
                ),
            );
        }
    }

    pub(super) fn finish(mut self, last_line: usize) -> Result<Toolpath> {
        if self.points.is_empty() {
            return Err(self.error(last_line.max(1), "no motion blocks"));
        }
        if let Some(c) = self.corner.take() {
            return Err(self.error(
                c.line,
                format!(
                    "`{}`: a chamfer or rounding needs a next move to meet, and the program \
                     ends without one",
                    c.text
                ),
            ));
        }
        if !self.saw_rotary {
            for p in &mut self.points {
                p.rotary = None;
            }
        }
        Ok(Toolpath {
            source: self.source.to_path_buf(),
            points: self.points,
            warnings: self.warnings,
            dwells: self.dwells,
            tool_changes: self.tool_changes,
            spindle_changes: self.spindle_changes,
            switches: self.switches,
            work_offset: self.offsets.start_named().map(str::to_string),
            offset_changes: self.offset_changes,
            machine_points: self.machine_points,
            length_offsets: (self.spec.length_offsets != LengthOffsets::Absent)
                .then_some(self.length_offsets),
            taps: self.taps,
            files: Vec::new(),
        })
    }

    /// Sorts a block's words, warning about unknown ones.
    fn collect(&mut self, line: usize, items: Vec<Item>) -> Result<Block> {
        let mut block = Block::default();
        let mut call_word: Option<String> = None;
        let name = self.spec.name;
        for item in items {
            let (text, address, num) = match item {
                Item::Word { text, address, num } => (text, address, num),
                Item::Keyword { text, action, args } => {
                    block.actions.push((text, action, args));
                    continue;
                }
                Item::Skipped => continue,
                Item::ToolName(name) => {
                    if block.tool_name.replace(name).is_some() {
                        return Err(
                            self.error(line, "`T=`: the same word appears twice in the block")
                        );
                    }
                    continue;
                }
                Item::Unknown { text, call: false }
                    if self.spec.subprograms == super::dialect::Subprograms::Procs
                        && text.len() > 1
                        && text.starts_with(|c: char| c.is_ascii_alphabetic())
                        && text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                        && !self.procs.contains(&text)
                        && self.subprogram_file(&text) =>
                {
                    // A subprogram in a file `NAME.SPF`: a call, as for PROC NAME in the file.
                    self.procs.push(text.clone());
                    if let Some(first) = call_word.replace(text.clone()) {
                        return Err(self.error(
                            line,
                            format!("`{first}`, `{text}`: two subprogram calls in one block"),
                        ));
                    }
                    continue;
                }
                Item::Unknown { text, .. } if self.procs.contains(&text) => {
                    if let Some(first) = call_word.replace(text.clone()) {
                        return Err(self.error(
                            line,
                            format!("`{first}`, `{text}`: two subprogram calls in one block"),
                        ));
                    }
                    continue;
                }
                Item::Unknown { text, call: true } => {
                    return Err(self.error(
                        line,
                        format!(
                            "`{text}(…)`: a call of a cycle or subprogram feedopt does not know; \
                             it may move the tool, so it is not skipped. Post the operation as \
                             G0/G1/G2/G3 moves, or define the subprogram in this file (PROC \
                             {text} … RET); the {name} cycles feedopt reads are CYCLE81–CYCLE89 \
                             and CYCLE800"
                        ),
                    ));
                }
                Item::Unknown { text, call: false }
                    if self.spec.spaces == Spaces::Separate
                        && text.len() > 1
                        && text.chars().all(|c| c.is_ascii_alphabetic() || c == '_') =>
                {
                    // Sinumerik: a bare name is a command or a subprogram call, either of which
                    // may change the motion (`TRAOOF` for TRAFOOF leaves TRAORI on).
                    let like = nearest_keyword(self.spec, &text)
                        .map(|k| format!(" (did the post mean `{k}`?)"))
                        .unwrap_or_default();
                    return Err(self.error(
                        line,
                        format!(
                            "`{text}`: not a {name} command feedopt knows{like}; a bare name \
                             switches a function or calls a subprogram, which may change the \
                             motion, so it is not skipped: correct it, remove it, define \
                             PROC {text} … RET in this file, or give the directory of its \
                             file {text}.SPF with --subprogram-dir"
                        ),
                    ));
                }
                Item::Unknown { text, call: false } => {
                    self.warn(
                        line,
                        format!("unknown word `{text}` (not a {name} word): ignored"),
                    );
                    continue;
                }
            };
            if num.value.abs() > MAX_COORDINATE_MM * 1e3 {
                return Err(self.error(line, format!("`{text}`: {} is out of range", num.value)));
            }
            if let Some(c) = text.chars().next()
                && c.is_ascii_uppercase()
                && (text.len() == 1 || !text[1..].starts_with(|ch: char| ch.is_ascii_alphabetic()))
            {
                block.letters[(c as u8 - b'A') as usize] = Some(num);
            }
            let source = self.source;
            let duplicate = |taken: bool| -> Result<()> {
                if taken {
                    Err(Error::parse(
                        source,
                        line,
                        format!("`{text}`: the same word appears twice in the block"),
                    ))
                } else {
                    Ok(())
                }
            };
            match address {
                Address::Axis(_)
                | Address::IncrementalAxis(_)
                | Address::AbsoluteAxis(_)
                | Address::RotaryTo(..)
                | Address::ArcCentre(_)
                | Address::Radius => {
                    let degrees = matches!(
                        address,
                        Address::Axis(3..)
                            | Address::IncrementalAxis(3..)
                            | Address::AbsoluteAxis(3..)
                            | Address::RotaryTo(..)
                    );
                    self.note_increments(line, &block, &text, num, degrees);
                }
                // A Q is a length (a peck), but not `G5.1 Q1`'s, which switches a Fanuc's AI
                // contour control on (NX's Mori posts write it): no increments there.
                Address::Ignored
                    if text.starts_with('Q')
                        && !block.actions.iter().any(|(t, _, _)| code_name(t) == "G5.1") =>
                {
                    self.note_increments(line, &block, &text, num, false);
                }
                _ => {}
            }
            match address {
                Address::Axis(i) => {
                    duplicate(block.axes[i].is_some())?;
                    self.check_axis(line, &text, i)?;
                    block.axes[i] = Some(num);
                }
                Address::IncrementalAxis(i) => {
                    duplicate(block.axes[i].is_some())?;
                    self.check_axis(line, &text, i)?;
                    block.axes[i] = Some(num);
                    block.incremental[i] = true;
                }
                Address::AbsoluteAxis(i) => {
                    duplicate(block.axes[i].is_some())?;
                    self.check_axis(line, &text, i)?;
                    block.axes[i] = Some(num);
                    block.absolute[i] = true;
                }
                Address::RotaryTo(i, way) => {
                    duplicate(block.axes[i].is_some())?;
                    self.check_axis(line, &text, i)?;
                    block.axes[i] = Some(num);
                    block.absolute[i] = true;
                    block.rotary_way[i] = Some(way);
                }
                Address::PlaneRotary(i) => {
                    duplicate(block.axes[3 + i].is_some() || block.plane_rotary[i])?;
                    self.check_axis(line, &text, 3 + i)?;
                    block.plane_rotary[i] = true;
                }
                Address::ArcDirection => {
                    duplicate(block.direction.is_some())?;
                    block.direction = Some(num.value);
                }
                Address::PolarAngle(incremental) => {
                    duplicate(block.polar_angle.is_some())?;
                    block.polar_angle = Some((num.value, incremental));
                }
                Address::PolarRadius(incremental) => {
                    duplicate(block.polar_radius.is_some())?;
                    block.polar_radius = Some((num.value, incremental));
                }
                Address::Retract => {
                    duplicate(block.retract.is_some())?;
                    block.retract = Some(num.value);
                }
                Address::ArcCentre(i) => {
                    duplicate(block.centre[i].is_some())?;
                    block.centre[i] = Some(num);
                }
                Address::ArcCentreAs(i, absolute) => {
                    duplicate(block.centre[i].is_some())?;
                    block.centre[i] = Some(num);
                    block.centre_as[i] = Some(absolute);
                }
                Address::ToolVector(i) => {
                    duplicate(block.vector[i].is_some())?;
                    block.vector[i] = Some(num.value);
                }
                Address::Radius => {
                    duplicate(block.radius.is_some())?;
                    block.radius = Some(num);
                }
                Address::ArcTurns => {
                    duplicate(block.turns.is_some())?;
                    block.turns = Some(num.value);
                }
                Address::ArcExtraTurns => {
                    duplicate(block.extra_turns.is_some())?;
                    block.extra_turns = Some(num.value);
                }
                Address::Feed => {
                    duplicate(block.feed.is_some())?;
                    block.feed = Some(num.value);
                    block.feed_point = Some(num.point);
                }
                Address::G | Address::M => {
                    let table = if address == Address::G {
                        self.spec.g_codes
                    } else {
                        self.spec.m_codes
                    };
                    match lookup_code(table, num.value) {
                        Some(Action::Unsupported(message)) => {
                            return Err(self.error(line, format!("{text}: {message}")));
                        }
                        Some(action) => block.actions.push((text, action, None)),
                        None if address == Address::G => {
                            return Err(self.error(
                                line,
                                format!(
                                    "{text}: not a {name} G code feedopt knows; a G code may \
                                     move the tool, so it is not skipped (remove it or post \
                                     the program for a supported control)"
                                ),
                            ));
                        }
                        None => self.warn(
                            line,
                            format!("unknown word `{text}` (not a {name} code): ignored"),
                        ),
                    }
                }
                Address::Corner(CornerWord::Feed) => {
                    if num.value != 0.0 {
                        return Err(self.error(
                            line,
                            format!(
                                "`{text}`: a feed of its own for chamfers and roundings is not \
                                 modelled (feedopt runs them at the F of the move that asks \
                                 for them): remove it"
                            ),
                        ));
                    }
                }
                Address::Corner(CornerWord::RoundModal) => {
                    if num.value != 0.0 {
                        return Err(self.error(
                            line,
                            format!(
                                "`{text}`: modal rounding of every following corner is not \
                                 supported: write RND= on the moves whose corners are rounded"
                            ),
                        ));
                    }
                }
                Address::Corner(word) => {
                    duplicate(block.corner.is_some())?;
                    block.corner = Some((text, word, num));
                }
                Address::Ignored => {}
                Address::Call => {
                    if let Some(first) = call_word.replace(text.clone()) {
                        return Err(self.error(
                            line,
                            format!("`{first}`, `{text}`: two subprogram calls in one block"),
                        ));
                    }
                }
                Address::Unsupported(message) => {
                    return Err(self.error(line, format!("{text}: {message}")));
                }
            }
        }
        if let Some(name) = call_word {
            // Sinumerik `L123`, `MYSUB`: the name is the word as written (L0123 is another
            // program than L123); P is the repeat count.
            self.set_call(line, name, block.letter('P'))?;
        }
        Ok(block)
    }

    /// A Sinumerik cycle as the read options alias it: the name to show and the number to
    /// expand (a warning names each alias the first time it applies).
    fn alias(&mut self, line: usize, text: &str, number: u32) -> (String, u32) {
        let Some((_, to)) = self.cycle_aliases.iter().find(|(from, _)| from == text) else {
            return (text.to_string(), number);
        };
        let to = to.clone();
        let Some(n) = to.strip_prefix("CYCLE").and_then(|d| d.parse().ok()) else {
            return (text.to_string(), number);
        };
        if !self.aliases_used.iter().any(|a| a == text) {
            self.aliases_used.push(text.to_string());
            self.warn(
                line,
                format!("{text} is read as {to}, as the cycle alias {text}={to} says"),
            );
        }
        (format!("{text} (as {to})"), n)
    }

    /// An axis word for an axis the machine lacks is an error naming it.
    fn check_axis(&self, line: usize, text: &str, i: usize) -> Result<()> {
        if let Some(m) = self.machine
            && !m.has_axis(AXIS_NAMES[i])
        {
            return Err(self.error(
                line,
                format!(
                    "`{text}`: the machine ({}) has no {} axis; use a machine file with that \
                     axis or a program posted for this machine",
                    m.file.display(),
                    AXIS_NAMES[i]
                ),
            ));
        }
        Ok(())
    }

    /// Records a call of subprogram `name` repeated `count` times (P).
    fn set_call(&mut self, line: usize, name: String, count: Option<Num>) -> Result<()> {
        let (text, repeats) = match count {
            None => (name.clone(), 1),
            Some(p) => (
                format!("{name} P{}", p.value),
                self.count(line, &format!("{name} P"), p.value)?,
            ),
        };
        self.call = Some(Call {
            text,
            targets: vec![(name, repeats)],
        });
        Ok(())
    }

    /// A whole, non-negative number (a program number or repeat count).
    fn count(&self, line: usize, what: &str, value: f64) -> Result<u64> {
        if value < 0.0 || value.fract() != 0.0 || value > 1e12 {
            return Err(self.error(
                line,
                format!("`{what}{value}`: expected a whole number of at least 0"),
            ));
        }
        Ok(value as u64)
    }

    /// Fanuc/Haas `M98 P<program> [L<count>]`; without L, a P of more than four digits may
    /// pack the count before a four-digit program number (`P32000`: O2000 three times).
    fn fanuc_call(&mut self, line: usize, block: &Block) -> Result<()> {
        let Some(p) = block.letter('P') else {
            return Err(self.error(
                line,
                "M98 without P (the program number to call): add P<program number>",
            ));
        };
        let number = self.count(line, "M98 P", p.value)?;
        let mut text = format!("M98 P{number}");
        let targets = match block.letter('L') {
            Some(l) => {
                let count = self.count(line, "M98 L", l.value)?;
                text.push_str(&format!(" L{count}"));
                vec![(format!("O{number}"), count)]
            }
            None if number > 9999 => vec![
                (format!("O{number}"), 1),
                (format!("O{}", number % 10000), number / 10000),
            ],
            None => vec![(format!("O{number}"), 1)],
        };
        if self.call.is_some() {
            return Err(self.error(line, format!("`{text}`: two subprogram calls in one block")));
        }
        self.call = Some(Call { text, targets });
        Ok(())
    }

    /// Scale of a length word (mm per written unit), honouring integer increments.
    fn length(&self, num: Num) -> f64 {
        let scale = match (self.increments, num.point) {
            (Some(inc), false) => match self.units {
                Units::Mm => inc.mm,
                Units::Inch => inc.inch * MM_PER_INCH,
            },
            _ => self.units.mm_per_unit(),
        };
        num.value * scale
    }

    fn angle(&self, num: Num) -> f64 {
        match (self.increments, num.point) {
            (Some(inc), false) => num.value * inc.deg,
            _ => num.value,
        }
    }

    /// A cycle parameter list `a,b,,d` (empty: not given), evaluated.
    fn arguments(&self, line: usize, text: &str) -> Result<Vec<Option<f64>>> {
        if text.len() > 2000 {
            return Err(self.error(line, "cycle argument list longer than 2000 characters"));
        }
        text.split(',')
            .map(|a| {
                let a = a.trim();
                if a.is_empty() || a.starts_with('"') {
                    Ok(None)
                } else {
                    super::expr::eval(a, &self.vars)
                        .map(Some)
                        .map_err(|e| self.error(line, format!("argument `{a}`: {e}")))
                }
            })
            .collect()
    }

    /// Whether a file in the subprogram directories holds Sinumerik subprogram `name`
    /// (looked for once per name).
    fn subprogram_file(&mut self, name: &str) -> bool {
        if self.not_files.contains(name) {
            return false;
        }
        let found = super::subprograms::in_directories(
            &self.subprogram_search,
            super::dialect::Subprograms::Procs,
            name,
        );
        if !found {
            self.not_files.insert(name.to_string());
        }
        found
    }

    /// Whether a number without a decimal point counts least input increments (Fanuc's
    /// default, DPI = 0).
    pub(super) fn integer_increments(&self) -> bool {
        self.increments.is_some()
    }

    /// Interprets one block.
    pub(super) fn block(&mut self, line: usize, items: Vec<Item>) -> Result<()> {
        let done = self.block_words(line, items);
        // A switch that stops the spindle or the coolant acts after the block's motion (a
        // control runs `G0 Z50 M5` as the retract, then the stop).
        let point = self.points.len();
        for switch in std::mem::take(&mut self.stops) {
            self.switches.push(MachineSwitch {
                point,
                line,
                switch,
            });
        }
        match self.offset_error.take() {
            Some(e) => Err(e),
            None => done,
        }
    }

    /// Interprets one block's words ([`Self::block`] adds the work offsets' check of the
    /// points they made).
    fn block_words(&mut self, line: usize, items: Vec<Item>) -> Result<()> {
        let block = self.collect(line, items)?;
        self.m92 = false;
        self.length_offset(line, &block)?;

        // Modal settings first (feed mode, F, units, plane, distance, TCP), then the motion.
        let mut motion_code: Option<(&str, Motion)> = None;
        let mut machine = false;
        let mut no_motion: Option<&str> = None;
        let mut end = false;
        let mut end_of_program = false;
        let mut fanuc_call = false;
        let mut reference: Option<u8> = None;
        let mut rigid_tap = false;
        let mut dwell = false;
        let mut spindle_limit = false;
        let mut frame_op: Option<(&str, FrameOp)> = None;
        let mut new_cycle: Option<(&str, u32)> = None;
        let mut sinumerik_cycle: Option<(String, u32, String)> = None;
        let mut modal_call = false;
        let mut tilted_plane = false;
        let mut klartext = KlartextWords::default();
        let mut tool_change: Option<&str> = None;
        let mut set_tool = false;
        let mut set_offset: Option<(&str, OffsetNumbering)> = None;
        let mut local_offset = false;
        let mut position_offset = None;
        if let Some(name) = &block.tool_name {
            self.prepared_tool = Some(ToolSelect::Name(name.clone()));
        } else if self.spec.spaces != Spaces::Klartext
            && let Some(t) = block.letter('T')
        {
            self.prepared_tool = Some(ToolSelect::Number(self.tool_number(line, "T", t.value)?));
        }
        for (text, action, args) in &block.actions {
            match *action {
                Action::FeedMode(mode) => self.set_feed_mode(mode),
                Action::SurfaceSpeed { on, feed } => {
                    self.surface_speed = on;
                    if on {
                        self.rpm = None;
                    }
                    if let Some(mode) = feed {
                        self.set_feed_mode(mode);
                    }
                }
                Action::Motion(m) => {
                    // The same motion code twice (a Fadal program's `G0 G90 G0 X0 Y0 E1`,
                    // round 22) moves as once, whichever of the two counts: a Fanuc reads the
                    // last G code of a group given twice (its operator's manuals, G code
                    // list: "the G code specified last is valid"). LinuxCNC refuses any two
                    // of one group (rs274ngc NCE_TWO_G_CODES_USED_FROM_SAME_MODAL_GROUP), and
                    // two different ones stay an error everywhere.
                    let repeated = motion_code.is_some_and(|(other, _)| {
                        self.spec.subprograms == Subprograms::OPrograms
                            && code_name(other) == code_name(text)
                    });
                    if let Some((other, _)) = motion_code
                        && !repeated
                    {
                        return Err(self.error(
                            line,
                            format!("two motion codes in one block: {other} and {text}"),
                        ));
                    }
                    motion_code = Some((text.as_str(), m));
                    self.cycle = None;
                }
                Action::MotionCancel => {
                    self.motion = None;
                    self.cycle = None;
                }
                Action::CycleCancel => self.cycle = None,
                Action::Cycle(code) => new_cycle = Some((text.as_str(), code)),
                Action::CycleReturn(to_r) => self.return_to_r = to_r,
                Action::Plane(p) => self.plane = p,
                Action::Units { units, feed } => {
                    self.units = units;
                    self.units_selected = true;
                    if feed {
                        self.feed_units = units;
                        self.basic_system_set = true;
                    } else if !self.basic_system_set {
                        // Sinumerik G70/G71: F stays in the control's basic system, taken as
                        // the unit the program first selects.
                        self.basic_system_set = true;
                        self.feed_units = units;
                        if units == Units::Inch {
                            self.warn(
                                line,
                                format!(
                                    "{text}: F is read in inch/min: a Sinumerik control keeps F \
                                     in its basic system under G70, taken as inch because the \
                                     program selects inch first (G700 makes F inch explicitly)"
                                ),
                            );
                        }
                    }
                }
                Action::Distance(d) => self.distance = d,
                Action::ArcDistance(d) => self.arc_distance = d,
                Action::Tcp(t) => {
                    if t == Tcp::On {
                        self.no_tcp_on_machine_coordinates(line)?;
                    }
                    if t != Tcp::Off {
                        self.tcp_code = code_name(text);
                    }
                    if t != self.tcp {
                        self.non_tcp_warned = false;
                    }
                    self.switch_tcp(t);
                }
                Action::MachineCoordinates => machine = true,
                Action::BuilderDatum => {
                    machine = true;
                    self.m92 = true;
                }
                Action::Reference(k) => reference = Some(k),
                Action::RigidTap => rigid_tap = true,
                Action::Dwell => dwell = true,
                Action::Frame(op) => frame_op = Some((text.as_str(), op)),
                Action::Swivel => {
                    let args = match args {
                        Some(a) => self.arguments(line, a)?,
                        None => Vec::new(),
                    };
                    let scale = self.units.mm_per_unit();
                    let args: Vec<Option<f64>> = args
                        .iter()
                        .enumerate()
                        .map(|(k, a)| {
                            a.map(|v| {
                                if [4, 5, 6, 10, 11, 12].contains(&k) {
                                    v * scale
                                } else {
                                    v
                                }
                            })
                        })
                        .collect();
                    self.swivel = frames::cycle800(&args).map_err(|e| self.error(line, e))?;
                }
                Action::TiltedPlane => tilted_plane = true,
                Action::TiltedPlaneCancel => self.swivel = None,
                Action::ModalCall => modal_call = true,
                Action::SinumerikCycle(n) => {
                    let (text, n) = self.alias(line, text, n);
                    sinumerik_cycle = Some((text, n, args.clone().unwrap_or_default()));
                }
                Action::NoMotion(message) => {
                    no_motion = Some(message);
                    self.warn(line, format!("{text}: {message}"));
                }
                Action::ProgramEnd => {
                    end = true;
                    end_of_program = true;
                }
                Action::Return => end = true,
                Action::Call => fanuc_call = true,
                Action::Switch(list) => {
                    for &switch in list {
                        if switch.stops() {
                            self.stops.push(switch);
                        } else {
                            self.switches.push(MachineSwitch {
                                point: self.points.len(),
                                line,
                                switch,
                            });
                        }
                    }
                }
                Action::ToolChange => tool_change = Some(text.as_str()),
                Action::SetTool => set_tool = true,
                Action::Path(kind) => klartext.path = Some((text.clone(), kind)),
                Action::Statement(st) => {
                    klartext.statement = Some((text.clone(), st, args.clone().unwrap_or_default()));
                }
                Action::RapidBlock => klartext.rapid = true,
                Action::ToolCallFeed => klartext.tool_feed = true,
                Action::CycleCallAt(now) => klartext.cycle_call = Some(now),
                Action::RotaryShortestPath(on) => self.shortest_path = on,
                Action::RetractToolAxis => klartext.retract = true,
                Action::RetractMax => klartext.retract_max = true,
                Action::WorkOffset => {
                    // G54.1 P n: the P word names the offset.
                    let code = code_name(text);
                    let name = match block.letter('P') {
                        Some(p) if code.contains('.') => format!("{code} P{}", p.value),
                        _ => code,
                    };
                    self.select_work_offset(line, name);
                }
                Action::SetOffset(numbering) => set_offset = Some((text.as_str(), numbering)),
                Action::LocalOffset => local_offset = true,
                Action::PositionOffset(numbering) => position_offset = Some(numbering),
                Action::LocalOffsetCancel { clear } => {
                    let before = self.offsets.shift();
                    for i in 0..6 {
                        self.offsets.set_local(i, 0.0);
                    }
                    if clear {
                        self.g92_params = Some([0.0; 6]);
                    }
                    self.shift_changed(before);
                }
                Action::LocalOffsetRestore => {
                    let Some(saved) = self.g92_params else {
                        return Err(self.error(
                            line,
                            format!(
                                "{text}: the G52/G92 shift restored from parameters 5211–5219, \
                                 which the program has not set (their values are the \
                                 control's): program the shift (G92 or G52) instead"
                            ),
                        ));
                    };
                    let before = self.offsets.shift();
                    for (i, v) in saved.into_iter().enumerate() {
                        self.offsets.set_local(i, v);
                    }
                    self.shift_changed(before);
                }
                Action::ContourTolerance => {
                    if let Some(p) = block.letter('P') {
                        let mm = self.length(p);
                        self.warn(
                            line,
                            contour_tolerance_note(&format!("{text} P{}", p.value), mm),
                        );
                    }
                }
                Action::SpindleLimit => {
                    if block.axes.iter().any(Option::is_some) {
                        return Err(self.error(
                            line,
                            format!(
                                "{text} with axis words: on Sinumerik G92 limits the spindle \
                                 speed (G92 S…) and moves nothing; set a position with a frame \
                                 (TRANS, G54…)"
                            ),
                        ));
                    }
                    spindle_limit = true;
                }
                Action::FeedGroup => {
                    let given = args.as_deref().unwrap_or("");
                    let mut axes: Vec<String> = given
                        .split(',')
                        .map(|a| a.trim().to_ascii_uppercase())
                        .filter(|a| !a.is_empty())
                        .collect();
                    axes.sort();
                    let default = axes.is_empty() || axes == ["X", "Y", "Z"];
                    if !default {
                        return Err(self.error(
                            line,
                            format!(
                                "`{text}({given})`: F would be the speed along the combined \
                                 path of these axes; feedopt reads a Sinumerik F along X Y Z, \
                                 the default feed group (`FGROUP()` or `FGROUP(X,Y,Z)`). Post \
                                 the program with the default feed group"
                            ),
                        ));
                    }
                }
                // G50 cancels scaling on a mill (Fanuc M series, Tormach) and takes no
                // words; on a lathe (Fanuc T series, G-code system A; PathPilot lathe) `G50
                // S…` limits the spindle speed and `G50 X… Z…` sets the position. Ignoring
                // those would read a turning program, F per revolution and all, as milling.
                Action::Ignored
                    if text.trim_start_matches(['G', 'g']).parse::<f64>() == Ok(50.0)
                        && (block.letter('S').is_some()
                            || block.axes.iter().any(Option::is_some)) =>
                {
                    return Err(self.error(
                        line,
                        format!(
                            "`{text}` with {}: a lathe's {} (Fanuc T series, G-code system A), \
                             so this is a turning program (X a diameter, F per revolution \
                             under G99), which feedopt does not read: it reads milling \
                             programs. On a mill, G50 cancels scaling and takes no words",
                            if block.letter('S').is_some() {
                                "S"
                            } else {
                                "axis words"
                            },
                            if block.letter('S').is_some() {
                                "spindle speed limit"
                            } else {
                                "position setting"
                            }
                        ),
                    ));
                }
                // Fanuc G05: `G05 P10000` switches high-precision contour control (HPCC, the
                // look-ahead of the 16i/18i/21i-MB) on and `G05 P0` off, moving nothing
                // (Makino's Pro3 posts write them around every cut). With another P, or none,
                // G05 is high-speed cycle machining (`G05 P1`…: a cycle of binary motion data
                // held in the control), whose moves the program does not carry.
                Action::Ignored
                    if text.trim_start_matches(['G', 'g']).parse::<f64>() == Ok(5.0)
                        && !matches!(block.letter('P'), Some(p) if p.value == 10000.0 || p.value == 0.0) =>
                {
                    return Err(self.error(
                        line,
                        format!(
                            "{}: only `G05 P10000` and `G05 P0` (high-precision contour \
                             control on and off, no motion) are read; another G05 runs \
                             high-speed cycle machining, motion from data held in the control \
                             that the program does not carry: post the moves as G1/G2/G3",
                            block
                                .letter('P')
                                .map_or(format!("`{text}` without P"), |p| format!(
                                    "`{text} P{}`",
                                    p.value
                                ))
                        ),
                    ));
                }
                Action::Ignored => {}
                Action::Note(message) => self.warn(line, format!("{text}: {message}")),
                Action::CutterCompensation => {
                    if self.machine.is_some_and(|m| m.wear_compensation) {
                        self.warn(
                            line,
                            format!(
                                "{text}: cutter radius compensation taken as wear only \
                                 (--wear-compensation): the programmed path is the tool centre's"
                            ),
                        );
                    } else {
                        return Err(self.error(
                            line,
                            format!(
                                "{text}: cutter radius compensation moves the tool off the \
                                 programmed path by the tool's radius, which feedopt does not \
                                 model: post the program with the tool centre's path (CAM \
                                 compensation in the computer), or, where its path already is \
                                 the tool centre's and the offset register holds only wear (CAM \
                                 wear compensation), pass --wear-compensation"
                            ),
                        ));
                    }
                }
                Action::Unsupported(message) => {
                    return Err(self.error(line, format!("{text}: {message}")));
                }
            }
        }
        // Fadal (read in the Fanuc dialect: its programs start `N1 O1`): `E1`…`E48` select a
        // fixture offset, as G54… do, and `E0` cancels it, the machine's coordinates then
        // standing for the program's, in the block they are written in and after it (Autodesk's
        // Fusion post "Fadal", $Revision 42984: property onlyENumbers, "Set to 'Yes' to output
        // E-codes or 'No' to output G54-G59 for WCS offsets", and its format 1 header `G90 G94
        // G17 H0 E0`; the Polish shop's programs of round 22: `G90 G0 X0 Y0 E1`, and `E0 X0.
        // Y250.` to park). They were skipped in silence: a Fanuc has no E word on a mill.
        // Read as an offset selected without its values (taken as equal to the one in force,
        // with a warning, as `G55` without `G10`). Not in a block that gives E to another
        // code: Haas `G187 E` (smoothing tolerance), macro arguments `G65 … E` (#8).
        if self.spec.subprograms == Subprograms::OPrograms
            && let Some(e) = block.letter('E')
            && !block
                .actions
                .iter()
                .any(|(text, _, _)| matches!(code_name(text).as_str(), "G187" | "G65"))
        {
            if e.value.fract() != 0.0 || !(0.0..=48.0).contains(&e.value) {
                return Err(self.error(
                    line,
                    format!(
                        "`E{}`: on a Fadal control E selects a fixture offset, E1 to E48 (E0 \
                         cancels it); this is none, and a Fanuc mill has no E word",
                        e.value
                    ),
                ));
            }
            self.select_work_offset(line, format!("E{}", e.value as u32));
        }
        // `S`: the spindle speed, rpm (not in a dwell, where Sinumerik's `G4 S` counts
        // revolutions; Klartext's comes with `TOOL CALL`).
        if self.spec.spaces != Spaces::Klartext
            && !dwell
            && !spindle_limit
            && let Some(s) = block.letter('S')
        {
            if self.surface_speed {
                // A cutting speed (m/min): the spindle's rpm follows the diameter.
                self.rpm = None;
            } else {
                self.set_spindle(line, s.value);
            }
        }
        if set_tool {
            // LinuxCNC `M61 Q<n>`: tool n is in the spindle from here on.
            let Some(q) = block.letter('Q') else {
                return Err(self.error(line, "M61 without Q: give the tool number, M61 Q<n>"));
            };
            let n = self.tool_number(line, "M61 Q", q.value)?;
            self.change_tool(line, ToolSelect::Number(n));
        }
        if let Some(text) = tool_change {
            match self.prepared_tool.clone() {
                Some(tool) => self.change_tool(line, tool),
                None => self.warn(
                    line,
                    format!("{text} without a T word before it: no tool change recorded"),
                ),
            }
        }
        if fanuc_call {
            self.fanuc_call(line, &block)?;
        }
        // An L word is read by G10, a canned cycle (repeats), `M98` (repeats) and LinuxCNC's
        // `M66` (wait mode). Elsewhere it is no word of these dialects, but a Fadal control's
        // subprogram definition and call (`L900`, `L901`) and arc repeat (`G3 I-4.5 L14`):
        // moves feedopt would drop in silence (round 8, a Fadal program read as 0.2 s).
        if matches!(
            self.spec.subprograms,
            Subprograms::OWordSub | Subprograms::OPrograms
        ) && let Some(l) = block.letter('L')
            && !(fanuc_call
                || set_offset.is_some()
                || new_cycle.is_some()
                || self.cycle.is_some()
                || block
                    .actions
                    .iter()
                    .any(|(text, _, _)| code_name(text) == "M66"))
        {
            return Err(self.error(
                line,
                format!(
                    "`L{}`: an L word with no G10, canned cycle or M98 in the block to read it; \
                     on a Fadal control L calls a subprogram (L901: subroutine 9 once), which \
                     feedopt reads when the file defines it (L900 … M17, before an M30 that \
                     ends the definitions), or repeats a move (G3 … L14), which feedopt does \
                     not read: write the repeated moves out, or post the program for a \
                     Fanuc-style control (M98 P… calls, moves written out)",
                    l.value
                ),
            ));
        }
        if end && self.call.is_some() {
            return Err(self.error(
                line,
                "a subprogram call and a program end or return in one block: put them in \
                 blocks of their own",
            ));
        }
        self.end_of_program = end_of_program;
        if let Some(f) = block.feed {
            if f < 0.0 {
                return Err(self.error(line, format!("F{f}: a feed cannot be negative")));
            }
            if self.feed_mode == FeedMode::PerRevolution
                && self.increments.is_some()
                && block.feed_point == Some(false)
                && f != 0.0
            {
                return Err(self.error(
                    line,
                    format!(
                        "F{f} under G95 without a decimal point: a Fanuc control reads it in \
                         units its parameters set (0.01 or 0.001 mm per revolution on many); \
                         write the feed per revolution with a decimal point (F{f}. for {f} mm)"
                    ),
                ));
            }
            if self.feed_mode != FeedMode::InverseTime {
                self.feed = (f > 0.0).then(|| ModalFeed {
                    mm_per_min: f * self.feed_units.mm_per_unit(),
                    raw: f,
                });
            }
        }
        if let Some((_, m)) = motion_code {
            self.motion = Some(m);
        }
        if self.spec.spaces == Spaces::Klartext {
            return self
                .klartext_block(line, block, klartext, machine)
                .map(|()| self.end_if(end));
        }

        if dwell {
            return self.dwell(line, &block).map(|()| self.end_if(end));
        }
        if let Some((text, op)) = frame_op {
            return self
                .frame(line, text, op, &block)
                .map(|()| self.end_if(end));
        }
        if let Some((text, numbering)) = set_offset {
            return self
                .g10(line, text, numbering, &block)
                .map(|()| self.end_if(end));
        }
        if local_offset {
            return self.g52(line, &block).map(|()| self.end_if(end));
        }
        if let Some(numbering) = position_offset {
            return self.g92(line, numbering, &block).map(|()| self.end_if(end));
        }
        if tilted_plane {
            return self.tilted_plane(line, &block).map(|()| self.end_if(end));
        }
        if let Some(k) = reference {
            return self.reference(line, k, &block).map(|()| self.end_if(end));
        }
        if rigid_tap {
            return self.rigid_tap(line, &block).map(|()| self.end_if(end));
        }
        if let Some((text, number, args)) = sinumerik_cycle {
            let args = self.arguments(line, &args)?;
            let args = self.sinumerik_cycle_units(number, args);
            if modal_call {
                // The call's errors and notes depend on its arguments only: said once, where
                // the program calls it, not at every position after it.
                let (steps, notes) = cycles::sinumerik_steps(number, &args, self.rpm)
                    .map_err(|e| self.error(line, format!("MCALL {text}: {e}")))?;
                for n in notes {
                    self.warn(line, format!("MCALL {text}: {n}"));
                }
                let tap = (number == 84).then(|| self.sinumerik_tap(&args));
                self.mcall = Some(ModalCall { number, steps, tap });
            } else {
                self.run_sinumerik_cycle(line, &text, number, &args)?;
            }
        } else if modal_call {
            self.mcall = None;
        }
        if let Some((text, code)) = new_cycle {
            self.start_cycle(line, text, code, &block)?;
        }

        let has_axes = block.axes.iter().any(Option::is_some);
        let has_vector = block.vector.iter().any(Option::is_some);
        let has_centre = block.centre.iter().any(Option::is_some);
        if let Some((text, ..)) = &block.corner
            && (no_motion.is_some() || !has_axes || self.cycle.is_some())
        {
            return Err(self.error(
                line,
                format!(
                    "`{text}`: a chamfer or rounding is written on a straight move (G1 with axis \
                     words), where it cuts the corner to the next move; this block makes none"
                ),
            ));
        }
        if self.cycle.is_some() && no_motion.is_none() && !machine {
            if new_cycle.is_some() || has_axes || block.radius.is_some() {
                self.hole(line, &block)?;
            }
            self.end_if(end);
            return Ok(());
        }
        let is_arc = matches!(self.motion, Some(Motion::ArcCw | Motion::ArcCcw));
        let ijk_vector = self.tcp == Tcp::OnIjkVector && !is_arc;
        let moves = no_motion.is_none()
            && (has_axes || has_vector || (has_centre && (ijk_vector || is_arc)));
        if moves {
            self.motion_block(line, &block, machine)?;
            if let Some(call) = self.mcall.take()
                && block.axes[..2].iter().any(Option::is_some)
            {
                let from = self.points.len();
                let name = format!("MCALL CYCLE{}", call.number);
                let run = self
                    .cycle_plane(line, &name)
                    .and_then(|()| self.cycle_along_tool(line, &name))
                    .and_then(|()| self.run_steps(line, &call.steps));
                if let Some(tap) = call.tap {
                    self.tapping(line, "MCALL CYCLE84".into(), from, tap);
                }
                self.mcall = Some(call);
                run?;
            }
        } else if no_motion.is_none() && (has_centre || block.radius.is_some()) {
            self.warn(line, "I/J/K or R without a move: ignored");
        }
        self.end_if(end);
        Ok(())
    }

    /// Records the block's tool length offset code (`G43`, `G44`, `G49`; tool-tip mode's
    /// `G43.4`, `G43.5`, Haas `G234` for their H) where the dialect has them, before the
    /// block's motion, which the control runs with it.
    fn length_offset(&mut self, line: usize, block: &Block) -> Result<()> {
        if self.spec.length_offsets == LengthOffsets::Absent {
            return Ok(());
        }
        for (text, _, _) in &block.actions {
            // (Every block passes here: the code's number, without making its name.)
            let Some(n) = text
                .strip_prefix(['G', 'g'])
                .and_then(|n| n.parse::<f64>().ok())
            else {
                continue;
            };
            let sign = if [43.0, 43.4, 43.5, 234.0].contains(&n) {
                Some(true)
            } else if n == 44.0 {
                Some(false)
            } else if n == 49.0 {
                None
            } else {
                continue;
            };
            let offset = match sign {
                None => LengthOffset::Cancel,
                Some(plus) => {
                    let h = match block.letter('H') {
                        Some(h) => {
                            let n =
                                self.tool_number(line, &format!("{} H", code_name(text)), h.value)?;
                            self.last_h = Some(n);
                            Some(n)
                        }
                        None => match self.spec.length_offsets {
                            LengthOffsets::BareTakesTool => {
                                self.tool_changes.last().and_then(|c| match c.tool {
                                    ToolSelect::Number(n) => Some(n),
                                    _ => None,
                                })
                            }
                            _ => self.last_h,
                        },
                    };
                    if plus {
                        LengthOffset::Plus(h)
                    } else {
                        LengthOffset::Minus(h)
                    }
                }
            };
            self.length_offsets.push(LengthOffsetChange {
                point: self.points.len(),
                line,
                offset,
            });
        }
        Ok(())
    }

    /// A tool number as written after `what` (T, M61 Q): a whole number from 0 to 4294967295.
    fn tool_number(&self, line: usize, what: &str, value: f64) -> Result<u32> {
        if value >= 0.0 && value.fract() == 0.0 && value <= u32::MAX as f64 {
            Ok(value as u32)
        } else {
            Err(self.error(
                line,
                format!("{what}{value}: a tool number is a whole number from 0"),
            ))
        }
    }

    /// The spindle turns at `rpm` from the next move on (a speed that is not positive and
    /// finite, or the same as before, changes nothing).
    pub(super) fn set_spindle(&mut self, line: usize, rpm: f64) {
        self.rpm = Some(rpm.abs());
        SpindleChange::record(&mut self.spindle_changes, self.points.len(), line, rpm);
    }

    /// G93, G94 or G95 from here on. Leaving G93 forgets F (an inverse time is no feed), and
    /// so does a change to or from G95 (F per revolution and per minute are different
    /// quantities: LinuxCNC sets F to 0 at G94 and G95, and a Fanuc program gives F again);
    /// LinuxCNC's every `G94` sets F to 0.
    fn set_feed_mode(&mut self, mode: FeedMode) {
        let per_rev = |m: FeedMode| m == FeedMode::PerRevolution;
        if (self.spec.g94_clears_feed && mode == FeedMode::PerMinute)
            || (mode != self.feed_mode
                && (self.feed_mode == FeedMode::InverseTime
                    || per_rev(mode)
                    || per_rev(self.feed_mode)))
        {
            self.feed = None;
        }
        self.feed_mode = mode;
    }

    /// The modal feed at a move of line `line` (not under G93): G94's F, or under G95 F × S,
    /// the spindle speed last programmed; an error naming the line when no F is in force.
    /// Under G95 a move
    /// with an F and no spindle speed (none programmed, S0, or G96's cutting speed) is an
    /// error naming the line.
    fn modal_feed(&self, line: usize) -> Result<ModalFeed> {
        let Some(f) = self.feed else {
            // Every control refuses it (LinuxCNC: "Cannot do G1 with zero feed rate"; Fanuc:
            // alarm PS0011; Sinumerik: alarm 10860; grbl: error 22): it is not a rapid.
            return Err(self.error(
                line,
                "a feed move with no feed rate (no F programmed before it, or F0): the control \
                 stops here; program F before the move",
            ));
        };
        if self.feed_mode != FeedMode::PerRevolution {
            return Ok(f);
        }
        let why = match self.rpm {
            _ if self.surface_speed => {
                "under G96 (constant surface speed) S is a cutting speed, and the spindle's rpm \
                 follows the diameter: program G97 S<rpm>"
            }
            None => "no spindle speed S is programmed before it: program S<rpm> before the move",
            Some(rpm) if rpm <= 0.0 || !rpm.is_finite() => {
                "the spindle speed is S0: program S<rpm> before the move"
            }
            Some(rpm) => {
                return Ok(ModalFeed {
                    mm_per_min: f.mm_per_min * rpm,
                    raw: f.raw * rpm,
                });
            }
        };
        Err(self.error(
            line,
            format!(
                "G95 (feed per revolution): the feed of this move is F × S, and {why} (or G94 \
                 and F per minute)"
            ),
        ))
    }

    /// `tool` goes into the spindle here: the next move is its first.
    pub(super) fn change_tool(&mut self, line: usize, tool: ToolSelect) {
        self.tool_changes.push(ToolChange {
            point: self.points.len(),
            line,
            tool,
        });
    }

    fn end_if(&mut self, end: bool) {
        if end {
            self.ended = true;
        }
    }

    /// `G4`: P seconds (LinuxCNC), P milliseconds or X seconds (Fanuc), F seconds (Sinumerik).
    fn dwell(&mut self, line: usize, block: &Block) -> Result<()> {
        let seconds = if self.spec.spaces == Spaces::Separate {
            match (block.feed, block.letter('S')) {
                (Some(f), _) => f,
                (None, Some(_)) => {
                    return Err(self.error(
                        line,
                        "G4 S (dwell in spindle revolutions) is not supported: program G4 F \
                         (seconds)",
                    ));
                }
                (None, None) => return Err(self.error(line, "G4 without F (seconds)")),
            }
        } else {
            match (block.letter('P'), block.axes[0]) {
                // P counts milliseconds on Fanuc whatever DPI says (P takes no decimal
                // point); X is seconds, in increments of 0.001 s when written without one
                // (`G4 X2500` is 2.5 s) unless the input is calculator-type.
                (Some(p), _) if self.spec.integer_increments.is_some() && !p.point => {
                    p.value / 1000.0
                }
                (Some(p), _) => p.value,
                (None, Some(x)) => match self.increments {
                    Some(_) if !x.point => x.value / 1000.0,
                    _ => x.value,
                },
                // Marlin (Snapmaker, Prusa firmware) reads `G4 S2` as 2 s; here S is the
                // spindle speed and the dwell has no time.
                (None, None) if block.letter('S').is_some() => {
                    return Err(self.error(
                        line,
                        "G4 without P (the dwell time): its S is a spindle speed here, \
                         although Marlin firmware (Snapmaker, Fusion's Marlin posts) reads \
                         `G4 S…` as seconds; write the dwell as `G4 P…` (seconds in LinuxCNC, \
                         milliseconds in Fanuc)",
                    ));
                }
                (None, None) => return Err(self.error(line, "G4 without P (the dwell time)")),
            }
        };
        if !(0.0..=1e6).contains(&seconds) {
            return Err(self.error(line, format!("G4: dwell of {seconds} s is out of range")));
        }
        self.add_dwell(line, seconds);
        Ok(())
    }

    fn add_dwell(&mut self, line: usize, seconds: f64) {
        if seconds > 0.0 {
            self.dwells.push(Dwell {
                point: self.points.len().saturating_sub(1),
                seconds,
                line,
            });
        }
    }

    /// Sinumerik `TRANS`/`ATRANS`/`ROT`/`AROT` with the block's X Y Z (none: cancel).
    fn frame(&mut self, line: usize, text: &str, op: FrameOp, block: &Block) -> Result<()> {
        if block.axes[3..].iter().any(Option::is_some) {
            let rotary: Vec<&str> = ["A", "B", "C"]
                .into_iter()
                .zip(&block.axes[3..])
                .filter(|(_, a)| a.is_some())
                .map(|(n, _)| n)
                .collect();
            let rotary = rotary.join(", ");
            // Siemens (Programming Manual Fundamentals, "TRANS, ATRANS"): the offset may name
            // any axis, a rotary one included, whose zero it shifts. feedopt's frames move X Y
            // Z only; a rotary axis' shift changes where its programmed angles are, and on a
            // 5-axis machine where the tool is, so it is an error, not a skipped word.
            let what = match op {
                FrameOp::Trans | FrameOp::ATrans => format!(
                    "`{text}` with {rotary}: a shift of the zero of rotary axis {rotary}, which \
                     feedopt does not model (the programmed angles, and on a 5-axis machine the \
                     tool's position, depend on it). Remove it where the shift is 0, or add the \
                     shift to the program's {rotary} words"
                ),
                FrameOp::Rot | FrameOp::ARot => format!(
                    "`{text}` with {rotary}: feedopt rotates frames about X, Y and Z only \
                     (`{text} X… Y… Z…`, angles in degrees)"
                ),
            };
            return Err(self.error(line, what));
        }
        let given = block.axes[..3].iter().any(Option::is_some);
        let v: [f64; 3] = std::array::from_fn(|i| match (block.axes[i], op) {
            (Some(n), FrameOp::Trans | FrameOp::ATrans) => self.length(n),
            (Some(n), _) => n.value,
            (None, _) => 0.0,
        });
        let f = match op {
            FrameOp::Trans | FrameOp::ATrans => Frame::translation(Vector3::from(v)),
            FrameOp::Rot | FrameOp::ARot => Frame::rotation(frames::rot_zyx(v)),
        };
        self.programmable = match op {
            FrameOp::Trans | FrameOp::Rot if !given => Frame::IDENTITY,
            FrameOp::Trans | FrameOp::Rot => f,
            FrameOp::ATrans | FrameOp::ARot => self.programmable.then_inner(&f),
        };
        Ok(())
    }

    /// Fanuc `G68.2 X Y Z I J K`.
    fn tilted_plane(&mut self, line: usize, block: &Block) -> Result<()> {
        let origin: [f64; 3] =
            std::array::from_fn(|i| block.axes[i].map_or(0.0, |n| self.length(n)));
        let angle = |i: usize| block.centre[i].map_or(0.0, |n| self.angle(n));
        if block.axes[3..].iter().any(Option::is_some) {
            return Err(self.error(line, "G68.2 with A/B/C words"));
        }
        self.swivel = Some(Frame {
            r: frames::euler_zxz(angle(0), angle(1), angle(2)),
            t: Vector3::from(origin),
        });
        Ok(())
    }

    /// The frame from program coordinates to workpiece coordinates, without the work
    /// offsets' shift.
    fn frame_inner(&self) -> Frame {
        match &self.swivel {
            Some(s) => s.then_inner(&self.programmable),
            None => self.programmable,
        }
    }

    /// The frame from program coordinates to toolpath coordinates: the frames, then the work
    /// offsets' shift ([`offsets`]; none until a program sets one).
    fn frame_now(&self) -> Frame {
        let inner = self.frame_inner();
        let s = self.offsets.shift();
        if s[..3] == [0.0; 3] {
            inner
        } else {
            Frame::translation(Vector3::new(s[0], s[1], s[2])).then_inner(&inner)
        }
    }

    /// The work offsets' shift was `before` and is now another: the position stays where it
    /// is, so its program coordinates change (LinuxCNC and Fanuc show the new ones at once).
    fn shift_changed(&mut self, before: [f64; 6]) {
        let after = self.offsets.shift();
        if after == before {
            return;
        }
        let inner = self.frame_inner();
        let d = Vector3::new(
            before[0] - after[0],
            before[1] - after[1],
            before[2] - after[2],
        );
        let q =
            inner.invert(&(inner.apply(&Vector3::new(self.pos[0], self.pos[1], self.pos[2])) + d));
        self.pos[..3].copy_from_slice(q.as_slice());
        for i in 3..6 {
            self.pos[i] += before[i] - after[i];
        }
    }

    /// `G10 L2 P…` / `G10 L20 P…`: sets a work offset ([`offsets`]); other `L` values set
    /// tool data or parameters, which the toolpath does not use (a warning).
    fn g10(
        &mut self,
        line: usize,
        text: &str,
        numbering: OffsetNumbering,
        block: &Block,
    ) -> Result<()> {
        let l = block.letter('L').map(|n| n.value);
        let l20 = match l {
            Some(2.0) => false,
            Some(20.0) => true,
            _ => {
                let which = l.map_or(String::new(), |v| format!(" L{v}"));
                self.warn(
                    line,
                    format!(
                        "{text}{which}: sets tool data or control parameters, which the \
                         toolpath does not use; nothing moves"
                    ),
                );
                return Ok(());
            }
        };
        let code = if l20 { "G10 L20" } else { "G10 L2" };
        let Some(p) = block.letter('P') else {
            return Err(self.error(
                line,
                format!("{code} without P (the offset it sets): add P, e.g. {code} P1 X0 Y0 Z0"),
            ));
        };
        let mut written = format!("{code} P{}", p.value);
        for (i, axis) in block.axes.iter().enumerate() {
            if let Some(n) = axis {
                written.push_str(&format!(
                    " {}{}",
                    AXIS_NAMES[i],
                    crate::error::number(n.value)
                ));
            }
        }
        if let Some(r) = block.radius
            && r.value != 0.0
        {
            return Err(self.error(
                line,
                format!(
                    "`{written} R{}`: R turns the coordinate system about Z, which feedopt does \
                     not follow: post the program without the rotation",
                    crate::error::number(r.value)
                ),
            ));
        }
        if self.swivel.is_some() {
            return Err(self.error(
                line,
                format!(
                    "`{written}` under a tilted plane (G68.2): set work offsets before the plane"
                ),
            ));
        }
        const LINUXCNC: [&str; 9] = [
            "G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3",
        ];
        let whole = (p.value >= 0.0 && p.value.fract() == 0.0).then_some(p.value as usize);
        let target = match (numbering, l20, whole) {
            (OffsetNumbering::LinuxCnc, _, Some(0)) => {
                offsets::Target::Offset(self.offsets.active().to_string())
            }
            (OffsetNumbering::LinuxCnc, _, Some(n @ 1..=9)) => {
                offsets::Target::Offset(LINUXCNC[n - 1].to_string())
            }
            (OffsetNumbering::Fanuc, false, Some(0)) => offsets::Target::External,
            (OffsetNumbering::Fanuc, false, Some(n @ 1..=6)) => {
                offsets::Target::Offset(LINUXCNC[n - 1].to_string())
            }
            (OffsetNumbering::Fanuc, true, Some(n @ 1..=300)) => {
                offsets::Target::Offset(format!("G54.1 P{n}"))
            }
            _ => {
                let range = match (numbering, l20) {
                    (OffsetNumbering::LinuxCnc, _) => "P0 (the offset in force) to P9 (G59.3)",
                    (OffsetNumbering::Fanuc, false) => {
                        "P0 (the external offset) or P1 (G54) to P6 (G59)"
                    }
                    (OffsetNumbering::Fanuc, true) => "P1 to P300 (G54.1 P1 …)",
                };
                return Err(self.error(
                    line,
                    format!("`{written}`: P names no work offset; expected {range}"),
                ));
            }
        };
        let offset = match &target {
            offsets::Target::Offset(name) => name.clone(),
            offsets::Target::External => "the external offset".to_string(),
        };
        let cause = offsets::Cause {
            line,
            text: written.clone(),
            offset,
        };
        let work = self.machine.map_or([0.0; 3], |c| c.work_offset);
        let here = {
            let p = self
                .frame_now()
                .apply(&Vector3::new(self.pos[0], self.pos[1], self.pos[2]));
            let s = self.offsets.shift();
            [
                p.x,
                p.y,
                p.z,
                self.pos[3] + s[3],
                self.pos[4] + s[4],
                self.pos[5] + s[5],
            ]
        };
        let incremental =
            numbering == OffsetNumbering::Fanuc && self.distance == Distance::Incremental;
        let before = self.offsets.shift();
        for i in 0..6 {
            let Some(n) = block.axes[i] else { continue };
            let v = if i < 3 { self.length(n) } else { self.angle(n) };
            let how = if l20 && numbering == OffsetNumbering::LinuxCnc {
                if i < 3 && !self.known[i] {
                    return Err(self.error(
                        line,
                        format!(
                            "`{written}` makes the current position {}{} in the offset, but \
                             the current {} is not known yet (no absolute {} programmed \
                             before): program a move first",
                            AXIS_NAMES[i],
                            crate::error::number(v),
                            AXIS_NAMES[i],
                            AXIS_NAMES[i]
                        ),
                    ));
                }
                offsets::Setting::Position {
                    here: here[i],
                    given: v,
                }
            } else if incremental {
                offsets::Setting::Increment(v)
            } else {
                let w = match target {
                    offsets::Target::Offset(_) if i < 3 => work[i],
                    _ => 0.0,
                };
                offsets::Setting::Machine(v - w)
            };
            self.offsets.set(&target, i, how, &cause);
        }
        self.shift_changed(before);
        Ok(())
    }

    /// `G52 X… Y…`: the local shift of every work offset on the named axes (`G52 X0 Y0`
    /// cancels it). Under G91 the words would be increments on some controls and values on
    /// others: the block is an error unless both read the same (no shift in force on the
    /// named axes).
    fn g52(&mut self, line: usize, block: &Block) -> Result<()> {
        if block.axes.iter().all(Option::is_none) {
            return Err(self.error(
                line,
                "G52 without axis words: name the axes it shifts (G52 X0 Y0 cancels the local \
                 shift)",
            ));
        }
        let before = self.offsets.shift();
        for i in 0..6 {
            let Some(n) = block.axes[i] else { continue };
            let v = if i < 3 { self.length(n) } else { self.angle(n) };
            if v == self.offsets.local(i) {
                continue;
            }
            if self.swivel.is_some() {
                return Err(self.error(
                    line,
                    "G52 under a tilted plane (G68.2): set the local shift before the plane",
                ));
            }
            if self.offsets.position(i) != 0.0 {
                return Err(self.error(
                    line,
                    format!(
                        "G52 {}{} while a G92 shift is in force on {}: controls differ on how \
                         the two combine; program one of them",
                        AXIS_NAMES[i],
                        crate::error::number(n.value),
                        AXIS_NAMES[i]
                    ),
                ));
            }
            if self.distance == Distance::Incremental && self.offsets.local(i) != 0.0 {
                return Err(self.error(
                    line,
                    format!(
                        "G52 {}{} under G91 while a local shift is in force on {}: controls read \
                         it as a new value or as an increment; program G52 under G90",
                        AXIS_NAMES[i],
                        crate::error::number(n.value),
                        AXIS_NAMES[i]
                    ),
                ));
            }
            self.offsets.set_local(i, v);
        }
        self.g92_params = Some(std::array::from_fn(|i| self.offsets.local(i)));
        self.shift_changed(before);
        Ok(())
    }

    /// `G92 X… Y…`: the current position gets the coordinates named, by a shift of every work
    /// offset on those axes ([`offsets`]); the tool does not move. On an axis the program has
    /// not placed yet, the position is the unknown start (taken as 0), and the moves after it
    /// are exact relative to it. LinuxCNC keeps the shift in `G52`'s register; Fanuc apart from
    /// it, and where both would be in force on an axis the block is an error (whether `G92`
    /// cancels `G52` there is the control's matter).
    fn g92(&mut self, line: usize, numbering: OffsetNumbering, block: &Block) -> Result<()> {
        if block.axes.iter().all(Option::is_none) {
            // A lathe's G92 S (Fanuc T series, G-code systems B and C; G50 S in system A)
            // limits the spindle speed under G96: a turning program, whose X is a diameter.
            if let Some(s) = block.letter('S') {
                return Err(self.error(
                    line,
                    format!(
                        "`G92 S{}` without axis words: a lathe's spindle speed limit (Fanuc T \
                         series, G-code systems B and C), so this is a turning program (X a \
                         diameter, U/W incremental axes), which feedopt does not read: it reads \
                         milling programs. On a mill, G92 X… Y… Z… sets the current position",
                        s.value
                    ),
                ));
            }
            return Err(self.error(
                line,
                "G92 without axis words: name the axes whose current position it sets (G92 X0 \
                 Y0 Z0 makes the current point the origin)",
            ));
        }
        if block.axes[..3].iter().any(Option::is_some) && !self.frame_inner().is_identity() {
            return Err(self.error(
                line,
                "G92 under a rotated, scaled or tilted frame (G68, G51, G68.2): set the position \
                 before the frame",
            ));
        }
        let before = self.offsets.shift();
        for i in 0..6 {
            let Some(n) = block.axes[i] else { continue };
            let v = if i < 3 { self.length(n) } else { self.angle(n) };
            // The shift that makes the position read v: pos − v more than the one in force.
            let by = self.pos[i] - v;
            match numbering {
                OffsetNumbering::LinuxCnc => {
                    self.offsets.set_local(i, self.offsets.local(i) + by);
                }
                OffsetNumbering::Fanuc => {
                    if self.offsets.local(i) != 0.0 {
                        return Err(self.error(
                            line,
                            format!(
                                "G92 {}{} while a G52 local shift is in force on {}: cancel it \
                                 first (G52 {}0)",
                                AXIS_NAMES[i],
                                crate::error::number(n.value),
                                AXIS_NAMES[i],
                                AXIS_NAMES[i]
                            ),
                        ));
                    }
                    self.offsets.set_position(i, self.offsets.position(i) + by);
                }
            }
            if i < 3 {
                self.known[i] = true;
            }
        }
        if numbering == OffsetNumbering::LinuxCnc {
            self.g92_params = Some(std::array::from_fn(|i| self.offsets.local(i)));
        }
        self.shift_changed(before);
        Ok(())
    }

    /// The error of a point made across offsets on different bases ([`offsets::Mismatch`]),
    /// at the `G10` behind it (the move at `line`).
    fn offset_mismatch(&self, line: usize, m: offsets::Mismatch) -> Error {
        let axis = AXIS_NAMES[m.axis];
        let Some(cause) = m.cause else {
            return self.error(
                line,
                format!(
                    "the move's length in {axis} depends on work offsets feedopt does not know"
                ),
            );
        };
        let side = if m.ends_on_machine {
            format!(
                "the move at line {line} starts from a point made with the offsets as the \
                 control had them before"
            )
        } else {
            format!("the move at line {line} ends at a point in an offset the program does not set")
        };
        Error::parse(
            self.source,
            cause.line,
            format!(
                "`{}`: sets {} in machine coordinates, and {side}, whose values feedopt does not \
                 know, so that move's length in {axis} is not known. Set the offsets the program \
                 moves in with G10 L2 before its first move, or relative to the current position \
                 (G10 L20 on LinuxCNC, G91 G10 L2 on Fanuc)",
                cause.text, cause.offset
            ),
        )
    }

    /// The M92 datum of axis `i` (X Y Z), machine coordinates: the machine file's
    /// `axes.<X|Y|Z>.m92`, or machine zero (M91's datum) with a warning where it gives none.
    fn m92_datum(&mut self, line: usize, i: usize) -> f64 {
        if let Some(d) = self.machine.and_then(|c| c.m92[i]) {
            return d;
        }
        if !self.m92_warned[i] {
            self.m92_warned[i] = true;
            let file = self.machine.map_or("the machine file".to_string(), |c| {
                c.file.display().to_string()
            });
            self.warn(
                line,
                format!(
                    "M92: the machine builder's datum of {} is machine data feedopt does not \
                     know: taken as machine zero (M91's); give it as axes.{}.m92 (machine \
                     coordinates, mm) in {file}",
                    AXIS_NAMES[i], AXIS_NAMES[i]
                ),
            );
        }
        0.0
    }

    /// Where the machine file does not give the work offset a machine-coordinate move needs:
    /// what that means and the field to set (else empty).
    fn unknown_work_offset(&self) -> String {
        match self.machine {
            Some(c) if !c.work_offset_given => format!(
                ": {} gives no work offset, so a machine position is read as the same position \
                 in program coordinates (G53 Z0, the top of Z's travel, as the part's Z0); set \
                 \"work_offset\": [x, y, z], the machine coordinates of the program's origin \
                 (its G54 offset), mm",
                c.file.display()
            ),
            _ => String::new(),
        }
    }

    /// Machine coordinates → program (frame) coordinates, X Y Z.
    fn machine_to_program(&self, m: Vector3<f64>) -> Vector3<f64> {
        let offset = self.machine.map_or([0.0; 3], |c| c.work_offset);
        self.frame_now().invert(&(m - Vector3::from(offset)))
    }

    fn to_machine(&self, p: Vector3<f64>) -> Vector3<f64> {
        let offset = self.machine.map_or([0.0; 3], |c| c.work_offset);
        self.frame_now().apply(&p) + Vector3::from(offset)
    }

    /// `G28`/`G30` (k = 1, 2; `G30 P3`: 3): via the intermediate point the axis words give
    /// (program coordinates, absolute or incremental), to the reference point of the same
    /// axes (machine coordinates from the machine file; where it gives none, machine zero,
    /// with a warning and [`Assumed::reference_at_machine_zero`]). Both moves are rapids.
    /// Without axis words, LinuxCNC sends every axis the machine has straight to its
    /// reference ([`DialectSpec::bare_reference_moves_all`]); elsewhere that is an error.
    fn reference(&mut self, line: usize, k: u8, block: &Block) -> Result<()> {
        let k = match (k, block.letter('P')) {
            (2, Some(p)) if (2.0..=4.0).contains(&p.value) && p.value.fract() == 0.0 => {
                p.value as usize
            }
            (2, Some(p)) => {
                return Err(self.error(line, format!("G30 P{}: expected P2, P3 or P4", p.value)));
            }
            (k, _) => k as usize,
        };
        let code = if k == 1 { "G28" } else { "G30" };
        let mut named: Vec<usize> = (0..6).filter(|&i| block.axes[i].is_some()).collect();
        if named.is_empty()
            && (self.spec.bare_reference_moves_all || self.machine.is_some_and(|m| m.g28_all_axes))
        {
            // LinuxCNC: straight to the stored position, every axis the machine has (X Y Z
            // where the machine file is not known).
            named = match self.machine.and_then(|m| m.axes.as_ref()) {
                Some(axes) => (0..6).filter(|&i| axes.contains(&AXIS_NAMES[i])).collect(),
                None => vec![0, 1, 2],
            };
        }
        if named.is_empty() {
            return Err(self.error(
                line,
                format!(
                    "{code} without axis words is read differently by the controls of this \
                     dialect: a Haas returns every axis to its reference point, a Fanuc none; \
                     name the axes the control returns (a Haas: `G91 {code} X0 Y0 Z0`), or set \
                     \"g28_without_axes\": \"all\" in the machine file of a Haas"
                ),
            ));
        }
        // The intermediate point.
        let mut via = self.pos;
        for &i in &named {
            let Some(num) = block.axes[i] else { continue };
            let v = if i < 3 {
                self.length(num)
            } else {
                self.angle(num)
            };
            via[i] = if self.distance == Distance::Incremental {
                self.pos[i] + v
            } else {
                v
            };
        }
        self.go_to_reference(line, code, k, &named, via)
    }

    /// grbl's homing cycle, `$H` (every axis it homes: Z first, then X and Y, as grbl's and
    /// grblHAL's default `HOMING_CYCLE_0` (Z) and `HOMING_CYCLE_1` (X, Y) order it), or one
    /// axis, grblHAL's `$HX`, `$HY`, `$HZ`, `$HA`, …: the axes go to the machine's home
    /// position, the machine file's `reference` (G28's point), else machine zero — where grbl
    /// sets machine position 0 when homing in its default (positive) direction. Before any
    /// move, the program starts there (every axis at once: the start is not a path); after
    /// one, each group is a rapid to home, and the cycle's switch search at the homing rates
    /// (`$24`, `$25`, pull-off `$27`) is not timed: said with the line.
    pub(super) fn homing(&mut self, line: usize, text: &str, axes: &[usize]) -> Result<()> {
        let present: Vec<usize> = match self.machine.and_then(|m| m.axes.as_ref()) {
            Some(names) => (0..6).filter(|&i| names.contains(&AXIS_NAMES[i])).collect(),
            None => vec![0, 1, 2],
        };
        if let Some(&missing) = axes.iter().find(|i| !present.contains(i)) {
            return Err(self.error(
                line,
                format!(
                    "`{text}` homes {}, an axis this machine does not have",
                    AXIS_NAMES[missing]
                ),
            ));
        }
        let started = self.known.iter().any(|&k| k);
        let groups: Vec<Vec<usize>> = if !axes.is_empty() {
            vec![axes.to_vec()]
        } else if !started {
            vec![present.iter().copied().filter(|&i| i < 3).collect()]
        } else {
            vec![
                vec![2],
                present.iter().copied().filter(|&i| i < 2).collect(),
            ]
        };
        if started {
            self.warn(
                line,
                format!(
                    "`{text}`: grbl's homing cycle is read as rapids to the home position \
                     (the machine file's reference, else machine zero), {}; the cycle's switch \
                     search at the homing rates ($24, $25, pull-off $27) is not timed",
                    if axes.is_empty() {
                        "Z first, then X and Y (grbl's default order)"
                    } else {
                        "that axis alone"
                    }
                ),
            );
        }
        for group in groups.iter().filter(|g| !g.is_empty()) {
            let via = self.pos;
            self.go_to_reference(line, &format!("`{text}`"), 1, group, via)?;
        }
        Ok(())
    }

    /// The move of `G28`/`G30` (`code`; k: the reference point, 1 for G28's) from `via` to
    /// the reference point of the `named` axes, shared with grbl's homing cycle.
    fn go_to_reference(
        &mut self,
        line: usize,
        code: &str,
        k: usize,
        named: &[usize],
        via: [f64; 6],
    ) -> Result<()> {
        let mut target = via;
        let mut machine_xyz = self.to_machine(Vector3::new(via[0], via[1], via[2]));
        let mut defaulted = Vec::new();
        let mut at = [0.0; 6];
        for &i in named {
            // The machine file's reference, else machine zero: the controls' default (Fanuc
            // parameters 1240–1243, LinuxCNC 5161–5169 / 5181–5189 are 0 in machine
            // coordinates, and Fanuc's machine zero is the reference position).
            let r = match self
                .machine
                .and_then(|m| m.reference[i].get(k - 1).copied())
            {
                Some(r) => r,
                None => {
                    if !self.assumed.reference_at_machine_zero[i] {
                        self.assumed.reference_at_machine_zero[i] = true;
                        defaulted.push(AXIS_NAMES[i]);
                    }
                    0.0
                }
            };
            at[i] = r;
            if i < 3 {
                machine_xyz[i] = r;
            } else {
                // A machine coordinate, as the program coordinate the offsets take to it.
                target[i] = r - self.offsets.shift()[i];
            }
        }
        if named.iter().any(|&i| i < 3) {
            let unknown = self.unknown_work_offset();
            if !unknown.is_empty() {
                self.warn(
                    line,
                    format!("{code}: the reference point is a machine position{unknown}"),
                );
            }
        }
        if !defaulted.is_empty() {
            let file = self.machine.map_or("the machine file".to_string(), |m| {
                m.file.display().to_string()
            });
            let fields: Vec<String> = defaulted
                .iter()
                .map(|a| format!("axes.{a}.reference"))
                .collect();
            let which = if k == 1 {
                String::new()
            } else {
                format!(" to a list [<G28 position>, <G30 position>, …] of {k} entries")
            };
            self.warn(
                line,
                format!(
                    "{code}: {file} gives no reference point for {}: machine zero (machine \
                     coordinate 0, the controls' default) is used; to use another, set {}{which} \
                     (machine coordinates, mm or °)",
                    defaulted
                        .iter()
                        .map(|a| a.to_string())
                        .collect::<Vec<_>>()
                        .join(", "),
                    fields.join(", ")
                ),
            );
        }
        let xyz = self.machine_to_program(machine_xyz);
        target[..3].copy_from_slice(xyz.as_slice());
        for &i in named {
            if i >= 3 {
                self.saw_rotary = true;
            }
        }
        // Only the named axes move: the others stay where they are, and where the program has
        // not placed them yet that is the unknown start (taken as 0, with the usual warning:
        // a Fusion post's leading `G28 G91 Z0` had hidden it, and the first move from X0 Y0
        // was counted in silence).
        for &i in named.iter().filter(|&&i| i < 3) {
            self.known[i] = true;
        }
        self.warn_unknown(line);
        if via != self.pos {
            self.push(line, &via, Feed::Rapid);
        }
        // The reference point is a machine position: outside the work offsets' check.
        self.machine_point = true;
        self.push(line, &target, Feed::Rapid);
        self.machine_point = false;
        self.machine_points.push(MachinePoint {
            point: self.points.len() - 1,
            line,
            kind: MachineMove::Reference {
                k: k as u8,
                axes: std::array::from_fn(|i| named.contains(&i)),
                at,
            },
        });
        self.pos = target;
        Ok(())
    }

    /// Enters (or changes) a Fanuc/LinuxCNC canned cycle.
    fn start_cycle(&mut self, line: usize, text: &str, code: u32, block: &Block) -> Result<()> {
        let Some(kind) = cycles::Kind::from_code(code) else {
            return Err(self.error(line, format!("{text}: not a drilling cycle feedopt knows")));
        };
        if self.plane != Plane::Xy {
            return Err(self.error(
                line,
                format!("{text} outside G17: canned cycles are read in the XY plane only"),
            ));
        }
        if self.feed_mode == FeedMode::InverseTime {
            return Err(self.error(line, format!("{text} under G93 (inverse time)")));
        }
        let initial = self.pos[2];
        let keep = self.cycle.filter(|c| c.kind == kind);
        self.cycle = Some(CycleMode {
            kind,
            code,
            r: keep.and_then(|c| c.r),
            z: keep.and_then(|c| c.z),
            q: keep.and_then(|c| c.q),
            dwell: keep.map_or(0.0, |c| c.dwell),
            initial: self.cycle.map_or(initial, |c| c.initial),
        });
        let _ = block;
        Ok(())
    }

    /// One hole of the Fanuc/LinuxCNC cycle in force, at the block's X Y (and new R Z Q P).
    fn hole(&mut self, line: usize, block: &Block) -> Result<()> {
        let Some(mut c) = self.cycle else {
            return Ok(());
        };
        if block.axes[3..].iter().any(Option::is_some) {
            let words: Vec<&str> = ["A", "B", "C"]
                .iter()
                .zip(&block.axes[3..])
                .filter(|(_, w)| w.is_some())
                .map(|(n, _)| *n)
                .collect();
            return Err(self.error(
                line,
                format!(
                    "G{}: rotary axis words ({}) in a cycle block: whether and when a control \
                     turns them for the hole is its own setting, so feedopt does not guess; \
                     turn the rotary axes in a block of their own before the cycle (post the \
                     program so)",
                    c.code,
                    words.join(" ")
                ),
            ));
        }
        self.cycle_along_tool(line, &format!("G{}", c.code))?;
        let incremental = self.distance == Distance::Incremental;
        if let Some(r) = block.radius {
            let r = self.length(r);
            c.r = Some(if incremental { c.initial + r } else { r });
        }
        let r = c
            .r
            .ok_or_else(|| self.error(line, format!("G{}: R (the R plane) is missing", c.code)))?;
        if let Some(z) = block.axes[2] {
            let z = self.length(z);
            c.z = Some(if incremental { r + z } else { z });
        }
        let bottom = c.z.ok_or_else(|| {
            self.error(line, format!("G{}: Z (the hole bottom) is missing", c.code))
        })?;
        if let Some(q) = block.letter('Q') {
            c.q = Some(self.length(q).abs());
            if matches!(c.kind, cycles::Kind::G74 | cycles::Kind::G84) {
                // Fanuc's peck tapping is machine data (parameter 5200#6 PCT): read as one pass.
                self.warn(
                    line,
                    format!(
                        "G{}: Q in a tapping cycle pecks (Fanuc peck tapping, parameter 5200#6 \
                         PCT = 1) or is ignored (PCT = 0): read as one pass, without pecks",
                        c.code
                    ),
                );
            }
        }
        if let Some(p) = block.letter('P') {
            c.dwell = if self.spec.integer_increments.is_some() && !p.point {
                p.value / 1000.0
            } else {
                p.value
            };
            if !(0.0..=1e6).contains(&c.dwell) {
                return Err(self.error(line, format!("G{}: dwell P out of range", c.code)));
            }
        }
        self.cycle = Some(c);
        // Repeats: the dialect's letters ([`DialectSpec::cycle_repeat`]).
        let repeat = self.spec.cycle_repeat;
        if block.letter('K').is_some() && !repeat.contains(&'K') {
            return Err(self.error(
                line,
                format!(
                    "G{}: K is not a {} canned-cycle word ({} repeats with {})",
                    c.code,
                    self.spec.name,
                    self.spec.name,
                    repeat.iter().collect::<String>()
                ),
            ));
        }
        let count = repeat.iter().find_map(|&l| block.letter(l));
        let repeats = match count {
            None => 1,
            Some(n)
                if n.value.fract() == 0.0
                    && (0.0..=cycles::MAX_REPEATS as f64).contains(&n.value) =>
            {
                n.value as usize
            }
            Some(n) => {
                return Err(self.error(
                    line,
                    format!(
                        "G{}: repeat count {} (at most {})",
                        c.code,
                        n.value,
                        cycles::MAX_REPEATS
                    ),
                ));
            }
        };
        let clear = if self.return_to_r {
            r
        } else {
            c.initial.max(r)
        };
        let h = cycles::Hole {
            kind: c.kind,
            r,
            bottom,
            q: c.q,
            dwell: c.dwell,
            clear,
            initial: c.initial,
        };
        let (steps, note) =
            cycles::fanuc_steps(&h).map_err(|e| self.error(line, format!("G{}: {e}", c.code)))?;
        if let Some(note) = note {
            self.warn(line, format!("G{}: {note}", c.code));
        }
        let tap = matches!(c.kind, cycles::Kind::G74 | cycles::Kind::G84).then_some(Tap {
            pitch: None,
            rpm: self.rpm,
            left_hand: c.kind == cycles::Kind::G74,
        });
        // Each repeat: up to R, over the hole, and the cycle's moves.
        self.check_room(
            line,
            &format!("G{} with {repeats} repeats", c.code),
            repeats.saturating_mul(steps.len() + 3),
        )?;
        for k in 0..repeats {
            let mut xy = [self.pos[0], self.pos[1]];
            for i in 0..2 {
                if let Some(n) = block.axes[i] {
                    let v = self.length(n);
                    xy[i] = if incremental {
                        self.pos[i] + v
                    } else if k == 0 {
                        v
                    } else {
                        xy[i]
                    };
                    self.known[i] = true;
                }
            }
            // Up to R first when below it, then over the hole, then down to R.
            if self.pos[2] < r {
                self.rapid_z(line, r);
            }
            if xy != [self.pos[0], self.pos[1]] {
                let mut q = self.pos;
                q[0] = xy[0];
                q[1] = xy[1];
                self.push(line, &q, Feed::Rapid);
                self.pos = q;
            }
            self.known[2] = true;
            let shift = cycles::g87_shift(&h);
            if shift > 0.0 {
                self.run_steps(line, &[cycles::Step::ShiftX(shift)])?;
            }
            self.rapid_z(line, r);
            let from = self.points.len();
            self.run_steps(line, &steps)?;
            if let Some(tap) = tap {
                self.tapping(line, format!("G{}", c.code), from, tap);
            }
        }
        Ok(())
    }

    /// LinuxCNC `G33.1 Z- K- I-` (rigid tapping, the LinuxCNC manual's "G33.1 Rigid
    /// Tapping"): from the current point to Z synchronised with the spindle at K per
    /// revolution, the spindle reverses, and back to the start at I times the speed (I
    /// optional, 1). The overtravel while the spindle reverses is not modelled. Read along Z
    /// only: X and Y, if given, must be where the tool stands (the manual: otherwise the tap
    /// runs on a slant to the point), and the spindle must turn at a known speed. Its motion
    /// mode ends with the block: an axis word after it needs a new motion code.
    fn rigid_tap(&mut self, line: usize, block: &Block) -> Result<()> {
        self.cycle_along_tool(line, "G33.1")?;
        let fail = |m: &str| Err(self.error(line, format!("G33.1: {m}")));
        if self.plane != Plane::Xy {
            return fail("rigid tapping is read in the XY plane (G17) only");
        }
        if block.axes[3..].iter().any(Option::is_some) {
            return fail("rotary axis words in a rigid tap");
        }
        let incremental = self.distance == Distance::Incremental;
        for i in 0..2 {
            if let Some(n) = block.axes[i] {
                let v = self.length(n);
                let at = if incremental { self.pos[i] + v } else { v };
                if (at - self.pos[i]).abs() > 1e-9 || !self.known[i] {
                    return fail(
                        "X or Y off the point where the tool stands: the tap would run on a \
                        slant to it; position over the hole first and give only Z",
                    );
                }
            }
        }
        let Some(z) = block.axes[2] else {
            return fail("Z (the hole's bottom) is missing");
        };
        let z = self.length(z);
        let bottom = if incremental { self.pos[2] + z } else { z };
        let Some(k) = block.letter('K') else {
            return fail("K (the distance per revolution) is missing");
        };
        let pitch = self.length(k).abs();
        let factor = block.letter('I').map_or(1.0, |i| i.value);
        let Some(rpm) = self.rpm.filter(|r| *r > 0.0) else {
            return fail("no spindle speed (S) before it: the tap feeds at K × S");
        };
        let down = pitch * rpm;
        if !(pitch > 0.0 && (1e-3..=1e9).contains(&down)) {
            return fail("K × S is out of range");
        }
        if !(factor.is_finite() && factor > 0.0 && factor <= 100.0) {
            return fail("the return's speed factor I must be positive");
        }
        if !self.known[2] {
            return fail("the tool's Z is not known before the tap");
        }
        let top = self.pos[2];
        if bottom == top {
            return fail("Z is where the tool stands: the tap has no depth");
        }
        let from = self.points.len();
        self.check_room(line, "G33.1", 2)?;
        let mut q = self.pos;
        q[2] = bottom;
        self.push(line, &q, Feed::Programmed(down / 60.0));
        q[2] = top;
        self.push(line, &q, Feed::Programmed(down * factor / 60.0));
        self.motion = None;
        let tap = Tap {
            pitch: Some(pitch),
            rpm: Some(rpm),
            left_hand: self.spindle_reversed(),
        };
        self.tapping(line, "G33.1".into(), from, tap);
        Ok(())
    }

    fn rapid_z(&mut self, line: usize, z: f64) {
        let mut q = self.pos;
        q[2] = z;
        if q != self.pos {
            self.push(line, &q, Feed::Rapid);
            self.pos = q;
        }
    }

    /// Executes cycle steps from the current position.
    fn run_steps(&mut self, line: usize, steps: &[Step]) -> Result<()> {
        self.check_room(line, "the cycle", steps.len())?;
        let centre = [self.pos[0], self.pos[1]];
        for step in steps {
            let mut q = self.pos;
            let feed = match *step {
                Step::Rapid(z) => {
                    q[2] = z;
                    Feed::Rapid
                }
                Step::Feed(z, f) => {
                    q[2] = z;
                    let mm_per_min = match f {
                        Some(f) => f,
                        None => self.modal_feed(line)?.mm_per_min,
                    };
                    Feed::Programmed(mm_per_min / 60.0)
                }
                Step::ShiftX(dx) => {
                    q[0] += dx;
                    Feed::Rapid
                }
                Step::Across(dx, dy, f) => {
                    q[0] = centre[0] + dx;
                    q[1] = centre[1] + dy;
                    Feed::Programmed(f / 60.0)
                }
                Step::RapidAcross(dx, dy) => {
                    q[0] = centre[0] + dx;
                    q[1] = centre[1] + dy;
                    Feed::Rapid
                }
                Step::Helix {
                    radius,
                    sweep,
                    z,
                    feed,
                } => {
                    self.cycle_arc(line, centre, radius, sweep, z, feed)?;
                    continue;
                }
                Step::Arc {
                    cx,
                    cy,
                    sweep,
                    z,
                    feed,
                } => {
                    let c = [centre[0] + cx, centre[1] + cy];
                    let radius = (self.pos[0] - c[0]).hypot(self.pos[1] - c[1]);
                    self.cycle_arc(line, c, radius, sweep, z, feed)?;
                    continue;
                }
                Step::Dwell(s) => {
                    self.add_dwell(line, s);
                    continue;
                }
            };
            if q != self.pos {
                self.push(line, &q, feed);
                self.pos = q;
            }
        }
        Ok(())
    }

    /// A cycle's arc (a helix when Z changes) about `c` (X Y), `radius` mm, from the current
    /// point (at that distance from `c`) by `sweep` radians (counter-clockwise when positive),
    /// Z linearly to `z`, at `feed` mm/min: chords within the arc tolerance.
    fn cycle_arc(
        &mut self,
        line: usize,
        c: [f64; 2],
        radius: f64,
        sweep: f64,
        z: f64,
        feed: f64,
    ) -> Result<()> {
        let chords = crate::toolpath::arc_chords(sweep, radius).map_err(|e| self.error(line, e))?;
        self.check_room(line, "the cycle's helix", chords)?;
        let (x, y) = (self.pos[0] - c[0], self.pos[1] - c[1]);
        let start = y.atan2(x);
        let z0 = self.pos[2];
        for k in 1..=chords {
            let t = k as f64 / chords as f64;
            let phi = start + t * sweep;
            let mut p = self.pos;
            p[0] = c[0] + radius * phi.cos();
            p[1] = c[1] + radius * phi.sin();
            p[2] = z0 + t * (z - z0);
            self.push(line, &p, Feed::Programmed(feed / 60.0));
            self.pos = p;
        }
        Ok(())
    }

    /// Scales a Sinumerik cycle's length (and feed) parameters to mm (mm/min).
    fn sinumerik_cycle_units(&self, number: u32, args: Vec<Option<f64>>) -> Vec<Option<f64>> {
        let length = self.units.mm_per_unit();
        let feed = self.feed_units.mm_per_unit();
        let ptab = args.get(13).copied().flatten().map_or(0, |v| v as i64);
        args.into_iter()
            .enumerate()
            .map(|(k, a)| {
                a.map(|v| {
                    // CYCLE84's PIT in the unit _PTAB names (0: the program's).
                    if number == 84 && k == 8 {
                        return match ptab {
                            1 => v,
                            2 if v != 0.0 => MM_PER_INCH / v,
                            3 => v * MM_PER_INCH,
                            _ => v * length,
                        };
                    }
                    let is_length = k <= 4 || (number == 83 && (5..=7).contains(&k));
                    let is_feed = number == 85 && (6..=7).contains(&k);
                    if is_length {
                        v * length
                    } else if is_feed {
                        v * feed
                    } else {
                        v
                    }
                })
            })
            .collect()
    }

    fn run_sinumerik_cycle(
        &mut self,
        line: usize,
        text: &str,
        number: u32,
        args: &[Option<f64>],
    ) -> Result<()> {
        self.cycle_plane(line, text)?;
        self.cycle_along_tool(line, text)?;
        let (steps, notes) = cycles::sinumerik_steps(number, args, self.rpm)
            .map_err(|e| self.error(line, format!("{text}: {e}")))?;
        for n in notes {
            self.warn(line, format!("{text}: {n}"));
        }
        let from = self.points.len();
        self.run_steps(line, &steps)?;
        if number == 84 {
            let tap = self.sinumerik_tap(args);
            self.tapping(line, text.to_string(), from, tap);
        }
        Ok(())
    }

    /// CYCLE84's pitch PIT (mm, converted), speed SST (else the S in force) and hand: a
    /// negative PIT or MPIT is a left-hand thread; without either, the spindle's direction.
    fn sinumerik_tap(&self, args: &[Option<f64>]) -> Tap {
        let get = |k: usize| args.get(k).copied().flatten().filter(|v| *v != 0.0);
        let pitch = get(8);
        let left_hand = match pitch.or(get(7)) {
            Some(p) => p < 0.0,
            None => self.spindle_reversed(),
        };
        Tap {
            pitch: pitch.map(f64::abs),
            rpm: get(10).map(f64::abs).or(self.rpm),
            left_hand,
        }
    }

    /// The spindle's last direction switch is M4 (counter-clockwise).
    pub(super) fn spindle_reversed(&self) -> bool {
        self.switches
            .iter()
            .rev()
            .find(|s| {
                matches!(
                    s.switch,
                    Switch::SpindleClockwise | Switch::SpindleCounterClockwise
                )
            })
            .is_some_and(|s| s.switch == Switch::SpindleCounterClockwise)
    }

    /// Records one hole of a tapping cycle whose moves were made from CL point `from` on
    /// ([`Toolpath::taps`]): the run of feed moves after its first, into the hole and out.
    pub(super) fn tapping(&mut self, line: usize, name: String, from: usize, tap: Tap) {
        let pts = &self.points;
        let fed = |i: usize| matches!(pts[i].feed, Feed::Programmed(_));
        let Some(a) = (from..pts.len()).find(|&i| fed(i)) else {
            return;
        };
        let b = (a..pts.len()).find(|&i| !fed(i)).unwrap_or(pts.len());
        let mm_per_min = |i: usize| match pts[i].feed {
            Feed::Programmed(v) => v * 60.0,
            _ => 0.0,
        };
        let (feed_in, feed_out) = (mm_per_min(a), mm_per_min(b - 1));
        let dwell = self
            .dwells
            .iter()
            .filter(|d| d.point == a)
            .map(|d| d.seconds)
            .sum();
        let axis = self.frame_now().r * Vector3::z();
        self.taps.push(crate::toolpath::TapCycle {
            line,
            name,
            points: a..b,
            feed_in,
            feed_out,
            pitch: tap.pitch,
            rpm: tap.rpm,
            left_hand: tap.left_hand,
            dwell,
            axis,
        });
    }

    /// Cycles are read in the XY plane only.
    fn cycle_plane(&self, line: usize, text: &str) -> Result<()> {
        if self.plane != Plane::Xy {
            return Err(self.error(
                line,
                format!("{text} outside G17: cycles are read in the XY plane only"),
            ));
        }
        Ok(())
    }

    /// A motion block: resolves the target and emits its point(s).
    fn motion_block(&mut self, line: usize, block: &Block, machine: bool) -> Result<()> {
        let Some(motion) = self.motion else {
            return Err(self.error(
                line,
                "axis words without a motion mode: program G0, G1, G2 or G3 first",
            ));
        };
        let is_arc = matches!(motion, Motion::ArcCw | Motion::ArcCcw);
        if machine && is_arc {
            return Err(self.error(line, "G53/SUPA/M91 (machine coordinates) with an arc"));
        }
        // A chamfer or rounding asked for by the last move is made with this one, which must
        // be a straight feed move right after it.
        let corner = self.corner.take();
        if let Some(c) = &corner {
            let between = self.points.len() != c.at + 1 || self.event_counts() != c.counts;
            let what = if is_arc {
                Some("an arc: a chamfer or rounding into an arc is not modelled")
            } else if motion == Motion::Rapid {
                Some(
                    "a rapid (G0): the control makes a chamfer or rounding between feed moves only",
                )
            } else if machine {
                Some("a machine-coordinate move")
            } else if between {
                Some(
                    "a move that does not follow it directly (a dwell, a cycle, a reference \
                     move, a tool or spindle change between): not modelled",
                )
            } else {
                None
            };
            if let Some(what) = what {
                return Err(self.corner_error(&c.clone(), line, what));
            }
        }
        if let Some((text, ..)) = &block.corner
            && (is_arc || motion != Motion::Linear || machine)
        {
            return Err(self.error(
                line,
                format!(
                    "`{text}`: a chamfer or rounding is read after a straight feed move (G1) \
                     only; on an arc, a rapid or a machine-coordinate move it is not modelled: \
                     post the corner as its own move"
                ),
            ));
        }
        let points_before = self.points.len();
        if block.plane_rotary.iter().any(|&q| q) {
            if self.swivel.is_none() {
                return Err(self.error(
                    line,
                    "Q120–Q122 hold the rotary positions the control computes for a PLANE, but \
                     no PLANE is active: program PLANE SPATIAL (or the rotary positions) first",
                ));
            }
            // The tilted plane's tool vector rules: the rotary axes go where it points.
            self.saw_rotary = true;
        }
        // Under `PLANE … SEQ±` the control computed the positions (Q120–Q122): the rotary
        // axes go there, as if the block programmed them (axis positions, degrees).
        let plane_positions = if block.plane_rotary.iter().any(|&q| q) {
            self.klartext.sequence.take()
        } else {
            None
        };
        if plane_positions.is_some() {
            self.klartext.sequence_point = true;
        }
        let plane_positions = plane_positions.unwrap_or([None; 3]);

        let start = self.pos;
        let mut end = start;
        let mut machine_xyz = self.to_machine(Vector3::new(start[0], start[1], start[2]));
        // In machine coordinates, the named axes' (for the writer: [`MachinePoint`]).
        let mut machine_words: [Option<f64>; 6] = [None; 6];
        // Whether the rotary axes stand where an earlier block put them (not at the unknown
        // start).
        let rotary_known = self.saw_rotary;
        for (i, word) in block.axes.iter().enumerate() {
            let from_plane = i >= 3 && plane_positions[i - 3].is_some();
            let word = if from_plane {
                plane_positions[i - 3].map(|value| Num { value, point: true })
            } else {
                *word
            };
            let Some(num) = word else { continue };
            let value = if i < 3 {
                self.length(num)
            } else {
                self.angle(num)
            };
            if !value.is_finite() || value.abs() > MAX_COORDINATE_MM {
                return Err(self.error(
                    line,
                    format!(
                        "{}: {} is beyond ±{MAX_COORDINATE_MM:e} mm (or °): check the number \
                         and the units",
                        AXIS_NAMES[i],
                        crate::error::number(value)
                    ),
                ));
            }
            if machine && i < 3 {
                machine_xyz[i] = value
                    + if self.m92 {
                        self.m92_datum(line, i)
                    } else {
                        0.0
                    };
                machine_words[i] = Some(machine_xyz[i]);
                self.known[i] = true;
                continue;
            }
            if machine {
                machine_words[i] = Some(value);
            }
            let incremental = (self.distance == Distance::Incremental || block.incremental[i])
                && !machine
                && !from_plane
                && !block.absolute[i];
            // A rotary machine coordinate (or a position the control computed for a plane):
            // the program coordinate that the offsets in force take to it (`push` adds their
            // shift; the X Y Z are converted below).
            let value = if machine || from_plane {
                value - self.offsets.shift()[i]
            } else {
                value
            };
            // The way a rotary axis turns to an absolute position, where not by the sign of
            // the difference: the word's own (Sinumerik DC 0, ACP +1, ACN −1), else the
            // shorter way (0) under Klartext M126 or on a modulo axis the machine file sets so
            // (unless the word says AC(): by the sign, as on a modulo axis).
            let modulo = self
                .machine
                .is_some_and(|c| i >= 3 && c.shortest_way[i - 3]);
            let way = block.rotary_way[i].or((i >= 3
                && (self.shortest_path || (modulo && !block.absolute[i])))
                .then_some(0));
            end[i] = if incremental {
                start[i] + value
            } else if let Some(way) = way {
                // To the position modulo 360° the way chosen.
                match way {
                    0 => start[i] + (value - start[i] + 180.0).rem_euclid(360.0) - 180.0,
                    1 => start[i] + (value - start[i]).rem_euclid(360.0),
                    _ => start[i] - (start[i] - value).rem_euclid(360.0),
                }
            } else {
                if i >= 3 && (value - start[i]).abs() > 180.0 && rotary_known && !block.absolute[i]
                {
                    // Read as written; a modulo axis set to take the shorter way would turn
                    // the other way, less than half a turn (a blade mill's A going 359.5° →
                    // 4° in a spiral).
                    self.warn(
                        line,
                        format!(
                            "{0}: a rotary position more than 180° from where {0} stands is \
                             reached by the sign of the difference, the long way round, as a \
                             control moves an axis that is not a modulo axis set to take the \
                             shorter way (Sinumerik MD30455 bit 2, Fanuc parameter 1008 RAB = \
                             0, LinuxCNC WRAPPED_ROTARY; a Heidenhain program says M126); if \
                             this machine's {0} takes the shorter way, set \"shortest_way\": \
                             true for {0} in the machine file",
                            AXIS_NAMES[i]
                        ),
                    );
                }
                value
            };
            if i < 3 && !incremental {
                self.known[i] = true;
            }
            if i >= 3 {
                self.saw_rotary = true;
            }
        }
        if machine {
            let offset = self.machine.map_or([0.0; 3], |c| c.work_offset);
            let what = if self.m92 {
                "M92: a move relative to the machine builder's datum (machine coordinates), \
                 taken as"
            } else {
                "G53/SUPA/M91: machine-coordinate move, taken as"
            };
            let unknown = self.unknown_work_offset();
            self.warn(
                line,
                format!(
                    "{what} program coordinates + the work offset ({}, {}, {}) mm{unknown}",
                    offset[0], offset[1], offset[2]
                ),
            );
            let p = self.machine_to_program(machine_xyz);
            end[..3].copy_from_slice(p.as_slice());
        }
        self.warn_unknown(line);

        // Tool vector: Sinumerik-style words, or I J K on G0/G1 under Fanuc G43.5.
        let vector_words: [Option<f64>; 3] = if self.tcp == Tcp::OnIjkVector && !is_arc {
            std::array::from_fn(|i| block.centre[i].map(|n| n.value))
        } else {
            block.vector
        };
        if vector_words.iter().any(Option::is_some) {
            let v = Vector3::new(
                vector_words[0].unwrap_or(0.0),
                vector_words[1].unwrap_or(0.0),
                vector_words[2].unwrap_or(0.0),
            );
            let Some(unit) = crate::toolpath::unit_tool_vector(v) else {
                return Err(self.error(
                    line,
                    format!("tool vector ({}, {}, {}) has no direction", v.x, v.y, v.z),
                ));
            };
            self.vector = unit;
        } else if !is_arc {
            let stray: Vec<&str> = ["I", "J", "K"]
                .iter()
                .zip(&block.centre)
                .filter(|(_, c)| c.is_some())
                .map(|(n, _)| *n)
                .collect();
            if !stray.is_empty() || block.radius.is_some() {
                let mut words = stray.join(" ");
                if block.radius.is_some() {
                    if !words.is_empty() {
                        words.push(' ');
                    }
                    words.push('R');
                }
                self.warn(line, format!("{words} on a straight move: ignored"));
            }
        }

        let vector = vector_words.iter().any(Option::is_some);
        // Under a tilted working plane (Klartext PLANE, CYCLE800, G68.2) X Y Z are the tip in
        // the plane's coordinates, as the control reads them: a block that moves them with the
        // rotary axes standing where the plane put them is read as the control runs it (a
        // warning there was noise in every hyperMILL 3+2 program).
        let framed = (self.swivel.is_some()
            || self.programmable.r != nalgebra::Matrix3::identity()
            || self.klartext.rotary_unknown.is_some())
            && !block.axes[3..].iter().any(Option::is_some);
        if self.tcp == Tcp::Off
            && !self.non_tcp_warned
            && !framed
            && !self.machine.is_some_and(|m| m.machine_coordinates)
            && !block.plane_rotary.iter().any(|&q| q)
            && (vector || self.axis_kinematics().is_none())
            && (end[3..] != [0.0; 3] || block.axes[3..].iter().any(Option::is_some) || vector)
        {
            self.non_tcp_warned = true;
            let text = if vector {
                "a tool vector outside tool-tip (TCP) mode: X Y Z taken as the tool tip along \
                 it, as under tool-tip mode"
            } else if self.machine.is_some_and(|m| m.kinematics.is_some()) {
                // Under a frame (its X Y Z the tip in the frame's coordinates), or where the
                // rotary positions are not known.
                "motion with rotary axes or a tool vector outside tool-tip (TCP) mode: X Y Z \
                 taken as the tool tip (a four-axis machine's program, in machine \
                 coordinates, needs kinematics xyza, xyzb or xyzc)"
            } else {
                "motion with rotary axes outside tool-tip (TCP) mode, read without the \
                 machine's kinematics: X Y Z taken as the tool tip, as under tool-tip mode (a \
                 control without it moves the axes to X Y Z A B C, which puts the tip \
                 elsewhere once a rotary axis is off zero); give the machine file to read the \
                 block as the control runs it (a four-axis machine's program, in machine \
                 coordinates, needs kinematics xyza, xyzb or xyzc)"
            };
            self.warn(line, text);
        }

        if block.axes[3..].iter().any(Option::is_some) || block.plane_rotary.iter().any(|&q| q) {
            // Klartext PLANE … STAY: the rotary axes are positioned now.
            self.klartext.stay_orientation = None;
        }
        // Whether the rotary axes' start positions are known (not after a Klartext PLANE …
        // TURN that left the solution to the control, which this block may now resolve).
        let start_rotary_known = self.klartext.rotary_unknown.is_none();
        // Rotary words under a Klartext PLANE are programmed positions (checked against the
        // plane's tool axis).
        self.klartext.programmed_rotary = self.plane_rotary_words(line, block, &end)?;
        if is_arc {
            if self.reads_axes(&start, &end) && (3..6).any(|i| start[i] != end[i]) {
                return Err(self.error(
                    line,
                    "an arc that turns a rotary axis outside tool-tip (TCP) mode: the control \
                     moves the axes along it and the tool tip relative to the part follows a \
                     curve feedopt does not model; program the rotary move as its own block, \
                     or the arc under tool-tip mode",
                ));
            }
            self.arc(line, motion, block, start, end)?;
            self.straight_end = None;
        } else {
            let feed = self.linear_feed(line, motion, block, &start, &end)?;
            // A G53 point is a machine position: outside the work offsets' check.
            self.machine_point = machine;
            let along = if self.reads_axes(&start, &end) && !vector && start_rotary_known {
                self.axis_motion_points(line, &start, &end)?
            } else {
                None
            };
            let turn = if along.is_none() && !vector && start_rotary_known {
                self.frame_turn_points(line, &start, &end)?
            } else {
                None
            };
            if let Some(points) = turn {
                // Under a frame, outside tool-tip mode, the rotary axes turn alone: the tip
                // goes with them; the block's time is its F rule's, split evenly.
                let n = points.len() as f64;
                let feed = match feed {
                    Feed::BlockTime(t) => Feed::BlockTime(t / n),
                    other => other,
                };
                self.klartext.sequence_point = false;
                for &(p, o, rotary) in &points {
                    self.check_offsets(line);
                    self.points.push(ClPoint {
                        p,
                        o,
                        feed,
                        rotary: Some(rotary),
                        line,
                    });
                }
                // Where the carried tip now is, in the frame's coordinates.
                if let Some(&(p, _, _)) = points.last() {
                    let q = self.frame_now().invert(&p);
                    end[..3].copy_from_slice(q.as_slice());
                }
            } else if let Some(qs) = along {
                // The axes move linearly; the tip follows the kinematics. The block's time is
                // the control's F rule for the axes' motion, split evenly over the points
                // (uniform in the axes' interpolation parameter).
                let n = qs.len() as f64;
                let feed = match feed {
                    Feed::Programmed(v) => {
                        let d = (0..3)
                            .map(|i| (end[i] - start[i]).powi(2))
                            .sum::<f64>()
                            .sqrt();
                        Feed::BlockTime(d / v / n)
                    }
                    Feed::BlockTime(t) => Feed::BlockTime(t / n),
                    other => other,
                };
                for q in &qs {
                    self.push(line, q, feed);
                }
            } else {
                self.push(line, &end, feed);
            }
            if machine {
                self.machine_points.push(MachinePoint {
                    point: self.points.len() - 1,
                    line,
                    kind: MachineMove::Coordinates(machine_words),
                });
            }
            self.machine_point = false;
            let pushed = self.points.len() - points_before;
            if let Some(c) = corner {
                self.corner_to(line, c, pushed)?;
            }
            if let Some((text, word, num)) = &block.corner {
                self.corner_from(line, text, *word, *num, pushed)?;
            }
            self.straight_end = (motion == Motion::Linear && pushed == 1 && !machine)
                .then(|| (self.points.len(), self.event_counts()));
            let (a, b) = (end[0] - start[0], end[1] - start[1]);
            let len = a.hypot(b);
            self.tangent = (len > XYZ_MOVE_THRESHOLD_MM)
                .then(|| (Plane::Xy, [a / len, b / len], self.points.len()));
        }
        self.klartext.programmed_rotary = false;
        self.pos = end;
        Ok(())
    }

    /// The error of a corner word (`c`, asked for at its line) that the move at `line` cannot
    /// make, and why.
    fn corner_error(&self, c: &PendingCorner, line: usize, why: &str) -> Error {
        self.error(
            c.line,
            format!(
                "`{}`: the chamfer or rounding of the corner after this move cannot be made: the \
                 next move (line {line}) is {why}; post the corner as a move of its own",
                c.text
            ),
        )
    }

    /// Records the corner word of the straight move just made (`pushed`: its points), to be
    /// made by the next move.
    fn corner_from(
        &mut self,
        line: usize,
        text: &str,
        word: CornerWord,
        num: Num,
        pushed: usize,
    ) -> Result<()> {
        let size = self.length(num);
        if size <= 0.0 {
            return Err(self.error(
                line,
                format!("`{text}`: a chamfer or rounding must be larger than 0"),
            ));
        }
        if pushed != 1 {
            return Err(self.error(
                line,
                format!(
                    "`{text}`: a chamfer or rounding is modelled between two straight moves of \
                     X, Y and Z only; this move turns a rotary axis: post the corner as its own \
                     move"
                ),
            ));
        }
        self.corner = Some(PendingCorner {
            line,
            text: text.to_string(),
            word,
            size,
            at: self.points.len() - 1,
            counts: self.event_counts(),
            feed: None,
        });
        Ok(())
    }

    /// The dwells, tool changes and spindle changes so far: a chamfer or rounding is made
    /// only where none comes between its two moves.
    pub(super) fn event_counts(&self) -> [usize; 3] {
        [
            self.dwells.len(),
            self.tool_changes.len(),
            self.spindle_changes.len(),
        ]
    }

    /// Makes the chamfer or rounding `c` between the move that asked for it and the straight
    /// move just made (`pushed`: its points; the last point is its end). The corner point
    /// becomes the point `t` before it on the first move, then the chamfer's end or the
    /// rounding arc's chords (within [`MAX_CHORD_ERROR_MM`]) to the point `t` after it on the
    /// second: t = the chamfer's leg (Fanuc `,C`, Sinumerik `CHR=`), L / (2 cos(θ/2)) for a
    /// chamfer of length L (`CHF=`), R tan(θ/2) for a rounding of radius R (`,R`, `RND=`), θ
    /// the turn between the moves. The inserted points keep the first move's line and feed
    /// (Sinumerik: `FRC=0`, the chamfer or rounding at the F in force; Fanuc and Haas run the
    /// inserted block at the modal F).
    fn corner_to(&mut self, line: usize, c: PendingCorner, pushed: usize) -> Result<()> {
        if pushed != 1 {
            return Err(self.corner_error(
                &c,
                line,
                "a move that turns a rotary axis: a chamfer or rounding is modelled between two \
                 straight moves of X, Y and Z only",
            ));
        }
        let k = c.at;
        if k == 0 {
            return Err(self.corner_error(
                &c,
                line,
                "after a first move from where the program has not placed the tool",
            ));
        }
        let (a, p, b) = (
            self.points[k - 1].clone(),
            self.points[k].clone(),
            self.points[k + 1].clone(),
        );
        if a.o != p.o || p.o != b.o || a.rotary != p.rotary || p.rotary != b.rotary {
            return Err(self.corner_error(
                &c,
                line,
                "a move that changes the tool's orientation: not modelled",
            ));
        }
        let Feed::Programmed(first) = p.feed else {
            return Err(self.corner_error(
                &c,
                line,
                "read under inverse time (G93): a chamfer or rounding is modelled under a feed \
                 per minute or per revolution only",
            ));
        };
        if !matches!(b.feed, Feed::Programmed(_)) {
            return Err(self.corner_error(&c, line, "not a feed move at a programmed feed"));
        }
        let feed = c.feed.unwrap_or(first);
        let (d1, d2) = (p.p - a.p, b.p - p.p);
        let (l1, l2) = (d1.norm(), d2.norm());
        if l1 <= XYZ_MOVE_THRESHOLD_MM || l2 <= XYZ_MOVE_THRESHOLD_MM {
            return Err(self.corner_error(&c, line, "a move of no length: there is no corner"));
        }
        let (u1, u2) = (d1 / l1, d2 / l2);
        let turn = crate::base::angle_between(&u1, &u2);
        if turn < 1e-9 {
            return Err(self.corner_error(
                &c,
                line,
                "in line with it: there is no corner to cut (the control alarms)",
            ));
        }
        if turn > std::f64::consts::PI - 1e-9 {
            return Err(self.corner_error(
                &c,
                line,
                "straight back along it: the corner cannot be cut (the control alarms)",
            ));
        }
        let t = match c.word {
            CornerWord::Round => c.size * (turn / 2.0).tan(),
            CornerWord::ChamferLength => c.size / (2.0 * (turn / 2.0).cos()),
            _ => c.size,
        };
        // Within rounding of the numbers written (a chamfer as long as the move).
        let slack = 1e-9 * (1.0 + l1.max(l2));
        if t > l1 + slack || t > l2 + slack {
            return Err(self.corner_error(
                &c,
                line,
                &format!(
                    "too short for it: it takes {t:.6} mm of each move, and the moves are \
                     {l1:.6} mm and {l2:.6} mm long (the control alarms)"
                ),
            ));
        }
        let at = |q: Vector3<f64>| ClPoint {
            p: q,
            feed: Feed::Programmed(feed),
            line: c.line,
            ..p.clone()
        };
        let s = p.p - u1 * t;
        let mut made = vec![at(s)];
        if c.word == CornerWord::Round {
            let r = c.size;
            // Towards the inside of the turn, square to the first move.
            let inward = (u2 - u1 * u1.dot(&u2)).normalize();
            let centre = s + inward * r;
            let step = if r > MAX_CHORD_ERROR_MM {
                2.0 * (1.0 - MAX_CHORD_ERROR_MM / r).acos()
            } else {
                turn
            };
            let n = (turn / step).ceil().max(1.0) as usize;
            self.check_room(line, "a rounding", n)?;
            for i in 1..=n {
                let phi = turn * i as f64 / n as f64;
                made.push(at(centre + (s - centre) * phi.cos() + u1 * (r * phi.sin())));
            }
        } else {
            made.push(at(p.p + u2 * t));
        }
        self.points.truncate(k);
        self.points.extend(made);
        self.points.push(b);
        Ok(())
    }

    /// Warns once per axis that X, Y or Z is used before the program set it.
    fn warn_unknown(&mut self, line: usize) {
        let unknown: Vec<String> = (0..3)
            .filter(|&i| !self.known[i] && !self.unknown_warned[i])
            .map(|i| AXIS_NAMES[i].to_string())
            .collect();
        if !unknown.is_empty() {
            for i in 0..3 {
                if !self.known[i] {
                    self.unknown_warned[i] = true;
                }
            }
            self.warn(
                line,
                format!(
                    "{} not programmed yet: taken as 0 (the start position is unknown)",
                    unknown.join(", ")
                ),
            );
        }
    }

    /// Checks, before this block makes `more` CL points (an arc's chords, a cycle's moves;
    /// 0: the points made so far), that the program stays within
    /// [`crate::toolpath::MAX_POINTS`].
    pub(super) fn check_room(&self, line: usize, what: &str, more: usize) -> Result<()> {
        crate::toolpath::check_room(self.source, line, what, self.points.len(), more)
    }

    /// Checks that the work offsets in force agree (outside a machine-coordinate point).
    fn check_offsets(&mut self, line: usize) {
        if !self.machine_point {
            let axes = if self.saw_rotary { 0..6 } else { 0..3 };
            if let Err(m) = self.offsets.check(axes)
                && self.offset_error.is_none()
            {
                self.offset_error = Some(self.offset_mismatch(line, m));
            }
        }
    }

    fn push(&mut self, line: usize, q: &[f64; 6], feed: Feed) {
        self.check_offsets(line);
        let frame = self.frame_now();
        // Rotary axes shifted by their work offsets (none unless a G10 or G52 gives one).
        let s = self.offsets.shift();
        let q_rot = [q[3] + s[3], q[4] + s[4], q[5] + s[5]];
        if let Some(pose) = self.axes_pose(q) {
            // Outside tool-tip mode, a rotary axis off zero: the tip the axes give.
            self.klartext.sequence_point = false;
            self.points.push(ClPoint {
                p: pose.p,
                o: pose.k,
                feed,
                rotary: Some(q_rot),
                line,
            });
            return;
        }
        if let Some(o) = self.klartext.stay_orientation {
            // Klartext PLANE … STAY: the rotary axes have not moved yet; the tool keeps the
            // orientation it had (workpiece coordinates).
            let p = frame.apply(&Vector3::new(q[0], q[1], q[2]));
            self.points.push(ClPoint {
                p,
                o,
                feed,
                rotary: None,
                line,
            });
            return;
        }
        let positioned = std::mem::take(&mut self.klartext.sequence_point);
        let (p, o, rotary) = if frame.is_identity() {
            (Vector3::new(q[0], q[1], q[2]), self.vector, Some(q_rot))
        } else {
            let p = frame.apply(&Vector3::new(q[0], q[1], q[2]));
            let o = frame.r * self.vector;
            // Under a swivel frame the control sets the rotary axes: the tool vector rules,
            // but where they were positioned to the solution a `PLANE … SEQ±` asked for, or
            // where a block under a Klartext PLANE programs them (`L A-90 C+270`): the
            // control moves them where the block says.
            let rotary = if self.swivel.is_some() && !positioned && !self.klartext.programmed_rotary
            {
                None
            } else {
                Some(q_rot)
            };
            (p, o, rotary)
        };
        self.points.push(ClPoint {
            p,
            o,
            feed,
            rotary,
            line,
        });
    }

    /// The F of a G93 feed block, seconds for the whole block.
    fn inverse_time(&self, line: usize, block: &Block) -> Result<f64> {
        match block.feed {
            None => Err(self.error(
                line,
                "G93 (inverse time): F is required on every G1/G2/G3 block",
            )),
            Some(f) if f <= 0.0 => Err(self.error(
                line,
                format!("G93 (inverse time): F must be positive, found {f}"),
            )),
            Some(f) => Ok(60.0 / f),
        }
    }

    fn linear_feed(
        &mut self,
        line: usize,
        motion: Motion,
        block: &Block,
        start: &[f64; 6],
        end: &[f64; 6],
    ) -> Result<Feed> {
        if motion == Motion::Rapid {
            return Ok(Feed::Rapid);
        }
        if self.feed_mode == FeedMode::InverseTime {
            return Ok(Feed::BlockTime(self.inverse_time(line, block)?));
        }
        let feed = self.modal_feed(line)?;
        let moves_xyz = (0..3).any(|i| (end[i] - start[i]).abs() > XYZ_MOVE_THRESHOLD_MM);
        let rotary = (3..6)
            .map(|i| (end[i] - start[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let diameters = self.machine.map_or([None; 3], |m| m.feed_diameter);
        if rotary > 0.0 && self.spec.rotary_feed == RotaryFeed::Combined && self.tcp == Tcp::Off {
            // Fanuc: F over the combined distance, linear axes in F's unit (mm or inch),
            // rotary axes in degrees: a degree counts as one unit of length, or as π·D/360 mm
            // where the machine file gives the axis' feed diameter D (Haas settings 34/79).
            let unit = self.feed_units.mm_per_unit();
            // F's units of length per mm (X Y Z) or per degree (A B C).
            let scale = |i: usize| match i {
                0..3 => 1.0 / unit,
                _ => diameters[i - 3].map_or(1.0, |d| std::f64::consts::PI * d / 360.0 / unit),
            };
            let distance = (0..6)
                .map(|i| ((end[i] - start[i]) * scale(i)).powi(2))
                .sum::<f64>()
                .sqrt();
            let undiametered = (3..6).any(|i| end[i] != start[i] && diameters[i - 3].is_none());
            if moves_xyz && undiametered {
                // The time differs from other controls' by the whole rotary share: said, so a
                // user of a control that converts degrees otherwise (Haas) knows.
                self.warn(
                    line,
                    "a block that turns a rotary axis while X, Y or Z move: F is taken over the \
                     combined distance, a degree counting as one unit of length, as a Fanuc \
                     control feeds it (a Haas control turns degrees into length through its \
                     rotary diameter settings 34/79 instead: give them as the axis' \
                     feed_diameter in the machine file)",
                );
            }
            return Ok(Feed::BlockTime(distance / (feed.raw / 60.0)));
        }
        if rotary > 0.0 && diameters.iter().any(Option::is_some) && !self.feed_diameter_warned {
            // Another dialect's rule, or tool-tip mode: the diameters do not enter.
            self.feed_diameter_warned = true;
            self.warn(
                line,
                "the machine file gives a rotary axis a feed_diameter, which only a \
                 Fanuc-family control's G94 feed outside tool-tip mode uses (Haas settings \
                 34/79): F is read here, and after, without it",
            );
        }
        if rotary > 0.0 && moves_xyz && self.tcp == Tcp::Off && self.dialect_defaulted {
            // grbl (which feedopt has no dialect for) and the Fanuc family take F over the
            // combined distance: such a program read in the default dialect runs faster here
            // than on its control, by the rotary share of every such block.
            self.dialect_defaulted = false;
            self.warn(
                line,
                format!(
                    "a block that turns a rotary axis while X, Y or Z move: F is read along X,                      Y and Z, as the {} dialect (the default: nothing named the program's)                      reads it; grbl and Fanuc-family controls take it over the combined                      distance, a degree counting as a unit of length: if the program is for                      one, give --dialect fanuc",
                    self.spec.name
                ),
            );
        }
        Ok(if !moves_xyz && rotary > 0.0 {
            Feed::BlockTime(rotary / (feed.raw / 60.0))
        } else {
            Feed::Programmed(feed.mm_per_min / 60.0)
        })
    }

    /// G2/G3: linearises the arc into chords.
    fn arc(
        &mut self,
        line: usize,
        motion: Motion,
        block: &Block,
        start: [f64; 6],
        end: [f64; 6],
    ) -> Result<()> {
        let arc_plane = block.arc_plane.unwrap_or(self.plane);
        let (a, b, n) = arc_plane.axes();
        let plane = arc_plane.code();
        let centre_names = ['I', 'J', 'K'];
        if block.centre[n].is_some() {
            self.warn(
                line,
                format!(
                    "{} is not a centre word of a {plane} arc: ignored",
                    centre_names[n]
                ),
            );
        }
        let mut ccw = motion == Motion::ArcCcw;
        let (s0, s1) = (start[a], start[b]);
        let (e0, e1) = (end[a], end[b]);
        let chord = (e0 - s0).hypot(e1 - s1);
        let in_plane = block.centre[a].is_some() || block.centre[b].is_some();

        let (c0, c1) = if let Some(ArcCentre::At(c)) = block.arc_centre {
            (c[0], c[1])
        } else if let Some(ArcCentre::Tangent(t)) = block.arc_centre {
            // Klartext CT: the circle through start and end tangent to t at the start; its
            // centre lies on the start's normal n at s = |d|² / (2 n·d), d = end − start.
            let (d0, d1) = (e0 - s0, e1 - s1);
            let (n0, n1) = (-t[1], t[0]);
            let nd = n0 * d0 + n1 * d1;
            if chord < FULL_CIRCLE_MM || nd.abs() <= 1e-9 * chord.max(1.0) {
                return Err(self.error(
                    line,
                    "CT: the end point lies on the tangent of the contour before it, so the \
                     tangential arc is a straight line: program L",
                ));
            }
            let s = (d0 * d0 + d1 * d1) / (2.0 * nd);
            ccw = s > 0.0;
            (s0 + s * n0, s1 + s * n1)
        } else if let Some(r) = block.radius {
            if in_plane {
                return Err(self.error(line, "an arc with both R and I/J/K"));
            }
            let r = self.length(r);
            if chord < FULL_CIRCLE_MM {
                return Err(self.error(
                    line,
                    "an R arc needs an end point different from its start (use I/J/K for a \
                     full circle)",
                ));
            }
            if r == 0.0 {
                return Err(self.error(line, "arc radius R is 0"));
            }
            let half = chord / 2.0;
            if half > r.abs() + R_ARC_TOLERANCE_MM {
                return Err(self.error(
                    line,
                    format!(
                        "arc radius {:.4} mm is smaller than half the distance to the end point \
                         ({half:.4} mm)",
                        r.abs()
                    ),
                ));
            }
            let h = (r * r - half * half).max(0.0).sqrt();
            let (m0, m1) = ((s0 + e0) / 2.0, (s1 + e1) / 2.0);
            // Left of the chord direction: counter-clockwise short arcs, clockwise long ones.
            let (l0, l1) = (-(e1 - s1) / chord, (e0 - s0) / chord);
            let side = if ccw == (r > 0.0) { 1.0 } else { -1.0 };
            (m0 + side * h * l0, m1 + side * h * l1)
        } else {
            if !in_plane {
                return Err(self.error(
                    line,
                    format!(
                        "{} arc needs its centre ({}, {}) or a radius R",
                        plane, centre_names[a], centre_names[b]
                    ),
                ));
            }
            let word = |i: usize| block.centre[i].map_or(0.0, |num| self.length(num));
            let modal = self.arc_distance == Distance::Absolute;
            let coordinate = |i: usize, start: f64| {
                if block.centre_as[i].unwrap_or(modal) {
                    word(i)
                } else {
                    start + word(i)
                }
            };
            (coordinate(a, s0), coordinate(b, s1))
        };

        let r_start = (s0 - c0).hypot(s1 - c1);
        let r_end = (e0 - c0).hypot(e1 - c1);
        let off_circle = |r_start: f64, r_end: f64| {
            let mismatch = (r_end - r_start).abs();
            mismatch > ARC_RADIUS_MISMATCH_MM
                && mismatch > ARC_RADIUS_MISMATCH_RELATIVE * r_start.max(r_end)
        };
        if off_circle(r_start, r_end) {
            // What the program most likely meant, where the block shows it: a centre word
            // of another plane (a lathe's `G02 X… Z… I… K…` read in G17), or I J K measured
            // from the end point (NX sample posts), which no control reads so.
            let mut hint = String::new();
            if block.centre[n].is_some() {
                hint = format!(
                    "; the block gives {}, which a {plane} arc does not use: an arc in another \
                     plane needs its G17/G18/G19 first (a turning program's X–Z arcs are G18, \
                     and feedopt reads milling programs)",
                    centre_names[n]
                );
            } else if in_plane
                && block.arc_centre.is_none()
                && block.radius.is_none()
                && !block.centre_as[a].unwrap_or(self.arc_distance == Distance::Absolute)
                && !block.centre_as[b].unwrap_or(self.arc_distance == Distance::Absolute)
            {
                let word = |i: usize| block.centre[i].map_or(0.0, |num| self.length(num));
                let fits = |f0: f64, f1: f64| {
                    !off_circle((s0 - f0).hypot(s1 - f1), (e0 - f0).hypot(e1 - f1))
                };
                // The centre with one or both signs reversed (a post that writes I J
                // unsigned, or with the wrong sign: the NX sample posts' lead-out arcs, whose
                // Klartext twin puts CC there), or measured from the end point.
                let mm = |x: f64| crate::base::trimmed(x, 4);
                let mut readings = Vec::new();
                for (k0, k1) in [(1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                    let (w0, w1) = (k0 * word(a), k1 * word(b));
                    // A zero word's sign changes nothing: each centre once.
                    let same = |(v0, v1): (f64, f64)| v0 == w0 && v1 == w1;
                    let tried = [(1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
                        .iter()
                        .take_while(|k| **k != (k0, k1))
                        .any(|(j0, j1)| same((j0 * word(a), j1 * word(b))));
                    if !tried && !same((word(a), word(b))) && fits(s0 + w0, s1 + w1) {
                        readings.push(format!(
                            "{}{} {}{} mm (the sign reversed), centre ({}, {}) mm",
                            centre_names[a],
                            mm(w0),
                            centre_names[b],
                            mm(w1),
                            mm(s0 + w0),
                            mm(s1 + w1)
                        ));
                    }
                }
                let (f0, f1) = (e0 + word(a), e1 + word(b));
                if fits(f0, f1) {
                    readings.push(format!(
                        "{} {} measured from the end point, centre ({}, {}) mm",
                        centre_names[a],
                        centre_names[b],
                        mm(f0),
                        mm(f1)
                    ));
                }
                // I J K as the centre's coordinates: a post for a control set to read arc
                // centres absolute (LinuxCNC's G90.1, Mach3's and UCCNC's absolute IJ mode)
                // that does not say so in the program. Every arc of such a program fails
                // the same way, so this reading comes first.
                let absolute = fits(word(a), word(b));
                if absolute {
                    let dialect = if self.spec.name == "LinuxCNC" {
                        String::new()
                    } else {
                        " and read it with --dialect linuxcnc".to_string()
                    };
                    hint = format!(
                        "; {} {} read as the centre's coordinates would fit, centre ({}, {}) \
                         mm: the post writes absolute arc centres, as a control set so reads \
                         them (LinuxCNC after G90.1; Mach3's and UCCNC's absolute IJ mode), \
                         but the program does not say so: if this control reads them so, \
                         write G90.1 ahead of its first arc{dialect}",
                        centre_names[a],
                        centre_names[b],
                        mm(word(a)),
                        mm(word(b))
                    );
                }
                if !readings.is_empty() {
                    hint.push_str(&format!(
                        "; {} would fit: {}. {} {} are the centre's offset from the start \
                         point, with its sign: the post wrote them wrong; post the program \
                         again (the arc ends where the next move starts, so each reading \
                         gives another path)",
                        if absolute {
                            "read as an offset, these"
                        } else {
                            "these"
                        },
                        readings.join("; or "),
                        centre_names[a],
                        centre_names[b]
                    ));
                }
            }
            // Numbers without a decimal point read as least input increments by default
            // (`Z-3` as -0.003 mm): a program written for a control that reads them as whole
            // millimetres (Fusion's hobby posts, read in the Fanuc dialect) fails here first.
            if let Some((at, text, read, _)) = &self.increments_first {
                hint.push_str(&format!(
                    "; numbers without a decimal point are read as least input increments \
                     (line {at}: `{text}` as {read}, parameter 3401#0 DPI = 0): if the control \
                     reads them as written, pass --decimal-point-input calculator"
                ));
                if self.dialect_unnamed {
                    hint.push_str(&format!(
                        " (nothing in the program names its dialect: it is read as the \
                         written program's, {}; --input-dialect linuxcnc reads it as `feedopt \
                         solve` does)",
                        self.spec.name
                    ));
                }
            }
            return Err(self.error(
                line,
                format!(
                    "arc end point is not on the circle: radius {r_end:.4} mm at the end, \
                     {r_start:.4} mm at the start{hint}"
                ),
            ));
        }
        if r_start == 0.0 || r_end == 0.0 {
            return Err(self.error(line, "arc centre coincides with its start or end point"));
        }

        let theta_s = (s1 - c1).atan2(s0 - c0);
        let theta_e = (e1 - c1).atan2(e0 - c0);
        let tau = std::f64::consts::TAU;
        let mut sweep = if let Some(sweep) = block.arc_sweep {
            // Klartext CP: the signed sweep as programmed (turns included).
            sweep.abs()
        } else if chord < FULL_CIRCLE_MM {
            tau
        } else if ccw {
            (theta_e - theta_s).rem_euclid(tau)
        } else {
            (theta_s - theta_e).rem_euclid(tau)
        };
        let extra = match (block.turns, block.extra_turns) {
            (Some(p), _) => {
                if p < 1.0 || p.fract() != 0.0 {
                    return Err(self.error(
                        line,
                        format!("arc turns P must be a whole number ≥ 1, found {p}"),
                    ));
                }
                p - 1.0
            }
            (None, Some(t)) => {
                if t < 0.0 || t.fract() != 0.0 {
                    return Err(
                        self.error(line, format!("TURN must be a whole number ≥ 0, found {t}"))
                    );
                }
                t
            }
            (None, None) => 0.0,
        };
        sweep += extra * tau;
        if !ccw {
            sweep = -sweep;
        }

        let r_max = r_start.max(r_end);
        let chords = crate::toolpath::arc_chords(sweep, r_max).map_err(|e| self.error(line, e))?;
        self.check_room(line, "the arc", chords)?;
        let phi_end = theta_s + sweep;
        let turn = sweep.signum();
        let tangent = [-phi_end.sin() * turn, phi_end.cos() * turn];
        let mut qs = Vec::with_capacity(chords);
        for k in 1..=chords {
            if k == chords {
                qs.push(end);
                break;
            }
            let t = k as f64 / chords as f64;
            let phi = theta_s + t * sweep;
            let r = r_start + t * (r_end - r_start);
            let mut q = [0.0; 6];
            for i in 0..6 {
                q[i] = start[i] + t * (end[i] - start[i]);
            }
            q[a] = c0 + r * phi.cos();
            q[b] = c1 + r * phi.sin();
            qs.push(q);
        }

        match self.feed_mode {
            FeedMode::InverseTime => {
                let total = self.inverse_time(line, block)?;
                let mut lengths = Vec::with_capacity(qs.len());
                let mut prev = start;
                for q in &qs {
                    lengths.push(
                        ((q[0] - prev[0]).powi(2)
                            + (q[1] - prev[1]).powi(2)
                            + (q[2] - prev[2]).powi(2))
                        .sqrt(),
                    );
                    prev = *q;
                }
                let sum: f64 = lengths.iter().sum();
                for (q, len) in qs.iter().zip(&lengths) {
                    let share = if sum > 0.0 {
                        len / sum
                    } else {
                        1.0 / qs.len() as f64
                    };
                    self.push(line, q, Feed::BlockTime(total * share));
                }
            }
            FeedMode::PerMinute | FeedMode::PerRevolution => {
                let feed = Feed::Programmed(self.modal_feed(line)?.mm_per_min / 60.0);
                for q in &qs {
                    self.push(line, q, feed);
                }
            }
        }
        self.tangent = Some((arc_plane, tangent, self.points.len()));
        Ok(())
    }
}

/// The dialect's keyword closest to `word` (an edit or two away: a post's typo), if any.
fn nearest_keyword(spec: &DialectSpec, word: &str) -> Option<&'static str> {
    fn distance(a: &str, b: &str) -> usize {
        let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
        let mut row: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.iter().enumerate() {
            let mut prev = row[0];
            row[0] = i + 1;
            for (j, cb) in b.iter().enumerate() {
                let here = row[j + 1];
                row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(here + 1);
                prev = here;
            }
        }
        row[b.len()]
    }
    let upper = word.to_ascii_uppercase();
    spec.keywords
        .iter()
        .map(|&(k, _)| (distance(&upper, k), k))
        .filter(|&(d, k)| d <= 2 && d < k.len() / 2)
        .min()
        .map(|(_, k)| k)
}

/// The warning for a program's contour tolerance (`G64 P0.02`, `CYCL DEF 32.1 T0.075`, of
/// `mm` mm): corners stay exact stops unless the user blends them.
pub(super) fn contour_tolerance_note(text: &str, mm: f64) -> String {
    format!(
        "{text}: the program lets the control cut corners by {} mm; --corner-tolerance {} \
         does so, without it feedopt stops at every corner sharper than --corner-angle",
        crate::error::number(mm),
        crate::error::number(mm)
    )
}
