//! APT cutter-location (CL) reader: the `.cls` / `.apt` text that NX, Fusion, CATIA and most
//! CAM post-processor front ends emit.
//!
//! # Accepted format
//!
//! A file is a sequence of *records*, one per line:
//!
//! * A record is `MAJOR/minor,minor,...` or a bare `MAJOR` word. Words are case-insensitive and
//!   spaces (or tabs) are allowed anywhere around `/` and `,` (`goto / 1.0, 2.0 ,3`). Runs of
//!   spaces inside a major word are collapsed (`TOOL  PATH` is `TOOL PATH`).
//! * A `$` at the end of a line continues the record on the next line (the two texts are joined
//!   without a separator). Error messages give the record's *first* line.
//! * `$$` starts a comment that runs to the end of the line. Blank lines are skipped.
//! * Numbers are decimal with an optional sign, fraction and exponent: `1`, `1.`, `-.5`,
//!   `1.0E+01`; the Fortran exponent letter `D` (`1.0D+01`) is accepted too. NaN and infinities
//!   are rejected.
//!
//! Records that shape the toolpath:
//!
//! * `GOTO/x,y,z` or `GOTO/x,y,z,i,j,k` — one CL point. Positions are in the current
//!   [`UNITS`](#units) and converted to mm. The tool vector `(i,j,k)` is normalised; a vector
//!   shorter than `1e-12` is an error. A 3-number `GOTO` keeps the previous orientation
//!   (initially `(0,0,1)`).
//! * `FEDRAT/f`, `FEDRAT/MMPM,f`, `FEDRAT/f,MMPM`, `FEDRAT/IPM,f`, `FEDRAT/f,IPM` — the feed of
//!   every following `GOTO` until the next `FEDRAT`. `MMPM` is mm/min, `IPM` inch/min, and a bare
//!   number is per minute in the current `UNITS`. Feeds are stored in mm/s
//!   ([`Feed::Programmed`]). Feed per revolution (`MMPR`, `IPR`) is rejected, as is a zero,
//!   negative or non-finite feed. Before the first `FEDRAT` points get [`Feed::Unspecified`].
//! * `RAPID` — the *next* `GOTO` only is a rapid move ([`Feed::Rapid`]); the programmed feed
//!   resumes after it.
//! * `TLAXIS/i,j,k` — the tool axis of the following moves, as a 6-number `GOTO` sets it (also
//!   under `MULTAX/OFF`); a 3-number `GOTO` keeps it.
//! * `DELAY/t` (seconds) and `DELAY/REV,n` (n spindle revolutions at the last `SPINDL/`
//!   speed) — a dwell at the current point ([`Toolpath::dwells`]), counted in the cycle time
//!   like a G-code `G4`.
//! * `MULTAX/ON` (or bare `MULTAX`) and `MULTAX/OFF`. Under `OFF` the orientation is frozen at its
//!   last value and the `i,j,k` of a 6-number `GOTO` are ignored (they must still be numbers,
//!   but a zero vector is not an error there). A file without any `MULTAX` record behaves as
//!   under `ON`, so 5-axis files that omit it keep their tool vectors.
//! * `FROM/x,y,z[,i,j,k]` — the start position; read exactly like a `GOTO` (it is a point the
//!   tool is at).
//! * `GODLTA/dx,dy,dz` — a straight move from the last point by that vector (in the `MSYS`
//!   frame, in the current units); `GODLTA/d` — by d along the tool axis. The orientation and
//!   the feed (or a `RAPID` before it) as for a `GOTO`; before any point, after a `CIRCLE` or
//!   inside a `CYCLE` it is an error.
//!
//! # Units
//!
//! `UNITS/MM` (the default; also `MILLIMETERS`, `MILLIMETRES`) and `UNITS/INCHES` (also `INCH`,
//! `IN`). Under `INCHES`, later positions and unit-less feeds are multiplied by 25.4. Tool
//! vectors are unit-free. The returned [`Toolpath`] is always in mm and mm/s.
//!
//! # Records that are skipped
//!
//! Records that do not affect the motion are skipped silently; [`NON_MOTION_WORDS`] lists the
//! known ones (`TOOL PATH`, `TLDATA`, `LOADTL`, `PPRINT`, `SPINDL`, `COOLNT`, `CSYS` —
//! SolidWorks CAM writes it with `TRNTYP/WORLD`: its GOTOs are already in world coordinates —,
//! `END-OF-PATH`, `FINI`, ...). A record with an *unknown* major word is skipped too, with a
//! warning naming the word and its line ([`Toolpath::warnings`]): post-processors emit many
//! vendor-specific words, and none is dropped silently.
//!
//! # Arcs, curves, frames and cycles
//!
//! * `CIRCLE/cx,cy,cz,i,j,k[,r,…]` (NX, SolidWorks CAM) and `MOVARC/cx,cy,cz,i,j,k[,r,…]`
//!   (Fusion): the *next* `GOTO` ends an arc about the centre, counter-clockwise about the axis
//!   (i,j,k) (right hand), from the current point; the motion along the axis is linear (a
//!   helix) and a start and end radius that differ by less than the G-code tolerance
//!   ([`super::gcode::ARC_RADIUS_MISMATCH_MM`]) make a spiral. End = start is a full circle.
//!   The arc is cut into chords exactly as G2/G3 are ([`super::arc_chords`]: sagitta at most
//!   [`super::gcode::MAX_CHORD_ERROR_MM`]), every chord end a CL point. A radius `r` that
//!   differs from the start point's distance by more than that tolerance is an error, and so is
//!   a Fusion `MOVARC/…, r, ANGLE, a` whose sweep a differs from the one the end point makes
//!   by more than [`ARC_ANGLE_MISMATCH_DEG`] (an axis pointing the wrong way, or an arc of more
//!   than one turn).
//! * `NURBS/` (NX): the `KNOT/` and `CNTRL/x,y,z[,w]` records that follow (until any other
//!   record) define a (rational) B-spline whose degree is knots − control points − 1; the curve
//!   is evaluated (de Boor) and sampled adaptively until every sample interval's chord lies
//!   within [`super::gcode::MAX_CHORD_ERROR_MM`] of the curve at its midpoint and quarter points
//!   (at most [`NURBS_MAX_POINTS`] points per curve); each sample is a CL point. The tool
//!   vector stays the last one. A toolpath has at most [`super::MAX_POINTS`] CL points: an
//!   arc or curve that would make more is an error before its points are made.
//! * `MSYS/x0,y0,z0,xi,xj,xk,yi,yj,yk` (NX): the frame the following records are written in:
//!   origin and the directions of its X and Y axes in world coordinates (Z = X × Y). Every
//!   later point becomes origin + R·p and every tool vector R·v; `MSYS/` without numbers (or
//!   an identity) ends it.
//! * `CYCLE/DRILL|FACE|DEEP|BRKCHP|TAP|BORE|REAM, …` (and SolidWorks CAM's `DEEP2`: `DEEP`
//!   whose first peck `1STPECK p` differs from the others, `SUBPECK s`; with a warning) with
//!   the keywords `FEDTO d` (depth below
//!   the point), `MMPM|IPM f` (feed), `RAPTO c` (clearance above the point), `RTRCTO r`
//!   (retract level above the point; default: the clearance), `STEP s` (peck, DEEP and
//!   BRKCHP), `DWELL t` (seconds), or the positional NX form `CYCLE/DRILL,d,MMPM,f,c`: every
//!   following `GOTO` is a hole at that point, drilled along the tool axis: rapid to the retract
//!   level over it, rapid to the clearance, feed to the depth (DEEP: pecks of STEP with a rapid
//!   back to the clearance; BRKCHP: pecks with a retract of
//!   [`super::gcode::cycles::PECK_CLEARANCE_MM`]), dwell, back to the retract level (TAP, BORE
//!   and REAM at the feed, the others rapid). `CYCLE/OFF` ends it; `CYCLE/INIT` and `CYCLE/ON`
//!   change nothing.
//! * `UNIT/MM` (SolidWorks CAM) is read as `UNITS/MM`.
//!
//! # Records that are rejected
//!
//! Motion records this reader cannot represent are errors rather than being skipped, because
//! skipping them would silently change the geometry: see [`UNSUPPORTED_MOTION_WORDS`]
//! (`GOHOME`, `INDIRV`, `GOFWD`, …), and `ROTABL`/`ROTHED` (a rotary table or head index: the
//! moves after it are written in the turned part's frame).
//!
//! Every error is an [`Error::Parse`] naming the file and the 1-based line where the record
//! starts.

use nalgebra::Vector3;
use std::path::Path;

use nalgebra::Matrix3;

use crate::error::{Error, Result};
use crate::toolpath::gcode::cycles::PECK_CLEARANCE_MM;
use crate::toolpath::gcode::{
    ARC_RADIUS_MISMATCH_MM, ARC_RADIUS_MISMATCH_RELATIVE, MAX_CHORD_ERROR_MM,
};
use crate::toolpath::{
    ClPoint, Dwell, Feed, MachineContext, MachineSwitch, SpindleChange, Switch, ToolChange,
    ToolSelect, Toolpath, Units,
};

/// Known major words that do not affect the motion and are skipped.
///
/// Unknown words are skipped too (see the module documentation); this list documents what is
/// skipped on purpose.
pub const NON_MOTION_WORDS: &[&str] = &[
    "TOOL PATH",
    "TLDATA",
    "CSYS",
    "TRNTYP",
    "LOADTL",
    "CUTTER",
    "PAINT",
    "PPRINT",
    "END-OF-PATH",
    "FINI",
    "SPINDL",
    "COOLNT",
    "PARTNO",
    "INSERT",
    "CLRSRF",
    "SELECT",
    "MACHIN",
    "AUXFUN",
    "PPFUN",
    "STOP",
    "OPSTOP",
    "END",
    "REMARK",
    "DISPLY",
    "TURRET",
    "CUTCOM",
    "INTOL",
    "OUTTOL",
    "TOLER",
    "LINTOL",
    "SEQNO",
    "OPERATION NAME",
    "ORIGIN",
    "RETRCT",
    "CLAMP",
    "PLABEL",
    "PREFUN",
    "LOAD",
    "HEAD",
    "MODE",
];

/// Major words that move the tool in ways a list of straight CL moves cannot represent; they are
/// rejected (`CYCLE/OFF` is accepted and skipped).
pub const UNSUPPORTED_MOTION_WORDS: &[&str] = &[
    "GOHOME", "GOFWD", "GOLFT", "GORGT", "GOUP", "GODOWN", "GOBACK", "INDIRV", "INDIRP", "PSIS",
    "AUTOPS",
];

/// Largest difference between a `MOVARC`'s stated `ANGLE` and the sweep its end point makes,
/// degrees. The angle is written to a few decimals, far below 0.5°; a reversed axis turns a
/// sweep θ into 360° − θ, which this catches unless θ is within 0.25° of a half turn.
pub const ARC_ANGLE_MISMATCH_DEG: f64 = 0.5;

/// Most CL points one NURBS curve may become.
pub const NURBS_MAX_POINTS: usize = 1_000_000;

/// Reads an APT CL file. Bytes that are not valid UTF-8 (e.g. Latin-1 in `PPRINT` text) are
/// replaced, not rejected.
pub fn read(path: &Path) -> Result<Toolpath> {
    let bytes = crate::toolpath::read_bytes(path)?;
    let text = String::from_utf8_lossy(&bytes);
    parse(path, &text)
}

/// Parses APT CL text; `source` is only used to name the file in the result and in errors.
pub fn parse(source: &Path, text: &str) -> Result<Toolpath> {
    parse_for(source, text, None)
}

/// Parses APT CL text for a machine (the machine is not needed by any record today; the
/// signature matches the G-code reader's).
pub fn parse_for(source: &Path, text: &str, _machine: Option<&MachineContext>) -> Result<Toolpath> {
    let mut reader = Reader::new(source);
    let mut pending: Option<(usize, String)> = None;
    let mut last_line = 0;

    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (index, raw) in text.lines().enumerate() {
        let line_no = index + 1;
        last_line = line_no;
        let without_comment = match raw.find("$$") {
            Some(at) => &raw[..at],
            None => raw,
        };
        let trimmed = without_comment.trim_end();
        let (content, continues) = match trimmed.strip_suffix('$') {
            Some(head) => (head, true),
            None => (trimmed, false),
        };
        match pending.as_mut() {
            Some((_, record)) => record.push_str(content),
            None => {
                if content.trim().is_empty() && !continues {
                    continue;
                }
                pending = Some((line_no, content.to_string()));
            }
        }
        if !continues && let Some((start, record)) = pending.take() {
            reader.record(start, &record)?;
            reader.check_room(start, "this record", 0)?;
        }
    }
    // A `$` on the last line: take the record as it is.
    if let Some((start, record)) = pending.take() {
        reader.record(start, &record)?;
        reader.check_room(start, "this record", 0)?;
    }
    reader.flush_nurbs()?;
    if let Some((line, _)) = reader.arc {
        return Err(Error::parse(
            source,
            line,
            "CIRCLE/MOVARC without the GOTO that ends the arc",
        ));
    }

    if reader.points.is_empty() {
        return Err(Error::parse(source, last_line.max(1), "no GOTO records"));
    }
    Ok(Toolpath {
        source: source.to_path_buf(),
        points: reader.points,
        warnings: reader.warnings,
        dwells: reader.dwells,
        tool_changes: reader.tool_changes,
        spindle_changes: reader.spindle_changes,
        switches: reader.switches,
        taps: reader.taps,
        ..Default::default()
    })
}

/// `MULTAX` state: `None` until the first `MULTAX` record (behaves as on).
type Multax = Option<bool>;

/// Modal state while reading.
struct Reader<'a> {
    source: &'a Path,
    units: Units,
    multax: Multax,
    orientation: Vector3<f64>,
    feed: Feed,
    rapid_next: bool,
    points: Vec<ClPoint>,
    warnings: Vec<crate::toolpath::Warning>,
    dwells: Vec<Dwell>,
    /// `MSYS` frame: world = origin + R·p.
    msys: Option<(Vector3<f64>, Matrix3<f64>)>,
    /// A `CIRCLE`/`MOVARC` waiting for its end `GOTO`: (line, centre, unit axis, radius).
    arc: Option<(usize, ArcSpec)>,
    /// A `NURBS/` being read: (line, knots, control points with weights).
    nurbs: Option<(usize, Vec<f64>, Vec<[f64; 4]>)>,
    cycle: Option<AptCycle>,
    /// `CUTTER/` and `TLDATA/MILL` records, in program order.
    tool_changes: Vec<ToolChange>,
    /// `SPINDL/` speeds, in program order.
    spindle_changes: Vec<SpindleChange>,
    /// `SPINDL/` directions and `COOLNT/` states, in program order.
    switches: Vec<MachineSwitch>,
    /// `CYCLE/TAP` holes, in program order.
    taps: Vec<crate::toolpath::TapCycle>,
}

/// An APT arc's centre, unit axis and radius (if given), in world mm.
#[derive(Debug, Clone, Copy)]
struct ArcSpec {
    centre: Vector3<f64>,
    axis: Vector3<f64>,
    radius: Option<f64>,
    /// The sweep the record states (`MOVARC/…, ANGLE, a`), degrees.
    angle: Option<f64>,
}

/// A `CYCLE/` in force.
#[derive(Debug, Clone, Copy)]
struct AptCycle {
    kind: &'static str,
    depth: f64,
    feed: Option<f64>,
    clearance: f64,
    retract: f64,
    step: Option<f64>,
    /// The first peck, where it differs from the others (`CYCLE/DEEP2 … 1STPECK`).
    first_step: Option<f64>,
    dwell: f64,
}

impl<'a> Reader<'a> {
    fn new(source: &'a Path) -> Self {
        Reader {
            source,
            units: Units::Mm,
            multax: None,
            orientation: Vector3::new(0.0, 0.0, 1.0),
            feed: Feed::Unspecified,
            rapid_next: false,
            points: Vec::new(),
            warnings: Vec::new(),
            dwells: Vec::new(),
            taps: Vec::new(),
            msys: None,
            arc: None,
            nurbs: None,
            cycle: None,
            tool_changes: Vec::new(),
            spindle_changes: Vec::new(),
            switches: Vec::new(),
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::parse(self.source, line, message)
    }

    /// `SPINDL/RPM, n, CLW` (or `SPINDL/n, …`): the speed n from the next move on; `SPINDL/OFF`
    /// and a record without a number change nothing (the motion does not depend on it).
    fn spindle(&mut self, line: usize, args: &str) {
        if let Some(rpm) = args.split(',').find_map(|a| a.trim().parse::<f64>().ok()) {
            SpindleChange::record(&mut self.spindle_changes, self.points.len(), line, rpm);
        }
        // The direction (`CLW`, `CCLW`) or `OFF`, for the writer.
        self.switch(
            line,
            args,
            &[
                ("OFF", Switch::SpindleStop),
                ("CCLW", Switch::SpindleCounterClockwise),
                ("CLW", Switch::SpindleClockwise),
                ("ON", Switch::SpindleClockwise),
            ],
        );
    }

    /// `COOLNT/ON` (or `FLOOD`), `MIST`, `OFF`: the coolant's state, for the writer (other
    /// kinds, `THRU`, `AIR`, `TAP`, the machine's own, are not recorded).
    fn coolant(&mut self, line: usize, args: &str) {
        self.switch(
            line,
            args,
            &[
                ("OFF", Switch::CoolantOff),
                ("MIST", Switch::CoolantMist),
                ("ON", Switch::CoolantFlood),
                ("FLOOD", Switch::CoolantFlood),
            ],
        );
    }

    /// Records the switch of the first entry of `table` whose word is one of the record's
    /// comma-separated `args` (none where no word is).
    fn switch(&mut self, line: usize, args: &str, table: &[(&str, Switch)]) {
        let words: Vec<String> = args
            .split(',')
            .map(|a| a.trim().to_ascii_uppercase())
            .collect();
        let switch = table
            .iter()
            .find(|(w, _)| words.iter().any(|a| a == w))
            .map(|&(_, s)| s);
        if let Some(switch) = switch {
            self.switches.push(MachineSwitch {
                point: self.points.len(),
                line,
                switch,
            });
        }
    }

    /// `TLAXIS/i,j,k`: the tool axis of the following moves (a 3-number `GOTO` keeps it), in the
    /// `MSYS` frame where one is set; read under `MULTAX/OFF` too, since it is the way a fixed
    /// tool axis is given (CAMWorks writes `TLAXIS/0,-1,0` for a side face, CATIA
    /// `TLAXIS/0,0,1` before every tool change).
    fn tlaxis(&mut self, line: usize, minor: &str) -> Result<()> {
        let v = self.numbers(line, "TLAXIS", minor)?;
        let [i, j, k] = v.as_slice() else {
            return Err(self.error(
                line,
                format!(
                    "TLAXIS: expected the tool axis as 3 numbers (i,j,k), found {}",
                    v.len()
                ),
            ));
        };
        let Some(v) = crate::toolpath::unit_tool_vector(Vector3::new(*i, *j, *k)) else {
            return Err(self.error(
                line,
                format!("TLAXIS: tool axis ({i}, {j}, {k}) has zero length"),
            ));
        };
        self.orientation = match self.msys {
            Some((_, r)) => r * v,
            None => v,
        };
        Ok(())
    }

    /// `DELAY/t` (seconds) or `DELAY/REV, n` (`DELAY/n, REV`: n spindle revolutions at the
    /// last `SPINDL/` speed): the tool dwells at the current point. The motion is unchanged but
    /// the time counts, as a G-code `G4` does (CATIA and NX write it in drilling and
    /// spring-pass operations).
    fn delay(&mut self, line: usize, minor: &str) -> Result<()> {
        let fields: Vec<String> = minor
            .split(',')
            .map(|f| f.trim().to_ascii_uppercase())
            .filter(|f| !f.is_empty())
            .collect();
        let revolutions = fields.iter().any(|f| matches!(f.as_str(), "REV" | "REVS"));
        let values: Vec<&String> = fields
            .iter()
            .filter(|f| {
                !matches!(
                    f.as_str(),
                    "REV" | "REVS" | "SEC" | "SECS" | "SECOND" | "SECONDS"
                )
            })
            .collect();
        let [value] = values.as_slice() else {
            return Err(self.error(
                line,
                format!(
                    "DELAY/{}: expected a time in seconds (DELAY/t) or spindle revolutions \
                     (DELAY/REV, n)",
                    minor.trim()
                ),
            ));
        };
        let n = number(value)
            .map_err(|bad| self.error(line, format!("DELAY: the time {}", bad.describe())))?;
        let seconds = if revolutions {
            match self.spindle_changes.last().map(|s| s.rpm) {
                Some(rpm) if rpm > 0.0 => n * 60.0 / rpm,
                _ => {
                    return Err(self.error(
                        line,
                        "DELAY/REV: a dwell in spindle revolutions needs the spindle speed \
                         (a SPINDL/ record before it)",
                    ));
                }
            }
        } else {
            n
        };
        if !(0.0..=1e6).contains(&seconds) {
            return Err(self.error(
                line,
                format!("DELAY: a dwell of {seconds} s is out of range"),
            ));
        }
        if seconds > 0.0 {
            self.dwells.push(Dwell {
                point: self.points.len().saturating_sub(1),
                seconds,
                line,
            });
        }
        Ok(())
    }

    /// `CUTTER/d, r, …` or NX's `TLDATA/MILL, d, r, length, taper, tip`: the tool from the
    /// next move on (diameter and corner radius in the program's units; r 0 when not given).
    fn cutter(&mut self, line: usize, word: &str, args: &str) -> Result<()> {
        let mut nums = args.split(',').map(|a| a.trim().parse::<f64>().ok());
        let (Some(Some(d)), r) = (nums.next(), nums.next()) else {
            return Err(self.error(line, format!("{word} without a diameter")));
        };
        let scale = self.units.mm_per_unit();
        let r = r.flatten().unwrap_or(0.0);
        if !(d.is_finite() && r.is_finite()) {
            return Err(self.error(
                line,
                format!("{word}: diameter {d} and radius {r} must be finite"),
            ));
        }
        self.tool_changes.push(ToolChange {
            point: self.points.len(),
            line,
            tool: ToolSelect::Cutter {
                diameter: d * scale,
                corner_radius: r * scale,
            },
        });
        Ok(())
    }

    /// Handles one complete (continuation-joined, comment-stripped) record.
    fn record(&mut self, line: usize, record: &str) -> Result<()> {
        let (major_text, minor) = match record.find('/') {
            Some(at) => (&record[..at], Some(&record[at + 1..])),
            None => (record, None),
        };
        let major = normalise_word(major_text);
        if self.nurbs.is_some() && !matches!(major.as_str(), "KNOT" | "CNTRL") {
            self.flush_nurbs()?;
        }

        match (major.as_str(), minor) {
            ("GOTO", Some(minor)) => self.goto(line, "GOTO", minor),
            ("FROM", Some(minor)) => self.goto(line, "FROM", minor),
            ("GODLTA", Some(minor)) => self.godlta(line, minor),
            ("FEDRAT", Some(minor)) => self.fedrat(line, minor),
            ("UNITS" | "UNIT", Some(minor)) => self.units(line, minor),
            ("MULTAX", minor) => self.multax(line, minor),
            ("RAPID", minor) => self.rapid(line, minor),
            ("CIRCLE" | "MOVARC", Some(minor)) => self.circle(line, &major, minor),
            ("MSYS", minor) => self.msys(line, minor.unwrap_or("")),
            ("NURBS", _) => {
                self.nurbs = Some((line, Vec::new(), Vec::new()));
                Ok(())
            }
            ("KNOT", Some(minor)) => self.knot(line, minor),
            ("CNTRL", Some(minor)) => self.cntrl(line, minor),
            ("CYCLE", Some(minor)) => self.cycle(line, minor),
            ("CUTTER", Some(minor)) => self.cutter(line, "CUTTER", minor),
            ("DELAY", Some(minor)) => self.delay(line, minor),
            ("TLAXIS", Some(minor)) => self.tlaxis(line, minor),
            (word @ ("ROTABL" | "ROTHED"), _) => Err(self.error(
                line,
                format!(
                    "{word}: a rotary {} index (it turns a rotary axis), which feedopt does not \
                     read from a CL file, so the moves after it would be in the wrong place: \
                     output the toolpath in one fixed frame with tool vectors \
                     (MULTAX/ON, GOTO/x,y,z,i,j,k or TLAXIS/i,j,k), or post it for the machine \
                     as G-code",
                    if word == "ROTABL" { "table" } else { "head" }
                ),
            )),
            ("SPINDL", Some(minor)) => {
                self.spindle(line, minor);
                Ok(())
            }
            ("COOLNT", Some(minor)) => {
                self.coolant(line, minor);
                Ok(())
            }
            ("TLDATA", Some(minor))
                if minor.trim_start().to_ascii_uppercase().starts_with("MILL") =>
            {
                let args = minor.trim_start()[4..].trim_start().trim_start_matches(',');
                self.cutter(line, "TLDATA/MILL", args)
            }
            (word, _) if UNSUPPORTED_MOTION_WORDS.contains(&word) => Err(self.error(
                line,
                format!(
                    "{word} is not supported (only straight GOTO moves are); \
                     output the toolpath linearised"
                ),
            )),
            (word @ ("GOTO" | "FROM" | "FEDRAT" | "UNITS" | "DELAY"), None) => {
                Err(self.error(line, format!("{word}: missing `/` and parameters")))
            }
            _ => {
                // No `/`: a malformed motion record such as `GOTO 1,2,3` has a motion word
                // followed by something else.
                if minor.is_none() {
                    let first = major
                        .split(|c: char| c.is_whitespace() || c == ',')
                        .next()
                        .unwrap_or("");
                    if matches!(
                        first,
                        "GOTO"
                            | "FROM"
                            | "FEDRAT"
                            | "UNITS"
                            | "MULTAX"
                            | "RAPID"
                            | "CIRCLE"
                            | "MOVARC"
                            | "CYCLE"
                            | "KNOT"
                            | "CNTRL"
                    ) {
                        return Err(self.error(
                            line,
                            format!("{first}: malformed record `{}`", record.trim()),
                        ));
                    }
                }
                // Known non-motion words are skipped; unknown ones too, with a warning.
                let known = NON_MOTION_WORDS
                    .iter()
                    .any(|w| major == *w || major.starts_with(&format!("{w} ")));
                if !known {
                    self.warnings.push(crate::toolpath::Warning {
                        line,
                        message: format!("unknown APT record `{}`: skipped", major).into(),
                    });
                }
                // Compensation on (as G41/G42 and Klartext RL/RR say): the CL points may be
                // the part contour the control offsets by the tool radius.
                if major == "CUTCOM"
                    && let Some(m) = minor
                    && m.split(',')
                        .next()
                        .is_some_and(|w| matches!(w.trim(), "LEFT" | "RIGHT"))
                {
                    self.warnings.push(crate::toolpath::Warning {
                        line,
                        message: format!(
                            "CUTCOM/{}: cutter radius compensation is not applied: the CL \
                             points are taken as the tool path",
                            m.trim()
                        )
                        .into(),
                    });
                }
                Ok(())
            }
        }
    }

    /// `GOTO/x,y,z[,i,j,k]` (and `FROM/...`).
    fn goto(&mut self, line: usize, word: &str, minor: &str) -> Result<()> {
        let fields: Vec<&str> = minor.split(',').collect();
        if fields.len() != 3 && fields.len() != 6 {
            return Err(self.error(
                line,
                format!(
                    "{word}: expected 3 numbers (x,y,z) or 6 (x,y,z,i,j,k), found {}",
                    fields.len()
                ),
            ));
        }
        let mut values = [0.0; 6];
        for (k, field) in fields.iter().enumerate() {
            values[k] = number(field).map_err(|bad| {
                self.error(line, format!("{word}: number {} {}", k + 1, bad.describe()))
            })?;
        }

        let p =
            self.world(Vector3::new(values[0], values[1], values[2]) * self.units.mm_per_unit());
        self.check_point(line, word, &p)?;
        if fields.len() == 6 && self.multax != Some(false) {
            let v = Vector3::new(values[3], values[4], values[5]);
            let Some(v) = crate::toolpath::unit_tool_vector(v) else {
                return Err(self.error(
                    line,
                    format!(
                        "{word}: tool vector ({}, {}, {}) has zero length",
                        v.x, v.y, v.z
                    ),
                ));
            };
            self.orientation = match self.msys {
                Some((_, r)) => r * v,
                None => v,
            };
        }

        let feed = self.next_feed();
        if let Some((arc_line, arc)) = self.arc.take() {
            return self.arc_to(line, arc_line, arc, p, feed);
        }
        if let Some(c) = self.cycle
            && word == "GOTO"
        {
            return self.hole(line, c, p);
        }
        self.emit(p, feed, line);
        Ok(())
    }

    /// `GODLTA/d` (by d along the tool axis) or `GODLTA/dx,dy,dz` (by that vector, in the
    /// `MSYS` frame where one is set): a straight move from the last point, at the feed (or
    /// rapid after `RAPID`), keeping the tool axis.
    fn godlta(&mut self, line: usize, minor: &str) -> Result<()> {
        let v = self.numbers(line, "GODLTA", minor)?;
        let d = match v.as_slice() {
            [d] => self.orientation * *d,
            [x, y, z] => {
                let d = Vector3::new(*x, *y, *z);
                match self.msys {
                    Some((_, r)) => r * d,
                    None => d,
                }
            }
            _ => {
                return Err(self.error(
                    line,
                    format!(
                        "GODLTA: expected 1 number (along the tool axis) or 3 (dx,dy,dz), found \
                         {}",
                        v.len()
                    ),
                ));
            }
        };
        if self.arc.is_some() || self.cycle.is_some() {
            return Err(self.error(
                line,
                "GODLTA after CIRCLE or inside CYCLE/: post the move as GOTO",
            ));
        }
        let Some(last) = self.points.last().map(|p| p.p) else {
            return Err(self.error(
                line,
                "GODLTA before any GOTO or FROM: the point it moves from is unknown",
            ));
        };
        let p = last + d * self.units.mm_per_unit();
        self.check_point(line, "GODLTA", &p)?;
        let feed = self.next_feed();
        self.emit(p, feed, line);
        Ok(())
    }

    /// A tool-tip position (world, mm) within ±[`crate::toolpath::MAX_COORDINATE_MM`], or an
    /// error naming `word` and the axis.
    fn check_point(&self, line: usize, word: &str, p: &Vector3<f64>) -> Result<()> {
        match ["X", "Y", "Z"]
            .into_iter()
            .zip(p.iter())
            .find(|(_, c)| !(c.is_finite() && c.abs() <= crate::toolpath::MAX_COORDINATE_MM))
        {
            None => Ok(()),
            Some((axis, c)) => Err(self.error(
                line,
                format!(
                    "{word}: {axis} = {} mm is beyond ±{:e} mm (1 km): check the number and \
                     the units",
                    crate::error::number(*c),
                    crate::toolpath::MAX_COORDINATE_MM
                ),
            )),
        }
    }

    /// The feed of the next move: rapid once after `RAPID`, else the programmed feed.
    fn next_feed(&mut self) -> Feed {
        if std::mem::take(&mut self.rapid_next) {
            Feed::Rapid
        } else {
            self.feed
        }
    }

    /// Checks, before `what` makes `more` CL points (0: the points made so far), that the
    /// toolpath stays within [`super::MAX_POINTS`].
    fn check_room(&self, line: usize, what: &str, more: usize) -> Result<()> {
        super::check_room(self.source, line, what, self.points.len(), more)
    }

    fn emit(&mut self, p: Vector3<f64>, feed: Feed, line: usize) {
        self.points.push(ClPoint {
            p,
            o: self.orientation,
            feed,
            rotary: None,
            line,
        });
    }

    /// A point in the `MSYS` frame, in world coordinates.
    fn world(&self, p: Vector3<f64>) -> Vector3<f64> {
        match self.msys {
            Some((origin, r)) => origin + r * p,
            None => p,
        }
    }

    /// Numeric fields of a record.
    fn numbers(&self, line: usize, word: &str, minor: &str) -> Result<Vec<f64>> {
        minor
            .split(',')
            .enumerate()
            .map(|(k, f)| {
                number(f).map_err(|bad| {
                    self.error(line, format!("{word}: number {} {}", k + 1, bad.describe()))
                })
            })
            .collect()
    }

    /// `MSYS/x0,y0,z0,xi,xj,xk,yi,yj,yk`.
    fn msys(&mut self, line: usize, minor: &str) -> Result<()> {
        if minor.trim().is_empty() {
            self.msys = None;
            return Ok(());
        }
        let v = self.numbers(line, "MSYS", minor)?;
        if v.len() != 9 {
            return Err(self.error(
                line,
                format!(
                    "MSYS: expected 9 numbers (origin x,y,z, X axis i,j,k, Y axis i,j,k), found {}",
                    v.len()
                ),
            ));
        }
        let origin = Vector3::new(v[0], v[1], v[2]) * self.units.mm_per_unit();
        let x = Vector3::new(v[3], v[4], v[5]);
        let y = Vector3::new(v[6], v[7], v[8]);
        if (x.norm() - 1.0).abs() > 1e-3 || (y.norm() - 1.0).abs() > 1e-3 || x.dot(&y).abs() > 1e-3
        {
            return Err(self.error(
                line,
                "MSYS: the X and Y axis directions must be orthogonal unit vectors",
            ));
        }
        let x = x.normalize();
        let y = (y - x * x.dot(&y)).normalize();
        let r = Matrix3::from_columns(&[x, y, x.cross(&y)]);
        self.msys = (origin != Vector3::zeros() || r != Matrix3::identity()).then_some((origin, r));
        Ok(())
    }

    /// `CIRCLE/cx,cy,cz,i,j,k[,r,…]` and `MOVARC/…`: the next GOTO ends the arc.
    fn circle(&mut self, line: usize, word: &str, minor: &str) -> Result<()> {
        let fields: Vec<&str> = minor.split(',').collect();
        if fields.len() < 6 {
            return Err(self.error(
                line,
                format!("{word}: expected at least 6 numbers (centre x,y,z, axis i,j,k)"),
            ));
        }
        let mut v = [0.0; 7];
        for k in 0..fields.len().min(7) {
            if k == 6 && number(fields[6]).is_err() {
                break; // MOVARC/…,ANGLE,a: no radius
            }
            v[k] = number(fields[k]).map_err(|bad| {
                self.error(line, format!("{word}: number {} {}", k + 1, bad.describe()))
            })?;
        }
        let radius = (fields.len() >= 7 && number(fields[6]).is_ok())
            .then(|| v[6] * self.units.mm_per_unit());
        // Fusion's `MOVARC/…, r, ANGLE, a`: the sweep in degrees, checked against the one the
        // end point makes.
        let angle = match fields
            .iter()
            .position(|f| f.trim().eq_ignore_ascii_case("ANGLE"))
        {
            Some(at) => Some(
                fields
                    .get(at + 1)
                    .ok_or(BadNumber::Missing)
                    .and_then(|f| number(f))
                    .map_err(|bad| self.error(line, format!("{word}: ANGLE {}", bad.describe())))?,
            ),
            None => None,
        };
        let centre = self.world(Vector3::new(v[0], v[1], v[2]) * self.units.mm_per_unit());
        let axis = Vector3::new(v[3], v[4], v[5]);
        if axis.norm().is_nan() || axis.norm() <= 1e-9 {
            return Err(self.error(line, format!("{word}: the arc axis has no direction")));
        }
        let axis = match self.msys {
            Some((_, r)) => r * axis.normalize(),
            None => axis.normalize(),
        };
        if self.points.is_empty() {
            return Err(self.error(
                line,
                format!("{word}: an arc needs a start point (a GOTO before it)"),
            ));
        }
        self.arc = Some((
            line,
            ArcSpec {
                centre,
                axis,
                radius,
                angle,
            },
        ));
        Ok(())
    }

    /// The arc from the last point to `end` about `arc`.
    fn arc_to(
        &mut self,
        line: usize,
        arc_line: usize,
        arc: ArcSpec,
        end: Vector3<f64>,
        feed: Feed,
    ) -> Result<()> {
        let start = self.points.last().map_or(end, |p| p.p);
        let n = arc.axis;
        let rs = (start - arc.centre) - n * n.dot(&(start - arc.centre));
        let re = (end - arc.centre) - n * n.dot(&(end - arc.centre));
        let (r0, r1) = (rs.norm(), re.norm());
        let mismatch = (r1 - r0).abs();
        if r0 == 0.0 || r1 == 0.0 {
            return Err(self.error(
                arc_line,
                "CIRCLE: the centre coincides with the start or end point",
            ));
        }
        if mismatch > ARC_RADIUS_MISMATCH_MM && mismatch > ARC_RADIUS_MISMATCH_RELATIVE * r0.max(r1)
        {
            return Err(self.error(
                line,
                format!("arc end point is not on the circle: radius {r1:.4} mm at the end, {r0:.4} mm at the start"),
            ));
        }
        if let Some(r) = arc.radius
            && (r.abs() - r0).abs() > ARC_RADIUS_MISMATCH_MM.max(ARC_RADIUS_MISMATCH_RELATIVE * r0)
        {
            return Err(self.error(
                arc_line,
                format!("CIRCLE: radius {r} mm, but the start point is {r0:.4} mm from the centre"),
            ));
        }
        let u = rs / r0;
        let w = n.cross(&u);
        let angle_end = re.dot(&w).atan2(re.dot(&u));
        // End = start is a full circle; so is a Fusion helix turn (`ANGLE, 360.`) whose end
        // lies straight along the axis from its start.
        let full_turn = arc
            .angle
            .is_some_and(|a| (a.abs() - 360.0).abs() <= ARC_ANGLE_MISMATCH_DEG)
            && (re - rs).norm() < 1e-6;
        let sweep = if (end - start).norm() < 1e-9 || full_turn {
            std::f64::consts::TAU
        } else {
            angle_end.rem_euclid(std::f64::consts::TAU)
        };
        if let Some(a) = arc.angle
            && (a.abs() - sweep.to_degrees()).abs() > ARC_ANGLE_MISMATCH_DEG
        {
            return Err(self.error(
                arc_line,
                format!(
                    "MOVARC: ANGLE {a}°, but the arc from the start point to the next GOTO, \
                     counter-clockwise about the axis ({:.6}, {:.6}, {:.6}), sweeps {:.4}°: the \
                     axis points the wrong way (a clockwise arc needs the axis reversed) or \
                     the arc turns more than once, which one MOVARC cannot say to feedopt; \
                     output the toolpath with arcs of at most one turn, or linearised",
                    n.x,
                    n.y,
                    n.z,
                    sweep.to_degrees()
                ),
            ));
        }
        let along0 = n.dot(&(start - arc.centre));
        let along1 = n.dot(&(end - arc.centre));
        let chords = super::arc_chords(sweep, r0.max(r1))
            .map_err(|e| self.error(arc_line, format!("CIRCLE: {e}")))?;
        self.check_room(line, "the arc", chords)?;
        for k in 1..=chords {
            let t = k as f64 / chords as f64;
            let p = if k == chords {
                end
            } else {
                let phi = t * sweep;
                let r = r0 + t * (r1 - r0);
                arc.centre
                    + n * (along0 + t * (along1 - along0))
                    + (u * phi.cos() + w * phi.sin()) * r
            };
            self.emit(p, feed, line);
        }
        Ok(())
    }

    /// `KNOT/…`: knots of the NURBS being read.
    fn knot(&mut self, line: usize, minor: &str) -> Result<()> {
        let v = self.numbers(line, "KNOT", minor.trim_end_matches(','))?;
        match self.nurbs.as_mut() {
            Some((_, knots, _)) => {
                knots.extend(v);
                Ok(())
            }
            None => Err(self.error(line, "KNOT/ outside a NURBS/ curve")),
        }
    }

    /// `CNTRL/x,y,z[,w]`: a control point of the NURBS being read.
    fn cntrl(&mut self, line: usize, minor: &str) -> Result<()> {
        let v = self.numbers(line, "CNTRL", minor.trim_end_matches(','))?;
        if v.len() != 3 && v.len() != 4 {
            return Err(self.error(
                line,
                format!("CNTRL: expected x,y,z[,w], found {} numbers", v.len()),
            ));
        }
        let p = self.world(Vector3::new(v[0], v[1], v[2]) * self.units.mm_per_unit());
        let w = v.get(3).copied().unwrap_or(1.0);
        if w.is_nan() || w <= 0.0 {
            return Err(self.error(line, format!("CNTRL: weight {w} must be positive")));
        }
        match self.nurbs.as_mut() {
            Some((_, _, cps)) => {
                cps.push([p.x, p.y, p.z, w]);
                Ok(())
            }
            None => Err(self.error(line, "CNTRL/ outside a NURBS/ curve")),
        }
    }

    /// Evaluates and samples the NURBS read so far.
    fn flush_nurbs(&mut self) -> Result<()> {
        let Some((line, knots, cps)) = self.nurbs.take() else {
            return Ok(());
        };
        let curve = super::nurbs::Nurbs::new(knots, cps)
            .map_err(|e| self.error(line, format!("NURBS: {e}")))?;
        let samples = curve
            .sample(MAX_CHORD_ERROR_MM, NURBS_MAX_POINTS)
            .map_err(|e| self.error(line, format!("NURBS: {e}")))?;
        self.check_room(line, "the NURBS curve", samples.len())?;
        let feed = self.next_feed();
        for p in samples {
            self.emit(p, feed, line);
        }
        Ok(())
    }

    /// `CYCLE/…`.
    fn cycle(&mut self, line: usize, minor: &str) -> Result<()> {
        let fields: Vec<String> = minor.split(',').map(normalise_word).collect();
        let kind = fields.first().map(String::as_str).unwrap_or("");
        let kind: &'static str = match kind {
            "OFF" => {
                self.cycle = None;
                return Ok(());
            }
            "INIT" | "ON" | "" => return Ok(()),
            "DRILL" => "DRILL",
            "FACE" => "FACE",
            "DEEP" => "DEEP",
            // SolidWorks CAM (CAMWorks): a deep peck cycle with its first peck (1STPECK)
            // apart from the others (SUBPECK).
            "DEEP2" => {
                self.warnings.push(crate::toolpath::Warning {
                    line,
                    message: "CYCLE/DEEP2: read as CYCLE/DEEP with its first peck \
                              (1STPECK) apart from the others (SUBPECK): a rapid back to the \
                              clearance after every peck"
                        .into(),
                });
                "DEEP"
            }
            "BRKCHP" => "BRKCHP",
            "TAP" => "TAP",
            "BORE" => "BORE",
            "REAM" => "REAM",
            other => {
                return Err(self.error(
                    line,
                    format!("CYCLE/{other}: not a drilling cycle feedopt knows (DRILL, FACE, DEEP, BRKCHP, TAP, BORE, REAM)"),
                ));
            }
        };
        let scale = self.units.mm_per_unit();
        let mut c = AptCycle {
            kind,
            depth: f64::NAN,
            feed: None,
            clearance: 0.0,
            retract: f64::NAN,
            step: None,
            first_step: None,
            dwell: 0.0,
        };
        let mut positional = 0;
        let mut k = 1;
        while k < fields.len() {
            let f = fields[k].as_str();
            let next = |k: usize| -> Result<f64> {
                fields
                    .get(k + 1)
                    .ok_or_else(|| self.error(line, format!("CYCLE: `{f}` needs a number")))
                    .and_then(|t| {
                        number(t).map_err(|bad| {
                            self.error(line, format!("CYCLE: {f} {}", bad.describe()))
                        })
                    })
            };
            match f {
                "FEDTO" | "DEPTH" => c.depth = next(k)?.abs() * scale,
                "MMPM" => c.feed = Some(next(k)? / 60.0),
                "IPM" => c.feed = Some(next(k)? * 25.4 / 60.0),
                "RAPTO" | "CLEAR" => c.clearance = next(k)? * scale,
                "RTRCTO" => c.retract = next(k)? * scale,
                "STEP" | "INCR" | "SUBPECK" => c.step = Some(next(k)?.abs() * scale),
                "1STPECK" => c.first_step = Some(next(k)?.abs() * scale),
                "DWELL" => c.dwell = next(k)?.max(0.0),
                "MMPR" | "IPR" => {
                    return Err(self.error(line, "CYCLE: feed per revolution is not supported"));
                }
                _ => {
                    let v = number(f)
                        .map_err(|_| self.error(line, format!("CYCLE: unknown word `{f}`")))?;
                    match positional {
                        0 => c.depth = v.abs() * scale,
                        1 => c.clearance = v * scale,
                        _ => return Err(self.error(line, format!("CYCLE: unexpected number {v}"))),
                    }
                    positional += 1;
                    k += 1;
                    continue;
                }
            }
            k += 2;
        }
        if !c.depth.is_finite() {
            return Err(self.error(line, "CYCLE: the depth (FEDTO) is missing"));
        }
        if !c.retract.is_finite() {
            c.retract = c.clearance;
        }
        if matches!(kind, "DEEP" | "BRKCHP") && c.step.is_none_or(|s| s <= 0.0) {
            return Err(self.error(
                line,
                format!("CYCLE/{kind}: STEP (the peck) must be positive"),
            ));
        }
        if let Some(s) = c.step
            && c.depth + c.clearance > s * crate::toolpath::gcode::cycles::MAX_PECKS as f64
        {
            return Err(self.error(line, "CYCLE: more pecks than feedopt reads in one hole"));
        }
        self.cycle = Some(c);
        Ok(())
    }

    /// One hole of the `CYCLE/` in force at `p`, along the tool axis.
    fn hole(&mut self, line: usize, c: AptCycle, p: Vector3<f64>) -> Result<()> {
        let o = self.orientation;
        let at = |h: f64| p + o * h;
        let feed = c.feed.map_or(self.feed, Feed::Programmed);
        self.emit(at(c.retract), Feed::Rapid, line);
        self.emit(at(c.clearance), Feed::Rapid, line);
        let bottom = -c.depth;
        match (c.kind, c.step) {
            ("DEEP" | "BRKCHP", Some(step)) => {
                let mut h = c.clearance;
                let mut this = c.first_step.filter(|s| *s > 0.0).unwrap_or(step);
                loop {
                    let next = (h - this).max(bottom);
                    this = step;
                    self.emit(at(next), feed, line);
                    if next <= bottom {
                        break;
                    }
                    if c.kind == "DEEP" {
                        self.emit(at(c.clearance), Feed::Rapid, line);
                    }
                    self.emit(at(next + PECK_CLEARANCE_MM), Feed::Rapid, line);
                    h = next;
                }
            }
            _ => self.emit(at(bottom), feed, line),
        }
        if c.dwell > 0.0 {
            self.dwells.push(Dwell {
                point: self.points.len() - 1,
                seconds: c.dwell,
                line,
            });
        }
        let out = if matches!(c.kind, "TAP" | "BORE" | "REAM") {
            feed
        } else {
            Feed::Rapid
        };
        self.emit(at(c.retract), out, line);
        if c.kind == "TAP" {
            // Into the hole and back out along the tool axis, at the cycle's feed; the speed
            // is the last `SPINDL/`.
            let n = self.points.len();
            let mm_per_min = match feed {
                Feed::Programmed(v) => v * 60.0,
                _ => 0.0,
            };
            self.taps.push(crate::toolpath::TapCycle {
                line,
                name: "CYCLE/TAP".into(),
                points: n - 2..n,
                feed_in: mm_per_min,
                feed_out: mm_per_min,
                pitch: None,
                rpm: self.spindle_changes.last().map(|c| c.rpm),
                left_hand: false,
                dwell: c.dwell,
                axis: self.points[n - 1].o,
            });
        }
        Ok(())
    }

    /// `FEDRAT/f`, `FEDRAT/unit,f`, `FEDRAT/f,unit`.
    fn fedrat(&mut self, line: usize, minor: &str) -> Result<()> {
        let fields: Vec<&str> = minor.split(',').map(str::trim).collect();
        let mut value: Option<f64> = None;
        let mut unit: Option<Units> = None;
        for (k, field) in fields.iter().enumerate() {
            let word = field.to_ascii_uppercase();
            let this_unit = match word.as_str() {
                "MMPM" => Units::Mm,
                "IPM" => Units::Inch,
                "MMPR" | "IPR" => {
                    return Err(self.error(
                        line,
                        format!("FEDRAT: feed per revolution ({word}) is not supported"),
                    ));
                }
                _ => {
                    let v = number(field).map_err(|bad| {
                        let hint = match bad {
                            BadNumber::NotANumber(_) => " nor a feed unit (MMPM, IPM)",
                            _ => "",
                        };
                        self.error(
                            line,
                            format!("FEDRAT: field {} {}{hint}", k + 1, bad.describe()),
                        )
                    })?;
                    if value.replace(v).is_some() {
                        return Err(self.error(line, "FEDRAT: more than one feed value"));
                    }
                    continue;
                }
            };
            if unit.replace(this_unit).is_some() {
                return Err(self.error(line, "FEDRAT: more than one feed unit"));
            }
        }
        if fields.len() > 2 {
            return Err(self.error(
                line,
                format!(
                    "FEDRAT: expected FEDRAT/f, FEDRAT/MMPM,f or FEDRAT/f,MMPM; found {} fields",
                    fields.len()
                ),
            ));
        }
        let Some(value) = value else {
            return Err(self.error(line, "FEDRAT: feed value is missing"));
        };
        if value <= 0.0 {
            return Err(self.error(
                line,
                format!("FEDRAT: feed must be positive, found {value}"),
            ));
        }
        let mm_per_s = value * unit.unwrap_or(self.units).mm_per_unit() / 60.0;
        if !mm_per_s.is_finite() {
            return Err(self.error(line, format!("FEDRAT: feed {value} is out of range")));
        }
        self.feed = Feed::Programmed(mm_per_s);
        Ok(())
    }

    /// `UNITS/MM` or `UNITS/INCHES`.
    fn units(&mut self, line: usize, minor: &str) -> Result<()> {
        self.units = match normalise_word(minor).as_str() {
            "MM" | "MILLIMETERS" | "MILLIMETRES" | "MILLIMETER" | "MILLIMETRE" => Units::Mm,
            "INCHES" | "INCH" | "IN" => Units::Inch,
            other => {
                return Err(self.error(
                    line,
                    format!("UNITS: unknown unit `{other}` (expected MM or INCHES)"),
                ));
            }
        };
        Ok(())
    }

    /// `MULTAX`, `MULTAX/ON`, `MULTAX/OFF`.
    fn multax(&mut self, line: usize, minor: Option<&str>) -> Result<()> {
        let on = match minor.map(normalise_word).as_deref() {
            None | Some("ON") => true,
            Some("OFF") => false,
            Some(other) => {
                return Err(
                    self.error(line, format!("MULTAX: expected ON or OFF, found `{other}`"))
                );
            }
        };
        self.multax = Some(on);
        Ok(())
    }

    /// `RAPID` (no parameters).
    fn rapid(&mut self, line: usize, minor: Option<&str>) -> Result<()> {
        match minor {
            Some(m) if !m.trim().is_empty() => Err(self.error(
                line,
                format!("RAPID: takes no parameters, found `{}`", m.trim()),
            )),
            _ => {
                self.rapid_next = true;
                Ok(())
            }
        }
    }
}

/// Upper-cases a word and collapses inner whitespace runs to one space.
fn normalise_word(text: &str) -> String {
    text.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_ascii_uppercase()
}

/// Why a numeric field was rejected.
#[derive(Debug, Clone, PartialEq)]
enum BadNumber {
    Missing,
    NotANumber(String),
    NotFinite(String),
}

impl BadNumber {
    /// Completes "`GOTO: number 2` ...".
    fn describe(&self) -> String {
        match self {
            BadNumber::Missing => "is missing".to_string(),
            BadNumber::NotANumber(t) => format!("(`{t}`) is not a number"),
            BadNumber::NotFinite(t) => format!("(`{t}`) is not a finite number"),
        }
    }
}

/// Parses one numeric field (surrounding whitespace allowed).
fn number(field: &str) -> std::result::Result<f64, BadNumber> {
    let text = field.trim();
    if text.is_empty() {
        return Err(BadNumber::Missing);
    }
    // Only plain decimal syntax: Rust's parser would also take `inf`, `nan`, `infinity`.
    let plain = text
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '+' | '-' | '.' | 'e' | 'E' | 'd' | 'D'));
    let has_digit = text.chars().any(|c| c.is_ascii_digit());
    if !plain || !has_digit {
        let bare = text.trim_start_matches(['+', '-']).to_ascii_lowercase();
        return Err(if matches!(bare.as_str(), "nan" | "inf" | "infinity") {
            BadNumber::NotFinite(text.to_string())
        } else {
            BadNumber::NotANumber(text.to_string())
        });
    }
    let value: f64 = text
        .replace(['d', 'D'], "e")
        .parse()
        .map_err(|_| BadNumber::NotANumber(text.to_string()))?;
    if !value.is_finite() {
        return Err(BadNumber::NotFinite(text.to_string()));
    }
    Ok(value)
}
