//! Tests of machine files (`feedopt::machine::Machine::from_json`): what a valid file gives and
//! that every invalid one is rejected with the exact dotted field and a message saying what is
//! wrong.

use feedopt::error::Error;
use feedopt::machine::{
    AxisKind, KinematicsSpec, Limit, Machine, RotaryTable, TrunnionParams, TrunnionTilt,
};
use std::path::Path;

const FILE: &str = "machines/test_machine.json";

fn parse(text: &str) -> Result<Machine, Error> {
    Machine::from_json(Path::new(FILE), text)
}

fn ok(text: &str) -> Machine {
    match parse(text) {
        Ok(m) => m,
        Err(e) => panic!("unexpected error: {e}\n--- input ---\n{text}"),
    }
}

/// Asserts an `Error::Field` for exactly `field` whose message contains every one of `needles`
/// (case-insensitive); returns the error for further checks.
fn field_err(text: &str, field: &str, needles: &[&str]) -> Error {
    match parse(text) {
        Ok(m) => panic!("expected an error on `{field}`, got {m:?}\n--- input ---\n{text}"),
        Err(e) => {
            match &e {
                Error::Field {
                    file,
                    field: got,
                    message,
                } => {
                    assert_eq!(file, Path::new(FILE));
                    assert_eq!(got, field, "wrong field (message `{message}`)");
                    let lower = message.to_lowercase();
                    for needle in needles {
                        assert!(
                            lower.contains(&needle.to_lowercase()),
                            "message `{message}` for `{field}` does not mention `{needle}`"
                        );
                    }
                }
                other => panic!("expected Error::Field on `{field}`, got {other:?}"),
            }
            e
        }
    }
}

/// A valid xyz machine with `axis_x` as the X axis object (no feed section).
fn xyz_with_x(axis_x: &str) -> String {
    format!(
        r#"{{"name": "xyz", "kinematics": {{"type": "xyz"}},
            "axes": {{"X": {axis_x},
                      "Y": {{"velocity": 300, "acceleration": 1500}},
                      "Z": {{"velocity": 200, "acceleration": 1000}}}}}}"#
    )
}

/// A valid xyz machine with `axis_y` as the Y axis object.
fn xyz_with_y(axis_y: &str) -> String {
    format!(
        r#"{{"name": "xyz", "kinematics": {{"type": "xyz"}},
            "axes": {{"X": {{"velocity": 400, "acceleration": 2000}},
                      "Y": {axis_y},
                      "Z": {{"velocity": 200, "acceleration": 1000}}}}}}"#
    )
}

const XYZ_AXES: &str = r#"{"X": {"velocity": 400, "acceleration": 2000},
                          "Y": {"velocity": 300, "acceleration": 1500},
                          "Z": {"velocity": 200, "acceleration": 1000}}"#;

const HEAD_HEAD_AXES: &str = r#"{"X": {"velocity": 400, "acceleration": 2000},
                                "Y": {"velocity": 400, "acceleration": 2000},
                                "Z": {"velocity": 300, "acceleration": 1500},
                                "C": {"velocity": 120, "acceleration": 600},
                                "A": {"velocity": 60, "acceleration": 400}}"#;

fn head_head(kinematics: &str, feed: &str) -> String {
    format!(r#"{{"name": "hh", "kinematics": {kinematics}, "axes": {HEAD_HEAD_AXES}{feed}}}"#)
}

// ---------------------------------------------------------------------------------------------
// Valid files
// ---------------------------------------------------------------------------------------------

#[test]
fn valid_head_head() {
    // Axes deliberately listed out of order: the machine keeps the kinematics' order.
    let m = ok(r#"{
        "name": "seed double swivel head",
        "kinematics": {"type": "head_head", "tool_length": 200.0},
        "axes": {
            "A": {"velocity": 60, "acceleration": [-300, 400]},
            "C": {"velocity": 120, "acceleration": 600},
            "Z": {"velocity": [-250.5, 300], "acceleration": 1500},
            "Y": {"velocity": 400, "acceleration": 2000},
            "X": {"velocity": 410.5, "acceleration": 2100}
        },
        "feed": {"max": 150}
    }"#);
    assert_eq!(m.name, "seed double swivel head");
    assert_eq!(
        m.kinematics,
        KinematicsSpec::HeadHead { tool_length: 200.0 }
    );
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z", "C", "A"]);
    let kinds: Vec<AxisKind> = m.axes.iter().map(|a| a.kind).collect();
    assert_eq!(
        kinds,
        [
            AxisKind::Linear,
            AxisKind::Linear,
            AxisKind::Linear,
            AxisKind::Rotary,
            AxisKind::Rotary
        ]
    );
    // Symmetric numbers become [-v, v].
    assert_eq!(
        m.axes[0].velocity,
        Limit {
            min: -410.5,
            max: 410.5
        }
    );
    assert_eq!(
        m.axes[0].acceleration,
        Limit {
            min: -2100.0,
            max: 2100.0
        }
    );
    assert_eq!(
        m.axes[3].velocity,
        Limit {
            min: -120.0,
            max: 120.0
        }
    );
    assert_eq!(
        m.axes[3].acceleration,
        Limit {
            min: -600.0,
            max: 600.0
        }
    );
    // Asymmetric [min, max] is kept as written.
    assert_eq!(
        m.axes[2].velocity,
        Limit {
            min: -250.5,
            max: 300.0
        }
    );
    assert_eq!(
        m.axes[4].acceleration,
        Limit {
            min: -300.0,
            max: 400.0
        }
    );
    assert_eq!(m.axes[4].velocity, Limit::symmetric(60.0));
    assert_eq!(m.feed_max, Some(150.0));
    // No travel given: none stored.
    assert!(m.axes.iter().all(|a| a.travel.is_none()));
}

#[test]
fn valid_xyz_without_feed_section() {
    let m = ok(&format!(
        r#"{{"name": "router", "kinematics": {{"type": "xyz"}}, "axes": {XYZ_AXES}}}"#
    ));
    assert_eq!(m.name, "router");
    assert_eq!(m.kinematics, KinematicsSpec::Xyz);
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z"]);
    assert!(m.axes.iter().all(|a| a.kind == AxisKind::Linear));
    assert_eq!(m.axes[0].velocity, Limit::symmetric(400.0));
    assert_eq!(m.axes[1].acceleration, Limit::symmetric(1500.0));
    assert_eq!(
        m.axes[2].velocity,
        Limit {
            min: -200.0,
            max: 200.0
        }
    );
    assert_eq!(m.feed_max, None);
}

#[test]
fn valid_xyz_with_feed_and_without_name() {
    let m = ok(&format!(
        r#"{{"kinematics": {{"type": "xyz"}}, "axes": {XYZ_AXES}, "feed": {{"max": 83.5}}}}"#
    ));
    assert_eq!(m.name, "");
    assert_eq!(m.feed_max, Some(83.5));
}

// ---------------------------------------------------------------------------------------------
// Axes and limits
// ---------------------------------------------------------------------------------------------

#[test]
fn missing_axis() {
    let text = r#"{"kinematics": {"type": "head_head", "tool_length": 200},
        "axes": {"X": {"velocity": 400, "acceleration": 2000},
                 "Y": {"velocity": 400, "acceleration": 2000},
                 "Z": {"velocity": 300, "acceleration": 1500},
                 "A": {"velocity": 60, "acceleration": 400}}}"#;
    field_err(text, "axes.C", &["missing"]);
}

#[test]
fn missing_axes_section() {
    field_err(r#"{"kinematics": {"type": "xyz"}}"#, "axes", &["missing"]);
}

#[test]
fn missing_limit() {
    field_err(
        &xyz_with_x(r#"{"velocity": 400}"#),
        "axes.X.acceleration",
        &["missing"],
    );
    field_err(
        &xyz_with_y(r#"{"acceleration": 400}"#),
        "axes.Y.velocity",
        &["missing"],
    );
}

#[test]
fn negative_limit() {
    field_err(
        &xyz_with_y(r#"{"velocity": -5, "acceleration": 1500}"#),
        "axes.Y.velocity",
        &["positive", "-5"],
    );
}

#[test]
fn zero_limit() {
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 0}"#),
        "axes.X.acceleration",
        &["positive", "0"],
    );
    field_err(
        &xyz_with_y(r#"{"velocity": 0.0, "acceleration": 1500}"#),
        "axes.Y.velocity",
        &["positive"],
    );
}

#[test]
fn limit_of_wrong_type() {
    field_err(
        &xyz_with_x(r#"{"velocity": "400", "acceleration": 2000}"#),
        "axes.X.velocity",
        &["number"],
    );
    field_err(
        &xyz_with_x(r#"{"velocity": null, "acceleration": 2000}"#),
        "axes.X.velocity",
        &["number"],
    );
}

#[test]
fn min_max_with_nonnegative_min() {
    for pair in ["[0, 500]", "[10, 500]"] {
        field_err(
            &xyz_with_x(&format!(r#"{{"velocity": {pair}, "acceleration": 2000}}"#)),
            "axes.X.velocity",
            &["min < 0 < max"],
        );
    }
    // The message repeats what was found.
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": [10, 2000]}"#),
        "axes.X.acceleration",
        &["min < 0 < max", "10", "2000"],
    );
}

#[test]
fn min_max_with_nonpositive_max() {
    for pair in ["[-500, 0]", "[-500, -10]"] {
        field_err(
            &xyz_with_y(&format!(r#"{{"velocity": {pair}, "acceleration": 1500}}"#)),
            "axes.Y.velocity",
            &["min < 0 < max"],
        );
    }
    // Reversed order (max first) is not silently accepted either.
    field_err(
        &xyz_with_y(r#"{"velocity": 300, "acceleration": [1500, -1500]}"#),
        "axes.Y.acceleration",
        &["min < 0 < max", "1500", "-1500"],
    );
}

#[test]
fn min_max_of_wrong_shape() {
    for bad in ["[-1, 2, 3]", "[5]", "[]", r#"[-1, "2"]"#] {
        field_err(
            &xyz_with_x(&format!(r#"{{"velocity": {bad}, "acceleration": 2000}}"#)),
            "axes.X.velocity",
            &["[min, max]"],
        );
    }
}

#[test]
fn unknown_field_inside_axis() {
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 2000, "jerk_typo": 1}"#),
        "axes.X.jerk_typo",
        &["unknown field", "velocity", "acceleration"],
    );
}

#[test]
fn axis_that_is_not_an_object() {
    field_err(&xyz_with_x("400"), "axes.X", &["object"]);
}

#[test]
fn unknown_axis_for_the_kinematics() {
    let text = r#"{"kinematics": {"type": "xyz"},
        "axes": {"X": {"velocity": 400, "acceleration": 2000},
                 "Y": {"velocity": 400, "acceleration": 2000},
                 "Z": {"velocity": 300, "acceleration": 1500},
                 "B": {"velocity": 60, "acceleration": 400}}}"#;
    // The message should say which axes this kinematics has.
    field_err(text, "axes.B", &["unknown", "X", "Y", "Z"]);
    // A rotary axis on a 3-axis machine is unknown too.
    let text = r#"{"kinematics": {"type": "xyz"},
        "axes": {"X": {"velocity": 400, "acceleration": 2000},
                 "Y": {"velocity": 400, "acceleration": 2000},
                 "Z": {"velocity": 300, "acceleration": 1500},
                 "C": {"velocity": 60, "acceleration": 400}}}"#;
    field_err(text, "axes.C", &["unknown"]);
}

// ---------------------------------------------------------------------------------------------
// Top level, kinematics, feed
// ---------------------------------------------------------------------------------------------

#[test]
fn unknown_top_level_field() {
    let text =
        format!(r#"{{"kinematics": {{"type": "xyz"}}, "axes": {XYZ_AXES}, "colour": "red"}}"#);
    field_err(&text, "colour", &["unknown field", "kinematics", "axes"]);
}

#[test]
fn top_level_not_an_object() {
    match parse("[1, 2, 3]") {
        Err(Error::Field { message, .. }) => {
            assert!(message.contains("object"), "message: {message}")
        }
        other => panic!("expected a field error, got {other:?}"),
    }
}

#[test]
fn name_not_a_string() {
    let text = format!(r#"{{"name": 5, "kinematics": {{"type": "xyz"}}, "axes": {XYZ_AXES}}}"#);
    field_err(&text, "name", &["string"]);
}

#[test]
fn missing_kinematics() {
    field_err(
        &format!(r#"{{"axes": {XYZ_AXES}}}"#),
        "kinematics",
        &["missing"],
    );
    field_err(
        &format!(r#"{{"kinematics": {{}}, "axes": {XYZ_AXES}}}"#),
        "kinematics.type",
        &["missing"],
    );
}

#[test]
fn unknown_kinematics_type() {
    let e = field_err(
        &head_head(r#"{"type": "table_table", "tool_length": 200}"#, ""),
        "kinematics.type",
        &["unknown kinematics", "table_table", "xyz", "head_head"],
    );
    assert!(e.to_string().contains("kinematics.type"));
    field_err(
        &format!(r#"{{"kinematics": {{"type": 3}}, "axes": {XYZ_AXES}}}"#),
        "kinematics.type",
        &["unknown kinematics"],
    );
}

#[test]
fn head_head_without_tool_length() {
    field_err(
        &head_head(r#"{"type": "head_head"}"#, ""),
        "kinematics.tool_length",
        &["missing"],
    );
}

#[test]
fn head_head_with_nonpositive_tool_length() {
    field_err(
        &head_head(r#"{"type": "head_head", "tool_length": -200}"#, ""),
        "kinematics.tool_length",
        &["positive", "-200"],
    );
    field_err(
        &head_head(r#"{"type": "head_head", "tool_length": 0}"#, ""),
        "kinematics.tool_length",
        &["positive"],
    );
}

#[test]
fn unknown_field_in_kinematics() {
    // tool_length means nothing to an xyz machine.
    field_err(
        &format!(r#"{{"kinematics": {{"type": "xyz", "tool_length": 200}}, "axes": {XYZ_AXES}}}"#),
        "kinematics.tool_length",
        &["unknown field"],
    );
}

#[test]
fn nonpositive_feed_max() {
    let hh = r#"{"type": "head_head", "tool_length": 200}"#;
    field_err(
        &head_head(hh, r#", "feed": {"max": 0}"#),
        "feed.max",
        &["positive", "0"],
    );
    field_err(
        &head_head(hh, r#", "feed": {"max": -150}"#),
        "feed.max",
        &["positive", "-150"],
    );
    // A feed section must say its max.
    field_err(&head_head(hh, r#", "feed": {}"#), "feed.max", &["missing"]);
    field_err(
        &head_head(hh, r#", "feed": {"max": 150, "min": 1}"#),
        "feed.min",
        &["unknown field"],
    );
    // And the whole head_head file is otherwise valid.
    let m = ok(&head_head(hh, r#", "feed": {"max": 150}"#));
    assert_eq!(m.feed_max, Some(150.0));
    assert_eq!(m.axes.len(), 5);
}

// ---------------------------------------------------------------------------------------------
// JSON syntax and Display
// ---------------------------------------------------------------------------------------------

#[test]
fn invalid_json_names_the_line() {
    // Missing comma after line 3's value: the error is found on line 4.
    let text = "{\n  \"name\": \"m\",\n  \"kinematics\": {\"type\": \"xyz\"}\n  \"axes\": {}\n}\n";
    match parse(text) {
        Err(Error::Parse {
            file,
            line,
            message,
        }) => {
            assert_eq!(file, Path::new(FILE));
            assert_eq!(line, 4, "message: {message}");
            assert!(
                message.to_lowercase().contains("json"),
                "message: {message}"
            );
        }
        other => panic!("expected Error::Parse, got {other:?}"),
    }
    // Truncated file: the error is at the last line.
    let text = "{\n  \"name\": \"m\",\n  \"axes\": {\n";
    match parse(text) {
        Err(Error::Parse { line, .. }) => assert_eq!(line, 4),
        other => panic!("expected Error::Parse, got {other:?}"),
    }
    // Trailing comma on line 2.
    let text = "{\"kinematics\": {\"type\": \"xyz\"},\n \"axes\": {},\n}";
    let e = parse(text).expect_err("trailing comma must be rejected");
    assert!(
        matches!(e, Error::Parse { line: 3, .. }),
        "expected Error::Parse on line 3, got {e:?}"
    );
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("{FILE}:3: ")),
        "display: {shown}"
    );
}

#[test]
fn field_error_display_starts_with_file_and_names_field() {
    let e = field_err(
        &xyz_with_y(r#"{"velocity": -5, "acceleration": 1500}"#),
        "axes.Y.velocity",
        &[],
    );
    let shown = e.to_string();
    assert!(shown.starts_with(FILE), "display: {shown}");
    assert!(shown.contains("axes.Y.velocity"), "display: {shown}");
    assert!(shown.contains("-5"), "display: {shown}");
    assert!(!shown.contains('\n'), "display spans lines: {shown}");
}

#[test]
fn from_file_reads_and_names_missing_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.json");
    std::fs::write(
        &path,
        format!(r#"{{"kinematics": {{"type": "xyz"}}, "axes": {XYZ_AXES}}}"#),
    )
    .unwrap();
    let m = Machine::from_file(&path).unwrap();
    assert_eq!(m.axes.len(), 3);

    let missing = dir.path().join("nope.json");
    match Machine::from_file(&missing) {
        Err(e @ Error::Io { .. }) => {
            assert!(
                e.to_string().starts_with(&missing.display().to_string()),
                "display: {e}"
            );
        }
        other => panic!("expected Error::Io, got {other:?}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Trunnion (LinuxCNC xyzac-trt / xyzbc-trt), head_table, dresser; axis travel
// ---------------------------------------------------------------------------------------------

/// Five axes X Y Z plus `tilt` and C, with travel on every axis.
fn five_axes(tilt: &str) -> String {
    format!(
        r#"{{"X": {{"velocity": 20, "acceleration": 300, "min": -200, "max": 200}},
            "Y": {{"velocity": 20, "acceleration": 300, "min": -100, "max": 100}},
            "Z": {{"velocity": 20, "acceleration": 300, "min": -120, "max": 120}},
            "{tilt}": {{"velocity": 30, "acceleration": 300, "min": -100, "max": 50}},
            "C": {{"velocity": 30, "acceleration": 300, "min": -36000, "max": 36000}}}}"#
    )
}

fn with_kinematics(kinematics: &str, axes: &str) -> String {
    format!(r#"{{"name": "m", "kinematics": {kinematics}, "axes": {axes}}}"#)
}

const AC_FULL: &str = r#"{"type": "table_table_ac",
    "x-rot-point": 1.5, "y-rot-point": -2.0, "z-rot-point": 3.25,
    "y-offset": 20.0, "z-offset": 10.0, "tool-offset": 7.5,
    "conventional-directions": true, "work-offset": [0.5, -0.25, 13.25]}"#;

const BC_REQUIRED: &str = r#"{"type": "table_table_bc",
    "x-rot-point": 0, "y-rot-point": 0, "z-rot-point": 0,
    "x-offset": -20, "z-offset": -15}"#;

#[test]
fn valid_table_table_ac_with_every_parameter() {
    let m = ok(&with_kinematics(AC_FULL, &five_axes("A")));
    assert_eq!(
        m.kinematics,
        KinematicsSpec::TableTable {
            tilt: TrunnionTilt::A,
            params: TrunnionParams {
                rot_point: [1.5, -2.0, 3.25],
                tilt_offset: 20.0,
                z_offset: 10.0,
                tool_offset: 7.5,
                conventional_directions: true,
                work_offset: [0.5, -0.25, 13.25],
            }
        }
    );
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z", "A", "C"]);
    let kinds: Vec<AxisKind> = m.axes.iter().map(|a| a.kind).collect();
    assert_eq!(
        kinds,
        [
            AxisKind::Linear,
            AxisKind::Linear,
            AxisKind::Linear,
            AxisKind::Rotary,
            AxisKind::Rotary
        ]
    );
    assert_eq!(m.axes[0].travel, Some((-200.0, 200.0)));
    assert_eq!(m.axes[3].travel, Some((-100.0, 50.0)));
    assert_eq!(m.axes[4].travel, Some((-36000.0, 36000.0)));
    assert!(m.axes[3].within_travel(50.0) && m.axes[3].within_travel(-100.0));
    assert!(!m.axes[3].within_travel(50.001) && !m.axes[3].within_travel(-100.5));
}

#[test]
fn valid_table_table_bc_defaults_the_optional_parameters() {
    let m = ok(&with_kinematics(BC_REQUIRED, &five_axes("B")));
    assert_eq!(
        m.kinematics,
        KinematicsSpec::TableTable {
            tilt: TrunnionTilt::B,
            params: TrunnionParams {
                rot_point: [0.0; 3],
                tilt_offset: -20.0,
                z_offset: -15.0,
                tool_offset: 0.0,
                conventional_directions: false,
                work_offset: [0.0; 3],
            }
        }
    );
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z", "B", "C"]);
}

#[test]
fn valid_table_table_ab_takes_the_ac_parameters_and_axes_x_y_z_a_b() {
    let ab_axes = five_axes("A").replace("\"C\":", "\"B\":");
    let ab = AC_FULL.replace("table_table_ac", "table_table_ab");
    let m = ok(&with_kinematics(&ab, &ab_axes));
    let KinematicsSpec::TableTable { tilt, params } = m.kinematics else {
        panic!("{:?}", m.kinematics)
    };
    assert_eq!(tilt, TrunnionTilt::AB);
    let ac = ok(&with_kinematics(AC_FULL, &five_axes("A")));
    assert_eq!(
        ac.kinematics,
        KinematicsSpec::TableTable {
            tilt: TrunnionTilt::A,
            params
        }
    );
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z", "A", "B"]);
    assert!(m.axes[3..].iter().all(|a| a.kind == AxisKind::Rotary));
    assert_eq!(m.axes[4].travel, Some((-36000.0, 36000.0)));
    // Its tilt axis is placed by y-offset, as xyzac-trt's; an A/C axis set is the wrong machine.
    let with_x = ab.replace("\"y-offset\": 20.0", "\"x-offset\": 20.0");
    field_err(
        &with_kinematics(&with_x, &ab_axes),
        "kinematics.x-offset",
        &["unknown field", "y-offset"],
    );
    field_err(
        &with_kinematics(&ab, &five_axes("A")),
        "axes.C",
        &["unknown field", "B"],
    );
}

#[test]
fn valid_head_table_and_dresser() {
    let m = ok(&with_kinematics(
        r#"{"type": "head_table", "pivot_length": 150}"#,
        &five_axes("B"),
    ));
    assert_eq!(
        m.kinematics,
        KinematicsSpec::HeadTable {
            pivot_length: 150.0,
            table: RotaryTable::C,
        }
    );
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z", "B", "C"]);

    // With table A (a blade mill's rotary axis about X): X Y Z A B.
    let axes = five_axes("B").replace("\"C\"", "\"A\"");
    let m = ok(&with_kinematics(
        r#"{"type": "head_table", "pivot_length": 150, "table": "A"}"#,
        &axes,
    ));
    assert_eq!(
        m.kinematics,
        KinematicsSpec::HeadTable {
            pivot_length: 150.0,
            table: RotaryTable::A,
        }
    );
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z", "A", "B"]);
    field_err(
        &with_kinematics(
            r#"{"type": "head_table", "pivot_length": 150, "table": "B"}"#,
            &axes,
        ),
        "kinematics.table",
        &["\"C\"", "\"A\"", "about X"],
    );

    // The dresser: X Z B, in that order whatever the file's order; a zero tool length (tip on
    // the B axis) is allowed.
    let m = ok(&with_kinematics(
        r#"{"type": "dresser", "tool_length": 0}"#,
        r#"{"B": {"velocity": 90, "acceleration": 500, "min": -135, "max": 135},
            "Z": {"velocity": 50, "acceleration": 400},
            "X": {"velocity": 50, "acceleration": 400}}"#,
    ));
    assert_eq!(m.kinematics, KinematicsSpec::Dresser { tool_length: 0.0 });
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Z", "B"]);
    assert_eq!(m.axes[2].kind, AxisKind::Rotary);
    assert_eq!(m.axes[2].travel, Some((-135.0, 135.0)));
    assert_eq!(m.axes[0].travel, None);
}

#[test]
fn unknown_kinematics_type_lists_the_new_types() {
    field_err(
        &with_kinematics(r#"{"type": "table_table_ca"}"#, &five_axes("A")),
        "kinematics.type",
        &[
            "table_table_ca",
            "table_table_ab",
            "table_table_ac",
            "table_table_bc",
            "head_table",
            "dresser",
        ],
    );
}

#[test]
fn trunnion_unknown_parameters_are_named() {
    // xyzac-trt has no x-offset (its A axis is placed by y-offset), xyzbc-trt no y-offset.
    let ac = AC_FULL.replace("\"y-offset\": 20.0", "\"x-offset\": 20.0");
    field_err(
        &with_kinematics(&ac, &five_axes("A")),
        "kinematics.x-offset",
        &["unknown field", "y-offset"],
    );
    let bc = BC_REQUIRED.replace("\"z-offset\"", "\"y-offset\": 1, \"z-offset\"");
    field_err(
        &with_kinematics(&bc, &five_axes("B")),
        "kinematics.y-offset",
        &["unknown field", "x-offset"],
    );
    // Underscored spellings are not LinuxCNC's pin names.
    let ac = AC_FULL.replace("\"tool-offset\"", "\"tool_offset\"");
    field_err(
        &with_kinematics(&ac, &five_axes("A")),
        "kinematics.tool_offset",
        &["unknown field", "tool-offset"],
    );
    field_err(
        &with_kinematics(
            r#"{"type": "head_table", "pivot_length": 150, "tool_length": 5}"#,
            &five_axes("B"),
        ),
        "kinematics.tool_length",
        &["unknown field", "pivot_length"],
    );
    field_err(
        &with_kinematics(
            r#"{"type": "dresser", "tool_length": 5, "pivot_length": 5}"#,
            r#"{"X": {"velocity": 1, "acceleration": 1}, "Z": {"velocity": 1, "acceleration": 1},
                "B": {"velocity": 1, "acceleration": 1}}"#,
        ),
        "kinematics.pivot_length",
        &["unknown field"],
    );
}

#[test]
fn trunnion_missing_parameters_are_named() {
    for (field, text) in [
        ("z-offset", BC_REQUIRED.replace(", \"z-offset\": -15", "")),
        ("x-offset", BC_REQUIRED.replace("\"x-offset\": -20,", "")),
        (
            "y-rot-point",
            BC_REQUIRED.replace("\"y-rot-point\": 0,", ""),
        ),
        ("y-offset", AC_FULL.replace("\"y-offset\": 20.0,", "")),
    ] {
        let tilt = if text.contains("_ac") { "A" } else { "B" };
        field_err(
            &with_kinematics(&text, &five_axes(tilt)),
            &format!("kinematics.{field}"),
            &["missing"],
        );
    }
    field_err(
        &with_kinematics(r#"{"type": "head_table"}"#, &five_axes("B")),
        "kinematics.pivot_length",
        &["missing"],
    );
    field_err(
        &with_kinematics(
            r#"{"type": "dresser"}"#,
            r#"{"X": {"velocity": 1, "acceleration": 1}, "Z": {"velocity": 1, "acceleration": 1},
                "B": {"velocity": 1, "acceleration": 1}}"#,
        ),
        "kinematics.tool_length",
        &["missing"],
    );
}

#[test]
fn trunnion_parameters_of_the_wrong_type() {
    let ac = AC_FULL.replace(
        "\"conventional-directions\": true",
        "\"conventional-directions\": 1",
    );
    field_err(
        &with_kinematics(&ac, &five_axes("A")),
        "kinematics.conventional-directions",
        &["true or false"],
    );
    for bad in ["[0, 0]", "[0, 0, \"1\"]", "13.25", "[0, 0, 0, 0]"] {
        let ac = AC_FULL.replace("[0.5, -0.25, 13.25]", bad);
        field_err(
            &with_kinematics(&ac, &five_axes("A")),
            "kinematics.work-offset",
            &["[x, y, z]"],
        );
    }
    let ac = AC_FULL.replace("\"z-offset\": 10.0", "\"z-offset\": \"10\"");
    field_err(
        &with_kinematics(&ac, &five_axes("A")),
        "kinematics.z-offset",
        &["number"],
    );
    field_err(
        &with_kinematics(
            r#"{"type": "head_table", "pivot_length": -1}"#,
            &five_axes("B"),
        ),
        "kinematics.pivot_length",
        &["zero or positive", "-1"],
    );
}

#[test]
fn trunnion_axes_follow_the_tilt() {
    // An AC machine with a B axis: B is unknown, and A is missing.
    field_err(
        &with_kinematics(AC_FULL, &five_axes("B")),
        "axes.B",
        &["unknown", "A", "C"],
    );
    let axes = r#"{"X": {"velocity": 1, "acceleration": 1}, "Y": {"velocity": 1, "acceleration": 1},
        "Z": {"velocity": 1, "acceleration": 1}, "C": {"velocity": 1, "acceleration": 1}}"#;
    field_err(&with_kinematics(AC_FULL, axes), "axes.A", &["missing"]);
}

#[test]
fn travel_min_must_be_below_max() {
    for (min, max) in [("50", "50"), ("60", "50")] {
        field_err(
            &xyz_with_x(&format!(
                r#"{{"velocity": 400, "acceleration": 2000, "min": {min}, "max": {max}}}"#
            )),
            "axes.X.min",
            &["less than max", min, max],
        );
    }
}

#[test]
fn travel_needs_both_ends_as_numbers() {
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 2000, "min": -5}"#),
        "axes.X.max",
        &["missing", "min and max"],
    );
    field_err(
        &xyz_with_y(r#"{"velocity": 400, "acceleration": 2000, "max": 5}"#),
        "axes.Y.min",
        &["missing", "min and max"],
    );
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 2000, "min": "a", "max": 5}"#),
        "axes.X.min",
        &["number"],
    );
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 2000, "min": -5, "max": null}"#),
        "axes.X.max",
        &["number"],
    );
    // Travel may be one-sided of zero (it is a position, not a rate).
    let m = ok(&xyz_with_x(
        r#"{"velocity": 400, "acceleration": 2000, "min": 10, "max": 500}"#,
    ));
    assert_eq!(m.axes[0].travel, Some((10.0, 500.0)));
}

#[test]
fn joint_machines_may_give_travel() {
    let m = ok(r#"{"kinematics": {"type": "joint"},
        "axes": {"J1": {"velocity": 1, "acceleration": 2, "min": -3, "max": 3}}}"#);
    assert_eq!(m.axes[0].travel, Some((-3.0, 3.0)));
}

#[test]
fn jerk_limits_are_optional_per_axis() {
    let m = ok(r#"{"kinematics": {"type": "xyz"}, "axes": {
        "X": {"velocity": 400, "acceleration": 2000, "jerk": 50000},
        "Y": {"velocity": 400, "acceleration": 2000, "jerk": [-40000, 60000]},
        "Z": {"velocity": 300, "acceleration": 1500}}}"#);
    assert_eq!(m.axes[0].jerk, Some(Limit::symmetric(50000.0)));
    assert_eq!(
        m.axes[1].jerk,
        Some(Limit {
            min: -40000.0,
            max: 60000.0
        })
    );
    assert_eq!(m.axes[2].jerk, None);
    assert!(m.has_jerk());
    let plain = ok(&format!(
        r#"{{"kinematics": {{"type": "xyz"}}, "axes": {XYZ_AXES}}}"#
    ));
    assert!(!plain.has_jerk());
}

#[test]
fn bad_jerk_limit_names_its_field() {
    field_err(
        r#"{"kinematics": {"type": "xyz"}, "axes": {
        "X": {"velocity": 400, "acceleration": 2000, "jerk": -5},
        "Y": {"velocity": 400, "acceleration": 2000},
        "Z": {"velocity": 300, "acceleration": 1500}}}"#,
        "axes.X.jerk",
        &["positive"],
    );
}

// ---------------------------------------------------------------------------------------------
// Issue 14: duplicate keys, implausible magnitudes, bounded reads, UTF-8
// ---------------------------------------------------------------------------------------------

#[test]
fn a_duplicate_axis_names_the_key_and_its_line() {
    // serde_json would keep the second X silently.
    let text = r#"{"name": "xyz", "kinematics": {"type": "xyz"},
 "axes": {"X": {"velocity": 400, "acceleration": 2000},
          "Y": {"velocity": 300, "acceleration": 1500},
          "X": {"velocity": 1, "acceleration": 1},
          "Z": {"velocity": 200, "acceleration": 1000}}}"#;
    field_err(text, "axes.X", &["twice", "line 4", "remove one"]);
}

#[test]
fn a_duplicate_field_anywhere_names_its_path() {
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 2000, "velocity": 4}"#),
        "axes.X.velocity",
        &["twice"],
    );
    field_err(
        &format!(
            r#"{{"name": "a", "name": "b", "kinematics": {{"type": "xyz"}}, "axes": {XYZ_AXES}}}"#
        ),
        "name",
        &["twice"],
    );
    field_err(
        &head_head(
            r#"{"type": "head_head", "tool_length": 200, "tool_length": 2}"#,
            "",
        ),
        "kinematics.tool_length",
        &["twice"],
    );
    // The same key in two different objects is no duplicate.
    ok(&xyz_with_x(r#"{"velocity": 400, "acceleration": 2000}"#));
}

#[test]
fn implausibly_small_or_large_limits_name_the_field() {
    field_err(
        &xyz_with_x(r#"{"velocity": 1e-300, "acceleration": 2000}"#),
        "axes.X.velocity",
        &["implausibly small", "1e-6", "mm/s", "unit"],
    );
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 1e300}"#),
        "axes.X.acceleration",
        &["implausibly large", "1e9", "mm/s²"],
    );
    field_err(
        &xyz_with_x(r#"{"velocity": [-1e-9, 400], "acceleration": 2000}"#),
        "axes.X.velocity",
        &["implausibly small"],
    );
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 2000, "jerk": 1e15}"#),
        "axes.X.jerk",
        &["implausibly large", "1e12", "mm/s³"],
    );
    let hh = r#"{"type": "head_head", "tool_length": 200}"#;
    field_err(
        &head_head(hh, r#", "feed": {"max": 1e-300}"#),
        "feed.max",
        &["implausibly small"],
    );
    // A rotary axis's limits are in degrees.
    let axes = HEAD_HEAD_AXES.replace(r#""C": {"velocity": 120"#, r#""C": {"velocity": 1e10"#);
    field_err(
        &format!(r#"{{"kinematics": {hh}, "axes": {axes}}}"#),
        "axes.C.velocity",
        &["°/s"],
    );
    // The bounds themselves are accepted.
    ok(&xyz_with_x(
        r#"{"velocity": 1e-6, "acceleration": 1e9, "jerk": 1e12}"#,
    ));
}

#[test]
fn implausible_lengths_name_the_field() {
    field_err(
        &head_head(r#"{"type": "head_head", "tool_length": 1e300}"#, ""),
        "kinematics.tool_length",
        &["implausibly large", "1e6"],
    );
    field_err(
        &with_kinematics(
            &AC_FULL.replace(r#""z-offset": 10.0"#, r#""z-offset": -1e7"#),
            &five_axes("A"),
        ),
        "kinematics.z-offset",
        &["implausibly large"],
    );
    field_err(
        &with_kinematics(
            &AC_FULL.replace("[0.5, -0.25, 13.25]", "[0.5, -0.25, 1e300]"),
            &five_axes("A"),
        ),
        "kinematics.work-offset",
        &["three numbers"],
    );
    field_err(
        &xyz_with_x(r#"{"velocity": 400, "acceleration": 2000, "min": -1e12, "max": 5}"#),
        "axes.X.min",
        &["implausibly large"],
    );
}

#[test]
fn not_utf8_names_the_line_and_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.json");
    let mut bytes = b"{\"kinematics\": {\"type\": \"xyz\"},\n \"name\": \"fr".to_vec();
    bytes.push(0xe4); // ä in Latin-1
    bytes.extend_from_slice(format!("se\",\n \"axes\": {XYZ_AXES}}}").as_bytes());
    std::fs::write(&path, bytes).unwrap();
    let e = Machine::from_file(&path).expect_err("not UTF-8");
    let text = e.to_string();
    assert!(
        text.contains("latin1.json:2:") && text.contains("UTF-8") && text.contains("save"),
        "{text}"
    );
}

#[test]
fn a_file_that_never_ends_is_refused() {
    // Bigger than any machine file: refused before it is read, not read to its end.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.json");
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(2 << 20).unwrap(); // sparse: no disk used
    let e = Machine::from_file(&path).expect_err("too large");
    assert!(e.to_string().contains("larger than 1 MiB"), "{e}");
    #[cfg(unix)]
    {
        let e = Machine::from_file(Path::new("/dev/zero")).expect_err("endless");
        assert!(
            e.to_string().contains("/dev/zero: larger than 1 MiB"),
            "{e}"
        );
    }
}

/// `feed_diameter` (mm) on a rotary axis: read for the toolpath readers; on a linear axis, at
/// or below 0, or not a number, an error naming the field.
#[test]
fn a_rotary_axis_may_give_its_feed_diameter() {
    use feedopt::machine::references_from_json;
    let with = |axis: &str, d: &str| {
        let mut axes: Vec<String> = ["X", "Y", "Z", "A", "C"]
            .iter()
            .map(|n| format!(r#""{n}": {{"velocity": 100, "acceleration": 1000"#))
            .collect();
        for (n, a) in ["X", "Y", "Z", "A", "C"].iter().zip(&mut axes) {
            if *n == axis {
                a.push_str(&format!(r#", "feed_diameter": {d}"#));
            }
            a.push('}');
        }
        format!(
            r#"{{"name": "trt", "kinematics": {{"type": "table_table_ac", "x-rot-point": 0,
                "y-rot-point": 0, "z-rot-point": 0, "y-offset": 0, "z-offset": 0}},
                "axes": {{{}}}}}"#,
            axes.join(", ")
        )
    };
    let text = with("C", "50");
    let m = ok(&text);
    let r = references_from_json(Path::new("m.json"), &text, &m).unwrap();
    assert_eq!(r.feed_diameter, vec![("C".to_string(), 50.0)]);
    for (axis, d, says) in [
        ("X", "50", "only a rotary axis"),
        ("C", "0", "above 0"),
        ("A", "-3", "above 0"),
        ("C", "\"50\"", "feed_diameter"),
    ] {
        let text = with(axis, d);
        let m = ok(&text);
        let e = references_from_json(Path::new("m.json"), &text, &m)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("axes.{axis}.feed_diameter")) && e.contains(says),
            "{axis} {d}: {e}"
        );
    }
}

/// `program_units`: "mm" or "inch", the unit the control reads a program that selects none in
/// (for the toolpath readers); anything else is an error naming the field.
#[test]
fn program_units_is_mm_or_inch() {
    use feedopt::machine::{LengthUnit, references_from_json};
    let with = |u: &str| {
        format!(
            r#"{{"name": "xyz", "kinematics": {{"type": "xyz"}}, "program_units": {u},
                "axes": {{"X": {{"velocity": 400, "acceleration": 2000}},
                         "Y": {{"velocity": 400, "acceleration": 2000}},
                         "Z": {{"velocity": 400, "acceleration": 2000}}}}}}"#
        )
    };
    for (u, want) in [("\"mm\"", LengthUnit::Mm), ("\"inch\"", LengthUnit::Inch)] {
        let text = with(u);
        let m = ok(&text);
        let r = references_from_json(Path::new("m.json"), &text, &m).unwrap();
        assert_eq!(r.program_units, Some(want));
    }
    for bad in ["\"in\"", "25.4", "null"] {
        let text = with(bad);
        let m = ok(&text);
        let e = references_from_json(Path::new("m.json"), &text, &m)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("program_units") && e.contains("inch"),
            "{bad}: {e}"
        );
    }
}

/// `decimal_point_input`: "increment" or "calculator", how the control reads a Fanuc number
/// without a decimal point (parameter 3401#0, DPI); anything else is an error naming the
/// field and both choices.
#[test]
fn decimal_point_input_is_increment_or_calculator() {
    use feedopt::machine::{DecimalPointInput, references_from_json};
    let with = |u: &str| {
        format!(
            r#"{{"name": "xyz", "kinematics": {{"type": "xyz"}}, "decimal_point_input": {u},
                "axes": {{"X": {{"velocity": 400, "acceleration": 2000}},
                         "Y": {{"velocity": 400, "acceleration": 2000}},
                         "Z": {{"velocity": 400, "acceleration": 2000}}}}}}"#
        )
    };
    for (u, want) in [
        ("\"increment\"", DecimalPointInput::Increment),
        ("\"calculator\"", DecimalPointInput::Calculator),
    ] {
        let text = with(u);
        let m = ok(&text);
        let r = references_from_json(Path::new("m.json"), &text, &m).unwrap();
        assert_eq!(r.decimal_point_input, Some(want));
    }
    for bad in ["\"dpi\"", "1", "true"] {
        let text = with(bad);
        let m = ok(&text);
        let e = references_from_json(Path::new("m.json"), &text, &m)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("decimal_point_input") && e.contains("calculator") && e.contains("3401"),
            "{bad}: {e}"
        );
    }
}

/// `"shortest_way"` on a rotary axis: true or false; on a linear axis, or anything but a
/// boolean, an error naming the field.
#[test]
fn shortest_way_is_a_rotary_axis_boolean() {
    let with = |axis: &str, v: &str| {
        let axes = five_axes("A").replace(
            &format!("\"{axis}\": {{"),
            &format!("\"{axis}\": {{\"shortest_way\": {v}, "),
        );
        with_kinematics(AC_FULL, &axes)
    };
    let refs = |text: &str| {
        let m = ok(text);
        feedopt::machine::references_from_json(Path::new(FILE), text, &m).map(|r| r.shortest_way)
    };
    assert_eq!(refs(&with("A", "true")).unwrap(), ["A"]);
    assert!(refs(&with("C", "false")).unwrap().is_empty());
    let e = refs(&with("X", "true")).unwrap_err().to_string();
    assert!(
        e.contains("axes.X.shortest_way") && e.contains("rotary"),
        "{e}"
    );
    let e = refs(&with("A", "1")).unwrap_err().to_string();
    assert!(
        e.contains("axes.A.shortest_way") && e.contains("true"),
        "{e}"
    );
}
