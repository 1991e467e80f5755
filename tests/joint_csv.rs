//! The joint-space CSV reader (`feedopt::toolpath::joint_csv`): a valid file is read as given;
//! every degenerate one (a path that does not move, positions or derivatives of absurd size,
//! rows too close in s, s not increasing, text that is not UTF-8) is an error naming the file,
//! the line and, for a value, its column.

use feedopt::error::Error;
use feedopt::toolpath::joint_csv;
use std::path::Path;

const FILE: &str = "paths/joint.csv";

fn parse(text: &str) -> Result<joint_csv::JointPath, Error> {
    joint_csv::parse(Path::new(FILE), text)
}

/// Asserts an `Error::Parse` on `line` whose one-line message contains every one of
/// `needles`; returns the message.
fn line_err(text: &str, line: usize, needles: &[&str]) -> String {
    match parse(text) {
        Ok(p) => panic!("expected an error on line {line}, got {p:?}\n--- input ---\n{text}"),
        Err(Error::Parse {
            file,
            line: got,
            message,
        }) => {
            assert_eq!(file, Path::new(FILE));
            assert_eq!(got, line, "wrong line (message `{message}`)");
            assert!(
                !message.contains('\n'),
                "message is not one line: {message:?}"
            );
            for needle in needles {
                assert!(
                    message.contains(needle),
                    "message `{message}` does not mention `{needle}`"
                );
            }
            message
        }
        Err(other) => panic!("expected Error::Parse on line {line}, got {other}"),
    }
}

/// Two axes along s ∈ [0, 1] in five rows, with first derivatives.
const VALID: &str = "s,q_a,q_b,dq_a,dq_b\n\
                     0,0,0,1,2\n\
                     0.25,0.25,0.5,1,2\n\
                     0.5,0.5,1,1,2\n\
                     0.75,0.75,1.5,1,2\n\
                     1,1,2,1,2\n";

#[test]
fn a_valid_path_is_read_as_given() {
    let p = parse(VALID).expect("valid");
    assert_eq!(p.axes, ["a", "b"]);
    assert_eq!(p.s, [0.0, 0.25, 0.5, 0.75, 1.0]);
    assert_eq!(p.q[4][1], 2.0);
    assert_eq!(p.dq.as_ref().expect("dq")[2][1], 2.0);
    assert_eq!(p.lines, [2, 3, 4, 5, 6]);
    // A byte-order mark (as spreadsheet programs write) is not part of the header.
    let with_bom = format!("\u{feff}{VALID}");
    assert_eq!(parse(&with_bom).expect("valid with BOM"), p);
}

#[test]
fn a_path_that_does_not_move_is_refused() {
    let text = "s,q_a,q_b\n0,1,2\n0.5,1,2\n1,1,2\n";
    line_err(text, 1, &["does not move", "line 2", "line 4"]);
    // A picometre is not motion either.
    let text = "s,q_a\n0,1\n1,1.0000000000001\n";
    line_err(text, 1, &["does not move"]);
}

#[test]
fn positions_of_absurd_size_name_line_and_column() {
    let text = "s,q_a,q_b\n0,0,0\n0.5,1e308,1\n1,2,2\n";
    line_err(
        text,
        3,
        &["column 2", "`q_a`", "1e308", "implausibly large"],
    );
    let text = "s,q_a\n0,0\n1e300,1\n";
    line_err(text, 3, &["column 1", "`s`", "implausibly large"]);
}

#[test]
fn rows_too_close_in_s_are_refused() {
    let text = "s,q_a\n0,0\n1e-298,1\n";
    line_err(text, 3, &["column 1", "apart in s", "rescale s"]);
}

#[test]
fn s_must_increase() {
    let text = "s,q_a\n0,0\n1,1\n1,2\n";
    line_err(text, 4, &["column 1", "increase strictly"]);
    let text = "s,q_a\n0,0\n1,1\n0.5,2\n";
    line_err(text, 4, &["increase strictly", "0.5 after 1"]);
}

#[test]
fn derivatives_of_absurd_size_name_line_and_column() {
    let text = "s,q_a,dq_a,ddq_a,dddq_a\n0,0,0,0,0\n0.5,0.5,1,0,1e300\n1,1,1,0,0\n";
    line_err(
        text,
        3,
        &["column 5", "`dddq_a`", "1e300", "with respect to s"],
    );
    let text = "s,q_a,dq_a\n0,0,1e12\n1,1,1\n";
    line_err(text, 2, &["column 3", "`dq_a`", "more than 1e7"]);
    // A full-scale sine two rows per period is a path: its third derivative's term is
    // π³/6 ≈ 5.2 times the amplitude, here 1e6.
    let mut text = String::from("s,q_a,dq_a,ddq_a,dddq_a\n");
    let w = std::f64::consts::PI; // period 2 in s, rows 1 apart
    for i in 0..=4 {
        let s = i as f64;
        let q = 1e6 * (w * s + 0.3).sin();
        let (d1, d2, d3) = (
            1e6 * w * (w * s + 0.3).cos(),
            -1e6 * w * w * (w * s + 0.3).sin(),
            -1e6 * w * w * w * (w * s + 0.3).cos(),
        );
        text.push_str(&format!("{s},{q},{d1},{d2},{d3}\n"));
    }
    parse(&text).expect("a full-scale sine at two rows per period");
    // The same kind of derivative is fine where the rows are close enough for it to be
    // plausible: dddq = 1e6 over Δs = 1e-3 is a Taylor term of 1.7e-4.
    let mut text = String::from("s,q_a,dq_a,ddq_a,dddq_a\n");
    for i in 0..=10 {
        let s = i as f64 * 1e-3;
        text.push_str(&format!("{s},{s},1,0,1e6\n"));
    }
    parse(&text).expect("large but plausible derivatives");
}

#[test]
fn text_that_is_not_utf8_names_the_line() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("latin1.csv");
    std::fs::write(&path, b"s,q_a\n0,0\n1,1 \xb0\n").expect("write");
    let e = joint_csv::read(&path).expect_err("not UTF-8");
    let text = e.to_string();
    assert!(
        text.contains("latin1.csv:3:") && text.contains("UTF-8") && text.contains("save"),
        "{text}"
    );
}
