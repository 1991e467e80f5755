//! Seed 000's fixed-bed double swivel head: tool direction turned by θ1 (axis C) about the
//! vertical, then by θ2 (axis A); the table moves in x and y, the head in z; d2 is the tool
//! length from the swivel pivot to the tool tip.

use nalgebra::Vector3;

use super::branch::{self, Layout, Target};
use super::dual::Real;
use super::{Effective, MAX_AXES, PATH_DIM, PathJet, ToolPose, rad_to_deg, tip_derivatives};
use crate::error::Result;

/// Eq. 27: x = −Px + d2 sin θ2 sin θ1, y = −Py − d2 sin θ2 cos θ1, z = Pz + d2 − d2 cos θ2;
/// C = θ1 and A = θ2 in degrees.
pub fn axis_positions<T: Real>(d2: f64, w: [T; PATH_DIM], out: &mut [T; MAX_AXES]) {
    let [px, py, pz, t1, t2] = [w[0], w[1], w[2], w[3], w[4]];
    let (s1, c1, s2, c2) = (t1.sin(), t1.cos(), t2.sin(), t2.cos());
    out[0] = -px + (s2 * s1).scale(d2);
    out[1] = -py - (s2 * c1).scale(d2);
    out[2] = pz + T::cst(d2) - c2.scale(d2);
    out[3] = t1.scale(rad_to_deg());
    out[4] = t2.scale(rad_to_deg());
}

/// Eq. 15: the unit tool direction for angles (θ1, θ2).
pub fn orientation(t1: f64, t2: f64) -> Vector3<f64> {
    Vector3::new(t2.sin() * t1.sin(), -t2.sin() * t1.cos(), t2.cos())
}

/// The forward kinematics of eq. 27: X, Y, Z (mm), C, A (degrees) to the tool tip
/// P = (−x + d2 sin θ2 sin θ1, −y − d2 sin θ2 cos θ1, z − d2 + d2 cos θ2) and the tool axis.
pub fn forward(d2: f64, q: &[f64]) -> ToolPose {
    let (t1, t2) = (q[3].to_radians(), q[4].to_radians());
    let (s1, c1) = t1.sin_cos();
    let (s2, c2) = t2.sin_cos();
    ToolPose {
        p: Vector3::new(
            -q[0] + d2 * s2 * s1,
            -q[1] - d2 * s2 * c1,
            q[2] - d2 + d2 * c2,
        ),
        k: orientation(t1, t2),
        angles: [t1, t2],
    }
}

/// Eq. 16: θ2 ≥ 0 and θ1 (`None` at the singular pose, tool parallel to z1) with
/// [`orientation`]`(θ1, θ2) = o`; the other solution is (θ1 + π, −θ2).
pub fn tool_vector_ik(o: &Vector3<f64>) -> (f64, Option<f64>) {
    let h = o.x.hypot(o.y);
    let t2 = h.atan2(o.z);
    if h < branch::SINGULAR {
        return (t2, None);
    }
    (t2, Some(o.x.atan2(-o.y)))
}

/// Eq. 16 on one continuous branch, without travel limits. Of the two solutions (θ1, θ2) and
/// (θ1 + π, −θ2) the first point takes θ2 ≥ 0; every later point takes the solution, with the
/// angles unwrapped by multiples of 2π, nearest to its predecessor, so the angles never jump by
/// 2π nor switch branch. At the singular pose (tool parallel to z1, θ2 = 0) θ1 is undefined and
/// keeps its previous value; within [`branch::POLE_CONE`] of it θ1 is interpolated
/// ([`branch`], rule 3). ([`crate::kinematics::Kinematics::rotary_angles`] adds travel and
/// programmed rotary positions.)
pub fn continuous_angles(orientations: &[Vector3<f64>], lines: &[usize]) -> Result<Vec<[f64; 2]>> {
    let targets: Vec<Target> = orientations
        .iter()
        .map(|o| {
            let (tilt, spin) = tool_vector_ik(o);
            Target::Vector { k: *o, tilt, spin }
        })
        .collect();
    branch::follow(&targets, lines, &layout([None, None]), &|a| {
        orientation(a[0], a[1])
    })
}

/// θ2 (A) is the tilt, θ1 (C) the spin.
pub(crate) fn layout(travel: [Option<(f64, f64)>; 2]) -> Layout {
    Layout {
        tilt: 1,
        travel,
        names: ["C", "A"],
        offset: [0.0; 2],
    }
}

/// The closed forms of seed 000 at one point of a moving path: effective tangents (eq. 31–33)
/// and effective curvatures (eq. 37–39) of X, Y, Z, and t_θ, K_θ of C, A (eq. 19–26), from
/// the tool tip's tangent t_p and curvature vector K_p (eq. 7–14). `None` where |P'| = 0.
pub fn effective(d2: f64, w: &PathJet) -> Option<Effective> {
    let (dp, ddp) = tip_derivatives(w);
    let n = dp.norm();
    if n <= 1e-12 * (1.0 + ddp.norm()) {
        return None;
    }
    let (n2, n4) = (n * n, n * n * n * n);
    let tp = dp / n; // eq. 7–9
    let kp = dp.cross(&ddp).cross(&dp) / n4; // eq. 14
    let pp = dp.dot(&ddp);
    // Eq. 19–26: t_θ = θ'/|P'|, K_θ = θ''/|P'|² − θ'(P'·P'')/|P'|⁴.
    let tt1 = w.d1[3] / n;
    let tt2 = w.d1[4] / n;
    let kt1 = w.d2[3] / n2 - w.d1[3] * pp / n4;
    let kt2 = w.d2[4] / n2 - w.d1[4] * pp / n4;
    let (s1, c1) = w.value[3].sin_cos();
    let (s2, c2) = w.value[4].sin_cos();
    let sq = tt1 * tt1 + tt2 * tt2;
    let deg = rad_to_deg();
    let mut e = Effective::default();
    // Eq. 31–33: effective tangents.
    e.t[0] = -tp.x + d2 * c2 * s1 * tt2 + d2 * s2 * c1 * tt1;
    e.t[1] = -tp.y - d2 * c2 * c1 * tt2 + d2 * s2 * s1 * tt1;
    e.t[2] = tp.z + d2 * s2 * tt2;
    e.t[3] = tt1 * deg;
    e.t[4] = tt2 * deg;
    // Eq. 37–39: effective curvatures.
    e.k[0] =
        -kp.x + d2 * (s2 * c1 * kt1 + c2 * s1 * kt2 - s2 * s1 * sq + 2.0 * c2 * c1 * tt1 * tt2);
    e.k[1] =
        -kp.y + d2 * (s2 * s1 * kt1 - c2 * c1 * kt2 + s2 * c1 * sq + 2.0 * c2 * s1 * tt1 * tt2);
    e.k[2] = kp.z + d2 * (s2 * kt2 + c2 * tt2 * tt2);
    e.k[3] = kt1 * deg;
    e.k[4] = kt2 * deg;
    Some(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_reproduce_the_orientation_and_stay_continuous() {
        // Tool circling about z at 30° tilt, twice round: θ1 must grow past 2π without a jump.
        let os: Vec<_> = (0..200)
            .map(|k| orientation(k as f64 * 0.07, 30f64.to_radians()))
            .collect();
        let lines: Vec<usize> = (1..=200).collect();
        let a = continuous_angles(&os, &lines).unwrap();
        for (k, (o, [t1, t2])) in os.iter().zip(&a).enumerate() {
            assert!((orientation(*t1, *t2) - o).norm() < 1e-12);
            if k > 0 {
                assert!((t1 - a[k - 1][0]).abs() < 0.1);
            }
        }
        assert!(a[199][0] > 13.0);
    }

    #[test]
    fn passing_through_the_singular_pose_keeps_theta1() {
        // The tool swings from +x tilt through vertical to −x tilt in the x–z plane.
        let os: Vec<_> = (-10..=10)
            .map(|k| {
                let t = k as f64 * 0.02;
                Vector3::new(t.sin(), 0.0, t.cos())
            })
            .collect();
        let lines: Vec<usize> = (1..=21).collect();
        let a = continuous_angles(&os, &lines).unwrap();
        for w in a.windows(2) {
            assert!((w[1][0] - w[0][0]).abs() < 1e-9, "θ1 jumped: {w:?}");
            assert!((w[1][1] - w[0][1]).abs() < 0.021);
        }
    }
}
