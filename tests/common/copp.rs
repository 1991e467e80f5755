//! The COPP benchmark's limits as a feedopt machine file (shared by tests/copp.rs and
//! benches/copp.rs; the data stay in ../shared).

use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// The machine file (kinematics `joint`, axis j named `j` as the CSV's `q_j`) of a COPP path's
/// `limits` (`vel_min`, `vel_max`, `acc_min`, `acc_max` arrays).
#[allow(dead_code)]
pub fn machine_json(limits: &Value) -> String {
    machine_json_with(limits, false)
}

/// The same with the jerk limits (`jerk_min`, `jerk_max`) too.
#[allow(dead_code)]
pub fn machine_json_jerk(limits: &Value) -> String {
    machine_json_with(limits, true)
}

fn machine_json_with(limits: &Value, jerk: bool) -> String {
    let arr = |key: &str| -> Vec<f64> {
        limits[key]
            .as_array()
            .unwrap_or_else(|| panic!("limits.{key} is an array"))
            .iter()
            .map(|v| v.as_f64().expect("a number"))
            .collect()
    };
    let (vmin, vmax, amin, amax) = (
        arr("vel_min"),
        arr("vel_max"),
        arr("acc_min"),
        arr("acc_max"),
    );
    let mut axes = serde_json::Map::new();
    for j in 0..vmax.len() {
        let mut axis = json!({"velocity": [vmin[j], vmax[j]], "acceleration": [amin[j], amax[j]]});
        if jerk {
            axis["jerk"] = json!([arr("jerk_min")[j], arr("jerk_max")[j]]);
        }
        axes.insert(j.to_string(), axis);
    }
    json!({"name": "COPP random 7-axis", "kinematics": {"type": "joint"}, "axes": axes}).to_string()
}

/// The shared benchmark folder (`../shared/bench/copp_random7`), or `None` with a note on
/// stderr when it is absent.
#[allow(dead_code)]
pub fn data_dir() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/bench/copp_random7");
    if dir.join("path_000.json").is_file() {
        Some(dir)
    } else {
        eprintln!("skipping: {} is absent", dir.display());
        None
    }
}
