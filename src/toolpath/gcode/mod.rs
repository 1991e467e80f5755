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
//!   `G20`/`G21`; the motion mode starts as G0. **Numbers without a decimal point**: in X Y Z
//!   A B C, I J K (arc centres and the `G68.2` angles; a `G43.5` tool vector is normalised, so
//!   its scale does not matter), R and Q one counts least input increments (0.001 mm, 0.0001
//!   inch, 0.001°; `G4 X2500` is 2.5 s), Fanuc's default with parameter 3401#0 DPI = 0.
//!   Calculator-type input (DPI = 1: `X100` is 100 mm, as LinuxCNC, grbl and Mach3 read it) is
//!   chosen by [`Settings::decimal_point_input`] (the CLI's `--decimal-point-input`) or the
//!   machine file's `decimal_point_input` (the settings win). Where neither chooses, the first
//!   such word whose value is not 0 is one warning (not one per word) naming it, what it was
//!   read as and how to choose (a 0 reads the same either way). Read as written under both:
//!   F under G94 (F is in whole mm/min, or inch/min under G20, on these controls: `F600` is
//!   600 mm/min), `G4 P` and cycle `P` (milliseconds: P takes no decimal point), S, T, H, D,
//!   N, the repeat counts K and L, and program numbers. An F without a decimal point under
//!   `G95` is an error (see Feeds).
//! * [`SINUMERIK`]: `;` comments (parentheses are not comments); spaces separate words, which
//!   may be keywords (`TRAORI`, `MSG("…")`) or `NAME=value`; TCP on `TRAORI`, off `TRAFOOF`;
//!   tool vector `A3= B3= C3=`; `CR=` radius, `TURN=` extra turns; `G70`/`G71` inch/mm for
//!   geometry only, `G700`/`G710` for F too; the motion mode starts as G0.
//! * [`HEIDENHAIN`]: TNC 640 Klartext, not G-code: a block number and a statement whose first
//!   word says what it is (`L X+10 FMAX`, `CC`, `C … DR+`, `CYCL DEF 200`, `PLANE SPATIAL`).
//!   Its own lexer ([`klartext`]) turns each block into the words this interpreter reads, and
//!   the table holds the path functions, statements, named words and M functions; what they
//!   do is described in [`klartext`] and the interpreter's Klartext part. Subprograms are
//!   labels ([`Subprograms::Labels`]). TCP on `M128` / `FUNCTION TCPM`, off `M129` /
//!   `FUNCTION RESET TCPM`; tool vector `TX TY TZ` on `LN` blocks.
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
//!   [`Feed::BlockTime`] = distance / (F/60) s (F as written, not inch-scaled). That is the
//!   rule of LinuxCNC, Sinumerik (F applies to the geometry axes, the default FGROUP) and
//!   Klartext ([`RotaryFeed::Xyz`]). A Fanuc control feeds a block that turns a rotary axis,
//!   with or without linear axes, along the combined distance ([`RotaryFeed::Combined`]):
//!   outside tool-tip mode such a block gets [`Feed::BlockTime`] = √(ΔX²+ΔY²+ΔZ²+ΔA²+ΔB²+ΔC²)
//!   / (F/60) s, X Y Z in F's unit (mm, or inch under G20) and A B C in degrees, so
//!   `G91 G1 X20 C40 F300` takes √(20²+40²)/300 min = 8.94 s (Fanuc operator's manual,
//!   "Linear interpolation (G01)"); a pure rotary block is the same |ΔA B C|/F as above. A
//!   Haas control, read in this dialect, instead turns degrees into a length through the
//!   rotary axis' diameter (settings 34/79): where the machine file gives it as the axis'
//!   `feed_diameter` D (mm), a degree of that axis counts as π·D/360 mm in the combined
//!   distance, with or without X Y Z; without it each such block warns. Arcs keep F along
//!   the chords in every dialect. A feed move before any F, after `F0`, or after a mode change
//!   forgot F is an error naming its line: every control stops there (LinuxCNC "Cannot do G1
//!   with zero feed rate", Fanuc alarm PS0011, Sinumerik alarm 10860); it is not a move at the
//!   machine's maximum feed. Under `G93` (inverse time) every G1/G2/G3
//!   block must carry its own F (an error naming the line otherwise) and gets
//!   [`Feed::BlockTime`] = 60/F s; on an arc that time is split over the chords in proportion to
//!   their length. Leaving G93 forgets F (LinuxCNC: every `G94` sets F to 0), so a feed move must
//!   program F again. Under `G95` (feed per revolution) F is mm (inch under G20) per spindle
//!   revolution and a feed move gets [`Feed::Programmed`] F × S, S the spindle speed (rpm)
//!   programmed last before it (rigid tapping `G95 M29 S500` … `G84 … F1.75` taps at 875
//!   mm/min); a feed move under G95 with an F but no S before it, after `S0`, or under `G96`
//!   (constant surface speed: S is a cutting speed, the rpm follows the diameter, and it is
//!   not recorded as a spindle speed) is an error naming its line. A change to or from G95 forgets F too (F per minute and per revolution
//!   are different quantities; LinuxCNC sets F to 0). Sinumerik's `G96` and `G97` are in the
//!   feed-type group: both are feed per revolution (G96 with a cutting speed, so an error at
//!   the first feed move). A Fanuc F without a decimal point under G95 is an error: the control
//!   reads it in units its parameters set (0.01 or 0.001 mm per revolution on many).
//! * **Tool-tip mode (TCP).** The codes above switch it on and off. In TCP mode X Y Z are the
//!   tool tip in workpiece coordinates and A B C the rotary axis positions. Outside it, on a
//!   five-axis machine whose kinematics the reader has ([`MachineContext::kinematics`]), X Y Z
//!   A B C are where the control moves the axes (X Y Z as at zero rotary angles, where they
//!   are the tip): with every rotary axis at zero nothing changes; with one off zero the CL
//!   point is the tip the forward kinematics gives, and a block that turns a rotary axis
//!   becomes CL points along the tip's curve as the axes move linearly (chords within
//!   [`MAX_CHORD_ERROR_MM`], the last one the block's end), its time the F rule's above
//!   ([`Feed::BlockTime`] split evenly; a rapid stays a rapid). Under a frame that maps X Y Z
//!   (Klartext `PLANE`, `CYCLE800`, `G68.2`, a rotation) X Y Z stay the tip in the frame's
//!   coordinates, but a block that turns rotary axes alone turns them with the linear axes
//!   standing, the tip carried along. Switching TCP on or off, or a Klartext frame, keeps the
//!   axes where they are and re-expresses the position the next block starts from. An arc
//!   that turns a rotary axis outside TCP is an error. Without the kinematics (a library read
//!   without a machine), or under a frame, or with a tool vector, X Y Z are taken as the tool
//!   tip with one warning per stretch of such blocks.
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
//! * **G53**, Sinumerik **SUPA** (machine coordinates, one block): the move is included, its
//!   words read as machine coordinates = program coordinates + the machine's work offset
//!   ([`MachineContext::work_offset`]: a trunnion's `kinematics.work-offset`, else the machine
//!   file's `work_offset`; zero without either), with a warning saying so, which names
//!   `work_offset` where the file gives none (so does a G28/G30 of X, Y or Z).
//! * **G28/G30** (`G91 G28 Z0`, `G28 X0 Y0 B0`, `G30 P3 …`): a rapid to the intermediate point
//!   the words give, then a rapid of the named axes to their reference point, read from the
//!   machine file's `reference`. Where the file gives none, machine zero (machine coordinate
//!   0): the controls' default (Fanuc parameters 1240–1243 and LinuxCNC 5161–5169 /
//!   5181–5189 are 0, and Fanuc's machine zero is set at the reference position), with a
//!   warning naming `axes.Z.reference` and [`Assumed::reference_at_machine_zero`] (the
//!   summary's `reference` line and `--json` field).
//! * **Canned cycles and dwells**: see [`cycles`]; `G4` (P seconds on LinuxCNC, P ms or X
//!   seconds on Fanuc, F seconds on Sinumerik) and every cycle dwell become
//!   [`crate::toolpath::Dwell`]s: the tool stops there and the time counts.
//! * **Variables and expressions**: see [`expr`] (Sinumerik `DEF`, R parameters, Fanuc `#n`).
//! * **Frames**: see [`frames`] (`TRANS`/`ROT`/`ATRANS`/`AROT`, `CYCLE800`, `G68.2`).
//! * **Chamfers and roundings** between two straight feed moves: Fanuc's (and Haas')
//!   `,C` / `,R` on a G1 block (`G1 X50. ,R5.`: blanks between are ignored, and a number
//!   without a decimal point is a length like X's), Sinumerik `CHR=` (the chamfer's leg, as
//!   `,C`), `CHF=` (its length) and `RND=` (as `,R`). The corner at the end of the move is cut
//!   from t before it to t after it along the two moves (t the leg, L / (2 cos(θ/2)) for a
//!   chamfer of length L, R tan(θ/2) for a rounding, θ the turn), the rounding an arc of radius
//!   R in chords within [`MAX_CHORD_ERROR_MM`], at the first move's line and feed. What is not
//!   modelled is an error naming the word: the next move an arc, a rapid, after a dwell, a
//!   cycle, a tool or spindle change, or turning a rotary axis; no next move; moves too short
//!   for it, in line or reversed (the controls alarm there too); Sinumerik `RNDM=` (modal) and
//!   `FRC=`/`FRCM=` (a feed of the corner's own) other than 0.
//! * **Work offsets**: see [`offsets`]. `G54`–`G59` (LinuxCNC `G59.1`–`G59.3`, Fanuc
//!   `G54.1 P…`, Sinumerik `G500` and `G505`–`G599`) select one; `G10 L2` / `L20` set one (LinuxCNC P0–P9,
//!   Fanuc P0 the external offset, P1–P6, and `L20` the extended offsets), `G52` shifts
//!   them all (`G52 X0 Y0` cancels; LinuxCNC `G92.1`/`G92.2` too) and `G92` shifts them so that
//!   the current position has the coordinates named: the points follow as on the
//!   control, the tool staying where it is when the offset changes. Where a move's length
//!   would depend on values the program does not give — a `G10 L2` of the offset in force
//!   after moves in it, in machine coordinates — it is an error naming the `G10` and the move;
//!   a change relative to the current one (LinuxCNC `G10 L20`, Fanuc `G91 G10 L2`) is exact,
//!   and a `G10` before the first move, or of an offset not used after it, is no error. A
//!   change to an offset the program never set is a warning: the move is sized as if the two
//!   were equal. Other `G10` (tool data `L1`, `L10`–`L13`, parameters `L50`) moves nothing and
//!   is a warning; `G10 L2 R` (a rotation) is an error, as is `G52` under G91 while a shift is
//!   in force (an increment on some controls, a value on others).
//! * **Sinumerik units**: `G70`/`G71` change the geometry only; F stays in the control's basic
//!   system, taken as the unit the program selects first (a warning when that is inch);
//!   `G700`/`G710` change F too.
//! * **Bounds**: an axis word beyond ±[`MAX_COORDINATE_MM`] is an error naming it; an arc needs
//!   at most [`MAX_ARC_CHORDS`] chords (so `P1000000000` turns or `TURN=100000000` are errors
//!   before any work); exponent notation (`X1e309`) is an error naming the word. The whole
//!   program makes at most [`crate::toolpath::MAX_POINTS`] CL points: an arc, a cycle (with
//!   its repeats) or a block that would take it past that is an error naming its line, before
//!   its points are made, however the program got there (repeats, calls, jumps).
//! * **Fanuc macro control flow**: `WHILE [#1 LT 3.] DO1` … `END1`, `IF [cond] GOTO n`,
//!   `GOTO n`, `IF [cond] THEN #1=5.` with `EQ NE GT GE LT LE` and `AND OR XOR` (module
//!   `macro_b`); every block a loop runs counts against the bound on blocks a program may run
//!   ([`subprograms::MAX_EXPANDED_BLOCKS`]), and a jump back with no macro variable changed
//!   since it was last taken is an error at once, so no program hangs.
//! * **Subprograms in the file**: see [`subprograms`] (Fanuc/Haas `M98 P L` with `O<n> … M99`,
//!   Sinumerik `PROC NAME … RET` and `L123`, LinuxCNC `o100 sub` / `o100 call`): expanded
//!   where called, nesting and expansion bounded; a call of one not in the file is an error.
//! * **The machine**: with [`parse_for`] and a [`MachineContext`], an axis word for an axis the
//!   machine lacks is an error naming the axis.
//!
//! # What is accepted and ignored
//!
//! Line numbers `N`; `S`, `T`, `H`, `D` and the other parameter letters of the table; M codes
//! of the table (spindle, coolant, tool change, pauses; Sinumerik `M202(0.0059)` arguments);
//! `G40`, `G43` (LinuxCNC), `G49`, path control
//! `G61`/`G64`; Haas `G254`/`G255` (dynamic work offset: the program is read in workpiece
//! coordinates either way; `G234` is TCP on); `%` lines; blank lines; nested `(( ))` comments. Program
//! end (`M2`, `M30`; in the main program also Sinumerik `M17`, `RET`, Fanuc `M99`) stops
//! reading: later lines are not parsed. Cutter radius compensation `G41`/`G42` (Klartext
//! `RL`/`RR`) is an error, as it moves the tool off the programmed path, unless the machine
//! context says the path is the tool centre's with wear-only offsets
//! ([`crate::toolpath::MachineContext::wear_compensation`]): then a warning. A block starting with `/` (block delete, or `/1` … `/9`)
//! runs, as on a control whose block-skip switch is off, or is skipped under
//! [`Settings::block_delete`]; either way with a warning. I J K or R on a straight move (outside G43.5) or without a
//! move are skipped with a warning. U V W axis words are errors: they move an axis feedopt
//! does not model.
//!
//! # What is rejected
//!
//! * A G code the dialect does not know is an **error** naming it (a G code may move the tool).
//!   So is a Sinumerik name the table does not know, written alone (`TRAOOF`: letters only, no
//!   value, no `=`): on an 840D a bare name is a command or a subprogram call, either of which
//!   may change the motion (a post's typo `TRAOOF` for `TRAFOOF` left TRAORI on); the message
//!   names the keyword one or two letters away, if there is one. Any other unknown word
//!   (letter, M code, named word) is skipped with a [`Warning`] naming the word and its line,
//!   never silently.
//! * Errors ([`crate::error::Error::Parse`] naming the file and line): a malformed number (`X1.2.3`, `Y-`,
//!   `F`), an unclosed `(` comment, a parameter read before it is set, Sinumerik `IC(..)`,
//!   LinuxCNC O-word control flow (`if`, `while`, …), the same word twice in a block, two motion codes in one
//!   block, axis words without a motion mode, a G93 feed block without F, a negative F,
//!   impossible arcs, and codes that move the tool in ways a list of CL points cannot follow
//!   silently: the stored `G92` shift (`G92.3`), splines, threading, probing, polar coordinates, scaling,
//!   mirroring, calls of subprograms not in the file, Haas `M97`, Sinumerik
//!   `CYCLE76`/`CYCLE77` (spigot milling), and the Sinumerik words that give an end point or
//!   the tool's orientation another way (`ANG=`; `A2= B2= C2=`, `LEAD= TILT=`, `THETA= PHI=
//!   PSI=`, `A4=`…`C5=`, `XH= YH= ZH=`: under TRAORI the control turns the rotary axes to them).

pub mod cycles;
mod dialect;
pub mod expr;
pub mod frames;
mod interp;
pub mod klartext;
mod lexer;
mod macro_b;
pub mod offsets;
pub mod subprograms;

use std::path::Path;

use crate::error::Result;
pub use crate::toolpath::Units;
use crate::toolpath::{Assumed, MachineContext, Toolpath};
#[allow(unused_imports)] // named by the module docs
use crate::toolpath::{ClPoint, Feed, Warning};
pub use dialect::*;
use interp::Interpreter;
pub use interp::{MAX_ARC_CHORDS, MAX_COORDINATE_MM};
use subprograms::Program;

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

/// File extensions read as G-code (Heidenhain Klartext: `.h`).
pub const EXTENSIONS: &[&str] = &["ngc", "nc", "gcode", "tap", "h"];

// ---------------------------------------------------------------------------------------------
// Entry points
// ---------------------------------------------------------------------------------------------

/// Reads a G-code file. Bytes that are not valid UTF-8 (e.g. Latin-1 in comments) are replaced,
/// not rejected.
pub fn read(path: &Path, dialect: Dialect) -> Result<Toolpath> {
    let bytes = crate::toolpath::read_bytes(path)?;
    let text = String::from_utf8_lossy(&bytes);
    parse(path, &text, dialect)
}

/// Parses G-code text in a built-in dialect; `source` names the file in the result and errors.
pub fn parse(source: &Path, text: &str, dialect: Dialect) -> Result<Toolpath> {
    parse_with(source, text, dialect.spec())
}

/// Parses G-code text with any dialect table.
pub fn parse_with(source: &Path, text: &str, spec: &DialectSpec) -> Result<Toolpath> {
    parse_for(source, text, spec, None)
}

/// Parses G-code text with any dialect table for a machine: axis words for axes it lacks are
/// errors, and `G28`/`G30`/`G53`/`SUPA` use its reference positions and work offset.
pub fn parse_for(
    source: &Path,
    text: &str,
    spec: &DialectSpec,
    machine: Option<&MachineContext>,
) -> Result<Toolpath> {
    parse_assumed(source, text, spec, machine, &[]).map(|(toolpath, _)| toolpath)
}

/// A cycle alias `FROM=TO` (`CYCLE76=CYCLE86`): a Sinumerik cycle a machine builder or a post
/// names `FROM`, read as the standard cycle `TO` (one feedopt expands: `CYCLE81`–`CYCLE89`).
/// For machines whose own cycle works like a standard one; the reader warns where it applies
/// one. Names are case-insensitive; an alias that is not two such names is an error saying
/// what to write.
pub fn parse_cycle_alias(text: &str) -> Result<(String, String)> {
    let bad = |why: &str| {
        crate::error::Error::Usage(format!(
            "cycle alias `{text}`: {why}; write FROM=TO with Sinumerik cycle names, e.g. \
             CYCLE76=CYCLE86"
        ))
    };
    let (from, to) = text.split_once('=').ok_or_else(|| bad("no `=`"))?;
    let name = |s: &str| -> Option<(String, u32)> {
        let upper = s.trim().to_ascii_uppercase();
        let n: u32 = upper.strip_prefix("CYCLE")?.parse().ok()?;
        Some((upper, n))
    };
    let (from, _) = name(from).ok_or_else(|| bad("the name before `=` is not CYCLE<number>"))?;
    let (to, n) = name(to).ok_or_else(|| bad("the name after `=` is not CYCLE<number>"))?;
    if !(81..=89).contains(&n) {
        return Err(bad(&format!(
            "{to} is not a cycle feedopt expands (CYCLE81–CYCLE89)"
        )));
    }
    if from == to {
        return Err(bad("a cycle cannot be its own alias"));
    }
    Ok((from, to))
}

/// As [`parse_for`], with cycle aliases ([`parse_cycle_alias`]: a cycle called by the first
/// name is read as the second), and what the reader assumed where the machine file is silent
/// (each assumption is also a warning with its line).
pub fn parse_assumed(
    source: &Path,
    text: &str,
    spec: &DialectSpec,
    machine: Option<&MachineContext>,
    cycle_aliases: &[(String, String)],
) -> Result<(Toolpath, Assumed)> {
    let settings = Settings {
        cycle_aliases: cycle_aliases.to_vec(),
        ..Settings::default()
    };
    parse_configured(source, text, spec, machine, &settings)
}

/// What a control's operator sets rather than the program, and feedopt cannot read from it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Settings {
    /// Cycles read under another name ([`parse_cycle_alias`]).
    pub cycle_aliases: Vec<(String, String)>,
    /// The block-skip switch (block delete): `true` skips every block that starts with `/`
    /// (any skip level: `/`, `/1` … `/9`), as a control with the switch on does; `false`, the
    /// default, runs them, as with the switch off (a program run once, as posted: a post's
    /// `/M30` ends it). Each such block is a warning either way, naming what was done.
    pub block_delete: bool,
    /// The diameter of the tool in the spindle, mm, for a cycle whose path depends on it
    /// (Klartext `CYCL DEF 208`, bore milling): a control takes it from its tool table, which
    /// the program does not carry. `None`: such a cycle is an error that says so.
    pub tool_diameter: Option<f64>,
    /// How a Fanuc control reads a number without a decimal point (parameter 3401#0, DPI),
    /// before the machine file's `decimal_point_input`. Where neither says, as least input
    /// increments (Fanuc's default), with one warning at the first such word whose value is
    /// not 0. The other dialects have no such setting and ignore it.
    pub decimal_point_input: Option<crate::machine::DecimalPointInput>,
    /// Where a call of a subprogram the program does not hold (Fanuc `M98 P1002`, LinuxCNC
    /// `o<name> call`, Sinumerik `NAME`, `L1234`, `EXTCALL "NAME"`) looks for its file, after
    /// the main program's own directory, in order (the CLI's `--subprogram-dir`). See
    /// [`subprograms`] for the file names each dialect's calls look for.
    pub subprogram_dirs: Vec<std::path::PathBuf>,
    /// Nothing named the program's dialect (neither the program, nor its extension, nor the
    /// user): it is read in one chosen for it (`feedopt gcode` reads it in the written
    /// program's). A number without a decimal point that this dialect reads as least input
    /// increments, where nothing chose that reading, is then an error naming it: the default
    /// dialect, LinuxCNC's, which `feedopt solve` reads such a program in, reads it as
    /// written, and the two readings are two paths (a Fusion 360 program's `Z3` clearance
    /// written to Fanuc as `Z0.003`).
    pub dialect_unnamed: bool,
    /// Nothing named the dialect the program is read in (not the user, nor the program's
    /// content, nor an extension that belongs to one control: `.ngc`, `.mpf`, `.spf`, `.h`):
    /// where the dialects' readings of a feed differ (a block that turns a rotary axis while
    /// X, Y or Z move), the first such block warns, naming the other reading.
    pub dialect_defaulted: bool,
}

/// As [`parse_assumed`], under the operator's `settings`.
pub fn parse_configured(
    source: &Path,
    text: &str,
    spec: &DialectSpec,
    machine: Option<&MachineContext>,
    settings: &Settings,
) -> Result<(Toolpath, Assumed)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let text = program_header(spec, source, text)?;
    let mut program = Program::scan(spec, source, &text)?;
    program.search_in(source, &settings.subprogram_dirs);
    let mut interp = Interpreter::new(spec, source, machine);
    interp.procs = program.proc_names();
    interp.subprogram_search = program.search();
    interp.cycle_aliases = settings.cycle_aliases.clone();
    interp.block_delete = settings.block_delete;
    interp.tool_diameter = settings.tool_diameter;
    interp.set_decimal_point_input(settings.decimal_point_input);
    interp.dialect_unnamed = settings.dialect_unnamed;
    interp.dialect_defaulted = settings.dialect_defaulted;
    program.run(spec, &mut interp, source)?;
    if settings.dialect_unnamed
        && let Some(message) = interp.increments_unnamed_dialect()
    {
        return Err(program.localize(message, source));
    }
    interp.note_units();
    interp.note_assumed_parameters();
    let assumed = interp.assumed;
    let mut toolpath = interp
        .finish(program.last_line())
        .map_err(|e| program.localize(e, source))?;
    toolpath.files = program.included();
    Ok((toolpath, assumed))
}

/// The first line of a program that holds code: not blank, not a `%` line, not a `( … )`
/// comment line. Returns its 0-based index and its text.
fn first_code_line(text: &str) -> Option<(usize, &str)> {
    text.lines().enumerate().find(|(_, l)| {
        let l = l.trim();
        !l.is_empty() && !l.starts_with('%') && !l.starts_with('(')
    })
}

/// Whether a (trimmed) line starts with ISO code's program number `:1234`.
fn starts_with_colon_number(line: &str) -> bool {
    line.strip_prefix(':')
        .is_some_and(|rest| rest.starts_with(|c: char| c.is_ascii_digit()))
}

/// What the head of a program says before its blocks are read.
///
/// * **ISO code's program number.** Fanuc's program number is `O1234`, and "in ISO code, the
///   colon (`:`) can be used instead of O" (Fanuc operator's manuals, "Program number";
///   older Fanuc 0 and 6 controls punch and send `:` on their own, and NX's posts for Fadal and
///   Fanuc 0M write `:1234 (PROGRAM)`). In a dialect whose programs are headed `O1234`
///   ([`Subprograms::OPrograms`]), a first code line `:1234` is read as `O1234` (the same
///   length, so every line keeps its number). A `:` word further down is not taken for a
///   program number (an `O` there starts a subprogram, which would end the main program
///   silently): the lexer names it as an error.
/// * **Heidenhain DIN/ISO.** A TNC's ISO program starts `%NAME G71 *` (G70: inch), as NX's
///   Mikron WF21D post writes it: the TNC's ISO dialect, not Fanuc's or LinuxCNC's (G70/G71
///   are its units, G30/G31 the blank form, M91/M92 machine positions). That first line is an
///   error saying so and naming Klartext, which feedopt reads, instead of an error further
///   down about a word whose meaning differs.
/// * **Okuma OSP.** An Okuma program file starts with `$NAME.MIN%` (`.SSB`, `.SDF`, `.LIB`
///   likewise): OSP's own language (`VC` variables, `CALL O…`, labels `N…` as jump targets,
///   `G15 H` work offsets), which feedopt does not read. That first line is an error saying so,
///   not "unexpected character `$`".
fn program_header<'t>(
    spec: &DialectSpec,
    source: &Path,
    text: &'t str,
) -> Result<std::borrow::Cow<'t, str>> {
    if let Some((index, line)) = text.lines().enumerate().find(|(_, l)| !l.trim().is_empty())
        && let Some(rest) = line.trim().strip_prefix('%')
    {
        let words: Vec<&str> = rest.split_whitespace().filter(|w| *w != "*").collect();
        if let [name, unit] = words[..]
            && matches!(
                unit.to_ascii_uppercase().trim_end_matches('*'),
                "G70" | "G71"
            )
        {
            return Err(crate::error::Error::parse(
                source,
                index + 1,
                format!(
                    "`%{name} {unit}` heads a Heidenhain DIN/ISO program, which feedopt does \
                     not read (its G codes differ from Fanuc's and LinuxCNC's: G70/G71 \
                     units, G30/G31 blank form, M91 machine positions): post the program \
                     in Klartext (`BEGIN PGM {name} MM`)"
                ),
            ));
        }
    }
    let Some((index, line)) = first_code_line(text) else {
        return Ok(text.into());
    };
    let trimmed = line.trim();
    if let Some(name) = trimmed.strip_prefix('$')
        && let Some((name, _)) = name.split_once('%')
        && name.contains('.')
        && !name.contains(char::is_whitespace)
    {
        return Err(crate::error::Error::parse(
            source,
            index + 1,
            format!(
                "`${name}%` heads an Okuma OSP program file; OSP's language (VC variables, \
                 CALL, G15 H work offsets) is not read by feedopt: post the toolpath for a \
                 Fanuc, LinuxCNC, Sinumerik or Heidenhain control"
            ),
        ));
    }
    if spec.subprograms == Subprograms::OPrograms && starts_with_colon_number(trimmed) {
        // The line's start in the text (`lines()` drops `\n` and `\r\n` line ends).
        let start: usize = text.split_inclusive('\n').take(index).map(str::len).sum();
        let colon = start + (line.len() - line.trim_start().len());
        let mut owned = String::with_capacity(text.len());
        owned.push_str(&text[..colon]);
        owned.push('O');
        owned.push_str(&text[colon + 1..]);
        return Ok(owned.into());
    }
    Ok(text.into())
}

/// The dialect a program's text (upper-cased) shows, if any: Heidenhain (a first block
/// `BEGIN PGM`, with or without a block number), Sinumerik (`TRAORI`, `TRAFOOF`, `MCALL`,
/// `CYCLE8…(`, `DEF REAL`, `SUPA`, `G710`, `G700`, `MSG(`), Fanuc (`G43.4`, `G43.5`, `G68.2`,
/// `G05.1`, `M98`, look-ahead `G08 P…`, high-precision contour control `G05 P10000`, macro
/// calls `G65 P…`, Haas `G187`, a first block
/// `O1234` (after a block number too: `N1 O3`) or ISO code's `:1234` after any comment lines), LinuxCNC (`M428`–`M430`, `O<`, and an `O` number followed
/// by an O-word keyword: `o100 sub`, `o100 call`, `o101 if`, …, which is not a Fanuc program
/// number).
pub fn detect_dialect(upper: &str) -> Option<Dialect> {
    if is_klartext(upper) {
        return Some(Dialect::Heidenhain);
    }
    let has = |w: &str| upper.contains(w);
    let sinumerik = [
        "TRAORI", "TRAFOOF", "MCALL", "CYCLE8", "DEF REAL", "SUPA ", "G710", "G700", "MSG(",
    ]
    .iter()
    .any(|w| has(w));
    let fanuc = [
        "G43.4",
        "G43.5",
        "G68.2",
        "G05.1",
        "G5.1",
        "M98",
        "G08 P",
        "G08P",
        "G65 P",
        "G65P",
        "G187",
        "G05 P10000",
        "G05P10000",
        "G5 P10000",
        "G5P10000",
    ]
    .iter()
    .any(|w| has(w))
        || upper
            .lines()
            .find(|l| {
                let l = l.trim();
                !l.is_empty() && !l.starts_with('%') && !l.starts_with('(')
            })
            .is_some_and(|l| {
                // After a block number as Fadal programs write it (round 8: `N1 O3 ( … )`).
                let l = strip_sequence_number(l.trim());
                (l.starts_with('O')
                    && l[1..].chars().next().is_some_and(|c| c.is_ascii_digit())
                    && !is_oword_control(l))
                    || starts_with_colon_number(l)
            });
    let linuxcnc = ["M428", "M429", "M430", "O<"].iter().any(|w| has(w))
        || upper.lines().any(is_oword_control);
    match (sinumerik, fanuc, linuxcnc) {
        (true, _, _) => Some(Dialect::Sinumerik),
        (false, true, _) => Some(Dialect::Fanuc),
        (false, false, true) => Some(Dialect::LinuxCnc),
        _ => None,
    }
}

/// A line without its block number `N<digits>` (and the blanks after it).
fn strip_sequence_number(l: &str) -> &str {
    match l.strip_prefix('N') {
        Some(rest) if rest.starts_with(|c: char| c.is_ascii_digit()) => rest
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start(),
        _ => l,
    }
}

/// LinuxCNC's O-word keywords: an `O` number followed by one of them is a subroutine or
/// control-flow line (`o100 sub`, `o100 call [2]`, `o101 if [#1 GT 0]`), not a Fanuc program
/// number.
const OWORD_KEYWORDS: [&str; 15] = [
    "SUB",
    "ENDSUB",
    "CALL",
    "RETURN",
    "IF",
    "ELSEIF",
    "ELSE",
    "ENDIF",
    "WHILE",
    "ENDWHILE",
    "DO",
    "REPEAT",
    "ENDREPEAT",
    "BREAK",
    "CONTINUE",
];

/// Whether an upper-cased line is a LinuxCNC O-word line with a numbered O word (`O100 SUB`,
/// `N10 O100 CALL [1]`): the number, then a keyword, then the end of the line, a space, `[` or
/// `(`.
fn is_oword_control(line: &str) -> bool {
    let l = strip_sequence_number(line.trim_start());
    let Some(rest) = l.strip_prefix('O') else {
        return false;
    };
    let digits = rest.len() - rest.trim_start_matches(|c: char| c.is_ascii_digit()).len();
    if digits == 0 {
        return false;
    }
    let tail = rest[digits..].trim_start();
    OWORD_KEYWORDS.iter().any(|kw| {
        tail.strip_prefix(kw).is_some_and(|after| {
            after.is_empty()
                || after.starts_with(|c: char| c.is_whitespace() || c == '[' || c == '(')
        })
    })
}

/// Whether a program's text (upper-cased) is Heidenhain Klartext: its first block (after
/// blank and comment lines) is `BEGIN PGM`, with or without a block number.
pub fn is_klartext(upper: &str) -> bool {
    upper
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with(';') && !l.starts_with('%'))
        .is_some_and(|l| {
            klartext::strip_block_number(l)
                .split_whitespace()
                .take(2)
                .eq(["BEGIN", "PGM"])
        })
}
