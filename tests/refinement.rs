//! The adaptive station refinement (issue 11): closed forms, the error estimate, the station
//! count, and the final solve against an all-Clarabel solve on the same grid.

use std::path::Path;

use feedopt::machine::Machine;
use feedopt::optimize::{Options, Solution, optimize, optimize_input};
use feedopt::solver::interval_times;
use feedopt::solver::{SolverKind, SolverSettings, clarabel};
use feedopt::toolpath;
use nalgebra::Vector3;

mod common;
use common::{UP, machine, toolpath};

const XYZ: &str = r#"{"name": "xyz", "kinematics": {"type": "xyz"},
    "axes": {"X": {"velocity": 500, "acceleration": 3000},
             "Y": {"velocity": 500, "acceleration": 3000},
             "Z": {"velocity": 500, "acceleration": 3000}},
    "feed": {"max": 500}}"#;

/// 400 zig-zag moves of √25.25 mm at 1 mm/s (`G1 X5 Y0.5 F60`, `G1 X0 Y1 F60`, …): every
/// corner turns by 168°, so every move is a rest-to-rest span whose ramps (1/6000 mm) are far
/// shorter than any interval a uniform grid would give it.
fn zigzag() -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let mut pts = vec![(Vector3::zeros(), UP)];
    for i in 0..400 {
        let x = if i % 2 == 0 { 5.0 } else { 0.0 };
        pts.push((Vector3::new(x, 0.5 * (i + 1) as f64, 0.0), UP));
    }
    pts
}

#[test]
fn zigzag_converges_to_its_closed_form_in_few_stations() {
    let m = machine(XYZ);
    let t = toolpath(&zigzag(), Some(1.0));
    let sol = optimize(&m, &t, &Options::default()).expect("solves");
    // Rest to rest along a line of length L at feed V under tip acceleration A (V²/A ≪ L): a
    // ramp of V/A s each end, so L/V + V/A per move. X, moving 5 mm of every L = √25.25 mm,
    // reaches its 3000 mm/s² first: A = 3000 L / 5.
    let l = 25.25f64.sqrt();
    let (v, a) = (1.0, 3000.0 * l / 5.0);
    let exact = 400.0 * (l / v + v / a);
    let time = sol.schedule.cycle_time;
    let err = (time - exact).abs() / exact;
    assert!(err < 1e-8, "T {time} vs closed form {exact}: {err:e}");
    let est = sol
        .error_estimate
        .expect("automatic refinement gives an estimate");
    assert!(est <= 1e-4, "estimate {est:e}");
    assert!(sol.stations() <= 20_000, "{} stations", sol.stations());
    assert!(sol.verification.verified);
}

/// A ramp within a long straight move: the error estimate bounds the true error, which the
/// closed form gives (rest to rest at the acceleration limit, feed capped).
#[test]
fn the_error_estimate_bounds_the_true_error() {
    let m = machine(XYZ);
    for (len, feed) in [(100.0, 400.0), (10.0, 100.0), (0.5, 200.0)] {
        let pts = [(Vector3::zeros(), UP), (Vector3::new(len, 0.0, 0.0), UP)];
        let t = toolpath(&pts, Some(feed));
        let sol = optimize(&m, &t, &Options::default()).expect("solves");
        let a: f64 = 3000.0;
        // Triangle if the feed cannot be reached, else trapezoid.
        let exact = if feed * feed / a >= len {
            2.0 * (len / a).sqrt()
        } else {
            len / feed + feed / a
        };
        let time = sol.schedule.cycle_time;
        let err = (time - exact).abs() / exact;
        let est = sol.error_estimate.expect("estimate");
        assert!(
            err <= est.max(1e-12) && est <= 1e-4,
            "L {len} F {feed}: T {time} vs {exact} ({err:e}), estimate {est:e}"
        );
    }
}

/// The convex program's objective at profile `b` on stations `u`: eq. 43 with b linear between
/// stations.
fn chord_time(u: &[f64], b: &[f64]) -> f64 {
    feedopt::motion::interval_times(u, b, Default::default())
        .expect("finite")
        .iter()
        .sum()
}

/// The total time of a solution recomputed from its profiles (eq. 43).
fn time_of(sol: &Solution) -> f64 {
    sol.problems
        .iter()
        .zip(&sol.solutions)
        .map(|(p, s)| interval_times(p, s).expect("finite").iter().sum::<f64>())
        .sum()
}

/// The default answer (lattice relaxation where it is exact, Clarabel on the windows where it
/// is not) equals Clarabel run on every span in one piece, with every row from the start (no
/// constraint generation), on the same final stations.
#[test]
fn default_answer_equals_all_clarabel_on_the_same_grid() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let mut used_clarabel = false;
    let mut exact_somewhere = false;
    for (m, t) in [
        ("xyz_pocket/machine.json", "xyz_pocket/pocket_contour.cls"),
        (
            "seed_head_head/machine.json",
            "seed_head_head/impeller_blade.cls",
        ),
    ] {
        let machine = Machine::from_file(&root.join(m)).expect("machine");
        let input = toolpath::read_input(&root.join(t)).expect("toolpath");
        let sol = optimize_input(&machine, &input, &Options::default()).expect("solves");
        let settings = SolverSettings {
            window: usize::MAX,
            tol_gap: 1e-8,
            ..SolverSettings::default()
        };
        let (mut all_clarabel, mut objective) = (0.0, [0.0; 2]);
        for (p, s) in sol.problems.iter().zip(&sol.solutions) {
            let (c, _) = clarabel::solve_rows(p, &settings, clarabel::Rows0::Every)
                .expect("Clarabel solves the span");
            all_clarabel += interval_times(p, &c).expect("finite").iter().sum::<f64>();
            for (o, x) in objective.iter_mut().zip([&s.b, &c.b]) {
                *o += chord_time(&p.u, x);
            }
            used_clarabel |= s.iterations > 0;
            exact_somewhere |= s.iterations == 0 && p.intervals() > 10;
        }
        let default = time_of(&sol);
        let rel = (default - all_clarabel).abs() / all_clarabel;
        let rel_objective = (objective[0] - objective[1]).abs() / objective[1];
        eprintln!("{t}: time {rel:e}, objective {rel_objective:e}");
        // Both solve the same program (its objective: eq. 43 with b linear between stations;
        // the motion's time, ü linear between stations, differs from it by O(Δu³) an
        // interval). All-Clarabel runs to a relative gap of 1e-8: at its default 1e-6 it
        // stopped 2.1e-6 above the default answer on the seed blade, whose windows and exact
        // lattice parts are closer to the optimum than that.
        assert!(
            rel_objective <= 1e-6 && rel <= 1e-6,
            "{t}: default {default} vs all-Clarabel {all_clarabel}: {rel:e} (objective \
             {} vs {}: {rel_objective:e})",
            objective[0],
            objective[1]
        );
    }
    // Both ways of the final solve were exercised.
    assert!(used_clarabel && exact_somewhere);
}

/// Clarabel's constraint generation (`solver::clarabel`), from the rows near the reachability
/// profile or from the velocity rows alone (more rounds), gives the time and the sensitivities
/// of the program with every row, on every span of the bundled blade (to a gap of 1e-9, so
/// that two solves of the same optimum agree well inside the 1e-6 checked).
#[test]
fn generated_rows_give_the_whole_program() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let machine = Machine::from_file(&root.join("seed_head_head/machine.json")).expect("machine");
    let input = toolpath::read_input(&root.join("seed_head_head/impeller_blade.cls")).expect("tp");
    let sol = optimize_input(&machine, &input, &Options::default()).expect("solves");
    let settings = SolverSettings {
        tol_gap: 1e-9,
        ..SolverSettings::default()
    };
    assert!(!sol.problems.is_empty());
    for p in &sol.problems {
        let time = |s: &feedopt::solver::SpanSolution| -> f64 {
            interval_times(p, s).expect("finite").iter().sum()
        };
        let (every, se) =
            clarabel::solve_rows(p, &settings, clarabel::Rows0::Every).expect("solves");
        for first in [clarabel::Rows0::NearReach, clarabel::Rows0::Velocity] {
            let (got, sg) = clarabel::solve_rows(p, &settings, first).expect("solves");
            let rel = (time(&got) - time(&every)).abs() / time(&every);
            assert!(rel <= 1e-6, "{first:?}: time differs by {rel:e}");
            for (a, b) in sg.acceleration.iter().zip(&se.acceleration) {
                let d = (a.max - b.max).abs() + (a.min - b.min).abs();
                let s = b.max.abs() + b.min.abs();
                assert!(d <= 1e-3 * s + 1e-9, "{first:?}: dT/da {a:?} vs {b:?}");
            }
            // dT/dμ for every velocity bound scaled by μ: Σ dT/db_max_i · b_max_i (the
            // stations fixed on their bound take theirs through the cones).
            let dmu = |s: &clarabel::Sensitivity| -> f64 {
                (1..p.intervals())
                    .filter(|&i| p.b_max[i].is_finite())
                    .map(|i| s.b_max[i] * p.b_max[i])
                    .sum()
            };
            let (g, e) = (dmu(&sg), dmu(&se));
            assert!(
                (g - e).abs() <= 1e-3 * e.abs() + 1e-9,
                "{first:?}: dT/dμ of the velocity bounds {g} vs {e}"
            );
        }
    }
    // Without velocity bounds, a first program of the velocity rows alone has no row at all
    // and leaves b unbounded above: its solution breaks the acceleration rows, which join
    // (had Clarabel failed on it, every row would have: the same answer either way).
    let mut p = sol
        .problems
        .iter()
        .max_by_key(|p| p.intervals())
        .unwrap()
        .clone();
    let n = p.intervals();
    p.b_max[1..n].fill(f64::INFINITY);
    let time = |s: &feedopt::solver::SpanSolution| -> f64 {
        interval_times(&p, s).expect("finite").iter().sum()
    };
    let (every, _) = clarabel::solve_rows(&p, &settings, clarabel::Rows0::Every).expect("solves");
    let (got, _) = clarabel::solve_rows(&p, &settings, clarabel::Rows0::Velocity).expect("solves");
    let rel = (time(&got) - time(&every)).abs() / time(&every);
    assert!(
        rel <= 1e-6,
        "unbounded first program: time differs by {rel:e}"
    );
}

/// A fixed grid (`stations`) is solved as given, without an estimate; the reach solver on the
/// same stations is never faster than the default.
#[test]
fn fixed_grid_has_no_estimate_and_reach_is_not_faster() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let machine = Machine::from_file(&root.join("xyz_pocket/machine.json")).expect("machine");
    let input = toolpath::read_input(&root.join("xyz_pocket/pocket_contour.cls")).expect("tp");
    let fixed = |kind| Options {
        stations: Some(3000),
        solver_kind: kind,
        refine_until_verified: false,
        ..Options::default()
    };
    let c = optimize_input(&machine, &input, &fixed(SolverKind::Clarabel)).expect("solves");
    let r = optimize_input(&machine, &input, &fixed(SolverKind::Reach)).expect("solves");
    assert!(c.error_estimate.is_none());
    assert_eq!(c.stations(), r.stations());
    assert!(r.schedule.cycle_time >= c.schedule.cycle_time * (1.0 - 1e-7));
}

/// The LinuxCNC impeller (4,503 lines, 197 spans) by default: within 2e-4 of its converged
/// cycle time (1173.2516 s, uniform refinement to 1.38 M stations), on a grid that grows with
/// its features (tens of thousands of stations, not millions).
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn linuxcnc_impeller_by_default() {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/linuxcnc");
    let machine =
        Machine::from_file(&d.join("impeller-7bl-xyzac.machine.json")).expect("machine file");
    let input = toolpath::read_input(&d.join("impeller-7bl-xyzac.ngc")).expect("program");
    let sol = optimize_input(&machine, &input, &Options::default()).expect("solves");
    let t = sol.schedule.cycle_time;
    let rel = (t - 1173.2516).abs() / 1173.2516;
    assert!(rel <= 2e-4, "T {t}: {rel:e}");
    assert!(sol.error_estimate.expect("estimate") <= 1e-4);
    assert!(sol.stations() < 100_000, "{} stations", sol.stations());
    assert!(sol.verification.verified);
}

/// The station limit ends the refinement with the last round's answer, verified, its estimate
/// and why it is above the target — not an error that leaves the user nothing (a 64,698-line
/// hyperMILL finish stopped so at 1.1e-4 with 2.7 M stations).
#[test]
fn the_station_limit_returns_the_last_round_with_its_estimate() {
    let m = machine(XYZ);
    // One and a half turns of radius 10 mm in 200 chords, drifting 4 mm along X, at 500 mm/s:
    // the curvature holds the feed down everywhere, and the refinement takes four rounds.
    let pts: Vec<_> = (0..=200)
        .map(|i| {
            let a = 3.0 * std::f64::consts::PI * i as f64 / 200.0;
            let p = Vector3::new(10.0 * a.cos() + 0.02 * i as f64, 10.0 * a.sin(), 0.0);
            (p, UP)
        })
        .collect();
    // (ü constant per interval: its first-order error takes rounds to converge on this
    // curve; with ü linear, the default, the first round is within the target.)
    let t = toolpath(&pts, Some(500.0));
    let constant = Options {
        ramp: feedopt::constraints::Ramp::Constant,
        ..Options::default()
    };
    let free = optimize(&m, &t, &constant).expect("solves");
    assert!(free.unconverged.is_none(), "{:?}", free.unconverged);
    let first = free.refinement[0].stations;
    assert!(free.refinement.len() >= 2, "{:?}", free.refinement);
    // A limit the first round's refinement would pass.
    let capped = Options {
        max_stations: 2 * first - 1,
        ..constant.clone()
    };
    let sol = optimize(&m, &t, &capped).expect("returns the last round");
    let (est, target) = (
        sol.error_estimate.expect("estimate"),
        sol.error_target.expect("target"),
    );
    let why = sol.unconverged.as_deref().expect("says why it stopped");
    assert!(est > target, "estimate {est:e}, target {target:e}");
    assert!(
        why.contains(&format!("{} stations", 2 * first - 1)),
        "{why}"
    );
    assert!(sol.verification.verified);
    assert_eq!(sol.refinement.len(), 1, "{:?}", sol.refinement);
    // The estimate bounds its distance from the converged time.
    let (tc, tf) = (sol.schedule.cycle_time, free.schedule.cycle_time);
    assert!(
        (tc - tf).abs() / tf <= est,
        "{tc} vs {tf}, estimate {est:e}"
    );
}

/// A window of the final solve is left on the feasible reach profile only with a certificate:
/// the lattice relaxation's time (a lower bound on the window's optimum) within Clarabel's own
/// relative gap of the profile's. On a serpentine of 20 mm lines and R5 half circles at 200
/// mm/s (the half circles limit the speed to √(3000·5) ≈ 122 mm/s; at each crest X's or Y's
/// velocity crosses zero and the relaxation leaves rows out, as on hyperMILL's finishing
/// paths), every span whose relaxation breaks a row and that took no interior-point iteration
/// lies within that gap of its lower bound, and the default answer stays within 1e-6 of
/// Clarabel on every span in one piece.
#[test]
fn windows_left_on_the_reach_profile_carry_a_certificate() {
    use feedopt::solver::{Status, optimal, reach};
    let m = machine(XYZ);
    let mut pts = vec![(Vector3::zeros(), UP)];
    for i in 0..6 {
        let d = if i % 2 == 0 { 1.0 } else { -1.0 };
        let (x0, y0) = (pts.last().unwrap().0.x, pts.last().unwrap().0.y);
        for k in 1..=40 {
            pts.push((Vector3::new(x0 + d * 0.5 * k as f64, y0, 0.0), UP));
        }
        let (cx, cy) = (x0 + d * 20.0, y0 + 5.0);
        for k in 1..=30 {
            let th = -std::f64::consts::FRAC_PI_2 + d * std::f64::consts::PI * k as f64 / 30.0;
            pts.push((
                Vector3::new(cx + 5.0 * d * th.cos(), cy + 5.0 * th.sin(), 0.0),
                UP,
            ));
        }
    }
    let t = toolpath(&pts, Some(200.0));
    // ü constant per interval: its rows at a crest are the ones the relaxation leaves out.
    // (With ü linear, the default, the axis turning round there bounds b alone, and every
    // span of this path is exact on its relaxation.)
    let options = Options {
        ramp: feedopt::constraints::Ramp::Constant,
        ..Options::default()
    };
    let sol = optimize(&m, &t, &options).expect("solves");
    let settings = SolverSettings::default();
    let every = SolverSettings {
        window: usize::MAX,
        ..SolverSettings::default()
    };
    let time = |p, b: &feedopt::solver::SpanSolution| -> f64 {
        interval_times(p, b).expect("finite").iter().sum()
    };
    let (mut certified, mut solved) = (0, 0);
    for p in &sol.problems {
        let greedy = reach::solve(p).expect("feasible");
        let relaxed = reach::solve_lattice(p).expect("feasible");
        if reach::lattice_violations(p, &relaxed.b, 1e-9).is_empty() {
            continue;
        }
        let s = optimal(p, &greedy, &settings).expect("solves");
        let (c, _) = clarabel::solve_rows(p, &every, clarabel::Rows0::Every).expect("solves");
        let (ts, tc, lower) = (time(p, &s), time(p, &c), time(p, &relaxed));
        assert!(lower <= ts * (1.0 + 1e-12), "{lower} > {ts}");
        // (Clarabel stops within its gap of the optimum: a solved window may end a little
        // slower than the reach profile.)
        assert!(ts <= time(p, &greedy) * (1.0 + settings.tol_gap));
        assert!((ts - tc).abs() <= 1e-6 * tc, "{ts} vs all-Clarabel {tc}");
        if s.iterations == 0 && s.status == Status::Optimal {
            assert!(ts - lower <= settings.tol_gap * ts, "{ts} vs {lower}");
            certified += 1;
        } else {
            solved += 1;
        }
    }
    assert!(
        certified > 0,
        "no span left on a certified reach profile ({solved} solved)"
    );
}

/// A curve held down by its axes' accelerations: y = u, z = 2 sin(u/3) for u in 0…60 mm, in
/// chords of 0.25 mm, on the machine's limits alone (no programmed feed).
fn sine() -> feedopt::toolpath::Toolpath {
    let pts: Vec<_> = (0..=240)
        .map(|i| {
            let y = 0.25 * i as f64;
            (Vector3::new(0.0, y, 2.0 * (y / 3.0).sin()), UP)
        })
        .collect();
    toolpath(&pts, None)
}

/// The cause of the first-order convergence on curves, and its cure: with ü constant per
/// interval the time lost on every acceleration ramp along a curve is of first order in Δu
/// (each halving of a uniform grid halves the change of T), with ü linear between the ends of
/// each interval of second order (each halving quarters it). Both tend to the same T. (The
/// grids divide each of the 240 chords into 2, 4, 8 and 16 equal parts.)
#[test]
fn linear_ramps_converge_at_second_order_on_a_curve() {
    use feedopt::constraints::Ramp;
    let m = machine(XYZ);
    let t = sine();
    let times = |ramp: Ramp| -> Vec<f64> {
        [480, 960, 1920, 3840]
            .iter()
            .map(|&n| {
                let o = Options {
                    stations: Some(n),
                    refine_until_verified: false,
                    ramp,
                    ..Options::default()
                };
                optimize(&m, &t, &o).expect("solves").schedule.cycle_time
            })
            .collect()
    };
    // The change of T over the first halving against that over the third: 2² = 4 at first
    // order, 4² = 16 at second (one halving alone is noisier: 3.1 and 4.9 for the linear law).
    let fall = |t: &[f64]| (t[0] - t[1]) / (t[2] - t[3]);
    let (constant, linear) = (times(Ramp::Constant), times(Ramp::Linear));
    let (fc, fl) = (fall(&constant), fall(&linear));
    eprintln!("constant ü: T {constant:?}, fall {fc}\nlinear ü: T {linear:?}, fall {fl}");
    assert!((2.5..6.0).contains(&fc), "constant ü: first order, {fc}");
    assert!(fl > 10.0, "linear ü: second order, {fl}");
    // Richardson's limits of the two agree.
    let limit_c = 2.0 * constant[3] - constant[2];
    let limit_l = (4.0 * linear[3] - linear[2]) / 3.0;
    assert!(
        ((limit_c - limit_l) / limit_l).abs() < 2e-5,
        "{limit_c} vs {limit_l}"
    );
    // At 3,200 intervals the linear law is closer to that limit than the constant law.
    assert!((linear[3] - limit_l).abs() < 0.1 * (constant[3] - limit_l).abs());
}

/// The automatic refinement on the curve: the linear-ü law needs a few thousand stations, the
/// constant-ü law many times more, and every schedule verifies at 1 ms.
#[test]
fn the_curve_converges_in_few_stations() {
    use feedopt::constraints::Ramp;
    let m = machine(XYZ);
    let t = sine();
    let run = |ramp: Ramp| {
        let o = Options {
            ramp,
            ..Options::default()
        };
        optimize(&m, &t, &o).expect("solves")
    };
    let (c, l) = (run(Ramp::Constant), run(Ramp::Linear));
    eprintln!(
        "constant ü: {} stations, T {}; linear ü: {} stations, T {}",
        c.stations(),
        c.schedule.cycle_time,
        l.stations(),
        l.schedule.cycle_time
    );
    for s in [&c, &l] {
        assert!(s.verification.verified && s.unconverged.is_none());
        assert!(s.error_estimate.expect("estimate") <= 1e-4);
    }
    assert!(l.stations() < 5_000, "{} stations", l.stations());
    assert!(3 * l.stations() < c.stations());
    // Within their estimates of each other.
    let rel = (c.schedule.cycle_time - l.schedule.cycle_time).abs() / l.schedule.cycle_time;
    assert!(rel <= 2e-4, "{rel:e}");
    // ü at the ends of every interval meets every axis's rows there, and b stays above a
    // quarter of its ends' mean inside (the control point of the quadratic).
    for (p, s) in l.problems.iter().zip(&l.solutions) {
        let ends = s.ends.as_ref().expect("linear-ü profile");
        for (k, e) in ends.iter().enumerate() {
            for (i, a) in [(k, e[0]), (k + 1, e[1])] {
                let (lo, hi) = p.udd_range(i, s.b[i]);
                let slack = 1e-9 * (lo.abs() + hi.abs()).max(1.0);
                assert!(
                    a >= lo - slack && a <= hi + slack,
                    "interval {k}: {a} in {lo}…{hi}"
                );
            }
            let mean = 0.5 * (s.b[k] + s.b[k + 1]);
            assert!(s.b[k] + p.du(k) * e[0] >= 0.5 * mean * (1.0 - 1e-9));
        }
    }
}
