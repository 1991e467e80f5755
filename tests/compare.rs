//! `feedopt compare`: the baselines against closed forms (a straight line, a square with 90°
//! corners), the common re-simulation, and the acceptance test on the LinuxCNC impeller.

mod common;

use std::path::Path;
use std::process::Command;

use feedopt::compare::baseline::{self, junction_speed};
use feedopt::compare::{CompareOptions, Comparison, compare};
use feedopt::machine::Machine;
use feedopt::optimize;
use feedopt::solver::SolverKind;
use feedopt::toolpath::{self, Input};
use nalgebra::Vector3;

/// X: 400 mm/s, 2000 mm/s²; Y: 100 mm/s, 500 mm/s²: on a diagonal move Y binds.
const XYZ: &str = r#"{"name": "test mill", "kinematics": {"type": "xyz"},
  "axes": {"X": {"velocity": 400, "acceleration": 2000},
           "Y": {"velocity": 100, "acceleration": 500},
           "Z": {"velocity": 300, "acceleration": 1500}},
  "feed": {"max": 150}}"#;

/// Equal X and Y limits, for the square.
const SQUARE_MILL: &str = r#"{"name": "square mill", "kinematics": {"type": "xyz"},
  "axes": {"X": {"velocity": 200, "acceleration": 1000},
           "Y": {"velocity": 200, "acceleration": 1000},
           "Z": {"velocity": 200, "acceleration": 1000}},
  "feed": {"max": 150}}"#;

const PERIOD: f64 = 1e-3;

fn options(stations: usize) -> CompareOptions {
    let mut o = CompareOptions::default();
    o.solve.stations = Some(stations);
    o.solve.solver_kind = SolverKind::Reach;
    o.solve.geometry.tolerance_mm = 0.0;
    o
}

fn run(
    machine: &Machine,
    points: &[Vector3<f64>],
    feed: Option<f64>,
    o: &CompareOptions,
) -> Comparison {
    let pts: Vec<_> = points.iter().map(|p| (*p, common::UP)).collect();
    let input = Input::Cl(common::toolpath(&pts, feed));
    compare(machine, &input, "test", o).expect("compare")
}

#[test]
fn straight_line_controller_is_the_exact_trapezoid_and_equals_feedopt() {
    let m = common::machine(XYZ);
    let (dx, dy) = (100.0f64, 50.0f64);
    let l = dx.hypot(dy);
    let (cx, cy) = (dx / l, dy / l);
    // Velocity and acceleration along the line: the most restrictive axis, and the feed cap.
    let v = (400.0 / cx).min(100.0 / cy).min(150.0);
    let a = (2000.0 / cx).min(500.0 / cy);
    assert!(l > v * v / a, "the trapezoid has a cruise phase");
    let exact = l / v + v / a;

    let cmp = run(
        &m,
        &[Vector3::zeros(), Vector3::new(dx, dy, 0.0)],
        None,
        &options(400),
    );
    let b = cmp.row("controller").expect("controller row");
    let c = cmp.row("feedopt").expect("feedopt row");
    assert!(
        (b.cycle_time_s - exact).abs() < 1e-9 * exact,
        "controller {} vs closed form {exact}",
        b.cycle_time_s
    );
    assert!(
        b.verified,
        "the exact trapezoid keeps every limit: {}",
        b.worst_ratio
    );
    // Y binds both velocity (100/cy = 223.6 > 150: no, the feed) and acceleration.
    let y = &b.axes[1];
    assert!(
        (y.acceleration - 1.0).abs() < 1e-6,
        "Y acceleration ratio {}",
        y.acceleration
    );
    assert!((b.worst_feed_ratio - 1.0).abs() < 1e-6);
    // feedopt's discrete optimum is the same profile to O(Δu²).
    assert!(
        (c.cycle_time_s - exact).abs() < 1e-3 * exact,
        "feedopt {} vs exact {exact}",
        c.cycle_time_s
    );
    assert!(c.verified);

    // (a): constant 150 mm/s, from and to rest within one period each: T/2 lost at each end,
    // and the ramp's acceleration F/T along the line.
    let p = cmp.row("programmed").expect("programmed row");
    let f = 150.0;
    assert!(
        (p.cycle_time_s - (l / f + PERIOD)).abs() < 1e-9,
        "programmed {} vs {}",
        p.cycle_time_s,
        l / f + PERIOD
    );
    let ax = f / PERIOD * cx / 2000.0;
    let ay = f / PERIOD * cy / 500.0;
    assert!(
        (p.axes[0].acceleration - ax).abs() < 1e-6 * ax,
        "{}",
        p.axes[0].acceleration
    );
    assert!((p.axes[1].acceleration - ay).abs() < 1e-6 * ay);
    assert!(!p.verified);
    assert_eq!(p.worst_limit, "Y acceleration");
}

#[test]
fn square_corners_pass_at_the_junction_deviation_speed() {
    let m = common::machine(SQUARE_MILL);
    let side = 100.0;
    let pts = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(side, 0.0, 0.0),
        Vector3::new(side, side, 0.0),
        Vector3::new(0.0, side, 0.0),
        Vector3::new(0.0, 0.0, 0.0),
    ];
    let delta = 0.05;
    let mut o = options(400);
    o.junction_deviation = delta;
    let cmp = run(&m, &pts, Some(100.0), &o);

    // 90° corner: θ = 90° between the reversed incoming and the outgoing direction; the
    // junction vector (−1, 1)/√2 lets the tip accelerate a·√2 before X or Y reaches a.
    let a = 1000.0;
    let s = (45f64).to_radians().sin();
    let vj = (a * 2f64.sqrt() * delta * s / (1.0 - s)).sqrt();
    assert!(vj < 100.0, "the junction, not the feed, limits the corner");
    assert!((junction_speed(0.0, a * 2f64.sqrt(), delta) - vj).abs() < 1e-12);
    assert_eq!(junction_speed(1.0, a, delta), f64::INFINITY, "straight on");
    assert_eq!(junction_speed(-1.0, a, delta), 0.0, "reversal");

    // The plan itself: three corners at v_j, rest at both ends.
    let input = Input::Cl(common::toolpath(
        &pts.iter().map(|p| (*p, common::UP)).collect::<Vec<_>>(),
        Some(100.0),
    ));
    let Input::Cl(tp) = &input else {
        unreachable!()
    };
    let sol = optimize::optimize(&m, tp, &o.solve).expect("solve");
    let plan = baseline::plan_controller(&m, &sol.path, &sol.kinematics, delta).expect("plan");
    assert_eq!(plan.blocks.len(), 4);
    assert_eq!(plan.blocks[0].entry, 0.0);
    assert_eq!(plan.blocks[3].exit, 0.0);
    for k in 1..4 {
        assert!(
            (plan.blocks[k].entry - vj).abs() < 1e-9 * vj,
            "corner {k}: {} vs {vj}",
            plan.blocks[k].entry
        );
    }
    // Each side in closed form: accelerate at a (one axis moves) from v0 to 100, cruise,
    // brake to v1.
    let side_time = |v0: f64, v1: f64| {
        let f = 100.0;
        let (x1, x2) = ((f * f - v0 * v0) / (2.0 * a), (f * f - v1 * v1) / (2.0 * a));
        (f - v0) / a + (f - v1) / a + (side - x1 - x2) / f
    };
    let expected = side_time(0.0, vj) + 2.0 * side_time(vj, vj) + side_time(vj, 0.0);
    assert!((plan.time() - expected).abs() < 1e-9 * expected);

    // The common re-simulation integrates the same profile: the same time.
    let b = cmp.row("controller").unwrap();
    assert!(
        (b.cycle_time_s - expected).abs() < 1e-9 * expected,
        "re-simulated {} vs planned {expected}",
        b.cycle_time_s
    );
    // Passing a 90° corner at v_j swaps one axis's velocity v_j for the other's within a
    // servo period: an acceleration v_j / T on both axes.
    assert_eq!(b.corners_at_speed, 3);
    let jump = vj / PERIOD / a;
    assert!(
        (b.worst_corner_ratio - jump).abs() < 1e-6 * jump,
        "corner jump {} vs {jump}",
        b.worst_corner_ratio
    );
    assert!(!b.verified);
    // feedopt stops at each corner (a rest-to-rest span each side), so it is slower than the
    // controller here, and keeps every limit.
    let c = cmp.row("feedopt").unwrap();
    assert_eq!(c.corners_at_speed, 0);
    assert!(c.verified);
    assert!(c.cycle_time_s > b.cycle_time_s);
    // With a zero junction deviation the controller stops too: then it is the exact optimum,
    // and feedopt matches it.
    let mut o0 = options(400);
    o0.junction_deviation = 0.0;
    let cmp0 = run(&m, &pts, Some(100.0), &o0);
    let (b0, c0) = (
        cmp0.row("controller").unwrap(),
        cmp0.row("feedopt").unwrap(),
    );
    assert!(b0.verified && b0.corners_at_speed == 0);
    assert!((b0.cycle_time_s - 4.0 * side_time(0.0, 0.0)).abs() < 1e-9);
    assert!((c0.cycle_time_s - b0.cycle_time_s).abs() < 1e-3 * b0.cycle_time_s);
}

#[test]
fn every_schedule_is_listed_and_json_has_the_table() {
    let m = common::machine(XYZ);
    let cmp = run(
        &m,
        &[
            Vector3::zeros(),
            Vector3::new(30.0, 0.0, 0.0),
            Vector3::new(60.0, 5.0, 0.0),
        ],
        Some(80.0),
        &options(200),
    );
    let keys: Vec<&str> = cmp.schedules.iter().map(|r| r.key.as_str()).collect();
    let listed: Vec<&str> = feedopt::compare::SCHEDULES.iter().map(|e| e.key).collect();
    // Without jerk limits in the machine file the jerk-limited row is omitted, with a reason.
    assert_eq!(keys, listed[..listed.len() - 1]);
    assert_eq!(cmp.omitted.len(), 1);
    assert_eq!(cmp.omitted[0].key, "feedopt_jerk");
    assert!(cmp.omitted[0].reason.contains("jerk"));
    let json: serde_json::Value = serde_json::to_value(&cmp).unwrap();
    for row in json["schedules"].as_array().unwrap() {
        assert!(row["cycle_time_s"].as_f64().unwrap() > 0.0);
        assert!(
            row["axes"][0]["jerk"].is_null(),
            "no jerk limit in the machine file"
        );
        assert!(row["axes"][0]["peak_jerk"].as_f64().unwrap().is_finite());
    }
    let text = cmp.to_string();
    assert!(text.contains("cycle time (s)") && text.contains("X jerk / limit"));
}

#[test]
fn jerk_limits_are_checked_when_the_machine_file_gives_them() {
    // The programmed feed starts from rest within one period: q̈ = F/T for one period, so
    // the sampled accelerations jump by F/T twice: jerk F/T² on X.
    let m = common::machine(
        r#"{"name": "jerk mill", "kinematics": {"type": "xyz"},
        "axes": {"X": {"velocity": 400, "acceleration": 2000, "jerk": 50000},
                 "Y": {"velocity": 400, "acceleration": 2000, "jerk": 50000},
                 "Z": {"velocity": 300, "acceleration": 1500, "jerk": 50000}},
        "feed": {"max": 150}}"#,
    );
    let cmp = run(
        &m,
        &[Vector3::zeros(), Vector3::new(40.0, 0.0, 0.0)],
        Some(100.0),
        &options(200),
    );
    let p = cmp.row("programmed").unwrap();
    let jerk = p.axes[0].jerk.expect("jerk ratio");
    // Samples fall inside the one-period ramp or not depending on phase; at most F/T².
    assert!(
        jerk > 0.5 * 100.0 / PERIOD / PERIOD / 50000.0,
        "jerk ratio {jerk}"
    );
    assert!(jerk <= 1.0001 * 100.0 / PERIOD / PERIOD / 50000.0);
    assert!(!p.verified);
    // feedopt's trapezoid switches acceleration 0 ↔ ±a at once: jerk a/T = 2e6 ≫ 5e4.
    let c = cmp.row("feedopt").unwrap();
    assert!(
        c.axes[0].jerk.unwrap() > 1.0 && !c.verified,
        "not jerk-limited (issue 6)"
    );
    // The jerk-limited schedule keeps every limit, jerk included, and takes longer.
    let d = cmp.row("feedopt_jerk").expect("a jerk-limited row");
    assert!(d.verified, "jerk-limited schedule verifies: {:?}", d.axes);
    assert!(d.axes[0].jerk.unwrap() <= 1.001);
    assert!(d.cycle_time_s > c.cycle_time_s);
}

/// The LinuxCNC impeller (G93, 5-axis trunnion): `compare` shows every schedule's worst
/// overshoot; feedopt is no slower than any schedule that keeps every limit, and a schedule
/// faster than feedopt exceeds some joint limit. The first blocks only (debug builds).
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn impeller_head_compare_acceptance() {
    let dir = Path::new("../shared/realworld/linuxcnc");
    assert!(dir.is_dir(), "../shared is present (cfg shared_data)");
    let text = std::fs::read_to_string(dir.join("impeller-7bl-xyzac.ngc")).unwrap();
    let head: String = text.lines().take(400).map(|l| format!("{l}\n")).collect();
    let tmp = tempfile::tempdir().unwrap();
    let ngc = tmp.path().join("impeller-head.ngc");
    std::fs::write(&ngc, head).unwrap();
    acceptance(&dir.join("impeller-7bl-xyzac.machine.json"), &ngc);
}

/// The whole impeller program (about 10 s in a release build).
#[test]
#[ignore]
fn impeller_full_compare_acceptance() {
    let dir = Path::new("../shared/realworld/linuxcnc");
    assert!(dir.is_dir(), "../shared is present (cfg shared_data)");
    acceptance(
        &dir.join("impeller-7bl-xyzac.machine.json"),
        &dir.join("impeller-7bl-xyzac.ngc"),
    );
}

fn acceptance(machine: &Path, ngc: &Path) {
    let m = Machine::from_file(machine).unwrap();
    let input = toolpath::read_input(ngc).unwrap();
    let mut o = CompareOptions::default();
    o.solve.solver_kind = SolverKind::Reach;
    let cmp = compare(&m, &input, "impeller", &o).unwrap();
    println!("{cmp}");
    let c = cmp.row("feedopt").unwrap();
    assert!(c.verified, "feedopt keeps every limit: {}", c.worst_ratio);
    for r in &cmp.schedules {
        assert!(r.worst_ratio.is_finite() && r.worst_ratio > 0.0);
        if r.verified {
            assert!(
                c.cycle_time_s <= r.cycle_time_s * (1.0 + 1e-3),
                "{} keeps every limit in {} s, feedopt takes {} s",
                r.key,
                r.cycle_time_s,
                c.cycle_time_s
            );
        }
        if r.cycle_time_s < c.cycle_time_s {
            assert!(
                !r.verified && r.worst_ratio > 1.001,
                "{} is faster ({} s < {} s) and must exceed a limit",
                r.key,
                r.cycle_time_s,
                c.cycle_time_s
            );
            // It is an axis (joint) limit that is exceeded, not only the feed.
            let axis_worst = r
                .axes
                .iter()
                .flat_map(|a| [a.velocity, a.acceleration])
                .fold(0.0, f64::max);
            assert!(
                axis_worst > 1.001,
                "{}: worst joint ratio {axis_worst}",
                r.key
            );
        }
    }
}

#[test]
fn cli_compare_prints_the_table_and_json() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("m.json"), XYZ).unwrap();
    std::fs::write(
        tmp.path().join("p.cls"),
        "FEDRAT/MMPM,6000\nGOTO/0,0,0\nGOTO/50,0,0\nGOTO/50,50,0\n",
    )
    .unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_feedopt"))
            .args(args)
            .current_dir(tmp.path())
            .output()
            .unwrap()
    };
    let out = run(&[
        "compare",
        "-m",
        "m.json",
        "p.cls",
        "--stations",
        "200",
        "--solver",
        "reach",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("programmed") && text.contains("controller") && text.contains("feedopt"));
    let out = run(&[
        "compare",
        "-m",
        "m.json",
        "p.cls",
        "--stations",
        "200",
        "--json",
        "--plot",
        "cmp.svg",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["schedules"].as_array().unwrap().len(), 3);
    let svg = std::fs::read_to_string(tmp.path().join("cmp.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("feed V (mm/s)"));
    // Bad options fail before any work, naming what is wrong.
    let out = run(&[
        "compare",
        "-m",
        "m.json",
        "p.cls",
        "--junction-deviation=-1",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("junction-deviation"));
    let out = run(&["compare", "-m", "m.json", "p.cls", "--plot", "x.png"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("PNG"));
}

/// A program's dwells are part of every schedule's cycle time, as `solve` reports it: each
/// row's time is its schedule's plus the 2.5 s dwell, and feedopt's row equals `solve`'s time.
#[test]
fn dwells_count_in_every_row_as_in_solve() {
    let m = common::machine(XYZ);
    let text = "G21 G90\nG0 X0 Y0 Z0\nG1 X50 F6000\nG4 P2.5\nG1 X100\nM2\n";
    let tp = feedopt::toolpath::gcode::parse(
        Path::new("dwell.ngc"),
        text,
        feedopt::toolpath::gcode::Dialect::LinuxCnc,
    )
    .expect("reads");
    assert_eq!(tp.dwell_time(), 2.5);
    let o = options(400);
    let input = Input::Cl(tp);
    let cmp = compare(&m, &input, "dwell", &o).expect("compare");
    assert_eq!(cmp.dwell_time_s, 2.5);
    assert!(cmp.schedules.len() >= 3);
    for row in &cmp.schedules {
        assert!(
            (row.cycle_time_s - row.schedule.cycle_time - 2.5).abs() < 1e-9,
            "{}: {} vs its schedule's {}",
            row.key,
            row.cycle_time_s,
            row.schedule.cycle_time
        );
    }
    let solved = optimize::optimize_input(&m, &input, &o.solve).expect("solves");
    let feedopt = cmp.row("feedopt").expect("feedopt row");
    assert!(
        (feedopt.cycle_time_s - (solved.schedule.cycle_time + 2.5)).abs() < 1e-9,
        "compare {} vs solve {} + 2.5",
        feedopt.cycle_time_s,
        solved.schedule.cycle_time
    );
}

/// A VMC with a rotary table on `letter` ([`common::four_axis_json`]).
fn four_axis(letter: char) -> feedopt::machine::Machine {
    common::machine(&common::four_axis_json(letter))
}

/// A table turned alone at F, out and back (round 10: NX's Mazak Nexus 510 four-axis sample):
/// every row times each block at its programmed rate of turn, F = 100 °/min, 54 s a block.
/// The programmed row counted the move's whole time on every piece the geometry cut it into at
/// the reversal (4,104 s here; 1,128,184 s for the Mazak program), and the controller and
/// feedopt ran the turn at B's limits (2.2 s).
#[test]
fn a_turn_alone_at_f_takes_its_programmed_time_in_every_row() {
    let m = four_axis('B');
    let tp = feedopt::toolpath::gcode::parse(
        Path::new("turn.ngc"),
        "G21 G90 G94\nG1 X0 Y0 Z0 B0 F100\nG1 B90\nB0\nM2\n",
        feedopt::toolpath::gcode::Dialect::LinuxCnc,
    )
    .expect("reads");
    let mut o = CompareOptions::default();
    o.solve.solver_kind = SolverKind::Reach;
    let cmp = compare(&m, &Input::Cl(tp), "turn", &o).expect("compare");
    // 2 × 90° at 100/60 °/s; (within the angular tolerance, 0.01°, the fitted turn may cut
    // its reversal short by up to 0.02°).
    let want = 2.0 * 54.0;
    for key in ["programmed", "controller", "feedopt"] {
        let t = cmp.row(key).expect("row").cycle_time_s;
        assert!(
            (t - want).abs() <= 2e-3 * want,
            "{key}: {t} s, want {want} s"
        );
    }
    assert!(cmp.row("controller").unwrap().verified);
    assert!(cmp.row("feedopt").unwrap().verified);
}

/// On a four-axis machine u is the chord in joint space (a degree as a millimetre), and the
/// programmed row still times a block by its feed along X Y Z (LinuxCNC's rule): X 10 mm with
/// A turning 90° at F600 takes 1 s, not the 9.06 s of F along the joint chord (as on main).
#[test]
fn a_four_axis_block_is_timed_by_its_feed_along_the_tip() {
    let m = four_axis('A');
    let tp = feedopt::toolpath::gcode::parse(
        Path::new("xa.ngc"),
        "G21 G90 G94\nG1 X0 Y0 Z0 A0 F600\nG1 X10 A90\nM2\n",
        feedopt::toolpath::gcode::Dialect::LinuxCnc,
    )
    .expect("reads");
    let cmp = compare(&m, &Input::Cl(tp), "xa", &CompareOptions::default()).expect("compare");
    let t = cmp.row("programmed").expect("row").cycle_time_s;
    // (Plus one servo period's ramp in and out: 1.001 s.)
    assert!((t - 1.001).abs() <= 1e-6, "programmed: {t} s, want 1.001 s");
}
