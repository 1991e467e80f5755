//! Helpers shared by the integration tests: in-memory machines and toolpaths.
#![allow(dead_code)] // each test binary uses its own subset

use std::path::PathBuf;

use feedopt::machine::Machine;
use feedopt::toolpath::{ClPoint, Feed, Toolpath};
use nalgebra::Vector3;

/// An A/C trunnion (LinuxCNC's xyzac-trt, the table's centre at the origin), no jerk limits, A
/// at 60 °/s and 600 °/s², the linear axes far faster than a tip needs in a test.
pub const AC_TABLE: &str = r#"{"name": "A/C table", "kinematics": {"type": "table_table_ac",
      "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0,
      "y-offset": 0, "z-offset": 0, "conventional-directions": true},
    "axes": {"X": {"velocity": 500, "acceleration": 5000},
             "Y": {"velocity": 500, "acceleration": 5000},
             "Z": {"velocity": 500, "acceleration": 5000},
             "A": {"velocity": 60, "acceleration": 600, "min": -120, "max": 120},
             "C": {"velocity": 120, "acceleration": 1200}},
    "feed": {"max": 2000}}"#;

/// A VMC with a rotary table on `letter` (A, B or C: 100 °/s, 500 °/s²), as machine-file JSON.
pub fn four_axis_json(letter: char) -> String {
    format!(
        r#"{{"name": "4-axis", "kinematics": {{"type": "xyz{}"}},
            "axes": {{"X": {{"velocity": 500, "acceleration": 3000}},
                     "Y": {{"velocity": 500, "acceleration": 3000}},
                     "Z": {{"velocity": 500, "acceleration": 3000}},
                     "{letter}": {{"velocity": 100, "acceleration": 500, "min": -720, "max": 720}}}},
            "feed": {{"max": 500}}}}"#,
        letter.to_ascii_lowercase()
    )
}

/// Every one of `parts` is in the message `e`.
pub fn assert_mentions(e: &str, parts: &[&str]) {
    for part in parts {
        assert!(e.contains(part), "{part:?} not in: {e}");
    }
}

/// A machine from JSON text (must be valid).
pub fn machine(json: &str) -> Machine {
    Machine::from_json("test.json".as_ref(), json).expect("valid machine")
}

/// A toolpath through (tip, tool vector) pairs, all at `feed_mm_s` (or unspecified).
pub fn toolpath(points: &[(Vector3<f64>, Vector3<f64>)], feed_mm_s: Option<f64>) -> Toolpath {
    Toolpath {
        source: PathBuf::from("test.cls"),
        points: points
            .iter()
            .enumerate()
            .map(|(k, (p, o))| ClPoint {
                p: *p,
                o: o.normalize(),
                feed: feed_mm_s.map_or(Feed::Unspecified, Feed::Programmed),
                rotary: None,
                line: k + 1,
            })
            .collect(),
        ..Default::default()
    }
}

/// The tool pointing up.
pub const UP: Vector3<f64> = Vector3::new(0.0, 0.0, 1.0);

/// Runs the `feedopt` binary with `args` from the crate's root.
pub fn feedopt(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_feedopt"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}
