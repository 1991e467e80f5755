//! Work bounded before it starts, and solver failure that is not the user's problem (issue 14,
//! the parts in the solve pipeline).

use std::path::Path;

use feedopt::error::Error;
use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize, optimize_input};
use feedopt::solver::{SolverSettings, Status};
use feedopt::toolpath;
use nalgebra::Vector3;

mod common;
use common::{UP, machine, toolpath};

const XYZ: &str = r#"{"name": "xyz", "kinematics": {"type": "xyz"},
    "axes": {"X": {"velocity": 500, "acceleration": 3000},
             "Y": {"velocity": 500, "acceleration": 3000},
             "Z": {"velocity": 500, "acceleration": 3000}},
    "feed": {"max": 500}}"#;

fn square(feed: f64) -> toolpath::Toolpath {
    let pts = [
        (Vector3::zeros(), UP),
        (Vector3::new(10.0, 0.0, 0.0), UP),
        (Vector3::new(10.0, 10.0, 0.0), UP),
    ];
    toolpath(&pts, Some(feed))
}

/// A feed of 1e-7 mm/s (6e-6 mm/min) makes a 20 mm path last months: the re-simulation at 1 ms
/// would take ~1e11 instants. Refused at once, naming the CL line of the slowest stretch.
#[test]
fn a_schedule_too_long_to_re_simulate_is_refused_up_front() {
    let t0 = std::time::Instant::now();
    let err = optimize(&machine(XYZ), &square(1e-7), &Options::default())
        .expect_err("months of motion at 1 ms");
    let msg = err.to_string();
    assert!(
        msg.contains("servo instants") && msg.contains("CL line"),
        "{msg}"
    );
    assert!(!msg.contains('\n'));
    // No sample was taken: the refusal comes before the work (generous bound for debug builds).
    assert!(t0.elapsed().as_secs_f64() < 30.0);
}

/// A feed so small its square underflows leaves b = 0 over whole intervals: an error naming the
/// span, the CL line and the limit, not a NaN or an infinite time.
#[test]
fn a_zero_feed_names_where_and_which_limit() {
    let err =
        optimize(&machine(XYZ), &square(1e-170), &Options::default()).expect_err("no speed at all");
    let Error::Infeasible(msg) = &err else {
        panic!("not an infeasibility: {err}")
    };
    assert!(
        msg.contains("span 0") && msg.contains("CL line") && msg.contains("programmed feed"),
        "{msg}"
    );
}

/// Clarabel stopped by its time limit (here: none at all) is not an error: the windows it did
/// not finish keep the feasible reach profile, the status says so, and the schedule verifies.
#[test]
fn clarabel_out_of_time_falls_back_to_the_reach_profile() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems/xyz_pocket");
    let m = Machine::from_file(&root.join("machine.json")).expect("machine");
    let input = toolpath::read_input(&root.join("pocket_contour.cls")).expect("toolpath");
    let default = optimize_input(&m, &input, &Options::default()).expect("solves");
    let no_time = Options {
        solver: SolverSettings {
            time_limit: 0.0,
            ..SolverSettings::default()
        },
        ..Options::default()
    };
    let fallback = optimize_input(&m, &input, &no_time).expect("solves without Clarabel");
    assert_eq!(fallback.status, Status::Greedy);
    assert!(fallback.verification.verified);
    // The reach profile is feasible, so never faster than the optimum (up to the solver's gap).
    assert!(fallback.schedule.cycle_time >= default.schedule.cycle_time * (1.0 - 1e-6));
    assert_eq!(default.status, Status::Optimal);
}
