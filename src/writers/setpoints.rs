//! The setpoints of [`crate::interpolate::sample`] as files.
//!
//! **CSV** ([`setpoints_csv`]): a header naming each column with its unit,
//! `t_s,s_mm,feed_mm_s,X_mm,Y_mm,Z_mm,C_deg,A_deg` (a joint-space path: `t_s,s,feed,<axis>_mm|
//! _deg…`, s in the file's own unit), then one row per sample.
//!
//! **Binary** ([`setpoints_bin`], read back by [`read_setpoints_bin`]), all little-endian:
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `FOSETPT\0` |
//! | 4 | u32 version = 1 |
//! | 4 | u32 flags: bit 0 set = joint-space path (s and feed in the path's own units) |
//! | 4 | u32 axis count n |
//! | 8 | f64 period T, s |
//! | 8 | u64 sample count m |
//! | per axis | u8 name length, the name (UTF-8), u8 unit: 0 = mm, 1 = degrees |
//! | m × (3 + n) × 8 | records of f64: t (s), s (mm), feed (mm/s), q₁ … qₙ (mm or °) |

use std::path::Path;

use super::Format;
use crate::error::{Error, Result};
use std::io::Write;

use crate::interpolate::{Sample, Setpoints, SetpointsHeader};
use crate::kinematics::MAX_AXES;
use crate::machine::AxisKind;
use crate::machine::Machine;
use crate::optimize::Solution;

/// The formats setpoints are written in: `.csv` ([`setpoints_csv`]) or `.bin`
/// ([`setpoints_bin`]).
pub const SETPOINTS: &[Format] = &[Format::Csv, Format::Bin];

fn unit_name(kind: AxisKind) -> &'static str {
    match kind {
        AxisKind::Linear => "mm",
        AxisKind::Rotary => "deg",
    }
}

/// The setpoints as CSV: header `t_s,s_mm,feed_mm_s,<axis>_<unit>…`, one row per sample.
pub fn setpoints_csv(sp: &Setpoints) -> String {
    let mut out = Vec::with_capacity(sp.samples.len() * (24 * (3 + sp.axes.len())));
    // (Writing to a Vec cannot fail, and every byte written is UTF-8.)
    let _ = csv_header(&mut out, &header_of(sp));
    for s in &sp.samples {
        let _ = csv_row(&mut out, s, sp.axes.len());
    }
    String::from_utf8(out).unwrap_or_default()
}

fn header_of(sp: &Setpoints) -> SetpointsHeader {
    SetpointsHeader {
        axes: sp.axes.clone(),
        kinds: sp.kinds.clone(),
        joint: sp.joint,
        period: sp.period,
        count: sp.samples.len(),
    }
}

fn csv_header(w: &mut dyn Write, h: &SetpointsHeader) -> std::io::Result<()> {
    w.write_all(if h.joint {
        b"t_s,s,feed"
    } else {
        b"t_s,s_mm,feed_mm_s"
    })?;
    for (name, kind) in h.axes.iter().zip(&h.kinds) {
        write!(w, ",{name}_{}", unit_name(*kind))?;
    }
    writeln!(w)
}

fn csv_row(w: &mut dyn Write, s: &Sample, na: usize) -> std::io::Result<()> {
    write!(w, "{},{},{}", s.t, s.s, s.feed)?;
    for q in &s.q[..na] {
        write!(w, ",{q}")?;
    }
    writeln!(w)
}

/// Magic bytes of the binary setpoint file.
pub const MAGIC: &[u8; 8] = b"FOSETPT\0";
/// Version of the binary layout.
pub const VERSION: u32 = 1;

/// The setpoints in the binary layout of the module doc.
pub fn setpoints_bin(sp: &Setpoints) -> Result<Vec<u8>> {
    let na = sp.axes.len();
    let mut out = Vec::with_capacity(64 + sp.samples.len() * 8 * (3 + na));
    bin_header(&mut out, &header_of(sp)).map_err(|e| Error::Usage(e.to_string()))?;
    for s in &sp.samples {
        let _ = bin_record(&mut out, s, na);
    }
    Ok(out)
}

fn bin_header(w: &mut dyn Write, h: &SetpointsHeader) -> std::io::Result<()> {
    w.write_all(MAGIC)?;
    w.write_all(&VERSION.to_le_bytes())?;
    w.write_all(&u32::from(h.joint).to_le_bytes())?;
    w.write_all(&(h.axes.len() as u32).to_le_bytes())?;
    w.write_all(&h.period.to_le_bytes())?;
    w.write_all(&(h.count as u64).to_le_bytes())?;
    for (name, kind) in h.axes.iter().zip(&h.kinds) {
        let len = u8::try_from(name.len())
            .map_err(|_| std::io::Error::other(format!("axis name `{name}` is too long")))?;
        w.write_all(&[len])?;
        w.write_all(name.as_bytes())?;
        w.write_all(&[u8::from(*kind == AxisKind::Rotary)])?;
    }
    Ok(())
}

fn bin_record(w: &mut dyn Write, s: &Sample, na: usize) -> std::io::Result<()> {
    for x in [s.t, s.s, s.feed].iter().chain(&s.q[..na]) {
        w.write_all(&x.to_le_bytes())?;
    }
    Ok(())
}

/// Reads the binary layout back (positions only: [`Sample::qd`], [`Sample::qdd`] are 0).
/// `source` names the file in errors.
pub fn read_setpoints_bin(source: &Path, bytes: &[u8]) -> Result<Setpoints> {
    let bad = |what: &str| {
        Error::io(
            source,
            std::io::Error::new(std::io::ErrorKind::InvalidData, what.to_string()),
        )
    };
    let mut at = 0usize;
    let mut take = |n: usize| -> Result<&[u8]> {
        let slice = bytes
            .get(at..at + n)
            .ok_or_else(|| bad("truncated setpoint file"))?;
        at += n;
        Ok(slice)
    };
    if take(8)? != MAGIC {
        return Err(bad("not a feedopt setpoint file (bad magic bytes)"));
    }
    let u32_of = |b: &[u8]| u32::from_le_bytes(b.try_into().unwrap_or([0; 4]));
    let f64_of = |b: &[u8]| f64::from_le_bytes(b.try_into().unwrap_or([0; 8]));
    let version = u32_of(take(4)?);
    if version != VERSION {
        return Err(bad(&format!(
            "setpoint file version {version} (expected 1)"
        )));
    }
    let joint = u32_of(take(4)?) & 1 == 1;
    let na = u32_of(take(4)?) as usize;
    if na > MAX_AXES {
        return Err(bad(&format!("{na} axes (at most {MAX_AXES})")));
    }
    let period = f64_of(take(8)?);
    let m = u64::from_le_bytes(take(8)?.try_into().unwrap_or([0; 8]));
    let mut axes = Vec::with_capacity(na);
    let mut kinds = Vec::with_capacity(na);
    for _ in 0..na {
        let len = take(1)?[0] as usize;
        let name = std::str::from_utf8(take(len)?).map_err(|_| bad("axis name is not UTF-8"))?;
        axes.push(name.to_string());
        kinds.push(match take(1)?[0] {
            0 => AxisKind::Linear,
            1 => AxisKind::Rotary,
            u => return Err(bad(&format!("unknown axis unit code {u}"))),
        });
    }
    let record = 8 * (3 + na);
    let rest = bytes.len() - at;
    if (rest as u64) != m.saturating_mul(record as u64) {
        return Err(bad(&format!(
            "{m} records of {record} bytes announced, {rest} bytes present"
        )));
    }
    let samples = bytes[at..]
        .chunks_exact(record)
        .map(|r| {
            let x = |k: usize| f64_of(&r[8 * k..8 * k + 8]);
            let mut q = [0.0; MAX_AXES];
            for (j, qj) in q.iter_mut().enumerate().take(na) {
                *qj = x(3 + j);
            }
            Sample {
                t: x(0),
                s: x(1),
                feed: x(2),
                q,
                qd: [0.0; MAX_AXES],
                qdd: [0.0; MAX_AXES],
            }
        })
        .collect();
    Ok(Setpoints {
        axes,
        kinds,
        joint,
        period,
        samples,
    })
}

/// Writes the setpoints to `path` (format by extension), atomically.
pub fn write_setpoints(path: &Path, sp: &Setpoints) -> Result<()> {
    let bytes = match super::output_format(path, SETPOINTS)? {
        Format::Bin => setpoints_bin(sp)?,
        _ => setpoints_csv(sp).into_bytes(),
    };
    super::write_atomically(path, &bytes)
}

/// Samples `solution` at `period` ([`crate::interpolate::for_each`]) straight into `path`
/// (format by extension), one setpoint at a time: memory does not grow with the motion's
/// length. Atomic as every writer: an error on the way leaves no file. Returns what was
/// written.
pub fn write_sampled(
    path: &Path,
    machine: &Machine,
    solution: &Solution,
    period: f64,
) -> Result<SetpointsHeader> {
    let bin = super::output_format(path, SETPOINTS)? == Format::Bin;
    let na = solution.kinematics.n_axes().min(machine.axes.len());
    let io = |e: std::io::Error| Error::io(path, e);
    let mut header = None;
    super::write_atomically_try(path, |w| {
        let w = std::cell::RefCell::new(w);
        let h = crate::interpolate::for_each(
            machine,
            solution,
            period,
            |h| {
                let w = &mut **w.borrow_mut();
                if bin {
                    bin_header(w, h)
                } else {
                    csv_header(w, h)
                }
                .map_err(io)
            },
            |s| {
                let w = &mut **w.borrow_mut();
                if bin {
                    bin_record(w, s, na)
                } else {
                    csv_row(w, s, na)
                }
                .map_err(io)
            },
        )?;
        header = Some(h);
        Ok(())
    })?;
    header.ok_or_else(|| Error::Solver("no setpoints were written".into()))
}
