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
//! * `MULTAX/ON` (or bare `MULTAX`) and `MULTAX/OFF`. Under `OFF` the orientation is frozen at its
//!   last value and the `i,j,k` of a 6-number `GOTO` are ignored (they must still be numbers,
//!   but a zero vector is not an error there). A file without any `MULTAX` record behaves as
//!   under `ON`, so 5-axis files that omit it keep their tool vectors.
//! * `FROM/x,y,z[,i,j,k]` — the start position; read exactly like a `GOTO` (it is a point the
//!   tool is at).
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
//! known ones (`TOOL PATH`, `TLDATA`, `MSYS`, `LOADTL`, `PPRINT`, `SPINDL`, `COOLNT`,
//! `END-OF-PATH`, `FINI`, ...). A record with an *unknown* major word is skipped too, with a
//! warning naming the word and its line ([`Toolpath::warnings`]): post-processors emit many
//! vendor-specific words, and none is dropped silently.
//!
//! # Records that are rejected
//!
//! Motion records this reader cannot represent as straight CL moves are errors rather than being
//! skipped, because skipping them would silently change the geometry: see
//! [`UNSUPPORTED_MOTION_WORDS`] (`CIRCLE`, `MOVARC`, `GODLTA`, `GOHOME`, and canned cycles
//! `CYCLE/...` other than `CYCLE/OFF`). Output the toolpath linearised (arcs as `GOTO` chains)
//! instead.
//!
//! Every error is an [`Error::Parse`] naming the file and the 1-based line where the record
//! starts.

use nalgebra::Vector3;
use std::path::Path;

use crate::error::{Error, Result};
use crate::toolpath::{ClPoint, Feed, Toolpath, Units};

/// Tool vectors shorter than this are rejected as having no direction.
const MIN_TOOL_VECTOR_NORM: f64 = 1e-12;

/// Known major words that do not affect the motion and are skipped.
///
/// Unknown words are skipped too (see the module documentation); this list documents what is
/// skipped on purpose.
pub const NON_MOTION_WORDS: &[&str] = &[
    "TOOL PATH",
    "TLDATA",
    "MSYS",
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
    "DELAY",
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
pub const UNSUPPORTED_MOTION_WORDS: &[&str] = &["CIRCLE", "MOVARC", "GODLTA", "GOHOME", "CYCLE"];

/// Reads an APT CL file. Bytes that are not valid UTF-8 (e.g. Latin-1 in `PPRINT` text) are
/// replaced, not rejected.
pub fn read(path: &Path) -> Result<Toolpath> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let text = String::from_utf8_lossy(&bytes);
    parse(path, &text)
}

/// Parses APT CL text; `source` is only used to name the file in the result and in errors.
pub fn parse(source: &Path, text: &str) -> Result<Toolpath> {
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
        }
    }
    // A `$` on the last line: take the record as it is.
    if let Some((start, record)) = pending.take() {
        reader.record(start, &record)?;
    }

    if reader.points.is_empty() {
        return Err(Error::parse(source, last_line.max(1), "no GOTO records"));
    }
    Ok(Toolpath {
        source: source.to_path_buf(),
        points: reader.points,
        warnings: reader.warnings,
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
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::parse(self.source, line, message)
    }

    /// Handles one complete (continuation-joined, comment-stripped) record.
    fn record(&mut self, line: usize, record: &str) -> Result<()> {
        let (major_text, minor) = match record.find('/') {
            Some(at) => (&record[..at], Some(&record[at + 1..])),
            None => (record, None),
        };
        let major = normalise_word(major_text);

        match (major.as_str(), minor) {
            ("GOTO", Some(minor)) => self.goto(line, "GOTO", minor),
            ("FROM", Some(minor)) => self.goto(line, "FROM", minor),
            ("FEDRAT", Some(minor)) => self.fedrat(line, minor),
            ("UNITS", Some(minor)) => self.units(line, minor),
            ("MULTAX", minor) => self.multax(line, minor),
            ("RAPID", minor) => self.rapid(line, minor),
            ("CYCLE", Some(minor)) if normalise_word(minor) == "OFF" => Ok(()),
            (word, _) if UNSUPPORTED_MOTION_WORDS.contains(&word) => Err(self.error(
                line,
                format!(
                    "{word} is not supported (only straight GOTO moves are); \
                     output the toolpath linearised"
                ),
            )),
            (word @ ("GOTO" | "FROM" | "FEDRAT" | "UNITS"), None) => {
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
                        "GOTO" | "FROM" | "FEDRAT" | "UNITS" | "MULTAX" | "RAPID"
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
                        message: format!("unknown APT record `{}`: skipped", major),
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

        let p = Vector3::new(values[0], values[1], values[2]) * self.units.mm_per_unit();
        if !p.iter().all(|c| c.is_finite()) {
            return Err(self.error(line, format!("{word}: position is out of range")));
        }
        if fields.len() == 6 && self.multax != Some(false) {
            let v = Vector3::new(values[3], values[4], values[5]);
            // Scale by the largest component first so that huge vectors cannot overflow.
            let largest = v.amax();
            let scaled_norm = if largest > 0.0 {
                (v / largest).norm()
            } else {
                0.0
            };
            if largest * scaled_norm < MIN_TOOL_VECTOR_NORM {
                return Err(self.error(
                    line,
                    format!(
                        "{word}: tool vector ({}, {}, {}) has zero length",
                        v.x, v.y, v.z
                    ),
                ));
            }
            self.orientation = v / largest / scaled_norm;
        }

        let feed = if self.rapid_next {
            self.rapid_next = false;
            Feed::Rapid
        } else {
            self.feed
        };
        self.points.push(ClPoint {
            p,
            o: self.orientation,
            feed,
            rotary: None,
            line,
        });
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
