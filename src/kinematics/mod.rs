//! Kinematics: from the path's tool tip P(u) and rotary angles θ(u) to every machine axis.
//!
//! For each axis q at each station this stage gives the position q, and its derivatives along
//! the path parameter u, `dq/du` and `d²q/du²`. Along a moving path (|P'| > 0) they are the
//! seed's *effective tangent* t_q = dq/ds and *effective curvature* K_q = d²q/ds² (eq. 28–39)
//! scaled by the parametrisation:
//!
//! `dq/du = t_q |P'|`,   `d²q/du² = K_q |P'|² + t_q (P'·P'')/|P'|`,
//!
//! so q̇ = t_q V and q̈ = t_q A + K_q V² (eq. 28–39) hold with V = |P'| u̇. Where the tool tip
//! stands still (pure reorientation, |P'| = 0) only the u-form exists; the solver works in u
//! throughout, so nothing divides by |P'|.
//!
//! Two independent routes compute the derivatives: the closed forms of seed 000 for the double
//! swivel head ([`head_head::effective`], eq. 31–39), and the generic route, which pushes
//! second-order dual numbers ([`dual::Dual2`]) through the inverse kinematics. Tests hold them
//! to 1e-9 relative agreement.

pub mod dual;
pub mod head_head;

use nalgebra::Vector3;

use crate::error::Result;
use crate::geometry::spline::Jet;
use crate::machine::{KinematicsSpec, Machine};
use dual::{Dual2, Real};

/// Largest number of machine axes.
pub const MAX_AXES: usize = 8;

/// Number of path coordinates: for a CL path the tool tip x, y, z (mm) and two rotary angles
/// (radians), the rest zero; for a joint-space path the axis positions themselves.
pub const PATH_DIM: usize = MAX_AXES;

/// Path coordinates w = (Px, Py, Pz, θ1, θ2, 0, …) or (q_1, …, q_n) and their first two
/// u-derivatives.
pub type PathJet = Jet<PATH_DIM>;

const DEG: f64 = 180.0 / std::f64::consts::PI;

/// Position and u-derivatives of every axis at one station (file units: mm or degrees).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisJets {
    pub q: [f64; MAX_AXES],
    pub dq: [f64; MAX_AXES],
    pub ddq: [f64; MAX_AXES],
}

/// A machine's kinematics, ready to evaluate.
#[derive(Debug, Clone, PartialEq)]
pub enum Kinematics {
    Xyz,
    HeadHead {
        d2: f64,
    },
    /// A joint-space path: the path coordinates are the `n` axis positions.
    Joint {
        n: usize,
    },
}

impl Kinematics {
    pub fn new(machine: &Machine) -> Self {
        match machine.kinematics {
            KinematicsSpec::Xyz => Kinematics::Xyz,
            KinematicsSpec::HeadHead { tool_length } => Kinematics::HeadHead { d2: tool_length },
            KinematicsSpec::Joint => Kinematics::Joint {
                n: machine.axes.len(),
            },
        }
    }

    /// Number of machine axes this kinematics drives.
    pub fn n_axes(&self) -> usize {
        match self {
            Kinematics::Xyz => 3,
            Kinematics::HeadHead { .. } => 5,
            Kinematics::Joint { n } => *n,
        }
    }

    /// Whether the tool orientation moves any axis (false: pure reorientations take no time).
    pub fn uses_orientation(&self) -> bool {
        matches!(self, Kinematics::HeadHead { .. })
    }

    /// Rotary angles (θ1, θ2) in radians at each CL orientation, on one continuous branch:
    /// angles unwrapped (no 2π jumps) and no switch between the two inverse solutions.
    /// `lines` names the CL line of each orientation for errors.
    pub fn rotary_angles(
        &self,
        orientations: &[Vector3<f64>],
        lines: &[usize],
    ) -> Result<Vec<[f64; 2]>> {
        match self {
            Kinematics::Xyz | Kinematics::Joint { .. } => Ok(vec![[0.0; 2]; orientations.len()]),
            Kinematics::HeadHead { .. } => head_head::continuous_angles(orientations, lines),
        }
    }

    /// Axis positions for path coordinates `w` in any [`Real`] type (eq. 27 for head_head).
    /// Rotary axes are returned in degrees.
    pub fn axis_positions<T: Real>(&self, w: [T; PATH_DIM], out: &mut [T; MAX_AXES]) {
        match self {
            Kinematics::Xyz => {
                out[0] = w[0];
                out[1] = w[1];
                out[2] = w[2];
            }
            Kinematics::HeadHead { d2 } => head_head::axis_positions(*d2, w, out),
            Kinematics::Joint { n } => out[..*n].copy_from_slice(&w[..*n]),
        }
    }

    /// Every axis's q, dq/du, d²q/du² by the generic route (dual numbers through
    /// [`Kinematics::axis_positions`]).
    pub fn axis_jets_generic(&self, w: &PathJet) -> AxisJets {
        let wd: [Dual2; PATH_DIM] =
            std::array::from_fn(|i| Dual2::new(w.value[i], w.d1[i], w.d2[i]));
        let mut q = [Dual2::cst(0.0); MAX_AXES];
        self.axis_positions(wd, &mut q);
        let mut out = AxisJets::default();
        for i in 0..self.n_axes() {
            out.q[i] = q[i].v;
            out.dq[i] = q[i].d;
            out.ddq[i] = q[i].dd;
        }
        out
    }

    /// Every axis's q, dq/du, d²q/du²: the closed forms of seed 000 (eq. 31–39) where the tool
    /// tip moves on a head_head machine, the generic route everywhere else.
    pub fn axis_jets(&self, w: &PathJet) -> AxisJets {
        if let Kinematics::HeadHead { d2 } = self {
            if let Some(eff) = head_head::effective(*d2, w) {
                let mut out = eff.to_u_derivatives(w);
                let mut q = [0.0; MAX_AXES];
                self.axis_positions(w.value, &mut q);
                out.q = q;
                return out;
            }
        }
        self.axis_jets_generic(w)
    }
}

/// Seed 000's effective tangents t_q = dq/ds and effective curvatures K_q = d²q/ds² of every
/// axis at one point of a moving path (eq. 28–39; rotary axes in degrees).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Effective {
    pub t: [f64; MAX_AXES],
    pub k: [f64; MAX_AXES],
}

impl Effective {
    /// Converts arc-length derivatives to u-derivatives: `dq/du = t|P'|`,
    /// `d²q/du² = K|P'|² + t (P'·P'')/|P'|`.
    pub fn to_u_derivatives(&self, w: &PathJet) -> AxisJets {
        let (dp, ddp) = tip_derivatives(w);
        let speed = dp.norm();
        let along = dp.dot(&ddp) / speed;
        let mut out = AxisJets::default();
        for i in 0..MAX_AXES {
            out.dq[i] = self.t[i] * speed;
            out.ddq[i] = self.k[i] * speed * speed + self.t[i] * along;
        }
        out
    }

    /// The inverse of [`Effective::to_u_derivatives`]; `None` where the tip stands still.
    pub fn from_u_derivatives(j: &AxisJets, w: &PathJet) -> Option<Effective> {
        let (dp, ddp) = tip_derivatives(w);
        let speed = dp.norm();
        if speed <= f64::MIN_POSITIVE {
            return None;
        }
        let along = dp.dot(&ddp) / speed;
        let mut e = Effective::default();
        for i in 0..MAX_AXES {
            e.t[i] = j.dq[i] / speed;
            e.k[i] = (j.ddq[i] - e.t[i] * along) / (speed * speed);
        }
        Some(e)
    }
}

/// P'(u) and P''(u) of a path jet.
pub fn tip_derivatives(w: &PathJet) -> (Vector3<f64>, Vector3<f64>) {
    (
        Vector3::new(w.d1[0], w.d1[1], w.d1[2]),
        Vector3::new(w.d2[0], w.d2[1], w.d2[2]),
    )
}

pub(crate) fn rad_to_deg() -> f64 {
    DEG
}
