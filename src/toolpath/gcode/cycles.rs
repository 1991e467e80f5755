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
//! | G87 | back boring: rapid to R (below the hole), feed up to Z, rapid to the initial level (the shifts of the oriented tool are not modelled) |
//! | G88 | feed to Z, dwell P, (the operator retracts by hand: not timed, a warning), rapid out |
//! | G89 | feed to Z, dwell P, feed back to R |
//!
//! P is seconds on LinuxCNC and milliseconds on Fanuc. A peck cycle with Q ≤ 0 or without Q
//! drills in one pass, with a warning. A hole needs at most [`MAX_PECKS`] pecks, else it is an
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
//! # Heidenhain (`CYCL DEF 200`, `203`, `207`)
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
    /// A helix about the hole centre: radius (mm), from the current point (on the circle) by
    /// `sweep` radians (counter-clockwise when positive) while Z goes to `z`, at `feed`
    /// (mm/min).
    Helix {
        radius: f64,
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
    /// Peck depth (G73, G83) or shift (G76), mm.
    pub q: Option<f64>,
    pub dwell: f64,
    /// Return level: the initial level (G98) or R (G99).
    pub clear: f64,
    pub initial: f64,
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
                note = Some("peck depth Q missing or ≤ 0: the hole is drilled in one pass");
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
        Kind::G87 => s.extend([Feed(h.bottom, None), Rapid(h.initial.max(h.bottom))]),
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

/// Heidenhain drilling cycle `number` (200, 203, 207, 208) from its Q parameters (`q(200)`
/// …), the spindle speed (rpm, for 207), the `TOOL CALL`'s feed (mm/min, for a feed
/// parameter given as `AUTO`), the tool's diameter (mm, for 208: the control takes it from its
/// tool table) and a raise of the surface Q203 by `offset` mm (a pattern point's Z). Starts
/// from where the tool is (over the hole). The second value names assumptions, for
/// warnings.
///
/// Cycle 208 (bore milling), as the TNC 640 runs it with one pass (no Q370): rapid to the
/// set-up clearance, over to the circle of radius (Q335 − D)/2 about the hole, a helix down
/// at Q206 with Q334 per turn to the depth, one more full circle there, back to the centre and
/// up at rapid to the set-up clearance (or the second, Q204). Where Q335 equals the tool's
/// diameter the tool bores straight down. Climb (Q351 = +1) runs counter-clockwise with M3.
pub fn heidenhain_steps(
    number: u32,
    q: &dyn Fn(u32) -> Option<QValue>,
    spindle_rpm: Option<f64>,
    tool_feed: Option<f64>,
    tool_diameter: Option<f64>,
    offset: f64,
) -> Result<(Vec<Step>, Vec<&'static str>), String> {
    use Step::*;
    if !matches!(number, 200 | 203 | 207 | 208) {
        return Err(format!(
            "cycle {number} is not a cycle feedopt can expand (200, 203, 207 and 208 are): post \
             the operation as L moves"
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
    let mut s = vec![Rapid(safe)];
    let mut notes = Vec::new();
    match number {
        200 | 203 => {
            let f = plunging()?;
            let plunge = finite(202, need(202)?)?.abs();
            if plunge == 0.0 {
                return Err(format!("cycle {number}: plunging depth Q202 is 0"));
            }
            let (top, bottom_dwell) = (dwell(210)?, dwell(211)?);
            let (decrement, breaks, minimum, retract_feed, chip) = if number == 203 {
                // Q208: MAX is rapid, 0 (or none) Q206.
                let retract = match raw(208) {
                    Some(QValue::Number(v)) if finite(208, v)? <= 0.0 => Rate::PerMinute(f),
                    None => Rate::PerMinute(f),
                    _ => rate(208, true)?.unwrap_or(Rate::PerMinute(f)),
                };
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
            let pitch = finite(239, need(239)?)?.abs();
            let Some(rpm) = spindle_rpm.filter(|r| r.is_finite() && *r > 0.0) else {
                return Err(
                    "cycle 207: rigid tapping feeds at pitch × spindle speed, and no TOOL CALL \
                     gave S"
                        .to_string(),
                );
            };
            let f = pitch * rpm;
            if !(1e-3..=1e9).contains(&f) {
                return Err(format!(
                    "cycle 207: the tapping feed Q239 × S = {f} mm/min is out of range"
                ));
            }
            s.extend([Feed(bottom, Some(f)), Feed(safe, Some(f))]);
            if second > clearance {
                s.push(Rapid(surface + second));
            }
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
