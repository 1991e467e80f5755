//! A tilting head B with a rotary table C, like LinuxCNC's maxkins (Chris Radek's "max").
//!
//! Convention (conventional directions: a positive angle turns the tool right-handedly relative
//! to the workpiece):
//!
//! - The head tilts about an axis parallel to machine Y through the B pivot; the tool tip sits
//!   `pivot_length` L from the pivot along the tool axis. In the machine frame the tool axis is
//!   k_m = R_y(B)·ẑ = (sin B, 0, cos B). X, Y, Z position the pivot, with Z read so that Z is the
//!   tip height at B = 0 (the pivot is at Z + L).
//! - The table turns about machine Z through the machine origin, which is also the program
//!   origin (the C centre at X = Y = 0). A table C turns the workpiece by −C in the machine
//!   frame, so the tool turns by +C relative to the workpiece: a point p of the workpiece is at
//!   R_z(−C)·p in the machine.
//!
//! ```text
//! inverse:   m = R_z(−C)·P,   X = m_x + L sin B,   Y = m_y,   Z = m_z + L cos B − L
//! forward:   P = R_z(C)·(X − L sin B, Y, Z + L − L cos B)
//! tool axis: k = R_z(C)·R_y(B)·ẑ = (sin B cos C, sin B sin C, cos B)
//! ```
//!
//! This is maxkins with `conventional-directions` = 1, tool-length 0 and U = V = W = 0; with
//! maxkins' default (0) its B turns the other way. Path coordinates w = (Px, Py, Pz, B, C) in
//! radians; axes X Y Z B C, rotary in degrees.

use nalgebra::Vector3;

use super::dual::Real;
use super::{MAX_AXES, PATH_DIM, ToolPose, rad_to_deg};

/// A head–table machine: the distance from the B pivot to the tool tip, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadTable {
    /// From the B pivot to the tool tip, mm.
    pub pivot_length: f64,
}

impl HeadTable {
    /// The inverse kinematics for w = (Px, Py, Pz, B, C) in any [`Real`]: X, Y, Z (mm) and
    /// B, C (degrees).
    pub fn axis_positions<T: Real>(&self, w: [T; PATH_DIM], out: &mut [T; MAX_AXES]) {
        let l = self.pivot_length;
        let (b, c) = (w[3], w[4]);
        let (sc, cc) = (c.sin(), c.cos());
        out[0] = cc * w[0] + sc * w[1] + b.sin().scale(l);
        out[1] = cc * w[1] - sc * w[0];
        out[2] = w[2] + b.cos().scale(l) - T::cst(l);
        out[3] = b.scale(rad_to_deg());
        out[4] = c.scale(rad_to_deg());
    }

    /// The forward kinematics: X, Y, Z (mm), B, C (degrees) to the tool tip and tool axis.
    pub fn forward(&self, q: &[f64]) -> ToolPose {
        let l = self.pivot_length;
        let (b, c) = (q[3].to_radians(), q[4].to_radians());
        let (sb, cb) = b.sin_cos();
        let (sc, cc) = c.sin_cos();
        let m = Vector3::new(q[0] - l * sb, q[1], q[2] + l - l * cb);
        ToolPose {
            p: Vector3::new(cc * m.x - sc * m.y, sc * m.x + cc * m.y, m.z),
            k: self.tool_axis(b, c),
            angles: [b, c],
        }
    }

    /// The tool axis for B, C in radians: (sin B cos C, sin B sin C, cos B).
    pub fn tool_axis(&self, b: f64, c: f64) -> Vector3<f64> {
        let (sb, cb) = b.sin_cos();
        let (sc, cc) = c.sin_cos();
        Vector3::new(sb * cc, sb * sc, cb)
    }

    /// The tool-vector inverse: B ≥ 0 and C (`None` where k is vertical); the other solution is
    /// (−B, C + π).
    pub fn tool_vector_ik(&self, k: &Vector3<f64>) -> (f64, Option<f64>) {
        let h = k.x.hypot(k.y);
        let b = h.atan2(k.z);
        if h < super::branch::SINGULAR {
            return (b, None);
        }
        (b, Some(k.y.atan2(k.x)))
    }
}
