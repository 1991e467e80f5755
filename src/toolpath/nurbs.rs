//! Rational B-spline (NURBS) curves as NX writes them in CLSF (`NURBS/`, `KNOT/`, `CNTRL/`):
//! evaluation by de Boor's algorithm in homogeneous coordinates and adaptive sampling within a
//! chord tolerance.

use nalgebra::Vector3;

/// A NURBS curve: knots t₀ ≤ … ≤ t_{n+p}, control points with weights, degree p = knots −
/// control points − 1.
#[derive(Debug, Clone)]
pub struct Nurbs {
    knots: Vec<f64>,
    /// (w·x, w·y, w·z, w).
    homogeneous: Vec<[f64; 4]>,
    degree: usize,
}

/// Deepest bisection of one knot span while sampling.
const MAX_BISECTIONS: u32 = 30;

impl Nurbs {
    /// Checks the data: at least two control points, degree ≥ 1, non-decreasing finite knots,
    /// a non-empty parameter range.
    pub fn new(knots: Vec<f64>, control: Vec<[f64; 4]>) -> Result<Nurbs, String> {
        let n = control.len();
        if n < 2 {
            return Err(format!(
                "needs at least 2 control points (CNTRL/), found {n}"
            ));
        }
        if knots.len() < n + 2 {
            return Err(format!(
                "{} knots for {n} control points: a curve of degree p needs control points + p + \
                 1 knots (p ≥ 1)",
                knots.len()
            ));
        }
        let degree = knots.len() - n - 1;
        if knots.iter().any(|k| !k.is_finite()) || knots.windows(2).any(|w| w[1] < w[0]) {
            return Err("knots must be finite and non-decreasing".into());
        }
        if knots[n] <= knots[degree] {
            return Err("the knots leave no parameter range".into());
        }
        let homogeneous = control
            .iter()
            .map(|c| [c[0] * c[3], c[1] * c[3], c[2] * c[3], c[3]])
            .collect();
        Ok(Nurbs {
            knots,
            homogeneous,
            degree,
        })
    }

    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The parameter range [t_p, t_n].
    pub fn range(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.homogeneous.len()])
    }

    /// The point at parameter `t` (clamped to the range), de Boor.
    pub fn eval(&self, t: f64) -> Vector3<f64> {
        let p = self.degree;
        let n = self.homogeneous.len();
        let (a, b) = self.range();
        let t = t.clamp(a, b);
        // Span k with t_k ≤ t < t_{k+1}, p ≤ k ≤ n − 1.
        let mut k = p;
        while k + 1 < n && self.knots[k + 1] <= t {
            k += 1;
        }
        let mut d: Vec<[f64; 4]> = (0..=p).map(|j| self.homogeneous[j + k - p]).collect();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = j + k - p;
                let denom = self.knots[i + p + 1 - r] - self.knots[i];
                let alpha = if denom > 0.0 {
                    (t - self.knots[i]) / denom
                } else {
                    0.0
                };
                for c in 0..4 {
                    d[j][c] = (1.0 - alpha) * d[j - 1][c] + alpha * d[j][c];
                }
            }
        }
        let h = d[p];
        Vector3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3])
    }

    /// Points along the curve from its start to its end (the start included) such that every
    /// chord stays within `tolerance` (mm) of the curve at its midpoint and quarter points;
    /// an error past `max_points`.
    pub fn sample(&self, tolerance: f64, max_points: usize) -> Result<Vec<Vector3<f64>>, String> {
        let n = self.homogeneous.len();
        let mut out = vec![self.eval(self.range().0)];
        for k in self.degree..n {
            let (a, b) = (self.knots[k], self.knots[k + 1]);
            if b <= a {
                continue;
            }
            let mut stack = vec![(a, b, 0u32)];
            while let Some((t0, t1, depth)) = stack.pop() {
                let (p0, p1) = (self.eval(t0), self.eval(t1));
                let off = [0.25, 0.5, 0.75].iter().any(|s| {
                    let q = self.eval(t0 + s * (t1 - t0));
                    distance_to_segment(&q, &p0, &p1) > tolerance
                });
                if off && depth < MAX_BISECTIONS {
                    let m = 0.5 * (t0 + t1);
                    stack.push((m, t1, depth + 1));
                    stack.push((t0, m, depth + 1));
                } else {
                    out.push(p1);
                    if out.len() > max_points {
                        return Err(format!(
                            "more than {max_points} points within the chord tolerance"
                        ));
                    }
                }
            }
        }
        Ok(out)
    }
}

fn distance_to_segment(q: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((q - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (q - (a + ab * t)).norm()
}
