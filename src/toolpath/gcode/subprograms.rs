//! Subprograms, in the same file or in files of their own, expanded where they are called.
//!
//! # What a file holds
//!
//! * **Fanuc / Haas** ([`Subprograms::OPrograms`]): programs headed `O2000` (a block starting
//!   with `O` and a number). The first program is the main one: everything before the first
//!   `O` header that follows a block of code, its own `O` header included. Every later
//!   `O<n>` header starts subprogram `O<n>` (leading zeros do not count: `M98 P100` calls
//!   `O0100`), which runs to `M99` or the next header. `M98 P<n> L<count>` calls it `count`
//!   times (`L0`: not at all); without L a P of more than four digits that names no program
//!   in the file packs the count before a four-digit number (`M98 P32000`: O2000 three
//!   times, Fanuc's form). Fadal subroutines, in the same dialect: `L0100` (or `L100`) heads
//!   subroutine 1's definition, which runs to `M17`; the definitions come before the main
//!   program, and an `M30` after the last one ends them (the main program follows it, and
//!   runs from there; the lines before the first definition are its start). `L0102` (`L102`)
//!   calls subroutine 1 twice: a block of that word alone, in a file that defines Fadal
//!   subroutines. A move repeat (`G3 I-4.5 L14`) is not read: an error.
//! * **Sinumerik** ([`Subprograms::Procs`]): `PROC NAME …` or `%_N_NAME_SPF` (with or
//!   without a `PROC NAME` line after it) starts subprogram NAME, which runs to `RET`, `M17`
//!   or the next header. A header before any code starts the main program. A block with the
//!   word `NAME` (or `L123` for `PROC L123`, the name as written: `L0123` is another program)
//!   calls it, `P<count>` in the same block repeating it. `EXTERN` declarations are skipped.
//!   PROC parameters are not passed: a body that reads one is an error naming it.
//! * **LinuxCNC** ([`Subprograms::OWordSub`]): `o100 sub` … `o100 endsub` (or `o<name>`)
//!   anywhere in the file; those lines are not part of the main program. `o100 call` runs the
//!   body once, `o100 return` returns early. `o100 call [10] [#5+1]` passes its arguments,
//!   each an expression in brackets evaluated where the call is, as `#1`, `#2`, … (at most
//!   [`MAX_CALL_ARGUMENTS`]), as LinuxCNC does: `#1`–`#30` are local to the call, those past
//!   the arguments keep the caller's values, and all thirty get the caller's values back on
//!   return. Other O-words (`if`, `while`, …) are errors.
//! * **Heidenhain** ([`Subprograms::Labels`]): one program with labels `LBL 5` / `LBL "NAME"`
//!   (each defined once). `CALL LBL 5` runs from the label to `LBL 0` (or the end of the
//!   program) and returns to the block after the call. `CALL LBL 5 REP m` with the label
//!   before the call is a program-section repeat: the section from the label to the call,
//!   which has run once already, runs m more times, then the program goes on after the call
//!   (REP on a call of a label after it is an error: a repeat count belongs to a section
//!   repeat). A main program that runs into a label or `LBL 0` goes on (the control does the
//!   same: a subprogram before `M30` runs once). `FN 9: IF a EQU b GOTO LBL n` (`FN 10` `NE`,
//!   `FN 11` `GT`, `FN 12` `LT`) jumps to the label when the condition holds. A jump taken a
//!   second time with no Q parameter changed since the first (and the same calls running)
//!   would run the same pass for ever: an error naming the jump and its label, at once. A
//!   `~` at the end of a line continues the block on the next line.
//!
//! # Subprograms in other files
//!
//! A call of a subprogram the program does not hold reads its file, as the control reads it
//! from its memory: the main program's directory is searched first, then
//! [`Settings::subprogram_dirs`](super::Settings) (`--subprogram-dir`) in the order given; the
//! first directory that holds a file for the name wins, and two files in one directory that
//! could both hold it are an error naming both. What each call looks for
//! (`file_holds`):
//!
//! * Fanuc/Haas `M98 P1002` (`L3`, the packed `P31002`) and `G65 P1002 …`: a file `O1002`,
//!   `O1002.nc`, `1002.nc`, `o01002.tap`, … (the letter O or none, leading zeros or none, any
//!   case, no extension or `.nc .tap .ngc .cnc .txt .eia .prg`). The file's first program is
//!   the one its `O` header names (a file whose header names another program is an error); a
//!   file without a header holds the program called. Further `O` programs in the file come
//!   with it. Haas `M98 "name.nc"` reads the file of that name (any case).
//! * LinuxCNC `o<name> call`: `name.ngc`, exactly (LinuxCNC lower-cases the name; numbered
//!   `o100` subroutines are never in files). The file holds `o<name> sub` … `o<name> endsub`
//!   and nothing else but comments, blank lines, `%` and `M2`/`M30` (an error naming the line
//!   otherwise, and for a second subroutine).
//! * Sinumerik `NAME`, `NAME P3`, `L1234`, `CALL "NAME"`, `EXTCALL "NAME"` (a path in the
//!   string is reduced to its last part, `.SPF`/`.MPF` and `_N_…_SPF` taken off): `NAME.SPF`
//!   or `NAME.MPF`, any case. A bare name that is neither a PROC of the file nor a file's is
//!   the error it was.
//! * Heidenhain `CALL PGM name`, `CALL PGM TNC:\dir\name.h`, `PGM CALL name`, `SEL PGM
//!   "name"` + `CALL SELECTED PGM`: `name.h`, any case (the path's directories are not
//!   followed: the file is searched for by name). The called program has its own labels; its
//!   `END PGM` returns to the caller.
//!
//! Each file is read once however often it is called (a name not found is looked for once);
//! at most [`MAX_SUBPROGRAM_FILES`] files and [`MAX_SUBPROGRAM_BYTES`] together. A call that
//! finds no file is an error naming the line, the names tried, the directories and
//! `--subprogram-dir`. Modal state (units, G90/G91, feed, plane, work offset, tool-tip mode)
//! carries into the called file and back out, as on the controls; variables too, but for the
//! locals a call gets (LinuxCNC `#1`–`#30`, Fanuc G65's `#1`–`#33`). A subprogram that calls
//! itself is bounded by [`MAX_CALL_DEPTH`] (the message says that it calls itself).
//!
//! **Lines.** A called file's lines are numbered after the main program's, in the order the
//! files are read: every line the reader records (points, warnings, dwells, changes) is a
//! number in that one sequence, and [`crate::toolpath::Toolpath::files`] maps it back to its
//! file and line there. The reader's own errors name the file and line directly.
//!
//! # Fanuc G65 macro calls
//!
//! `G65 P9010 L2 A1. B2. …` calls O9010 (in the file or a file) `L` times with argument
//! specification I (A → `#1`, B → `#2`, C → `#3`, I J K → `#4`–`#6`, D E F → `#7`–`#9`, H
//! `#11`, M `#13`, Q R S T U V W → `#17`–`#23`, X Y Z → `#24`–`#26`): the macro's `#1`–`#33` are
//! its own, vacant but for the arguments, and the caller's come back on return. Under
//! increment input an argument without a decimal point (other than 0) is an error: the
//! control scales it by its address's increment. `G66` and specification II are errors.
//!
//! # How a call runs
//!
//! The block's own words run first (a move in the same block is made), then the body's blocks
//! with the caller's modal state, which they may change as on the control (units, feed, G90/91,
//! motion mode, TCP); every point keeps the line of the block in the body that made it. A call
//! of a subprogram that is not in the file is an error naming the line, the call and what to
//! do; so are calls nested more than [`MAX_CALL_DEPTH`] deep, a repeat count above
//! [`MAX_EXPANDED_BLOCKS`] (before the work is done), and a program that runs more than
//! [`MAX_EXPANDED_BLOCKS`] blocks or [`MAX_EXPANDED_BYTES`] of block text past its own
//! (every block run counts, with its length: repeats, calls and jumps alike, so any loop
//! ends). What the blocks make is bounded too: at most
//! [`crate::toolpath::MAX_POINTS`] CL points, checked before an arc's chords or a cycle's
//! moves are made, so a loop whose passes hold a helix or a cycle ends in an error, not in
//! minutes of work and gigabytes of points. A program end (`M2`, `M30`) in a
//! subprogram ends the whole program; a return (`M99`, `M17`, `RET`, `endsub`) in the main
//! program ends it.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::dialect::{DialectSpec, LINUXCNC, Semicolon, Subprograms};
use super::expr::Variables;
use super::interp::{Call, Interpreter};
use super::klartext::{self, LabelOp};
use super::lexer::{Item, lex, split_blocks};
use super::macro_b::{self, Statement};
use crate::error::{Error, Result};

/// Deepest nesting of subprogram calls (the main program is depth 0).
pub const MAX_CALL_DEPTH: usize = 8;

/// Most arguments a LinuxCNC `o… call` passes (`#1`–`#30`, the subroutine's local
/// parameters).
pub const MAX_CALL_ARGUMENTS: usize = 30;

/// Most blocks a program may run past its own lines: what subprogram calls, repeats (nesting
/// multiplied out) and jumps add. A block costs about 2 µs to read, so this bounds the blocks'
/// own work to seconds; what they make is bounded by [`crate::toolpath::MAX_POINTS`].
pub const MAX_EXPANDED_BLOCKS: usize = 1_000_000;

/// Most characters of blocks a program may run past its own text (32 MiB): a block's work
/// grows with its length (an expression of up to [`super::expr::MAX_EXPRESSION_LEN`]
/// characters is evaluated at every pass), so a loop of long blocks is bounded by what it
/// reads, not only by how many blocks (about 60 ns a character: a second or two).
pub const MAX_EXPANDED_BYTES: usize = 32 << 20;

/// One line of a file: its 1-based number in its file, the file (an index into
/// [`Program::files`]: 0 is the main program's) and its blocks with comments removed (or the
/// message of an unclosed comment, reported if the line is ever run).
struct Line {
    number: usize,
    file: usize,
    blocks: std::result::Result<Vec<String>, String>,
}

/// A file read into the program: the main program's (the first) or one a call read.
struct Unit {
    path: PathBuf,
    /// The lines of the files before it: its line n is line `offset + n` of the sequence the
    /// toolpath's lines are numbered in ([`crate::toolpath::SourceFile`]).
    offset: usize,
    /// Its line count.
    lines: usize,
}

/// A program or subprogram: its name and header line, and the indices of its lines.
struct Section {
    name: String,
    header: usize,
    lines: Vec<usize>,
}

/// Where a running program or subprogram stands.
struct Frame {
    section: usize,
    /// Next line (index into the section's lines) and block within it.
    pos: usize,
    block: usize,
    /// Where a run starts (0; for a Heidenhain label, the line after it).
    start: usize,
    /// Runs still to make, this one included.
    runs: u64,
    /// The call as written and its line (none for the main program).
    call: Option<(String, usize)>,
    /// A Heidenhain label call: the index of the calling line (a section repeat's pass ends
    /// there) and the label's name.
    label: Option<(usize, String)>,
    /// A LinuxCNC O-word call (with arguments or without): the caller's `#1`–`#30`, given back
    /// on return.
    locals: Option<Vec<Option<f64>>>,
}

/// The state when a Klartext jump (`FN 9`–`12`) is taken: the count of variable changes
/// ([`super::expr::Variables::changes`]) and where every running (sub)program stands. A
/// program's course depends on nothing else (the conditions, repeats and calls read only Q
/// parameters and constants), so a jump taken again in the same state runs the same pass
/// again, for ever.
#[derive(Debug, PartialEq)]
struct Loop {
    changes: u64,
    frames: Vec<(usize, usize, usize, usize, u64)>,
}

impl Loop {
    fn now(stack: &[Frame], changes: u64) -> Loop {
        Loop {
            changes,
            frames: stack
                .iter()
                .map(|f| (f.section, f.pos, f.block, f.start, f.runs))
                .collect(),
        }
    }
}

/// Where Fanuc macro loops end and start and where numbered blocks are, per section, found
/// once by a scan of the section's blocks.
#[derive(Default)]
struct MacroPlaces {
    /// (section, line, block) of a `DO m` → (line, block) of its `END m`, and back.
    ends: HashMap<(usize, usize, usize), Option<(usize, usize)>>,
    starts: HashMap<(usize, usize, usize), Option<(usize, usize)>>,
    /// (section, n) → the first block numbered `N n`.
    numbers: HashMap<(usize, u64), Option<(usize, usize)>>,
}

impl MacroPlaces {
    /// The section's blocks from (line, block) on, forwards or backwards, with their places.
    fn blocks<'a>(
        program: &'a Program,
        section: usize,
    ) -> impl DoubleEndedIterator<Item = ((usize, usize), &'a str)> + 'a {
        program.sections[section]
            .lines
            .iter()
            .enumerate()
            .flat_map(move |(pos, &index)| {
                let blocks: &[String] = match &program.lines[index].blocks {
                    Ok(b) => b,
                    Err(_) => &[],
                };
                blocks
                    .iter()
                    .enumerate()
                    .map(move |(b, text)| ((pos, b), text.as_str()))
            })
    }

    /// The `END id` that closes the loop opened at (pos, block): the first after it.
    fn loop_end(
        &mut self,
        program: &Program,
        section: usize,
        pos: usize,
        block: usize,
        id: u32,
    ) -> Option<(usize, usize)> {
        *self.ends.entry((section, pos, block)).or_insert_with(|| {
            Self::blocks(program, section)
                .filter(|(at, _)| *at > (pos, block))
                .find(|(_, text)| {
                    matches!(macro_b::statement(text), Some(Ok(Statement::End { id: e })) if e == id)
                })
                .map(|(at, _)| at)
        })
    }

    /// The `WHILE … DO id` or `DO id` that the `END id` at (pos, block) closes: the last
    /// before it.
    fn loop_start(
        &mut self,
        program: &Program,
        section: usize,
        pos: usize,
        block: usize,
        id: u32,
    ) -> Option<(usize, usize)> {
        *self.starts.entry((section, pos, block)).or_insert_with(|| {
            Self::blocks(program, section)
                .rev()
                .filter(|(at, _)| *at < (pos, block))
                .find(|(_, text)| {
                    matches!(
                        macro_b::statement(text),
                        Some(Ok(Statement::While { id: d, .. } | Statement::Do { id: d })) if d == id
                    )
                })
                .map(|(at, _)| at)
        })
    }

    /// The first block numbered `N n` in the section.
    fn numbered(&mut self, program: &Program, section: usize, n: u64) -> Option<(usize, usize)> {
        *self.numbers.entry((section, n)).or_insert_with(|| {
            Self::blocks(program, section)
                .find(|(_, text)| macro_b::sequence_number(text) == Some(n))
                .map(|(at, _)| at)
        })
    }
}

/// A LinuxCNC O-word subroutine line: `o100 sub`, `o<name> call [..]`, …
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum OWord {
    Sub,
    EndSub,
    Call,
    Return,
}

/// The name and keyword of a LinuxCNC O-word subroutine block, and what follows the keyword
/// (without spaces, upper-cased: a call's arguments) (`None`: not one).
fn oword(block: &str) -> Option<(String, OWord, String)> {
    let compact: String = block
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_lowercase();
    let rest = strip_block_number(&compact);
    let rest = rest.strip_prefix('o')?;
    let name_end = if rest.starts_with('<') {
        rest.find('>')? + 1
    } else {
        rest.find(|c: char| !c.is_ascii_digit())?
    };
    if name_end == 0 {
        return None;
    }
    let (name, tail) = rest.split_at(name_end);
    let name = if name.starts_with('<') {
        format!("O{name}")
    } else {
        format!("O{}", name.trim_start_matches('0'))
    };
    // After `call` come its arguments, checked when it runs (`o100 call 5` is an error
    // saying how to write them).
    let word = |kw: &str| {
        tail.strip_prefix(kw)
            .is_some_and(|t| t.is_empty() || t.starts_with('[') || kw == "call")
    };
    // `endsub` before `sub`: no keyword is a prefix of another that comes first.
    [
        ("endsub", OWord::EndSub),
        ("sub", OWord::Sub),
        ("call", OWord::Call),
        ("return", OWord::Return),
    ]
    .into_iter()
    .find(|(kw, _)| word(kw))
    .map(|(kw, k)| (name, k, tail[kw.len()..].to_ascii_uppercase()))
}

/// A LinuxCNC call's arguments `[a][b]…` (without spaces), each evaluated with `vars`.
fn call_arguments(text: &str, vars: &Variables) -> std::result::Result<Vec<f64>, String> {
    let chars: Vec<char> = text.chars().collect();
    let mut values = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '[' {
            return Err(format!(
                "`{}`: a call's arguments are expressions in brackets, `[10] [#2*2]`",
                chars[i..].iter().collect::<String>()
            ));
        }
        let mut depth = 0usize;
        let mut end = i;
        while end < chars.len() {
            match chars[end] {
                '[' => depth += 1,
                ']' => depth -= 1,
                _ => {}
            }
            end += 1;
            if depth == 0 {
                break;
            }
        }
        if depth > 0 {
            return Err("a call argument has no closing `]`".into());
        }
        let argument: String = chars[i..end].iter().collect();
        values.push(
            super::expr::eval(&argument, vars)
                .map_err(|e| format!("argument `{argument}`: {e}"))?,
        );
        if values.len() > MAX_CALL_ARGUMENTS {
            return Err(format!(
                "more than {MAX_CALL_ARGUMENTS} arguments (#1–#{MAX_CALL_ARGUMENTS} are all a \
                 subroutine has)"
            ));
        }
        i = end;
    }
    Ok(values)
}

/// `N10 …` → `…` (lower or upper case).
fn strip_block_number(text: &str) -> &str {
    let t = text.trim_start();
    match t.strip_prefix(['n', 'N']) {
        Some(rest) if rest.starts_with(|c: char| c.is_ascii_digit()) => rest
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start(),
        _ => t,
    }
}

/// The first word of a block, upper-cased, after any block number.
fn first_word(block: &str) -> String {
    strip_block_number(block)
        .split(|c: char| c.is_whitespace() || c == '(')
        .next()
        .unwrap_or("")
        .to_ascii_uppercase()
}

/// A Fanuc `O2000` header's program name (`O` and the number without leading zeros).
fn fanuc_header(block: &str) -> Option<String> {
    let compact: String = block.chars().filter(|c| !c.is_whitespace()).collect();
    let rest = strip_block_number(&compact).strip_prefix(['O', 'o'])?;
    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
    if digits.is_empty() {
        return None;
    }
    let n: u64 = digits.parse().ok()?;
    Some(format!("O{n}"))
}

/// A Fadal subroutine word alone in its block (after a block number): `L0100` or `L100` →
/// (1, 0), `L901` → (9, 1). The digits are the subroutine's number (1–99) and a count, two
/// digits each: count 0 heads the subroutine's definition, 1–99 calls it that many times.
fn fadal_subroutine(block: &str) -> Option<(u32, u32)> {
    let t = strip_block_number(block).trim();
    let digits = t.strip_prefix(['L', 'l'])?;
    if !(3..=4).contains(&digits.len()) || !digits.chars().all(|c| c.is_ascii_digit()) {
        return None;
    }
    let n: u32 = digits.parse().ok()?;
    let (number, count) = (n / 100, n % 100);
    (1..=99).contains(&number).then_some((number, count))
}

/// Whether the block is `M<code>` alone (`M17`, `M30`), after a block number.
fn lone_m(block: &str, code: u32) -> bool {
    let t = strip_block_number(block).trim();
    t.strip_prefix(['M', 'm'])
        .and_then(|d| d.parse::<u32>().ok())
        .is_some_and(|m| m == code)
}

/// A Fadal subroutine's section name (`L1` … `L99`).
fn fadal_name(name: &str) -> bool {
    name.strip_prefix('L')
        .is_some_and(|d| !d.is_empty() && d.chars().all(|c| c.is_ascii_digit()))
}

/// A Sinumerik header: `PROC NAME(…)` → (NAME, false), `%_N_NAME_SPF` → (NAME, false),
/// `%_N_NAME_MPF` → (NAME, true: a main program).
fn sinumerik_header(block: &str) -> Option<(String, bool)> {
    let t = block.trim();
    if let Some(rest) = t.strip_prefix("%_N_") {
        let upper = rest.to_ascii_uppercase();
        let (name, main) = if let Some(n) = upper.strip_suffix("_SPF") {
            (n, false)
        } else if let Some(n) = upper.strip_suffix("_MPF") {
            (n, true)
        } else {
            return None;
        };
        return Some((name.to_string(), main));
    }
    if first_word(t) != "PROC" {
        return None;
    }
    let after = strip_block_number(t)[4..].trim_start();
    let name: String = after
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect::<String>()
        .to_ascii_uppercase();
    (!name.is_empty()).then_some((name, false))
}

/// A Sinumerik `EXTCALL "NAME"` or `CALL "NAME"` block as a call of NAME: the name is the
/// string's last path component (`"/_N_WKS_DIR/_N_PART_WPD/NAME"`, `"D:\\NC\\NAME.SPF"`)
/// without an extension `.SPF`/`.MPF` or the control's `_N_…_SPF` form, upper-cased. Nothing
/// else may stand in the block.
fn sinumerik_call(block: &str) -> std::result::Result<Call, String> {
    let body = strip_block_number(block);
    let keyword = first_word(body);
    let rest = body[keyword.len()..].trim();
    let fail = || {
        format!(
            "`{}`: expected {keyword} \"NAME\" alone in its block (the program's name in \
             double quotes)",
            block.trim()
        )
    };
    let inner = rest
        .strip_prefix('"')
        .and_then(|r| r.strip_suffix('"'))
        .filter(|r| !r.contains('"'))
        .ok_or_else(fail)?;
    let last = inner
        .rsplit(['/', '\\'])
        .next()
        .unwrap_or(inner)
        .to_ascii_uppercase();
    let mut name = last.as_str();
    for ext in [".SPF", ".MPF", "_SPF", "_MPF"] {
        name = name.strip_suffix(ext).unwrap_or(name);
    }
    let name = name.strip_prefix("_N_").unwrap_or(name);
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(fail());
    }
    Ok(Call {
        text: format!("{keyword} \"{inner}\""),
        targets: vec![(name.to_string(), 1)],
    })
}

/// A Haas `M98 "name.nc"` or `M98 "name.nc" L3` block: a call of the program in file
/// `name.nc` (its name in the call is the quoted text, quotes included). Nothing else may
/// stand in the block.
fn haas_file_call(block: &str) -> std::result::Result<Call, String> {
    let body = strip_block_number(block);
    let fail = || {
        format!(
            "`{}`: expected M98 \"file name\" and at most a repeat count L, alone in its block",
            block.trim()
        )
    };
    let rest = body[3..].trim_start();
    let inner_end = rest
        .strip_prefix('"')
        .and_then(|r| r.find('"'))
        .ok_or_else(fail)?;
    let file = &rest[1..=inner_end];
    let tail: String = rest[inner_end + 2..]
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect();
    let runs = match tail.strip_prefix(['L', 'l']) {
        None if tail.is_empty() => 1,
        Some(n) => n.parse::<u64>().map_err(|_| fail())?,
        None => return Err(fail()),
    };
    if file.is_empty() || file.contains(['/', '\\']) {
        return Err(fail());
    }
    let mut text = format!("M98 \"{file}\"");
    if !tail.is_empty() {
        text.push_str(&format!(" L{runs}"));
    }
    Ok(Call {
        text,
        targets: vec![(format!("\"{file}\""), runs)],
    })
}

/// A Heidenhain block about another program.
enum ProgramCall {
    /// `CALL PGM name`, `PGM CALL name` (`Some`), `CALL SELECTED PGM` (`None`).
    Call(Option<String>),
    /// `SEL PGM "name"`.
    Select(String),
    /// `END PGM …`.
    End,
}

/// A Heidenhain `CALL PGM name` / `CALL PGM TNC:\dir\name.h` / `PGM CALL name`, `SEL PGM
/// "name"`, `CALL SELECTED PGM` or `END PGM` block (`None`: none of them). The program's
/// name is the path's last component without `.h`, upper-cased (the TNC's file names do not
/// depend on case).
fn program_call(body: &str) -> Option<std::result::Result<ProgramCall, String>> {
    let t = body.trim().trim_end_matches('~').trim();
    let upper = t.to_ascii_uppercase();
    if upper.starts_with("END PGM") {
        return Some(Ok(ProgramCall::End));
    }
    if upper.starts_with("CALL SELECTED PGM") {
        return Some(Ok(ProgramCall::Call(None)));
    }
    let (rest, select) = if let Some(r) = upper
        .strip_prefix("CALL PGM ")
        .or_else(|| upper.strip_prefix("PGM CALL "))
    {
        (&t[t.len() - r.len()..], false)
    } else if let Some(r) = upper.strip_prefix("SEL PGM ") {
        (&t[t.len() - r.len()..], true)
    } else {
        return None;
    };
    let written = rest.split_whitespace().next().unwrap_or("");
    let path = written.trim_matches(['"', '\'']);
    let last = path.rsplit(['\\', '/', ':']).next().unwrap_or(path);
    let stem = match last.rsplit_once('.') {
        Some((stem, ext)) if ext.eq_ignore_ascii_case("h") => stem,
        _ => last,
    };
    if stem.is_empty() || stem.contains(char::is_whitespace) {
        return Some(Err(format!(
            "`{t}`: expected the program's name after PGM (`CALL PGM name`, `CALL PGM \
             TNC:\\dir\\name.h`)"
        )));
    }
    let name = stem.to_ascii_uppercase();
    Some(Ok(if select {
        ProgramCall::Select(name)
    } else {
        ProgramCall::Call(Some(name))
    }))
}

/// Whether a file in `dirs` holds subprogram `name` as `style` names files ([`file_holds`]).
pub(super) fn in_directories(dirs: &[PathBuf], style: Subprograms, name: &str) -> bool {
    dirs.iter().any(|dir| {
        std::fs::read_dir(dir).is_ok_and(|entries| {
            entries.flatten().any(|e| {
                e.file_name()
                    .to_str()
                    .is_some_and(|f| file_holds(style, name, f))
                    && e.path().is_file()
            })
        })
    })
}

/// Fanuc's local variables `#1`–`#33`: a `G65` macro call gets its own (vacant but for its
/// arguments), and the caller's come back on return.
pub const MACRO_LOCALS: usize = 33;

/// Fanuc argument specification I: the letter of a `G65` argument and the local variable it
/// sets.
const MACRO_ARGUMENTS: [(char, usize); 21] = [
    ('A', 1),
    ('B', 2),
    ('C', 3),
    ('I', 4),
    ('J', 5),
    ('K', 6),
    ('D', 7),
    ('E', 8),
    ('F', 9),
    ('H', 11),
    ('M', 13),
    ('Q', 17),
    ('R', 18),
    ('S', 19),
    ('T', 20),
    ('U', 21),
    ('V', 22),
    ('W', 23),
    ('X', 24),
    ('Y', 25),
    ('Z', 26),
];

/// Whether a Fanuc block is a `G65` macro call.
fn is_macro_call(items: &[Item]) -> bool {
    items.iter().any(|i| {
        matches!(i, Item::Word { text, num, .. }
            if text.starts_with(['G', 'g']) && num.value == 65.0)
    })
}

/// A Fanuc `G65 P9010 L2 A1. B2.` block: the call (program `O<P>`, `L` times) and its
/// arguments as (local variable, value) by argument specification I. A letter that is no
/// argument, a word that is no letter, and (where numbers without a decimal point count
/// increments, `increments`) an argument without a decimal point other than 0 are errors: the
/// control scales such an argument by its address's increment, which differs between letters
/// and controls.
fn macro_call(
    items: &[Item],
    increments: bool,
) -> std::result::Result<(Call, Vec<(usize, f64)>), String> {
    let mut program = None;
    let mut count = None;
    let mut arguments: Vec<(usize, f64)> = Vec::new();
    let whole = |what: &str, v: f64| {
        if v < 0.0 || v.fract() != 0.0 || v > 1e12 {
            Err(format!(
                "`{what}{v}`: expected a whole number of at least 0"
            ))
        } else {
            Ok(v as u64)
        }
    };
    for item in items {
        let Item::Word { text, num, .. } = item else {
            return Err(
                "a G65 block holds the call, its P, L and arguments only (argument \
                 specification I: A B C D E F H I J K M Q R S T U V W X Y Z)"
                    .into(),
            );
        };
        let letter = text.chars().next().unwrap_or(' ').to_ascii_uppercase();
        match letter {
            'G' if num.value == 65.0 => {}
            'N' => {}
            'P' => program = Some(whole("P", num.value)?),
            'L' => count = Some(whole("L", num.value)?),
            _ => {
                let Some(&(_, k)) = MACRO_ARGUMENTS.iter().find(|(l, _)| *l == letter) else {
                    return Err(format!(
                        "`{text}` is no G65 argument (argument specification I: A B C D E F H I \
                         J K M Q R S T U V W X Y Z; G66 and specification II are not read)"
                    ));
                };
                if arguments.iter().any(|&(seen, _)| seen == k) {
                    // Specification II repeats I J K (`I1. J2. K3. I4. …` → #4 … #33): read
                    // as specification I, the second would overwrite the first.
                    return Err(format!(
                        "`{text}`: {letter} given twice; argument specification II (I J K \
                         repeated) is not read: give each argument once (specification I)"
                    ));
                }
                if increments && !num.point && num.value != 0.0 {
                    return Err(format!(
                        "G65 argument `{text}` without a decimal point: the control scales it \
                         by the increment of address {letter}; write it with a decimal point \
                         (`{letter}{}.`), or read the program with --decimal-point-input \
                         calculator",
                        num.value
                    ));
                }
                arguments.push((k, num.value));
            }
        }
    }
    let Some(program) = program else {
        return Err("G65 without P (the macro's program number): add P<program number>".into());
    };
    let mut text = format!("G65 P{program}");
    let runs = match count {
        Some(l) => {
            text.push_str(&format!(" L{l}"));
            l
        }
        None => 1,
    };
    Ok((
        Call {
            text,
            targets: vec![(format!("O{program}"), runs)],
        },
        arguments,
    ))
}

/// The file split into its main program and subprograms.
pub(super) struct Program {
    lines: Vec<Line>,
    /// The file's length in bytes.
    bytes: usize,
    sections: Vec<Section>,
    by_name: HashMap<String, usize>,
    /// Heidenhain labels: (section, name) → the label's position in the section (each
    /// program, the main one or one a `CALL PGM` read, has its own).
    labels: HashMap<(usize, String), usize>,
    /// Heidenhain `SEL PGM "name"`: the program `CALL SELECTED PGM` calls.
    selected: std::cell::RefCell<Option<String>>,
    style: Subprograms,
    /// The files read: the main program's first, then each a call read, in the order read.
    files: Vec<Unit>,
    /// The name of the first section's own header (Fanuc `O1002`, Sinumerik `PROC NAME`), if
    /// it has one.
    first_header: Option<String>,
    /// Where a call of a subprogram the program does not hold looks for its file: the main
    /// program's directory, then [`Settings::subprogram_dirs`](super::Settings) in order.
    search: Vec<PathBuf>,
    /// The names of the files in each searched directory, listed once.
    listings: HashMap<PathBuf, Vec<String>>,
    /// The names looked for in the directories and not found (each is looked for once).
    missing: std::collections::HashSet<String>,
    /// The bytes of the files calls read.
    bytes_included: usize,
}

/// Most files a program may read for its calls.
pub const MAX_SUBPROGRAM_FILES: usize = 1000;

/// Most bytes the files a program's calls read may hold together (as much as one toolpath
/// may: [`crate::files::MAX_TOOLPATH_BYTES`]).
pub const MAX_SUBPROGRAM_BYTES: usize = crate::files::MAX_TOOLPATH_BYTES as usize;

/// The extensions (lower case; "" none) a Fanuc/Haas subprogram's file may have.
const FANUC_EXTENSIONS: [&str; 8] = ["", "nc", "tap", "ngc", "cnc", "txt", "eia", "prg"];

/// Whether `file` (a file name in a searched directory) holds subprogram `name` as `style`
/// names its files: Fanuc/Haas `O1002` in `O1002`, `O1002.nc`, `1002.nc`, `o01002.tap` (the
/// letter O or none, the number with or without leading zeros, any case, an extension of
/// [`FANUC_EXTENSIONS`]); Sinumerik `NAME` (`L1234`) in `NAME.SPF` or `NAME.MPF`, any case;
/// LinuxCNC `o<name>` in `name.ngc` exactly (LinuxCNC lower-cases the name, and the file
/// system's case counts). Numbered LinuxCNC subroutines (`o100`) and Heidenhain labels are
/// never in files.
pub(super) fn file_holds(style: Subprograms, name: &str, file: &str) -> bool {
    let (stem, ext) = match file.rsplit_once('.') {
        Some((stem, ext)) if !stem.is_empty() => (stem, ext),
        _ => (file, ""),
    };
    match style {
        Subprograms::OPrograms => {
            // Haas `M98 "name.nc"`: the file of that name.
            if let Some(quoted) = name.strip_prefix('"').and_then(|n| n.strip_suffix('"')) {
                return file.eq_ignore_ascii_case(quoted);
            }
            let Some(Ok(n)) = name.strip_prefix('O').map(str::parse::<u64>) else {
                return false;
            };
            let digits = stem.strip_prefix(['O', 'o']).unwrap_or(stem);
            FANUC_EXTENSIONS.contains(&ext.to_ascii_lowercase().as_str())
                && !digits.is_empty()
                && digits.len() <= 12
                && digits.chars().all(|c| c.is_ascii_digit())
                && digits.parse::<u64>() == Ok(n)
        }
        Subprograms::Procs => {
            matches!(ext.to_ascii_lowercase().as_str(), "spf" | "mpf")
                && stem.eq_ignore_ascii_case(name)
        }
        Subprograms::OWordSub => name
            .strip_prefix("O<")
            .and_then(|n| n.strip_suffix('>'))
            .is_some_and(|n| !n.is_empty() && ext == "ngc" && stem == n),
        Subprograms::Labels => ext.eq_ignore_ascii_case("h") && stem.eq_ignore_ascii_case(name),
    }
}

/// What a call looks for, for messages: `O1002`, `O1002.nc`, `1002.nc`, … .
fn file_names(style: Subprograms, name: &str) -> String {
    match style {
        Subprograms::OPrograms if name.starts_with('"') => {
            format!("{} (any case)", name.trim_matches('"'))
        }
        Subprograms::OPrograms => {
            let n = name.trim_start_matches('O');
            format!("{name}, {name}.nc, {n}.nc, {name}.tap, … (any case)")
        }
        Subprograms::Procs => format!("{name}.SPF, {name}.MPF (any case)"),
        Subprograms::OWordSub => {
            let n = name.trim_start_matches("O<").trim_end_matches('>');
            format!("{n}.ngc")
        }
        Subprograms::Labels => format!("{name}.h (any case)"),
    }
}

impl Program {
    /// Reads the file's structure (headers only; no block is interpreted).
    pub(super) fn scan(spec: &DialectSpec, source: &Path, text: &str) -> Result<Program> {
        let lines: Vec<Line> = text
            .lines()
            .enumerate()
            .map(|(i, raw)| Line {
                number: i + 1,
                file: 0,
                blocks: split_blocks(spec, raw),
            })
            .collect();
        let mut program = Program {
            files: vec![Unit {
                path: source.to_path_buf(),
                offset: 0,
                lines: lines.len(),
            }],
            first_header: None,
            search: Vec::new(),
            listings: HashMap::new(),
            missing: Default::default(),
            bytes_included: 0,
            lines,
            bytes: text.len(),
            sections: vec![Section {
                name: "the main program".into(),
                header: 0,
                lines: Vec::new(),
            }],
            by_name: HashMap::new(),
            labels: HashMap::new(),
            selected: Default::default(),
            style: spec.subprograms,
        };
        match spec.subprograms {
            Subprograms::OWordSub => program.scan_owords(source)?,
            Subprograms::OPrograms | Subprograms::Procs => program.scan_headers(source)?,
            Subprograms::Labels => {
                program.join_continuations(text);
                program.scan_labels(source)?;
            }
        }
        Ok(program)
    }

    /// Klartext: a line ending in `~` continues on the next line (its block is joined to this
    /// line's; the next line is left empty).
    fn join_continuations(&mut self, text: &str) {
        let raw: Vec<&str> = text.lines().collect();
        let mut i = 0;
        while i < self.lines.len() {
            // A comment block (`4 ;MCX FILE -~`, `* - …~`: nothing but the block number
            // before the comment) continues as comment: Mastercam's Heidenhain post wraps a
            // long comment so, and the TNC reads the lines that follow as part of it.
            let comment_block = matches!(&self.lines[i].blocks, Ok(b)
                if b.iter().all(|s| klartext::strip_block_number(s).trim().is_empty()));
            let mut j = i;
            while j + 1 < self.lines.len()
                && raw.get(j).is_some_and(|r| r.trim_end().ends_with('~'))
            {
                j += 1;
                if comment_block {
                    self.lines[j].blocks = Ok(Vec::new());
                    continue;
                }
                let next = std::mem::replace(&mut self.lines[j].blocks, Ok(Vec::new()));
                let add = match next {
                    Ok(b) => b.join(" "),
                    Err(m) => {
                        self.lines[i].blocks = Err(m);
                        continue;
                    }
                };
                if let Ok(blocks) = &mut self.lines[i].blocks {
                    match blocks.last_mut() {
                        Some(last) => *last = klartext::join_continued(last, &add),
                        None => blocks.push(add),
                    }
                }
            }
            i = j + 1;
        }
    }

    /// Heidenhain: one section with every line; labels are positions in it.
    fn scan_labels(&mut self, source: &Path) -> Result<()> {
        for i in 0..self.lines.len() {
            self.sections[0].lines.push(i);
            let number = self.lines[i].number;
            let block = klartext::strip_block_number(self.first_block(i));
            // Other label blocks, and malformed ones, are read when they run.
            if let Ok(Some(LabelOp::Label(name))) = klartext::label_op(block) {
                if let Some(&k) = self.labels.get(&(0, name.clone())) {
                    return Err(Error::parse(
                        source,
                        number,
                        format!(
                            "LBL {name} is defined twice (lines {} and {number}): rename one",
                            self.lines[k].number
                        ),
                    ));
                }
                self.labels.insert((0, name), i);
            }
        }
        Ok(())
    }

    /// The first block of line `i`, trimmed (empty when it has none or an unclosed comment).
    fn first_block(&self, i: usize) -> &str {
        match &self.lines[i].blocks {
            Ok(b) => b.first().map_or("", |s| s.trim()),
            Err(_) => "",
        }
    }

    fn add_section(&mut self, source: &Path, name: String, line: usize) -> Result<usize> {
        if let Some(&k) = self.by_name.get(&name) {
            return Err(Error::parse(
                source,
                line,
                format!(
                    "subprogram {name} is defined twice (lines {} and {line}): rename one",
                    self.sections[k].header
                ),
            ));
        }
        self.sections.push(Section {
            name: name.clone(),
            header: line,
            lines: Vec::new(),
        });
        let k = self.sections.len() - 1;
        self.by_name.insert(name, k);
        Ok(k)
    }

    /// LinuxCNC: `oN sub` … `oN endsub` regions are subroutines (the `endsub` line is their
    /// last line: it returns); every other line is the main program.
    fn scan_owords(&mut self, source: &Path) -> Result<()> {
        let mut open: Option<(usize, String)> = None;
        for i in 0..self.lines.len() {
            let number = self.lines[i].number;
            let word = oword(self.first_block(i)).map(|(name, kind, _)| (name, kind));
            match (&open, word) {
                (None, Some((name, OWord::Sub))) => {
                    let k = self.add_section(source, name.clone(), number)?;
                    open = Some((k, name));
                }
                (Some((_, outer)), Some((name, OWord::Sub))) => {
                    return Err(Error::parse(
                        source,
                        number,
                        format!(
                            "O-word {name} sub inside {outer} sub: subroutines cannot be \
                             defined inside one another"
                        ),
                    ));
                }
                (Some((k, open_name)), Some((name, OWord::EndSub))) if *open_name == name => {
                    self.sections[*k].lines.push(i);
                    open = None;
                }
                (None, Some((name, OWord::EndSub))) => {
                    return Err(Error::parse(
                        source,
                        number,
                        format!("O-word {name} endsub without {name} sub"),
                    ));
                }
                (Some((k, _)), _) => self.sections[*k].lines.push(i),
                (None, _) => self.sections[0].lines.push(i),
            }
        }
        if let Some((k, name)) = open {
            return Err(Error::parse(
                source,
                self.sections[k].header,
                format!("O-word {name} sub has no {name} endsub: close the subroutine"),
            ));
        }
        Ok(())
    }

    /// Fanuc and Sinumerik: headers start sections; the first section is the main program.
    fn scan_headers(&mut self, source: &Path) -> Result<()> {
        let mut current = 0usize;
        // The current section has a block of code (a header after code starts a new one).
        let mut has_code = false;
        // Fadal (read in the Fanuc dialect): the subroutine being defined (its section and
        // header line), and whether one was closed since the main program's last code.
        let mut fadal: Option<(usize, usize)> = None;
        let mut after_fadal = false;
        for i in 0..self.lines.len() {
            let number = self.lines[i].number;
            let block = self.first_block(i);
            if self.style == Subprograms::OPrograms {
                // Fadal subroutines: `L0100` (or `L100`) … `M17` defines subroutine 1; the
                // definitions come first, and an `M30` after the last one ends them: the
                // main program follows it (the Polish shop's Fadal programs of round 22:
                // `N2 L100`, hole positions, `N7 M17`, …, `N11 M30`, then the main program
                // calling `L101`). Neither the header, the `M17` nor that `M30` is run.
                let sub = fadal_subroutine(block);
                if let Some((k, header)) = fadal {
                    if lone_m(block, 17) {
                        fadal = None;
                        after_fadal = true;
                    } else if let Some((n, 0)) = sub {
                        return Err(Error::parse(
                            source,
                            number,
                            format!(
                                "Fadal subroutine L{n} defined inside {} (line {header}), \
                                 which has no M17 before it: end each definition with M17",
                                self.sections[k].name
                            ),
                        ));
                    } else {
                        self.sections[k].lines.push(i);
                    }
                    continue;
                }
                if let Some((n, 0)) = sub {
                    let k = self.add_section(source, format!("L{n}"), number)?;
                    fadal = Some((k, number));
                    continue;
                }
                if after_fadal && !block.trim().is_empty() {
                    after_fadal = false;
                    if lone_m(block, 30) {
                        continue;
                    }
                }
            }
            let header = match self.style {
                Subprograms::OPrograms => fanuc_header(block).map(|n| (n, false)),
                _ => sinumerik_header(block),
            };
            match header {
                Some((name, main)) => {
                    let same_proc = self.sections[current].name == name;
                    if !has_code && (current == 0 || same_proc) {
                        // The main program's own header, or `PROC NAME` after `%_N_NAME_SPF`.
                        if current == 0 && self.sections[0].header == 0 {
                            self.sections[0].header = number;
                            self.first_header = Some(name.clone());
                        }
                        self.sections[current].lines.push(i);
                        continue;
                    }
                    if main {
                        return Err(Error::parse(
                            source,
                            number,
                            format!("a second main program ({name}) in one file: split the file"),
                        ));
                    }
                    current = self.add_section(source, name, number)?;
                    has_code = false;
                    self.sections[current].lines.push(i);
                }
                None => {
                    let t = block.trim();
                    if !t.is_empty() && !t.starts_with('%') {
                        has_code = true;
                    }
                    self.sections[current].lines.push(i);
                }
            }
        }
        if let Some((k, header)) = fadal {
            return Err(Error::parse(
                source,
                header,
                format!(
                    "Fadal subroutine {} has no M17 after it: end its definition with M17",
                    self.sections[k].name
                ),
            ));
        }
        Ok(())
    }

    /// Where calls look for files ([`Self::search_in`]).
    pub(super) fn search(&self) -> Vec<PathBuf> {
        self.search.clone()
    }

    /// The names a bare word may call (Sinumerik `PROC` names).
    pub(super) fn proc_names(&self) -> Vec<String> {
        if self.style == Subprograms::Procs {
            self.sections[1..].iter().map(|s| s.name.clone()).collect()
        } else {
            Vec::new()
        }
    }

    /// The last line number (for "no motion blocks").
    pub(super) fn last_line(&self) -> usize {
        self.files[0].lines
    }

    /// Runs the main program through `interp`, expanding calls (a call of a subprogram the
    /// program does not hold reads its file from [`Self::search`]). An error in a block of a
    /// file a call read names that file and its line.
    pub(super) fn run(
        &mut self,
        spec: &DialectSpec,
        interp: &mut Interpreter,
        source: &Path,
    ) -> Result<()> {
        let run = self.run_lines(spec, interp, source);
        run.map_err(|e| self.localize(e, source))
    }

    /// An error at a line of the sequence the program's lines are numbered in (the interpreter's
    /// and this module's errors name `source`, the main program, and that line) as the file
    /// and line it is at.
    pub(super) fn localize(&self, e: Error, source: &Path) -> Error {
        match e {
            Error::Parse {
                file,
                line,
                message,
            } if file == source && line > self.files[0].lines => {
                let (path, local) = self.place(line);
                Error::Parse {
                    file: path.to_path_buf(),
                    line: local,
                    message,
                }
            }
            e => e,
        }
    }

    /// The file and its line of line `global` of the sequence.
    fn place(&self, global: usize) -> (&Path, usize) {
        let unit = self
            .files
            .iter()
            .rev()
            .find(|u| global > u.offset)
            .unwrap_or(&self.files[0]);
        (&unit.path, global - unit.offset)
    }

    /// `line 12`, or `line 12 of sub/O1002.nc` when line `global` is in a file a call read.
    fn line_name(&self, global: usize) -> String {
        let (path, local) = self.place(global);
        if global <= self.files[0].lines {
            format!("line {local}")
        } else {
            format!("line {local} of {}", path.display())
        }
    }

    /// The line number of line index `index` in the sequence all files' lines are numbered in.
    fn global(&self, index: usize) -> usize {
        let line = &self.lines[index];
        self.files[line.file].offset + line.number
    }

    /// The files calls read, after the main program: (path, lines before it in the sequence,
    /// its line count).
    pub(super) fn included(&self) -> Vec<crate::toolpath::SourceFile> {
        self.files[1..]
            .iter()
            .map(|u| crate::toolpath::SourceFile {
                path: u.path.clone(),
                offset: u.offset,
                lines: u.lines,
            })
            .collect()
    }

    /// Sets where calls look for the files of subprograms the program does not hold: the main
    /// program's directory (`source`'s), then `dirs` in order.
    pub(super) fn search_in(&mut self, source: &Path, dirs: &[PathBuf]) {
        let own = match source.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        self.search = std::iter::once(own).chain(dirs.iter().cloned()).collect();
    }

    /// The file that holds subprogram `name`: the first searched directory with one wins;
    /// two in one directory are an error naming both.
    fn find_file(&mut self, name: &str) -> std::result::Result<Option<PathBuf>, String> {
        for dir in self.search.clone() {
            if !self.listings.contains_key(&dir) {
                let entries = std::fs::read_dir(&dir).map_err(|e| {
                    format!(
                        "cannot list the subprogram directory {}: {e}",
                        dir.display()
                    )
                })?;
                let names: Vec<String> = entries
                    .flatten()
                    .filter_map(|e| e.file_name().to_str().map(str::to_string))
                    .collect();
                self.listings.insert(dir.clone(), names);
            }
            let mut found: Vec<&String> = self.listings[&dir]
                .iter()
                .filter(|f| file_holds(self.style, name, f) && dir.join(f).is_file())
                .collect();
            found.sort();
            match found[..] {
                [] => continue,
                [one] => return Ok(Some(dir.join(one))),
                [a, b, ..] => {
                    return Err(format!(
                        "both {} and {} in {} could hold {name}: remove or rename one",
                        a,
                        b,
                        dir.display()
                    ));
                }
            }
        }
        Ok(None)
    }

    /// Reads the file of subprogram `name` (if a searched directory holds one) and adds its
    /// programs to this one. `Ok(false)`: no file holds it.
    fn load(&mut self, spec: &DialectSpec, name: &str) -> Result<bool> {
        if self.missing.contains(name) {
            return Ok(false);
        }
        let path = match self.find_file(name) {
            Ok(Some(path)) => path,
            Ok(None) => {
                self.missing.insert(name.to_string());
                return Ok(false);
            }
            Err(m) => return Err(Error::Usage(m)),
        };
        if self.files.len() > MAX_SUBPROGRAM_FILES {
            return Err(Error::parse(
                &path,
                1,
                format!(
                    "the program's calls read more than {MAX_SUBPROGRAM_FILES} subprogram                      files: post the program with fewer"
                ),
            ));
        }
        let bytes = crate::toolpath::read_bytes(&path)?;
        if self.bytes_included + bytes.len() > MAX_SUBPROGRAM_BYTES {
            return Err(Error::parse(
                &path,
                1,
                format!(
                    "the program's subprogram files hold more than {} MiB together: split the                      program",
                    MAX_SUBPROGRAM_BYTES >> 20
                ),
            ));
        }
        let text = String::from_utf8_lossy(&bytes);
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let text = super::program_header(spec, &path, text)?;
        let sub = Program::scan(spec, &path, &text)?;
        self.bytes_included += bytes.len();
        self.merge(sub, name, &path)?;
        Ok(true)
    }

    /// Adds the programs of file `path` (scanned as `sub`), read for a call of `name`: its
    /// first program is `name` (Fanuc: the program its own `O` header names; LinuxCNC: the
    /// file holds `o<name> sub` … `endsub` and nothing else but comments and `M2`/`M30`), and
    /// the file's other programs come with it. An error names the file and line where the
    /// file does not hold `name` or defines a program the program has already.
    fn merge(&mut self, sub: Program, name: &str, path: &Path) -> Result<()> {
        let base = self.lines.len();
        let file = self.files.len();
        let offset = self.files.last().map_or(0, |u| u.offset + u.lines);
        let Program {
            lines,
            bytes,
            sections,
            first_header,
            labels,
            ..
        } = sub;
        if self.style == Subprograms::Labels {
            // One program, its own labels.
            let k = self.sections.len();
            for ((_, label), pos) in labels {
                self.labels.insert((k, label), pos);
            }
        }
        let defined = |sections: &[Section]| -> String {
            sections
                .iter()
                .skip(1)
                .map(|s| s.name.clone())
                .chain(first_header.clone())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let holds = defined(&sections);
        let mut added = Vec::new();
        for (k, section) in sections.into_iter().enumerate() {
            let section_name = if k > 0 {
                section.name
            } else {
                match self.style {
                    Subprograms::OWordSub => {
                        // Outside the subroutine: comments, blank lines, `%`, M2 or M30 only.
                        for &i in &section.lines {
                            let Ok(blocks) = &lines[i].blocks else {
                                continue;
                            };
                            let code = blocks.iter().map(|b| b.trim()).find(|b| {
                                !b.is_empty()
                                    && !b.starts_with('%')
                                    && !matches!(first_word(b).as_str(), "M2" | "M02" | "M30")
                            });
                            if let Some(code) = code {
                                return Err(Error::parse(
                                    path,
                                    lines[i].number,
                                    format!(
                                        "`{code}` outside `{name} sub` … `{name} endsub`: \
                                         LinuxCNC reads a subroutine's file for the one \
                                         subroutine it defines; move the block into it"
                                    ),
                                ));
                            }
                        }
                        continue;
                    }
                    Subprograms::OPrograms if !name.starts_with('"') => {
                        first_header.clone().unwrap_or_else(|| name.to_string())
                    }
                    _ => name.to_string(),
                }
            };
            if let Some(&other) = self.by_name.get(&section_name) {
                let there = self.sections[other]
                    .lines
                    .first()
                    .map_or(0, |&i| self.global(i));
                return Err(Error::parse(
                    path,
                    section.header.max(1),
                    format!(
                        "subprogram {section_name} is defined here and at {}: rename one",
                        self.line_name(there)
                    ),
                ));
            }
            added.push(section_name.clone());
            self.by_name
                .insert(section_name.clone(), self.sections.len());
            self.sections.push(Section {
                name: section_name,
                header: section.header,
                lines: section.lines.iter().map(|i| i + base).collect(),
            });
        }
        if self.style == Subprograms::OWordSub && added.len() > 1 {
            return Err(Error::parse(
                path,
                1,
                format!(
                    "{} defines {}: LinuxCNC reads a subroutine's file for one subroutine, \
                     the one it is named after; move the others to files of their own",
                    path.display(),
                    added.join(", ")
                ),
            ));
        }
        self.files.push(Unit {
            path: path.to_path_buf(),
            offset,
            lines: lines.len(),
        });
        self.bytes += bytes;
        self.lines
            .extend(lines.into_iter().map(|l| Line { file, ..l }));
        if !self.by_name.contains_key(name) {
            let holds = if holds.is_empty() {
                "no subprogram".to_string()
            } else {
                holds
            };
            return Err(Error::parse(
                path,
                1,
                format!(
                    "read for a call of {name}, this file holds {holds}: name the file after \
                     the program it holds"
                ),
            ));
        }
        Ok(())
    }

    fn run_lines(
        &mut self,
        spec: &DialectSpec,
        interp: &mut Interpreter,
        source: &Path,
    ) -> Result<()> {
        let mut stack = vec![Frame {
            section: 0,
            pos: 0,
            block: 0,
            start: 0,
            runs: 1,
            call: None,
            label: None,
            locals: None,
        }];
        // Every block run counts, and its length: past the file's own lines plus
        // MAX_EXPANDED_BLOCKS, or its own text plus MAX_EXPANDED_BYTES, repeats, calls or jumps
        // have run the program too long.
        let (mut run_blocks, mut run_bytes) = (0usize, 0usize);
        let mut jumps = 0usize;
        // Klartext jumps taken: the line's index → the state then (see `Loop`).
        let mut taken: HashMap<usize, Loop> = HashMap::new();
        // Fanuc macro jumps taken: (line index, block) → the state then; and where each
        // loop's other end and each block number is, found once.
        let mut macro_taken: HashMap<(usize, usize), Loop> = HashMap::new();
        let mut macro_places = MacroPlaces::default();
        while let Some(&Frame {
            section,
            pos,
            block,
            ..
        }) = stack.last()
        {
            let Some(&index) = self.sections[section].lines.get(pos) else {
                // The section ran out: a return.
                if !self.ret(&mut stack, &mut interp.vars) {
                    return Ok(());
                }
                continue;
            };
            let number = self.global(index);
            let line = &self.lines[index];
            interp.vars.line = number;
            let blocks = match &line.blocks {
                Ok(b) => b,
                Err(m) => {
                    return Err(self.located(Error::parse(source, number, m.clone()), &stack));
                }
            };
            if let Some(top) = stack.last_mut() {
                if block + 1 >= blocks.len() {
                    top.pos += 1;
                    top.block = 0;
                } else {
                    top.block += 1;
                }
            }
            let Some(text) = blocks.get(block) else {
                continue;
            };
            let text = text.trim();
            if text.is_empty() {
                continue;
            }
            if let Some(rest) = text.strip_prefix('%') {
                let rest = rest.trim();
                // (Sinumerik's `%_N_NAME_SPF` and `%MPF123` head programs: not such lines.)
                if !rest.is_empty() && self.style != Subprograms::Procs {
                    // A `%` line is the tape's start or end mark only when it is `%` alone.
                    // LinuxCNC (rs274ngc `Interp::open`) takes a first line as the percent line
                    // when nothing but blanks follows the `%`; otherwise it reads the file from
                    // its first line as G-code, where `%` is no word: it refuses the line, and
                    // the program does not run. (Round 20: an MPCNC start file's `% vfd
                    // enable`, `% LED ON`, written for another sender or control, were skipped
                    // in silence.) The line moves nothing on any reading: a warning naming it,
                    // as for an M code the control does not know.
                    let message = if spec.name == LINUXCNC.name {
                        format!(
                            "`{text}`: a `%` line with text after it is no tape start or end \
                             mark, which LinuxCNC reads only as `%` alone: it reads this line \
                             as G-code and refuses it (`%` is no word), so the program does not \
                             run on LinuxCNC as written; skipped here (it moves nothing). If \
                             it is a command for another sender or control, keep it; for \
                             LinuxCNC make it a comment `({rest})`"
                        )
                    } else {
                        format!(
                            "`{text}`: a `%` line with text after it, skipped as a tape start or \
                             end mark (`{rest}` is not read)"
                        )
                    };
                    interp.warn(number, message);
                }
                continue;
            }
            // grbl's system commands, `$H`, `$X`, `$22=1`, … (not Sinumerik's `$` system
            // variables, `$P_…`, nor Klartext): gSender's programs home with `$H` and then set
            // the work offset from there with `G10 L20`.
            if text.starts_with('$')
                && !matches!(self.style, Subprograms::Procs | Subprograms::Labels)
            {
                match grbl_command(text) {
                    GrblCommand::Home(axes) => {
                        if let Err(e) = interp.homing(number, text, &axes) {
                            return Err(self.located(e, &stack));
                        }
                    }
                    GrblCommand::Still(what) => interp.warn(
                        number,
                        format!("`{text}`: grbl's {what}; it moves nothing, skipped"),
                    ),
                    GrblCommand::Refused(why) => {
                        return Err(self.located(
                            Error::parse(source, number, format!("`{text}`: {why}")),
                            &stack,
                        ));
                    }
                }
                continue;
            }
            run_blocks += 1;
            run_bytes += text.len();
            if run_blocks > MAX_EXPANDED_BLOCKS + self.lines.len()
                || run_bytes > MAX_EXPANDED_BYTES + self.bytes
            {
                return Err(self.too_many(source, number, &stack, jumps));
            }
            let run_deleted;
            let mark = self.block_delete_mark(text);
            let deleted = mark.is_some();
            let text = match mark {
                None => text,
                Some(_) if interp.block_delete => {
                    interp.warn(
                        number,
                        "block delete `/`: block skipped (--block-delete: the control's \
                         block-skip switch on)",
                    );
                    continue;
                }
                Some(rest) => {
                    interp.warn(
                        number,
                        "block delete `/`: block run, as with the control's block-skip switch \
                         off (--block-delete skips it)",
                    );
                    run_deleted = rest;
                    run_deleted.as_str()
                }
            };
            if self.style == Subprograms::Labels {
                let body = klartext::strip_block_number(text);
                match program_call(body) {
                    None => {}
                    Some(Err(m)) => {
                        return Err(self.located(Error::parse(source, number, m), &stack));
                    }
                    Some(Ok(ProgramCall::Select(name))) => {
                        self.selected.replace(Some(name));
                        continue;
                    }
                    // The end of a program a CALL PGM runs returns to the caller; the main
                    // program's ends it (read as the table says).
                    Some(Ok(ProgramCall::End))
                        if stack
                            .last()
                            .is_some_and(|f| f.section > 0 && f.label.is_none()) =>
                    {
                        if !self.ret(&mut stack, &mut interp.vars) {
                            return Ok(());
                        }
                        continue;
                    }
                    Some(Ok(ProgramCall::End)) => {}
                    Some(Ok(ProgramCall::Call(name))) => {
                        let name = match name {
                            Some(name) => name,
                            None => self.selected.borrow().clone().ok_or_else(|| {
                                self.located(
                                    Error::parse(
                                        source,
                                        number,
                                        "CALL SELECTED PGM with no SEL PGM before it: select \
                                         the program with SEL PGM \"name\"",
                                    ),
                                    &stack,
                                )
                            })?,
                        };
                        let call = Call {
                            text: body.trim().to_string(),
                            targets: vec![(name, 1)],
                        };
                        self.enter(spec, &mut stack, call, number, source)?;
                        continue;
                    }
                }
                let op = klartext::label_op(body)
                    .map_err(|m| self.located(Error::parse(source, number, m), &stack))?;
                match op {
                    None => {}
                    Some(LabelOp::Label(_)) => continue,
                    Some(LabelOp::End) => {
                        // In a program (the main one, or one a CALL PGM runs), a subprogram's
                        // end is run through; it ends a label call.
                        let in_label = stack.last().is_some_and(|f| f.label.is_some());
                        if in_label && !self.ret(&mut stack, &mut interp.vars) {
                            return Ok(());
                        }
                        continue;
                    }
                    Some(LabelOp::Call { name, repeats }) => {
                        let own = stack
                            .last()
                            .and_then(|f| f.label.as_ref())
                            .is_some_and(|(at, _)| *at == pos);
                        if own {
                            // A section repeat's pass is over.
                            if !self.ret(&mut stack, &mut interp.vars) {
                                return Ok(());
                            }
                        } else {
                            self.enter_label(&mut stack, &name, repeats, pos, number, source)?;
                        }
                        continue;
                    }
                    Some(LabelOp::Jump {
                        name,
                        a,
                        compare,
                        b,
                    }) => {
                        let value = |e: &str| {
                            klartext::value(e, &interp.vars).map_err(|m| {
                                self.located(
                                    Error::parse(source, number, format!("`{e}`: {m}")),
                                    &stack,
                                )
                            })
                        };
                        let (a, b) = (value(&a)?, value(&b)?);
                        if klartext::holds(compare, a, b) {
                            let target = self.label(&name, number, source, &stack)?;
                            let now = Loop::now(&stack, interp.vars.changes());
                            if taken.get(&index) == Some(&now) {
                                let at = self.global(self.sections[section].lines[target]);
                                return Err(self.endless(source, number, body, &name, at));
                            }
                            taken.insert(index, now);
                            jumps += 1;
                            if let Some(top) = stack.last_mut() {
                                top.pos = target + 1;
                                top.block = 0;
                            }
                        }
                        continue;
                    }
                }
            }
            if self.style == Subprograms::OWordSub
                && let Some((name, kind, tail)) = oword(text)
            {
                match kind {
                    OWord::Call => {
                        let written = if tail.is_empty() {
                            format!("{name} call")
                        } else {
                            format!("{name} call {tail}")
                        };
                        let arguments = call_arguments(&tail, &interp.vars).map_err(|m| {
                            self.located(
                                Error::parse(source, number, format!("`{written}`: {m}")),
                                &stack,
                            )
                        })?;
                        let call = Call {
                            text: written,
                            targets: vec![(name, 1)],
                        };
                        let depth = stack.len();
                        self.enter(spec, &mut stack, call, number, source)?;
                        if stack.len() > depth
                            && let Some(top) = stack.last_mut()
                        {
                            // #1–#30 are the call's own: the arguments, then the caller's
                            // values, all given back on return.
                            top.locals = Some(bind_locals(
                                &mut interp.vars,
                                MAX_CALL_ARGUMENTS,
                                false,
                                arguments.iter().enumerate().map(|(k, v)| (k + 1, *v)),
                            ));
                        }
                    }
                    OWord::Return | OWord::EndSub => {
                        if !self.ret(&mut stack, &mut interp.vars) {
                            return Ok(());
                        }
                    }
                    // Definitions were taken apart by the scan.
                    OWord::Sub => {}
                }
                continue;
            }
            // A Fadal subroutine call `L0102` / `L102`: subroutine 1, twice (only in a file that
            // defines Fadal subroutines; elsewhere a bare L is the interpreter's error).
            if self.style == Subprograms::OPrograms
                && let Some((n, runs)) = fadal_subroutine(text)
                && runs > 0
                && self.by_name.keys().any(|k| fadal_name(k))
            {
                let call = Call {
                    text: strip_block_number(text).trim().to_string(),
                    targets: vec![(format!("L{n}"), u64::from(runs))],
                };
                self.enter(spec, &mut stack, call, number, source)?;
                continue;
            }
            if self.style == Subprograms::OPrograms
                && text.contains('"')
                && first_word(text).starts_with("M98")
            {
                let call = haas_file_call(text)
                    .map_err(|m| self.located(Error::parse(source, number, m), &stack))?;
                self.enter(spec, &mut stack, call, number, source)?;
                continue;
            }
            if self.style == Subprograms::Procs
                && matches!(first_word(text).as_str(), "EXTCALL" | "CALL")
            {
                let call = sinumerik_call(text)
                    .map_err(|m| self.located(Error::parse(source, number, m), &stack))?;
                self.enter(spec, &mut stack, call, number, source)?;
                continue;
            }
            let mut then_text = String::new();
            let text = match self.style {
                Subprograms::OPrograms => match macro_b::statement(text) {
                    None => text,
                    Some(statement) => {
                        let located =
                            |m: String| self.located(Error::parse(source, number, m), &stack);
                        let statement = statement.map_err(located)?;
                        let holds = |condition: &str| {
                            macro_b::condition(condition, &interp.vars).map_err(located)
                        };
                        // Where the program goes on: (line in the section, block).
                        let jump = match &statement {
                            Statement::While { condition, id } => {
                                if holds(condition)? {
                                    None
                                } else {
                                    let end = macro_places
                                        .loop_end(self, section, pos, block, *id)
                                        .ok_or_else(|| {
                                            located(format!(
                                                "WHILE … DO{id} has no END{id} after it in                                                  this program"
                                            ))
                                        })?;
                                    // After the END: its next block.
                                    Some((end.0, end.1 + 1, false))
                                }
                            }
                            Statement::Do { .. } => None,
                            Statement::End { id } => {
                                let start = macro_places
                                    .loop_start(self, section, pos, block, *id)
                                    .ok_or_else(|| {
                                        located(format!(
                                            "END{id} has no DO{id} before it in this program"
                                        ))
                                    })?;
                                Some((start.0, start.1, true))
                            }
                            Statement::IfGoto { condition, target } if holds(condition)? => {
                                let n = macro_b::target(target, &interp.vars).map_err(located)?;
                                let at =
                                    macro_places.numbered(self, section, n).ok_or_else(|| {
                                        located(format!("GOTO {n}: no block N{n} in this program"))
                                    })?;
                                Some((at.0, at.1, true))
                            }
                            Statement::IfGoto { .. } => None,
                            Statement::Goto { target } => {
                                let n = macro_b::target(target, &interp.vars).map_err(located)?;
                                let at =
                                    macro_places.numbered(self, section, n).ok_or_else(|| {
                                        located(format!("GOTO {n}: no block N{n} in this program"))
                                    })?;
                                Some((at.0, at.1, true))
                            }
                            Statement::IfThen { condition, then } => {
                                if !holds(condition)? {
                                    continue;
                                }
                                then_text = then.clone();
                                None
                            }
                        };
                        if let Statement::IfThen { .. } = statement {
                            then_text.as_str()
                        } else {
                            if let Some((to_pos, to_block, back)) = jump {
                                if back {
                                    // The same jump in the same state: the same pass for ever.
                                    let now = Loop::now(&stack, interp.vars.changes());
                                    if macro_taken.get(&(index, block)) == Some(&now) {
                                        return Err(located(format!(
                                            "`{}` jumps to {} for ever: no macro                                              variable has changed since it last jumped, so                                              every pass runs the same way; make the loop                                              change what its condition reads (a counter)",
                                            text,
                                            self.line_name(
                                                self.global(self.sections[section].lines[to_pos])
                                            )
                                        )));
                                    }
                                    macro_taken.insert((index, block), now);
                                }
                                jumps += 1;
                                if let Some(top) = stack.last_mut() {
                                    top.pos = to_pos;
                                    top.block = to_block;
                                }
                            }
                            continue;
                        }
                    }
                },
                _ => text,
            };
            if self.style == Subprograms::Procs
                && (matches!(first_word(text).as_str(), "PROC" | "EXTERN")
                    || sinumerik_header(text).is_some())
            {
                continue;
            }
            let items = lex(spec, text, &mut interp.vars).map_err(|m| {
                // Text after a `;`, which ends a block in this dialect (Fanuc's), that is no
                // block: most likely a comment as Mach3 and LinuxCNC write them (round 8,
                // SolidCAM's Mach3 post: `G0 G53 Z123 ; move up to tool_z_level`).
                let m = if block > 0 && spec.semicolon == Semicolon::EndOfBlock {
                    format!(
                        "{m}, in `{text}` after a `;`, which ends a block in the {} dialect; \
                         if the `;` starts a comment (as Mach3 and LinuxCNC read it), remove \
                         the comment, or read the program in the LinuxCNC dialect \
                         (--dialect linuxcnc)",
                        spec.name
                    )
                } else {
                    m
                };
                self.located(
                    delete_hint(Error::parse(source, number, m), deleted),
                    &stack,
                )
            })?;
            if self.style == Subprograms::OPrograms && is_macro_call(&items) {
                let (call, arguments) =
                    macro_call(&items, interp.integer_increments()).map_err(|m| {
                        self.located(
                            Error::parse(source, number, format!("`{text}`: {m}")),
                            &stack,
                        )
                    })?;
                let depth = stack.len();
                self.enter(spec, &mut stack, call, number, source)?;
                if stack.len() > depth
                    && let Some(top) = stack.last_mut()
                {
                    // #1–#33 are the macro's own: vacant but for the arguments, the caller's
                    // given back on return.
                    top.locals = Some(bind_locals(&mut interp.vars, MACRO_LOCALS, true, arguments));
                }
                continue;
            }
            interp
                .block(number, items)
                .and_then(|()| interp.check_room(number, "this block", 0))
                .map_err(|e| self.located(delete_hint(e, deleted), &stack))?;
            if let Some(call) = interp.call.take() {
                self.enter(spec, &mut stack, call, number, source)?;
            } else if interp.ended {
                interp.ended = false;
                if interp.end_of_program || !self.ret(&mut stack, &mut interp.vars) {
                    return Ok(());
                }
            }
        }
        Ok(())
    }

    /// A block that starts with the block-delete mark `/` (after its block number, in
    /// Klartext): the block without it (and without a skip level `/1` … `/9`, outside
    /// Klartext, whose `/80 M30` puts the block number right after the mark).
    fn block_delete_mark(&self, text: &str) -> Option<String> {
        if self.style == Subprograms::Labels {
            if let Some(rest) = text.strip_prefix('/') {
                return Some(rest.trim_start().to_string());
            }
            let body = klartext::strip_block_number(text);
            let rest = body.strip_prefix('/')?;
            let number = &text[..text.len() - body.len()];
            return Some(format!("{number}{rest}"));
        }
        let rest = text.strip_prefix('/')?;
        let rest = rest
            .strip_prefix(|c: char| c.is_ascii_digit())
            .unwrap_or(rest);
        Some(rest.trim_start().to_string())
    }

    /// Returns from the running (sub)program: runs it again while repeats remain, else pops
    /// it (a LinuxCNC O-word call gives the caller its `#1`–`#30` back). `false`: the
    /// main program has ended.
    fn ret(&self, stack: &mut Vec<Frame>, vars: &mut Variables) -> bool {
        if stack.len() <= 1 {
            return false;
        }
        let Some(top) = stack.last_mut() else {
            return false;
        };
        if top.runs > 1 {
            top.runs -= 1;
            top.pos = top.start;
            top.block = 0;
        } else if let Some(Frame {
            locals: Some(saved),
            ..
        }) = stack.pop()
        {
            for (k, v) in saved.into_iter().enumerate() {
                vars.restore(&format!("#{}", k + 1), v);
            }
        }
        true
    }

    /// Starts a call made at line `number`.
    fn enter(
        &mut self,
        spec: &DialectSpec,
        stack: &mut Vec<Frame>,
        call: Call,
        number: usize,
        source: &Path,
    ) -> Result<()> {
        let mut found = call
            .targets
            .iter()
            .find_map(|(name, runs)| self.by_name.get(name).map(|&k| (k, *runs)));
        if found.is_none() {
            for (name, runs) in &call.targets {
                if self.load(spec, name)? {
                    found = self.by_name.get(name).map(|&k| (k, *runs));
                    break;
                }
            }
        }
        let Some((section, runs)) = found else {
            let name = &call.targets[0].0;
            let how = match self.style {
                Subprograms::OPrograms => format!("{name} … M99"),
                Subprograms::Procs => format!("PROC {name} … RET"),
                Subprograms::OWordSub => format!("{name} sub … {name} endsub"),
                Subprograms::Labels => format!("LBL {name} … LBL 0"),
            };
            let files = call
                .targets
                .iter()
                .map(|(n, _)| file_names(self.style, n))
                .filter(|f| !f.is_empty())
                .collect::<Vec<_>>()
                .join("; ");
            let message = if files.is_empty() {
                format!(
                    "`{}`: subprogram {name} is not in this file: add {how} to it, or post the \
                     program without subprogram calls",
                    call.text
                )
            } else {
                let dirs = self
                    .search
                    .iter()
                    .map(|d| d.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ");
                let add = if self.style == Subprograms::Labels {
                    String::new()
                } else {
                    format!(", or add {how} to this file")
                };
                format!(
                    "`{}`: {} {name} is neither in this file nor in a file {files} in {dirs}: \
                     give the directory that holds it with --subprogram-dir DIR{add}",
                    call.text,
                    if self.style == Subprograms::Labels {
                        "program"
                    } else {
                        "subprogram"
                    }
                )
            };
            return Err(self.located(Error::parse(source, number, message), stack));
        };
        let frame = Frame {
            section,
            pos: 0,
            block: 0,
            start: 0,
            runs,
            call: Some((call.text, number)),
            label: None,
            locals: None,
        };
        self.call(stack, frame, number, source)
    }

    /// Starts the call `frame` made at line `number` (every style's calls, and Klartext label
    /// calls and section repeats): nothing for zero runs; an error past [`MAX_CALL_DEPTH`], or
    /// for more runs than [`MAX_EXPANDED_BLOCKS`] (each run costs at least one block: a huge
    /// repeat count of an empty body is refused before it starts).
    fn call(
        &self,
        stack: &mut Vec<Frame>,
        frame: Frame,
        number: usize,
        source: &Path,
    ) -> Result<()> {
        if frame.runs == 0 {
            return Ok(());
        }
        let text = frame.call.as_ref().map_or("", |(t, _)| t.as_str());
        if stack.len() > MAX_CALL_DEPTH {
            let what = if frame.label.is_some() {
                "label calls"
            } else {
                "subprogram calls"
            };
            // A subprogram that calls itself (directly or through others) without an end.
            let own = stack[1..]
                .iter()
                .any(|f| f.section == frame.section && f.label.is_none())
                && frame.label.is_none();
            let why = if own {
                format!(
                    "{} calls itself, and does not stop before that: a subprogram that calls \
                     itself must end the recursion on a condition",
                    self.sections[frame.section].name
                )
            } else {
                "does a subprogram call itself?".to_string()
            };
            return Err(self.located(
                Error::parse(
                    source,
                    number,
                    format!("`{text}`: {what} nested more than {MAX_CALL_DEPTH} deep ({why})"),
                ),
                stack,
            ));
        }
        if frame.runs > MAX_EXPANDED_BLOCKS as u64 {
            return Err(self.too_many(source, number, stack, 0));
        }
        stack.push(frame);
        Ok(())
    }

    /// The line index of label `name` (an error naming it when the file lacks it).
    fn label(&self, name: &str, number: usize, source: &Path, stack: &[Frame]) -> Result<usize> {
        let section = stack.last().map_or(0, |f| f.section);
        self.labels
            .get(&(section, name.to_string()))
            .copied()
            .ok_or_else(|| {
                self.located(
                Error::parse(
                    source,
                    number,
                    format!(
                        "LBL {name} is not in this file: add `LBL {name}` … `LBL 0`, or post the \
                         program without the call"
                    ),
                ),
                stack,
            )
            })
    }

    /// `CALL LBL name [REP repeats]` at line index `at` (line `number`).
    fn enter_label(
        &self,
        stack: &mut Vec<Frame>,
        name: &str,
        repeats: Option<u64>,
        at: usize,
        number: usize,
        source: &Path,
    ) -> Result<()> {
        let target = self.label(name, number, source, stack)?;
        let text = match repeats {
            Some(r) => format!("CALL LBL {name} REP {r}"),
            None => format!("CALL LBL {name}"),
        };
        let runs = match repeats {
            None => 1,
            Some(_) if target > at => {
                return Err(self.located(
                    Error::parse(
                        source,
                        number,
                        format!(
                            "`{text}`: LBL {name} comes after the call (a subprogram); a repeat \
                             count belongs to a program-section repeat, whose label comes \
                             before the call: call the subprogram without REP, from a repeated \
                             section"
                        ),
                    ),
                    stack,
                ));
            }
            Some(r) => r,
        };
        let frame = Frame {
            section: stack.last().map_or(0, |f| f.section),
            pos: target + 1,
            block: 0,
            start: target + 1,
            runs,
            call: Some((text, number)),
            label: Some((at, name.to_string())),
            locals: None,
        };
        self.call(stack, frame, number, source)
    }

    /// The error of a program that runs more than [`MAX_EXPANDED_BLOCKS`] blocks past its own
    /// lines (or a call that would), after `jumps` Klartext jumps.
    fn too_many(&self, source: &Path, number: usize, stack: &[Frame], jumps: usize) -> Error {
        let jumped = if jumps > 0 {
            format!(" ({jumps} jumps FN 9–12 taken: does a jump loop?)")
        } else {
            String::new()
        };
        self.located(
            Error::parse(
                source,
                number,
                format!(
                    "subprogram calls, repeats and jumps run more than {MAX_EXPANDED_BLOCKS} \
                     blocks or {} MiB of blocks past the program's own{jumped}: lower the \
                     repeat counts, or post the program without subprogram calls",
                    MAX_EXPANDED_BYTES >> 20
                ),
            ),
            stack,
        )
    }

    /// The error of a Klartext jump `block` at line `number` to label `name` (at line index
    /// `target`) taken a second time with the same state: it loops for ever.
    fn endless(
        &self,
        source: &Path,
        number: usize,
        block: &str,
        name: &str,
        target: usize,
    ) -> Error {
        Error::parse(
            source,
            number,
            format!(
                "`{block}` jumps back to LBL {name} ({}) for ever: no Q parameter has \
                 changed since it last jumped, so every pass runs the same way; make the loop \
                 change what the condition reads (a counter), or remove the jump",
                self.line_name(target)
            ),
        )
    }

    /// Adds to a parse error inside a subprogram where it was called from.
    fn located(&self, e: Error, stack: &[Frame]) -> Error {
        let Some(Frame {
            section,
            call: Some((text, line)),
            label,
            ..
        }) = stack.last()
        else {
            return e;
        };
        let name = match label {
            Some((_, name)) => format!("LBL {name}"),
            None => format!("subprogram {}", self.sections[*section].name),
        };
        match e {
            Error::Parse {
                file,
                line: at,
                message,
            } => Error::Parse {
                file,
                line: at,
                message: format!(
                    "{message} (in {name}, called by `{text}` at {})",
                    self.line_name(*line)
                ),
            },
            other => other,
        }
    }
}

/// An error in a block run with the block-delete mark `/` (the control's block-skip switch
/// off): says that `--block-delete` skips it (round 8: a TNC program's probing cycle under
/// `/`, which the shop runs with the switch on).
fn delete_hint(e: Error, deleted: bool) -> Error {
    match e {
        Error::Parse {
            file,
            line,
            message,
        } if deleted => Error::Parse {
            file,
            line,
            message: format!(
                "{message} (the block starts with `/`, block delete: --block-delete skips \
                 it, as the control's block-skip switch does)"
            ),
        },
        e => e,
    }
}

/// A call's own local variables `#1`–`#count`: the caller's, returned for [`Program::ret`] to
/// give back, then vacant where `vacate` (a Fanuc macro's), and `arguments` (`(k, v)`: `#k`
/// = v) set.
fn bind_locals(
    vars: &mut Variables,
    count: usize,
    vacate: bool,
    arguments: impl IntoIterator<Item = (usize, f64)>,
) -> Vec<Option<f64>> {
    let saved = (1..=count).map(|k| vars.value(&format!("#{k}"))).collect();
    if vacate {
        for k in 1..=count {
            vars.restore(&format!("#{k}"), None);
        }
    }
    for (k, v) in arguments {
        vars.set(&format!("#{k}"), v);
    }
    saved
}

/// What a grbl system command line (`$…`) does, as the grbl 1.1 and grblHAL documents list
/// them (grbl wiki "Grbl v1.1 Commands": `$$`, `$#`, `$G`, `$I`, `$N`, `$x=value`,
/// `$Nx=line`, `$C`, `$X`, `$H`, `$J=line`, `$RST=…`, `$SLP`; grblHAL adds `$HX`, `$HY`, …
/// to home one axis).
#[derive(Debug, PartialEq)]
pub(crate) enum GrblCommand {
    /// `$H`: every axis grbl homes (an empty list); `$HX`: the axes (indices into X Y Z A B C).
    Home(Vec<usize>),
    /// A command that moves nothing: what it is.
    Still(&'static str),
    /// A command feedopt does not read, why.
    Refused(String),
}

pub(crate) fn grbl_command(text: &str) -> GrblCommand {
    let body: String = text[1..]
        .chars()
        .take_while(|&c| c != '(' && c != ';')
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_uppercase();
    if let Some(axes) = body.strip_prefix('H') {
        let found: Option<Vec<usize>> = axes.chars().map(|c| "XYZABC".find(c)).collect();
        return match found {
            Some(list) => GrblCommand::Home(list),
            None => GrblCommand::Refused(
                "not a grbl homing command (`$H`, or grblHAL's `$HX`, `$HY`, `$HZ`, … for one \
                 axis)"
                    .into(),
            ),
        };
    }
    match body.as_str() {
        "X" => return GrblCommand::Still("alarm unlock (kill alarm lock)"),
        "$" | "#" | "G" | "I" | "N" => {
            return GrblCommand::Still("report of its settings or state");
        }
        "C" => {
            return GrblCommand::Refused(
                "grbl's check mode: the control then parses the blocks that follow without \
                 moving, which feedopt does not model; remove it to time the program"
                    .into(),
            );
        }
        "SLP" => {
            return GrblCommand::Refused(
                "grbl's sleep: the control disables its steppers and stops until reset, so the \
                 blocks after it do not run as a program; remove it to time the program"
                    .into(),
            );
        }
        _ => {}
    }
    if body.starts_with("J=") {
        return GrblCommand::Refused(
            "a grbl jog, which moves the tool and is not read: write it as a G1 move".into(),
        );
    }
    if body.starts_with("RST=") {
        return GrblCommand::Still("settings reset (the machine file gives the limits)");
    }
    if let Some((key, _)) = body.split_once('=')
        && !key.is_empty()
        && (key.chars().all(|c| c.is_ascii_digit())
            || (key.starts_with('N') && key[1..].chars().all(|c| c.is_ascii_digit())))
    {
        return GrblCommand::Still(
            "setting or startup block, stored for later (the machine file gives the limits)",
        );
    }
    GrblCommand::Refused(
        "not a grbl system command feedopt knows (`$H` homing, `$X`, `$$`, `$#`, `$G`, `$I`, \
         `$N`, `$n=value` settings); it may move the tool, so it is not skipped"
            .into(),
    )
}
