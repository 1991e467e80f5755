//! `feedopt solve --plot`: the SVG written, its labels and legend, errors before solving, and
//! the thinning of long series.

use std::process::Command;

use feedopt::writers::plot::thin;
use feedopt::writers::{PLOT, output_format};

const MACHINE: &str = r#"{"name": "test mill", "kinematics": {"type": "xyz"},
  "axes": {"X": {"velocity": 400, "acceleration": 2000},
           "Y": {"velocity": 400, "acceleration": 2000},
           "Z": {"velocity": 300, "acceleration": 1500}},
  "feed": {"max": 150}}"#;

/// 100 mm/s along a 100 mm line: the feed binds in the middle, X acceleration at both ends.
const LINE: &str = "FEDRAT/MMPM,6000\nGOTO/0,0,0\nGOTO/100,0,0\n";

fn feedopt(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_feedopt"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run feedopt")
}

#[test]
fn solve_plot_writes_an_svg_with_labels_limits_and_binding_legend() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("m.json"), MACHINE).unwrap();
    std::fs::write(tmp.path().join("line.cls"), LINE).unwrap();
    let out = feedopt(
        tmp.path(),
        &[
            "solve",
            "-m",
            "m.json",
            "line.cls",
            "--stations",
            "200",
            "--plot",
            "p.svg",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(tmp.path().join("p.svg")).unwrap();
    assert!(svg.starts_with("<svg"));
    for text in [
        "tool-tip path length s (mm)",
        "feed V (mm/s)",
        "time t (s)",
        "|velocity| / limit",
        "|acceleration| / limit",
        "feed V held by feed",
        "feed V held by X acceleration",
        "feed cap",
        "maximum-velocity curve",
    ] {
        assert!(svg.contains(text), "the plot lacks `{text}`");
    }
    // Only the plot and the inputs: the temporary file was renamed into place.
    let n = std::fs::read_dir(tmp.path()).unwrap().count();
    assert_eq!(n, 3);
}

#[test]
fn bad_plot_paths_fail_before_solving() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("m.json"), MACHINE).unwrap();
    // An unreadable toolpath: the plot error must come first, so nothing was read or solved.
    for (plot, says) in [
        ("p.png", "PNG plots are not supported"),
        ("p.pdf", "unknown plot format"),
        ("missing/p.svg", "does not exist"),
    ] {
        let out = feedopt(
            tmp.path(),
            &["solve", "-m", "m.json", "absent.cls", "--plot", plot],
        );
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{plot}: {err}");
    }
    assert!(output_format("a.SVG".as_ref(), PLOT).is_ok());
}

#[test]
fn joint_space_plots_label_the_path_parameter() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(
        tmp.path().join("m.json"),
        r#"{"name": "two joints", "kinematics": {"type": "joint"},
           "axes": {"0": {"velocity": 2, "acceleration": 5},
                    "1": {"velocity": 1, "acceleration": 4}}}"#,
    )
    .unwrap();
    let mut csv = String::from("s,q_0,q_1\n");
    for k in 0..=20 {
        let s = k as f64 / 20.0;
        csv += &format!("{s},{},{}\n", s, (3.0 * s).sin());
    }
    std::fs::write(tmp.path().join("p.csv"), csv).unwrap();
    let out = feedopt(
        tmp.path(),
        &[
            "solve",
            "-m",
            "m.json",
            "p.csv",
            "--stations",
            "200",
            "--plot",
            "p.svg",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(tmp.path().join("p.svg")).unwrap();
    assert!(svg.contains("path parameter s") && svg.contains("ds/dt"));
    assert!(!svg.contains("tool-tip path length"));
}

#[test]
fn thinning_keeps_every_bin_extreme() {
    // A fast oscillation under a slow envelope: 200,000 points.
    let pts: Vec<(f64, f64)> = (0..200_000)
        .map(|i| {
            let x = i as f64 * 1e-3;
            (x, (x * 0.05).sin() + 0.3 * (x * 40.0).sin())
        })
        .collect();
    let t = thin(&pts);
    assert!(t.len() < 10_000, "{} points kept", t.len());
    let max = |p: &[(f64, f64)]| p.iter().map(|q| q.1).fold(f64::MIN, f64::max);
    let min = |p: &[(f64, f64)]| p.iter().map(|q| q.1).fold(f64::MAX, f64::min);
    assert_eq!(max(&t), max(&pts));
    assert_eq!(min(&t), min(&pts));
    assert_eq!(t.first(), pts.first());
    assert_eq!(t.last(), pts.last());
    assert!(t.windows(2).all(|w| w[0].0 <= w[1].0), "order kept");
    // Short series are left alone.
    assert_eq!(thin(&pts[..100]), pts[..100].to_vec());
}
