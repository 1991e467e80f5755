//! Each distinct span problem solved once (`Options::reuse_spans`): a program that repeats
//! moves (a drilling cycle at every hole) gets the schedule it gets when every span is solved
//! on its own, bit for bit, with the repeated solves answered from the first.

mod common;

use feedopt::optimize::{Options, Solution, optimize};
use feedopt::toolpath::Toolpath;
use feedopt::toolpath::gcode::{Dialect, parse};
use std::path::Path;

/// A three-axis mill; with `jerk`, jerk limits of 10 × the acceleration per second.
fn mill(jerk: bool) -> feedopt::machine::Machine {
    let j = if jerk { r#", "jerk": 20000"# } else { "" };
    let axis = format!(r#"{{"velocity": 200, "acceleration": 2000{j}}}"#);
    common::machine(&format!(
        r#"{{"kinematics": {{"type": "xyz"}}, "feed": {{"max": 200}},
            "axes": {{"X": {axis}, "Y": {axis}, "Z": {axis}}}}}"#
    ))
}

/// G81 drilling at a row of holes 5 mm apart, then a second row at another depth and feed:
/// the plunges and retracts of a row are the same problem at every hole, the rows' are not.
fn drilling() -> Toolpath {
    let mut text = String::from("G21 G90 G17\nG0 X0 Y0 Z20\nG98 G81 Z-10 R2 F300\n");
    for k in 0..6 {
        text.push_str(&format!("X{} Y0\n", 5 * k));
    }
    text.push_str("G98 G81 Z-12.5 R1 F240\n");
    for k in 0..5 {
        text.push_str(&format!("X{} Y7\n", 5 * k));
    }
    text.push_str("G80\nG0 Z50\nM30\n");
    parse(Path::new("holes.ngc"), &text, Dialect::LinuxCnc).unwrap_or_else(|e| panic!("{e}"))
}

fn solve(jerk: bool, reuse: bool) -> Solution {
    let options = Options {
        reuse_spans: reuse,
        ..Options::default()
    };
    optimize(&mill(jerk), &drilling(), &options).expect("solves")
}

/// The same schedule, bit for bit: stations, profiles and cycle time.
fn assert_same(a: &Solution, b: &Solution) {
    assert_eq!(
        a.schedule.cycle_time.to_bits(),
        b.schedule.cycle_time.to_bits()
    );
    assert_eq!(a.problems.len(), b.problems.len());
    for (si, (p, q)) in a.problems.iter().zip(&b.problems).enumerate() {
        assert_eq!(p.u, q.u, "span {si}: stations");
    }
    for (si, (s, t)) in a.solutions.iter().zip(&b.solutions).enumerate() {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&s.b), bits(&t.b), "span {si}: b");
        assert_eq!(
            s.a.as_deref().map(bits),
            t.a.as_deref().map(bits),
            "span {si}: ü"
        );
        assert_eq!(s.slopes, t.slopes, "span {si}: a'");
    }
}

#[test]
fn repeated_holes_are_solved_once_and_give_the_same_schedule() {
    for jerk in [false, true] {
        let (on, off) = (solve(jerk, true), solve(jerk, false));
        assert!(on.verification.verified && off.verification.verified);
        assert_same(&on, &off);
        assert_eq!(off.reused_solves, 0);
        // Eleven holes in two rows: at least the nine later plunges and retracts reuse.
        assert!(
            on.reused_solves >= 2 * 9,
            "jerk {jerk}: {} solves reused",
            on.reused_solves
        );
        eprintln!(
            "jerk {jerk}: {} of the span solves reused, {} IP iterations against {}",
            on.reused_solves, on.iterations, off.iterations
        );
        // Without jerk limits these spans are exact in the lattice relaxation (no interior
        // point iterations either way); with them each solve is a sequential programme.
        if jerk {
            assert!(on.iterations < off.iterations);
        } else {
            assert!(on.iterations <= off.iterations);
        }
    }
}

/// The same shape at another place is the same problem only where the limits do not depend
/// on where the axes stand: the key is the stations, the bounds and the axis derivatives,
/// so a move that differs in any of them (here one hole 1 µm deeper) is solved on its own.
#[test]
fn a_hole_that_differs_is_solved_on_its_own() {
    let text = "G21 G90\nG0 X0 Y0 Z20\nG98 G81 Z-10 R2 F300\nX0\nX5\nX10 Z-10.001\nG80\nM30\n";
    let tp = parse(Path::new("h.ngc"), text, Dialect::LinuxCnc).expect("reads");
    let m = mill(false);
    let on = optimize(&m, &tp, &Options::default()).expect("solves");
    let off = optimize(
        &m,
        &tp,
        &Options {
            reuse_spans: false,
            ..Options::default()
        },
    )
    .expect("solves");
    assert_same(&on, &off);
    // The plunge at X5 is X0's, and so is its retract (the deeper hole's differ: were they
    // taken from another, its profile would not be the one solved without reuse).
    assert!(on.reused_solves >= 2, "{}", on.reused_solves);
}
