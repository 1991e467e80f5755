//! Tests of the APT CL reader (`feedopt::toolpath::apt`).

use approx::assert_relative_eq;
use feedopt::error::Error;
use feedopt::toolpath::apt::{parse, read};
use feedopt::toolpath::{Feed, Toolpath};
use nalgebra::Vector3;
use std::path::Path;

fn ok(text: &str) -> Toolpath {
    match parse(Path::new("test.cls"), text) {
        Ok(tp) => tp,
        Err(e) => panic!("unexpected error: {e}\n--- input ---\n{text}"),
    }
}

/// Asserts a parse error at `line` whose message contains every one of `needles`
/// (case-insensitive).
fn err(text: &str, line: usize, needles: &[&str]) {
    match parse(Path::new("bad.cls"), text) {
        Ok(tp) => panic!("expected an error, got {} points\n{text}", tp.points.len()),
        Err(Error::Parse {
            file,
            line: got_line,
            message,
        }) => {
            assert_eq!(file, Path::new("bad.cls"));
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

fn feed_mm_s(feed: Feed) -> f64 {
    match feed {
        Feed::Programmed(f) => f,
        other => panic!("expected a programmed feed, got {other:?}"),
    }
}

#[test]
fn basic_goto_and_source() {
    let tp = ok("GOTO/1,2,3\nGOTO/4,5,6,0,0,1\n");
    assert_eq!(tp.source, Path::new("test.cls"));
    assert_eq!(tp.points.len(), 2);
    assert_eq!(tp.points[0].p, Vector3::new(1.0, 2.0, 3.0));
    assert_eq!(tp.points[0].o, Vector3::new(0.0, 0.0, 1.0));
    assert_eq!(tp.points[0].feed, Feed::Unspecified);
    assert_eq!(tp.points[0].line, 1);
    assert_eq!(tp.points[1].p, Vector3::new(4.0, 5.0, 6.0));
    assert_eq!(tp.points[1].line, 2);
}

#[test]
fn spaces_case_and_number_forms() {
    let tp = ok("  goto / 1.0, 2.0 ,3\nGoTo/1.,-.5,1.0E+01\nGOTO\t/\t+2 , 1e-1 , 1.5D+01 \n");
    assert_eq!(tp.points[0].p, Vector3::new(1.0, 2.0, 3.0));
    assert_eq!(tp.points[1].p, Vector3::new(1.0, -0.5, 10.0));
    assert_eq!(tp.points[2].p, Vector3::new(2.0, 0.1, 15.0));
}

#[test]
fn crlf_and_bom() {
    let tp = ok("\u{feff}FEDRAT/MMPM,60\r\nGOTO/1,2,3\r\n");
    assert_eq!(tp.points.len(), 1);
    assert_eq!(tp.points[0].p, Vector3::new(1.0, 2.0, 3.0));
    assert_relative_eq!(feed_mm_s(tp.points[0].feed), 1.0);
}

#[test]
fn fedrat_both_orders() {
    let tp = ok("FEDRAT/MMPM,250\nGOTO/0,0,0\nFEDRAT/ 300 , mmpm\nGOTO/1,0,0\nGOTO/2,0,0\n");
    assert_relative_eq!(feed_mm_s(tp.points[0].feed), 250.0 / 60.0);
    assert_relative_eq!(feed_mm_s(tp.points[1].feed), 5.0);
    assert_relative_eq!(feed_mm_s(tp.points[2].feed), 5.0, epsilon = 1e-12);
}

#[test]
fn fedrat_bare_number_uses_units() {
    let tp = ok("FEDRAT/120\nGOTO/0,0,0\nUNITS/INCHES\nFEDRAT/10\nGOTO/1,0,0\n");
    assert_relative_eq!(feed_mm_s(tp.points[0].feed), 2.0);
    assert_relative_eq!(feed_mm_s(tp.points[1].feed), 10.0 * 25.4 / 60.0);
}

#[test]
fn fedrat_ipm() {
    let tp = ok("FEDRAT/IPM,60\nGOTO/0,0,0\nFEDRAT/30,IPM\nGOTO/1,0,0\n");
    assert_relative_eq!(feed_mm_s(tp.points[0].feed), 25.4);
    assert_relative_eq!(feed_mm_s(tp.points[1].feed), 12.7);
}

#[test]
fn units_inches_scales_coordinates_not_vectors() {
    let tp = ok("GOTO/1,1,1\nUNITS/INCHES\nGOTO/1,2,3,0,0,2\nUNITS/MM\nGOTO/1,2,3\n");
    assert_eq!(tp.points[0].p, Vector3::new(1.0, 1.0, 1.0));
    assert_relative_eq!(tp.points[1].p, Vector3::new(25.4, 50.8, 76.2));
    assert_relative_eq!(tp.points[1].o, Vector3::new(0.0, 0.0, 1.0));
    assert_eq!(tp.points[2].p, Vector3::new(1.0, 2.0, 3.0));
    // MMPM stays mm/min under INCHES.
    let tp = ok("UNITS/INCHES\nFEDRAT/MMPM,600\nGOTO/0,0,0\n");
    assert_relative_eq!(feed_mm_s(tp.points[0].feed), 10.0);
}

#[test]
fn tool_vector_is_normalised() {
    let tp = ok("GOTO/0,0,0,0,3,4\nGOTO/0,0,0,1e-3,0,0\n");
    assert_relative_eq!(tp.points[0].o, Vector3::new(0.0, 0.6, 0.8), epsilon = 1e-15);
    assert_relative_eq!(tp.points[1].o, Vector3::new(1.0, 0.0, 0.0));
    for pt in &tp.points {
        assert_relative_eq!(pt.o.norm(), 1.0, epsilon = 1e-15);
    }
}

#[test]
fn multax_off_keeps_orientation() {
    let text = "MULTAX/ON\nGOTO/0,0,0,1,0,0\nMULTAX/OFF\nGOTO/1,0,0,0,1,0\nGOTO/2,0,0,0,0,0\n\
                GOTO/3,0,0\nMULTAX\nGOTO/4,0,0,0,1,0\nGOTO/5,0,0\n";
    let tp = ok(text);
    let x = Vector3::new(1.0, 0.0, 0.0);
    let y = Vector3::new(0.0, 1.0, 0.0);
    assert_eq!(tp.points[0].o, x);
    assert_eq!(tp.points[1].o, x, "i,j,k ignored under MULTAX/OFF");
    assert_eq!(tp.points[2].o, x, "zero i,j,k ignored under MULTAX/OFF");
    assert_eq!(tp.points[3].o, x);
    assert_eq!(tp.points[4].o, y, "bare MULTAX turns it on");
    assert_eq!(
        tp.points[5].o, y,
        "3-number GOTO keeps the last orientation"
    );
    assert_eq!(tp.points[5].p, Vector3::new(5.0, 0.0, 0.0));
}

#[test]
fn multax_off_from_start_uses_z() {
    let tp = ok("multax / off\nGOTO/0,0,0,1,0,0\n");
    assert_eq!(tp.points[0].o, Vector3::new(0.0, 0.0, 1.0));
}

#[test]
fn rapid_applies_to_next_goto_only() {
    let tp = ok(
        "RAPID\nGOTO/0,0,0\nGOTO/1,0,0\nFEDRAT/MMPM,600\nGOTO/2,0,0\n\
                 RAPID\nGOTO/3,0,0\nGOTO/4,0,0\n",
    );
    assert_eq!(tp.points[0].feed, Feed::Rapid);
    assert_eq!(tp.points[1].feed, Feed::Unspecified);
    assert_eq!(tp.points[2].feed, Feed::Programmed(10.0));
    assert_eq!(tp.points[3].feed, Feed::Rapid);
    assert_eq!(tp.points[4].feed, Feed::Programmed(10.0));
}

#[test]
fn continuation_and_comments() {
    let text = "$$ header comment\n\
                \n\
                GOTO/1.0,$\n\
                2.0,$  $$ comment after the dollar\n\
                3.0\n\
                GOTO/4,5,6 $$ trailing comment\n\
                GOTO/7,$\n\
                x,9\n";
    // Records: line 3 (spanning 3-5), line 6, line 7 (spanning 7-8, bad).
    err(text, 7, &["number 2", "`x`", "not a number"]);
    let good = text.replace("x,9", "8,9");
    let tp = ok(&good);
    assert_eq!(tp.points.len(), 3);
    assert_eq!(tp.points[0].p, Vector3::new(1.0, 2.0, 3.0));
    assert_eq!(tp.points[0].line, 3);
    assert_eq!(tp.points[1].p, Vector3::new(4.0, 5.0, 6.0));
    assert_eq!(tp.points[1].line, 6);
    assert_eq!(tp.points[2].p, Vector3::new(7.0, 8.0, 9.0));
    assert_eq!(tp.points[2].line, 7);
}

#[test]
fn error_line_after_continuation() {
    let text = "GOTO/0,$\n0,$\n0\nGOTO/1,,3\n";
    err(text, 4, &["GOTO", "number 2", "missing"]);
}

#[test]
fn non_motion_records_are_skipped() {
    let text = "TOOL PATH/PUBLIC,TOOL,MILL\n\
                PARTNO/DEMO PART\n\
                MSYS/0.0,0.0,0.0,1.0,0.0,0.0,0.0,1.0,0.0\n\
                TLDATA/MILL,10.0000,0.0000,75.0000,0.0000,0.0000\n\
                LOADTL/1\n\
                CUTTER/10\n\
                SELECT/TOOL,1\n\
                SPINDL/RPM,12000,CLW\n\
                COOLNT/ON\n\
                PAINT/COLOR,186\n\
                PPRINT/ANY TEXT, EVEN GOTO/1,2 AND $ SIGNS\n\
                INSERT/G04 P1\n\
                CLRSRF/Z,50\n\
                CYCLE/OFF\n\
                SOMETHING/UNKNOWN,1,2\n\
                WHATEVER\n\
                GOTO/1,2,3\n\
                END-OF-PATH\n\
                FINI\n";
    let tp = ok(text);
    assert_eq!(tp.points.len(), 1);
    assert_eq!(tp.points[0].p, Vector3::new(1.0, 2.0, 3.0));
    assert_eq!(tp.points[0].line, 17);
}

#[test]
fn duplicate_points_are_kept() {
    let tp = ok("GOTO/1,2,3\nGOTO/1,2,3\n");
    assert_eq!(tp.points.len(), 2);
}

#[test]
fn from_is_a_point() {
    let tp = ok("FROM/0,0,100\nGOTO/0,0,5\n");
    assert_eq!(tp.points.len(), 2);
    assert_eq!(tp.points[0].p, Vector3::new(0.0, 0.0, 100.0));
}

#[test]
fn error_malformed_number() {
    err(
        "FEDRAT/100\nGOTO/1.0,abc,3\n",
        2,
        &["GOTO", "number 2", "abc", "not a number"],
    );
    err("GOTO/1.0,2.0.0,3\n", 1, &["2.0.0", "not a number"]);
    err("GOTO/1.0,1 0,3\n", 1, &["1 0", "not a number"]);
}

#[test]
fn error_missing_number() {
    err("GOTO/0,0,0\nGOTO/1,,3\n", 2, &["number 2", "missing"]);
    err("GOTO/1,2,\n", 1, &["number 3", "missing"]);
    err("GOTO/\n", 1, &["expected 3", "found 1"]);
}

#[test]
fn error_non_finite() {
    err("GOTO/1,NaN,3\n", 1, &["NaN", "not a finite number"]);
    err("GOTO/1,2,-inf\n", 1, &["-inf", "not a finite number"]);
    err("GOTO/1,2,1e999\n", 1, &["1e999", "not a finite number"]);
}

#[test]
fn error_zero_tool_vector() {
    err(
        "GOTO/0,0,0\n\nGOTO/1,2,3,0,0,0\n",
        3,
        &["tool vector (0, 0, 0) has zero length"],
    );
    err("GOTO/1,2,3,1e-13,0,0\n", 1, &["tool vector", "zero length"]);
}

#[test]
fn error_wrong_count() {
    err("GOTO/1,2,3,4\n", 1, &["expected 3", "or 6", "found 4"]);
    err("GOTO/1,2\n", 1, &["found 2"]);
    err("GOTO/1,2,3,4,5,6,7\n", 1, &["found 7"]);
}

#[test]
fn error_malformed_motion_records() {
    err("GOTO\n", 1, &["GOTO", "missing `/`"]);
    err("GOTO 1,2,3\n", 1, &["GOTO", "malformed"]);
    err("GOTO/1,2,3\nFEDRAT\n", 2, &["FEDRAT", "missing `/`"]);
    err("MULTAX/SIDEWAYS\nGOTO/1,2,3\n", 1, &["MULTAX", "SIDEWAYS"]);
    err("UNITS/FEET\nGOTO/1,2,3\n", 1, &["UNITS", "FEET"]);
    err("RAPID/ON\nGOTO/1,2,3\n", 1, &["RAPID", "no parameters"]);
    // An arc whose centre is its start point, a cycle without depth, an unknown cycle, a
    // record that moves the tool in a way this reader does not follow.
    err(
        "GOTO/0,0,0\nCIRCLE/0,0,0,0,0,1,5\nGOTO/5,0,0\n",
        2,
        &["CIRCLE", "centre"],
    );
    err("CYCLE/DRILL,MMPM,100\nGOTO/1,2,3\n", 1, &["CYCLE", "depth"]);
    err("CYCLE/THREAD,5\nGOTO/1,2,3\n", 1, &["CYCLE/THREAD"]);
    err("GOTO/1,2,3\nGOHOME\n", 2, &["GOHOME", "not supported"]);
    err("GODLTA/0,0,5\nGOTO/1,2,3\n", 1, &["GODLTA", "unknown"]);
    err("GOTO/1,2,3\nGODLTA/0,5\n", 2, &["GODLTA", "found 2"]);
}

/// `GODLTA/dx,dy,dz` moves by that vector (in the MSYS frame), `GODLTA/d` by d along the tool
/// axis; `RAPID` before it makes it a rapid; in inches it scales like GOTO.
#[test]
fn godlta_moves_by_a_vector_or_along_the_tool_axis() {
    let tp = ok(
        "MULTAX/ON\nFEDRAT/MMPM,600\nGOTO/1,2,3,0,0.6,0.8\nGODLTA/0,0,5\nRAPID\nGODLTA/10\n\
                 MSYS/0,0,0,0,1,0,-1,0,0\nGODLTA/1,0,0\n",
    );
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    let close = |a: Vector3<f64>, b: Vector3<f64>| (a - b).norm() < 1e-12;
    assert!(close(p[1], Vector3::new(1.0, 2.0, 8.0)), "{:?}", p[1]);
    assert!(close(p[2], Vector3::new(1.0, 8.0, 16.0)), "{:?}", p[2]);
    // MSYS x axis is world +Y.
    assert!(close(p[3], Vector3::new(1.0, 9.0, 16.0)), "{:?}", p[3]);
    assert_eq!(tp.points[1].feed, Feed::Programmed(10.0));
    assert_eq!(tp.points[2].feed, Feed::Rapid);
    let tp = ok("UNITS/INCHES\nGOTO/0,0,0\nGODLTA/0,0,1\n");
    assert!((tp.points[1].p.z - 25.4).abs() < 1e-12);
}

#[test]
fn error_feed_per_revolution() {
    err(
        "FEDRAT/MMPR,0.1\nGOTO/1,2,3\n",
        1,
        &["feed per revolution", "not supported"],
    );
    err(
        "FEDRAT/0.004,IPR\n",
        1,
        &["feed per revolution", "not supported"],
    );
}

#[test]
fn error_bad_feed_values() {
    err("FEDRAT/MMPM,0\n", 1, &["positive"]);
    err("FEDRAT/-100,MMPM\n", 1, &["positive"]);
    err("FEDRAT/MMPM,inf\n", 1, &["not a finite number"]);
    err("FEDRAT/MMPM\n", 1, &["feed value", "missing"]);
    err("FEDRAT/MMPM,\n", 1, &["field 2", "missing"]);
    err(
        "FEDRAT/FAST,100\n",
        1,
        &["FAST", "not a number", "feed unit"],
    );
    err("FEDRAT/MMPM,100,200\n", 1, &["more than one"]);
    err("FEDRAT/100,200\n", 1, &["more than one feed value"]);
    err("FEDRAT/MMPM,IPM,3\n", 1, &["more than one feed unit"]);
}

#[test]
fn error_no_goto() {
    err("", 1, &["no GOTO records"]);
    err(
        "TOOL PATH/X\nFEDRAT/100\nEND-OF-PATH\n",
        3,
        &["no GOTO records"],
    );
    let e = parse(Path::new("some/dir/empty.cls"), "FINI\n").unwrap_err();
    assert!(e.to_string().contains("empty.cls"), "{e}");
}

#[test]
fn display_names_file_and_line() {
    let e = parse(Path::new("part.cls"), "GOTO/0,0,0\nGOTO/1,2,3,4\n").unwrap_err();
    let s = e.to_string();
    assert!(s.starts_with("part.cls:2: "), "{s}");
}

#[test]
fn garbage_does_not_panic() {
    let inputs = [
        "/",
        "/////",
        "$",
        "$$",
        "$\n$\n$",
        ",,,",
        "GOTO/$",
        "GOTO/1,2,3$",
        "GOTO/é,ü,3",
        "ÉGOTO/1,2,3",
        "GOTO/1,2,3,\u{0},0,1",
        "FEDRAT/,",
        "UNITS/",
        "MULTAX/",
        "GOTO/-,+,.",
        "GOTO/e,E,d",
        "GOTO/1e,2,3",
        "GOTO/1,2,3,1e308,1e308,1e308",
        "UNITS/INCHES\nGOTO/1e308,0,0",
    ];
    for text in inputs {
        let _ = parse(Path::new("x.cls"), text);
    }
    // A huge but finite tool vector normalises without overflowing.
    let tp = ok("GOTO/1,2,3,1e308,1e308,0\n");
    assert_relative_eq!(tp.points[0].o.norm(), 1.0, epsilon = 1e-12);
    // A `$` on the very last line: the record is taken as it stands.
    let tp = ok("GOTO/1,2,3$");
    assert_eq!(tp.points[0].p, Vector3::new(1.0, 2.0, 3.0));
}

#[test]
fn read_reports_io_error() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.cls");
    match read(&missing) {
        Err(Error::Io { file, .. }) => assert_eq!(file, missing),
        other => panic!("expected Error::Io, got {other:?}"),
    }
    let path = dir.path().join("ok.cls");
    std::fs::write(&path, b"PPRINT/caf\xe9\nGOTO/1,2,3\n").unwrap();
    let tp = read(&path).unwrap();
    assert_eq!(tp.source, path);
    assert_eq!(tp.points.len(), 1);
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared")]
fn shared_cases_parse() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/cases");
    assert!(dir.is_dir(), "../shared is present (cfg shared_data)");
    let expected = [
        ("p1_spiral_tilt.cls", 801),
        ("p2_xyz_rounded_square.cls", 6001),
        ("p3_s_curve_lean.cls", 2401),
    ];
    for (name, count) in expected {
        let path = dir.join(name);
        let tp = read(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(tp.points.len(), count, "{name}");
        for pt in &tp.points {
            assert_relative_eq!(pt.o.norm(), 1.0, epsilon = 1e-12);
            assert!(matches!(pt.feed, Feed::Programmed(f) if f > 0.0), "{name}");
        }
    }
    let p1 = read(&dir.join("p1_spiral_tilt.cls")).unwrap();
    for pt in &p1.points {
        assert_relative_eq!(feed_mm_s(pt.feed), 120.0, epsilon = 1e-9);
    }
    assert_eq!(p1.points[0].line, 4);
    assert_relative_eq!(p1.points[0].p, Vector3::new(40.0, 0.0, 0.0));
    // p2 is 3-axis under MULTAX/OFF: the tool stays along +Z.
    let p2 = read(&dir.join("p2_xyz_rounded_square.cls")).unwrap();
    assert!(
        p2.points
            .iter()
            .all(|pt| pt.o == Vector3::new(0.0, 0.0, 1.0))
    );
}

#[test]
fn unknown_records_are_skipped_with_a_warning_naming_the_line() {
    let t = ok(
        "TOOL PATH/PUBLIC,TOOL,MILL\nTLDATA/MILL,10,0,50,0\nFOOBAR/1,2\nGOTO/0,0,0\nPPRINT hi\nGOTO/1,0,0\nEND-OF-PATH\n",
    );
    assert_eq!(t.points.len(), 2);
    assert_eq!(t.warnings.len(), 1, "{:?}", t.warnings);
    assert_eq!(t.warnings[0].line, 3);
    assert!(t.warnings[0].message.contains("FOOBAR"));
}

/// `CUTCOM/LEFT` (and `RIGHT`) is said, as G41/G42 are: the CL points may be a contour the
/// control offsets by the tool radius, which feedopt does not do. `CUTCOM/OFF` says nothing.
/// Round 4 found it skipped in silence (a SolidWorks CAM program with 20 of them).
#[test]
fn cutcom_on_is_said_and_off_is_not() {
    let tp = ok(
        "UNITS/MM\nGOTO/0,0,0\nFEDRAT/300,MMPM\nCUTCOM/LEFT\nGOTO/10,0,0\nCUTCOM/OFF\nGOTO/10,10,0\n",
    );
    assert_eq!(tp.points.len(), 3);
    let said: Vec<_> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("compensation"))
        .map(|w| w.line)
        .collect();
    assert_eq!(said, [4], "{:?}", tp.warnings);
}

/// SolidWorks CAM's `CYCLE/DEEP2` (round 4: refused, in three of four of its programs) is a
/// deep peck cycle whose first peck (`1STPECK`) differs from the others (`SUBPECK`), read as
/// `CYCLE/DEEP` with that first peck, with a warning saying so: from the clearance 2 mm above
/// the point, pecks to −2 (4 mm), −5, −8 and the depth −10 (3 mm each), at the feed.
#[test]
fn deep2_pecks_first_by_its_first_peck_then_by_the_others() {
    let text = "UNITS/MM\nRAPID\nGOTO/0,0,20\nCYCLE/DEEP2,FEDTO,10.,1STPECK,4.,SUBPECK,3.,MMPM,200.,\
                RAPTO,2.,RTRCTO,20.\nGOTO/0,0,0\nCYCLE/OFF\n";
    let tp = ok(text);
    let pecks: Vec<f64> = tp
        .points
        .iter()
        .filter(|p| matches!(p.feed, Feed::Programmed(_)))
        .map(|p| p.p.z)
        .collect();
    assert_eq!(pecks, [-2.0, -5.0, -8.0, -10.0], "{:?}", tp.points);
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.line == 4 && w.message.contains("DEEP2")),
        "{:?}",
        tp.warnings
    );
}

/// `DELAY/t` is a dwell of t seconds (CATIA V5 writes `DELAY/   50.000000` at the bottom of each
/// peck of a deep-hole drilling operation; round 9: the seven dwells, 350 s of a 2,149 s
/// program, were skipped as a non-motion record and left out of the cycle time). `DELAY/REV,n`
/// is n spindle revolutions at the last `SPINDL/` speed; without a speed, or with no number, it
/// is an error naming the line.
#[test]
fn delay_is_a_dwell_counted_in_seconds_or_revolutions() {
    let tp = ok(
        "UNITS/MM\nSPINDL/600,RPM,CLW\nGOTO/0,0,1\nFEDRAT/100,MMPM\nGOTO/0,0,-5\n\
                 DELAY/   50.000000\nGOTO/0,0,1\nDELAY/REV,3\nGOTO/0,0,5\n",
    );
    let dwells: Vec<(usize, usize, f64)> = tp
        .dwells
        .iter()
        .map(|d| (d.line, d.point, d.seconds))
        .collect();
    assert_eq!(dwells.len(), 2, "{:?}", tp.dwells);
    assert_eq!((dwells[0].0, dwells[0].1), (6, 1));
    assert_relative_eq!(dwells[0].2, 50.0);
    assert_eq!((dwells[1].0, dwells[1].1), (8, 2));
    assert_relative_eq!(dwells[1].2, 0.3, epsilon = 1e-12);
    assert_relative_eq!(tp.dwell_time(), 50.3, epsilon = 1e-12);
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);

    err("GOTO/0,0,1\nDELAY/REV,3\n", 2, &["DELAY/REV", "SPINDL"]);
    err("GOTO/0,0,1\nDELAY/1,2\n", 2, &["DELAY", "seconds"]);
    err("GOTO/0,0,1\nDELAY/-1\n", 2, &["DELAY", "out of range"]);
}

/// `TLAXIS/i,j,k` sets the tool axis of the following moves, under `MULTAX/OFF` too (round 9:
/// CAMWorks writes `TLAXIS/ 0.000000,-1.000000,0.000000` for a side face and CATIA V5
/// `TLAXIS/ 0.000000, 0.000000, 1.000000`; both were skipped with a warning, leaving the axis
/// vertical). A `TLAXIS` with other than 3 numbers, or a zero axis, is an error.
#[test]
fn tlaxis_sets_the_tool_axis_of_the_following_moves() {
    let tp = ok(
        "UNITS/MM\nMULTAX/OFF\nGOTO/0,0,10\nTLAXIS/ 0.000000,-2.000000,0.000000\n\
                 GOTO/0,-10,0\nGOTO/5,-10,0\n",
    );
    let axes: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.o).collect();
    assert_eq!(axes[0], Vector3::new(0.0, 0.0, 1.0));
    assert_eq!(axes[1], Vector3::new(0.0, -1.0, 0.0));
    assert_eq!(axes[2], Vector3::new(0.0, -1.0, 0.0));
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);

    err("GOTO/0,0,1\nTLAXIS/0,1\n", 2, &["TLAXIS", "3 numbers"]);
    err("GOTO/0,0,1\nTLAXIS/0,0,0\n", 2, &["TLAXIS", "zero length"]);
}

/// `ROTABL/a,AAXIS,…` (CAMWorks: the table turned 90° before each side-face operation, the
/// GOTOs after it in the turned part's frame) moves a rotary axis: it was skipped with a
/// warning; it is now an error naming the word and what to do.
#[test]
fn a_rotary_table_index_is_an_error_naming_it() {
    err(
        "UNITS/ MM\nROTABL/ 1.570796,AAXIS,TABLE,CCLW\nRAPID/\nGOTO/ -30.0,-15.0,25.0\n",
        2,
        &["ROTABL", "rotary table", "GOTO/x,y,z,i,j,k"],
    );
    err("ROTHED/ 90,BAXIS\n", 1, &["ROTHED", "rotary head"]);
}

/// Fusion's `MOVARC/cx,cy,cz, i,j,k, r, ANGLE, a` states the sweep. An arc is counter-clockwise
/// about (i,j,k); a post that wrote a clockwise arc's axis unreversed (the 2011 HSMWorks APT
/// post writes `getCircularNormal()` as it is) made a 270° arc of a 90° one with no error,
/// and a helix of two turns was read as one. A stated ANGLE that the end point does not make
/// is now an error; one that it makes reads as before.
#[test]
fn a_movarc_angle_the_end_point_does_not_make_is_an_error() {
    // A quarter circle counter-clockwise about +Z from (10,0) to (0,10): 90°.
    let good = "UNITS/MM\nGOTO/10,0,0\nFEDRAT/100,MMPM\n\
                MOVARC/0, 0, 0, 0., 0., 1., 10., ANGLE, 90.\nGOTO/0,10,0\n";
    let tp = ok(good);
    assert_relative_eq!(tp.points.last().unwrap().p.y, 10.0);
    // The same record with the axis reversed sweeps 270°.
    err(
        &good.replace("0., 0., 1.", "0., 0., -1."),
        4,
        &["MOVARC", "ANGLE 90", "sweeps 270.0000", "wrong way"],
    );
    // One turn of a helix, the end straight below the start: a full turn, not a plunge.
    let tp = ok("UNITS/MM\nGOTO/10,0,0\nFEDRAT/100,MMPM\n\
                 MOVARC/0,0,0,0,0,1,10,ANGLE,360.\nGOTO/10,0,-2\n");
    let length: f64 = tp.points.windows(2).map(|w| (w[1].p - w[0].p).norm()).sum();
    let helix = (std::f64::consts::TAU * 10.0).hypot(2.0);
    assert!(
        length > 0.99 * helix && length < helix,
        "{length} vs {helix}"
    );
    // Two turns of a helix, start and end over each other: one MOVARC reads one turn.
    err(
        "UNITS/MM\nGOTO/10,0,0\nFEDRAT/100,MMPM\nMOVARC/0,0,0,0,0,1,10,ANGLE,720.\nGOTO/10,0,-2\n",
        4,
        &["ANGLE 720", "more than once"],
    );
    err(
        "GOTO/10,0,0\nMOVARC/0,0,0,0,0,1,10,ANGLE\nGOTO/0,10,0\n",
        2,
        &["MOVARC: ANGLE is missing"],
    );
}

/// A three-axis machine's tool cannot tilt: a CL point whose tool vector is not +Z (here a
/// `TLAXIS/0,-1,0` for a horizontal tool) is an error naming its line, not a move read with
/// the tool along +Z.
#[test]
fn a_tilted_tool_vector_on_a_three_axis_machine_is_an_error() {
    use feedopt::machine::Machine;
    use feedopt::optimize::{Options, optimize};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems/xyz_pocket");
    let m = Machine::from_file(&dir.join("machine.json")).expect("machine");
    let tilted = parse(
        Path::new("t.cls"),
        "FEDRAT/MMPM,600\nGOTO/0,0,10\nTLAXIS/0,-1,0\nGOTO/10,0,10\nFINI\n",
    )
    .unwrap();
    let e = optimize(&m, &tilted, &Options::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 4") && e.contains("tool vector") && e.contains("xyz"),
        "{e}"
    );
    // Along +Z it solves.
    let vertical = parse(
        Path::new("v.cls"),
        "FEDRAT/MMPM,600\nGOTO/0,0,10\nTLAXIS/0,0,1\nGOTO/10,0,10\nFINI\n",
    )
    .unwrap();
    assert!(optimize(&m, &vertical, &Options::default()).is_ok());
}
