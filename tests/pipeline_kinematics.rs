//! The new kinematics through the whole pipeline: singular poses, travel, reader warnings.

use std::path::{Path, PathBuf};
use std::process::Command;

use feedopt::error::Error;
use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize};
use feedopt::toolpath::{ClPoint, Feed, Toolpath};
use nalgebra::Vector3;

fn path(points: Vec<(Vector3<f64>, Vector3<f64>)>) -> Toolpath {
    Toolpath {
        source: PathBuf::from("test.cls"),
        points: points
            .into_iter()
            .enumerate()
            .map(|(k, (p, o))| ClPoint {
                p,
                o: o.normalize(),
                feed: Feed::Programmed(50.0),
                rotary: None,
                line: k + 1,
            })
            .collect(),
        ..Default::default()
    }
}

/// The tip moves 40 mm along X while the tool swings in a plane that misses the vertical by
/// `miss` degrees, from 15° one side to 15° the other: the rotary axis about z must turn
/// through about 180° near the pole.
fn near_vertical_pass(miss_deg: f64) -> Toolpath {
    let miss = miss_deg.to_radians();
    path(
        (0..=400)
            .map(|k| {
                let s = k as f64 / 400.0;
                let tilt = (-15.0 + 30.0 * s).to_radians();
                let o = Vector3::new(tilt.sin(), miss.sin(), tilt.cos() * miss.cos());
                (Vector3::new(40.0 * s, 0.0, 0.0), o)
            })
            .collect(),
    )
}

fn machine(json: &str) -> Machine {
    Machine::from_json(Path::new("m.json"), json).unwrap()
}

const HEAD_HEAD: &str = r#"{"name": "hh", "kinematics": {"type": "head_head", "tool_length": 150},
    "axes": {"X": {"velocity": 400, "acceleration": 2000}, "Y": {"velocity": 400, "acceleration": 2000},
             "Z": {"velocity": 400, "acceleration": 2000}, "C": {"velocity": 90, "acceleration": 450},
             "A": {"velocity": 45, "acceleration": 300}}, "feed": {"max": 100}}"#;

const TRUNNION_AC: &str = r#"{"name": "ac", "kinematics": {"type": "table_table_ac",
      "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0, "y-offset": 20, "z-offset": 10},
    "axes": {"X": {"velocity": 400, "acceleration": 2000}, "Y": {"velocity": 400, "acceleration": 2000},
             "Z": {"velocity": 400, "acceleration": 2000}, "A": {"velocity": 45, "acceleration": 300},
             "C": {"velocity": 90, "acceleration": 450}}, "feed": {"max": 100}}"#;

#[test]
fn a_near_vertical_pass_slows_as_the_rotary_limits_require_and_nothing_is_nan() {
    for (name, json, c_axis) in [
        ("head_head", HEAD_HEAD, 3),
        ("table_table_ac", TRUNNION_AC, 4),
    ] {
        let m = machine(json);
        let wide = optimize(&m, &near_vertical_pass(5.0), &Options::default()).unwrap();
        let close = optimize(&m, &near_vertical_pass(0.5), &Options::default()).unwrap();
        for sol in [&wide, &close] {
            assert!(sol.verification.verified, "{name}");
            for (k, st) in sol.schedule.stations.iter().enumerate() {
                let sch = &sol.schedule;
                let all = sch.q(k).iter().chain(sch.qd(k)).chain(sch.qdd(k));
                assert!(
                    all.copied().chain([st.t, st.v, st.a]).all(f64::is_finite),
                    "{name}"
                );
            }
        }
        // C swings through ~180° either way, faster the closer the pass: the closer pass is
        // held down by C and takes longer.
        let c_range = |s: &feedopt::optimize::Solution| {
            let c = (0..s.schedule.stations.len()).map(|k| s.schedule.q(k)[c_axis]);
            c.clone().fold(f64::MIN, f64::max) - c.fold(f64::MAX, f64::min)
        };
        assert!(
            c_range(&close) > 150.0 && c_range(&close) < 210.0,
            "{name}: C range"
        );
        assert!(
            close.schedule.cycle_time > wide.schedule.cycle_time,
            "{name}: {} vs {}",
            close.schedule.cycle_time,
            wide.schedule.cycle_time
        );
        let summary = feedopt::report::Summary::new(&m, "pass", &close);
        assert!(
            summary.binding.iter().any(|b| b.name.starts_with('C')),
            "{name}: {:?}",
            summary.binding
        );
    }
}

#[test]
fn leaving_an_axis_travel_is_an_error_naming_the_axis_and_line() {
    let m = machine(
        r#"{"name": "small", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 100, "acceleration": 1000, "min": -10, "max": 10},
                     "Y": {"velocity": 100, "acceleration": 1000},
                     "Z": {"velocity": 100, "acceleration": 1000}}}"#,
    );
    let up = Vector3::z();
    let t = path(vec![
        (Vector3::zeros(), up),
        (Vector3::new(5.0, 0.0, 0.0), up),
        (Vector3::new(25.0, 0.0, 0.0), up),
    ]);
    let err = optimize(&m, &t, &Options::default()).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, Error::Infeasible(_)), "{msg}");
    // Checked on the CL points before the path is fitted: the program's line, at once.
    assert!(
        msg.contains("test.cls:3: axis X would be at 25.0000")
            && msg.contains("outside its travel [-10, 10]"),
        "{msg}"
    );
}

#[test]
fn reader_warnings_reach_the_user_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("m.json"),
        r#"{"name": "m", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 100, "acceleration": 1000},
                     "Y": {"velocity": 100, "acceleration": 1000},
                     "Z": {"velocity": 100, "acceleration": 1000}}}"#,
    )
    .unwrap();
    std::fs::write(
        dir.path().join("p.ngc"),
        "G21 G90 G0 X0 Y0\nG1 X10 F600\nG1 X20 M300\n",
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_feedopt"))
        .args(["solve", "-m", "m.json", "p.ngc", "--json"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning") && stderr.contains("p.ngc:3:"),
        "{stderr}"
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let w = json["warnings"].as_array().unwrap();
    assert!(
        w.iter().any(|x| x.as_str().unwrap().contains(":3:")),
        "{w:?}"
    );
}

const TRUNNION_AB: &str = r#"{"name": "haas-tr-like", "kinematics": {"type": "table_table_ab",
      "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0, "y-offset": 20, "z-offset": 10},
    "axes": {"X": {"velocity": 400, "acceleration": 2000}, "Y": {"velocity": 400, "acceleration": 2000},
             "Z": {"velocity": 400, "acceleration": 2000},
             "A": {"velocity": 45, "acceleration": 300, "min": -120, "max": 120},
             "B": {"velocity": 90, "acceleration": 450}}, "feed": {"max": 100}}"#;

/// A Fanuc/Haas program in tool-tip mode with A and B words, read for the A/B machine.
fn ab_program(machine: &Machine, text: &str) -> feedopt::error::Result<Toolpath> {
    use feedopt::machine::references_from_json;
    use feedopt::toolpath::MachineContext;
    use feedopt::toolpath::gcode::{Dialect, parse_for};
    let refs = references_from_json(Path::new("m.json"), TRUNNION_AB, machine)?;
    let ctx = MachineContext::new(machine, &refs);
    parse_for(Path::new("ab.nc"), text, Dialect::Fanuc.spec(), Some(&ctx))
}

#[test]
fn an_a_b_program_solves_on_an_a_b_trunnion() {
    let m = machine(TRUNNION_AB);
    let tp = ab_program(
        &m,
        "G21 G90 G94 G17\nG43.4 H1\nG0 X0. Y0. Z20. A0. B0.\nG1 Z5. F600.\n\
         G1 X20. Y0. A15. B45.\nG1 X30. Y10. A30. B90.\nG49\nM30\n",
    )
    .unwrap();
    assert_eq!(tp.points.len(), 4);
    assert_eq!(tp.points[3].rotary, Some([30.0, 90.0, 0.0]));
    let sol = optimize(&m, &tp, &Options::default()).unwrap();
    assert!(sol.verification.verified);
    assert!(sol.schedule.cycle_time.is_finite() && sol.schedule.cycle_time > 0.0);
    // The last station: A = 30°, B = 90° as programmed, and X Y Z by hand from the module
    // doc's inverse (r = 0, D = (0, 20, 10), L = 0, σ = +1) at P = (30, 10, 5):
    // R_z(90°)P − D = (−10, 10, −5); R_x(30°) of it = (−10, 10 cos30° + 5 sin30°,
    // 10 sin30° − 5 cos30°); + D.
    let last_q = sol.schedule.q(sol.schedule.stations.len() - 1);
    let (s30, c30) = 30f64.to_radians().sin_cos();
    let want = [
        -10.0,
        10.0 * c30 + 5.0 * s30 + 20.0,
        10.0 * s30 - 5.0 * c30 + 10.0,
        30.0,
        90.0,
    ];
    for (i, w) in want.iter().enumerate() {
        assert!(
            (last_q[i] - w).abs() < 1e-6,
            "axis {i}: {} vs {w}",
            last_q[i]
        );
    }
    // B turned through 90° at most 90 °/s: at least a second.
    assert!(sol.schedule.cycle_time > 1.0, "{}", sol.schedule.cycle_time);
}

#[test]
fn a_c_word_on_an_a_b_trunnion_is_an_error_naming_c() {
    let m = machine(TRUNNION_AB);
    let e = ab_program(&m, "G43.4 H1\nG0 X0. Y0. Z20. A0. B0.\nG1 X5. C10. F600.\n").unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains(":3:") && msg.contains("no C axis"), "{msg}");
}

#[test]
fn a_fanuc_block_turning_a_rotary_axis_takes_the_combined_distance_over_f() {
    // G1 X100. A90. F1000. outside tool-tip mode: a Fanuc control feeds √(100²+90²) at
    // 1000 per minute, 8.07 s (LinuxCNC's rule would give 100 mm at 1000 mm/min, 6 s). The
    // axes' limits are far above what the block needs, so only the ramps add a little.
    let m = machine(TRUNNION_AB);
    let tp = ab_program(
        &m,
        "G21 G90 G94 G17\nG0 X0. Y0. Z0. A0. B0.\nG1 X100. A90. F1000.\nM30\n",
    )
    .unwrap();
    let sol = optimize(&m, &tp, &Options::default()).unwrap();
    let want = (100f64.powi(2) + 90f64.powi(2)).sqrt() / 1000.0 * 60.0;
    let t = sol.schedule.cycle_time;
    assert!(t >= want * (1.0 - 1e-3) && t < want * 1.02, "{t} vs {want}");
}
