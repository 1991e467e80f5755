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
        warnings: Vec::new(),
        dwells: Vec::new(),
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
            for st in &sol.schedule.stations {
                let all = st.q.iter().chain(&st.qd).chain(&st.qdd);
                assert!(
                    all.copied().chain([st.t, st.v, st.a]).all(f64::is_finite),
                    "{name}"
                );
            }
        }
        // C swings through ~180° either way, faster the closer the pass: the closer pass is
        // held down by C and takes longer.
        let c_range = |s: &feedopt::optimize::Solution| {
            let c = s.schedule.stations.iter().map(|st| st.q[c_axis]);
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
            summary.binding.iter().any(|b| b.limit.starts_with('C')),
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
    assert!(
        msg.contains("axis X") && msg.contains("travel") && msg.contains("CL line"),
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
