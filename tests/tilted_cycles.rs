//! Round 21: a drilling or tapping cycle under tool-tip control with the tool tilted off Z and
//! no tilted working plane. Every reader fed such a cycle along the program's Z, the tool
//! standing at an angle to it, and `feedopt solve` timed it without a word (two NX programs:
//! G74 under G43.4 at B-54.736 on a Mori NMV5000, MCALL CYCLE84 under TRAORI at B81.101 on a
//! DMU 70 eVo). The cycles feed along the working plane's third axis (Fanuc: Zp of the selected
//! plane; LinuxCNC: "Move the Z-axis only at the current feed rate"; Sinumerik CYCLE8x and
//! Heidenhain's cycles 200–209: the plane's infeed axis); tool-tip control does not turn it,
//! and no Fanuc, Sinumerik or Heidenhain manual found says the cycle then feeds along the tool
//! instead (module doc of `toolpath::gcode::interp::cycle_axis`, /tmp/r21/FINDINGS.md). So:
//! an error naming the line, the angle and what to do on those controls; on LinuxCNC, whose
//! interpreter computes the cycle along Z before any kinematics, the path read is the one it
//! runs, with a warning. The untilted case is read as before.

mod common;

use feedopt::machine::References;
use feedopt::toolpath::gcode::{Dialect, parse_for};
use feedopt::toolpath::{Feed, MachineContext, Toolpath};
use std::path::Path;

/// The axes and feed of both B/C machines below (their kinematics apart).
const BC_AXES: &str = r#""axes": {"X": {"velocity": 500, "acceleration": 5000},
    "Y": {"velocity": 500, "acceleration": 5000},
    "Z": {"velocity": 500, "acceleration": 5000},
    "B": {"velocity": 60, "acceleration": 600, "min": -120, "max": 120},
    "C": {"velocity": 60, "acceleration": 600}},
  "feed": {"max": 2000}"#;

/// A B/C machine of `name` and `kinematics` (JSON), with [`BC_AXES`].
fn bc_machine(name: &str, kinematics: &str) -> MachineContext {
    let m = common::machine(&format!(
        r#"{{"name": "{name}", "kinematics": {kinematics}, {BC_AXES}}}"#
    ));
    MachineContext::new(&m, &References::default())
}

/// A B/C trunnion as the Mori NMV5000's machine file (B about −Y in the file's convention).
fn bc_table() -> MachineContext {
    bc_machine(
        "B/C table",
        r#"{"type": "table_table_bc", "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0,
            "x-offset": 0, "z-offset": 0, "tool-offset": 0,
            "conventional-directions": false, "work-offset": [0, 0, 0]}"#,
    )
}

/// A B head over a C table, as the DMU 70 eVo's machine file.
fn head_table() -> MachineContext {
    bc_machine(
        "B head, C table",
        r#"{"type": "head_table", "pivot_length": 200}"#,
    )
}

/// An A/C trunnion (LinuxCNC xyzac-trt).
fn ac_table() -> MachineContext {
    let m = common::machine(common::AC_TABLE);
    MachineContext::new(&m, &References::default())
}

fn read(dialect: Dialect, ctx: &MachineContext, file: &str, text: &str) -> Toolpath {
    parse_for(Path::new(file), text, dialect.spec(), Some(ctx))
        .unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn fails(dialect: Dialect, ctx: &MachineContext, file: &str, text: &str) -> String {
    match parse_for(Path::new(file), text, dialect.spec(), Some(ctx)) {
        Ok(tp) => panic!("expected an error, read {} points\n{text}", tp.points.len()),
        Err(e) => e.to_string(),
    }
}

/// The CL points fed at a programmed feed, as (x, y, z).
fn fed(tp: &Toolpath) -> Vec<[f64; 3]> {
    tp.points
        .iter()
        .filter(|p| matches!(p.feed, Feed::Programmed(_)))
        .map(|p| [p.p.x, p.p.y, p.p.z])
        .collect()
}

fn near(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9)
}

/// The Mori program's left-hand tap (lines 562–567), with the tilt `b`.
fn mori_tap(b: &str) -> String {
    format!(
        "G21 G90 G17\nG54\nG00 B{b} C135. S900 M04\nG43.4 G90 X12.216 Y0.0 H02\nZ3.\n\
         G98 G74 Z-.898 R3. F10.\nX23.109 Y2.399\nG80\nG49\nM30\n"
    )
}

/// Fanuc G74 under G43.4 with the tool 54.736° off Z: an error at the cycle's block naming the
/// cycle, the angle, the rotary positions, the tool-tip code and the tilted plane to use.
#[test]
fn fanuc_cycle_under_g43_4_with_a_tilted_tool_is_an_error_naming_the_angle() {
    let e = fails(Dialect::Fanuc, &bc_table(), "t.nc", &mori_tap("-54.736"));
    common::assert_mentions(
        &e,
        &[
            "t.nc:6:",
            "G74: a drilling or tapping cycle under tool-tip control (G43.4)",
            "54.736° off Z (B-54.736 C135)",
            "no tilted working plane",
            "no Fanuc manual",
            "post these holes under a tilted working plane (G68.2 with G53.1)",
        ],
    );
    // Haas's G234 (TCPC) alike.
    let haas = mori_tap("-54.736").replace("G43.4 G90", "G234 G90");
    let e = fails(Dialect::Fanuc, &bc_table(), "t.nc", &haas);
    assert!(
        e.contains("t.nc:6: G74:") && e.contains("tool-tip control (G234)"),
        "{e}"
    );
    // Every cycle, not only taps: G81 and the G43.5 tool vector alike.
    let text = "G21 G90 G17\nG43.5 X0 Y0 Z10 I0 J-1 K1 H1\nG99 G81 X5 Y0 Z-2 R2 F100\nG80\nM30\n";
    let e = fails(Dialect::Fanuc, &head_table(), "t.nc", text);
    assert!(
        e.contains("t.nc:3: G81:")
            && e.contains("(G43.5)")
            && e.contains("45.000° off Z (tool vector 0, -0.707106781, 0.707106781)"),
        "{e}"
    );
}

/// The untilted case is read as before: the table turned about the vertical tool (C135, B0),
/// the tap fed straight down along Z from R to the bottom at each hole.
#[test]
fn fanuc_cycle_under_g43_4_with_the_tool_along_z_reads_as_before() {
    let tp = read(Dialect::Fanuc, &bc_table(), "t.nc", &mori_tap("0.0"));
    let fed = fed(&tp);
    let want = [
        [12.216, 0.0, -0.898],
        [12.216, 0.0, 3.0],
        [23.109, 2.399, -0.898],
        [23.109, 2.399, 3.0],
    ];
    assert_eq!(fed.len(), want.len(), "{fed:?}");
    assert!(fed.iter().zip(want).all(|(a, b)| near(*a, b)), "{fed:?}");
    assert_eq!(tp.taps.len(), 2);
    assert!(tp.warnings.iter().all(|w| !w.message.contains("off Z")));
}

/// Sinumerik MCALL CYCLE84 under TRAORI with the B head at 81.101° (the DMU program, N895–
/// N904 in mm): an error at the first block the modal call runs at; a plain CYCLE81 call the
/// same; with the head at B0 both read as before.
#[test]
fn sinumerik_cycle_under_traori_with_a_tilted_tool_is_an_error() {
    let mcall = |b: &str| {
        format!(
            "G71 G90 G17 G94\nG0 B{b}\nG0 C30\nTRAORI\nG0 X-7.849 Y-36.573 Z46.3 S900 M4\n\
             F10\nMCALL CYCLE84(3,43.3,3,42.4,,,,,,,)\nX2.713 Y-40.16\nMCALL\nTRAFOOF\nM30\n"
        )
    };
    let e = fails(Dialect::Sinumerik, &head_table(), "t.mpf", &mcall("81.101"));
    common::assert_mentions(
        &e,
        &[
            "t.mpf:8: MCALL CYCLE84: a drilling or tapping cycle under tool-tip control (TRAORI)",
            "81.101° off Z (B81.101 C30)",
            "no Sinumerik manual",
            "(CYCLE800)",
        ],
    );
    let tp = read(Dialect::Sinumerik, &head_table(), "t.mpf", &mcall("0"));
    assert_eq!(tp.taps.len(), 1);
    assert!(near(fed(&tp)[0], [2.713, -40.16, 42.4]), "{:?}", fed(&tp));

    let call = |b: &str| {
        format!(
            "G71 G90 G17 G94\nG0 B{b}\nTRAORI\nG0 X10 Y0 Z20 S900 M3\nF100\n\
             CYCLE81(10,0,2,-5,)\nTRAFOOF\nM30\n"
        )
    };
    let e = fails(Dialect::Sinumerik, &head_table(), "t.mpf", &call("30"));
    assert!(
        e.contains("t.mpf:6: CYCLE81:") && e.contains("30.000° off Z (B30)"),
        "{e}"
    );
    let tp = read(Dialect::Sinumerik, &head_table(), "t.mpf", &call("0"));
    assert!(near(fed(&tp)[0], [10.0, 0.0, -5.0]), "{:?}", fed(&tp));
}

/// Heidenhain cycle 200 called under M128 (or FUNCTION TCPM) with the head at B+30: an error
/// naming the cycle and PLANE; at B+0 the cycle's moves are as before.
#[test]
fn heidenhain_cycle_under_m128_with_a_tilted_tool_is_an_error() {
    let text = |b: &str| {
        format!(
            "0 BEGIN PGM T MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-20\n2 BLK FORM 0.2 X+100 Y+100 Z+0\n\
             3 TOOL CALL 1 Z S5000\n4 L X+0 Y+0 Z+50 B+0 C+0 R0 FMAX\n5 M128\n\
             6 L B{b} FMAX\n7 L X+10 Y+0 Z+20 FMAX\n\
             8 CYCL DEF 200 DRILLING ~\n  Q200=+2 ;SET-UP CLEARANCE ~\n  Q201=-10 ;DEPTH ~\n\
             Q206=+120 ;FEED RATE FOR PLNGNG ~\n  Q202=+10 ;PLUNGING DEPTH ~\n\
             Q210=+0 ;DWELL TIME AT TOP ~\n  Q203=+0 ;SURFACE COORDINATE ~\n\
             Q204=+20 ;2ND SET-UP CLEARANCE ~\n  Q211=+0 ;DWELL TIME AT DEPTH\n\
             9 CYCL CALL\n10 M129\n11 END PGM T MM\n"
        )
    };
    let e = fails(Dialect::Heidenhain, &head_table(), "t.h", &text("+30"));
    common::assert_mentions(
        &e,
        &[
            "t.h:18: cycle 200: a drilling or tapping cycle under tool-tip control (M128)",
            "30.000° off Z (B30)",
            "no Heidenhain manual",
            "(PLANE … TURN, or cycle 19)",
        ],
    );
    // FUNCTION TCPM alike, named so.
    let tcpm = text("+30").replace("5 M128", "5 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS");
    let e = fails(Dialect::Heidenhain, &head_table(), "t.h", &tcpm);
    assert!(
        e.contains("t.h:18: cycle 200:") && e.contains("tool-tip control (FUNCTION TCPM)"),
        "{e}"
    );
    let tp = read(Dialect::Heidenhain, &head_table(), "t.h", &text("+0"));
    assert!(near(fed(&tp)[0], [10.0, 0.0, -10.0]), "{:?}", fed(&tp));
}

/// LinuxCNC G81 under M428 with the table tilted 30°: its interpreter feeds the program's Z
/// (the path read, unchanged), with one warning naming the angle.
#[test]
fn linuxcnc_cycle_under_tcp_with_a_tilted_tool_is_read_along_z_with_a_warning() {
    let text = "G21 G90 G94 G17\nG0 X0 Y0 Z20 A0 C0\nM428\nG0 A30\n\
                G98 G81 X10 Y0 Z-5 R2 F100\nX20\nG80\nM429\nM2\n";
    let tp = read(Dialect::LinuxCnc, &ac_table(), "t.ngc", text);
    let fed = fed(&tp);
    assert!(
        fed.len() == 2 && near(fed[0], [10.0, 0.0, -5.0]) && near(fed[1], [20.0, 0.0, -5.0]),
        "{fed:?}"
    );
    let said: Vec<_> = tp
        .warnings
        .iter()
        .filter(|w| w.message.contains("off Z"))
        .collect();
    assert!(
        !said.is_empty()
            && said[0].line == 5
            && said[0].message.contains(
                "G81: under tool-tip control (M428) the tool axis stands 30.000° off Z (A30)"
            )
            && said[0].message.contains("feeds along the program's Z"),
        "{:?}",
        tp.warnings
    );
    // The tool along Z: no warning.
    let tp = read(
        Dialect::LinuxCnc,
        &ac_table(),
        "t.ngc",
        &text.replace("G0 A30", "G0 C30"),
    );
    assert!(tp.warnings.iter().all(|w| !w.message.contains("off Z")));
}
