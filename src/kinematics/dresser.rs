//! Seed 001's wheel dresser: two linear slides X, Z in the profile plane and a rotary axis B
//! that keeps the dressing tool on the profile normal.
//!
//! Convention: the wheel profile lies in the program's X–Z plane (Py = 0) and stands still; the
//! slides carry the B axis (parallel to Y), which carries the dressing tool. The tool axis,
//! from the tool tip towards the B axis, is the profile normal n = (sin θ, 0, cos θ): θ is the
//! right-handed angle about Y from +Z, so B = 0 points the tool along −Z onto the profile from
//! above. The tool tip lies `tool_length` L from the B axis (L = 0: the tip on the axis, so
//! turning B alone does not move it). X and Z are the B axis's position:
//!
//! ```text
//! inverse:   X = Px + L sin θ,   Z = Pz + L cos θ,   B = θ
//! forward:   Px = X − L sin B,   Pz = Z − L cos B,   n = (sin B, 0, cos B)
//! ```
//!
//! Path coordinates (Px, Pz, θ) sit in w = (Px, ·, Pz, θ, 0, …) (w₁ is unused), θ in radians;
//! axes X Z B, B in degrees. There is no singular pose: θ = atan2(n_x, n_z), unwrapped along the
//! path.

use nalgebra::Vector3;

use super::dual::Real;
use super::{MAX_AXES, PATH_DIM, ToolPose, rad_to_deg};

/// A dresser: the distance from the B axis to the dressing tool's tip, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dresser {
    /// From the B axis to the tool tip, mm.
    pub tool_length: f64,
}

impl Dresser {
    /// The inverse kinematics for w = (Px, ·, Pz, θ) in any [`Real`]: X, Z (mm) and B (degrees).
    pub fn axis_positions<T: Real>(&self, w: [T; PATH_DIM], out: &mut [T; MAX_AXES]) {
        let l = self.tool_length;
        let theta = w[3];
        out[0] = w[0] + theta.sin().scale(l);
        out[1] = w[2] + theta.cos().scale(l);
        out[2] = theta.scale(rad_to_deg());
    }

    /// The forward kinematics: X, Z (mm), B (degrees) to the tool tip (y = 0) and tool axis.
    pub fn forward(&self, q: &[f64]) -> ToolPose {
        let l = self.tool_length;
        let theta = q[2].to_radians();
        let (s, c) = theta.sin_cos();
        ToolPose {
            p: Vector3::new(q[0] - l * s, 0.0, q[1] - l * c),
            k: self.tool_axis(theta),
            angles: [theta, 0.0],
        }
    }

    /// The tool axis (profile normal) for θ in radians.
    pub fn tool_axis(&self, theta: f64) -> Vector3<f64> {
        let (s, c) = theta.sin_cos();
        Vector3::new(s, 0.0, c)
    }

    /// The tool-vector inverse, θ in (−π, π]; `None` when k has no component in the X–Z plane.
    pub fn tool_vector_ik(&self, k: &Vector3<f64>) -> Option<f64> {
        (k.x.hypot(k.z) > 1e-9).then(|| k.x.atan2(k.z))
    }
}
