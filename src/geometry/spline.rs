//! Piecewise polynomial curves in one parameter u: the path geometry of every span.
//!
//! - [`CubicSpline`] (seed 000, eq. 1–3 and 17–18) interpolates points through knots
//!   `u_0 < u_1 < … < u_n` with C² piecewise cubics and *not-a-knot* end conditions (the third
//!   derivative is continuous at `u_1` and `u_{n-1}`), the usual choice when nothing is known
//!   about the ends. Two knots give a straight line, three a parabola.
//! - When the derivatives at the knots are given (joint-space input with `dq`, `ddq` columns),
//!   [`CubicSpline::hermite`] builds the piecewise quintic (or, with first derivatives only,
//!   cubic) Hermite interpolant that takes them exactly.
//!
//! Both are stored alike: per segment, polynomial coefficients in h = u − u_k.

pub use crate::base::Jet;

/// A piecewise polynomial curve through `D`-dimensional points (cubic spline or Hermite).
#[derive(Debug, Clone)]
pub struct CubicSpline<const D: usize> {
    knots: Vec<f64>,
    /// Per segment `k` and coordinate: `y = Σ c_p h^p`, `h = u − u_k`, degree ≤ 5.
    coef: Vec<[[f64; 6]; D]>,
}

impl<const D: usize> CubicSpline<D> {
    /// Interpolates `values[k]` at `knots[k]`. Knots must be strictly increasing, at least two.
    pub fn new(knots: &[f64], values: &[[f64; D]]) -> Self {
        assert!(knots.len() >= 2 && knots.len() == values.len());
        debug_assert!(knots.windows(2).all(|w| w[1] > w[0]));
        let n = knots.len();
        let dx: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let slope: Vec<[f64; D]> = (0..n - 1)
            .map(|k| std::array::from_fn(|j| (values[k + 1][j] - values[k][j]) / dx[k]))
            .collect();
        let s = match n {
            2 => vec![slope[0], slope[0]],
            3 => parabola_slopes(&dx, &slope),
            _ => not_a_knot_slopes(&dx, &slope),
        };
        let coef = (0..n - 1)
            .map(|k| {
                std::array::from_fn(|j| {
                    let t = (s[k][j] + s[k + 1][j] - 2.0 * slope[k][j]) / dx[k];
                    [
                        values[k][j],
                        s[k][j],
                        (slope[k][j] - s[k][j]) / dx[k] - t,
                        t / dx[k],
                        0.0,
                        0.0,
                    ]
                })
            })
            .collect();
        CubicSpline {
            knots: knots.to_vec(),
            coef,
        }
    }

    /// The Hermite interpolant taking the given values, first and (if given) second
    /// derivatives at the knots: quintic per segment with second derivatives, cubic without.
    pub fn hermite(
        knots: &[f64],
        values: &[[f64; D]],
        d1: &[[f64; D]],
        d2: Option<&[[f64; D]]>,
    ) -> Self {
        assert!(knots.len() >= 2 && knots.len() == values.len() && d1.len() == values.len());
        let coef = (0..knots.len() - 1)
            .map(|k| {
                let h = knots[k + 1] - knots[k];
                std::array::from_fn(|j| {
                    let (y0, y1, v0, v1) = (values[k][j], values[k + 1][j], d1[k][j], d1[k + 1][j]);
                    let (a0, a1) = d2.map_or((0.0, 0.0), |d| (d[k][j], d[k + 1][j]));
                    match d2 {
                        // Quintic: matches value, slope and curvature at both ends.
                        Some(_) => {
                            let c2 = a0 / 2.0;
                            // Residuals at u_{k+1} after the known low-order terms.
                            let r0 = y1 - (y0 + v0 * h + c2 * h * h);
                            let r1 = v1 - (v0 + 2.0 * c2 * h);
                            let r2 = a1 - a0;
                            let (h2, h3) = (h * h, h * h * h);
                            let c3 = (20.0 * r0 - 8.0 * r1 * h + r2 * h2) / (2.0 * h3);
                            let c4 = (-30.0 * r0 + 14.0 * r1 * h - 2.0 * r2 * h2) / (2.0 * h3 * h);
                            let c5 = (12.0 * r0 - 6.0 * r1 * h + r2 * h2) / (2.0 * h3 * h2);
                            [y0, v0, c2, c3, c4, c5]
                        }
                        // Cubic: matches value and slope at both ends.
                        None => {
                            let m = (y1 - y0) / h;
                            let c2 = (3.0 * m - 2.0 * v0 - v1) / h;
                            let c3 = (v0 + v1 - 2.0 * m) / (h * h);
                            [y0, v0, c2, c3, 0.0, 0.0]
                        }
                    }
                })
            })
            .collect();
        CubicSpline {
            knots: knots.to_vec(),
            coef,
        }
    }

    /// The knots `u_0 … u_n`.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Index of the segment containing `u` (clamped to the ends).
    pub fn segment(&self, u: f64) -> usize {
        let k = self.knots.partition_point(|&x| x <= u);
        k.saturating_sub(1).min(self.coef.len() - 1)
    }

    /// Value and derivatives at `u` (extrapolates the end segments outside the knots).
    pub fn eval(&self, u: f64) -> Jet<D> {
        self.eval_in(self.segment(u), u)
    }

    /// Value and derivatives at `u`, using segment `k` (no search).
    pub fn eval_in(&self, k: usize, u: f64) -> Jet<D> {
        let h = u - self.knots[k];
        let c = &self.coef[k];
        Jet {
            value: std::array::from_fn(|j| {
                let [a, b, cc, d, e, f] = c[j];
                a + h * (b + h * (cc + h * (d + h * (e + h * f))))
            }),
            d1: std::array::from_fn(|j| {
                let [_, b, cc, d, e, f] = c[j];
                b + h * (2.0 * cc + h * (3.0 * d + h * (4.0 * e + h * 5.0 * f)))
            }),
            d2: std::array::from_fn(|j| {
                let [_, _, cc, d, e, f] = c[j];
                2.0 * cc + h * (6.0 * d + h * (12.0 * e + h * 20.0 * f))
            }),
        }
    }
}

impl<const D: usize> CubicSpline<D> {
    /// Third derivative of every coordinate at `u` on segment `k` (constant on a cubic
    /// segment; it jumps at knots, so the segment says which side): what jerk limits need.
    pub fn d3_in(&self, k: usize, u: f64) -> [f64; D] {
        let h = u - self.knots[k];
        std::array::from_fn(|j| {
            let [_, _, _, d, e, f] = self.coef[k][j];
            6.0 * d + h * (24.0 * e + h * 60.0 * f)
        })
    }
}

/// Three points: the one parabola through them (not-a-knot degenerates to it).
fn parabola_slopes<const D: usize>(dx: &[f64], slope: &[[f64; D]]) -> Vec<[f64; D]> {
    let mut s = vec![[0.0; D]; 3];
    for j in 0..D {
        let curv = (slope[1][j] - slope[0][j]) / (dx[0] + dx[1]); // half the second derivative
        s[0][j] = slope[0][j] - curv * dx[0];
        s[1][j] = slope[0][j] + curv * dx[0];
        s[2][j] = slope[1][j] + curv * dx[1];
    }
    s
}

/// Slopes at the knots of the not-a-knot cubic spline: a tridiagonal system (n ≥ 4 knots),
/// solved by Gaussian elimination with partial pivoting (the end rows are not diagonally
/// dominant).
fn not_a_knot_slopes<const D: usize>(dx: &[f64], slope: &[[f64; D]]) -> Vec<[f64; D]> {
    let n = dx.len() + 1;
    let mut lower = vec![0.0; n]; // lower[i]: coefficient of s[i-1] in row i
    let mut diag = vec![0.0; n];
    let mut upper = vec![0.0; n]; // upper[i]: coefficient of s[i+1] in row i
    let mut rhs = vec![[0.0; D]; n];
    for i in 1..n - 1 {
        lower[i] = dx[i];
        diag[i] = 2.0 * (dx[i - 1] + dx[i]);
        upper[i] = dx[i - 1];
        rhs[i] = std::array::from_fn(|j| 3.0 * (dx[i] * slope[i - 1][j] + dx[i - 1] * slope[i][j]));
    }
    let d = dx[0] + dx[1];
    diag[0] = dx[1];
    upper[0] = d;
    rhs[0] = std::array::from_fn(|j| {
        ((dx[0] + 2.0 * d) * dx[1] * slope[0][j] + dx[0] * dx[0] * slope[1][j]) / d
    });
    let (a, b) = (dx[n - 2], dx[n - 3]);
    let d = a + b;
    lower[n - 1] = d;
    diag[n - 1] = b;
    rhs[n - 1] = std::array::from_fn(|j| {
        (a * a * slope[n - 3][j] + (2.0 * d + a) * b * slope[n - 2][j]) / d
    });
    solve_tridiagonal(&mut lower, &mut diag, &mut upper, &mut rhs);
    rhs
}

/// Solves a tridiagonal system in place with partial pivoting (LAPACK `dgtsv`'s scheme: one
/// extra super-diagonal of fill). `lower[i]` multiplies `x[i-1]` in row `i`, `upper[i]`
/// multiplies `x[i+1]`. The solution overwrites `rhs`.
fn solve_tridiagonal<const D: usize>(
    lower: &mut [f64],
    diag: &mut [f64],
    upper: &mut [f64],
    rhs: &mut [[f64; D]],
) {
    let n = diag.len();
    // dl[i] = sub-diagonal entry of row i+1; after a row swap it holds the fill of row i.
    let mut dl: Vec<f64> = lower[1..].to_vec();
    for i in 0..n - 1 {
        if diag[i].abs() >= dl[i].abs() {
            let f = dl[i] / diag[i];
            diag[i + 1] -= f * upper[i];
            let ri = rhs[i];
            for (r, x) in rhs[i + 1].iter_mut().zip(ri) {
                *r -= f * x;
            }
            dl[i] = 0.0;
        } else {
            let f = diag[i] / dl[i];
            diag[i] = dl[i];
            let t = diag[i + 1];
            diag[i + 1] = upper[i] - f * t;
            if i + 2 < n {
                dl[i] = upper[i + 1];
                upper[i + 1] = -f * dl[i];
            } else {
                dl[i] = 0.0;
            }
            upper[i] = t;
            let (ri, rn) = (rhs[i], rhs[i + 1]);
            rhs[i] = rn;
            rhs[i + 1] = std::array::from_fn(|j| ri[j] - f * rn[j]);
        }
    }
    for i in (0..n).rev() {
        for j in 0..D {
            let mut r = rhs[i][j];
            if i + 1 < n {
                r -= upper[i] * rhs[i + 1][j];
            }
            if i + 2 < n {
                r -= dl[i] * rhs[i + 2][j];
            }
            rhs[i][j] = r / diag[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_a_cubic_exactly() {
        // Not-a-knot reproduces any cubic polynomial, on uneven knots too.
        let f = |u: f64| 1.0 - 2.0 * u + 0.5 * u * u - 0.25 * u * u * u;
        let knots = [0.0, 0.3, 1.1, 1.5, 2.6, 3.0, 4.2];
        let vals: Vec<[f64; 1]> = knots.iter().map(|&u| [f(u)]).collect();
        let s = CubicSpline::new(&knots, &vals);
        for &u in &[0.0, 0.2, 0.77, 1.3, 2.0, 2.9, 4.2] {
            let j = s.eval(u);
            assert!((j.value[0] - f(u)).abs() < 1e-12);
            assert!((j.d1[0] - (-2.0 + u - 0.75 * u * u)).abs() < 1e-11);
            assert!((j.d2[0] - (1.0 - 1.5 * u)).abs() < 1e-10);
        }
    }

    #[test]
    fn pivoting_path_reproduces_a_cubic() {
        // Very uneven first knots make the first row's sub-diagonal larger than its diagonal.
        let f = |u: f64| 3.0 + u * u * u;
        let knots = [0.0, 5.0, 5.1, 5.2, 9.0, 9.01];
        let vals: Vec<[f64; 1]> = knots.iter().map(|&u| [f(u)]).collect();
        let s = CubicSpline::new(&knots, &vals);
        for &u in &[1.0, 5.05, 7.0, 9.005] {
            let j = s.eval(u);
            assert!((j.value[0] - f(u)).abs() < 1e-9 * f(u));
            assert!((j.d2[0] - 6.0 * u).abs() < 1e-8 * u);
        }
    }

    #[test]
    fn quintic_hermite_takes_the_given_derivatives_and_reproduces_a_quintic() {
        let f = |u: f64| {
            0.3 - u + 0.5 * u.powi(2) + 0.2 * u.powi(3) - 0.1 * u.powi(4) + 0.03 * u.powi(5)
        };
        let f1 = |u: f64| -1.0 + u + 0.6 * u.powi(2) - 0.4 * u.powi(3) + 0.15 * u.powi(4);
        let f2 = |u: f64| 1.0 + 1.2 * u - 1.2 * u.powi(2) + 0.6 * u.powi(3);
        let knots = [0.0, 0.4, 1.5, 2.0];
        let v: Vec<[f64; 1]> = knots.iter().map(|&u| [f(u)]).collect();
        let d1: Vec<[f64; 1]> = knots.iter().map(|&u| [f1(u)]).collect();
        let d2: Vec<[f64; 1]> = knots.iter().map(|&u| [f2(u)]).collect();
        let s = CubicSpline::hermite(&knots, &v, &d1, Some(&d2));
        for &u in &[0.0, 0.1, 0.4, 0.9, 1.5, 1.77, 2.0] {
            let j = s.eval(u);
            assert!((j.value[0] - f(u)).abs() < 1e-12, "value at {u}");
            assert!((j.d1[0] - f1(u)).abs() < 1e-11, "d1 at {u}");
            assert!((j.d2[0] - f2(u)).abs() < 1e-10, "d2 at {u}");
        }
        // Without second derivatives: the cubic Hermite, exact for cubics.
        let g = |u: f64| 1.0 + 2.0 * u - u * u * u;
        let v: Vec<[f64; 1]> = knots.iter().map(|&u| [g(u)]).collect();
        let d1: Vec<[f64; 1]> = knots.iter().map(|&u| [2.0 - 3.0 * u * u]).collect();
        let s = CubicSpline::hermite(&knots, &v, &d1, None);
        let j = s.eval(1.1);
        assert!((j.value[0] - g(1.1)).abs() < 1e-12 && (j.d2[0] + 6.6).abs() < 1e-10);
    }

    #[test]
    fn two_and_three_points() {
        let s = CubicSpline::new(&[0.0, 2.0], &[[1.0], [5.0]]);
        assert_eq!(s.eval(1.0).value[0], 3.0);
        assert_eq!(s.eval(1.0).d2[0], 0.0);
        let s = CubicSpline::new(&[0.0, 1.0, 3.0], &[[0.0], [1.0], [9.0]]);
        let j = s.eval(2.0);
        assert!((j.value[0] - 4.0).abs() < 1e-12 && (j.d2[0] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn interpolates_and_is_c2() {
        let knots: Vec<f64> = (0..20).map(|i| (i as f64).powf(1.3)).collect();
        let vals: Vec<[f64; 2]> = knots.iter().map(|&u| [u.sin(), (0.3 * u).cos()]).collect();
        let s = CubicSpline::new(&knots, &vals);
        for k in 1..knots.len() - 1 {
            let (a, b) = (s.eval_in(k - 1, knots[k]), s.eval_in(k, knots[k]));
            for j in 0..2 {
                assert!((a.value[j] - vals[k][j]).abs() < 1e-12);
                assert!((a.d1[j] - b.d1[j]).abs() < 1e-10);
                assert!((a.d2[j] - b.d2[j]).abs() < 1e-9);
            }
        }
    }
}
