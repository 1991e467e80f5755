//! Seed corpora per target: the bundled `problems/`, small hand-made programs that use what
//! each reader knows (cycles, subprograms, expressions, frames, reference moves, arcs, NURBS,
//! CSV derivative columns), and — when `../shared` is beside the crate — excerpts of the real
//! programs there, each with its machine file.
//!
//! A G-code dialect is one row of [`DIALECTS`]: its hand-made programs, their machine file and
//! the dialect's own words for structure-aware mutations. The words of the dialect's table
//! ([`DialectSpec`]: every G and M code, keyword and named word) are added to the vocabulary
//! by themselves. The real programs are rows of [`SHARED`], each naming its dialect.

use std::path::{Path, PathBuf};

use feedopt::toolpath::apt::{NON_MOTION_WORDS, UNSUPPORTED_MOTION_WORDS};
use feedopt::toolpath::gcode::{Address, Dialect, DialectSpec};

use super::mutate::{PLAIN, Vocabulary, lines};

/// One seed: an input, the machine it runs on, and how to read it.
#[derive(Debug, Clone)]
pub struct Seed {
    /// Where it came from (`problems/...`, `hand-made linuxcnc 1`, `shared ... lines 1-40, …`).
    pub name: String,
    /// The toolpath's extension (`cls`, `ngc`, `csv`), or `json` for a machine file.
    pub ext: &'static str,
    /// The input's bytes (the toolpath, or the machine file itself for the machine target).
    pub text: Vec<u8>,
    /// The machine file the toolpath runs on (JSON).
    pub machine: Vec<u8>,
    /// The dialect of a G-code toolpath.
    pub dialect: Option<Dialect>,
}

/// A G-code dialect's row: the dialect, the extension of its programs, hand-made programs,
/// the machine file they run on, and words and lines of the dialect beyond its table
/// (constructs with arguments).
pub type DialectRow = (
    Dialect,
    &'static str,
    &'static [&'static str],
    &'static str,
    &'static [&'static str],
);

/// Every dialect fuzzed, one row each. Adding a dialect to [`Dialect::ALL`] adds its target
/// `gcode-<name>`; its row here gives it seeds (without one the short run fails and says so),
/// and its real programs are rows of [`SHARED`].
#[rustfmt::skip]
pub const DIALECTS: &[DialectRow] = &[
    (Dialect::LinuxCnc, "ngc", LINUXCNC_PROGRAMS, TRUNNION_AC, LINUXCNC_WORDS),
    (Dialect::Fanuc, "nc", FANUC_PROGRAMS, TRUNNION_BC, FANUC_WORDS),
    (Dialect::Sinumerik, "mpf", SINUMERIK_PROGRAMS, TRUNNION_BC, SINUMERIK_WORDS),
    (Dialect::Heidenhain, "h", HEIDENHAIN_PROGRAMS, TRUNNION_AC, HEIDENHAIN_WORDS),
];

/// Real programs under `../shared`: (program, machine file, reader: a dialect name or `apt`),
/// the machine files `realworld/cam/README.md` names. Machine files without `reference`
/// positions get `[0, 0]` on every axis (G28/G30 need them).
#[rustfmt::skip]
pub const SHARED: &[(&str, &str, &str)] = &[
    ("realworld/cam/elmoe_keychain.mpf", "realworld/cam/machines/trt_bc_spinner_u5.json", "sinumerik"),
    ("realworld/cam/nx_dmu70evo_840d.mpf", "realworld/cam/machines/headtable_dmu70.json", "sinumerik"),
    ("realworld/cam/nx_mori_nmv5000_mm.nc", "realworld/cam/machines/trt_bc_mori_nmv5000.json", "fanuc"),
    ("realworld/cam/nx_roeders_rfm600_finish.nc", "realworld/cam/machines/xyz_mill.json", "fanuc"),
    ("realworld/linuxcnc/boat-xyzac.ngc", "realworld/linuxcnc/boat-xyzac.machine.json", "linuxcnc"),
    ("realworld/linuxcnc/boat-xyzbc.ngc", "realworld/linuxcnc/boat-xyzbc.machine.json", "linuxcnc"),
    ("realworld/linuxcnc/impeller-7bl-xyzac.ngc", "realworld/linuxcnc/impeller-7bl-xyzac.machine.json", "linuxcnc"),
    ("realworld/cam/camotics_bear.nc", "realworld/cam/machines/xyz_mill.json", "linuxcnc"),
    ("realworld/cam/camotics_flower_mold.nc", "realworld/cam/machines/xyz_mill.json", "linuxcnc"),
    ("realworld/cam/aamorim_boss.apt", "realworld/cam/machines/xyz_mill.json", "apt"),
    ("realworld/cam/aamorim_basemach.apt", "realworld/cam/machines/xyz_mill.json", "apt"),
];

// ---------------------------------------------------------------------------------------------
// Machine files of the hand-made seeds
// ---------------------------------------------------------------------------------------------

/// An A/C trunnion with travel limits and reference positions (G28, G30).
pub const TRUNNION_AC: &str = r#"{
  "name": "trunnion A/C",
  "kinematics": {"type": "table_table_ac", "x-rot-point": 0, "y-rot-point": 0,
                 "z-rot-point": 0, "y-offset": 0, "z-offset": 20},
  "axes": {
    "X": {"velocity": 200, "acceleration": 1000, "min": -500, "max": 500, "reference": [0, -100]},
    "Y": {"velocity": 200, "acceleration": 1000, "reference": [0, 0]},
    "Z": {"velocity": 150, "acceleration": 800, "reference": [100, 50], "m92": 250},
    "A": {"velocity": 60, "acceleration": 300, "min": -120, "max": 120, "reference": [0, 0]},
    "C": {"velocity": 90, "acceleration": 400, "reference": [0, 0]}
  },
  "feed": {"max": 120}
}
"#;

/// A B/C trunnion with reference positions, jerk limits on the linear axes and a work offset.
pub const TRUNNION_BC: &str = r#"{
  "name": "trunnion B/C",
  "kinematics": {"type": "table_table_bc", "x-rot-point": 0, "y-rot-point": 0,
                 "z-rot-point": 0, "x-offset": 0, "z-offset": 0, "tool-offset": 0,
                 "conventional-directions": false, "work-offset": [0, 0, 10]},
  "axes": {
    "X": {"velocity": 500, "acceleration": 3000, "jerk": 30000, "reference": [0, 0]},
    "Y": {"velocity": 500, "acceleration": 3000, "jerk": 30000, "reference": [0, 0]},
    "Z": {"velocity": 500, "acceleration": 3000, "jerk": [-20000, 30000], "reference": [200, 150]},
    "B": {"velocity": 60, "acceleration": 600, "min": -120, "max": 120, "reference": 0},
    "C": {"velocity": [-60, 60], "acceleration": 600, "reference": [0, 0]}
  },
  "feed": {"max": 500}
}
"#;

/// Two joints for the joint CSV seeds.
pub const JOINT_MACHINE: &str = r#"{"name": "two joints", "kinematics": {"type": "joint"},
 "axes": {"a": {"velocity": [-1, 1.2], "acceleration": 2, "jerk": 20},
          "b": {"velocity": 0.8, "acceleration": [-3, 2.5]}}}
"#;

/// Three joints, with jerk limits on all of them.
pub const JOINT_MACHINE_3: &str = r#"{"name": "three joints", "kinematics": {"type": "joint"},
 "axes": {"j1": {"velocity": 2, "acceleration": 5, "jerk": 50},
          "j2": {"velocity": 2, "acceleration": 5, "jerk": 50},
          "j3": {"velocity": [-1, 3], "acceleration": [-4, 6], "jerk": [-40, 60]}}}
"#;

/// A B head on a C table (the machine of the hand-made APT seed).
pub const HEAD_TABLE: &str = r#"{
  "name": "B head + C table",
  "kinematics": {"type": "head_table", "pivot_length": 150},
  "axes": {
    "X": {"velocity": 300, "acceleration": 2000, "min": -400, "max": 400},
    "Y": {"velocity": 300, "acceleration": 2000},
    "Z": {"velocity": 300, "acceleration": 2000, "jerk": 40000},
    "B": {"velocity": 45, "acceleration": 300, "min": -100, "max": 100},
    "C": {"velocity": 90, "acceleration": 500}
  },
  "feed": {"max": 200}
}
"#;

// ---------------------------------------------------------------------------------------------
// Hand-made programs
// ---------------------------------------------------------------------------------------------

const LINUXCNC_PROGRAMS: &[&str] = &[
    "%\n(hand-made LinuxCNC program: TCP, arcs, helix, cycles, subprogram, parameters)\n\
o100 sub\n\
  G91 G1 X1 Y0.5 F600\n\
  G90\n\
o100 endsub\n\
#<depth> = -3\n\
#1 = 5\n\
G21 G90 G94 G17 G40 G49 G54\n\
G0 X0 Y0 Z10 A0 C0\n\
M428\n\
G1 Z0 F3000\n\
G1 X10 Y2 A5 C10\n\
G1 X[#1*4] Y0 A10 C25 F2400\n\
G2 X30 Y0 I5 J0 F1500\n\
G3 X40 Y0 R5\n\
G2 X40 Y0 Z-1 I-5 J0 P2\n\
G18 G2 X45 Z-1 I2.5 K0\n\
G17\n\
G93 G1 X45 A0 C0 F120\n\
G94 F1000\n\
M429\n\
G0 Z5\n\
G98 G81 X5 Y5 Z#<depth> R2 F300\n\
X10 Y5\n\
G99 G83 X15 Y5 Z-6 R2 Q2\n\
G73 X20 Y5 Z-4 R1 Q1.5 L2\n\
G82 X25 Y5 Z-2 R2 P0.5\n\
G80\n\
G0 X25 Y5 Z2\n\
G90.1 G2 X30 Y10 I25 J10 F800\n\
G91.1\n\
o100 call\n\
G4 P0.5\n\
G91 G28 Z0\n\
G90\n\
G30 X0 Y0\n\
G53 G0 Z-10\n\
M2\n%\n",
    "G20 G90 G0 X0 Y0 Z0\nG1 X1 Y1 F10\nM428\nG93 G1 X2 A30 F2\nG94\nG3 X0 Y1 I-1 J-1 P3 F20\n\
G91 G1 X0.5 Y-0.25 Z0.1\nG90\nM2\n",
];

const LINUXCNC_WORDS: &[&str] = &[
    "o100 call",
    "o100 sub",
    "o100 endsub",
    "o100 return",
    "o<sq> call",
    "#<x> = [#1 + 2]",
    "#5 = [SIN[30] * 10]",
    "X#<depth>",
    "G98 G83 X1 Y1 Z-5 R2 Q1 F100",
    "G91 G28 Z0",
    "G2 X0 Y0 I5 J0 P3",
    "(MSG, hello)",
    "; a comment",
    "/G1 X5",
    "N100",
];

const FANUC_PROGRAMS: &[&str] = &[
    "%\nO1000 (HAND-MADE FANUC: TCP, VECTORS, G68.2, CYCLES, SUBPROGRAM, VARIABLES)\n\
G21 G90 G94 G17 G40 G49 G80\n\
#100=5.\n\
#101=[#100*2.+1.]\n\
G28 G91 Z0.\n\
G90 G54 G0 X0. Y0. B0. C0.\n\
G43.4 H1 Z50.\n\
G1 X10. Y5. Z2. B10. C20. F1000.\n\
G1 X#100 Y[#101-6.] B15. C40.\n\
G2 X15. Y5. I5. J0. F800.\n\
G3 X10. Y5. R5.\n\
G49\n\
G0 Z50. B0. C0.\n\
G68.2 X0. Y0. Z0. I0. J30. K0.\n\
G53.1\n\
G0 X0. Y0. Z10.\n\
G1 Z-1. F300.\n\
G69\n\
G0 Z50.\n\
G43.5 H1\n\
G1 X5. Y5. Z5. I0. J0.5 K1. F1200.\n\
G1 X6. I0.1 J0.4 K1.\n\
G49\n\
G0 Z20.\n\
G98 G81 X10. Y10. Z-5. R2. F200.\n\
G83 X20. Y10. Z-8. R2. Q2.\n\
G82 X30. Y10. Z-3. R2. P500\n\
G73 X40. Y10. Z-4. R1. Q1. K2\n\
G80\n\
G0 Z50.\n\
M98 P2000 L2\n\
G4 P250\n\
G30 G91 Z0.\n\
G90\n\
M30\n\
O2000 (STEP)\n\
G91 G1 X1. F600.\n\
G1 Y1.\n\
G90\n\
M99\n\
%\n",
    "O0001\nG90 G54 G0 X1000 Y2000 Z3000\nG1 X5000 Y-2000 F100.\nG2 X7000 Y0 R2000\nM30\n",
    // Macro B control flow, and a rotary axis turning with X (the combined-distance feed).
    "O0002 (MACRO B)\nG21 G90 G94 G17\n#1=0.\n#4=63./2.\nG0 X0. Y0. Z5. C0.\n\
WHILE [#1 LT 3.] DO1\nG1 X[#1*10.] Y#4 F500.\nIF [#1 EQ 1.] THEN #2=5.\n\
IF [#1 GT 5.] GOTO 20\n#1=#1+1.\nEND1\nG1 X30. C45. F300.\nN20 G0 Z50.\nM30\n",
];

const FANUC_WORDS: &[&str] = &[
    "M98 P2000",
    "M98 P2000 L3",
    "M98 P32000",
    "O2000",
    "M99",
    "#100=[#101/2.]",
    "#102=SIN[30.]",
    "X[#100+1.]",
    "G68.2 X0 Y0 Z0 I45. J20. K0",
    "G43.4 H1",
    "G43.5 H1",
    "G98 G83 X1. Y1. Z-5. R2. Q1. F100.",
    "G4 X1.5",
    "G10 L2 P1 X0 Y0 Z0",
    "G28 X0. Y0.",
    "G30 P3 Z0.",
    "(COMMENT)",
    "%",
    // (Loop and jump words inserted alone mostly end a program in an error — a DO without
    // END, a GOTO to a missing N — and the seed program has them.)
    "N20",
    "IF [#1 EQ 1.] THEN #2=3.",
    "#1=#1+1.",
    "G1 X5. C30. F200.",
];

/// Heidenhain Klartext: lines, arcs, Q parameters, TCPM, datum shift, tilted plane, cycles,
/// patterns, labels and jumps.
const HEIDENHAIN_PROGRAMS: &[&str] = &[
    include_str!("../common/everything.h"),
    // Cycles added on 2026-11-26: reaming, boring, tapping with chip breaking, single-lip
    // deep-hole drilling (thread milling, 262, needs a tool diameter the seeds cannot give:
    // every seed must read cleanly).
    "0 BEGIN PGM CYC MM\n1 TOOL CALL 5 Z S3000\n2 L X+30 Y+40 Z+50 R0 FMAX\n\
3 CYCL DEF 201 REAMING ~\n Q200=2 ;SET-UP CLEARANCE ~\n Q201=-15 ;DEPTH ~\n\
 Q206=100 ;FEED RATE FOR PLNGNG ~\n Q211=0.5 ;DWELL TIME AT DEPTH ~\n\
 Q208=250 ;RETRACTION FEED RATE ~\n Q203=+0 ;SURFACE COORDINATE ~\n\
 Q204=50 ;2ND SET-UP CLEARANCE\n4 L X+30 Y+40 R0 FMAX M99\n\
5 CYCL DEF 202 BORING ~\n Q200=2 ~\n Q201=-15 ~\n Q206=100 ~\n Q211=0 ~\n Q208=250 ~\n\
 Q203=+0 ~\n Q204=50 ~\n Q214=1 ;DISENGAGING DIRECTN ~\n Q336=0 ;ANGLE OF SPINDLE\n\
6 L X+50 R0 FMAX M99\n\
7 CYCL DEF 209 TAPPING W/ CHIP BRKG ~\n Q200=2 ~\n Q201=-12 ~\n Q239=+1.5 ;PITCH ~\n\
 Q203=+0 ~\n Q204=50 ~\n Q257=4 ;DEPTH FOR CHIP BRKNG ~\n Q256=1 ;DIST FOR CHIP BRKNG ~\n\
 Q336=0 ~\n Q403=1.5 ;RPM FACTOR\n8 L X+70 R0 FMAX M99\n\
9 CYCL DEF 241 SINGLE-LIP D.H.DRLNG ~\n Q200=2 ~\n Q201=-40 ~\n Q206=150 ~\n Q211=0 ~\n\
 Q203=+0 ~\n Q204=50 ~\n Q379=7.5 ;STARTING POINT ~\n Q253=750 ;F PRE-POSITIONING ~\n\
 Q208=1000 ~\n Q426=3 ;DIR. OF SPINDLE ROT. ~\n Q427=0 ~\n Q428=0 ~\n Q429=0 ~\n\
 Q430=0 ;COOLANT OFF\n10 L X+90 R0 FMAX M99\n\
11 END PGM CYC MM\n",
];

/// Klartext words and blocks for structure-aware mutations.
const HEIDENHAIN_WORDS: &[&str] = &[
    "FMAX", "F MAX", "FAUTO", "F500", "R0", "DR+", "DR-", "IX+2", "IZ-1", "X+Q1", "M128", "M129",
    "M99", "M126", "TX+0", "TY-0.5", "TZ+0.866", "NZ+1", "PA+30", "PR+5", "R+4",
];

const SINUMERIK_PROGRAMS: &[&str] = &[
    "; hand-made Sinumerik program: variables, TRAORI, vectors, frames, cycles, subprograms\n\
DEF REAL _Z_HOME=50, _DEPTH\n\
R1=5\n\
_DEPTH=-3\n\
G71 G90 G94 G17\n\
SUPA G0 Z=_Z_HOME D0\n\
G0 X0 Y0 B0 C0\n\
TRAORI\n\
G1 X10 Y2 Z5 B5 C10 F3000\n\
G1 X=R1*4 Y0 B10 C25 F2400\n\
G2 X30 Y0 I5 J0 F1500\n\
G3 X40 Y0 CR=5\n\
G2 X40 Y0 Z-1 I-5 J0 TURN=1\n\
G1 X10 Y10 Z10 A3=0 B3=0.2 C3=1\n\
G1 X12 A3=0.1 B3=0 C3=1\n\
TRAFOOF\n\
G0 Z50 B0 C0\n\
CYCLE800(1,\"TC1\",0,57,0,0,0,0,30,0,0,0,0,-1,100,1)\n\
G0 X0 Y0 Z10\n\
G1 Z-1 F300\n\
CYCLE800()\n\
TRANS X10\n\
AROT Z30\n\
G0 X5 Y5 Z5\n\
ATRANS Y2\n\
G1 X6 F500\n\
TRANS\n\
G0 Z20\n\
F120\n\
MCALL CYCLE83(20,0,2,_DEPTH,,-1,,1,,,,1)\n\
X10 Y10\n\
X20\n\
MCALL\n\
CYCLE81(10,0,2,-2)\n\
G4 F1\n\
MYSUB P2\n\
L123\n\
G700 G1 X1 F10\n\
G710\n\
M30\n\
PROC MYSUB\n\
G91 G1 X1 F600\n\
G90\n\
RET\n\
%_N_L123_SPF\n\
G1 Y7\n\
M17\n",
    "N10 G71 G90 G0 X0 Y0 Z5\nN20 G1 X10 F1000\nN30 G2 X20 Y0 CR=5\nN40 G3 X10 Y0 CR=-5\n\
N50 ROT Z45\nN60 G1 X5 Y5\nN70 ROT\nN80 M30\n",
];

const SINUMERIK_WORDS: &[&str] = &[
    "CYCLE84 (10, 0, 2, -20, , 0, 3, 10, 1.5, 0, 800, 800)",
    "CYCLE81 (10, 0, 2, -5)",
    "TRAOOF",
    "DEF REAL _A=5",
    "DEF REAL _B, _C",
    "R2=R1*R1+1",
    "X=R1*2",
    "Z=(R1+1)/2",
    "X=_Z_HOME",
    "MCALL CYCLE83(20,0,2,-10,,-4,,,,,,1)",
    "MCALL CYCLE81(10,0,2,-2)",
    "MCALL",
    "CYCLE82(10,0,2,-3,,1)",
    "CYCLE800(1,\"TC1\",0,57,0,0,0,0,30,0,0,0,0,-1,100,1)",
    "CYCLE800()",
    "TRANS X10 Y5",
    "ATRANS Z-2",
    "ROT Z30",
    "AROT X15",
    "TRANS",
    "SUPA G0 Z100 D0",
    "MYSUB",
    "MYSUB P3",
    "L123",
    "PROC MYSUB",
    "RET",
    "EXTERN MYSUB",
    "MSG(\"HELLO\")",
    "TURN=",
    "CR=",
    "A3=",
    "B3=",
    "C3=",
];

const APT_PROGRAMS: &[&str] = &[
    "$$ hand-made APT: units, feeds, arcs, frames, cycles, NURBS, continuation\n\
PARTNO/HAND MADE\n\
UNITS/MM\n\
MULTAX/ON\n\
FROM/0,0,50,0,0,1\n\
RAPID\n\
GOTO/10,0,5,0,0,1\n\
FEDRAT/MMPM,1200\n\
GOTO/10,0,0\n\
CIRCLE/0,0,0,0,0,1,10\n\
GOTO/0,10,0\n\
CIRCLE/0,0,0,0,0,1,10,0.05,0.5,10,0\n\
GOTO/0,10,-1\n\
GOTO/5,10,-1,0.1,0,$\n\
0.99498744\n\
FEDRAT/500,MMPM\n\
MSYS/10,0,0,0,1,0,-1,0,0\n\
GOTO/1,0,0,1,0,0\n\
MSYS/\n\
CYCLE/DEEP,FEDTO,10,STEP,2,MMPM,100,RAPTO,3,RTRCTO,25\n\
GOTO/0,0,0\n\
GOTO/20,0,0\n\
CYCLE/OFF\n\
CYCLE/DRILL,5,MMPM,150,2\n\
GOTO/30,0,0\n\
CYCLE/OFF\n\
NURBS/\n\
KNOT/0,0,0,1,1,1\n\
CNTRL/0,0,0\n\
CNTRL/10,10,0\n\
CNTRL/20,0,0\n\
GOTO/1,2,3\n\
UNITS/INCHES\n\
FEDRAT/IPM,20\n\
GOTO/1,1,1\n\
MULTAX/OFF\n\
GOTO/2,1,1,0,0,0\n\
END\n\
FINI\n",
];

const APT_LINES: &[&str] = &[
    "GOTO/1,2,3",
    "GOTO/1,2,3,0,0,1",
    "GOTO/5,5,5,0.5,0.5,0.7071",
    "FEDRAT/MMPM,100",
    "FEDRAT/IPM,10",
    "FEDRAT/MMPR,0.1",
    "RAPID",
    "MULTAX/ON",
    "MULTAX/OFF",
    "UNITS/INCHES",
    "UNITS/MM",
    "CIRCLE/0,0,0,0,0,1,5",
    "MOVARC/0,0,0,0,0,-1,5",
    "CYCLE/DRILL,FEDTO,5,MMPM,100,RAPTO,2",
    "CYCLE/DEEP,FEDTO,10,STEP,0.5,MMPM,100,RAPTO,3,RTRCTO,25,DWELL,1",
    "CYCLE/BRKCHP,FEDTO,8,STEP,1,MMPM,80,RAPTO,2",
    "CYCLE/TAP,FEDTO,8,MMPM,80,RAPTO,2",
    "CYCLE/OFF",
    "MSYS/0,0,0,1,0,0,0,1,0",
    "MSYS/5,5,5,0,1,0,0,0,1",
    "MSYS/",
    "NURBS/",
    "KNOT/0,0,0,0,1,1,1,1",
    "CNTRL/0,0,0,2",
    "FROM/0,0,0",
    "$$ comment",
    "GOTO/1,$",
    "UNIT/MM",
];

// ---------------------------------------------------------------------------------------------
// Joint CSV seeds
// ---------------------------------------------------------------------------------------------

/// Two joints along s ∈ [0, 1], with first and second derivatives.
fn joint_csv() -> String {
    let mut t = String::from("s,q_a,q_b,dq_a,dq_b,ddq_a,ddq_b\n");
    for i in 0..=20 {
        let s = i as f64 / 20.0;
        let (a, b) = ((3.0 * s).sin(), s * s);
        let (da, db) = (3.0 * (3.0 * s).cos(), 2.0 * s);
        let (dda, ddb) = (-9.0 * (3.0 * s).sin(), 2.0);
        t.push_str(&format!("{s},{a},{b},{da},{db},{dda},{ddb}\n"));
    }
    t
}

/// Three joints along s ∈ [0, 2] with derivatives up to the third, a comment and blank line.
fn joint_csv_3() -> String {
    let mut t = String::from(
        "# three joints, q, dq, ddq, dddq\n\ns,q_j1,q_j2,q_j3,dq_j1,dq_j2,dq_j3,ddq_j1,ddq_j2,ddq_j3,dddq_j1,dddq_j2,dddq_j3\n",
    );
    for i in 0..=30 {
        let s = 2.0 * i as f64 / 30.0;
        let q = [s.cos(), 0.5 * s, (s * s * s) / 8.0];
        let d = [-s.sin(), 0.5, 3.0 * s * s / 8.0];
        let dd = [-s.cos(), 0.0, 6.0 * s / 8.0];
        let ddd = [s.sin(), 0.0, 6.0 / 8.0];
        let cells: Vec<String> = std::iter::once(s)
            .chain(q)
            .chain(d)
            .chain(dd)
            .chain(ddd)
            .map(|x| format!("{x:.9}"))
            .collect();
        t.push_str(&cells.join(","));
        t.push('\n');
    }
    t
}

/// Positions only (a spline is fitted), unevenly spaced in s.
fn joint_csv_plain() -> String {
    let mut t = String::from("s,q_a,q_b\n");
    for i in 0..=25 {
        let s = (i as f64 / 25.0).powf(1.3) * 4.0;
        t.push_str(&format!(
            "{s},{},{}\n",
            (s * 0.7).sin() * 0.5,
            1.0 - (-s).exp()
        ));
    }
    t
}

const CSV_WORDS: &[&str] = &["s", "q_a", "dq_a", "ddq_b", "dddq_a", "q_c", "q_", "s_"];

// ---------------------------------------------------------------------------------------------
// Machine files
// ---------------------------------------------------------------------------------------------

const MACHINE_WORDS: &[&str] = &[
    "name",
    "kinematics",
    "axes",
    "feed",
    "type",
    "xyz",
    "joint",
    "head_head",
    "head_table",
    "table_table_ac",
    "table_table_bc",
    "table_table_ab",
    "dresser",
    "tool_length",
    "pivot_length",
    "x-rot-point",
    "z-offset",
    "work-offset",
    "conventional-directions",
    "velocity",
    "acceleration",
    "jerk",
    "min",
    "max",
    "reference",
    "X",
    "A",
    "B",
    "C",
    "U",
    "true",
    "null",
    "[-1, 2]",
    "[0, 0, 0]",
    "{}",
    "[]",
];

const MACHINE_LINES: &[&str] = &[
    "\"jerk\": 5000,",
    "\"reference\": [0, -100],",
    "\"min\": -100, \"max\": 100,",
    "\"velocity\": [-50, 80],",
    "\"feed\": {\"max\": 100},",
    "\"Y\": {\"velocity\": 10, \"acceleration\": 100},",
    "\"B\": {\"velocity\": 10, \"acceleration\": 100, \"min\": -90, \"max\": 90},",
    "\"tool_length\": 150,",
    "\"work-offset\": [1, 2, 3],",
];

// ---------------------------------------------------------------------------------------------
// Assembling the corpora
// ---------------------------------------------------------------------------------------------

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// `../shared` beside the crate.
pub fn shared_dir() -> PathBuf {
    repo("../shared")
}

fn file(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The first `n` lines of `bytes`.
pub fn head(bytes: &[u8], n: usize) -> Vec<u8> {
    let ls = lines(bytes);
    match ls.get(n.min(ls.len()).saturating_sub(1)) {
        Some(l) => bytes[..l.1].to_vec(),
        None => Vec::new(),
    }
}

/// The first `n` lines of `bytes`, and more while the last one continues into the next
/// ([`continues`]: an APT arc without its `GOTO`).
fn head_whole(bytes: &[u8], n: usize) -> Vec<u8> {
    let ls = lines(bytes);
    let mut k = n.min(ls.len());
    while k > 0
        && k < ls.len()
        && continues(&String::from_utf8_lossy(&bytes[ls[k - 1].0..ls[k - 1].1]))
    {
        k += 1;
    }
    head(bytes, k)
}

/// Lines a record continues on (`$` at the end) or that an APT arc or curve needs the next
/// record for: a window does not end on them.
fn continues(line: &str) -> bool {
    let l = line.trim_end().to_ascii_uppercase();
    l.ends_with('$')
        || ["CIRCLE/", "MOVARC/", "NURBS", "KNOT/", "CNTRL/", "CYCLE/"]
            .iter()
            .any(|w| l.starts_with(w))
}

/// Whether a window may start at `line` (after `prev`): at a straight move that sets the
/// position from which the next arc starts (a G-code `G0`/`G1` block with X and Y, an APT
/// `GOTO` that does not end an arc), so that no arc starts from a point of another window.
fn starts_window(line: &str, prev: &str) -> bool {
    let l = line.to_ascii_uppercase();
    let p = prev.trim_start().to_ascii_uppercase();
    if l.trim_start().starts_with("GOTO/") {
        return !(p.starts_with("CIRCLE/") || p.starts_with("MOVARC/") || p.ends_with('$'));
    }
    let b = l.as_bytes();
    let word = |i: usize, letter: u8| {
        b[i] == letter && (i == 0 || !b[i - 1].is_ascii_alphanumeric() && b[i - 1] != b'_')
    };
    let number_after = |i: usize| b.get(i + 1).is_some_and(|c| b"=-+.0123456789".contains(c));
    let straight = (0..b.len()).any(|i| {
        if !word(i, b'G') {
            return false;
        }
        let digits: Vec<u8> = b[i + 1..]
            .iter()
            .copied()
            .take_while(|c| c.is_ascii_digit() || *c == b'.')
            .collect();
        matches!(&digits[..], b"0" | b"1" | b"00" | b"01")
    });
    let has = |letter: u8| (0..b.len()).any(|i| word(i, letter) && number_after(i));
    straight && has(b'X') && has(b'Y')
}

/// The first line at or after `from` (before `to`) where a window may start, else `from`.
fn window_start(ls: &[&str], from: usize, to: usize) -> usize {
    (from..to)
        .find(|&i| i > 0 && starts_window(ls[i], ls[i - 1]))
        .unwrap_or(from)
}

/// An excerpt of a long program: its header (the lines that set modes), `windows` windows of
/// `size` lines spread over the file (`phase` ∈ [0, 1) shifts them; each starts at a straight
/// move: [`starts_window`]), and its last lines (the program end, subprograms after it). A program of at most `HEADER + windows · size +
/// FOOTER` lines is kept whole. The name says which lines were kept.
pub fn excerpt(text: &str, windows: usize, size: usize, phase: f64) -> (String, String) {
    const HEADER: usize = 40;
    const FOOTER: usize = 15;
    let ls: Vec<&str> = text.lines().collect();
    let n = ls.len();
    if n <= HEADER + windows * size + FOOTER {
        return (text.to_string(), format!("all {n} lines"));
    }
    let mut ranges = vec![(0, HEADER)];
    let body = n - HEADER - FOOTER;
    for w in 0..windows {
        let start = HEADER + ((w as f64 + phase) / windows as f64 * body as f64) as usize;
        let start = window_start(&ls, start, (start + size).min(n - FOOTER));
        let mut end = (start + size).min(n - FOOTER);
        // Do not cut a record from the one it needs.
        while end < n - FOOTER && end > start && continues(ls[end - 1]) {
            end += 1;
        }
        ranges.push((start.max(ranges.last().map_or(0, |r| r.1)), end));
    }
    let footer = window_start(&ls, n - FOOTER, n);
    let footer = if footer > n - FOOTER {
        footer
    } else {
        n - FOOTER
    };
    ranges.push((footer.max(ranges.last().map_or(0, |r| r.1)), n));
    let mut out = String::new();
    let mut names = Vec::new();
    for (a, b) in ranges {
        if a >= b {
            continue;
        }
        for l in &ls[a..b] {
            out.push_str(l);
            out.push('\n');
        }
        names.push(format!("{}-{}", a + 1, b));
    }
    (out, format!("lines {}", names.join(", ")))
}

/// A machine file from `../shared` with `reference: [0, 0]` on every axis that has none.
fn shared_machine(path: &Path) -> Vec<u8> {
    let text = String::from_utf8(file(path)).expect("UTF-8 machine file");
    let mut json: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    if let Some(axes) = json.get_mut("axes").and_then(|a| a.as_object_mut()) {
        for axis in axes.values_mut() {
            if axis.get("reference").is_none() {
                axis["reference"] = serde_json::json!([0.0, 0.0]);
            }
        }
    }
    let mut out = serde_json::to_string_pretty(&json).expect("serialises");
    out.push('\n');
    out.into_bytes()
}

/// The excerpts of the real programs for `reader` (a dialect name or `apt`): two per program
/// (windows at two phases), a few hundred lines each.
fn shared_seeds(reader: &str) -> Vec<Seed> {
    let dir = shared_dir();
    let mut out = Vec::new();
    for &(program, machine, r) in SHARED {
        if r != reader {
            continue;
        }
        let path = dir.join(program);
        let bytes = file(&path);
        let text = String::from_utf8_lossy(&bytes);
        let machine = shared_machine(&dir.join(machine));
        let ext = match path.extension().and_then(|e| e.to_str()) {
            Some("apt") => "apt",
            Some("mpf") => "mpf",
            Some("ngc") => "ngc",
            _ => "nc",
        };
        let dialect = Dialect::ALL.into_iter().find(|d| d.name() == reader);
        for phase in [0.0, 0.5] {
            let (t, which) = excerpt(&text, 4, 60, phase);
            out.push(Seed {
                name: format!("../shared/{program} ({which})"),
                ext,
                text: t.into_bytes(),
                machine: machine.clone(),
                dialect,
            });
            if which.starts_with("all") {
                break;
            }
        }
    }
    out
}

/// The seeds of the APT target.
pub fn apt(shared: bool) -> Vec<Seed> {
    let mut out = Vec::new();
    for (p, m) in [
        (
            "problems/seed_head_head/impeller_blade.cls",
            "problems/seed_head_head/machine.json",
        ),
        (
            "problems/xyz_pocket/pocket_contour.cls",
            "problems/xyz_pocket/machine.json",
        ),
    ] {
        out.push(Seed {
            name: p.to_string(),
            ext: "cls",
            text: file(&repo(p)),
            machine: file(&repo(m)),
            dialect: None,
        });
    }
    for (k, t) in APT_PROGRAMS.iter().enumerate() {
        out.push(Seed {
            name: format!("hand-made apt {}", k + 1),
            ext: "cls",
            text: t.as_bytes().to_vec(),
            machine: HEAD_TABLE.as_bytes().to_vec(),
            dialect: None,
        });
    }
    if shared {
        out.extend(shared_seeds("apt"));
    }
    out
}

/// The row of `dialect` in [`DIALECTS`].
pub fn dialect_row(dialect: Dialect) -> Option<&'static DialectRow> {
    DIALECTS.iter().find(|r| r.0 == dialect)
}

/// The seeds of the G-code target of `dialect` (empty when it has no row).
pub fn gcode(dialect: Dialect, shared: bool) -> Vec<Seed> {
    let Some(&(_, ext, programs, machine, _)) = dialect_row(dialect) else {
        return Vec::new();
    };
    let mut out: Vec<Seed> = programs
        .iter()
        .enumerate()
        .map(|(k, t)| Seed {
            name: format!("hand-made {} {}", dialect.name(), k + 1),
            ext,
            text: t.as_bytes().to_vec(),
            machine: machine.as_bytes().to_vec(),
            dialect: Some(dialect),
        })
        .collect();
    if shared {
        out.extend(shared_seeds(dialect.name()));
    }
    out
}

/// The seeds of the joint CSV target.
pub fn joint_csv_seeds() -> Vec<Seed> {
    [
        (
            "generated: two joints, q dq ddq",
            joint_csv(),
            JOINT_MACHINE,
        ),
        (
            "generated: three joints, q dq ddq dddq",
            joint_csv_3(),
            JOINT_MACHINE_3,
        ),
        (
            "generated: two joints, q only",
            joint_csv_plain(),
            JOINT_MACHINE,
        ),
    ]
    .into_iter()
    .map(|(name, text, machine)| Seed {
        name: name.to_string(),
        ext: "csv",
        text: text.into_bytes(),
        machine: machine.as_bytes().to_vec(),
        dialect: None,
    })
    .collect()
}

/// Every toolpath seed (APT, each dialect, joint CSV).
pub fn toolpaths(shared: bool) -> Vec<Seed> {
    let mut out = apt(shared);
    for d in Dialect::ALL {
        out.extend(gcode(d, shared));
    }
    out.extend(joint_csv_seeds());
    out
}

/// The seeds of the machine-file target: every machine file the toolpath seeds run on, once.
pub fn machines(shared: bool) -> Vec<Seed> {
    let mut out: Vec<Seed> = Vec::new();
    for s in toolpaths(shared) {
        if out.iter().all(|m| m.text != s.machine) {
            out.push(Seed {
                name: format!("machine of {}", s.name),
                ext: "json",
                text: s.machine.clone(),
                machine: s.machine,
                dialect: None,
            });
        }
    }
    let jerk = repo("problems/seed_head_head/machine_jerk.json");
    out.push(Seed {
        name: "problems/seed_head_head/machine_jerk.json".into(),
        ext: "json",
        text: file(&jerk),
        machine: file(&jerk),
        dialect: None,
    });
    out
}

/// The seeds of the CLI target: every toolpath seed with its machine, the long ones cut to
/// their first `max_lines` lines so that each solve stays short.
pub fn solves(shared: bool, max_lines: usize) -> Vec<Seed> {
    toolpaths(shared)
        .into_iter()
        .map(|mut s| {
            if lines(&s.text).len() > max_lines && s.ext != "csv" {
                s.text = head_whole(&s.text, max_lines);
                s.name = format!("{} (first {max_lines} lines)", s.name);
            }
            s
        })
        .collect()
}

/// The mutation vocabulary of a G-code dialect: every code and word of its table, with
/// numbers where they take one, and the row's constructs.
pub fn gcode_vocabulary(dialect: Dialect) -> Vocabulary {
    let spec: &DialectSpec = dialect.spec();
    let mut words: Vec<String> = Vec::new();
    let codes = |prefix: char, table: &[(&str, feedopt::toolpath::gcode::Action)]| {
        let mut out = Vec::new();
        for (code, _) in table {
            match code.split_once("..") {
                Some((lo, hi)) => {
                    let (lo, hi): (u32, u32) = (lo.parse().unwrap_or(0), hi.parse().unwrap_or(0));
                    out.push(format!("{prefix}{lo}"));
                    out.push(format!("{prefix}{hi}"));
                }
                None => out.push(format!("{prefix}{code}")),
            }
        }
        out
    };
    words.extend(codes('G', spec.g_codes));
    words.extend(codes('M', spec.m_codes));
    words.extend(spec.keywords.iter().map(|(k, _)| k.to_string()));
    words.extend(spec.named.iter().map(|(n, _)| format!("{n}=")));
    for (letter, address) in spec.letters {
        if !matches!(address, Address::G | Address::M) {
            words.push(letter.to_string());
        }
    }
    let extra = dialect_row(dialect).map_or(&[][..], |r| r.4);
    words.extend(extra.iter().map(|w| w.to_string()));
    Vocabulary {
        lines: extra.iter().map(|w| w.to_string()).collect(),
        words,
        csv: false,
    }
}

/// The mutation vocabulary of APT: the records above, every known major word.
pub fn apt_vocabulary() -> Vocabulary {
    let mut words: Vec<String> = [
        "GOTO/", "GODLTA/", "FEDRAT/", "MMPM", "IPM", "FEDTO", "STEP",
    ]
    .iter()
    .chain(
        [
            "RAPTO", "RTRCTO", "DWELL", "ON", "OFF", "DRILL", "DEEP", "BRKCHP",
        ]
        .iter(),
    )
    .map(|s| s.to_string())
    .collect();
    words.extend(NON_MOTION_WORDS.iter().map(|w| format!("{w}/")));
    words.extend(UNSUPPORTED_MOTION_WORDS.iter().map(|w| format!("{w}/")));
    let mut lines: Vec<String> = APT_LINES.iter().map(|s| s.to_string()).collect();
    lines.extend(["GODLTA/0,0,5".to_string(), "GODLTA/-2.5".to_string()]);
    lines.extend(NON_MOTION_WORDS.iter().map(|w| format!("{w}/1")));
    lines.extend(
        UNSUPPORTED_MOTION_WORDS
            .iter()
            .map(|w| format!("{w}/1,2,3")),
    );
    Vocabulary {
        words,
        lines,
        csv: false,
    }
}

/// The mutation vocabulary of the joint CSV: column names, numbers, columns.
pub fn csv_vocabulary() -> Vocabulary {
    let mut words: Vec<String> = CSV_WORDS.iter().map(|s| s.to_string()).collect();
    words.extend(PLAIN.iter().map(|s| s.to_string()));
    Vocabulary {
        words,
        lines: vec!["# comment".into(), String::new(), "1,2,3".into()],
        csv: true,
    }
}

/// The mutation vocabulary of machine files: keys and kinematics types (a word replaces one
/// inside its quotes), values, whole members.
pub fn machine_vocabulary() -> Vocabulary {
    Vocabulary {
        words: MACHINE_WORDS.iter().map(|s| s.to_string()).collect(),
        lines: MACHINE_LINES.iter().map(|s| s.to_string()).collect(),
        csv: false,
    }
}
