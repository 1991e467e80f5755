//! LinuxCNC's table-rotary-tilting ("trunnion") kinematics xyzac-trt and xyzbc-trt: a table
//! tilting about an axis parallel to X (A) or Y (B), carrying a rotary table C; the spindle is
//! fixed along machine +Z and X, Y, Z move the tool relative to the machine frame.
//!
//! The maths is LinuxCNC's (`src/emc/kinematics/trtfuncs.c`, as stated in the shared
//! realworld/linuxcnc README); a Haas A/B table is the AC machine with C lettered B (below).
//! Notation: R_x, R_y, R_z are right-handed rotations; σ = +1, or −1
//! when `conventional-directions` is true; p = (Px, Py, Pz) is the tool tip in program
//! coordinates, w the work offset, L the tool length (`tool-offset`), r the C centre
//! (`x/y/z-rot-point`) and D the tilt axis relative to it:
//! D = (0, `y-offset`, `z-offset` + L) for AC, D = (`x-offset`, 0, `z-offset` + L) for BC.
//! With the machine pose P = p + w + (0, 0, L) and the tilt angle T (A or B):
//!
//! ```text
//! inverse:   J = r + D + R_tilt(σT) · ( R_z(σC) · (P − r) − D ),   J_T = T,  J_C = C
//! forward:   P = r + R_z(−σC) · ( R_tilt(−σT) · (J − r − D) + D )
//! tool axis: k = R_z(−σC) · R_tilt(−σT) · ẑ
//!            AC: k = (sin T sin C,  σ sin T cos C, cos T)
//!            BC: k = (−σ sin T cos C, sin T sin C, cos T)
//! ```
//!
//! with R_tilt = R_x for AC and R_y for BC. The path coordinates are w = (Px, Py, Pz, T, C) with
//! the angles in radians; the axes are X Y Z A C (AC) or X Y Z B C (BC), rotary in degrees.
//!
//! # The A/B table (`table_table_ab`, Haas TR-series)
//!
//! A Haas TR160/TR210-style trunnion is the AC machine with its platter lettered B: A tilts the
//! trunnion about an axis parallel to machine X (placed by `y-offset`, `z-offset` from the
//! platter centre r), and B turns the platter about the platter's own normal, which is machine
//! +Z at A = 0 and R_x(−σA)·ẑ in the machine frame after the tilt (Haas letters the fifth axis
//! B; it does not turn about Y). With C renamed B every formula above holds unchanged:
//!
//! ```text
//! inverse:   J = r + D + R_x(σA) · ( R_z(σB) · (P − r) − D ),   D = (0, y-offset, z-offset + L)
//! forward:   P = r + R_z(−σB) · ( R_x(−σA) · (J − r − D) + D )
//! tool axis: k = (sin A sin B,  σ sin A cos B,  cos A)
//! ```
//!
//! so A = 90°, B = 0 puts the tool along +σY of the workpiece and A = 90°, B = 90° along +X.
//! The path coordinates are w = (Px, Py, Pz, A, B), the axes X Y Z A B. The tool-vector inverse
//! and its branch rule are the AC ones: A = atan2(√(k_x² + k_y²), k_z) ≥ 0 and
//! B = atan2(k_x, σ k_y), the other solution (−A, B + π), B undefined where k ∥ ẑ; [`branch`]
//! then picks the solution nearest the previous point within travel.
//!
//! [`branch`]: super::branch

use nalgebra::Vector3;

use super::dual::Real;
use super::{MAX_AXES, PATH_DIM, ToolPose, rad_to_deg};
use crate::machine::{TrunnionParams, TrunnionTilt};

/// A trunnion machine: which table tilts (and the platter's letter), and LinuxCNC's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trunnion {
    /// Which table tilts, and the platter's letter.
    pub tilt: TrunnionTilt,
    /// The machine file's parameters.
    pub params: TrunnionParams,
}

impl Trunnion {
    /// σ = +1, or −1 with `conventional-directions`.
    pub fn sigma(&self) -> f64 {
        if self.params.conventional_directions {
            -1.0
        } else {
            1.0
        }
    }

    /// D: the tilt axis relative to the C centre, with the tool length in its z.
    pub fn d(&self) -> Vector3<f64> {
        let p = &self.params;
        let dz = p.z_offset + p.tool_offset;
        if self.tilt.about_x() {
            Vector3::new(0.0, p.tilt_offset, dz)
        } else {
            Vector3::new(p.tilt_offset, 0.0, dz)
        }
    }

    fn r(&self) -> Vector3<f64> {
        Vector3::from(self.params.rot_point)
    }

    /// P − r for p = 0: the work offset and tool length less the C centre.
    fn shift(&self) -> Vector3<f64> {
        let p = &self.params;
        Vector3::from(p.work_offset) + Vector3::new(0.0, 0.0, p.tool_offset) - self.r()
    }

    /// The inverse kinematics for path coordinates w = (Px, Py, Pz, T, C) in any [`Real`]:
    /// X, Y, Z (mm) and T, C (degrees).
    pub fn axis_positions<T: Real>(&self, w: [T; PATH_DIM], out: &mut [T; MAX_AXES]) {
        let sigma = self.sigma();
        let (shift, d, r) = (self.shift(), self.d(), self.r());
        let q = [
            w[0] + T::cst(shift.x),
            w[1] + T::cst(shift.y),
            w[2] + T::cst(shift.z),
        ];
        let (tilt, spin) = (w[3], w[4]);
        let (st, ct) = (tilt.sin().scale(sigma), tilt.cos());
        let (sc, cc) = (spin.sin().scale(sigma), spin.cos());
        // U = R_z(σC)(P − r) − D.
        let u = [
            cc * q[0] - sc * q[1] - T::cst(d.x),
            sc * q[0] + cc * q[1] - T::cst(d.y),
            q[2] - T::cst(d.z),
        ];
        // V = R_tilt(σT) U.
        let v = if self.tilt.about_x() {
            [u[0], ct * u[1] - st * u[2], st * u[1] + ct * u[2]]
        } else {
            [ct * u[0] + st * u[2], u[1], ct * u[2] - st * u[0]]
        };
        out[0] = v[0] + T::cst(r.x + d.x);
        out[1] = v[1] + T::cst(r.y + d.y);
        out[2] = v[2] + T::cst(r.z + d.z);
        out[3] = tilt.scale(rad_to_deg());
        out[4] = spin.scale(rad_to_deg());
    }

    /// The forward kinematics: axis positions (X, Y, Z mm, T, C degrees) to the tool tip in
    /// program coordinates and the tool axis.
    pub fn forward(&self, q: &[f64]) -> ToolPose {
        let sigma = self.sigma();
        let (d, r) = (self.d(), self.r());
        let (tilt, spin) = (q[3].to_radians(), q[4].to_radians());
        let (st, ct) = (sigma * tilt.sin(), tilt.cos());
        let (sc, cc) = (sigma * spin.sin(), spin.cos());
        let v = Vector3::new(q[0], q[1], q[2]) - r - d;
        // U = R_tilt(−σT) V + D.
        let u = if self.tilt.about_x() {
            Vector3::new(v.x, ct * v.y + st * v.z, ct * v.z - st * v.y)
        } else {
            Vector3::new(ct * v.x - st * v.z, v.y, st * v.x + ct * v.z)
        } + d;
        // P = r + R_z(−σC) U, p = P − w − L ẑ.
        let big_p = r + Vector3::new(cc * u.x + sc * u.y, cc * u.y - sc * u.x, u.z);
        ToolPose {
            p: big_p - self.shift() - r,
            k: self.tool_axis(tilt, spin),
            angles: [tilt, spin],
        }
    }

    /// The tool axis k (unit, from the tip towards the spindle) in program coordinates for tilt
    /// and spin angles in radians.
    pub fn tool_axis(&self, tilt: f64, spin: f64) -> Vector3<f64> {
        let sigma = self.sigma();
        let (st, ct) = tilt.sin_cos();
        let (sc, cc) = spin.sin_cos();
        if self.tilt.about_x() {
            Vector3::new(st * sc, sigma * st * cc, ct)
        } else {
            Vector3::new(-sigma * st * cc, st * sc, ct)
        }
    }

    /// The tool-vector inverse: the tilt T ≥ 0 and the spin C (`None` where k is parallel to
    /// the C axis) with [`Trunnion::tool_axis`]`(T, C) = k`; the other solution is (−T, C + π).
    pub fn tool_vector_ik(&self, k: &Vector3<f64>) -> (f64, Option<f64>) {
        let sigma = self.sigma();
        let h = k.x.hypot(k.y);
        let tilt = h.atan2(k.z);
        if h < super::branch::SINGULAR {
            return (tilt, None);
        }
        let spin = if self.tilt.about_x() {
            k.x.atan2(sigma * k.y)
        } else {
            k.y.atan2(-sigma * k.x)
        };
        (tilt, Some(spin))
    }
}
