//! Second-order dual numbers: the generic route to axis derivatives.
//!
//! A [`Dual2`] carries a value and its first two derivatives with respect to the path parameter
//! u. Pushing the path's spline jets through a machine's inverse kinematics in `Dual2`
//! arithmetic gives every axis's q, dq/du, d²q/du² by the chain rule, for any kinematics, without
//! a hand-derived formula. It is the independent check of the closed forms (eq. 31–39).

use std::ops::{Add, Mul, Neg, Sub};

/// `v + d·ε + ½·dd·ε²` truncated after second order: value, first and second derivative.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual2 {
    /// Value.
    pub v: f64,
    /// First derivative.
    pub d: f64,
    /// Second derivative.
    pub dd: f64,
}

impl Dual2 {
    /// `v + d·ε + ½·dd·ε²`.
    pub fn new(v: f64, d: f64, dd: f64) -> Self {
        Dual2 { v, d, dd }
    }
}

/// What inverse kinematics needs of a number type: field arithmetic, sin and cos.
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self>
{
    /// The constant `x`.
    fn cst(x: f64) -> Self;
    /// The sine.
    fn sin(self) -> Self;
    /// The cosine.
    fn cos(self) -> Self;
    /// Multiplied by the constant `k`.
    fn scale(self, k: f64) -> Self;
}

impl Real for f64 {
    fn cst(x: f64) -> Self {
        x
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
    fn scale(self, k: f64) -> Self {
        self * k
    }
}

impl Add for Dual2 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Dual2::new(self.v + o.v, self.d + o.d, self.dd + o.dd)
    }
}

impl Sub for Dual2 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Dual2::new(self.v - o.v, self.d - o.d, self.dd - o.dd)
    }
}

impl Mul for Dual2 {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Dual2::new(
            self.v * o.v,
            self.d * o.v + self.v * o.d,
            self.dd * o.v + 2.0 * self.d * o.d + self.v * o.dd,
        )
    }
}

impl Neg for Dual2 {
    type Output = Self;
    fn neg(self) -> Self {
        Dual2::new(-self.v, -self.d, -self.dd)
    }
}

impl Real for Dual2 {
    fn cst(x: f64) -> Self {
        Dual2::new(x, 0.0, 0.0)
    }
    fn sin(self) -> Self {
        let (s, c) = self.v.sin_cos();
        Dual2::new(s, c * self.d, c * self.dd - s * self.d * self.d)
    }
    fn cos(self) -> Self {
        let (s, c) = self.v.sin_cos();
        Dual2::new(c, -s * self.d, -s * self.dd - c * self.d * self.d)
    }
    fn scale(self, k: f64) -> Self {
        Dual2::new(self.v * k, self.d * k, self.dd * k)
    }
}

/// `v + d·ε + ½·dd·ε² + ⅙·ddd·ε³` truncated after third order: the generic route to q''' for
/// jerk limits (issue 6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual3 {
    /// Value.
    pub v: f64,
    /// First derivative.
    pub d: f64,
    /// Second derivative.
    pub dd: f64,
    /// Third derivative.
    pub ddd: f64,
}

impl Dual3 {
    /// `v + d·ε + ½·dd·ε² + ⅙·ddd·ε³`.
    pub fn new(v: f64, d: f64, dd: f64, ddd: f64) -> Self {
        Dual3 { v, d, dd, ddd }
    }

    /// f(self) for a scalar function with derivatives `f0 … f3` at `self.v` (Faà di Bruno to
    /// third order).
    fn compose(self, f0: f64, f1: f64, f2: f64, f3: f64) -> Self {
        let (d, dd, ddd) = (self.d, self.dd, self.ddd);
        Dual3::new(
            f0,
            f1 * d,
            f1 * dd + f2 * d * d,
            f1 * ddd + 3.0 * f2 * d * dd + f3 * d * d * d,
        )
    }
}

impl Add for Dual3 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Dual3::new(self.v + o.v, self.d + o.d, self.dd + o.dd, self.ddd + o.ddd)
    }
}

impl Sub for Dual3 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Dual3::new(self.v - o.v, self.d - o.d, self.dd - o.dd, self.ddd - o.ddd)
    }
}

impl Mul for Dual3 {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Dual3::new(
            self.v * o.v,
            self.d * o.v + self.v * o.d,
            self.dd * o.v + 2.0 * self.d * o.d + self.v * o.dd,
            self.ddd * o.v + 3.0 * (self.dd * o.d + self.d * o.dd) + self.v * o.ddd,
        )
    }
}

impl Neg for Dual3 {
    type Output = Self;
    fn neg(self) -> Self {
        Dual3::new(-self.v, -self.d, -self.dd, -self.ddd)
    }
}

impl Real for Dual3 {
    fn cst(x: f64) -> Self {
        Dual3::new(x, 0.0, 0.0, 0.0)
    }
    fn sin(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.compose(s, c, -s, -c)
    }
    fn cos(self) -> Self {
        let (s, c) = self.v.sin_cos();
        self.compose(c, -s, -c, s)
    }
    fn scale(self, k: f64) -> Self {
        Dual3::new(self.v * k, self.d * k, self.dd * k, self.ddd * k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_rule_of_sin_of_product() {
        // f(u) = sin(u²) at u = 0.7: f' = 2u cos(u²), f'' = 2 cos(u²) − 4u² sin(u²).
        let u = Dual2::new(0.7, 1.0, 0.0);
        let f = (u * u).sin();
        let x: f64 = 0.49;
        assert!((f.v - x.sin()).abs() < 1e-15);
        assert!((f.d - 1.4 * x.cos()).abs() < 1e-15);
        assert!((f.dd - (2.0 * x.cos() - 4.0 * x * x.sin())).abs() < 1e-14);
    }

    #[test]
    fn third_order_chain_rule_against_finite_differences() {
        // f(u) = cos(u³ − u) · sin(2u) at u = 0.4, derivatives by central differences of the
        // analytic f (step 1e-3: error O(h²) ≈ 1e-6 relative).
        let f = |u: f64| (u * u * u - u).cos() * (2.0 * u).sin();
        let x = Dual3::new(0.4, 1.0, 0.0, 0.0);
        let y = (x * x * x - x).cos() * x.scale(2.0).sin();
        let h = 1e-3;
        let u = 0.4;
        let d1 = (f(u + h) - f(u - h)) / (2.0 * h);
        let d2 = (f(u + h) - 2.0 * f(u) + f(u - h)) / (h * h);
        let d3 =
            (f(u + 2.0 * h) - 2.0 * f(u + h) + 2.0 * f(u - h) - f(u - 2.0 * h)) / (2.0 * h * h * h);
        assert!((y.v - f(u)).abs() < 1e-15);
        assert!((y.d - d1).abs() < 1e-5, "{} vs {d1}", y.d);
        assert!((y.dd - d2).abs() < 1e-4, "{} vs {d2}", y.dd);
        assert!(
            (y.ddd - d3).abs() < 1e-3 * (1.0 + d3.abs()),
            "{} vs {d3}",
            y.ddd
        );
    }
}
