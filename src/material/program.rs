//! What a program says about the process: spindle speed (G-code `S` words, APT `SPINDL/`) and
//! the cutter (APT `CUTTER/d, r` or NX's `TLDATA/MILL, d, r, …`), read from the program text
//! with their lines.
//!
//! The material model takes one tool and one spindle speed: a program with several different
//! `CUTTER/` records is an error naming both lines; where the spindle speed changes, the
//! *lowest* speed is taken (the chip-load bound f_z·z·n/60 grows with n, so the lowest is the
//! safe one) and the summary says so.

use std::path::Path;

use crate::error::{Error, Result};

/// The process data found in a program.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ProgramProcess {
    /// The lowest spindle speed programmed (rpm) and its line.
    pub spindle_speed: Option<(f64, usize)>,
    /// How many different spindle speeds the program gives.
    pub spindle_speeds: usize,
    /// The cutter's diameter and corner radius (mm) and the line of its `CUTTER/` (or
    /// `TLDATA/MILL`).
    pub cutter: Option<(f64, f64, usize)>,
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
    let inches = apt
        && text.lines().any(|l| {
            l.to_ascii_uppercase()
                .replace(' ', "")
                .starts_with("UNITS/INCH")
        });
    let mut out = ProgramProcess::default();
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
            let word = word.trim();
            // NX's `TLDATA/MILL, D, R, length, taper, tip` gives the same D and R as CUTTER/.
            let mill = word == "TLDATA" && args.trim_start().starts_with("MILL");
            match word {
                _ if word == "CUTTER" || mill => {
                    let scale = if inches { 25.4 } else { 1.0 };
                    let Some(&d) = nums.first() else {
                        return Err(Error::parse(
                            source,
                            line,
                            format!("{word}/ without a diameter"),
                        ));
                    };
                    let r = nums.get(1).copied().unwrap_or(0.0);
                    let c = (d * scale, r * scale, line);
                    match out.cutter {
                        Some((d0, r0, l0)) if (d0, r0) != (c.0, c.1) => {
                            return Err(Error::parse(
                                source,
                                line,
                                format!(
                                    "a second cutter (D {} mm, r {} mm; the first at line {l0}: \
                                     D {d0} mm, r {r0} mm): the material model takes one tool; \
                                     split the program by tool",
                                    c.0, c.1
                                ),
                            ));
                        }
                        Some(_) => {}
                        None => out.cutter = Some(c),
                    }
                }
                "SPINDL" => {
                    if let Some(&n) = nums.first() {
                        add_speed(n.abs(), line, &mut out);
                    }
                }
                _ => {}
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
    fn apt_cutter_and_spindle() {
        let t = "CUTTER/10.000000,2.000000\nSPINDL/RPM,8000,CLW\nGOTO/0,0,0\nSPINDL/RPM,6000\n";
        let p = scan(Path::new("a.cls"), t).unwrap();
        assert_eq!(p.cutter, Some((10.0, 2.0, 1)));
        assert_eq!(p.spindle_speed, Some((6000.0, 4)));
        assert_eq!(p.spindle_speeds, 2);
        let bad = "CUTTER/10\nGOTO/0,0,0\nCUTTER/6\n";
        let e = scan(Path::new("a.cls"), bad).unwrap_err().to_string();
        assert!(e.starts_with("a.cls:3:"), "{e}");
    }

    #[test]
    fn nx_tldata_mill_is_a_cutter() {
        // NX CLSF: TLDATA/MILL, diameter, lower radius, length, taper, tip (a 6 mm ball).
        let t = "TOOL PATH/BLADE,TOOL,BALL6\nTLDATA/MILL,6.0000,3.0000,50.0000,2.0000,0.0000\n\
                 GOTO/0,0,0\n";
        let p = scan(Path::new("a.cls"), t).unwrap();
        assert_eq!(p.cutter, Some((6.0, 3.0, 2)));
        // The same tool again as CUTTER/: one tool; another size: an error naming both lines.
        let same = format!("{t}CUTTER/6,3\n");
        assert_eq!(
            scan(Path::new("a.cls"), &same).unwrap().cutter,
            Some((6.0, 3.0, 2))
        );
        let other = format!("{t}TLDATA/MILL,10.0000,0.0000,40.0000,0.0000,0.0000\n");
        let e = scan(Path::new("a.cls"), &other).unwrap_err().to_string();
        assert!(e.starts_with("a.cls:4:") && e.contains("line 2"), "{e}");
        // Other TLDATA kinds (a lathe tool) are not a milling cutter.
        let lathe = "TLDATA/TURN,0.4\nGOTO/0,0,0\n";
        assert_eq!(scan(Path::new("a.cls"), lathe).unwrap().cutter, None);
    }

    #[test]
    fn gcode_s_words() {
        let t = "G21 (SPEED S9999)\nM3 S12000\nG1 X1 F100 ; S5\nM3S9000\nSUPA G0 Z5\n";
        let p = scan(Path::new("a.ngc"), t).unwrap();
        assert_eq!(p.spindle_speed, Some((9000.0, 4)));
        assert_eq!(p.spindle_speeds, 2);
    }
}
