//! Dialects as data: the tables the one interpreter reads.

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::toolpath::{Switch, Units};

// ---------------------------------------------------------------------------------------------
// Dialects as data
// ---------------------------------------------------------------------------------------------

/// The built-in dialects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Dialect {
    /// LinuxCNC rs274ngc, with the trt sims' `M428`/`M429` switchkins remaps.
    #[default]
    LinuxCnc,
    /// Fanuc (Series 30i style, M series), 5-axis as far as `G43.4`/`G43.5` need.
    Fanuc,
    /// Siemens Sinumerik 840D, 5-axis as far as `TRAORI` and tool vectors need.
    Sinumerik,
    /// Heidenhain TNC 640 Klartext (conversational, `.h`): not G-code, but read by the same
    /// interpreter through [`HEIDENHAIN`] and the Klartext lexer (see [`super::klartext`]).
    Heidenhain,
}

impl Dialect {
    /// All built-in dialects.
    pub const ALL: [Dialect; 4] = [
        Dialect::LinuxCnc,
        Dialect::Fanuc,
        Dialect::Sinumerik,
        Dialect::Heidenhain,
    ];

    /// The G-code dialects (those the G-code writer writes; Klartext is not G-code).
    pub const GCODE: [Dialect; 3] = [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik];

    /// The dialect's table.
    pub fn spec(self) -> &'static DialectSpec {
        match self {
            Dialect::LinuxCnc => &LINUXCNC,
            Dialect::Fanuc => &FANUC,
            Dialect::Sinumerik => &SINUMERIK,
            Dialect::Heidenhain => &HEIDENHAIN,
        }
    }

    /// The name used on the command line (`linuxcnc`, `fanuc`, `sinumerik`, `heidenhain`).
    pub fn name(self) -> &'static str {
        match self {
            Dialect::LinuxCnc => "linuxcnc",
            Dialect::Fanuc => "fanuc",
            Dialect::Sinumerik => "sinumerik",
            Dialect::Heidenhain => "heidenhain",
        }
    }
}

impl fmt::Display for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Dialect {
    type Err = Error;

    /// `linuxcnc`, `fanuc`, `sinumerik` or `heidenhain` (case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        let wanted = s.trim().to_ascii_lowercase();
        Dialect::ALL
            .into_iter()
            .find(|d| d.name() == wanted)
            .ok_or_else(|| {
                Error::Usage(format!(
                    "unknown G-code dialect `{s}` (expected linuxcnc, fanuc, sinumerik or \
                     heidenhain)"
                ))
            })
    }
}

/// What `;` means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Semicolon {
    /// A comment to the end of the line.
    Comment,
    /// The end of a block (ISO EOB): the rest of the line is another block.
    EndOfBlock,
}

/// How whitespace outside comments is treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spaces {
    /// Removed before reading (`G1  X  16.339` is `G1X16.339`); words are single letters.
    Ignored,
    /// Separates words, which may then be keywords (`TRAORI`) or `NAME=value`.
    Separate,
    /// Heidenhain Klartext: a block number, then a statement whose first word(s) say what it
    /// is (`L`, `CC`, `CYCL DEF`, …); words `NAME±value` (`X+10`, `IX-5`, `DR+`) separated by
    /// spaces (see [`super::klartext`]).
    Klartext,
}

/// What F means on a G94 (or G95) feed block that turns a rotary axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RotaryFeed {
    /// LinuxCNC (NIST RS274): F is the speed along X Y Z when any of them moves; the rotary
    /// axes follow. Only when X Y Z stay is F degrees per minute over the A B C distance.
    Xyz,
    /// Fanuc: F is the speed along the combined distance √(ΔX²+ΔY²+ΔZ²+ΔA²+ΔB²+ΔC²), linear
    /// axes in the program's unit and rotary axes in degrees (a degree counts as a mm, or an
    /// inch under G20). `G91 G1 X20 C40 F300` takes √(20²+40²)/300 = 0.149 min (Fanuc
    /// operator's manuals, "Linear interpolation (G01)"). Not in tool-tip mode (G43.4/G43.5),
    /// where F is the tool tip's speed. A rotary axis with a `feed_diameter` D in the machine
    /// file (Haas settings 34/79) counts a degree as π·D/360 mm instead.
    Combined,
}

/// What a letter or named word addresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Address {
    /// Axis 0–5: X Y Z (length) A B C (degrees).
    Axis(usize),
    /// Arc centre 0–2 (I J K); under [`Tcp::OnIjkVector`] on G0/G1 blocks, the tool vector.
    ArcCentre(usize),
    /// Arc centre 0–2 written `I=AC(…)` (`true`: absolute, in program coordinates) or
    /// `I=IC(…)` (`false`: from the arc's start), whatever the modal arc-centre mode
    /// (Sinumerik). Made by the lexer, in no dialect's table.
    ArcCentreAs(usize, bool),
    /// Tool-vector component 0–2 (Sinumerik `A3= B3= C3=`).
    ToolVector(usize),
    /// Arc radius (`R`, Sinumerik `CR=`).
    Radius,
    /// Number of turns of an arc, 1 = the plain arc (LinuxCNC `P` on G2/G3; ignored elsewhere).
    ArcTurns,
    /// Extra full turns of an arc (Sinumerik `TURN=`).
    ArcExtraTurns,
    /// Feed `F`.
    Feed,
    /// A G code, looked up in [`DialectSpec::g_codes`].
    G,
    /// An M code, looked up in [`DialectSpec::m_codes`].
    M,
    /// Accepted, no effect on motion (N, S, T, H, D, parameters of other codes).
    Ignored,
    /// Rejected with this error (LinuxCNC O-words other than subroutines).
    Unsupported(&'static str),
    /// A subprogram call by number, the word as written naming it (Sinumerik `L123`; `P`
    /// in the same block is the repeat count).
    Call,
    /// Klartext: an incremental axis word 0–5 (`IX+5`: this word only, never modal); Sinumerik
    /// `X=IC(5)`. Made by the lexer for Sinumerik, in Klartext's table.
    IncrementalAxis(usize),
    /// Sinumerik `X=AC(5)`: axis word 0–5 absolute whatever G90/G91 (this word only). Made by
    /// the lexer, in no dialect's table.
    AbsoluteAxis(usize),
    /// Sinumerik rotary axis 3–5 to an absolute position by a way of its own, this word
    /// only: `C=DC(v)` the shorter way (0), `C=ACP(v)` turning positive (+1), `C=ACN(v)`
    /// negative (−1). Made by the lexer, in no dialect's table.
    RotaryTo(usize, i8),
    /// Klartext: the direction of a circular path, `DR+` (counter-clockwise, value +1) or
    /// `DR-` (clockwise, −1).
    ArcDirection,
    /// A corner between this straight move and the next cut off as a chamfer or rounded:
    /// Fanuc `,C` / `,R` (made by the lexer where [`DialectSpec::comma_corners`]), Sinumerik
    /// `RND=`, `CHF=`, `CHR=` (and `RNDM=`, `FRC=`, `FRCM=`, read to refuse them).
    Corner(CornerWord),
    /// Klartext: a polar angle about the pole `CC`, degrees; `true`: incremental (`IPA`).
    PolarAngle(bool),
    /// Klartext: a polar radius from the pole `CC`, mm; `true`: incremental (`IPR`).
    PolarRadius(bool),
    /// Klartext `M140 MB`: the retract distance along the tool axis, mm (`MB MAX` is the
    /// keyword [`Action::RetractMax`]).
    Retract,
    /// Klartext `A+Q120`, `B+Q121`, `C+Q122` (0–2 = A B C): the rotary axis positioned to the
    /// solution the control computes for the active `PLANE` (Q120–Q122 are its output).
    PlaneRotary(usize),
}

/// Motion modes (modal group 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
}

/// What a corner word asks for ([`Address::Corner`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CornerWord {
    /// A rounding arc of this radius, tangent to both moves (Fanuc `,R`, Sinumerik `RND=`).
    Round,
    /// Sinumerik `RNDM=`: rounding of every following corner (modal).
    RoundModal,
    /// A chamfer from this far before the corner to this far after it along the moves
    /// (Fanuc `,C`, Sinumerik `CHR=`).
    ChamferLeg,
    /// A chamfer of this length (Sinumerik `CHF=`).
    ChamferLength,
    /// Sinumerik `FRC=` / `FRCM=`: the feed of a chamfer or rounding.
    Feed,
}

/// Arc planes: XY (G17), ZX (G18), YZ (G19).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plane {
    Xy,
    Zx,
    Yz,
}

impl Plane {
    /// (first, second, normal) axis indices, a right-handed triple.
    pub(super) fn axes(self) -> (usize, usize, usize) {
        match self {
            Plane::Xy => (0, 1, 2),
            Plane::Zx => (2, 0, 1),
            Plane::Yz => (1, 2, 0),
        }
    }

    pub(super) fn code(self) -> &'static str {
        match self {
            Plane::Xy => "G17",
            Plane::Zx => "G18",
            Plane::Yz => "G19",
        }
    }
}

/// Absolute or incremental values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Distance {
    Absolute,
    Incremental,
}

/// Feed modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeedMode {
    /// G93: F is 1 / block time in minutes.
    InverseTime,
    /// G94: F is length units (or degrees) per minute.
    PerMinute,
    /// G95: F is length units (or degrees) per spindle revolution; the feed at a move is F × S
    /// (S the spindle speed programmed before it, rpm).
    PerRevolution,
}

/// Tool-tip (TCP) mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tcp {
    /// X Y Z are not the tool tip (identity or other kinematics).
    Off,
    /// X Y Z are the tool tip; orientation by rotary words or tool-vector words.
    On,
    /// As `On`, and I J K on G0/G1 blocks are the tool vector (Fanuc G43.5).
    OnIjkVector,
}

/// What a G code, M code or keyword does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    Motion(Motion),
    /// Cutter radius compensation on (G41, G42; Klartext RL, RR): an error unless the
    /// program's path is the tool centre's ([`crate::toolpath::MachineContext::wear_compensation`]).
    CutterCompensation,
    /// Spindle or coolant switches (M3, M8; Klartext M13 is both), recorded for the writer
    /// ([`crate::toolpath::MachineSwitch`]); they do not move the tool.
    Switch(&'static [Switch]),
    /// Cancels the motion mode (LinuxCNC G80): axis words need a new G0–G3.
    MotionCancel,
    Plane(Plane),
    /// Length units; `feed: true` when F is scaled too (all but Sinumerik G70/G71).
    Units {
        units: Units,
        feed: bool,
    },
    Distance(Distance),
    /// I J K absolute (LinuxCNC G90.1) or incremental (G91.1).
    ArcDistance(Distance),
    FeedMode(FeedMode),
    /// Constant surface speed (`G96`: `on`, S is a cutting speed, not rpm) or not (`G97`: S is
    /// rpm); `feed`: the code also sets the feed mode (Sinumerik, whose G96/G97 are in G94 and
    /// G95's group: both feed per revolution).
    SurfaceSpeed {
        on: bool,
        feed: Option<FeedMode>,
    },
    Tcp(Tcp),
    /// G53: this block's axis words are machine coordinates.
    MachineCoordinates,
    /// Heidenhain M92: this block's X Y Z are relative to the machine builder's M92 datum
    /// (machine coordinates from the machine file's `axes.<X|Y|Z>.m92`).
    BuilderDatum,
    /// The block's axis words belong to this code, not to a move (dwell `G4`); the warning
    /// text says what is not modelled.
    NoMotion(&'static str),
    /// Stop reading (M2, M30).
    ProgramEnd,
    /// The end of a subprogram (Fanuc `M99`, Sinumerik `M17`, `RET`): back to the caller; in
    /// the main program, stop reading.
    Return,
    /// Fanuc/Haas `M98`: call program `O<P>` of this file `L` times (see
    /// [`super::subprograms`]).
    Call,
    /// `M6`: the tool the last `T` word selected goes into the spindle.
    ToolChange,
    /// LinuxCNC `M61 Q<n>`: tool n is taken as in the spindle, without a change.
    SetTool,
    /// A Fanuc/LinuxCNC canned cycle (73, 74, 76, 81–89): modal until `G80` or a motion code.
    Cycle(u32),
    /// `G80` (Fanuc): cancels the canned cycle; the motion mode stays.
    CycleCancel,
    /// `G98` (false: return to the initial level) / `G99` (true: to R).
    CycleReturn(bool),
    /// `G28` (1) / `G30` (2): via an intermediate point to a reference point.
    Reference(u8),
    /// LinuxCNC `G33.1 Z- K- I-`: rigid tapping, into the hole at K per spindle revolution and
    /// back to the start at I times the speed.
    RigidTap,
    /// `G4`: dwell.
    Dwell,
    /// Sinumerik programmable frame instructions.
    Frame(FrameOp),
    /// Sinumerik `CYCLE800(...)` (swivel plane; `CYCLE800()` cancels).
    Swivel,
    /// Fanuc `G68.2` tilted working plane.
    TiltedPlane,
    /// Fanuc `G69`: cancels `G68.2`.
    TiltedPlaneCancel,
    /// Sinumerik `MCALL`: the cycle in the same block is called after every positioning
    /// block; bare `MCALL` cancels.
    ModalCall,
    /// Sinumerik `CYCLE81`–`CYCLE89` (and the spigot cycles 76/77, an error).
    SinumerikCycle(u32),
    /// Klartext path functions other than the straight lines `L`/`LN`
    /// ([`Motion::Linear`]).
    Path(PathKind),
    /// Klartext statements: the keyword (one or more words) takes the rest of the block as
    /// its arguments.
    Statement(Statement),
    /// Klartext `FMAX`: this block is a rapid (F stays as programmed for the next block).
    RapidBlock,
    /// Klartext `FAUTO`: the feed the `TOOL CALL` gave.
    ToolCallFeed,
    /// Klartext `M99` (`true`: call the defined cycle at the end of this block) and `M89`
    /// (`false`: after every positioning block until `M99` or `CYCL DEF`).
    CycleCallAt(bool),
    /// Klartext `M126` (true) / `M127` (false): rotary axes take the shorter way to an
    /// absolute position.
    RotaryShortestPath(bool),
    /// Klartext `M140`: retract along the tool axis by the block's `MB` (see
    /// [`Address::Retract`], [`Action::RetractMax`]).
    RetractToolAxis,
    /// Klartext `MB MAX`: retract to the travel limit.
    RetractMax,
    /// A work offset (`G54`–`G59`, Fanuc `G54.1 P…`, Sinumerik `G500` (none: the base frame)
    /// and `G505`–`G599`): the program's
    /// coordinates are read in the frame it selects (see [`super::offsets`]: a change to one
    /// whose values the program does not give is a warning, the move between them sized as if
    /// the two were equal).
    WorkOffset,
    /// `G10`: with `L2` (and `L20`) sets a work offset's values (see [`super::offsets`]); the
    /// P numbers name the offsets as the dialect does. Other `L` values set tool data or
    /// parameters the toolpath does not use (a warning).
    SetOffset(OffsetNumbering),
    /// `G52`: the local shift of every work offset, by the block's axis words.
    LocalOffset,
    /// LinuxCNC `G92.1`, `G92.2`: the `G52`/`G92` shift is cancelled; `G92.1` also clears the
    /// parameters it is kept in (5211–5219), `G92.2` keeps them for a `G92.3`.
    LocalOffsetCancel {
        /// `G92.1`: the parameters are set to 0.
        clear: bool,
    },
    /// LinuxCNC `G92.3`: the shift is restored from parameters 5211–5219: those a `G92`,
    /// `G52` or `G92.1` of the program left there (an error where the program has set none:
    /// their values are the control's).
    LocalOffsetRestore,
    /// `G92 X… Y…`: the current position is given these coordinates, by a shift of every
    /// work offset (LinuxCNC keeps it in `G52`'s register; Fanuc apart from it).
    PositionOffset(OffsetNumbering),
    /// LinuxCNC `G64 P…`: path blending within the tolerance P. Corners stay exact stops
    /// unless `--corner-tolerance` is given (a warning saying so, with P).
    ContourTolerance,
    /// Sinumerik `G92 S…`: the spindle speed limit under G96; moves nothing, and its S is no
    /// spindle speed. Axis words with it are an error.
    SpindleLimit,
    /// Sinumerik `FGROUP(…)`: the axes the path feed F applies to. Siemens' programming
    /// manual (Fundamentals, "Feedrate for positioning axes … FGROUP"): `FGROUP()` without
    /// axes restores the default of the machine data, F along the geometry axes X Y Z, which
    /// is how feedopt reads every Sinumerik F; so do `FGROUP(X,Y,Z)` in any order. A group with
    /// other axes makes F the speed along their combined path: an error naming the word.
    FeedGroup,
    /// Accepted, no effect on motion.
    Ignored,
    /// Accepted with this warning.
    Note(&'static str),
    /// Rejected with this error.
    Unsupported(&'static str),
}

/// What `G10 L2 P…` and `G10 L20 P…` set, by dialect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OffsetNumbering {
    /// LinuxCNC: `L2` sets P1–P9 = `G54`–`G59.3` (P0 the one in force) to machine
    /// coordinates, whatever G90/G91; `L20` sets them so that the current position has the
    /// given coordinates.
    LinuxCnc,
    /// Fanuc: `L2` sets P1–P6 = `G54`–`G59` (P0 the external offset, added to all) and `L20`
    /// the extended offsets `G54.1 P1`… to machine coordinates, or under G91 moves them by
    /// the values.
    Fanuc,
}

/// Klartext path functions (see [`super::klartext`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathKind {
    /// `CC X Y`: the circle centre (and pole); no motion.
    Centre,
    /// `C X Y DR±`: an arc about `CC` to the end point.
    PoleArc,
    /// `CR X Y R± DR±`: an arc of radius R to the end point.
    RadiusArc,
    /// `CT X Y`: an arc tangent to the contour before it.
    TangentArc,
    /// `CP PA/IPA DR±`: an arc about `CC` to a polar angle.
    PolarArc,
    /// `LP PR PA`: a line to polar coordinates about `CC`.
    PolarLine,
}

/// Klartext statements: their arguments are read by the interpreter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Statement {
    /// `BEGIN PGM name MM`.
    ProgramBegin,
    /// `TOOL CALL n Z S… F…`.
    ToolCall,
    /// `CYCL DEF n …`.
    CycleDef,
    /// `CYCL CALL`, `CYCL CALL PAT`, `CYCL CALL POS X Y Z`.
    CycleCall,
    /// `PATTERN DEF POS1 (X Y Z) …`.
    PatternDef,
    /// `PLANE SPATIAL|EULER|VECTOR|RELATIV|RESET …`.
    Plane,
    /// `FUNCTION TCPM …`.
    Tcpm,
    /// `FN k: …` (Q-parameter arithmetic; `FN 9`–`FN 12` jumps are the runner's).
    Fn,
    /// `RND R…` / `CHF …` between two straight lines (`true`: chamfer).
    Corner(bool),
}

/// Sinumerik programmable frame instructions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameOp {
    Trans,
    ATrans,
    Rot,
    ARot,
}

/// How a dialect's files hold subprograms (see [`super::subprograms`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Subprograms {
    /// LinuxCNC: `o100 sub` … `o100 endsub` anywhere in the file, called by `o100 call`.
    OWordSub,
    /// Fanuc/Haas: programs `O2000` … `M99` after the main program, called by `M98 P2000`.
    OPrograms,
    /// Sinumerik: `PROC NAME` (or a `%_N_NAME_SPF` header) … `RET`/`M17` after the main
    /// program, called by name (`NAME`, `L123`).
    Procs,
    /// Heidenhain: labels `LBL n` / `LBL "NAME"` in the one program; `CALL LBL n` runs from
    /// the label to `LBL 0` and returns, `CALL LBL n REP m` repeats the section between the
    /// label and the call m more times; `FN 9`–`FN 12` jump to a label.
    Labels,
}

/// Numbers without a decimal point count least input increments (Fanuc's default).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegerIncrements {
    /// Length increment under metric units, mm.
    pub mm: f64,
    /// Length increment under inch units, inch.
    pub inch: f64,
    /// Rotary increment, degrees.
    pub deg: f64,
}

/// A dialect, as data the interpreter reads. Code tables map a code (as written after `G`/`M`,
/// without leading zeros: `"1"`, `"43.4"`) or an inclusive range of whole codes (`"81..89"`)
/// to an [`Action`]; codes and words missing from the tables are warnings.
#[derive(Debug, Clone, Copy)]
pub struct DialectSpec {
    /// Name used in messages.
    pub name: &'static str,
    /// `( … )` are comments.
    pub paren_comments: bool,
    pub semicolon: Semicolon,
    pub spaces: Spaces,
    /// Single-letter words.
    pub letters: &'static [(char, Address)],
    /// `NAME=value` words with a name longer than one letter (Sinumerik).
    pub named: &'static [(&'static str, Address)],
    pub g_codes: &'static [(&'static str, Action)],
    pub m_codes: &'static [(&'static str, Action)],
    /// Bare keywords (Sinumerik `TRAORI`), possibly followed by `( … )` arguments.
    pub keywords: &'static [(&'static str, Action)],
    /// Motion mode at program start (`None`: axis words need a G0–G3 first).
    pub initial_motion: Option<Motion>,
    /// Every `G94` sets F to 0 (LinuxCNC); otherwise only leaving G93 forgets F.
    pub g94_clears_feed: bool,
    /// `G28`/`G30` without axis words send every axis straight to its reference position
    /// (LinuxCNC); otherwise such a block is an error (Fanuc: the axis words say which axes
    /// return).
    pub bare_reference_moves_all: bool,
    pub integer_increments: Option<IntegerIncrements>,
    /// How subprograms are written.
    pub subprograms: Subprograms,
    /// A program that selects no unit is read in the unit a control setting gives (Fanuc and
    /// Sinumerik parameters, LinuxCNC's INI file), which the machine file may give
    /// (`program_units`); otherwise in mm, with a warning. Klartext's unit is the program's
    /// own (`BEGIN PGM … MM`).
    pub units_by_setting: bool,
    /// The letters that repeat a G81–G89 canned cycle, the first given wins: `L` on LinuxCNC,
    /// `K` (or `L`) on Fanuc. A `K` in a cycle block of a dialect whose repeat letters do not
    /// include it is an error (LinuxCNC's K is G87's offset).
    pub cycle_repeat: &'static [char],
    /// What F means on a feed block that turns a rotary axis.
    pub rotary_feed: RotaryFeed,
    /// `,C` and `,R` after a straight move chamfer or round the corner to the next one
    /// (Fanuc's "chamfering and corner R", as Haas reads it too).
    pub comma_corners: bool,
    /// Tool length offsets (`G43 H…`, `G44`, `G49`), recorded for the writer
    /// ([`crate::toolpath::Toolpath::length_offsets`]).
    pub length_offsets: LengthOffsets,
}

/// Whether a dialect has tool length offset words, and the offset a `G43` without H takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthOffsets {
    /// None (Sinumerik and Klartext apply the tool's length with the tool).
    Absent,
    /// The tool in the spindle's (LinuxCNC: "G43 without an H word uses the currently loaded
    /// tool").
    BareTakesTool,
    /// The last H given (Fanuc: H is modal; a program gives it with its first G43).
    BareTakesLastH,
}

use Action::{
    ArcDistance, BuilderDatum, Distance as Dist, FeedMode as Fm, MachineCoordinates, Motion as Mo,
    MotionCancel, NoMotion, Note, ProgramEnd, Return, Unsupported as Unsup,
};
use Address::{ArcCentre, Axis};

const CANNED: &str = "this canned cycle is not supported: post the toolpath as G0/G1/G2/G3";
/// G70/G71 on LinuxCNC (and Fanuc lathes) are turning cycles; on Siemens, Fagor, Heidenhain
/// ISO and Beckhoff controls, and Fanuc lathes in G-code system B/C, they select inch/mm.
/// Hobby and NX posts write a lone `G71` (Vectric-style `G71G91.1` headers, NX's Fryer post
/// `G70`) in that second sense, which a LinuxCNC or Fanuc mill would refuse too.
const G70_71: &str = "not a unit on this control: G70/G71 are lathe cycles here (finishing, \
                      roughing), which feedopt does not expand. A post that writes G70/G71 for \
                      inch/mm (as Siemens, Fagor and Heidenhain ISO controls read them) means \
                      G20/G21: write those instead (a Siemens program: --dialect sinumerik)";
const SPLINES: &str = "spline and polynomial interpolation is not supported";
const THREADS: &str = "spindle-synchronised motion (threading, tapping) is not supported";
const PER_REV: &str = "feed per revolution is not supported";
const G60: &str = "single-direction positioning approaches the end point from one side, past \
                   it by an amount the control's parameters set; that approach is not modelled: \
                   the move goes straight to its end point";
/// The text of [`UVW`], for [`UVW_FANUC`] to extend.
macro_rules! uvw {
    () => {
        "a U, V or W word moves an axis feedopt does not model (parallel axes, a quill); the \
         move would be lost: post the program without it"
    };
}
const UVW: &str = uvw!();
/// Fanuc's U/V/W: as [`UVW`], and on a Fanuc lathe U and W are X and Z incremental (round 8:
/// a Fusion lathe post's `G28 U0. W0.` was named a parallel axis only).
const UVW_FANUC: &str = concat!(
    uvw!(),
    ". On a Fanuc lathe (T series) U and W are X and Z incremental: then this is a turning \
     program, which feedopt does not read (it reads milling programs)"
);
/// Sinumerik words that set the tool's orientation other than by the rotary axes' positions or
/// the tool vector `A3= B3= C3=` (round 16: they were unknown words, skipped with a warning,
/// while under TRAORI the control turns the rotary axes to them).
const ORI_ANGLES: &str = "tool orientation by angles (A2= B2= C2=: Euler, RPY or virtual-axis \
                          angles) is not supported: post it as the rotary axes' positions or as \
                          a tool vector A3= B3= C3=";
const ORI_LEAD_TILT: &str = "tool orientation by lead and tilt angles (LEAD= TILT=) is not \
                             supported: post it as the rotary axes' positions or as a tool \
                             vector A3= B3= C3=";
const ORI_CONE: &str = "orientation by rotation or cone angles (THETA= PHI= PSI=) is not \
                        supported: post it as the rotary axes' positions or as a tool vector \
                        A3= B3= C3=";
const ORI_NORMALS: &str = "surface normal vectors (A4= B4= C4=, A5= B5= C5=) are not supported: \
                           they steer 3D tool compensation and path-relative orientation, \
                           which feedopt does not model";
const ORI_CURVE: &str = "orientation by a second contour (XH= YH= ZH=, ORICURVE) is not \
                         supported: post it as the rotary axes' positions or as a tool vector \
                         A3= B3= C3=";
/// Fanuc and LinuxCNC `G96`/`G97`: the spindle-speed mode only (feed mode is G94/G95's).
const CSS_ON: Action = Action::SurfaceSpeed {
    on: true,
    feed: None,
};
const CSS_OFF: Action = Action::SurfaceSpeed {
    on: false,
    feed: None,
};
const TRANSFORM: &str = "coordinate transformations (polar, rotation, scaling, mirroring, tilted \
                         planes) are not supported";

/// LinuxCNC (rs274ngc). M428/M429/M430 are the trt sims' switchkins remaps (TCP / identity /
/// user kinematics); M100–M199 are user M codes (ignored).
pub static LINUXCNC: DialectSpec = DialectSpec {
    name: "LinuxCNC",
    paren_comments: true,
    semicolon: Semicolon::Comment,
    spaces: Spaces::Ignored,
    letters: &[
        ('X', Axis(0)),
        ('Y', Axis(1)),
        ('Z', Axis(2)),
        ('A', Axis(3)),
        ('B', Axis(4)),
        ('C', Axis(5)),
        ('I', ArcCentre(0)),
        ('J', ArcCentre(1)),
        ('K', ArcCentre(2)),
        ('R', Address::Radius),
        ('P', Address::ArcTurns),
        ('F', Address::Feed),
        ('G', Address::G),
        ('M', Address::M),
        ('N', Address::Ignored),
        ('S', Address::Ignored),
        ('T', Address::Ignored),
        ('H', Address::Ignored),
        ('D', Address::Ignored),
        ('E', Address::Ignored),
        ('L', Address::Ignored),
        ('Q', Address::Ignored),
        ('U', Address::Unsupported(UVW)),
        ('V', Address::Unsupported(UVW)),
        ('W', Address::Unsupported(UVW)),
        (
            'O',
            Address::Unsupported(
                "LinuxCNC reads an O word only as an O-word statement, and of those feedopt \
                 reads the subroutines (sub, endsub, call, return), not O-word control flow \
                 (if, while, do, repeat); a bare `O1234` at the top is a Fanuc program \
                 number: remove it, or read the program with --dialect fanuc",
            ),
        ),
    ],
    named: &[],
    g_codes: &[
        ("0", Mo(Motion::Rapid)),
        ("1", Mo(Motion::Linear)),
        ("2", Mo(Motion::ArcCw)),
        ("3", Mo(Motion::ArcCcw)),
        ("4", Action::Dwell),
        ("5", Unsup(SPLINES)),
        ("5.1", Unsup(SPLINES)),
        ("5.2", Unsup(SPLINES)),
        ("5.3", Unsup(SPLINES)),
        ("7", Unsup("lathe diameter mode (G7) is not supported")),
        ("8", Action::Ignored),
        ("10", Action::SetOffset(OffsetNumbering::LinuxCnc)),
        ("17", Action::Plane(Plane::Xy)),
        ("18", Action::Plane(Plane::Zx)),
        ("19", Action::Plane(Plane::Yz)),
        ("17.1", Unsup("U V W arc planes are not supported")),
        ("18.1", Unsup("U V W arc planes are not supported")),
        ("19.1", Unsup("U V W arc planes are not supported")),
        (
            "20",
            Action::Units {
                units: Units::Inch,
                feed: true,
            },
        ),
        (
            "21",
            Action::Units {
                units: Units::Mm,
                feed: true,
            },
        ),
        ("28", Action::Reference(1)),
        ("28.1", Action::Ignored),
        ("30", Action::Reference(2)),
        ("30.1", Action::Ignored),
        ("33", Unsup(THREADS)),
        ("33.1", Action::RigidTap),
        ("38.2", Unsup("probing moves are not supported")),
        ("38.3", Unsup("probing moves are not supported")),
        ("38.4", Unsup("probing moves are not supported")),
        ("38.5", Unsup("probing moves are not supported")),
        ("40", Action::Ignored),
        ("41", Action::CutterCompensation),
        ("41.1", Action::CutterCompensation),
        ("42", Action::CutterCompensation),
        ("42.1", Action::CutterCompensation),
        ("43", Action::Ignored),
        ("43.1", Action::Ignored),
        ("43.2", Action::Ignored),
        ("49", Action::Ignored),
        // Tormach PathPilot (LinuxCNC) cancels scaling with G50; Fusion's Tormach post writes
        // it in every program's safe-start line. G51 (scaling on) is not read, so no scaling
        // is ever in force and G50 changes nothing.
        ("50", Action::Ignored),
        ("52", Action::LocalOffset),
        ("53", MachineCoordinates),
        ("54..59", Action::WorkOffset),
        ("59.1", Action::WorkOffset),
        ("59.2", Action::WorkOffset),
        ("59.3", Action::WorkOffset),
        ("61", Action::Ignored),
        ("61.1", Action::Ignored),
        ("64", Action::ContourTolerance),
        ("70..71", Unsup(G70_71)),
        ("72", Unsup(CANNED)),
        ("73", Action::Cycle(73)),
        ("74", Action::Cycle(74)),
        (
            "76",
            Unsup("G76 is LinuxCNC's threading cycle: not supported"),
        ),
        ("80", MotionCancel),
        ("81", Action::Cycle(81)),
        ("82", Action::Cycle(82)),
        ("83", Action::Cycle(83)),
        ("84", Action::Cycle(84)),
        ("85", Action::Cycle(85)),
        ("86", Action::Cycle(86)),
        (
            "87",
            Unsup("LinuxCNC back boring (with its I J K offsets) is not supported"),
        ),
        ("88", Action::Cycle(88)),
        ("89", Action::Cycle(89)),
        ("90", Dist(Distance::Absolute)),
        ("91", Dist(Distance::Incremental)),
        ("90.1", ArcDistance(Distance::Absolute)),
        ("91.1", ArcDistance(Distance::Incremental)),
        ("92", Action::PositionOffset(OffsetNumbering::LinuxCnc)),
        ("92.1", Action::LocalOffsetCancel { clear: true }),
        ("92.2", Action::LocalOffsetCancel { clear: false }),
        ("92.3", Action::LocalOffsetRestore),
        ("93", Fm(FeedMode::InverseTime)),
        ("94", Fm(FeedMode::PerMinute)),
        ("95", Fm(FeedMode::PerRevolution)),
        ("96", CSS_ON),
        ("97", CSS_OFF),
        ("98", Action::CycleReturn(false)),
        ("99", Action::CycleReturn(true)),
    ],
    m_codes: &[
        ("0", Action::Ignored),
        ("1", Action::Ignored),
        ("2", ProgramEnd),
        ("3", Action::Switch(&[Switch::SpindleClockwise])),
        ("4", Action::Switch(&[Switch::SpindleCounterClockwise])),
        ("5", Action::Switch(&[Switch::SpindleStop])),
        ("6", Action::ToolChange),
        ("7", Action::Switch(&[Switch::CoolantMist])),
        ("8", Action::Switch(&[Switch::CoolantFlood])),
        ("9", Action::Switch(&[Switch::CoolantOff])),
        ("19", Action::Ignored),
        ("30", ProgramEnd),
        ("48..53", Action::Ignored),
        ("60", Action::Ignored),
        ("61", Action::SetTool),
        ("62..68", Action::Ignored),
        ("70..73", Action::Ignored),
        ("100..199", Action::Ignored),
        ("428", Action::Tcp(Tcp::On)),
        ("429", Action::Tcp(Tcp::Off)),
        ("430", Action::Tcp(Tcp::Off)),
    ],
    keywords: &[],
    initial_motion: None,
    g94_clears_feed: true,
    bare_reference_moves_all: true,
    integer_increments: None,
    subprograms: Subprograms::OWordSub,
    // The INI file's start-up codes (RS274NGC_STARTUP_CODE) and LINEAR_UNITS set it: an inch
    // program without G20 was read as mm in silence (round 4, 1.09 m for about 27.8 m).
    units_by_setting: true,
    cycle_repeat: &['L'],
    rotary_feed: RotaryFeed::Xyz,
    comma_corners: false,
    length_offsets: LengthOffsets::BareTakesTool,
};

/// Fanuc (M series). G43.4 = TCP with rotary words, G43.5 = TCP with tool vector I J K; any
/// other group-08 code (G43, G44, G49) switches TCP off.
pub static FANUC: DialectSpec = DialectSpec {
    name: "Fanuc",
    paren_comments: true,
    semicolon: Semicolon::EndOfBlock,
    spaces: Spaces::Ignored,
    letters: &[
        ('X', Axis(0)),
        ('Y', Axis(1)),
        ('Z', Axis(2)),
        ('A', Axis(3)),
        ('B', Axis(4)),
        ('C', Axis(5)),
        ('I', ArcCentre(0)),
        ('J', ArcCentre(1)),
        ('K', ArcCentre(2)),
        ('R', Address::Radius),
        ('F', Address::Feed),
        ('G', Address::G),
        ('M', Address::M),
        ('N', Address::Ignored),
        ('O', Address::Ignored),
        ('S', Address::Ignored),
        ('T', Address::Ignored),
        ('H', Address::Ignored),
        ('D', Address::Ignored),
        ('E', Address::Ignored),
        ('L', Address::Ignored),
        ('P', Address::Ignored),
        ('Q', Address::Ignored),
        ('U', Address::Unsupported(UVW_FANUC)),
        ('V', Address::Unsupported(UVW_FANUC)),
        ('W', Address::Unsupported(UVW_FANUC)),
    ],
    named: &[],
    g_codes: &[
        ("0", Mo(Motion::Rapid)),
        ("1", Mo(Motion::Linear)),
        ("2", Mo(Motion::ArcCw)),
        ("3", Mo(Motion::ArcCcw)),
        ("4", Action::Dwell),
        // G05 P10000 / G05 P0: high-precision contour control on / off (the look-ahead of
        // the Fanuc 16i/18i/21i-MB), no motion; any other G05 is refused where it is read
        // (`Interpreter`: high-speed cycle machining runs motion from data in the control).
        ("5", Action::Ignored),
        ("5.1", Action::Ignored),
        ("6.2", Unsup(SPLINES)),
        ("8", Action::Ignored),
        ("9", Action::Ignored),
        ("10", Action::SetOffset(OffsetNumbering::Fanuc)),
        ("11", Action::Ignored),
        // Haas circular pocket milling (G12 clockwise, G13 counter-clockwise: I, K, Q, L, Z,
        // D): a cycle whose lead-in and passes feedopt does not expand. Haas programs are read
        // in this dialect, so the error names it rather than "not a Fanuc G code".
        (
            "12..13",
            Unsup(
                "Haas circular pocket milling (G12/G13) is not expanded: post the pocket as \
                 G2/G3 moves",
            ),
        ),
        ("15", Action::Ignored),
        ("16", Unsup(TRANSFORM)),
        ("17", Action::Plane(Plane::Xy)),
        ("18", Action::Plane(Plane::Zx)),
        ("19", Action::Plane(Plane::Yz)),
        (
            "20",
            Action::Units {
                units: Units::Inch,
                feed: true,
            },
        ),
        (
            "21",
            Action::Units {
                units: Units::Mm,
                feed: true,
            },
        ),
        ("28", Action::Reference(1)),
        (
            "29",
            Unsup("G29 (return from the reference point) is not supported"),
        ),
        ("30", Action::Reference(2)),
        ("33", Unsup(THREADS)),
        ("40", Action::Ignored),
        ("41", Action::CutterCompensation),
        ("42", Action::CutterCompensation),
        ("43", Action::Tcp(Tcp::Off)),
        ("44", Action::Tcp(Tcp::Off)),
        ("43.4", Action::Tcp(Tcp::On)),
        ("43.5", Action::Tcp(Tcp::OnIjkVector)),
        ("49", Action::Tcp(Tcp::Off)),
        ("50", Action::Ignored),
        ("51", Unsup(TRANSFORM)),
        ("50.1", Action::Ignored),
        ("51.1", Unsup(TRANSFORM)),
        ("52", Action::LocalOffset),
        ("53", MachineCoordinates),
        ("53.1", Action::Ignored),
        ("54..59", Action::WorkOffset),
        ("54.1", Action::WorkOffset),
        ("60", Note(G60)),
        ("61..64", Action::Ignored),
        // A G65 block is read as a macro call before the table (subprograms.rs).
        ("65", Unsup("macro calls (G65) are not supported here")),
        (
            "66",
            Unsup("modal macro calls (G66) are not supported: call the macro with G65"),
        ),
        ("67", Action::Ignored),
        ("68", Unsup(TRANSFORM)),
        ("68.2", Action::TiltedPlane),
        ("69", Action::TiltedPlaneCancel),
        ("70..71", Unsup(G70_71)),
        ("73", Action::Cycle(73)),
        ("74", Action::Cycle(74)),
        ("75", Unsup(CANNED)),
        ("76", Action::Cycle(76)),
        ("77..79", Unsup(CANNED)),
        ("80", Action::CycleCancel),
        ("81", Action::Cycle(81)),
        ("82", Action::Cycle(82)),
        ("83", Action::Cycle(83)),
        ("84", Action::Cycle(84)),
        ("85", Action::Cycle(85)),
        ("86", Action::Cycle(86)),
        ("87", Action::Cycle(87)),
        ("88", Action::Cycle(88)),
        ("89", Action::Cycle(89)),
        ("234", Action::Tcp(Tcp::On)),
        ("254", Action::Ignored),
        ("255", Action::Ignored),
        // Haas: the smoothness setting (P1 rough … P3 finish, E the corner tolerance); the
        // control's corner rounding is not modelled either way.
        ("187", Action::Ignored),
        ("90", Dist(Distance::Absolute)),
        ("91", Dist(Distance::Incremental)),
        ("92", Action::PositionOffset(OffsetNumbering::Fanuc)),
        ("93", Fm(FeedMode::InverseTime)),
        ("94", Fm(FeedMode::PerMinute)),
        ("95", Fm(FeedMode::PerRevolution)),
        ("96", CSS_ON),
        ("97", CSS_OFF),
        ("98", Action::CycleReturn(false)),
        ("99", Action::CycleReturn(true)),
    ],
    m_codes: &[
        ("0", Action::Ignored),
        ("1", Action::Ignored),
        ("2", ProgramEnd),
        ("3", Action::Switch(&[Switch::SpindleClockwise])),
        ("4", Action::Switch(&[Switch::SpindleCounterClockwise])),
        ("5", Action::Switch(&[Switch::SpindleStop])),
        ("6", Action::ToolChange),
        ("7", Action::Switch(&[Switch::CoolantMist])),
        ("8", Action::Switch(&[Switch::CoolantFlood])),
        ("9", Action::Switch(&[Switch::CoolantOff])),
        ("19", Action::Ignored),
        ("29", Action::Ignored),
        ("30", ProgramEnd),
        (
            "97",
            Unsup(
                "local subprogram calls (Haas M97 P<label>) are not supported: post the \
                 program with M98 and O-numbered subprograms, or without subprograms",
            ),
        ),
        ("98", Action::Call),
        ("99", Return),
    ],
    keywords: &[],
    initial_motion: Some(Motion::Rapid),
    g94_clears_feed: false,
    bare_reference_moves_all: false,
    integer_increments: Some(IntegerIncrements {
        mm: 0.001,
        inch: 0.0001,
        deg: 0.001,
    }),
    subprograms: Subprograms::OPrograms,
    units_by_setting: true,
    cycle_repeat: &['K', 'L'],
    rotary_feed: RotaryFeed::Combined,
    comma_corners: true,
    length_offsets: LengthOffsets::BareTakesLastH,
};

/// Siemens Sinumerik 840D. TRAORI = TCP (rotary words or tool vector `A3= B3= C3=`),
/// TRAFOOF = off.
pub static SINUMERIK: DialectSpec = DialectSpec {
    name: "Sinumerik",
    paren_comments: false,
    semicolon: Semicolon::Comment,
    spaces: Spaces::Separate,
    letters: &[
        ('X', Axis(0)),
        ('Y', Axis(1)),
        ('Z', Axis(2)),
        ('A', Axis(3)),
        ('B', Axis(4)),
        ('C', Axis(5)),
        ('I', ArcCentre(0)),
        ('J', ArcCentre(1)),
        ('K', ArcCentre(2)),
        ('F', Address::Feed),
        ('G', Address::G),
        ('M', Address::M),
        ('N', Address::Ignored),
        ('S', Address::Ignored),
        ('T', Address::Ignored),
        ('D', Address::Ignored),
        ('H', Address::Ignored),
        ('P', Address::Ignored),
        ('L', Address::Call),
    ],
    named: &[
        ("A3", Address::ToolVector(0)),
        ("B3", Address::ToolVector(1)),
        ("C3", Address::ToolVector(2)),
        ("CR", Address::Radius),
        ("TURN", Address::ArcExtraTurns),
        (
            "AR",
            Address::Unsupported("arcs by opening angle (AR=) are not supported"),
        ),
        (
            "ANG",
            Address::Unsupported(
                "a contour's end point by its angle (ANG=) is not supported: post the end \
                 point's coordinates",
            ),
        ),
        ("A2", Address::Unsupported(ORI_ANGLES)),
        ("B2", Address::Unsupported(ORI_ANGLES)),
        ("C2", Address::Unsupported(ORI_ANGLES)),
        ("LEAD", Address::Unsupported(ORI_LEAD_TILT)),
        ("TILT", Address::Unsupported(ORI_LEAD_TILT)),
        ("THETA", Address::Unsupported(ORI_CONE)),
        ("PHI", Address::Unsupported(ORI_CONE)),
        ("PSI", Address::Unsupported(ORI_CONE)),
        ("A4", Address::Unsupported(ORI_NORMALS)),
        ("B4", Address::Unsupported(ORI_NORMALS)),
        ("C4", Address::Unsupported(ORI_NORMALS)),
        ("A5", Address::Unsupported(ORI_NORMALS)),
        ("B5", Address::Unsupported(ORI_NORMALS)),
        ("C5", Address::Unsupported(ORI_NORMALS)),
        ("XH", Address::Unsupported(ORI_CURVE)),
        ("YH", Address::Unsupported(ORI_CURVE)),
        ("ZH", Address::Unsupported(ORI_CURVE)),
        ("RND", Address::Corner(CornerWord::Round)),
        ("RNDM", Address::Corner(CornerWord::RoundModal)),
        ("CHF", Address::Corner(CornerWord::ChamferLength)),
        ("CHR", Address::Corner(CornerWord::ChamferLeg)),
        ("FRC", Address::Corner(CornerWord::Feed)),
        ("FRCM", Address::Corner(CornerWord::Feed)),
        (
            "AP",
            Address::Unsupported("polar coordinates (AP=, RP=) are not supported"),
        ),
        (
            "RP",
            Address::Unsupported("polar coordinates (AP=, RP=) are not supported"),
        ),
    ],
    g_codes: &[
        ("0", Mo(Motion::Rapid)),
        ("1", Mo(Motion::Linear)),
        ("2", Mo(Motion::ArcCw)),
        ("3", Mo(Motion::ArcCcw)),
        ("4", Action::Dwell),
        ("9", Action::Ignored),
        ("17", Action::Plane(Plane::Xy)),
        ("18", Action::Plane(Plane::Zx)),
        ("19", Action::Plane(Plane::Yz)),
        (
            "25",
            NoMotion("G25/G26 working-area limits are not modelled"),
        ),
        (
            "26",
            NoMotion("G25/G26 working-area limits are not modelled"),
        ),
        ("33", Unsup(THREADS)),
        ("40", Action::Ignored),
        ("41", Action::CutterCompensation),
        ("42", Action::CutterCompensation),
        ("53", MachineCoordinates),
        ("60", Action::Ignored),
        ("62", Action::Ignored),
        ("621", Action::Ignored),
        ("63", Action::Ignored),
        ("64", Action::Ignored),
        (
            "70",
            Action::Units {
                units: Units::Inch,
                feed: false,
            },
        ),
        (
            "71",
            Action::Units {
                units: Units::Mm,
                feed: false,
            },
        ),
        ("54..57", Action::WorkOffset),
        ("90", Dist(Distance::Absolute)),
        ("91", Dist(Distance::Incremental)),
        ("92", Action::SpindleLimit),
        ("93", Fm(FeedMode::InverseTime)),
        ("94", Fm(FeedMode::PerMinute)),
        ("95", Fm(FeedMode::PerRevolution)),
        (
            "96",
            Action::SurfaceSpeed {
                on: true,
                feed: Some(FeedMode::PerRevolution),
            },
        ),
        (
            "97",
            Action::SurfaceSpeed {
                on: false,
                feed: Some(FeedMode::PerRevolution),
            },
        ),
        ("110..112", Unsup(TRANSFORM)),
        ("153", MachineCoordinates),
        ("331", Unsup(THREADS)),
        ("332", Unsup(THREADS)),
        ("450", Action::Ignored),
        ("451", Action::Ignored),
        ("500", Action::WorkOffset),
        ("505..599", Action::WorkOffset),
        ("601..603", Action::Ignored),
        ("641..645", Action::Ignored),
        (
            "700",
            Action::Units {
                units: Units::Inch,
                feed: true,
            },
        ),
        (
            "710",
            Action::Units {
                units: Units::Mm,
                feed: true,
            },
        ),
    ],
    m_codes: &[
        ("0", Action::Ignored),
        ("1", Action::Ignored),
        ("2", ProgramEnd),
        ("3", Action::Switch(&[Switch::SpindleClockwise])),
        ("4", Action::Switch(&[Switch::SpindleCounterClockwise])),
        ("5", Action::Switch(&[Switch::SpindleStop])),
        ("6", Action::ToolChange),
        ("7", Action::Switch(&[Switch::CoolantMist])),
        ("8", Action::Switch(&[Switch::CoolantFlood])),
        ("9", Action::Switch(&[Switch::CoolantOff])),
        ("17", Return),
        ("19", Action::Ignored),
        ("30", ProgramEnd),
        ("40..45", Action::Ignored),
    ],
    keywords: &[
        ("TRAORI", Action::Tcp(Tcp::On)),
        ("TRAFOOF", Action::Tcp(Tcp::Off)),
        ("TRACYL", Unsup(TRANSFORM)),
        ("TRANSMIT", Unsup(TRANSFORM)),
        ("TRANS", Action::Frame(FrameOp::Trans)),
        ("ATRANS", Action::Frame(FrameOp::ATrans)),
        ("ROT", Action::Frame(FrameOp::Rot)),
        ("AROT", Action::Frame(FrameOp::ARot)),
        ("SUPA", MachineCoordinates),
        ("SCALE", Unsup(TRANSFORM)),
        ("ASCALE", Unsup(TRANSFORM)),
        ("MIRROR", Unsup(TRANSFORM)),
        ("AMIRROR", Unsup(TRANSFORM)),
        ("CYCLE800", Action::Swivel),
        (
            "CIP",
            Unsup("arcs through an intermediate point (CIP) are not supported"),
        ),
        ("CT", Unsup("tangential arcs (CT) are not supported")),
        ("ASPLINE", Unsup(SPLINES)),
        ("BSPLINE", Unsup(SPLINES)),
        ("CSPLINE", Unsup(SPLINES)),
        ("POLY", Unsup(SPLINES)),
        ("CYCLE76", Action::SinumerikCycle(76)),
        ("CYCLE77", Action::SinumerikCycle(77)),
        ("CYCLE81", Action::SinumerikCycle(81)),
        ("CYCLE82", Action::SinumerikCycle(82)),
        ("CYCLE83", Action::SinumerikCycle(83)),
        ("CYCLE84", Action::SinumerikCycle(84)),
        ("CYCLE85", Action::SinumerikCycle(85)),
        ("CYCLE86", Action::SinumerikCycle(86)),
        ("CYCLE87", Action::SinumerikCycle(87)),
        ("CYCLE88", Action::SinumerikCycle(88)),
        ("CYCLE89", Action::SinumerikCycle(89)),
        ("MCALL", Action::ModalCall),
        ("FGROUP", Action::FeedGroup),
        ("FNORM", Action::Ignored),
        (
            "CALL",
            Unsup(
                "indirect subprogram calls (CALL \"NAME\") are not supported: call the \
                 subprogram by its name (NAME, with PROC NAME … RET in this file)",
            ),
        ),
        ("GOTOF", Unsup("control flow is not supported")),
        ("GOTOB", Unsup("control flow is not supported")),
        ("GOTO", Unsup("control flow is not supported")),
        ("IF", Unsup("control flow is not supported")),
        ("WHILE", Unsup("control flow is not supported")),
        ("FOR", Unsup("control flow is not supported")),
        ("REPEAT", Unsup("control flow is not supported")),
        ("LOOP", Unsup("control flow is not supported")),
        ("RET", Return),
        ("SOFT", Action::Ignored),
        ("BRISK", Action::Ignored),
        ("FFWON", Action::Ignored),
        ("FFWOF", Action::Ignored),
        ("UPATH", Action::Ignored),
        ("SPATH", Action::Ignored),
        ("ORIWKS", Action::Ignored),
        ("ORIMKS", Action::Ignored),
        ("ORIAXES", Action::Ignored),
        ("ORIVECT", Action::Ignored),
        ("ORICONO", Action::Ignored),
        ("ORIEULER", Action::Ignored),
        ("ORIRPY", Action::Ignored),
        ("COMPCAD", Action::Ignored),
        ("COMPCURV", Action::Ignored),
        ("COMPOF", Action::Ignored),
        ("CFC", Action::Ignored),
        ("CFTCP", Action::Ignored),
        ("CFIN", Action::Ignored),
        ("STOPRE", Action::Ignored),
        ("MSG", Action::Ignored),
        ("CYCLE832", Action::Ignored),
        // The master spindle (SETMS(1)): no motion.
        ("SETMS", Action::Ignored),
    ],
    initial_motion: Some(Motion::Rapid),
    g94_clears_feed: false,
    bare_reference_moves_all: false,
    integer_increments: None,
    subprograms: Subprograms::Procs,
    units_by_setting: true,
    cycle_repeat: &['K', 'L'],
    rotary_feed: RotaryFeed::Xyz,
    comma_corners: false,
    length_offsets: LengthOffsets::Absent,
};

/// Heidenhain TNC 640 Klartext. The path functions `L`, `LN`, `C`, `CC`, `CR`, `CT`, `CP`,
/// `LP` and the statements (`TOOL CALL`, `CYCL DEF`, `PLANE`, …) are keywords; the words
/// after them are letters (`X+10`, `F500`, `M3`, `R+5`) and named words (`IX-5`, `DR+`,
/// `TX+0.7`). There are no G codes. See [`super::klartext`] for what each does.
pub static HEIDENHAIN: DialectSpec = DialectSpec {
    name: "Heidenhain",
    paren_comments: false,
    semicolon: Semicolon::Comment,
    spaces: Spaces::Klartext,
    letters: &[
        ('X', Axis(0)),
        ('Y', Axis(1)),
        ('Z', Axis(2)),
        ('A', Axis(3)),
        ('B', Axis(4)),
        ('C', Axis(5)),
        ('R', Address::Radius),
        ('F', Address::Feed),
        ('M', Address::M),
        ('S', Address::Ignored),
    ],
    named: &[
        ("IX", Address::IncrementalAxis(0)),
        ("IY", Address::IncrementalAxis(1)),
        ("IZ", Address::IncrementalAxis(2)),
        ("IA", Address::IncrementalAxis(3)),
        ("IB", Address::IncrementalAxis(4)),
        ("IC", Address::IncrementalAxis(5)),
        ("TX", Address::ToolVector(0)),
        ("TY", Address::ToolVector(1)),
        ("TZ", Address::ToolVector(2)),
        // LN surface normals: only 3D radius compensation (a DR2 delta) reads them.
        ("NX", Address::Ignored),
        ("NY", Address::Ignored),
        ("NZ", Address::Ignored),
        ("DR", Address::ArcDirection),
        ("PA", Address::PolarAngle(false)),
        ("IPA", Address::PolarAngle(true)),
        ("PR", Address::PolarRadius(false)),
        ("IPR", Address::PolarRadius(true)),
        ("MB", Address::Retract),
        ("LA", Address::Ignored),
        ("LR", Address::Ignored),
        (
            "FU",
            Address::Unsupported("feed per revolution (FU) is not supported: program F in mm/min"),
        ),
        (
            "FZ",
            Address::Unsupported("feed per tooth (FZ) is not supported: program F in mm/min"),
        ),
    ],
    g_codes: &[],
    m_codes: &[
        ("0", Action::Ignored),
        ("1", Action::Ignored),
        ("2", ProgramEnd),
        ("3", Action::Switch(&[Switch::SpindleClockwise])),
        ("4", Action::Switch(&[Switch::SpindleCounterClockwise])),
        ("5", Action::Switch(&[Switch::SpindleStop])),
        ("6..7", Action::Ignored),
        ("8", Action::Switch(&[Switch::CoolantFlood])),
        ("9", Action::Switch(&[Switch::CoolantOff])),
        (
            "13",
            Action::Switch(&[Switch::SpindleClockwise, Switch::CoolantFlood]),
        ),
        (
            "14",
            Action::Switch(&[Switch::SpindleCounterClockwise, Switch::CoolantFlood]),
        ),
        ("19", Action::Ignored),
        ("30", ProgramEnd),
        ("89", Action::CycleCallAt(false)),
        ("91", MachineCoordinates),
        ("92", BuilderDatum),
        (
            "94",
            Unsup(
                "M94 (rotary display reduced below 360°) is not supported: post the program \
                 without it",
            ),
        ),
        ("99", Action::CycleCallAt(true)),
        ("101", Action::Ignored),
        ("102", Action::Ignored),
        (
            "103",
            Note("M103 (reduced plunging feed) is not modelled: F is used as programmed"),
        ),
        ("104", Action::Ignored),
        ("105..108", Action::Ignored),
        (
            "109..111",
            Note(
                "M109–M111 (feed at the cutting edge on arcs) are not modelled: F is used as programmed",
            ),
        ),
        (
            "114",
            Unsup("M114 (the old tilted-axis compensation) is not supported: post with M128"),
        ),
        ("115", Action::Tcp(Tcp::Off)),
        (
            "116",
            Note(
                "M116 (rotary feed in mm/min) is not modelled: F on a rotary-only block is read as °/min",
            ),
        ),
        ("117", Action::Ignored),
        ("118", Action::Ignored),
        ("120", Action::Ignored),
        ("126", Action::RotaryShortestPath(true)),
        ("127", Action::RotaryShortestPath(false)),
        ("128", Action::Tcp(Tcp::On)),
        ("129", Action::Tcp(Tcp::Off)),
        (
            "130",
            Unsup(
                "M130 (untilted coordinates in a tilted plane) is not supported: post the move \
                 in the tilted plane's coordinates",
            ),
        ),
        ("134", Action::Ignored),
        ("135", Action::Ignored),
        ("136", Unsup(PER_REV)),
        ("137", Action::Ignored),
        ("138", Action::Ignored),
        ("140", Action::RetractToolAxis),
        ("141..145", Action::Ignored),
        ("148..150", Action::Ignored),
        ("197", Action::Ignored),
    ],
    keywords: &[
        ("L", Mo(Motion::Linear)),
        ("LN", Mo(Motion::Linear)),
        ("C", Action::Path(PathKind::PoleArc)),
        ("CC", Action::Path(PathKind::Centre)),
        ("CR", Action::Path(PathKind::RadiusArc)),
        ("CT", Action::Path(PathKind::TangentArc)),
        ("CP", Action::Path(PathKind::PolarArc)),
        ("LP", Action::Path(PathKind::PolarLine)),
        ("FMAX", Action::RapidBlock),
        ("FAUTO", Action::ToolCallFeed),
        ("R0", Action::Ignored),
        ("RL", Action::CutterCompensation),
        ("RR", Action::CutterCompensation),
        (
            "R+",
            Unsup(
                "paraxial radius compensation (R+/R-: the move lengthened or shortened by the \
                 tool radius) is not supported: post the tool-centre path with R0",
            ),
        ),
        (
            "R-",
            Unsup(
                "paraxial radius compensation (R+/R-: the move lengthened or shortened by the \
                 tool radius) is not supported: post the tool-centre path with R0",
            ),
        ),
        ("MB MAX", Action::RetractMax),
        ("RND", Action::Statement(Statement::Corner(false))),
        ("CHF", Action::Statement(Statement::Corner(true))),
        (
            "APPR",
            Unsup("approach functions (APPR) are not supported: post the approach as L/C blocks"),
        ),
        (
            "DEP",
            Unsup("departure functions (DEP) are not supported: post the departure as L/C blocks"),
        ),
        (
            "FPOL",
            Unsup("FK free contour programming is not supported: post the contour as L/C blocks"),
        ),
        (
            "FL",
            Unsup("FK free contour programming is not supported: post the contour as L/C blocks"),
        ),
        (
            "FC",
            Unsup("FK free contour programming is not supported: post the contour as L/C blocks"),
        ),
        (
            "FLT",
            Unsup("FK free contour programming is not supported: post the contour as L/C blocks"),
        ),
        (
            "FCT",
            Unsup("FK free contour programming is not supported: post the contour as L/C blocks"),
        ),
        ("SPL", Unsup(SPLINES)),
        ("BEGIN PGM", Action::Statement(Statement::ProgramBegin)),
        ("END PGM", ProgramEnd),
        ("BLK FORM", Action::Ignored),
        ("TOOL CALL", Action::Statement(Statement::ToolCall)),
        ("TOOL DEF", Action::Ignored),
        ("CYCL DEF", Action::Statement(Statement::CycleDef)),
        ("CYCL CALL", Action::Statement(Statement::CycleCall)),
        ("PATTERN DEF", Action::Statement(Statement::PatternDef)),
        (
            "SEL PATTERN",
            Unsup(
                "point tables (SEL PATTERN) are not supported: they are another file; post the \
                 holes as positions or a PATTERN DEF",
            ),
        ),
        ("PLANE", Action::Statement(Statement::Plane)),
        ("FUNCTION TCPM", Action::Statement(Statement::Tcpm)),
        ("FUNCTION RESET TCPM", Action::Tcp(Tcp::Off)),
        (
            "FUNCTION",
            Unsup("this FUNCTION is not supported (FUNCTION TCPM and FUNCTION RESET TCPM are)"),
        ),
        ("FN", Action::Statement(Statement::Fn)),
        ("STOP", Action::Ignored),
        (
            "TCH PROBE",
            Unsup("probing cycles (TCH PROBE) are not supported: they move until a contact"),
        ),
        (
            "CALL PGM",
            Unsup(
                "calls of other programs (CALL PGM) are not supported: feedopt reads one file; \
                 post the program with its subprograms as LBL sections",
            ),
        ),
        (
            "SEL PGM",
            Unsup("SEL PGM (another program file) is not supported: feedopt reads one file"),
        ),
        (
            "SEL CYCLE",
            Unsup("SEL CYCLE (a cycle in another file) is not supported: feedopt reads one file"),
        ),
        ("SEL TABLE", Action::Ignored),
        ("SEL CORR-TABLE", Action::Ignored),
        (
            "DECLARE",
            Unsup("string parameters (DECLARE STRING) are not supported"),
        ),
    ],
    initial_motion: None,
    g94_clears_feed: false,
    bare_reference_moves_all: false,
    integer_increments: None,
    subprograms: Subprograms::Labels,
    units_by_setting: false,
    cycle_repeat: &['K', 'L'],
    rotary_feed: RotaryFeed::Xyz,
    comma_corners: false,
    length_offsets: LengthOffsets::Absent,
};

/// Looks a G or M code up: `code` is the value as written (`1`, `01`, `43.4`).
/// Whether `name` (`G55`, `G54.1 P3`, as [`crate::toolpath::Toolpath::work_offset`] names
/// it) selects a work offset in `dialect`.
pub fn is_work_offset(dialect: Dialect, name: &str) -> bool {
    let mut words = name.split_whitespace();
    let code = words
        .next()
        .and_then(|w| w.strip_prefix('G'))
        .and_then(|v| v.parse::<f64>().ok());
    let p = match words.next() {
        None => true,
        Some(w) => w
            .strip_prefix('P')
            .is_some_and(|n| n.parse::<u32>().is_ok()),
    };
    p && words.next().is_none()
        && code.is_some_and(|c| {
            matches!(
                lookup_code(dialect.spec().g_codes, c),
                Some(Action::WorkOffset)
            )
        })
}

pub(super) fn lookup_code(table: &[(&'static str, Action)], value: f64) -> Option<Action> {
    let tenths = (value * 10.0).round();
    if value < 0.0 || (value * 10.0 - tenths).abs() > 1e-6 || tenths > 1e9 {
        return None;
    }
    let tenths = tenths as u64;
    let canonical = if tenths % 10 == 0 {
        format!("{}", tenths / 10)
    } else {
        format!("{}.{}", tenths / 10, tenths % 10)
    };
    table.iter().find_map(|&(key, action)| {
        let hit = match key.split_once("..") {
            Some((lo, hi)) => {
                let whole = tenths % 10 == 0;
                let (lo, hi) = (lo.parse::<u64>().ok(), hi.parse::<u64>().ok());
                whole
                    && lo
                        .zip(hi)
                        .is_some_and(|(lo, hi)| (lo..=hi).contains(&(tenths / 10)))
            }
            None => key == canonical,
        };
        hit.then_some(action)
    })
}
