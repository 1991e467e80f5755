//! `feedopt interpolate`: setpoints at a fixed period follow the schedule's motion, stay within
//! every axis limit when differentiated numerically, match the closed-form trapezoid and
//! triangle profiles of a straight line, and survive the binary file round trip.

mod common;

use std::path::{Path, PathBuf};

use feedopt::interpolate::{Setpoints, sample};
use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize};
use feedopt::solver::SolverKind;
use feedopt::toolpath;
use feedopt::writers::setpoints::{read_setpoints_bin, setpoints_bin, setpoints_csv};
use nalgebra::Vector3;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn seed_setpoints(period: f64) -> (Machine, Setpoints, f64, f64) {
    let m = Machine::from_file(&root().join("problems/seed_head_head/machine.json")).unwrap();
    let t = toolpath::read(&root().join("problems/seed_head_head/impeller_blade.cls")).unwrap();
    let sol = optimize(&m, &t, &Options::default()).unwrap();
    let sp = sample(&m, &sol, period).unwrap();
    let length = sol.schedule.stations.last().unwrap().s;
    (m, sp, sol.schedule.cycle_time, length)
}

#[test]
fn finite_differences_of_the_setpoints_stay_within_every_axis_limit() {
    let period = 1e-3;
    let (m, sp, cycle, length) = seed_setpoints(period);
    let s = &sp.samples;
    // t = kT up to the cycle time, and the final instant itself.
    assert_eq!(s.len(), (cycle / period).ceil() as usize + 1);
    assert_eq!(s.last().unwrap().t, cycle);
    assert!(
        s.windows(2)
            .all(|w| w[1].t > w[0].t && w[1].t - w[0].t <= period * (1.0 + 1e-9))
    );
    let tol = 1.001;
    let (mut worst_v, mut worst_a) = (0.0f64, 0.0f64);
    for (j, axis) in m.axes.iter().enumerate() {
        for k in 0..s.len() - 1 {
            let h = s[k + 1].t - s[k].t;
            let v = (s[k + 1].q[j] - s[k].q[j]) / h;
            assert!(!v.is_nan());
            let r = axis.velocity.ratio(v);
            worst_v = worst_v.max(r);
            assert!(r <= tol, "{} velocity {v} at t = {}", axis.name, s[k].t);
            if k > 0 {
                // Second difference on a possibly uneven last step.
                let h0 = s[k].t - s[k - 1].t;
                let a = 2.0 * ((s[k + 1].q[j] - s[k].q[j]) / h - (s[k].q[j] - s[k - 1].q[j]) / h0)
                    / (h + h0);
                assert!(!a.is_nan());
                let r = axis.acceleration.ratio(a);
                worst_a = worst_a.max(r);
                assert!(r <= tol, "{} acceleration {a} at t = {}", axis.name, s[k].t);
            }
        }
    }
    // The schedule is time-optimal: some axis runs at its acceleration limit.
    assert!(worst_a > 0.9, "worst acceleration ratio {worst_a}");
    eprintln!("worst ratios: velocity {worst_v:.5}, acceleration {worst_a:.5}");
    // The feed never exceeds the machine's maximum (the programmed feeds are lower still).
    let fmax = m.feed_max.unwrap();
    assert!(s.iter().all(|x| x.feed.is_finite() && x.feed <= fmax * tol));
    // s never decreases, never outruns the maximum feed, and ends at the schedule's length.
    for w in s.windows(2) {
        let ds = w[1].s - w[0].s;
        assert!(
            ds >= -1e-12 && ds <= fmax * tol * (w[1].t - w[0].t),
            "Δs {ds}"
        );
    }
    assert!((s.last().unwrap().s - length).abs() < 1e-9 * length);
}

/// Setpoints of a straight line of length `len` along X on an xyz machine with velocity and
/// acceleration limits `v`, `a`, rest to rest, on 1,000 stations (the profile's kinks at
/// u = v²/2a and len − v²/2a fall on stations for the values used).
fn line(len: f64, v: f64, a: f64, period: f64) -> (Setpoints, f64) {
    let m = common::machine(&format!(
        r#"{{"name": "line", "kinematics": {{"type": "xyz"}},
            "axes": {{"X": {{"velocity": {v}, "acceleration": {a}}},
                     "Y": {{"velocity": {v}, "acceleration": {a}}},
                     "Z": {{"velocity": {v}, "acceleration": {a}}}}}}}"#
    ));
    let t = common::toolpath(
        &[
            (Vector3::new(0.0, 0.0, 0.0), common::UP),
            (Vector3::new(len, 0.0, 0.0), common::UP),
        ],
        None,
    );
    let options = Options {
        solver_kind: SolverKind::Reach,
        stations: Some(1000),
        ..Options::default()
    };
    let sol = optimize(&m, &t, &options).unwrap();
    (sample(&m, &sol, period).unwrap(), sol.schedule.cycle_time)
}

/// Position of the trapezoid (or triangle) profile at t: accelerate at a to v_peak, cruise,
/// brake at a.
fn trapezoid(len: f64, v: f64, a: f64, t: f64) -> (f64, f64) {
    let vp = v.min((a * len).sqrt());
    let ta = vp / a;
    let total = 2.0 * ta + (len - vp * ta) / vp;
    if t <= ta {
        (0.5 * a * t * t, a * t)
    } else if t <= total - ta {
        (0.5 * vp * ta + vp * (t - ta), vp)
    } else {
        let r = total - t;
        (len - 0.5 * a * r * r, a * r)
    }
}

#[test]
fn a_straight_line_follows_the_trapezoid_and_the_triangle() {
    for (len, v, a) in [(100.0, 100.0, 1000.0), (4.0, 1000.0, 1000.0)] {
        let (sp, cycle) = line(len, v, a, 1e-3);
        let vp = v.min((a * len).sqrt());
        let expect = 2.0 * vp / a + (len - vp * vp / a) / vp;
        assert!(
            (cycle - expect).abs() < 1e-9 * expect,
            "T {cycle} vs {expect}"
        );
        for s in &sp.samples {
            let (x, feed) = trapezoid(len, v, a, s.t);
            assert!(
                (s.q[0] - x).abs() < 1e-9 * len,
                "t {}: x {} vs {x}",
                s.t,
                s.q[0]
            );
            assert!(
                (s.feed - feed).abs() < 1e-9 * v,
                "t {}: feed {} vs {feed}",
                s.t,
                s.feed
            );
            assert!((s.s - x).abs() < 1e-9 * len);
            assert!((s.qd[0] - feed).abs() < 1e-9 * v);
            assert_eq!((s.q[1], s.q[2]), (0.0, 0.0));
        }
        let last = sp.samples.last().unwrap();
        assert_eq!((last.t, last.q[0]), (cycle, len));
    }
}

#[test]
fn the_binary_file_reads_back_and_the_csv_names_its_units() {
    let (sp, _) = line(4.0, 1000.0, 1000.0, 5e-4);
    let bytes = setpoints_bin(&sp).unwrap();
    let src = Path::new("line.bin");
    let back = read_setpoints_bin(src, &bytes).unwrap();
    assert_eq!(
        (back.axes.clone(), back.kinds.clone()),
        (sp.axes.clone(), sp.kinds.clone())
    );
    assert_eq!((back.period, back.joint), (sp.period, sp.joint));
    assert_eq!(back.samples.len(), sp.samples.len());
    for (a, b) in back.samples.iter().zip(&sp.samples) {
        assert_eq!((a.t, a.s, a.feed, a.q), (b.t, b.s, b.feed, b.q));
    }
    // Header 8 + 4·3 + 8 + 8, axes 3 × (1 + 1 + 1), records (3 + 3) f64.
    assert_eq!(bytes.len(), 36 + 9 + sp.samples.len() * 48);
    // Damaged files are errors, never panics.
    assert!(read_setpoints_bin(src, &bytes[..bytes.len() - 3]).is_err());
    assert!(read_setpoints_bin(src, &bytes[..20]).is_err());
    let mut bad = bytes.clone();
    bad[0] = b'X';
    assert!(read_setpoints_bin(src, &bad).is_err());
    let csv = setpoints_csv(&sp);
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t_s,s_mm,feed_mm_s,X_mm,Y_mm,Z_mm"));
    assert_eq!(lines.count(), sp.samples.len());
}

#[test]
fn the_cli_writes_csv_and_binary_setpoints() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["pocket.csv", "pocket.bin"] {
        let out = dir.path().join(name);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_feedopt"))
            .args([
                "interpolate",
                "--solver",
                "reach",
                "--period",
                "2ms",
                "--machine",
                "problems/xyz_pocket/machine.json",
                "problems/xyz_pocket/pocket_contour.cls",
                "-o",
                out.to_str().unwrap(),
            ])
            .current_dir(root())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(out.exists());
    }
    let bytes = std::fs::read(dir.path().join("pocket.bin")).unwrap();
    let sp = read_setpoints_bin(Path::new("pocket.bin"), &bytes).unwrap();
    assert_eq!(sp.period, 2e-3);
    let csv = std::fs::read_to_string(dir.path().join("pocket.csv")).unwrap();
    assert_eq!(csv.lines().count(), sp.samples.len() + 1);
    // An unknown extension is refused before any work.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_feedopt"))
        .args([
            "interpolate",
            "--machine",
            "problems/xyz_pocket/machine.json",
            "problems/xyz_pocket/pocket_contour.cls",
            "-o",
            dir.path().join("x.txt").to_str().unwrap(),
        ])
        .current_dir(root())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// More setpoints than [`feedopt::interpolate::MAX_SAMPLES`] are refused before sampling, with
/// the period that would do.
#[test]
fn too_many_setpoints_are_refused_before_sampling() {
    let m = common::machine(
        r#"{"name": "line", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 10, "acceleration": 100},
                     "Y": {"velocity": 10, "acceleration": 100},
                     "Z": {"velocity": 10, "acceleration": 100}}}"#,
    );
    let t = common::toolpath(
        &[
            (Vector3::new(0.0, 0.0, 0.0), common::UP),
            (Vector3::new(1000.0, 0.0, 0.0), common::UP),
        ],
        None,
    );
    let options = Options {
        solver_kind: SolverKind::Reach,
        stations: Some(100),
        ..Options::default()
    };
    let sol = optimize(&m, &t, &options).unwrap();
    // 100.1 s: 100,100 setpoints at 1 ms, 100.1 million at 1 µs.
    assert!(sample(&m, &sol, 1e-3).is_ok());
    let t0 = std::time::Instant::now();
    let e = sample(&m, &sol, 1e-6).expect_err("too many setpoints");
    assert!(t0.elapsed().as_secs_f64() < 0.5, "{:?}", t0.elapsed());
    let text = e.to_string();
    assert!(
        text.contains("40000000 setpoints") && text.contains("at least 2.5"),
        "{text}"
    );
}

/// `feedopt interpolate` writes the setpoints as they are sampled
/// ([`feedopt::writers::setpoints::write_sampled`]): the same bytes as the file of all the
/// setpoints sampled first ([`sample`]), in both formats, with the count it announces.
#[test]
fn streamed_setpoints_are_the_collected_ones() {
    let m = Machine::from_file(&root().join("problems/seed_head_head/machine.json")).unwrap();
    let t = toolpath::read(&root().join("problems/seed_head_head/impeller_blade.cls")).unwrap();
    let sol = optimize(&m, &t, &Options::default()).unwrap();
    let sp = sample(&m, &sol, 1e-3).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for (name, all) in [
        ("s.csv", setpoints_csv(&sp).into_bytes()),
        ("s.bin", setpoints_bin(&sp).unwrap()),
    ] {
        let path = dir.path().join(name);
        let h = feedopt::writers::setpoints::write_sampled(&path, &m, &sol, 1e-3).unwrap();
        assert_eq!(h.count, sp.samples.len(), "{name}");
        assert_eq!(h.axes, sp.axes, "{name}");
        assert!(
            std::fs::read(&path).unwrap() == all,
            "{name}: the files differ"
        );
    }
}

/// The program's dwells are part of the setpoints' time: where the tool dwells between two
/// moves the setpoints hold its position, at rest, for the dwell's duration, and the motion
/// around them is the schedule's, shifted by the dwells before it. (They were left out: the NX
/// DMU 70 eVo program's setpoints ran 1,056.27 s, its cycle time 1,131.30 s with 75.03 s of
/// drilling dwells.)
#[test]
fn dwells_hold_the_position_for_their_time() {
    let m = Machine::from_file(&root().join("problems/xyz_pocket/machine.json")).unwrap();
    let read = |text: &str| {
        toolpath::gcode::parse(
            Path::new("drill.ngc"),
            text,
            toolpath::gcode::Dialect::LinuxCnc,
        )
        .unwrap()
    };
    let program = "G21 G90 G94\nG0 X0 Y0 Z5\nG4 P0.25\nG1 Z-3 F300\nG4 P1.5\nG1 Z5\n\
                   G1 X20 F600\nG1 Z-3 F300\nG4 P0.5\nG1 Z5\nG4 P0.3\nM2\n";
    let with = read(program);
    let without = read(
        &program
            .lines()
            .filter(|l| !l.starts_with("G4"))
            .collect::<Vec<_>>()
            .join("\n"),
    );
    assert!((with.dwell_time() - 2.55).abs() < 1e-12);
    let options = Options {
        solver_kind: SolverKind::Reach,
        ..Options::default()
    };
    let (a, b) = (
        optimize(&m, &with, &options).unwrap(),
        optimize(&m, &without, &options).unwrap(),
    );
    // Before the first move, after the first plunge, after the second, at the end.
    let holds = &a.path.holds;
    assert_eq!(holds.len(), a.path.spans.len() + 1);
    let nonzero: Vec<f64> = holds.iter().copied().filter(|&h| h > 0.0).collect();
    assert_eq!(nonzero, vec![0.25, 1.5, 0.5, 0.3], "{holds:?}");
    assert_eq!(holds[0], 0.25);
    assert_eq!(*holds.last().unwrap(), 0.3);
    let motion = b.schedule.cycle_time;
    assert!((a.schedule.cycle_time - motion).abs() < 1e-9 * motion);
    let period = 1e-3;
    let (sa, sb) = (
        sample(&m, &a, period).unwrap(),
        sample(&m, &b, period).unwrap(),
    );
    let cycle = motion + 2.55;
    assert_eq!(sa.samples.len(), (cycle / period).ceil() as usize + 1);
    assert!((sa.samples.last().unwrap().t - cycle).abs() < 1e-12);
    // Each dwell's interval on the clock: it starts where its span ends (the schedule's time
    // plus the dwells before).
    let span_end = |s: usize| {
        b.schedule
            .stations
            .iter()
            .filter(|st| st.span == s)
            .map(|st| st.t)
            .fold(0.0, f64::max)
    };
    // Each dwell's interval on the clock and where the tool stands.
    let points = [
        [0.0, 0.0, 5.0],
        [0.0, 0.0, -3.0],
        [20.0, 0.0, -3.0],
        [20.0, 0.0, 5.0],
    ];
    let mut stands: Vec<(f64, f64)> = vec![(0.0, holds[0])];
    let mut shift = holds[0];
    for (s, &h) in holds.iter().enumerate().skip(1) {
        if h > 0.0 {
            let start = span_end(s - 1) + shift;
            stands.push((start, start + h));
            shift += h;
        }
    }
    let mut held = 0;
    for p in &sa.samples {
        if let Some(k) = stands.iter().position(|(s, e)| p.t > *s && p.t < *e) {
            // Inside a dwell: where it stands, at rest.
            let err = (0..3)
                .map(|i| (p.q[i] - points[k][i]).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-9 && p.feed == 0.0, "t = {}: {:?}", p.t, &p.q[..3]);
            held += 1;
            continue;
        }
        // Outside: the dwell-free setpoint at the time less the dwells before (every dwell a
        // whole number of periods, so that is one of its instants).
        let before: f64 = stands
            .iter()
            .filter(|(_, e)| *e <= p.t)
            .map(|(s, e)| e - s)
            .sum();
        let j = ((p.t - before) / period).round() as usize;
        let q = &sb.samples[j.min(sb.samples.len() - 1)];
        let err = (0..3).map(|i| (p.q[i] - q.q[i]).abs()).fold(0.0, f64::max);
        assert!(
            err < 1e-6,
            "t = {}: {:?} vs {:?}",
            p.t,
            &p.q[..3],
            &q.q[..3]
        );
    }
    assert!((held as f64 - 2.55 / period).abs() <= 8.0, "{held}");
}
