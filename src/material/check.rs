//! The overload check (seed 003's tool-breakage detection): where the *programmed* feed
//! exceeds a process limit, and where a rapid moves through material.
//!
//! One finding per CL move and limit, with the move's worst sample: the programmed feed (times
//! the feed override), the limit's allowed feed there, and by how much the first exceeds the
//! second. A rapid (`G0` / `RAPID`) that removes material is an error-level finding whatever
//! the limits, once it removes more than one cell cube (h_x·h_y·min(h_x, h_y)): less is the
//! grid grazing a wall the tool slides along (a retract along the tool axis), not a cut.
//! Excesses up to [`CHECK_TOLERANCE`] are not reported. A cutting move that leaves material
//! standing more than a cell above its flutes' top is an error-level finding too: the shank
//! (or the holder) runs into it (a tool whose flutes are longer than the default 2 D needs its
//! flute length given). A vertical tool's shank is checked over each sample's whole sweep, a
//! tilted tool's at each sample's end pose ([`super::cut::Sample::shank_depth`]).

use super::cut::Sample;
use super::{Material, ProcessLimit, Simulation};

/// Programmed feeds up to this fraction above a limit are not findings (the samples' A carries
/// the grid's discretisation error, about a percent at the default resolution).
pub const CHECK_TOLERANCE: f64 = 0.02;

/// How serious a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    /// The programmed feed overloads the tool.
    Warning,
    /// A rapid through material: a likely crash or broken tool.
    Error,
}

/// Which kind of finding.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FindingKind {
    /// The programmed feed exceeds a process limit.
    Overload,
    /// A rapid through material.
    Rapid,
    /// Material above the flutes' top where a cutting move takes the tool: the shank in it.
    Shank,
}

/// What the check found about one CL move.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Finding {
    /// Which kind.
    pub kind: FindingKind,
    /// Warning (a limit exceeded) or error (a rapid through material, the shank in it).
    pub severity: Severity,
    /// Source line of the CL point the move ends at.
    pub line: usize,
    /// The CL point the move ends at (index into the toolpath's points).
    pub point: usize,
    /// The limit exceeded (`None` for a rapid through material).
    pub limit: Option<ProcessLimit>,
    /// The programmed feed (times the override), mm/s (`None` for a rapid).
    pub programmed_feed: Option<f64>,
    /// The feed the limit allows at the worst sample, mm/s (`None` for a rapid).
    pub allowed_feed: Option<f64>,
    /// programmed / allowed − 1 (0 for a rapid).
    pub excess: f64,
    /// Material the move removes, mm³.
    pub removed: f64,
    /// A at the worst sample, mm².
    pub area: f64,
    /// How far material reaches above the flutes' top, mm ([`FindingKind::Shank`]; else 0).
    pub shank_depth: f64,
}

/// `warning: …` or `error: …` (the caller puts the file and line in front).
impl std::fmt::Display for Finding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.kind == FindingKind::Shank {
            return write!(
                f,
                "error: material stands {:.3} mm above the flutes' top where this move takes the \
                 tool: the shank runs into it (if the tool's flutes are longer, give \
                 --tool-flute-length or the tool table's)",
                self.shank_depth
            );
        }
        match (self.limit, self.programmed_feed, self.allowed_feed) {
            (Some(l), Some(p), Some(a)) => write!(
                f,
                "warning: programmed feed {:.3} mm/s exceeds the {} limit {:.3} mm/s by {:.1} % \
                 (A {:.3} mm²)",
                p,
                l.label(),
                a,
                100.0 * self.excess,
                self.area
            ),
            _ => write!(
                f,
                "error: rapid through material (removes {:.3} mm³)",
                self.removed
            ),
        }
    }
}

/// The findings of a simulation under `m`'s limits, each move with its own tool
/// ([`Material::tool_at`]), in path order; `feed_override` scales every programmed feed (1: as
/// programmed).
pub fn overloads(sim: &Simulation, m: &Material, feed_override: f64) -> Vec<Finding> {
    let mut out: Vec<Finding> = Vec::new();
    let mut by_move: Vec<&Sample> = Vec::new();
    let grazing = sim.cell.0 * sim.cell.1 * sim.cell.0.min(sim.cell.1);
    let flush = |group: &[&Sample], out: &mut Vec<Finding>| {
        let Some(first) = group.first() else { return };
        let removed: f64 = group.iter().map(|s| s.removed).sum();
        if first.rapid {
            if removed > grazing {
                let area = group.iter().map(|s| s.area).fold(0.0, f64::max);
                out.push(Finding {
                    kind: FindingKind::Rapid,
                    severity: Severity::Error,
                    line: first.line,
                    point: first.point,
                    limit: None,
                    programmed_feed: None,
                    allowed_feed: None,
                    excess: 0.0,
                    removed,
                    area,
                    shank_depth: 0.0,
                });
            }
            return;
        }
        let shank_depth = group.iter().map(|s| s.shank_depth).fold(0.0, f64::max);
        if shank_depth > sim.cell.0.min(sim.cell.1) {
            let area = group.iter().map(|s| s.area).fold(0.0, f64::max);
            out.push(Finding {
                kind: FindingKind::Shank,
                severity: Severity::Error,
                line: first.line,
                point: first.point,
                limit: None,
                programmed_feed: first.programmed_feed.map(|f| f * feed_override),
                allowed_feed: None,
                excess: 0.0,
                removed,
                area,
                shank_depth,
            });
        }
        let Some(feed) = first.programmed_feed.map(|f| f * feed_override) else {
            return;
        };
        // The worst sample per limit.
        let mut worst: Vec<(ProcessLimit, f64, f64)> = Vec::new(); // (limit, allowed, area)
        let tool = m.tool_at(first.point);
        for s in group.iter().filter(|s| s.area > 0.0) {
            for (allowed, lim) in m.process_at(s.point).bounds(s, tool.diameter, tool.flutes) {
                match worst.iter_mut().find(|w| w.0 == lim) {
                    Some(w) if allowed < w.1 => *w = (lim, allowed, s.area),
                    Some(_) => {}
                    None => worst.push((lim, allowed, s.area)),
                }
            }
        }
        for (lim, allowed, area) in worst {
            let excess = feed / allowed - 1.0;
            if excess > CHECK_TOLERANCE {
                out.push(Finding {
                    kind: FindingKind::Overload,
                    severity: Severity::Warning,
                    line: first.line,
                    point: first.point,
                    limit: Some(lim),
                    programmed_feed: Some(feed),
                    allowed_feed: Some(allowed),
                    excess,
                    removed,
                    area,
                    shank_depth: 0.0,
                });
            }
        }
    };
    for s in &sim.samples {
        if by_move.first().is_some_and(|f| f.point != s.point) {
            flush(&by_move, &mut out);
            by_move.clear();
        }
        by_move.push(s);
    }
    flush(&by_move, &mut out);
    out
}
