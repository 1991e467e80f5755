//! Heidenhain TNC 640 Klartext, the fourth dialect (issue 12 item 7): each construct against
//! hand-computed paths, lengths, orientations and times.

mod common;

use feedopt::optimize::{Options, optimize};
use feedopt::toolpath::gcode::{Dialect, parse, parse_for};
use feedopt::toolpath::{self, ClPoint, Feed, Format, MachineContext, ReadOptions, Toolpath};
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::path::Path;

fn read(text: &str) -> Toolpath {
    parse(Path::new("t.h"), text, Dialect::Heidenhain).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn fails(text: &str) -> String {
    match parse(Path::new("t.h"), text, Dialect::Heidenhain) {
        Ok(tp) => panic!("expected an error, read {} points\n{text}", tp.points.len()),
        Err(e) => e.to_string(),
    }
}

fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
    Vector3::new(x, y, z)
}

fn close(a: Vector3<f64>, b: Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol
}

/// Length of the moves between the points.
fn length(points: &[ClPoint]) -> f64 {
    points.windows(2).map(|w| (w[1].p - w[0].p).norm()).sum()
}

/// Chords within e = 1 µm of an arc are shorter than it by α²/6 = e/(3r) relative (α their
/// half angle, 1 − cos α = e/r): at most 3.4e-5 for r ≥ 10 mm.
fn arc_close(got: f64, want: f64) -> bool {
    got <= want + 1e-9 && want - got <= 3.4e-5 * want
}

/// Time of the feed moves at their programmed feeds, s.
fn feed_time(tp: &Toolpath) -> f64 {
    tp.points
        .windows(2)
        .map(|w| match w[1].feed {
            Feed::Programmed(f) => (w[1].p - w[0].p).norm() / f,
            _ => 0.0,
        })
        .sum()
}

const HEADER: &str = "0 BEGIN PGM T MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-20\n\
                      2 BLK FORM 0.2 X+100 Y+100 Z+0\n3 TOOL CALL 1 Z S5000\n";

#[test]
fn lines_and_an_arc_about_cc_give_the_hand_computed_path_and_length() {
    let text = format!(
        "{HEADER}4 L X+0 Y+0 Z+5 R0 FMAX M3\n5 L Z-2 F300\n6 L X+50 F600\n7 CC X+50 Y+20\n\
         8 C X+70 Y+20 DR+\n9 L IY+30 ; incremental, this word only\n10 L X+0\n\
         11 END PGM T MM\n"
    );
    let tp = read(&text);
    assert_eq!(tp.points[0].p, v(0.0, 0.0, 5.0));
    assert_eq!(tp.points[0].feed, Feed::Rapid);
    assert_eq!(tp.points[1].p, v(0.0, 0.0, -2.0));
    assert_eq!(tp.points[1].feed, Feed::Programmed(5.0));
    assert_eq!(tp.points[2].p, v(50.0, 0.0, -2.0));
    assert_eq!(tp.points[2].feed, Feed::Programmed(10.0));
    // The quarter circle about (50, 20), radius 20, counter-clockwise from −90° to 0°.
    let arc: Vec<&ClPoint> = tp.points.iter().filter(|p| p.line == 9).collect();
    assert!(arc.len() > 50, "chords within 1 µm: {}", arc.len());
    let mut last_angle = -PI / 2.0;
    for p in &arc {
        let r = (p.p - v(50.0, 20.0, -2.0)).norm();
        assert!((r - 20.0).abs() < 1e-9, "{r}");
        let angle = (p.p.y - 20.0).atan2(p.p.x - 50.0);
        assert!(angle > last_angle, "counter-clockwise");
        last_angle = angle;
        assert_eq!(p.feed, Feed::Programmed(10.0));
    }
    assert_eq!(arc.last().map(|p| p.p), Some(v(70.0, 20.0, -2.0)));
    let n = tp.points.len();
    assert_eq!(tp.points[n - 2].p, v(70.0, 50.0, -2.0));
    assert_eq!(tp.points[n - 1].p, v(0.0, 50.0, -2.0));
    // 7 + 50 + 10π (the chords a little shorter, see `arc_close`) + 30 + 70 mm.
    let want = 7.0 + 50.0 + 10.0 * PI + 30.0 + 70.0;
    let got = length(&tp.points);
    assert!(
        got <= want && want - got < 3.4e-5 * 10.0 * PI,
        "{got} vs {want}"
    );
    // DR− goes the other way round: 270° clockwise, 30π mm.
    let cw = read(&text.replace("DR+", "DR-"));
    let arc: Vec<&ClPoint> = cw.points.iter().filter(|p| p.line == 9).collect();
    let mut pts = vec![cw.points[2].clone()];
    pts.extend(arc.iter().map(|p| (*p).clone()));
    assert!(arc_close(length(&pts), 30.0 * PI), "{}", length(&pts));
    // …passing left of the centre, through x = 30 within the 1 µm sagitta.
    let left = arc.iter().map(|p| p.p.x).fold(f64::INFINITY, f64::min);
    assert!((30.0..30.001).contains(&left), "{left}");
}

#[test]
fn fmax_is_this_block_only_and_f_stays_modal() {
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+0 F500\n5 L X+10\n6 L X+20 FMAX\n7 L X+30\n8 L X+40 F MAX\n\
         9 * - 1/2\" DRILL NEXT\n10 L X+50\n"
    ));
    let feeds: Vec<Feed> = tp.points.iter().map(|p| p.feed).collect();
    let f = Feed::Programmed(500.0 / 60.0);
    assert_eq!(feeds[1..], [f, Feed::Rapid, f, Feed::Rapid, f]);
}

#[test]
fn cr_arc_by_radius_short_and_long() {
    // From (50, 0) to (70, 20) with radius 20: R+ DR+ is the quarter circle about (50, 20);
    // R− DR+ the three-quarter circle about (70, 0).
    for (r, centre, sweep) in [
        ("+20", v(50.0, 20.0, 0.0), 0.5 * PI),
        ("-20", v(70.0, 0.0, 0.0), 1.5 * PI),
    ] {
        let tp = read(&format!(
            "{HEADER}4 L X+50 Y+0 Z+0 F600\n5 CR X+70 Y+20 R{r} DR+\n"
        ));
        for p in &tp.points[1..] {
            assert!(
                ((p.p - centre).norm() - 20.0).abs() < 1e-9,
                "R{r}: {:?}",
                p.p
            );
        }
        assert_eq!(tp.points.last().map(|p| p.p), Some(v(70.0, 20.0, 0.0)));
        assert!(
            arc_close(length(&tp.points), 20.0 * sweep),
            "R{r}: {}",
            length(&tp.points)
        );
    }
    let e = fails(&format!(
        "{HEADER}4 L X+50 Y+0 Z+0 F600\n5 CR X+70 Y+20 DR+\n"
    ));
    assert!(e.contains(":6:") && e.contains("without R"), "{e}");
}

#[test]
fn ct_continues_the_line_tangentially() {
    // Along +X to (10, 0), then CT to (20, 10): the circle tangent to +X at (10, 0) through
    // (20, 10) has its centre at (10, 10) (s = |d|²/(2 n·d) = 200/20), radius 10, 90° ccw.
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+0 F600\n5 L X+10\n6 CT X+20 Y+10\n"
    ));
    let arc: Vec<&ClPoint> = tp.points.iter().filter(|p| p.line == 7).collect();
    for p in &arc {
        assert!(((p.p - v(10.0, 10.0, 0.0)).norm() - 10.0).abs() < 1e-9);
    }
    // The first chord leaves along +X (tangent continuity), up to the chord's half angle.
    let d = (arc[0].p - v(10.0, 0.0, 0.0)).normalize();
    assert!(d.x > 0.999 && d.y > 0.0, "{d:?}");
    assert!(arc_close(length(&tp.points[1..]), 5.0 * PI));
    // Without a contour element just before it: an error naming the line.
    let e = fails(&format!("{HEADER}4 CT X+20 Y+10\n"));
    assert!(e.contains(":5:") && e.contains("CT"), "{e}");
}

#[test]
fn cp_by_incremental_angle_is_a_helix_and_cc_y_z_is_the_yz_plane() {
    // Two turns of radius 10 about the origin, 4 mm down: length √((40π)² + 4²).
    let tp = read(&format!(
        "{HEADER}4 L X+10 Y+0 Z+0 F600\n5 CC X+0 Y+0\n6 CP IPA+720 IZ-4 DR+\n"
    ));
    assert!(close(
        tp.points.last().unwrap().p,
        v(10.0, 0.0, -4.0),
        1e-12
    ));
    let want = ((40.0 * PI).powi(2) + 16.0).sqrt();
    assert!(
        (length(&tp.points) - want).abs() < 1e-2,
        "{}",
        length(&tp.points)
    );
    // A lead-in arc as a CAM post writes it (`CC Y Z`, `CP IPA+90 DR+`): from (Y, Z) =
    // (−58.6, −0.3) about (−57.4, −0.3), +90° about +X ends at (−57.4, −1.5), tangent to the
    // line that follows along +Y.
    let tp = read(&format!(
        "{HEADER}4 L X+1.2 Y-58.6 Z-0.3 F600\n5 CC Y-57.4 Z-0.3\n6 CP IPA+90 DR+\n\
         7 L Y-56.2 Z-1.5\n"
    ));
    let end = tp.points.iter().rfind(|p| p.line == 7).unwrap().p;
    assert!(close(end, v(1.2, -57.4, -1.5), 1e-9), "{end:?}");
    // …and `CC X Z` with DR+ turns from Z to X (positive about +Y).
    let tp = read(&format!(
        "{HEADER}4 L X+93.175 Y-14 Z+3.1 F600\n5 CC X+92.575 Z+3.1\n6 CP IPA+90 DR+\n"
    ));
    assert!(close(
        tp.points.last().unwrap().p,
        v(92.575, -14.0, 2.5),
        1e-9
    ));
    // Against its DR: an error.
    let e = fails(&format!(
        "{HEADER}4 L X+10 Y+0 Z+0 F600\n5 CC X+0 Y+0\n6 CP IPA+90 DR-\n"
    ));
    assert!(e.contains(":7:"), "{e}");
}

/// hyperMILL's post for a DMU 100 P duoblock (round 28) writes the feed joined to the
/// direction: `CP IPA+90 IZ-0.5 DR+FQ1`. It was refused ("the direction is DR+ or DR-");
/// a direction is its sign alone, so what follows is the next word: DR+ and F Q1.
#[test]
fn a_word_joined_to_the_arc_direction_is_the_next_word() {
    let joined = format!(
        "{HEADER}4 FN 0: Q1=1200\n5 L X+10 Y+0 Z+0 F600\n6 CC X+0 Y+0\n\
         7 CP IPA+90 IZ-0.5 DR+FQ1\n8 L X-5 F300\n"
    );
    let spaced = joined.replace("DR+FQ1", "DR+ FQ1");
    let (a, b) = (read(&joined), read(&spaced));
    assert_eq!(a.points.len(), b.points.len());
    for (p, q) in a.points.iter().zip(&b.points) {
        assert!(close(p.p, q.p, 1e-12), "{:?} {:?}", p.p, q.p);
        assert_eq!(p.feed, q.feed);
    }
    // The arc turns +90° about Z from (10, 0) to (0, 10), at Q1 = 1200 mm/min, 0.5 down.
    let arc_end = a.points.iter().rfind(|p| p.line == 8).unwrap();
    assert!(
        close(arc_end.p, v(0.0, 10.0, -0.5), 1e-9),
        "{:?}",
        arc_end.p
    );
    assert_eq!(arc_end.feed, Feed::Programmed(20.0));
    assert_eq!(a.points.last().unwrap().feed, Feed::Programmed(5.0));
    // A word that starts with a character of several bytes is no direction and no panic
    // (the fuzzer's `\u{fffd}FMAX` found the first version of this split slicing inside one).
    let e = fails(&format!("{HEADER}4 L X+10 Y+0 Z+0 \u{fffd}FMAX\n"));
    assert!(e.contains("unexpected word"), "{e}");
    // A sign followed by a digit is still no direction.
    let e = fails(&format!(
        "{HEADER}4 L X+10 Y+0 Z+0 F600\n5 CC X+0 Y+0\n6 CP IPA+90 DR+5\n"
    ));
    assert!(e.contains("the direction is DR+ or DR-"), "{e}");
}

#[test]
fn ln_tool_vectors_under_m128_on_a_five_axis_machine() {
    let m = common::machine(
        r#"{"name": "hh", "kinematics": {"type": "head_head", "tool_length": 200},
            "axes": {"X": {"velocity": 400, "acceleration": 2000},
                     "Y": {"velocity": 400, "acceleration": 2000},
                     "Z": {"velocity": 400, "acceleration": 2000},
                     "C": {"velocity": 120, "acceleration": 600},
                     "A": {"velocity": 60, "acceleration": 400}},
            "feed": {"max": 150}}"#,
    );
    let refs = feedopt::machine::References::default();
    let ctx = MachineContext::new(&m, &refs);
    let text = format!(
        "{HEADER}4 M128\n5 LN X+0 Y+0 Z+10 NX+0 NY+0 NZ+1 TX+0 TY+0 TZ+1 FMAX\n\
         6 LN X+10 Y+0 Z+10 NX+0 NY+0 NZ+1 TX+0 TY-0.5 TZ+0.8660254 F1200\n\
         7 LN X+20 Y+0 Z+10 TX+0 TY-1 TZ+1\n8 M129\n9 END PGM T MM\n"
    );
    let tp = parse_for(
        Path::new("t.h"),
        &text,
        Dialect::Heidenhain.spec(),
        Some(&ctx),
    )
    .unwrap();
    assert_eq!(tp.points.len(), 3);
    assert!(close(tp.points[1].o, v(0.0, -0.5, 0.866_025_4), 1e-7));
    // Normalised: (0, −1, 1)/√2.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert!(close(tp.points[2].o, v(0.0, -h, h), 1e-12));
    assert!(tp.points.iter().all(|p| p.rotary.is_none()));
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    let sol = optimize(&m, &tp, &Options::default()).unwrap();
    assert!(sol.verification.verified);
    // An A/B word for an axis the machine lacks is an error naming it.
    let e = parse_for(
        Path::new("t.h"),
        &format!("{HEADER}4 M128\n5 L X+0 B+10 FMAX\n"),
        Dialect::Heidenhain.spec(),
        Some(&ctx),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains(":6:") && e.contains("no B axis"), "{e}");
}

#[test]
fn plane_spatial_turns_about_the_shifted_datum() {
    // Datum shift X+10, then SPB+90: p = (10, 0, 0) + Ry(90°)·p'; the tool along Ry(90°)·Z =
    // +X.
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+50 FMAX\n5 CYCL DEF 7.0 DATUM SHIFT\n6 CYCL DEF 7.1 X+10\n\
         7 CYCL DEF 7.2 Y+0\n8 PLANE SPATIAL SPA+0 SPB+90 SPC+0 TURN FMAX\n\
         9 L X+0 Y+0 Z+5 FMAX\n10 L X+2 Y+3 Z+5 F600\n11 PLANE RESET TURN FMAX\n\
         12 L X+0 Y+0 Z+50 FMAX\n"
    ));
    // Point 1: the tool turned where it stood (a reorientation), then the moves.
    assert_eq!(tp.points[1].p, v(0.0, 0.0, 50.0));
    assert!(close(tp.points[1].o, v(1.0, 0.0, 0.0), 1e-12));
    assert!(
        close(tp.points[2].p, v(15.0, 0.0, 0.0), 1e-12),
        "{:?}",
        tp.points[2].p
    );
    // (2, 3, 5) tilted: Ry(90°)·(2, 3, 5) = (5, 3, −2), plus the shift.
    assert!(
        close(tp.points[3].p, v(15.0, 3.0, -2.0), 1e-12),
        "{:?}",
        tp.points[3].p
    );
    // PLANE RESET TURN: the tool back to +Z, in place; the shift stays.
    assert!(close(tp.points[4].p, v(15.0, 3.0, -2.0), 1e-12));
    assert!(close(tp.points[4].o, v(0.0, 0.0, 1.0), 1e-12));
    assert!(close(tp.points[5].p, v(10.0, 0.0, 50.0), 1e-12));
    // SPA+90 SPC+180 (as hyperMILL writes for "A-90 C0"): the tool along
    // Rz(180°)·Rx(90°)·Z = +Y; STAY keeps the tool upright until the rotary axes move.
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+50 A+0 C+0 FMAX\n5 PLANE SPATIAL SPA90 SPB0 SPC180 STAY SEQ- TABLE ROT\n\
         6 L X+1 Y+0 Z+50 FMAX\n7 L A+Q120 C+Q122 R0 FMAX M126\n8 L X+1 Y+0 Z+10 FMAX\n"
    ));
    assert!(
        close(tp.points[1].o, v(0.0, 0.0, 1.0), 1e-12),
        "STAY: not turned yet"
    );
    assert!(close(tp.points[2].o, v(0.0, 1.0, 0.0), 1e-12));
    assert_eq!(
        tp.points[1].p, tp.points[2].p,
        "positioning the rotary axes moves no tip"
    );
    // (1, 0, 10) in the tilted plane: Rz(180°)·Rx(90°)·(1, 0, 10) = (−1, 10, 0).
    assert!(
        close(tp.points[3].p, v(-1.0, 10.0, 0.0), 1e-12),
        "{:?}",
        tp.points[3].p
    );
    // A shift while the plane is tilted, and PLANE AXIAL: errors naming the line.
    let e = fails(&format!(
        "{HEADER}4 PLANE SPATIAL SPA+0 SPB+30 SPC+0 STAY\n5 CYCL DEF 7.0 DATUM SHIFT\n\
         6 CYCL DEF 7.1 X+5\n7 L X+0 Y+0 Z+0 FMAX\n"
    ));
    assert!(
        e.contains(":8:") && e.contains("line 7") && e.contains("before PLANE"),
        "{e}"
    );
    // A shift reset to 0 axis by axis under the plane, as posts write it, is fine.
    read(&format!(
        "{HEADER}4 CYCL DEF 7.0 DATUM SHIFT\n5 CYCL DEF 7.1 X+5\n6 CYCL DEF 7.2 Y+5\n\
         7 PLANE SPATIAL SPA+0 SPB+30 SPC+0 TURN\n8 L X+0 Y+0 Z+0 FMAX\n\
         9 CYCL DEF 7.0 DATUM SHIFT\n10 CYCL DEF 7.1 X+0\n11 CYCL DEF 7.2 Y+0\n\
         12 PLANE RESET TURN\n13 L X+0 Y+0 Z+10 FMAX\n"
    ));
    let e = fails(&format!("{HEADER}4 PLANE AXIAL B+30 TURN FMAX\n"));
    assert!(e.contains(":5:") && e.contains("PLANE AXIAL"), "{e}");
}

/// A cycle 200 of hand-computed moves: surface 0, clearance 2, depth −10 in infeeds of 4,
/// feed 120 mm/min, dwell 0.5 s at the top and 1.5 s at the depth, 2nd clearance 20.
const DRILL_NEW: &str = "5 CYCL DEF 200 DRILLING ~\n  Q200=+2 ;SET-UP CLEARANCE ~\n\
                         Q201=-10 ;DEPTH ~\n  Q206=+120 ;FEED RATE FOR PLNGNG ~\n\
                         Q202=+4 ;PLUNGING DEPTH ~\n  Q210=+0.5 ;DWELL TIME AT TOP ~\n\
                         Q203=+0 ;SURFACE COORDINATE ~\n  Q204=+20 ;2ND SET-UP CLEARANCE ~\n\
                         Q211=+1.5 ;DWELL TIME AT DEPTH\n";
const DRILL_OLD: &str = "5 CYCL DEF 200 DRILLING\n  Q200=2 ;SET-UP CLEARANCE\n\
                         Q201=-10 ;DEPTH\n  Q206=120 ;FEED RATE FOR PLUNGING\n\
                         Q202=4 ;PLUNGING DEPTH\n  Q210=0.5 ;DWELL TIME AT TOP\n\
                         Q203=0 ;SURFACE COORDINATE\n  Q204=20 ;2ND SET-UP CLEARANCE\n\
                         Q211=1.5 ;DWELL TIME AT DEPTH\n";

#[test]
fn cycle_200_expands_into_its_moves_and_dwells() {
    for def in [DRILL_NEW, DRILL_OLD] {
        let tp = read(&format!(
            "{HEADER}4 L X+10 Y+10 Z+50 R0 FMAX\n{def}20 CYCL CALL\n21 L X+30 Y+10 FMAX M99\n"
        ));
        // Z: rapid to 2; feed to −4; rapid to 2, dwell; rapid to −2; feed to −8; rapid to 2,
        // dwell; rapid to −6; feed to −10; dwell 1.5; rapid to 0 + max(2, 20).
        let hole = [2.0, -4.0, 2.0, -2.0, -8.0, 2.0, -6.0, -10.0, 20.0];
        let z: Vec<f64> = tp.points[1..10].iter().map(|p| p.p.z).collect();
        assert_eq!(z, hole, "{def}");
        let feeds: Vec<bool> = tp.points[1..10]
            .iter()
            .map(|p| p.feed == Feed::Programmed(2.0))
            .collect();
        assert_eq!(
            feeds,
            [false, true, false, false, true, false, false, true, false]
        );
        // M99 after the move: the same hole at X 30.
        assert_eq!(tp.points[10].p, v(30.0, 10.0, 20.0));
        let z2: Vec<f64> = tp.points[11..].iter().map(|p| p.p.z).collect();
        assert_eq!(z2, hole);
        // Per hole: 6 + 6 + 4 mm at 2 mm/s and 0.5 + 0.5 + 1.5 s of dwell.
        assert!(
            (feed_time(&tp) - 2.0 * 8.0).abs() < 1e-9,
            "{}",
            feed_time(&tp)
        );
        assert!(
            (tp.dwell_time() - 2.0 * 2.5).abs() < 1e-12,
            "{:?}",
            tp.dwells
        );
    }
}

#[test]
fn cycle_call_pat_drills_every_pattern_point() {
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+50 R0 FMAX\n{DRILL_NEW}20 PATTERN DEF ~\n  POS1 (X+10 Y+10 Z+0) ~\n\
         POS2 (X+20 IY+5 Z-1)\n21 CYCL CALL PAT FMAX M13\n"
    ));
    let bottoms: Vec<Vector3<f64>> = tp
        .points
        .iter()
        .filter(|p| p.feed == Feed::Programmed(2.0) && (p.p.z == -10.0 || p.p.z == -11.0))
        .map(|p| p.p)
        .collect();
    assert_eq!(bottoms, [v(10.0, 10.0, -10.0), v(20.0, 15.0, -11.0)]);
    // Between the points, at the 2nd set-up clearance of the first (0 + 20).
    assert!(tp.points.iter().any(|p| p.p == v(20.0, 15.0, 20.0)));
}

#[test]
fn cycle_203_with_chip_breaking_and_207_tapping() {
    // 203: infeeds 4, 3, 3 (decrement 1, minimum 3) to −10; one chip break (retract 0.5 at
    // rapid) before every full retract (at Q208 = 600 mm/min).
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+10 R0 FMAX\n5 CYCL DEF 203 UNIVERSAL DRILLING ~\n Q200=+2 ~\n\
         Q201=-10 ~\n Q206=+120 ~\n Q202=+4 ~\n Q210=+0 ~\n Q203=+0 ~\n Q204=+5 ~\n Q212=+1 ~\n\
         Q213=+1 ~\n Q205=+3 ~\n Q211=+0 ~\n Q208=+600 ~\n Q256=+0.5\n6 CYCL CALL\n"
    ));
    let z: Vec<f64> = tp.points[1..].iter().map(|p| p.p.z).collect();
    assert_eq!(z, [2.0, -4.0, -3.5, -7.0, 2.0, -5.0, -10.0, 2.0, 5.0]);
    assert_eq!(
        tp.points[5].feed,
        Feed::Programmed(10.0),
        "full retract at Q208"
    );
    // 207: feed = pitch 1.5 × S 1000 = 1500 mm/min in and out.
    let tp = read(
        "0 BEGIN PGM T MM\n1 TOOL CALL 3 Z S1000\n2 L X+0 Y+0 Z+10 R0 FMAX\n\
         3 CYCL DEF 207 RIGID TAPPING NEW~\n Q200=3 ;SET-UP CLEARANCE~\n Q201=-12 ;DEPTH~\n\
         Q239=+1.5 ;THREAD PITCH~\n Q203=0 ;SURFACE COORDINATE~\n Q204=5 ;2ND SET-UP CLEARANCE\n\
         4 L X+0 Y+0 R0 F MAX M99\n",
    );
    // (The positioning block moves nothing: the tool is there already.)
    let z: Vec<(f64, Feed)> = tp.points[2..].iter().map(|p| (p.p.z, p.feed)).collect();
    assert_eq!(
        z,
        [
            (3.0, Feed::Rapid),
            (-12.0, Feed::Programmed(25.0)),
            (3.0, Feed::Programmed(25.0)),
            (5.0, Feed::Rapid)
        ]
    );
    // A cycle feedopt cannot expand: defined with a warning, called with an error.
    let e = fails(&format!(
        "{HEADER}4 L X+0 Y+0 Z+10 FMAX\n5 CYCL DEF 204 BACK BORING~\n Q200=3~\n\
         Q249=+5\n6 L X+0 Y+0 FMAX M99\n"
    ));
    assert!(e.contains(":9:") && e.contains("cycle 204"), "{e}");
}

#[test]
fn labels_repeat_sections_and_call_subprograms() {
    let tp = read(
        "0 BEGIN PGM R MM\n1 L X+0 Y+0 Z+0 F100\n2 LBL 1\n3 L IX+10\n4 CALL LBL 1 REP 2/2\n\
         5 L Y+5\n6 CALL LBL \"Down\"\n7 L X+0\n8 M30\n9 LBL \"Down\"\n10 L IZ-1\n11 LBL 0\n\
         12 END PGM R MM\n",
    );
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    // The section runs once, then twice more (REP 2); the subprogram once, then back.
    assert_eq!(
        p,
        [
            v(0.0, 0.0, 0.0),
            v(10.0, 0.0, 0.0),
            v(20.0, 0.0, 0.0),
            v(30.0, 0.0, 0.0),
            v(30.0, 5.0, 0.0),
            v(30.0, 5.0, -1.0),
            v(0.0, 5.0, -1.0),
        ]
    );
    assert_eq!(tp.points[5].line, 11, "the subprogram's own line");
    // FN 9–12 jumps with Q parameters: a counted loop of three.
    let tp = read(
        "0 BEGIN PGM R MM\n1 L X+0 Y+0 Z+0 F100\n2 FN 0: Q1 = +0\n3 LBL 2\n4 L IX+1\n\
         5 FN 1: Q1 = +Q1 + +1\n6 FN 12: IF +Q1 LT +3 GOTO LBL 2\n7 END PGM R MM\n",
    );
    assert_eq!(tp.points.last().map(|p| p.p), Some(v(3.0, 0.0, 0.0)));
    assert_eq!(tp.points.len(), 4);
    // A loop that never ends is an error, not a hang (at its second pass: nothing changed);
    // so is a call of a missing label.
    let e =
        fails("0 BEGIN PGM R MM\n1 L X+0 Y+0 Z+0 F100\n2 LBL 3\n3 FN 9: IF +0 EQU +0 GOTO LBL 3\n");
    assert!(e.contains("t.h:4:") && e.contains("for ever"), "{e}");
    let e = fails("0 BEGIN PGM R MM\n1 L X+0 Y+0 Z+0 F100\n2 CALL LBL 9\n");
    assert!(e.contains(":3:") && e.contains("LBL 9"), "{e}");
}

/// Fuzz case 6471 of gcode-heidenhain (seed 2), cut down: `LBL 2` moved before an `FN 9 …
/// GOTO LBL 2` whose condition stays true, with a 720° helix in every pass. Bounded only by
/// the 1,000,000 blocks a program may run, it made about 19 million CL points (2 GB) before
/// its error, past the fuzz time bound of 5 s. Now the second pass, in the same state as the
/// first, is the error: the jump's line, its label and what to do.
#[test]
fn a_jump_loop_through_a_helix_ends_in_an_error_naming_the_jump() {
    let e = fails(
        "0 BEGIN PGM F MM\n1 L X+0 Y+0 Z+5 R0 FMAX\n2 LBL 2\n3 CC X+10 Y+0\n\
         4 CP IPA+720 IZ-2 DR+ F600\n5 FN 0: Q1 = +3\n6 FN 9: IF +Q1 EQU +3 GOTO LBL 2\n\
         7 END PGM F MM\n",
    );
    assert!(
        e.contains("t.h:7:")
            && e.contains("`FN 9: IF +Q1 EQU +3 GOTO LBL 2`")
            && e.contains("LBL 2 (line 3) for ever")
            && e.contains("a counter"),
        "{e}"
    );
}

/// A loop that does end, but after more passes than a toolpath holds: a counter to 100,000
/// around a helix of 720° (445 chords), 45 million CL points. The arc that would pass
/// `toolpath::MAX_POINTS` is refused before its chords are made, with its line.
#[test]
fn a_counted_loop_past_the_point_limit_is_an_error_before_the_points() {
    let e = fails(
        "0 BEGIN PGM F MM\n1 L X+0 Y+0 Z+5 R0 FMAX\n2 FN 0: Q1 = +0\n3 CC X+10 Y+0\n\
         4 LBL 2\n5 CP IPA+720 IZ-0.1 DR+ F500\n6 FN 1: Q1 = +Q1 + +1\n\
         7 FN 12: IF +Q1 LT +100000 GOTO LBL 2\n8 END PGM F MM\n",
    );
    assert!(
        e.contains("t.h:6:")
            && e.contains(&format!("more than the {}", toolpath::MAX_POINTS))
            && e.contains("check the jumps and repeat counts"),
        "{e}"
    );
}

#[test]
fn detected_by_extension_h_and_by_content() {
    let opts = ReadOptions::default();
    let body = "L X+0 Y+0 Z+0 FMAX\nL X+10 F100\n";
    let d = toolpath::detect(Path::new("part.H"), body, &opts).unwrap();
    assert_eq!(
        (d.format, d.dialect, d.dialect_by),
        (Format::Gcode, Some(Dialect::Heidenhain), "extension")
    );
    let text = format!("; a comment first\n0  BEGIN PGM part MM\n1 {body}");
    for name in ["part.nc", "part.txt", "part.prg"] {
        let d = toolpath::detect(Path::new(name), &text, &opts).unwrap();
        assert_eq!(d.format, Format::Gcode, "{name}");
        assert_eq!(
            (d.dialect, d.dialect_by),
            (Some(Dialect::Heidenhain), "content"),
            "{name}"
        );
    }
    // Read from a file with the defaults.
    let dir = std::env::temp_dir().join(format!("feedopt-heidenhain-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("part.h");
    std::fs::write(
        &file,
        format!("{HEADER}4 L X+0 Y+0 Z+0 FMAX\n5 L X+10 F100\n6 END PGM T MM\n"),
    )
    .unwrap();
    let tp = toolpath::read(&file).unwrap();
    assert_eq!(tp.points.len(), 2);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        "heidenhain".parse::<Dialect>().unwrap(),
        Dialect::Heidenhain
    );
}

#[test]
fn an_unknown_word_is_an_error_naming_line_and_word() {
    let e = fails(&format!(
        "{HEADER}4 L X+0 Y+0 Z+0 FMAX\n5 L X+10 FOO+3 F100\n"
    ));
    assert!(e.contains(":6:") && e.contains("FOO+3"), "{e}");
    let e = fails(&format!("{HEADER}4 X+10\n"));
    assert!(e.contains(":5:") && e.contains("path function"), "{e}");
    // A rounding after an arc is not modelled (between two L moves it is, below).
    let e = fails(&format!(
        "{HEADER}4 L X+0 Y+0 Z+0 F100\n5 CC X+10 Y+0\n6 C X+20 Y+0 DR+\n7 RND R2\n8 L Y+10\n"
    ));
    assert!(e.contains(":8:") && e.contains("RND R2"), "{e}");
    let e = fails(&format!(
        "{HEADER}4 L X+0 Y+0 Z+0 F100\n5 APPR LT X+10 Y+0 LEN5 RL\n"
    ));
    assert!(e.contains(":6:") && e.contains("APPR"), "{e}");
    let e = fails(&format!("{HEADER}4 L X+Q7 Y+0 Z+0 F100\n"));
    assert!(e.contains(":5:") && e.contains("Q7"), "{e}");
    // Paraxial compensation lengthens the move by the tool radius: not the path as written.
    let e = fails(&format!("{HEADER}4 L X+0 Y+0 Z+0 F100\n5 L X+10 R+ F100\n"));
    assert!(e.contains(":6:") && e.contains("R+"), "{e}");
}

#[test]
fn m140_mb_max_retracts_to_the_z_travel_limit() {
    let m = common::machine(
        r#"{"name": "xyz", "kinematics": {"type": "xyz"},
            "axes": {"X": {"velocity": 400, "acceleration": 2000},
                     "Y": {"velocity": 400, "acceleration": 2000},
                     "Z": {"velocity": 400, "acceleration": 2000, "min": -400, "max": 120}}}"#,
    );
    let ctx = MachineContext::new(&m, &feedopt::machine::References::default());
    let text =
        format!("{HEADER}4 L X+5 Y+5 Z+2 FMAX\n5 L M140 MB MAX\n6 L X+10 Y+0 FMAX\n7 M140 MB 20\n");
    let tp = parse_for(
        Path::new("t.h"),
        &text,
        Dialect::Heidenhain.spec(),
        Some(&ctx),
    )
    .unwrap();
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    assert_eq!(
        p,
        [
            v(5.0, 5.0, 2.0),
            v(5.0, 5.0, 120.0),
            v(10.0, 0.0, 120.0),
            v(10.0, 0.0, 140.0)
        ]
    );
    // Without the travel: an error naming the field to add.
    let e = parse(Path::new("t.h"), &text, Dialect::Heidenhain)
        .unwrap_err()
        .to_string();
    assert!(e.contains(":6:") && e.contains("axes.Z"), "{e}");
}

/// Every Klartext construct the reader knows, in one program (also a seed of the fuzzers).
const EVERYTHING: &str = include_str!("common/everything.h");

#[test]
fn a_program_with_every_construct_reads() {
    let tp = read(EVERYTHING);
    // Cycle 9's 1.5 s in the subprogram; cycle 200 has no dwells.
    assert!((tp.dwell_time() - 1.5).abs() < 1e-12, "{:?}", tp.dwells);
    // The section repeat: LBL 1 … CALL LBL 1 REP 3 moves +1 in X four times.
    let repeat: Vec<&ClPoint> = tp.points.iter().filter(|p| p.line == 36).collect();
    assert_eq!(repeat.len(), 4);
    assert!(tp.points.len() > 100);
}

/// hyperMILL's TNC posts go to the tool-change height with `L Z+0 R0 FMAX M92`: Z relative to
/// the machine builder's datum. With the datum in the machine file (`axes.Z.m92`, machine
/// coordinates), the move ends there; without it, at machine zero (M91's), with a warning that
/// names the field. Only X, Y and Z have one.
#[test]
fn m92_moves_relative_to_the_builders_datum_from_the_machine_file() {
    let json = r#"{"name": "xyz", "kinematics": {"type": "xyz"},
        "axes": {"X": {"velocity": 400, "acceleration": 2000, "m92": -250},
                 "Y": {"velocity": 400, "acceleration": 2000},
                 "Z": {"velocity": 400, "acceleration": 2000, "m92": 180.5}}}"#;
    let m = common::machine(json);
    let refs = feedopt::machine::references_from_json(Path::new("m.json"), json, &m).unwrap();
    let ctx = MachineContext::new(&m, &refs);
    let text = format!(
        "{HEADER}4 L X+5 Y+5 Z+2 FMAX\n5 L Z+0 R0 FMAX M92\n6 L X+10 Y+3 R0 FMAX M92\n\
         7 L X+20 Y+20 FMAX\n"
    );
    let tp = parse_for(
        Path::new("t.h"),
        &text,
        Dialect::Heidenhain.spec(),
        Some(&ctx),
    )
    .unwrap();
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    assert_eq!(
        p,
        [
            v(5.0, 5.0, 2.0),
            v(5.0, 5.0, 180.5),
            // X from its datum; Y has none: machine zero.
            v(-240.0, 3.0, 180.5),
            v(20.0, 20.0, 180.5)
        ]
    );
    let notes: Vec<&str> = tp.warnings.iter().map(|w| &*w.message).collect();
    assert!(notes.iter().any(|w| w.contains("axes.Y.m92")), "{notes:?}");
    assert!(
        !notes
            .iter()
            .any(|w| w.contains("axes.Z.m92") || w.contains("axes.X.m92"))
    );
    // Only X, Y and Z have an M92 datum.
    let bad = r#"{"name": "hh", "kinematics": {"type": "head_head", "tool_length": 100},
        "axes": {"X": {"velocity": 400, "acceleration": 2000},
                 "Y": {"velocity": 400, "acceleration": 2000},
                 "Z": {"velocity": 400, "acceleration": 2000},
                 "C": {"velocity": 400, "acceleration": 2000, "m92": 0},
                 "A": {"velocity": 400, "acceleration": 2000}}}"#;
    let m = feedopt::machine::Machine::from_json(Path::new("m.json"), bad).unwrap();
    let e = feedopt::machine::references_from_json(Path::new("m.json"), bad, &m)
        .unwrap_err()
        .to_string();
    assert!(e.contains("axes.C.m92"), "{e}");
}

/// The block-skip switch: off by default, so a `/` block runs (hyperMILL's `/80 M30` ends the
/// program before its subprograms); `--block-delete` (on) skips it, and the program runs on
/// into them. Either way each such block is a warning.
#[test]
fn block_delete_runs_slash_blocks_unless_the_switch_is_on() {
    let text = format!(
        "{HEADER}4 L X+5 Y+5 Z+2 FMAX\n5 CALL LBL 1\n/6 M30\n7 LBL 1\n8 L X+50 F600\n9 LBL 0\n\
         10 END PGM T MM\n"
    );
    let read = |block_delete: bool| {
        let settings = feedopt::toolpath::gcode::Settings {
            block_delete,
            ..Default::default()
        };
        feedopt::toolpath::gcode::parse_configured(
            Path::new("t.h"),
            &text,
            Dialect::Heidenhain.spec(),
            None,
            &settings,
        )
        .unwrap()
        .0
    };
    let run = read(false);
    // LBL 1 once (called), then M30.
    let x: Vec<f64> = run.points.iter().map(|p| p.p.x).collect();
    assert_eq!(x, [5.0, 50.0]);
    assert!(
        run.warnings
            .iter()
            .any(|w| w.line == 7 && w.message.contains("block run"))
    );
    let skipped = read(true);
    // M30 skipped: the label's body runs again, as the control runs through it.
    let x: Vec<f64> = skipped.points.iter().map(|p| p.p.x).collect();
    assert_eq!(x, [5.0, 50.0, 50.0]);
    assert!(
        skipped
            .warnings
            .iter()
            .any(|w| w.line == 7 && w.message.contains("block skipped"))
    );
    // Outside Klartext a skip level may follow the mark: `/2 G1 X10`.
    let g = "G21 G90 G17\nG0 X0. Y0. Z5.\nF600.\n/2 G1 X10.\nG1 Y10.\nM30\n";
    for (block_delete, want) in [(false, vec![0.0, 10.0, 10.0]), (true, vec![0.0, 0.0])] {
        let settings = feedopt::toolpath::gcode::Settings {
            block_delete,
            ..Default::default()
        };
        let (tp, _) = feedopt::toolpath::gcode::parse_configured(
            Path::new("t.ngc"),
            g,
            Dialect::Fanuc.spec(),
            None,
            &settings,
        )
        .unwrap();
        let x: Vec<f64> = tp.points.iter().map(|p| p.p.x).collect();
        assert_eq!(x, want, "block delete {block_delete}");
    }
}

/// A post that writes the cycle number against `DEF` and its decimal part apart
/// (`CYCL DEF9 .0 VARAKOZASI IDO`, `CYCL DEF9.1 V.IDO5`: a Hungarian TNC's dwell time) defines
/// the same cycle as `CYCL DEF 9.0 DWELL TIME` / `9.1 DWELL 5`.
#[test]
fn cycle_def_with_the_number_against_def_and_a_localised_dwell() {
    let text = format!(
        "{HEADER}4 L X+5 Y+5 Z+2 FMAX\n5 CYCL DEF9 .0 VARAKOZASI IDO\n6 CYCL DEF9.1 V.IDO5\n\
         7 L X+10 F600\n8 CYCL DEF 9 .1 DWELL 1.5\n"
    );
    let tp = read(&text);
    assert!((tp.dwell_time() - 6.5).abs() < 1e-12, "{:?}", tp.dwells);
    // `FN0: Q1 = 25` (hand-typed, the number against FN) is `FN 0: Q1 = 25`.
    let tp = read(&format!(
        "{HEADER}4 FN0: Q1 = 25\n5 FN2: Q2 = Q1 - 5\n6 L X+0 Y+0 Z+2 FMAX\n7 L X+Q2 F600\n"
    ));
    assert_eq!(tp.points.last().unwrap().p, v(20.0, 0.0, 2.0));
}

/// Cycle 208 (bore milling) on a 10 mm hole with a 6 mm tool: a helix of radius 2 mm from the
/// set-up clearance (Z 2) down to −10 at 2 mm a turn (6 turns), a full circle there, back to
/// the centre, up at rapid. Its feed length against the closed form; with Q335 equal to the
/// tool's diameter a straight plunge; without the tool's diameter an error saying where to
/// give it.
#[test]
fn cycle_208_mills_a_helix_of_the_hole_radius_minus_the_tool_radius() {
    let def = |nominal: f64| {
        format!(
            "{HEADER}4 L X+30 Y+40 Z+50 R0 FMAX\n5 CYCL DEF 208 BORE MILLING~\n  Q200=2 ;SET-UP \
             CLEARANCE~\n  Q201=-10 ;DEPTH~\n  Q206=600 ;FEED~\n  Q334=2 ;PLUNGING DEPTH~\n  \
             Q203=0 ;SURFACE~\n  Q204=20 ;2ND SET-UP CLEARANCE~\n  Q335={nominal} ;NOMINAL \
             DIAMETER~\n  Q342=0 ;ROUGHING DIAMETER~\n  Q351=+1 ;CLIMB OR UP-CUT\n\
             6 L X+30 Y+40 R0 FMAX M99\n"
        )
    };
    let read = |text: &str, tool: Option<f64>| {
        let settings = feedopt::toolpath::gcode::Settings {
            tool_diameter: tool,
            ..Default::default()
        };
        feedopt::toolpath::gcode::parse_configured(
            Path::new("t.h"),
            text,
            Dialect::Heidenhain.spec(),
            None,
            &settings,
        )
        .map(|(tp, _)| tp)
    };
    let tp = read(&def(10.0), Some(6.0)).unwrap();
    let (r, turns, drop) = (2.0, 6.0, 12.0);
    let helix = ((turns * 2.0 * PI * r).powi(2) + drop * drop).sqrt();
    let want = r + helix + 2.0 * PI * r + r;
    let fed: f64 = tp
        .points
        .windows(2)
        .filter(|w| w[1].feed == Feed::Programmed(10.0))
        .map(|w| (w[1].p - w[0].p).norm())
        .sum();
    // Chords within 1 µm of a 2 mm circle are shorter by at most e/(3r) = 1.7e-4 relative.
    assert!(
        fed <= want + 1e-9 && want - fed <= 1e-3 / (3.0 * r) * want,
        "fed {fed}, closed form {want}"
    );
    // Every helix point on the circle of radius 2 about the hole, Z falling; then up to 20.
    for p in tp
        .points
        .iter()
        .filter(|p| p.feed == Feed::Programmed(10.0))
    {
        let d = (p.p.x - 30.0).hypot(p.p.y - 40.0);
        assert!((d - 2.0).abs() < 1e-9 || d < 1e-9, "{:?}", p.p);
    }
    assert_eq!(tp.points.last().unwrap().p, v(30.0, 40.0, 20.0));
    // Climb milling with M3: counter-clockwise (the first helix point turns towards +Y).
    let first = tp
        .points
        .iter()
        .position(|p| p.p.z < 2.0 && p.feed == Feed::Programmed(10.0))
        .unwrap();
    assert!(tp.points[first].p.y > 40.0);
    // The tool as wide as the hole: straight down and up.
    let tp = read(&def(6.0), Some(6.0)).unwrap();
    assert!(tp.points.iter().all(|p| p.p.x == 30.0 && p.p.y == 40.0));
    assert!(tp.points.iter().any(|p| p.p.z == -10.0));
    // No tool diameter: the error says where to give it.
    let e = read(&def(10.0), None).unwrap_err().to_string();
    assert!(e.contains(":16:") && e.contains("--tool-diameter"), "{e}");
}

/// Inch Klartext is refused with a message that says so, for `INCH` and for NX's `IN` (which
/// read as a program without its unit before).
#[test]
fn inch_programs_are_refused_as_inch() {
    for unit in ["INCH", "IN"] {
        let e = fails(&format!(
            "0 BEGIN PGM PART {unit}\n1 L X+1 FMAX\n2 END PGM PART {unit}\n"
        ));
        assert!(
            e.contains(&format!("BEGIN PGM … {unit}")) && e.contains("inch Klartext"),
            "{e}"
        );
    }
    let e = fails("0 BEGIN PGM PART\n1 L X+1 FMAX\n2 END PGM PART\n");
    assert!(e.contains("without its unit"), "{e}");
}

/// Cycle 200 with its parameters spaced about `=` in three ways, one a line (`~`), at `L`
/// line 5 and `CYCL DEF` line 6 (the parameters on lines 7–14); `{bad}` replaces Q206's
/// value and `{tail}` follows Q204's.
fn spaced_drill(bad: &str, tail: &str) -> String {
    format!(
        "{HEADER}4 L X+0 Y+0 Z+10 R0 FMAX\n5 CYCL DEF 200 DRILLING ~\n  Q200 = +2 ;SET-UP ~\n\
         Q201= -10 ;DEPTH ~\n  Q206 ={bad} ;FEED ~\n  Q202=+4 ~\n  Q210=+0 ~\n  Q203=+0 ~\n\
         Q204=+20 {tail};2ND SET-UP CLEARANCE ~\n  Q211=+0\n6 CYCL CALL\n"
    )
}

/// Parameters of a `CYCL DEF` as posts space them (`Q200 = +2`, `Q201= -10`, `Q206 =+120`)
/// are read, and an error in a parameter of a `CYCL DEF` written on several lines names the
/// line of that parameter, not the `CYCL DEF`'s: a value that is no number, and a word after
/// the parameters that is none (it could change what the cycle does).
#[test]
fn cycle_parameters_spaced_about_equals_and_errors_at_their_own_line() {
    let tp = read(&spaced_drill("+120", ""));
    let z: Vec<f64> = tp.points[1..].iter().map(|p| p.p.z).collect();
    assert_eq!(z, [2.0, -4.0, 2.0, -2.0, -8.0, 2.0, -6.0, -10.0, 20.0]);
    assert!(feed_time(&tp) > 0.0 && (feed_time(&tp) - 16.0 / 2.0).abs() < 1e-9);
    let e = fails(&spaced_drill("FOO", ""));
    assert!(e.contains("t.h:9:") && e.contains("`Q206 =FOO`"), "{e}");
    let e = fails(&spaced_drill("+120", "BAR "));
    assert!(e.contains("t.h:13:") && e.contains("`BAR`"), "{e}");
    // A `~` inside a line continues nothing: a word like `BAR`, on its own line (the fuzz
    // campaign's `Q206=100 ~ M14` was counted as a line break and named the line after).
    let e = fails(&spaced_drill("+120", "~ M14 "));
    assert!(e.contains("t.h:13:") && e.contains("`~`"), "{e}");
    let e = fails(&spaced_drill("", ""));
    assert!(e.contains("t.h:9:") && e.contains("no value"), "{e}");
}

/// Cycle 203 as Fusion's Heidenhain post writes it (polymech_m7s_sides.h): `Q208= MAX`, the
/// retraction feed at FMAX, as the TNC 640 stores it.
const FUSION_203: &str = "0 BEGIN PGM Q208 MM\n1 TOOL CALL 4 Z S2911\n2 L X+0 Y+0 Z+15 R0 FMAX\n\
    3 CYCL DEF 203 UNIVERSAL DRILLING ~\n    Q200=+5 ;SET-UP CLEARANCE ~\n\
    Q201=-33 ;DEPTH ~\n    Q206=+437 ;FEED RATE FOR PLNGNG ~\n    Q202=+10 ;PLUNGING DEPTH ~\n\
    Q210=+0 ;DWELL TIME AT TOP ~\n    Q203=+0 ;SURFACE COORDINATE ~\n\
    Q204=+5 ;2ND SET-UP CLEARANCE ~\n    Q212=+0 ;DECREMENT ~\n    Q213=+2 ;NR OF BREAKS ~\n\
    Q205=+10 ;MIN. PLUNGING DEPTH ~\n    Q211=+0 ;DWELL TIME AT DEPTH ~\n\
    Q208= MAX ;RETRACTION FEED RATE ~\n    Q256=+1 ;DIST FOR CHIP BRKNG\n\
    4 L X+10 FMAX M99\n5 END PGM Q208 MM\n";

/// Feed parameters as the TNC 640 stores FMAX and FAUTO: `Q208=MAX` (Fusion: `Q208= MAX`)
/// retracts at rapid; `Q206=AUTO` (or `FAUTO`, here on a line of its own as older programs
/// write parameters) plunges at the `TOOL CALL`'s F. FMAX for the plunging feed, a word in a
/// parameter that is not a feed, AUTO without a `TOOL CALL` F and an expression that reads such
/// a parameter are errors.
#[test]
fn feed_parameters_max_and_auto_are_rapid_and_the_tool_calls_feed() {
    let tp = read(FUSION_203);
    // Over the hole at Z 15; rapid to 5; 10 mm infeeds with two chip breaks (up 1 mm at
    // rapid), then the full retract at Q208 = FMAX, back to 5 above the depth, the last 3 mm,
    // out at FMAX.
    let moves: Vec<(f64, bool)> = tp.points[2..]
        .iter()
        .map(|p| (p.p.z, p.feed == Feed::Rapid))
        .collect();
    assert_eq!(
        moves,
        [
            (5.0, true),
            (-10.0, false),
            (-9.0, true),
            (-20.0, false),
            (-19.0, true),
            (-30.0, false),
            (5.0, true),
            (-25.0, true),
            (-33.0, false),
            (5.0, true)
        ]
    );
    assert!(
        tp.points[2..]
            .iter()
            .all(|p| p.feed == Feed::Rapid || p.feed == Feed::Programmed(437.0 / 60.0))
    );
    // Q206 = AUTO, FAUTO: the TOOL CALL's F (300 mm/min = 5 mm/s).
    for auto in ["AUTO", "FAUTO"] {
        let drill = DRILL_OLD.replace("Q206=120", &format!("Q206={auto}"));
        let tp = read(&format!(
            "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S5000 F300\n4 L X+10 Y+10 Z+50 R0 FMAX\n{drill}\
             20 CYCL CALL\n"
        ));
        assert!(
            tp.points.iter().any(|p| p.feed == Feed::Programmed(5.0)),
            "{auto}: {:?}",
            tp.points
        );
        assert!((feed_time(&tp) - 16.0 / 5.0).abs() < 1e-9, "{auto}");
    }
    let e = fails(&FUSION_203.replace("Q206=+437", "Q206=MAX"));
    // Read when the cycle is called (line 18), naming its definition.
    assert!(
        e.contains(":18:") && e.contains("Q206 = MAX") && e.contains("CYCL DEF at line 4"),
        "{e}"
    );
    let e = fails(&FUSION_203.replace("Q201=-33", "Q201=MAX"));
    assert!(
        e.contains("Q201 = MAX") && e.contains("feed parameter"),
        "{e}"
    );
    let e = fails(&FUSION_203.replace("Q206=+437", "Q206=AUTO"));
    assert!(
        e.contains("Q206 = AUTO") && e.contains("no TOOL CALL gave F"),
        "{e}"
    );
    let e = fails(&FUSION_203.replace("4 L X+10 FMAX M99", "4 L X+10 Z+Q208 FMAX"));
    assert!(
        e.contains(":18:") && e.contains("`Q208` holds `MAX`"),
        "{e}"
    );
}

/// Cycles active on definition that move nothing, as hyperMILL writes them at every tool
/// (332 TUNING, 392 ATC), are skipped without a warning: the cycle a later `M99` runs is the
/// machining cycle defined before them, and a call with none before is an error, as is a call of
/// a cycle feedopt cannot expand. A pattern cycle (220, 221), which drills when it is defined,
/// is an error at its definition.
#[test]
fn cycles_active_on_definition_that_move_nothing_are_skipped() {
    const TUNING: &str = "CYCL DEF 332 TUNING ~\n     Q395=+3 ; TUNING MODE\n";
    const ATC: &str = "CYCL DEF 392 ATC~\n  Q240=0 ;TUNING MODE~\n  Q241=1 ;WEIGHT MODE\n";
    let tp = read(&format!(
        "0 BEGIN PGM C332 MM\n1 TOOL CALL 1 Z S1000\n2 {TUNING}3 {ATC}4 L X+0 Y+0 Z+10 R0 FMAX\n\
         5 L X+100 F600\n6 END PGM C332 MM\n"
    ));
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    assert_eq!(length(&tp.points), 100.0);
    // Drilled at X 10 and, after both, at X 30 by the same cycle 200.
    let tp = read(&format!(
        "{HEADER}4 L X+10 Y+10 Z+50 R0 FMAX\n{DRILL_NEW}20 CYCL CALL\n21 {TUNING}22 {ATC}\
         23 L X+30 Y+10 FMAX M99\n"
    ));
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    let bottoms: Vec<Vector3<f64>> = tp
        .points
        .iter()
        .filter(|p| p.p.z == -10.0)
        .map(|p| p.p)
        .collect();
    assert_eq!(bottoms, [v(10.0, 10.0, -10.0), v(30.0, 10.0, -10.0)]);
    let e = fails(&format!("{HEADER}4 {TUNING}5 L X+0 Y+0 Z+10 R0 FMAX M99\n"));
    assert!(e.contains(":7:") && e.contains("without a CYCL DEF"), "{e}");
    let e = fails(&format!(
        "{HEADER}4 L X+0 Y+0 Z+10 FMAX\n5 CYCL DEF 204 BACK BORING~\n\
         Q200=3~\n Q249=+5\n6 {TUNING}7 L X+0 Y+0 FMAX M99\n"
    ));
    assert!(e.contains(":11:") && e.contains("cycle 204"), "{e}");
    for (n, name) in [(220, "POLAR PATTERN"), (221, "CARTESIAN PATTERN")] {
        let e = fails(&format!(
            "{HEADER}4 L X+0 Y+0 Z+10 FMAX\n{DRILL_NEW}6 CYCL DEF {n} {name} ~\n  Q216=+50 ~\n\
             Q217=+50\n7 L Z+100 FMAX\n"
        ));
        assert!(
            e.contains(":15:")
                && e.contains(&format!("CYCL DEF {n}"))
                && e.contains("when it is defined"),
            "{e}"
        );
    }
}

/// Q395 (depth reference) is a parameter of cycles 200 and 203 only: one that an earlier
/// definition left at 1 does not stop a later rigid tapping cycle 207, which has none.
#[test]
fn q395_concerns_cycles_200_and_203_only() {
    let tp = read(
        "0 BEGIN PGM T MM\n1 TOOL CALL 3 Z S1000\n2 L X+0 Y+0 Z+10 R0 FMAX\n\
         3 CYCL DEF 200 DRILLING~\n Q200=2~\n Q201=-5~\n Q206=100~\n Q202=5~\n Q203=0~\n\
         Q204=5~\n Q395=+1 ;DEPTH REFERENCE\n\
         4 CYCL DEF 207 RIGID TAPPING NEW~\n Q200=3~\n Q201=-12~\n Q239=+1.5~\n Q203=0~\n\
         Q204=5\n5 L X+0 Y+0 R0 FMAX M99\n",
    );
    assert!(tp.points.iter().any(|p| p.p.z == -12.0));
    // 200 itself still refuses it.
    let e = fails(
        "0 BEGIN PGM T MM\n1 TOOL CALL 3 Z S1000\n2 L X+0 Y+0 Z+10 R0 FMAX\n\
         3 CYCL DEF 200 DRILLING~\n Q200=2~\n Q201=-5~\n Q206=100~\n Q202=5~\n Q203=0~\n\
         Q204=5~\n Q395=+1 ;DEPTH REFERENCE\n4 CYCL CALL\n",
    );
    assert!(e.contains("Q395 = 1") && e.contains("point angle"), "{e}");
}

/// A program's contour tolerance (`CYCL DEF 32.1 T0.075`, as hyperMILL posts it) moves
/// nothing and is said once, with the option that applies it; the path is unchanged.
#[test]
fn the_programs_contour_tolerance_is_said_with_the_option_that_applies_it() {
    let tp = read(
        "0 BEGIN PGM T MM\n1 CYCL DEF 32.0 TOLERANCE\n2 CYCL DEF 32.1 T0.075\n\
         3 L X+0 Y+0 Z+5 FMAX\n4 L X+10 F1000\n5 END PGM T MM\n",
    );
    assert_eq!(tp.points.last().map(|p| p.p.x), Some(10.0));
    let said: Vec<_> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("--corner-tolerance 0.075"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", tp.warnings);
    assert_eq!(said[0].line, 3);
}

/// The Z and feed (mm/s; `None`: rapid) of every point from `from` on, at X Y `at`.
fn z_feeds(tp: &Toolpath, from: usize) -> Vec<(f64, Option<f64>)> {
    tp.points[from..]
        .iter()
        .map(|p| {
            let f = match p.feed {
                Feed::Programmed(f) => Some(f),
                _ => None,
            };
            (p.p.z, f)
        })
        .collect()
}

fn warned(tp: &Toolpath, text: &str) -> bool {
    tp.warnings.iter().any(|w| w.message.contains(text))
}

/// Cycle 201 (reaming) at X 10 Y 20: surface 0, set-up clearance 2, depth −15, plunging
/// 120 mm/min, dwell 0.5 s, retraction 600 mm/min, 2nd set-up clearance 20; by `M99` at two
/// holes. Retraction feed 0 is the plunging feed, `MAX` rapid; a missing Q206 an error at the
/// call naming the parameter.
#[test]
fn cycle_201_reams_in_and_out_at_its_two_feeds() {
    let program = |q208: &str| {
        format!(
            "0 BEGIN PGM R MM\n1 TOOL CALL 1 Z S1000\n2 L X+10 Y+20 Z+50 R0 FMAX\n\
             3 CYCL DEF 201 REAMING~\n Q200=2 ;SET-UP CLEARANCE~\n Q201=-15 ;DEPTH~\n\
             Q206=120 ;FEED RATE FOR PLNGNG~\n Q211=0.5 ;DWELL TIME AT DEPTH~\n\
             Q208={q208} ;RETRACTION FEED RATE~\n Q203=+0 ;SURFACE COORDINATE~\n\
             Q204=20 ;2ND SET-UP CLEARANCE\n4 L X+10 Y+20 R0 FMAX M99\n5 L X+40 FMAX M99\n"
        )
    };
    let tp = read(&program("600"));
    // Down at 2 mm/s, 0.5 s at the depth, up at 10 mm/s to the set-up clearance, rapid to 20.
    let hole = [
        (2.0, None),
        (-15.0, Some(2.0)),
        (2.0, Some(10.0)),
        (20.0, None),
    ];
    // (Point 1 is the block at line 3.)
    assert_eq!(tp.points[1].p, v(10.0, 20.0, 50.0));
    assert_eq!(z_feeds(&tp, 2)[..4], hole);
    assert!(
        tp.points[2..6]
            .iter()
            .all(|p| p.p.x == 10.0 && p.p.y == 20.0)
    );
    // The second hole at X 40, over from the 2nd set-up clearance.
    assert_eq!(tp.points[6].p, v(40.0, 20.0, 20.0));
    assert_eq!(z_feeds(&tp, 7), hole);
    // Per hole 17 mm at 2 mm/s and 17 mm at 10 mm/s, 0.5 s of dwell; 48 + 34 + 18 mm, and
    // 30 mm across.
    assert!(
        (feed_time(&tp) - 2.0 * (8.5 + 1.7)).abs() < 1e-9,
        "{}",
        feed_time(&tp)
    );
    assert!((tp.dwell_time() - 1.0).abs() < 1e-12);
    let holes = (48.0 + 34.0 + 18.0) + 30.0 + (18.0 + 34.0 + 18.0);
    assert!((length(&tp.points[1..]) - holes).abs() < 1e-9);
    // Q208 = 0: out at the plunging feed; Q208 = MAX: out at rapid.
    let tp = read(&program("0"));
    assert_eq!(z_feeds(&tp, 2)[2], (2.0, Some(2.0)));
    let tp = read(&program("MAX"));
    assert_eq!(z_feeds(&tp, 2)[2], (2.0, None));
    // Without Q206: an error at the call (line 12), naming Q206 and the definition.
    let e = fails(&program("600").replace("Q206=120 ;FEED RATE FOR PLNGNG~\n", ""));
    assert!(
        e.contains("t.h:11:") && e.contains("Q206 is not defined") && e.contains("line 4"),
        "{e}"
    );
}

/// Cycle 202 (boring) as 201, retracting at the plunging feed (Q208 = 0): at the depth the
/// tool moves 0.2 mm off the wall in the direction Q214 (3: +X, 2: −Y), feeds out there,
/// returns over the centre and rises to the 2nd set-up clearance. Q214 = 0 stays on the
/// axis; a direction that is none is an error.
#[test]
fn cycle_202_moves_off_the_wall_before_it_retracts() {
    let program = |q214: &str| {
        format!(
            "0 BEGIN PGM B MM\n1 TOOL CALL 1 Z S800\n2 L X+10 Y+20 Z+50 R0 FMAX\n\
             3 CYCL DEF 202 BORING~\n Q200=2 ;SET-UP CLEARANCE~\n Q201=-15 ;DEPTH~\n\
             Q206=120 ;FEED RATE FOR PLNGNG~\n Q211=0.5 ;DWELL TIME AT DEPTH~\n\
             Q208=0 ;RETRACTION FEED RATE~\n Q203=+0 ;SURFACE COORDINATE~\n\
             Q204=20 ;2ND SET-UP CLEARANCE~\n Q214={q214} ;DISENGAGING DIRECTN~\n\
             Q336=0 ;ANGLE OF SPINDLE\n4 L X+10 Y+20 R0 FMAX M99\n"
        )
    };
    let tp = read(&program("3"));
    let path: Vec<(Vector3<f64>, Feed)> = tp.points[2..].iter().map(|p| (p.p, p.feed)).collect();
    assert_eq!(
        path,
        [
            (v(10.0, 20.0, 2.0), Feed::Rapid),
            (v(10.0, 20.0, -15.0), Feed::Programmed(2.0)),
            (v(10.2, 20.0, -15.0), Feed::Rapid),
            (v(10.2, 20.0, 2.0), Feed::Programmed(2.0)),
            (v(10.0, 20.0, 2.0), Feed::Rapid),
            (v(10.0, 20.0, 20.0), Feed::Rapid),
        ]
    );
    assert!((tp.dwell_time() - 0.5).abs() < 1e-12);
    assert!((feed_time(&tp) - 17.0).abs() < 1e-9, "{}", feed_time(&tp));
    let hole = 48.0 + 17.0 + 0.2 + 17.0 + 0.2 + 18.0;
    assert!((length(&tp.points[1..]) - hole).abs() < 1e-9);
    assert!(warned(&tp, "cycle 202: the oriented spindle stop"));
    let tp = read(&program("2"));
    assert_eq!(tp.points[4].p, v(10.0, 19.8, -15.0));
    let tp = read(&program("0"));
    assert!(
        tp.points[1..]
            .iter()
            .all(|p| p.p.x == 10.0 && p.p.y == 20.0)
    );
    assert!((length(&tp.points[1..]) - 100.0).abs() < 1e-9);
    let e = fails(&program("5"));
    assert!(e.contains("t.h:14:") && e.contains("Q214 = 5"), "{e}");
}

/// Cycle 209 (tapping with chip breaking), S 500 and pitch 1.5: tapping at 750 mm/min
/// (12.5 mm/s), in steps of Q257 = 8 to −20, backing out Q256 = 2 pitches (3 mm) at Q403 = 2
/// times the feed (25 mm/s), out at that speed; with Q256 = 0 fully out to the set-up
/// clearance each time; called at two pattern points.
#[test]
fn cycle_209_taps_in_infeeds_and_backs_out_at_the_rpm_factor() {
    let program = |q256: &str, tail: &str| {
        format!(
            "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S500\n2 L X+0 Y+0 Z+50 R0 FMAX\n\
             3 CYCL DEF 209 TAPPING W/ CHIP BRKG~\n Q200=2 ;SET-UP CLEARANCE~\n\
             Q201=-20 ;DEPTH~\n Q239=+1.5 ;THREAD PITCH~\n Q203=+0 ;SURFACE COORDINATE~\n\
             Q204=10 ;2ND SET-UP CLEARANCE~\n Q257=8 ;DEPTH FOR CHIP BRKNG~\n\
             Q256={q256} ;DIST FOR CHIP BRKNG~\n Q336=0 ;ANGLE OF SPINDLE{tail}\n\
             4 L X+0 Y+0 R0 FMAX M99\n"
        )
    };
    let tp = read(&program("2", "~\n Q403=2 ;RPM FACTOR"));
    let (f, b) = (Some(12.5), Some(25.0));
    assert_eq!(
        z_feeds(&tp, 2),
        [
            (2.0, None),
            (-8.0, f),
            (-5.0, b),
            (-16.0, f),
            (-13.0, b),
            (-20.0, f),
            (2.0, b),
            (10.0, None)
        ]
    );
    // In: 10 + 11 + 7 mm at 12.5 mm/s; out: 3 + 3 + 22 mm at 25 mm/s.
    assert!((feed_time(&tp) - (28.0 / 12.5 + 28.0 / 25.0)).abs() < 1e-9);
    // Q256 = 0: out to the set-up clearance after each infeed; without Q403 out at the
    // tapping feed.
    let tp = read(&program("0", ""));
    assert_eq!(
        z_feeds(&tp, 2),
        [
            (2.0, None),
            (-8.0, f),
            (2.0, f),
            (-16.0, f),
            (2.0, f),
            (-20.0, f),
            (2.0, f),
            (10.0, None)
        ]
    );
    assert!((feed_time(&tp) - 100.0 / 12.5).abs() < 1e-9);
    // At every PATTERN DEF point: the same hole at X 10 and X 30.
    let pat = program("2", "").replace(
        "4 L X+0 Y+0 R0 FMAX M99\n",
        "4 PATTERN DEF ~\n POS1 (X+10 Y+0 Z+0) ~\n POS2 (X+30 Y+0 Z+0)\n5 CYCL CALL PAT\n",
    );
    let tp = read(&pat);
    let bottoms: Vec<Vector3<f64>> = tp
        .points
        .iter()
        .filter(|p| p.p.z == -20.0)
        .map(|p| p.p)
        .collect();
    assert_eq!(bottoms, [v(10.0, 0.0, -20.0), v(30.0, 0.0, -20.0)]);
    // Tapping needs the spindle speed.
    let e = fails(&program("2", "").replace("TOOL CALL 1 Z S500", "TOOL CALL 1 Z"));
    assert!(
        e.contains("t.h:13:") && e.contains("no TOOL CALL gave S"),
        "{e}"
    );
}

/// Cycle 241 (single-lip deep-hole drilling) as in the user's repro: from the set-up
/// clearance (2) at Q253 = 750 mm/min to Q200 above the deepened starting point Q379 = 7.5
/// (Z −5.5), drilling at 150 mm/min to −40, dwell 1 s, out at Q208 = 1000 mm/min, rapid to
/// the 2nd set-up clearance 50. With a dwell depth Q435 = 20 and Q401 = 50 %: a dwell at −20
/// and the rest at 75 mm/min. Q253 = MAX positions at rapid; a Q202 shorter than the depth
/// (several infeeds) is an error.
#[test]
fn cycle_241_prepositions_to_the_deepened_start_and_drills_at_its_feeds() {
    let program = |q253: &str, q435: &str, tail: &str| {
        format!(
            "0 BEGIN PGM C241 MM\n1 TOOL CALL 1 Z S1000\n2 L X+0 Y+0 Z+50 R0 FMAX\n\
             3 CYCL DEF 241 SINGLE-LIP D.H.DRLNG ~\n Q200=2 ;SET-UP CLEARANCE ~\n\
             Q201=-40 ;DEPTH ~\n Q206=150 ;FEED RATE FOR PLNGNG ~\n\
             Q211=1 ;DWELL TIME AT DEPTH ~\n Q203=+0 ;SURFACE COORDINATE ~\n\
             Q204=50 ;2ND SET-UP CLEARANCE ~\n Q379=7.5 ;STARTING POINT ~\n\
             Q253={q253} ;F PRE-POSITIONING ~\n Q208=1000 ;RETRACTION FEED RATE ~\n\
             Q426=3 ;DIR. OF SPINDLE ROT. ~\n Q427=1000 ;ROT.SPEED INFEED/OUT ~\n\
             Q428=1000 ;ROT. SPEED DRILLING ~\n Q429=8 ;COOLANT ON ~\n Q430=9 ;COOLANT OFF ~\n\
             Q435={q435} ;DWELL DEPTH{tail}\n4 L X+10 Y+10 R0 FMAX M99\n"
        )
    };
    let tp = read(&program("750", "0", ""));
    let out = 1000.0 / 60.0;
    assert_eq!(tp.points[1].p, v(10.0, 10.0, 50.0));
    assert_eq!(
        z_feeds(&tp, 2),
        [
            (2.0, None),
            (-5.5, Some(12.5)),
            (-40.0, Some(2.5)),
            (2.0, Some(out)),
            (50.0, None)
        ]
    );
    // 7.5 mm at 12.5 mm/s, 34.5 mm at 2.5 mm/s, 42 mm at 1000/60 mm/s; one 1 s dwell.
    let want = 0.6 + 13.8 + 42.0 / out;
    assert!((feed_time(&tp) - want).abs() < 1e-9, "{}", feed_time(&tp));
    assert!((tp.dwell_time() - 1.0).abs() < 1e-12);
    let moves = 48.0 + 42.0 + 42.0 + 48.0;
    assert!((length(&tp.points[1..]) - moves).abs() < 1e-9);
    assert!(warned(&tp, "Q426–Q428"));
    // Dwell depth 20 and feed factor 50 %.
    let tp = read(&program("750", "20", "~\n Q401=50 ;FEED FACTOR"));
    assert_eq!(
        z_feeds(&tp, 2),
        [
            (2.0, None),
            (-5.5, Some(12.5)),
            (-20.0, Some(2.5)),
            (-40.0, Some(1.25)),
            (2.0, Some(out)),
            (50.0, None)
        ]
    );
    assert!((tp.dwell_time() - 2.0).abs() < 1e-12);
    assert!((feed_time(&tp) - (0.6 + 5.8 + 16.0 + 42.0 / out)).abs() < 1e-9);
    // Q253 = MAX: to the deepened start at rapid.
    let tp = read(&program("MAX", "0", ""));
    assert_eq!(z_feeds(&tp, 2)[1], (-5.5, None));
    // Several infeeds (Q202 = 10 of 34.5 mm) are refused.
    let e = fails(&program("750", "0", "~\n Q202=10 ;MAX. PLUNGING DEPTH"));
    assert!(e.contains("t.h:21:") && e.contains("Q202"), "{e}");
}

/// Cycle 262 (thread milling) of an M10 × 1.5 thread, 9 mm deep, with a 6 mm tool about
/// (30, 40): the tool centre runs on a helix of radius R = (10 − 6)/2 = 2 mm at 1.5 mm a
/// turn, 9 / 1.5 = 6 turns. Right-hand and climb: upwards and counter-clockwise, from Q253
/// positioning down the axis to a quarter pitch below the depth, an approach half circle of
/// radius 1 rising 0.375 onto the circle, the helix from −9 to 0, the departure half circle
/// to the centre at 0.375, rapid up. Lengths in closed form; up-cut works downwards and
/// clockwise; Q355 = 0 is one turn at the depth; without the tool's diameter, or with a tool
/// as wide as the thread, an error.
#[test]
fn cycle_262_mills_the_thread_on_a_helix_with_approach_and_departure_arcs() {
    let program = |q351: &str, q355: &str| {
        format!(
            "0 BEGIN PGM TH MM\n1 TOOL CALL 5 Z S3000\n2 L X+30 Y+40 Z+50 R0 FMAX\n\
             3 CYCL DEF 262 THREAD MILLING~\n Q335=10 ;NOMINAL DIAMETER~\n\
             Q239=+1.5 ;THREAD PITCH~\n Q201=-9 ;THREAD DEPTH~\n\
             Q355={q355} ;THREADS PER STEP~\n Q253=300 ;F PRE-POSITIONING~\n\
             Q351={q351} ;CLIMB OR UP-CUT~\n Q200=2 ;SET-UP CLEARANCE~\n\
             Q203=+0 ;SURFACE COORDINATE~\n Q204=20 ;2ND SET-UP CLEARANCE~\n\
             Q207=600 ;FEED RATE MILLING\n4 L X+30 Y+40 R0 FMAX M99\n"
        )
    };
    let read = |text: &str, tool: Option<f64>| {
        let settings = feedopt::toolpath::gcode::Settings {
            tool_diameter: tool,
            ..Default::default()
        };
        feedopt::toolpath::gcode::parse_configured(
            Path::new("t.h"),
            text,
            Dialect::Heidenhain.spec(),
            None,
            &settings,
        )
        .map(|(tp, _)| tp)
    };
    let (r, p, depth) = (2.0, 1.5, 9.0);
    let turns = depth / p;
    let tp = read(&program("+1", "1"), Some(6.0)).unwrap();
    // Down the axis at 300 mm/min to −9 − 1.5/4.
    assert_eq!(tp.points[2].p, v(30.0, 40.0, 2.0));
    assert_eq!(tp.points[3].p, v(30.0, 40.0, -9.375));
    assert_eq!(tp.points[3].feed, Feed::Programmed(5.0));
    let milled: Vec<&ClPoint> = tp
        .points
        .iter()
        .filter(|p| p.feed == Feed::Programmed(10.0))
        .collect();
    // The helix: the points on the circle of radius 2 from the approach's end (32, 40, −9)
    // on; Z = −9 + 1.5 × (angle turned)/2π; 6 turns counter-clockwise to (32, 40, 0).
    let on_circle = |q: &ClPoint| ((q.p.x - 30.0).hypot(q.p.y - 40.0) - r).abs() < 1e-9;
    let start = milled.iter().position(|q| on_circle(q)).unwrap();
    let end = milled.iter().rposition(|q| on_circle(q)).unwrap();
    assert!(close(milled[start].p, v(32.0, 40.0, -9.0), 1e-9));
    assert!(close(milled[end].p, v(32.0, 40.0, 0.0), 1e-9));
    let mut angle = 0.0;
    let mut last = 0.0f64;
    for q in &milled[start..=end] {
        assert!(on_circle(q), "{:?}", q.p);
        let a = (q.p.y - 40.0).atan2(q.p.x - 30.0);
        let mut d = a - last;
        while d < -PI {
            d += 2.0 * PI;
        }
        while d > PI {
            d -= 2.0 * PI;
        }
        assert!(d >= 0.0, "counter-clockwise");
        angle += d;
        last = a;
        assert!(
            (q.p.z - (-9.0 + p * angle / (2.0 * PI))).abs() < 1e-9,
            "{:?}",
            q.p
        );
    }
    assert!((angle - turns * 2.0 * PI).abs() < 1e-9, "{angle}");
    // The approach and departure points lie on the half circles of radius 1 about (31, 40).
    for q in milled[..start].iter().chain(&milled[end + 1..]) {
        assert!(
            ((q.p.x - 31.0).hypot(q.p.y - 40.0) - 1.0).abs() < 1e-9,
            "{:?}",
            q.p
        );
    }
    assert!(close(milled.last().unwrap().p, v(30.0, 40.0, 0.375), 1e-9));
    // Milled length: helix √((6·2π·2)² + 9²) and two half circles √((π·1)² + 0.375²).
    let helix = ((turns * 2.0 * PI * r).powi(2) + depth * depth).sqrt();
    let arc = (PI.powi(2) + 0.375f64.powi(2)).sqrt();
    let want = helix + 2.0 * arc;
    let mut fed = vec![tp.points[3].clone()];
    fed.extend(milled.iter().map(|q| (*q).clone()));
    let got = length(&fed);
    // Chords within 1 µm of a 1 mm circle are shorter by at most e/(3r) = 3.4e-4 relative.
    assert!(
        got <= want + 1e-9 && want - got <= 3.4e-4 * want,
        "{got} vs {want}"
    );
    // Time at the feeds: 11.375 mm at 5 mm/s and the milled length at 10 mm/s.
    assert!((feed_time(&tp) - (11.375 / 5.0 + got / 10.0)).abs() < 1e-9);
    // Up, then to the 2nd set-up clearance.
    let n = tp.points.len();
    assert_eq!(tp.points[n - 2].p, v(30.0, 40.0, 2.0));
    assert_eq!(tp.points[n - 1].p, v(30.0, 40.0, 20.0));
    assert!(warned(&tp, "half circles"));
    // Up-cut: from the surface down, clockwise; the positioning stops a quarter pitch above.
    let tp = read(&program("-1", "1"), Some(6.0)).unwrap();
    assert_eq!(tp.points[3].p, v(30.0, 40.0, 0.375));
    let first = tp
        .points
        .iter()
        .position(|q| q.feed == Feed::Programmed(10.0))
        .unwrap();
    assert!(tp.points[first].p.y > 40.0, "clockwise approach passes +Y");
    let zs: Vec<f64> = tp.points.iter().map(|q| q.p.z).collect();
    assert!(zs.iter().any(|z| *z == -9.0) && zs.iter().all(|z| *z >= -9.375));
    // Q355 = 0: one turn at the depth, from −9 to −7.5.
    let tp = read(&program("+1", "0"), Some(6.0)).unwrap();
    let top = tp
        .points
        .iter()
        .filter(|q| q.feed == Feed::Programmed(10.0))
        .map(|q| q.p.z)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!((top - (-7.5 + 0.375)).abs() < 1e-9, "{top}");
    // The tool's diameter is needed, and must be less than the thread's.
    let e = read(&program("+1", "1"), None).unwrap_err().to_string();
    assert!(
        e.contains("t.h:15:") && e.contains("--tool-diameter"),
        "{e}"
    );
    let e = read(&program("+1", "1"), Some(10.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("not narrower"), "{e}");
}

/// Mastercam's Heidenhain post (MPPOSTABILITY_AVIA_VMC_800_4X, round 8's n091.h) wraps a long
/// comment with `~`: the next line is the rest of the comment (a file path here), not a block.
/// A structure comment continued so is comment too; a cycle's parameter lines, whose `~` ends
/// a parameter's comment, still continue the cycle.
#[test]
fn a_comment_block_continued_with_a_tilde_continues_as_comment() {
    let text = format!(
        "{HEADER}4 ;MCX FILE  -~\n Z:\\00NZL\\KR\\PART.MCX-9\n5 * - LONG ~\n X+500 Y+500\n\
         6 L X+10 Y+0 Z+0 F600\n7 L X+20\n8 END PGM T MM\n"
    );
    let tp = read(&text);
    let xs: Vec<f64> = tp.points.iter().map(|q| q.p.x).collect();
    assert!(xs.iter().all(|x| *x <= 20.0), "{xs:?}");
    assert!((length(&tp.points) - 10.0).abs() < 1e-9);
    // The cycle's lines still join (`~` after a parameter's comment).
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+50 R0 FMAX\n{DRILL_NEW}13 L X+10 Y+10 R0 FMAX M99\n14 END PGM T MM\n"
    ));
    assert!(tp.points.iter().any(|q| (q.p.z + 10.0).abs() < 1e-9));
}

/// A shop's TNC program (round 8, KOLEK-MOC-STR1.H) keeps its probing cycle under `/`: run
/// with the block-skip switch on. Read with the switch off, the refusal of `TCH PROBE` says
/// that the block is a block-delete one and that `--block-delete` skips it.
#[test]
fn an_error_in_a_block_delete_block_names_block_delete() {
    let text = format!(
        "{HEADER}/ 4 TCH PROBE 413 PKT.BAZ.OKRAG ZEWN. ~\n    Q321=+0 ;SRODEK ~\n    \
         Q322=+0 ;SRODEK\n5 L X+0 Y+0 Z+5 R0 FMAX\n6 END PGM T MM\n"
    );
    let e = fails(&text);
    assert!(
        e.contains("t.h:5:") && e.contains("TCH PROBE") && e.contains("--block-delete"),
        "{e}"
    );
    let e = fails(&format!(
        "{HEADER}4 TCH PROBE 413 ~\n    Q321=+0 ;X\n5 END PGM T MM\n"
    ));
    assert!(!e.contains("--block-delete"), "{e}");
}

/// A hand-written A/C table (A about X carrying C, as on a DMU 85 monoBLOCK), table centre at
/// the origin, A's travel `a_min`…`a_max`; slow X Y Z, so that the swing of the linear axes
/// while the table turns under a held tool tip (outside TCPM) differs between the two
/// solutions and shows in the time.
fn ac_table(a_min: f64, a_max: f64) -> (feedopt::machine::Machine, MachineContext) {
    ac_table_travel(&format!(r#", "min": {a_min}, "max": {a_max}"#))
}

/// [`ac_table`] with A's travel given as its JSON fields (`""`: unlimited).
fn ac_table_travel(a_travel: &str) -> (feedopt::machine::Machine, MachineContext) {
    let m = common::machine(&format!(
        r#"{{"name": "A/C table", "kinematics": {{"type": "table_table_ac",
              "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0,
              "y-offset": 0, "z-offset": 0, "conventional-directions": true}},
            "axes": {{"X": {{"velocity": 50, "acceleration": 500}},
                     "Y": {{"velocity": 50, "acceleration": 500}},
                     "Z": {{"velocity": 50, "acceleration": 500}},
                     "A": {{"velocity": 60, "acceleration": 600{a_travel}}},
                     "C": {{"velocity": 120, "acceleration": 1200}}}},
            "feed": {{"max": 500}}}}"#
    ));
    let ctx = MachineContext::new(&m, &feedopt::machine::References::default());
    (m, ctx)
}

fn read_on(ctx: &MachineContext, text: &str) -> Result<Toolpath, String> {
    parse_for(
        Path::new("t.h"),
        text,
        Dialect::Heidenhain.spec(),
        Some(ctx),
    )
    .map_err(|e| e.to_string())
}

/// The rotary angles (degrees, A and C) the kinematics gives every point.
fn ac_angles(m: &feedopt::machine::Machine, tp: &Toolpath) -> Vec<[f64; 2]> {
    feedopt::kinematics::Kinematics::new(m)
        .rotary_angles(&tp.points, &m.axes)
        .unwrap()
        .iter()
        .map(|a| a.map(f64::to_degrees))
        .collect()
}

/// `PLANE … SYM±` (TNC7) selects the solution whose master axis stands above (`SYM+`) or below
/// (`SYM-`) its symmetry point, the centre of its travel, where `SEQ±` takes the sign from 0
/// (TNC7 user's manual, "Tilting solution"). It used to be skipped, the kinematics choosing by
/// its own rule. The plane's tool axis +X needs A ±90°.
#[test]
fn plane_sym_picks_the_side_of_the_master_axis_travel_centre() {
    let program = |s: &str, spa: f64| {
        format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA{spa} SPB0 SPC90 STAY {s} TABLE ROT\n\
             6 L A+Q120 C+Q122 R0 FMAX M126\n7 L X+10 Y+20 Z+5 FMAX\n8 END PGM T MM\n"
        )
    };
    // A's travel −150…120°: the symmetry point is −15°. SYM+ takes A +90°, SYM− A −90°.
    let (m, ctx) = ac_table(-150.0, 120.0);
    for (s, a) in [("SYM+", 90.0), ("SYM-", -90.0)] {
        let tp = read_on(&ctx, &program(s, 90.0)).unwrap();
        // Where the positioning block leaves the axes (outside tool-tip mode the table
        // turns with X Y Z standing, through points along the way).
        let got = ac_angles(&m, &tp);
        let end = got.last().unwrap();
        assert!((end[0] - a).abs() < 1e-9, "{s}: {end:?}");
    }
    // A's travel −120…30°: the symmetry point is −45°. A plane tilted by 30° needs A ±30°:
    // SEQ− takes A −30° (below 0), but no solution lies below −45°, so SYM− is refused as the
    // control refuses it, naming the line and the symmetry point; SYM+ takes the one nearer
    // A 0 of the two above −45°.
    let (m2, ctx2) = ac_table(-120.0, 30.0);
    let tp = read_on(&ctx2, &program("SEQ-", 30.0)).unwrap();
    assert!((ac_angles(&m2, &tp).last().unwrap()[0] + 30.0).abs() < 1e-9);
    let e = read_on(&ctx2, &program("SYM-", 30.0)).unwrap_err();
    assert!(
        e.contains("t.h:6:") && e.contains("SYM-") && e.contains("below -45°"),
        "{e}"
    );
    let tp = read_on(&ctx2, &program("SYM+", 30.0)).unwrap();
    assert!((ac_angles(&m2, &tp).last().unwrap()[0].abs() - 30.0).abs() < 1e-9);
    // Without travel limits there is no symmetry point: an error saying so.
    let (_, ctx3) = ac_table_travel("");
    let e = read_on(&ctx3, &program("SYM+", 90.0)).unwrap_err();
    assert!(
        e.contains("t.h:6:") && e.contains("symmetry point of A") && e.contains("no travel"),
        "{e}"
    );
    // SEQ needs none.
    assert!(read_on(&ctx3, &program("SEQ+", 90.0)).is_ok());
}

/// `PLANE SPATIAL SPA90 SPB0 SPC90 STAY SEQ±` and `L A+Q120 C+Q122 M126`, as hyperMILL posts
/// for a DMU 85 monoBLOCK ("A-90 C270" in its comment for SEQ-): the tool axis is
/// Rz(90°)·Rx(90°)·Z = +X, which an A/C table reaches at A +90°, C +90° or at A −90°,
/// C 270°. SEQ+ takes the first (A, the master axis, positive), SEQ− the second; from C 0
/// under M126 C goes the shorter way, to −90°. Each reads, solves and times as the same
/// program with the positions written out (`L A-90 C+270` under the plane; the tilted plane's
/// point (10, 20, 5) is Rz(90°)·Rx(90°)·(10, 20, 5) = (5, 10, 20) of the workpiece); until
/// 2026-11-27 SEQ was skipped and SEQ− ran at A +90°, C +90°. Outside M128 the table turns
/// with X Y Z standing (at 40, 30, 50), carrying the tip with the part.
#[test]
fn plane_seq_picks_the_master_axis_sign() {
    let (m, ctx) = ac_table(-120.0, 120.0);
    let seq = |s: &str| {
        format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC90 STAY {s} TABLE ROT\n\
             6 L A+Q120 C+Q122 R0 FMAX M126\n7 L X+10 Y+20 Z+5 FMAX\n8 END PGM T MM\n"
        )
    };
    let explicit = |a: &str, c: &str| {
        format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC90 STAY TABLE ROT\n\
             6 L A{a} C{c} R0 FMAX M126\n7 L X+10 Y+20 Z+5 FMAX\n8 END PGM T MM\n"
        )
    };
    let time = |tp: &Toolpath| {
        let s = optimize(&m, tp, &Options::default()).unwrap();
        assert!(s.verification.verified);
        s.schedule.cycle_time
    };
    let mut times = Vec::new();
    for (s, a, c, want) in [
        ("SEQ-", "-90", "+270", [-90.0, -90.0]),
        ("SEQ+", "+90", "+90", [90.0, 90.0]),
    ] {
        let tp = read_on(&ctx, &seq(s)).unwrap();
        let n = tp.points.len();
        assert!(n > 3, "{s}");
        // The positioning block carries the control's positions (A, B, C), along the turn.
        assert_eq!(
            tp.points[n - 2].rotary,
            Some([want[0], 0.0, want[1]]),
            "{s}"
        );
        assert!(close(tp.points[n - 1].p, v(5.0, 10.0, 20.0), 1e-12), "{s}");
        assert!(close(tp.points[n - 1].o, v(1.0, 0.0, 0.0), 1e-12), "{s}");
        let got = ac_angles(&m, &tp);
        for k in n - 2..n {
            assert!(
                (got[k][0] - want[0]).abs() < 1e-9 && (got[k][1] - want[1]).abs() < 1e-9,
                "{s}: point {k} at A, C = {:?}, want {want:?}",
                got[k]
            );
        }
        let written = read_on(&ctx, &explicit(a, c)).unwrap();
        assert_eq!(written.points, tp.points, "{s}");
        let (t, tw) = (time(&tp), time(&written));
        assert!(
            (t - tw).abs() <= 1e-9 * tw,
            "{s}: {t} s, written out {tw} s"
        );
        times.push(t);
    }
    // The two solutions swing X Y Z differently here: the choice shows in the time.
    assert!(
        (times[0] - times[1]).abs() > 0.01 * times[1],
        "SEQ- {} s, SEQ+ {} s",
        times[0],
        times[1]
    );

    // PLANE … TURN SEQ-: the turn itself goes to A −90°, C −90°.
    let tp = read_on(
        &ctx,
        &format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC90 TURN SEQ- FMAX\n6 L X+10 Y+20 Z+5 FMAX\n"
        ),
    )
    .unwrap();
    let got = ac_angles(&m, &tp);
    assert!(
        got[1..]
            .iter()
            .all(|a| (a[0] + 90.0).abs() < 1e-9 && (a[1] + 90.0).abs() < 1e-9),
        "{got:?}"
    );

    // A's travel −10…120°: SEQ- asks for A −90°, outside it; the control refuses, and so does
    // the reader, naming the line and SEQ. SEQ+ runs at A +90°.
    let (m2, ctx2) = ac_table(-10.0, 120.0);
    let e = read_on(&ctx2, &seq("SEQ-")).unwrap_err();
    assert!(
        e.contains("t.h:6:") && e.contains("SEQ-") && e.contains("A negative"),
        "{e}"
    );
    assert!(e.contains("A [-10, 120]°"), "{e}");
    let tp = read_on(&ctx2, &seq("SEQ+")).unwrap();
    assert!((ac_angles(&m2, &tp).last().unwrap()[0] - 90.0).abs() < 1e-9);

    // Without SEQ the kinematics chooses, as before: the solution within travel (A −120…10°:
    // A −90°), or from A 0 the positive one.
    let no_seq = seq("");
    let (m3, ctx3) = ac_table(-120.0, 10.0);
    let tp = read_on(&ctx3, &no_seq).unwrap();
    assert!(tp.points.iter().all(|p| p.rotary.is_none() || p.line == 5));
    assert!((ac_angles(&m3, &tp)[2][0] + 90.0).abs() < 1e-9);
    let tp = read_on(&ctx, &no_seq).unwrap();
    assert!((ac_angles(&m, &tp)[2][0] - 90.0).abs() < 1e-9);

    // Tilt 0 (hyperMILL's `SPA0 SPB0 SPC0 … SEQ+`): one solution, nothing to choose.
    let tp = read_on(
        &ctx,
        &format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA0 SPB0 SPC0 STAY SEQ+ TABLE ROT\n\
             6 L A+Q120 C+Q122 R0 FMAX M126\n7 L X+10 Y+20 Z+5 FMAX\n"
        ),
    )
    .unwrap();
    assert!(ac_angles(&m, &tp).iter().all(|a| a == &[0.0, 0.0]));
    let tp = read(&format!(
        "{HEADER}4 L X+40 Y+30 Z+50 FMAX
5 PLANE SPATIAL SPA0 SPB0 SPC0 STAY SEQ+ TABLE ROT
\
             6 L A+Q120 C+Q122 R0 FMAX M126\n"
    ));
    assert!(
        tp.warnings.iter().all(|w| !w.message.contains("SEQ")),
        "{:?}",
        tp.warnings
    );
    // Read without a machine file the solution cannot be computed: a warning naming SEQ.
    let tp = read(&seq("SEQ-"));
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.line == 6 && w.message.contains("SEQ-")),
        "{:?}",
        tp.warnings
    );
    // A SEQ without its sign is an error.
    let e = read_on(&ctx, &seq("SEQ")).unwrap_err();
    assert!(e.contains("t.h:6:") && e.contains("SEQ+ or SEQ-"), "{e}");
}

/// `PLANE SPATIAL SPA90 SPB0 SPC90 STAY` and then the rotary axes positioned by the block's
/// own words, `L A-90 C+270 R0 FMAX M126`: STAY moves nothing, and the control moves the axes
/// where that block says, the tilted plane staying the plane's. Until 2026-11-27 the words
/// were dropped for the plane's tool vector and the kinematics ran A +90°, C +90° (2.4000 s
/// instead of 2.7817 s on this table). Now the block's points end at A −90°, C −90° (C 270°
/// the shorter way from 0), the next point continues there, and the program reads and times
/// as the same turn written before the plane: outside M128 the table turns with X Y Z
/// standing either way (at 40, 30, 50), carrying the tip with the part, and the plane's
/// point (10, 20, 5) is (5, 10, 20) of the workpiece. The two toolpaths have the same tips
/// and the same axis positions at every point, so the solves are the same problem and the
/// times agree to round-off.
#[test]
fn rotary_words_under_a_plane_are_programmed_positions() {
    let (m, ctx) = ac_table(-120.0, 120.0);
    let under_plane = |mode: &str, words: &str| {
        format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC90 {mode} TABLE ROT\n\
             6 L {words} R0 FMAX M126\n7 L X+10 Y+20 Z+5 FMAX\n8 END PGM T MM\n"
        )
    };
    let written = format!(
        "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n5 L A-90 C+270 R0 FMAX M126\n\
         6 PLANE SPATIAL SPA90 SPB0 SPC90 STAY TABLE ROT\n\
         7 L X+10 Y+20 Z+5 FMAX\n8 END PGM T MM\n"
    );
    let time = |tp: &Toolpath| {
        let s = optimize(&m, tp, &Options::default()).unwrap();
        assert!(s.verification.verified);
        s.schedule.cycle_time
    };
    let tp = read_on(&ctx, &under_plane("STAY", "A-90 C+270")).unwrap();
    let n = tp.points.len();
    assert!(n > 3);
    assert_eq!(tp.points[n - 2].line, 7);
    assert_eq!(tp.points[n - 2].rotary, Some([-90.0, 0.0, -90.0]));
    // The tip went with the table: X Y Z stand at (40, 30, 50), so the tip is
    // Rx(90°)·Rz(90°)·(40, 30, 50) … of the workpiece, as the kinematics gives.
    let pose = feedopt::kinematics::Kinematics::new(&m)
        .forward(&[40.0, 30.0, 50.0, -90.0, -90.0])
        .unwrap();
    assert!(close(tp.points[n - 2].p, pose.p, 1e-9));
    assert!(!close(tp.points[n - 2].p, v(40.0, 30.0, 50.0), 1.0));
    // A point under the plane without rotary words: the tool vector rules, as before.
    assert_eq!(tp.points[n - 1].rotary, None);
    assert!(close(tp.points[n - 1].p, v(5.0, 10.0, 20.0), 1e-12));
    assert!(close(tp.points[n - 1].o, v(1.0, 0.0, 0.0), 1e-12));
    let got = ac_angles(&m, &tp);
    assert!(
        got[n - 2..]
            .iter()
            .all(|a| (a[0] + 90.0).abs() < 1e-9 && (a[1] + 90.0).abs() < 1e-9),
        "{got:?}"
    );
    let w = read_on(&ctx, &written).unwrap();
    assert_eq!(w.points.len(), n);
    for (a, b) in w.points.iter().zip(&tp.points) {
        assert!(
            close(a.p, b.p, 1e-9) && close(a.o, b.o, 1e-9),
            "{a:?} {b:?}"
        );
    }
    for (a, b) in ac_angles(&m, &w).iter().zip(&got) {
        assert!(
            (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9,
            "{a:?} {b:?}"
        );
    }
    let (t, tw) = (time(&tp), time(&w));
    assert!((t - tw).abs() <= 1e-9 * tw, "{t} s, written out {tw} s");
    // The other solution (the kinematics' own choice from A 0) times differently here: the
    // words decide.
    let other = read_on(&ctx, &under_plane("STAY", "A+90 C+90")).unwrap();
    let k = other.points.len() - 2;
    assert_eq!(other.points[k].rotary, Some([90.0, 0.0, 90.0]));
    let to = time(&other);
    assert!((t - to).abs() > 0.01 * to, "A-90: {t} s, A+90: {to} s");

    // Words that contradict the plane's tool axis (+X): A −90°, C 0 puts the tool along +Y
    // of the workpiece (Rx(−90°)·Z, this table turning the part against its axes). The control would machine the part at that angle; an error naming
    // the line, the plane's line and both directions.
    let e = read_on(&ctx, &under_plane("STAY", "A-90 C+0")).unwrap_err();
    assert!(e.contains("t.h:7:") && e.contains("PLANE of line 6"), "{e}");
    assert!(e.contains("A = -90°, C = 0°"), "{e}");
    assert!(
        e.contains("along (0, 1, 0)") && e.contains("along (1, 0, 0)"),
        "{e}"
    );
    assert!(e.contains("90.0000° apart"), "{e}");
    // Off by less than the posts' rounding (A to 0.0001°): accepted.
    let tp = read_on(&ctx, &under_plane("STAY", "A-90.0001 C+270")).unwrap();
    let k = tp.points.len() - 2;
    assert_eq!(tp.points[k].rotary.map(|r| r[0]), Some(-90.0001));

    // PLANE … TURN without SEQ turns the axes to a solution the kinematics chooses; a block
    // that then positions them all is run where it says (C 270 without M126: as written)…
    let turn = |words: &str| {
        format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC90 TURN FMAX\n\
             6 L {words} R0 FMAX\n7 L X+10 Y+20 Z+5 FMAX\n8 END PGM T MM\n"
        )
    };
    let tp = read_on(&ctx, &turn("A-90 C+270")).unwrap();
    let got = ac_angles(&m, &tp);
    assert_eq!(tp.points.last().unwrap().rotary, None);
    assert!(
        (got[1][0] - 90.0).abs() < 1e-9 && (got[1][1] - 90.0).abs() < 1e-9,
        "the turn: {got:?}"
    );
    assert!(
        got[2..]
            .iter()
            .all(|a| (a[0] + 90.0).abs() < 1e-9 && (a[1] - 270.0).abs() < 1e-9),
        "{got:?}"
    );
    // … but one that positions C alone leaves A where the reader does not know it: an error.
    let e = read_on(&ctx, &turn("C+270")).unwrap_err();
    assert!(
        e.contains("t.h:7:") && e.contains("where A stands") && e.contains("SEQ+ or SEQ-"),
        "{e}"
    );
    // With SEQ- the reader knows the turn's positions (A −90°, C −90°): C alone is fine.
    let tp = read_on(
        &ctx,
        &format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC90 TURN SEQ- FMAX\n6 L C+270 R0 FMAX\n"
        ),
    )
    .unwrap();
    assert_eq!(tp.points.last().unwrap().rotary, Some([-90.0, 0.0, 270.0]));
    // So after `L A+Q120 C+Q122` to the positions of a STAY SEQ-, after a TURN that left them
    // unknown (M126 stays in force: C 270 the shorter way from −90°).
    let tp = read_on(
        &ctx,
        &format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC90 TURN FMAX\n\
             6 PLANE SPATIAL SPA90 SPB0 SPC90 STAY SEQ-\n\
             7 L A+Q120 C+Q122 R0 FMAX M126\n8 L C+270 R0 FMAX\n"
        ),
    )
    .unwrap();
    assert_eq!(tp.points.last().unwrap().rotary, Some([-90.0, 0.0, -90.0]));

    // Under tool-tip control (M128) the rotary axes orient the tool as they do without a
    // plane: run as programmed, no check against the plane.
    let tp = read_on(
        &ctx,
        &format!(
            "{HEADER}4 L X+40 Y+30 Z+50 A+0 C+0 FMAX\n5 FUNCTION TCPM F TCP AXIS POS\n\
             6 PLANE SPATIAL SPA90 SPB0 SPC90 STAY\n7 L A-90 C+0 R0 FMAX\n"
        ),
    )
    .unwrap();
    assert_eq!(tp.points.last().unwrap().rotary, Some([-90.0, 0.0, 0.0]));

    // Read without a machine file the check cannot be made: the words are run as
    // programmed, with one warning.
    let tp = read(&under_plane("STAY", "A-90 C+270"));
    assert_eq!(tp.points[1].rotary, Some([-90.0, 0.0, -90.0]));
    let said: Vec<_> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("under a PLANE"))
        .collect();
    assert!(said.len() == 1 && said[0].line == 7, "{:?}", tp.warnings);
}

/// Round 16: `RND R…` and `CHF …` between two straight moves were errors ("not supported");
/// they round or chamfer the corner as the G-code readers' `,R`/`RND=` and `,C`/`CHR=` now
/// do, an F in the block being the corner's own feed. Next to an arc, after FMAX, or with no
/// next move, still an error naming the block.
#[test]
fn rnd_and_chf_between_two_straight_moves_round_and_chamfer_the_corner() {
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+0 R0 F600\n5 L X+50\n6 RND R5\n7 L Y+50\n8 CHF 3\n\
         9 L X+0\n10 RND R2 F300\n11 L Y+0\n12 END PGM T MM\n"
    ));
    // 200 mm less 10 − 5π/2, 6 − 3√2 and 4 − π at the three corners (the roundings' chords a
    // little shorter).
    let want = 200.0 - (10.0 - 2.5 * PI) - (6.0 - 3.0 * 2f64.sqrt()) - (4.0 - PI);
    let got = length(&tp.points);
    assert!(got < want && got > want - 2e-3, "{got} vs {want}");
    let on =
        |line: usize| -> Vec<&ClPoint> { tp.points.iter().filter(|p| p.line == line).collect() };
    for p in &on(7) {
        assert!(
            ((p.p - v(45.0, 5.0, 0.0)).norm() - 5.0).abs() < 1e-9,
            "{:?}",
            p.p
        );
        assert_eq!(p.feed, Feed::Programmed(10.0));
    }
    let chf: Vec<Vector3<f64>> = on(9).iter().map(|p| p.p).collect();
    assert_eq!(chf, vec![v(50.0, 47.0, 0.0), v(47.0, 50.0, 0.0)]);
    // The rounding with F300 runs at it; the move after it at the contour's F600.
    for p in on(11).iter().skip(1) {
        assert_eq!(p.feed, Feed::Programmed(5.0));
    }
    assert_eq!(tp.points.last().unwrap().feed, Feed::Programmed(10.0));
    for (text, line, says) in [
        (
            "4 L X+0 Y+0 Z+0 FMAX\n5 L X+50 FMAX\n6 RND R5\n7 L Y+50 F600\n",
            7,
            "FMAX",
        ),
        (
            "4 L X+0 Y+0 Z+0 F600\n5 L X+50\n6 RND R5\n7 L Y+50 FMAX\n",
            7,
            "rapid",
        ),
        (
            "4 L X+0 Y+0 Z+0 F600\n5 L X+50\n6 RND R5\n7 END PGM T MM\n",
            7,
            "ends",
        ),
        (
            "4 L X+0 Y+0 Z+0 F600\n5 L X+50\n6 RND R60\n7 L Y+50\n",
            7,
            "too short",
        ),
        (
            "4 L X+0 Y+0 Z+0 F600\n5 L X+50\n6 CHF 0\n7 L Y+50\n",
            7,
            "side length",
        ),
    ] {
        let e = fails(&format!("{HEADER}{text}"));
        assert!(e.contains(&format!(":{line}:")) && e.contains(says), "{e}");
    }
}

/// Under a tilted plane X Y Z are the tip in the plane's coordinates, as the control reads
/// them: a move there is read as it runs, and the warning that X Y Z are "taken as the tool
/// tip" outside tool-tip mode said nothing that could change the path (round 17: it came with
/// every hyperMILL 3+2 program). A block that turns a rotary axis, read without kinematics,
/// still warns.
#[test]
fn moves_in_a_tilted_plane_draw_no_tool_tip_warning() {
    let (_, ctx) = ac_table(-150.0, 120.0);
    let tip = |tp: &Toolpath| {
        tp.warnings
            .iter()
            .filter(|w| w.message.contains("outside tool-tip (TCP) mode"))
            .count()
    };
    let tp = read_on(
        &ctx,
        &format!(
            "{HEADER}4 L X+0 Y+0 Z+50 A+0 C+0 FMAX\n\
             5 PLANE SPATIAL SPA90 SPB0 SPC180 STAY SEQ- TABLE ROT\n\
             6 L A+Q120 C+Q122 R0 FMAX M126\n7 L X+127 Y+7 R0 FMAX M3\n\
             8 L Z-5 F300\n9 L X+100 F600\n10 END PGM T MM\n"
        ),
    )
    .unwrap();
    assert_eq!(tip(&tp), 0, "{:?}", tp.warnings);
    // A move that turns A, read without the machine's kinematics: the warning stays.
    let tp = read(&format!(
        "{HEADER}4 L X+0 Y+0 Z+50 A+0 C+0 FMAX\n5 L X+10 A+30 F600\n6 END PGM T MM\n"
    ));
    assert_eq!(tip(&tp), 1, "{:?}", tp.warnings);
}

/// Activating a preset (cycle 247) resets cycle 7's datum shift: the TNC's cycle manuals
/// (cycle 247 PRESETTING, its notes: the control resets the datum shift, mirroring, rotation
/// and scaling when it activates a preset from the preset table). A Polish shop's program
/// (round 22, `fi104.H`) relies on it: `247`, `CYCL DEF 7.1 IX-60`, a bore; `247`, `CYCL DEF
/// 7.1 IX+60`, the other bore, at X+60. Keeping the shift put it at X0, quietly.
#[test]
fn presetting_again_resets_the_datum_shift() {
    let text = format!(
        "{HEADER}4 CYCL DEF 247 DATUM SETTING ~\n    Q339=+1    ;PRESET NUMBER\n\
         5 CYCL DEF 7.0 DATUM SHIFT\n6 CYCL DEF 7.1 IX-60\n7 L X+0 Y+0 Z+5 R0 FMAX\n\
         8 CYCL DEF 247 DATUM SETTING ~\n    Q339=+1    ;PRESET NUMBER\n\
         9 CYCL DEF 7.0 DATUM SHIFT\n10 CYCL DEF 7.1 IX+60\n11 L X+0 Y+0 Z+5 R0 FMAX\n"
    );
    let tp = read(&text);
    assert!(
        tp.points
            .iter()
            .any(|p| close(p.p, v(-60.0, 0.0, 5.0), 1e-9))
    );
    let last = tp.points.last().unwrap().p;
    assert!(close(last, v(60.0, 0.0, 5.0), 1e-9), "{last}");
}

/// `L Z 25.000 FMAX`: an APT post's Klartext (aamorim1913/AptPostProcessor
/// `tests/parts-tools/boss/12.h`, line 12) writes a blank between the address and its value.
/// The TNC's program format joins them (`L Z+25 FMAX`, as its editor stores a block); feedopt
/// refuses the block, and the message now says what is wrong and how to write it (it was "`Z`
/// has no value", which reads as if the value were missing).
#[test]
fn a_value_apart_from_its_address_is_named() {
    let m =
        fails("0 BEGIN PGM T MM\n1 L X+0 Y+0 Z+50 R0 FMAX\n2 L Z 25.000 FMAX\n3 END PGM T MM\n");
    assert!(m.contains(":3:"), "{m}");
    assert!(m.contains("`Z 25.000`") && m.contains("`Z+25.000`"), "{m}");
}
