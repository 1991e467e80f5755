//! Writers: the schedule as JSON or CSV. Every file is written to a temporary file in the
//! target's directory and renamed into place, so no half-written output is ever left behind.

pub mod gcode;
pub mod plot;

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};
use crate::schedule::Schedule;

/// Formats a schedule can be written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScheduleFormat {
    Json,
    Csv,
}

/// Checks an output path before any work is done: a known extension and an existing directory.
pub fn schedule_format(path: &Path) -> Result<ScheduleFormat> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let format = match ext.as_deref() {
        Some("json") => ScheduleFormat::Json,
        Some("csv") => ScheduleFormat::Csv,
        _ => {
            return Err(Error::Usage(format!(
                "{}: unknown output format (use .json or .csv)",
                path.display()
            )));
        }
    };
    check_directory(path)?;
    Ok(format)
}

/// An output path's directory must exist (checked before any work is done).
pub fn check_directory(path: &Path) -> Result<()> {
    let dir = parent_dir(path);
    if dir.is_dir() {
        Ok(())
    } else {
        Err(Error::Usage(format!(
            "{}: the directory {} does not exist",
            path.display(),
            dir.display()
        )))
    }
}

/// Writes `schedule` to `path`, in the format of its extension (`.json` or `.csv`).
pub fn write_schedule(path: &Path, schedule: &Schedule) -> Result<()> {
    let bytes = match schedule_format(path)? {
        ScheduleFormat::Json => schedule_json(schedule)?,
        ScheduleFormat::Csv => schedule_csv(schedule).into_bytes(),
    };
    write_atomically(path, &bytes)
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// The schedule as JSON: `{"axes": [...], "cycle_time_s": …, "stations": [{span, u, s, t, v,
/// a, q: {X: …}, qd: {…}, qdd: {…}}, …]}`.
pub fn schedule_json(schedule: &Schedule) -> Result<Vec<u8>> {
    use serde_json::{Map, Value, json};
    let na = schedule.axes.len();
    let per_axis = |x: &[f64]| -> Value {
        let m: Map<String, Value> = schedule
            .axes
            .iter()
            .zip(&x[..na])
            .map(|(n, v)| (n.clone(), json!(v)))
            .collect();
        Value::Object(m)
    };
    let stations: Vec<Value> = schedule
        .stations
        .iter()
        .map(|s| {
            json!({"span": s.span, "u": s.u, "s": s.s, "t": s.t, "v": s.v, "a": s.a,
                   "q": per_axis(&s.q), "qd": per_axis(&s.qd), "qdd": per_axis(&s.qdd)})
        })
        .collect();
    let doc = json!({
        "units": {"length": "mm", "angle": "deg", "time": "s"},
        "axes": schedule.axes,
        "cycle_time_s": schedule.cycle_time,
        "stations": stations,
    });
    serde_json::to_vec_pretty(&doc).map_err(|e| Error::Solver(format!("JSON encoding: {e}")))
}

/// The schedule as CSV, one row per station: `span,u,s,t,v,a,q_X,…,qd_X,…,qdd_X,…`.
pub fn schedule_csv(schedule: &Schedule) -> String {
    use std::fmt::Write as _;
    let na = schedule.axes.len();
    let mut out = String::from("span,u,s,t,v,a");
    for prefix in ["q", "qd", "qdd"] {
        for n in &schedule.axes {
            let _ = write!(out, ",{prefix}_{n}");
        }
    }
    out.push('\n');
    for s in &schedule.stations {
        let _ = write!(out, "{},{},{},{},{},{}", s.span, s.u, s.s, s.t, s.v, s.a);
        for x in [&s.q, &s.qd, &s.qdd] {
            for v in &x[..na] {
                let _ = write!(out, ",{v}");
            }
        }
        out.push('\n');
    }
    out
}

/// Writes `bytes` to a temporary file next to `path`, then renames it over `path`.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    // The temporary file's own name stays out of messages: they name the target.
    let plain = |e: std::io::Error| Error::io(path, std::io::Error::from(e.kind()));
    let mut tmp = tempfile::NamedTempFile::new_in(parent_dir(path)).map_err(plain)?;
    tmp.write_all(bytes).map_err(|e| Error::io(path, e))?;
    tmp.as_file().sync_all().map_err(|e| Error::io(path, e))?;
    tmp.persist(path).map_err(|e| plain(e.error))?;
    Ok(())
}
