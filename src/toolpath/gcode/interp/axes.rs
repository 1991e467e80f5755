//! Blocks outside tool-tip mode on a machine whose kinematics the reader knows: X Y Z A B C
//! are where the control moves the axes, not the tool tip.
//!
//! Outside tool-tip mode (no `M128`/`FUNCTION TCPM`, `TRAORI`, `G43.4`/`G43.5`, …) and outside
//! a frame that maps X Y Z (a swivel frame, a programmable rotation), a control moves every
//! axis linearly from the block's start to its end: X Y Z are the linear axes' positions (as at
//! zero rotary angles, where they are the tool tip: the work offset and tool length are the
//! kinematics'), A B C the rotary axes'. The tool tip relative to the part is then what the
//! forward kinematics gives for those positions. Where every rotary axis stands at zero this is
//! the programmed X Y Z itself, and the reading is left as it was (the tip).
//!
//! * A block at fixed non-zero rotary angles moves the tip along the image of the axes' line
//!   under a rigid motion (table) or a shift (head): one CL point at its end, mapped.
//! * A block that turns a rotary axis: CL points along the tip's curve, uniform in the axes'
//!   interpolation parameter, with chords within [`super::MAX_CHORD_ERROR_MM`] of the curve;
//!   the last one the block's end. Its time is the control's F rule for the axes' motion
//!   ([`Feed::BlockTime`], split in proportion to the parameter), a rapid stays a rapid.
//! * Switching tool-tip mode on or off with a rotary axis off zero: the axes stay; the
//!   position the next block starts from is re-expressed (tip ↔ axes), as a control's display
//!   does.

use nalgebra::{Matrix3, Vector3};

use super::*;
use crate::kinematics::{Kinematics, MAX_AXES, PATH_DIM, ToolPose};

/// A CL point of a turn: the tip, the tool axis, the rotary positions `[A, B, C]` (degrees).
pub(super) type TurnPoint = (Vector3<f64>, Vector3<f64>, [f64; 3]);

/// At most this many CL points for one block that turns a rotary axis outside tool-tip mode.
const MAX_SUBPOINTS: usize = 1 << 16;

/// The largest rotary change, degrees, between two samples of a chord of a turn's tip curve
/// where its error is checked (`chord_count`).
const MAX_STEP_DEG: f64 = 30.0;

impl Interpreter<'_> {
    /// The machine's kinematics where a block outside tool-tip mode is read as the axes'
    /// motion: a five-axis kinematics known to the reader, no frame mapping X Y Z (swivel,
    /// rotation), no Klartext `PLANE … STAY` pending. `None`: X Y Z are taken as the tool tip.
    pub(super) fn axis_kinematics(&self) -> Option<&Kinematics> {
        let kin = self.five_axis_kinematics()?;
        (self.swivel.is_none()
            && self.programmable.r == Matrix3::identity()
            && self.klartext.rotary_unknown.is_none())
        .then_some(kin)
    }

    /// The machine's kinematics where it has two rotary axes and a tool tip (head–head,
    /// table–table, head–table).
    fn five_axis_kinematics(&self) -> Option<&Kinematics> {
        let kin = self.machine?.kinematics.as_ref()?;
        matches!(
            kin,
            Kinematics::HeadHead { .. } | Kinematics::TableTable(_) | Kinematics::HeadTable(_)
        )
        .then_some(kin)
    }

    /// Whether the block from `start` to `end` (program coordinates, rotary positions) is read
    /// as the axes' motion: outside tool-tip mode, with kinematics, a rotary axis off zero.
    pub(super) fn reads_axes(&self, start: &[f64; 6], end: &[f64; 6]) -> bool {
        self.tcp == Tcp::Off
            && self.axis_kinematics().is_some()
            && (self.rotary_positions(start) != [0.0; 3] || self.rotary_positions(end) != [0.0; 3])
    }

    /// The rotary axes' positions (degrees) of program position `q`: its A B C and their work
    /// offsets.
    pub(super) fn rotary_positions(&self, q: &[f64; 6]) -> [f64; 3] {
        let s = self.offsets.shift();
        [q[3] + s[3], q[4] + s[4], q[5] + s[5]]
    }

    /// The tool pose the axes at program position `q` give (X Y Z the linear axes as at zero
    /// rotary angles, in the frame's translation; A B C the rotary axes), or `None` where it is
    /// the programmed point itself (tool-tip mode, no kinematics, every rotary axis at zero).
    pub(super) fn axes_pose(&self, q: &[f64; 6]) -> Option<ToolPose> {
        if self.tcp != Tcp::Off {
            return None;
        }
        let kin = self.axis_kinematics()?;
        let rotary = self.rotary_positions(q);
        if rotary == [0.0; 3] {
            return None;
        }
        let p = self.frame_now().apply(&Vector3::new(q[0], q[1], q[2]));
        kin.forward(&axis_positions(kin, p, rotary))
    }

    /// The tool tip (toolpath coordinates) at program position `q` as the reader reads it now.
    pub(super) fn tip_at(&self, q: &[f64; 6]) -> Vector3<f64> {
        match self.axes_pose(q) {
            Some(pose) => pose.p,
            None => self.frame_now().apply(&Vector3::new(q[0], q[1], q[2])),
        }
    }

    /// The program X Y Z that put the tip at `tip` (toolpath coordinates) with the rotary
    /// positions of `q`, as the reader reads a block now: [`Self::tip_at`]'s inverse.
    pub(super) fn program_at(&self, tip: Vector3<f64>, q: &[f64; 6]) -> Vector3<f64> {
        let frame = self.frame_now();
        let rotary = self.rotary_positions(q);
        if self.tcp == Tcp::Off
            && rotary != [0.0; 3]
            && let Some(kin) = self.axis_kinematics()
        {
            let j = inverse(kin, tip, rotary);
            if let Some(p) = linear_axes_inverse(kin, Vector3::new(j[0], j[1], j[2])) {
                return frame.invert(&p);
            }
        }
        frame.invert(&tip)
    }

    /// Tool-tip mode changes to `to`: the axes stay where they are; with a rotary axis off
    /// zero, the position the next block starts from is re-expressed as the new mode reads it
    /// (the tool tip under tool-tip mode, the axes outside it).
    pub(super) fn switch_tcp(&mut self, to: Tcp) {
        let tip = self.tip_at(&self.pos);
        self.tcp = to;
        let q = self.program_at(tip, &self.pos);
        self.pos[..3].copy_from_slice(q.as_slice());
    }

    /// A linear block from `start` to `end` read as the axes' motion (see [`Self::reads_axes`]):
    /// the program positions of its CL points, uniform in the axes' interpolation parameter,
    /// the last `end` exactly, and each one's share of the parameter. `None`: the block does
    /// not turn a rotary axis (one point at its end, mapped by [`Self::axes_pose`]).
    pub(super) fn axis_motion_points(
        &self,
        line: usize,
        start: &[f64; 6],
        end: &[f64; 6],
    ) -> Result<Option<Vec<[f64; 6]>>> {
        if (3..6).all(|i| start[i] == end[i]) {
            return Ok(None);
        }
        let at =
            |t: f64| -> [f64; 6] { std::array::from_fn(|i| start[i] + t * (end[i] - start[i])) };
        let turn = (3..6)
            .map(|i| end[i] - start[i])
            .fold(0.0, |m: f64, d| m.max(d.abs()));
        let n = self.chord_count(line, turn, |t| self.tip_at(&at(t)))?;
        self.check_room(line, "the rotary move", n)?;
        Ok(Some(
            (1..=n)
                .map(|k| {
                    if k == n {
                        *end
                    } else {
                        at(k as f64 / n as f64)
                    }
                })
                .collect(),
        ))
    }

    /// How many equal steps of the parameter t ∈ [0, 1] keep the chords of the tip's curve
    /// `tip(t)` within [`MAX_CHORD_ERROR_MM`] of it (checked at each chord's midpoint and
    /// quarter points), the CL points they make counted against the program's limit. `turn`:
    /// the largest rotary axis change, degrees: each chord is checked at least every
    /// [`MAX_STEP_DEG`] of it too, so that the samples cannot alias a curve that turns whole
    /// times (a table turned by 720° with the tip off its axis comes back to the same tip at
    /// every quarter of the block).
    fn chord_count(
        &self,
        line: usize,
        turn: f64,
        tip: impl Fn(f64) -> Vector3<f64>,
    ) -> Result<usize> {
        let least = (turn.abs() / MAX_STEP_DEG).ceil();
        let error = |n: usize| -> f64 {
            let mut worst: f64 = 0.0;
            let mut a = tip(0.0);
            // Samples per chord beyond its quarters: one per MAX_STEP_DEG of it.
            let extra = (least / n as f64).ceil() as usize;
            for k in 1..=n {
                let b = tip(k as f64 / n as f64);
                let more = (1..extra).map(|j| j as f64 / extra as f64);
                for f in [0.25, 0.5, 0.75].into_iter().chain(more) {
                    let m = tip((k as f64 - 1.0 + f) / n as f64);
                    worst = worst.max((m - (a + (b - a) * f)).norm());
                }
                a = b;
            }
            worst
        };
        if least.is_nan() || least > MAX_SUBPOINTS as f64 {
            return Err(self.error(
                line,
                format!(
                    "a block that turns a rotary axis outside tool-tip mode by {} degrees: split \
                     it into shorter turns (at most {} degrees a block)",
                    crate::error::number(turn.abs()),
                    MAX_SUBPOINTS as f64 * MAX_STEP_DEG
                ),
            ));
        }
        let mut n = 1usize;
        loop {
            let e = error(n);
            if !e.is_finite() {
                return Err(self.error(
                    line,
                    "a block that turns a rotary axis outside tool-tip mode: the machine's \
                     kinematics gives no tool tip for it",
                ));
            }
            if e <= MAX_CHORD_ERROR_MM {
                break;
            }
            // The error falls as 1/n² once the chords are short.
            let grow = ((e / MAX_CHORD_ERROR_MM).sqrt() * 1.1).ceil() as usize;
            n = n.saturating_mul(grow.clamp(2, 64));
            if n > MAX_SUBPOINTS {
                return Err(self.error(
                    line,
                    format!(
                        "a block that turns a rotary axis outside tool-tip mode needs more than \
                         {MAX_SUBPOINTS} points to follow the tool tip within \
                         {MAX_CHORD_ERROR_MM} mm: split it into shorter turns"
                    ),
                ));
            }
        }
        self.check_room(line, "the rotary move", n)?;
        Ok(n)
    }

    /// A block that turns rotary axes alone (X Y Z not programmed to move) under a frame that
    /// maps X Y Z (a swivel frame such as a Klartext `PLANE`, `CYCLE800`, `G68.2`, or a
    /// rotation), outside tool-tip mode: the control turns the rotary axes and the linear axes
    /// stand, so the tip is carried with the part (table) or swung with the head. The CL points
    /// along it (tip, tool axis, rotary positions `[A, B, C]`), uniform in the axes'
    /// interpolation parameter, the last at the block's end; `None` where this does not apply
    /// (tool-tip mode, X Y Z moving, no frame or no five-axis kinematics, rotary positions
    /// unknown).
    pub(super) fn frame_turn_points(
        &self,
        line: usize,
        start: &[f64; 6],
        end: &[f64; 6],
    ) -> Result<Option<Vec<TurnPoint>>> {
        if self.tcp != Tcp::Off
            || (0..3).any(|i| start[i] != end[i])
            || (3..6).all(|i| start[i] == end[i])
            || self.klartext.rotary_unknown.is_some()
            || (self.swivel.is_none() && self.programmable.r == Matrix3::identity())
        {
            return Ok(None);
        }
        let Some(kin) = self.five_axis_kinematics() else {
            return Ok(None);
        };
        let tip0 = self
            .frame_now()
            .apply(&Vector3::new(start[0], start[1], start[2]));
        let (r0, r1) = (self.rotary_positions(start), self.rotary_positions(end));
        let rotary_at =
            |t: f64| -> [f64; 3] { std::array::from_fn(|i| r0[i] + t * (r1[i] - r0[i])) };
        // The axes at the block's start; the linear ones stand.
        let j0 = inverse(kin, tip0, r0);
        let pose = |rotary: [f64; 3]| -> Option<ToolPose> {
            let turned = axis_positions(kin, tip0, rotary);
            let mut j = j0;
            let n = kin.n_axes();
            j[3..n].copy_from_slice(&turned[3..n]);
            kin.forward(&j)
        };
        let tip = |t: f64| pose(rotary_at(t)).map_or(Vector3::repeat(f64::NAN), |p| p.p);
        let turn = (0..3)
            .map(|i| r1[i] - r0[i])
            .fold(0.0, |m: f64, d| m.max(d.abs()));
        let n = self.chord_count(line, turn, tip)?;
        let mut points = Vec::with_capacity(n);
        for k in 1..=n {
            let rotary = if k == n {
                r1
            } else {
                rotary_at(k as f64 / n as f64)
            };
            let Some(p) = pose(rotary) else {
                return Ok(None);
            };
            points.push((p.p, p.k, rotary));
        }
        Ok(Some(points))
    }
}

/// The machine axis positions (the kinematics' order) for program tip `p` as the linear axes
/// put it at zero rotary angles, and rotary axis positions `rotary` (`[A, B, C]`, degrees).
pub(super) fn axis_positions(
    kin: &Kinematics,
    p: Vector3<f64>,
    rotary: [f64; 3],
) -> [f64; MAX_AXES] {
    let mut linear = linear_axes(kin, p);
    let turned = inverse(kin, p, rotary);
    let n = kin.n_axes();
    linear[3..n].copy_from_slice(&turned[3..n]);
    linear
}

/// The inverse kinematics: the axis positions (the kinematics' order) that put the tip at
/// `p` (program coordinates) with the rotary axes at `rotary` (`[A, B, C]`, degrees).
fn inverse(kin: &Kinematics, p: Vector3<f64>, rotary: [f64; 3]) -> [f64; MAX_AXES] {
    let mut w = [0.0; PATH_DIM];
    w[..3].copy_from_slice(p.as_slice());
    let a = kin.angles_from_rotary(rotary);
    w[3] = a[0];
    w[4] = a[1];
    let mut out = [0.0; MAX_AXES];
    kin.axis_positions(w, &mut out);
    out
}

/// The axis positions at zero rotary angles that put the tip at `p`.
fn linear_axes(kin: &Kinematics, p: Vector3<f64>) -> [f64; MAX_AXES] {
    inverse(kin, p, [0.0; 3])
}

/// The tip `p` whose zero-angle linear axes are `j` (the map is affine).
fn linear_axes_inverse(kin: &Kinematics, j: Vector3<f64>) -> Option<Vector3<f64>> {
    let lin = |p: Vector3<f64>| {
        let q = linear_axes(kin, p);
        Vector3::new(q[0], q[1], q[2])
    };
    let o = lin(Vector3::zeros());
    let m = Matrix3::from_columns(&[
        lin(Vector3::x()) - o,
        lin(Vector3::y()) - o,
        lin(Vector3::z()) - o,
    ]);
    m.try_inverse().map(|inv| inv * (j - o))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Machine;

    fn kinematics(json: &str) -> Kinematics {
        let m = Machine::from_json("t.json".as_ref(), json).unwrap();
        Kinematics::new(&m)
    }

    /// Every five-axis kinematics at zero rotary angles: the axes the reader puts X Y Z on
    /// give back X Y Z as the tip and +z as the tool axis, to rounding; the map back is the
    /// inverse.
    #[test]
    fn at_zero_angles_the_axes_give_back_the_programmed_tip() {
        for kin in test_kinematics() {
            for p in [
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(12.5, -40.0, 73.0),
                Vector3::new(-300.0, 425.0, -5.0),
            ] {
                let j = axis_positions(&kin, p, [0.0; 3]);
                let pose = kin.forward(&j).unwrap();
                assert!((pose.p - p).norm() < 1e-9, "{kin:?}: {p} → {}", pose.p);
                assert!(
                    (pose.k - Vector3::z()).norm() < 1e-12,
                    "{kin:?}: {}",
                    pose.k
                );
                let back = linear_axes_inverse(&kin, Vector3::new(j[0], j[1], j[2])).unwrap();
                assert!((back - p).norm() < 1e-9, "{kin:?}");
            }
        }
    }

    fn test_kinematics() -> Vec<Kinematics> {
        let axes5 = |names: &[&str]| {
            names
                .iter()
                .map(|n| format!(r#""{n}": {{"velocity": 50, "acceleration": 500}}"#))
                .collect::<Vec<_>>()
                .join(", ")
        };
        vec![
            kinematics(&format!(
                r#"{{"name": "ac", "kinematics": {{"type": "table_table_ac",
                  "x-rot-point": 10, "y-rot-point": -20, "z-rot-point": 30,
                  "y-offset": 5, "z-offset": 40, "tool-offset": 100,
                  "work-offset": [1, 2, 3]}},
                  "axes": {{{}}}}}"#,
                axes5(&["X", "Y", "Z", "A", "C"])
            )),
            kinematics(&format!(
                r#"{{"name": "bc", "kinematics": {{"type": "table_table_bc",
                  "x-rot-point": 10, "y-rot-point": -20, "z-rot-point": 30,
                  "x-offset": 5, "z-offset": 40, "conventional-directions": true}},
                  "axes": {{{}}}}}"#,
                axes5(&["X", "Y", "Z", "B", "C"])
            )),
            kinematics(&format!(
                r#"{{"name": "hh", "kinematics": {{"type": "head_head", "tool_length": 150}},
                  "axes": {{{}}}}}"#,
                axes5(&["X", "Y", "Z", "C", "A"])
            )),
            kinematics(&format!(
                r#"{{"name": "ht", "kinematics": {{"type": "head_table", "pivot_length": 120}},
                  "axes": {{{}}}}}"#,
                axes5(&["X", "Y", "Z", "B", "C"])
            )),
            kinematics(&format!(
                r#"{{"name": "hta", "kinematics": {{"type": "head_table", "pivot_length": 120,
                  "table": "A"}},
                  "axes": {{{}}}}}"#,
                axes5(&["X", "Y", "Z", "A", "B"])
            )),
        ]
    }
}
