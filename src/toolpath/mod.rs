//! Toolpath readers: files in, plain [`Toolpath`] data out.
//!
//! A toolpath is a list of cutter-location (CL) points in workpiece coordinates: tool-tip
//! position **P** (mm), unit tool orientation **O**, and the feed programmed for the move that
//! arrives at the point. Readers never interpolate or judge geometry; that is
//! [`crate::geometry`]'s job.

pub mod apt;
pub mod gcode;
pub mod joint_csv;

use nalgebra::Vector3;
use std::path::{Path, PathBuf};

use crate::error::Result;

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
    /// No feed was programmed before this move: the machine's maximum feed applies.
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

/// A toolpath as read from a file: CL points in program order.
#[derive(Debug, Clone, PartialEq)]
pub struct Toolpath {
    /// The file it came from (for error messages).
    pub source: PathBuf,
    pub points: Vec<ClPoint>,
    /// Things the reader skipped or doubted, with their lines (never silently dropped).
    pub warnings: Vec<Warning>,
}

/// A reader's warning: a line and what about it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    pub line: usize,
    pub message: String,
}

/// Any input path: cutter locations or joint positions.
#[derive(Debug, Clone, PartialEq)]
pub enum Input {
    Cl(Toolpath),
    Joint(joint_csv::JointPath),
}

/// Reads any input path, choosing the reader by extension (`.cls`, `.apt`: APT CL; `.ngc`,
/// `.nc`, `.gcode`, `.tap`: G-code in the default dialect, LinuxCNC; `.csv`: joint space).
pub fn read_input(path: &Path) -> Result<Input> {
    read_as(path, None, gcode::Dialect::default())
}

/// An input format, to override the choice by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Apt,
    Gcode,
    Csv,
}

/// Reads any input path: in `format` if given, else by extension; G-code in `dialect`.
pub fn read_as(path: &Path, format: Option<Format>, dialect: gcode::Dialect) -> Result<Input> {
    let by_ext = || {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "csv" => Some(Format::Csv),
            "ngc" | "nc" | "gcode" | "tap" => Some(Format::Gcode),
            "cls" | "apt" | "cl" => Some(Format::Apt),
            _ => None,
        }
    };
    let format = match format.or_else(by_ext) {
        Some(f) => f,
        None => return read(path).map(Input::Cl), // says what is wrong with the extension
    };
    let bytes = read_bytes(path)?;
    match format {
        Format::Csv => joint_csv::parse(path, &crate::files::utf8(path, bytes)?).map(Input::Joint),
        // The CL readers replace bytes that are not UTF-8 (Latin-1 comments), as their `read`.
        Format::Gcode => gcode::parse(path, &String::from_utf8_lossy(&bytes), dialect)
            .and_then(plausible)
            .map(Input::Cl),
        Format::Apt => apt::parse(path, &String::from_utf8_lossy(&bytes))
            .and_then(plausible)
            .map(Input::Cl),
    }
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

/// Reads a toolpath file, choosing the reader by extension (`.cls`, `.apt`: APT CL; `.ngc`,
/// `.nc`, `.gcode`, `.tap`: G-code in the default dialect, LinuxCNC).
pub fn read(path: &Path) -> Result<Toolpath> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "cls" | "apt" | "cl" => {
            apt::parse(path, &String::from_utf8_lossy(&read_bytes(path)?)).and_then(plausible)
        }
        "ngc" | "nc" | "gcode" | "tap" => gcode::parse(
            path,
            &String::from_utf8_lossy(&read_bytes(path)?),
            gcode::Dialect::default(),
        )
        .and_then(plausible),
        "" => Err(crate::error::Error::Usage(format!(
            "{}: the toolpath file has no extension (expected .cls, .apt, .ngc, .nc, .gcode, \
             .tap or .csv)",
            path.display()
        ))),
        other => Err(crate::error::Error::Usage(format!(
            "{}: unknown toolpath format `.{other}` (expected .cls, .apt, .ngc, .nc, .gcode, \
             .tap or .csv)",
            path.display()
        ))),
    }
}
