//! Seed 001's dresser end to end: a groove profile (line, 90° arc, line) written to 1 µm, its
//! tool on the profile normal. The profile is fitted by tangent-continuous lines and arcs and B
//! follows the fitted normal.

use std::path::{Path, PathBuf};

use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize};
use feedopt::toolpath::{ClPoint, Feed, Toolpath};
use nalgebra::Vector3;

fn groove() -> Toolpath {
    let round = |x: f64| (x * 1000.0).round() / 1000.0;
    let mut pts: Vec<(f64, f64, f64)> = Vec::new(); // (x, z, θ)
    for k in 0..=50 {
        pts.push((-10.0 + 0.2 * k as f64, 0.0, 0.0));
    }
    for k in 1..=39 {
        let phi = (90.0 * k as f64 / 39.0).to_radians();
        pts.push((5.0 * phi.sin(), -5.0 + 5.0 * phi.cos(), phi));
    }
    for k in 1..=50 {
        pts.push((5.0, -5.0 - 0.2 * k as f64, std::f64::consts::FRAC_PI_2));
    }
    Toolpath {
        source: PathBuf::from("groove.cls"),
        points: pts
            .iter()
            .enumerate()
            .map(|(k, &(x, z, t))| ClPoint {
                p: Vector3::new(round(x), 0.0, round(z)),
                o: Vector3::new(t.sin(), 0.0, t.cos()),
                feed: Feed::Programmed(20.0),
                rotary: None,
                line: k + 1,
            })
            .collect(),
        ..Default::default()
    }
}

fn dresser() -> Machine {
    Machine::from_json(
        Path::new("dresser.json"),
        r#"{"name": "dresser", "kinematics": {"type": "dresser", "tool_length": 10},
            "axes": {"X": {"velocity": 50, "acceleration": 500},
                     "Z": {"velocity": 50, "acceleration": 500},
                     "B": {"velocity": 60, "acceleration": 300}},
            "feed": {"max": 50}}"#,
    )
    .unwrap()
}

#[test]
fn a_groove_is_fitted_by_biarcs_and_b_follows_the_profile_normal() {
    let m = dresser();
    let t = groove();
    // The reach pass keeps the test quick; Clarabel agrees on such paths to 1e-7.
    let options = Options {
        solver_kind: feedopt::solver::SolverKind::Reach,
        ..Options::default()
    };
    let fitted = optimize(&m, &t, &options).unwrap();
    assert!(fitted.verification.verified);
    assert_eq!(fitted.problems.len(), 1, "tangent-continuous: one span");
    let (dev_mm, dev_rad) = fitted.path.spans[0].deviation;
    assert!(dev_mm <= 0.005 + 1e-9, "profile deviation {dev_mm}");
    assert!(
        dev_rad.to_degrees() < 0.5,
        "normal vs programmed tool: {}°",
        dev_rad.to_degrees()
    );
    // B (degrees) equals the normal angle of the true groove along the way: 0 on the first
    // line, 45 in the arc's middle, 90 on the last line.
    let b_at = |x: f64, z: f64| {
        let sch = &fitted.schedule;
        let d = |k: usize| {
            // X and Z are the B axis's position; the tip is 10 mm back along the normal.
            let q = sch.q(k);
            let th = q[2].to_radians();
            (q[0] - 10.0 * th.sin() - x).hypot(q[1] - 10.0 * th.cos() - z)
        };
        let k = (0..sch.stations.len())
            .min_by(|&a, &b| d(a).total_cmp(&d(b)))
            .unwrap();
        sch.q(k)[2]
    };
    assert!(b_at(-5.0, 0.0).abs() < 0.1);
    let s45 = 45f64.to_radians();
    assert!((b_at(5.0 * s45.sin(), -5.0 + 5.0 * s45.cos()) - 45.0).abs() < 1.0);
    assert!((b_at(5.0, -10.0) - 90.0).abs() < 0.1);
    // Through every rounded point exactly instead (tolerance 0). Fitting costs little time:
    // within 2.5 %. (It cost none while the exact cubic swung off the programmed chords between
    // points; since it follows them, within 1 µm, it runs 1.9 % faster than the fit here.)
    let mut exact = options.clone();
    exact.geometry.tolerance_mm = 0.0;
    exact.geometry.tolerance_deg = 0.0;
    let raw = optimize(&m, &t, &exact).unwrap();
    assert!(raw.verification.verified);
    eprintln!(
        "fitted {:.4} s, exact {:.4} s",
        fitted.schedule.cycle_time, raw.schedule.cycle_time
    );
    assert!(
        fitted.schedule.cycle_time <= raw.schedule.cycle_time * (1.0 + 2.5e-2),
        "fitted {} vs exact {}",
        fitted.schedule.cycle_time,
        raw.schedule.cycle_time
    );
}
