//! The base types every stage shares, below all of them: the axis count, the jets of the path
//! coordinates (value and two derivatives in the path parameter) and the process limits that
//! name a feed bound. They sit here, not in the stage that computes them, so that the machine,
//! the readers, the geometry and the kinematics can all name them without depending on each
//! other (issue 15: no loop between modules).

/// The angle between two unit vectors, radians, accurate near 0 and π (`atan2` of the sine
/// and cosine, where `acos` of the dot product loses half the digits near 0).
pub fn angle_between(a: &nalgebra::Vector3<f64>, b: &nalgebra::Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// `x` to `places` decimals without trailing zeros, for a message or a written word: `38.1`
/// for 1.5 × 25.4 to 4 places, `6` for 6.0, `0` for −0.0 and for what rounds to it.
pub fn trimmed(x: f64, places: usize) -> String {
    let s = format!("{x:.places$}");
    let t = s.trim_end_matches('0').trim_end_matches('.');
    if t == "-0" {
        "0".to_string()
    } else {
        t.to_string()
    }
}

/// Largest number of machine axes.
pub const MAX_AXES: usize = 8;

/// Number of path coordinates: for a CL path the tool tip x, y, z (mm) and two rotary angles
/// (radians), the rest zero; for a joint-space path the axis positions themselves.
pub const PATH_DIM: usize = MAX_AXES;

/// Path coordinates w = (Px, Py, Pz, θ1, θ2, 0, …) or (q_1, …, q_n) and their first two
/// u-derivatives.
pub type PathJet = Jet<PATH_DIM>;

/// Value and first two derivatives of every coordinate at one parameter value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet<const D: usize> {
    /// The value.
    pub value: [f64; D],
    /// The first derivative.
    pub d1: [f64; D],
    /// The second derivative.
    pub d2: [f64; D],
}

/// The process limit that sets a feed bound (reports and plots name them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ProcessLimit {
    /// Chip load per tooth ("chip load").
    ChipLoad,
    /// Material removal rate ("MRR").
    Mrr,
    /// Spindle power ("power").
    Power,
    /// The air-cut feed where the tool removes nothing ("air").
    Air,
}

impl ProcessLimit {
    /// The name in reports: "chip load", "MRR", "power", "air".
    pub fn label(self) -> &'static str {
        match self {
            ProcessLimit::ChipLoad => "chip load",
            ProcessLimit::Mrr => "MRR",
            ProcessLimit::Power => "power",
            ProcessLimit::Air => "air",
        }
    }
}
