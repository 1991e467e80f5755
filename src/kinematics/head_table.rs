//! A tilting head B with a rotary table: C about Z, like LinuxCNC's maxkins (Chris Radek's
//! "max"), or A about X, as on a blade mill (the workpiece turns between centres while the head
//! swivels, e.g. a HAMUEL HSTM or a Starrag LX).
//!
//! Convention (conventional directions: a positive angle turns the tool right-handedly relative
//! to the workpiece):
//!
//! - The head tilts about an axis parallel to machine Y through the B pivot; the tool tip sits
//!   `pivot_length` L from the pivot along the tool axis. In the machine frame the tool axis is
//!   k_m = R_y(B)·ẑ = (sin B, 0, cos B). X, Y, Z position the pivot, with Z read so that Z is the
//!   tip height at B = 0 (the pivot is at Z + L).
//! - The table turns about machine Z (C) or machine X (A) through the machine origin, which is
//!   also the program origin. A table angle θ turns the workpiece by −θ in the machine frame,
//!   so the tool turns by +θ relative to the workpiece: a point p of the workpiece is at
//!   R(−θ)·p in the machine.
//!
//! ```text
//! table C:   m = R_z(−C)·P,   X = m_x + L sin B,   Y = m_y,   Z = m_z + L cos B − L
//!            P = R_z(C)·(X − L sin B, Y, Z + L − L cos B)
//!            k = R_z(C)·R_y(B)·ẑ = (sin B cos C, sin B sin C, cos B)
//! table A:   m = R_x(−A)·P, X Y Z as above,  P = R_x(A)·(X − L sin B, Y, Z + L − L cos B)
//!            k = R_x(A)·R_y(B)·ẑ = (sin B, −sin A cos B, cos A cos B)
//! ```
//!
//! With table C this is maxkins with `conventional-directions` = 1, tool-length 0 and
//! U = V = W = 0; with maxkins' default (0) its B turns the other way. Path coordinates
//! w = (Px, Py, Pz, θ1, θ2), radians; axes X Y Z B C (rotary in degrees), or X Y Z A B.
//!
//! **The path angles with table A.** The rotary-angle walk ([`super::branch`]) measures the
//! tool by its *tilt* t from the table's axis and its *spin* about it, the tool-vector inverse
//! having the two solutions (t, s) and (−t, s + π). With table C the tilt is B itself. With
//! table A the table's axis is X, and the tool's angle from X is 90° − B: the path angles are
//! then (t, A) with t = B − 90° (so k = (cos t, sin A sin t, −cos A sin t), and the other
//! solution of a tool vector, (180° − B, A + 180°), is (−t, A + π)). Machine B is t + 90°
//! wherever an axis position is written or read ([`HeadTable::tilt_offset`]).

use nalgebra::Vector3;
use std::f64::consts::FRAC_PI_2;

use super::dual::Real;
use super::{MAX_AXES, PATH_DIM, ToolPose, rad_to_deg};
use crate::machine::RotaryTable;

/// A head–table machine: the distance from the B pivot to the tool tip, mm, and its table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadTable {
    /// From the B pivot to the tool tip, mm.
    pub pivot_length: f64,
    /// The rotary axis that carries the workpiece.
    pub table: RotaryTable,
}

impl HeadTable {
    /// Machine B minus path angle 0, radians: 0 with table C, 90° with table A (module doc).
    pub fn tilt_offset(&self) -> f64 {
        match self.table {
            RotaryTable::C => 0.0,
            RotaryTable::A => FRAC_PI_2,
        }
    }

    /// The inverse kinematics for w = (Px, Py, Pz, θ1, θ2) in any [`Real`]: X, Y, Z (mm) and
    /// the rotary axes (degrees) in the machine's order (B C, or A B).
    pub fn axis_positions<T: Real>(&self, w: [T; PATH_DIM], out: &mut [T; MAX_AXES]) {
        let l = self.pivot_length;
        match self.table {
            RotaryTable::C => {
                let (b, c) = (w[3], w[4]);
                let (sc, cc) = (c.sin(), c.cos());
                out[0] = cc * w[0] + sc * w[1] + b.sin().scale(l);
                out[1] = cc * w[1] - sc * w[0];
                out[2] = w[2] + b.cos().scale(l) - T::cst(l);
                out[3] = b.scale(rad_to_deg());
                out[4] = c.scale(rad_to_deg());
            }
            RotaryTable::A => {
                // B = t + 90°: sin B = cos t, cos B = −sin t.
                let (t, a) = (w[3], w[4]);
                let (sa, ca) = (a.sin(), a.cos());
                out[0] = w[0] + t.cos().scale(l);
                out[1] = ca * w[1] + sa * w[2];
                out[2] = ca * w[2] - sa * w[1] - t.sin().scale(l) - T::cst(l);
                out[3] = a.scale(rad_to_deg());
                out[4] = (t + T::cst(FRAC_PI_2)).scale(rad_to_deg());
            }
        }
    }

    /// The forward kinematics: X, Y, Z (mm) and the rotary axes (degrees, the machine's order)
    /// to the tool tip and tool axis.
    pub fn forward(&self, q: &[f64]) -> ToolPose {
        let l = self.pivot_length;
        let (b, spin) = match self.table {
            RotaryTable::C => (q[3].to_radians(), q[4].to_radians()),
            RotaryTable::A => (q[4].to_radians(), q[3].to_radians()),
        };
        let (sb, cb) = b.sin_cos();
        let (ss, cs) = spin.sin_cos();
        let m = Vector3::new(q[0] - l * sb, q[1], q[2] + l - l * cb);
        let p = match self.table {
            RotaryTable::C => Vector3::new(cs * m.x - ss * m.y, ss * m.x + cs * m.y, m.z),
            RotaryTable::A => Vector3::new(m.x, cs * m.y - ss * m.z, ss * m.y + cs * m.z),
        };
        let tilt = b - self.tilt_offset();
        ToolPose {
            p,
            k: self.tool_axis(tilt, spin),
            angles: [tilt, spin],
        }
    }

    /// The tool axis for the path angles (radians): (sin B cos C, sin B sin C, cos B) with
    /// table C; (cos t, sin A sin t, −cos A sin t), t = B − 90°, with table A.
    pub fn tool_axis(&self, tilt: f64, spin: f64) -> Vector3<f64> {
        let (st, ct) = tilt.sin_cos();
        let (ss, cs) = spin.sin_cos();
        match self.table {
            RotaryTable::C => Vector3::new(st * cs, st * ss, ct),
            RotaryTable::A => Vector3::new(ct, ss * st, -cs * st),
        }
    }

    /// The tool-vector inverse: the tilt t ≥ 0 from the table's axis and the spin (`None`
    /// where k is parallel to that axis); the other solution is (−t, spin + π).
    pub fn tool_vector_ik(&self, k: &Vector3<f64>) -> (f64, Option<f64>) {
        // (along the table's axis, the two components across it that the spin turns)
        let (along, u, v) = match self.table {
            RotaryTable::C => (k.z, k.x, k.y),
            RotaryTable::A => (k.x, -k.z, k.y),
        };
        let h = u.hypot(v);
        let tilt = h.atan2(along);
        if h < super::branch::SINGULAR {
            return (tilt, None);
        }
        (tilt, Some(v.atan2(u)))
    }
}
