//! What a program says about the process: spindle speed (G-code `S` words, APT `SPINDL/`),
//! read from the program text with its lines, and the tools it selects (read by the toolpath
//! readers: [`crate::toolpath::Toolpath::tool_changes`]).
//!
//! Where the spindle speed changes, the *lowest* speed is taken (the chip-load bound
//! f_z·z·n/60 grows with n, so the lowest is the safe one) and the summary says so.

use std::path::{Path, PathBuf};

use crate::error::Result;
use crate::toolpath::{ToolChange, Toolpath};

/// The process data found in a program.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProgramProcess {
    /// The program file (for messages).
    pub source: PathBuf,
    /// The lowest spindle speed programmed (rpm) and its line.
    pub spindle_speed: Option<(f64, usize)>,
    /// How many different spindle speeds the program gives.
    pub spindle_speeds: usize,
    /// The tools the program selects, in order ([`ProgramProcess::with_toolpath`]).
    pub tool_changes: Vec<ToolChange>,
    /// The toolpath's CL points (a tool change at or after the last cuts nothing).
    pub points: usize,
}

impl ProgramProcess {
    /// With the tool changes and the point count of the toolpath read from the program.
    pub fn with_toolpath(mut self, tp: &Toolpath) -> ProgramProcess {
        self.tool_changes = tp.tool_changes.clone();
        self.points = tp.points.len();
        self
    }
}

/// Scans the program at `path` (read up to the toolpath bound).
pub fn scan_file(path: &Path) -> Result<ProgramProcess> {
    let bytes = crate::files::read_bounded(path, crate::files::MAX_TOOLPATH_BYTES, "toolpath")?;
    scan(path, &String::from_utf8_lossy(&bytes))
}

/// The leading number of `s` (after blanks), if any.
fn leading_number(s: &str) -> Option<f64> {
    let s = s.trim_start();
    let end = s
        .char_indices()
        .find(|&(i, c)| !(c.is_ascii_digit() || c == '.' || ((c == '-' || c == '+') && i == 0)))
        .map_or(s.len(), |(i, _)| i);
    s[..end].parse::<f64>().ok().filter(|x| x.is_finite())
}

/// Scans program text (`source` names it in errors): APT when it has a `GOTO/` record, else
/// G-code.
pub fn scan(source: &Path, text: &str) -> Result<ProgramProcess> {
    let apt = text
        .lines()
        .any(|l| l.trim_start().to_ascii_uppercase().starts_with("GOTO"));
    let mut out = ProgramProcess {
        source: source.to_path_buf(),
        ..ProgramProcess::default()
    };
    let mut speeds: Vec<f64> = Vec::new();
    let mut add_speed = |n: f64, line: usize, out: &mut ProgramProcess| {
        if n > 0.0 {
            if !speeds.contains(&n) {
                speeds.push(n);
            }
            if out.spindle_speed.is_none_or(|(m, _)| n < m) {
                out.spindle_speed = Some((n, line));
            }
            out.spindle_speeds = speeds.len();
        }
    };
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        if apt {
            let upper = raw.trim_start().to_ascii_uppercase();
            let Some((word, args)) = upper.split_once('/') else {
                continue;
            };
            let nums: Vec<f64> = args
                .split(',')
                .filter_map(|a| a.trim().parse::<f64>().ok())
                .filter(|x| x.is_finite())
                .collect();
            if word.trim() == "SPINDL"
                && let Some(&n) = nums.first()
            {
                add_speed(n.abs(), line, &mut out);
            }
        } else {
            // Comments: (…) and everything after ';'.
            let mut code = String::with_capacity(raw.len());
            let mut depth = 0;
            for c in raw.chars() {
                match c {
                    ';' if depth == 0 => break,
                    '(' => depth += 1,
                    ')' if depth > 0 => depth -= 1,
                    _ if depth == 0 => code.push(c),
                    _ => {}
                }
            }
            let bytes = code.as_bytes();
            for (k, &b) in bytes.iter().enumerate() {
                if (b == b'S' || b == b's') && (k == 0 || !bytes[k - 1].is_ascii_alphabetic()) {
                    let rest = &code[k + 1..];
                    if rest.starts_with(|c: char| c.is_ascii_digit() || c == '.' || c == ' ') {
                        if let Some(n) = leading_number(rest) {
                            add_speed(n, line, &mut out);
                        }
                    }
                }
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn apt_spindle() {
        let t = "CUTTER/10.000000,2.000000\nSPINDL/RPM,8000,CLW\nGOTO/0,0,0\nSPINDL/RPM,6000\n";
        let p = scan(Path::new("a.cls"), t).unwrap();
        assert_eq!(p.spindle_speed, Some((6000.0, 4)));
        assert_eq!(p.spindle_speeds, 2);
    }

    #[test]
    fn gcode_s_words() {
        let t = "G21 (SPEED S9999)\nM3 S12000\nG1 X1 F100 ; S5\nM3S9000\nSUPA G0 Z5\n";
        let p = scan(Path::new("a.ngc"), t).unwrap();
        assert_eq!(p.spindle_speed, Some((9000.0, 4)));
        assert_eq!(p.spindle_speeds, 2);
    }
}
