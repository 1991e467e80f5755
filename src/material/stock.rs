//! The blank the program cuts, in workpiece coordinates (the toolpath's), mm.

/// A blank: an axis-aligned box or a cylinder about a vertical axis.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stock {
    /// The box `min ≤ (x, y, z) ≤ max`.
    Box {
        /// Lowest corner (x, y, z), mm.
        min: [f64; 3],
        /// Highest corner (x, y, z), mm.
        max: [f64; 3],
    },
    /// The cylinder of `radius` about the vertical line through `center` (x, y), from `z[0]`
    /// to `z[1]`.
    Cylinder {
        /// Axis position (x, y), mm.
        center: [f64; 2],
        /// Radius, mm.
        radius: f64,
        /// Bottom and top z, mm.
        z: [f64; 2],
    },
}

impl Stock {
    /// Checks the dimensions (positive extent, finite, within ±1e6 mm): a one-line reason.
    pub fn validate(&self) -> Result<(), String> {
        let ok = |x: f64| x.is_finite() && x.abs() <= 1e6;
        match *self {
            Stock::Box { min, max } => {
                if !(min.iter().chain(&max).all(|&x| ok(x))) {
                    return Err("box corners must be finite and within ±1e6 mm".into());
                }
                if (0..3).any(|k| max[k] <= min[k]) {
                    return Err(format!(
                        "box max {max:?} must exceed min {min:?} on every axis"
                    ));
                }
            }
            Stock::Cylinder { center, radius, z } => {
                if !(ok(center[0]) && ok(center[1]) && ok(z[0]) && ok(z[1]) && ok(radius)) {
                    return Err("cylinder dimensions must be finite and within ±1e6 mm".into());
                }
                if radius <= 0.0 || z[1] <= z[0] {
                    return Err(format!(
                        "cylinder needs a positive radius ({radius}) and z[1] > z[0] ({z:?})"
                    ));
                }
            }
        }
        Ok(())
    }

    /// The XY bounding rectangle `[x0, y0, x1, y1]`.
    pub fn xy_bounds(&self) -> [f64; 4] {
        match *self {
            Stock::Box { min, max } => [min[0], min[1], max[0], max[1]],
            Stock::Cylinder { center, radius, .. } => [
                center[0] - radius,
                center[1] - radius,
                center[0] + radius,
                center[1] + radius,
            ],
        }
    }

    /// The material on the vertical line through (x, y): `[z0, z1]`, if any.
    pub fn column(&self, x: f64, y: f64) -> Option<[f64; 2]> {
        match *self {
            Stock::Box { min, max } => (x >= min[0] && x <= max[0] && y >= min[1] && y <= max[1])
                .then_some([min[2], max[2]]),
            Stock::Cylinder { center, radius, z } => {
                ((x - center[0]).powi(2) + (y - center[1]).powi(2) <= radius * radius).then_some(z)
            }
        }
    }

    /// The exact volume, mm³.
    pub fn volume(&self) -> f64 {
        match *self {
            Stock::Box { min, max } => (0..3).map(|k| max[k] - min[k]).product(),
            Stock::Cylinder { radius, z, .. } => {
                std::f64::consts::PI * radius * radius * (z[1] - z[0])
            }
        }
    }
}
