//! Subprograms in other files: Fanuc/Haas `M98 P…` to `O1002.nc`, LinuxCNC `o<name> call` to
//! `name.ngc`, Sinumerik `NAME`, `L1234`, `EXTCALL "NAME"` to `NAME.SPF`, read from the
//! program's directory and `--subprogram-dir`. Each call reads the same points as the same
//! subprogram pasted into the file; the errors a call can meet name the file and line.

use feedopt::toolpath::Toolpath;
use feedopt::toolpath::gcode::{Dialect, Settings, parse_configured};
use std::path::{Path, PathBuf};

mod common;
use common::feedopt;

/// A fresh directory for one test, with `files` (relative path, text) written into it.
fn scratch(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "feedopt-external-subprograms-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    for (path, text) in files {
        let path = dir.join(path);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
    dir
}

fn read_in(dialect: Dialect, main: &Path, dirs: &[PathBuf]) -> feedopt::error::Result<Toolpath> {
    let text = std::fs::read_to_string(main).unwrap();
    let settings = Settings {
        subprogram_dirs: dirs.to_vec(),
        ..Settings::default()
    };
    parse_configured(main, &text, dialect.spec(), None, &settings).map(|(t, _)| t)
}

fn read(dialect: Dialect, main: &Path, dirs: &[PathBuf]) -> Toolpath {
    read_in(dialect, main, dirs).unwrap_or_else(|e| panic!("{e}"))
}

fn fails(dialect: Dialect, main: &Path, dirs: &[PathBuf]) -> String {
    match read_in(dialect, main, dirs) {
        Ok(t) => panic!("{} points", t.points.len()),
        Err(e) => e.to_string(),
    }
}

/// Every point's position, rotary axes and feed, to compare two readings.
fn motion(tp: &Toolpath) -> Vec<String> {
    tp.points
        .iter()
        .map(|p| {
            format!(
                "{:.6} {:.6} {:.6} {:?} {:?}",
                p.p.x, p.p.y, p.p.z, p.rotary, p.feed
            )
        })
        .collect()
}

const FANUC_MAIN: &str = "%\n\
O1000\n\
G21 G90 G94 G17\n\
G0 X0. Y0. Z5.\n\
G1 Z0. F600.\n\
M98 P1002 L2\n\
G1 X50.\n\
M98 P31003\n\
G0 Z5.\n\
M30\n\
%\n";

const FANUC_O1002: &str = "%\n\
O1002 (SQUARE, INCREMENTAL)\n\
G91 G1 X10.\n\
Y10. F1200.\n\
X-10.\n\
Y-10.\n\
G90\n\
M99\n\
%\n";

const FANUC_O1003: &str = "O1003\nG1 Y5.\nG1 Y0.\nM99\n";

/// `M98 P1002 L2` and the packed `M98 P31003` (O1003 three times) read files `O1002.nc` (in
/// --subprogram-dir) and `1003.nc` (beside the program) to the points the same programs
/// pasted into the file give, with the modal state carried in and out (G91 set and reset in
/// the body; F1200 set in the body holds for the main program's `G1 X50.`).
#[test]
fn fanuc_m98_reads_the_file_to_the_points_of_the_pasted_program() {
    let dir = scratch(
        "fanuc",
        &[
            ("main.nc", FANUC_MAIN),
            ("subs/O1002.nc", FANUC_O1002),
            ("1003.nc", FANUC_O1003),
            (
                "pasted.nc",
                &format!(
                    "{}{}{}",
                    FANUC_MAIN.trim_end_matches("%\n"),
                    FANUC_O1002.trim_start_matches("%\n"),
                    FANUC_O1003
                ),
            ),
        ],
    );
    let subs = vec![dir.join("subs")];
    let external = read(Dialect::Fanuc, &dir.join("main.nc"), &subs);
    let pasted = read(Dialect::Fanuc, &dir.join("pasted.nc"), &[]);
    assert_eq!(motion(&external), motion(&pasted));
    // 2 runs of 4 moves, the X50 move, 3 runs of 2 moves, plus the first rapid, plunge, retract.
    assert_eq!(external.points.len(), 3 + 8 + 1 + 6);
    // The body's F1200 carries out: the main program's X50 runs at 20 mm/s.
    let x50 = &external.points[2 + 8];
    assert_eq!(x50.feed, feedopt::toolpath::Feed::Programmed(20.0));
    // Lines: the body's points are numbered after the main program's 11 lines, and map back.
    let first_sub = &external.points[2];
    assert_eq!(
        external.place(first_sub.line),
        (dir.join("subs/O1002.nc").as_path(), 3)
    );
    assert_eq!(
        external.line_name(first_sub.line),
        format!("line 3 of {}", dir.join("subs/O1002.nc").display())
    );
    assert_eq!(external.line_name(x50.line), "line 7");
    let o1003 = &external.points[11];
    assert_eq!(
        external.place(o1003.line),
        (dir.join("1003.nc").as_path(), 2)
    );
    // Each file is read once, however often it is called.
    assert_eq!(external.files.len(), 2);
    // Without --subprogram-dir, O1002 is not found: the message names the line, the call, the
    // file names tried, the directory and the option.
    let e = fails(Dialect::Fanuc, &dir.join("main.nc"), &[]);
    assert!(
        e.contains("main.nc:6:")
            && e.contains("`M98 P1002 L2`")
            && e.contains("O1002.nc, 1002.nc")
            && e.contains(&dir.display().to_string())
            && e.contains("--subprogram-dir"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The directories are searched in order, after the program's own: the first that holds the
/// program wins; two files in one directory that could hold it are an error naming both.
#[test]
fn the_search_order_and_two_candidates_in_one_directory() {
    let near = "O1002\nG1 X1. F100.\nM99\n";
    let far = "O1002\nG1 X2. F100.\nM99\n";
    let dir = scratch(
        "order",
        &[
            ("main.nc", "O1000\nG0 X0. Y0. Z0.\nM98 P1002\nM30\n"),
            ("a/O1002.nc", near),
            ("b/O1002.nc", far),
            ("c/O1002.nc", far),
            ("c/1002.tap", far),
        ],
    );
    let (a, b, c) = (dir.join("a"), dir.join("b"), dir.join("c"));
    let x = |dirs: &[PathBuf]| {
        read(Dialect::Fanuc, &dir.join("main.nc"), dirs).points[1]
            .p
            .x
    };
    assert_eq!(x(&[a.clone(), b.clone()]), 1.0);
    assert_eq!(x(&[b.clone(), a.clone()]), 2.0);
    let e = fails(Dialect::Fanuc, &dir.join("main.nc"), &[c]);
    assert!(e.contains("1002.tap") && e.contains("O1002.nc"), "{e}");
    // A file whose own header names another program does not hold the one called.
    let dir2 = scratch(
        "header",
        &[
            ("main.nc", "O1000\nG0 X0. Y0. Z0.\nM98 P1002\nM30\n"),
            ("O1002.nc", "O2000\nG1 X1. F100.\nM99\n"),
        ],
    );
    let e = fails(Dialect::Fanuc, &dir2.join("main.nc"), &[]);
    assert!(
        e.contains("O1002.nc:1:") && e.contains("holds O2000"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&dir2);
}

/// A subprogram that calls itself for ever is an error at the nesting bound, naming the
/// file and line of the call and where it was called from; a program that calls its own
/// number does the same.
#[test]
fn a_self_call_is_an_error_naming_its_file_and_line() {
    let dir = scratch(
        "self",
        &[
            ("main.nc", "O1000\nG0 X0. Y0. Z0.\nM98 P1002\nM30\n"),
            ("O1002.nc", "O1002\nG91 G1 X1. F100.\nM98 P1002\nM99\n"),
        ],
    );
    let e = fails(Dialect::Fanuc, &dir.join("main.nc"), &[]);
    assert!(
        e.starts_with(&format!("{}:3:", dir.join("O1002.nc").display()))
            && e.contains("nested more than")
            && e.contains("calls itself"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// An error inside a called file names that file and its line, and the call.
#[test]
fn an_error_inside_a_called_file_names_that_file_and_line() {
    let dir = scratch(
        "inner",
        &[
            ("main.nc", "O1000\nG0 X0. Y0. Z0.\n\nM98 P1002\nM30\n"),
            ("lib/O1002.nc", "O1002\nG1 X1. F100.\nG1 X1.2.3\nM99\n"),
        ],
    );
    let e = fails(Dialect::Fanuc, &dir.join("main.nc"), &[dir.join("lib")]);
    assert!(
        e.starts_with(&format!("{}:3:", dir.join("lib/O1002.nc").display()))
            && e.contains("1.2.3")
            && e.contains("called by `M98 P1002` at line 4"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

const LINUXCNC_MAIN: &str = "G21 G90 G17\n\
G0 X0 Y0 Z5\n\
G1 Z0 F600\n\
#1 = 7\n\
o<square> call [10] [#1 * 2]\n\
G1 X#1\n\
M2\n";

const LINUXCNC_SUB: &str = "(a square of side #1 at depth -#2/10)\n\
o<square> sub\n\
G91 G1 X#1\n\
Y#1 Z[-#2/10]\n\
X-#1\n\
Y-#1\n\
G90\n\
#1 = 99\n\
o<square> endsub\n\
M2\n";

/// `o<square> call [10] [#1*2]` reads `square.ngc` to the points of the subroutine pasted into
/// the file: the arguments are `#1`, `#2` in the body, and the caller's `#1` comes back.
#[test]
fn linuxcnc_call_reads_name_ngc_with_its_arguments() {
    let body: String = LINUXCNC_SUB
        .lines()
        .skip(1)
        .take(8)
        .collect::<Vec<_>>()
        .join("\n");
    let dir = scratch(
        "linuxcnc",
        &[
            ("main.ngc", LINUXCNC_MAIN),
            ("nc_subroutines/square.ngc", LINUXCNC_SUB),
            ("pasted.ngc", &format!("{body}\n{LINUXCNC_MAIN}")),
        ],
    );
    let subs = vec![dir.join("nc_subroutines")];
    let external = read(Dialect::LinuxCnc, &dir.join("main.ngc"), &subs);
    let pasted = read(Dialect::LinuxCnc, &dir.join("pasted.ngc"), &[]);
    assert_eq!(motion(&external), motion(&pasted));
    // The second move is Y+10 and Z to -1.4 (#2 = 14); the last is X7 (the caller's #1).
    assert!((external.points[3].p.z + 1.4).abs() < 1e-9);
    assert_eq!(external.points.last().unwrap().p.x, 7.0);
    // A file with code outside the subroutine is an error naming it.
    std::fs::write(
        dir.join("nc_subroutines/square.ngc"),
        "G0 Z50\no<square> sub\nG1 X1\no<square> endsub\n",
    )
    .unwrap();
    let e = fails(Dialect::LinuxCnc, &dir.join("main.ngc"), &subs);
    assert!(e.contains("square.ngc:1:") && e.contains("outside"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

const SINUMERIK_MAIN: &str = "G71 G90 G17\n\
G0 X0 Y0 Z5\n\
G1 Z0 F600\n\
SQUARE P2\n\
L1234\n\
EXTCALL \"FINISH\"\n\
G1 X50\n\
M30\n";

/// Sinumerik `SQUARE P2` (a bare name with a repeat count), `L1234` and `EXTCALL "FINISH"`
/// read `SQUARE.SPF`, `L1234.spf` and `finish.SPF` (the control's `%_N_…_SPF` header) to the
/// points of the same subprograms pasted into the file as PROCs.
#[test]
fn sinumerik_name_l_and_extcall_read_spf_files() {
    let dir = scratch(
        "sinumerik",
        &[
            ("MAIN.MPF", SINUMERIK_MAIN),
            (
                "spf/SQUARE.SPF",
                "PROC SQUARE\nG91 G1 X10\nY10\nX-10\nY-10\nG90\nRET\n",
            ),
            ("spf/L1234.spf", "G1 Y5\nY0\nM17\n"),
            (
                "spf/finish.SPF",
                "%_N_FINISH_SPF\n;$PATH=/_N_SPF_DIR\nG1 X20 Y20 F900\nM17\n",
            ),
            (
                "PASTED.MPF",
                &format!(
                    "{}PROC SQUARE\nG91 G1 X10\nY10\nX-10\nY-10\nG90\nRET\n\
                     PROC L1234\nG1 Y5\nY0\nM17\nPROC FINISH\nG1 X20 Y20 F900\nM17\n",
                    SINUMERIK_MAIN.replace("EXTCALL \"FINISH\"", "FINISH")
                ),
            ),
        ],
    );
    let subs = vec![dir.join("spf")];
    let external = read(Dialect::Sinumerik, &dir.join("MAIN.MPF"), &subs);
    let pasted = read(Dialect::Sinumerik, &dir.join("PASTED.MPF"), &[]);
    assert_eq!(motion(&external), motion(&pasted));
    assert_eq!(external.points.len(), 2 + 8 + 2 + 1 + 1);
    // Without the directory the bare name is an error that says where to look.
    let e = fails(Dialect::Sinumerik, &dir.join("MAIN.MPF"), &[]);
    assert!(
        e.contains("MAIN.MPF:4:") && e.contains("--subprogram-dir"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// On the command line: `--subprogram-dir` reaches the reader; a warning and `check`'s
/// findings at a line of the called file name that file and line (text and JSON).
#[test]
fn warnings_and_check_findings_name_the_called_file() {
    let dir = scratch(
        "cli",
        &[
            (
                "main.ngc",
                "G21 G90 G17\nS10000 M3\nG0 X10 Y10 Z5\nG1 Z-1 F300\no<slot> call\nG0 Z5\nM2\n",
            ),
            (
                "subs/slot.ngc",
                "o<slot> sub\nG1 X50 F300\n/G1 Y12\nG0 X20 Y20 Z-2\no<slot> endsub\n",
            ),
        ],
    );
    let machine =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("problems/material_pocket/machine.json");
    let main = dir.join("main.ngc");
    let subs = dir.join("subs");
    let sub_file = subs.join("slot.ngc");
    let args = |cmd: &str, json: bool| {
        let mut a = vec![
            cmd.to_string(),
            "--machine".into(),
            machine.display().to_string(),
            main.display().to_string(),
            "--subprogram-dir".into(),
            subs.display().to_string(),
        ];
        if json {
            a.push("--json".into());
        }
        a
    };
    let run = |a: Vec<String>| feedopt(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let out = run(args("check", false));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    // The block-delete warning at line 3 of the called file.
    assert!(
        stderr.contains(&format!("{}:3: block delete", sub_file.display())),
        "{stderr}"
    );
    // The rapid into the stock at line 4 of the called file.
    assert!(
        stdout.contains(&format!("{}:4:", sub_file.display())),
        "{stdout}"
    );
    let out = run(args("check", true));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rapid = v["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["file"].as_str() == Some(&sub_file.display().to_string()))
        .unwrap_or_else(|| panic!("{v:#}"));
    assert_eq!(rapid["line"], 4);
    // Without the option the call is an error naming the line and the option.
    let out = feedopt(&[
        "solve",
        "--machine",
        &machine.display().to_string(),
        &main.display().to_string(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr.contains("main.ngc:5:")
            && stderr.contains("slot.ngc")
            && stderr.contains("--subprogram-dir"),
        "{stderr}"
    );
    // A directory that does not exist is a usage error.
    let out = feedopt(&[
        "solve",
        "--machine",
        &machine.display().to_string(),
        &main.display().to_string(),
        "--subprogram-dir",
        &dir.join("nowhere").display().to_string(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

const FANUC_G65_MAIN: &str = "O1000\n\
G21 G90 G94 G17\n\
G0 X0. Y0. Z5.\n\
#1 = 3.\n\
G65 P9010 A10. B2. L2\n\
G1 X#1 F300.\n\
M30\n";

const FANUC_O9010: &str = "O9010 (SQUARE OF SIDE #1 AT DEPTH #2)\n\
G1 Z-#2 F600.\n\
G91 X#1\n\
Y#1\n\
G90\n\
M99\n";

/// `G65 P9010 A10. B2. L2` reads `O9010.nc` to the points of the macro pasted into the file:
/// A and B are `#1` and `#2` in the body, and the caller's `#1`
/// comes back; an argument without a decimal point is an error (the control scales it by its
/// address's increment).
#[test]
fn fanuc_g65_passes_its_arguments_as_local_variables() {
    let dir = scratch(
        "g65",
        &[
            ("main.nc", FANUC_G65_MAIN),
            ("O9010.nc", FANUC_O9010),
            ("pasted.nc", &format!("{FANUC_G65_MAIN}{FANUC_O9010}")),
            ("bad.nc", &FANUC_G65_MAIN.replace("A10. B2.", "A10 B2.")),
        ],
    );
    let external = read(Dialect::Fanuc, &dir.join("main.nc"), &[]);
    let pasted = read(Dialect::Fanuc, &dir.join("pasted.nc"), &[]);
    assert_eq!(motion(&external), motion(&pasted));
    let xyz: Vec<[f64; 3]> = external
        .points
        .iter()
        .map(|p| [p.p.x, p.p.y, p.p.z])
        .collect();
    assert_eq!(
        xyz,
        vec![
            [0.0, 0.0, 5.0],
            [0.0, 0.0, -2.0],
            [10.0, 0.0, -2.0],
            [10.0, 10.0, -2.0],
            [10.0, 10.0, -2.0],
            [20.0, 10.0, -2.0],
            [20.0, 20.0, -2.0],
            [3.0, 20.0, -2.0],
        ]
    );
    let e = fails(Dialect::Fanuc, &dir.join("bad.nc"), &[]);
    assert!(
        e.contains("bad.nc:5:") && e.contains("decimal point"),
        "{e}"
    );
    // Specification II (I J K repeated) is refused, not read as I overwritten.
    std::fs::write(
        dir.join("bad.nc"),
        FANUC_G65_MAIN.replace("A10. B2.", "A10. B2. I1. I2."),
    )
    .unwrap();
    let e = fails(Dialect::Fanuc, &dir.join("bad.nc"), &[]);
    assert!(
        e.contains("bad.nc:5:") && e.contains("specification II"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

const KLARTEXT_MAIN: &str = "0  BEGIN PGM MAIN MM\n\
1  BLK FORM 0.1 Z  X+0  Y+0  Z-20\n\
2  BLK FORM 0.2  X+100  Y+100  Z+0\n\
3  TOOL CALL 1 Z S5000\n\
4  L  X+0  Y+0  Z+5 R0 FMAX M3\n\
5  L  Z+0 F600\n\
6  CALL PGM TNC:\\PARTS\\SQUARE.H\n\
7  L  X+50 F1200\n\
8  SEL PGM \"square\"\n\
9  CALL SELECTED PGM\n\
10 L  Z+5 FMAX\n\
11 END PGM MAIN MM\n";

/// Heidenhain `CALL PGM TNC:\PARTS\SQUARE.H` and `SEL PGM` + `CALL SELECTED PGM` read
/// `square.h` (its own label LBL 1, called and then run through) to the points of its blocks
/// written out in the main program; END PGM of the called program returns.
#[test]
fn heidenhain_call_pgm_reads_the_program_file() {
    let square = "0  BEGIN PGM SQUARE MM\n1  L  IX+10\n2  CALL LBL 1\n3  L  IY+10\n\
                  4  LBL 1\n5  L  IX+1\n6  LBL 0\n7  L  IX-10\n8  END PGM SQUARE MM\n";
    let body = "L  IX+10\nL  IX+1\nL  IY+10\nL  IX+1\nL  IX-10\n";
    let written = KLARTEXT_MAIN
        .replace("6  CALL PGM TNC:\\PARTS\\SQUARE.H\n", body)
        .replace("8  SEL PGM \"square\"\n9  CALL SELECTED PGM\n", body);
    let dir = scratch(
        "klartext",
        &[
            ("MAIN.H", KLARTEXT_MAIN),
            ("pgm/square.h", square),
            ("WRITTEN.H", &written),
        ],
    );
    let external = read(Dialect::Heidenhain, &dir.join("MAIN.H"), &[dir.join("pgm")]);
    let pasted = read(Dialect::Heidenhain, &dir.join("WRITTEN.H"), &[]);
    assert_eq!(motion(&external), motion(&pasted));
    assert_eq!(external.files.len(), 1);
    let e = fails(Dialect::Heidenhain, &dir.join("MAIN.H"), &[]);
    assert!(
        e.contains("MAIN.H:7:") && e.contains("SQUARE.h") && e.contains("--subprogram-dir"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Haas `M98 "pocket.nc" L2` reads the file of that name (any case) as `M98 P…` reads a
/// program, and repeats it.
#[test]
fn haas_m98_with_a_file_name() {
    let sub = "O2000\nG91 G1 X5. F300.\nG90\nM99\n";
    let dir = scratch(
        "haas",
        &[
            (
                "main.nc",
                "O1000\nG0 X0. Y0. Z0.\nM98 \"Pocket.NC\" L2\nM30\n",
            ),
            ("subs/pocket.nc", sub),
            (
                "pasted.nc",
                &format!("O1000\nG0 X0. Y0. Z0.\nM98 P2000 L2\nM30\n{sub}"),
            ),
        ],
    );
    let external = read(Dialect::Fanuc, &dir.join("main.nc"), &[dir.join("subs")]);
    let pasted = read(Dialect::Fanuc, &dir.join("pasted.nc"), &[]);
    assert_eq!(motion(&external), motion(&pasted));
    assert_eq!(external.points.last().unwrap().p.x, 10.0);
    let e = fails(Dialect::Fanuc, &dir.join("main.nc"), &[]);
    assert!(
        e.contains("main.nc:3:") && e.contains("Pocket.NC (any case)"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
