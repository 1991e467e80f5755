//! Robustness (issues 12 and 14): no input makes a reader panic. Deterministic mutations of
//! the bundled programs and small hand-written ones in every dialect — byte flips, deleted
//! and duplicated lines, truncation, extreme numbers — are read by the APT and G-code readers;
//! each must return a toolpath or an error, never panic.

use feedopt::toolpath::apt;
use feedopt::toolpath::gcode::{Dialect, parse};
use std::path::Path;

/// A small deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const EXTREMES: &[&str] = &[
    "1e309",
    "-1e309",
    "1E5",
    "99999999999999999999",
    "0.000000000001",
    "-0",
    "NaN",
    "inf",
    "P1000000000",
    "TURN=100000000",
    "I1e12",
    "I1000000000000",
    "#1",
    "[#1+",
    "R1=R1*R1*R1",
    "Q0",
    "Q-1",
    "L1000000",
    "K999999",
    "(",
    "((",
    ")",
    "\"",
    "=",
    ",,,,",
    "$",
    "/",
];

const SEEDS_GCODE: &[&str] = &[
    "G21 G90 G0 X0 Y0 Z10\nG98 G83 X5 Y0 Z-3 R2 Q2 F60\nX10\nG80\nG2 X20 Y0 I5 J0\nG91 G28 Z0\nM30\n",
    "O0001\nG90 G54 G0 X1. Y2. Z3.\nG43.4 H1\nG1 X5. B10. C20. F100.\nG68.2 X0 Y0 Z0 I0 J30. K0\nG53.1\nG1 Z-1.\nG69\n#100=5.\nG1 X#100 Y[#100*2]\nG4 P500\nG10 L2 P1 X0 Y0 Z0\nM30\n",
    "DEF REAL _Z_HOME, _X\n_Z_HOME=50\nG71 G90 G0 X0 Y0 Z=_Z_HOME\nTRAORI\nCYCLE800(1,\"TC1\",0,57,0,0,0,0,30,0,0,0,0,-1,100,1)\nF120\nMCALL CYCLE83(20,0,2,-10,,-4,,,,,,1)\nX10\nX20\nMCALL\nTRANS X10\nAROT Z30\nG2 X5 Y5 CR=5\nG4 F1\nCYCLE800()\nSUPA G0 Z100 D0\nM30\n",
    "G20 G0 X0 Y0 Z0\nG1 X1 Y1 F10\nG93 G1 X2 A30 F2\nG94\nM428\nG3 X0 Y0 I-1 J-1 P3\nM2\n",
];

/// Heidenhain Klartext: every construct the reader knows (`heidenhain.rs` reads it whole).
const SEEDS_KLARTEXT: &[&str] = &[include_str!("common/everything.h")];

const SEEDS_APT: &[&str] = &[
    "UNITS/MM\nFEDRAT/MMPM,100\nGOTO/10,0,0\nCIRCLE/0,0,0,0,0,-1,10\nGOTO/0,-10,0\nMSYS/10,0,0,0,1,0,-1,0,0\nGOTO/1,0,0,1,0,0\nMSYS/\nCYCLE/DEEP,FEDTO,10,STEP,2,MMPM,100,RAPTO,3,RTRCTO,25\nGOTO/0,0,0\nCYCLE/OFF\nNURBS/\nKNOT/0,0,0,1,1,1\nCNTRL/0,0,0\nCNTRL/10,10,0\nCNTRL/20,0,0\nGOTO/1,2,3\n",
];

fn mutate(rng: &mut Rng, text: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        lines.push(String::new());
    }
    for _ in 0..1 + rng.below(3) {
        let k = rng.below(lines.len());
        match rng.below(6) {
            0 => {
                // Flip a byte to any ASCII character.
                let mut bytes = lines[k].clone().into_bytes();
                if !bytes.is_empty() {
                    let i = rng.below(bytes.len());
                    bytes[i] = (rng.below(95) + 32) as u8;
                }
                lines[k] = String::from_utf8_lossy(&bytes).into_owned();
            }
            1 => {
                if lines.len() > 1 {
                    lines.remove(k);
                }
            }
            2 => {
                let copy = lines[k].clone();
                lines.insert(k, copy);
            }
            3 => {
                let keep = rng.below(lines[k].len() + 1);
                lines[k] = lines[k].chars().take(keep).collect();
                lines.truncate(k + 1);
            }
            _ => {
                // Replace a number (or append a word) with an extreme one.
                let extreme = EXTREMES[rng.below(EXTREMES.len())];
                let line = &lines[k];
                let digits: Vec<usize> = line
                    .char_indices()
                    .filter(|(_, c)| c.is_ascii_digit())
                    .map(|(i, _)| i)
                    .collect();
                lines[k] = if digits.is_empty() {
                    format!("{line} X{extreme}")
                } else {
                    let at = digits[rng.below(digits.len())];
                    format!("{}{extreme}{}", &line[..at], &line[at + 1..])
                };
            }
        }
    }
    lines.join("\n")
}

fn seeds_from_problems() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let mut out = Vec::new();
    for dir in std::fs::read_dir(&root).expect("problems/").flatten() {
        for f in std::fs::read_dir(dir.path())
            .into_iter()
            .flatten()
            .flatten()
        {
            let p = f.path();
            if matches!(p.extension().and_then(|e| e.to_str()), Some("cls" | "ngc")) {
                let text = std::fs::read_to_string(&p).expect("readable");
                // The first 150 lines keep thousands of cases within seconds.
                out.push(text.lines().take(150).collect::<Vec<_>>().join("\n"));
            }
        }
    }
    assert!(!out.is_empty(), "no seed programs in problems/");
    out
}

#[test]
fn no_reader_input_panics() {
    let mut seeds: Vec<String> = seeds_from_problems();
    seeds.extend(SEEDS_GCODE.iter().map(|s| s.to_string()));
    seeds.extend(SEEDS_KLARTEXT.iter().map(|s| s.to_string()));
    seeds.extend(SEEDS_APT.iter().map(|s| s.to_string()));
    let mut rng = Rng(12);
    let mut cases = 0;
    let start = std::time::Instant::now();
    for round in 0..600 {
        for seed in &seeds {
            let text = if round == 0 {
                seed.clone()
            } else {
                mutate(&mut rng, seed)
            };
            let outcome = std::panic::catch_unwind(|| {
                let _ = apt::parse(Path::new("f.cls"), &text);
                for d in Dialect::ALL {
                    let _ = parse(Path::new("f.ngc"), &text, d);
                }
            });
            assert!(outcome.is_ok(), "a reader panicked on:\n{text}");
            cases += 1;
        }
    }
    assert!(cases >= 3000, "{cases} cases");
    eprintln!("{cases} mutated programs read in {:?}", start.elapsed());
}
