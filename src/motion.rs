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
//! - [`Law::Quadratic`]: a = ü linear in u between a_0 at the interval's start and a_1 at its
//!   end, so b is quadratic, `b(x) = b_0 + 2 a_0 x + α x²` with `α = (a_1 − a_0)/Δu`, and
//!   `b_1 − b_0 = Δu (a_0 + a_1)`; the path jerk is `u⃛ = dü/dt = α u̇`. Jerk-limited profiles
//!   (issue 6) give ü at the stations, continuous; acceleration-limited ones under
//!   [`Ramp::Linear`](crate::constraints::Ramp::Linear) give it at both ends of every
//!   interval ([`Shape::ends`]), and it may jump at a station. Time is `∫ dx / √b(x)` in
//!   closed form (`time_to`); from or to rest (b = 0 at an end, ü leading away) it is finite,
//!   as under the linear law.
//! - [`Law::Cubic`] (jerk-limited, issue 11): a' = dü/du linear in u between its values s_0,
//!   s_1 at the interval's ends (a' may jump at a station), so ü is quadratic and b cubic:
//!   `a(x) = a_0 + s_0 x + (s_1 − s_0) x²/(2Δu)`, `b(x) = b_0 + 2 a_0 x + s_0 x² +
//!   (s_1 − s_0) x³/(3Δu)`, with `a_1 − a_0 = Δu (s_0 + s_1)/2` and
//!   `b_1 − b_0 = 2Δu a_0 + Δu² (2 s_0 + s_1)/3`. The path jerk is `u⃛ = a'(x) u̇`. Where the
//!   jerk limit holds a ramp, a' must follow a bound that varies along the interval: a
//!   constant a' (the quadratic law) meets it at one end only and loses time of first order
//!   in Δu there, a linear one of second order. Time is `∫ dx / √b(x)` (adaptive
//!   Gauss–Legendre), and x(τ) its inverse (safeguarded Newton).
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
    /// b linear in u (module doc).
    Linear,
    /// ü linear in u, b quadratic (module doc).
    Quadratic,
    /// a' = dü/du linear in u, ü quadratic, b cubic (module doc).
    Cubic,
    /// From rest at constant path jerk (module doc).
    RestStart,
    /// To rest at constant path jerk (module doc).
    RestEnd,
}

/// An end of a cubic-law interval whose b is below this fraction of b's rise across the
/// interval is integrated over √b rather than u ([`Interval::thin_end`]).
const THIN_END: f64 = 1e-2;

/// One station interval: its length in u, b and ü at both ends, and its law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Length in u.
    pub du: f64,
    /// b at the start.
    pub b0: f64,
    /// b at the end.
    pub b1: f64,
    /// ü at the start.
    pub a0: f64,
    /// ü at the end.
    pub a1: f64,
    /// a' = dü/du just after the start (equal to `s1` under the quadratic law, 0 under the
    /// linear one; unused by the rest laws).
    pub s0: f64,
    /// a' just before the end.
    pub s1: f64,
    /// How u moves in between.
    pub law: Law,
}

/// An [`Interval`] evaluated at non-decreasing times ([`Interval::marcher`]).
#[derive(Debug, Clone, Copy)]
pub struct Marcher<'a> {
    iv: &'a Interval,
    dur: f64,
    /// The last instant's x and τ.
    x: f64,
    t: f64,
}

impl Marcher<'_> {
    /// The motion `tau` after the interval's start, as [`Interval::at`]; `tau` should not
    /// decrease from one call to the next (if it does, the cubic law starts over from the
    /// interval's start).
    pub fn at(&mut self, tau: f64) -> State {
        if self.iv.law != Law::Cubic {
            return self.iv.at(tau, self.dur);
        }
        let tau = tau.clamp(0.0, self.dur);
        if tau < self.t {
            (self.x, self.t) = (0.0, 0.0);
        }
        let x = self.iv.cubic_x_from(self.x, self.t, tau, self.dur);
        (self.x, self.t) = (x, tau);
        self.iv.cubic_state(x)
    }
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

impl State {
    /// An axis's jerk at this instant from its u-derivatives q' (`dq`), q'' (`ddq`) and q'''
    /// (`dddq`): `q⃛ = q''' u̇³ + 3 q'' u̇ ü + q' u⃛` (u̇³ as u̇·b). The one jerk formula of the
    /// re-simulation and the reports.
    pub fn jerk(&self, dq: f64, ddq: f64, dddq: f64) -> f64 {
        dddq * self.ud * self.b + 3.0 * ddq * self.ud * self.udd + dq * self.uddd
    }
}

/// What a profile gives beside b at its stations, which decides each interval's law
/// ([`Interval::of`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Shape<'a> {
    /// ü at every station of a jerk-limited profile (ü continuous).
    pub a: Option<&'a [f64]>,
    /// With `a`: a' = dü/du at both ends of every interval ([`Law::Cubic`]).
    pub slopes: Option<&'a [[f64; 2]]>,
    /// Without `a`: ü at both ends of every interval of an acceleration-limited profile whose ü
    /// is linear between stations ([`crate::constraints::Ramp::Linear`]; [`Law::Quadratic`]).
    pub ends: Option<&'a [[f64; 2]]>,
}

/// Time taken by each interval of a profile (eq. 43 under its law): `b` at the stations `u`
/// and the rest of the profile in `shape`, as in [`Interval::of`]. The one time integration
/// every stage uses (the schedule, the solvers, the re-simulation, the setpoints); an interval
/// the profile cannot traverse (b zero on the whole of it) is [`Error::Infeasible`].
pub fn interval_times(u: &[f64], b: &[f64], shape: Shape) -> Result<Vec<f64>> {
    (0..u.len().saturating_sub(1))
        .map(|k| {
            Interval::of(u, b, shape, k).duration().map_err(|_| {
                Error::Infeasible(format!(
                    "the feed is zero on a whole interval (station {k}): the path cannot be \
                     traversed"
                ))
            })
        })
        .collect()
}

/// The end slopes σ⁰, σ¹ of the cubic law ([`Law::Cubic`]) on an interval of length `du` when
/// b is the Hermite cubic through b and b' = 2ü at both ends: their weights on
/// (b_0, b_1, a_0, a_1), `σ⁰ = 3(b_1 − b_0)/Δu² − (4a_0 + 2a_1)/Δu` and
/// `σ¹ = −3(b_1 − b_0)/Δu² + (2a_0 + 4a_1)/Δu`. (With `b_1 − b_0 = Δu (a_0 + a_1)` both are
/// the quadratic law's `(a_1 − a_0)/Δu`.)
pub fn hermite_slope_weights(du: f64) -> [[f64; 4]; 2] {
    let (d, e) = (3.0 / (du * du), 1.0 / du);
    [[-d, d, -4.0 * e, -2.0 * e], [d, -d, 2.0 * e, 4.0 * e]]
}

impl Interval {
    /// Interval `k` of a profile: `b` at the stations `u`, and in `shape` ü at the stations
    /// for a jerk-limited profile, with `slopes` (a' at both ends of every interval:
    /// [`Law::Cubic`]) or without ([`Law::Quadratic`]; the rest laws from or to b = 0); for an
    /// acceleration-limited profile ü at both ends of every interval ([`Law::Quadratic`]) or
    /// nothing ([`Law::Linear`]). Negative rounding noise in b is clamped to 0.
    pub fn of(u: &[f64], b: &[f64], shape: Shape, k: usize) -> Interval {
        let du = u[k + 1] - u[k];
        let (b0, b1) = (b[k].max(0.0), b[k + 1].max(0.0));
        match (shape.a, shape.ends) {
            (None, None) => {
                let udd = (b1 - b0) / (2.0 * du);
                Interval {
                    du,
                    b0,
                    b1,
                    a0: udd,
                    a1: udd,
                    s0: 0.0,
                    s1: 0.0,
                    law: Law::Linear,
                }
            }
            (None, Some(e)) => {
                // ü⁰ + ü¹ = (b_1 − b_0)/Δu holds for the clamped b as for the solver's: the
                // end ü are taken as given and ü¹ follows from the b actually used.
                let a0 = e[k][0];
                let a1 = (b1 - b0) / du - a0;
                let alpha = (a1 - a0) / du;
                Interval {
                    du,
                    b0,
                    b1,
                    a0,
                    a1,
                    s0: alpha,
                    s1: alpha,
                    // Where the ends' ü are the chord's (most intervals), b is linear: the same
                    // motion, evaluated the cheaper way.
                    law: if alpha == 0.0 {
                        Law::Linear
                    } else {
                        Law::Quadratic
                    },
                }
            }
            (Some(a), _) => {
                let slopes = shape.slopes;
                let law = if b0 == 0.0 && b1 > 0.0 {
                    Law::RestStart
                } else if b1 == 0.0 && b0 > 0.0 {
                    Law::RestEnd
                } else if slopes.is_some() {
                    Law::Cubic
                } else {
                    Law::Quadratic
                };
                let [s0, s1] = match (law, slopes) {
                    (Law::Cubic, Some(s)) => s[k],
                    _ => {
                        let alpha = (a[k + 1] - a[k]) / du;
                        [alpha, alpha]
                    }
                };
                Interval {
                    du,
                    b0,
                    b1,
                    a0: a[k],
                    a1: a[k + 1],
                    s0,
                    s1,
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

    /// ∫_0^x dξ / √b(ξ) under the quadratic law, in closed form. With r = √b and a = ü, the
    /// motion obeys ṙ = a, ȧ = α r, so K = a² − α b is constant along it and:
    ///
    /// - α < 0 (ω = √−α): (a, ω r) turns on a circle of radius √K at rate ω, and the time is the
    ///   angle between the end states over ω (`atan2` of their cross and dot products);
    /// - α > 0 (ω = √α): `a + ω r` grows as e^{ωτ} and `a − ω r` decays as e^{−ωτ}; the time is
    ///   a logarithm of whichever ratio has no cancellation (`a + ωr` where a ≥ 0, `a − ωr`
    ///   where a ≤ 0), the interval split where ü changes sign;
    /// - α = 0: `2x / (√b_0 + √b(x))`.
    ///
    /// Every difference is formed from exact identities (b(x) − b_0 = x (a_0 + a(x))), so the
    /// time keeps full relative precision on short intervals and near a stall.
    fn time_to(&self, x: f64) -> f64 {
        let alpha = (self.a1 - self.a0) / self.du;
        let (a0, r0) = (self.a0, self.b0.max(0.0).sqrt());
        let a1 = a0 + alpha * x;
        let r1 = self.b_at(x).max(0.0).sqrt();
        if alpha > 0.0 && a0 < 0.0 && a1 > 0.0 {
            // ü changes sign inside: to the vertex (a = 0, b minimal) and on from it.
            let xv = -a0 / alpha;
            let rv = self.b_at(xv).max(0.0).sqrt();
            return piece_time(xv, a0, 0.0, r0, rv, alpha)
                + piece_time(x - xv, 0.0, a1, rv, r1, alpha);
        }
        piece_time(x, a0, a1, r0, r1, alpha)
    }

    /// The smallest b on the interval (quadratic law; the vertex if it lies inside).
    #[cfg(test)]
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

    /// Whether the motion under the quadratic law stops on the interval: b reaches 0 inside,
    /// or at an end where ü does not lead away from it (from rest ü⁰ > 0, to rest ü¹ < 0 take
    /// finite time: b is linear in x there, as under the linear law).
    fn quadratic_stalls(&self) -> bool {
        let alpha = (self.a1 - self.a0) / self.du;
        let xv = if alpha > 0.0 { -self.a0 / alpha } else { -1.0 };
        (xv > 0.0 && xv < self.du && self.b_at(xv) <= 0.0)
            || (self.b0 <= 0.0 && self.a0 <= 0.0)
            || (self.b1 <= 0.0 && self.a1 >= 0.0)
            || (self.b0 <= 0.0 && self.b1 <= 0.0)
    }

    /// b at x (cubic law).
    fn cubic_b(&self, x: f64) -> f64 {
        let d = (self.s1 - self.s0) / self.du;
        self.b0 + x * (2.0 * self.a0 + x * (self.s0 + x * d / 3.0))
    }

    /// ü at x (cubic law).
    fn cubic_a(&self, x: f64) -> f64 {
        let d = (self.s1 - self.s0) / self.du;
        self.a0 + x * (self.s0 + 0.5 * x * d)
    }

    /// a' at x (cubic law).
    fn cubic_slope(&self, x: f64) -> f64 {
        self.s0 + (self.s1 - self.s0) * x / self.du
    }

    /// The smallest b on the interval (cubic law): the ends, and where ü = 0 inside.
    fn cubic_b_min(&self) -> f64 {
        let mut m = self.b0.min(self.b1);
        // ü(x) = a0 + s0 x + (d/2) x² = 0.
        let (qa, qb, qc) = (0.5 * (self.s1 - self.s0) / self.du, self.s0, self.a0);
        let mut roots = [f64::NAN; 2];
        if qa.abs() <= 1e-300 {
            if qb != 0.0 {
                roots[0] = -qc / qb;
            }
        } else {
            let disc = qb * qb - 4.0 * qa * qc;
            if disc >= 0.0 {
                let q = -0.5 * (qb + qb.signum() * disc.sqrt());
                roots = [q / qa, if q != 0.0 { qc / q } else { f64::NAN }];
            }
        }
        for x in roots {
            if x > 0.0 && x < self.du {
                m = m.min(self.cubic_b(x));
            }
        }
        m
    }

    /// ∫_p^q dξ / √b(ξ) under the cubic law: the 15-point Gauss–Kronrod rule, whose embedded
    /// 7-point Gauss rule estimates its error; halved until that estimate is within 1e-13
    /// (relative) of the whole (the integrand is analytic where b > 0). 15 evaluations a
    /// panel, where 8-point Gauss–Legendre checked against its two halves took 24; the time
    /// integrals are 5–9 % of a jerk-limited solve (SCP steps and the re-simulation's servo
    /// instants).
    ///
    /// On a panel shorter than an eighth of the interval, first the 7-point Gauss–Kronrod rule
    /// with its embedded 3-point Gauss rule: where they agree within the same 1e-13, the
    /// 7-point value is taken (its error is far below the 3-point rule's, which the difference
    /// estimates). A servo instant's panel, a millisecond of motion over which b barely
    /// changes, passes so with 7 evaluations instead of 15 (91 % of them on COPP path 3 with
    /// jerk limits). An interval's whole time, where b changes more, mostly failed the check:
    /// it takes the rule above directly.
    fn cubic_time(&self, p: f64, q: f64) -> f64 {
        // The 7-point Kronrod nodes but the centre (±XK7[1] = ±√(3/5) and 0 are the 3-point
        // Gauss nodes) and weights, and the Gauss weights 5/9 and 8/9.
        const XK7: [f64; 3] = [
            0.960_491_268_708_020_3,
            0.774_596_669_241_483_4,
            0.434_243_749_346_802_6,
        ];
        const WK7: [f64; 4] = [
            0.104_656_226_026_467_27,
            0.268_488_089_868_333_44,
            0.401_397_414_775_962_2,
            0.450_916_538_658_474_14,
        ];
        const WG3: [f64; 2] = [5.0 / 9.0, 8.0 / 9.0];
        // Nodes and weights of QUADPACK's qk15: the Kronrod nodes but the centre (the odd ones,
        // 1, 3, 5, and the centre are the 7-point Gauss nodes) and weights, and the Gauss
        // weights (each rule's centre weight last).
        const XK: [f64; 7] = [
            0.991_455_371_120_812_6,
            0.949_107_912_342_758_5,
            0.864_864_423_359_769_1,
            0.741_531_185_599_394_4,
            0.586_087_235_467_691_1,
            0.405_845_151_377_397_2,
            0.207_784_955_007_898_5,
        ];
        const WK: [f64; 8] = [
            0.022_935_322_010_529_22,
            0.063_092_092_629_978_55,
            0.104_790_010_322_250_2,
            0.140_653_259_715_525_9,
            0.169_004_726_639_267_9,
            0.190_350_578_064_785_4,
            0.204_432_940_075_298_9,
            0.209_482_141_084_727_8,
        ];
        const WG: [f64; 4] = [
            0.129_484_966_168_869_7,
            0.279_705_391_489_276_7,
            0.381_830_050_505_118_9,
            0.417_959_183_673_469_4,
        ];
        /// (Kronrod's value, |Kronrod − Gauss|) on [p, q] of a Gauss–Kronrod pair: the Kronrod
        /// nodes `xk` but the centre, whose odd ones are the Gauss nodes, and the weights `wk`,
        /// `wg`, each rule's centre weight last.
        fn pair(
            f: &impl Fn(f64) -> f64,
            p: f64,
            q: f64,
            xk: &[f64],
            wk: &[f64],
            wg: &[f64],
        ) -> (f64, f64) {
            let (c, h) = (0.5 * (p + q), 0.5 * (q - p));
            let centre = f(c);
            let (mut k, mut g) = (wk[xk.len()] * centre, wg[xk.len() / 2] * centre);
            for (j, x) in xk.iter().enumerate() {
                let pair = f(c - h * x) + f(c + h * x);
                k += wk[j] * pair;
                if j % 2 == 1 {
                    g += wg[j / 2] * pair;
                }
            }
            (h * k, (h * (k - g)).abs())
        }
        /// The 15-point pair.
        fn gk(f: &impl Fn(f64) -> f64, p: f64, q: f64) -> (f64, f64) {
            pair(f, p, q, &XK, &WK, &WG)
        }
        // `tol`: absolute, split between the halves, so the total error stays within the
        // whole's; `budget`: panels left, so a sharp peak of 1/√b (b nearly 0 inside) cannot
        // make the recursion exponential.
        // `(k, err)`: gk on [p, q].
        fn adapt(
            f: &impl Fn(f64) -> f64,
            p: f64,
            q: f64,
            (k, err): (f64, f64),
            tol: f64,
            budget: &mut u32,
        ) -> f64 {
            if *budget == 0 || err <= tol {
                return k;
            }
            *budget -= 1;
            let m = 0.5 * (p + q);
            adapt(f, p, m, gk(f, p, m), 0.5 * tol, budget)
                + adapt(f, m, q, gk(f, m, q), 0.5 * tol, budget)
        }
        /// ∫_p^q f: the 7-point pair first on a `short` panel, then the adaptive 15-point one.
        fn integral(f: &impl Fn(f64) -> f64, p: f64, q: f64, short: bool) -> f64 {
            if short {
                let (k, err) = pair(f, p, q, &XK7, &WK7, &WG3);
                if err <= 1e-13 * k.abs() {
                    return k;
                }
            }
            let whole = gk(f, p, q);
            let mut budget = 4096;
            adapt(f, p, q, whole, 1e-13 * whole.0.abs(), &mut budget)
        }
        if q <= p {
            return 0.0;
        }
        let short = q - p < 0.125 * self.du;
        if let Some((at_start, k, b_end)) = self.thin_end() {
            // s: the distance from the thin end; r = √(b_e + k s), s = (r² − b_e)/k, and
            // dx/√b = (2r/k) dr/√b with b = r² + c₂ s² + c₃ s³ (b's expansion about that
            // end, b''/2 = a' there and b'''/6 = ±(a'₁ − a'₀)/(3Δu)): smooth in r, and b
            // without the cancellation of the other end's expansion, whose terms are
            // thousands of times b_e there.
            let cubic = (self.s1 - self.s0) / (3.0 * self.du);
            let (sp, sq, c2, c3) = if at_start {
                (p, q, self.s0, cubic)
            } else {
                (self.du - q, self.du - p, self.s1, -cubic)
            };
            let r = |s: f64| (b_end + k * s).sqrt();
            let g = |r: f64| {
                let r2 = r * r;
                let s = ((r2 - b_end) / k).clamp(0.0, self.du);
                let b = r2 + s * s * (c2 + c3 * s);
                2.0 * r / (k * b.max(f64::MIN_POSITIVE).sqrt())
            };
            return integral(&g, r(sp), r(sq), short);
        }
        let f = |x: f64| 1.0 / self.cubic_b(x).max(f64::MIN_POSITIVE).sqrt();
        integral(&f, p, q, short)
    }

    /// An end of a cubic-law interval where b nearly vanishes, b_e ≤ [`THIN_END`] · k Δu with
    /// k > 0 the slope of b away from it (2ü at the start, −2ü at the end): whether it is the
    /// start, k and b_e. There 1/√b has a square-root singularity just outside the interval
    /// (b ≈ b_e + k s at a distance s from that end), which the plain rule resolves only by
    /// thousands of halvings; [`Interval::cubic_time`] then integrates over r = √(b_e + k s)
    /// instead, in which the integrand is smooth. (On COPP path 10 with jerk limits, twelve
    /// intervals next to the rest end, b_e ≈ 1e-10 and k Δu ≈ 2e-3, each exhausted the
    /// halvings' budget, 8,192 pairs of rules: 42 % of all the time integrals' work.)
    fn thin_end(&self) -> Option<(bool, f64, f64)> {
        let (k0, k1) = (2.0 * self.a0, -2.0 * self.a1);
        if k0 > 0.0 && self.b0 <= THIN_END * k0 * self.du {
            Some((true, k0, self.b0))
        } else if k1 > 0.0 && self.b1 <= THIN_END * k1 * self.du {
            Some((false, k1, self.b1))
        } else {
            None
        }
    }

    /// The motion at x under the cubic law.
    fn cubic_state(&self, x: f64) -> State {
        let b = self.cubic_b(x).max(0.0);
        let ud = b.sqrt();
        State {
            x,
            ud,
            b,
            udd: self.cubic_a(x),
            uddd: self.cubic_slope(x) * ud,
        }
    }

    /// x reached τ after the start (cubic law), given that x0 is reached at t0 ≤ τ: the root of
    /// `T(x) = τ`, T increasing with T' = 1/√b, by Newton's method kept inside a shrinking
    /// bracket [x0, Δu] (bisection where a step would leave it), each T(x) the last one plus
    /// the integral over the step.
    fn cubic_x_from(&self, x0: f64, t0: f64, tau: f64, dur: f64) -> f64 {
        if tau <= t0 {
            return x0;
        }
        if tau >= dur {
            return self.du;
        }
        let (mut lo, mut hi) = (x0, self.du);
        // A first guess from the motion at x0: x ≈ x0 + u̇ dτ + ü dτ²/2 + u⃛ dτ³/6.
        let dt = tau - t0;
        let (b0, a0) = (self.cubic_b(x0).max(0.0), self.cubic_a(x0));
        let ud0 = b0.sqrt();
        let jerk0 = self.cubic_slope(x0) * ud0;
        let guess = x0 + ud0 * dt + 0.5 * a0 * dt * dt + jerk0 * dt * dt * dt / 6.0;
        let mut x = guess.clamp(x0, self.du);
        let mut t = t0 + self.cubic_time(x0, x);
        for _ in 0..100 {
            let err = t - tau;
            if err > 0.0 {
                hi = x;
            } else {
                lo = x;
            }
            if err.abs() <= 1e-14 * dur || hi - lo <= 1e-15 * self.du {
                break;
            }
            let ud = self.cubic_b(x).max(0.0).sqrt();
            let mut next = x - err * ud;
            // Newton's step leaves T(next) − τ ≈ ½ T'' (next − x)² = −ü err² / (2 u̇) (T' =
            // 1/u̇, T'' = −ü/u̇³): where that is within the tolerance, next is the answer, and
            // the integral to it is not needed (COPP paths 3 and 10 with jerk limits:
            // 1.1 quadratures a servo instant instead of 2.7).
            if next > lo
                && next < hi
                && ud > 0.0
                && self.cubic_a(x).abs() * err * err <= 2e-15 * dur * ud
            {
                return next;
            }
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            t += if next > x {
                self.cubic_time(x, next)
            } else {
                -self.cubic_time(next, x)
            };
            x = next;
        }
        x
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
                if self.quadratic_stalls() {
                    return stall();
                }
                self.time_to(self.du)
            }
            Law::Cubic => {
                if self.cubic_b_min() <= 0.0 {
                    return stall();
                }
                self.cubic_time(0.0, self.du)
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
            Law::Cubic => self.cubic_state(self.cubic_x_from(0.0, 0.0, tau, dur)),
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

    /// An evaluator of this interval at non-decreasing times (a re-simulation's servo
    /// instants): under the cubic law each instant's x(τ) continues from the last one, so it
    /// costs the integral over one period, not over the interval so far.
    pub fn marcher(&self, dur: f64) -> Marcher<'_> {
        Marcher {
            iv: self,
            dur,
            x: 0.0,
            t: 0.0,
        }
    }

    /// b and ü where u − u_0 = `x` (0 ≤ x ≤ Δu): the profile as a function of u.
    pub fn at_x(&self, x: f64) -> (f64, f64) {
        let x = x.clamp(0.0, self.du);
        match self.law {
            Law::Cubic => (self.cubic_b(x).max(0.0), self.cubic_a(x)),
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

    /// a' = dü/du where u − u_0 = `x`, just inside the interval (0 under the linear law; the
    /// rest laws' own, `2 b_far/(9Δu²)` at the far end).
    pub fn slope_at_x(&self, x: f64) -> f64 {
        let x = x.clamp(0.0, self.du);
        match self.law {
            Law::Linear => 0.0,
            Law::Quadratic => (self.a1 - self.a0) / self.du,
            Law::Cubic => self.cubic_slope(x),
            // x = Δu s³: ü = (2/3) s b₁/Δu, so a' = dü/du = (2/9) b₁/(Δu² s²).
            Law::RestStart => {
                let s = (x / self.du).cbrt().max(1e-300);
                2.0 * self.b1 / (9.0 * self.du * self.du * s * s)
            }
            Law::RestEnd => {
                let s = ((self.du - x) / self.du).cbrt().max(1e-300);
                2.0 * self.b0 / (9.0 * self.du * self.du * s * s)
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
            Law::Cubic => self.cubic_time(0.0, x).min(dur),
            Law::RestStart => dur * (x / self.du).cbrt(),
            Law::RestEnd => dur * (1.0 - ((self.du - x) / self.du).cbrt()),
        })
    }

    /// The motion at the interval's start (τ = 0) and end (τ = duration), exactly.
    pub fn ends(&self) -> (State, State) {
        let (g0, g1) = match self.law {
            Law::Quadratic => {
                let alpha = (self.a1 - self.a0) / self.du;
                (alpha, alpha)
            }
            Law::Cubic => (self.s0, self.s1),
            _ => (0.0, 0.0),
        };
        let state = |b: f64, a: f64, x: f64, g: f64| {
            let ud = b.sqrt();
            State {
                x,
                ud,
                b,
                udd: a,
                uddd: g * ud,
            }
        };
        let (mut s0, mut s1) = (
            state(self.b0, self.a0, 0.0, g0),
            state(self.b1, self.a1, self.du, g1),
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
            // C = τ² Σ z^k/(2k+2)!, S = τ Σ z^k/(2k+1)!: 13 terms reach 1e-17 at |z| = 0.5;
            // the sums stop where the next terms no longer change them (after two to four on
            // the short intervals of an acceleration-limited profile, where |z| ~ 1e-6).
            let (mut c, mut s) = (0.0, 0.0);
            let (mut tc, mut ts) = (0.5, 1.0);
            for k in 0..13 {
                c += tc;
                s += ts;
                let m = (2 * k + 2) as f64;
                ts *= z / (m * (m + 1.0));
                tc *= z / ((m + 1.0) * (m + 2.0));
                if ts.abs() <= 1e-17 * s.abs() && tc.abs() <= 1e-17 * c.abs() {
                    break;
                }
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

/// The time over `dx` of a quadratic-law piece from (ü, √b) = (a0, r0) to (a1, r1), with
/// ü' = α and, where α > 0, no sign change of ü inside (see [`Interval::time_to`]).
fn piece_time(dx: f64, a0: f64, a1: f64, r0: f64, r1: f64, alpha: f64) -> f64 {
    if dx <= 0.0 {
        return 0.0;
    }
    let rs = r0 + r1;
    if alpha == 0.0 || rs <= 0.0 {
        return 2.0 * dx / rs;
    }
    // (r1 − r0) = (b1 − b0)/(r0 + r1) = dx (a0 + a1)/(r0 + r1).
    let dr = dx * (a0 + a1) / rs;
    if alpha < 0.0 {
        let w = (-alpha).sqrt();
        // cross = ω (a0 r1 − a1 r0), with a1 = a0 + α dx: ω [a0 (r1 − r0) − α dx r0].
        let cross = w * (a0 * dr - alpha * dx * r0);
        let dot = a0 * a1 + w * w * r0 * r1;
        return cross.atan2(dot) / w;
    }
    let w = alpha.sqrt();
    if a0 >= 0.0 {
        // e^{ωτ} = (a1 + ω r1)/(a0 + ω r0) = 1 + (α dx + ω dr)/(a0 + ω r0).
        (((alpha * dx + w * dr) / (a0 + w * r0)).ln_1p()) / w
    } else {
        // e^{ωτ} = (a0 − ω r0)/(a1 − ω r1) = 1 + (α dx − ω dr)/(ω r1 − a1), a1 ≤ 0.
        (((alpha * dx - w * dr) / (w * r1 - a1)).ln_1p()) / w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Under the linear-ü law an interval may start or end at rest (b = 0) with ü leading away
    /// from it: its time is finite, the integral of 1/√b from the rest end, where b is linear
    /// in x to first order. Checked against the constant-ü closed form (ü⁰ = ü¹) and, with ü
    /// changing, against Gauss–Legendre on x = Δu s² (which takes the rest end's 1/√x away).
    #[test]
    fn the_quadratic_law_leaves_and_reaches_rest_in_finite_time() {
        let du = 0.3;
        let same = quad(0.0, 5.0, 5.0, du);
        assert!((same.duration().unwrap() - (2.0 * du / 5.0).sqrt()).abs() < 1e-14);
        for (a0, a1) in [(5.0, 1.0), (1.0, 5.0), (5.0, -2.0)] {
            let iv = quad(0.0, a0, a1, du);
            let (x, w) = gauss_legendre_32();
            let numeric: f64 = x
                .iter()
                .zip(&w)
                .map(|(&x, &w)| {
                    let s = 0.5 * (x + 1.0);
                    let u = du * s * s;
                    0.5 * w * 2.0 * du * s / iv.b_at(u).sqrt()
                })
                .sum();
            let t = iv.duration().unwrap();
            assert!(
                (t - numeric).abs() < 1e-10 * t,
                "{a0} {a1}: {t} vs {numeric}"
            );
            // The same interval run backwards, to rest: the same time.
            let back = Interval {
                b0: iv.b1,
                b1: 0.0,
                a0: -a1,
                a1: -a0,
                ..iv
            };
            assert!((back.duration().unwrap() - t).abs() < 1e-12 * t);
        }
        // Leaving rest with ü = 0, or b = 0 at both ends, is no motion.
        assert!(quad(0.0, 0.0, 4.0, du).duration().is_err());
    }

    /// Nodes and weights of 32-point Gauss–Legendre on [−1, 1] (Golub–Welsch would need a
    /// matrix; Newton on P_32 is enough for a test).
    fn gauss_legendre_32() -> (Vec<f64>, Vec<f64>) {
        let n = 32;
        let (mut x, mut w) = (Vec::new(), Vec::new());
        for i in 1..=n {
            let mut z = (std::f64::consts::PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, z);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                let dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
                let dz = p1 / dp;
                z -= dz;
                if dz.abs() < 1e-16 {
                    // P' at the root: the last step moved z by less than 1e-16.
                    x.push(z);
                    w.push(2.0 / ((1.0 - z * z) * dp * dp));
                    break;
                }
            }
        }
        (x, w)
    }

    fn quad(b0: f64, a0: f64, a1: f64, du: f64) -> Interval {
        Interval {
            du,
            b0,
            b1: b0 + du * (a0 + a1),
            a0,
            a1,
            s0: (a1 - a0) / du,
            s1: (a1 - a0) / du,
            law: Law::Quadratic,
        }
    }

    /// Durations against ∫ dx/√b by mpmath's adaptive quadrature at 40 digits (split at the
    /// vertex): near a stall (b from 1e-4, its zero 1 % of the interval away — a 4-panel
    /// Gauss–Legendre rule was 9e-5 off here), through a vertex of b with α > 0 (ü changes
    /// sign), through a maximum of b (α < 0), and decelerating.
    #[test]
    fn quadratic_durations_match_high_precision_quadrature() {
        for (iv, reference) in [
            (quad(1e-4, 0.5, -0.4, 0.01), 0.241_130_433_482_887_64),
            (quad(1e-3, -0.09, 0.1, 0.01), 0.374_319_852_382_043_94),
            (quad(0.5, 0.02, -0.4, 1.0), 1.701_925_656_158_549_2),
            (quad(2.0, -0.5, -0.1, 1.0), 0.785_774_677_376_744_4),
        ] {
            let t = iv.duration().unwrap();
            assert!(
                (t - reference).abs() < 1e-14 * reference,
                "{iv:?}: {t} vs {reference}"
            );
        }
    }

    /// Pseudo-random numbers in [0, 1) from `seed` (xorshift).
    fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Two independent closed forms agree on 2,000 pseudo-random intervals (every sign of α
    /// and ü, b varying up to a thousandfold): the time to x (invariant a² − αb) and the
    /// position at τ (the linear ODE ẍ = a_0 + αx).
    #[test]
    fn time_and_position_closed_forms_agree() {
        let mut next = uniform(0x2545_f491_4f6c_dd1du64);
        let mut checked = 0;
        while checked < 2000 {
            let du = 10f64.powf(-3.0 + 3.0 * next());
            let b0 = 10f64.powf(-3.0 + 4.0 * next());
            let scale = b0 / du;
            let (a0, a1) = (scale * (2.0 * next() - 1.0), scale * (2.0 * next() - 1.0));
            let iv = quad(b0, a0, a1, du);
            if iv.b_min() <= 1e-3 * b0 || iv.b1 <= 0.0 {
                continue;
            }
            let dur = iv.duration().unwrap();
            for k in 1..8 {
                let tau = dur * k as f64 / 8.0;
                let x = iv.x_at(tau, dur);
                assert!((iv.time_to(x) - tau).abs() < 1e-11 * dur, "{iv:?} at {tau}");
            }
            checked += 1;
        }
    }

    #[test]
    fn quadratic_time_matches_the_closed_form() {
        // α > 0: ∫ dx/√(αx² + βx + γ) = ln(2√α √b + 2αx + β)/√α; b varying by 2× and 1.4×.
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
            s0: 0.0,
            s1: 0.0,
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
            s0: 0.0,
            s1: 0.0,
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
        let flat = Interval::of(&[0.0, 1.0], &[0.0, 0.0], Default::default(), 0);
        assert!(flat.duration().is_err());
    }

    #[test]
    fn the_law_and_its_inverse_agree() {
        let iv = Interval::of(&[1.0, 3.0], &[4.0, 9.0], Default::default(), 0);
        // Δt = 2·2/(2+3) = 0.8 s; ü = 5/4.
        let dur = iv.duration().unwrap();
        assert!((dur - 0.8).abs() < 1e-15);
        for k in 0..=8 {
            let tau = 0.1 * k as f64;
            let st = iv.at(tau, dur);
            assert!((st.ud - (2.0 + 1.25 * tau).min(3.0)).abs() < 1e-12);
            assert!((iv.time_to_x(st.x).unwrap() - tau).abs() < 1e-12, "{tau}");
        }
        // From rest: u = ½ ü τ².
        let rest = Interval::of(&[0.0, 2.0], &[0.0, 16.0], Default::default(), 0);
        let st = rest.at(0.5, rest.duration().unwrap());
        assert!((st.udd - 4.0).abs() < 1e-15 && (st.x - 0.5).abs() < 1e-15);
        assert!((rest.time_to_x(0.5).unwrap() - 0.5).abs() < 1e-15);
    }

    /// A cubic-law interval from b₀, ü₀ and the end slopes: b₁, ü₁ by the law's identities.
    fn cubic(b0: f64, a0: f64, s0: f64, s1: f64, du: f64) -> Interval {
        Interval {
            du,
            b0,
            b1: b0 + 2.0 * du * a0 + du * du * (2.0 * s0 + s1) / 3.0,
            a0,
            a1: a0 + 0.5 * du * (s0 + s1),
            s0,
            s1,
            law: Law::Cubic,
        }
    }

    /// With equal end slopes the cubic law is the quadratic one: the same durations and
    /// states from two independent computations (closed forms against quadrature and Newton).
    #[test]
    fn cubic_with_equal_slopes_is_the_quadratic_law() {
        for (b0, a0, a1, du) in [
            (4.0, 1.0, 3.0, 0.5),
            (9.0, -2.0, 1.0, 0.7),
            (1.0, 0.5, -1.5, 0.3),
        ] {
            let q = quad(b0, a0, a1, du);
            let alpha = (a1 - a0) / du;
            let c = cubic(b0, a0, alpha, alpha, du);
            assert!((c.b1 - q.b1).abs() < 1e-12 && (c.a1 - q.a1).abs() < 1e-12);
            let (dq, dc) = (q.duration().unwrap(), c.duration().unwrap());
            assert!((dq - dc).abs() < 1e-12 * dq, "{dq} vs {dc}");
            for f in [0.1, 0.37, 0.5, 0.9] {
                let (sq, sc) = (q.at(f * dq, dq), c.at(f * dq, dq));
                assert!((sq.x - sc.x).abs() < 1e-11 * du, "{sq:?} {sc:?}");
                assert!((sq.b - sc.b).abs() < 1e-10 && (sq.udd - sc.udd).abs() < 1e-10);
                assert!((sq.uddd - sc.uddd).abs() < 1e-9);
            }
        }
    }

    /// The cubic law against its definition: the duration against composite Simpson on 20,000
    /// panels, x(τ) inverting the time, db/dx = 2ü and dü/dx = a' by differences, u⃛ = a' u̇,
    /// and the ends' states.
    #[test]
    fn cubic_law_agrees_with_its_definition() {
        for (b0, a0, s0, s1, du) in [
            (4.0, 1.0, 6.0, -2.0, 0.5),
            (2.0, -1.5, 1.0, 8.0, 0.6),
            (0.05, 0.0, 3.0, -1.0, 0.4),
        ] {
            let iv = cubic(b0, a0, s0, s1, du);
            let n = 20_000;
            let h = du / n as f64;
            let f = |x: f64| 1.0 / iv.cubic_b(x).sqrt();
            let simpson: f64 = (0..n)
                .map(|k| {
                    let x = k as f64 * h;
                    h / 6.0 * (f(x) + 4.0 * f(x + 0.5 * h) + f(x + h))
                })
                .sum();
            let dur = iv.duration().unwrap();
            assert!((dur - simpson).abs() < 1e-10 * dur, "{dur} vs {simpson}");
            for frac in [0.05, 0.3, 0.5, 0.77, 0.99] {
                let st = iv.at(frac * dur, dur);
                let back = iv.time_to_x(st.x).unwrap();
                assert!(
                    (back - frac * dur).abs() < 1e-11 * dur,
                    "{back} vs {}",
                    frac * dur
                );
                let e = 1e-6;
                let (bp, ap) = iv.at_x(st.x + e);
                let (bm, am) = iv.at_x(st.x - e);
                assert!(((bp - bm) / (2.0 * e) - 2.0 * st.udd).abs() < 1e-6);
                let slope = iv.slope_at_x(st.x);
                assert!(((ap - am) / (2.0 * e) - slope).abs() < 1e-6);
                assert!((st.uddd - slope * st.ud).abs() < 1e-12 * (1.0 + st.uddd.abs()));
            }
            let (e0, e1) = iv.ends();
            assert!((e0.uddd - s0 * b0.sqrt()).abs() < 1e-12);
            assert!((e1.uddd - s1 * iv.b1.sqrt()).abs() < 1e-12);
            let end = iv.at(dur, dur);
            assert!((end.b - iv.b1).abs() < 1e-12 && (end.udd - iv.a1).abs() < 1e-12);
        }
    }

    /// The marcher (x continued from the last instant) and `at` (x from the interval's start)
    /// agree at every servo instant, and a step back in time starts over.
    #[test]
    fn marching_agrees_with_evaluating_from_the_start() {
        for (b0, a0, s0, s1, du) in [
            (4.0, 1.0, 6.0, -2.0, 0.5),
            (2.0, -1.5, 1.0, 8.0, 0.6),
            (0.05, 0.0, 3.0, -1.0, 0.4),
        ] {
            let iv = cubic(b0, a0, s0, s1, du);
            let dur = iv.duration().unwrap();
            let mut m = iv.marcher(dur);
            let n = 997;
            for k in 0..=n {
                let tau = dur * k as f64 / n as f64;
                let (a, b) = (m.at(tau), iv.at(tau, dur));
                assert!((a.x - b.x).abs() <= 1e-12 * du, "{k}: {} vs {}", a.x, b.x);
                assert!((a.b - b.b).abs() <= 1e-11 * (1.0 + b.b), "{k}");
            }
            let back = m.at(0.3 * dur);
            assert!((back.x - iv.at(0.3 * dur, dur).x).abs() <= 1e-12 * du);
        }
    }

    /// An end where b nearly vanishes (b_e ≪ k Δu, [`Interval::thin_end`]): the time against
    /// the closed form 2(√(b_e + kΔu) − √b_e)/k where b is linear, and against composite
    /// Simpson on panels graded towards that end (each 1.02 times the last, 8 Simpson steps
    /// apiece) where it is cubic; the whole interval and parts of it, at either end (the same
    /// interval mirrored).
    #[test]
    fn times_near_a_thin_end_match_closed_forms_and_graded_simpson() {
        let mirror = |iv: &Interval| Interval {
            b0: iv.b1,
            b1: iv.b0,
            a0: -iv.a1,
            a1: -iv.a0,
            s0: iv.s1,
            s1: iv.s0,
            ..*iv
        };
        // Composite Simpson of 1/√b over [p, q], panels graded from the thin start x = 0.
        let graded = |iv: &Interval, p: f64, q: f64| {
            let f = |x: f64| 1.0 / iv.cubic_b(x).sqrt();
            let mut cuts = vec![iv.du];
            while *cuts.last().unwrap() > 1e-18 * iv.du {
                cuts.push(cuts.last().unwrap() / 1.02);
            }
            cuts.push(0.0);
            cuts.reverse();
            let mut sum = 0.0;
            for w in cuts.windows(2) {
                let (a, b) = (w[0].max(p), w[1].min(q));
                if b <= a {
                    continue;
                }
                let h = (b - a) / 8.0;
                for k in 0..8 {
                    let x = a + k as f64 * h;
                    sum += h / 6.0 * (f(x) + 4.0 * f(x + 0.5 * h) + f(x + h));
                }
            }
            sum
        };
        for b0 in [0.0, 1e-14, 1e-10, 1e-6] {
            for (k, du) in [(10.5, 1.9e-4), (2.0, 1.0), (0.3, 0.05)] {
                // b linear: ü constant, a' = 0.
                let lin = cubic(b0, 0.5 * k, 0.0, 0.0, du);
                assert!(lin.thin_end().is_some(), "{b0} {k} {du}");
                let exact = 2.0 * ((b0 + k * du).sqrt() - b0.sqrt()) / k;
                for iv in [lin, mirror(&lin)] {
                    let t = iv.cubic_time(0.0, du);
                    assert!((t - exact).abs() <= 1e-13 * exact, "{iv:?}: {t} vs {exact}");
                }
                let (p, q) = (0.1 * du, 0.35 * du);
                let part = 2.0 * ((b0 + k * q).sqrt() - (b0 + k * p).sqrt()) / k;
                let t = mirror(&lin).cubic_time(du - q, du - p);
                assert!((t - part).abs() <= 1e-13 * part, "{t} vs {part}");
                // b cubic: a' changing across the interval, b staying positive.
                for (s0, s1) in [(3.0 * k / du, -k / du), (-0.5 * k / du, 2.0 * k / du)] {
                    let iv = cubic(b0, 0.5 * k, s0, s1, du);
                    if iv.cubic_b_min() < b0 || iv.b1 <= 0.0 {
                        continue;
                    }
                    for (p, q) in [(0.0, du), (0.0, 1e-3 * du), (0.2 * du, 0.9 * du)] {
                        let reference = graded(&iv, p, q);
                        for (t, what) in [
                            (iv.cubic_time(p, q), "start"),
                            (mirror(&iv).cubic_time(du - q, du - p), "end"),
                        ] {
                            assert!(
                                (t - reference).abs() <= 1e-10 * reference,
                                "{what} {iv:?} on [{p}, {q}]: {t} vs {reference}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// The time over a panel, short (a servo instant's: the 7-point rule) or the whole
    /// interval (where that rule's check fails and the adaptive 15-point rule answers), against
    /// composite Simpson on 20,000 sub-panels (error of order 1e-17 here), on 300 pseudo-random
    /// cubic intervals whose b stays above a hundredth of its largest value.
    #[test]
    fn panel_times_match_composite_simpson() {
        let mut next = uniform(0x9e37_79b9_7f4a_7c15u64);
        let (mut checked, mut short) = (0, 0);
        while checked < 300 {
            let du = 10f64.powf(-3.0 + 3.0 * next());
            let b0 = 10f64.powf(-2.0 + 4.0 * next());
            let scale = b0 / du;
            let iv = cubic(
                b0,
                scale * (next() - 0.5),
                scale / du * (2.0 * next() - 1.0),
                scale / du * (2.0 * next() - 1.0),
                du,
            );
            let (lo, hi) = (iv.cubic_b_min(), iv.b0.max(iv.b1));
            if lo <= 1e-2 * hi {
                continue;
            }
            let p = du * next();
            let len = du * 10f64.powf(-4.0 * next());
            let q = (p + len).min(du);
            for (p, q) in [(p, q), (0.0, du)] {
                let n = 20_000;
                let h = (q - p) / n as f64;
                let f = |x: f64| 1.0 / iv.cubic_b(x).sqrt();
                let simpson: f64 = (0..n)
                    .map(|k| {
                        let x = p + k as f64 * h;
                        h / 6.0 * (f(x) + 4.0 * f(x + 0.5 * h) + f(x + h))
                    })
                    .sum();
                let t = iv.cubic_time(p, q);
                assert!(
                    (t - simpson).abs() <= 2e-13 * simpson,
                    "{iv:?} on [{p}, {q}]: {t} vs {simpson}"
                );
            }
            short += usize::from(q - p < 1e-2 * du);
            checked += 1;
        }
        assert!(short > 50, "only {short} short panels");
    }

    /// A cubic whose b reaches 0 inside the interval stalls.
    #[test]
    fn cubic_stall_is_an_error() {
        // b(x) = 1 − 2x + x² − …: ü < 0 pulls b to 0 near x = 1.
        let iv = cubic(1.0, -1.0, 1.0, 1.0, 2.0);
        assert!(iv.cubic_b_min() <= 1e-12);
        assert!(iv.duration().is_err());
    }
}
