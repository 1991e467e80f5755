//! Closed-form physics: cases whose time-optimal answer is known exactly.

use feedopt::machine::Machine;
use feedopt::optimize::{Options, Solution, optimize};
use feedopt::toolpath::Toolpath;
use nalgebra::Vector3;

mod common;
use common::{UP, machine, toolpath};

fn solve(m: &Machine, t: &Toolpath) -> Solution {
    optimize(m, t, &Options::default()).expect("solves")
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Tool tip on a circle of radius r, `turns` times round, starting at angle 0.
fn circle(r: f64, turns: usize, per_turn: usize) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    (0..=turns * per_turn)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / per_turn as f64;
            (Vector3::new(r * a.cos(), r * a.sin(), 0.0), UP)
        })
        .collect()
}

/// Stations in the middle turn of a multi-turn path (by arc length).
fn middle(sol: &Solution, turns: f64) -> Vec<f64> {
    let len = sol.schedule.stations.last().unwrap().s;
    let (lo, hi) = (len * (0.5 - 0.5 / turns), len * (0.5 + 0.5 / turns));
    sol.schedule
        .stations
        .iter()
        .filter(|s| s.s >= lo && s.s <= hi)
        .map(|s| s.v)
        .collect()
}

const XYZ_2000: &str = r#"{"name": "xyz", "kinematics": {"type": "xyz"},
    "axes": {"X": {"velocity": 10000, "acceleration": 2000},
             "Y": {"velocity": 10000, "acceleration": 2000},
             "Z": {"velocity": 10000, "acceleration": 2000}}}"#;

#[test]
fn circle_limited_by_centripetal_acceleration_runs_at_sqrt_a_r() {
    // With equal X/Y limits a, the axis-aligned points of the circle need V²/R ≤ a from one
    // axis alone (its tangent is zero there), so the feed dips to exactly √(aR) there and
    // nowhere lower.
    let (r, a) = (20.0, 2000.0);
    let m = machine(XYZ_2000);
    let sol = solve(&m, &toolpath(&circle(r, 7, 240), None));
    let v = middle(&sol, 7.0);
    let vmin = v.iter().copied().fold(f64::INFINITY, f64::min);
    let expect = (a * r).sqrt();
    assert!(rel(vmin, expect) < 1e-3, "V_min {vmin} vs √(aR) {expect}");
}

#[test]
fn circle_limited_by_the_feed_runs_at_the_feed() {
    // F below √(aR) = 200 mm/s: the whole middle turn runs at F.
    let m = machine(XYZ_2000);
    let f = 150.0;
    let sol = solve(&m, &toolpath(&circle(20.0, 7, 240), Some(f)));
    for v in middle(&sol, 7.0) {
        assert!(rel(v, f) < 1e-3, "V {v} vs F {f}");
    }
}

fn line(len: f64) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    vec![(Vector3::zeros(), UP), (Vector3::new(len, 0.0, 0.0), UP)]
}

#[test]
fn long_line_rest_to_rest_is_a_trapezoid() {
    // T = L/F + F/a when the line is long enough to reach F (L ≥ F²/a).
    let m = machine(XYZ_2000);
    let (l, f, a) = (120.0, 100.0, 2000.0);
    let sol = solve(&m, &toolpath(&line(l), Some(f)));
    let expect = l / f + f / a;
    assert!(
        rel(sol.schedule.cycle_time, expect) < 1e-3,
        "T {} vs {expect}",
        sol.schedule.cycle_time
    );
}

#[test]
fn short_line_rest_to_rest_is_a_triangle() {
    // Too short to reach F: accelerate half-way, brake the other half, T = 2√(L/a).
    let m = machine(XYZ_2000);
    let (l, f, a) = (2.0, 100.0, 2000.0);
    assert!(l < f * f / a);
    let sol = solve(&m, &toolpath(&line(l), Some(f)));
    let expect = 2.0 * (l / a).sqrt();
    assert!(
        rel(sol.schedule.cycle_time, expect) < 1e-3,
        "T {} vs {expect}",
        sol.schedule.cycle_time
    );
}

#[test]
fn pure_reorientation_on_head_head_is_limited_by_c() {
    // The tip stays put while the tool turns by Δ about the vertical at a fixed tilt: only C
    // moves by Δ (A stays, X/Y follow with generous limits). T = Δ/v + v/a.
    let m = machine(
        r#"{"name": "hh", "kinematics": {"type": "head_head", "tool_length": 200},
            "axes": {"X": {"velocity": 1e5, "acceleration": 1e6},
                     "Y": {"velocity": 1e5, "acceleration": 1e6},
                     "Z": {"velocity": 1e5, "acceleration": 1e6},
                     "C": {"velocity": 120, "acceleration": 600},
                     "A": {"velocity": 60, "acceleration": 400}},
            "feed": {"max": 150}}"#,
    );
    let (delta, v, a) = (90.0f64, 120.0, 600.0);
    let tilt = 30f64.to_radians();
    let tip = Vector3::new(10.0, -5.0, 3.0);
    let pts: Vec<_> = (0..=60)
        .map(|k| {
            let t1 = (delta * k as f64 / 60.0).to_radians();
            let o = Vector3::new(tilt.sin() * t1.sin(), -tilt.sin() * t1.cos(), tilt.cos());
            (tip, o)
        })
        .collect();
    let sol = solve(&m, &toolpath(&pts, Some(100.0)));
    let expect = delta / v + v / a;
    assert!(
        rel(sol.schedule.cycle_time, expect) < 1e-3,
        "T {} vs {expect}",
        sol.schedule.cycle_time
    );
    // The tool tip never moves, so the feed is zero throughout.
    assert!(sol.schedule.stations.iter().all(|s| s.v == 0.0));
}

#[test]
fn a_sharp_corner_is_an_exact_stop() {
    // Two lines at 90°: two rest-to-rest trapezoids.
    let m = machine(XYZ_2000);
    let (l, f, a) = (50.0, 100.0, 2000.0);
    let pts = vec![
        (Vector3::zeros(), UP),
        (Vector3::new(l, 0.0, 0.0), UP),
        (Vector3::new(l, l, 0.0), UP),
    ];
    let sol = solve(&m, &toolpath(&pts, Some(f)));
    assert_eq!(sol.problems.len(), 2);
    let expect = 2.0 * (l / f + f / a);
    assert!(rel(sol.schedule.cycle_time, expect) < 1e-3);
}

#[test]
fn the_schedule_respects_every_limit_at_every_station() {
    // A 5-axis path; peaks from the report must not exceed 1 beyond solver tolerance.
    let m = machine(
        r#"{"name": "hh", "kinematics": {"type": "head_head", "tool_length": 150},
            "axes": {"X": {"velocity": 400, "acceleration": 2000},
                     "Y": {"velocity": 400, "acceleration": 2000},
                     "Z": {"velocity": [-300, 200], "acceleration": [-1000, 1500]},
                     "C": {"velocity": 90, "acceleration": 450},
                     "A": {"velocity": 45, "acceleration": 300}},
            "feed": {"max": 120}}"#,
    );
    let pts: Vec<_> = (0..=300)
        .map(|k| {
            let s = k as f64 / 300.0;
            let a = std::f64::consts::TAU * s;
            let p = Vector3::new(40.0 * a.cos(), 25.0 * (2.0 * a).sin(), 8.0 * s);
            let t2 = (20.0 + 10.0 * a.sin()).to_radians();
            let t1 = 1.5 * a;
            (
                p,
                Vector3::new(t2.sin() * t1.sin(), -t2.sin() * t1.cos(), t2.cos()),
            )
        })
        .collect();
    let sol = solve(&m, &toolpath(&pts, None));
    let summary = feedopt::report::Summary::new(&m, "test", &sol);
    let mut binding = 0;
    for (name, p) in &summary.axes {
        assert!(p.peak_velocity_ratio <= 1.0 + 1e-6, "{name} {p:?}");
        assert!(p.peak_acceleration_ratio <= 1.0 + 1e-6, "{name} {p:?}");
        if p.peak_velocity_ratio > 0.999 || p.peak_acceleration_ratio > 0.999 {
            binding += 1;
        }
    }
    assert!(
        binding >= 1,
        "a time-optimal schedule uses some limit fully"
    );
    assert!(
        sol.schedule
            .stations
            .iter()
            .all(|s| s.t.is_finite() && s.v.is_finite())
    );
}

/// A 90° corner between two long feed moves, with a corner tolerance ε
/// (`GeometryOptions::corner_tolerance_mm`): the path runs through it (one span, no stop) on
/// the quintic blend whose control points lie at d, 2d/3, d/3 from the corner on each move,
/// d = 16 ε / (S sin 45°), S = 1 + 5·2/3 + 10/3; it stays within ε (and the fitting tolerance)
/// of the programmed lines and comes ε close to the corner; it is nowhere faster than the
/// blend's own curvature allows (computed here from the control points: at each point the
/// largest V that some tangential acceleration keeps within both axes' limits, its lowest over
/// the curve, 17.61 mm/s); and the cycle time is below the exact stop's.
#[test]
fn a_blended_corner_runs_through_at_its_curvatures_speed() {
    let (a, eps) = (2000.0, 0.05);
    let m = machine(XYZ_2000);
    let pts = [
        (Vector3::new(0.0, 0.0, 0.0), UP),
        (Vector3::new(100.0, 0.0, 0.0), UP),
        (Vector3::new(100.0, 100.0, 0.0), UP),
    ];
    let tp = toolpath(&pts, Some(1000.0));
    let stop = solve(&m, &tp);
    assert_eq!(stop.path.spans.len(), 2);
    let mut options = Options::default();
    options.geometry.corner_tolerance_mm = eps;
    // Through the blend's points exactly (the default smoothing within 5 µm rounds its
    // curvature peak off a little: 16.56 mm/s there against the blend's own 16.13).
    options.geometry.tolerance_mm = 0.0;
    let sol = optimize(&m, &tp, &options).expect("solves");
    assert!(sol.verification.verified);
    assert_eq!((sol.path.spans.len(), sol.corners_blended), (1, 1));
    // The blend's slowest admissible speed, from its control points.
    let sum = 1.0 + 5.0 * 2.0 / 3.0 + 10.0 / 3.0;
    let d = 16.0 * eps / (sum * std::f64::consts::FRAC_PI_4.sin());
    let c: Vec<[f64; 2]> = [1.0, 2.0 / 3.0, 1.0 / 3.0]
        .iter()
        .map(|s| [100.0 - d * s, 0.0])
        .chain([1.0 / 3.0, 2.0 / 3.0, 1.0].iter().map(|s| [100.0, d * s]))
        .collect();
    let binom = [1.0, 5.0, 10.0, 10.0, 5.0, 1.0];
    // Derivatives of a Bézier curve: differences of the control points.
    let deriv = |p: &[[f64; 2]]| -> Vec<[f64; 2]> {
        let n = (p.len() - 1) as f64;
        p.windows(2)
            .map(|w| [n * (w[1][0] - w[0][0]), n * (w[1][1] - w[0][1])])
            .collect()
    };
    let eval = |p: &[[f64; 2]], t: f64| -> [f64; 2] {
        let n = p.len() - 1;
        let bin: Vec<f64> = match n {
            5 => binom.to_vec(),
            4 => vec![1.0, 4.0, 6.0, 4.0, 1.0],
            _ => vec![1.0, 3.0, 3.0, 1.0],
        };
        let mut s = [0.0; 2];
        for (i, q) in p.iter().enumerate() {
            let w = bin[i] * t.powi(i as i32) * (1.0 - t).powi((n - i) as i32);
            s[0] += w * q[0];
            s[1] += w * q[1];
        }
        s
    };
    let (d1, d2) = (deriv(&c), deriv(&deriv(&c)));
    // The largest V at each point of the blend: V² such that some tangential acceleration A
    // keeps both axes within a (|T_j A + κn_j V²| ≤ a, an interval of A per axis; they must
    // meet), found by bisection; the slowest point of the curve is the lowest of these.
    let vmax = (1..1000)
        .map(|k| {
            let t = k as f64 / 1000.0;
            let (v, w) = (eval(&d1, t), eval(&d2, t));
            let speed2 = v[0] * v[0] + v[1] * v[1];
            let tan = [v[0] / speed2.sqrt(), v[1] / speed2.sqrt()];
            // The normal acceleration per unit V²: the part of P'' across P', over |P'|².
            let along = (w[0] * v[0] + w[1] * v[1]) / speed2;
            let kn = [
                (w[0] - along * v[0]) / speed2,
                (w[1] - along * v[1]) / speed2,
            ];
            let feasible = |b: f64| {
                let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
                for j in 0..2 {
                    let c = kn[j] * b;
                    if tan[j].abs() < 1e-12 {
                        if c.abs() > a {
                            return false;
                        }
                        continue;
                    }
                    let (x, y) = ((-a - c) / tan[j], (a - c) / tan[j]);
                    lo = lo.max(x.min(y));
                    hi = hi.min(x.max(y));
                }
                lo <= hi
            };
            let (mut lo, mut hi) = (0.0, 1e6);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if feasible(mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo.sqrt()
        })
        .fold(f64::INFINITY, f64::min);
    let fit = 1e-3;
    let corner = Vector3::new(100.0, 0.0, 0.0);
    let (mut closest, mut vmin) = (f64::INFINITY, f64::INFINITY);
    for (k, st) in sol.schedule.stations.iter().enumerate() {
        let (x, y) = (sol.schedule.q(k)[0], sol.schedule.q(k)[1]);
        // Distance to the programmed polyline (two axis-aligned lines).
        let off = if x <= 100.0 - y {
            y.abs()
        } else {
            (x - 100.0).abs()
        };
        assert!(off <= eps + fit, "({x}, {y}) is {off} mm off the lines");
        closest = closest.min((Vector3::new(x, y, 0.0) - corner).norm());
        if (Vector3::new(x, y, 0.0) - corner).norm() < 2.0 {
            vmin = vmin.min(st.v);
        }
    }
    assert!((closest - eps).abs() <= fit, "closest {closest} vs ε {eps}");
    eprintln!(
        "blended {:.6} s, V_min {vmin:.3} (the blend's {vmax:.3}); exact stop {:.6} s",
        sol.schedule.cycle_time, stop.schedule.cycle_time
    );
    // No faster than the curve allows anywhere; a little slower than its slowest point (0.94
    // of it), as the blend begins to turn while X still brakes at its limit from the feed.
    assert!(
        vmin <= vmax * 1.001 && vmin > 0.9 * vmax,
        "V_min {vmin} vs {vmax}"
    );
    assert!(sol.schedule.cycle_time < stop.schedule.cycle_time);
}
