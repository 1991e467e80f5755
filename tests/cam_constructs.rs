//! What CAM posts write (issue 12): canned cycles, reference moves, arcs, NURBS, frames, units
//! and axes, each against hand-computed moves and times.

use feedopt::error::Error;
use feedopt::machine::LengthUnit;
use feedopt::toolpath::gcode::{Dialect, parse, parse_assumed, parse_cycle_alias, parse_for};
use feedopt::toolpath::{Feed, MachineContext, Toolpath, Warning, apt};
use nalgebra::Vector3;
use std::path::Path;

fn gcode(dialect: Dialect, text: &str) -> Toolpath {
    parse(Path::new("t.ngc"), text, dialect).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn apt_ok(text: &str) -> Toolpath {
    apt::parse(Path::new("t.cls"), text).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
    Vector3::new(x, y, z)
}

fn assert_close(a: Vector3<f64>, b: Vector3<f64>, tol: f64) {
    assert!((a - b).norm() <= tol, "{a:?} != {b:?}");
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

fn message(e: Error) -> String {
    e.to_string()
}

#[test]
fn g83_peck_cycle_moves_and_time() {
    // Initial level 10, R 2, bottom −3, pecks of 2: depths 0, −2, −3; after each peck a rapid
    // to R and back to 0.254 mm above the last depth; G98 returns to the initial level.
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90 G0 X0 Y0 Z10\nG98 G83 X5 Y0 Z-3 R2 Q2 F60\nG80\n",
    );
    let z: Vec<f64> = tp.points[1..].iter().map(|p| p.p.z).collect();
    let want = [10.0, 2.0, 0.0, 2.0, 0.254, -2.0, 2.0, -1.746, -3.0, 10.0];
    assert_eq!(z.len(), want.len(), "{z:?}");
    for (a, b) in z.iter().zip(want) {
        assert!((a - b).abs() < 1e-9, "{z:?}");
    }
    assert!(tp.points[1..].iter().all(|p| p.p.x == 5.0));
    // Feed moves: 2 + 2.254 + 1.254 mm at 1 mm/s; every other move is a rapid.
    assert!((feed_time(&tp) - 5.508).abs() < 1e-9, "{}", feed_time(&tp));
    let rapids = tp.points[1..]
        .iter()
        .filter(|p| p.feed == Feed::Rapid)
        .count();
    assert_eq!(rapids, 7);
    // G99 returns to R instead; Fanuc P is milliseconds (G82 P1500 = 1.5 s), counted.
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90 G0 X0 Y0 Z10.\nG99 G82 X5. Y0 Z-3. R2. P1500 F60.\nX6.\nG80\n",
    );
    assert!((tp.dwell_time() - 3.0).abs() < 1e-12, "{:?}", tp.dwells);
    assert_eq!(tp.points.last().map(|p| p.p), Some(v(6.0, 0.0, 2.0)));
}

/// Fanuc G87 back boring shifts the oriented tool by Q (+X assumed, as G76) at the initial
/// level, rapids down through the hole to R, shifts back, feeds up to Z, shifts again, rapids
/// to the initial level and shifts back. The shifts were not modelled (round 28: a Fusion
/// Fanuc post's `G87 … Q0.01 P0`): moves of the tool left out in silence. Without Q the
/// tool goes straight down and up, as before.
#[test]
fn g87_back_boring_shifts_by_q_around_the_rapid_through_the_hole() {
    let tp = gcode(
        Dialect::Fanuc,
        "O1\nG21 G90 G0 X0 Y0 Z10.\nG98 G87 X5. Y2. Z-4. R-12. Q0.5 F60.\nG80\n",
    );
    let xz: Vec<(f64, f64)> = tp.points[1..].iter().map(|p| (p.p.x, p.p.z)).collect();
    let want = [
        (5.0, 10.0),  // over the hole at the initial level
        (5.5, 10.0),  // shift
        (5.5, -12.0), // rapid down to R, below the hole
        (5.0, -12.0), // shift back
        (5.0, -4.0),  // feed up to Z
        (5.5, -4.0),  // shift
        (5.5, 10.0),  // rapid to the initial level
        (5.0, 10.0),  // shift back
    ];
    assert_eq!(xz.len(), want.len(), "{xz:?}");
    for (a, b) in xz.iter().zip(want) {
        assert!(
            (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9,
            "{xz:?}"
        );
    }
    assert!(tp.points[1..].iter().all(|p| p.p.y == 2.0));
    // Only the bore is fed: 8 mm at 1 mm/s.
    assert!((feed_time(&tp) - 8.0).abs() < 1e-9, "{}", feed_time(&tp));
    let fed = tp.points[1..]
        .iter()
        .filter(|p| p.feed != Feed::Rapid)
        .count();
    assert_eq!(fed, 1);
    // Without Q: down, up, out, no shifts.
    let tp = gcode(
        Dialect::Fanuc,
        "O1\nG21 G90 G0 X0 Y0 Z10.\nG98 G87 X5. Y2. Z-4. R-12. F60.\nG80\n",
    );
    let z: Vec<f64> = tp.points[1..].iter().map(|p| p.p.z).collect();
    assert_eq!(z, vec![10.0, -12.0, -4.0, 10.0]);
    assert!(tp.points[1..].iter().all(|p| p.p.x == 5.0));
}

/// A peck cycle (G83, G73) without a peck depth Q, or with Q ≤ 0, is drilled in one pass
/// with a warning naming the block and saying that the controls refuse it (Fanuc alarm
/// PS0045 "address Q not found", LinuxCNC "Q must be positive") and what to write. Until
/// round 17 the warning said only "drilled in one pass", as if a control did that: NX posts
/// write `G83 … Q0.0` (a Haas program, and the Mori NMV5000 program of ../shared).
#[test]
fn a_peck_cycle_without_a_positive_peck_depth_says_the_control_refuses_it() {
    for (dialect, cycle) in [
        (Dialect::Fanuc, "G83 X5. Y0 Z-10. R2. Q0.0 F100."),
        (Dialect::Fanuc, "G73 X5. Y0 Z-10. R2. F100."),
        (Dialect::LinuxCnc, "G83 X5 Y0 Z-10 R2 Q0 F100"),
    ] {
        let tp = gcode(
            dialect,
            &format!("G21 G90 G0 X0 Y0 Z10.\nG99 {cycle}\nG80\n"),
        );
        let said: Vec<&Warning> = tp
            .warnings
            .iter()
            .filter(|w| w.message.contains("peck depth Q"))
            .collect();
        assert!(
            said.len() == 1
                && said[0].line == 2
                && said[0].message.contains("alarm PS0045")
                && said[0].message.contains("Q must be positive")
                && said[0].message.contains("give the peck depth Q > 0"),
            "{cycle}: {:?}",
            tp.warnings
        );
        // One pass: feed from R 2 to −10 (12 mm at 100 mm/min), no pecks.
        assert!((feed_time(&tp) - 7.2).abs() < 1e-9, "{}", feed_time(&tp));
    }
}

/// A peck cycle repeated 1000 times (`L1000`), 5000 pecks a hole: 15 million moves from one
/// block, more than a toolpath may hold (`toolpath::MAX_POINTS`). Refused before a move is
/// made, naming the block and the repeat count.
#[test]
fn a_cycle_repeated_past_the_point_limit_is_refused_before_its_moves() {
    let e = parse(
        Path::new("t.ngc"),
        "G21 G90 G0 X0 Y0 Z10\nG91 G83 X1 Y0 Z-1000 R0 Q0.2 L1000 F60\n",
        Dialect::LinuxCnc,
    )
    .map(|tp| tp.points.len())
    .expect_err("15 million moves");
    let e = message(e);
    assert!(
        e.contains("t.ngc:2:")
            && e.contains("G83 with 1000 repeats")
            && e.contains(&format!("more than the {}", feedopt::toolpath::MAX_POINTS)),
        "{e}"
    );
}

#[test]
fn mcall_cycle83_at_three_positions() {
    // RTP 20, RFP 0, SDIS 2, DP −10, FDEP −4 (first depth 4), VARI 1 (swarf removal):
    // depths −4, −8, −10; per hole 6 + 4.254 + 2.254 mm of feed at 2 mm/s = 6.254 s.
    let tp = gcode(
        Dialect::Sinumerik,
        "G71 G90 G0 X0 Y0 Z20\nF120\nMCALL CYCLE83(20,0,2,-10,,-4,,,,,,1)\nX10\nX20\nX30\nMCALL\nX40\n",
    );
    let bottoms: Vec<f64> = tp
        .points
        .iter()
        .filter(|p| (p.p.z + 10.0).abs() < 1e-9)
        .map(|p| p.p.x)
        .collect();
    assert_eq!(bottoms, vec![10.0, 20.0, 30.0]);
    assert!(
        (feed_time(&tp) - 3.0 * 6.254).abs() < 1e-9,
        "{}",
        feed_time(&tp)
    );
    // After the bare MCALL, X40 is only a rapid at the retract plane.
    let last = tp.points.last().map(|p| p.p);
    assert_eq!(last, Some(v(40.0, 0.0, 20.0)));
}

/// Round 20: a Fusion 360 program for a hobby control (Makera Carvera: `Z15`, `G19 G3 Y-1.169
/// Z-3 J0.317 K0`) written to Fanuc by `feedopt gcode --dialect fanuc` is read in the Fanuc
/// dialect, where `Z-3` counts increments (-0.003 mm). Its lead-in arc then fails "arc end point
/// is not on the circle" with nothing about the reading: the warning that named it is not
/// shown with an error. The arc's error now names the first word read so and the option.
#[test]
fn an_arc_that_fails_under_increment_input_names_the_reading() {
    use feedopt::machine::DecimalPointInput;
    use feedopt::toolpath::gcode::{Settings, parse_configured};
    let text = "G90 G94\nG17\nG21\nG0 X35.764 Y-1.487\nZ15\nG1 Z-2.683 F1000\n\
                G19 G3 Y-1.169 Z-3 J0.317 K0\nG1 Y-0.852\nM30\n";
    let read = |setting: Option<DecimalPointInput>| {
        let settings = Settings {
            decimal_point_input: setting,
            ..Settings::default()
        };
        parse_configured(
            Path::new("t.nc"),
            text,
            Dialect::Fanuc.spec(),
            None,
            &settings,
        )
    };
    let message = match read(None) {
        Err(feedopt::error::Error::Parse { line, message, .. }) => {
            assert_eq!(line, 7, "{message}");
            message
        }
        other => panic!("expected the arc's error, got {other:?}"),
    };
    for needle in [
        "not on the circle",
        "line 5: `Z15` as 0.015 mm",
        "--decimal-point-input calculator",
    ] {
        assert!(message.contains(needle), "{needle}: {message}");
    }
    // Read as written, the arc closes: a quarter turn of radius 0.317 mm down to Z-3.
    let tp = read(Some(DecimalPointInput::Calculator)).unwrap().0;
    assert_close(tp.points.last().unwrap().p, v(35.764, -0.852, -3.0), 1e-9);
    // With increments chosen, the reading is the user's: the arc's error stays as it was.
    match read(Some(DecimalPointInput::Increment)) {
        Err(feedopt::error::Error::Parse { message, .. }) => {
            assert!(!message.contains("decimal point"), "{message}")
        }
        other => panic!("expected the arc's error, got {other:?}"),
    }
}

fn context(axes: &str, reference: [Vec<f64>; 6], work_offset: [f64; 3]) -> MachineContext {
    MachineContext {
        file: "m.json".into(),
        axes: Some(axes.chars().collect()),
        reference,
        work_offset,
        work_offset_given: true,
        g28_all_axes: false,
        travel: Default::default(),
        m92: [None; 3],
        program_units: None,
        decimal_point_input: None,
        feed_diameter: [None; 3],
        shortest_way: [false; 3],
        machine_coordinates: false,
        wear_compensation: false,
        kinematics: None,
    }
}

/// A Fanuc-family G94 block that turns a rotary axis with a feed diameter D in the machine
/// file (Haas settings 34/79): a degree counts as π·D/360 mm of the combined distance, with
/// X Y Z or alone, in mm or inch; D = 360/π mm gives the Fanuc rule (a degree as one mm) back.
/// Other dialects, and tool-tip mode, read F without it and say so once.
#[test]
fn a_rotary_feed_diameter_turns_degrees_into_length() {
    use std::f64::consts::PI;
    let with = |d: f64| MachineContext {
        feed_diameter: [None, None, Some(d)],
        ..context("XYZAC", Default::default(), [0.0; 3])
    };
    let read = |dialect: Dialect, d: f64, text: &str| {
        parse_for(Path::new("t.nc"), text, dialect.spec(), Some(&with(d))).unwrap()
    };
    let time = |tp: &Toolpath, k: usize| match tp.points[k].feed {
        Feed::BlockTime(t) => t,
        f => panic!("point {k}: {f:?}"),
    };
    let fanuc = |d: f64, text: &str| read(Dialect::Fanuc, d, text);
    // X 20 mm and C 40° at D = 50 mm: C's 40° are 50π·40/360 = 17.45 mm along the part.
    let tp = fanuc(
        50.0,
        "G21 G90 G94 G0 X0. Y0. Z0. C0.
G91 G1 X20. C40. F300.
",
    );
    let arc = PI * 50.0 * 40.0 / 360.0;
    let want = (20f64 * 20.0 + arc * arc).sqrt() / 300.0 * 60.0;
    assert!(
        (time(&tp, 1) - want).abs() < 1e-9,
        "{} {want}",
        time(&tp, 1)
    );
    assert!(
        tp.warnings.iter().all(|w| !w.message.contains("combined")),
        "{:?}",
        tp.warnings
    );
    // C alone, 90° at F100 mm/min on D = 50 mm: 39.27 mm, 23.56 s (not 90°/100 °/min = 54 s).
    let tp = fanuc(
        50.0,
        "G21 G90 G94 G0 X0. Y0. Z0. C0.
G1 C90. F100.
",
    );
    assert!((time(&tp, 1) - PI * 50.0 / 4.0 / 100.0 * 60.0).abs() < 1e-9);
    // Under G20: F in inch/min, the 39.27 mm in inch.
    let tp = fanuc(
        50.0,
        "G20 G90 G94 G0 X0. Y0. Z0. C0.
G1 C90. F10.
",
    );
    assert!((time(&tp, 1) - PI * 50.0 / 4.0 / 25.4 / 10.0 * 60.0).abs() < 1e-9);
    // D = 360/π: a degree is a mm again, the Fanuc manual's √(20² + 40²)/300 min.
    let tp = fanuc(
        360.0 / PI,
        "G21 G90 G0 X0. Y0. Z0. C0.
G91 G1 X20. C40. F300.
",
    );
    assert!((time(&tp, 1) - (2000f64).sqrt() / 300.0 * 60.0).abs() < 1e-9);
    // A turns too and has no diameter: it counts a degree as a mm, and the block says so.
    let tp = fanuc(
        50.0,
        "G21 G90 G0 X0. Y0. Z0. A0. C0.
G1 X20. A10. C40. F300.
",
    );
    let want = (400.0 + 100.0 + arc * arc).sqrt() / 300.0 * 60.0;
    assert!((time(&tp, 1) - want).abs() < 1e-9);
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.line == 2 && w.message.contains("feed_diameter"))
    );
    // LinuxCNC's rule has no diameter: F along X Y Z, and one warning that D is not used.
    let tp = read(
        Dialect::LinuxCnc,
        50.0,
        "G21 G90 G0 X0 Y0 Z0 C0
G1 X20 C40 F300
G1 X0 C0
",
    );
    assert_eq!(tp.points[1].feed, Feed::Programmed(5.0));
    let said: Vec<_> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("feed_diameter"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", tp.warnings);
    assert_eq!(said[0].line, 2);
}

#[test]
fn g28_goes_via_the_intermediate_point() {
    let refs = [
        vec![-200.0],
        vec![0.0],
        vec![150.0],
        vec![],
        vec![0.0],
        vec![0.0],
    ];
    let m = context("XYZBC", refs, [0.0, 0.0, 100.0]);
    // G91 G28 Z10: via Z 5 + 10 = 15, then to the Z reference 150 (machine) = 50 (program).
    let tp = parse_for(
        Path::new("t.nc"),
        "G90 G0 X10. Y10. Z5.\nG91 G28 Z10.\nG90 G28 X0. Y10. B0.\n",
        Dialect::Fanuc.spec(),
        Some(&m),
    )
    .unwrap();
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    assert_eq!(p[1], v(10.0, 10.0, 15.0));
    assert_eq!(p[2], v(10.0, 10.0, 50.0));
    // Absolute G28 X0 Y10: via (0, 10), then X, Y to their references (−200, 0).
    assert_eq!(p[3], v(0.0, 10.0, 50.0));
    assert_eq!(p[4], v(-200.0, 0.0, 50.0));
    assert!(tp.points[1..].iter().all(|p| p.feed == Feed::Rapid));
}

/// LinuxCNC (and Tormach's PathPilot, which Fusion's Tormach post writes for): `G28` or `G30`
/// without axis words sends every axis the machine has straight to its stored position (no
/// intermediate point); Fanuc's axis words say which axes return, so there it stays an error.
/// `G50` (PathPilot's scaling cancel, in that post's safe-start line) moves nothing.
#[test]
fn bare_g28_and_g30_send_every_axis_home_on_linuxcnc() {
    let refs = [
        vec![-200.0, -100.0],
        vec![0.0, 50.0],
        vec![150.0, 120.0],
        vec![],
        vec![],
        vec![],
    ];
    let m = context("XYZ", refs, [0.0, 0.0, 100.0]);
    let tp = parse_for(
        Path::new("t.ngc"),
        "G90 G54 G64 G50 G17\nG0 X10 Y10 Z5\nG28\nG0 X10 Y10 Z5\nG30\n",
        Dialect::LinuxCnc.spec(),
        Some(&m),
    )
    .unwrap();
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    // Program = machine − work offset (0, 0, 100).
    assert_eq!(
        p,
        [
            v(10.0, 10.0, 5.0),
            v(-200.0, 0.0, 50.0),
            v(10.0, 10.0, 5.0),
            v(-100.0, 50.0, 20.0),
        ]
    );
    assert!(tp.points[1..].iter().all(|p| p.feed == Feed::Rapid));
    let e = parse_for(
        Path::new("t.nc"),
        "G90 G0 X10. Y10. Z5.\nG28\n",
        Dialect::Fanuc.spec(),
        Some(&m),
    )
    .unwrap_err();
    let text = message(e);
    assert!(text.contains("t.nc:2: G28 without axis words"), "{text}");
    // Round 16: three Haas student programs start with a bare `G28`, which a Haas reads as
    // every axis home; the message said to name Z alone.
    assert!(
        text.contains("Haas") && text.contains("`G91 G28 X0 Y0 Z0`"),
        "{text}"
    );
    // A Haas's machine file says so: every axis goes straight to its reference point.
    let haas = MachineContext {
        g28_all_axes: true,
        ..m.clone()
    };
    let tp = parse_for(
        Path::new("t.nc"),
        "G90 G0 X10. Y10. Z5.\nG28\n",
        Dialect::Fanuc.spec(),
        Some(&haas),
    )
    .unwrap();
    let last = tp.points.last().unwrap();
    assert_eq!(last.feed, Feed::Rapid);
    assert_eq!(last.p, v(-200.0, 0.0, 50.0));
}

#[test]
fn g28_without_a_reference_goes_to_machine_zero_and_says_so() {
    // No reference in the machine file: machine zero, the controls' default. Machine = program
    // + work offset (−300, −200, −250), so machine zero is program (300, 200, 250).
    let m = context("XYZBC", Default::default(), [-300.0, -200.0, -250.0]);
    let text = "G90 G0 X10. Y20. Z5.\nG91 G28 Z0.\nG91 G28 Z10.\nG90 G28 X0. Y0.\n";
    let (tp, assumed) = parse_assumed(
        Path::new("t.nc"),
        text,
        Dialect::Fanuc.spec(),
        Some(&m),
        &[],
    )
    .unwrap();
    let p: Vec<Vector3<f64>> = tp.points.iter().map(|p| p.p).collect();
    assert_eq!(
        p,
        [
            v(10.0, 20.0, 5.0),
            // G91 G28 Z0: the intermediate point is where the tool is; then Z to machine 0.
            v(10.0, 20.0, 250.0),
            // G91 G28 Z10: via Z 260, back to 250.
            v(10.0, 20.0, 260.0),
            v(10.0, 20.0, 250.0),
            // G90 G28 X0 Y0: via program (0, 0), then to machine zero (300, 200).
            v(0.0, 0.0, 250.0),
            v(300.0, 200.0, 250.0),
        ]
    );
    assert!(tp.points[1..].iter().all(|p| p.feed == Feed::Rapid));
    assert_eq!(
        assumed.reference_at_machine_zero,
        [true, true, true, false, false, false]
    );
    let note = assumed.reference_note().unwrap();
    assert!(
        note.contains("axes.Z.reference") && note.contains("machine zero"),
        "{note}"
    );
    // One warning per axis, at its first use, naming the field to set.
    let w: Vec<&Warning> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("reference"))
        .collect();
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].line == 2 && w[0].message.contains("axes.Z.reference"),
        "{w:?}"
    );
    assert!(w[1].line == 4 && w[1].message.contains("axes.X.reference, axes.Y.reference"));
    // Given references are used and assume nothing.
    let refs = [vec![1.0], vec![2.0], vec![3.0], vec![], vec![], vec![]];
    let m = context("XYZBC", refs, [0.0; 3]);
    let (tp, assumed) = parse_assumed(
        Path::new("t.nc"),
        text,
        Dialect::Fanuc.spec(),
        Some(&m),
        &[],
    )
    .unwrap();
    assert_eq!(tp.points[1].p, v(10.0, 20.0, 3.0));
    assert_eq!(assumed.reference_note(), None);
}

#[test]
fn apt_circle_is_the_same_arc_as_g2() {
    let a = apt_ok("FEDRAT/MMPM,100\nGOTO/10,0,0\nCIRCLE/0,0,0,0,0,-1,10\nGOTO/0,-10,0\n");
    let g = gcode(Dialect::LinuxCnc, "G0 X10 Y0 Z0\nG2 X0 Y-10 I-10 J0 F100\n");
    assert_eq!(a.points.len(), g.points.len());
    assert!(a.points.len() > 50, "a quarter circle of r 10 within 1 µm");
    for (p, q) in a.points.iter().zip(&g.points) {
        assert_close(p.p, q.p, 1e-9);
    }
    assert!((feed_time(&a) - feed_time(&g)).abs() < 1e-12);
    // A full circle: end = start.
    let full = apt_ok("GOTO/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nGOTO/10,0,0\n");
    let len: f64 = full
        .points
        .windows(2)
        .map(|w| (w[1].p - w[0].p).norm())
        .sum();
    // The chord polygon is shorter than the circle by a few µm (sagitta 1 µm).
    assert!(
        (len - 2.0 * std::f64::consts::PI * 10.0).abs() < 5e-3,
        "{len}"
    );
}

#[test]
fn nurbs_is_followed_not_its_control_polygon() {
    // A quadratic Bézier (0,0) (10,10) (20,0): B(t) = (20t, 20t(1 − t)); its length is
    // (1/20)[10√800 + 200 ln((20 + √800)/20)] = 22.9559 mm; the control polygon is 28.284 mm.
    let tp = apt_ok(
        "FEDRAT/MMPM,60\nGOTO/0,0,0\nNURBS/\nKNOT/0,0,0,1,1,1\nCNTRL/0,0,0\nCNTRL/10,10,0\nCNTRL/20,0,0\nGOTO/20,0,5\n",
    );
    let exact = (10.0 * 800f64.sqrt() + 200.0 * ((20.0 + 800f64.sqrt()) / 20.0).ln()) / 20.0;
    let curve: Vec<&feedopt::toolpath::ClPoint> =
        tp.points.iter().filter(|p| p.p.z == 0.0).collect();
    let len: f64 = curve.windows(2).map(|w| (w[1].p - w[0].p).norm()).sum();
    assert!((len - exact).abs() < 1e-3, "{len} vs {exact}");
    assert!(
        curve
            .iter()
            .any(|p| (p.p - v(10.0, 5.0, 0.0)).norm() < 1e-9)
    );
    // At 1 mm/s the curve takes its length in seconds, not the polygon's 28.28.
    let t = feed_time(&tp) - 5.0;
    assert!((t - exact).abs() < 1e-3, "{t}");
}

#[test]
fn msys_rotates_points_and_tool_vectors() {
    // X axis along world +Y, Y axis along world −X (90° about Z), origin (10, 0, 0).
    let tp = apt_ok("MSYS/10,0,0,0,1,0,-1,0,0\nGOTO/1,0,0,1,0,0\nMSYS/\nGOTO/1,0,0,1,0,0\n");
    assert_close(tp.points[0].p, v(10.0, 1.0, 0.0), 1e-12);
    assert_close(tp.points[0].o, v(0.0, 1.0, 0.0), 1e-12);
    assert_close(tp.points[1].p, v(1.0, 0.0, 0.0), 1e-12);
    assert_close(tp.points[1].o, v(1.0, 0.0, 0.0), 1e-12);
}

#[test]
fn cycle800_swivels_a_3_plus_2_plane() {
    // _MODE 57: X, then Y, then Z; B = 90° about Y: program Z is world +X, and the tool
    // points along it; CYCLE800() clears the plane.
    let tp = gcode(
        Dialect::Sinumerik,
        "CYCLE800(1,\"TC1\",0,57,0,0,0,0,90,0,0,0,0,-1,100,1)\nG0 X0 Y0 Z10\nX5\nCYCLE800()\nG0 X0 Y0 Z10\n",
    );
    assert_close(tp.points[0].p, v(10.0, 0.0, 0.0), 1e-12);
    assert_close(tp.points[0].o, v(1.0, 0.0, 0.0), 1e-12);
    assert_close(tp.points[1].p, v(10.0, 0.0, -5.0), 1e-12);
    assert_eq!(tp.points[0].rotary, None);
    assert_close(tp.points[2].p, v(0.0, 0.0, 10.0), 1e-12);
    // Rotary words under CYCLE800 still give way to the plane's tool vector: the rule that
    // makes them programmed positions is Klartext's PLANE only (what an 840D does with them
    // was not established).
    let tp = gcode(
        Dialect::Sinumerik,
        "CYCLE800(1,\"TC1\",0,57,0,0,0,0,90,0,0,0,0,-1,100,1)\nG0 X0 Y0 Z10\nG0 X5 B0 C90\n",
    );
    assert_eq!(tp.points[1].rotary, None);
    assert_close(tp.points[1].o, v(1.0, 0.0, 0.0), 1e-12);
    // TRANS and AROT: a programmable frame.
    let tp = gcode(
        Dialect::Sinumerik,
        "TRANS X100\nAROT Z90\nG0 X10 Y0 Z0\nTRANS\nG0 X10 Y0 Z0\n",
    );
    assert_close(tp.points[0].p, v(100.0, 10.0, 0.0), 1e-12);
    assert_close(tp.points[1].p, v(10.0, 0.0, 0.0), 1e-12);
}

#[test]
fn sinumerik_g70_feed_units() {
    // G70 first: the program is in inches, F in inch/min (the basic system taken as inch).
    let tp = gcode(Dialect::Sinumerik, "G70\nG0 X0 Y0 Z0\nG1 X1 F10\n");
    assert_close(tp.points[1].p, v(25.4, 0.0, 0.0), 1e-12);
    assert_eq!(tp.points[1].feed, Feed::Programmed(10.0 * 25.4 / 60.0));
    // A metric basic system: G70 changes the geometry only, F stays mm/min.
    let tp = gcode(Dialect::Sinumerik, "G71\nG70\nG0 X0 Y0 Z0\nG1 X1 F254\n");
    assert_close(tp.points[1].p, v(25.4, 0.0, 0.0), 1e-12);
    assert_eq!(tp.points[1].feed, Feed::Programmed(254.0 / 60.0));
    // G700: F in inch/min too.
    let tp = gcode(Dialect::Sinumerik, "G710\nG700\nG0 X0 Y0 Z0\nG1 X1 F10\n");
    assert_eq!(tp.points[1].feed, Feed::Programmed(10.0 * 25.4 / 60.0));
}

#[test]
fn variables_and_expressions() {
    let tp = gcode(
        Dialect::Sinumerik,
        "DEF REAL _Z_HOME, _X=2\n_Z_HOME=50 R2=3\nR1=R2+5\nG0 X=R1*2 Y=_X Z=_Z_HOME\n",
    );
    assert_eq!(tp.points[0].p, v(16.0, 2.0, 50.0));
    let tp = gcode(
        Dialect::Fanuc,
        "#100=5.\n#101=#100*2\nG0 X#101 Y[#100+1] Z-#100\n",
    );
    assert_eq!(tp.points[0].p, v(10.0, 6.0, -5.0));
    // G10 L2 sets an offset and moves nothing.
    let tp = gcode(Dialect::Fanuc, "G10 L2 P1 X0 Y0 Z0\nG0 X1. Y1. Z1.\n");
    assert_eq!(tp.points.len(), 1);
}

#[test]
fn an_ab_program_on_an_ac_machine_names_b() {
    let m = context("XYZAC", Default::default(), [0.0; 3]);
    let e = parse_for(
        Path::new("t.nc"),
        "G0 X0. Y0. Z0. A0.\nG0 A10. B20.\n",
        Dialect::Fanuc.spec(),
        Some(&m),
    )
    .unwrap_err();
    let text = message(e);
    assert!(text.contains(":2:") && text.contains("no B axis"), "{text}");
}

#[test]
fn arc_turns_and_chords_are_bounded() {
    // Turn counts and radii whose chords would be past MAX_ARC_CHORDS: errors up front.
    let fails = |text: &str, dialect: Dialect| match parse(Path::new("t"), text, dialect) {
        Ok(tp) => panic!("{} points from {text}", tp.points.len()),
        Err(e) => message(e),
    };
    let e = fails(
        "G0 X10 Y0 Z0\nG2 X10 Y0 I-10 J0 P1000000000 F100\n",
        Dialect::LinuxCnc,
    );
    assert!(e.contains("chords"), "{e}");
    let e = fails(
        "G0 X10 Y0 Z0\nG2 X10 Y0 I-10 J0 TURN=100000000 F100\n",
        Dialect::Sinumerik,
    );
    assert!(e.contains("chords"), "{e}");
    let e = fails(
        "G0 X10 Y0 Z0\nG2 X10 Y0 I-1000000000000 J0 F100\n",
        Dialect::LinuxCnc,
    );
    assert!(e.contains("out of range") || e.contains("chords"), "{e}");
}

#[test]
fn cycle76_with_a_boring_list_reads_as_cycle86_and_a_spigot_call_is_an_error() {
    // As NX posts "BORING_NO_DRAG" for an 840D: CYCLE86's list under the name CYCLE76. A
    // standard 840D refuses it as a spigot (no _LENG/_WID), so it is read as CYCLE86, said at
    // its line, with the way to choose another boring cycle.
    let nx = "G71 G90 G0 X0 Y0 Z20\nF120\nMCALL CYCLE76(20,0,2,-10,,3,,,,)\nX10\nX20\nMCALL\n";
    let read = gcode(Dialect::Sinumerik, nx);
    let as86 = gcode(Dialect::Sinumerik, &nx.replace("CYCLE76", "CYCLE86"));
    assert_eq!(read.points, as86.points);
    assert_eq!(read.dwells, as86.dwells);
    let note = read
        .warnings
        .iter()
        .find(|w| w.message.contains("read as CYCLE86"))
        .unwrap_or_else(|| panic!("{:?}", read.warnings));
    for needle in ["_LENG", "_WID", "--cycle-alias CYCLE76=CYCLE85"] {
        assert!(note.message.contains(needle), "{needle}: {}", note.message);
    }
    // A spigot call with its dimensions is an error (feedopt mills no spigots).
    let e = parse(
        Path::new("t.mpf"),
        "G71 G0 X0 Y0 Z20\nCYCLE76(20,0,2,-10,,40,30,5)\n",
        Dialect::Sinumerik,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains(":2:") && e.contains("spigot") && e.contains("--cycle-alias"),
        "{e}"
    );
    let e = parse(
        Path::new("t.mpf"),
        "G71 G0 X0 Y0 Z20\nCYCLE77(20,0,2,-10,,40)\n",
        Dialect::Sinumerik,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains(":2:") && e.contains("_PRAD"), "{e}");
    // An alias chooses another boring cycle: CYCLE85 feeds out instead of the rapid.
    let (as85, _) = parse_assumed(
        Path::new("t.mpf"),
        nx,
        Dialect::Sinumerik.spec(),
        None,
        &[parse_cycle_alias("CYCLE76=CYCLE85").unwrap()],
    )
    .unwrap();
    assert_eq!(
        as85.points,
        gcode(Dialect::Sinumerik, &nx.replace("CYCLE76", "CYCLE85")).points
    );
    assert_ne!(as85.points, as86.points);
    // With the alias: exactly CYCLE86's moves (per hole: rapid to RFP + SDIS = 2, feed to −10,
    // dwell DTB = 3 s, rapid to RTP = 20), and a warning naming the alias where it applies.
    let alias = parse_cycle_alias(" cycle76 = CYCLE86 ").unwrap();
    assert_eq!(alias, ("CYCLE76".to_string(), "CYCLE86".to_string()));
    let (aliased, _) = parse_assumed(
        Path::new("t.mpf"),
        nx,
        Dialect::Sinumerik.spec(),
        None,
        &[alias],
    )
    .unwrap();
    let plain = gcode(Dialect::Sinumerik, &nx.replace("CYCLE76", "CYCLE86"));
    assert_eq!(aliased.points, plain.points);
    assert_eq!(aliased.dwells, plain.dwells);
    assert!((aliased.dwell_time() - 6.0).abs() < 1e-12);
    let z: Vec<f64> = aliased.points[1..5].iter().map(|p| p.p.z).collect();
    assert_eq!(z, [20.0, 2.0, -10.0, 20.0]);
    assert!(
        aliased
            .warnings
            .iter()
            .any(|w| w.line == 3 && w.message.contains("CYCLE76 is read as CYCLE86")),
        "{:?}",
        aliased.warnings
    );
    // Aliases are two cycle names, the second one feedopt expands.
    for bad in [
        "CYCLE76",
        "CYCLE76=CYCLE100",
        "G76=G86",
        "CYCLE86=CYCLE86",
        "=CYCLE86",
    ] {
        let e = parse_cycle_alias(bad).unwrap_err().to_string();
        assert!(
            e.contains("cycle alias") && e.contains("CYCLE76=CYCLE86"),
            "{bad}: {e}"
        );
    }
}

/// A Sinumerik call feedopt does not know (a cycle or subprogram with an argument list, here
/// NX's thread-milling CYCLE90 from a Huron KX20 post) may move the tool: an error naming the
/// line and the call, not a warning that drops it. CYCLE832 (tolerances), MSG and SETMS (the
/// master spindle; a 840D sl package's CAM test) are read and ignored. A bare unknown name is
/// a command or a subprogram call on an 840D (its alarm stops the program): an error too,
/// with the keyword a typo stands for (NX's Cincinnati post writes `TRAOOF` for TRAFOOF,
/// which left TRAORI on). An unknown M code stays a warning.
#[test]
fn an_unknown_sinumerik_call_is_an_error() {
    let text =
        "G90 G54\nG0 X0 Y0 Z10\nCYCLE90(-17,-17,,-36,,28,25,2,1000,2,0,72.415,-34)\nG1 X10 F100\n";
    let e = message(parse(Path::new("t.mpf"), text, Dialect::Sinumerik).unwrap_err());
    assert!(e.contains("t.mpf:3") && e.contains("CYCLE90(…)"), "{e}");
    let tp = gcode(
        Dialect::Sinumerik,
        "CYCLE832(0.01,_ORI_FINISH,1)\nMSG(\"roughing\")\nSETMS(1)\nM204\nG0 X0 Y0 Z10\nG1 X10 F100\n",
    );
    assert_eq!(tp.points.len(), 2);
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.message.contains("unknown word `M204`")),
        "{:?}",
        tp.warnings
    );
    let text = "G90 G54\nG0 X0 Y0 Z10\nFOO\nG1 X10 F100\n";
    let e = message(parse(Path::new("t.mpf"), text, Dialect::Sinumerik).unwrap_err());
    assert!(e.contains("t.mpf:3") && e.contains("`FOO`"), "{e}");
    let text = "G71 G90 G17 G94\nTRAORI(1)\nG0 X1 Y0 Z1 A0 C0\nG1 X2 F10\nTRAOOF\nG0 Z2\n";
    let e = message(parse(Path::new("t.mpf"), text, Dialect::Sinumerik).unwrap_err());
    assert!(
        e.contains("t.mpf:5") && e.contains("`TRAOOF`") && e.contains("`TRAFOOF`"),
        "{e}"
    );
}

/// Haas G187 (the smoothness setting, written by many Haas posts: `G187 P1 E0.05`) moves
/// nothing: read without a word (it was an unknown G code, an error). Its `E0.05` after a
/// space is a word, not the exponent of `P1` (the Fanuc dialect removes spaces; `P1E0.05`
/// written together stays an error, as exponent notation).
#[test]
fn haas_g187_is_read() {
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90\nG187 P1 E0.05\nG0 X0. Y0. Z10.\nG1 X10. F100.\nG187\nM30\n",
    );
    assert_eq!(tp.points.len(), 2);
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    let e = message(
        parse(
            Path::new("t.nc"),
            "G21 G90\nG187 P1E0.05\nM30\n",
            Dialect::Fanuc,
        )
        .unwrap_err(),
    );
    assert!(e.contains("t.nc:2") && e.contains("exponent"), "{e}");
}

/// Fanuc G60 (single-direction positioning, one-shot; a Kuraki KBT post writes
/// `G60G00X-.9843Y-1.0891`): the move to its end point, with a warning that the overshoot the
/// control's parameters set is not modelled.
#[test]
fn fanuc_g60_moves_to_its_end_point_with_a_warning() {
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90\nG0 X0. Y0. Z10.\nG60 G0 X5. Y2.\nG1 X10. F100.\n",
    );
    assert_eq!(tp.points.len(), 3);
    assert_close(tp.points[1].p, v(5.0, 2.0, 10.0), 1e-12);
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.line == 3 && w.message.contains("single-direction positioning")),
        "{:?}",
        tp.warnings
    );
}

/// Sinumerik `I=AC(…)` gives an arc centre in program coordinates and `I=IC(…)` from the
/// start, whatever the modal mode (an NX post for a Huron KX20 writes
/// `G2 X39 Y0 Z-10 I=AC(0.) J=AC(0.) TURN=1`): the same helix as the plain incremental I J.
#[test]
fn sinumerik_ac_and_ic_arc_centres() {
    let head = "G90 G17\nG0 X39 Y0 Z0\nF100\n";
    let points = |arc: &str| gcode(Dialect::Sinumerik, &format!("{head}{arc}\n")).points;
    let plain = points("G2 X39 Y0 Z-2 I-39 J0 TURN=1");
    assert!(plain.len() > 20, "a helix of two turns in chords");
    for arc in [
        "G2 X39 Y0 Z-2 I=AC(0.) J=AC(0.) TURN=1",
        "G2 X39 Y0 Z-2 I=IC(-39) J=AC(0) TURN=1",
        "G2 X39 Y0 Z-2 I=AC(0) TURN=1",
    ] {
        let got = points(arc);
        assert_eq!(got.len(), plain.len(), "{arc}");
        for (g, p) in got.iter().zip(&plain) {
            assert_close(g.p, p.p, 1e-12);
        }
    }
    // An off-origin centre: (10, 0) absolute is I-29 from (39, 0).
    let a = points("G3 X-19 Y0 I=AC(10) J=AC(0)");
    let b = points("G3 X-19 Y0 I-29 J0");
    assert_eq!(a.len(), b.len());
    assert_close(a[a.len() / 2].p, b[b.len() / 2].p, 1e-12);
    assert_close(a[a.len() / 2].p, v(10.0, 29.0, 0.0), 1e-6);
}

/// A Fanuc, Sinumerik or LinuxCNC program that selects no unit is read in the unit the control
/// is set to (parameters; LinuxCNC's INI file), which only the machine file can give
/// (`program_units`). Without it: mm, a warning at the first move and the `units` note (an NX
/// post for a Makino, "_in", with no G20 was read in mm with no word said; round 4, an inch
/// LinuxCNC sample, 1.09 m for about 27.8 m). With `inch`: coordinates and F in inch. A program
/// that selects its unit says nothing.
#[test]
fn a_program_without_a_unit_is_read_in_the_machine_files_unit_or_said_to_be_mm() {
    let text = "G90 G0 X1. Y0. Z0.\nG1 X2. F10.\n";
    let read = |spec, units| {
        let mut m = context("XYZ", Default::default(), [0.0; 3]);
        m.program_units = units;
        parse_assumed(Path::new("t.nc"), text, spec, Some(&m), &[]).unwrap()
    };
    for d in [Dialect::Fanuc, Dialect::Sinumerik, Dialect::LinuxCnc] {
        let (tp, assumed) = read(d.spec(), None);
        assert!(assumed.units_mm && assumed.units_note().unwrap().contains("program_units"));
        let w: Vec<&Warning> = tp
            .warnings
            .iter()
            .filter(|w| w.message.contains("selects no unit"))
            .collect();
        assert!(w.len() == 1 && w[0].line == 1, "{d:?}: {w:?}");
        assert_close(tp.points[1].p, v(2.0, 0.0, 0.0), 1e-12);
        let (tp, assumed) = read(d.spec(), Some(LengthUnit::Mm));
        assert!(
            !assumed.units_mm && tp.warnings.is_empty(),
            "{:?}",
            tp.warnings
        );
        let (tp, _) = read(d.spec(), Some(LengthUnit::Inch));
        assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
        assert_close(tp.points[1].p, v(50.8, 0.0, 0.0), 1e-12);
        match tp.points[1].feed {
            Feed::Programmed(f) => assert!((f - 10.0 * 25.4 / 60.0).abs() < 1e-12, "{f}"),
            other => panic!("{other:?}"),
        }
        // The program's own G21 / G71 wins over the machine file.
        let own = if d == Dialect::Sinumerik {
            "G71 "
        } else {
            "G21 "
        };
        let mut m = context("XYZ", Default::default(), [0.0; 3]);
        m.program_units = Some(LengthUnit::Inch);
        let (tp, assumed) = parse_assumed(
            Path::new("t.nc"),
            &format!("{own}{text}"),
            d.spec(),
            Some(&m),
            &[],
        )
        .unwrap();
        assert!(!assumed.units_mm);
        assert_close(tp.points[1].p, v(2.0, 0.0, 0.0), 1e-12);
        // F: Fanuc's G21 sets it in mm/min; Sinumerik's G71 changes lengths only, F stays in
        // the basic system the machine file gives (inch/min).
        let f = if d == Dialect::Sinumerik {
            10.0 * 25.4
        } else {
            10.0
        };
        match tp.points[1].feed {
            Feed::Programmed(got) => assert!((got - f / 60.0).abs() < 1e-12, "{d:?}: {got}"),
            other => panic!("{other:?}"),
        }
    }
}

/// `G95` (feed per revolution) with the spindle speed known: the feed at a move is F × S. The
/// pitch form of rigid tapping in Fusion's Fanuc/Haas posts (round 3, fusion_efgarro_6686
/// line 151: `G95 M29 S500`, `G84 … F1.75`) taps at 1.75 mm × 500 rpm = 875 mm/min; it was
/// an error. Moves without S, or with S0, or under G96 (S a cutting speed) are errors naming
/// the line; G94 comes back to F per minute, and F must be given again after a change of feed
/// mode.
#[test]
fn g95_feed_per_revolution_is_f_times_s() {
    let tp = gcode(
        Dialect::Fanuc,
        "O1000\nG21 G90 G17 G94\nG0 X16. Y-12. Z85.\nS500 M3\nG95 M29 S500\n\
         G98 G84 X16. Y-12. Z64.627 R85. F1.75\nG80\nG94\nM30\n",
    );
    let tap: Vec<f64> = tp
        .points
        .iter()
        .filter_map(|p| match p.feed {
            Feed::Programmed(f) => Some(f),
            _ => None,
        })
        .collect();
    assert!(!tap.is_empty(), "{:?}", tp.points);
    for f in tap {
        assert!((f - 875.0 / 60.0).abs() < 1e-12, "{f}");
    }
    // LinuxCNC and Sinumerik, lines and arcs: 0.1 mm/rev at 1200 rpm = 120 mm/min = 2 mm/s.
    for (dialect, text) in [
        (
            Dialect::LinuxCnc,
            "G21 G90 G0 X0 Y0 Z0\nS1200 M3\nG95 G1 X10 F0.1\nG2 X20 Y0 R5\n",
        ),
        (
            Dialect::Sinumerik,
            "G71 G90 G0 X0 Y0 Z0\nS1200 M3\nG95 G1 X10 F0.1\nG2 X20 Y0 CR=5\n",
        ),
    ] {
        let tp = gcode(dialect, text);
        for p in &tp.points[1..] {
            assert!(
                matches!(p.feed, Feed::Programmed(f) if (f - 2.0).abs() < 1e-12),
                "{text}"
            );
        }
    }
    // A new S changes the feed of the next move.
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90 G0 X0 Y0 Z0\nS600\nG95 G1 X10 F0.1\nS1200\nG1 X20\n",
    );
    let feeds: Vec<Feed> = tp.points[1..].iter().map(|p| p.feed).collect();
    assert_eq!(feeds, [Feed::Programmed(1.0), Feed::Programmed(2.0)]);
    // G94 again: F per minute, which the program gives again (an F per revolution is
    // forgotten, not read as 0.1 mm/min).
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90 G0 X0 Y0 Z0\nS1000\nG95 G1 X10. F0.1\nG94 G1 X20. F600.\n",
    );
    let feeds: Vec<Feed> = tp.points[1..].iter().map(|p| p.feed).collect();
    assert_eq!(
        feeds,
        [Feed::Programmed(100.0 / 60.0), Feed::Programmed(10.0)]
    );
    // A feed move after the F is forgotten stops the control, as before any F or after F0
    // (LinuxCNC "Cannot do G1 with zero feed rate", Fanuc PS0011, Sinumerik 10860): an error
    // naming the line, never a move at the machine's maximum feed.
    for (dialect, text, line) in [
        (
            Dialect::Fanuc,
            "G21 G90 G0 X0 Y0 Z0\nS1000\nG95 G1 X10. F0.1\nG94 G1 X20.\n",
            4,
        ),
        (Dialect::LinuxCnc, "G21 G90 G0 X0 Y0 Z5\nG1 Z-1\n", 2),
        (Dialect::LinuxCnc, "G21 G90 G0 X0 Y0 Z5\nG1 Z-1 F0\n", 2),
        (
            Dialect::LinuxCnc,
            "G21 G90 G0 X0 Y0 Z5\nF100\nG1 Z-1 F0.\nG1 X50\n",
            3,
        ),
        (
            Dialect::LinuxCnc,
            "G20 G90 G0 X0 Y0 Z0.4\nS400 M3\nG98 G84 X0 Y0 Z-0.48 R0.1 F0.\n",
            3,
        ),
        (Dialect::Sinumerik, "G71 G90 G0 X0 Y0 Z5\nG1 X10\n", 2),
        (Dialect::Fanuc, "G21 G90 G0 X0 Y0 Z5\nG2 X10 Y0 R5\n", 2),
    ] {
        let e = message(parse(Path::new("t.ngc"), text, dialect).unwrap_err());
        assert!(
            e.starts_with(&format!("t.ngc:{line}: a feed move with no feed rate")),
            "{e}\n{text}"
        );
    }
    for (dialect, text, line, needle) in [
        (
            Dialect::LinuxCnc,
            "G21 G90 G0 X0 Y0 Z0\nG95 G1 X10 F0.1\n",
            2,
            "no spindle speed",
        ),
        (
            Dialect::LinuxCnc,
            "G21 G90 G0 X0 Y0 Z0\nS0\nG95 G1 X10 F0.1\n",
            3,
            "S0",
        ),
        (
            Dialect::Fanuc,
            "G21 G90 G0 X0 Y0 Z0\nG96 S200\nG95 G1 X10. F0.1\n",
            3,
            "G96",
        ),
        (
            Dialect::Fanuc,
            "G21 G90 G0 X0 Y0 Z0\nS1000\nG95 G84 X0. Y0. Z-10. R2. F2\n",
            3,
            "decimal point",
        ),
        (
            Dialect::Sinumerik,
            "G71 G90 G0 X0 Y0 Z0\nG96 S200\nG1 X10 F0.1\n",
            3,
            "G96",
        ),
    ] {
        let e = parse(Path::new("t.ngc"), text, dialect).expect_err(text);
        let m = message(e);
        assert!(
            m.contains(&format!("t.ngc:{line}:")) && m.contains(needle),
            "{text}: {m}"
        );
    }
}

/// A Fanuc number without a decimal point counts least input increments (parameter 3401#0
/// DPI = 0, Fanuc's default): round 3's `O0001 … G1 X100 Y50` read as a 0.118 mm path with no
/// word said. The reading stays, with one warning at the first such word that is not 0, naming
/// it, what it was read as and how to choose calculator-type input (DPI = 1: `X100` is 100 mm),
/// which the read settings or the machine file's `decimal_point_input` select; either choice
/// silences the warning. A dwell `G4 X2500` is 2.5 s in increments, `G4 P2500` always.
#[test]
fn fanuc_integer_words_are_increments_said_once_or_calculator_input_by_setting() {
    use feedopt::machine::DecimalPointInput;
    use feedopt::toolpath::gcode::{Settings, parse_configured};
    let text = "O0001\nG21 G90 G94\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X100 Y50 F600\nG4 X2500\nM30\n";
    let read = |setting: Option<DecimalPointInput>, file: Option<DecimalPointInput>| {
        let mut m = context("XYZ", Default::default(), [0.0; 3]);
        m.decimal_point_input = file;
        let settings = Settings {
            decimal_point_input: setting,
            ..Settings::default()
        };
        parse_configured(
            Path::new("t.nc"),
            text,
            Dialect::Fanuc.spec(),
            Some(&m),
            &settings,
        )
        .unwrap()
        .0
    };
    let length =
        |tp: &Toolpath| -> f64 { tp.points.windows(2).map(|w| (w[1].p - w[0].p).norm()).sum() };
    let said = |tp: &Toolpath| -> Vec<Warning> {
        tp.warnings
            .iter()
            .filter(|w| w.message.contains("decimal point"))
            .cloned()
            .collect()
    };
    let tp = read(None, None);
    assert_close(tp.points.last().unwrap().p, v(0.1, 0.05, -0.001), 1e-12);
    assert!((tp.dwells[0].seconds - 2.5).abs() < 1e-12);
    let w = said(&tp);
    assert_eq!(w.len(), 1, "{:?}", tp.warnings);
    assert_eq!(w[0].line, 3);
    for needle in [
        "`Z5`",
        "0.005 mm",
        "3401",
        "calculator",
        "decimal_point_input",
        "5 mm",
    ] {
        assert!(w[0].message.contains(needle), "{needle}: {}", w[0].message);
    }
    // Calculator-type input, from the settings or the machine file: 117.8 mm, the program's
    // length; increments chosen: the same 0.118 mm without the warning. The settings win.
    for (setting, file) in [
        (Some(DecimalPointInput::Calculator), None),
        (None, Some(DecimalPointInput::Calculator)),
        (
            Some(DecimalPointInput::Calculator),
            Some(DecimalPointInput::Increment),
        ),
    ] {
        let tp = read(setting, file);
        assert!(said(&tp).is_empty(), "{:?}", tp.warnings);
        assert_close(tp.points.last().unwrap().p, v(100.0, 50.0, -1.0), 1e-12);
        // Z5 → Z−1, then (0, 0) → (100, 50).
        assert!((length(&tp) - (6.0 + 100f64.hypot(50.0))).abs() < 1e-9);
        assert!((tp.dwells[0].seconds - 2500.0).abs() < 1e-9);
    }
    let tp = read(Some(DecimalPointInput::Increment), None);
    assert!(said(&tp).is_empty(), "{:?}", tp.warnings);
    assert_close(tp.points.last().unwrap().p, v(0.1, 0.05, -0.001), 1e-12);
    // Only non-zero words tell: `X0 Y0` reads the same either way. Rotary words and I J K R
    // are increments too (0.001°, 0.001 mm); LinuxCNC has no such reading.
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G0 X0 Y0 Z0\nG1 X1. F100.\nG2 X3. I1000 J0\n",
    );
    let w = said(&tp);
    assert!(
        w.len() == 1 && w[0].line == 3 && w[0].message.contains("`I1000`"),
        "{w:?}"
    );
    assert_close(tp.points.last().unwrap().p, v(3.0, 0.0, 0.0), 1e-9);
    // The unit the block selects: G20 before the word.
    let tp = gcode(Dialect::Fanuc, "G20 G0 X1000 Y0. Z0.\n");
    assert!(
        said(&tp)[0].message.contains("0.1 inch"),
        "{:?}",
        tp.warnings
    );
    assert!((tp.points[0].p.x - 2.54).abs() < 1e-12);
    let tp = gcode(Dialect::Fanuc, "G21 G0 X0. Y0. Z0. A90000\n");
    assert!(said(&tp)[0].message.contains("90°"), "{:?}", tp.warnings);
    assert_eq!(tp.points[0].rotary.unwrap()[0], 90.0);
    let tp = gcode(Dialect::LinuxCnc, "G21 G0 X100 Y0 Z0\n");
    assert!(said(&tp).is_empty());
    assert_eq!(tp.points[0].p.x, 100.0);
}

fn xs(tp: &Toolpath) -> Vec<f64> {
    tp.points.iter().map(|p| p.p.x).collect()
}

/// `G10 L2` on the work offset in force after moves made in it (round 3,
/// repro_g10l2_active.ngc): the control moves 100 mm more than the program's coordinates say,
/// by how much depends on the offset's old value, which the program does not give; it was a
/// warning saying the coordinates are used as written. It is an error naming the G10 and the
/// move. Set before the first move (CAMotics writes `G10 L2 P1 X0 Y0 Z0` at the top), or on
/// an offset the program does not move in afterwards, it is none; two offsets set in machine
/// coordinates lie exactly that far apart.
#[test]
fn g10_l2_on_the_offset_in_force_is_followed_or_refused() {
    let e = parse(
        Path::new("t.ngc"),
        "G21 G90 G54\nG0 X0 Y0 Z10\nG10 L2 P1 X100\nG0 X0\nG1 X10 F600\nM2\n",
        Dialect::LinuxCnc,
    )
    .unwrap_err();
    let m = message(e);
    for needle in [
        "t.ngc:3:",
        "`G10 L2 P1 X100`",
        "G54",
        "line 4",
        "G10 L20",
        "G91 G10 L2",
    ] {
        assert!(m.contains(needle), "{needle}: {m}");
    }
    // Before the first move: the offsets' values place the program (no word said).
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90\nG10 L2 P1 X0 Y0 Z0\nG10 L2 P2 X0 Y0 Z0\nG55\nG10 L2 P2 X0 Y0 Z0\nG55\n\
         G0 X1 Y1 Z1\nG1 X2 F600\nM2\n",
    );
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    assert_eq!(xs(&tp), [1.0, 2.0]);
    // Two offsets set in machine coordinates: the move between them is 150 mm, said nowhere.
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90\nG10 L2 P1 X100 Y0 Z0\nG10 L2 P2 X250 Y0 Z0\nG54 G0 X0 Y0 Z0\nG55 G0 X0\n\
         G54 G0 X1\nM2\n",
    );
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    assert_eq!(xs(&tp), [100.0, 250.0, 101.0]);
    // Set on X only, G55's Y and Z are the control's: taken as G54's, and said.
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90\nG10 L2 P1 X100\nG10 L2 P2 X250\nG54 G0 X0 Y0 Z0\nG55 G0 X0\nM2\n",
    );
    assert_eq!(xs(&tp), [100.0, 250.0]);
    assert!(
        tp.warnings.len() == 1 && tp.warnings[0].line == 5,
        "{:?}",
        tp.warnings
    );
    // An offset set after moves but not moved in afterwards: no error.
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90 G54 G0 X0 Y0 Z0\nG10 L2 P2 X100\nG1 X10 F600\nM2\n",
    );
    assert_eq!(xs(&tp), [0.0, 10.0]);
    // … unless the program then moves in it: the move into G55 is the one not known.
    let e = parse(
        Path::new("t.ngc"),
        "G21 G90 G54 G0 X0 Y0 Z0\nG10 L2 P2 X100\nG1 X10 F600\nG55\nG1 X0\nM2\n",
        Dialect::LinuxCnc,
    )
    .unwrap_err();
    let m = message(e);
    assert!(
        m.contains("t.ngc:2:") && m.contains("G55") && m.contains("line 5"),
        "{m}"
    );
    // The reverse: moves in an offset set in machine coordinates, then back in the one the
    // program started in (the control's own values). (An offset never named before is taken
    // as equal to the one in force, with a warning, as any change of offset is.)
    let e = parse(
        Path::new("t.ngc"),
        "G21 G90\nG10 L2 P2 X100 Y0 Z0\nG55 G0 X0 Y0 Z0\nG54\nG0 X1\nM2\n",
        Dialect::LinuxCnc,
    )
    .unwrap_err();
    let m = message(e);
    assert!(
        m.contains("t.ngc:2:") && m.contains("line 5") && m.contains("does not set"),
        "{m}"
    );
    // G53 stands outside: a machine-coordinate move between them does not count.
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90\nG10 L2 P1 X0 Y0 Z0\nG0 X5 Y0 Z0\nG53 G0 Z0\nG0 X6\nM2\n",
    );
    assert_eq!(xs(&tp), [5.0, 5.0, 6.0]);
}

/// Offsets changed relative to the current one are exact whatever the old values: LinuxCNC
/// `G10 L20` (the current position becomes the given coordinates) and Fanuc `G91 G10 L2` (an
/// increment; round 3's G10 L2 P1 X100 written so is the 110 mm the control runs), and
/// Fanuc's external offset `P0` under G91. Tool data (`G10 L1`, `L10`, `L11`) moves nothing
/// and is said; a G10 L2 without P, or with a P naming no offset or a rotation R, is an error.
#[test]
fn g10_relative_to_the_current_offset_is_exact() {
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90 G0 X10 Y0 Z0\nG10 L20 P1 X0\nG0 X5\nG10 L20 P0 Y2\nG0 Y3\nM2\n",
    );
    assert_eq!(xs(&tp), [10.0, 15.0, 15.0]);
    assert_eq!(tp.points.last().map(|p| p.p.y), Some(1.0));
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90 G54 G0 X0. Y0. Z10.\nG91 G10 L2 P1 X100.\nG90 G0 X0.\nG1 X10. F600.\nM30\n",
    );
    assert_eq!(xs(&tp), [0.0, 100.0, 110.0]);
    let path: f64 = tp.points.windows(2).map(|w| (w[1].p - w[0].p).norm()).sum();
    assert!((path - 110.0).abs() < 1e-9, "{path}");
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90 G0 X0. Y0. Z0.\nG91 G10 L2 P0 Z-2.\nG90 G0 Z0.\nM30\n",
    );
    assert_eq!(tp.points.last().map(|p| p.p.z), Some(-2.0));
    // Fanuc L20 sets the extended offsets: G54.1 P3 in machine coordinates, before any move.
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90\nG10 L20 P3 X40.\nG54.1 P3 G0 X0. Y0. Z0.\nG1 X1. F100.\nM30\n",
    );
    assert_eq!(xs(&tp), [40.0, 41.0]);
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90 G0 X0 Y0 Z0\nG10 L1 P1 Z1.5\nG10 L10 P1 Z1.5\nG1 X1 F100\nM2\n",
    );
    let said: Vec<usize> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("tool data"))
        .map(|w| w.line)
        .collect();
    assert_eq!(said, [2, 3]);
    for (dialect, text, line, needle) in [
        (
            Dialect::LinuxCnc,
            "G0 X0 Y0 Z0\nG10 L2 X1\n",
            2,
            "without P",
        ),
        (Dialect::LinuxCnc, "G0 X0 Y0 Z0\nG10 L2 P10 X1\n", 2, "P9"),
        (Dialect::Fanuc, "G0 X0. Y0. Z0.\nG10 L2 P7 X1.\n", 2, "P6"),
        (Dialect::LinuxCnc, "G10 L2 P1 X1 R30\n", 1, "R30"),
        (
            Dialect::LinuxCnc,
            "G21 G90\nG10 L20 P1 X0\n",
            2,
            "not known",
        ),
    ] {
        let e = parse(Path::new("t.ngc"), text, dialect).expect_err(text);
        let m = message(e);
        assert!(
            m.contains(&format!("t.ngc:{line}:")) && m.contains(needle),
            "{text}: {m}"
        );
    }
}

/// `G52`, the local shift: round 3's `G15 G52 X0 Y0` (Fusion's safety block,
/// fusion_efgarro_6686.nc:18) cancels none and was refused; it is read. A shift moves the
/// points by it, `G52 X0` cancels it, LinuxCNC's `G92.1` too; a G52 without axis words is an
/// error, and so is one under G91 while a shift is in force (an increment on some controls,
/// a value on others).
#[test]
fn g52_shifts_every_offset_and_zero_cancels() {
    let tp = gcode(
        Dialect::Fanuc,
        "O1000\nG21 G90 G17 G94\nG15 G52 X0 Y0\nG0 X0. Y0. Z10.\nG1 X10. F600.\nM30\n",
    );
    assert_eq!(xs(&tp), [0.0, 10.0]);
    for dialect in [Dialect::Fanuc, Dialect::LinuxCnc] {
        let tp = gcode(
            dialect,
            "G21 G90 G0 X0. Y0. Z0.\nG52 X5. Y-1.\nG0 X0.\nG0 Y0.\nG55\nG0 X1.\nG52 X0 Y0\n\
             G0 X0.\n",
        );
        // The shift leaves the tool where it is: Y moves when Y is programmed.
        assert_eq!(xs(&tp), [0.0, 5.0, 5.0, 6.0, 0.0], "{dialect:?}");
        let ys: Vec<f64> = tp.points.iter().map(|p| p.p.y).collect();
        assert_eq!(ys, [0.0, 0.0, -1.0, -1.0, -1.0], "{dialect:?}");
    }
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90 G0 X0 Y0 Z0\nG91 G52 X5\nG90 G0 X0\nG92.1\nG0 X0\n",
    );
    assert_eq!(xs(&tp), [0.0, 5.0, 0.0]);
    for (text, line, needle) in [
        ("G21 G0 X0 Y0 Z0\nG52\n", 2, "without axis words"),
        ("G21 G0 X0 Y0 Z0\nG52 X5\nG91 G52 X1\n", 3, "G90"),
    ] {
        let e = parse(Path::new("t.ngc"), text, Dialect::LinuxCnc).expect_err(text);
        let m = message(e);
        assert!(
            m.contains(&format!("t.ngc:{line}:")) && m.contains(needle),
            "{text}: {m}"
        );
    }
}

/// `G92`: the current position gets the coordinates named (a shift of every offset; the tool
/// does not move). It was refused ("not supported"). LinuxCNC keeps it in `G52`'s register
/// (`G92.1` cancels it); Fanuc apart, and a `G52` and a `G92` both in force on one axis is an
/// error there. A program that starts with `G92 X0 Y0 Z0` names the unknown start as its
/// origin: its moves are exact relative to it, and nothing is said about an unknown start.
#[test]
fn g92_gives_the_current_position_the_coordinates_named() {
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc] {
        let tp = gcode(
            dialect,
            "G21 G90 G0 X10. Y0. Z0.\nG92 X0.\nG1 X5. F600.\nG55\nG1 X6.\nG91 G1 X1.\n",
        );
        assert_eq!(xs(&tp), [10.0, 15.0, 16.0, 17.0], "{dialect:?}");
        // Inches: the named position is in the program's unit.
        let tp = gcode(dialect, "G20 G90 G0 X1. Y0. Z0.\nG92 X0.\nG1 X1. F60.\n");
        assert_eq!(xs(&tp), [25.4, 50.8], "{dialect:?}");
        // From the unknown start: exact relative to it, no warning about it.
        let tp = gcode(dialect, "G21 G90\nG92 X0 Y0 Z0\nG1 X5. F600.\nG1 Y5.\n");
        assert_eq!(xs(&tp), [5.0, 5.0], "{dialect:?}");
        assert!(tp.warnings.is_empty(), "{dialect:?}: {:?}", tp.warnings);
    }
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90 G0 X10 Y0 Z0\nG92 X0\nG1 X5 F600\nG92.1\nG0 X0\nG92 X2\nG52 X0\nG0 X1\n",
    );
    // G92.1 cancels the shift (the position reads 15); G52 X0 too (G92 X2 had shifted by −2).
    assert_eq!(xs(&tp), [10.0, 15.0, 0.0, 1.0], "{:?}", tp.points);
    for (dialect, text, line, needle) in [
        (
            Dialect::LinuxCnc,
            "G21 G0 X0 Y0 Z0\nG92\n",
            2,
            "without axis words",
        ),
        (
            Dialect::Fanuc,
            "G21 G0 X0 Y0 Z0\nG52 X5.\nG92 X0\n",
            3,
            "G52 local shift",
        ),
        (
            Dialect::Fanuc,
            "G21 G0 X0 Y0 Z0\nG92 X5.\nG52 X1.\n",
            3,
            "G92 shift",
        ),
    ] {
        let e = parse(Path::new("t.ngc"), text, dialect).expect_err(text);
        let m = message(e);
        assert!(
            m.contains(&format!("t.ngc:{line}:")) && m.contains(needle),
            "{text}: {m}"
        );
    }
}

/// LinuxCNC `G64 P0.02` (blending within 0.02 mm) is said with the option that applies it.
#[test]
fn g64_p_is_said_with_the_option_that_applies_it() {
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90 G64 P0.02\nG0 X0 Y0 Z0\nG1 X10 F600\nG64\n",
    );
    let said: Vec<_> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("--corner-tolerance 0.02"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", tp.warnings);
    assert_eq!(said[0].line, 1);
    assert_eq!(xs(&tp), [0.0, 10.0]);
}

/// A leading `G28 G91 Z0` (Fusion's Fanuc and Haas posts) moves Z only: X and Y are still the
/// unknown start, and the first move from there is said to be from X0 Y0, as after a leading
/// `G0 Z0`. Round 4 found it counted in silence (+1101 mm on a Fusion program).
#[test]
fn a_reference_move_of_one_axis_leaves_the_others_unknown_and_says_so() {
    let text = "G21 G90\nG28 G91 Z0\nG90\nG0 X100 Y0\nG1 X110 F600\n";
    for dialect in [Dialect::LinuxCnc, Dialect::Fanuc] {
        let tp = gcode(dialect, text);
        let said: Vec<_> = tp
            .warnings
            .iter()
            .filter(|w| w.message.contains("X, Y not programmed yet"))
            .collect();
        assert_eq!(said.len(), 1, "{dialect:?}: {:?}", tp.warnings);
        assert_eq!(said[0].line, 2);
    }
    // Every axis named: nothing is unknown after it.
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90\nG28 G91 X0 Y0 Z0\nG90\nG0 X100 Y0\n",
    );
    assert!(
        tp.warnings
            .iter()
            .all(|w| !w.message.contains("not programmed yet")),
        "{:?}",
        tp.warnings
    );
}

/// Sinumerik `G92 S3000` limits the spindle speed under G96 and moves nothing: it was refused
/// as an unknown G code (round 4). Its S is no spindle speed: a G95 feed still takes the S in
/// force before it. `G92` with axis words is an error there.
#[test]
fn sinumerik_g92_s_is_a_speed_limit_not_a_speed() {
    let tp = gcode(
        Dialect::Sinumerik,
        "G90 G71\nS1000 M3\nG0 X10 Y0 Z0\nG92 S3000\nG95 G1 X20 F0.1\n",
    );
    assert_eq!(xs(&tp), [10.0, 20.0]);
    match tp.points[1].feed {
        // 0.1 mm/rev × 1000 rpm = 100 mm/min.
        Feed::Programmed(f) => assert!((f - 100.0 / 60.0).abs() < 1e-12, "{f}"),
        other => panic!("{other:?}"),
    }
    let e = parse(
        Path::new("t.mpf"),
        "G90 G71\nG0 X10 Y0 Z0\nG92 X0\n",
        Dialect::Sinumerik,
    )
    .expect_err("G92 X");
    let m = message(e);
    assert!(m.contains("t.mpf:3:") && m.contains("spindle"), "{m}");
}

/// LinuxCNC `G92.2` cancels the `G92` shift but keeps it in parameters 5211–5219, and `G92.3`
/// restores it from there (round 4: it was refused, though the program had set them); after
/// `G92.1` (which clears them) it restores 0. Before the program sets them they are the
/// control's: an error.
#[test]
fn g92_3_restores_what_the_program_left_in_the_parameters() {
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90\nG0 X10 Y0 Z0\nG92 X0\nG1 X5 F600\nG92.2\nG1 X0\nG92.3\nG1 X5\nG92.1\nG92.3\n\
         G1 X1\n",
    );
    assert_eq!(xs(&tp), [10.0, 15.0, 0.0, 15.0, 1.0]);
    let e = parse(
        Path::new("t.ngc"),
        "G21 G90\nG0 X10 Y0 Z0\nG92.3\n",
        Dialect::LinuxCnc,
    )
    .expect_err("G92.3 first");
    let m = message(e);
    assert!(m.contains("t.ngc:3:") && m.contains("5211"), "{m}");
}

/// Siemens allows blanks after an address letter and around `=` (round 4: `R1 = 100` was
/// "malformed word `=`", `G1 X 100` "`X` has no number", in hand-written 840D programs). Each
/// reads as its compact form, an expression's terms included.
#[test]
fn sinumerik_blanks_after_an_address_and_around_equals_read_as_the_compact_form() {
    let compact = gcode(
        Dialect::Sinumerik,
        "G90 G71\nDEF REAL OFF\nR1=100\nOFF=R1+5\nG0 X0 Y0 Z0\nG1 X=OFF F600\nG1 X=R1-2*3\nG1 X100\n\
         R2=SIN(30)+1\nG1 X=R2\n",
    );
    let spaced = gcode(
        Dialect::Sinumerik,
        "G90 G71\nDEF REAL OFF\nR1 = 100\nOFF = R1 + 5\nG0 X 0 Y 0 Z 0\nG1 X = OFF F 600\n\
         G1 X= R1 - 2 * 3\nG1 X 100\nR2 = SIN(30) + 1\nG1 X = R2\n",
    );
    assert_eq!(xs(&compact), [0.0, 105.0, 94.0, 100.0, 1.5]);
    assert_eq!(xs(&spaced), xs(&compact));
    assert_eq!(spaced.points[1].feed, compact.points[1].feed);
}

/// A machine-coordinate position of a rotary axis (`G53 A…`, the `G28` reference) is not
/// shifted by a work offset on that axis: with `G52 A10` in force, `A5` is at 15° and
/// `G53 A30` at 30° (it was put at 40°, the shift added to a machine coordinate).
#[test]
fn rotary_machine_coordinates_are_not_shifted_by_the_offsets() {
    let tp = gcode(
        Dialect::LinuxCnc,
        "G21 G90\nG0 X0 Y0 Z0 A0\nG52 A10\nG0 A5\nG53 G0 A30\nG0 A0\n",
    );
    let a: Vec<f64> = tp.points.iter().map(|p| p.rotary.unwrap()[0]).collect();
    assert_eq!(a, [0.0, 15.0, 30.0, 10.0], "{:?}", tp.points);
}

/// Sinumerik CYCLE84 (rigid tapping) feeds at pitch × speed, as the 840D's cycle does: PIT
/// (or the metric size MPIT) × SST in, × SST1 out (round 5: it tapped at the last F, 68.6 s
/// for about 7 s). CYCLE84(RTP, RFP, SDIS, DP, DPR, DTB, SDAC, MPIT, PIT, POSS, SST, SST1).
#[test]
fn sinumerik_cycle84_taps_at_pitch_times_speed() {
    let tap = |call: &str| {
        gcode(
            Dialect::Sinumerik,
            &format!("G71 G90 G17 G94\nS800 M3\nG0 X0 Y0 Z50\nF60\nMCALL {call}\nX10\nMCALL\n"),
        )
    };
    // RFP 3, SDIS 0, DP −30.875: 33.875 mm in at 1.25 × 500 mm/min, out at 1.25 × 400.
    let depth = 33.875;
    let tp = tap("CYCLE84(3,3,,-30.875,,,3,,1.25,0,500,400)");
    let want = depth / (1.25 * 500.0 / 60.0) + depth / (1.25 * 400.0 / 60.0);
    assert!((feed_time(&tp) - want).abs() < 1e-9, "{}", feed_time(&tp));
    assert!(tp.warnings.iter().all(|w| !w.message.contains("CYCLE84")));
    // SST1 empty or 0: out at SST too. MPIT 10 is M10, pitch 1.5 mm.
    let tp = tap("CYCLE84(3,3,,-30.875,,,3,10,,0,500,0)");
    assert!((feed_time(&tp) - 2.0 * depth / (1.5 * 500.0 / 60.0)).abs() < 1e-9);
    // _PTAB 2: PIT in threads per inch (20 tpi: 1.27 mm).
    let tp = tap("CYCLE84(3,3,,-30.875,,,3,,20,0,500,,,2)");
    assert!((feed_time(&tp) - 2.0 * depth / (1.27 * 500.0 / 60.0)).abs() < 1e-9);
    // Without SST: the S programmed before the call (800 rpm).
    let tp = tap("CYCLE84(3,3,,-30.875,,,3,,1.25)");
    assert!((feed_time(&tp) - 2.0 * depth / (1.25 * 800.0 / 60.0)).abs() < 1e-9);
    // Without a pitch: the programmed F (60 mm/min), with a warning.
    let tp = tap("CYCLE84(3,3,,-30.875,,,3,,,0,500)");
    assert!((feed_time(&tp) - 2.0 * depth).abs() < 1e-9);
    assert!(
        tp.warnings
            .iter()
            .any(|w| w.message.contains("without a pitch"))
    );
    // A thread size that is not a metric coarse thread is an error naming the line.
    let e = message(
        parse(
            Path::new("t.mpf"),
            "G71 G90 G17\nS500 M3\nG0 X0 Y0 Z50\nCYCLE84(3,3,,-10,,,3,7)\n",
            Dialect::Sinumerik,
        )
        .unwrap_err(),
    );
    assert!(e.contains("t.mpf:4") && e.contains("MPIT 7"), "{e}");
}

/// Siemens treats a blank as a separator, so `CYCLE81 (10,0,2,-5)` (NX's Huron post) is the
/// call `CYCLE81(10,0,2,-5)` (round 5: "unexpected character `(`").
#[test]
fn sinumerik_blank_before_an_argument_list() {
    let program = |call: &str| {
        format!("G71 G90 G17 G94\nS1000 M3\nG0 X0 Y0 Z50\nF100\n{call}\nMCALL {call}\nX20\nMCALL\n")
    };
    let compact = gcode(Dialect::Sinumerik, &program("CYCLE81(10,0,2,-5)"));
    let spaced = gcode(Dialect::Sinumerik, &program("CYCLE81 (10,0,2,-5)"));
    assert_eq!(spaced.points, compact.points);
    // Hole at X0 and X20: 7 mm of feed each (RFP + SDIS = 2 down to −5).
    assert!((feed_time(&compact) - 2.0 * 7.0 / (100.0 / 60.0)).abs() < 1e-9);
}

/// Fanuc macro B: arithmetic on constants after `#n=` (round 5: `#4=63./2.` was "unexpected
/// character `/`" while `#4=#1/2.` read), functions, and blanks.
#[test]
fn fanuc_macro_assignments_of_constant_expressions() {
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90\n#4= 63. / 2.\n#5=80./2.+#4+5.\n#6=SIN[30.]*4.\n#7 = 10. * 2. - 1.\n\
         G0 X#4 Y#5 Z#6\nG0 X#7\n",
    );
    assert_close(tp.points[0].p, v(31.5, 76.5, 2.0), 1e-12);
    assert_eq!(tp.points[1].p.x, 19.0);
}

fn fanuc_error(text: &str) -> String {
    message(parse(Path::new("t.nc"), text, Dialect::Fanuc).unwrap_err())
}

/// Fanuc macro B control flow: WHILE … DO m / END m, IF … GOTO n, GOTO n, IF … THEN, with
/// EQ NE GT GE LT LE and AND/OR (round 5: `WHILE` was read as a W axis word).
#[test]
fn fanuc_macro_while_if_goto() {
    // Three passes: X 0, 10, 20, each a 10 mm feed move, at F600 (1 s each but the first).
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90\n#1=0.\nG0 X-10. Y0. Z5.\nWHILE [#1 LT 3.] DO1\nG1 X[#1*10.] F600.\n\
         #1=#1+1.\nEND1\nG0 Z10.\n",
    );
    assert_eq!(xs(&tp), [-10.0, 0.0, 10.0, 20.0, 20.0]);
    assert!((feed_time(&tp) - 3.0).abs() < 1e-9);
    // Nested loops take different numbers: 2 × 3 points.
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90 G0 X0. Y0. Z0.\n#1=0\nWHILE[#1LT2]DO1\n#2=0\nWHILE[#2LT3]DO2\n\
         G1 X#2 Y#1 F100.\n#2=#2+1\nEND2\n#1=#1+1\nEND1\n",
    );
    assert_eq!(tp.points.len(), 7);
    assert_eq!(tp.points[6].p, v(2.0, 1.0, 0.0));
    // A false condition at the start skips the loop.
    let tp = gcode(
        Dialect::Fanuc,
        "G0 X0. Y0. Z0.\n#1=5.\nWHILE [#1 LT 3.] DO1\nG1 X1. F100.\nEND1\nG0 X2.\n",
    );
    assert_eq!(xs(&tp), [0.0, 2.0]);
    // IF … THEN runs its statement when the condition holds; AND / OR join comparisons.
    let tp = gcode(
        Dialect::Fanuc,
        "#1=0.\n#2=0.\nIF [#1 LT 3.] THEN #1=5.\nIF [[#1 GT 4.] AND [#1 LE 5.]] THEN #2=7.\n\
         IF [[#1 EQ 0] OR [#2 NE 7.]] THEN #2=9.\nG0 X#1 Y#2 Z0.\n",
    );
    assert_eq!(tp.points[0].p, v(5.0, 7.0, 0.0));
    // IF … GOTO skips forward; GOTO jumps back (a counted loop): X 1, 2, 3, then 10.
    let tp = gcode(
        Dialect::Fanuc,
        "G0 X0. Y0. Z0.\n#1=0\nN10 #1=#1+1\nG0 X#1\nIF [#1 GE 3] GOTO 20\nGOTO 10\n\
         G0 X99.\nN20 G0 X10.\n",
    );
    assert_eq!(xs(&tp), [0.0, 1.0, 2.0, 3.0, 10.0]);
    // In a subprogram, GOTO looks for the block number there.
    let tp = gcode(
        Dialect::Fanuc,
        "O1\nG0 X0. Y0. Z0.\nM98 P2\nM30\nO2\nGOTO 5\nG0 X99.\nN5 G0 X5.\nM99\n",
    );
    assert_eq!(xs(&tp), [0.0, 5.0]);
}

/// A macro loop that cannot end is an error naming the file and line, not a hang: at once
/// when nothing its condition reads has changed since its last pass; after the bound on the
/// blocks a program may run otherwise. Malformed or unmatched statements are errors too.
#[test]
fn fanuc_macro_loops_are_bounded_and_checked() {
    let e = fanuc_error("#1=0\nG0 X0. Y0. Z0.\nWHILE [#1 LT 3] DO1\nG91 G1 X1. F100.\nEND1\n");
    assert!(e.contains("t.nc:5") && e.contains("for ever"), "{e}");
    let e = fanuc_error("#1=0\nG0 X0. Y0. Z0.\nWHILE [#1 GE 0] DO1\n#1=#1+1\nEND1\n");
    assert!(e.contains("t.nc:") && e.contains("blocks"), "{e}");
    let e = fanuc_error("G0 X0. Y0. Z0.\nEND1\n");
    assert!(e.contains("t.nc:2") && e.contains("END1 has no DO1"), "{e}");
    let e = fanuc_error("#1=5\nWHILE [#1 LT 3] DO1\nG0 X1. Y0. Z0.\n");
    assert!(e.contains("t.nc:2") && e.contains("no END1"), "{e}");
    let e = fanuc_error("G0 X0. Y0. Z0.\nGOTO 50\n");
    assert!(e.contains("t.nc:2") && e.contains("N50"), "{e}");
    let e = fanuc_error("#1=0\nIF [#1 FOO 3] GOTO 5\n");
    assert!(e.contains("t.nc:2") && e.contains("FOO"), "{e}");
    let e = fanuc_error("#1=0\nWHILE #1 LT 3 DO1\n");
    assert!(e.contains("t.nc:2") && e.contains("WHILE"), "{e}");
}

/// NX's Haas post leaves `O ENTER OP AND LAST 3 DIGITS` for the program number: the error says
/// that `O` needs one, in either dialect (it said "O-word control flow … is not supported").
#[test]
fn an_o_without_a_number_says_so() {
    let text = "%\nO ENTER OP AND LAST 3 DIGITS\nG90 G0 X0. Y0. Z1.\nM30\n%\n";
    let e = fanuc_error(text);
    assert!(e.contains("t.nc:2") && e.contains("program number"), "{e}");
    let e = message(parse(Path::new("t.ngc"), text, Dialect::LinuxCnc).unwrap_err());
    assert!(
        e.contains("t.ngc:2") && e.contains("`O` without a number"),
        "{e}"
    );
}

/// Sinumerik `FGROUP()` (HAMUEL's blade-milling posts end every operation with it) restores
/// the default feed group, F along X Y Z, which is how feedopt reads F: the program reads as
/// without it; a group with a rotary axis changes what F means and is refused, naming it.
#[test]
fn the_default_sinumerik_feed_group_is_read_and_another_is_named() {
    let plain = "G0 X0 Y0 Z0\nG1 X10 F600\nY10\n";
    let with = "FGROUP()\nG0 X0 Y0 Z0\nFGROUP(Z, Y,X)\nG1 X10 F600\nY10\nFGROUP()\n";
    let a = gcode(Dialect::Sinumerik, plain);
    let b = gcode(Dialect::Sinumerik, with);
    assert_eq!(a.points.len(), b.points.len());
    for (p, q) in a.points.iter().zip(&b.points) {
        assert_close(p.p, q.p, 0.0);
        assert_eq!(format!("{:?}", p.feed), format!("{:?}", q.feed));
    }
    assert!((feed_time(&b) - 2.0).abs() < 1e-12, "{}", feed_time(&b));
    let e = message(
        parse(
            Path::new("t.mpf"),
            "G0 X0 Y0 Z0\nFGROUP(X,Y,Z,A)\nG1 X10 A5 F600\n",
            Dialect::Sinumerik,
        )
        .unwrap_err(),
    );
    assert!(
        e.contains("t.mpf:2") && e.contains("`FGROUP(X,Y,Z,A)`") && e.contains("default"),
        "{e}"
    );
}

/// A Sinumerik frame on a rotary axis (`TRANS A=R25` in HAMUEL's posts) is refused, naming the
/// axis and what to do (it said "TRANS with A/B/C: not supported").
#[test]
fn a_frame_on_a_rotary_axis_names_the_axis_and_what_to_do() {
    let e = message(
        parse(
            Path::new("t.mpf"),
            "G0 X0 Y0 Z0\nTRANS  A=10\nG0 X1\n",
            Dialect::Sinumerik,
        )
        .unwrap_err(),
    );
    assert!(
        e.contains("t.mpf:2")
            && e.contains("`TRANS` with A")
            && e.contains("Remove it where the shift is 0"),
        "{e}"
    );
}

/// The older Siemens languages' `@` codes (`@430 K1 K1 K0 K1525`) are named as such, with what
/// feedopt reads instead (it said "unexpected character `@`").
#[test]
fn an_old_siemens_at_code_is_named() {
    for dialect in [Dialect::Sinumerik, Dialect::LinuxCnc, Dialect::Fanuc] {
        let e = message(
            parse(
                Path::new("t.nc"),
                "G0 X0 Y0 Z0\n@430 K1 K1 K0 K1525\n",
                dialect,
            )
            .unwrap_err(),
        );
        assert!(
            e.contains("t.nc:2") && e.contains("`@430`") && e.contains("840D"),
            "{e}"
        );
    }
}

/// A lathe program's `G92 S4000` (Fusion's Fanuc turning post) is named a turning program,
/// not a G92 missing its axis words.
#[test]
fn a_lathe_spindle_limit_names_a_turning_program() {
    let e = fanuc_error("%\nO1001\nG90 G94 G18\nG21\nG92 S4000\nG28 U0.\n");
    assert!(e.contains("t.nc:5") && e.contains("turning program"), "{e}");
    let e = fanuc_error("G90 G0 X0. Y0. Z0.\nG92\n");
    assert!(e.contains("t.nc:2") && e.contains("name the axes"), "{e}");
}

/// A Sinumerik R parameter read before the program sets it is taken as 0 (its value after the
/// control's reset), and the reader says so at the line of its first read, once per parameter:
/// R parameters keep their values between programs, and this one moves the tool (a post wrote
/// `TRANS X=R24-243.6` with R24 set elsewhere). One the program sets is not mentioned.
#[test]
fn an_unset_r_parameter_is_read_as_0_and_said() {
    let tp = gcode(
        Dialect::Sinumerik,
        "R2=5\nG0 X0 Y0 Z0\nTRANS X=R24-10\nG1 X=R2 Y=R24 F1000\nG1 X=R7+R24\nM30\n",
    );
    let said: Vec<&Warning> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("is read before the program sets it"))
        .collect();
    assert_eq!(said.len(), 2, "{:?}", tp.warnings);
    assert!(
        said[0].message.contains("`R24`") && said[0].line == 3,
        "{said:?}"
    );
    assert!(
        said[1].message.contains("`R7`") && said[1].line == 5,
        "{said:?}"
    );
    // Both as 0: TRANS X=R24-10 shifts X by −10, and the last point, X = R7 + R24 = 0 in
    // that frame, lies at X −10.
    let last = tp.points.last().unwrap().p;
    assert!((last.x + 10.0).abs() < 1e-9, "{last:?}");
}

/// A modulo rotary axis set to take the shorter way (`"shortest_way": true`; Sinumerik
/// MD30455 bit 2, Fanuc RAB = 0, LinuxCNC WRAPPED_ROTARY): a blade mill's spiral writes A
/// 359.499 then A 3.9768, which that A reaches by turning +4.48°, not −355.5°. Without the
/// setting the program is read as written (the sign of the difference, as a control moves an
/// axis that is not such a modulo axis), and a warning names the setting, once per axis.
#[test]
fn a_modulo_axis_set_to_the_shorter_way_continues_past_360_degrees() {
    let text = "G90 G1 X0. Y0. Z10. A350. F1000.\nX0.1 A359.499\nX0.2 A3.9768\nX0.3 A10.\nX0.4 A355.\nM30\n";
    for dialect in [Dialect::Sinumerik, Dialect::Fanuc, Dialect::LinuxCnc] {
        let a = |tp: &Toolpath| -> Vec<f64> {
            tp.points.iter().map(|p| p.rotary.unwrap()[0]).collect()
        };
        let plain = context("XYZA", Default::default(), [0.0; 3]);
        let tp = parse_for(Path::new("t.nc"), text, dialect.spec(), Some(&plain)).unwrap();
        assert_eq!(a(&tp), [350.0, 359.499, 3.9768, 10.0, 355.0], "{dialect}");
        let said: Vec<&Warning> = tp
            .warnings
            .iter()
            .filter(|w| w.message.contains("shortest_way"))
            .collect();
        // At X0.2 (−355.5°) and X0.4 (+345°), one text.
        assert_eq!(said.len(), 2, "{dialect}: {:?}", tp.warnings);
        assert_eq!(said[0].line, 3);
        assert!(said[0].message.starts_with("A: ") && said[0].message == said[1].message);

        let modulo = MachineContext {
            shortest_way: [true, false, false],
            ..plain.clone()
        };
        let tp = parse_for(Path::new("t.nc"), text, dialect.spec(), Some(&modulo)).unwrap();
        let got = a(&tp);
        // From A 0 (where the axis stands before the program) the shorter way to 350° is −10°;
        // every later position continues from there the shorter way.
        let want = [-10.0, -0.501, 3.9768, 10.0, -5.0];
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-9, "{dialect}: {got:?}");
        }
        assert!(
            tp.warnings
                .iter()
                .all(|w| !w.message.contains("shortest_way")),
            "{dialect}: {:?}",
            tp.warnings
        );
    }
}

/// On a modulo axis set to take the shorter way, Sinumerik's `A=AC(…)` still goes by the sign
/// of the difference (as AC does for a modulo axis), without the warning; `A=DC(…)` the
/// shorter way, and a plain word as the machine file says.
#[test]
fn sinumerik_ac_on_a_modulo_axis_goes_by_the_sign_of_the_difference() {
    let modulo = MachineContext {
        shortest_way: [true, false, false],
        ..context("XYZA", Default::default(), [0.0; 3])
    };
    let text = "G90 G1 X0 Y0 Z10 A359.5 F1000\nX1 A=AC(350)\nX2 A=DC(0)\nX3 A4\nM30\n";
    let tp = parse_for(
        Path::new("t.mpf"),
        text,
        Dialect::Sinumerik.spec(),
        Some(&modulo),
    )
    .unwrap();
    let a: Vec<f64> = tp.points.iter().map(|p| p.rotary.unwrap()[0]).collect();
    // From 0 the shorter way to 359.5 is −0.5; AC(350) turns +350.5 by the sign (the shorter
    // way would be −10.5); DC(0) +10 to 360; the plain A4 +4 to 364, the shorter way.
    let want = [-0.5, 350.0, 360.0, 364.0];
    assert_eq!(a.len(), want.len(), "{a:?}");
    for (g, w) in a.iter().zip(want) {
        assert!((g - w).abs() < 1e-9, "{a:?}");
    }
    assert!(
        tp.warnings
            .iter()
            .all(|w| !w.message.contains("shortest_way"))
    );
}

/// NX's SINUMERIK ONE post (round 8, LOMO's G300 A/C trunnion program) writes `C=DC(0.0)`:
/// the rotary axis to 0° the shorter way. DC, ACP (turning positive) and ACN (negative) go to
/// the position modulo 360° their way; `X=AC(…)` is absolute under G91 and `X=IC(…)`
/// incremental under G90, this word only. On a linear axis DC is refused, naming the word.
#[test]
fn sinumerik_dc_acp_acn_ac_ic_axis_words() {
    let c_after = |text: &str| -> Vec<f64> {
        let tp = gcode(Dialect::Sinumerik, text);
        tp.points.iter().map(|p| p.rotary.unwrap()[2]).collect()
    };
    let head = "G71 G90 G94\nG0 X0 Y0 Z50 A0 C350\n";
    // From 350°: DC(10) goes +20° (to 370), ACN(10) −340° (to 10), ACP(340) +350° (to 700).
    assert_eq!(
        *c_after(&format!("{head}G0 C=DC(10)\n")).last().unwrap(),
        370.0
    );
    assert_eq!(
        *c_after(&format!("{head}G0 C=ACN(10)\n")).last().unwrap(),
        10.0
    );
    assert_eq!(
        *c_after(&format!("{head}G0 C=ACP(340)\n")).last().unwrap(),
        700.0
    );
    assert_eq!(
        *c_after(&format!("{head}G0 C=DC(350.0)\n")).last().unwrap(),
        350.0
    );
    // AC under G91, IC under G90.
    let tp = gcode(
        Dialect::Sinumerik,
        "G71 G90 G94\nG0 X10 Y0 Z50\nG91 G1 X=AC(40) Y5 F1000\nG90 X=IC(5) Y0\n",
    );
    let last = tp.points.len() - 1;
    assert_close(tp.points[last].p, v(45.0, 0.0, 50.0), 1e-9);
    assert!(
        tp.points
            .iter()
            .any(|p| (p.p - v(40.0, 5.0, 50.0)).norm() < 1e-9)
    );
    let e = message(
        parse(
            Path::new("t.mpf"),
            "G71 G90\nG0 X0 Y0 Z50\nG0 X=DC(10)\n",
            Dialect::Sinumerik,
        )
        .unwrap_err(),
    );
    assert!(
        e.contains("t.mpf:3:") && e.contains("X=DC(10)") && e.contains("linear"),
        "{e}"
    );
}

/// Fusion's Fanuc turning post (system A) writes `G50 S6000`, the spindle speed limit, and
/// feeds per revolution under `G99`; with no U or W word such a program (round 9: ardikaidzal
/// 1002.nc, a facing pass `G96 S200` / `G1 X-1.6 F1.`) was read as milling, G50 as a scaling
/// cancel, F1 as 1 mm/min: 15,795 s and no error. `G50` with S or axis words now names a
/// turning program; a bare `G50` (Fanuc M, Tormach: scaling cancel) still reads.
#[test]
fn a_fanuc_g50_spindle_limit_names_a_turning_program() {
    let e = fanuc_error("%\nO01002\nG98 G18\nG21\nG50 S6000\nG53 G0 X0.\nG99\nG1 X-1.6 F1.\n");
    assert!(
        e.contains("t.nc:5") && e.contains("`G50` with S") && e.contains("turning program"),
        "{e}"
    );
    let e = fanuc_error("G21 G90\nG50 X100. Z50.\n");
    assert!(
        e.contains("t.nc:2") && e.contains("position setting"),
        "{e}"
    );
    let tp = gcode(
        Dialect::Fanuc,
        "G21 G90 G17 G40 G49 G50 G80\nG0 X1. Y2. Z3.\n",
    );
    assert_eq!(tp.points.last().unwrap().p.x, 1.0);
}

/// Round 16: a Haas/Mastercam 3-axis program retracts with `G53 G0 Z0.` (the top of Z's
/// travel) and `G28 G91 Z0.`; on a three-axis machine file the machine position was read as
/// the same program position, Z0 on the part's top face, with a warning that named no way to
/// say otherwise: the retracts (2.5 m of 8.6 m in a 767-line program) were lost. The machine
/// file's `work_offset` [x, y, z] (the program origin's machine coordinates, the G54 offset)
/// now places them, and where it is missing the warning names it.
#[test]
fn a_three_axis_machine_file_gives_the_work_offset_that_machine_positions_need() {
    use feedopt::machine::{Machine, references_from_json};
    use feedopt::toolpath::MachineContext;
    use feedopt::toolpath::gcode::{Dialect, parse_for};
    use std::path::Path;
    let json = |extra: &str| {
        format!(
            r#"{{"name": "vmc", "kinematics": {{"type": "xyz"}}{extra},
                "axes": {{"X": {{"velocity": 500, "acceleration": 3000}},
                         "Y": {{"velocity": 500, "acceleration": 3000}},
                         "Z": {{"velocity": 500, "acceleration": 3000, "reference": 0}}}}}}"#
        )
    };
    let read = |text: &str| {
        let m = Machine::from_json(Path::new("m.json"), text).unwrap();
        let refs = references_from_json(Path::new("m.json"), text, &m).unwrap();
        let ctx = MachineContext::new(&m, &refs);
        parse_for(
            Path::new("p.nc"),
            "O1000\nG90 G21 G94\nG0 X10. Y20. Z5.\nG53 G0 Z0.\nG0 X30.\nG91 G28 Z0.\nM30\n",
            Dialect::Fanuc.spec(),
            Some(&ctx),
        )
        .unwrap()
    };
    let tp = read(&json(r#", "work_offset": [-250, -200, -400]"#));
    let zs: Vec<f64> = tp.points.iter().map(|p| p.p.z).collect();
    // G53 Z0 and the G28 reference (machine Z 0) are 400 mm above the program's Z0.
    assert_eq!(zs, vec![5.0, 400.0, 400.0, 400.0], "{zs:?}");
    assert!(
        !tp.warnings
            .iter()
            .any(|w| w.message.contains("work_offset")),
        "{:?}",
        tp.warnings
    );
    // Without it: read as before (program Z0), and said, naming the field.
    let tp = read(&json(""));
    let zs: Vec<f64> = tp.points.iter().map(|p| p.p.z).collect();
    assert_eq!(zs, vec![5.0, 0.0, 0.0, 0.0], "{zs:?}");
    for line in [4, 6] {
        assert!(
            tp.warnings
                .iter()
                .any(|w| w.line == line && w.message.contains("\"work_offset\"")),
            "line {line}: {:?}",
            tp.warnings
        );
    }
    // A bad value names the field; a trunnion gives its own.
    for (extra, says) in [
        (r#", "work_offset": [0, 0]"#, "work_offset"),
        (r#", "work_offset": [0, 0, 1e9]"#, "work_offset[2]"),
        (r#", "g28_without_axes": "none""#, "g28_without_axes"),
    ] {
        let text = json(extra);
        let m = Machine::from_json(Path::new("m.json"), &text).unwrap();
        let e = references_from_json(Path::new("m.json"), &text, &m)
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{e}");
    }
    let trt = r#"{"name": "trt", "kinematics": {"type": "table_table_ac", "x-rot-point": 0,
        "y-rot-point": 0, "z-rot-point": 0, "y-offset": 0, "z-offset": 0},
        "work_offset": [0, 0, -400],
        "axes": {"X": {"velocity": 100, "acceleration": 1000},
                 "Y": {"velocity": 100, "acceleration": 1000},
                 "Z": {"velocity": 100, "acceleration": 1000},
                 "A": {"velocity": 100, "acceleration": 1000},
                 "C": {"velocity": 100, "acceleration": 1000}}}"#;
    let m = Machine::from_json(Path::new("m.json"), trt).unwrap();
    let e = references_from_json(Path::new("m.json"), trt, &m)
        .unwrap_err()
        .to_string();
    assert!(e.contains("kinematics.work-offset"), "{e}");
}

/// `G5.1 Q1` switches a Fanuc's AI contour control on (NX's Mori posts write it): its Q is no
/// length, so it is no word read in increments and says nothing; a peck's `Q2` is one.
#[test]
fn the_q_of_g5_1_is_no_length_in_increments() {
    let said = |text: &str| -> Vec<usize> {
        let m = context("XYZ", Default::default(), [0.0; 3]);
        parse_for(Path::new("t.nc"), text, Dialect::Fanuc.spec(), Some(&m))
            .unwrap()
            .warnings
            .iter()
            .filter(|w| w.message.contains("decimal point"))
            .map(|w| w.line)
            .collect()
    };
    let head = "O0001\nG21 G90 G94\nG0 X0. Y0. Z5.\n";
    assert!(said(&format!("{head}G05.1 Q1\nG1 Z-1. F100\nM30\n")).is_empty());
    assert_eq!(
        said(&format!("{head}G99 G83 Z-3. R3. Q2 F100\nG80\nM30\n")),
        [4]
    );
}
