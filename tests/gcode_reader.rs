//! Tests of the G-code reader (`feedopt::toolpath::gcode`).
//!
//! The LinuxCNC programs are third-party test data read from `../shared/realworld/linuxcnc`
//! when that folder exists (reported as ignored otherwise); they are never copied into the crate.

use feedopt::error::Error;
use feedopt::toolpath::gcode::{Dialect, MAX_CHORD_ERROR_MM, parse};
use feedopt::toolpath::{ClPoint, Feed, Toolpath, Warning};
use nalgebra::Vector3;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn ok_in(dialect: Dialect, text: &str) -> Toolpath {
    match parse(Path::new("test.ngc"), text, dialect) {
        Ok(tp) => tp,
        Err(e) => panic!("unexpected error: {e}\n--- input ---\n{text}"),
    }
}

fn ok(text: &str) -> Toolpath {
    ok_in(Dialect::LinuxCnc, text)
}

/// The warnings but the one that a program selects no unit (G20/G21): LinuxCNC's unit is its
/// INI file's, which a test program without G21 leaves to the machine file (none here).
fn others(tp: &Toolpath) -> Vec<&Warning> {
    tp.warnings
        .iter()
        .filter(|w| !w.message.contains("selects no unit") && !w.message.contains("shortest_way"))
        .collect()
}

/// The lines where a rotary axis turns more than 180° by the sign of the difference (the
/// warning that names `shortest_way`), with the axis.
fn long_way(tp: &Toolpath) -> Vec<(usize, char)> {
    tp.warnings
        .iter()
        .filter(|w| w.message.contains("shortest_way"))
        .map(|w| (w.line, w.message.chars().next().unwrap_or('?')))
        .collect()
}

/// Asserts a parse error at `line` whose message contains every one of `needles`
/// (case-insensitive).
fn err_in(dialect: Dialect, text: &str, line: usize, needles: &[&str]) {
    match parse(Path::new("bad.ngc"), text, dialect) {
        Ok(tp) => panic!("expected an error, got {} points\n{text}", tp.points.len()),
        Err(Error::Parse {
            file,
            line: got_line,
            message,
        }) => {
            assert_eq!(file, Path::new("bad.ngc"));
            assert_eq!(got_line, line, "wrong line for `{message}`");
            let lower = message.to_lowercase();
            for needle in needles {
                assert!(
                    lower.contains(&needle.to_lowercase()),
                    "message `{message}` does not mention `{needle}`"
                );
            }
        }
        Err(other) => panic!("expected Error::Parse, got {other:?}"),
    }
}

fn err(text: &str, line: usize, needles: &[&str]) {
    err_in(Dialect::LinuxCnc, text, line, needles);
}

fn close(a: Vector3<f64>, b: Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol
}

fn assert_close(a: Vector3<f64>, b: Vector3<f64>, tol: f64) {
    assert!(close(a, b, tol), "{a:?} != {b:?} (tolerance {tol})");
}

fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
    Vector3::new(x, y, z)
}

fn programmed(feed: Feed) -> f64 {
    match feed {
        Feed::Programmed(f) => f,
        other => panic!("expected a programmed feed, got {other:?}"),
    }
}

fn block_time(feed: Feed) -> f64 {
    match feed {
        Feed::BlockTime(t) => t,
        other => panic!("expected a block time, got {other:?}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Dialect names
// ---------------------------------------------------------------------------------------------

#[test]
fn dialect_from_str_and_default() {
    assert_eq!(Dialect::default(), Dialect::LinuxCnc);
    assert_eq!("linuxcnc".parse::<Dialect>().unwrap(), Dialect::LinuxCnc);
    assert_eq!("Fanuc".parse::<Dialect>().unwrap(), Dialect::Fanuc);
    assert_eq!("SINUMERIK".parse::<Dialect>().unwrap(), Dialect::Sinumerik);
    assert_eq!(
        "Heidenhain".parse::<Dialect>().unwrap(),
        Dialect::Heidenhain
    );
    let e = "mazak".parse::<Dialect>().unwrap_err().to_string();
    assert!(e.contains("mazak") && e.contains("linuxcnc"), "{e}");
    for d in Dialect::ALL {
        assert_eq!(d.to_string().parse::<Dialect>().unwrap(), d);
    }
}

// ---------------------------------------------------------------------------------------------
// Modal motion, distance mode, units
// ---------------------------------------------------------------------------------------------

#[test]
fn modal_g0_g1_and_feeds() {
    let tp = ok("G0 X1 Y2 Z3\nX4\nG1 X5 F600\nY6\nG0 Z10\nX0\nG1 X1\n");
    let f: Vec<Feed> = tp.points.iter().map(|p| p.feed).collect();
    assert_eq!(
        f,
        vec![
            Feed::Rapid,
            Feed::Rapid,
            Feed::Programmed(10.0),
            Feed::Programmed(10.0),
            Feed::Rapid,
            Feed::Rapid,
            Feed::Programmed(10.0),
        ]
    );
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    assert_eq!(p[0], v(1.0, 2.0, 3.0));
    assert_eq!(p[1], v(4.0, 2.0, 3.0));
    assert_eq!(p[2], v(5.0, 2.0, 3.0));
    assert_eq!(p[3], v(5.0, 6.0, 3.0));
    assert_eq!(p[6], v(1.0, 6.0, 10.0));
    let lines: Vec<usize> = tp.points.iter().map(|p| p.line).collect();
    assert_eq!(lines, vec![1, 2, 3, 4, 5, 6, 7]);
    // No rotary word anywhere: no rotary positions; no tool vector: +Z.
    assert!(tp.points.iter().all(|p| p.rotary.is_none()));
    assert!(tp.points.iter().all(|p| p.o == v(0.0, 0.0, 1.0)));
    assert!(others(&tp).is_empty(), "{:?}", tp.warnings);
}

#[test]
fn a_feed_move_before_any_f_or_at_f0_is_an_error() {
    // LinuxCNC: "Cannot do G1 with zero feed rate"; not a move at the machine's maximum feed.
    err("G0 X0 Y0 Z0\nG1 X1\nF120 X2\n", 2, &["no feed rate"]);
    err("G0 X0 Y0 Z0\nG1 X1 F0\n", 2, &["no feed rate", "F0"]);
    let tp = ok("G0 X0 Y0 Z0\nF120\nG1 X1\n");
    assert_eq!(tp.points[1].feed, Feed::Programmed(2.0));
}

#[test]
fn g90_g91() {
    let tp = ok("G90 G0 X1 Y1 Z1\nG91 X1 Y-2\nG1 Z0.5 F60\nG90 X0\n");
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    assert_eq!(
        p,
        vec![
            v(1.0, 1.0, 1.0),
            v(2.0, -1.0, 1.0),
            v(2.0, -1.0, 1.5),
            v(0.0, -1.0, 1.5)
        ]
    );
}

#[test]
fn g20_scales_positions_increments_arcs_and_feed() {
    let tp = ok("G20 G90 G0 X1 Y2 Z0\nG91 G1 X1 F10\nG90 G21 X10\n");
    assert_close(tp.points[0].p, v(25.4, 50.8, 0.0), 1e-12);
    assert_close(tp.points[1].p, v(50.8, 50.8, 0.0), 1e-12);
    // 10 inch/min = 254 mm/min.
    assert!((programmed(tp.points[1].feed) - 254.0 / 60.0).abs() < 1e-12);
    // Back in mm: positions as written, and the feed keeps its mm value.
    assert_close(tp.points[2].p, v(10.0, 50.8, 0.0), 1e-12);
    assert!((programmed(tp.points[2].feed) - 254.0 / 60.0).abs() < 1e-12);

    // An inch arc: radius 1 inch.
    let tp = ok("G20 G17 G0 X1 Y0 Z0\nG3 X0 Y1 I-1 J0 F10\n");
    for p in &tp.points[1..] {
        assert!(((p.p.x.hypot(p.p.y)) - 25.4).abs() <= 1e-9);
    }
    assert_eq!(tp.points.last().unwrap().p, v(0.0, 25.4, 0.0));
}

#[test]
fn g93_inverse_time() {
    let tp = ok("G0 X0 Y0 Z0\nG93 G1 X10 F2\nY5 F0.5\nG0 X0\nG1 X1 F120\n");
    assert_eq!(tp.points[1].feed, Feed::BlockTime(30.0));
    assert_eq!(tp.points[2].feed, Feed::BlockTime(120.0));
    assert_eq!(tp.points[3].feed, Feed::Rapid);
    assert_eq!(tp.points[4].feed, Feed::BlockTime(0.5));
    // F on every G93 feed block, or an error naming the line.
    err("G0 X0 Y0 Z0\nG93\nG1 X1 F10\nX2\n", 4, &["G93", "F"]);
    err("G0 X0 Y0 Z0\nG93 G1 X1 F0\n", 2, &["F"]);
    // Leaving G93 forgets F (LinuxCNC: G94 sets F to 0).
    err(
        "G0 X0 Y0 Z0\nG93 G1 X1 F10\nG94 G1 X2\nX3 F60\n",
        3,
        &["no feed rate"],
    );
    let tp = ok("G0 X0 Y0 Z0\nG93 G1 X1 F10\nG94 G1 X3 F60\n");
    assert_eq!(tp.points[2].feed, Feed::Programmed(1.0));
}

#[test]
fn g94_rotary_only_move_uses_degrees() {
    // A rotary-only move at F90 (deg/min): 30° take 20 s; A and C together: their Euclidean
    // distance in degrees.
    let tp = ok("G0 X0 Y0 Z0 A0 C0\nG1 A30 F90\nA0 C40\nX1 A10\nX1.00000001 A20\n");
    assert!((block_time(tp.points[1].feed) - 20.0).abs() < 1e-12);
    assert!((block_time(tp.points[2].feed) - 50.0 / 1.5).abs() < 1e-12);
    // X moves too: the XYZ length rules, F is mm/min.
    assert_eq!(tp.points[3].feed, Feed::Programmed(1.5));
    // X moves by 1e-8 mm (below LinuxCNC's 1e-7): rotary only again.
    assert!((block_time(tp.points[4].feed) - 10.0 / 1.5).abs() < 1e-9);
    // Rotary-only under G20: F is still degrees per minute.
    let tp = ok("G20 G0 X0 Y0 Z0 C0\nG1 C60 F60\n");
    assert!((block_time(tp.points[1].feed) - 60.0).abs() < 1e-12);
}

#[test]
fn fanuc_g94_feed_with_a_rotary_axis_is_along_the_combined_distance() {
    // The Fanuc manual's example: G91 G01 X20.0 C40.0 F300.0 takes √(20²+40²)/300 min.
    let fanuc = |text: &str| ok_in(Dialect::Fanuc, text);
    let tp = fanuc("G21 G90 G94 G0 X0. Y0. Z0. C0.\nG91 G1 X20. C40. F300.\n");
    let want = (20f64.powi(2) + 40f64.powi(2)).sqrt() / 300.0 * 60.0;
    assert!((want - 0.14907 * 60.0).abs() < 1e-3, "{want}");
    assert!((block_time(tp.points[1].feed) - want).abs() < 1e-9);
    // Said at the block (a Haas converts degrees otherwise).
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.line == 2 && w.message.contains("combined distance")),
        "{:?}",
        tp.warnings
    );
    // X, Y and two rotary axes all count: √(3²+4²+12²+(−84)²) mm/° = √(9+16+144+7056) = 85.
    let tp = fanuc("G21 G90 G0 X0. Y0. Z0. A0. B0.\nG1 X3. Y4. A12. B-84. F170.\n");
    assert!((block_time(tp.points[1].feed) - 85.0 / 170.0 * 60.0).abs() < 1e-9);
    // Under G20 the linear part is in inch and F in inch/min: √(1²+1²)/10 min.
    let tp = fanuc("G20 G90 G0 X0. Y0. Z0. A0.\nG1 X1. A1. F10.\n");
    assert!((block_time(tp.points[1].feed) - 2f64.sqrt() / 10.0 * 60.0).abs() < 1e-9);
    // A linear block keeps F as a speed; a pure rotary block is |ΔC|/F as before: 30° at
    // 90 °/min = 20 s.
    let tp = fanuc("G21 G90 G0 X0. Y0. Z0. C0.\nG1 X30. F300.\nC30. F90.\n");
    assert_eq!(tp.points[1].feed, Feed::Programmed(5.0));
    assert!((block_time(tp.points[2].feed) - 20.0).abs() < 1e-12);
    assert!(tp.warnings.iter().all(|w| !w.message.contains("combined")));
    // In tool-tip mode (G43.4) F is the tool tip's speed.
    let tp = fanuc("G21 G90 G43.4 H1\nG0 X0. Y0. Z0. C0.\nG1 X20. C40. F300.\nG49\n");
    assert_eq!(tp.points[1].feed, Feed::Programmed(5.0));
    // LinuxCNC (and Sinumerik) keep F along X Y Z when they move.
    let tp = ok("G21 G90 G0 X0 Y0 Z0 C0\nG91 G1 X20 C40 F300\n");
    assert_eq!(tp.points[1].feed, Feed::Programmed(5.0));
    let tp = ok_in(
        Dialect::Sinumerik,
        "G71 G90 G0 X0 Y0 Z0 C0\nG91 G1 X20 C40 F300\n",
    );
    assert_eq!(tp.points[1].feed, Feed::Programmed(5.0));
}

// ---------------------------------------------------------------------------------------------
// Arcs
// ---------------------------------------------------------------------------------------------

/// Checks an arc's points: every chord end on the circle about `centre` (in the plane axes
/// `a`, `b`) within 1 µm, every chord's midpoint within the chord error, the last point exact.
fn check_arc(
    points: &[ClPoint],
    start: Vector3<f64>,
    end: Vector3<f64>,
    centre: Vector3<f64>,
    radius: f64,
    (a, b): (usize, usize),
) {
    assert!(points.len() > 1, "an arc gives several chords");
    let in_plane =
        |p: Vector3<f64>| ((p[a] - centre[a]).powi(2) + (p[b] - centre[b]).powi(2)).sqrt();
    let mut prev = start;
    for p in points {
        let r = in_plane(p.p);
        assert!(
            (r - radius).abs() <= 1e-6,
            "chord end {:?} off the circle by {}",
            p.p,
            r - radius
        );
        let mid = (prev + p.p) / 2.0;
        let sagitta = radius - in_plane(mid);
        assert!(
            (-1e-9..=MAX_CHORD_ERROR_MM + 1e-12).contains(&sagitta),
            "chord sagitta {sagitta}"
        );
        prev = p.p;
    }
    assert_eq!(points.last().unwrap().p, end, "end point exact");
    let line = points[0].line;
    assert!(points.iter().all(|p| p.line == line));
}

/// Signed swept angle of an arc's points about `centre` in the (a, b) plane.
fn swept(
    points: &[ClPoint],
    start: Vector3<f64>,
    centre: Vector3<f64>,
    (a, b): (usize, usize),
) -> f64 {
    let angle = |p: Vector3<f64>| (p[b] - centre[b]).atan2(p[a] - centre[a]);
    let mut total = 0.0;
    let mut prev = angle(start);
    for p in points {
        let now = angle(p.p);
        let mut d = now - prev;
        if d > std::f64::consts::PI {
            d -= std::f64::consts::TAU;
        } else if d < -std::f64::consts::PI {
            d += std::f64::consts::TAU;
        }
        total += d;
        prev = now;
    }
    total
}

#[test]
fn xy_arcs_ijk_and_r_cw_and_ccw() {
    use std::f64::consts::{FRAC_PI_2, PI};
    let xy = (0, 1);
    let s = v(10.0, 0.0, 0.0);
    let e = v(0.0, 10.0, 0.0);
    let o = v(0.0, 0.0, 0.0);
    // CCW quarter by IJK.
    let tp = ok("G17 G0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0 F600\n");
    check_arc(&tp.points[1..], s, e, o, 10.0, xy);
    assert!((swept(&tp.points[1..], s, o, xy) - FRAC_PI_2).abs() < 1e-9);
    // CW the long way round (three quarters).
    let tp = ok("G17 G0 X10 Y0 Z0\nG2 X0 Y10 I-10 J0 F600\n");
    check_arc(&tp.points[1..], s, e, o, 10.0, xy);
    assert!((swept(&tp.points[1..], s, o, xy) + 3.0 * FRAC_PI_2).abs() < 1e-9);
    // R > 0: the short arc; R < 0: the long one.
    let tp = ok("G17 G0 X10 Y0 Z0\nG3 X0 Y10 R10 F600\n");
    check_arc(&tp.points[1..], s, e, o, 10.0, xy);
    assert!((swept(&tp.points[1..], s, o, xy) - FRAC_PI_2).abs() < 1e-9);
    let tp = ok("G17 G0 X10 Y0 Z0\nG2 X0 Y10 R-10 F600\n");
    check_arc(&tp.points[1..], s, e, o, 10.0, xy);
    assert!((swept(&tp.points[1..], s, o, xy) + 3.0 * FRAC_PI_2).abs() < 1e-9);
    // CW short arc by R: centre (10, 10).
    let tp = ok("G17 G0 X10 Y0 Z0\nG2 X0 Y10 R10 F600\n");
    let c = v(10.0, 10.0, 0.0);
    check_arc(&tp.points[1..], s, e, c, 10.0, xy);
    assert!((swept(&tp.points[1..], s, c, xy) + FRAC_PI_2).abs() < 1e-9);
    // Half circle by R (centre on the chord).
    let tp = ok("G0 X-5 Y0 Z0\nG2 X5 Y0 R5 F600\n");
    check_arc(
        &tp.points[1..],
        v(-5.0, 0.0, 0.0),
        v(5.0, 0.0, 0.0),
        o,
        5.0,
        xy,
    );
    assert!((swept(&tp.points[1..], v(-5.0, 0.0, 0.0), o, xy) + PI).abs() < 1e-9);
    // Every chord feeds at F.
    assert!(
        tp.points[1..]
            .iter()
            .all(|p| p.feed == Feed::Programmed(10.0))
    );
}

#[test]
fn full_circle_and_chord_count() {
    let tp = ok("G0 X5 Y0 Z0\nG2 X5 Y0 I-5 J0 F600\n");
    let arc = &tp.points[1..];
    check_arc(
        arc,
        v(5.0, 0.0, 0.0),
        v(5.0, 0.0, 0.0),
        v(0.0, 0.0, 0.0),
        5.0,
        (0, 1),
    );
    assert!(
        (swept(arc, v(5.0, 0.0, 0.0), v(0.0, 0.0, 0.0), (0, 1)) + std::f64::consts::TAU).abs()
            < 1e-9
    );
    // Chord count: the fewest chords with sagitta ≤ 1 µm.
    let step = 2.0 * (1.0 - MAX_CHORD_ERROR_MM / 5.0f64).acos();
    assert_eq!(arc.len(), (std::f64::consts::TAU / step).ceil() as usize);
    // Incremental full circle, and LinuxCNC P turns.
    let tp = ok("G0 X5 Y0 Z0\nG91 G3 X0 Y0 I-5 J0 P2 F600\n");
    let arc = &tp.points[1..];
    assert!(
        (swept(arc, v(5.0, 0.0, 0.0), v(0.0, 0.0, 0.0), (0, 1)) - 2.0 * std::f64::consts::TAU)
            .abs()
            < 1e-9
    );
}

#[test]
fn xz_and_yz_arcs() {
    use std::f64::consts::FRAC_PI_2;
    // G18: plane (Z, X); CCW = positive rotation about +Y, which takes +Z towards +X.
    let tp = ok("G18 G0 X0 Y0 Z10\nG3 X10 Z0 I0 K-10 F600\n");
    let (s, e, c) = (v(0.0, 0.0, 10.0), v(10.0, 0.0, 0.0), v(0.0, 0.0, 0.0));
    check_arc(&tp.points[1..], s, e, c, 10.0, (2, 0));
    assert!((swept(&tp.points[1..], s, c, (2, 0)) - FRAC_PI_2).abs() < 1e-9);
    let tp = ok("G18 G0 X0 Y0 Z10\nG2 X10 Z0 R-10 F600\n");
    check_arc(&tp.points[1..], s, e, c, 10.0, (2, 0));
    assert!((swept(&tp.points[1..], s, c, (2, 0)) + 3.0 * FRAC_PI_2).abs() < 1e-9);
    let tp = ok("G18 G0 X0 Y0 Z10\nG2 X10 Z0 R10 F600\n");
    let c2 = v(10.0, 0.0, 10.0);
    check_arc(&tp.points[1..], s, e, c2, 10.0, (2, 0));
    assert!(tp.points[1..].iter().all(|p| p.p.y == 0.0));
    // G19: plane (Y, Z); CCW takes +Y towards +Z.
    let tp = ok("G19 G0 X0 Y10 Z0\nG3 Y0 Z10 J-10 K0 F600\n");
    let (s, e) = (v(0.0, 10.0, 0.0), v(0.0, 0.0, 10.0));
    check_arc(&tp.points[1..], s, e, c, 10.0, (1, 2));
    assert!((swept(&tp.points[1..], s, c, (1, 2)) - FRAC_PI_2).abs() < 1e-9);
    let tp = ok("G19 G0 X0 Y10 Z0\nG2 Y0 Z10 R10 F600\n");
    let c3 = v(0.0, 10.0, 10.0);
    check_arc(&tp.points[1..], s, e, c3, 10.0, (1, 2));
    assert!(tp.points[1..].iter().all(|p| p.p.x == 0.0));
}

#[test]
fn helical_arc() {
    // A full turn and a quarter in XY while Z falls 5 mm and C turns 90°.
    let tp = ok("G0 X10 Y0 Z0 C0\nG3 X0 Y10 Z-5 C90 I-10 J0 P2 F600\n");
    let arc = &tp.points[1..];
    check_arc(
        arc,
        v(10.0, 0.0, 0.0),
        v(0.0, 10.0, -5.0),
        v(0.0, 0.0, 0.0),
        10.0,
        (0, 1),
    );
    let total = swept(arc, v(10.0, 0.0, 0.0), v(0.0, 0.0, 0.0), (0, 1));
    assert!((total - 2.5 * std::f64::consts::PI).abs() < 1e-9);
    // Z and C are linear in the swept angle.
    let mut so_far = 0.0;
    let mut prev = v(10.0, 0.0, 0.0);
    for p in arc {
        so_far += swept(std::slice::from_ref(p), prev, v(0.0, 0.0, 0.0), (0, 1));
        prev = p.p;
        let t = so_far / total;
        assert!((p.p.z - (-5.0 * t)).abs() < 1e-9);
        assert!((p.rotary.unwrap()[2] - 90.0 * t).abs() < 1e-9);
    }
}

#[test]
fn g93_arc_splits_block_time_by_chord_length() {
    let tp = ok("G0 X10 Y0 Z0\nG93 G3 X-10 Y0 I-10 J0 F6\n");
    let arc = &tp.points[1..];
    let total: f64 = arc.iter().map(|p| block_time(p.feed)).sum();
    assert!((total - 10.0).abs() < 1e-12);
    let mut prev = tp.points[0].p;
    let mut lengths = Vec::new();
    for p in arc {
        lengths.push((p.p - prev).norm());
        prev = p.p;
    }
    let sum: f64 = lengths.iter().sum();
    for (p, len) in arc.iter().zip(&lengths) {
        assert!((block_time(p.feed) - 10.0 * len / sum).abs() < 1e-12);
    }
}

#[test]
fn bad_arcs_are_errors() {
    err("G0 X0 Y0 Z0\nG2 X10 Y0 R4 F100\n", 2, &["radius"]);
    err("G0 X0 Y0 Z0\nG2 X10 Y0 I5 J0 R5 F100\n", 2, &["R", "I/J/K"]);
    err("G0 X0 Y0 Z0\nG2 X10 Y0 F100\n", 2, &["centre"]);
    err(
        "G0 X0 Y0 Z0\nG2 X10 Y0 I4 J0 F100\n",
        2,
        &["not on the circle"],
    );
}

// ---------------------------------------------------------------------------------------------
// Rotary words
// ---------------------------------------------------------------------------------------------

#[test]
fn rotary_words_are_never_wrapped() {
    let tp = ok("G0 X0 Y0 Z0 C350\nG1 C370 F600\nG91 C20\nC-400\nG90 A-30 B720\n");
    let r: Vec<[f64; 3]> = tp.points.iter().map(|p| p.rotary.unwrap()).collect();
    assert_eq!(
        r,
        vec![
            [0.0, 0.0, 350.0],
            [0.0, 0.0, 370.0],
            [0.0, 0.0, 390.0],
            [0.0, 0.0, -10.0],
            [-30.0, 720.0, -10.0],
        ]
    );
}

#[test]
fn rotary_present_anywhere_gives_every_point_rotary() {
    // The first rotary word comes late: earlier points get 0 for A B C.
    let tp = ok("G0 X0 Y0 Z0\nG1 X1 F100\nG0 A10\n");
    assert_eq!(tp.points[0].rotary, Some([0.0, 0.0, 0.0]));
    assert_eq!(tp.points[2].rotary, Some([10.0, 0.0, 0.0]));
}

// ---------------------------------------------------------------------------------------------
// Words, comments, warnings, errors
// ---------------------------------------------------------------------------------------------

#[test]
fn unknown_word_warns_with_its_line() {
    // An unknown M code moves nothing: a warning. An unknown G code may move the tool: an
    // error naming it (issue 12: never drop a move silently).
    let tp = ok("G0 X0 Y0 Z0\nG1 X1 F100\nM999\n");
    assert_eq!(tp.points.len(), 2);
    assert_eq!(others(&tp).len(), 1, "{:?}", tp.warnings);
    assert_eq!(others(&tp)[0].line, 3);
    assert!(
        others(&tp)[0].message.contains("M999"),
        "{:?}",
        others(&tp)[0]
    );
    err("G0 X0 Y0 Z0\nG1 X1 F100 G43.4\n", 2, &["G43.4", "move"]);
    // Sinumerik: an unknown named word is a warning; an unknown bare name is a command or a
    // subprogram call on the control, which may move the tool: an error naming it.
    let tp = ok_in(
        Dialect::Sinumerik,
        "G71 G0 X0 Y0 Z0\nG1 X1 F100\nBAR=3 Y1\n",
    );
    assert_eq!(tp.points.len(), 3);
    assert_eq!(tp.warnings.len(), 1, "{:?}", tp.warnings);
    assert!(tp.warnings[0].line == 3 && tp.warnings[0].message.contains("BAR"));
    err_in(
        Dialect::Sinumerik,
        "G71 G0 X0 Y0 Z0\nFOO G1 X1 F100\n",
        2,
        &["`FOO`", "subprogram"],
    );
    // U V W move axes feedopt does not model: an error naming the word, in LinuxCNC and
    // Fanuc (a warning before, and the move was lost).
    err(
        "G0 X0 Y0 Z0\nG1 X1 U5 F100\n",
        2,
        &["U5", "post the program without it"],
    );
    let e = parse(
        Path::new("t.nc"),
        "G21 G90\nG0 X0 Y0 Z0\nG00 W3.\n",
        Dialect::Fanuc,
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("t.nc:3:") && e.contains("W3."), "{e}");
}

#[test]
fn malformed_numbers_are_errors_naming_the_line() {
    err("G0 X0 Y0 Z0\nG1 X1.2.3 F100\n", 2, &["1.2.3", "X"]);
    err("G0 X0 Y0 Z0\n\nG1 Y- F100\n", 3, &["Y"]);
    err("G0 X0 Y0 Z0\nG1 X1 F\n", 2, &["F"]);
    err("G0 X0 Y0 Z0\nG1 X+-1 F100\n", 2, &["+-1"]);
    // No exponents in G-code: `F1E3` and `X1e309` are errors naming the word (issue 12 item
    // 7: an `E` word was silently dropped before, so `X1e309` read as X1).
    err("G0 X0 Y0 Z0\nG1 X1 F1E3\n", 2, &["F1E3", "exponent"]);
    err("G0 X0 Y0 Z0\nG1 X1e309\n", 2, &["X1e309", "exponent"]);
    err_in(
        Dialect::Fanuc,
        "G0 X0 Y0 Z0\nG1 C1E12\n",
        2,
        &["C1E12", "exponent"],
    );
    // Coordinates beyond 1e6 mm are an error naming the word.
    err("G0 X0 Y0 Z0\nG1 X2000000 F100\n", 2, &["X", "2e6", "1e6"]);
    err_in(
        Dialect::Sinumerik,
        "G0 X0 Y0 Z0\nG1 A3=0..5 X1\n",
        2,
        &["A3"],
    );
    err_in(Dialect::Fanuc, "G0 X0 Y0 Z0\nG1 X-1-2 F100\n", 2, &["X"]);
}

#[test]
fn other_errors_name_the_line() {
    err("G0 X0 Y0 Z0\nG1 X#1 F100\n", 2, &["#1", "before it is set"]);
    err("G0 X0 Y0 Z0\no100 sub\n", 2, &["O-word"]);
    err("G0 X0 Y0 Z0\nG81 X1 Y1 Z-1\n", 2, &["G81", "R"]);
    // NX's Mori inch post writes `G98 G82 X… Y… Z… B90. C2700. R… P5`: the message names the
    // words and what to do.
    err(
        "G0 X0 Y0 Z5\nG82 X5 Y5 Z-2 R1 P5 B90 C270 F100\n",
        2,
        &["G82", "(B C)", "block of their own"],
    );
    // LinuxCNC repeats a cycle with L; K there is not a repeat count (it drilled the hole K
    // times before), and G87 is back boring with I J K offsets (they were dropped).
    err("G0 X0 Y0 Z5\nG81 X5 Y5 Z-2 R1 K3\n", 2, &["G81", "K", "L"]);
    err(
        "G0 X0 Y0 Z5\nG87 X5 Y5 Z-2 R1 I2 J0 K3\n",
        2,
        &["G87", "back boring"],
    );
    let tp = ok("G0 X0 Y0 Z5\nG91 G81 X5 Y0 Z-3 R-4 L3 F100\n");
    let bottoms = tp
        .points
        .iter()
        .filter(|p| (p.p.z - -2.0).abs() < 1e-9)
        .count();
    assert_eq!(bottoms, 3, "L3: three holes");
    let tp = ok_in(
        Dialect::Fanuc,
        "G21 G90\nG0 X0. Y0. Z5.\nG91 G81 X5. Y0. Z-3. R-4. K3 F100.\nM30\n",
    );
    let bottoms = tp
        .points
        .iter()
        .filter(|p| (p.p.z - -2.0).abs() < 1e-9)
        .count();
    assert_eq!(bottoms, 3, "Fanuc K3: three holes");
    err("G0 X0 Y0 Z0\nG1 X1 X2 F100\n", 2, &["twice"]);
    err("G0 X0 Y0 Z0\nG0 G1 X1\n", 2, &["two motion codes"]);
    err("X1 Y2\n", 1, &["motion mode"]);
    err("G0 X0 (unclosed\n", 1, &["unclosed"]);
    err("G0 X0 Y0 Z0\nG1 X1 F-5\n", 2, &["negative"]);
    err("(only comments)\n", 1, &["no motion"]);
}

#[test]
fn comments_of_both_kinds_and_skipped_lines() {
    let text = "%\n\
                (header comment)\n\
                G0 X1 Y1 Z1 ; a semicolon comment with X99 in it\n\
                G1 (inline; with a semicolon) X2 F60 (and another)\n\
                /G1 X50\n\
                N100 G1 Y2 S1000 M3 T1 M6 ; Z99\n\
                g1 x  3  (lower case and spaces)\n\
                %\n";
    let tp = ok(text);
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    assert_eq!(
        p,
        vec![
            v(1.0, 1.0, 1.0),
            v(2.0, 1.0, 1.0),
            v(50.0, 1.0, 1.0),
            v(50.0, 2.0, 1.0),
            v(3.0, 2.0, 1.0)
        ]
    );
    assert_eq!(tp.points[1].line, 4);
    // The block-delete line runs (the block-skip switch off, the default), with a warning.
    assert_eq!(others(&tp).len(), 1, "{:?}", tp.warnings);
    assert_eq!(others(&tp)[0].line, 5);
    assert!(others(&tp)[0].message.contains("block run"));
    // Sinumerik: `;` comments only.
    let tp = ok_in(
        Dialect::Sinumerik,
        "G0 X1 Y1 Z1 ; (not a paren comment) X9\nG1 X2 F60\n",
    );
    assert_eq!(tp.points[0].p, v(1.0, 1.0, 1.0));
    // Fanuc: `( )` comments, `;` ends a block.
    let tp = ok_in(Dialect::Fanuc, "G0 X1. Y1. Z1. (start);G1 X2. F60.;\n");
    assert_eq!(tp.points.len(), 2);
    assert_eq!(tp.points[1].p, v(2.0, 1.0, 1.0));
}

#[test]
fn tolerated_codes_do_not_move() {
    let tp = ok(
        "G17 G21 G40 G49 G59.1 G64 G61 G90 G94\nG0 G43 H1 X0 Y0 Z5 M8\nG59.1 G1 X1 F60\n\
         M5 M9\nM30\nG1 X99\n",
    );
    assert_eq!(tp.points.len(), 2, "M30 ends the program");
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
}

#[test]
fn g53_moves_are_included_with_a_warning() {
    let tp = ok("G0 X1 Y1 Z1\nG53 G0 Z30\nG53 Y0 B0 C0\n");
    assert_eq!(tp.points.len(), 3);
    assert_eq!(tp.points[1].p, v(1.0, 1.0, 30.0));
    assert_eq!(tp.points[2].p, v(1.0, 0.0, 30.0));
    let g53: Vec<usize> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("machine-coordinate"))
        .map(|w| w.line)
        .collect();
    assert_eq!(g53, vec![2, 3]);
}

#[test]
fn unknown_start_position_warns_once() {
    let tp = ok("G0 Z5\nX1 Y2\nZ1\n");
    assert_eq!(tp.points[0].p, v(0.0, 0.0, 5.0));
    assert_eq!(others(&tp).len(), 1, "{:?}", tp.warnings);
    assert_eq!(others(&tp)[0].line, 1);
    assert!(others(&tp)[0].message.contains("X, Y"));
}

// ---------------------------------------------------------------------------------------------
// TCP and tool vectors per dialect
// ---------------------------------------------------------------------------------------------

#[test]
fn tcp_modes_per_dialect() {
    // LinuxCNC: M428 on; rotary motion without it warns once per stretch.
    let tp = ok("M428\nG0 X0 Y0 Z0 A10 C20\nM429\nG0 A0\nA5\n");
    assert_eq!(tp.points[0].rotary, Some([10.0, 0.0, 20.0]));
    let tcp: Vec<usize> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("TCP"))
        .map(|w| w.line)
        .collect();
    assert_eq!(tcp, vec![4]);
    // Fanuc G43.4: rotary words in TCP mode, no warnings.
    let tp = ok_in(
        Dialect::Fanuc,
        "G21 G43.4 H1\nG0 X0. Y0. Z0. A10. C20.\nG49\n",
    );
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    // Fanuc G43.5: I J K on G1 are the tool vector (normalised); rotary stays None.
    let tp = ok_in(
        Dialect::Fanuc,
        "G21 G43.5 H1\nG0 X0. Y0. Z0. I0. J0. K1.\nG1 X1. I1. K1. F600.\nG1 X2.\n",
    );
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    assert!(tp.points.iter().all(|p| p.rotary.is_none()));
    assert_eq!(tp.points[0].o, v(0.0, 0.0, 1.0));
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert_close(tp.points[1].o, v(h, 0.0, h), 1e-15);
    assert_close(tp.points[2].o, v(h, 0.0, h), 1e-15);
    // Sinumerik TRAORI with A3 B3 C3.
    let tp = ok_in(
        Dialect::Sinumerik,
        "G71 TRAORI\nG0 X0 Y0 Z0 A3=0 B3=0 C3=1\nG1 X1 A3=0 B3=1 C3=1 F600\nTRAFOOF\nM30\n",
    );
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    assert_close(tp.points[1].o, v(0.0, h, h), 1e-15);
    err_in(
        Dialect::Sinumerik,
        "TRAORI\nG0 X0 Y0 Z0 A3=0 B3=0 C3=0\n",
        2,
        &["tool vector"],
    );
}

#[test]
fn fanuc_numbers_without_a_decimal_point_are_increments() {
    let tp = ok_in(
        Dialect::Fanuc,
        "G21 G0 X100 Y1. Z-2500 C90000\nG1 X1 F100\n",
    );
    assert_close(tp.points[0].p, v(0.1, 1.0, -2.5), 1e-12);
    assert!((tp.points[0].rotary.unwrap()[2] - 90.0).abs() < 1e-9);
    // F is not a dimension: F100 is 100 mm/min.
    assert!((programmed(tp.points[1].feed) - 100.0 / 60.0).abs() < 1e-12);
}

#[test]
fn sinumerik_units_radius_and_spaces() {
    // G71 mm; CR= radius; N numbers; G70 inch geometry leaves F alone, G700 scales it.
    let tp = ok_in(
        Dialect::Sinumerik,
        "N10 G71 G17 G0 X10 Y0 Z0\nN20 G3 X0 Y10 CR=10 F600\nN30 G70 G1 X1 F60\nN40 G700 X2 F60\n",
    );
    let arc: Vec<&ClPoint> = tp.points.iter().filter(|p| p.line == 2).collect();
    for p in &arc {
        assert!((p.p.x.hypot(p.p.y) - 10.0).abs() < 1e-9);
    }
    let n = tp.points.len();
    assert_close(tp.points[n - 2].p, v(25.4, 10.0, 0.0), 1e-12);
    assert_eq!(tp.points[n - 2].feed, Feed::Programmed(1.0));
    assert!((programmed(tp.points[n - 1].feed) - 25.4).abs() < 1e-12);
}

// ---------------------------------------------------------------------------------------------
// The LinuxCNC demo programs (GPL-2.0 test data in ../shared; ignored when absent)
// ---------------------------------------------------------------------------------------------

fn linuxcnc_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/realworld/linuxcnc");
    assert!(dir.is_dir(), "../shared is present (cfg shared_data)");
    dir
}

fn read_demo(name: &str) -> (Toolpath, String) {
    let path = linuxcnc_dir().join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let tp = feedopt::toolpath::gcode::read(&path, Dialect::LinuxCnc)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    // The extension chooses the same reader.
    assert_eq!(feedopt::toolpath::read(&path).unwrap(), tp);
    (tp, text)
}

/// Programmed feed time: Σ BlockTime + Σ chord length / programmed feed.
fn programmed_feed_time(tp: &Toolpath) -> (f64, f64) {
    let (mut inverse, mut per_minute) = (0.0, 0.0);
    for w in tp.points.windows(2) {
        match w[1].feed {
            Feed::BlockTime(t) => inverse += t,
            Feed::Programmed(f) => per_minute += (w[1].p - w[0].p).norm() / f,
            Feed::Rapid => {}
            Feed::Unspecified => panic!("line {}: feed move without F", w[1].line),
        }
    }
    if let Feed::BlockTime(t) = tp.points[0].feed {
        inverse += t;
    }
    (inverse, per_minute)
}

/// Motion blocks per kind: lines whose points are rapids, block times or programmed feeds.
fn blocks_by_feed(tp: &Toolpath) -> BTreeMap<&'static str, usize> {
    let mut kind_of_line: BTreeMap<usize, &'static str> = BTreeMap::new();
    for p in &tp.points {
        let kind = match p.feed {
            Feed::Rapid => "rapid",
            Feed::BlockTime(_) => "block time",
            Feed::Programmed(_) => "programmed",
            Feed::Unspecified => "unspecified",
        };
        let previous = kind_of_line.insert(p.line, kind);
        assert!(
            previous.is_none_or(|k| k == kind),
            "line {} mixes feeds",
            p.line
        );
    }
    let mut counts = BTreeMap::new();
    for kind in kind_of_line.values() {
        *counts.entry(*kind).or_insert(0) += 1;
    }
    counts
}

fn report_warnings(name: &str, tp: &Toolpath) {
    eprintln!(
        "{name}: {} points, {} warnings",
        tp.points.len(),
        tp.warnings.len()
    );
    for w in &tp.warnings {
        eprintln!("  line {}: {}", w.line, w.message);
    }
}

/// Lines of `text` that start with `code` followed by a space (after leading blanks).
fn lines_starting(text: &str, code: &str) -> Vec<usize> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().starts_with(&format!("{code} ")))
        .map(|(i, _)| i + 1)
        .collect()
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn linuxcnc_impeller() {
    let (tp, text) = read_demo("impeller-7bl-xyzac.ngc");
    report_warnings("impeller-7bl-xyzac", &tp);
    let counts = blocks_by_feed(&tp);
    assert_eq!(counts.get("block time"), Some(&4306), "{counts:?}");
    assert_eq!(counts.get("rapid"), Some(&186), "{counts:?}");
    assert_eq!(counts.len(), 2, "{counts:?}");
    // Each motion block is one point on its own line, as the file says.
    let mut lines: Vec<usize> = tp.points.iter().map(|p| p.line).collect();
    lines.dedup();
    assert_eq!(lines.len(), tp.points.len());
    let mut expected = lines_starting(&text, "G1");
    expected.extend(lines_starting(&text, "G0"));
    expected.sort();
    assert_eq!(lines, expected);
    let (inverse, per_minute) = programmed_feed_time(&tp);
    eprintln!("impeller programmed feed time: {inverse:.4} s (G93)");
    assert_eq!(per_minute, 0.0);
    assert!((inverse - 1078.68).abs() < 0.01, "{inverse}");
    // Rotary words as written, never wrapped.
    let c_min = tp
        .points
        .iter()
        .map(|p| p.rotary.unwrap()[2])
        .fold(f64::INFINITY, f64::min);
    assert!((c_min + 399.805).abs() < 1e-9, "{c_min}");
    assert!(tp.points.iter().all(|p| p.o == v(0.0, 0.0, 1.0)));
    assert!(others(&tp).is_empty(), "{:?}", tp.warnings);
    // C turns the long way three times, as LinuxCNC does without WRAPPED_ROTARY: the rapids
    // between operations (C −345.249 → −43.723 at line 3401, and at 4146) and the return to
    // C 0 at the end (line 4504, from −399.805).
    assert_eq!(long_way(&tp), [(3401, 'C'), (4146, 'C'), (4504, 'C')]);
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn linuxcnc_boat_xyzac() {
    let (tp, _) = read_demo("boat-xyzac.ngc");
    report_warnings("boat-xyzac", &tp);
    let (inverse, per_minute) = programmed_feed_time(&tp);
    eprintln!(
        "boat-xyzac programmed feed time: {:.4} s (G93 {inverse:.4} + G94 {per_minute:.4})",
        inverse + per_minute
    );
    assert!((inverse + per_minute - 459.42).abs() < 0.02);
    assert!((inverse - 293.43).abs() < 0.01, "{inverse}");
    assert!((per_minute - 165.99).abs() < 0.01, "{per_minute}");
    let counts = blocks_by_feed(&tp);
    assert_eq!(counts.get("block time"), Some(&1454), "{counts:?}");
    assert_eq!(counts.get("programmed"), Some(&(281 + 4)), "{counts:?}");
    assert_eq!(counts.get("rapid"), Some(&93), "{counts:?}");
    // The four G2 arcs are several chords each.
    let arc_lines = [51usize, 53, 262, 264];
    for line in arc_lines {
        assert!(tp.points.iter().filter(|p| p.line == line).count() > 10);
    }
    assert!(tp.points.iter().all(|p| p.rotary.is_some()));
    // The only warning: the first move (`Z5`) comes before any X and Y; and C's return to 0
    // at the end turns the long way.
    assert_eq!(others(&tp).len(), 1, "{:?}", tp.warnings);
    assert_eq!(others(&tp)[0].line, 11);
    assert_eq!(long_way(&tp), [(1878, 'C')]);
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn linuxcnc_boat_xyzbc() {
    let (tp, _) = read_demo("boat-xyzbc.ngc");
    report_warnings("boat-xyzbc", &tp);
    let (inverse, per_minute) = programmed_feed_time(&tp);
    eprintln!(
        "boat-xyzbc programmed feed time: {:.4} s (G93 {inverse:.4} + G94 {per_minute:.4})",
        inverse + per_minute
    );
    assert!((inverse + per_minute - 301.90).abs() < 0.01);
    let counts = blocks_by_feed(&tp);
    assert_eq!(counts.get("block time"), Some(&1720), "{counts:?}");
    assert_eq!(counts.get("rapid"), Some(&101), "{counts:?}");
    let g53: Vec<usize> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("G53"))
        .map(|w| w.line)
        .collect();
    assert_eq!(g53, vec![1863, 1864]);
    // And the first move (line 11) comes before any Z; C's return to 0 turns the long way.
    assert_eq!(others(&tp).len(), 3, "{:?}", tp.warnings);
    assert_eq!(others(&tp)[0].line, 11);
    assert_eq!(long_way(&tp), [(1864, 'C')]);
}

/// A program that selects one work offset reads its coordinates in that frame, without a
/// word; one that changes to another (a second setup) gets a warning at the change, naming
/// both: feedopt does not know their values, so the move between the setups is sized as if
/// they were equal (it was silent before).
#[test]
fn a_change_of_work_offset_is_a_warning_naming_both() {
    let warned = |tp: &Toolpath| -> Vec<(usize, String)> {
        tp.warnings
            .iter()
            .filter(|w| w.message.contains("work offset"))
            .map(|w| (w.line, w.message.to_string()))
            .collect()
    };
    let one = ok_in(
        Dialect::Fanuc,
        "G21 G90 G54\nG0 X0. Y0. Z5.\nG1 X10. F100.\nG54 G0 Z10.\nM30\n",
    );
    assert!(warned(&one).is_empty(), "{:?}", one.warnings);
    // One warning each, at the line of the change, naming the offsets: G54 → G55; Fanuc's
    // extended offsets told apart by P; Sinumerik's G505–G599 too.
    for (dialect, text, line, names) in [
        (
            Dialect::Fanuc,
            "G21 G90 G54\nG0 X0. Y0. Z5.\nG1 X10. F100.\nG55 G0 X0. Y0.\nG1 X5.\nM30\n",
            4,
            &["G55", "G54"][..],
        ),
        (
            Dialect::Fanuc,
            "G21 G90 G54.1 P1\nG0 X0. Y0. Z5.\nG54.1 P3 G0 X1.\nM30\n",
            3,
            &["P3"][..],
        ),
        (
            Dialect::Sinumerik,
            "G71 G90 G54\nG0 X0 Y0 Z5\nG505\nG0 X1\nM30\n",
            3,
            &["G505"][..],
        ),
        // LinuxCNC's eighth and ninth offsets (they were taken as codes without effect).
        (
            Dialect::LinuxCnc,
            "G21 G90 G54\nG0 X0 Y0 Z5\nG59.2\nG0 X1\nM2\n",
            3,
            &["G59.2", "G54"][..],
        ),
        // Sinumerik's G500 (no settable offset: the base frame) was ignored silently.
        (
            Dialect::Sinumerik,
            "G71 G90 G54\nG0 X0 Y0 Z5\nG500\nG0 Z100\nM30\n",
            3,
            &["G500", "G54"][..],
        ),
    ] {
        let w = warned(&ok_in(dialect, text));
        assert!(
            w.len() == 1 && w[0].0 == line && names.iter().all(|n| w[0].1.contains(n)),
            "{text}: {w:?}"
        );
    }
    // Before the first point a selection only names the frame the program starts in: a
    // Sinumerik header's G500 then G54, or G54 then G55, say nothing.
    for (dialect, text) in [
        (
            Dialect::Sinumerik,
            "G17 G90 G500 G71\nG54\nG0 X0 Y0 Z10\nG1 X10 F100\nM30\n",
        ),
        (
            Dialect::Fanuc,
            "G21 G90 G54\nG55\nG0 X0. Y0. Z5.\nG1 X10. F100.\nM30\n",
        ),
    ] {
        let tp = ok_in(dialect, text);
        assert!(warned(&tp).is_empty(), "{text}: {:?}", tp.warnings);
    }
}

/// Fanuc programs are told by their Fanuc-only words: besides TCP, tilted planes and M98, the
/// look-ahead `G08 P1`, high-precision contour control `G05 P10000`, macro calls `G65 P…` and
/// Haas `G187`, and an `O` number as the first block after a tool-list comment (NX's Mori
/// SH8000 and Haas posts; read as LinuxCNC before,
/// where their G87 is an error).
#[test]
fn fanuc_only_words_tell_the_dialect() {
    use feedopt::toolpath::gcode::detect_dialect;
    for text in [
        "%\nG20\nG08 P01\nG0 X0 Y0\n",
        "%\nG65 P9021 T1000\n",
        "G187\nG0 X0\n",
        "(TOOL LIST)\n(T1 D10)\nO1234\nG0 X0\n",
        // Round 8: a Fadal program numbers its first block, `N1 O3 ( … )`.
        "N1 O3 ( ZAMEK-INTERP )\nN2 ( UWAGA )\nN3 L900\n",
        // Round 17: NX's Makino E33 post, no O number, switches the Fanuc's high-precision
        // contour control on and off (read as LinuxCNC, `G05 P10000` was a cubic spline).
        "(Start of Program Event)\nG91 G28 Z0.0\nG05 P10000\nZ3.937\nG05 P0\n",
    ] {
        assert_eq!(detect_dialect(text), Some(Dialect::Fanuc), "{text}");
    }
    assert_eq!(detect_dialect("G21 G90\nG0 X0 Y0\nG1 X1 F100\n"), None);
    assert_eq!(
        detect_dialect("N10 O100 SUB\nG0 X0\nN20 O100 ENDSUB\n"),
        Some(Dialect::LinuxCnc)
    );
}

/// Fanuc's ISO code writes the program number with a colon, `:1234` for `O1234` (Fanuc
/// operator's manuals, "Program number"; Fanuc 0 controls send `:` themselves, and NX's Fadal
/// and Fanuc 0M posts write `:1234 (PROGRAM)`). Such a program was an error at its first block
/// ("unexpected character `:`"); it now reads as the same program headed `O1234`, point for
/// point and line for line (also with CRLF line ends), and is detected as Fanuc.
#[test]
fn a_colon_program_number_heads_a_fanuc_program_as_o_does() {
    use feedopt::toolpath::gcode::detect_dialect;
    let body = "G21 G90\nG0 X0. Y0. Z5.\nG1 Z-1. F100.\nM98 P2000 L2\nG0 Z5.\nM30\n\
                O2000\nG91 G1 X5.\nG90\nM99\n%\n";
    for eol in ["\n", "\r\n"] {
        let with_o = format!("%\n(PART 7)\nO1234 (FLANGE)\n{body}").replace('\n', eol);
        let with_colon = with_o.replace("O1234", ":1234");
        assert_eq!(
            detect_dialect(&with_colon.to_uppercase()),
            Some(Dialect::Fanuc)
        );
        let a = ok_in(Dialect::Fanuc, &with_o);
        let b = ok_in(Dialect::Fanuc, &with_colon);
        // Two calls of O2000 (X +5 each) after the plunge: the subprogram is found, so the
        // header split main and subprogram as `O1234` does.
        let xs: Vec<f64> = b.points.iter().map(|p| p.p.x).collect();
        assert_eq!(xs, vec![0.0, 0.0, 5.0, 10.0, 10.0]);
        assert_eq!(a.points.len(), b.points.len());
        for (p, q) in a.points.iter().zip(&b.points) {
            assert_eq!(p.p, q.p);
            assert_eq!(p.line, q.line);
        }
    }
}

/// A `:` word further down is not a program number (an `O` there would start a subprogram and
/// end the main program silently): NX's Mori SH8000 post writes `:0110 T01 M06` at a tool
/// change. It is an error naming the word and what to write; an Okuma OSP file (`$NAME.MIN%`
/// first) is an error saying that OSP is not read, not "unexpected character `$`", and a
/// Heidenhain DIN/ISO program (`%123 G71 *`, NX's Mikron post) one naming Klartext, not "axis
/// words without a motion mode" at its first `G90 Z-25. M91`.
#[test]
fn a_colon_inside_a_program_and_okuma_and_din_iso_headers_are_named() {
    err_in(
        Dialect::Fanuc,
        "%\nO0001\nG0 X0. Y0. Z5.\n:0110 T01 M06\nG0 X1.\nM30\n",
        4,
        &["`:0110`", "N0110", "program number"],
    );
    // A Heidenhain DIN/ISO program: its header says so, where its words would be misread.
    for header in ["%123 G71 *", "% PART7 G70"] {
        let text = format!("{header}\nN10 G30 G17 X+0 Y+0 Z-40 *\nN20 G90 Z-25. M91\n");
        err_in(
            Dialect::LinuxCnc,
            &text,
            1,
            &["Heidenhain DIN/ISO", "Klartext"],
        );
    }
    for header in ["$FLANGE.MIN%", "$OKUMA.SSB%"] {
        let text = format!("{header}\n(OKUMA)\nG0 G90 X0 Y0\nVC1=2\nM02\n");
        for dialect in [Dialect::Fanuc, Dialect::LinuxCnc] {
            err_in(dialect, &text, 1, &["Okuma OSP", header]);
        }
    }
}

/// A lone `G71` or `G70` in a mill program's header (`G00G21G17G90G40G49G80` / `G71G91.1`, as
/// hobby posts write it; NX's Fryer post `G40 G17 G90 G70`) means mm or inch on the control
/// it was posted for. On LinuxCNC and Fanuc these are lathe cycles, and feedopt said "this
/// canned cycle is not supported: post the toolpath as G0/G1/G2/G3", which tells the user
/// nothing. The error now says what such a word means and what to write.
#[test]
fn g70_and_g71_as_units_are_named_with_what_to_write() {
    let text = "G00G21G17G90G40G49G80\nG71G91.1\nG0 X0 Y0 Z5\nG1 Z-1 F100\nM30\n";
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc] {
        err_in(dialect, text, 2, &["G71", "lathe", "G20/G21"]);
        err_in(dialect, &text.replace("G71", "G70"), 2, &["G70", "G20/G21"]);
    }
}

/// A shop's Haas program tests a tool-life timer, `IF [#5405 GE 6000] THEN #3000=15`: the
/// control holds #5405, the program never sets it. feedopt said only "read before it is set";
/// it now says that the variable is the control's and what to do. A user parameter (`#100`)
/// keeps the short message.
#[test]
fn a_system_variable_read_before_it_is_set_is_named_as_the_controls() {
    let text = "O1\nG0 G90 X0. Y0. Z5.\nIF [#5405 GE 6000] THEN #3000=15\nM30\n";
    err_in(
        Dialect::Fanuc,
        text,
        3,
        &["#5405", "system variable", "machine's"],
    );
    let text = "O1\nG0 G90 X#2001 Y0. Z5.\nM30\n";
    err_in(
        Dialect::Fanuc,
        text,
        2,
        &["#2001", "Fanuc and Haas", "system variable"],
    );
    match parse(Path::new("u.nc"), "O1\nG0 X#100\n", Dialect::Fanuc) {
        Err(Error::Parse { message, .. }) => {
            assert!(
                message.contains("`#100` is read before it is set"),
                "{message}"
            );
            assert!(!message.contains("system"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

/// A MillMaster Pro program comments with `//`; a Haas shop program mills a circle with
/// `G12 I0.75 F10. Z-1.2 D01`. Both were errors that did not say what to do ("unexpected
/// character `/`", "not a Fanuc G code feedopt knows"); they now say it. A single leading `/`
/// is still block delete, read as before.
#[test]
fn double_slash_comments_and_haas_g12_say_what_to_do() {
    err(
        "G21 G90\n// rest position -1, 0, 0.5\nG0 X0 Y0 Z1\n",
        2,
        &["`//` does not start a comment", "( … )"],
    );
    let tp = ok("G21 G90\nG0 X0 Y0 Z1\n/G0 X5\nG0 Y5\n");
    assert_eq!(tp.points.len(), 3);
    for g in ["G12", "G13"] {
        err_in(
            Dialect::Fanuc,
            &format!("O1\nG0 G90 X0. Y0. Z1.\n{g} I0.75 F10. Z-1.2 D01\nM30\n"),
            3,
            &[g, "Haas circular pocket", "G2/G3"],
        );
    }
}

/// A LinuxCNC file that defines its numbered subroutines first (`o100 sub` on line 1, the
/// usual layout) was taken for Fanuc by its `O` number: `S` of `sub` then had no number, and
/// with a call the subroutine was "defined twice". An O number followed by an O-word keyword
/// marks LinuxCNC; a Fanuc program number (with or without a comment after it) stays Fanuc.
#[test]
fn numbered_oword_subroutines_tell_linuxcnc() {
    use feedopt::toolpath::gcode::detect_dialect;
    for text in [
        "o100 sub\nG0 X7 Y8\no100 endsub\nG21 G90\nG0 X0 Y0 Z5\nG1 X10 F100\nM2\n",
        "o100 sub\n  G1 X10 F600\no100 endsub\nG21 G90\nG0 X0 Y0 Z5\no100 call\nM2\n",
        "(header)\nO0100SUB\nO0100 ENDSUB\n",
        "G0 X0\nN20 o101 if [#1 GT 0]\no101 endif\n",
        "G0 X0\no102 while [#1 LT 3]\no102 endwhile\n",
        "G0 X0\no103 repeat [2]\no103 endrepeat\n",
    ] {
        assert_eq!(
            detect_dialect(&text.to_uppercase()),
            Some(Dialect::LinuxCnc),
            "{text}"
        );
    }
    for text in [
        "O0100\nG0 X0\n",
        "O1000 (SUB PROGRAM)\nG0 X0\n",
        "O2000(CALLS)\nG0 X0\n",
    ] {
        assert_eq!(
            detect_dialect(&text.to_uppercase()),
            Some(Dialect::Fanuc),
            "{text}"
        );
    }
    // And the two repro programs read as LinuxCNC, through detection, with their moves.
    for (text, length) in [
        (
            "o100 sub\nG0 X7 Y8\no100 endsub\nG21 G90\nG0 X0 Y0 Z5\nG1 X10 F100\nM2\n",
            10.0,
        ),
        (
            "o100 sub\n  G1 X10 F600\no100 endsub\nG21 G90\nG0 X0 Y0 Z5\no100 call\nM2\n",
            10.0,
        ),
    ] {
        let dialect = detect_dialect(&text.to_uppercase()).expect("a dialect");
        let tp = ok_in(dialect, text);
        let path: f64 = tp.points.windows(2).map(|w| (w[1].p - w[0].p).norm()).sum();
        assert!((path - length).abs() < 1e-9, "{text}: {path}");
    }
}

/// A warning said of many blocks keeps one copy of its text: every occurrence shares it (the
/// Fanuc combined-feed rule's 390 characters on each block of a 100k-block four-axis program
/// took 32 MB), while each keeps its own line.
#[test]
fn a_warning_said_again_shares_its_text() {
    let tp = ok_in(
        Dialect::Sinumerik,
        "G71\nG0 X0 Y0 Z0\nG1 X1 F100 M348\nG1 X2 M348\nG1 X3 M348\nM30\n",
    );
    let said: Vec<&Warning> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("M348"))
        .collect();
    assert_eq!(said.len(), 3, "{:?}", tp.warnings);
    assert_eq!(
        said.iter().map(|w| w.line).collect::<Vec<_>>(),
        vec![3, 4, 5]
    );
    assert!(
        said.windows(2)
            .all(|w| std::sync::Arc::ptr_eq(&w[0].message, &w[1].message)),
        "one text, shared"
    );
}

/// A Fadal program (round 8: `L900` defines subprogram 9, `L901` calls it, `G3 I-4.5 L14`
/// repeats the arc 14 times) read as LinuxCNC or Fanuc dropped every such move in silence.
/// An L word with nothing in its block to read it is an error naming it; G10, canned cycles
/// (their repeat count), M98 and LinuxCNC's M66 still read theirs.
#[test]
fn an_l_word_nothing_reads_is_an_error_naming_it() {
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc] {
        err_in(
            dialect,
            "G21 G90\nG0 X0. Y0. Z0.\nN3 L901\nG1 X10. F100.\n",
            3,
            &["`L901`", "Fadal"],
        );
        err_in(
            dialect,
            "G21 G90\nG0 X4.5 Y0. Z0.\nG91 G3 I-4.5 Z-0.5 L14 F80.\n",
            3,
            &["`L14`"],
        );
    }
    ok(
        "G21 G90\nG10 L2 P1 X0 Y0 Z0\nG0 X0 Y0 Z5\nG81 X5 Y0 Z-3 R1 L2 F100\nX10\nG80\nM66 P0 L3 Q1\n",
    );
    ok_in(
        Dialect::Fanuc,
        "G21 G90\nG0 X0. Y0. Z5.\nG81 X5. Z-3. R1. K2 F100.\nX10. L2\nG80\n",
    );
}

/// SolidCAM's Mach3 post (round 8) writes `G0 G53 Z123  ; move up to tool_z_level` in a
/// program headed `O1`, read in the Fanuc dialect, where `;` ends a block: the words after it
/// were "`M` has no number". The error now says what the `;` is taken for and what to do.
#[test]
fn text_after_a_fanuc_end_of_block_semicolon_names_the_semicolon() {
    err_in(
        Dialect::Fanuc,
        "O1 (TEST)\nG21 G90\nG0 G53 Z123  ; move up to tool_z_level\n",
        3,
        &[
            "`M` has no number",
            "after a `;`",
            "Fanuc",
            "--dialect linuxcnc",
        ],
    );
    // A `;` as Fanuc's end of block before another block still reads.
    let tp = ok_in(Dialect::Fanuc, "G21 G90\nG0 X0. Y0. Z5. ; G1 X10. F100.\n");
    assert_eq!(tp.points.last().unwrap().p.x, 10.0);
}

/// A Fusion lathe post's `G28 U0. W0.` (round 8) read in the Fanuc dialect: the refusal of
/// the U word says that on a Fanuc lathe U and W are X and Z incremental, a turning program.
/// (The program's `G50 S6000` is left out here: since round 9 that line stops first, naming a
/// turning program too.)
#[test]
fn a_fanuc_u_word_names_the_lathe_reading() {
    err_in(
        Dialect::Fanuc,
        "%\nO2001\nN10 G99 G18\nN11 G21\nN12 G97 S1000 M3\nN13 G28 U0. W0.\n",
        6,
        &["`U0.`", "lathe", "turning program"],
    );
}

/// A Fanuc macro program run on its own (round 8, Brown-Industries' O9250 starts `IF [#1 EQ
/// #0] THEN #3000=1`): its arguments #1–#33 are unset. The error says they are a macro call's
/// arguments and to solve the calling program.
#[test]
fn a_macro_argument_read_before_it_is_set_names_the_macro_call() {
    err_in(
        Dialect::Fanuc,
        "%\nO9250 (DYNAMIC ROTATION CALC)\nIF [#1 EQ #0] THEN #3000=1 (NEED AXIS)\nM99\n",
        3,
        &["`#1`", "macro call's arguments", "G65", "calls it"],
    );
    err_in(
        Dialect::Fanuc,
        "G21 G90\nG0 X[#100] Y0. Z0.\n",
        2,
        &["`#100` is read before it is set"],
    );
}

/// Fusion's Snapmaker (Marlin) post writes `G4 S2` for a 2 s dwell (round 9: four of the
/// Titans of CNC Snapmaker programs). Here S is the spindle speed, so the dwell has no time:
/// still refused, but the refusal names the Marlin reading and says to write `G4 P…`.
#[test]
fn a_marlin_g4_s_dwell_names_the_marlin_reading() {
    err(
        ";Pockets\nM3 P100\nG4 S2\nG21\nG90\nG0 X1 Y1 Z5\n",
        3,
        &["G4 without P", "Marlin", "`G4 S…` as seconds", "`G4 P…`"],
    );
    err_in(
        Dialect::Fanuc,
        "G21 G90\nG4 S2\n",
        2,
        &["Marlin", "milliseconds in Fanuc"],
    );
    // Without S the message stays the short one.
    err("G21 G90\nG4\n", 2, &["G4 without P (the dwell time)"]);
}

/// Makino's Pro3 posts (NX, round 10) write `G05 P10000` before a cut and `G05 P0` after it:
/// high-precision contour control (HPCC) on and off, the look-ahead of the Fanuc 16i/18i-MB,
/// which moves nothing. It was refused as an unknown G code. Any other G05 is high-speed
/// cycle machining (motion from data held in the control) and stays an error naming it.
#[test]
fn fanuc_g05_high_precision_contour_control_moves_nothing() {
    let plain = "O1\nG21 G90 G17\nG0 X0 Y0 Z5\nG1 Z0 F300\nX10 Y5\nG0 Z5\nM30\n";
    let hpcc = "O1\nG21 G90 G17\nG05 P10000\nG0 X0 Y0 Z5\nG1 Z0 F300\nX10 Y5\nG05 P0\nG0 Z5\nM30\n";
    let a = ok_in(Dialect::Fanuc, plain);
    let b = ok_in(Dialect::Fanuc, hpcc);
    assert_eq!(a.points.len(), b.points.len());
    for (p, q) in a.points.iter().zip(&b.points) {
        assert!(close(p.p, q.p, 1e-12), "{:?} vs {:?}", p.p, q.p);
        assert_eq!(p.feed, q.feed);
    }
    err_in(
        Dialect::Fanuc,
        "O1\nG21 G90\nG0 X0 Y0 Z0\nG05 P2\n",
        4,
        &["`G05 P2`", "G05 P10000", "high-speed cycle machining"],
    );
    err_in(
        Dialect::Fanuc,
        "O1\nG21 G90\nG05\n",
        3,
        &["`G05` without P", "G05 P0"],
    );
}

/// An arc whose end is off its circle says what the block shows the program meant. A lathe
/// program (NX's Giddings & Lewis 802L post, round 10) writes `G02 X… Z… I… K…` with no G18:
/// read in G17, K is not a centre word and the radius check fails, which named neither. NX's
/// sample part, posted for Toyoda, Mazak, Makino and Mighty Viper machines (and, round 17,
/// Burgmaster, Fadal, Yama Seiki, Makino V33 and Mori SH8000), writes a lead-out arc whose J
/// has the wrong sign (start (1.8701, −0.3937), end (1.6439, −0.5118), J 0.2756: the end is
/// 0.4541 from that centre). Its Klartext twin (the Bridgeport 412 post) puts the centre at
/// J −0.2756 (`CC X1.8701 Y-.6693`), tangent to the cut before it; I J measured from the end
/// point fit the radius too, and the message said only that (until round 17), naming the
/// wrong reading. Both are named now, the sign first.
#[test]
fn an_arc_off_its_circle_names_what_the_block_shows() {
    err_in(
        Dialect::Fanuc,
        "O1\nG20 G90 G17\nG0 X1.055 Z4.7043\nG02 X1.0143 Z4.745 I-.0407 K0.0 F.03\n",
        4,
        &[
            "not on the circle",
            "gives K",
            "G17 arc does not use",
            "G18",
        ],
    );
    err_in(
        Dialect::Fanuc,
        "O1\nG20 G90 G17\nG0 X1.8701 Y-.3937 Z0\nG03 X1.6439 Y-.5118 I0.0 J.2756 F20.\n",
        4,
        &[
            "not on the circle",
            "these would fit: I0 J-7.0002 mm (the sign reversed), centre (47.5005, -17.0002) mm",
            "; or I J measured from the end point, centre (41.7551, -5.9995) mm",
            "the post wrote them wrong",
        ],
    );
    // An arc that fits neither way keeps the plain message.
    match parse(
        Path::new("bad.ngc"),
        "G21 G90 G17\nG0 X0 Y0 Z0\nG2 X10 Y0 I3 J0 F100\n",
        Dialect::LinuxCnc,
    ) {
        Err(Error::Parse { line, message, .. }) => {
            assert_eq!(line, 3);
            assert!(message.contains("not on the circle"), "{message}");
            assert!(!message.contains(';'), "{message}");
        }
        other => panic!("expected the radius error, got {other:?}"),
    }
}

/// A post for a control set to read arc centres absolute (LinuxCNC after G90.1, Mach3's and
/// UCCNC's absolute IJ mode) that does not write G90.1 (round 28: a 3,460-line 3-axis
/// program in a public repository, every arc `G2 X… Y… Z… I… J…` with I J the centre's
/// coordinates) failed at its first arc with only the two radii. The message now names that
/// reading, its centre and what to write; the dialect option where the program is not read
/// as LinuxCNC's. Readings as an offset still follow when they fit too.
#[test]
fn an_arc_whose_centre_words_are_absolute_names_g90_1() {
    let text = "G21 G90 G17\nG0 X-2. Y-4. Z5.\nG1 Z0. F100.\nG2 X-2. Y4. Z-1. I1. J0.\n";
    err_in(
        Dialect::LinuxCnc,
        text,
        4,
        &[
            "not on the circle",
            "I J read as the centre's coordinates would fit, centre (1, 0) mm",
            "absolute arc centres",
            "write G90.1 ahead of its first arc",
        ],
    );
    match parse(Path::new("abs.ngc"), text, Dialect::LinuxCnc) {
        Err(Error::Parse { message, .. }) => {
            assert!(!message.contains("--dialect"), "{message}");
            assert!(!message.contains("these would fit"), "{message}");
        }
        other => panic!("expected the radius error, got {other:?}"),
    }
    err_in(
        Dialect::Fanuc,
        &format!("O1\n{text}"),
        5,
        &[
            "centre (1, 0) mm",
            "write G90.1 ahead of its first arc and read it with --dialect linuxcnc",
        ],
    );
    // With G90.1 the same program reads, the arc about (1, 0), radius 5, clockwise from
    // (-2, -4) through (-4, 0) to (-2, 4).
    let tp = ok(&format!("G90.1\n{text}"));
    assert_close(
        tp.points.last().expect("points").p,
        v(-2.0, 4.0, -1.0),
        1e-9,
    );
    let arc: Vec<_> = tp.points.iter().filter(|q| q.line == 5).collect();
    assert!(arc.len() > 4, "{} points on the arc", arc.len());
    for q in &arc {
        let r = (q.p.x - 1.0).hypot(q.p.y);
        assert!((r - 5.0).abs() < 1e-6, "{:?} off the circle (r {r})", q.p);
        assert!(q.p.x <= -2.0 + 1e-9, "{:?}: the long way round", q.p);
    }
}

/// NX writes a posted program into an "Information listing" (round 10: the Mazak Nexus 510,
/// Mitsubishi VR33 and Okuma 7000M samples) whose header starts with a rule of `=`. The error
/// said "unexpected character `=`"; it now says that the line is not G-code and what to do.
#[test]
fn a_line_of_text_where_a_block_starts_is_named() {
    err(
        "============================================================\nG21 G90\nG0 X1 Y1 Z1\n",
        1,
        &["`=` at the start of a block", "not G-code", "remove it"],
    );
    // Inside a block the short message stays.
    err("G21 G90\nG0 X1 = Y1\n", 2, &["unexpected character `=`"]);
}

/// NX's DeVlieg 120 post writes `N8 T00O00` (round 10). The program names no dialect, so it is
/// read as LinuxCNC, and the O word was refused as "O-word control flow (if, while, do, repeat)
/// is not supported", which it is not: an O word after other words is neither an O-word
/// statement nor a program number. The error now says so; an O word that starts its block
/// (after a line number at most) keeps the control-flow message.
#[test]
fn an_o_word_after_other_words_is_named_as_such() {
    err(
        "G21 G90\nN8 T00O00\n",
        2,
        &["`O00` after `N8", "T00` in the same block", "own line"],
    );
    err("G21 G90\nN8 O00\n", 2, &["O-word control flow"]);
}

/// Round 20: a Mastercam program edited by hand (`O0000(ACRYLIC TOP)`, `N1 G21; mm mode`) is
/// refused in the Fanuc dialect at its `;` comments with the advice to read it as LinuxCNC;
/// read so, its program number was refused as "O-word control flow (if, while, do, repeat) is
/// not supported", which sent the user looking for a loop. The message now names the bare O
/// number as a Fanuc program number and says what to do.
#[test]
fn a_bare_program_number_read_as_linuxcnc_is_named() {
    err_in(
        Dialect::LinuxCnc,
        "O0000(ACRYLIC TOP)\nG21\nG0 X1 Y1 Z1\n",
        1,
        &[
            "`O0000`",
            "a bare `O1234` at the top is a Fanuc program number",
            "remove it",
        ],
    );
}

// ---------------------------------------------------------------------------------------------
// Chamfers and roundings between straight moves (Fanuc `,C` `,R`, Sinumerik `CHR=` `CHF=` `RND=`)
// ---------------------------------------------------------------------------------------------

/// The length of the polyline through the points.
fn polyline_length(tp: &Toolpath) -> f64 {
    tp.points.windows(2).map(|w| (w[1].p - w[0].p).norm()).sum()
}

#[test]
fn fanuc_comma_r_and_comma_c_cut_the_corner_to_the_next_move() {
    // Round 16: a hand-written Fanuc program (`G01 X 92 Y 50, R 15;`) was refused at the comma
    // ("unexpected character"); Haas and Fanuc round the corner with an arc of radius R tangent
    // to both moves, and `,C` chamfers it from C before to C after the corner.
    let tp = ok_in(
        Dialect::Fanuc,
        "O1000\nG90 G21 G94\nG1 X0. Y0. Z0. F600.\nG1 X50. , R 5.\nG1 Y50. ,C3.\nG1 X0.\nM30\n",
    );
    let ps: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    // The first move stops 5 mm short of the corner; the arc about (45, 5) ends 5 mm up the
    // second, every chord end on the circle.
    assert_close(ps[1], v(45.0, 0.0, 0.0), 1e-12);
    let arc: Vec<&ClPoint> = tp.points.iter().filter(|p| p.line == 4).collect();
    assert!(arc.len() > 10, "{} points on the rounding", arc.len());
    for p in &arc {
        assert!(
            ((p.p - v(45.0, 5.0, 0.0)).norm() - 5.0).abs() < 1e-9,
            "{:?}",
            p.p
        );
        assert!((programmed(p.feed) - 10.0).abs() < 1e-12);
    }
    assert_close(arc.last().unwrap().p, v(50.0, 5.0, 0.0), 1e-9);
    // The chamfer: from 3 mm before (50, 50) to 3 mm after it.
    let chamfer: Vec<Vector3<f64>> = tp
        .points
        .iter()
        .filter(|p| p.line == 5)
        .map(|p| p.p)
        .collect();
    assert_eq!(chamfer.len(), 2, "{chamfer:?}");
    assert_close(chamfer[0], v(50.0, 47.0, 0.0), 1e-12);
    assert_close(chamfer[1], v(47.0, 50.0, 0.0), 1e-12);
    assert_close(*ps.last().unwrap(), v(0.0, 50.0, 0.0), 1e-12);
    // 150 mm less 10 − 5π/2 at the rounding (its chords a little shorter) and 6 − 3√2.
    let expected = 150.0 - (10.0 - 5.0 * std::f64::consts::FRAC_PI_2) - (6.0 - 3.0 * 2f64.sqrt());
    let got = polyline_length(&tp);
    assert!(
        got < expected && got > expected - 1e-3,
        "{got} vs {expected}"
    );
}

#[test]
fn sinumerik_rnd_chf_and_chr_cut_the_corner_to_the_next_move() {
    // They were unknown words skipped with a warning: the corners stayed sharp, a path the
    // control does not run.
    let tp = ok_in(
        Dialect::Sinumerik,
        "G90 G71 G94\nG1 X0 Y0 Z0 F600\nG1 X50 RND=5\nG1 Y50 CHF=3\nG1 X0 CHR=2\nG1 Y0\nM30\n",
    );
    assert!(
        !tp.warnings.iter().any(|w| w.message.contains("unknown")),
        "{:?}",
        tp.warnings
    );
    for p in tp.points.iter().filter(|p| p.line == 3).skip(1) {
        assert!(
            ((p.p - v(45.0, 5.0, 0.0)).norm() - 5.0).abs() < 1e-9,
            "{:?}",
            p.p
        );
    }
    // CHF=3 is the chamfer's own length: at a right angle it starts 3/√2 before the corner.
    let leg = 3.0 / 2f64.sqrt();
    let chf: Vec<Vector3<f64>> = tp
        .points
        .iter()
        .filter(|p| p.line == 4)
        .map(|p| p.p)
        .collect();
    assert_eq!(chf.len(), 2, "{chf:?}");
    assert_close(chf[0], v(50.0, 50.0 - leg, 0.0), 1e-12);
    assert_close(chf[1], v(50.0 - leg, 50.0, 0.0), 1e-12);
    assert!(((chf[1] - chf[0]).norm() - 3.0).abs() < 1e-12);
    // CHR=2 is the leg.
    let chr: Vec<Vector3<f64>> = tp
        .points
        .iter()
        .filter(|p| p.line == 5)
        .map(|p| p.p)
        .collect();
    assert_close(chr[0], v(2.0, 50.0, 0.0), 1e-12);
    assert_close(chr[1], v(0.0, 48.0, 0.0), 1e-12);
}

#[test]
fn a_chamfer_or_rounding_feedopt_cannot_make_is_an_error_naming_its_word() {
    let fanuc =
        |text: &str, line: usize, needles: &[&str]| err_in(Dialect::Fanuc, text, line, needles);
    let head = "O1000\nG90 G21 G94\nG1 X0. Y0. Z0. F600.\n";
    // Into an arc (round 16's college program), a rapid, or nothing.
    fanuc(
        &format!("{head}G1 X50. ,R5.\nG3 X60. Y10. R10.\nM30\n"),
        4,
        &[",R5.", "line 5", "arc"],
    );
    fanuc(
        &format!("{head}G1 X50. ,C2.\nG0 Y50.\nM30\n"),
        4,
        &[",C2.", "rapid"],
    );
    fanuc(&format!("{head}G1 X50. ,R5.\nM30\n"), 4, &[",R5.", "ends"]);
    // Larger than the moves allow (Fanuc alarms), or with a dwell between.
    fanuc(
        &format!("{head}G1 X50. ,R60.\nG1 Y50.\nM30\n"),
        4,
        &[",R60.", "too short"],
    );
    fanuc(
        &format!("{head}G1 X50. ,R5.\nG4 X1.\nG1 Y50.\nM30\n"),
        4,
        &[",R5.", "dwell"],
    );
    // In line with the next move: no corner.
    fanuc(
        &format!("{head}G1 X50. ,C2.\nG1 X80.\nM30\n"),
        4,
        &[",C2.", "no corner"],
    );
    // On an arc, or a block that moves nothing.
    fanuc(
        &format!("{head}G2 X20. Y0. R10. ,R2.\nG1 Y50.\nM30\n"),
        4,
        &[",R2.", "straight"],
    );
    fanuc(
        &format!("{head}G1 X50.\nM8 ,R2.\nG1 Y50.\nM30\n"),
        5,
        &[",R2.", "straight move"],
    );
    // Sinumerik: modal rounding and a corner feed of its own are refused where they act.
    let sin =
        |text: &str, line: usize, needles: &[&str]| err_in(Dialect::Sinumerik, text, line, needles);
    sin(
        "G71 G94\nG1 X0 Y0 Z0 F600\nRNDM=2\nG1 X50\nG1 Y50\n",
        3,
        &["RNDM=", "modal"],
    );
    sin(
        "G71 G94\nG1 X0 Y0 Z0 F600\nG1 X50 RND=2 FRC=100\nG1 Y50\n",
        3,
        &["FRC=", "feed"],
    );
    let tp = ok_in(
        Dialect::Sinumerik,
        "G71 G94\nG1 X0 Y0 Z0 F600\nRNDM=0 FRC=0\nG1 X50\nG1 Y50\n",
    );
    assert_eq!(tp.points.len(), 3);
    // LinuxCNC has no such words: the comma stays an error, which names the Fanuc dialect.
    err(
        "G21 G1 X0 Y0 Z0 F600\nG1 X50 ,R5\nG1 Y50\n",
        2,
        &[",R", "--dialect fanuc"],
    );
}

#[test]
fn sinumerik_words_that_set_an_end_point_or_the_orientation_another_way_are_errors() {
    // Round 16: each was an unknown word skipped with a warning: `G1 X60 ANG=30` went to X60
    // alone, and under TRAORI `A2= B2= C2=` or `LEAD= TILT=` left the tool where the last
    // block had it, while the control turns the rotary axes to them.
    let sin = |word: &str, needle: &str| {
        err_in(
            Dialect::Sinumerik,
            &format!("G71 G94\nG1 X0 Y0 Z0 F600\nTRAORI\nG1 X50 {word}\nG1 Y50\n"),
            4,
            &[needle],
        )
    };
    sin("ANG=30", "ANG=");
    sin("A2=10 B2=20 C2=0", "A2=");
    sin("LEAD=10 TILT=5", "LEAD=");
    sin("THETA=30", "THETA=");
    sin("PHI=10", "PHI=");
    sin("A4=0 B4=0 C4=1", "A4=");
    sin("A5=0", "A5=");
    sin("XH=10 YH=0 ZH=5", "XH=");
}

#[test]
fn a_macro_call_is_named_not_its_u_v_w_arguments() {
    // Round 16: a Haas program's `G65 P9001 A.125 C.625 V10100.` was refused at `V10100.`
    // as a parallel axis; the letters are the macro's arguments (V is #22).
    err_in(
        Dialect::Fanuc,
        "O2001\nG90 G20 G94\nG1 X0. Y0. Z0. F10.\nG65 P9001 A.125 C.625 V10100.\nM30\n",
        4,
        &["G65", "macro call", "V10100."],
    );
    // Outside a macro call, V is still a parallel axis.
    err_in(
        Dialect::Fanuc,
        "O2001\nG90 G20 G94\nG1 X0. Y0. Z0. F10.\nG1 V1.\nM30\n",
        4,
        &["V1.", "U, V or W"],
    );
}

/// G41/G42 (Klartext RL/RR) move the tool off the programmed path by its radius, which
/// feedopt does not model: an error naming the line and word, unless the user says the path
/// is the tool centre's and the offset only wear (`--wear-compensation`; the reader then reads
/// it as programmed, and says so). It was a warning, while a hand-written program's part
/// contour was run as the tool centre (round 16: a ½ in end mill "engaging" 27.9 mm).
#[test]
fn cutter_radius_compensation_is_an_error_unless_it_is_wear_only() {
    let g = "G21 G90 G94\nG0 X0 Y0 Z5\nG1 Z-1 F300\nG41 D1 G1 X10\nG1 Y10\nG40 G1 X0\nM2\n";
    err_in(Dialect::LinuxCnc, g, 4, &["G41", "--wear-compensation"]);
    err_in(Dialect::Fanuc, &g.replace("G41", "G42"), 4, &["G42"]);
    err_in(Dialect::Sinumerik, &g.replace("G21", "G71"), 4, &["G41"]);
    let h = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S5000\n2 L X+0 Y+0 Z+5 R0 FMAX\n\
             3 L Z-1 F300\n4 L X+10 RL\n5 L Y+10\n6 L X+0 R0\n7 END PGM T MM\n";
    err_in(Dialect::Heidenhain, h, 5, &["RL", "--wear-compensation"]);
    // Wear only: read as programmed, said once per block.
    let m = feedopt::machine::Machine::from_json(
        Path::new("m.json"),
        r#"{"kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 100, "acceleration": 1000},
                     "Y": {"velocity": 100, "acceleration": 1000},
                     "Z": {"velocity": 100, "acceleration": 1000}}}"#,
    )
    .unwrap();
    let ctx = feedopt::toolpath::MachineContext {
        wear_compensation: true,
        ..feedopt::toolpath::MachineContext::new(&m, &Default::default())
    };
    let tp = feedopt::toolpath::gcode::parse_for(
        Path::new("t.ngc"),
        g,
        Dialect::LinuxCnc.spec(),
        Some(&ctx),
    )
    .unwrap();
    let xs: Vec<[f64; 3]> = tp.points.iter().map(|p| [p.p.x, p.p.y, p.p.z]).collect();
    assert_eq!(
        xs,
        [
            [0.0, 0.0, 5.0],
            [0.0, 0.0, -1.0],
            [10.0, 0.0, -1.0],
            [10.0, 10.0, -1.0],
            [0.0, 10.0, -1.0]
        ]
    );
    let said: Vec<usize> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("wear only"))
        .map(|w| w.line)
        .collect();
    assert_eq!(said, [4]);
}

/// LinuxCNC `G33.1 Z- K- I-` (the G-code reference's "G33.1 Rigid Tapping"): from where the
/// tool stands to Z at K per revolution (feed K × S), and back to the start at I times the
/// speed; a tap ([`Toolpath::taps`]) of its two points, in the spindle's direction. Until
/// round 19 it was refused as spindle-synchronised motion.
#[test]
fn linuxcnc_rigid_tapping_g33_1_feeds_at_k_times_s_and_back_at_i_times_that() {
    let tp = ok("G21 G90 G94\nG0 X5 Y3 Z2 S400 M4\nG33.1 Z-10 K1.25 I2\nG0 X20\nM2\n");
    let z: Vec<f64> = tp.points.iter().map(|p| p.p.z).collect();
    assert_eq!(z, [2.0, -10.0, 2.0, 2.0]);
    assert_eq!(tp.points[1].feed, Feed::Programmed(500.0 / 60.0));
    assert_eq!(tp.points[2].feed, Feed::Programmed(1000.0 / 60.0));
    let tap = &tp.taps[0];
    assert_eq!(
        (tap.line, tap.name.as_str(), tap.points.clone()),
        (3, "G33.1", 1..3)
    );
    assert_eq!(
        (tap.pitch, tap.rpm, tap.left_hand),
        (Some(1.25), Some(400.0), true)
    );
    assert!(others(&tp).is_empty(), "{:?}", tp.warnings);
    // Inch: K in inches per revolution.
    let tp = ok("G20 G90\nG0 X0 Y0 Z0.1 S100 M3\nG33.1 Z-0.75 K0.05\nM2\n");
    let want = 0.05 * 25.4 * 100.0 / 60.0;
    assert!(
        matches!(tp.points[1].feed, Feed::Programmed(v) if (v - want).abs() < 1e-9),
        "{:?}",
        tp.points[1].feed
    );
    // Its motion ends with the block: an axis word after it is no tap, and no G1.
    for (text, says) in [
        (
            "G21 G90\nG0 X0 Y0 Z2 S400 M3\nG33.1 Z-10 K1.25\nZ-5\nM2\n",
            "without a motion mode",
        ),
        (
            "G21 G90\nG0 X0 Y0 Z2 S400 M3\nG33.1 X5 Z-10 K1.25\nM2\n",
            "slant",
        ),
        (
            "G21 G90\nG0 X0 Y0 Z2 M3\nG33.1 Z-10 K1.25\nM2\n",
            "no spindle speed",
        ),
        (
            "G21 G90\nG0 X0 Y0 Z2 S400 M3\nG33.1 Z-10\nM2\n",
            "K (the distance per revolution)",
        ),
        (
            "G21 G90\nG0 X0 Y0 Z2 S400 M3\nG33.1 Z-10 K1 I0\nM2\n",
            "speed factor I",
        ),
    ] {
        let e = parse(Path::new("test.ngc"), text, Dialect::LinuxCnc)
            .unwrap_err()
            .to_string();
        assert!(e.contains("test.ngc:") && e.contains(says), "{text}: {e}");
    }
}

/// A `%` line with text after it (an MPCNC user's start file: `% vfd enable`, round 20) is no
/// tape start or end mark. LinuxCNC takes a line as its percent line only when nothing but
/// blanks follows the `%` (rs274ngc `Interp::open`: `if (line[index] == '%') { for
/// (index--; (index >= 0) && (isspace(line[index])); index--); if (index == -1) percent_flag
/// = true; … else … going back to line 0 }`), and then reads the line as G-code, where `%` is
/// no word, and refuses it. The line moves nothing: a warning naming it and saying so (it was
/// skipped in silence); in the other dialects a warning naming the text.
#[test]
fn a_percent_line_with_text_is_named() {
    let text = "%\nG21 G90\n% vfd enable\nG0 X0 Y0 Z5\nG1 X10 F100\nM2\n%\n";
    for (dialect, text, needle) in [
        (Dialect::LinuxCnc, text.to_string(), "refuses it"),
        (Dialect::Fanuc, text.replace("X10", "X10."), "is not read"),
    ] {
        let tp = ok_in(dialect, &text);
        let w: Vec<_> = tp
            .warnings
            .iter()
            .filter(|w| w.message.contains("`% vfd enable`"))
            .collect();
        assert_eq!(w.len(), 1, "{:?}", tp.warnings);
        assert_eq!(w[0].line, 3);
        assert!(w[0].message.contains(needle), "{}", w[0].message);
        assert_eq!(tp.points.last().map(|p| p.p.x), Some(10.0));
    }
    // `%` alone, at the start and the end, stays the tape mark: no warning.
    let plain = ok(&text.replace("% vfd enable\n", ""));
    assert!(
        !plain.warnings.iter().any(|w| w.message.contains('%')),
        "{:?}",
        plain.warnings
    );
}

/// Fadal's fixture offsets (`E1`…`E48` select a fixture offset, `E0` cancels it; Autodesk's
/// Fusion post "Fadal": "output E-codes or … G54-G59 for WCS offsets"): a Polish shop's Fadal programs (round 22) write `G90 G0 X0 Y0 E1` and park
/// with `E0 X0. Y250.`. Read in the Fanuc dialect (the programs start `N1 O1`), the E word was
/// skipped in silence; it is now an offset selection, whose values the program does not give:
/// a warning naming it, as for `G55` without `G10`. An E that names no fixture offset is an
/// error; Haas `G187 P2 E0.005` (a smoothing tolerance) is no offset.
#[test]
fn fadal_fixture_offset_words_are_offset_selections() {
    let text = "N1 O1 (PLAN)\nN2 G0 G90 M6 T10\nN3 G90 G0 X0. Y0 E1\nN4 Z5.\n\
                N5 G1 Z-0.3 F200.\nN6 G1 X160.\nN7 G0 Z50.\nN8 E0 X0. Y250.\nN9 M2\n";
    let tp = ok_in(Dialect::Fanuc, text);
    let w: Vec<_> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("E0"))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", tp.warnings);
    assert_eq!(w[0].line, 8);
    assert!(w[0].message.contains("E1"), "{}", w[0].message);
    err_in(
        Dialect::Fanuc,
        &text.replace("E1", "E2.5"),
        3,
        &["`E2.5`", "fixture offset"],
    );
    let haas = ok_in(
        Dialect::Fanuc,
        "O1\nG187 P2 E0.005\nG0 X0. Y0. Z5.\nG1 X10. F100.\nM30\n",
    );
    assert!(
        !haas.warnings.iter().any(|w| w.message.contains("E0")),
        "{:?}",
        haas.warnings
    );
}

/// Fadal subroutines (a Polish shop's Fadal programs, round 22): `L100` (or `L0100`) … `M17`
/// defines subroutine 1; the definitions come first and an `M30` after the last one ends
/// them, the main program following it; `L101` calls subroutine 1 once, `L102` twice. With
/// a canned cycle defined with `L0` (no hole where it is defined, Fanuc's K0/L0), the
/// subroutine's positions are the holes. They were an error at `L100` (round 8's message).
#[test]
fn fadal_subroutines_run_where_called() {
    let text = "N1 O1 (OTW)\nN2 L100\nN3 X-10. Y5.\nN4 X10. Y5.\nN5 M17\n\nN6 M30\n\n\
                N7 G0 G90 G80 G17\nN8 G0 G90 X0 Y0\nN9 Z20.\n\
                N10 G98 G81 X0 Y0 Z-3. R2. F60. L0\nN11 L102\nN12 G80\nN13 G0 Z50.\nN14 M2\n";
    let tp = ok_in(Dialect::Fanuc, text);
    let bottoms: Vec<(f64, f64)> = tp
        .points
        .iter()
        .filter(|p| (p.p.z + 3.0).abs() < 1e-9)
        .map(|p| (p.p.x, p.p.y))
        .collect();
    assert_eq!(
        bottoms,
        [(-10.0, 5.0), (10.0, 5.0), (-10.0, 5.0), (10.0, 5.0)]
    );
    // The M30 that ends the definitions does not end the program.
    assert_eq!(tp.points.last().map(|p| p.p.z), Some(50.0));
    err_in(
        Dialect::Fanuc,
        "N1 O1\nN2 L100\nN3 X1. Y1.\nN4 M30\n",
        2,
        &["L1", "no M17"],
    );
    err_in(
        Dialect::Fanuc,
        "N1 O1\nN2 L100\nN3 X1. Y1.\nN4 M17\nN5 M30\nN6 G0 X0. Y0. Z5.\nN7 L301\n",
        7,
        &["`L301`", "L3"],
    );
}

/// The same motion code twice in a block (a Fadal program's `G0 G90 G0 X0 Y0 E1`, round 22)
/// moves as once on a Fanuc, which takes the last G code of a group given twice; LinuxCNC
/// refuses two G codes of one modal group, and two different motion codes stay an error.
#[test]
fn the_same_motion_code_twice_is_read_in_the_fanuc_dialect() {
    let tp = ok_in(
        Dialect::Fanuc,
        "O1\nG0 G90 G0 X1. Y2. Z3.\nG1 X5. F100.\nM30\n",
    );
    assert_eq!(tp.points.last().map(|p| p.p.x), Some(5.0));
    err_in(
        Dialect::LinuxCnc,
        "G0 G90 G0 X1 Y2 Z3\n",
        1,
        &["two motion codes"],
    );
    err_in(
        Dialect::Fanuc,
        "O1\nG0 G1 X1. Y2. Z3.\n",
        2,
        &["two motion codes"],
    );
}

/// The length of the path through a toolpath's points.
fn path_length(tp: &Toolpath) -> f64 {
    tp.points.windows(2).map(|w| (w[1].p - w[0].p).norm()).sum()
}

/// grbl's homing cycle `$H` (grbl wiki, "Grbl v1.1 Commands": "`$H` - Run homing cycle"; the
/// homed position is machine zero when homing in grbl's default positive direction: "If you
/// home in a positive direction your position will be 0", Grbl_Esp32 wiki "Machine Space and
/// Homing"). gSender's programs (Sienci-Labs/gsender `examples/gcode/KB-435 test.gcode`) start
/// `G21` / `$H` / `G10 L20 P1 X0 Y0 Z50` / `G54`, so the start is home and the work offset is
/// set from there; the line was refused as "unexpected character `$`". Read as the start at
/// home (the machine file's reference, else machine zero, as for `G28`): the program solves,
/// the path starting at home.
#[test]
fn grbl_homing_at_the_start_places_the_program() {
    let tp = ok("G21\n$H\nG10 L20 P1 X0 Y0 Z50\nG54\nG0 X10 Y0 Z50\nG1 X20 F100\nM2\n");
    assert!(
        (path_length(&tp) - 20.0).abs() < 1e-9,
        "{}",
        path_length(&tp)
    );
    assert!(
        !tp.warnings
            .iter()
            .any(|w| w.message.contains("not programmed yet")),
        "{:?}",
        tp.warnings
    );
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.line == 2 && w.message.contains("`$H`")),
        "{:?}",
        tp.warnings
    );
}

/// `$H` after moves (gSender's `KB-850 test.nc` homes again after an `M0` part change, line
/// 21425): the axes go home as grbl's default homing cycles order them, `HOMING_CYCLE_0` Z,
/// then `HOMING_CYCLE_1` X and Y (grbl `config.h`), timed as rapids, with a warning that the
/// switch search is not; grblHAL's `$HX` homes X alone. Other system commands move nothing
/// (`$X` unlock, `$$` report, `$22=1` a setting): a warning each; a jog `$J=…` and check mode
/// `$C` are errors naming the line.
#[test]
fn grbl_homing_after_moves_and_other_system_commands() {
    let tp = ok("G21\nG0 X5 Y5 Z-5\n$X\n$22=1\n$H\nM2\n");
    let last: Vec<Vector3<f64>> = tp.points.iter().rev().take(2).map(|p| p.p).collect();
    assert_close(last[1], v(5.0, 5.0, 0.0), 1e-9);
    assert_close(last[0], v(0.0, 0.0, 0.0), 1e-9);
    assert!(
        tp.warnings.iter().any(|w| w.line == 5
            && w.message.contains("homing cycle")
            && w.message.contains("Z first")),
        "{:?}",
        tp.warnings
    );
    for line in [3, 4] {
        assert!(
            tp.warnings
                .iter()
                .any(|w| w.line == line && w.message.contains("moves nothing")),
            "{:?}",
            tp.warnings
        );
    }
    let one = ok("G21\nG0 X5 Y5 Z-5\n$HX\nM2\n");
    assert_close(one.points.last().unwrap().p, v(0.0, 5.0, -5.0), 1e-9);
    err("G21\nG0 X5 Y5 Z-5\n$J=G91 X10 F100\nM2\n", 3, &["jog"]);
    err("G21\n$C\nG0 X5 Y5 Z-5\nM2\n", 2, &["check mode"]);
    err(
        "G21\n$Q\nG0 X5 Y5 Z-5\nM2\n",
        2,
        &["not a grbl system command"],
    );
}
