//! Frames: program coordinates in a shifted and rotated coordinate system.
//!
//! A [`Frame`] maps program coordinates p to workpiece coordinates R·p + t. Two frames are
//! active at once and compose as `swivel ∘ programmable`:
//!
//! * the **programmable frame**, Sinumerik `TRANS`/`ROT` (replace the programmable frame:
//!   Sinumerik deletes the earlier `TRANS`/`ROT`/`ATRANS`/`AROT` instructions), `ATRANS`/`AROT`
//!   (append to it); bare `TRANS` or `ROT` clears it. `ROT X… Y… Z…` turns by the angles about
//!   X, Y and Z in Sinumerik's default order (machine data 10600 `FRAME_ANGLE_ORDER` = ZYX): R =
//!   Rz(γ)·Ry(β)·Rx(α); `AROT` appends that rotation to the frame (p ↦ F(R·p)), `ATRANS`
//!   appends a translation in the current frame's coordinates.
//! * the **swivel frame** of 3+2 work: Sinumerik `CYCLE800(_FR, _TC, _ST, _MODE, _X0, _Y0,
//!   _Z0, _A, _B, _C, _X1, _Y1, _Z1, _DIR, …)` with `_MODE` axis by axis (bits 7–6 = 00; bits
//!   1–0, 3–2, 5–4 name the first, second and third rotation axis: 01 X, 10 Y, 11 Z; 57 is
//!   X then Y then Z), each turn about the already turned axes: p_wcs = P0 + Ra·Rb·Rc·(P1 + p)
//!   with P0 = (_X0, _Y0, _Z0) and P1 = (_X1, _Y1, _Z1); other `_MODE`s (solid angle,
//!   projection angles, direct rotary positions) are an error. `CYCLE800()` clears it. Fanuc
//!   `G68.2 X Y Z I J K` (tilted working plane): origin (X, Y, Z) and Euler angles I, J, K
//!   turned Z–X–Z: R = Rz(I)·Rx(J)·Rz(K); `G69` clears it; `G53.1` (turn the tool onto the
//!   plane) moves nothing the toolpath records.
//!
//! Under a swivel frame the tool points along the frame's Z (the control turns the rotary
//! axes there), so CL points get the tool vector R·(0, 0, 1) and no rotary positions.

use nalgebra::{Matrix3, Rotation3, Vector3};

/// p ↦ R·p + t.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub r: Matrix3<f64>,
    pub t: Vector3<f64>,
}

impl Default for Frame {
    fn default() -> Self {
        Frame::IDENTITY
    }
}

impl Frame {
    pub const IDENTITY: Frame = Frame {
        r: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        t: Vector3::new(0.0, 0.0, 0.0),
    };

    pub fn translation(t: Vector3<f64>) -> Frame {
        Frame {
            r: Matrix3::identity(),
            t,
        }
    }

    pub fn rotation(r: Matrix3<f64>) -> Frame {
        Frame {
            r,
            t: Vector3::zeros(),
        }
    }

    pub fn is_identity(&self) -> bool {
        *self == Frame::IDENTITY
    }

    /// self ∘ other: first `other`, then `self`.
    pub fn then_inner(&self, other: &Frame) -> Frame {
        Frame {
            r: self.r * other.r,
            t: self.r * other.t + self.t,
        }
    }

    pub fn apply(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.r * p + self.t
    }

    /// The inverse map (R is a rotation).
    pub fn invert(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.r.transpose() * (p - self.t)
    }
}

fn about(axis: usize, deg: f64) -> Matrix3<f64> {
    let a = Vector3::ith_axis(axis);
    *Rotation3::from_axis_angle(&a, deg.to_radians()).matrix()
}

/// Sinumerik `ROT X α Y β Z γ`: Rz(γ)·Ry(β)·Rx(α).
pub fn rot_zyx(angles: [f64; 3]) -> Matrix3<f64> {
    about(2, angles[2]) * about(1, angles[1]) * about(0, angles[0])
}

/// Fanuc `G68.2` Euler angles I J K: Rz(I)·Rx(J)·Rz(K).
pub fn euler_zxz(i: f64, j: f64, k: f64) -> Matrix3<f64> {
    about(2, i) * about(0, j) * about(2, k)
}

/// `CYCLE800` arguments (lengths already in mm); `None` for `CYCLE800()`.
pub fn cycle800(args: &[Option<f64>]) -> Result<Option<Frame>, String> {
    if args.iter().all(Option::is_none) {
        return Ok(None);
    }
    let get = |k: usize| args.get(k).copied().flatten().unwrap_or(0.0);
    let mode = get(3);
    if mode.fract() != 0.0 || !(0.0..=255.0).contains(&mode) {
        return Err(format!("CYCLE800: _MODE {mode} is not a swivel mode"));
    }
    let mode = mode as u32;
    if mode >> 6 != 0 {
        return Err(format!(
            "CYCLE800: _MODE {mode} (solid angle, projection angles or rotary positions) is not \
             supported; only axis-by-axis rotation (_MODE bits 7–6 = 00, e.g. 57) is"
        ));
    }
    let angles = [get(7), get(8), get(9)];
    let mut r = Matrix3::identity();
    for (k, angle) in angles.iter().enumerate() {
        let axis = match (mode >> (2 * k)) & 3 {
            1 => 0,
            2 => 1,
            3 => 2,
            _ if *angle == 0.0 => continue,
            _ => {
                return Err(format!(
                    "CYCLE800: _MODE {mode} names no axis for rotation {} ({angle}°)",
                    k + 1
                ));
            }
        };
        r *= about(axis, *angle);
    }
    let p0 = Vector3::new(get(4), get(5), get(6));
    let p1 = Vector3::new(get(10), get(11), get(12));
    Ok(Some(Frame { r, t: p0 + r * p1 }))
}
