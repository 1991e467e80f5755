//! Inputs are validated where they enter the library (issue 15): every check the command line
//! made on an option is made by the library entry point itself (`optimize`, `optimize_joint`,
//! `compare`, `sweep`, `interpolate::sample`, `writers::gcode::program`), which answers with
//! a typed [`Error::InvalidOption`] naming the field, before any work; a [`Machine`] built in
//! code is checked as a machine file is ([`Error::InvalidMachine`] naming the field).

mod common;

use feedopt::compare::{CompareOptions, compare};
use feedopt::constraints::Chord;
use feedopt::error::Error;
use feedopt::machine::{AxisKind, KinematicsSpec, Limit, Machine};
use feedopt::optimize::{Options, Solution, optimize, optimize_joint};
use feedopt::solver::SolverKind;
use feedopt::sweep::{MAX_STEPS, SweepOptions, SweptLimit, sweep};
use feedopt::toolpath::joint_csv;
use feedopt::toolpath::{Input, Toolpath};
use feedopt::validate::{MAX_END_FEED, MAX_PERIOD_S, MIN_PERIOD_S};
use feedopt::writers::gcode::{BlockFeed, GcodeOptions, program};
use nalgebra::Vector3;

use common::{UP, machine, toolpath};

/// A 3-axis mill with a 100 mm/s feed cap.
fn xyz() -> Machine {
    machine(
        r#"{"name": "xyz", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 100, "acceleration": 1000},
                     "Y": {"velocity": 100, "acceleration": 1000},
                     "Z": {"velocity": 100, "acceleration": 1000}},
            "feed": {"max": 100}}"#,
    )
}

/// The seed's double swivel head (rotary axes, for the G-code writer).
fn head_head() -> Machine {
    machine(
        r#"{"name": "hh", "kinematics": {"type": "head_head", "tool_length": 200},
            "axes": {"X": {"velocity": 400, "acceleration": 2000},
                     "Y": {"velocity": 400, "acceleration": 2000},
                     "Z": {"velocity": 400, "acceleration": 2000},
                     "C": {"velocity": 120, "acceleration": 600},
                     "A": {"velocity": 60, "acceleration": 400}},
            "feed": {"max": 150}}"#,
    )
}

/// A 40 mm line along X.
fn line() -> Toolpath {
    toolpath(
        &[(Vector3::zeros(), UP), (Vector3::new(40.0, 0.0, 0.0), UP)],
        None,
    )
}

/// Options that solve `line()` in a few milliseconds.
fn quick() -> Options {
    Options {
        stations: Some(50),
        solver_kind: SolverKind::Reach,
        ..Options::default()
    }
}

/// The field and reason of an [`Error::InvalidOption`]; anything else fails the test.
fn invalid_option<T: std::fmt::Debug>(r: feedopt::error::Result<T>) -> (String, String) {
    match r {
        Err(Error::InvalidOption { field, reason }) => (field, reason),
        other => panic!("expected an invalid option, got {other:?}"),
    }
}

/// `optimize` on the line refuses `options`, naming `field`, with every one of `needles` in
/// the reason; the message is one line that names the field.
fn refused(options: &Options, field: &str, needles: &[&str]) {
    let r = optimize(&xyz(), &line(), options);
    let e = match &r {
        Err(e) => e.to_string(),
        Ok(_) => String::new(),
    };
    let (f, reason) = invalid_option(r);
    assert_eq!(f, field, "{reason}");
    for n in needles {
        assert!(reason.contains(n), "`{n}` not in: {reason}");
    }
    assert!(
        !e.contains('\n') && e.contains(&format!("`{field}`")),
        "{e}"
    );
}

#[test]
fn the_default_options_and_the_quick_ones_are_valid() {
    Options::default().validate().unwrap();
    quick().validate_for(&xyz()).unwrap();
    optimize(&xyz(), &line(), &quick()).unwrap();
}

#[test]
fn corner_angle_between_0_and_180_degrees() {
    for a in [0.0, 180.0, 200.0, -5.0, f64::NAN] {
        let mut o = quick();
        o.geometry.corner_angle_deg = a;
        refused(&o, "geometry.corner_angle_deg", &["between 0 and 180"]);
    }
    let mut o = quick();
    o.geometry.corner_angle_deg = 179.0;
    optimize(&xyz(), &line(), &o).unwrap();
}

#[test]
fn at_least_two_stations() {
    let o = Options {
        stations: Some(1),
        ..quick()
    };
    refused(&o, "stations", &["at least 2", "got 1"]);
}

#[test]
fn at_most_max_stations() {
    let o = Options {
        stations: Some(4_000_001),
        ..quick()
    };
    refused(&o, "stations", &["4000001", "at most 4000000"]);
    let o = Options {
        stations: Some(60),
        max_stations: 59,
        ..quick()
    };
    refused(&o, "stations", &["at most 59"]);
}

#[test]
fn servo_period_from_1_us_to_1_s() {
    for p in [1e-12, 0.0, -1e-3, 2.0, f64::INFINITY, f64::NAN] {
        let mut o = quick();
        o.verify.period = p;
        refused(&o, "verify.period", &["outside", "1 µs to 1 s"]);
    }
    for p in [MIN_PERIOD_S, MAX_PERIOD_S] {
        let mut o = quick();
        o.verify.period = p;
        o.validate().unwrap();
    }
}

#[test]
fn start_and_end_feeds_from_0_to_1e6_mm_s() {
    for (field, v) in [
        ("start_feed", -1.0),
        ("start_feed", 1e300),
        ("end_feed", f64::INFINITY),
        ("end_feed", f64::NAN),
    ] {
        let o = match field {
            "start_feed" => Options {
                start_feed: v,
                ..quick()
            },
            _ => Options {
                end_feed: v,
                ..quick()
            },
        };
        refused(&o, field, &["outside 0 to 1e6 mm/s"]);
    }
    // At the bound the option is valid (the machine's feed cap is another check).
    Options {
        end_feed: MAX_END_FEED,
        ..quick()
    }
    .validate()
    .unwrap();
}

#[test]
fn start_and_end_feeds_at_most_the_machines_maximum_feed() {
    let o = Options {
        start_feed: 101.0,
        ..quick()
    };
    refused(&o, "start_feed", &["101 mm/s", "feed.max = 100"]);
    let o = Options {
        end_feed: 100.5,
        ..quick()
    };
    refused(&o, "end_feed", &["feed.max = 100"]);
    // Valid on its own: only the machine's cap refuses it.
    o.validate().unwrap();
}

#[test]
fn chord_tolerance_at_least_1_nm() {
    let mut o = quick();
    o.verify.chord = Some(Chord {
        tolerance: 1e-9,
        period: 1e-3,
    });
    refused(&o, "verify.chord.tolerance", &["at least 1e-6 mm"]);
    o.verify.chord = Some(Chord {
        tolerance: 0.001,
        period: 0.0,
    });
    refused(&o, "verify.chord.period", &["outside"]);
}

#[test]
fn tolerances_finite_and_not_negative() {
    let mut o = quick();
    o.geometry.tolerance_mm = -0.001;
    refused(&o, "geometry.tolerance_mm", &["≥ 0 mm", "-0.001"]);
    let mut o = quick();
    o.geometry.tolerance_deg = f64::NAN;
    refused(&o, "geometry.tolerance_deg", &["≥ 0 degrees"]);
}

#[test]
fn feed_override_from_0_001_to_1000() {
    for f in [0.0, 1e-300, -1.0, 1001.0, f64::NAN] {
        let mut o = quick();
        o.geometry.feed_override = f;
        refused(&o, "geometry.feed_override", &["0.001 to 1000"]);
    }
}

#[test]
fn solver_and_refinement_settings_have_ranges_too() {
    let mut o = quick();
    o.solver.tol_gap = 0.0;
    refused(&o, "solver.tol_gap", &["> 0"]);
    let mut o = quick();
    o.solver.max_iter = 0;
    refused(&o, "solver.max_iter", &["at least 1"]);
    let mut o = quick();
    o.solver.time_limit = -1.0;
    refused(&o, "solver.time_limit", &["0 s or more"]);
    let o = Options {
        convergence: 1.5,
        ..quick()
    };
    refused(&o, "convergence", &["between 0 and 1"]);
    let mut o = quick();
    o.jerk.max_iterations = 0;
    refused(&o, "jerk.max_iterations", &["at least 1"]);
}

#[test]
fn a_joint_space_solve_checks_its_options_too() {
    let m = machine(
        r#"{"kinematics": {"type": "joint"},
            "axes": {"a": {"velocity": 1, "acceleration": 1}}}"#,
    );
    let path = joint_csv::parse("j.csv".as_ref(), "s,q_a\n0,0\n1,1\n").unwrap();
    let o = Options {
        start_feed: -2.0,
        ..quick()
    };
    let (field, _) = invalid_option(optimize_joint(&m, &path, &o));
    assert_eq!(field, "start_feed");
    optimize_joint(&m, &path, &quick()).unwrap();
}

#[test]
fn junction_deviation_not_negative() {
    let o = CompareOptions {
        solve: quick(),
        junction_deviation: -1.0,
    };
    let (field, reason) = invalid_option(compare(&xyz(), &Input::Cl(line()), "line", &o));
    assert_eq!(field, "junction_deviation");
    assert!(reason.contains("≥ 0 mm"), "{reason}");
    // The solve options are checked there too, under `solve.`.
    let mut o = CompareOptions {
        solve: quick(),
        ..CompareOptions::default()
    };
    o.solve.verify.period = 5.0;
    let (field, _) = invalid_option(compare(&xyz(), &Input::Cl(line()), "line", &o));
    assert_eq!(field, "solve.verify.period");
}

/// A quick solve of a turn of the head (for the G-code writer).
fn turn() -> (Machine, Toolpath, Solution) {
    let m = head_head();
    let tilted = Vector3::new(0.5, 0.0, 0.866_025).normalize();
    let t = toolpath(
        &[
            (Vector3::new(0.0, 0.0, 50.0), UP),
            (Vector3::new(10.0, 0.0, 50.0), tilted),
        ],
        Some(50.0),
    );
    let sol = optimize(&m, &t, &quick()).unwrap();
    (m, t, sol)
}

#[test]
fn rotation_per_block_at_least_0_001_degrees() {
    let (m, t, sol) = turn();
    let geometry = quick().geometry;
    for d in [1e-6, 0.0, -3.0, f64::NAN] {
        let o = GcodeOptions {
            dialect: Default::default(),
            max_rotation_deg: Some(d),
            block_feed: BlockFeed::Average,
        };
        let (field, reason) = invalid_option(program(&m, &t, &sol, &geometry, &o));
        assert_eq!(field, "max_rotation_deg");
        assert!(reason.contains("at least 0.001°"), "{reason}");
    }
    let o = GcodeOptions {
        dialect: Default::default(),
        max_rotation_deg: Some(1.0),
        block_feed: BlockFeed::Average,
    };
    program(&m, &t, &sol, &geometry, &o).unwrap();
}

#[test]
fn interpolation_period_from_1_us_to_1_s() {
    let m = xyz();
    let sol = optimize(&m, &line(), &quick()).unwrap();
    for p in [0.0, 1e-9, 2.0, f64::NAN] {
        let (field, reason) = invalid_option(feedopt::interpolate::sample(&m, &sol, p));
        assert_eq!(field, "period");
        assert!(reason.contains("1 µs to 1 s"), "{reason}");
    }
    feedopt::interpolate::sample(&m, &sol, 1e-3).unwrap();
}

/// `sweep` on the line refuses `o` (with the quick solve options), naming `field`.
fn sweep_refused(mut o: SweepOptions, field: &str, needles: &[&str]) {
    o.solve = quick();
    let (f, reason) = invalid_option(sweep(&xyz(), &Input::Cl(line()), "line", &o));
    assert_eq!(f, field, "{reason}");
    for n in needles {
        assert!(reason.contains(n), "`{n}` not in: {reason}");
    }
}

#[test]
fn sweep_values_positive_and_increasing() {
    let a = SweptLimit::Acceleration;
    sweep_refused(
        SweepOptions::new("X", a, 0.0, 500.0, 3),
        "from",
        &["positive"],
    );
    sweep_refused(
        SweepOptions::new("X", a, 500.0, f64::NAN, 3),
        "to",
        &["positive"],
    );
    sweep_refused(
        SweepOptions::new("X", a, 800.0, 500.0, 3),
        "to",
        &["greater than from"],
    );
}

#[test]
fn sweep_steps_from_1_to_max_steps() {
    let a = SweptLimit::Acceleration;
    sweep_refused(
        SweepOptions::new("X", a, 500.0, 800.0, 0),
        "steps",
        &["at least 1"],
    );
    sweep_refused(
        SweepOptions::new("X", a, 500.0, 800.0, MAX_STEPS + 1),
        "steps",
        &["10000"],
    );
}

#[test]
fn sweep_finite_difference_step_below_one_half() {
    let mut o = SweepOptions::new("X", SweptLimit::Velocity, 50.0, 80.0, 2);
    o.fd_step = 0.5;
    sweep_refused(o, "fd_step", &["(0, 0.5)"]);
}

#[test]
fn sweep_axis_of_the_machine_and_range_near_its_limit() {
    let v = SweptLimit::Velocity;
    sweep_refused(
        SweepOptions::new("Q", v, 50.0, 80.0, 2),
        "axis",
        &["no such axis", "X, Y, Z"],
    );
    // X's velocity limit is 100: 0.1 to 100,000 may be swept.
    sweep_refused(
        SweepOptions::new("X", v, 0.01, 80.0, 2),
        "from",
        &["X velocity limit (100)"],
    );
    sweep_refused(
        SweepOptions::new("X", v, 50.0, 2e5, 2),
        "to",
        &["1/1000 to 1000 times"],
    );
    let mut o = SweepOptions::new("X", v, 50.0, 80.0, 2);
    o.solve = quick();
    o.solve.geometry.feed_override = 0.0;
    let (field, _) = invalid_option(sweep(&xyz(), &Input::Cl(line()), "line", &o));
    assert_eq!(field, "solve.geometry.feed_override");
}

// -------------------------------------------------------------------------------------------
// Machines built in code
// -------------------------------------------------------------------------------------------

/// The field of `m`'s [`Error::InvalidMachine`]; `optimize` refuses it the same way, and the
/// message is one line naming the field.
fn machine_refused(m: &Machine, field: &str, needles: &[&str]) {
    let (f, reason) = match m.validate() {
        Err(Error::InvalidMachine { field, reason }) => (field, reason),
        other => panic!("expected an invalid machine, got {other:?}"),
    };
    assert_eq!(f, field, "{reason}");
    for n in needles {
        assert!(reason.contains(n), "`{n}` not in: {reason}");
    }
    let e = match optimize(m, &line(), &quick()) {
        Err(e @ Error::InvalidMachine { .. }) => e.to_string(),
        other => panic!("optimize: expected an invalid machine, got {other:?}"),
    };
    assert!(
        !e.contains('\n') && e.contains(&format!("`{field}`")),
        "{e}"
    );
}

#[test]
fn machines_read_from_files_are_valid() {
    xyz().validate().unwrap();
    head_head().validate().unwrap();
}

#[test]
fn a_limit_needs_min_below_zero_below_max() {
    let mut m = xyz();
    m.axes[0].velocity = Limit {
        min: 10.0,
        max: 100.0,
    };
    machine_refused(&m, "axes.X.velocity", &["min < 0 < max"]);
    let mut m = xyz();
    m.axes[1].acceleration = Limit::symmetric(f64::NAN);
    machine_refused(&m, "axes.Y.acceleration", &["min < 0 < max"]);
}

#[test]
fn limits_within_plausible_magnitudes() {
    let mut m = xyz();
    m.axes[2].acceleration = Limit::symmetric(1e10);
    machine_refused(&m, "axes.Z.acceleration", &["implausibly large", "mm/s²"]);
    let mut m = xyz();
    m.axes[0].velocity = Limit::symmetric(1e-9);
    machine_refused(&m, "axes.X.velocity", &["implausibly small"]);
    let mut m = xyz();
    m.axes[0].jerk = Some(Limit::symmetric(1e13));
    machine_refused(&m, "axes.X.jerk", &["implausibly large", "mm/s³"]);
}

#[test]
fn travel_min_below_max() {
    let mut m = xyz();
    m.axes[0].travel = Some((10.0, -10.0));
    machine_refused(&m, "axes.X.min", &["less than max"]);
    let mut m = xyz();
    m.axes[0].travel = Some((0.0, 1e9));
    machine_refused(&m, "axes.X.max", &["implausibly large"]);
}

#[test]
fn feed_max_a_plausible_positive_limit() {
    for f in [0.0, -5.0, f64::NAN] {
        let mut m = xyz();
        m.feed_max = Some(f);
        machine_refused(&m, "feed.max", &["positive"]);
    }
    let mut m = xyz();
    m.feed_max = Some(1e12);
    machine_refused(&m, "feed.max", &["implausibly large"]);
}

#[test]
fn kinematics_parameters_finite_and_plausible() {
    let mut m = head_head();
    m.kinematics = KinematicsSpec::HeadHead { tool_length: 0.0 };
    machine_refused(&m, "kinematics.tool_length", &["positive"]);
    m.kinematics = KinematicsSpec::HeadHead {
        tool_length: f64::INFINITY,
    };
    machine_refused(&m, "kinematics.tool_length", &["finite"]);
}

#[test]
fn the_axes_the_kinematics_needs_in_its_order() {
    let mut m = xyz();
    m.axes.swap(0, 1);
    machine_refused(&m, "axes", &["X Y Z", "Y X Z"]);
    let mut m = xyz();
    m.axes.pop();
    machine_refused(&m, "axes", &["X Y Z in that order"]);
    let mut m = head_head();
    m.axes[3].kind = AxisKind::Linear;
    machine_refused(&m, "axes.C.kind", &["Rotary"]);
}

#[test]
fn a_joint_space_machine_has_named_axes_and_no_feed_cap() {
    let joint = || {
        machine(
            r#"{"kinematics": {"type": "joint"},
                "axes": {"a": {"velocity": 1, "acceleration": 1},
                         "b": {"velocity": 1, "acceleration": 1}}}"#,
        )
    };
    joint().validate().unwrap();
    let bad = |m: &Machine, field: &str| match m.validate() {
        Err(Error::InvalidMachine { field: f, .. }) => assert_eq!(f, field),
        other => panic!("expected an invalid machine, got {other:?}"),
    };
    let mut m = joint();
    m.feed_max = Some(100.0);
    bad(&m, "feed.max");
    let mut m = joint();
    m.axes[1].name = "a".into();
    bad(&m, "axes[1].name");
    let mut m = joint();
    m.axes.clear();
    bad(&m, "axes");
}
