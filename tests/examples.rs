//! The programs in `examples/` run and their output holds against physics: `cargo test` builds
//! them (next to the test binaries, in `target/<profile>/examples/`), this runs them.
//!
//! - `solve_apt`: the seed blade verifies, is no faster than its length at the feed cap, and
//!   gives the cycle time `feedopt solve` gives.
//! - `constraint_study`: the cycle time falls as the acceleration limit rises, and the
//!   sensitivity from the duals agrees with the finite differences.
//! - `custom_kinematics`: the user's double swivel head gives the cycle time of the built-in
//!   one it mimics.
//! - `joint_path`: a straight joint-space move takes the closed-form time of its binding axis
//!   (trapezoid L/v + v/a, or triangle 2√(L/a)).

use std::path::PathBuf;
use std::process::Command;

/// `target/<profile>/examples/NAME`, beside this test's `deps/` directory.
fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    let profile = exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("target/<profile>/deps");
    let path = profile
        .join("examples")
        .join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        path.is_file(),
        "{} missing: `cargo test` builds the examples (or `cargo build --examples`)",
        path.display()
    );
    path
}

/// Runs example `name` with `args`; its stdout (it must succeed).
fn run(name: &str, args: &[&str]) -> String {
    let out = Command::new(example(name))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("example runs");
    assert!(
        out.status.success(),
        "{name} {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The first number after `label` on the line that starts with it.
fn value(out: &str, label: &str) -> f64 {
    let line = out
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no `{label}` in:\n{out}"));
    line[label.len()..]
        .split(|c: char| c.is_whitespace() || c == ',')
        .find_map(|w| w.parse::<f64>().ok())
        .unwrap_or_else(|| panic!("no number in `{line}`"))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn solve_apt_gives_the_command_lines_cycle_time() {
    let out = run("solve_apt", &[]);
    let (t, length) = (value(&out, "cycle time"), value(&out, "path length"));
    assert!(out.contains("verified        true"), "{out}");
    // No faster than the whole length at the machine's feed cap (150 mm/s).
    assert!(t > length / 150.0, "{t} s for {length} mm");
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/problems/seed_head_head");
    let cli = Command::new(env!("CARGO_BIN_EXE_feedopt"))
        .args(["solve", "--json", "-m", &format!("{dir}/machine.json")])
        .arg(format!("{dir}/impeller_blade.cls"))
        .output()
        .expect("feedopt runs");
    assert!(cli.status.success());
    let json: serde_json::Value = serde_json::from_slice(&cli.stdout).expect("JSON");
    let t_cli = json["cycle_time_s"].as_f64().expect("cycle_time_s");
    assert!(
        rel(t, t_cli) < 1e-6,
        "example {t} s, feedopt solve {t_cli} s"
    );
}

#[test]
fn constraint_study_cycle_time_falls_as_the_limit_rises() {
    let out = run("constraint_study", &["3"]);
    let rows: Vec<Vec<f64>> = out
        .lines()
        .skip(1)
        .map(|l| l.split_whitespace().map(|w| w.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 3, "{out}");
    for w in rows.windows(2) {
        assert!(w[1][0] > w[0][0] && w[1][1] < w[0][1], "{out}");
    }
    for r in &rows {
        let (dual, fd) = (r[2], r[3]);
        assert!(dual < 0.0 && fd < 0.0, "{out}");
        assert!(rel(fd, dual) < 0.01, "dual {dual}, fd {fd}");
    }
}

#[test]
fn custom_kinematics_gives_the_builtin_cycle_time() {
    let out = run("custom_kinematics", &[]);
    let custom = value(&out, "custom kinematics");
    let builtin = value(&out, "built-in head_head");
    assert!(!out.contains("verified false"), "{out}");
    assert!(rel(custom, builtin) < 1e-3, "{out}");
    // The table holds the feed down: the nonlinear part of the user's kinematics matters.
    assert!(out.contains("custom binding        Y velocity"), "{out}");
}

#[test]
fn joint_path_takes_the_closed_form_time() {
    // L = 50 ≥ v²/a = 10: a trapezoid on axis a.
    let out = run("joint_path", &["50", "100", "1000"]);
    assert!(
        rel(value(&out, "cycle time"), 50.0 / 100.0 + 100.0 / 1000.0) < 1e-6,
        "{out}"
    );
    assert!((value(&out, "axis a") - 1.0).abs() < 1e-3, "{out}");
    assert!((value(&out, "axis b") - 0.5).abs() < 1e-3, "{out}");
    // L = 5 < 10: a triangle, peak velocity √(aL) ≈ 70.7 mm/s.
    let out = run("joint_path", &["5", "100", "1000"]);
    let t = 2.0 * (5.0f64 / 1000.0).sqrt();
    assert!(rel(value(&out, "cycle time"), t) < 1e-6, "{out}");
    assert!(
        rel(value(&out, "axis a"), (1000.0f64 * 5.0).sqrt() / 100.0) < 1e-3,
        "{out}"
    );
}
