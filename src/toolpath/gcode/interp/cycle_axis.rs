//! A drilling or tapping cycle under tool-tip control with the tool tilted off the axis the
//! cycle feeds along, and no tilted working plane.
//!
//! Every cycle the reader knows feeds along the third axis of the working plane (G17: the
//! program's Z, turned only by a frame): Fanuc's drilling axis is the one normal to the
//! positioning plane G17/G18/G19 selects (Xp, Yp, "Zp: Z-axis or axis parallel with the
//! Z-axis", Series 15i/150i-MA operator's manual, canned cycles), LinuxCNC's
//! "Move the Z-axis only at the current feed rate to the Z position" (G81, the G-code manual;
//! `convert_cycle_g81` in its interpreter's `interp_cycles.cc` moves the plane's third axis and
//! nothing else), Sinumerik's CYCLE81–CYCLE89 in the plane G17/G18/G19 selects, Heidenhain's
//! cycles 200–209 along the tool axis of the `TOOL CALL` (Z). Tool-tip control (G43.4/G43.5,
//! TRAORI, M128/FUNCTION TCPM, LinuxCNC's TCP kinematics) turns the tool about its tip; it
//! does not turn the program's Z. So with the tool standing at an angle to Z and no tilted
//! working plane (G68.2, CYCLE800, PLANE) that turns Z along it, a cycle read along Z feeds the
//! drill or tap at that angle to its own axis, which no tool can cut.
//!
//! What the controls do then:
//!
//! * LinuxCNC: its interpreter computes the cycle in program coordinates, along Z, before any
//!   kinematics; tool-tip kinematics map those coordinates to the axes afterwards. The path is
//!   the one feedopt reads, so the cycle is read as before, with a warning naming the angle.
//! * Fanuc (G43.4/G43.5, Haas G234), Sinumerik (TRAORI) and Heidenhain (M128, FUNCTION TCPM):
//!   no manual text found says that a canned cycle then feeds along the tool instead, or that
//!   it alarms. The Series 30i-A "Tool center point control for 5-axis machining" manual
//!   (A-79348E) describes positioning, linear and circular interpolation under G43.4/G43.5 and
//!   no canned cycle; Autodesk's Fusion posts (Haas, Fanuc, Sinumerik 840D, Heidenhain) write a
//!   canned cycle only where the tool stands along the output frame's Z
//!   (`isSameDirection(getRotation().forward, new Vector(0, 0, 1))`) and otherwise expand it
//!   into moves along the tool or refuse it. Timing the cycle along Z could be timing a path
//!   the control never runs, so the block is an error naming the cycle, the angle, the rotary
//!   positions and what to do: post the holes under a tilted working plane, whose Z the
//!   control does turn along the tool.
//!
//! The untilted case (tool along Z, rotary axes anywhere that leaves it so: a C table turned
//! under a vertical tool) is read as before. Under a tilted working plane or frame the check
//! is not made (the plane's Z is the cycle's axis there, and the rotary positions may be the
//! control's to choose).

use nalgebra::Vector3;

use super::*;

/// A tool within this angle (degrees) of the cycle's axis counts as along it: the same
/// bound `feedopt gcode` uses for a tilted tap.
const ALONG_DEG: f64 = 1e-6;

impl Interpreter<'_> {
    /// The tool axis in program coordinates under tool-tip control with no frame that turns
    /// X Y Z, where the reader knows it: the tool vector programmed (G43.5 I J K, A3 B3 C3),
    /// else the rotary positions through the machine's kinematics. `None` outside tool-tip
    /// mode, under a turning frame, or on a machine whose kinematics the reader does not have.
    fn tool_axis_now(&self) -> Option<Vector3<f64>> {
        if self.tcp == Tcp::Off
            || self.swivel.is_some()
            || self.programmable.r != nalgebra::Matrix3::identity()
            || self.klartext.rotary_unknown.is_some()
            || self.klartext.stay_orientation.is_some()
        {
            return None;
        }
        if self.vector != Vector3::z() {
            return Some(self.vector);
        }
        let kin = self.axis_kinematics()?;
        let rotary = self.rotary_positions(&self.pos);
        Some(kin.tool_axis(kin.angles_from_rotary(rotary)))
    }

    /// Checks the cycle `name` about to run at `line` (module doc): an error where the tool
    /// stands off Z under tool-tip control on a Fanuc, Sinumerik or Heidenhain control, a
    /// warning on LinuxCNC, nothing where the tool is along Z or its axis is not known.
    pub(super) fn cycle_along_tool(&mut self, line: usize, name: &str) -> Result<()> {
        let Some(tool) = self.tool_axis_now() else {
            return Ok(());
        };
        let off = tool.angle(&Vector3::z()).to_degrees();
        if off.is_nan() || off <= ALONG_DEG {
            return Ok(());
        }
        let at = if self.vector != Vector3::z() {
            format!(
                "tool vector {}, {}, {}",
                number(tool.x),
                number(tool.y),
                number(tool.z)
            )
        } else {
            let rotary = self.rotary_positions(&self.pos);
            let words: Vec<String> = ["A", "B", "C"]
                .iter()
                .zip(rotary)
                .filter(|(_, v)| *v != 0.0)
                .map(|(n, v)| format!("{n}{}", number(v)))
                .collect();
            words.join(" ")
        };
        let tcp = if self.tcp_code.is_empty() {
            "tool-tip control".to_string()
        } else {
            format!("tool-tip control ({})", self.tcp_code)
        };
        let plane = match self.spec.name {
            "LinuxCNC" => {
                self.warn(
                    line,
                    format!(
                        "{name}: under {tcp} the tool axis stands {off:.3}° off Z ({at}): \
                         LinuxCNC's canned cycle feeds along the program's Z whatever the \
                         tool's orientation, and so it is read, the drill or tap fed at that \
                         angle to its own axis"
                    ),
                );
                return Ok(());
            }
            "Sinumerik" => "CYCLE800",
            "Heidenhain" => "PLANE … TURN, or cycle 19",
            _ => "G68.2 with G53.1",
        };
        Err(self.error(
            line,
            format!(
                "{name}: a drilling or tapping cycle under {tcp} with the tool axis {off:.3}° \
                 off Z ({at}) and no tilted working plane: the cycle feeds along Z, {off:.3}° \
                 off the tool's own axis, and no {control} manual feedopt knows of says the \
                 control then feeds it along the tool instead or what else it does, so feedopt \
                 does not time it; post these holes under a tilted working plane ({plane}) \
                 that turns Z along the tool, or with the tool along Z",
                control = self.spec.name
            ),
        ))
    }
}

/// A number as a message shows it (no trailing zeros, no float noise past 1e-9).
fn number(v: f64) -> String {
    crate::error::number((v * 1e9).round() / 1e9)
}
