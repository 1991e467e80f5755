//! The motion between two stations: how u moves in time on one station interval.
//!
//! A solver gives b = u̇² at the stations (and, for a jerk-limited profile, the path
//! acceleration a = ü = ½ db/du there too). Between stations the motion follows one of four
//! laws, the same for the schedule ([`crate::schedule`]), the re-simulation
//! ([`crate::verify`]) and anything that samples the motion in time:
//!
//! - [`Law::Linear`] (acceleration-limited profiles, seed 000): b linear in u, so ü is
//!   constant and eq. 43 integrates in closed form, `Δt = 2Δu / (√b_0 + √b_1)`;
//!   `√b(t) = √b_0 + ü t`. ü jumps at stations.
//! - [`Law::Quadratic`] (jerk-limited, issue 6): a = ü linear in u between its station values
//!   a_0, a_1, so b is quadratic, `b(x) = b_0 + 2 a_0 x + α x²` with `α = (a_1 − a_0)/Δu`, and
//!   `b_1 − b_0 = Δu (a_0 + a_1)`. ü is continuous; the path jerk is `u⃛ = dü/dt = α u̇`.
//!   Time is `∫ dx / √b(x)` (Gauss–Legendre; the integrand is analytic on the interval).
//! - [`Law::RestStart`] / [`Law::RestEnd`] (jerk-limited, the first and last interval of a
//!   rest-to-rest span): from rest with ü = 0, constant path jerk j: `u = j t³/6`, so
//!   `u̇ = j t²/2`, `ü = j t`. Reaching b_1 at the far station takes `τ = 3Δu/√b_1` and
//!   ends with `ü = 2 b_1 / (3Δu)` — a linear relation the solver imposes. (A quadratic b from
//!   b = ü = 0 would take infinite time: b ∝ x² near rest, and ∫ dx/x diverges.)
//!
//! Axis motion follows by the chain rule: `q̇ = q' u̇`, `q̈ = q'' u̇² + q' ü`,
//! `q⃛ = q''' u̇³ + 3 q'' u̇ ü + q' u⃛`.

use crate::error::{Error, Result};

/// How u moves between two stations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Law {
    Linear,
    Quadratic,
    RestStart,
    RestEnd,
}

/// One station interval: its length in u, b and ü at both ends, and its law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub du: f64,
    pub b0: f64,
    pub b1: f64,
    pub a0: f64,
    pub a1: f64,
    pub law: Law,
}

/// The motion at one instant of an interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// u − u_0 (0 ≤ x ≤ Δu).
    pub x: f64,
    /// u̇ = √b.
    pub ud: f64,
    /// b = u̇².
    pub b: f64,
    /// ü.
    pub udd: f64,
    /// u⃛ (0 under [`Law::Linear`], whose ü is constant).
    pub uddd: f64,
}

/// Gauss–Legendre nodes and weights on [−1, 1], 8 points.
const GL_X: [f64; 4] = [
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL_W: [f64; 4] = [
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];
/// Panels of the Gauss–Legendre rule over a quadratic interval.
const PANELS: usize = 4;

impl Interval {
    /// Interval `k` of a profile: `b` at the stations `u`, and `a` (ü at the stations) for a
    /// jerk-limited profile (`None`: [`Law::Linear`]). Negative rounding noise in b is
    /// clamped to 0.
    pub fn of(u: &[f64], b: &[f64], a: Option<&[f64]>, k: usize) -> Interval {
        let du = u[k + 1] - u[k];
        let (b0, b1) = (b[k].max(0.0), b[k + 1].max(0.0));
        match a {
            None => {
                let udd = (b1 - b0) / (2.0 * du);
                Interval {
                    du,
                    b0,
                    b1,
                    a0: udd,
                    a1: udd,
                    law: Law::Linear,
                }
            }
            Some(a) => {
                let law = if b0 == 0.0 && b1 > 0.0 {
                    Law::RestStart
                } else if b1 == 0.0 && b0 > 0.0 {
                    Law::RestEnd
                } else {
                    Law::Quadratic
                };
                Interval {
                    du,
                    b0,
                    b1,
                    a0: a[k],
                    a1: a[k + 1],
                    law,
                }
            }
        }
    }

    /// b at x (quadratic law).
    fn b_at(&self, x: f64) -> f64 {
        let alpha = (self.a1 - self.a0) / self.du;
        self.b0 + x * (2.0 * self.a0 + alpha * x)
    }

    /// ∫_0^x dξ / √b(ξ) under the quadratic law (Gauss–Legendre: one 8-point panel where b
    /// varies by less than a factor 2 over the interval — the integrand is then analytic well
    /// beyond it and the rule exact to ~1e-13 — else [`PANELS`] panels).
    fn time_to(&self, x: f64) -> f64 {
        let (lo, hi) = (self.b0.min(self.b1), self.b0.max(self.b1));
        let panels = if hi < 2.0 * lo && self.b_min() > 0.5 * lo {
            1
        } else {
            PANELS
        };
        let h = x / panels as f64;
        let mut t = 0.0;
        for p in 0..panels {
            let mid = (p as f64 + 0.5) * h;
            for (xi, w) in GL_X.iter().zip(GL_W) {
                for s in [-1.0, 1.0] {
                    let b = self.b_at(mid + s * xi * 0.5 * h);
                    t += w * 0.5 * h / b.sqrt();
                }
            }
        }
        t
    }

    /// The smallest b on the interval (quadratic law; the vertex if it lies inside).
    fn b_min(&self) -> f64 {
        let alpha = (self.a1 - self.a0) / self.du;
        let mut m = self.b0.min(self.b1);
        if alpha > 0.0 {
            let xv = -self.a0 / alpha;
            if xv > 0.0 && xv < self.du {
                m = m.min(self.b_at(xv));
            }
        }
        m
    }

    /// Time to traverse the interval (eq. 43 under the interval's law); an error where the
    /// motion stalls (b reaches 0 inside, or at both ends).
    pub fn duration(&self) -> Result<f64> {
        let stall = || {
            Err(Error::Infeasible(
                "the feed is zero on a whole interval: the path cannot be traversed".into(),
            ))
        };
        let t = match self.law {
            Law::Linear => {
                let root = self.b0.sqrt() + self.b1.sqrt();
                if root <= 0.0 {
                    return stall();
                }
                2.0 * self.du / root
            }
            Law::Quadratic => {
                if self.b_min() <= 0.0 {
                    return stall();
                }
                self.time_to(self.du)
            }
            Law::RestStart => 3.0 * self.du / self.b1.sqrt(),
            Law::RestEnd => 3.0 * self.du / self.b0.sqrt(),
        };
        if t.is_finite() { Ok(t) } else { stall() }
    }

    /// The motion `tau` after the interval's start (`dur` = [`Interval::duration`]), clamped
    /// to the interval so rounding never leaves it.
    pub fn at(&self, tau: f64, dur: f64) -> State {
        let tau = tau.clamp(0.0, dur);
        match self.law {
            Law::Linear => {
                let (ra, rb) = (self.b0.sqrt(), self.b1.sqrt());
                let udd = self.a0;
                let r = (ra + udd * tau).clamp(ra.min(rb), ra.max(rb));
                // This form stays exact and finite for ü → 0 and from rest.
                let x = (0.5 * tau * (ra + r)).clamp(0.0, self.du);
                State {
                    x,
                    ud: r,
                    b: r * r,
                    udd,
                    uddd: 0.0,
                }
            }
            Law::RestStart => {
                let j = 6.0 * self.du / dur.powi(3);
                let ud = 0.5 * j * tau * tau;
                State {
                    x: (j * tau.powi(3) / 6.0).clamp(0.0, self.du),
                    ud,
                    b: ud * ud,
                    udd: j * tau,
                    uddd: j,
                }
            }
            Law::RestEnd => {
                let j = 6.0 * self.du / dur.powi(3);
                let r = dur - tau;
                let ud = 0.5 * j * r * r;
                State {
                    x: (self.du - j * r.powi(3) / 6.0).clamp(0.0, self.du),
                    ud,
                    b: ud * ud,
                    udd: -j * r,
                    uddd: j,
                }
            }
            Law::Quadratic => {
                let x = self.x_at(tau, dur);
                let b = self.b_at(x).max(0.0);
                let ud = b.sqrt();
                let alpha = (self.a1 - self.a0) / self.du;
                State {
                    x,
                    ud,
                    b,
                    udd: self.a0 + alpha * x,
                    uddd: alpha * ud,
                }
            }
        }
    }

    /// b and ü where u − u_0 = `x` (0 ≤ x ≤ Δu): the profile as a function of u.
    pub fn at_x(&self, x: f64) -> (f64, f64) {
        let x = x.clamp(0.0, self.du);
        match self.law {
            Law::Linear => {
                let f = x / self.du;
                (self.b0 + f * (self.b1 - self.b0), self.a0)
            }
            Law::Quadratic => {
                let alpha = (self.a1 - self.a0) / self.du;
                (self.b_at(x).max(0.0), self.a0 + alpha * x)
            }
            // x = Δu s³ from the rest end: u̇ = s² √b_far, ü = ±(2/3) s b_far/Δu.
            Law::RestStart => {
                let s = (x / self.du).cbrt();
                (self.b1 * s.powi(4), 2.0 * s * self.b1 / (3.0 * self.du))
            }
            Law::RestEnd => {
                let s = ((self.du - x) / self.du).cbrt();
                (self.b0 * s.powi(4), -2.0 * s * self.b0 / (3.0 * self.du))
            }
        }
    }

    /// The time from the interval's start to reach u − u_0 = `x` (clamped to the interval): the
    /// inverse of [`Interval::at`].
    pub fn time_to_x(&self, x: f64) -> Result<f64> {
        let x = x.clamp(0.0, self.du);
        if x <= 0.0 {
            return Ok(0.0);
        }
        let dur = self.duration()?;
        Ok(match self.law {
            Law::Linear => {
                let b = self.b0 + (self.b1 - self.b0) * x / self.du;
                2.0 * x / (self.b0.sqrt() + b.max(0.0).sqrt())
            }
            Law::Quadratic => self.time_to(x).min(dur),
            Law::RestStart => dur * (x / self.du).cbrt(),
            Law::RestEnd => dur * (1.0 - ((self.du - x) / self.du).cbrt()),
        })
    }

    /// The motion at the interval's start (τ = 0) and end (τ = duration), exactly.
    pub fn ends(&self) -> (State, State) {
        let alpha = if self.law == Law::Quadratic {
            (self.a1 - self.a0) / self.du
        } else {
            0.0
        };
        let state = |b: f64, a: f64, x: f64| {
            let ud = b.sqrt();
            State {
                x,
                ud,
                b,
                udd: a,
                uddd: alpha * ud,
            }
        };
        let (mut s0, mut s1) = (
            state(self.b0, self.a0, 0.0),
            state(self.b1, self.a1, self.du),
        );
        match self.law {
            Law::RestStart => {
                let j = 2.0 * self.b1.powf(1.5) / (9.0 * self.du * self.du);
                (s0.uddd, s1.uddd) = (j, j);
                s0.udd = 0.0;
            }
            Law::RestEnd => {
                let j = 2.0 * self.b0.powf(1.5) / (9.0 * self.du * self.du);
                (s0.uddd, s1.uddd) = (j, j);
                s1.udd = 0.0;
            }
            _ => {}
        }
        (s0, s1)
    }

    /// x reached τ after the interval's start: under the quadratic law ü = a_0 + α x is linear
    /// in x, so x(τ) solves ẍ = a_0 + α x with x(0) = 0, ẋ(0) = √b_0 in closed form,
    /// `x = a_0 C + √b_0 S` with `S = sinh(√α τ)/√α` and `C = (cosh(√α τ) − 1)/α` (sin and
    /// 1 − cos for α < 0; both by their series, entire in α, where |α| τ² is small).
    fn x_at(&self, tau: f64, dur: f64) -> f64 {
        if tau <= 0.0 {
            return 0.0;
        }
        if tau >= dur {
            return self.du;
        }
        let alpha = (self.a1 - self.a0) / self.du;
        let z = alpha * tau * tau;
        let (c, s) = if z.abs() < 0.5 {
            // C = τ² Σ z^k/(2k+2)!, S = τ Σ z^k/(2k+1)!: 13 terms reach 1e-17 at |z| = 0.5.
            let (mut c, mut s) = (0.0, 0.0);
            let (mut tc, mut ts) = (0.5, 1.0);
            for k in 0..13 {
                c += tc;
                s += ts;
                let m = (2 * k + 2) as f64;
                ts *= z / (m * (m + 1.0));
                tc *= z / ((m + 1.0) * (m + 2.0));
            }
            (c * tau * tau, s * tau)
        } else if alpha > 0.0 {
            let w = alpha.sqrt();
            (((w * tau).cosh() - 1.0) / alpha, (w * tau).sinh() / w)
        } else {
            let w = (-alpha).sqrt();
            ((1.0 - (w * tau).cos()) / (w * w), (w * tau).sin() / w)
        };
        (self.a0 * c + self.b0.sqrt() * s).clamp(0.0, self.du)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(b0: f64, a0: f64, a1: f64, du: f64) -> Interval {
        Interval {
            du,
            b0,
            b1: b0 + du * (a0 + a1),
            a0,
            a1,
            law: Law::Quadratic,
        }
    }

    #[test]
    fn quadratic_time_matches_the_closed_form() {
        // α > 0: ∫ dx/√(αx² + βx + γ) = ln(2√α √b + 2αx + β)/√α; b varying by 2× (several
        // panels) and by 1.4× (one panel).
        for iv in [quad(4.0, -1.0, 3.0, 2.0), quad(4.0, 0.2, 0.6, 2.0)] {
            check_closed_form(iv);
        }
    }

    fn check_closed_form(iv: Interval) {
        let alpha: f64 = (iv.a1 - iv.a0) / iv.du;
        let beta = 2.0 * iv.a0;
        let f = |x: f64| {
            (2.0 * alpha.sqrt() * iv.b_at(x).sqrt() + 2.0 * alpha * x + beta).ln() / alpha.sqrt()
        };
        let exact = f(iv.du) - f(0.0);
        let t = iv.duration().unwrap();
        assert!((t - exact).abs() < 1e-12 * exact, "{t} vs {exact}");
    }

    #[test]
    fn sampled_states_are_consistent() {
        // x(τ) inverts the time integral; u̇ = √b; ü = a(x); the derivative of u̇ is ü.
        let iv = quad(1.0, 0.5, -0.2, 0.8);
        let dur = iv.duration().unwrap();
        let h = 1e-6;
        for k in 1..10 {
            let tau = dur * k as f64 / 10.0;
            let s = iv.at(tau, dur);
            assert!((iv.time_to(s.x) - tau).abs() < 1e-12);
            assert!((iv.time_to_x(s.x).unwrap() - tau).abs() < 1e-12);
            let (sp, sm) = (iv.at(tau + h, dur), iv.at(tau - h, dur));
            assert!(((sp.x - sm.x) / (2.0 * h) - s.ud).abs() < 1e-7);
            assert!(((sp.ud - sm.ud) / (2.0 * h) - s.udd).abs() < 1e-6);
            assert!(((sp.udd - sm.udd) / (2.0 * h) - s.uddd).abs() < 1e-6);
        }
        let (s0, s1) = iv.ends();
        let (e0, e1) = (iv.at(0.0, dur), iv.at(dur, dur));
        assert!((s0.udd - e0.udd).abs() < 1e-12 && (s1.udd - e1.udd).abs() < 1e-9);
        assert!((s1.x - e1.x).abs() < 1e-12 && (s1.ud - e1.ud).abs() < 1e-9);
    }

    /// ∫_0^x dξ/√(αξ² + βξ + γ) by its antiderivative (β = 2a_0, γ = b_0).
    fn exact_time(iv: &Interval, x: f64) -> f64 {
        let alpha = (iv.a1 - iv.a0) / iv.du;
        let (beta, gamma) = (2.0 * iv.a0, iv.b0);
        if alpha > 1e-9 {
            let w = alpha.sqrt();
            ((2.0 * w * iv.b_at(x).sqrt() + 2.0 * alpha * x + beta)
                / (2.0 * w * gamma.sqrt() + beta))
                .ln()
                / w
        } else if alpha < -1e-9 {
            let d = (beta * beta - 4.0 * alpha * gamma).sqrt();
            ((beta / d).asin() - ((2.0 * alpha * x + beta) / d).asin()) / (-alpha).sqrt()
        } else {
            2.0 * (iv.b_at(x).sqrt() - gamma.sqrt()) / beta
        }
    }

    #[test]
    fn the_closed_form_position_inverts_the_time_integral() {
        // α > 0, α < 0 and α ≈ 0, gentle and steep (the series and the closed forms), and a
        // decelerating interval: the exact time to x(τ) is τ.
        for iv in [
            quad(1.0, 0.5, -0.2, 0.8),
            quad(4.0, -1.0, 3.0, 2.0),
            quad(4.0, 0.2, 0.6, 2.0),
            quad(2.0, 0.3, 0.3 + 1e-14, 1.0),
            quad(1e-4, 0.5, -0.4, 0.01),
            quad(9.0, -2.0, -1.0, 1.5),
            quad(1.0, 30.0, -29.0, 1.0),
        ] {
            let dur = iv.duration().unwrap();
            for k in 1..20 {
                let tau = dur * k as f64 / 20.0;
                let x = iv.x_at(tau, dur);
                let t = exact_time(&iv, x);
                assert!(
                    (t - tau).abs() < 1e-12 * dur,
                    "{iv:?} τ = {tau}: x = {x}, t(x) = {t}"
                );
            }
        }
    }

    #[test]
    fn rest_start_is_constant_jerk_from_rest() {
        let (du, b1) = (0.3, 2.0);
        let iv = Interval {
            du,
            b0: 0.0,
            b1,
            a0: 0.0,
            a1: 2.0 * b1 / (3.0 * du),
            law: Law::RestStart,
        };
        let dur = iv.duration().unwrap();
        let end = iv.at(dur, dur);
        assert!((end.x - du).abs() < 1e-15);
        assert!((end.b - b1).abs() < 1e-12);
        assert!((end.udd - iv.a1).abs() < 1e-12);
        let (s0, s1) = iv.ends();
        assert_eq!((s0.ud, s0.udd), (0.0, 0.0));
        // As a function of u: at the sampled instant's x, the same b and ü.
        let mid = iv.at(0.4 * dur, dur);
        let (b, a) = iv.at_x(mid.x);
        assert!((b - mid.b).abs() < 1e-12 && (a - mid.udd).abs() < 1e-12);
        assert!((iv.time_to_x(mid.x).unwrap() - 0.4 * dur).abs() < 1e-12);
        assert!((s1.uddd - end.uddd).abs() < 1e-12 && (s0.uddd - end.uddd).abs() < 1e-12);
        // The mirror image ends at rest.
        let back = Interval {
            du,
            b0: b1,
            b1: 0.0,
            a0: -iv.a1,
            a1: 0.0,
            law: Law::RestEnd,
        };
        let s = back.at(0.0, dur);
        assert!((s.b - b1).abs() < 1e-12 && (s.udd + iv.a1).abs() < 1e-12 && s.x == 0.0);
        let e = back.at(dur, dur);
        assert!(e.ud == 0.0 && e.udd == 0.0 && (e.x - du).abs() < 1e-15);
    }

    #[test]
    fn stalls_are_errors() {
        // b dips below zero inside: a0 strongly negative, a1 positive.
        let iv = quad(0.01, -1.0, 1.0, 1.0);
        assert!(iv.b_min() < 0.0);
        assert!(iv.duration().is_err());
        let flat = Interval::of(&[0.0, 1.0], &[0.0, 0.0], None, 0);
        assert!(flat.duration().is_err());
    }
}
