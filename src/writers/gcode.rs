//! G-code writer: the toolpath written back as a program whose every block carries the
//! optimised feed, so a controller that follows the program's feeds runs the schedule's time.
//!
//! # Blocks and their time
//!
//! Every CL point that [`crate::geometry`] keeps (see [`span_points`]) is a knot of its span,
//! hence a station of the schedule; the block that ends at it takes the schedule's time between
//! the stations at the block's two CL points. (A dresser span refitted by biarcs has sample
//! knots instead: each programmed point is then projected onto the fitted profile and its time
//! taken there, by the inverse of the motion law, [`crate::motion::Interval::time_to_x`].)
//! Points the geometry drops (the same position, and on a machine that uses it the same
//! orientation, as the point before) are not written. Consecutive spans share their boundary
//! point, written once; a rest-to-rest stop and a pure reorientation (the tip stands, the tool
//! turns) are ordinary blocks whose time is the schedule's.
//!
//! # Feed words
//!
//! What a block's F states is [`GcodeOptions::block_feed`]:
//!
//! * [`BlockFeed::Peak`] (the command line's default): the **fastest feed the schedule
//!   reaches along the block** (the largest tool-tip feed at its stations, its ends included).
//!   A control accelerates and brakes between the blocks' feeds itself; under these F the
//!   schedule is feasible (it never runs faster than a block's F), and no motion under them
//!   can be faster than the schedule, which is time-optimal under the same limits and F no
//!   higher than the program's: a control that plans within the machine's limits runs the
//!   schedule's time. feedopt's own solve of the written program is such a control: NX's
//!   DMU 70 eVo program (840D, 1,198 lines), solved again from the written program, takes
//!   the schedule's time within 1e-4 (written with average feeds: 1.1 % longer; the Spinner
//!   keychain 7.2 %, the Röders finish 2.7 %). The program's time at its F without any
//!   acceleration ([`Program::time`]) is then shorter than the schedule's.
//!
//!   That holds where every block's cap is one number. A process-limited schedule's caps
//!   change *along* a move (the material stage's pieces: air, then the cut), so a block is
//!   cut where its cap changes ([`Program::process_split`]; the point on the span's curve,
//!   as the Δθ rule places its points): one block at its peak would take the tool into the
//!   material at the air's feed. The bundled pocket's program, solved again without the
//!   material stage, took 7.83 s against the schedule's 8.66 s with one block per move, and
//!   takes the schedule's time with its 87 added blocks.
//! * [`BlockFeed::Average`]: the schedule's **average** over the block, chord / Δt: the
//!   program's time at its F is the schedule's (a control that changed feed without
//!   accelerating would run it), but a control that accelerates cannot: along a block that
//!   starts from rest it must first reach the average, which the schedule passes halfway up
//!   its ramp (the first interval from rest alone takes 25 % longer).
//!
//! * A block that moves a rotary axis is written under **G93** (inverse time): F = 60 / the
//!   block's time in s: Δt (average), or the time the block takes at its peak feed (peak:
//!   the chord at the peak tool-tip feed; on a turn on the spot, the turn at the peak rate
//!   of turn), which is what the reader caps the tool tip (the turn) by.
//! * A block where only X, Y, Z move is written under **G94**: F in mm/min, the peak
//!   tool-tip feed (peak) or chord / Δt (average), the chord measured between the
//!   coordinates as written.
//!
//! F is written with 7 significant digits (always with a decimal point): each block's time
//! at its F is then exact to 5e-7.
//! **Tiny blocks**: a block shorter than [`MIN_BLOCK_TIME_S`] (10 µs, F = 6,000,000 under G93)
//! is merged with the next one — its end point is not written (the last block merges with the
//! one before instead). Because every feed is capped, such a point lies within 10 µs of travel
//! of its neighbour (0.35 µm at 35 mm/s). No F is therefore absurd, and no time is lost: the
//! merged block takes both blocks' time.
//!
//! **Dwells.** The program's dwells ([`crate::geometry::Path::holds`]) are written where they
//! stand: a G4
//! after the block that reaches the point (a dwell at a point the geometry drops, a repeat of
//! the point before, at that point; one at a merged tiny block's end, at the block kept), in
//! each dialect's word: LinuxCNC `G4 P` seconds, Fanuc `G4 X` seconds (with a decimal point,
//! to the control's 1 ms; `P` would count milliseconds), Sinumerik `G4 F` seconds. The
//! program's time counts them, as the cycle time does.
//!
//! # Tools, spindle and coolant
//!
//! What the program does between its moves without moving the tool is written where the
//! program does it ([`crate::toolpath::Toolpath::tool_changes`], `spindle_changes`,
//! `switches`), before the block that ends at the CL point it comes before (a stop, M5 or
//! M9, comes after its own block's move, so after the retract that carries it):
//!
//! * a numbered tool as `T n M6`; a named one as `T="name" M6` (Sinumerik), elsewhere a
//!   comment that says to select it (those controls number their tools); a tool given by its
//!   geometry alone (APT `CUTTER/`, `TLDATA/`) as a comment;
//! * the tool-tip mode switch comes after the first tool (Fanuc `G43.4 H n` with the length
//!   offset the program gives, else the tool's number, H1 where no numbered tool is
//!   selected); a tool change in tool-tip mode leaves it and switches it on again with the
//!   new tool;
//! * on a machine without tool-tip mode, the program's own length offsets where its
//!   language has them ([`crate::toolpath::Toolpath::length_offsets`]: LinuxCNC and Fanuc
//!   `G43 H n`, `G44`, `G49`) where it switches them: a LinuxCNC program without `G43` (the
//!   CAMotics bear) has its Z at the gauge line and is written so; on a Sinumerik, whose
//!   `T … M6` applies the tool's length, as `D1` and `D0`, and `D0` after a tool change
//!   where the program's offset is off. Where the language has none (APT, Sinumerik,
//!   Klartext: the tool tip is programmed), each numbered tool comes with its length offset,
//!   `G43 H n` (LinuxCNC, Fanuc);
//! * the spindle speed as `S` (a whole number of rpm on a Fanuc), with the direction of the
//!   same block (`S12000 M3`); `M3`, `M4`, `M5`; the coolant `M7`, `M8`, `M9` (a Klartext
//!   `M13` is written as M3 and M8).
//!
//! **Machine coordinates.** A move the program makes in machine coordinates (`G53`, `SUPA`,
//! `M91`, the `G28`/`G30` reference points: [`crate::toolpath::Toolpath::machine_points`])
//! is written so, out of tool-tip mode: the reader placed it through the machine file's work
//! offset and reference points, which the control does not read (the NX Mori program's
//! `G91 G28 Z0` was written as `G0 X0 Y0 Z0 B0 C0` under `G43.4`: the tip to the work
//! origin, where the machine file gives no reference). `G53 G0` with the axes it names
//! (Sinumerik `G0 SUPA`); a reference point as `G91 G28 Z0` then `G90` (`G30`, Fanuc's
//! `G30 P3`), and where the dialect has no such code (Sinumerik) as `SUPA` to the machine
//! coordinates the reader took for it. It runs at the control's rapid; the program's time
//! counts the schedule's for it.
//!
//! **Work offsets.** The header selects the work offset the program selects before its first
//! move ([`crate::toolpath::Toolpath::work_offset`], `G55`); a program that names none runs in
//! the control's default, as the program did. Each offset the program selects later
//! ([`crate::toolpath::Toolpath::offset_changes`]: an NX program for a Mori machines five
//! setups in G55, G56, G57, G54.1 P3 and G54) is selected where the program selects it, and
//! the coordinates after it are written in it: the points less the origin the reader took
//! for it, so the program's own coordinates where the reader took it as equal to the one
//! before (it does not know the control's values). An offset the output's dialect does not
//! have (Fanuc `G54.1 P3` written for LinuxCNC, `G58` for a Sinumerik, whose G58 is a
//! programmable shift) is named in a comment instead. The values a program gives its offsets
//! (`G10 L2`) are not written: the control's own are used for the offset the program starts
//! in. An offset selected later whose values the program gave itself
//! ([`crate::toolpath::OffsetChange::given`]) is not selected: the control's stored values
//! are not the program's, so the points go on in the offset in force, the difference in
//! their coordinates, and a comment names the selection (round 17: a CAMotics example sets
//! `G10 L2 P2 Y-101.6` and selects G55 again to cut a second part 101.6 mm over; written as a
//! bare `G55`, the second part was cut on the first). Nor are `G52`/`G92` shifts (the
//! coordinates include them), LinuxCNC's `G43.1`/`G43.2` or other M codes.
//!
//! **Tapping.** A tap ([`crate::toolpath::TapCycle`]: Fanuc/LinuxCNC `G84`/`G74`, LinuxCNC
//! `G33.1`, Sinumerik `CYCLE84`, Klartext 207, APT `CYCLE/TAP`) is written as the output
//! control's tapping cycle, never as G1 blocks, which would feed the tap in and out with the
//! spindle neither synchronised nor reversed. The moves to where its feed starts (over the
//! hole, at R) and from where it ends are written as any others; the cycle replaces exactly
//! the tap's two feeds, in at its bottom and back out, and taps from where the tool stands,
//! so that, read back, it makes the same two points at the same feeds:
//!
//! * Fanuc (rigid tapping): `M29 S…`, `G99 G84 X… Y… Z… R… [P ms] F…` (`G74` for a
//!   left-hand thread), `G80`; G94, F = pitch × S in mm/min, R the point where the tool
//!   stands, G99 back to it. A Fanuc G84 feeds out at F: a tap that feeds out at another
//!   speed (Sinumerik SST1, LinuxCNC I) is refused, as is an S that is not a whole number.
//! * LinuxCNC: `G33.1 Z… K… [I…]` (the manual's "G33.1 Rigid Tapping": from the current
//!   point to Z at K per revolution, the spindle reverses, back at I times the speed). LinuxCNC's
//!   G84 is floating-chuck tapping, not synchronised. G33.1 taps in the direction the spindle
//!   turns and has no dwell: a tap whose hand is not the spindle's direction, or that dwells
//!   at the bottom, is refused.
//! * Sinumerik: `CYCLE84(RTP, RFP, SDIS, DP, DPR, DTB, SDAC, MPIT, PIT, POSS, SST, SST1)` with
//!   RTP = RFP the Z where the tool stands, SDIS 0, DP the bottom, DTB the dwell, SDAC the
//!   spindle's direction before it (3, 4; 5: stopped), PIT the pitch (negative: left-hand),
//!   SST the speed in, SST1 out.
//!
//! The pitch written is the feed the tap was timed at over its speed, which must be the
//! program's pitch where it gives one. The program's time ([`Program::time`]) counts a tap at
//! its feed both ways, as its other blocks at their F, and its dwell; the schedule times it at
//! that feed too, with its stops at the ends. On a machine with tool-tip mode the cycle is
//! written out of it (`G49` and the tool's `G43 H`, `M429`, `TRAFOOF`), which the controls
//! require and which changes nothing where every rotary axis stands at zero. A tilted tap —
//! the tool axis off Z, or the rotary axes off zero — is refused, naming it: its cycle would
//! need the tilted working plane (`G68.2`, `CYCLE800`, `PLANE`), which is not written yet. So
//! is a tap that breaks chips (Klartext 209 with Q257), has no spindle speed, or does not feed
//! straight down Z and back to where it started. A Heidenhain output is not written at all.
//!
//! **Rapids.** The schedule times rapid moves like any other, at the machine's limits (and
//! `feed.max`); they are written as G1 blocks with their optimised feed, so the file's time is
//! the schedule's. Only the first point is reached by a G0, as every program starts: that move
//! comes before the schedule's t = 0 and is not part of its time. (A move in machine
//! coordinates is a G0 too: "Machine coordinates" above.)
//!
//! # Dialect
//!
//! The header, the tool-tip (TCP) switch, the feed-mode words and the comment syntax come from
//! the dialect, as the reader's tables in [`crate::toolpath::gcode`] define them (round-trip
//! tests read every written program back through those tables and require no warning):
//!
//! | dialect | units, plane | TCP on / off | comments | end |
//! |---|---|---|---|---|
//! | linuxcnc | `G21 G90 G17` | `M428` / `M429` (the trt sims' remaps) | `( … )` | `M30` |
//! | fanuc | `%`, `O1000`, `G21 G90 G17` | `G43.4 H1` / `G49` | `( … )` | `M30`, `%` lines |
//! | sinumerik | `G710 G90 G17` | `TRAORI` / `TRAFOOF` | `; …` | `M30` |
//!
//! TCP is switched on only on machines with rotary axes (not on a four-axis machine, `xyza`,
//! `xyzb`, `xyzc`, whose programs are in machine coordinates); X Y Z are then the tool tip and the
//! rotary words (named as the machine's axes: C and A on the head_head, A/B and C on trunnions,
//! B on the dresser) the machine's rotary positions in degrees, unwrapped as the schedule
//! follows them. Coordinates carry 6 decimals (1 nm, 1 µ°), always with a decimal point (a
//! Fanuc number without one counts increments of 0.001).
//!
//! # Rotary step Δθ (seed 001)
//!
//! With `max_rotation_deg` = Δθ, a block whose rotary axes turn by more than Δθ is split by
//! the rule of [`crate::geometry::biarc::limit_rotation`]: into 2ᵏ pieces of equal parameter
//! length, k the fewest halvings that bring every piece's turn to at most Δθ (at most 2²⁰).
//! The new points lie on the path the schedule follows (the span's curve: on a dresser's
//! fitted profile, points of the fitted arc, as `limit_rotation` places them), shifted
//! linearly along the block so that the block still starts and ends at the programmed points
//! (which lie within the fitting tolerance of the curve; on a dresser span fitted by a line the
//! fitted normal is constant, and the shift turns B evenly from one programmed angle to the
//! next); their times are the schedule's at the same u. It applies to every kinematics with rotary axes; seed 001's dresser is
//! the machine that needs it. A pure rotation on the spot is already a block of its own (a
//! reorientation span), split the same way.
//!
//! Joint-space input (a CSV of axis positions) has no tool tip to write: it is rejected.

use std::fmt::Write as _;
use std::path::Path;

use crate::error::number;
use crate::error::{Error, Result};
use crate::geometry::{GeometryOptions, Span, span_points};
use crate::kinematics::Kinematics;
use crate::machine::Machine;
use crate::optimize::Solution;
use crate::schedule::Timeline;
use crate::toolpath::gcode::Dialect;
use crate::toolpath::{
    Feed, LengthOffset, MachineMove, MachinePoint, OffsetChange, Switch, ToolSelect, Toolpath,
};
use crate::validate::MIN_ROTATION_DEG;

/// Blocks shorter than this (s) are merged with the next one.
pub const MIN_BLOCK_TIME_S: f64 = 1e-5;

/// Most halvings of one block under the Δθ rule (as `limit_rotation`).
const MAX_HALVINGS: u32 = 20;

/// The most blocks a written program may have (about 60 MB of G-code): `--max-rotation-deg`
/// splits blocks, and the count is checked while the splits are computed, before anything is
/// written.
pub const MAX_BLOCKS: usize = 1_000_000;

/// The program number of a written Fanuc program.
pub const FANUC_PROGRAM_NUMBER: &str = "O1000";

/// Significant digits of F.
const F_DIGITS: i32 = 7;

/// Options of the writer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GcodeOptions {
    /// The controller the program is written for (header, TCP switch, comments).
    pub dialect: Dialect,
    /// Δθ: the largest turn of any rotary axis within one block, degrees (`None`: no limit).
    pub max_rotation_deg: Option<f64>,
    /// What each block's F states: the schedule's peak feed along it or its average.
    pub block_feed: BlockFeed,
}

/// What a written block's F states (see the module doc, "Feed words").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BlockFeed {
    /// The fastest feed the schedule reaches along the block: a control that accelerates
    /// within the machine's limits runs the schedule's time.
    #[default]
    Peak,
    /// The schedule's average feed over the block: the blocks' times at their F add up to
    /// the schedule's, for a control that would change feed without accelerating.
    Average,
}

impl std::str::FromStr for BlockFeed {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "peak" => Ok(BlockFeed::Peak),
            "average" => Ok(BlockFeed::Average),
            _ => Err(format!("`{s}`: give peak or average")),
        }
    }
}

impl std::fmt::Display for BlockFeed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BlockFeed::Peak => "peak",
            BlockFeed::Average => "average",
        })
    }
}

/// A written program and what it contains.
#[derive(Debug, Clone, PartialEq)]
pub struct Program {
    /// The program, as written to the file.
    pub text: String,
    /// Motion blocks after the first point (each with its F; a tap's cycle counts as its two
    /// moves, in and out).
    pub blocks: usize,
    /// Of those, blocks under G93.
    pub inverse_time_blocks: usize,
    /// Sum of the written blocks' times at their F (no acceleration), s, and of the dwells
    /// (`dwell_time`): the schedule's cycle time under [`BlockFeed::Average`], less under
    /// [`BlockFeed::Peak`]. A tap's cycle counts at its feed in and out, as a control runs
    /// it: under `Average` too, less than the schedule's time for it by its stops.
    pub time: f64,
    /// Sum of the written dwells (G4, and those of the taps' cycles), s: the program's, each
    /// where it stands.
    pub dwell_time: f64,
    /// Blocks merged away because they were shorter than [`MIN_BLOCK_TIME_S`].
    pub merged: usize,
    /// Blocks added by the Δθ rule.
    pub split: usize,
    /// Blocks added where a process limit's cap changes along a move (module doc, "Feed
    /// words").
    pub process_split: usize,
}

/// One point to write: where, and when the schedule passes it.
#[derive(Debug, Clone, Copy)]
struct Node {
    /// Tool tip, mm.
    p: [f64; 3],
    /// Path angles, radians.
    angles: [f64; 2],
    /// Time, s.
    t: f64,
    /// Source line of the CL point (0 for a point added by the Δθ rule or at a change of a
    /// process limit).
    line: usize,
    /// The CL point the block ending here ends at (an added point: the block it cuts).
    point: usize,
    /// The program's dwells here, s (written as G4 after the block that reaches the point).
    dwell: f64,
    /// The block that ends here: the fastest tool-tip feed (mm/s) and rate u̇ (span units/s)
    /// the schedule reaches along it, and its length in u.
    peak: Peak,
}

/// The fastest tool-tip feed and u̇ along a block, and its length in u.
#[derive(Debug, Clone, Copy, Default)]
struct Peak {
    v: f64,
    udot: f64,
    du: f64,
}

impl Peak {
    /// Two consecutive blocks as one.
    fn join(self, o: Peak) -> Peak {
        Peak {
            v: self.v.max(o.v),
            udot: self.udot.max(o.udot),
            du: self.du + o.du,
        }
    }
}

/// What the program does between its moves that the written program does at the same place
/// (module doc, "Tools, spindle and coolant").
#[derive(Debug, Clone, Copy)]
enum Aux<'a> {
    Offset(&'a OffsetChange),
    /// A move in machine coordinates to a point no written block ends at (the reader put it
    /// where the tool already stood: machine zero from an unknown start).
    Machine(MachineMove),
    Tool(&'a ToolSelect),
    Speed(f64),
    Switch(Switch),
    Length(LengthOffset),
}

/// The toolpath's tool changes, spindle speeds and switches in the order the program makes
/// them, each with the CL point it comes before: by that point, then by line, and in one block
/// the tool change first, then the speed, then the switches.
fn auxiliaries<'a>(tp: &'a Toolpath, machine: &[MachinePoint]) -> Vec<(usize, Aux<'a>)> {
    let mut v: Vec<(usize, usize, u8, usize, Aux)> = Vec::new();
    // A move is the last thing before the block after it.
    v.extend(
        machine
            .iter()
            .enumerate()
            .map(|(i, m)| (m.point, m.line, 3, i, Aux::Machine(m.kind))),
    );
    v.extend(
        tp.offset_changes
            .iter()
            .enumerate()
            .map(|(i, c)| (c.point, c.line, 0, i, Aux::Offset(c))),
    );
    v.extend(
        tp.tool_changes
            .iter()
            .enumerate()
            .map(|(i, c)| (c.point, c.line, 0, i, Aux::Tool(&c.tool))),
    );
    v.extend(
        tp.spindle_changes
            .iter()
            .enumerate()
            .map(|(i, c)| (c.point, c.line, 1, i, Aux::Speed(c.rpm))),
    );
    v.extend(
        tp.switches
            .iter()
            .enumerate()
            .map(|(i, c)| (c.point, c.line, 2, i, Aux::Switch(c.switch))),
    );
    // (A length offset in a tool change's block comes after the change.)
    v.extend(
        tp.length_offsets
            .iter()
            .flatten()
            .enumerate()
            .map(|(i, c)| (c.point, c.line, 1, i, Aux::Length(c.offset))),
    );
    v.sort_by_key(|&(point, line, rank, i, _)| (point, line, rank, i));
    v.into_iter()
        .map(|(point, _, _, _, a)| (point, a))
        .collect()
}

/// The machine's state the writer keeps between blocks: tool-tip mode and the tool, and the
/// program's tool changes, speeds and switches still to write.
struct Setup<'a> {
    dialect: Dialect,
    words: &'a Words,
    /// The machine has a tool-tip mode (rotary axes, not programmed in machine coordinates).
    tcp: bool,
    tcp_active: bool,
    /// The tool in the spindle, by number.
    tool: Option<u32>,
    /// The program's own length offsets are written ([`Toolpath::length_offsets`]: its
    /// language has them), rather than one with each numbered tool.
    mirror_length: bool,
    /// The program's length offset is on (mirrored).
    length_on: bool,
    /// The last H the program gives a length offset (tool-tip mode's too).
    h: Option<u32>,
    /// The origin of the work offset in force, toolpath coordinates: written coordinates are
    /// the points less it.
    origin: [f64; 3],
    events: Vec<(usize, Aux<'a>)>,
    next: usize,
}

impl Setup<'_> {
    /// Tool-tip mode on (a Fanuc's `G43.4` with the tool's length offset, H1 where the program
    /// selects no numbered tool).
    fn tcp_on(&mut self, text: &mut String) {
        if self.tcp && !self.tcp_active {
            let on = match self.dialect {
                Dialect::Fanuc => format!("G43.4 H{}", self.h.or(self.tool).unwrap_or(1)),
                _ => self.words.tcp_on.to_string(),
            };
            let _ = writeln!(text, "{on}");
            self.tcp_active = true;
        }
    }

    fn tcp_off(&mut self, text: &mut String) {
        if self.tcp_active {
            let _ = writeln!(text, "{}", self.words.tcp_off);
            self.tcp_active = false;
        }
    }

    /// Writes what the program does before the move ending at CL point `point` and has not
    /// been written.
    fn before(&mut self, text: &mut String, point: usize) {
        while let Some(&(p, aux)) = self.events.get(self.next) {
            if p > point {
                break;
            }
            self.next += 1;
            match aux {
                Aux::Machine(mv) => self.machine_move(text, &mv),
                Aux::Offset(change) if change.given => {
                    // The program set this offset's values itself (G10), which the written
                    // program does not: the control's stored values are not those. The
                    // points go on in the offset in force, with the difference in them.
                    let _ = writeln!(
                        text,
                        "{}",
                        (self.words.comment)(&format!(
                            "the program selects work offset {} here with the values it gives \
                             it (line {}): written in the offset in force, the shift in the \
                             coordinates",
                            change.name, change.line
                        ))
                    );
                }
                Aux::Offset(change) => {
                    if crate::toolpath::gcode::is_work_offset(self.dialect, &change.name) {
                        let _ = writeln!(text, "{}", change.name);
                    } else {
                        let _ = writeln!(
                            text,
                            "{}",
                            (self.words.comment)(&format!(
                                "the program selects work offset {} here, which this dialect \
                                 does not have: select the same origin here",
                                change.name
                            ))
                        );
                    }
                    self.origin = change.origin;
                }
                Aux::Tool(tool) => {
                    // (A length offset the program switches on before the next move.)
                    let offset_follows = self.events[self.next..]
                        .iter()
                        .take_while(|&&(q, _)| q == p)
                        .any(|(_, a)| matches!(a, Aux::Length(o) if *o != LengthOffset::Cancel));
                    self.change(text, tool, offset_follows);
                }
                Aux::Speed(rpm) => {
                    // A direction in the same block goes with it (`S12000 M3`).
                    let with = match self.events.get(self.next) {
                        Some(&(q, Aux::Switch(sw)))
                            if q == p
                                && matches!(
                                    sw,
                                    Switch::SpindleClockwise | Switch::SpindleCounterClockwise
                                ) =>
                        {
                            self.next += 1;
                            format!(" {}", m_code(sw))
                        }
                        _ => String::new(),
                    };
                    let speed = if self.dialect == Dialect::Fanuc {
                        // A Fanuc S is a whole number of rpm.
                        format!("{}", rpm.round())
                    } else {
                        crate::base::trimmed(rpm, 3)
                    };
                    let _ = writeln!(text, "S{speed}{with}");
                }
                Aux::Switch(sw) => {
                    let _ = writeln!(text, "{}", m_code(sw));
                }
                Aux::Length(offset) => self.length(text, offset),
            }
        }
    }

    /// The program's length offset `offset` (module doc, "Tools, spindle and coolant"):
    /// under tool-tip mode only its H, which `G43.4` takes.
    fn length(&mut self, text: &mut String, offset: LengthOffset) {
        if let LengthOffset::Plus(Some(h)) | LengthOffset::Minus(Some(h)) = offset {
            self.h = Some(h);
        }
        if self.tcp {
            return;
        }
        let h = |h: Option<u32>| h.map(|h| format!(" H{h}")).unwrap_or_default();
        let block = match (offset, self.dialect) {
            (LengthOffset::Plus(_), Dialect::Sinumerik) => "D1".to_string(),
            (LengthOffset::Cancel, Dialect::Sinumerik) => "D0".to_string(),
            (LengthOffset::Plus(n), _) => format!("G43{}", h(n)),
            (LengthOffset::Cancel, _) => "G49".to_string(),
            (LengthOffset::Minus(n), Dialect::Fanuc) => format!("G44{}", h(n)),
            (LengthOffset::Minus(n), _) => (self.words.comment)(&format!(
                "the program subtracts tool length offset{} here (G44), which this dialect does \
                 not have: set the same length here",
                h(n)
            )),
        };
        self.length_on = offset != LengthOffset::Cancel;
        let _ = writeln!(text, "{block}");
    }

    /// A tool change: out of tool-tip mode and back with the new tool; on a machine without
    /// it, the new tool's length offset (`G43 H`) on a LinuxCNC or Fanuc control, unless the
    /// program's own are written (and on a Sinumerik, where `T… M6` applies the tool's
    /// length, `D0` where the program's length offset is off and is not switched on before
    /// the next move).
    fn change(&mut self, text: &mut String, tool: &ToolSelect, offset_follows: bool) {
        let comment = |c: String| (self.words.comment)(&c);
        let line = match (tool, self.dialect) {
            (ToolSelect::Number(n), _) => format!("T{n} M6"),
            (ToolSelect::Name(name), Dialect::Sinumerik) => format!("T=\"{name}\" M6"),
            (ToolSelect::Name(name), _) => {
                let _ = writeln!(
                    text,
                    "{}",
                    comment(format!(
                        "tool change: tool \"{name}\" (this control numbers its tools: \
                         select it here)"
                    ))
                );
                return;
            }
            (
                ToolSelect::Cutter {
                    diameter,
                    corner_radius,
                },
                _,
            ) => {
                let _ = writeln!(
                    text,
                    "{}",
                    comment(format!(
                        "tool: diameter {diameter} mm, corner radius {corner_radius} mm"
                    ))
                );
                return;
            }
        };
        // (Tool-tip mode comes back before the next move, with the new tool's length.)
        self.tcp_off(text);
        let _ = writeln!(text, "{line}");
        if self.dialect == Dialect::Sinumerik
            && self.mirror_length
            && !self.tcp
            && !self.length_on
            && !offset_follows
        {
            let _ = writeln!(text, "D0");
        }
        // (Tool-tip mode takes the new tool's number until the program gives its H.)
        self.h = None;
        if let ToolSelect::Number(n) = tool {
            self.tool = Some(*n);
            if !self.tcp && self.dialect != Dialect::Sinumerik && !self.mirror_length {
                let _ = writeln!(text, "G43 H{n}");
            }
        }
    }

    /// The block of a move the program makes in machine coordinates (module doc, "Machine
    /// coordinates"), out of tool-tip mode.
    fn machine_move(&mut self, text: &mut String, mv: &MachineMove) {
        self.tcp_off(text);
        const NAMES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
        let words = |values: [Option<f64>; 6]| -> String {
            (0..6)
                .filter_map(|i| values[i].map(|v| format!("{}{}", NAMES[i], coord(v))))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let coordinates = |values: [Option<f64>; 6]| match self.dialect {
            Dialect::Sinumerik => format!("G0 SUPA {}", words(values)),
            _ => format!("G53 G0 {}", words(values)),
        };
        let block = match (*mv, self.dialect) {
            (MachineMove::Coordinates(values), _) => coordinates(values),
            // The control's own reference point, reached from where the tool stands.
            (MachineMove::Reference { k, axes, .. }, Dialect::Fanuc)
            | (
                MachineMove::Reference {
                    k: k @ (1 | 2),
                    axes,
                    ..
                },
                Dialect::LinuxCnc,
            ) => {
                let code = match k {
                    1 => "G28".to_string(),
                    2 => "G30".to_string(),
                    k => format!("G30 P{k}"),
                };
                let zeros = words(std::array::from_fn(|i| axes[i].then_some(0.0)));
                format!("G91 {code} {zeros}\nG90")
            }
            // No such code: the machine coordinates the reader took for it.
            (MachineMove::Reference { axes, at, .. }, _) => {
                coordinates(std::array::from_fn(|i| axes[i].then_some(at[i])))
            }
        };
        let _ = writeln!(text, "{block}");
    }
}

/// A switch's M code (the same in the three dialects written).
fn m_code(sw: Switch) -> &'static str {
    match sw {
        Switch::SpindleClockwise => "M3",
        Switch::SpindleCounterClockwise => "M4",
        Switch::SpindleStop => "M5",
        Switch::CoolantMist => "M7",
        Switch::CoolantFlood => "M8",
        Switch::CoolantOff => "M9",
    }
}

/// The words of one dialect.
struct Words {
    header: &'static [&'static str],
    tcp_on: &'static str,
    tcp_off: &'static str,
    footer: &'static [&'static str],
    comment: fn(&str) -> String,
}

fn words(dialect: Dialect) -> Result<Words> {
    Ok(match dialect {
        Dialect::LinuxCnc => Words {
            header: &["G21 G90 G17"],
            tcp_on: "M428",
            tcp_off: "M429",
            footer: &["M30"],
            comment: |c| format!("({})", c.replace(['(', ')'], "")),
        },
        Dialect::Fanuc => Words {
            header: &["G21 G90 G17"],
            tcp_on: "G43.4 H1",
            tcp_off: "G49",
            footer: &["M30", "%"],
            comment: |c| format!("({})", c.replace(['(', ')', ';'], "")),
        },
        Dialect::Sinumerik => Words {
            header: &["G710 G90 G17"],
            tcp_on: "TRAORI",
            tcp_off: "TRAFOOF",
            footer: &["M30"],
            comment: |c| format!("; {c}"),
        },
        Dialect::Heidenhain => {
            return Err(Error::Usage(
                "the writer writes G-code (linuxcnc, fanuc or sinumerik), not Heidenhain \
                 Klartext: give --dialect linuxcnc, fanuc or sinumerik"
                    .into(),
            ));
        }
    })
}

/// A coordinate: 6 decimals, never `-0.000000`.
fn coord(x: f64) -> String {
    let s = format!("{x:.6}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        "0.000000".to_string()
    } else {
        s
    }
}

/// The value a written coordinate reads back as.
fn rounded(x: f64) -> f64 {
    coord(x).parse().unwrap_or(x)
}

/// A feed word's number: `F_DIGITS` significant digits, at least one decimal.
fn feed_number(f: f64) -> String {
    let mag = f.abs().log10().floor() as i32;
    let decimals = (F_DIGITS - 1 - mag).clamp(1, 12) as usize;
    format!("{f:.decimals$}")
}

/// The schedule's time at every CL point of the program and the points the Δθ rule adds, in
/// program order (each span's boundary point once).
fn nodes(
    machine: &Machine,
    toolpath: &Toolpath,
    solution: &Solution,
    geometry: &GeometryOptions,
    max_rotation_rad: Option<f64>,
) -> Result<(Vec<Node>, usize, usize)> {
    let kin = &solution.kinematics;
    let angles = kin.rotary_angles(&toolpath.points, &machine.axes)?;
    let plan = span_points(
        toolpath,
        &angles,
        kin.uses_orientation(),
        geometry.corner_angle_deg,
        machine.kinematics.machine_coordinates(),
    );
    let spans = &solution.path.spans;
    let timeline = Timeline::new(&solution.schedule, &solution.problems, &solution.solutions)?;
    if plan.len() != spans.len() {
        return Err(Error::Usage(format!(
            "{}: the solution has {} spans, the toolpath {}: was it solved with other options?",
            toolpath.source.display(),
            spans.len(),
            plan.len()
        )));
    }
    let pts = &toolpath.points;
    let stations = &solution.schedule.stations;
    let mut out: Vec<Node> = Vec::new();
    let mut split = 0usize;
    let mut process_split = 0usize;
    let mut offset = 0usize;
    for (si, ((idx, span), tl)) in plan.iter().zip(spans).zip(&timeline.spans).enumerate() {
        let us = point_parameters(toolpath, idx, span)?;
        let first = offset;
        offset += tl.u.len();
        // The fastest tool-tip feed and u̇ at the span's stations from ua to ub (both
        // included: CL points are stations; between stations b is linear in u, or under the
        // jerk-limited law within the verification's bounds, so √b peaks at a station).
        let peak = |ua: f64, ub: f64| {
            let lo = tl.u.partition_point(|&x| x < ua);
            let hi =
                tl.u.partition_point(|&x| x <= ub)
                    .max(lo + 1)
                    .min(tl.u.len());
            let lo = lo.min(hi - 1);
            let mut p = Peak {
                du: ub - ua,
                ..Peak::default()
            };
            for j in lo..hi {
                p.v = p.v.max(stations.get(first + j).map_or(0.0, |s| s.v));
                p.udot = p.udot.max(tl.b[j].max(0.0).sqrt());
            }
            p
        };
        let node = |k: usize, u: f64, peak: Peak| Node {
            p: [pts[idx[k]].p.x, pts[idx[k]].p.y, pts[idx[k]].p.z],
            angles: angles[idx[k]],
            t: tl.time_at(u),
            line: pts[idx[k]].line,
            point: idx[k],
            dwell: 0.0,
            peak,
        };
        // The program's dwells stand at span boundaries (Path::holds): before the first
        // span's motion, and after each span, at its last point.
        let hold = |s: usize| solution.path.holds.get(s).copied().unwrap_or(0.0);
        if si == 0 {
            out.push(Node {
                dwell: hold(0),
                ..node(0, us[0], Peak::default())
            });
        }
        for k in 1..idx.len() {
            let (ua, ub) = (us[k - 1], us[k]);
            // The span's curve between the block's ends, shifted linearly so that it meets the
            // programmed points there (they differ by at most the fitting tolerance): where a
            // block is cut in pieces.
            let prog = |k: usize| {
                let (p, a) = (pts[idx[k]].p, angles[idx[k]]);
                [p.x, p.y, p.z, a[0], a[1]]
            };
            let curve = |u: f64| {
                let w = span.eval(u).value;
                [w[0], w[1], w[2], w[3], w[4]]
            };
            let (ca, cb) = (curve(ua), curve(ub));
            let (pa, pb) = (prog(k - 1), prog(k));
            let at = |u: f64| -> [f64; 5] {
                let l = if ub > ua { (u - ua) / (ub - ua) } else { 0.0 };
                let c = curve(u);
                std::array::from_fn(|j| c[j] + (1.0 - l) * (pa[j] - ca[j]) + l * (pb[j] - cb[j]))
            };
            // Where the block is cut: the Δθ rule's points, and every change of a process
            // limit's cap inside it (the material stage's pieces), so that each block's F is
            // the schedule's peak under one cap. A control holds F along a block: a block that
            // runs from air into material at the air's peak would take the tool into the cut
            // at the air's feed (the bundled pocket, solved again from the written program,
            // ran 10 % under the schedule's time, faster than its process limits allow).
            let mut cuts: Vec<(f64, bool)> = Vec::new();
            if let Some(step) = max_rotation_rad {
                let parts = halvings(&at, ua, ub, step);
                if out.len() + parts > MAX_BLOCKS {
                    return Err(Error::parse(
                        &toolpath.source,
                        pts[idx[k]].line,
                        format!(
                            "splitting this move into {parts} blocks of at most {:.3e}° \
                             (--max-rotation-deg) makes the program longer than {MAX_BLOCKS} \
                             blocks: give a larger rotation per block",
                            step.to_degrees()
                        ),
                    ));
                }
                cuts.extend((1..parts).map(|j| (ua + (ub - ua) * j as f64 / parts as f64, true)));
            }
            if let Some(pc) = &span.process {
                cuts.extend(
                    pc.u.iter()
                        .filter(|&&u| u > ua && u < ub)
                        .filter(|&&u| !cuts.iter().any(|c| c.0 == u))
                        .map(|&u| (u, false))
                        .collect::<Vec<_>>(),
                );
                cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
            if out.len() + cuts.len() > MAX_BLOCKS {
                return Err(Error::Usage(format!(
                    "{}: the program would have more than {MAX_BLOCKS} blocks: write it in parts",
                    toolpath.source.display()
                )));
            }
            // Where the block's last piece starts.
            let mut last_u = ua;
            for &(u, by_rotation) in &cuts {
                let w = at(u);
                out.push(Node {
                    p: [w[0], w[1], w[2]],
                    angles: [w[3], w[4]],
                    t: tl.time_at(u),
                    line: 0,
                    point: idx[k],
                    dwell: 0.0,
                    peak: peak(last_u, u),
                });
                if by_rotation {
                    split += 1;
                } else {
                    process_split += 1;
                }
                last_u = u;
            }

            let dwell = if k + 1 == idx.len() {
                hold(si + 1)
            } else {
                0.0
            };
            out.push(Node {
                dwell,
                ..node(k, ub, peak(last_u, ub))
            });
        }
    }
    if out.len() > MAX_BLOCKS + 1 {
        return Err(Error::Usage(format!(
            "{}: the program would have {} blocks, more than {MAX_BLOCKS}: write it in parts",
            toolpath.source.display(),
            out.len() - 1
        )));
    }
    Ok((out, split, process_split))
}

/// The number of equal pieces (2ᵏ, k fewest) of [ua, ub] that keep every piece's turn of both
/// path angles (`at(u)[3..5]`) within `step` rad.
fn halvings(at: &dyn Fn(f64) -> [f64; 5], ua: f64, ub: f64, step: f64) -> usize {
    let turn = |a: [f64; 5], b: [f64; 5]| (a[3] - b[3]).abs().max((a[4] - b[4]).abs());
    for k in 0..=MAX_HALVINGS {
        let m = 1usize << k;
        let w: Vec<[f64; 5]> = (0..=m)
            .map(|j| at(ua + (ub - ua) * j as f64 / m as f64))
            .collect();
        if w.windows(2).all(|p| turn(p[0], p[1]) <= step) {
            return m;
        }
    }
    1 << MAX_HALVINGS
}

/// The span parameter u of each of the span's CL points: its knot, or on a dresser span
/// refitted by biarcs (knots ≠ CL points) the nearest point of the fitted profile.
fn point_parameters(toolpath: &Toolpath, idx: &[usize], span: &Span) -> Result<Vec<f64>> {
    let knots = span.spline.knots();
    let pts = &toolpath.points;
    if span.points.len() == knots.len() {
        // The knots at CL points (the geometry inserts others on the programmed chords).
        let at: Vec<usize> = (0..knots.len())
            .filter(|&k| span.points[k] != crate::geometry::INSERTED)
            .collect();
        let stray = (at.len() != idx.len()).then_some(0).or_else(|| {
            (0..idx.len())
                .find(|&k| span.points[at[k]] != idx[k] || span.lines[at[k]] != pts[idx[k]].line)
        });
        if let Some(k) = stray {
            let k = k.min(idx.len() - 1);
            return Err(Error::parse(
                &toolpath.source,
                pts[idx[k]].line,
                format!(
                    "internal: the span's knots are not this span's CL points (at the CL point \
                     of line {})",
                    pts[idx[k]].line
                ),
            ));
        }
        return Ok(at.iter().map(|&k| knots[k]).collect());
    }
    // Dresser refit: project on the fitted X–Z profile (a cursor moving forward along it).
    let d2 = |u: f64, k: usize| {
        let w = span.eval(u).value;
        let p = pts[idx[k]].p;
        (w[0] - p.x).powi(2) + (w[2] - p.z).powi(2)
    };
    let mut us = Vec::with_capacity(idx.len());
    let mut c = 0usize;
    let last = knots.len() - 1;
    for k in 0..idx.len() {
        if k == 0 {
            us.push(0.0);
            continue;
        }
        if k == idx.len() - 1 {
            us.push(knots[last]);
            continue;
        }
        while c < last && d2(knots[c + 1], k) <= d2(knots[c], k) {
            c += 1;
        }
        // Golden-section search on the two knot segments around the nearest knot.
        let (mut a, mut b) = (knots[c.saturating_sub(1)], knots[(c + 1).min(last)]);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..60 {
            let (x1, x2) = (b - g * (b - a), a + g * (b - a));
            if d2(x1, k) <= d2(x2, k) {
                b = x2;
            } else {
                a = x1;
            }
        }
        let u = (0.5 * (a + b)).max(*us.last().unwrap_or(&0.0));
        us.push(u);
    }
    Ok(us)
}

/// One tap as the writer writes it ([`crate::toolpath::TapCycle`], module doc "Tapping").
#[derive(Debug, Clone, Copy)]
struct TapPlan {
    /// Index into [`Toolpath::taps`].
    tap: usize,
    /// The feed in and out, mm/min; the speed, rpm; the pitch, mm; the dwell at the bottom, s.
    feed_in: f64,
    feed_out: f64,
    rpm: f64,
    pitch: f64,
    dwell: f64,
    left_hand: bool,
    /// The spindle's direction before the tap: M3 (`Some(false)`), M4 (`Some(true)`), none.
    reversed: Option<bool>,
}

/// The spindle's direction in force at the move ending at CL point `point`: the last M3, M4
/// or M5 that comes before it (M5: `None`).
fn spindle_direction(toolpath: &Toolpath, point: usize) -> Option<bool> {
    toolpath
        .switches
        .iter()
        .filter(|s| s.point <= point)
        .rev()
        .find_map(|s| match s.switch {
            Switch::SpindleClockwise => Some(Some(false)),
            Switch::SpindleCounterClockwise => Some(Some(true)),
            Switch::SpindleStop => Some(None),
            _ => None,
        })
        .flatten()
}

/// Why a tap whose tool stands `degrees` off the direction its cycle feeds (Z, no tilted
/// plane in force) is not written; `at`: the rotary words there.
fn off_axis(degrees: f64, at: &str) -> String {
    format!(
        "the tool axis stands {degrees:.3}° off the direction the cycle feeds (Z: no tilted \
         working plane is in force{at}): as read, the tap feeds at that angle to its own axis, \
         and a tilted tap, which needs the tilted working plane (G68.2, CYCLE800, PLANE), is \
         not written yet"
    )
}

/// Each tap of the toolpath as the output's cycle can write it, or an error naming the first
/// it cannot (module doc, "Tapping"): a tap is never written as feed moves.
fn tap_plans(toolpath: &Toolpath, dialect: Dialect) -> Result<Vec<TapPlan>> {
    let pts = &toolpath.points;
    let z = nalgebra::Vector3::z();
    let mut plans = Vec::with_capacity(toolpath.taps.len());
    for (j, tap) in toolpath.taps.iter().enumerate() {
        let refuse = |why: String| {
            Err(toolpath.error_at(
                tap.line,
                format!(
                    "{}: a tapping cycle that feedopt gcode cannot write as a {dialect} tapping \
                    cycle: {why} (written as feed moves, the tap would be fed in and out with \
                    the spindle neither synchronised nor reversed). `feedopt solve` times it; \
                    to write the other operations, post this tapping separately",
                    tap.name
                ),
            ))
        };
        let range = tap.points.clone();
        if range.start == 0 || range.end > pts.len() || range.len() < 2 {
            return refuse("its moves are not two feeds into the hole and out".into());
        }
        if range.len() > 2 {
            return refuse(
                "it breaks chips on the way in (Klartext 209's Q257), which is not written yet"
                    .into(),
            );
        }
        let (top, bottom, back) = (
            &pts[range.start - 1],
            &pts[range.start],
            &pts[range.end - 1],
        );
        // A tilted tap: under a tilted working plane or frame (APT: along a tilted tool).
        let tilt = |v: &nalgebra::Vector3<f64>| v.angle(&z).to_degrees();
        if tilt(&tap.axis) > 1e-6 {
            return refuse(format!(
                "it feeds along an axis {:.3}° off Z (a tilted working plane or frame, or a \
                 tilted tool), and a tilted tap is not written yet",
                tilt(&tap.axis)
            ));
        }
        // A tool off the direction the cycle feeds (points given with a tool vector; those
        // with rotary positions: the writer checks the tool axis they give).
        if let Some(o) = [top, bottom, back]
            .iter()
            .filter(|p| p.rotary.is_none())
            .map(|p| p.o)
            .find(|o| o.angle(&tap.axis) > 1e-8)
        {
            return refuse(off_axis(o.angle(&tap.axis).to_degrees(), ""));
        }
        let down = bottom.p - top.p;
        if (back.p - top.p).norm() > 1e-6 || down.xy().norm() > 1e-6 || down.z >= 0.0 {
            return refuse(
                "it does not feed straight down along Z and back to where it started".into(),
            );
        }
        let Some(rpm) = tap.rpm.filter(|r| r.is_finite() && *r > 0.0) else {
            return refuse(
                "the program gives no spindle speed for it, which the cycle needs (feed = \
                pitch × S)"
                    .into(),
            );
        };
        let (feed_in, feed_out) = (tap.feed_in, tap.feed_out);
        if !(feed_in > 0.0 && feed_out > 0.0 && feed_in.is_finite() && feed_out.is_finite()) {
            return refuse("its feed is not known".into());
        }
        // The cycle feeds at pitch × S: the pitch it is written with is the feed it was timed
        // at over the speed, which must be the program's pitch where it gives one.
        let pitch = feed_in / rpm;
        if let Some(p) = tap.pitch
            && (p - pitch).abs() > 1e-6 * p
        {
            return refuse(format!(
                "it was read at F = {feed_in} mm/min, not at its pitch {p} mm × S{rpm}"
            ));
        }
        let same_out = (feed_out - feed_in).abs() <= 1e-9 * feed_in;
        let reversed = spindle_direction(toolpath, range.start);
        match dialect {
            Dialect::Fanuc if !same_out => {
                return refuse(format!(
                    "it feeds out at {feed_out} mm/min, in at {feed_in}: G84 feeds out as in"
                ));
            }
            Dialect::Fanuc if rpm.fract() != 0.0 => {
                return refuse(format!(
                    "its speed S{rpm} is not a whole number of rpm, which a Fanuc S is"
                ));
            }
            Dialect::LinuxCnc if tap.dwell > 0.0 => {
                return refuse(format!(
                    "it dwells {} s at the bottom, and LinuxCNC's rigid tap G33.1 reverses \
                    without a dwell",
                    tap.dwell
                ));
            }
            Dialect::LinuxCnc if reversed != Some(tap.left_hand) => {
                return refuse(format!(
                    "a {} thread with the spindle {}: G33.1 taps in the direction the spindle \
                    turns",
                    if tap.left_hand {
                        "left-hand"
                    } else {
                        "right-hand"
                    },
                    match reversed {
                        Some(true) => "turning M4",
                        Some(false) => "turning M3",
                        None => "stopped",
                    }
                ));
            }
            _ => {}
        }
        plans.push(TapPlan {
            tap: j,
            feed_in,
            feed_out,
            rpm,
            pitch,
            dwell: tap.dwell,
            left_hand: tap.left_hand,
            reversed,
        });
    }
    Ok(plans)
}

/// The block of a tap's cycle ([`TapPlan`]) from `top` (written coordinates, where the tool
/// stands) down to `bottom` (Z) and back, with the time its moves take at the written feed
/// (in and out, no acceleration) and the dwell it writes (module doc, "Tapping"). Out of
/// tool-tip mode: on a Fanuc machine with it, the tool's length offset `G43 H` for the cycle.
fn tap_cycle(setup: &Setup, plan: &TapPlan, top: [f64; 3], bottom: f64) -> (String, f64, f64) {
    let depth = top[2] - bottom;
    let (x, y, r, z) = (coord(top[0]), coord(top[1]), coord(top[2]), coord(bottom));
    // The feed a cycle reads back: pitch × S as written.
    let parsed = |s: &str, v: f64| s.parse::<f64>().unwrap_or(v);
    match setup.dialect {
        Dialect::Fanuc => {
            // Fanuc rigid tapping (M29 S, then G84 right-hand / G74 left-hand; G94: F = pitch
            // × S in mm/min); G99 returns to R, where the tool started; P the dwell in ms.
            let f = feed_number(plan.feed_in);
            let fv = parsed(&f, plan.feed_in);
            let ms = (plan.dwell * 1000.0).round();
            let p = if ms > 0.0 {
                format!(" P{ms}")
            } else {
                String::new()
            };
            let code = if plan.left_hand { "G74" } else { "G84" };
            let length = if setup.tcp {
                format!("G43 H{}\n", setup.h.or(setup.tool).unwrap_or(1))
            } else {
                String::new()
            };
            (
                format!(
                    "{length}M29 S{}\nG99 {code} X{x} Y{y} Z{z} R{r}{p} F{f}\nG80",
                    plan.rpm
                ),
                2.0 * depth * 60.0 / fv,
                ms / 1000.0,
            )
        }
        Dialect::Sinumerik => {
            // CYCLE84(RTP, RFP, SDIS, DP, DPR, DTB, SDAC, MPIT, PIT, POSS, SST, SST1): from
            // where the tool stands (RFP + SDIS = RTP), pitch PIT (negative: left-hand) at
            // SST in, SST1 out; SDAC the spindle after it (3 M3, 4 M4, 5 M5).
            let pit = crate::base::trimmed(plan.pitch, 9);
            let (sst, sst1) = (
                crate::base::trimmed(plan.rpm, 6),
                crate::base::trimmed(plan.feed_out / plan.pitch, 6),
            );
            let pv = parsed(&pit, plan.pitch);
            let (down, up) = (pv * parsed(&sst, plan.rpm), pv * parsed(&sst1, plan.rpm));
            let sdac = match plan.reversed {
                Some(false) => 3,
                Some(true) => 4,
                None => 5,
            };
            let dtb = if plan.dwell > 0.0 {
                coord(plan.dwell)
            } else {
                String::new()
            };
            let sign = if plan.left_hand { "-" } else { "" };
            (
                format!("CYCLE84({r},{r},0,{z},,{dtb},{sdac},,{sign}{pit},0,{sst},{sst1})"),
                depth * 60.0 / down + depth * 60.0 / up,
                parsed(&dtb, 0.0),
            )
        }
        _ => {
            // LinuxCNC G33.1 (rigid tapping: down at K per revolution, the spindle reverses,
            // back at I × the speed), Z only, the tool already over the hole.
            let k = crate::base::trimmed(plan.pitch, 9);
            let ratio = plan.feed_out / plan.feed_in;
            let i = if ratio == 1.0 {
                String::new()
            } else {
                format!(" I{}", crate::base::trimmed(ratio, 9))
            };
            let down = parsed(&k, plan.pitch) * parsed(&crate::base::trimmed(plan.rpm, 3), 0.0);
            let iv = if i.is_empty() {
                1.0
            } else {
                parsed(&i[2..], ratio)
            };
            (
                format!("G33.1 Z{z} K{k}{i}"),
                depth * 60.0 / down + depth * 60.0 / (down * iv),
                0.0,
            )
        }
    }
}

/// Writes the toolpath back as G-code with the schedule's feed per block (see the module doc).
/// `geometry` must be the options the solution was computed with. Corners blended under
/// `geometry.corner_tolerance_mm` are written as the blends the schedule runs (G1 blocks
/// through their points, on the corner's line).
pub fn program(
    machine: &Machine,
    toolpath: &Toolpath,
    solution: &Solution,
    geometry: &GeometryOptions,
    options: &GcodeOptions,
) -> Result<Program> {
    let (blended, _) = crate::geometry::blend::blend_corners(
        toolpath,
        geometry.corner_tolerance_mm,
        geometry.corner_angle_deg,
    );
    let toolpath: &Toolpath = &blended;
    let w = words(options.dialect)?;
    let taps = tap_plans(toolpath, options.dialect)?;
    // The tap each CL point of a tap's moves belongs to.
    let tap_at: std::collections::HashMap<usize, usize> = taps
        .iter()
        .enumerate()
        .flat_map(|(k, plan)| toolpath.taps[plan.tap].points.clone().map(move |i| (i, k)))
        .collect();
    let kin = &solution.kinematics;
    if matches!(kin, Kinematics::Joint { .. }) {
        return Err(Error::Usage(
            "a joint-space path has no tool tip to write as G-code".into(),
        ));
    }
    options.validate()?;
    let step = options.max_rotation_deg.map(f64::to_radians);
    // Rotary words: (letter, path angle index) in the machine's axis order.
    let mut rotary: Vec<(String, usize)> = Vec::new();
    for (a, axis) in kin.rotary_axes().iter().enumerate() {
        if let Some(j) = *axis {
            let name = machine
                .axes
                .get(j)
                .map(|x| x.name.clone())
                .unwrap_or_default();
            if !matches!(name.as_str(), "A" | "B" | "C") {
                return Err(Error::Usage(format!(
                    "rotary axis `{name}` cannot be written as a G-code word (A, B or C)"
                )));
            }
            rotary.push((name, a));
        }
    }
    rotary.sort_by_key(|(n, _)| n.clone());
    let offsets = kin.angle_offsets();
    let (nodes, split, process_split) = nodes(machine, toolpath, solution, geometry, step)?;
    // Written words of each node, and the merge of tiny blocks.
    // `origin`: the work offset's in force, toolpath coordinates (module doc).
    let written = |n: &Node, origin: [f64; 3]| -> (Vec<String>, [f64; 3], Vec<f64>) {
        let p: [f64; 3] = std::array::from_fn(|i| rounded(n.p[i] - origin[i]));
        let r: Vec<f64> = rotary
            .iter()
            .map(|(_, a)| rounded((n.angles[*a] + offsets[*a]).to_degrees()))
            .collect();
        let mut w = vec![
            format!("X{}", coord(p[0])),
            format!("Y{}", coord(p[1])),
            format!("Z{}", coord(p[2])),
        ];
        for ((name, _), v) in rotary.iter().zip(&r) {
            w.push(format!("{name}{}", coord(*v)));
        }
        (w, p, r)
    };
    let mut keep: Vec<usize> = vec![0];
    // The dwell written after each kept node: its own and those of the nodes merged into it
    // (a merged node lies within 10 µs of travel of the kept one).
    let mut dwell_after: Vec<f64> = vec![nodes[0].dwell];
    // The peaks of each kept node's block, with those of the blocks merged into it.
    let mut peak_of: Vec<Peak> = vec![Peak::default()];
    let mut pending = Peak::default();
    let mut merged = 0usize;
    for i in 1..nodes.len() {
        let last = *keep.last().unwrap_or(&0);
        let same = written(&nodes[i], [0.0; 3]).0 == written(&nodes[last], [0.0; 3]).0;
        let tiny = nodes[i].t - nodes[last].t < MIN_BLOCK_TIME_S;
        let peak = pending.join(nodes[i].peak);
        if i == nodes.len() - 1 {
            let mut dwell = nodes[i].dwell;
            let mut peak = peak;
            if same || (tiny && keep.len() > 1) {
                // The last block merges with the one before (its end point is the program's).
                if keep.len() > 1 {
                    keep.pop();
                    dwell += dwell_after.pop().unwrap_or(0.0);
                    peak = peak_of.pop().unwrap_or_default().join(peak);
                    merged += 1;
                } else if same {
                    merged += 1;
                    if let Some(d) = dwell_after.last_mut() {
                        *d += dwell;
                    }
                    continue;
                }
            }
            keep.push(i);
            dwell_after.push(dwell);
            peak_of.push(peak);
        } else if same || tiny {
            merged += 1;
            pending = peak;
            if let Some(d) = dwell_after.last_mut() {
                *d += nodes[i].dwell;
            }
        } else {
            keep.push(i);
            dwell_after.push(nodes[i].dwell);
            peak_of.push(peak);
            pending = Peak::default();
        }
    }
    // G4 in each dialect's unit and word: LinuxCNC P seconds; Fanuc X seconds (with a decimal
    // point, to the control's 1 ms; P would count milliseconds); Sinumerik F seconds.
    // The block and the time it holds, as written.
    let dwell_block = |secs: f64| -> (String, f64) {
        let (word, number) = match options.dialect {
            Dialect::Fanuc => ("X", format!("{secs:.3}")),
            Dialect::Sinumerik => ("F", coord(secs)),
            _ => ("P", coord(secs)),
        };
        let value = number.parse().unwrap_or(secs);
        (format!("G4 {word}{number}"), value)
    };

    let mut text = String::new();
    let comment = |s: &str| (w.comment)(s);
    let _ = writeln!(
        text,
        "{}",
        comment(&format!(
            "feedopt: {} on {}, optimised feed per block",
            toolpath.source.display(),
            machine.name
        ))
    );
    let _ = writeln!(
        text,
        "{}",
        comment(&format!(
            "schedule cycle time {:.6} s{}; {}",
            solution.schedule.cycle_time + toolpath.dwell_time(),
            if toolpath.dwell_time() > 0.0 {
                format!(
                    " = motion {:.6} s + dwells {:.6} s",
                    solution.schedule.cycle_time,
                    toolpath.dwell_time()
                )
            } else {
                String::new()
            },
            match options.block_feed {
                BlockFeed::Peak => {
                    "F: the fastest feed of the schedule along each block (G94 mm/min, G93 60 / \
                     the block's time at it)"
                }
                BlockFeed::Average => "G93 F = 60 / block time s, G94 F in mm/min",
            }
        ))
    );
    if options.dialect == Dialect::Fanuc {
        // A Fanuc program in memory carries its number: `%`, then `O…` (which is also what
        // tells feedopt's reader, and a user, that the file is a Fanuc program).
        text.insert_str(0, &format!("%\n{FANUC_PROGRAM_NUMBER}\n"));
    }
    for h in w.header {
        let _ = writeln!(text, "{h}");
    }
    // The work offset the program's coordinates are in, where it names one.
    if let Some(name) = &toolpath.work_offset {
        if crate::toolpath::gcode::is_work_offset(options.dialect, name) {
            let _ = writeln!(text, "{name}");
        } else {
            let _ = writeln!(
                text,
                "{}",
                comment(&format!(
                    "the program's work offset is {name}, which this dialect does not \
                     have: select the same origin here"
                ))
            );
        }
    }
    // A machine programmed in machine coordinates has no tool-tip mode.
    let tcp = !rotary.is_empty() && !machine.kinematics.machine_coordinates();
    // The blocks in machine coordinates, by the CL point they go to; a node that is such a
    // block's end (not a point the writer added inside it) is written as it. Those whose
    // points no kept node ends at are written where they come, as the program's other words.
    let machine_moves: std::collections::HashMap<usize, MachineMove> = toolpath
        .machine_points
        .iter()
        .map(|m| (m.point, m.kind))
        .collect();
    let machine_move = |n: &Node| (n.line != 0).then(|| machine_moves.get(&n.point)).flatten();
    let ends: std::collections::HashSet<usize> = keep
        .iter()
        .map(|&i| &nodes[i])
        .filter(|n| n.line != 0)
        .map(|n| n.point)
        .collect();
    let unwritten: Vec<MachinePoint> = toolpath
        .machine_points
        .iter()
        .filter(|m| !ends.contains(&m.point))
        .copied()
        .collect();
    let mut setup = Setup {
        dialect: options.dialect,
        words: &w,
        tcp,
        tcp_active: false,
        tool: None,
        mirror_length: toolpath.length_offsets.is_some(),
        length_on: false,
        h: None,
        origin: [0.0; 3],
        events: auxiliaries(toolpath, &unwritten),
        next: 0,
    };
    let first = &nodes[keep[0]];
    // The tool, spindle and coolant the program sets before its first move, then tool-tip
    // mode (with the tool's length).
    setup.before(&mut text, first.point);
    let (words0, mut prev_p, mut prev_r) = written(first, setup.origin);
    if let Some(mv) = machine_move(first) {
        setup.machine_move(&mut text, mv);
    } else {
        setup.tcp_on(&mut text);
        let _ = writeln!(text, "G0 {}", words0.join(" "));
    }
    let mut inverse_mode = false;
    let (mut blocks, mut inverse_blocks, mut total) = (0usize, 0usize, 0.0f64);
    let mut dwell_time = 0.0;
    let mut dwell = |text: &mut String, secs: f64| {
        if secs > 0.0 {
            let (block, value) = dwell_block(secs);
            let _ = writeln!(text, "{block}");
            dwell_time += value;
        }
    };
    dwell(&mut text, dwell_after[0]);
    let mut prev_t = first.t;
    // The CL point the last block written as the program's ended at (not a point the writer
    // added), and the dwells the taps' cycles write.
    let mut last_point = first.point;
    let mut tap_dwell = 0.0;
    let mut taps_written = 0usize;
    for (w, &i) in keep.iter().enumerate().skip(1) {
        let n = &nodes[i];
        setup.before(&mut text, n.point);
        let (ws, p, r) = written(n, setup.origin);
        let dt = n.t - prev_t;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::Solver(format!(
                "block to line {} has no positive time ({dt} s)",
                n.line
            )));
        }
        if let Some(&k) = tap_at.get(&n.point) {
            // A tap's moves: its cycle, written at the block that reaches the bottom.
            let plan = &taps[k];
            let tap = &toolpath.taps[plan.tap];
            let (start, end) = (tap.points.start, tap.points.end);
            if n.line != 0 && n.point == start {
                // The tool stands where the feed in starts (the point before the tap's, or a
                // repeat of it that the geometry dropped).
                let top = toolpath.points[start - 1].p;
                let top: [f64; 3] = std::array::from_fn(|i| rounded(top[i] - setup.origin[i]));
                if last_point + 1 < start && (0..3).any(|i| (top[i] - prev_p[i]).abs() > 1e-6) {
                    return Err(toolpath.error_at(
                        tap.line,
                        format!(
                            "internal: {}: the block to where the tap starts was not written",
                            tap.name
                        ),
                    ));
                }
                // A tilted tap (module doc, "Tapping"): the tool off the direction the cycle
                // feeds, or on a machine with tool-tip mode the rotary axes off zero.
                let tool = kin.tool_axis(n.angles);
                let off = tool.angle(&tap.axis).to_degrees();
                let at: Vec<String> = rotary
                    .iter()
                    .zip(&r)
                    .map(|((name, _), v)| format!("{name}{v}"))
                    .collect();
                let why = if off > 1e-6 {
                    Some(off_axis(off, &format!("; {}", at.join(" "))))
                } else if setup.tcp && prev_r.iter().chain(&r).any(|a| *a != 0.0) {
                    Some(format!(
                        "the rotary axes stand at {}: the controls run a tapping cycle out of \
                         tool-tip mode, where these coordinates would turn with the axes, and \
                         such a tap is not written yet",
                        at.join(" ")
                    ))
                } else {
                    None
                };
                if let Some(why) = why {
                    return Err(toolpath.error_at(
                        tap.line,
                        format!(
                            "{}: a tapping cycle that feedopt gcode cannot write: {why}. \
                             `feedopt solve` times it; to write the other operations, post \
                             this tapping separately",
                            tap.name
                        ),
                    ));
                }
                if inverse_mode {
                    let _ = writeln!(text, "G94");
                    inverse_mode = false;
                }
                setup.tcp_off(&mut text);
                let (block, secs, dwell) = tap_cycle(&setup, plan, prev_p, p[2]);
                let _ = writeln!(text, "{block}");
                total += secs;
                tap_dwell += dwell;
                taps_written += 1;
                let rest = dwell_after[w] - plan.dwell;
                if rest.abs() > 1e-9 {
                    return Err(toolpath.error_at(
                        tap.line,
                        format!(
                            "{}: a dwell of {rest} s at the tap's bottom besides the cycle's \
                            own: it cannot be written inside the cycle",
                            tap.name
                        ),
                    ));
                }
            }
            if n.line != 0 {
                blocks += 1;
                last_point = n.point;
                if n.point + 1 == end {
                    dwell(&mut text, dwell_after[w]);
                }
            }
            (prev_p, prev_r, prev_t) = (p, r, n.t);
            continue;
        }
        if n.line != 0 {
            last_point = n.point;
        }
        if let Some(mv) = machine_move(n) {
            // At the control's rapid: the schedule's time stands for it.
            setup.machine_move(&mut text, mv);
            total += dt;
            dwell(&mut text, dwell_after[w]);
            blocks += 1;
            (prev_p, prev_r, prev_t) = (p, r, n.t);
            continue;
        }
        setup.tcp_on(&mut text);
        let turns = r.iter().zip(&prev_r).any(|(a, b)| a != b);
        let chord =
            ((p[0] - prev_p[0]).powi(2) + (p[1] - prev_p[1]).powi(2) + (p[2] - prev_p[2]).powi(2))
                .sqrt();
        // The block's time at its F: Δt (average), or at the peak feed (never longer than Δt:
        // the peak is at least the average).
        let pk = peak_of[w];
        let at_peak = match options.block_feed {
            BlockFeed::Average => dt,
            BlockFeed::Peak if chord > 0.0 && pk.v > 0.0 => (chord / pk.v).min(dt),
            BlockFeed::Peak if chord == 0.0 && pk.udot > 0.0 && pk.du > 0.0 => {
                (pk.du / pk.udot).min(dt)
            }
            BlockFeed::Peak => dt,
        };
        let (mode, f) = if turns || chord == 0.0 {
            inverse_blocks += 1;
            let m = if inverse_mode { "" } else { "G93 " };
            inverse_mode = true;
            (m, 60.0 / at_peak)
        } else {
            let m = if inverse_mode { "G94 " } else { "" };
            inverse_mode = false;
            (m, chord * 60.0 / at_peak)
        };
        let fw = feed_number(f);
        let fv: f64 = fw.parse().unwrap_or(f);
        total += if turns || chord == 0.0 {
            60.0 / fv
        } else {
            chord * 60.0 / fv
        };
        let _ = writeln!(text, "{mode}G1 {} F{fw}", ws.join(" "));
        dwell(&mut text, dwell_after[w]);
        blocks += 1;
        (prev_p, prev_r, prev_t) = (p, r, n.t);
    }
    if taps_written != taps.len() {
        // (A tap whose bottom no written block reached: never dropped quietly.)
        let tap = &toolpath.taps[taps[taps_written.min(taps.len() - 1)].tap];
        return Err(toolpath.error_at(
            tap.line,
            format!(
                "internal: {}: {} of the program's {} taps were written",
                tap.name,
                taps_written,
                taps.len()
            ),
        ));
    }
    if inverse_mode {
        let _ = writeln!(text, "G94");
    }
    // What the program does after its last move (M5, M9).
    setup.before(&mut text, usize::MAX);
    setup.tcp_off(&mut text);
    for f in w.footer {
        let _ = writeln!(text, "{f}");
    }
    Ok(Program {
        text,
        blocks,
        inverse_time_blocks: inverse_blocks,
        time: total + dwell_time + tap_dwell,
        dwell_time: dwell_time + tap_dwell,
        merged,
        split,
        process_split,
    })
}

/// Writes [`program`] to `path` atomically; returns the program.
pub fn write_gcode(
    path: &Path,
    machine: &Machine,
    toolpath: &Toolpath,
    solution: &Solution,
    geometry: &GeometryOptions,
    options: &GcodeOptions,
) -> Result<Program> {
    let prog = program(machine, toolpath, solution, geometry, options)?;
    super::write_atomically(path, prog.text.as_bytes())?;
    Ok(prog)
}

/// The time a program's feeds imply, as the reader records them: the sum over every point
/// after the first of its [`Feed::BlockTime`], or chord / feed for [`Feed::Programmed`]. A
/// rapid or a move without a feed has no programmed time: an error naming its line.
pub fn programmed_time(toolpath: &Toolpath) -> Result<f64> {
    let pts = &toolpath.points;
    let mut total = 0.0;
    for k in 1..pts.len() {
        total += match pts[k].feed {
            Feed::BlockTime(t) => t,
            Feed::Programmed(v) => (pts[k].p - pts[k - 1].p).norm() / v,
            Feed::Rapid | Feed::Unspecified => {
                return Err(Error::parse(
                    &toolpath.source,
                    pts[k].line,
                    "a rapid or a move without feed has no programmed time",
                ));
            }
        };
    }
    Ok(total)
}

impl GcodeOptions {
    /// Checks the largest rotation per block ([`crate::validate`]).
    /// [`write_gcode`] calls it before any work.
    pub fn validate(&self) -> Result<()> {
        match self.max_rotation_deg {
            Some(d) if !(d.is_finite() && d >= MIN_ROTATION_DEG) => Err(Error::option(
                "max_rotation_deg",
                format!(
                    "{}: give at least {MIN_ROTATION_DEG}° (a rotary axis's resolution; smaller \
                     steps only multiply the blocks)",
                    number(d)
                ),
            )),
            _ => Ok(()),
        }
    }
}
