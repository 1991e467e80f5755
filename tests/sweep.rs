//! The constraint study (`feedopt sweep`): closed-form sensitivities, duals against finite
//! differences, and the LinuxCNC impeller (read from ../shared when present).

use std::path::{Path, PathBuf};

use feedopt::constraints::Ramp;
use feedopt::machine::{Limit, Machine};
use feedopt::optimize::Options;
use feedopt::solver::Status;
use feedopt::sweep::{Sweep, SweepOptions, SweptLimit, scaled_limit, sweep};
use feedopt::toolpath::{self, Input, joint_csv};
use nalgebra::Vector3;

mod common;
use common::{UP, machine, toolpath};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// An xyz machine: X with the given velocity and acceleration, Y and Z fast.
fn xyz(vx: f64, ax: f64) -> Machine {
    machine(&format!(
        r#"{{"name": "xyz", "kinematics": {{"type": "xyz"}},
            "axes": {{"X": {{"velocity": {vx}, "acceleration": {ax}}},
                     "Y": {{"velocity": 1e5, "acceleration": 1e5}},
                     "Z": {{"velocity": 1e5, "acceleration": 1e5}}}}}}"#
    ))
}

/// A straight line along X of length `l`, rest to rest.
fn line(l: f64) -> Input {
    Input::Cl(toolpath(
        &[(Vector3::zeros(), UP), (Vector3::new(l, 0.0, 0.0), UP)],
        None,
    ))
}

/// Sweep with a fixed station count.
fn run(m: &Machine, input: &Input, o: SweepOptions, stations: usize) -> Sweep {
    run_ramp(m, input, o, stations, Ramp::default())
}

/// [`run`] with ü varying between stations as `ramp` says.
fn run_ramp(m: &Machine, input: &Input, o: SweepOptions, stations: usize, ramp: Ramp) -> Sweep {
    let o = SweepOptions {
        solve: Options {
            stations: Some(stations),
            ramp,
            ..Options::default()
        },
        ..o
    };
    sweep(m, input, "test", &o).expect("sweep runs")
}

#[test]
fn acceleration_limited_line_matches_t_equals_two_root_l_over_a() {
    // Bang-bang: b = 2au to the midpoint and back. With the midpoint a station the
    // piecewise-linear b is exact, so T = 2√(L/a) and dT/da = −√(L/a)/a exactly. The velocity
    // limit is above the peak √(aL) ≤ 285 mm/s of every solve (and not absurdly so: the solver
    // scales b by the velocity bounds).
    let l = 100.0;
    let m = xyz(400.0, 500.0);
    let s = run(
        &m,
        &line(l),
        SweepOptions::new("X", SweptLimit::Acceleration, 200.0, 800.0, 3),
        1000,
    );
    assert_eq!(s.points.len(), 3);
    for p in &s.points {
        let a = p.limit;
        let t = 2.0 * (l / a).sqrt();
        let dt = -(l / a).sqrt() / a;
        assert!(
            rel(p.cycle_time_s, t) < 1e-6,
            "a {a}: T {} vs {t}",
            p.cycle_time_s
        );
        let dual = p.sensitivity_dual.expect("clarabel gives duals");
        assert!(rel(dual, dt) < 1e-4, "a {a}: dual {dual} vs {dt}");
        // Central differences of 2√(L/a) at ±1 %: error ≈ (5/8)h² ≈ 6e-5.
        assert!(
            rel(p.sensitivity_fd, dt) < 2e-4,
            "a {a}: FD {} vs {dt}",
            p.sensitivity_fd
        );
        assert!(p.smooth && p.verified, "a {a}");
    }
}

/// L = 100 mm, v = 10 mm/s, a = v²/(2 u_c) with the corner of the trapezoid at u_c = 10.45 mm:
/// 104.5 intervals of ramp at 1000 stations (Δu = 0.1 mm), the corner halfway between two
/// stations. (With the corner *on* a station the discretised T(v) has a kink there — the rows
/// active at that station change — and the dual is one element of the subdifferential, whose
/// one-sided ends differ by about one station's share of the ramp.)
const L: f64 = 100.0;
const V: f64 = 10.0;
const A: f64 = V * V / (2.0 * 10.45);

#[test]
fn velocity_limited_line_matches_t_equals_l_over_v_plus_v_over_a() {
    let m = xyz(V, A);
    let t = L / V + V / A;
    // The discrete profile misses the corner by half an interval: O(Δu²) in T, and the
    // derivative of the discretised T differs from the continuous one by O((Δu/ramp)²).
    let tol = 5e-4;
    // Velocity sweep: dT/dv = −L/v² + 1/a.
    let s = run(
        &m,
        &line(L),
        SweepOptions::new("X", SweptLimit::Velocity, V, V, 1),
        1000,
    );
    let p = &s.points[0];
    assert!(rel(p.cycle_time_s, t) < 1e-5, "T {} vs {t}", p.cycle_time_s);
    let dt_dv = -L / (V * V) + 1.0 / A;
    let dual = p.sensitivity_dual.unwrap();
    eprintln!(
        "velocity: T {} vs {t}; dual {dual} FD {} exact {dt_dv}",
        p.cycle_time_s, p.sensitivity_fd
    );
    assert!(rel(dual, dt_dv) < tol, "dual {dual} vs {dt_dv}");
    assert!(
        rel(p.sensitivity_fd, dt_dv) < tol,
        "FD {} vs {dt_dv}",
        p.sensitivity_fd
    );
    // Acceleration sweep at the same point: dT/da = −v/a².
    let s = run(
        &m,
        &line(L),
        SweepOptions::new("X", SweptLimit::Acceleration, A, A, 1),
        1000,
    );
    let p = &s.points[0];
    let dt_da = -V / (A * A);
    let dual = p.sensitivity_dual.unwrap();
    eprintln!(
        "acceleration: dual {dual} FD {} exact {dt_da}",
        p.sensitivity_fd
    );
    assert!(rel(dual, dt_da) < tol, "dual {dual} vs {dt_da}");
    assert!(
        rel(p.sensitivity_fd, dt_da) < tol,
        "FD {} vs {dt_da}",
        p.sensitivity_fd
    );
}

/// Tool tip on a circle of radius r, `turns` times round.
fn circle(r: f64, turns: usize, per_turn: usize) -> Input {
    let pts: Vec<_> = (0..=turns * per_turn)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / per_turn as f64;
            (Vector3::new(r * a.cos(), r * a.sin(), 0.0), UP)
        })
        .collect();
    Input::Cl(toolpath(&pts, None))
}

#[test]
fn on_a_circle_the_duals_include_the_acceleration_limited_velocity_bound() {
    // Around a circle the feed is held down by the centripetal acceleration: at many stations
    // the binding bound is b* (the largest b the acceleration rows allow), stated as b_max.
    // Its multiplier belongs to the acceleration limit too (∂b*/∂μ), or the dual sensitivity
    // would fall short of the finite differences.
    let m = machine(
        r#"{"name": "xy", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 1e4, "acceleration": 1000},
                     "Y": {"velocity": 1e4, "acceleration": 2000},
                     "Z": {"velocity": 1e4, "acceleration": 1000}}}"#,
    );
    let s = run(
        &m,
        &circle(20.0, 3, 120),
        SweepOptions::new("X", SweptLimit::Acceleration, 500.0, 1500.0, 3),
        2000,
    );
    for p in &s.points {
        let dual = p.sensitivity_dual.unwrap();
        eprintln!(
            "a {}: T {} dual {dual} FD {} smooth {}",
            p.limit, p.cycle_time_s, p.sensitivity_fd, p.smooth
        );
        assert!(dual < 0.0);
        assert!(
            rel(dual, p.sensitivity_fd) < 0.02,
            "a {}: dual {dual} FD {}",
            p.limit,
            p.sensitivity_fd
        );
    }
}

/// A zig-zag of `n` straight moves of 10 mm along X, 5 mm across.
fn zigzag(n: usize) -> Input {
    let pts: Vec<_> = (0..=n)
        .map(|k| (Vector3::new(10.0 * k as f64, 5.0 * (k % 2) as f64, 0.0), UP))
        .collect();
    Input::Cl(toolpath(&pts, None))
}

/// The two ways to dT/dv agree: a cone program per span with Clarabel's multipliers, and the
/// central difference (ε = 1e-6) of the lattice relaxation's largest profile where that is the
/// exact optimum (the default). On the zig-zag every span is lattice-exact, so by default no
/// cone program is solved; around the circle, with ü constant per interval, the relaxation
/// breaks the centripetal rows where X's tangent vanishes, so the span is a cone program
/// either way, with the same answer. (With ü linear, the default, X turning round there bounds
/// b alone, and the circle is lattice-exact too.)
#[test]
fn the_lattice_derivative_equals_clarabels_duals() {
    let m = machine(
        r#"{"name": "xy", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 40, "acceleration": 1000},
                     "Y": {"velocity": 400, "acceleration": 2000},
                     "Z": {"velocity": 1e4, "acceleration": 1000}}}"#,
    );
    for (name, path, ramp, lattice_cones) in [
        ("zig-zag", zigzag(12), Ramp::Linear, 0),
        ("circle", circle(20.0, 3, 120), Ramp::Constant, 1),
        ("circle", circle(20.0, 3, 120), Ramp::Linear, 0),
    ] {
        for (which, from, to) in [
            (SweptLimit::Acceleration, 500.0, 1500.0),
            (SweptLimit::Velocity, 20.0, 60.0),
        ] {
            let o = SweepOptions::new("X", which, from, to, 3);
            let lattice = run_ramp(&m, &path, o.clone(), 2000, ramp);
            let duals = run_ramp(
                &m,
                &path,
                SweepOptions {
                    lattice: false,
                    ..o
                },
                2000,
                ramp,
            );
            for (a, b) in lattice.points.iter().zip(&duals.points) {
                let (da, db) = (a.sensitivity_dual.unwrap(), b.sensitivity_dual.unwrap());
                eprintln!(
                    "{name}, {which} {}: T {} / {}, dT/dv {da} / {db}, FD {}, cone spans {} / {} of {}",
                    a.limit,
                    a.cycle_time_s,
                    b.cycle_time_s,
                    a.sensitivity_fd,
                    a.cone_spans,
                    b.cone_spans,
                    duals.spans
                );
                assert_eq!((a.cone_spans, b.cone_spans), (lattice_cones, duals.spans));
                assert!(rel(a.cycle_time_s, b.cycle_time_s) < 1e-6);
                assert!(da < 0.0, "the {which} limit binds at {}", a.limit);
                assert!(rel(da, db) < 1e-3, "{which} {}: {da} against {db}", a.limit);
            }
        }
    }
}

#[test]
fn an_asymmetric_limit_is_scaled_proportionally() {
    let l = scaled_limit(
        Limit {
            min: -100.0,
            max: 300.0,
        },
        600.0,
    );
    assert_eq!((l.min, l.max), (-200.0, 600.0));
    let l = scaled_limit(Limit::symmetric(300.0), 50.0);
    assert_eq!((l.min, l.max), (-50.0, 50.0));
}

fn linuxcnc() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/linuxcnc");
    d.join("impeller-7bl-xyzac.ngc").exists().then_some(d)
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn impeller_c_acceleration_sweep_is_monotone_and_duals_match_finite_differences() {
    let dir = linuxcnc().expect("../shared is present (cfg shared_data)");
    let m = Machine::from_file(&dir.join("impeller-7bl-xyzac.machine.json")).unwrap();
    let input = toolpath::read(&dir.join("impeller-7bl-xyzac.ngc")).unwrap();
    let input = Input::Cl(input);
    // 5000 requested stations (8,535 with every CL point): each solve well under a second.
    // The program's own feeds stay: the sweep asks what C's acceleration costs this program.
    // Below ~250 °/s² the C acceleration holds the feed down somewhere; above, nowhere.
    let s = run(
        &m,
        &input,
        SweepOptions::new("C", SweptLimit::Acceleration, 40.0, 340.0, 6),
        5000,
    );
    check_impeller_sweep(&s);
}

/// The acceptance checks of an impeller C-acceleration sweep.
fn check_impeller_sweep(s: &Sweep) {
    eprintln!("{s}");
    let t: Vec<f64> = s.points.iter().map(|p| p.cycle_time_s).collect();
    for w in t.windows(2) {
        // Never slower with a larger limit, up to the solver's gap tolerance (1e-6 relative).
        assert!(w[1] <= w[0] * (1.0 + 1e-6), "T rose: {t:?}");
    }
    assert!(
        t[0] > t[t.len() - 1],
        "the C acceleration matters at 40 °/s²: {t:?}"
    );
    let mut compared = 0;
    for p in &s.points {
        let dual = p.sensitivity_dual.unwrap();
        assert!(p.worst_ratio.is_finite() && p.worst_ratio > 0.0);
        // The stations the steps' limits need are added for every step.
        assert!(p.verified, "{} °/s²: worst {}", p.limit, p.worst_ratio);
        if p.binds && p.smooth {
            let d = p.relative_difference.unwrap();
            assert!(
                d < 0.05,
                "{} °/s²: dual {dual} FD {} ({d})",
                p.limit,
                p.sensitivity_fd
            );
            compared += 1;
        } else if !p.binds {
            // Binding nowhere: dT/dv = 0 up to solver noise, both ways. A relative error ε in
            // T (the gap tolerance, 1e-6, at worst) gives |dT/dv|·v/T up to ε/h = 1e-4.
            for x in [dual, p.sensitivity_fd] {
                assert!(
                    x.abs() * p.limit / p.cycle_time_s < 1e-4,
                    "{} °/s²: {x}",
                    p.limit
                );
            }
        }
    }
    assert!(
        compared >= 3,
        "too few smooth binding steps to compare:\n{s}"
    );
}

/// The full-resolution study: automatic refinement at the nominal limits (31,267 stations
/// since the local refinement; 1.4 M when this test was written), then every step on those
/// stations (the lattice optimum on every span: 3 s in release; Clarabel on every span, 4 s;
/// it was ignored as slow while the stations were 1.4 M).
/// The steps stop at 240 °/s² (C's acceleration holds the feed down on 0.7 % of the time
/// there): at the nominal 300 °/s² (0.5 %) the limits that bind change within ±1 %, so that
/// step is not smooth and has no finite difference to compare (it made this test fail with
/// three steps from 60 to 300, before and after the constraint generation alike).
#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn impeller_c_acceleration_sweep_at_full_resolution() {
    let dir = linuxcnc().expect("../shared is present (cfg shared_data)");
    let m = Machine::from_file(&dir.join("impeller-7bl-xyzac.machine.json")).unwrap();
    let input = Input::Cl(toolpath::read(&dir.join("impeller-7bl-xyzac.ngc")).unwrap());
    let t0 = std::time::Instant::now();
    let s = sweep(
        &m,
        &input,
        "impeller-7bl-xyzac.ngc",
        &SweepOptions::new("C", SweptLimit::Acceleration, 60.0, 240.0, 4),
    )
    .unwrap();
    eprintln!("wall time {:.1} s", t0.elapsed().as_secs_f64());
    check_impeller_sweep(&s);
}

#[test]
fn the_command_writes_csv_json_and_svg_and_names_unknown_axes() {
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("m.json");
    std::fs::write(
        &m,
        r#"{"name": "xyz", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 400, "acceleration": 500},
                     "Y": {"velocity": 400, "acceleration": 500},
                     "Z": {"velocity": 400, "acceleration": 500}}}"#,
    )
    .unwrap();
    let t = dir.path().join("line.ngc");
    std::fs::write(&t, "G21 G90 G0 X0 Y0 Z0\nG1 X100 F60000\n").unwrap();
    let (csv, svg) = (dir.path().join("s.csv"), dir.path().join("s.svg"));
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_feedopt"))
            .arg("sweep")
            .arg("--machine")
            .arg(&m)
            .arg(&t)
            .args(["--limit", "acceleration", "--from", "200", "--to", "800"])
            .args(["--steps", "3", "--stations", "400"])
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run(&[
        "--axis",
        "X",
        "--json",
        "-o",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON only");
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), 3);
    // T = 2√(L/a) at the three limits.
    for p in points {
        let a = p["limit"].as_f64().unwrap();
        let t = p["cycle_time_s"].as_f64().unwrap();
        assert!(rel(t, 2.0 * (100.0 / a).sqrt()) < 1e-6);
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4);
    assert!(lines[0].starts_with("limit,cycle_time_s,dT_dlimit_dual,dT_dlimit_fd"));
    assert!(lines[0].contains("path_share_X_acceleration"));
    let plot = std::fs::read_to_string(&svg).unwrap();
    assert!(plot.starts_with("<svg"));
    for label in [
        "X acceleration limit [mm/s²]",
        "cycle time [s]",
        "dT/d(limit) [s per mm/s²]",
        "from the duals",
        "central differences",
    ] {
        assert!(plot.contains(label), "the plot lacks {label}");
    }
    // The readable table names the axis and its unit.
    let out = run(&["--axis", "X"]);
    let table = String::from_utf8(out.stdout).unwrap();
    assert!(table.contains("X acceleration limit") && table.contains("[mm/s²]"));

    let out = run(&["--axis", "B"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--axis B") && err.contains("X, Y, Z"), "{err}");
    let bad = dir.path().join("p.png");
    let out = run(&["--axis", "X", "--plot", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!bad.exists());
}

/// The program's dwells are part of every step's cycle time, as `solve` reports it; dT/dv
/// does not see them. (The sweep reported the motion alone: the NX DMU 70 eVo program's
/// nominal step said 1,056.27 s where solve says 1,131.30 s with 75.03 s of dwells.) The
/// closed form of the line at each step, plus the dwells.
#[test]
fn the_dwells_count_in_every_step() {
    let l = 100.0;
    let m = xyz(400.0, 500.0);
    let mut tp = match line(l) {
        Input::Cl(t) => t,
        Input::Joint(_) => unreachable!(),
    };
    tp.dwells.push(toolpath::Dwell {
        point: 0,
        seconds: 1.25,
        line: 1,
    });
    tp.dwells.push(toolpath::Dwell {
        point: 1,
        seconds: 0.5,
        line: 2,
    });
    let s = run(
        &m,
        &Input::Cl(tp),
        SweepOptions::new("X", SweptLimit::Acceleration, 200.0, 800.0, 3),
        2,
    );
    for p in &s.points {
        let want = 2.0 * (l / p.limit).sqrt() + 1.75;
        assert!(
            rel(p.cycle_time_s, want) < 1e-7,
            "{} vs {want}",
            p.cycle_time_s
        );
        let fd = -(l / p.limit).sqrt() / p.limit;
        assert!(
            rel(p.sensitivity_fd, fd) < 1e-3,
            "{} vs {fd}",
            p.sensitivity_fd
        );
    }
}

#[test]
fn a_machine_with_jerk_limits_is_refused_unless_they_are_dropped() {
    // The steps are the velocity- and acceleration-limited problem. Before, `--no-jerk` dropped
    // the jerk limits from the stations' solve but not from the steps' re-simulation, so every
    // step came out unverified (the flower mould: `N` at every step); without `--no-jerk` the
    // error came from the stations' reachability solve and named the wrong remedy.
    let m = machine(
        r#"{"name": "xyz with jerk", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 100, "acceleration": 500, "jerk": 2000},
                     "Y": {"velocity": 100, "acceleration": 500, "jerk": 2000},
                     "Z": {"velocity": 100, "acceleration": 500, "jerk": 2000}}}"#,
    );
    let o = SweepOptions::new("X", SweptLimit::Acceleration, 400.0, 600.0, 2);
    let e = sweep(&m, &zigzag(4), "zigzag", &o).unwrap_err().to_string();
    assert!(e.contains("jerk limits") && e.contains("--no-jerk"), "{e}");
    let mut o = o;
    o.solve.jerk_limited = false;
    o.solve.stations = Some(400);
    let s = sweep(&m, &zigzag(4), "zigzag", &o).unwrap();
    for p in &s.points {
        assert!(
            p.verified,
            "{} mm/s²: worst ratio {}",
            p.limit, p.worst_ratio
        );
        // Every span is lattice-exact: the optimum, not a fallback.
        assert_eq!((p.status, p.cone_spans), (Status::Optimal, 0));
    }
}

#[test]
fn the_step_at_the_machines_own_limit_verifies_where_solve_does() {
    // A B/C trunnion in tool-tip mode: a move that tilts the table to B90 C90, a short move
    // that turns it back to B64.761 C45 while the tip moves 0.5 mm (NX's Mori NMV5000
    // program, round 11, in miniature), then straight moves. The sweep takes one solve's
    // stations for every step; when that solve was a reachability solve, its profile verified
    // on them but the cone program's optimum on the same stations did not (worst ratio 1.0016
    // at the machine's own X acceleration, 1.206 on the whole NX program), while `solve`
    // verified there.
    let m = machine(
        r#"{"name": "B/C trunnion", "kinematics": {"type": "table_table_bc",
              "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0, "x-offset": 0,
              "z-offset": 0},
            "axes": {"X": {"velocity": 500, "acceleration": 3000},
                     "Y": {"velocity": 500, "acceleration": 3000},
                     "Z": {"velocity": 500, "acceleration": 3000},
                     "B": {"velocity": 60, "acceleration": 600},
                     "C": {"velocity": 60, "acceleration": 600}},
            "feed": {"max": 500}}"#,
    );
    let program = "G21 G90 G94\nG43.4 H1\nG1 X-29.463 Y17.678 Z29.167 B0 C0 F250.\n\
                   G1 X-37.207 Y24.805 Z0 B90. C90.\nX0 Y0\nX-.471 Y-.201 B64.761 C45.\n\
                   X-3.769 Y-1.607\nX-41.458 Y14.464\n";
    let t = toolpath::gcode::parse(
        Path::new("trunnion.nc"),
        program,
        toolpath::gcode::Dialect::Fanuc,
    )
    .unwrap();
    let input = Input::Cl(t);
    let solved = feedopt::optimize::optimize_input(&m, &input, &Options::default()).unwrap();
    let s = sweep(
        &m,
        &input,
        "trunnion.nc",
        &SweepOptions::new("X", SweptLimit::Acceleration, 3000.0, 6000.0, 2),
    )
    .unwrap();
    let own = &s.points[0];
    assert!(
        own.verified,
        "the step at the machine's own limit: worst ratio {}",
        own.worst_ratio
    );
    assert!(
        rel(own.cycle_time_s, solved.schedule.cycle_time) < 1e-5,
        "sweep {} s, solve {} s",
        own.cycle_time_s,
        solved.schedule.cycle_time
    );
}

/// The stations a step's limits need between them are added for every step: the sweep divides
/// the intervals where a step's re-simulation finds a limit exceeded, as `solve` would, and
/// solves every step again on the result. Before, every step kept the stations of the nominal
/// limits and a step with other limits could come out unverified (the README's impeller table:
/// 40 °/s², 3.3 % over C's acceleration between stations).
#[test]
fn every_step_verifies_on_stations_divided_where_a_step_needed_them() {
    // Two joint axes along smooth curves (q₀ = sin 6s, q₁ = ½ cos 9s), 41 rows.
    let m = machine(
        r#"{"name": "j2", "kinematics": {"type": "joint"},
            "axes": {"0": {"velocity": 2, "acceleration": 10},
                     "1": {"velocity": 2, "acceleration": 10}}}"#,
    );
    let mut csv = String::from("s,q_0,q_1\n");
    for k in 0..=40 {
        let s = k as f64 / 40.0;
        csv += &format!("{s},{},{}\n", (6.0 * s).sin(), 0.5 * (9.0 * s).cos());
    }
    let path = Input::Joint(joint_csv::parse(Path::new("curves.csv"), &csv).unwrap());
    let o = SweepOptions::new("0", SweptLimit::Velocity, 0.2, 2.0, 3);
    let fixed = SweepOptions {
        solve: Options {
            stations: Some(40),
            refine_until_verified: false,
            ..Options::default()
        },
        ..o.clone()
    };
    let kept = sweep(&m, &path, "test", &fixed).expect("sweep runs");
    eprintln!("{kept}");
    assert_eq!(kept.refinement_rounds, 0);
    assert!(
        kept.points.iter().any(|p| !p.verified),
        "the test needs a step the nominal stations do not verify"
    );
    let divided = run(&m, &path, o, 40);
    eprintln!("{divided}");
    assert!(divided.refinement_rounds >= 1);
    assert!(divided.stations > kept.stations);
    for p in &divided.points {
        assert!(p.verified, "{}: worst {}", p.limit, p.worst_ratio);
    }
    // Still one discretisation: never slower with a larger limit.
    for w in divided.points.windows(2) {
        assert!(w[1].cycle_time_s <= w[0].cycle_time_s * (1.0 + 1e-9));
    }
}

/// A chord tolerance (`--chord-tolerance`, seed 004) bounds every step's feed as it bounds
/// `solve`'s. The steps used to be solved without it (their problems were built from the
/// stations alone), so the step at the machine's own limit ran faster than `solve` and failed
/// its own re-simulation, which checks the chord error (the LinuxCNC impeller at 1e-6 mm:
/// 1173.3135 s, unverified, against `solve`'s 1173.3336 s).
#[test]
fn the_chord_tolerance_bounds_every_step_as_it_bounds_solve() {
    let m = machine(
        r#"{"name": "xy", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 1e4, "acceleration": 1000},
                     "Y": {"velocity": 1e4, "acceleration": 2000},
                     "Z": {"velocity": 1e4, "acceleration": 1000}}}"#,
    );
    let path = circle(20.0, 2, 120);
    let mut solve = Options {
        stations: Some(1000),
        ..Options::default()
    };
    let free = match &path {
        Input::Cl(t) => feedopt::optimize::optimize(&m, t, &solve).unwrap(),
        Input::Joint(_) => unreachable!(),
    };
    solve.verify.chord = Some(feedopt::constraints::Chord {
        tolerance: 1e-4,
        period: solve.verify.period,
    });
    let bounded = match &path {
        Input::Cl(t) => feedopt::optimize::optimize(&m, t, &solve).unwrap(),
        Input::Joint(_) => unreachable!(),
    };
    let t_solve = bounded.schedule.cycle_time;
    assert!(
        t_solve > free.schedule.cycle_time * 1.01,
        "the chord tolerance must hold the feed down: {t_solve} against {}",
        free.schedule.cycle_time
    );
    let s = sweep(
        &m,
        &path,
        "test",
        &SweepOptions {
            solve,
            ..SweepOptions::new("X", SweptLimit::Acceleration, 1000.0, 1000.0, 1)
        },
    )
    .unwrap();
    eprintln!("{s}");
    let p = &s.points[0];
    assert!(p.verified, "worst {}", p.worst_ratio);
    assert!(
        rel(p.cycle_time_s, t_solve) < 1e-6,
        "sweep {} against solve {t_solve}",
        p.cycle_time_s
    );
}
