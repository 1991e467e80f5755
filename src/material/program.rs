//! What a program says about the process, as its toolpath reader recorded it in the order the
//! program runs (subprograms where they are called): the spindle speeds (G-code `S`, Klartext
//! `TOOL CALL … S`, APT `SPINDL/`: [`crate::toolpath::Toolpath::spindle_changes`]) and the
//! tools it selects ([`crate::toolpath::Toolpath::tool_changes`]).
//!
//! Each move's chip load uses the spindle speed in force on that move
//! ([`crate::material::Material::spindle_at`]).

use std::path::PathBuf;

use crate::toolpath::{SpindleChange, ToolChange, Toolpath};

/// The process data found in a program.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProgramProcess {
    /// The program file (for messages).
    pub source: PathBuf,
    /// The spindle speeds the program sets, in order.
    pub spindle_changes: Vec<SpindleChange>,
    /// The tools the program selects, in order.
    pub tool_changes: Vec<ToolChange>,
    /// The toolpath's CL points (a change at or after the last applies to no move).
    pub points: usize,
}

impl ProgramProcess {
    /// The process data of the toolpath `tp`.
    pub fn from_toolpath(tp: &Toolpath) -> ProgramProcess {
        ProgramProcess {
            source: tp.source.clone(),
            spindle_changes: tp.spindle_changes.clone(),
            tool_changes: tp.tool_changes.clone(),
            points: tp.points.len(),
        }
    }

    /// How many different spindle speeds the program sets.
    pub fn spindle_speeds(&self) -> usize {
        let mut seen: Vec<f64> = Vec::new();
        for c in &self.spindle_changes {
            if !seen.contains(&c.rpm) {
                seen.push(c.rpm);
            }
        }
        seen.len()
    }
}
