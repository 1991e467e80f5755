//! G-code reader (RS-274 as LinuxCNC, Fanuc and Sinumerik controllers run it): `.ngc`, `.nc`,
//! `.gcode`, `.tap`.
//!
//! # One interpreter, one table per dialect
//!
//! Every dialect is a [`DialectSpec`]: plain data that says how comments look, whether spaces
//! separate words, which letters and named words exist and what they address, and what each
//! G code, M code and keyword does (an [`Action`]: motion mode, plane, units, TCP on/off, ...).
//! A single interpreter reads the program through that table (seed 003's re-programmable
//! interpreter). Adding a dialect means writing a new `DialectSpec` (and, for the built-in
//! ones, a [`Dialect`] variant); [`parse_with`] runs any table.
//!
//! The built-in tables:
//!
//! * [`LINUXCNC`]: comments `( … )` and `;` to the end of the line (a `;` inside `( )` belongs
//!   to the comment); spaces ignored everywhere (`G1  X  16.339`); TCP on `M428`, off `M429`
//!   (identity kins) and `M430` (user kins), the trt sims' switchkins remaps; no tool-vector
//!   words; `G20`/`G21`; axis words before any G0–G3 are an error (LinuxCNC starts in G80).
//! * [`FANUC`]: comments `( … )`, `;` ends a block; spaces ignored; TCP on `G43.4` (rotary
//!   words) or `G43.5` (tool vector: `I J K` on G0/G1 blocks), off `G49`, `G43`, `G44`;
//!   `G20`/`G21`; the motion mode starts as G0; a number without a decimal point in X Y Z A B C
//!   I J K R counts least input increments (0.001 mm, 0.0001 inch, 0.001°), Fanuc's default.
//! * [`SINUMERIK`]: `;` comments (parentheses are not comments); spaces separate words, which
//!   may be keywords (`TRAORI`, `MSG("…")`) or `NAME=value`; TCP on `TRAORI`, off `TRAFOOF`;
//!   tool vector `A3= B3= C3=`; `CR=` radius, `TURN=` extra turns; `G70`/`G71` inch/mm for
//!   geometry only, `G700`/`G710` for F too; the motion mode starts as G0.
//!
//! # What is read
//!
//! * **Motion.** `G0` (rapid), `G1`, `G2`/`G3` (clockwise / counter-clockwise) are modal; a block
//!   with axis words uses the motion mode in force (so `G54 X1 Y2 A0 C0` under G0 is a rapid).
//!   Axis words X Y Z (mm, or inch under G20: ×25.4) and A B C (degrees). `G90` absolute, `G91`
//!   incremental (increments add to the modal position). Rotary words are linear axes that wrap
//!   nothing: `C350` then `C370` stays 370, never reduced modulo 360.
//! * **Arcs.** `G17`/`G18`/`G19` select the XY / ZX / YZ plane (counter-clockwise is positive
//!   rotation about +Z / +Y / +X). The centre is given by I J K (offsets from the start point;
//!   LinuxCNC `G90.1` makes them absolute, `G91.1` incremental again) or by `R` (Sinumerik `CR=`):
//!   R > 0 the arc of at most 180°, R < 0 the longer one. Start = end with I J K is a full circle;
//!   LinuxCNC `P` (number of turns) and Sinumerik `TURN=` (extra turns) add whole turns. The axis
//!   normal to the plane and the rotary axes move linearly with the angle (helices). An I J K arc
//!   whose end radius differs from its start radius by more than [`ARC_RADIUS_MISMATCH_MM`] and
//!   [`ARC_RADIUS_MISMATCH_RELATIVE`] of the radius is an error; a smaller difference is followed
//!   as a spiral (radius linear in the angle), so the end point is met exactly. An R arc whose
//!   chord is longer than 2|R| + [`R_ARC_TOLERANCE_MM`] is an error. Arcs are **linearised**:
//!   chords whose sagitta is at most [`MAX_CHORD_ERROR_MM`] (1 µm), every chord end a
//!   [`ClPoint`] on the circle with the block's line; the last one is the programmed end point
//!   exactly.
//! * **Feeds.** `G0` → [`Feed::Rapid`]. Under `G94` (units per minute) F is modal and stored in
//!   mm/min (under G20, F × 25.4); a G1/G2/G3 block whose X, Y or Z moves by more than
//!   [`XYZ_MOVE_THRESHOLD_MM`] gets [`Feed::Programmed`] (F/60 mm/s). When only rotary axes move,
//!   LinuxCNC's length rule makes F degrees per minute over the A B C distance, so the block gets
//!   [`Feed::BlockTime`] = distance / (F/60) s (F as written, not inch-scaled). Before any F, or
//!   after `F0`, feed moves get [`Feed::Unspecified`]. Under `G93` (inverse time) every G1/G2/G3
//!   block must carry its own F (an error naming the line otherwise) and gets
//!   [`Feed::BlockTime`] = 60/F s; on an arc that time is split over the chords in proportion to
//!   their length. Leaving G93 forgets F (LinuxCNC: every `G94` sets F to 0), so a feed move must
//!   program F again.
//! * **Tool-tip mode (TCP).** The codes above switch it on and off. In TCP mode X Y Z are the
//!   tool tip in workpiece coordinates and A B C the rotary axis positions. A motion block that
//!   has (or keeps) a rotary position or tool vector while TCP is off gets one warning per
//!   stretch of such blocks: its X Y Z are still taken as the tool tip.
//! * **Tool vectors.** Sinumerik `A3= B3= C3=`, and Fanuc `I J K` on G0/G1 blocks under `G43.5`,
//!   set the tool orientation: a component not written in a block that writes another is 0, a
//!   block that writes none keeps the vector, and the vector is normalised (zero length is an
//!   error). On arcs I J K stay the centre.
//! * **Output.** One [`ClPoint`] per linear motion block (its end point), one per chord of an
//!   arc. `p` = X Y Z in mm in program coordinates; `o` = the tool vector when the program gives
//!   one, else (0, 0, 1); `rotary` = `Some([A, B, C])` (modal values in degrees, 0 for an axis
//!   never programmed) on every point when the program has any A, B or C word, `None`
//!   otherwise; `line` = the block's 1-based line. There is no implicit start point: the
//!   toolpath starts at the end of the first motion block. X, Y or Z not yet programmed at a
//!   motion block are taken as 0 with a warning (the machine's start position is unknown).
//! * **G53** (machine coordinates, one block): the move is included, its words read as
//!   absolute values, with a warning that machine coordinates are taken as program coordinates.
//!
//! # What is accepted and ignored
//!
//! Line numbers `N`; `S`, `T`, `H`, `D` and the other parameter letters of the table; M codes
//! of the table (spindle, coolant, tool change, pauses); `G40`, `G43` (LinuxCNC), `G49`, work
//! offsets `G54`–`G59` (`.1 .2 .3`), path control `G61`/`G64`; `%` lines; blank lines. Program
//! end (`M2`, `M30`, Sinumerik `M17`, `RET`, Fanuc `M99`) stops reading: later lines are not
//! parsed. These codes are accepted with a warning because the toolpath does not carry them:
//! cutter radius compensation `G41`/`G42` (the programmed path is used), dwell `G4` (its time
//! is not counted), `G10` offsets. A block starting with `/` (block delete) is skipped with a
//! warning. U V W axis words, and I J K or R on a straight move (outside G43.5) or without a
//! move, are skipped with a warning.
//!
//! # What is rejected
//!
//! * A word the dialect does not know (letter, G or M code, named word or keyword) is **not** an
//!   error: it is skipped with a [`Warning`] naming the word and its line, never silently.
//! * Errors ([`Error::Parse`] naming the file and line): a malformed number (`X1.2.3`, `Y-`,
//!   `F`), an unclosed `(` comment, parameters and expressions (`#1`, `[...]`, Sinumerik
//!   `IC(..)`), LinuxCNC O-word control flow, the same word twice in a block, two motion codes in
//!   one block, axis words without a motion mode, a G93 feed block without F, a negative F,
//!   impossible arcs, and codes that move the tool in ways a list of CL points cannot follow
//!   silently: canned cycles, `G28`/`G30`, `G92`/`G52` offsets, splines, threading, probing,
//!   polar coordinates, scaling, rotation, mirroring, feed per revolution, subprogram calls.

use nalgebra::Vector3;
use std::fmt;
use std::path::Path;
use std::str::FromStr;

use crate::error::{Error, Result};
pub use crate::toolpath::Units;
use crate::toolpath::{ClPoint, Feed, MM_PER_INCH, Toolpath, Warning};

/// Largest distance between an arc and the chords that replace it (the sagitta), mm: 1 µm.
///
/// The chord count of an arc of radius r and sweep Δ is ⌈Δ / (2 acos(1 − e/r))⌉ with e this
/// constant, so every chord's sagitta is at most e (on a helix, the in-plane sagitta).
pub const MAX_CHORD_ERROR_MM: f64 = 1e-3;

/// LinuxCNC's length rule: a block "moves X Y Z" when any of them moves more than this (mm).
pub const XYZ_MOVE_THRESHOLD_MM: f64 = 1e-7;

/// I J K arcs: the end radius may differ from the start radius by this much (mm) …
/// (LinuxCNC's default `CENTER_ARC_RADIUS_TOLERANCE_MM`, 0.02·√2).
pub const ARC_RADIUS_MISMATCH_MM: f64 = 0.02 * std::f64::consts::SQRT_2;

/// … or by this fraction of the radius, whichever is larger (LinuxCNC's
/// `SPIRAL_RELATIVE_TOLERANCE`).
pub const ARC_RADIUS_MISMATCH_RELATIVE: f64 = 1e-3;

/// R arcs: the chord may exceed the diameter by this much, mm (LinuxCNC's
/// `RADIUS_TOLERANCE_MM`); the centre is then the chord's midpoint.
pub const R_ARC_TOLERANCE_MM: f64 = 0.00127;

/// An I J K arc whose end is this close to its start (in the plane, mm) is a full circle.
const FULL_CIRCLE_MM: f64 = 1e-9;

/// Tool vectors shorter than this are rejected as having no direction.
const MIN_TOOL_VECTOR_NORM: f64 = 1e-12;

/// File extensions read as G-code.
pub const EXTENSIONS: &[&str] = &["ngc", "nc", "gcode", "tap"];

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
}

impl Dialect {
    /// All built-in dialects.
    pub const ALL: [Dialect; 3] = [Dialect::LinuxCnc, Dialect::Fanuc, Dialect::Sinumerik];

    /// The dialect's table.
    pub fn spec(self) -> &'static DialectSpec {
        match self {
            Dialect::LinuxCnc => &LINUXCNC,
            Dialect::Fanuc => &FANUC,
            Dialect::Sinumerik => &SINUMERIK,
        }
    }

    /// The name used on the command line (`linuxcnc`, `fanuc`, `sinumerik`).
    pub fn name(self) -> &'static str {
        match self {
            Dialect::LinuxCnc => "linuxcnc",
            Dialect::Fanuc => "fanuc",
            Dialect::Sinumerik => "sinumerik",
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

    /// `linuxcnc`, `fanuc` or `sinumerik` (case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        let wanted = s.trim().to_ascii_lowercase();
        Dialect::ALL
            .into_iter()
            .find(|d| d.name() == wanted)
            .ok_or_else(|| {
                Error::Usage(format!(
                    "unknown G-code dialect `{s}` (expected linuxcnc, fanuc or sinumerik)"
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
}

/// What a letter or named word addresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Address {
    /// Axis 0–5: X Y Z (length) A B C (degrees).
    Axis(usize),
    /// Arc centre 0–2 (I J K); under [`Tcp::OnIjkVector`] on G0/G1 blocks, the tool vector.
    ArcCentre(usize),
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
    /// Accepted but not modelled: skipped with this warning (U V W axes).
    Unmodelled(&'static str),
    /// Rejected with this error (LinuxCNC O-words, Sinumerik `L` subprogram calls).
    Unsupported(&'static str),
}

/// Motion modes (modal group 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    Rapid,
    Linear,
    ArcCw,
    ArcCcw,
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
    fn axes(self) -> (usize, usize, usize) {
        match self {
            Plane::Xy => (0, 1, 2),
            Plane::Zx => (2, 0, 1),
            Plane::Yz => (1, 2, 0),
        }
    }

    fn code(self) -> &'static str {
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
    Tcp(Tcp),
    /// G53: this block's axis words are machine coordinates.
    MachineCoordinates,
    /// The block's axis words belong to this code, not to a move (dwell `G4`); the warning
    /// text says what is not modelled.
    NoMotion(&'static str),
    /// Stop reading (M2, M30).
    ProgramEnd,
    /// Accepted, no effect on motion.
    Ignored,
    /// Accepted with this warning.
    Note(&'static str),
    /// Rejected with this error.
    Unsupported(&'static str),
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
    pub integer_increments: Option<IntegerIncrements>,
}

use Action::{
    ArcDistance, Distance as Dist, FeedMode as Fm, MachineCoordinates, Motion as Mo, MotionCancel,
    NoMotion, Note, ProgramEnd, Unsupported as Unsup,
};
use Address::{ArcCentre, Axis, Unmodelled};

const CANNED: &str = "canned cycles are not supported: post the toolpath as G0/G1/G2/G3";
const HOME: &str = "G28/G30 (move via a reference point) is not supported";
const OFFSETS: &str = "coordinate offsets that shift program coordinates (G92, G52) are not \
                       supported";
const SPLINES: &str = "spline and polynomial interpolation is not supported";
const THREADS: &str = "spindle-synchronised motion (threading, tapping) is not supported";
const PER_REV: &str = "feed per revolution (G95) is not supported";
const COMP: &str = "cutter radius compensation is not applied: the programmed path is used";
const DWELL: &str = "dwell: its time is not part of the toolpath";
const G10: &str = "G10 changes tool or work offsets: program coordinates are used as written";
const UVW: &str = "U V W axes are not modelled: word ignored";
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
        ('U', Unmodelled(UVW)),
        ('V', Unmodelled(UVW)),
        ('W', Unmodelled(UVW)),
        (
            'O',
            Address::Unsupported("O-word subroutines and control flow are not supported"),
        ),
    ],
    named: &[],
    g_codes: &[
        ("0", Mo(Motion::Rapid)),
        ("1", Mo(Motion::Linear)),
        ("2", Mo(Motion::ArcCw)),
        ("3", Mo(Motion::ArcCcw)),
        ("4", NoMotion(DWELL)),
        ("5", Unsup(SPLINES)),
        ("5.1", Unsup(SPLINES)),
        ("5.2", Unsup(SPLINES)),
        ("5.3", Unsup(SPLINES)),
        ("7", Unsup("lathe diameter mode (G7) is not supported")),
        ("8", Action::Ignored),
        ("10", Note(G10)),
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
        ("28", Unsup(HOME)),
        ("28.1", Action::Ignored),
        ("30", Unsup(HOME)),
        ("30.1", Action::Ignored),
        ("33", Unsup(THREADS)),
        ("33.1", Unsup(THREADS)),
        ("38.2", Unsup("probing moves are not supported")),
        ("38.3", Unsup("probing moves are not supported")),
        ("38.4", Unsup("probing moves are not supported")),
        ("38.5", Unsup("probing moves are not supported")),
        ("40", Action::Ignored),
        ("41", Note(COMP)),
        ("41.1", Note(COMP)),
        ("42", Note(COMP)),
        ("42.1", Note(COMP)),
        ("43", Action::Ignored),
        ("43.1", Action::Ignored),
        ("43.2", Action::Ignored),
        ("49", Action::Ignored),
        ("52", Unsup(OFFSETS)),
        ("53", MachineCoordinates),
        ("54..59", Action::Ignored),
        ("59.1", Action::Ignored),
        ("59.2", Action::Ignored),
        ("59.3", Action::Ignored),
        ("61", Action::Ignored),
        ("61.1", Action::Ignored),
        ("64", Action::Ignored),
        ("70..72", Unsup(CANNED)),
        ("73", Unsup(CANNED)),
        ("74", Unsup(CANNED)),
        ("76", Unsup(CANNED)),
        ("80", MotionCancel),
        ("81..89", Unsup(CANNED)),
        ("90", Dist(Distance::Absolute)),
        ("91", Dist(Distance::Incremental)),
        ("90.1", ArcDistance(Distance::Absolute)),
        ("91.1", ArcDistance(Distance::Incremental)),
        ("92", Unsup(OFFSETS)),
        ("92.1", Action::Ignored),
        ("92.2", Action::Ignored),
        ("92.3", Unsup(OFFSETS)),
        ("93", Fm(FeedMode::InverseTime)),
        ("94", Fm(FeedMode::PerMinute)),
        ("95", Unsup(PER_REV)),
        ("96", Action::Ignored),
        ("97", Action::Ignored),
        ("98", Action::Ignored),
        ("99", Action::Ignored),
    ],
    m_codes: &[
        ("0", Action::Ignored),
        ("1", Action::Ignored),
        ("2", ProgramEnd),
        ("3..9", Action::Ignored),
        ("19", Action::Ignored),
        ("30", ProgramEnd),
        ("48..53", Action::Ignored),
        ("60..68", Action::Ignored),
        ("70..73", Action::Ignored),
        ("100..199", Action::Ignored),
        ("428", Action::Tcp(Tcp::On)),
        ("429", Action::Tcp(Tcp::Off)),
        ("430", Action::Tcp(Tcp::Off)),
    ],
    keywords: &[],
    initial_motion: None,
    g94_clears_feed: true,
    integer_increments: None,
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
        ('U', Unmodelled(UVW)),
        ('V', Unmodelled(UVW)),
        ('W', Unmodelled(UVW)),
    ],
    named: &[],
    g_codes: &[
        ("0", Mo(Motion::Rapid)),
        ("1", Mo(Motion::Linear)),
        ("2", Mo(Motion::ArcCw)),
        ("3", Mo(Motion::ArcCcw)),
        ("4", NoMotion(DWELL)),
        ("5.1", Action::Ignored),
        ("6.2", Unsup(SPLINES)),
        ("8", Action::Ignored),
        ("9", Action::Ignored),
        ("10", Note(G10)),
        ("11", Action::Ignored),
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
        ("28", Unsup(HOME)),
        ("29", Unsup(HOME)),
        ("30", Unsup(HOME)),
        ("33", Unsup(THREADS)),
        ("40", Action::Ignored),
        ("41", Note(COMP)),
        ("42", Note(COMP)),
        ("43", Action::Tcp(Tcp::Off)),
        ("44", Action::Tcp(Tcp::Off)),
        ("43.4", Action::Tcp(Tcp::On)),
        ("43.5", Action::Tcp(Tcp::OnIjkVector)),
        ("49", Action::Tcp(Tcp::Off)),
        ("50", Action::Ignored),
        ("51", Unsup(TRANSFORM)),
        ("50.1", Action::Ignored),
        ("51.1", Unsup(TRANSFORM)),
        ("52", Unsup(OFFSETS)),
        ("53", MachineCoordinates),
        ("53.1", Unsup(TRANSFORM)),
        ("54..59", Action::Ignored),
        ("54.1", Action::Ignored),
        ("61..64", Action::Ignored),
        ("65", Unsup("macro calls (G65/G66) are not supported")),
        ("66", Unsup("macro calls (G65/G66) are not supported")),
        ("67", Action::Ignored),
        ("68", Unsup(TRANSFORM)),
        ("68.2", Unsup(TRANSFORM)),
        ("69", Action::Ignored),
        ("73..79", Unsup(CANNED)),
        ("80", Action::Ignored),
        ("81..89", Unsup(CANNED)),
        ("90", Dist(Distance::Absolute)),
        ("91", Dist(Distance::Incremental)),
        ("92", Unsup(OFFSETS)),
        ("93", Fm(FeedMode::InverseTime)),
        ("94", Fm(FeedMode::PerMinute)),
        ("95", Unsup(PER_REV)),
        ("96", Action::Ignored),
        ("97", Action::Ignored),
        ("98", Action::Ignored),
        ("99", Action::Ignored),
    ],
    m_codes: &[
        ("0", Action::Ignored),
        ("1", Action::Ignored),
        ("2", ProgramEnd),
        ("3..9", Action::Ignored),
        ("19", Action::Ignored),
        ("29", Action::Ignored),
        ("30", ProgramEnd),
        ("98", Unsup("subprogram calls (M98) are not supported")),
        ("99", ProgramEnd),
    ],
    keywords: &[],
    initial_motion: Some(Motion::Rapid),
    g94_clears_feed: false,
    integer_increments: Some(IntegerIncrements {
        mm: 0.001,
        inch: 0.0001,
        deg: 0.001,
    }),
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
        (
            'L',
            Address::Unsupported("subprogram calls (L…) are not supported"),
        ),
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
        ("4", NoMotion(DWELL)),
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
        ("41", Note(COMP)),
        ("42", Note(COMP)),
        ("53", MachineCoordinates),
        ("60", Action::Ignored),
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
        ("54..57", Action::Ignored),
        ("90", Dist(Distance::Absolute)),
        ("91", Dist(Distance::Incremental)),
        ("93", Fm(FeedMode::InverseTime)),
        ("94", Fm(FeedMode::PerMinute)),
        ("95", Unsup(PER_REV)),
        ("96", Action::Ignored),
        ("97", Action::Ignored),
        ("110..112", Unsup(TRANSFORM)),
        ("153", MachineCoordinates),
        ("331", Unsup(THREADS)),
        ("332", Unsup(THREADS)),
        ("450", Action::Ignored),
        ("451", Action::Ignored),
        ("500", Action::Ignored),
        ("505..599", Action::Ignored),
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
        ("3..9", Action::Ignored),
        ("17", ProgramEnd),
        ("19", Action::Ignored),
        ("30", ProgramEnd),
        ("40..45", Action::Ignored),
    ],
    keywords: &[
        ("TRAORI", Action::Tcp(Tcp::On)),
        ("TRAFOOF", Action::Tcp(Tcp::Off)),
        ("TRACYL", Unsup(TRANSFORM)),
        ("TRANSMIT", Unsup(TRANSFORM)),
        ("TRANS", Unsup(TRANSFORM)),
        ("ATRANS", Unsup(TRANSFORM)),
        ("ROT", Unsup(TRANSFORM)),
        ("AROT", Unsup(TRANSFORM)),
        ("SCALE", Unsup(TRANSFORM)),
        ("ASCALE", Unsup(TRANSFORM)),
        ("MIRROR", Unsup(TRANSFORM)),
        ("AMIRROR", Unsup(TRANSFORM)),
        ("CYCLE800", Unsup(TRANSFORM)),
        (
            "CIP",
            Unsup("arcs through an intermediate point (CIP) are not supported"),
        ),
        ("CT", Unsup("tangential arcs (CT) are not supported")),
        ("ASPLINE", Unsup(SPLINES)),
        ("BSPLINE", Unsup(SPLINES)),
        ("CSPLINE", Unsup(SPLINES)),
        ("POLY", Unsup(SPLINES)),
        ("CYCLE81", Unsup(CANNED)),
        ("CYCLE82", Unsup(CANNED)),
        ("CYCLE83", Unsup(CANNED)),
        ("CYCLE84", Unsup(CANNED)),
        ("CYCLE85", Unsup(CANNED)),
        ("CYCLE86", Unsup(CANNED)),
        ("MCALL", Unsup(CANNED)),
        ("CALL", Unsup("subprogram calls are not supported")),
        ("GOTOF", Unsup("control flow is not supported")),
        ("GOTOB", Unsup("control flow is not supported")),
        ("GOTO", Unsup("control flow is not supported")),
        ("IF", Unsup("control flow is not supported")),
        ("WHILE", Unsup("control flow is not supported")),
        ("FOR", Unsup("control flow is not supported")),
        ("REPEAT", Unsup("control flow is not supported")),
        ("LOOP", Unsup("control flow is not supported")),
        ("RET", ProgramEnd),
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
    ],
    initial_motion: Some(Motion::Rapid),
    g94_clears_feed: false,
    integer_increments: None,
};

/// Looks a G or M code up: `code` is the value as written (`1`, `01`, `43.4`).
fn lookup_code(table: &[(&'static str, Action)], value: f64) -> Option<Action> {
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

// ---------------------------------------------------------------------------------------------
// Entry points
// ---------------------------------------------------------------------------------------------

/// Reads a G-code file. Bytes that are not valid UTF-8 (e.g. Latin-1 in comments) are replaced,
/// not rejected.
pub fn read(path: &Path, dialect: Dialect) -> Result<Toolpath> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = String::from_utf8_lossy(&bytes);
    parse(path, &text, dialect)
}

/// Parses G-code text in a built-in dialect; `source` names the file in the result and errors.
pub fn parse(source: &Path, text: &str, dialect: Dialect) -> Result<Toolpath> {
    parse_with(source, text, dialect.spec())
}

/// Parses G-code text with any dialect table.
pub fn parse_with(source: &Path, text: &str, spec: &DialectSpec) -> Result<Toolpath> {
    let mut interp = Interpreter::new(spec, source);
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut last_line = 0;
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        last_line = line;
        let trimmed = raw.trim();
        if trimmed.is_empty() || trimmed.starts_with('%') {
            continue;
        }
        let blocks = split_blocks(spec, raw).map_err(|m| Error::parse(source, line, m))?;
        for block in blocks {
            let block = block.trim();
            if block.is_empty() {
                continue;
            }
            if block.starts_with('/') {
                interp.warn(line, "block delete `/`: block skipped");
                continue;
            }
            let items = lex(spec, block).map_err(|m| Error::parse(source, line, m))?;
            interp.block(line, items)?;
            if interp.ended {
                break;
            }
        }
        if interp.ended {
            break;
        }
    }
    interp.finish(last_line)
}

// ---------------------------------------------------------------------------------------------
// Lexing
// ---------------------------------------------------------------------------------------------

/// Removes comments and splits a line into block texts (more than one only where `;` ends a
/// block). Double-quoted strings are kept whole.
fn split_blocks(spec: &DialectSpec, line: &str) -> std::result::Result<Vec<String>, String> {
    let mut blocks = Vec::new();
    let mut current = String::new();
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        match c {
            '(' if spec.paren_comments => {
                if !chars.by_ref().any(|c| c == ')') {
                    return Err("unclosed `(` comment".to_string());
                }
            }
            ';' => match spec.semicolon {
                Semicolon::Comment => break,
                Semicolon::EndOfBlock => blocks.push(std::mem::take(&mut current)),
            },
            '"' => {
                current.push(c);
                let mut closed = false;
                for q in chars.by_ref() {
                    current.push(q);
                    if q == '"' {
                        closed = true;
                        break;
                    }
                }
                if !closed {
                    return Err("unclosed `\"` string".to_string());
                }
            }
            _ => current.push(c),
        }
    }
    blocks.push(current);
    Ok(blocks)
}

/// A number as written after a letter or `=`.
#[derive(Debug, Clone, Copy)]
struct Num {
    value: f64,
    /// Written with a decimal point (matters under [`DialectSpec::integer_increments`]).
    point: bool,
}

/// One word of a block, resolved through the dialect table.
#[derive(Debug, Clone)]
enum Item {
    /// A letter or named word with a number.
    Word {
        text: String,
        address: Address,
        num: Num,
    },
    /// A keyword the table knows.
    Keyword { text: String, action: Action },
    /// A known word whose value is not a number and does not matter (Sinumerik `T="MILL"`).
    Skipped,
    /// A word the dialect does not know.
    Unknown { text: String },
}

/// Parses the number after a letter or `=`: optional sign, digits with at most one decimal
/// point, at least one digit (no exponents: `E` is a word letter in G-code).
fn number(text: &str) -> Option<Num> {
    let body = text.strip_prefix(['+', '-']).unwrap_or(text);
    let digits = body.chars().filter(char::is_ascii_digit).count();
    let points = body.chars().filter(|&c| c == '.').count();
    if digits == 0 || points > 1 || digits + points != body.len() {
        return None;
    }
    let value: f64 = text.parse().ok()?;
    value.is_finite().then_some(Num {
        value,
        point: points == 1,
    })
}

fn letter_address(spec: &DialectSpec, letter: char) -> Option<Address> {
    spec.letters
        .iter()
        .find(|(l, _)| *l == letter)
        .map(|&(_, a)| a)
}

const EXPRESSIONS: &str = "parameters and expressions (`#`, `[ … ]`) are not supported";

/// Reads `LNUMBER LNUMBER …` (single-letter words, no spaces) into `items`.
fn lex_letters(
    spec: &DialectSpec,
    text: &str,
    items: &mut Vec<Item>,
) -> std::result::Result<(), String> {
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if !c.is_ascii_alphabetic() {
            return Err(match c {
                '#' | '[' | ']' => EXPRESSIONS.to_string(),
                _ => format!("unexpected character `{c}`"),
            });
        }
        let letter = c.to_ascii_uppercase();
        let address = letter_address(spec, letter);
        if let Some(Address::Unsupported(message)) = address {
            return Err(format!("`{letter}` word: {message}"));
        }
        let start = i + 1;
        let mut end = start;
        while end < chars.len() && (chars[end].is_ascii_digit() || "+-.".contains(chars[end])) {
            end += 1;
        }
        let value: String = chars[start..end].iter().collect();
        if end < chars.len() && matches!(chars[end], '#' | '[') {
            return Err(format!("`{letter}` word: {EXPRESSIONS}"));
        }
        let num = if value.is_empty() {
            return Err(format!("`{letter}` has no number"));
        } else {
            number(&value).ok_or_else(|| format!("malformed number `{value}` after `{letter}`"))?
        };
        let text = format!("{letter}{value}");
        items.push(match address {
            Some(address) => Item::Word { text, address, num },
            None => Item::Unknown { text },
        });
        i = end;
    }
    Ok(())
}

/// Splits a Sinumerik-style block at spaces outside `( )` and quotes.
fn split_words(text: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut current = String::new();
    let mut depth = 0usize;
    let mut quoted = false;
    for c in text.chars() {
        match c {
            '"' => quoted = !quoted,
            '(' if !quoted => depth += 1,
            ')' if !quoted => depth = depth.saturating_sub(1),
            _ => {}
        }
        if c.is_whitespace() && depth == 0 && !quoted {
            if !current.is_empty() {
                words.push(std::mem::take(&mut current));
            }
        } else {
            current.push(c);
        }
    }
    if !current.is_empty() {
        words.push(current);
    }
    words
}

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Reads one block's words through the dialect table.
fn lex(spec: &DialectSpec, block: &str) -> std::result::Result<Vec<Item>, String> {
    let mut items = Vec::new();
    match spec.spaces {
        Spaces::Ignored => {
            let compact: String = block.chars().filter(|c| !c.is_whitespace()).collect();
            lex_letters(spec, &compact, &mut items)?;
        }
        Spaces::Separate => {
            for word in split_words(block) {
                lex_separate_word(spec, &word, &mut items)?;
            }
        }
    }
    Ok(items)
}

/// One space-separated word: `NAME=value`, a keyword (two or more letters, optional `( … )`),
/// or letter words (`G1`, `X10`, `G1X10`).
fn lex_separate_word(
    spec: &DialectSpec,
    word: &str,
    items: &mut Vec<Item>,
) -> std::result::Result<(), String> {
    let upper = word.to_ascii_uppercase();
    if let Some((name, value)) = upper.split_once('=')
        && !name.contains('(')
    {
        if !is_identifier(name) {
            return Err(format!("malformed word `{word}`"));
        }
        let address = if name.len() == 1 {
            letter_address(spec, name.chars().next().unwrap_or(' '))
        } else {
            spec.named.iter().find(|(n, _)| *n == name).map(|&(_, a)| a)
        };
        let Some(address) = address else {
            items.push(Item::Unknown {
                text: format!("{name}="),
            });
            return Ok(());
        };
        match address {
            Address::Unsupported(message) => return Err(format!("`{name}=`: {message}")),
            Address::Ignored if number(value).is_none() => items.push(Item::Skipped),
            _ => {
                let num = if value.is_empty() {
                    return Err(format!("`{name}=` has no number"));
                } else {
                    number(value).ok_or_else(|| {
                        format!(
                            "malformed number `{value}` after `{name}=` (expressions are not \
                             supported)"
                        )
                    })?
                };
                items.push(Item::Word {
                    text: format!("{name}={value}"),
                    address,
                    num,
                });
            }
        }
        return Ok(());
    }
    let mut chars = upper.chars();
    let first_two_letters = chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    if first_two_letters {
        let name_end = upper
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(upper.len());
        let (name, rest) = upper.split_at(name_end);
        if !(rest.is_empty() || (rest.starts_with('(') && rest.ends_with(')'))) {
            return Err(format!("malformed word `{word}`"));
        }
        match spec.keywords.iter().find(|(k, _)| *k == name) {
            Some(&(_, Action::Unsupported(message))) => return Err(format!("{name}: {message}")),
            Some(&(_, action)) => items.push(Item::Keyword {
                text: name.to_string(),
                action,
            }),
            None => items.push(Item::Unknown {
                text: name.to_string(),
            }),
        }
        return Ok(());
    }
    lex_letters(spec, &upper, items)
}

// ---------------------------------------------------------------------------------------------
// Interpreting
// ---------------------------------------------------------------------------------------------

/// The words of one block, sorted by meaning.
#[derive(Debug, Default)]
struct Block {
    axes: [Option<Num>; 6],
    centre: [Option<Num>; 3],
    vector: [Option<f64>; 3],
    radius: Option<Num>,
    turns: Option<f64>,
    extra_turns: Option<f64>,
    feed: Option<f64>,
    /// Codes and keywords in the order written, with their text.
    actions: Vec<(String, Action)>,
}

/// The modal G94 feed.
#[derive(Debug, Clone, Copy)]
struct ModalFeed {
    /// Linear feed, mm/min.
    mm_per_min: f64,
    /// F as written (degrees per minute on rotary-only moves).
    raw: f64,
}

const AXIS_NAMES: [char; 6] = ['X', 'Y', 'Z', 'A', 'B', 'C'];

struct Interpreter<'a> {
    spec: &'a DialectSpec,
    source: &'a Path,
    units: Units,
    feed_units: Units,
    distance: Distance,
    arc_distance: Distance,
    plane: Plane,
    feed_mode: FeedMode,
    feed: Option<ModalFeed>,
    motion: Option<Motion>,
    tcp: Tcp,
    /// Modal position: X Y Z in mm, A B C in degrees.
    pos: [f64; 6],
    /// X Y Z set by an absolute word.
    known: [bool; 3],
    unknown_warned: [bool; 3],
    vector: Vector3<f64>,
    saw_rotary: bool,
    /// A warning about motion outside TCP mode was given for the current stretch.
    non_tcp_warned: bool,
    ended: bool,
    points: Vec<ClPoint>,
    warnings: Vec<Warning>,
}

impl<'a> Interpreter<'a> {
    fn new(spec: &'a DialectSpec, source: &'a Path) -> Self {
        Interpreter {
            spec,
            source,
            units: Units::Mm,
            feed_units: Units::Mm,
            distance: Distance::Absolute,
            arc_distance: Distance::Incremental,
            plane: Plane::Xy,
            feed_mode: FeedMode::PerMinute,
            feed: None,
            motion: spec.initial_motion,
            tcp: Tcp::Off,
            pos: [0.0; 6],
            known: [false; 3],
            unknown_warned: [false; 3],
            vector: Vector3::new(0.0, 0.0, 1.0),
            saw_rotary: false,
            non_tcp_warned: false,
            ended: false,
            points: Vec::new(),
            warnings: Vec::new(),
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::parse(self.source, line, message)
    }

    fn warn(&mut self, line: usize, message: impl Into<String>) {
        self.warnings.push(Warning {
            line,
            message: message.into(),
        });
    }

    fn finish(mut self, last_line: usize) -> Result<Toolpath> {
        if self.points.is_empty() {
            return Err(self.error(last_line.max(1), "no motion blocks"));
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
        })
    }

    /// Sorts a block's words, warning about unknown ones.
    fn collect(&mut self, line: usize, items: Vec<Item>) -> Result<Block> {
        let mut block = Block::default();
        let name = self.spec.name;
        for item in items {
            let (text, address, num) = match item {
                Item::Word { text, address, num } => (text, address, num),
                Item::Keyword { text, action } => {
                    block.actions.push((text, action));
                    continue;
                }
                Item::Skipped => continue,
                Item::Unknown { text } => {
                    self.warn(
                        line,
                        format!("unknown word `{text}` (not a {name} word): ignored"),
                    );
                    continue;
                }
            };
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
                Address::Axis(i) => {
                    duplicate(block.axes[i].is_some())?;
                    block.axes[i] = Some(num);
                }
                Address::ArcCentre(i) => {
                    duplicate(block.centre[i].is_some())?;
                    block.centre[i] = Some(num);
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
                        Some(action) => block.actions.push((text, action)),
                        None => self.warn(
                            line,
                            format!("unknown word `{text}` (not a {name} code): ignored"),
                        ),
                    }
                }
                Address::Ignored => {}
                Address::Unmodelled(message) => self.warn(line, format!("`{text}`: {message}")),
                Address::Unsupported(message) => {
                    return Err(self.error(line, format!("{text}: {message}")));
                }
            }
        }
        Ok(block)
    }

    /// Scale of a length word (mm per written unit), honouring integer increments.
    fn length(&self, num: Num) -> f64 {
        let scale = match (self.spec.integer_increments, num.point) {
            (Some(inc), false) => match self.units {
                Units::Mm => inc.mm,
                Units::Inch => inc.inch * MM_PER_INCH,
            },
            _ => self.units.mm_per_unit(),
        };
        num.value * scale
    }

    fn angle(&self, num: Num) -> f64 {
        match (self.spec.integer_increments, num.point) {
            (Some(inc), false) => num.value * inc.deg,
            _ => num.value,
        }
    }

    /// Interprets one block.
    fn block(&mut self, line: usize, items: Vec<Item>) -> Result<()> {
        let block = self.collect(line, items)?;

        // Modal settings first (feed mode, F, units, plane, distance, TCP), then the motion.
        let mut motion_code: Option<(&str, Motion)> = None;
        let mut machine = false;
        let mut no_motion: Option<&str> = None;
        let mut end = false;
        for (text, action) in &block.actions {
            match *action {
                Action::FeedMode(mode) => {
                    if (self.spec.g94_clears_feed && mode == FeedMode::PerMinute)
                        || (self.feed_mode == FeedMode::InverseTime && mode != self.feed_mode)
                    {
                        self.feed = None;
                    }
                    self.feed_mode = mode;
                }
                Action::Motion(m) => {
                    if let Some((other, _)) = motion_code {
                        return Err(self.error(
                            line,
                            format!("two motion codes in one block: {other} and {text}"),
                        ));
                    }
                    motion_code = Some((text.as_str(), m));
                }
                Action::MotionCancel => self.motion = None,
                Action::Plane(p) => self.plane = p,
                Action::Units { units, feed } => {
                    self.units = units;
                    if feed {
                        self.feed_units = units;
                    }
                }
                Action::Distance(d) => self.distance = d,
                Action::ArcDistance(d) => self.arc_distance = d,
                Action::Tcp(t) => {
                    if t != self.tcp {
                        self.non_tcp_warned = false;
                    }
                    self.tcp = t;
                }
                Action::MachineCoordinates => machine = true,
                Action::NoMotion(message) => {
                    no_motion = Some(message);
                    self.warn(line, format!("{text}: {message}"));
                }
                Action::ProgramEnd => end = true,
                Action::Ignored => {}
                Action::Note(message) => self.warn(line, format!("{text}: {message}")),
                Action::Unsupported(message) => {
                    return Err(self.error(line, format!("{text}: {message}")));
                }
            }
        }
        if let Some(f) = block.feed {
            if f < 0.0 {
                return Err(self.error(line, format!("F{f}: a feed cannot be negative")));
            }
            if self.feed_mode == FeedMode::PerMinute {
                self.feed = (f > 0.0).then(|| ModalFeed {
                    mm_per_min: f * self.feed_units.mm_per_unit(),
                    raw: f,
                });
            }
        }
        if let Some((_, m)) = motion_code {
            self.motion = Some(m);
        }

        let has_axes = block.axes.iter().any(Option::is_some);
        let has_vector = block.vector.iter().any(Option::is_some);
        let has_centre = block.centre.iter().any(Option::is_some);
        let is_arc = matches!(self.motion, Some(Motion::ArcCw | Motion::ArcCcw));
        let ijk_vector = self.tcp == Tcp::OnIjkVector && !is_arc;
        let moves = no_motion.is_none()
            && (has_axes || has_vector || (has_centre && (ijk_vector || is_arc)));
        if moves {
            self.motion_block(line, &block, machine)?;
        } else if no_motion.is_none() && (has_centre || block.radius.is_some()) {
            self.warn(line, "I/J/K or R without a move: ignored");
        }
        if end {
            self.ended = true;
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
        if machine {
            if is_arc {
                return Err(self.error(line, "G53 (machine coordinates) with an arc"));
            }
            self.warn(
                line,
                "G53: machine-coordinate move taken as program coordinates",
            );
        }

        let start = self.pos;
        let mut end = start;
        for (i, word) in block.axes.iter().enumerate() {
            let Some(num) = *word else { continue };
            let value = if i < 3 {
                self.length(num)
            } else {
                self.angle(num)
            };
            if !value.is_finite() {
                return Err(self.error(line, format!("{}: value out of range", AXIS_NAMES[i])));
            }
            let incremental = self.distance == Distance::Incremental && !machine;
            end[i] = if incremental { start[i] + value } else { value };
            if i < 3 && !incremental {
                self.known[i] = true;
            }
            if i >= 3 {
                self.saw_rotary = true;
            }
        }
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
            let largest = v.amax();
            let scaled_norm = if largest > 0.0 {
                (v / largest).norm()
            } else {
                0.0
            };
            if largest * scaled_norm < MIN_TOOL_VECTOR_NORM {
                return Err(self.error(
                    line,
                    format!("tool vector ({}, {}, {}) has no direction", v.x, v.y, v.z),
                ));
            }
            self.vector = v / largest / scaled_norm;
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

        if self.tcp == Tcp::Off
            && !self.non_tcp_warned
            && (end[3..] != [0.0; 3]
                || block.axes[3..].iter().any(Option::is_some)
                || vector_words.iter().any(Option::is_some))
        {
            self.non_tcp_warned = true;
            self.warn(
                line,
                "motion with rotary axes or a tool vector outside tool-tip (TCP) mode: X Y Z \
                 taken as the tool tip",
            );
        }

        if is_arc {
            self.arc(line, motion, block, start, end)?;
        } else {
            let feed = self.linear_feed(line, motion, block, &start, &end)?;
            self.push(line, &end, feed);
        }
        self.pos = end;
        Ok(())
    }

    fn push(&mut self, line: usize, q: &[f64; 6], feed: Feed) {
        self.points.push(ClPoint {
            p: Vector3::new(q[0], q[1], q[2]),
            o: self.vector,
            feed,
            rotary: Some([q[3], q[4], q[5]]),
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
        &self,
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
        let Some(feed) = self.feed else {
            return Ok(Feed::Unspecified);
        };
        let moves_xyz = (0..3).any(|i| (end[i] - start[i]).abs() > XYZ_MOVE_THRESHOLD_MM);
        let rotary = (3..6)
            .map(|i| (end[i] - start[i]).powi(2))
            .sum::<f64>()
            .sqrt();
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
        let (a, b, n) = self.plane.axes();
        let plane = self.plane.code();
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
        let ccw = motion == Motion::ArcCcw;
        let (s0, s1) = (start[a], start[b]);
        let (e0, e1) = (end[a], end[b]);
        let chord = (e0 - s0).hypot(e1 - s1);
        let in_plane = block.centre[a].is_some() || block.centre[b].is_some();

        let (c0, c1) = if let Some(r) = block.radius {
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
            match self.arc_distance {
                Distance::Incremental => (s0 + word(a), s1 + word(b)),
                Distance::Absolute => (word(a), word(b)),
            }
        };

        let r_start = (s0 - c0).hypot(s1 - c1);
        let r_end = (e0 - c0).hypot(e1 - c1);
        let mismatch = (r_end - r_start).abs();
        if mismatch > ARC_RADIUS_MISMATCH_MM
            && mismatch > ARC_RADIUS_MISMATCH_RELATIVE * r_start.max(r_end)
        {
            return Err(self.error(
                line,
                format!(
                    "arc end point is not on the circle: radius {r_end:.4} mm at the end, \
                     {r_start:.4} mm at the start"
                ),
            ));
        }
        if r_start == 0.0 || r_end == 0.0 {
            return Err(self.error(line, "arc centre coincides with its start or end point"));
        }

        let theta_s = (s1 - c1).atan2(s0 - c0);
        let theta_e = (e1 - c1).atan2(e0 - c0);
        let tau = std::f64::consts::TAU;
        let mut sweep = if chord < FULL_CIRCLE_MM {
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
        let step = 2.0 * (1.0 - MAX_CHORD_ERROR_MM / r_max).max(-1.0).acos();
        let chords = ((sweep.abs() / step).ceil() as usize).max(1);
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
            FeedMode::PerMinute => {
                let feed = match self.feed {
                    Some(f) => Feed::Programmed(f.mm_per_min / 60.0),
                    None => Feed::Unspecified,
                };
                for q in &qs {
                    self.push(line, q, feed);
                }
            }
        }
        Ok(())
    }
}
