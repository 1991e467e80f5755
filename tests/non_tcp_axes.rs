//! Blocks outside tool-tip mode on a five-axis machine file: X Y Z A B C are where the control
//! moves the axes. A table that turns with TCPM off leaves X Y Z standing and carries the part
//! past the tool; until 2026-11-27 the reader held the tip still on the part instead, so X Y Z
//! swung through arcs (hyperMILL's `L A+Q120 C+Q122 FMAX` after `L Y-425 M91` on a DMU 85:
//! arcs of up to 425 mm).

mod common;

use feedopt::kinematics::Kinematics;
use feedopt::machine::Machine;
use feedopt::optimize::{Options, optimize};
use feedopt::toolpath::gcode::{Dialect, parse_for};
use feedopt::toolpath::{Feed, MachineContext, Toolpath};
use nalgebra::Vector3;
use std::path::Path;

const HEADER: &str = "0 BEGIN PGM T MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-20\n\
                      2 BLK FORM 0.2 X+100 Y+100 Z+0\n3 TOOL CALL 1 Z S5000\n";

/// The A/C table of `common::AC_TABLE` and its context.
fn ac_table() -> (Machine, MachineContext) {
    let m = common::machine(common::AC_TABLE);
    let ctx = MachineContext::new(&m, &feedopt::machine::References::default());
    (m, ctx)
}

/// A double swivel head (C, A), pivot 150 mm above the tip.
fn head_head() -> (Machine, MachineContext) {
    let m = common::machine(
        r#"{"name": "head", "kinematics": {"type": "head_head", "tool_length": 150},
            "axes": {"X": {"velocity": 500, "acceleration": 5000},
                     "Y": {"velocity": 500, "acceleration": 5000},
                     "Z": {"velocity": 500, "acceleration": 5000},
                     "C": {"velocity": 90, "acceleration": 900},
                     "A": {"velocity": 45, "acceleration": 450, "min": -100, "max": 100}},
            "feed": {"max": 2000}}"#,
    );
    let ctx = MachineContext::new(&m, &feedopt::machine::References::default());
    (m, ctx)
}

fn read(dialect: Dialect, ctx: Option<&MachineContext>, text: &str) -> Toolpath {
    parse_for(Path::new("t.prg"), text, dialect.spec(), ctx).unwrap_or_else(|e| panic!("{e}"))
}

/// Every CL point's machine axes (the kinematics' order), through the inverse kinematics the
/// solver uses.
fn axes_of(m: &Machine, tp: &Toolpath) -> Vec<Vec<f64>> {
    let kin = Kinematics::new(m);
    let angles = kin.rotary_angles(&tp.points, &m.axes).unwrap();
    tp.points
        .iter()
        .zip(&angles)
        .map(|(p, a)| {
            let mut w = [0.0; feedopt::kinematics::PATH_DIM];
            w[..5].copy_from_slice(&[p.p.x, p.p.y, p.p.z, a[0], a[1]]);
            let mut q = [0.0; feedopt::kinematics::MAX_AXES];
            kin.axis_positions(w, &mut q);
            q[..kin.n_axes()].to_vec()
        })
        .collect()
}

fn solve(m: &Machine, tp: &Toolpath) -> feedopt::optimize::Solution {
    let s = optimize(m, tp, &Options::default()).unwrap();
    assert!(s.verification.verified);
    s
}

/// The cycle time `t` is the closed form `want` of axis `axis` moving alone, within `rel`.
fn assert_time(t: f64, want: f64, rel: f64, axis: &str) {
    assert!(
        (t - want).abs() <= rel * want,
        "{t} s, {axis} alone {want} s"
    );
}

/// Rest to rest over `d` at velocity `v` and acceleration `a`: bang-bang or trapezoid.
fn rest_to_rest(d: f64, v: f64, a: f64) -> f64 {
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

/// `L A+60 FMAX` after `L X+40 Y+30 Z+50 FMAX`, TCPM off: the control turns the table and X Y
/// Z stand at 40, 30, 50; the tip sweeps the arc the forward kinematics gives (about the A axis,
/// radius √(30² + 50²)), in chords within 1 µm, the last point the block's end. The turn takes A's
/// own time, 60/60 + 60/600 = 1.1 s (the tip at 61 mm/s, far below every other limit). Under
/// M128 the same program holds the tip at (40, 30, 50): one point, as before.
#[test]
fn a_table_turning_outside_tcp_leaves_x_y_z_standing() {
    let (m, ctx) = ac_table();
    let kin = Kinematics::new(&m);
    let program = |m128: &str| {
        format!("{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX{m128}\n5 L A+60 FMAX\n6 END PGM T MM\n")
    };
    let tp = read(Dialect::Heidenhain, Some(&ctx), &program(""));
    assert!(tp.points.len() > 10, "{} points", tp.points.len());
    assert!(tp.warnings.iter().all(|w| !w.message.contains("tool-tip")));
    let axes = axes_of(&m, &tp);
    for (k, q) in axes.iter().enumerate() {
        assert!(
            (q[0] - 40.0).abs() < 1e-9 && (q[1] - 30.0).abs() < 1e-9 && (q[2] - 50.0).abs() < 1e-9,
            "point {k}: axes {q:?}"
        );
    }
    // Every point is the forward kinematics of X Y Z standing, A where the block has it.
    let mut last_a = 0.0;
    for (k, p) in tp.points.iter().enumerate().skip(1) {
        let a = p.rotary.unwrap()[0];
        assert!(a > last_a && a <= 60.0, "point {k}: A {a}");
        last_a = a;
        let pose = kin.forward(&[40.0, 30.0, 50.0, a, 0.0]).unwrap();
        assert!((pose.p - p.p).norm() < 1e-9 && (pose.k - p.o).norm() < 1e-12);
        assert_eq!(p.line, 6);
        assert!(matches!(p.feed, Feed::Rapid));
        // The chord to it stays within 1 µm of the arc (its midpoint, radius 58.3 mm).
        let prev = &tp.points[k - 1];
        let a_mid = (a + prev.rotary.unwrap()[0]) / 2.0;
        let mid = kin.forward(&[40.0, 30.0, 50.0, a_mid, 0.0]).unwrap().p;
        assert!((mid - (p.p + prev.p) / 2.0).norm() <= 1e-3);
    }
    assert_eq!(tp.points.last().unwrap().rotary, Some([60.0, 0.0, 0.0]));
    // The tip went round the A axis (machine X) at radius √(30² + 50²).
    let end = tp.points.last().unwrap().p;
    assert!((end.x - 40.0).abs() < 1e-9);
    assert!((end.y.hypot(end.z) - 30f64.hypot(50.0)).abs() < 1e-9);
    assert!((end - Vector3::new(40.0, 30.0, 50.0)).norm() > 50.0);

    let s = solve(&m, &tp);
    let want = rest_to_rest(60.0, 60.0, 600.0);
    assert_time(s.schedule.cycle_time, want, 1e-6, "A");
    // The schedule's X Y Z stand still from start to end.
    let x = s.schedule.axes.iter().position(|a| a == "X").unwrap();
    let mut worst: f64 = 0.0;
    for i in 0..s.schedule.stations.len() {
        let q = s.schedule.q(i);
        worst = worst
            .max((Vector3::new(q[x], q[x + 1], q[x + 2]) - Vector3::new(40.0, 30.0, 50.0)).norm());
    }
    // Exactly at the CL points (above); between them the solver's fitted path stays within
    // its 5 µm of the chords.
    assert!(worst < 6e-3, "X Y Z move by {worst} mm");

    // Under M128 the tip stays at (40, 30, 50): one point, X Y Z swing.
    let tcp = read(Dialect::Heidenhain, Some(&ctx), &program(" M128"));
    assert_eq!(tcp.points.len(), 2);
    assert_eq!(tcp.points[1].p, Vector3::new(40.0, 30.0, 50.0));
    assert_eq!(tcp.points[1].rotary, Some([60.0, 0.0, 0.0]));
    assert_eq!(tcp.points[1].o, Vector3::z());
}

/// With every rotary axis at zero, a program reads exactly as without the machine's kinematics
/// (3-axis work on a five-axis machine file does not change): the same points, bit for bit.
#[test]
fn at_zero_rotary_angles_the_reading_is_unchanged() {
    let (_, ctx) = ac_table();
    let (_, hh) = head_head();
    let klartext = format!(
        "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n5 L X+10 Y-20 F500\n\
         6 CC X+0 Y+0\n7 C X+20 Y+10 DR+\n8 L Z+80 A+0 FMAX\n9 END PGM T MM\n"
    );
    let without = read(Dialect::Heidenhain, None, &klartext);
    let with = read(Dialect::Heidenhain, Some(&ctx), &klartext);
    assert_eq!(with.points, without.points);
    let fanuc = "G21 G90 G94 G17\nG0 X10. Y20. Z30. A0. C0.\nG1 X50. F600.\nG2 X70. Y40. R20.\n\
                 G1 Z5. C0. F300.\nM30\n";
    let without = read(Dialect::Fanuc, None, fanuc);
    let with = read(Dialect::Fanuc, Some(&hh), fanuc);
    assert_eq!(with.points, without.points);
}

/// A LinuxCNC program on a double swivel head: `G0 A30` with TCP off tilts the head about its
/// pivot, X Y Z standing; the tip swings on a circle of 150 mm (the pivot length) about the
/// pivot and takes A's own time (30/45 + 45/450 s). A straight move tilted (3+2 without a
/// frame) moves the axes as written: the tip moves by the same vector, 150·sin 30° = 75 mm
/// aside from the programmed point.
#[test]
fn a_head_tilting_outside_tcp_swings_the_tip_about_its_pivot() {
    let (m, ctx) = head_head();
    let tp = read(
        Dialect::LinuxCnc,
        Some(&ctx),
        "G90 G94 G17\nG0 X10 Y20 Z30 A0 C0\nG0 A30\nG1 X60 F1200\nM2\n",
    );
    let axes = axes_of(&m, &tp);
    let turn: Vec<usize> = (0..tp.points.len())
        .filter(|&k| tp.points[k].line == 3)
        .collect();
    assert!(turn.len() > 10);
    for &k in &turn {
        let q = &axes[k];
        assert!(
            (q[0] + 10.0).abs() < 1e-9 && (q[1] + 20.0).abs() < 1e-9 && (q[2] - 30.0).abs() < 1e-9,
            "point {k}: axes {q:?} (this kinematics' X, Y run against the tip's)"
        );
        // 150 mm from the pivot, which stands at (10, 20, 30 − 150) in this kinematics'
        // convention (the tip at the pivot + 150 mm along the tool axis).
        let pivot = Vector3::new(10.0, 20.0, -120.0);
        assert!(((tp.points[k].p - pivot).norm() - 150.0).abs() < 1e-9);
    }
    let last = tp.points.last().unwrap();
    assert_eq!(last.line, 4);
    // The tip: the pivot less 150 mm along the tool axis tilted 30° by A.
    let k = last.o;
    let want = Vector3::new(60.0, 20.0, -120.0) + 150.0 * k;
    assert!((last.p - want).norm() < 1e-9, "{} vs {want}", last.p);
    assert!(
        ((last.p - Vector3::new(60.0, 20.0, 30.0)).norm()
            - 150.0 * (2.0 - 2.0 * 30f64.to_radians().cos()).sqrt())
        .abs()
            < 1e-9
    );
    // The straight move at F1200 (20 mm/s) over 50 mm: F applies to the tip, which moves as
    // the axes do.
    assert_eq!(last.feed, Feed::Programmed(20.0));

    // The turn alone takes A's own time.
    let turn_only = read(
        Dialect::LinuxCnc,
        Some(&ctx),
        "G90 G94 G17\nG0 X10 Y20 Z30 A0 C0\nG0 A30\nM2\n",
    );
    let s = solve(&m, &turn_only);
    let want = rest_to_rest(30.0, 45.0, 450.0);
    assert_time(s.schedule.cycle_time, want, 1e-6, "A");
}

/// Feeds keep each control's rule for the axes' motion, split over the block's points: a
/// LinuxCNC `G1 A60 F600` (degrees per minute) takes 6 s, a `G1 X30 A20 F600` 3 s (F along X Y
/// Z), a Fanuc `G1 X30 A40 F300` √(30² + 40²)/300 min = 10 s (the combined distance), G93 `F6`
/// 10 s.
#[test]
fn a_turning_block_keeps_the_controls_feed_rule_over_its_points() {
    let (_, ctx) = ac_table();
    let block_time = |dialect: Dialect, text: &str, line: usize| -> f64 {
        let tp = read(dialect, Some(&ctx), text);
        let pts: Vec<_> = tp.points.iter().filter(|p| p.line == line).collect();
        assert!(pts.len() > 1, "{text}");
        pts.iter()
            .map(|p| match p.feed {
                Feed::BlockTime(t) => t,
                f => panic!("{f:?}"),
            })
            .sum()
    };
    let t = block_time(
        Dialect::LinuxCnc,
        "G90 G94\nG0 X10 Y40 Z30 A0 C0\nG1 A60 F600\nM2\n",
        3,
    );
    assert!((t - 6.0).abs() < 1e-9, "{t}");
    let t = block_time(
        Dialect::LinuxCnc,
        "G90 G94\nG0 X10 Y40 Z30 A0 C0\nG1 X40 A20 F600\nM2\n",
        3,
    );
    assert!((t - 3.0).abs() < 1e-9, "{t}");
    let t = block_time(
        Dialect::Fanuc,
        "G21 G90 G94\nG0 X10. Y40. Z30. A0. C0.\nG1 X40. A40. F300.\nM30\n",
        3,
    );
    assert!((t - 10.0).abs() < 1e-9, "{t}");
    let t = block_time(
        Dialect::LinuxCnc,
        "G90 G94\nG0 X10 Y40 Z30 A0 C0\nG93 G1 X40 A40 F6\nM2\n",
        3,
    );
    assert!((t - 10.0).abs() < 1e-9, "{t}");
}

/// Switching tool-tip mode on after a turn outside it: the axes stay, and the position the
/// next block starts from is the tip's (`G1 Z80` under M428 keeps the tip's X Y, not the axes').
/// Off again (M429): a block that moves Z alone moves the Z axis alone.
#[test]
fn switching_tool_tip_mode_keeps_the_axes_where_they_are() {
    let (m, ctx) = ac_table();
    let kin = Kinematics::new(&m);
    let tp = read(
        Dialect::LinuxCnc,
        Some(&ctx),
        "G90 G94\nG0 X10 Y40 Z30 A0 C0\nG0 A90\nM428\nG1 Z80 F600\nM429\nG0 Z100\nM2\n",
    );
    let tip = kin.forward(&[10.0, 40.0, 30.0, 90.0, 0.0]).unwrap().p;
    let under_tcp = tp.points.iter().find(|p| p.line == 5).unwrap();
    assert!(
        (under_tcp.p - Vector3::new(tip.x, tip.y, 80.0)).norm() < 1e-9,
        "{} from {tip}",
        under_tcp.p
    );
    let axes = axes_of(&m, &tp);
    let k = tp.points.len() - 1;
    assert_eq!(tp.points[k].line, 7);
    let before = &axes[k - 1];
    assert!(
        (axes[k][0] - before[0]).abs() < 1e-9
            && (axes[k][1] - before[1]).abs() < 1e-9
            && (axes[k][2] - 100.0).abs() < 1e-9,
        "{:?} after {before:?}",
        axes[k]
    );
}

/// An arc that turns a rotary axis outside tool-tip mode is refused, naming the line; without
/// the machine's kinematics a turn outside tool-tip mode keeps the old reading, said in a
/// warning that names the machine file as the way to remove the assumption.
#[test]
fn what_the_reader_cannot_model_is_said() {
    let (_, ctx) = ac_table();
    let e = parse_for(
        Path::new("t.ngc"),
        "G90 G94 G17\nG0 X10 Y0 Z30 A0 C0\nG2 X-10 Y0 I-10 J0 A30 F600\nM2\n",
        Dialect::LinuxCnc.spec(),
        Some(&ctx),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("t.ngc:3:") && e.contains("arc that turns a rotary axis"),
        "{e}"
    );
    let tp = read(
        Dialect::LinuxCnc,
        None,
        "G90 G94\nG0 X10 Y40 Z30 A0 C0\nG0 A60\nM2\n",
    );
    assert_eq!(tp.points.len(), 2);
    let w = tp
        .warnings
        .iter()
        .find(|w| w.message.contains("outside tool-tip"))
        .expect("the assumption is said");
    // At the first block that gives a rotary word.
    assert_eq!(w.line, 2);
    assert!(w.message.contains("give the machine file"), "{}", w.message);
}

/// hyperMILL's DMU 85 positioning: `PLANE SPATIAL … STAY SEQ+` then `L A+Q120 C+Q122 R0 FMAX
/// M126` with TCPM off. The control turns the table to the plane's solution (A +90°, C +90°)
/// and X Y Z stand (at 40, 30, 50); the tip is carried with the part. The turn takes A's own
/// time (90/60 + 60/600 = 1.6 s; C's 90° takes 0.85 s). The next block under the plane,
/// `L Z+20`, starts from where the carried tip is: along the plane's Z, which is the tool axis,
/// so only the Z axis moves. Under M128 the same turn holds the tip: one point, as before.
#[test]
fn a_turn_under_a_plane_outside_tcp_carries_the_tip_with_the_table() {
    let (m, ctx) = ac_table();
    let program = |m128: &str, tail: &str| {
        format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX{m128}\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC90 STAY SEQ+ TABLE ROT\n\
             6 L A+Q120 C+Q122 R0 FMAX M126\n{tail}8 END PGM T MM\n"
        )
    };
    let tp = read(
        Dialect::Heidenhain,
        Some(&ctx),
        &program("", "7 L Z+20 FMAX\n"),
    );
    let axes = axes_of(&m, &tp);
    let turn: Vec<usize> = (0..tp.points.len())
        .filter(|&k| tp.points[k].line == 7)
        .collect();
    assert!(turn.len() > 10);
    for &k in &turn {
        let q = &axes[k];
        assert!(
            (q[0] - 40.0).abs() < 1e-9 && (q[1] - 30.0).abs() < 1e-9 && (q[2] - 50.0).abs() < 1e-9,
            "point {k}: axes {q:?}"
        );
    }
    assert_eq!(
        tp.points[*turn.last().unwrap()].rotary,
        Some([90.0, 0.0, 90.0])
    );
    let last = axes.last().unwrap();
    assert_eq!(tp.points.last().unwrap().line, 8);
    assert!(
        (last[0] - 40.0).abs() < 1e-9 && (last[1] - 30.0).abs() < 1e-9,
        "{last:?}"
    );
    assert!((last[2] - 50.0).abs() > 1.0, "{last:?}");

    let turn_only = read(Dialect::Heidenhain, Some(&ctx), &program("", ""));
    // The tip's curve (A and C turning together) needs a finer grid than the default 1e-4
    // convergence to come within 1e-6 of the closed form (1.600065 s at the default).
    let options = Options {
        convergence: 1e-7,
        ..Options::default()
    };
    let s = optimize(&m, &turn_only, &options).unwrap();
    assert!(s.verification.verified);
    let want = rest_to_rest(90.0, 60.0, 600.0);
    assert_time(s.schedule.cycle_time, want, 1e-6, "A");

    let tcp = read(Dialect::Heidenhain, Some(&ctx), &program(" M128", ""));
    assert_eq!(tcp.points.iter().filter(|p| p.line == 7).count(), 1);
    assert_eq!(tcp.points.last().unwrap().p, Vector3::new(40.0, 30.0, 50.0));
}

/// 3+2 without a frame or TCP: at C 90° a `G1 X50` moves the X axis 50 mm, as the control
/// does, and the tip moves 50 mm along the part's −Y (the table turned under it). On a machine
/// whose X is slow (10 mm/s) and Y fast, the move takes X's time, 50/10 + 10/100 = 5.1 s;
/// read as the tip (until 2026-11-27) it ran on Y at F (100 mm/s) in 0.52 s.
#[test]
fn a_straight_move_at_a_standing_rotary_angle_moves_the_axes_as_written() {
    let m = common::machine(
        r#"{"name": "A/C table, slow X", "kinematics": {"type": "table_table_ac",
              "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0,
              "y-offset": 0, "z-offset": 0},
            "axes": {"X": {"velocity": 10, "acceleration": 100},
                     "Y": {"velocity": 500, "acceleration": 5000},
                     "Z": {"velocity": 500, "acceleration": 5000},
                     "A": {"velocity": 60, "acceleration": 600, "min": -120, "max": 120},
                     "C": {"velocity": 120, "acceleration": 1200}},
            "feed": {"max": 2000}}"#,
    );
    let ctx = MachineContext::new(&m, &feedopt::machine::References::default());
    let tp = read(
        Dialect::LinuxCnc,
        Some(&ctx),
        "G21 G90 G94\nG0 X0 Y0 Z20 A0 C90\nG1 X50 F6000\nM2\n",
    );
    assert_eq!(tp.points.len(), 2);
    let axes = axes_of(&m, &tp);
    assert!(
        (axes[1][0] - 50.0).abs() < 1e-9 && axes[1][1].abs() < 1e-9,
        "{axes:?}"
    );
    let d = tp.points[1].p - tp.points[0].p;
    assert!((d.norm() - 50.0).abs() < 1e-9 && d.x.abs() < 1e-9, "{d}");
    let s = solve(&m, &tp);
    let want = rest_to_rest(50.0, 10.0, 100.0);
    assert_time(s.schedule.cycle_time, want, 1e-6, "X");
}

/// A turn of whole times round (`L C+720 FMAX`, the tip 50 mm off the C axis) comes back to
/// the same tip at every quarter of the block: sampled at its ends and quarters alone, its
/// chords looked exact and the turn was one point, the tip held still while the table turned
/// twice (X Y swinging round). At least one sample per 30° of the turn: the tip follows two
/// circles, X Y Z stand.
#[test]
fn a_turn_of_whole_revolutions_is_followed_round() {
    let (m, ctx) = ac_table();
    let tp = read(
        Dialect::Heidenhain,
        Some(&ctx),
        &format!("{HEADER}4 L X+50 Y+0 Z+10 A+0 C+0 FMAX\n5 L C+720 FMAX\n6 END PGM T MM\n"),
    );
    // 720° at ≤ 30° a step, then chords within 1 µm of a 50 mm circle (sagitta 1 µm: ≈0.36°).
    assert!(tp.points.len() > 2 * 360, "{} points", tp.points.len());
    for (k, q) in axes_of(&m, &tp).iter().enumerate() {
        assert!(
            (q[0] - 50.0).abs() < 1e-9 && q[1].abs() < 1e-9 && (q[2] - 10.0).abs() < 1e-9,
            "point {k}: axes {q:?}"
        );
    }
    let s = solve(&m, &tp);
    // C's own time, to the chords' share: 1,400 chords within 1 µm of the circle put C
    // within 4e-6 of it.
    let want = rest_to_rest(720.0, 120.0, 1200.0);
    assert_time(s.schedule.cycle_time, want, 1e-5, "C");
}

#[test]
fn a_block_outside_tcp_that_moves_nothing_after_a_tcp_turn_is_no_turn() {
    // Under tool-tip mode a block's rotary words are its orientation (the reader keeps the
    // program's tool vector, +Z, beside them); outside it the axes give the vector. A block
    // outside TCP that moves nothing after a turn under TCP has the same angles and another
    // vector: the geometry took it for a turn of no angle, a span of zero length, whose axes
    // came out NaN ("axis X would be at NaN", a program feedopt gcode wrote for NX's Mori).
    let (m, ctx) = ac_table();
    let tp = read(
        Dialect::Fanuc,
        Some(&ctx),
        "%\nO1\nG21 G90\nG43.4 H1\nG1 X10. Y10. Z10. A0 C0 F1000.\n\
         G93 G1 X0 Y0 Z0 A-37.576 C45. F80.\nG94\nG49\nG91 G0 Z0.\nG90\nM30\n%\n",
    );
    assert_eq!(tp.points.len(), 3);
    let sol = solve(&m, &tp);
    assert!(sol.schedule.cycle_time.is_finite() && sol.verification.verified);
}
