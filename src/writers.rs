//! Writers: the schedule as JSON or CSV. Every file is written to a temporary file in the
//! target's directory and renamed into place, so no half-written output is ever left behind.

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};
use crate::schedule::Schedule;

/// Writes `schedule` to `path`, in the format of its extension (`.json` or `.csv`).
pub fn write_schedule(path: &Path, schedule: &Schedule) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let bytes = match ext.as_deref() {
        Some("json") => schedule_json(schedule)?,
        Some("csv") => schedule_csv(schedule).into_bytes(),
        _ => {
            return Err(Error::Usage(format!(
                "{}: unknown output format (use .json or .csv)",
                path.display()
            )));
        }
    };
    write_atomically(path, &bytes)
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
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(|e| Error::io(path, e))?;
    tmp.write_all(bytes).map_err(|e| Error::io(path, e))?;
    tmp.as_file().sync_all().map_err(|e| Error::io(path, e))?;
    tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
    Ok(())
}
