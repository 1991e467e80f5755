//! Re-simulation at the servo period: real schedules pass, tampered or under-resolved ones fail.

use feedopt::constraints::Ramp;
use feedopt::geometry::GeometryOptions;
use feedopt::machine::Machine;
use feedopt::optimize::{Options, Solution, optimize};
use feedopt::toolpath::Toolpath;
use feedopt::verify::{Quantity, Verification, VerifyOptions, verify};
use nalgebra::Vector3;

mod common;
use common::{UP, machine, toolpath};

const XYZ_2000: &str = r#"{"name": "xyz", "kinematics": {"type": "xyz"},
    "axes": {"X": {"velocity": 10000, "acceleration": 2000},
             "Y": {"velocity": 10000, "acceleration": 2000},
             "Z": {"velocity": 10000, "acceleration": 2000}}}"#;

const HEAD_HEAD: &str = r#"{"name": "hh", "kinematics": {"type": "head_head", "tool_length": 150},
    "axes": {"X": {"velocity": 400, "acceleration": 2000},
             "Y": {"velocity": 400, "acceleration": 2000},
             "Z": {"velocity": [-300, 200], "acceleration": [-1000, 1500]},
             "C": {"velocity": 90, "acceleration": 450},
             "A": {"velocity": 45, "acceleration": 300}},
    "feed": {"max": 120}}"#;

fn line(len: f64) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    vec![(Vector3::zeros(), UP), (Vector3::new(len, 0.0, 0.0), UP)]
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

/// The 5-axis path of tests/physics.rs: a figure-eight-like curve with a swinging tool.
fn five_axis_path() -> Vec<(Vector3<f64>, Vector3<f64>)> {
    (0..=300)
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
        .collect()
}

fn solve(m: &Machine, t: &Toolpath, options: &Options) -> Solution {
    optimize(m, t, options).expect("solves")
}

fn check(m: &Machine, sol: &Solution, options: &VerifyOptions) -> Verification {
    let v = verify(
        m,
        &sol.kinematics,
        &sol.path.spans,
        &sol.problems,
        &sol.solutions,
        options,
    )
    .expect("verifies");
    assert_no_nan(&v);
    v
}

/// Item 4: no NaN anywhere in the output.
fn assert_no_nan(v: &Verification) {
    assert!(!v.worst_feed.is_nan() && v.worst_feed >= 0.0);
    assert!(!v.worst_ratio().is_nan());
    for w in &v.worst {
        assert!(w.velocity.is_finite() && w.velocity >= 0.0, "{w:?}");
        assert!(w.acceleration.is_finite() && w.acceleration >= 0.0, "{w:?}");
    }
    for x in &v.violations {
        assert!(
            [x.u, x.t, x.value, x.limit, x.ratio]
                .iter()
                .all(|f| !f.is_nan()),
            "{x:?}"
        );
    }
    assert!(v.violations.windows(2).all(|w| w[0].ratio >= w[1].ratio));
    // The JSON form is valid too.
    serde_json::to_string(v).expect("serialises");
}

fn tamper(sol: &mut Solution, factor: f64) {
    for s in &mut sol.solutions {
        for b in &mut s.b {
            *b *= factor;
        }
        // ü at the intervals' ends (the linear-ü law) scales with b.
        for e in s.ends.iter_mut().flatten() {
            e[0] *= factor;
            e[1] *= factor;
        }
    }
}

#[test]
fn a_rest_to_rest_line_is_verified_and_bang_bang() {
    let m = machine(XYZ_2000);
    let (l, f, a) = (120.0, 100.0, 2000.0);
    let sol = solve(&m, &toolpath(&line(l), Some(f)), &Options::default());
    let opts = VerifyOptions::default();
    let v = check(&m, &sol, &opts);
    assert!(v.verified, "{v:?}");
    assert!((v.worst[0].acceleration - 1.0).abs() < 1e-3, "{v:?}");
    assert!((v.worst_feed - 1.0).abs() < 1e-3, "{v:?}");
    assert_eq!(v.worst[1].acceleration, 0.0);
    assert!((v.worst_ratio() - 1.0).abs() < 1e-3);
    let t = sol.schedule.cycle_time;
    assert!((t - (l / f + f / a)).abs() < 1e-3 * t);
    let expect = t / opts.period;
    assert!(
        (v.samples as f64 - expect).abs() <= 2.0 * sol.problems.len() as f64,
        "{} samples for T = {t} s",
        v.samples
    );
    assert_eq!(v.station_checks, 2 * (sol.stations() - sol.problems.len()));
}

#[test]
fn a_five_axis_schedule_is_verified_between_stations() {
    let m = machine(HEAD_HEAD);
    let sol = solve(&m, &toolpath(&five_axis_path(), None), &Options::default());
    let v = check(&m, &sol, &VerifyOptions::default());
    eprintln!(
        "5-axis: worst {:.6}, feed {:.6}, {:?}",
        v.worst_ratio(),
        v.worst_feed,
        v.worst
    );
    assert!(
        v.verified,
        "{:?}",
        &v.violations[..v.violations.len().min(5)]
    );
    assert_eq!(v.worst.len(), 5);
    for w in &v.worst {
        assert!(w.velocity <= 1.001 && w.acceleration <= 1.001, "{w:?}");
    }
    assert!(v.worst_feed <= 1.001);
    assert!(v.worst_ratio() >= 0.99, "{v:?}");
}

#[test]
fn a_schedule_run_too_fast_fails() {
    // b × 1.05: the feed 2.5 % and every acceleration 5 % over.
    let m = machine(XYZ_2000);
    let mut sol = solve(
        &m,
        &toolpath(&line(120.0), Some(100.0)),
        &Options::default(),
    );
    tamper(&mut sol, 1.05);
    let v = check(&m, &sol, &VerifyOptions::default());
    assert!(!v.verified);
    assert!(v.violating_intervals >= v.violations.len() && !v.violations.is_empty());
    let worst = &v.violations[0];
    assert_eq!((worst.axis, worst.kind), (Some(0), Quantity::Acceleration));
    assert!((worst.ratio - 1.05).abs() < 2e-3, "{worst:?}");
    // On the plateau nothing accelerates: there the feed is the violation.
    let feed: Vec<_> = v
        .violations
        .iter()
        .filter(|x| x.kind == Quantity::Feed)
        .collect();
    assert!(!feed.is_empty());
    assert!(feed.iter().all(|x| x.axis.is_none()));
    assert!(
        (v.worst_feed - 1.05f64.sqrt()).abs() < 2e-3,
        "{}",
        v.worst_feed
    );

    // On a circle in the XY plane the velocity limit of X binds where it moves alone.
    let m = machine(
        r#"{"name": "xyz", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 50, "acceleration": 1e5},
                     "Y": {"velocity": 1000, "acceleration": 1e5},
                     "Z": {"velocity": 1000, "acceleration": 1e5}}}"#,
    );
    let mut sol = solve(
        &m,
        &toolpath(&circle(10.0, 2, 60), None),
        &Options::default(),
    );
    let v = check(&m, &sol, &VerifyOptions::default());
    assert!(v.verified, "{:?}", v.violations.first());
    tamper(&mut sol, 1.05);
    let v = check(&m, &sol, &VerifyOptions::default());
    assert!(!v.verified);
    assert!(
        v.violations
            .iter()
            .any(|x| x.kind == Quantity::Velocity && x.axis == Some(0)),
    );
    assert!((v.worst[0].velocity - 1.05f64.sqrt()).abs() < 2e-3, "{v:?}");
    assert!(v.worst[1].velocity < 1.0);
}

/// Asserts the schedule holds the solver's rows at its stations (within the solver's
/// tolerance), and returns the re-simulation's worst acceleration ratio of X and Y.
fn station_ok_between_not(m: &Machine, sol: &Solution) -> (Verification, f64) {
    let summary = feedopt::report::Summary::new(m, "coarse", sol);
    for (name, p) in &summary.axes {
        assert!(p.peak_acceleration_ratio <= 1.0 + 1e-6, "{name} {p:?}");
    }
    let v = check(m, sol, &VerifyOptions::default());
    let worst = v.worst[0].acceleration.max(v.worst[1].acceleration);
    assert!(worst.is_finite());
    (v, worst)
}

#[test]
fn too_few_stations_on_a_circle_exceed_the_limits_between_them() {
    // Acceleration-limited circle (R = 10 mm, a = 2000), no feed cap, one interval per CL
    // segment. The solver holds its rows at the stations only; between them b is linear in u
    // while the demand b·q''(u) + q'(u)·ü of X and Y is not.
    //
    // What happens: a circle is nearly benign. With a multiple of 4 CL points per turn (e.g.
    // 40) stations sit on every axis-aligned point, the optimum is the constant √(aR) and
    // q̈ = b q'' stays within the limit everywhere (worst 1.0000). With 37 points per turn
    // (9.7°, just below the 10° exact-stop angle) no station sits on most axis-aligned points,
    // and the re-simulation finds an excess of about 0.2 % between stations (worst ≈ 1.0016).
    let m = machine(XYZ_2000);
    let options = Options {
        stations: Some(20),
        // Keep the coarse grid as it is: this test is about what the check finds there.
        refine_until_verified: false,
        ..Options::default()
    };
    let sol = solve(&m, &toolpath(&circle(10.0, 3, 37), None), &options);
    assert_eq!(sol.problems.len(), 1);
    assert_eq!(sol.stations(), 3 * 37 + 1, "one interval per CL segment");
    let (v, worst) = station_ok_between_not(&m, &sol);
    eprintln!(
        "coarse circle: worst X {:.5} Y {:.5}, {} violating intervals",
        v.worst[0].acceleration, v.worst[1].acceleration, v.violating_intervals
    );
    assert!(worst > 1.0, "worst acceleration ratio {worst}");
    assert!(
        v.violations
            .iter()
            .all(|x| x.kind == Quantity::Acceleration && matches!(x.axis, Some(0 | 1)))
    );
}

#[test]
fn a_curvature_peak_between_stations_is_found() {
    // A clearer case: a parabola y = c x² (c = 0.1 /mm) through CL points h = 2 mm apart, the
    // vertex (the curvature peak) midway between two of them, few stations, no feed cap. Near
    // the vertex y''(u) rises steeply while b, linear between stations, falls (braking into the
    // bend) or stays: b·y''(u) + y'(u)·ü peaks between stations, where the solver has no row.
    // The turns between chords reach 22°, so the exact-stop angle is raised to keep one span.
    //
    // Found: Y exceeds its acceleration limit by about 3 % between stations, while every
    // station is within the limit. (With the default 10° exact-stop angle the CL points must
    // be closer, c h ≤ 0.087, and the excess is only about 0.2–0.5 %.)
    let (c, h) = (0.1, 2.0);
    let pts: Vec<_> = (-6..6)
        .map(|k| {
            let x = (k as f64 + 0.5) * h;
            (Vector3::new(x, c * x * x, 0.0), UP)
        })
        .collect();
    let m = machine(XYZ_2000);
    let tp = toolpath(&pts, None);
    // b linear between stations, as above (the linear-ü law's rows hold ü at both ends).
    let options = Options {
        stations: Some(8),
        refine_until_verified: false,
        ramp: Ramp::Constant,
        geometry: GeometryOptions {
            corner_angle_deg: 30.0,
            ..GeometryOptions::default()
        },
        ..Options::default()
    };
    let sol = solve(&m, &tp, &options);
    assert_eq!(sol.problems.len(), 1);
    let (v, worst) = station_ok_between_not(&m, &sol);
    eprintln!(
        "coarse parabola: {} stations, worst X {:.5} Y {:.5}, {} violating intervals, first {:?}",
        sol.stations(),
        v.worst[0].acceleration,
        v.worst[1].acceleration,
        v.violating_intervals,
        v.violations.first()
    );
    // (About 3 %: the geometry now inserts knots where the curve would leave the chords by
    // more than their allowance, and so stations; 6.6 % before.)
    assert!(worst > 1.01, "worst acceleration ratio {worst}");
    assert!(!v.verified);
    let first = &v.violations[0];
    assert_eq!((first.kind, first.axis), (Quantity::Acceleration, Some(1)));
    // Near the vertex (u is about arc length; the vertex is at mid-path).
    let mid = sol.path.spans[0].length() / 2.0;
    assert!(
        (first.u - mid).abs() < 2.0 * h,
        "{first:?} vs vertex at u ≈ {mid}"
    );
    // The default refinement subdivides the segments and verifies.
    let fine = solve(
        &m,
        &tp,
        &Options {
            stations: None,
            ..options
        },
    );
    let v = check(&m, &fine, &VerifyOptions::default());
    eprintln!(
        "refined parabola: {} stations, worst {:.5}",
        fine.stations(),
        v.worst_ratio()
    );
    assert!(v.verified, "{:?}", v.violations.first());
}

#[test]
fn halving_the_period_doubles_the_samples() {
    let m = machine(XYZ_2000);
    let sol = solve(
        &m,
        &toolpath(&circle(20.0, 2, 120), Some(150.0)),
        &Options::default(),
    );
    let coarse = check(
        &m,
        &sol,
        &VerifyOptions {
            period: 2e-3,
            ..Default::default()
        },
    );
    let fine = check(&m, &sol, &VerifyOptions::default());
    let spans = sol.problems.len() as f64;
    let t = sol.schedule.cycle_time;
    assert!((coarse.samples as f64 - t / 2e-3).abs() <= 2.0 * spans);
    assert!((fine.samples as f64 - t / 1e-3).abs() <= 2.0 * spans);
    let ratio = fine.samples as f64 / coarse.samples as f64;
    assert!((ratio - 2.0).abs() < 0.01, "{ratio}");
    assert_eq!(coarse.station_checks, fine.station_checks);
    // The schedule is verified at either period.
    assert!(fine.verified && coarse.verified);
}

#[test]
fn the_pipeline_splits_intervals_until_the_schedule_verifies() {
    // The coarse circle of the test above, with the default: refine until verified. The grid
    // the user asked for stays, stations are added only where the check failed. (ü constant
    // per interval, whose rows leave slack at one end of each: the excess is at the circle's
    // tightest points only. Under the linear-ü law both ends are on the limit all round this
    // circle, which runs at its acceleration limit everywhere, and most intervals are divided.)
    let m = machine(XYZ_2000);
    let coarse = Options {
        stations: Some(20),
        ramp: Ramp::Constant,
        ..Options::default()
    };
    let sol = solve(&m, &toolpath(&circle(10.0, 3, 37), None), &coarse);
    assert!(
        sol.verification.verified,
        "{:?}",
        sol.verification.violations.first()
    );
    assert!(sol.verification.worst_ratio() <= 1.001);
    assert!(sol.stations() > 3 * 37 + 1, "stations were added");
    assert!(sol.stations() < 2 * (3 * 37 + 1), "only where needed");
    // Every CL point is still a station.
    let u: Vec<f64> = sol.problems[0].u.clone();
    for knot in sol.path.spans[0].spline.knots() {
        assert!(u.iter().any(|x| (x - knot).abs() < 1e-12));
    }
}

/// The re-simulation checks chunks of intervals in parallel: the same samples, worst ratios and
/// violations (in the same order) on one thread as on three.
#[test]
fn the_result_does_not_depend_on_the_threads() {
    let m = machine(XYZ_2000);
    let mut sol = solve(
        &m,
        &toolpath(&circle(20.0, 2, 120), Some(150.0)),
        &Options {
            stations: Some(3000),
            ..Options::default()
        },
    );
    assert!(sol.problems.iter().any(|p| p.intervals() > 1500));
    tamper(&mut sol, 1.02);
    let on = |threads| {
        check(
            &m,
            &sol,
            &VerifyOptions {
                threads,
                ..Default::default()
            },
        )
    };
    let one = on(1);
    assert!(!one.verified && one.violating_intervals > 10);
    assert_eq!(one, on(3));
    assert_eq!(one, on(0));
}

/// Where the local refinement has not settled within its rounds, the spans still over a limit
/// are slowed down instead, each by the least factor that keeps its limits (velocity as 1/f,
/// acceleration as 1/f², jerk as 1/f³): the schedule returned verifies and says so in
/// `slowed_down`. Here with no rounds at all, on the coarse circle of the tests above, whose
/// grid exceeds the acceleration limits between stations; slowing a span down by f
/// multiplies each of its intervals' times by f exactly.
#[test]
fn spans_the_refinement_has_not_settled_are_slowed_down_until_they_verify() {
    let m = machine(XYZ_2000);
    let tp = toolpath(&circle(10.0, 3, 37), None);
    let coarse = Options {
        stations: Some(20),
        local_rounds: 0,
        ..Options::default()
    };
    let sol = solve(&m, &tp, &coarse);
    assert!(
        sol.verification.verified,
        "{:?}",
        sol.verification.violations.first()
    );
    let why = sol.slowed_down.as_deref().expect("spans were slowed down");
    assert!(why.contains("slower instead"), "{why}");
    // Against the refined answer: slower, by the excess the coarse grid had between stations.
    let refined = solve(
        &m,
        &tp,
        &Options {
            stations: Some(20),
            ..Options::default()
        },
    );
    assert!(refined.slowed_down.is_none());
    let (t, r) = (sol.schedule.cycle_time, refined.schedule.cycle_time);
    eprintln!("{why}: {t} s against {r} s refined");
    assert!(t >= r && t <= 1.1 * r, "{t} vs {r}");
    // Slowing down is exact: every interval takes f times as long.
    let (p, s) = (&refined.problems[0], &refined.solutions[0]);
    let before = feedopt::solver::interval_times(p, s).unwrap();
    let mut slow = s.clone();
    slow.slow_down(1.25);
    let after = feedopt::solver::interval_times(p, &slow).unwrap();
    for (a, b) in after.iter().zip(&before) {
        assert!(
            (a - 1.25 * b).abs() <= 1e-12 * b.max(1e-9),
            "{a} vs 1.25 × {b}"
        );
    }
}

/// A turn of the table alone at F is held to its rate of turn, and the re-simulation checks
/// that rate as it checks the feed (in °/s): the schedule run 5 % faster (b × 1.1025) turns
/// 5 % over F, a feed violation with no axis, while B's velocity limit, far above, holds.
#[test]
fn a_turn_alone_run_too_fast_exceeds_its_rate_of_turn() {
    let m = machine(
        r#"{"name": "4-axis", "kinematics": {"type": "xyzb"},
            "axes": {"X": {"velocity": 500, "acceleration": 3000},
                     "Y": {"velocity": 500, "acceleration": 3000},
                     "Z": {"velocity": 500, "acceleration": 3000},
                     "B": {"velocity": 100, "acceleration": 500, "min": -720, "max": 720}}}"#,
    );
    let text = "G21 G90 G94\nG1 X0 Y0 Z0 B0 F600\nG1 B90\nM2\n";
    let ctx = feedopt::toolpath::MachineContext::new(&m, &feedopt::machine::References::default());
    let t = feedopt::toolpath::gcode::parse_for(
        std::path::Path::new("turn.ngc"),
        text,
        feedopt::toolpath::gcode::Dialect::LinuxCnc.spec(),
        Some(&ctx),
    )
    .expect("reads");
    let mut sol = solve(&m, &t, &Options::default());
    // 90° at 600 °/min = 10 °/s: 9 s and v/a.
    let want = 9.0 + 10.0 / 500.0;
    assert!((sol.schedule.cycle_time - want).abs() < 1e-4 * want);
    let v = check(&m, &sol, &VerifyOptions::default());
    assert!(v.verified, "{:?}", v.violations.first());
    tamper(&mut sol, 1.05 * 1.05);
    let v = check(&m, &sol, &VerifyOptions::default());
    assert!(!v.verified);
    // (The ramps' acceleration, 10 % over, is the worst; on the plateau the rate of turn.)
    let feed: Vec<_> = v
        .violations
        .iter()
        .filter(|x| x.kind == Quantity::Feed)
        .collect();
    assert!(!feed.is_empty(), "{:?}", v.violations);
    assert!(feed.iter().all(|x| x.axis.is_none()));
    let worst = feed[0];
    assert!((worst.ratio - 1.05).abs() < 2e-3, "{worst:?}");
    assert!((worst.limit - 10.0).abs() < 1e-9, "{worst:?}");
    assert!((v.worst_feed - 1.05).abs() < 2e-3, "{}", v.worst_feed);
    assert!(v.worst[3].velocity < 0.2, "{:?}", v.worst[3]);
}
