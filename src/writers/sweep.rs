//! A sweep's table ([`crate::sweep::Sweep`]) as JSON or CSV; its plot is in
//! [`super::plot`].

use std::path::Path;

use super::{Format, write_atomically};
use crate::error::{Error, Result};
use crate::sweep::Sweep;

impl Sweep {
    /// The sweep as JSON (the [`Sweep`] fields; `null` where a value does not exist).
    pub fn to_json(&self) -> Result<String> {
        let mut s = serde_json::to_string_pretty(self)
            .map_err(|e| Error::Solver(format!("JSON encoding: {e}")))?;
        s.push('\n');
        Ok(s)
    }

    /// The sweep as CSV, one row per step: `limit, cycle_time_s, dT_dlimit_dual,
    /// dT_dlimit_fd, cycle_time_minus_s, cycle_time_plus_s, binds, smooth, status, verified,
    /// worst_ratio`, then `path_share_<limit>` and `time_share_<limit>` for every limit that
    /// binds somewhere (spaces as `_`). An empty cell: no value (no duals with `reach`).
    pub fn to_csv(&self) -> String {
        use std::fmt::Write as _;
        let labels = self.binding_labels();
        let mut out = String::from(
            "limit,cycle_time_s,dT_dlimit_dual,dT_dlimit_fd,cycle_time_minus_s,\
             cycle_time_plus_s,binds,smooth,status,verified,worst_ratio",
        );
        for l in &labels {
            let l = l.replace(' ', "_");
            let _ = write!(out, ",path_share_{l},time_share_{l}");
        }
        out.push('\n');
        let opt = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
        for p in &self.points {
            let status = serde_json::to_value(p.status)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default();
            let _ = write!(
                out,
                "{},{},{},{},{},{},{},{},{},{},{}",
                p.limit,
                p.cycle_time_s,
                opt(p.sensitivity_dual),
                p.sensitivity_fd,
                p.cycle_time_minus_s,
                p.cycle_time_plus_s,
                p.binds,
                p.smooth,
                status,
                p.verified,
                p.worst_ratio
            );
            for l in &labels {
                let b = p.binding.iter().find(|b| &b.name == l);
                let (sp, st) = b.map_or((0.0, 0.0), |b| (b.share_of_path, b.share_of_time));
                let _ = write!(out, ",{sp},{st}");
            }
            out.push('\n');
        }
        out
    }

    /// Writes the table to `path` (`.csv` or `.json`), atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let bytes = match super::output_format(path, super::SCHEDULE)? {
            Format::Json => self.to_json()?.into_bytes(),
            _ => self.to_csv().into_bytes(),
        };
        write_atomically(path, &bytes)
    }
}
