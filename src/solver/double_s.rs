//! Straight moves from rest to rest in closed form: the double-S profile.
//!
//! Along a span on which every axis moves in proportion to the others (q = q₀ + d·u: a straight
//! line in joint space, as every `G0`/`G1` block between exact stops on a three-axis machine
//! is, and a five-axis one whose rotary axes stand still), with the same limits everywhere,
//! each axis's velocity, acceleration and jerk are d_j u̇, d_j ü and d_j u⃛. The axis limits
//! are then three bounds on the path alone, `u̇ ≤ V`, `|ü| ≤ A`, `|u⃛| ≤ J` (V from the
//! tightest velocity bound and feed cap, A and J the tightest over the moving axes), and the
//! time-optimal motion from rest to rest over the length L is the double-S (seven-segment)
//! profile: jerk +J, 0, −J (accelerating to the peak speed), a cruise, then −J, 0, +J (Biagiotti
//! & Melchiorri, *Trajectory Planning for Automatic Machines and Robots*, 2008, §3.4, with
//! v₀ = v₁ = 0). A jerk-limited solve takes it instead of the sequential convex programme: a
//! drilling program of 500 holes (1,501 such spans) took 102 s through the programme and 184 k
//! stations, and its profile was still an approximation of this one.
//!
//! **Stations and laws** ([`crate::motion`]). The profile is handed on at stations where its
//! phases meet, so that every phase but the two −J ones is one of the motion laws exactly: the
//! first and last intervals are the constant-jerk laws from and to rest
//! ([`crate::motion::Law::RestStart`], `RestEnd`: their relation ü₁ = 2b₁/(3Δu) holds at the end
//! of the +J phase), and under constant acceleration and at cruise b is linear in u, which the
//! cubic law with Hermite slopes reproduces. Inside a −J phase a' = u⃛/u̇ = −J/√b is not linear
//! in u; the phase is cut into equal times, as many as it takes ([`profile_stations`]) for the
//! cubic law to keep the time within [`TIME_TOLERANCE`] of the profile's and the jerk within
//! [`JERK_TOLERANCE`] of J (the re-simulation checks every limit at the servo period after).

use super::{SpanSolution, Status};
use crate::constraints::SpanProblem;
use crate::machine::Machine;
use crate::motion::{Interval, Shape, hermite_slope_weights};

/// The path's limits along a straight span: u̇ ≤ `v`, |ü| ≤ `a`, |u⃛| ≤ `j`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathLimits {
    /// The largest u̇ (the tightest velocity bound or feed cap).
    pub v: f64,
    /// The largest |ü| (the tightest acceleration limit over the moving axes).
    pub a: f64,
    /// The largest |u⃛| (the tightest jerk limit over the moving axes).
    pub j: f64,
}

/// How far (relative) q' may vary, q'' stray from 0 (times the span's length) and the bounds
/// differ between stations or between the two signs for a span to count as straight with
/// constant, symmetric limits.
const SAME: f64 = 1e-9;

impl PathLimits {
    /// The limits of `p` (a span's problem on any grid) if it is a straight line in joint space
    /// from rest to rest with the same, symmetric limits at every station and a jerk limit on
    /// some moving axis; `None` otherwise (the general solver then takes it).
    pub fn of_straight(p: &SpanProblem, machine: &Machine) -> Option<PathLimits> {
        let n = p.intervals();
        if n == 0 || p.b_start != 0.0 || p.b_end != 0.0 {
            return None;
        }
        let len = p.u[n] - p.u[0];
        let na = p.n_axes();
        let d0 = &p.jets.dq(0)[..na];
        let big = d0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if !(len > 0.0 && big > 0.0 && big.is_finite()) {
            return None;
        }
        let b0 = p.b_max[0];
        if !(b0.is_finite() && b0 > 0.0) {
            return None;
        }
        for i in 0..=n {
            let (d, dd) = (&p.jets.dq(i)[..na], &p.jets.ddq(i)[..na]);
            let straight = d.iter().zip(d0).all(|(x, y)| (x - y).abs() <= SAME * big)
                && dd.iter().all(|x| x.abs() * len <= SAME * big);
            if !straight || (p.b_max[i] - b0).abs() > SAME * b0 {
                return None;
            }
        }
        let (lo, hi) = p.udd_range(0, 0.0);
        let a = hi.min(-lo);
        if !(a.is_finite() && a > 0.0) || (hi + lo).abs() > SAME * a {
            return None;
        }
        let (up, down) = super::jerk::path_jerk_bounds(machine, d0);
        let j = up.min(down);
        if !(j.is_finite() && j > 0.0) || (up - down).abs() > SAME * j {
            return None;
        }
        Some(PathLimits { v: b0.sqrt(), a, j })
    }
}

/// The double-S profile from rest to rest over a length (module doc): phase times and peaks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoubleS {
    /// Length, in u.
    pub length: f64,
    /// The jerk bound J.
    pub jerk: f64,
    /// T_j: each constant-jerk phase.
    pub tj: f64,
    /// T_a: the whole acceleration (and the whole deceleration).
    pub ta: f64,
    /// T_v: the cruise.
    pub tv: f64,
    /// The peak acceleration: A, or J·T_j where A is not reached.
    pub a_peak: f64,
    /// The peak speed: V, or less where the move is too short to reach it.
    pub v_peak: f64,
}

impl DoubleS {
    /// The time-optimal profile over `length` under `lim` (Biagiotti & Melchiorri §3.4 with
    /// v₀ = v₁ = 0; lengths and limits positive and finite).
    pub fn new(length: f64, lim: PathLimits) -> DoubleS {
        let PathLimits { v, a, j } = lim;
        // Accelerating from rest to V: A reached if V·J ≥ A².
        let (tj, ta) = if v * j >= a * a {
            (a / j, a / j + v / a)
        } else {
            let tj = (v / j).sqrt();
            (tj, 2.0 * tj)
        };
        // From rest to V and back takes the length V·T_a: a cruise makes up the rest.
        if length >= v * ta {
            return DoubleS {
                length,
                jerk: j,
                tj,
                ta,
                tv: length / v - ta,
                a_peak: j * tj,
                v_peak: v,
            };
        }
        // No cruise: L = v_lim·T_a, with A reached (v_lim = A (T_a − T_j), T_a ≥ 2 T_j) or not
        // (T_a = 2 T_j, v_lim = J T_j²).
        let tj = a / j;
        let ta = 0.5 * (tj + (tj * tj + 4.0 * length / a).sqrt());
        if ta >= 2.0 * tj {
            return DoubleS {
                length,
                jerk: j,
                tj,
                ta,
                tv: 0.0,
                a_peak: a,
                v_peak: a * (ta - tj),
            };
        }
        let tj = (0.5 * length / j).cbrt();
        DoubleS {
            length,
            jerk: j,
            tj,
            ta: 2.0 * tj,
            tv: 0.0,
            a_peak: j * tj,
            v_peak: j * tj * tj,
        }
    }

    /// The whole time, 2 T_a + T_v.
    pub fn duration(&self) -> f64 {
        2.0 * self.ta + self.tv
    }

    /// (u, u̇, ü) at time `t` of the acceleration (0 ≤ t ≤ T_a).
    fn accelerating(&self, t: f64) -> [f64; 3] {
        let (j, tj, ta, am, vm) = (self.jerk, self.tj, self.ta, self.a_peak, self.v_peak);
        if t <= tj {
            [j * t * t * t / 6.0, 0.5 * j * t * t, j * t]
        } else if t <= ta - tj {
            let (u1, v1, s) = (j * tj * tj * tj / 6.0, 0.5 * am * tj, t - tj);
            [u1 + v1 * s + 0.5 * am * s * s, v1 + am * s, am]
        } else {
            // Mirrored from the end of the acceleration, where u = v_lim·T_a/2.
            let s = ta - t;
            [
                0.5 * vm * ta - vm * s + j * s * s * s / 6.0,
                vm - 0.5 * j * s * s,
                j * s,
            ]
        }
    }

    /// (u, u̇, ü) at time `t` (clamped to [0, T]).
    pub fn at(&self, t: f64) -> [f64; 3] {
        let total = self.duration();
        let t = t.clamp(0.0, total);
        if t <= self.ta {
            self.accelerating(t)
        } else if t <= self.ta + self.tv {
            [
                0.5 * self.v_peak * self.ta + self.v_peak * (t - self.ta),
                self.v_peak,
                0.0,
            ]
        } else {
            let [u, v, a] = self.accelerating(total - t);
            [self.length - u, v, -a]
        }
    }

    /// The times where phases meet, from 0 to T, each once, with every −J phase (`[T_a − T_j,
    /// T_a]` and its mirror, which meet where there is no cruise) cut into `parts` times graded
    /// towards its slow end ([`GRADING`]).
    fn times(&self, parts: usize) -> Vec<f64> {
        let (tj, ta, total) = (self.tj, self.ta, self.duration());
        let mut t = vec![0.0, tj, ta - tj];
        for k in 1..=parts {
            t.push(ta - tj + tj * (k as f64 / parts as f64).powf(GRADING));
        }
        t.push(ta + self.tv);
        for k in 1..=parts {
            t.push(ta + self.tv + tj * (1.0 - (1.0 - k as f64 / parts as f64).powf(GRADING)));
        }
        t.extend([total - tj, total]);
        // The last time is T exactly; zero-length phases (no constant acceleration, no
        // cruise) leave repeats.
        t.dedup_by(|b, a| *b - *a <= 1e-12 * total);
        if let Some(last) = t.last_mut() {
            *last = total;
        }
        t
    }
}

/// The largest relative difference allowed between the time the motion laws give on the
/// stations and the profile's own.
pub const TIME_TOLERANCE: f64 = 1e-7;

/// The largest share by which the cubic law's jerk inside a −J phase may pass J: half the
/// re-simulation's tolerance (the sequential convex programme's profiles pass their jerk
/// bounds between stations by as much). The excess falls as the square of the parts: on a
/// move that reaches A and not V, 9e-3 with 4 parts, 7.6e-4 with 16, 2.0e-4 with 32.
pub const JERK_TOLERANCE: f64 = 5e-4;

/// The times inside a −J phase go as (k/parts)^GRADING from its slower end, where b is smallest
/// and the law's misfit largest: with 1.5 the jerk's excess stays within [`JERK_TOLERANCE`]
/// at 16 parts where equal times needed 32 (and 32 where they needed 64, on a move too short to
/// reach A).
const GRADING: f64 = 1.5;

/// The most parts a −J phase is cut into.
const MAX_PARTS: usize = 256;

/// The profile's stations (offset by `u0`) and its solution under the motion laws (module doc):
/// the fewest parts per −J phase (doubling from 4) that keep the laws within
/// [`TIME_TOLERANCE`] and [`JERK_TOLERANCE`]; `None` where even `MAX_PARTS` do not (the
/// general solver then takes the span).
pub fn profile_stations(s: &DoubleS, u0: f64) -> Option<(Vec<f64>, SpanSolution)> {
    let exact = s.duration();
    let mut parts = 4;
    while parts <= MAX_PARTS {
        let states: Vec<[f64; 3]> = s.times(parts).into_iter().map(|t| s.at(t)).collect();
        let mut u: Vec<f64> = states.iter().map(|x| x[0]).collect();
        let mut b: Vec<f64> = states.iter().map(|x| x[1] * x[1]).collect();
        let mut a: Vec<f64> = states.iter().map(|x| x[2]).collect();
        let n = u.len() - 1;
        // Rest at both ends exactly; the end where the length is.
        (u[0], u[n], b[0], b[n], a[0], a[n]) = (0.0, s.length, 0.0, 0.0, 0.0, 0.0);
        let slopes: Vec<[f64; 2]> = (0..n)
            .map(|k| {
                let w = hermite_slope_weights(u[k + 1] - u[k]);
                let x = [b[k], b[k + 1], a[k], a[k + 1]];
                let dot = |w: &[f64; 4]| w.iter().zip(&x).map(|(w, x)| w * x).sum::<f64>();
                [dot(&w[0]), dot(&w[1])]
            })
            .collect();
        if u.windows(2).any(|w| w[1] <= w[0]) {
            return None;
        }
        let mut time = 0.0;
        let mut jerk_ok = true;
        for k in 0..n {
            let iv = Interval::of(
                &u,
                &b,
                Shape {
                    a: Some(&a),
                    slopes: Some(&slopes),
                    ends: None,
                },
                k,
            );
            time += iv.duration().ok()?;
            // The cubic law's path jerk a'(x)·√b(x) at a few points of the interval (the rest
            // laws are the profile's own).
            if matches!(iv.law, crate::motion::Law::Cubic) {
                for f in [0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0] {
                    let x = f * iv.du;
                    let jerk = iv.slope_at_x(x) * iv.at_x(x).0.sqrt();
                    if jerk.abs() > s.jerk * (1.0 + JERK_TOLERANCE) {
                        jerk_ok = false;
                    }
                }
            }
        }
        if jerk_ok && (time - exact).abs() <= TIME_TOLERANCE * exact {
            for x in &mut u {
                *x += u0;
            }
            let sol = SpanSolution {
                ends: None,
                b: std::mem::take(&mut b),
                a: Some(std::mem::take(&mut a)),
                slopes: Some(slopes),
                status: Status::Optimal,
                iterations: 0,
                solve_time: 0.0,
                scp_iterations: 0,
            };
            return Some((u, sol));
        }
        parts *= 2;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The profile against a plain integration of its own jerk in small time steps: the
    /// closed form's position, speed and acceleration at every phase, for the three cases
    /// (cruise; no cruise with A reached; neither).
    #[test]
    fn the_closed_form_is_its_jerk_integrated() {
        let lim = PathLimits {
            v: 100.0,
            a: 1000.0,
            j: 20_000.0,
        };
        for length in [50.0, 8.0, 0.5] {
            let s = DoubleS::new(length, lim);
            assert!(s.v_peak <= lim.v * (1.0 + 1e-12) && s.a_peak <= lim.a * (1.0 + 1e-12));
            let total = s.duration();
            let steps = 200_000;
            let dt = total / steps as f64;
            let (mut u, mut v, mut a) = (0.0, 0.0, 0.0);
            for k in 0..steps {
                // The jerk at the middle of the step, from the closed form's acceleration.
                let t = (k as f64 + 0.5) * dt;
                let j = (s.at(t + 0.5 * dt)[2] - s.at(t - 0.5 * dt)[2]) / dt;
                assert!(j.abs() <= lim.j * (1.0 + 1e-6), "jerk {j} at {t}");
                u += v * dt + 0.5 * a * dt * dt + j * dt * dt * dt / 6.0;
                v += a * dt + 0.5 * j * dt * dt;
                a += j * dt;
                if k % 10_000 == 9_999 {
                    let [cu, cv, ca] = s.at((k + 1) as f64 * dt);
                    assert!((cu - u).abs() <= 1e-6 * length, "{length}: u {cu} vs {u}");
                    assert!((cv - v).abs() <= 1e-6 * s.v_peak, "{length}: v {cv} vs {v}");
                    assert!((ca - a).abs() <= 1e-6 * s.a_peak, "{length}: a {ca} vs {a}");
                }
            }
            assert!((u - length).abs() <= 1e-6 * length && v.abs() <= 1e-6 * s.v_peak);
        }
        // Which case each length is.
        assert!(DoubleS::new(50.0, lim).tv > 0.0);
        let mid = DoubleS::new(8.0, lim);
        assert!(mid.tv == 0.0 && mid.a_peak == lim.a);
        let short = DoubleS::new(0.5, lim);
        assert!(short.tv == 0.0 && short.a_peak < lim.a);
    }

    /// The stations carry the profile: the motion laws give its time, within the tolerance.
    #[test]
    fn the_laws_on_the_stations_give_the_profile_time() {
        let lim = PathLimits {
            v: 100.0,
            a: 1000.0,
            j: 20_000.0,
        };
        for length in [50.0, 8.0, 0.5, 1e-3] {
            let s = DoubleS::new(length, lim);
            let (u, sol) = profile_stations(&s, 2.0).expect("within tolerance");
            assert_eq!(u[0], 2.0);
            assert!((u[u.len() - 1] - 2.0 - length).abs() <= 1e-12 * length.max(1.0));
            let t: f64 = crate::motion::interval_times(&u, &sol.b, sol.shape())
                .unwrap()
                .iter()
                .sum();
            assert!(
                (t - s.duration()).abs() <= TIME_TOLERANCE * s.duration(),
                "{length}: {t}"
            );
            assert!(u.len() <= 72, "{length}: {} stations", u.len());
        }
    }
}
