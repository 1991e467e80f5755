//! Subprograms in the same file (issue 12 item 4): Fanuc/Haas `M98 P L` with `O<n> … M99`,
//! Sinumerik `PROC NAME … RET` and `L123`, LinuxCNC `o100 sub … endsub` / `o100 call`; each
//! against hand-computed points, and the errors a call can meet.

use feedopt::toolpath::Toolpath;
use feedopt::toolpath::gcode::{Dialect, parse};
use nalgebra::Vector3;
use std::path::Path;

fn read(dialect: Dialect, text: &str) -> Toolpath {
    parse(Path::new("t.nc"), text, dialect).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn fails(dialect: Dialect, text: &str) -> String {
    match parse(Path::new("t.nc"), text, dialect) {
        Ok(tp) => panic!("{} points from\n{text}", tp.points.len()),
        Err(e) => e.to_string(),
    }
}

fn points(tp: &Toolpath) -> Vec<[f64; 3]> {
    tp.points.iter().map(|p| [p.p.x, p.p.y, p.p.z]).collect()
}

fn lines(tp: &Toolpath) -> Vec<usize> {
    tp.points.iter().map(|p| p.line).collect()
}

const FANUC_TWO_CALLS: &str = "O1000\n\
G21 G90 G94 G0 X0. Y0. Z5.\n\
M98 P2000\n\
G0 X10. Y0.\n\
M98 P2000\n\
M30\n\
O2000 (SQUARE STEP)\n\
G91 G1 X1. F600.\n\
G1 Y1.\n\
G90\n\
M99\n";

#[test]
fn fanuc_two_calls_run_the_body_twice_with_the_callers_state() {
    let tp = read(Dialect::Fanuc, FANUC_TWO_CALLS);
    // The body moves +1 in X then +1 in Y from wherever the caller is (G91 in the body).
    assert_eq!(
        points(&tp),
        [
            [0.0, 0.0, 5.0],
            [1.0, 0.0, 5.0],
            [1.0, 1.0, 5.0],
            [10.0, 0.0, 5.0],
            [11.0, 0.0, 5.0],
            [11.0, 1.0, 5.0],
        ]
    );
    // Every point keeps the line of the block that made it (the body's lines).
    assert_eq!(lines(&tp), [2, 8, 9, 4, 8, 9]);
    // The body's F600 (10 mm/s) is modal in the caller too.
    assert!(
        tp.points[1..]
            .iter()
            .filter(|p| p.line != 4)
            .all(|p| p.feed == feedopt::toolpath::Feed::Programmed(10.0))
    );
}

#[test]
fn fanuc_repeat_counts_l_and_packed_p() {
    let body = "O2000\nG91 G1 X1. F600.\nG90\nM99\n";
    let want = [
        [0.0, 0.0, 5.0],
        [1.0, 0.0, 5.0],
        [2.0, 0.0, 5.0],
        [3.0, 0.0, 5.0],
    ];
    for call in ["M98 P2000 L3", "M98 P32000", "M98 P02000 L3"] {
        let text = format!("O1\nG0 X0. Y0. Z5.\n{call}\nM30\n{body}");
        assert_eq!(points(&read(Dialect::Fanuc, &text)), want, "{call}");
    }
    // L0 calls nothing.
    let text = format!("O1\nG0 X0. Y0. Z5.\nM98 P2000 L0\nM30\n{body}");
    assert_eq!(points(&read(Dialect::Fanuc, &text)), want[..1]);
    // A subprogram that calls another, each repeated: 2 × (1 + 2) moves of 1 mm.
    let text = "O1\nG0 X0. Y0. Z5.\nM98 P10 L2\nM30\n\
                O10\nG91 G1 X1. F600.\nM98 P20 L2\nG90\nM99\n\
                O20\nG91 G1 Y1.\nM99\n";
    let tp = read(Dialect::Fanuc, text);
    assert_eq!(tp.points.len(), 7);
    assert_eq!(tp.points[6].p, Vector3::new(2.0, 4.0, 5.0));
}

#[test]
fn sinumerik_named_and_l_subprograms() {
    let text = "G71 G90 G0 X0 Y0 Z5\n\
                EXTERN MYSUB\n\
                MYSUB P2\n\
                L123\n\
                M30\n\
                PROC MYSUB\n\
                G91 G1 X1 F600\n\
                G90\n\
                RET\n\
                %_N_L123_SPF\n\
                G1 Y7\n\
                M17\n";
    let tp = read(Dialect::Sinumerik, text);
    assert_eq!(
        points(&tp),
        [
            [0.0, 0.0, 5.0],
            [1.0, 0.0, 5.0],
            [2.0, 0.0, 5.0],
            [2.0, 7.0, 5.0],
        ]
    );
    assert_eq!(lines(&tp), [1, 7, 7, 11]);
    assert!(tp.warnings.is_empty(), "{:?}", tp.warnings);
    // A file that is one PROC is its own main program.
    let tp = read(Dialect::Sinumerik, "PROC PART\nG0 X1 Y2 Z3\nRET\n");
    assert_eq!(points(&tp), [[1.0, 2.0, 3.0]]);
}

#[test]
fn linuxcnc_o_word_subroutines() {
    let text = "o100 sub\n\
                G91 G1 X2 F600\n\
                G90\n\
                o100 endsub\n\
                G21 G90 G0 X0 Y0 Z1\n\
                o100 call\n\
                O100 CALL (again)\n\
                M2\n";
    let tp = read(Dialect::LinuxCnc, text);
    assert_eq!(
        points(&tp),
        [[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [4.0, 0.0, 1.0]]
    );
    assert_eq!(lines(&tp), [5, 2, 2]);
    // `o<name> return` leaves early.
    let text = "o<step> sub\nG1 X1 F60\no<step> return\nG1 X99\no<step> endsub\n\
                G0 X0 Y0 Z0\no<step> call\nG1 Y1\nM2\n";
    assert_eq!(
        points(&read(Dialect::LinuxCnc, text)),
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]
    );
}

/// `o<dm> call [10] [20]` passes its arguments as #1, #2 (round 3: "#1 is read before it is
/// set"), evaluated where the call is; #1–#30 are the call's own: those past the arguments
/// keep the caller's values, and all come back on return, as on LinuxCNC.
#[test]
fn linuxcnc_call_arguments_are_the_subroutines_1_to_30() {
    let text = "o<dm> sub\n  G1 X#1 Y#2 F600\no<dm> endsub\nG21 G90\nG0 X0 Y0 Z5\n\
                o<dm> call [10] [20]\nM2\n";
    let tp = read(Dialect::LinuxCnc, text);
    assert_eq!(points(&tp), [[0.0, 0.0, 5.0], [10.0, 20.0, 5.0]]);
    assert_eq!(lines(&tp), [5, 2]);
    // Expressions with the caller's parameters; #3 past the arguments is the caller's; a
    // nested call has its own #1 and the outer body gets its #1 back; after the call the
    // caller's #1 (5) and #2 (unset) are back.
    let text = "o<in> sub\nG1 Z#1 F600\no<in> endsub\n\
                o<out> sub\nG1 X#1 Y#3 F600\no<in> call [-1]\nG1 Y#1\no<out> endsub\n\
                #1=5\n#3=7\nG0 X0 Y0 Z0\no<out> call [#1*2] [4]\nG1 X#1\nM2\n";
    let tp = read(Dialect::LinuxCnc, text);
    assert_eq!(
        points(&tp),
        [
            [0.0, 0.0, 0.0],
            [10.0, 7.0, 0.0],
            [10.0, 7.0, -1.0],
            [10.0, 10.0, -1.0],
            [5.0, 10.0, -1.0]
        ]
    );
    let e = fails(
        Dialect::LinuxCnc,
        "o<dm> sub\nG1 X#2 F600\no<dm> endsub\nG0 X0 Y0 Z0\no<dm> call [1]\nG1 Y#2\nM2\n",
    );
    assert!(
        e.contains("t.nc:2:") && e.contains("#2") && e.contains("O<dm> call [1]"),
        "{e}"
    );
    let e = fails(
        Dialect::LinuxCnc,
        "o<dm> sub\nG1 X#1 F600\no<dm> endsub\nG0 X0 Y0 Z0\no<dm> call 5\nM2\n",
    );
    assert!(e.contains("t.nc:5:") && e.contains("in brackets"), "{e}");
    let many = "[1]".repeat(31);
    let e = fails(
        Dialect::LinuxCnc,
        &format!("o<dm> sub\nG1 X#1 F600\no<dm> endsub\nG0 X0 Y0 Z0\no<dm> call {many}\nM2\n"),
    );
    assert!(e.contains("t.nc:5:") && e.contains("more than 30"), "{e}");
}

#[test]
fn a_call_of_a_subprogram_not_in_the_file_is_an_error_naming_line_call_and_fix() {
    let e = fails(
        Dialect::Fanuc,
        "O1\nG0 X0. Y0. Z5.\nM98 P3000\nM30\nO2000\nG1 X1.\nM99\n",
    );
    assert!(
        e.contains("t.nc:3:")
            && e.contains("M98 P3000")
            && e.contains("O3000")
            && e.contains("neither in this file")
            && e.contains("O3000 … M99"),
        "{e}"
    );
    let e = fails(Dialect::Sinumerik, "G0 X0 Y0 Z0\nL99 P2\nM30\n");
    assert!(
        e.contains(":2:") && e.contains("L99 P2") && e.contains("PROC L99"),
        "{e}"
    );
    let e = fails(Dialect::LinuxCnc, "G0 X0 Y0 Z0\no200 call\nM2\n");
    assert!(
        e.contains(":2:") && e.contains("O200 call") && e.contains("endsub"),
        "{e}"
    );
    // LinuxCNC control flow stays an error; an unclosed sub names its line.
    let e = fails(Dialect::LinuxCnc, "G0 X0 Y0 Z0\no1 if [1]\no1 endif\n");
    assert!(e.contains(":2:") && e.contains("O-word"), "{e}");
    let e = fails(Dialect::LinuxCnc, "G0 X0 Y0 Z0\no7 sub\nG1 X1\n");
    assert!(e.contains(":2:") && e.contains("endsub"), "{e}");
    // Haas M97 (local subprogram by N label) is an error, not a dropped call.
    let e = fails(Dialect::Fanuc, "G0 X0. Y0. Z0.\nM97 P100\nM30\n");
    assert!(e.contains(":2:") && e.contains("M97"), "{e}");
}

#[test]
fn errors_inside_a_subprogram_name_the_call() {
    let e = fails(
        Dialect::Fanuc,
        "O1\nG0 X0. Y0. Z5.\nM98 P2000\nM30\nO2000\nG1 X1. F-5.\nM99\n",
    );
    assert!(
        e.contains("t.nc:6:")
            && e.contains("negative")
            && e.contains("in subprogram O2000, called by `M98 P2000` at line 3"),
        "{e}"
    );
}

#[test]
fn recursion_and_huge_expansions_are_bounded_errors() {
    let e = fails(
        Dialect::Fanuc,
        "O1\nG0 X0. Y0. Z5.\nM98 P2000\nM30\nO2000\nG91 G1 X1. F600.\nM98 P2000\nM99\n",
    );
    assert!(e.contains("nested more than 8"), "{e}");
    // 9999 × 9999 blocks: stopped at the bound, with a message saying what to do.
    let e = fails(
        Dialect::Fanuc,
        "O1\nG0 X0. Y0. Z5.\nM98 P10 L9999\nM30\nO10\nM98 P20 L9999\nM99\nO20\nG91 G1 X1. \
         F600.\nM99\n",
    );
    assert!(e.contains("more than 1000000 blocks"), "{e}");
    let e = fails(
        Dialect::Fanuc,
        "O1\nG0 X0. Y0. Z5.\nM98 P10 L999999999\nM30\nO10\nM99\n",
    );
    assert!(e.contains("more than 1000000 blocks"), "{e}");
}

#[test]
fn a_program_end_in_a_subprogram_ends_the_program() {
    let tp = read(
        Dialect::Fanuc,
        "O1\nG0 X0. Y0. Z5.\nM98 P2000\nG0 X50.\nM30\nO2000\nG1 X1. F600.\nM30\n",
    );
    assert_eq!(points(&tp), [[0.0, 0.0, 5.0], [1.0, 0.0, 5.0]]);
    // M99 in the main program ends it, as before.
    let tp = read(Dialect::Fanuc, "G0 X0. Y0. Z5.\nM99\nG0 X9.\n");
    assert_eq!(tp.points.len(), 1);
}
