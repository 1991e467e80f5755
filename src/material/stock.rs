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

    /// The cells `i` (of `n` along X, centres x = `x0` + (i + ½)·`hx`) whose vertical line at
    /// `y` has material ([`Stock::column`] is `Some`): a run `ia..=ib`, if any; and the
    /// column's length there (the same on every line of a box or a cylinder), mm.
    ///
    /// The same cells as asking [`Stock::column`] cell by cell: the run is found by bisection
    /// on that very test, which is monotone on each side of the stock's middle (x is
    /// increasing in i, and so is every rounded operation of the test in its argument).
    pub fn row_cells(&self, y: f64, x0: f64, hx: f64, n: usize) -> Option<(usize, usize, f64)> {
        let inside = |i: usize| {
            let x = x0 + (super::dexel::index_f64(i) + 0.5) * hx;
            self.column(x, y).is_some()
        };
        let length = match *self {
            Stock::Box { min, max } => max[2] - min[2],
            Stock::Cylinder { z, .. } => z[1] - z[0],
        };
        if n == 0 {
            return None;
        }
        // The cells on either side of the middle: the test is non-decreasing in i up to the
        // first, non-increasing from the second; if neither has material, none has.
        let [bx0, _, bx1, _] = self.xy_bounds();
        let mid = 0.5 * (bx0 + bx1);
        let c = (((mid - x0) / hx - 0.5).floor().max(0.0) as usize).min(n - 1);
        let m = if inside(c) {
            c
        } else if c + 1 < n && inside(c + 1) {
            c + 1
        } else {
            return None;
        };
        // The first cell with material in 0..=m and the last in m..n (bisection).
        let (mut lo, mut hi) = (0, m);
        while lo < hi {
            let k = lo + (hi - lo) / 2;
            if inside(k) { hi = k } else { lo = k + 1 }
        }
        let ia = lo;
        let (mut lo, mut hi) = (m, n - 1);
        while lo < hi {
            let k = hi - (hi - lo) / 2;
            if inside(k) { lo = k } else { hi = k - 1 }
        }
        Some((ia, lo, length))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng as rng;

    /// [`Stock::row_cells`] finds the cells [`Stock::column`] gives material, row by row, on
    /// grids that reach past the stock, start inside it or lie beside it.
    #[test]
    fn row_cells_are_the_columns_cell_by_cell() {
        let mut rnd = rng(11);
        for case in 0..400 {
            let s = if case % 2 == 0 {
                let (a, b) = (-5.0 + 10.0 * rnd(), -5.0 + 10.0 * rnd());
                Stock::Box {
                    min: [a, b, -3.0],
                    max: [a + 0.1 + 8.0 * rnd(), b + 0.1 + 8.0 * rnd(), 1.0],
                }
            } else {
                Stock::Cylinder {
                    center: [-5.0 + 10.0 * rnd(), -5.0 + 10.0 * rnd()],
                    radius: 0.05 + 6.0 * rnd(),
                    z: [-2.0, 4.5],
                }
            };
            let (x0, hx) = (-12.0 + 8.0 * rnd(), 0.02 + 0.5 * rnd());
            let n = 1 + (60.0 * rnd()) as usize;
            for k in 0..40 {
                let y = -12.0 + 24.0 * f64::from(k) / 39.0;
                let want: Vec<usize> = (0..n)
                    .filter(|&i| s.column(x0 + (i as f64 + 0.5) * hx, y).is_some())
                    .collect();
                let got = s.row_cells(y, x0, hx, n);
                match (want.first(), want.last(), got) {
                    (None, None, None) => {}
                    (Some(&a), Some(&b), Some((ia, ib, length))) => {
                        assert_eq!((ia, ib), (a, b), "{s:?} x0 {x0} hx {hx} n {n} y {y}");
                        assert_eq!(want.len(), b - a + 1);
                        let c = s.column(x0 + (a as f64 + 0.5) * hx, y).unwrap();
                        assert_eq!(length, c[1] - c[0]);
                    }
                    _ => panic!("{s:?} x0 {x0} hx {hx} n {n} y {y}: {want:?} vs {got:?}"),
                }
            }
        }
    }
}
