//! Canned drilling cycles, expanded into the moves the control makes along the drilling axis
//! (Z of the working plane; only G17 is read).
//!
//! Each hole is: position over the hole (done by the interpreter: a rapid in X Y at the current
//! height; LinuxCNC and Fanuc first rapid up to R when the tool is below it), then the
//! [`Step`]s below, each timed like any move (rapids at the machine's limits, feeds at the
//! programmed feed) and every dwell counted as time.
//!
//! # Fanuc and LinuxCNC (`G73 G74 G76 G81–G89`, `G98`/`G99`, `R Z Q P K/L`)
//!
//! Rapid to R; then per cycle; then the return level: `G98` the initial level (the Z where the
//! cycle mode began, or R if that is lower), `G99` R.
//!
//! | cycle | moves |
//! |---|---|
//! | G81 | feed to Z, rapid out |
//! | G82 | feed to Z, dwell P, rapid out |
//! | G83 | pecks of Q: feed Q deeper, rapid to R, rapid back to [`PECK_CLEARANCE_MM`] above the last depth, … (Fanuc's d, parameter 5115, is machine data: LinuxCNC's 0.010 in is assumed), rapid out |
//! | G73 | pecks of Q with a short retract by [`PECK_CLEARANCE_MM`] (Fanuc parameter 5114 d) after each, rapid out |
//! | G74, G84 | tapping: feed to Z, dwell P, feed back to R (the spindle reverses), rapid to the return level |
//! | G85 | feed to Z, feed back to R |
//! | G86 | feed to Z, rapid out (spindle stopped) |
//! | G76 | fine boring: feed to Z, dwell P, shift Q in +X (the shift direction is Fanuc parameter 5101 RD1/RD2: +X assumed), rapid out, shift back |
//! | G87 | back boring: shift Q in +X (as G76), rapid to R (below the hole), shift back, feed up to Z, shift Q, rapid to the initial level, shift back |
//! | G88 | feed to Z, dwell P, (the operator retracts by hand: not timed, a warning), rapid out |
//! | G89 | feed to Z, dwell P, feed back to R |
//!
//! P is seconds on LinuxCNC and milliseconds on Fanuc. A peck cycle with Q ≤ 0 or without Q
//! drills in one pass, with a warning that says the controls refuse it (Fanuc alarm PS0045,
//! LinuxCNC's "Q must be positive"): NX posts write `G83 … Q0.0` where the operation has no
//! peck step (the Mori NMV5000 program of `../shared`, a Haas and a Makino program), and
//! an error would refuse those programs whole. A hole needs at most [`MAX_PECKS`] pecks, else it is an
//! error. Repeats `L` (LinuxCNC) / `K` or `L` (Fanuc) drill the hole again, under G91 each one
//! shifted by the X Y increment, at most [`MAX_REPEATS`] (the letters are the dialect's
//! [`super::dialect::DialectSpec::cycle_repeat`]). On LinuxCNC, `K` in a cycle block and
//! `G87` (back boring with I J K offsets) are errors.
//!
//! # Sinumerik (`CYCLE81`–`CYCLE89`, `MCALL`)
//!
//! Parameters (lengths in the current units): RTP retract plane, RFP reference plane, SDIS
//! safety distance, DP final depth (absolute) or DPR (relative to RFP). From the position: rapid
//! to RFP + SDIS, then per cycle, then rapid to RTP. CYCLE81: feed to DP. CYCLE82: feed, dwell
//! DTB s. CYCLE83 (…, FDEP, FDPR, DAM, DTB, DTS, FRF, VARI): the first depth FDEP (absolute) or
//! RFP − FDPR, later steps each DAM shorter (never below DAM); VARI = 1 (swarf removal): rapid
//! to RFP + SDIS after each step, dwell DTS, rapid back to [`PECK_CLEARANCE_MM`] above the
//! depth; VARI = 0 (chip breaking): retract by [`SINUMERIK_CHIP_BREAK_MM`] (the cycle's default
//! _VRT); dwell DTB at the final depth. CYCLE84 (rigid tapping: RTP, RFP, SDIS, DP, DPR,
//! DTB, SDAC, MPIT, PIT, POSS, SST, SST1, _AXN, _PTAB, …): feed to DP at |PIT| × SST, dwell
//! DTB, feed back to RFP + SDIS at |PIT| × SST1 (SST where SST1 is 0 or empty). PIT is in the
//! program's unit (_PTAB 0), mm (1), threads per inch (2) or inch per revolution (3); without
//! PIT, MPIT names a metric coarse thread (MPIT 10: M10, pitch 1.5 mm); without SST, the S
//! programmed before the call. A call without a pitch, or without any speed, taps at the
//! programmed F (a warning); chip breaking or removal steps (_VARI 1/2 with _DAM) are tapped
//! in one pass (a warning). CYCLE85 (…, DTB, FFR, RFF): feed FFR in, dwell, feed RFF out (0 or empty: the
//! programmed F). CYCLE86: feed, dwell, rapid out (the lift-off moves RPA/RPO/RPAP are not
//! read). CYCLE87/CYCLE88: feed, (CYCLE88: dwell), the operator's stop (M0: not timed, a
//! warning), rapid out. CYCLE89: feed, dwell, feed out. `CYCLE76`/`CYCLE77` are Sinumerik's
//! spigot milling cycles, not drilling. A call that gives the spigot's dimensions (`_LENG`,
//! `_WID`; `_PRAD`) is an error: feedopt mills no spigots. A call without them cannot be a
//! spigot (a standard 840D refuses it); its list is then CYCLE86's (RTP, RFP, SDIS, DP, DPR,
//! DTB, …), as NX posts its "boring, no drag" operation, and it is read as CYCLE86 with a
//! warning at its line. The boring cycles 85–89 all move down to DP and back to RTP; they
//! differ in the retract's feed and dwell, and a cycle alias ([`super::parse_cycle_alias`]:
//! `--cycle-alias CYCLE76=CYCLE85`) says which one a machine's CYCLE76 is. A cycle
//! whose RTP lies below RFP + SDIS retracts into the part as written, with a warning.
//!
//! # Heidenhain (`CYCL DEF 200`, `201`, `202`, `203`, `207`, `208`, `209`, `241`, `262`)
//!
//! Q parameters (mm, mm/min, s): Q200 set-up clearance (above the surface), Q201 depth
//! (negative, from the surface; 0: the cycle does nothing), Q203 surface coordinate, Q204 2nd
//! set-up clearance (above the surface), Q206 plunging feed, Q202 plunging depth, Q210 dwell at
//! the top, Q211 dwell at the depth. With S = Q203 + Q200 (the set-up height) and the depths
//! Q203 − Q202, Q203 − 2·Q202, … down to Q203 + Q201 (the last one exact):
//!
//! | cycle | moves |
//! |---|---|
//! | 200 DRILLING | rapid to S; per infeed: feed Q206 to the depth, then (not after the last) rapid to S, dwell Q210, rapid to Q200 above the depth reached; at the depth dwell Q211, rapid to Q203 + max(Q200, Q204) |
//! | 203 UNIVERSAL DRILLING | as 200, but each infeed Q212 shorter (never below Q205); after an infeed, Q213 times a chip break (rapid up Q256, feed on), then a full retract (feed Q208 to S, dwell Q210, rapid to Q200 above the depth); at the depth dwell Q211, feed Q208 to S, rapid to Q203 + Q204 if higher (Q208 = 0: Q206) |
//! | 207 RIGID TAPPING | rapid to S, feed |Q239| × S (pitch × the `TOOL CALL`'s spindle speed) to the depth and back to S, rapid to Q203 + Q204 if higher |
//! | 201 REAMING | rapid to S, feed Q206 to the depth, dwell Q211, feed Q208 to S (Q208 = 0: Q206; MAX: rapid), rapid to Q203 + Q204 if higher |
//! | 202 BORING | as 201, but after the dwell (the spindle stops oriented to Q336: not timed) the tool moves off the wall by [`BORING_DISENGAGE_MM`] in the direction Q214 (0 none, 1 −X, 2 −Y, 3 +X, 4 +Y; at rapid), feeds Q208 to S, moves back over the centre at rapid, then to Q204 |
//! | 209 TAPPING WITH CHIP BREAKING | rapid to S; feed |Q239| × S to Q203 − Q257, back by Q256 × |Q239| (Q256 = 0: out to S) at Q403 × that feed, in again to the next Q257, … to the depth (Q257 = 0: in one pass); out to S at Q403 × |Q239| × S, rapid to Q204 |
//! | 241 SINGLE-LIP DEEP-HOLE DRILLING | rapid to S; feed Q253 (or rapid: MAX) to Q200 above the deepened starting point Q203 − Q379; feed Q206 to the depth (with a dwell depth Q435: to Q203 − Q435, dwell Q211, on at Q206 × Q401 %); dwell Q211; feed Q208 to S (0: Q206), rapid to Q204 |
//! | 262 THREAD MILLING | see below |
//!
//! Sources: HEIDENHAIN TNC 640 user's manual for cycle programming (34059x), the sections
//! "REAMING (Cycle 201)", "BORING (Cycle 202)", "TAPPING WITH CHIP BREAKING (Cycle 209)"
//! (§4.4 of the 34059x-01 edition: Q256 is a multiple of the pitch, 0 retracts to the set-up
//! clearance; Q403 raises the speed and so the feed of the retraction), "SINGLE-LIP
//! DEEP-HOLE DRILLING (Cycle 241)" (Q379 counts from Q203 and takes Q200 into account: the
//! tool feeds at Q253 to Q200 above it) and "THREAD MILLING (Cycle 262)" (TNC 426/430
//! manual §8.3 for its parameters). Assumed where the manual is silent (each said in a
//! warning where it applies): 202's move off the wall and back to the centre at rapid; 209's
//! retraction not limited by the spindle's maximum speed; 241's dwell at Q435 as long as
//! Q211. 241's spindle and coolant parameters (Q426–Q430) move no axis and are not timed;
//! its newer parameters Q401 and Q202 (and 209's Q403, 262's Q512) are read only from the
//! cycle's own `CYCL DEF` (an older definition lacks them; a value an earlier cycle left
//! does not concern it); 241 with Q202 shorter than the depth (several infeeds) is an
//! error.
//!
//! 262 THREAD MILLING: Q335 nominal diameter, Q239 pitch (+ right-hand, − left-hand), Q201
//! thread depth, Q355 threads per step, Q253 pre-positioning feed, Q351 climb (+1) or up-cut
//! (−1) with M3, Q207 milling feed (Q512, feed for approaching, if given and not 0). The tool
//! centre runs on a helix of radius R = (Q335 − tool diameter)/2 (the diameter as for 208),
//! at the pitch |Q239|, counter-clockwise when climb. It works upwards (Z+) for a
//! right-hand thread climb or a left-hand one up-cut, else downwards. Q355 = 1: one helix
//! over the thread, from Q203 + Q201 to Q203 (or down), |Q201| / |Q239| turns; Q355 = 0:
//! one turn at the depth; Q355 = n > 1: one turn in every band of n threads from the depth
//! up (assumed). Each helix: from S at Q253 down the hole's axis to a quarter pitch before
//! the helix's start, an approach half circle of radius R/2 onto the thread's circle
//! (tangent to it, rising a quarter pitch: the thread's lead angle), the helix, the same
//! half circle back to the centre; at the end rapid to S and Q204. The control says only
//! that it approaches and departs "tangentially in a helical movement": the half circles
//! are assumed (a warning says so). The feeds are the tool centre's (no M109).
//!
//! The chip break's retract speed is the machine's: taken as rapid. Q395 = 1 (depth to the
//! full diameter, which needs the tool's point angle) is an error, as is a missing Q
//! parameter the cycle needs. Only 200 and 203 have Q395: 207 and 208 do not read it (a Q395
//! that an earlier definition left does not concern them).
//!
//! A feed parameter may be a word, as the TNC 640 stores them ([`QValue`]): `MAX` (FMAX,
//! written `Q208=MAX` or `Q208= MAX`) is the machine's rapid traverse, `AUTO` (FAUTO) the feed
//! of the `TOOL CALL`. Q208 (retraction feed) takes both; Q206 (plunging feed) takes AUTO only
//! (the control offers no FMAX for it, and plunging at rapid is no drilling): `Q206=MAX` is an
//! error, as is a word in a parameter that is not a feed.
//!
//! # Heidenhain cycles active on definition
//!
//! Most cycles act when called (`CYCL CALL`, `M99`, `M89`); a `CYCL DEF` of one only
//! defines it. Some act when defined: those that move nothing
//! ([`HEIDENHAIN_DEFINITION_ONLY`]: tolerance, spindle orientation, contour data, the
//! dynamics tuning cycles) are read and skipped, and are not the cycle a later call runs (a
//! call after one runs the machining cycle defined before it, or is an error if there is
//! none); those that move the tool when defined ([`HEIDENHAIN_MOVE_ON_DEFINITION`]: the point
//! patterns, which run the cycle defined before at each point) are an error. Datum shift (7),
//! dwell (9), preset (247) and the refused transformations (8, 10, 11, 19, 26) are read by the
//! interpreter.

/// Clearance of a peck's rapid return above the last depth (and G73's retract), mm: LinuxCNC's
/// 0.010 in; on Fanuc it is parameter 5114/5115.
pub const PECK_CLEARANCE_MM: f64 = 0.254;
/// Sinumerik CYCLE83 chip-breaking retract (the cycle's default `_VRT`), mm.
pub const SINUMERIK_CHIP_BREAK_MM: f64 = 1.0;
/// Most pecks in one hole.
pub const MAX_PECKS: usize = 10_000;
/// Most repeats of one hole (`L`, `K`).
pub const MAX_REPEATS: usize = 1_000;

/// One move of a cycle along the drilling axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// Rapid to this Z (mm).
    Rapid(f64),
    /// Feed to this Z (mm) at the programmed feed, or at this feed (mm/min).
    Feed(f64, Option<f64>),
    /// Dwell, seconds.
    Dwell(f64),
    /// Rapid shift in X by this much (mm), at the current Z.
    ShiftX(f64),
    /// A straight move in the working plane to the hole centre plus (dx, dy), mm, at the
    /// current Z, at this feed (mm/min).
    Across(f64, f64, f64),
    /// A rapid straight move in the working plane to the hole centre plus (dx, dy), mm, at the
    /// current Z.
    RapidAcross(f64, f64),
    /// A helix about the hole centre: radius (mm), from the current point (on the circle) by
    /// `sweep` radians (counter-clockwise when positive) while Z goes to `z`, at `feed`
    /// (mm/min).
    Helix {
        radius: f64,
        sweep: f64,
        z: f64,
        feed: f64,
    },
    /// A circular (helical when Z changes) arc about the point (cx, cy) from the hole centre,
    /// mm: from the current point, whose distance to that point is the radius, by `sweep`
    /// radians (counter-clockwise when positive) while Z goes linearly to `z`, at `feed`
    /// (mm/min). A thread's approach and departure arcs.
    Arc {
        cx: f64,
        cy: f64,
        sweep: f64,
        z: f64,
        feed: f64,
    },
}

/// Fanuc / LinuxCNC cycles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    G73,
    G74,
    G76,
    G81,
    G82,
    G83,
    G84,
    G85,
    G86,
    G87,
    G88,
    G89,
}

impl Kind {
    pub fn from_code(code: u32) -> Option<Kind> {
        Some(match code {
            73 => Kind::G73,
            74 => Kind::G74,
            76 => Kind::G76,
            81 => Kind::G81,
            82 => Kind::G82,
            83 => Kind::G83,
            84 => Kind::G84,
            85 => Kind::G85,
            86 => Kind::G86,
            87 => Kind::G87,
            88 => Kind::G88,
            89 => Kind::G89,
            _ => return None,
        })
    }
}

/// The data of one Fanuc/LinuxCNC hole, mm and seconds.
#[derive(Debug, Clone, Copy)]
pub struct Hole {
    pub kind: Kind,
    pub r: f64,
    pub bottom: f64,
    /// Peck depth (G73, G83) or shift (G76, G87), mm.
    pub q: Option<f64>,
    pub dwell: f64,
    /// Return level: the initial level (G98) or R (G99).
    pub clear: f64,
    pub initial: f64,
}

/// G87's shift of the oriented tool, mm (Q; the direction is Fanuc parameter 5101 RD1/RD2:
/// +X assumed, as for G76): the tool shifts by it at the initial level, rapids down to R
/// (below the hole) and shifts back, feeds up to Z, shifts again, rapids to the initial level
/// and shifts back (Fanuc's "back boring cycle G87").
pub fn g87_shift(h: &Hole) -> f64 {
    if h.kind == Kind::G87 {
        h.q.unwrap_or(0.0).abs()
    } else {
        0.0
    }
}

/// Pecks from `top` to `bottom` (downwards) of `q` each: the depths reached.
fn pecks(top: f64, bottom: f64, q: f64) -> Result<Vec<f64>, String> {
    let depth = top - bottom;
    let n = (depth / q).ceil();
    if n.is_nan() || n > MAX_PECKS as f64 {
        return Err(format!(
            "{n} pecks of {q} mm in one hole (more than {MAX_PECKS}): check Q"
        ));
    }
    let n = (n as usize).max(1);
    Ok((1..=n)
        .map(|k| if k == n { bottom } else { top - k as f64 * q })
        .collect())
}

/// The steps of a hole, from R on (the interpreter has rapidded to R already). The second
/// value names what is not timed, if anything (for a warning).
pub fn fanuc_steps(h: &Hole) -> Result<(Vec<Step>, Option<&'static str>), String> {
    use Step::*;
    let mut s = Vec::new();
    let mut note = None;
    let peck = |q: Option<f64>| q.filter(|q| *q > 0.0);
    match h.kind {
        Kind::G81 => s.extend([Feed(h.bottom, None), Rapid(h.clear)]),
        Kind::G82 => s.extend([Feed(h.bottom, None), Dwell(h.dwell), Rapid(h.clear)]),
        Kind::G83 | Kind::G73 => match peck(h.q) {
            None => {
                note = Some(
                    "peck depth Q missing or ≤ 0: a Fanuc control stops here (alarm PS0045, \
                     address Q not found) and LinuxCNC refuses the block (Q must be \
                     positive); feedopt drills the hole in one pass, as G81 does: give the \
                     peck depth Q > 0 for the pecks",
                );
                s.extend([Feed(h.bottom, None), Rapid(h.clear)]);
            }
            Some(q) => {
                let depths = pecks(h.r, h.bottom, q)?;
                let mut last = h.r;
                for (k, d) in depths.iter().enumerate() {
                    if k > 0 {
                        if h.kind == Kind::G83 {
                            s.push(Rapid(h.r));
                            s.push(Rapid((last + PECK_CLEARANCE_MM).min(h.r)));
                        } else {
                            s.push(Rapid((last + PECK_CLEARANCE_MM).min(h.r)));
                        }
                    }
                    s.push(Feed(*d, None));
                    last = *d;
                }
                s.push(Rapid(h.clear));
            }
        },
        Kind::G74 | Kind::G84 => {
            s.extend([Feed(h.bottom, None), Dwell(h.dwell), Feed(h.r, None)]);
            s.push(Rapid(h.clear));
        }
        Kind::G85 => s.extend([Feed(h.bottom, None), Feed(h.r, None), Rapid(h.clear)]),
        Kind::G86 => s.extend([Feed(h.bottom, None), Rapid(h.clear)]),
        Kind::G89 => s.extend([
            Feed(h.bottom, None),
            Dwell(h.dwell),
            Feed(h.r, None),
            Rapid(h.clear),
        ]),
        Kind::G76 => {
            let shift = h.q.unwrap_or(0.0).abs();
            s.extend([Feed(h.bottom, None), Dwell(h.dwell)]);
            if shift > 0.0 {
                s.push(ShiftX(shift));
            }
            s.push(Rapid(h.clear));
            if shift > 0.0 {
                s.push(ShiftX(-shift));
            }
        }
        // The shift before the rapid down to R is the interpreter's (`g87_shift`): it
        // comes before the rapid to R, which is not one of these steps.
        Kind::G87 => {
            let shift = g87_shift(h);
            if shift > 0.0 {
                s.push(ShiftX(-shift));
            }
            s.push(Feed(h.bottom, None));
            if shift > 0.0 {
                s.push(ShiftX(shift));
            }
            s.push(Rapid(h.initial.max(h.bottom)));
            if shift > 0.0 {
                s.push(ShiftX(-shift));
            }
        }
        Kind::G88 => {
            note = Some("G88 stops for a manual retract: the operator's time is not counted");
            s.extend([Feed(h.bottom, None), Dwell(h.dwell), Rapid(h.clear)]);
        }
    }
    Ok((s, note))
}

/// Heidenhain cycles that act when defined and move nothing: number and name. A `CYCL DEF` of
/// one is skipped; it does not replace the cycle a later `CYCL CALL` or `M99` runs.
pub const HEIDENHAIN_DEFINITION_ONLY: [(u32, &str); 7] = [
    (13, "ORIENTATION"),
    (14, "CONTOUR"),
    (20, "CONTOUR DATA"),
    (32, "TOLERANCE"),
    (271, "OCM CONTOUR DATA"),
    // Dynamics cycles, as hyperMILL posts them at every tool (332 for a Trimill, 392 for DMG
    // MORI machines): they tune the axes for the machining mode and the workpiece's weight.
    (332, "TUNING"),
    (392, "ATC"),
];

/// Heidenhain cycles that move the tool when defined: number and name. They run the
/// machining cycle defined before them at each point of a pattern, which feedopt does not
/// expand: a `CYCL DEF` of one is an error.
pub const HEIDENHAIN_MOVE_ON_DEFINITION: [(u32, &str); 3] = [
    (220, "POLAR PATTERN"),
    (221, "CARTESIAN PATTERN"),
    (224, "DATAMATRIX CODE PATTERN"),
];

/// The Heidenhain machining cycles feedopt expands when called.
pub const HEIDENHAIN_EXPANDED: [u32; 9] = [200, 201, 202, 203, 207, 208, 209, 241, 262];

/// [`HEIDENHAIN_EXPANDED`] for messages: "200, 201, … and 262 are".
pub fn expanded_list() -> String {
    let n: Vec<String> = HEIDENHAIN_EXPANDED.iter().map(u32::to_string).collect();
    format!("{} and {} are", n[..n.len() - 1].join(", "), n[n.len() - 1])
}

/// Cycle 202: how far the tool moves off the wall at the depth in the disengaging direction
/// Q214, mm: "0.2 mm (fixed value)" (TNC 640 cycle programming manual, BORING, Cycle 202,
/// cycle run step 5).
pub const BORING_DISENGAGE_MM: f64 = 0.2;

/// The value of a Heidenhain cycle's Q parameter: a number, or the word a feed parameter may
/// hold instead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum QValue {
    Number(f64),
    /// `MAX` (FMAX): the machine's rapid traverse.
    Max,
    /// `AUTO` (FAUTO): the feed of the `TOOL CALL`.
    Auto,
}

/// A speed a cycle moves at: a feed (mm/min) or rapid traverse.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Rate {
    PerMinute(f64),
    Rapid,
}

impl Rate {
    /// The move to `z` at this rate.
    fn to(self, z: f64) -> Step {
        match self {
            Rate::PerMinute(f) => Step::Feed(z, Some(f)),
            Rate::Rapid => Step::Rapid(z),
        }
    }
}

/// Heidenhain machining cycle `number` ([`HEIDENHAIN_EXPANDED`]) from its Q parameters
/// (`q(200)` …; `given(n)`: the cycle's own `CYCL DEF` gave Qn), the spindle speed (rpm, for
/// 207 and 209), the `TOOL CALL`'s feed (mm/min, for a feed parameter given as `AUTO`), the
/// tool's diameter (mm, for 208 and 262: the control takes it from its tool table) and a
/// raise of the surface Q203 by `offset` mm (a pattern point's Z). Starts from where the tool
/// is (over the hole). The second value names assumptions, for warnings. The moves of each
/// cycle: the module's documentation.
///
/// Cycle 208 (bore milling), as the TNC 640 runs it with one pass (no Q370): rapid to the
/// set-up clearance, over to the circle of radius (Q335 − D)/2 about the hole, a helix down
/// at Q206 with Q334 per turn to the depth, one more full circle there, back to the centre and
/// up at rapid to the set-up clearance (or the second, Q204). Where Q335 equals the tool's
/// diameter the tool bores straight down. Climb (Q351 = +1) runs counter-clockwise with M3.
#[allow(clippy::too_many_arguments)]
pub fn heidenhain_steps(
    number: u32,
    q: &dyn Fn(u32) -> Option<QValue>,
    given: &dyn Fn(u32) -> bool,
    spindle_rpm: Option<f64>,
    tool_feed: Option<f64>,
    tool_diameter: Option<f64>,
    offset: f64,
) -> Result<(Vec<Step>, Vec<&'static str>), String> {
    use Step::*;
    if !HEIDENHAIN_EXPANDED.contains(&number) {
        return Err(format!(
            "cycle {number} is not a cycle feedopt can expand ({}): post the operation as L \
             moves",
            expanded_list()
        ));
    }
    let raw = q;
    // A parameter that is not a feed: a number, if given.
    let q = |n: u32| -> Result<Option<f64>, String> {
        match raw(n) {
            None => Ok(None),
            Some(QValue::Number(v)) => Ok(Some(v)),
            Some(word) => Err(format!(
                "cycle {number}: Q{n} = {}: only a feed parameter may be MAX (FMAX) or AUTO \
                 (FAUTO)",
                if word == QValue::Max { "MAX" } else { "AUTO" }
            )),
        }
    };
    // A feed parameter: its rate, if given (`MAX` only where `rapid_allowed`).
    let rate = |n: u32, rapid_allowed: bool| -> Result<Option<Rate>, String> {
        let f = match raw(n) {
            None => return Ok(None),
            Some(QValue::Max) if rapid_allowed => return Ok(Some(Rate::Rapid)),
            Some(QValue::Max) => {
                return Err(format!(
                    "cycle {number}: Q{n} = MAX: this feed takes a value or AUTO (FAUTO), not \
                     FMAX"
                ));
            }
            Some(QValue::Auto) => tool_feed.filter(|f| f.is_finite()).ok_or_else(|| {
                format!(
                    "cycle {number}: Q{n} = AUTO (FAUTO) is the TOOL CALL's feed, and no TOOL \
                     CALL gave F"
                )
            })?,
            Some(QValue::Number(f)) => f,
        };
        if (1e-3..=1e9).contains(&f) {
            Ok(Some(Rate::PerMinute(f)))
        } else {
            Err(format!(
                "cycle {number}: feed Q{n} = {f} mm/min is out of range"
            ))
        }
    };
    let need = |n: u32| {
        q(n)?.ok_or_else(|| format!("cycle {number}: Q{n} is not defined (the CYCL DEF gives it)"))
    };
    let finite = |n: u32, v: f64| {
        if v.is_finite() && v.abs() <= crate::toolpath::MAX_COORDINATE_MM {
            Ok(v)
        } else {
            Err(format!("cycle {number}: Q{n} = {v} is out of range"))
        }
    };
    let surface = finite(203, need(203)?)? + offset;
    let clearance = finite(200, need(200)?)?.abs();
    let depth = finite(201, need(201)?)?;
    if depth > 0.0 {
        return Err(format!(
            "cycle {number}: depth Q201 = {depth} must be negative (below the surface Q203)"
        ));
    }
    if depth == 0.0 {
        return Ok((
            Vec::new(),
            vec!["depth Q201 = 0: the control does not run the cycle"],
        ));
    }
    // Depth reference: 200 and 203 have it (207 and 208 do not read Q395).
    if matches!(number, 200 | 203)
        && let Some(v) = q(395)?.filter(|v| *v != 0.0)
    {
        return Err(format!(
            "cycle {number}: Q395 = {v}: the depth is read to the tool's tip (Q395 = 0); Q395 = \
             1 (to the full diameter) needs the tool's point angle: post with Q395 = 0"
        ));
    }
    let second = finite(204, q(204)?.unwrap_or(0.0))?.max(0.0);
    let safe = surface + clearance;
    let bottom = surface + depth;
    let dwell = |n: u32| -> Result<f64, String> {
        let v = q(n)?.unwrap_or(0.0);
        if (0.0..=1e6).contains(&v) {
            Ok(v)
        } else {
            Err(format!(
                "cycle {number}: dwell Q{n} = {v} s is out of range"
            ))
        }
    };
    // The plunging feed Q206: a value or AUTO.
    let plunging = || -> Result<f64, String> {
        match rate(206, false)? {
            Some(Rate::PerMinute(f)) => Ok(f),
            _ => Err(format!(
                "cycle {number}: Q206 is not defined (the CYCL DEF gives it)"
            )),
        }
    };
    // The retraction feed Q208 (203, 201, 202, 241): MAX is rapid, 0 (or none) the plunging
    // feed `f`.
    let retraction = |f: f64| -> Result<Rate, String> {
        Ok(match raw(208) {
            Some(QValue::Number(v)) if finite(208, v)? <= 0.0 => Rate::PerMinute(f),
            None => Rate::PerMinute(f),
            _ => rate(208, true)?.unwrap_or(Rate::PerMinute(f)),
        })
    };
    // The spindle speed × pitch Q239 of the tapping cycles (207, 209): the feed, mm/min, and
    // the pitch, mm.
    let tapping = || -> Result<(f64, f64), String> {
        let pitch = finite(239, need(239)?)?.abs();
        if pitch == 0.0 {
            return Err(format!("cycle {number}: the thread pitch Q239 is 0"));
        }
        let Some(rpm) = spindle_rpm.filter(|r| r.is_finite() && *r > 0.0) else {
            return Err(format!(
                "cycle {number}: rigid tapping feeds at pitch × spindle speed, and no TOOL CALL \
                 gave S"
            ));
        };
        let f = pitch * rpm;
        if !(1e-3..=1e9).contains(&f) {
            return Err(format!(
                "cycle {number}: the tapping feed Q239 × S = {f} mm/min is out of range"
            ));
        }
        Ok((f, pitch))
    };
    // Up to the 2nd set-up clearance, where it is above the set-up clearance.
    let second_clearance = |s: &mut Vec<Step>| {
        if second > clearance {
            s.push(Rapid(surface + second));
        }
    };
    let mut s = vec![Rapid(safe)];
    let mut notes = Vec::new();
    match number {
        201 | 202 => {
            let f = plunging()?;
            let bottom_dwell = dwell(211)?;
            let retract = retraction(f)?;
            s.push(Feed(bottom, Some(f)));
            if bottom_dwell > 0.0 {
                s.push(Dwell(bottom_dwell));
            }
            // 202: the spindle stops oriented to Q336 (no axis moves), then the tool moves off
            // the wall in the direction Q214.
            let off = if number == 202 {
                let direction = finite(214, need(214)?)?;
                let d = BORING_DISENGAGE_MM;
                let whole = if direction.fract() == 0.0 {
                    direction as i64
                } else {
                    -1
                };
                let off = match whole {
                    0 => None,
                    1 => Some((-d, 0.0)),
                    2 => Some((0.0, -d)),
                    3 => Some((d, 0.0)),
                    4 => Some((0.0, d)),
                    _ => {
                        let v = direction;
                        return Err(format!(
                            "cycle 202: disengaging direction Q214 = {v}: it is 0 (none), 1 \
                             (−X), 2 (−Y), 3 (+X) or 4 (+Y)"
                        ));
                    }
                };
                notes.push(
                    "the oriented spindle stop (Q336) at the depth is not timed; the move off the \
                     wall (Q214, 0.2 mm) and back to the centre at the set-up clearance are \
                     taken at rapid traverse",
                );
                off
            } else {
                None
            };
            if let Some((dx, dy)) = off {
                s.push(RapidAcross(dx, dy));
            }
            s.push(retract.to(safe));
            if off.is_some() {
                s.push(RapidAcross(0.0, 0.0));
            }
            second_clearance(&mut s);
        }
        209 => {
            let (f, pitch) = tapping()?;
            // Q403 (RPM factor for retraction): a TNC 640 parameter an older 209 lacks; read
            // from this definition only.
            let factor = if given(403) {
                let v = q(403)?.unwrap_or(1.0);
                if !(v > 0.0 && v <= 10.0) {
                    return Err(format!(
                        "cycle 209: RPM factor for retraction Q403 = {v}: it is 0.0001 to 10"
                    ));
                }
                v
            } else {
                1.0
            };
            let back = f * factor;
            let infeed = finite(257, need(257)?)?.abs();
            let mut depth_now = surface;
            if infeed > 0.0 && infeed < surface - bottom {
                let retract = finite(256, need(256)?)?.abs() * pitch;
                let mut n = 0usize;
                loop {
                    let next = (depth_now - infeed).max(bottom);
                    s.push(Feed(next, Some(f)));
                    depth_now = next;
                    n += 1;
                    if depth_now <= bottom {
                        break;
                    }
                    if n >= MAX_PECKS {
                        return Err(format!(
                            "cycle 209: more than {MAX_PECKS} infeeds in one hole: check Q257"
                        ));
                    }
                    // Q256 = 0: out of the hole to the set-up clearance.
                    let up = if retract > 0.0 {
                        (depth_now + retract).min(safe)
                    } else {
                        safe
                    };
                    s.push(Feed(up, Some(back)));
                }
            } else {
                s.push(Feed(bottom, Some(f)));
            }
            s.push(Feed(safe, Some(back)));
            second_clearance(&mut s);
            notes.push(
                "the spindle orientation Q336 is not timed, and the retraction speed Q403 × S is \
                 taken as programmed (the control limits it to the gear range's maximum speed)",
            );
        }
        241 => {
            let f = plunging()?;
            let retract = retraction(f)?;
            let pre = rate(253, true)?.ok_or_else(|| {
                "cycle 241: Q253 is not defined (the CYCL DEF gives it)".to_string()
            })?;
            let start = finite(379, need(379)?)?;
            if start < 0.0 || surface - start < bottom {
                return Err(format!(
                    "cycle 241: the deepened starting point Q379 = {start} is not between the \
                     surface and the depth Q201"
                ));
            }
            // Newer parameters (TNC 640): read from this definition only, else as the cycle
            // without them (one infeed, no feed factor).
            if given(202) {
                let plunge = finite(202, q(202)?.unwrap_or(0.0))?.abs();
                if plunge > 0.0 && plunge < surface - start - bottom {
                    return Err(format!(
                        "cycle 241: maximum plunging depth Q202 = {plunge} mm is less than the \
                         depth: several infeeds (Q202, Q212, Q205) are not supported; post the \
                         cycle with Q202 = 0 or at least the depth"
                    ));
                }
            }
            let factor = if given(401) {
                let v = q(401)?.unwrap_or(100.0);
                if !(v > 0.0 && v <= 100.0) {
                    return Err(format!(
                        "cycle 241: feed rate factor Q401 = {v} %: it is 0.0001 to 100"
                    ));
                }
                v / 100.0
            } else {
                1.0
            };
            let bottom_dwell = dwell(211)?;
            // From the set-up clearance at Q253 to Q200 above the deepened starting point.
            let pre_z = surface - start + clearance;
            if pre_z < safe {
                s.push(pre.to(pre_z));
            }
            // Q435 (dwell depth, from the surface): dwell there, then on at Q206 × Q401.
            let dwell_depth = surface - finite(435, q(435)?.unwrap_or(0.0))?.abs();
            if dwell_depth < surface && dwell_depth > bottom && dwell_depth < pre_z {
                s.push(Feed(dwell_depth, Some(f)));
                if bottom_dwell > 0.0 {
                    s.push(Dwell(bottom_dwell));
                }
                s.push(Feed(bottom, Some(f * factor)));
                notes.push(
                    "the dwell at the dwell depth Q435 is taken as long as the dwell at the \
                     depth Q211",
                );
            } else {
                s.push(Feed(bottom, Some(f)));
            }
            if bottom_dwell > 0.0 {
                s.push(Dwell(bottom_dwell));
            }
            s.push(retract.to(safe));
            second_clearance(&mut s);
            if [426, 427, 428, 429, 430].iter().any(|&n| given(n)) {
                notes.push(
                    "the spindle direction and speeds Q426–Q428 and the coolant functions \
                     Q429/Q430 move no axis: not timed",
                );
            }
        }
        262 => {
            let mill = match rate(207, false)? {
                Some(Rate::PerMinute(f)) => f,
                _ => return Err("cycle 262: Q207 is not defined (the CYCL DEF gives it)".into()),
            };
            let pre = rate(253, true)?.ok_or_else(|| {
                "cycle 262: Q253 is not defined (the CYCL DEF gives it)".to_string()
            })?;
            // Q512 (feed for approaching, TNC 640): from this definition only; 0 is Q207.
            let approach = match raw(512) {
                Some(QValue::Number(v)) if given(512) && v == 0.0 => mill,
                Some(_) if given(512) => match rate(512, false)? {
                    Some(Rate::PerMinute(f)) => f,
                    _ => mill,
                },
                _ => mill,
            };
            let nominal = finite(335, need(335)?)?.abs();
            let signed_pitch = finite(239, need(239)?)?;
            let pitch = signed_pitch.abs();
            if pitch == 0.0 {
                return Err("cycle 262: the thread pitch Q239 is 0".to_string());
            }
            let per_step = finite(355, need(355)?)?;
            if per_step < 0.0 || per_step.fract() != 0.0 {
                return Err(format!(
                    "cycle 262: threads per step Q355 = {per_step}: it is 0, 1 or a whole number \
                     of threads"
                ));
            }
            let climb = finite(351, need(351)?)? >= 0.0;
            let Some(d) = tool_diameter.filter(|d| d.is_finite() && *d > 0.0) else {
                return Err(
                    "cycle 262 mills a helix of radius (Q335 − tool diameter)/2, and the control \
                     takes the diameter from its tool table: give it (--tool-diameter, or the \
                     machine file's tool.diameter)"
                        .to_string(),
                );
            };
            let radius = (nominal - d) / 2.0;
            if radius <= 1e-6 {
                return Err(format!(
                    "cycle 262: the tool ({d} mm) is not narrower than the thread Q335 = \
                     {nominal} mm"
                ));
            }
            let length = surface - bottom;
            // The working direction: Z+ (from the depth up) for a right-hand thread milled
            // climb or a left-hand one up-cut, else Z−; climb milling with M3 runs
            // counter-clockwise.
            let up = (signed_pitch > 0.0) == climb;
            let (dz, turn) = (if up { 1.0 } else { -1.0 }, if climb { 1.0 } else { -1.0 });
            // The helical passes (start Z, end Z): Q355 = 1 one over the thread's length;
            // 0 one turn at the depth; n > 1 one turn in every band of n threads from the depth
            // up (the tool offset by n × Q239 between them), taken in the working direction.
            let mut passes: Vec<(f64, f64)> = Vec::new();
            if per_step == 1.0 {
                passes.push(if up {
                    (bottom, surface)
                } else {
                    (surface, bottom)
                });
            } else {
                let band = if per_step == 0.0 {
                    length
                } else {
                    per_step * pitch
                };
                let k = (length / band).ceil().max(1.0);
                if k > MAX_PECKS as f64 {
                    return Err(format!(
                        "cycle 262: more than {MAX_PECKS} helical passes: check Q355"
                    ));
                }
                for j in 0..k as usize {
                    let base = bottom + j as f64 * band;
                    passes.push(if up {
                        (base, base + pitch)
                    } else {
                        (base + pitch, base)
                    });
                }
                if !up {
                    passes.reverse();
                }
                notes.push(
                    "threads per step Q355 ≠ 1: one 360° helix at the depth (0) or in every band \
                     of Q355 threads from the depth up (> 1) is assumed",
                );
            }
            let tau = std::f64::consts::TAU;
            let quarter = pitch / 4.0;
            for &(from, to) in &passes {
                let sweep = turn * tau * (to - from).abs() / pitch;
                if sweep.abs() / tau > MAX_PECKS as f64 {
                    return Err(format!(
                        "cycle 262: more than {MAX_PECKS} helix turns: check Q239 and Q201"
                    ));
                }
                // To the start of the approach arc, on the hole's axis: at Q253.
                let start = from - dz * quarter;
                s.push(pre.to(start));
                // The approach: a half circle of radius R/2 from the centre onto the thread's
                // circle at +X, tangent to it, rising Q239/4 (the thread's lead angle).
                s.push(Arc {
                    cx: radius / 2.0,
                    cy: 0.0,
                    sweep: turn * std::f64::consts::PI,
                    z: from,
                    feed: approach,
                });
                s.push(Helix {
                    radius,
                    sweep,
                    z: to,
                    feed: mill,
                });
                // The departure: the same half circle back to the centre.
                let end = sweep;
                s.push(Arc {
                    cx: radius / 2.0 * end.cos(),
                    cy: radius / 2.0 * end.sin(),
                    sweep: turn * std::f64::consts::PI,
                    z: to + dz * quarter,
                    feed: approach,
                });
            }
            s.push(Rapid(safe));
            second_clearance(&mut s);
            notes.push(
                "the approach and departure are taken as half circles of half the helix radius \
                 from and to the hole's centre, rising a quarter pitch each (the manual gives no \
                 dimensions)",
            );
        }
        200 | 203 => {
            let f = plunging()?;
            let plunge = finite(202, need(202)?)?.abs();
            if plunge == 0.0 {
                return Err(format!("cycle {number}: plunging depth Q202 is 0"));
            }
            let (top, bottom_dwell) = (dwell(210)?, dwell(211)?);
            let (decrement, breaks, minimum, retract_feed, chip) = if number == 203 {
                let retract = retraction(f)?;
                (
                    finite(212, q(212)?.unwrap_or(0.0))?.abs(),
                    finite(213, q(213)?.unwrap_or(0.0))?.max(0.0).round() as u64,
                    finite(205, q(205)?.unwrap_or(0.0))?.abs(),
                    retract,
                    finite(256, q(256)?.unwrap_or(0.0))?.abs(),
                )
            } else {
                (0.0, 0, 0.0, Rate::PerMinute(f), 0.0)
            };
            if breaks > 0 {
                notes.push("the chip-breaking retract Q256 is taken at rapid traverse");
            }
            let mut depth_now = surface;
            let mut step = plunge;
            let mut broken = 0u64;
            let mut n = 0usize;
            loop {
                let next = (depth_now - step).max(bottom);
                s.push(Feed(next, Some(f)));
                depth_now = next;
                n += 1;
                if depth_now <= bottom {
                    break;
                }
                if n >= MAX_PECKS {
                    return Err(format!(
                        "cycle {number}: more than {MAX_PECKS} infeeds in one hole: check Q202"
                    ));
                }
                if broken < breaks {
                    broken += 1;
                    s.push(Rapid((depth_now + chip).min(safe)));
                } else {
                    broken = 0;
                    if number == 203 {
                        s.push(retract_feed.to(safe));
                    } else {
                        s.push(Rapid(safe));
                    }
                    if top > 0.0 {
                        s.push(Dwell(top));
                    }
                    s.push(Rapid((depth_now + clearance).min(safe)));
                }
                if decrement > 0.0 {
                    step = (step - decrement).max(minimum);
                    if step <= 1e-6 {
                        return Err(format!(
                            "cycle {number}: the decrement Q212 brings the plunging depth to 0; \
                             give a minimum plunging depth Q205"
                        ));
                    }
                }
            }
            if bottom_dwell > 0.0 {
                s.push(Dwell(bottom_dwell));
            }
            if number == 203 {
                s.push(retract_feed.to(safe));
                if second > clearance {
                    s.push(Rapid(surface + second));
                }
            } else {
                s.push(Rapid(surface + clearance.max(second)));
            }
        }
        208 => {
            let f = plunging()?;
            let nominal = finite(335, need(335)?)?.abs();
            if q(370)?.is_some_and(|v| v != 0.0) {
                return Err(
                    "cycle 208: Q370 (path overlap: several passes out to the diameter) is not \
                     supported; post with one pass (no Q370)"
                        .to_string(),
                );
            }
            let Some(d) = tool_diameter.filter(|d| d.is_finite() && *d > 0.0) else {
                return Err(
                    "cycle 208 mills a circle of radius (Q335 − tool diameter)/2, and the \
                     control takes the diameter from its tool table: give it (--tool-diameter, \
                     or the machine file's tool.diameter)"
                        .to_string(),
                );
            };
            let radius = (nominal - d) / 2.0;
            if radius < -1e-6 {
                return Err(format!(
                    "cycle 208: the tool ({d} mm) is wider than the hole Q335 = {nominal} mm"
                ));
            }
            let ccw = q(351)?.unwrap_or(1.0) >= 0.0;
            if radius <= 1e-6 {
                // Q335 = the tool's diameter: straight down, no helix.
                s.push(Feed(bottom, Some(f)));
            } else {
                let pitch = finite(334, need(334)?)?.abs();
                if pitch <= 0.0 {
                    return Err("cycle 208: the infeed per helix Q334 is 0".to_string());
                }
                let turns = (safe - bottom) / pitch;
                if turns > MAX_PECKS as f64 {
                    return Err(format!(
                        "cycle 208: more than {MAX_PECKS} helix turns in one hole: check Q334"
                    ));
                }
                let sign = if ccw { 1.0 } else { -1.0 };
                let tau = std::f64::consts::TAU;
                s.extend([
                    Across(radius, 0.0, f),
                    Helix {
                        radius,
                        sweep: sign * turns * tau,
                        z: bottom,
                        feed: f,
                    },
                    Helix {
                        radius,
                        sweep: sign * tau,
                        z: bottom,
                        feed: f,
                    },
                    Across(0.0, 0.0, f),
                ]);
                notes.push(
                    "the move onto the circle is taken straight (the control's rounding arc is a \
                     little longer), the move back to the centre at Q206",
                );
            }
            s.push(Rapid(safe));
            if second > clearance {
                s.push(Rapid(surface + second));
            }
        }
        _ => {
            // 207
            let (f, _) = tapping()?;
            s.extend([Feed(bottom, Some(f)), Feed(safe, Some(f))]);
            second_clearance(&mut s);
        }
    }
    Ok((s, notes))
}

/// The pitch (mm) of ISO metric coarse thread `M<size>`, as CYCLE84's MPIT names it (3 to 48).
pub fn metric_coarse_pitch(size: f64) -> Option<f64> {
    const TABLE: [(f64, f64); 21] = [
        (3.0, 0.5),
        (4.0, 0.7),
        (5.0, 0.8),
        (6.0, 1.0),
        (8.0, 1.25),
        (10.0, 1.5),
        (12.0, 1.75),
        (14.0, 2.0),
        (16.0, 2.0),
        (18.0, 2.5),
        (20.0, 2.5),
        (22.0, 2.5),
        (24.0, 3.0),
        (27.0, 3.0),
        (30.0, 3.5),
        (33.0, 3.5),
        (36.0, 4.0),
        (39.0, 4.0),
        (42.0, 4.5),
        (45.0, 4.5),
        (48.0, 5.0),
    ];
    TABLE.iter().find(|(m, _)| *m == size).map(|&(_, p)| p)
}

/// Sinumerik `CYCLE8x(...)` parameters, lengths in mm (already scaled), positional; `rpm`: the
/// spindle speed programmed before the call (CYCLE84 taps at pitch × SST, or × this).
pub fn sinumerik_steps(
    number: u32,
    p: &[Option<f64>],
    rpm: Option<f64>,
) -> Result<(Vec<Step>, Vec<&'static str>), String> {
    use Step::*;
    let get = |k: usize| p.get(k).copied().flatten();
    let name = format!("CYCLE{number}");
    let rtp = get(0).ok_or_else(|| format!("{name}: RTP (retract plane) is missing"))?;
    let rfp = get(1).unwrap_or(0.0);
    let sdis = get(2).unwrap_or(0.0).abs();
    let dp = match (get(3), get(4)) {
        (Some(dp), _) => dp,
        (None, Some(dpr)) => rfp - dpr.abs(),
        (None, None) => return Err(format!("{name}: neither DP nor DPR (the depth) is given")),
    };
    let safe = rfp + sdis;
    let mut notes = Vec::new();
    if rtp < safe {
        notes
            .push("retract plane RTP below RFP + SDIS: the retract moves into the part as written");
    }
    let dwell = |k: usize| get(k).unwrap_or(0.0).max(0.0);
    let mut s = vec![Rapid(safe)];
    match number {
        81 => s.push(Feed(dp, None)),
        82 => s.extend([Feed(dp, None), Dwell(dwell(5))]),
        83 => {
            let first = match (get(5), get(6)) {
                (Some(fdep), _) => rfp - fdep,
                (None, Some(fdpr)) => fdpr.abs(),
                (None, None) => rfp - dp,
            };
            let first = if first > 0.0 { first } else { rfp - dp };
            let dam = get(7).unwrap_or(0.0).abs();
            let (dtb, dts) = (dwell(8), dwell(9));
            let vari = get(11).unwrap_or(0.0);
            let mut depth = rfp;
            let mut step = first;
            let mut n = 0usize;
            loop {
                let next = (depth - step).max(dp);
                if n > 0 {
                    if vari == 1.0 {
                        s.push(Rapid(safe));
                        if dts > 0.0 {
                            s.push(Dwell(dts));
                        }
                        s.push(Rapid(depth + PECK_CLEARANCE_MM));
                    } else {
                        s.push(Rapid(depth + SINUMERIK_CHIP_BREAK_MM));
                    }
                }
                s.push(Feed(next, None));
                depth = next;
                n += 1;
                if depth <= dp {
                    break;
                }
                if n >= MAX_PECKS {
                    return Err(format!(
                        "{name}: more than {MAX_PECKS} pecks in one hole: check FDEP/FDPR/DAM"
                    ));
                }
                if dam > 0.0 {
                    step = (step - dam).max(dam);
                }
            }
            if dtb > 0.0 {
                s.push(Dwell(dtb));
            }
        }
        84 => {
            // CYCLE84(RTP, RFP, SDIS, DP, DPR, DTB, SDAC, MPIT, PIT, POSS, SST, SST1, _AXN,
            // _PTAB, _TECHNO, _VARI, _DAM, …): PIT in mm here (the caller converted _PTAB).
            let pitch = match (get(8).filter(|v| *v != 0.0), get(7).filter(|v| *v != 0.0)) {
                (Some(pit), _) => Some(pit.abs()),
                (None, Some(mpit)) => Some(metric_coarse_pitch(mpit.abs()).ok_or_else(|| {
                    format!(
                        "{name}: MPIT {mpit} is not a metric thread size M3 … M48 whose coarse \
                         pitch the cycle takes: give the pitch as PIT"
                    )
                })?),
                (None, None) => None,
            };
            let speed = |k: usize| get(k).map(f64::abs).filter(|v| *v > 0.0);
            let tap = speed(10).or(rpm.filter(|r| *r > 0.0));
            let (down, up) = match (pitch, tap) {
                (Some(pitch), Some(tap)) => {
                    (Some(pitch * tap), Some(pitch * speed(11).unwrap_or(tap)))
                }
                (Some(_), None) => {
                    notes.push(
                        "CYCLE84 without a speed (SST, or S before the call): taps at the \
                         programmed F",
                    );
                    (None, None)
                }
                (None, _) => {
                    notes.push("CYCLE84 without a pitch (MPIT or PIT): taps at the programmed F");
                    (None, None)
                }
            };
            if matches!(get(15), Some(v) if v == 1.0 || v == 2.0)
                && get(16).is_some_and(|d| d != 0.0)
            {
                notes.push(
                    "CYCLE84 with _VARI 1 or 2 (chip breaking or removal in steps _DAM): the \
                     steps are not modelled, the hole is tapped in one pass",
                );
            }
            s.extend([Feed(dp, down), Dwell(dwell(5)), Feed(safe, up)]);
        }
        85 => {
            let feed = |k: usize| get(k).filter(|f| *f > 0.0);
            s.extend([Feed(dp, feed(6)), Dwell(dwell(5)), Feed(safe, feed(7))]);
        }
        86 => s.extend([Feed(dp, None), Dwell(dwell(5))]),
        87 => {
            notes.push("CYCLE87 stops (M0) for the operator: that time is not counted");
            s.push(Feed(dp, None));
        }
        88 => {
            notes.push("CYCLE88 stops (M0) for the operator: that time is not counted");
            s.extend([Feed(dp, None), Dwell(dwell(5))]);
        }
        89 => s.extend([Feed(dp, None), Dwell(dwell(5)), Feed(safe, None)]),
        76 | 77 => {
            // On an 840D these mill a spigot: CYCLE76 (RTP, RFP, SDIS, DP, DPR, _LENG, _WID,
            // …), CYCLE77 (…, DPR, _PRAD, …). A post that writes a boring cycle's list under
            // this name (NX's "BORING_NO_DRAG" writes CYCLE86's: …, DPR, DTB, SDIR, RPA, RPO,
            // RPAP) names a cycle of the machine builder or of the post.
            let what = if number == 76 {
                "rectangular spigot milling, whose 6th and 7th parameters are the spigot's \
                 length _LENG and width _WID"
            } else {
                "circular spigot milling, whose 6th parameter is the spigot's diameter _PRAD"
            };
            let missing = if number == 76 {
                get(5).is_none() || get(6).is_none()
            } else {
                get(5).is_none()
            };
            if missing {
                // The spigot reading is impossible (a standard 840D stops with an alarm), and
                // the list is CYCLE86's (RTP, RFP, SDIS, DP, DPR, DTB, …), as NX posts its
                // "boring, no drag" operation: read it so, and say so where it applies. Every
                // boring variant CYCLE85–89 moves along the same line (down to DP, back to RTP);
                // they differ in the retract's feed and the dwell, which an alias chooses.
                let (steps, mut notes) = sinumerik_steps(86, p, rpm)?;
                notes.push(if number == 76 {
                    "CYCLE76 without the spigot's length and width (_LENG, _WID), which a \
                     standard 840D would refuse, has CYCLE86's list (RTP, RFP, SDIS, DP, DPR, \
                     DTB …), as NX posts a boring cycle: read as CYCLE86 (feed to DP, dwell DTB, \
                     rapid out); if this machine's CYCLE76 is another cycle, say which: \
                     --cycle-alias CYCLE76=CYCLE85 (or 81–89)"
                } else {
                    "CYCLE77 without the spigot's diameter _PRAD, which a standard 840D would \
                     refuse, has CYCLE86's list (RTP, RFP, SDIS, DP, DPR, DTB …): read as \
                     CYCLE86 (feed to DP, dwell DTB, rapid out); if this machine's CYCLE77 is \
                     another cycle, say which: --cycle-alias CYCLE77=CYCLE85 (or 81–89)"
                });
                return Ok((steps, notes));
            }
            return Err(format!(
                "{name} on a Sinumerik 840D is {what}, not a drilling cycle; feedopt does not \
                 mill spigots. If this machine's {name} is a machine builder's or the post's \
                 cycle that works like a standard one, map it: --cycle-alias {name}=CYCLE86 (or \
                 the cycle it is; ReadOptions::cycle_aliases); else post the operation as \
                 CYCLE81–CYCLE89 or as G0/G1/G2/G3"
            ));
        }
        _ => return Err(format!("{name} is not a drilling cycle feedopt knows")),
    }
    s.push(Rapid(rtp));
    Ok((s, notes))
}
