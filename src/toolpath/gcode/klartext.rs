//! Heidenhain TNC 640 Klartext (conversational, `.h`): a lexer that turns each block into the
//! common interpreter's input (words resolved through [`super::HEIDENHAIN`]), and the
//! label, jump and `FN` statements the program runner and the lexer handle themselves.
//!
//! # Blocks
//!
//! A line is a block: an optional block number (`12 L X+10 FMAX`), then the statement. `;`
//! starts a comment, a block starting with `*` is a structure comment (`* - ROUGHING`), a
//! line ending in `~` continues on the next line (cycle definitions as the TNC 640 writes
//! them; a `CYCL DEF` keeps where its lines ended, so that an error names the line of its
//! parameter), `/` before the block skips it (block delete, as in the G-code dialects: skipped with
//! a warning). Numbers carry their sign (`X+10`, `X-5`; `X10` is read too) and may use a comma
//! as the decimal separator (`X-6,964`). A value may be a Q parameter (`X+Q1`, `FQ53`).
//!
//! The first word (or words) say what the block is; the table's keywords are matched longest
//! first (`FUNCTION RESET TCPM` before `FUNCTION`):
//!
//! * **Path functions**, followed by words: `L` / `LN` (straight line; `LN` with the tool
//!   vector `TX TY TZ`, the surface normal `NX NY NZ` is only read by 3D radius compensation
//!   and is ignored), `CC` (circle centre and pole), `C` (arc about `CC`), `CR` (arc by
//!   radius), `CT` (tangential arc), `CP` (arc about `CC` by polar angle), `LP` (line to polar
//!   coordinates).
//! * **Statements**, whose words belong to them: `BEGIN PGM`, `END PGM`, `BLK FORM`,
//!   `TOOL CALL`, `TOOL DEF`, `CYCL DEF`, `CYCL CALL`, `PATTERN DEF`, `PLANE`,
//!   `FUNCTION TCPM`, `FUNCTION RESET TCPM`, `RND`, `CHF`, `STOP`.
//! * **Other blocks**: `M` functions alone (`M3`, `M140 MB MAX`), Q-parameter assignments
//!   (`Q1 = 5`, `Q200=+2`, `FN 0: Q1 = +5`, `FN 1`–`FN 5`), labels and jumps (`LBL 1`,
//!   `LBL 0`, `CALL LBL 1 REP 2`, `FN 9: IF +Q1 EQU +1 GOTO LBL 5`; see
//!   [`super::subprograms`]).
//!
//! Within a block, words are `NAME±value`: the letters `X Y Z A B C R F M S`, the named words
//! `IX IY IZ IA IB IC` (incremental, this word only), `DR+`/`DR-`, `PA IPA PR IPR`,
//! `TX TY TZ`, `NX NY NZ`, `MB`; and the keywords `FMAX`/`F MAX` (this block is a rapid; F
//! stays), `FAUTO`/`F AUTO` (the `TOOL CALL` feed), `R0`/`RL`/`RR`, `MB MAX`. A word the
//! table does not know is an **error** naming it (a Klartext word may move the tool), except
//! an `M` function, which the interpreter warns about as in every dialect. Axis words outside
//! a path function are an error.
//!
//! # Q parameters
//!
//! `Q`, `QL`, `QR` parameters are read before they are set only by mistake: that is an error
//! naming the parameter, except `Q120`–`Q122` in a rotary word (`L A+Q120 C+Q122 FMAX`): they
//! hold the rotary positions the control computes for the active `PLANE`: the tool vector of
//! the tilted plane rules there, and under `SEQ+`/`SEQ-` the solution SEQ selects. Assignments: `Q1 = expr`
//! (`+ - * /`, parentheses and the functions of [`super::expr`]), `FN 0: Q1 = +5` (assign),
//! `FN 1` (+), `FN 2` (−), `FN 3` (×), `FN 4` (`DIV`), `FN 5: Q1 = SQRT +Q2`. `FN 16`
//! (`F-PRINT`) prints and is skipped; every other `FN` is an error naming it.
//!
//! # What the blocks do
//!
//! * **Lines** `L`/`LN` go to the end point at F (modal, mm/min), or at rapid under `FMAX`
//!   (this block only); `FAUTO` takes the `TOOL CALL`'s F. `LN … TX TY TZ` sets the tool
//!   vector (normalised), read as the tool orientation under `M128`/`FUNCTION TCPM`.
//! * **Arcs**: `CC` sets the circle centre (pole) and the arc plane from the two coordinates
//!   it names (`CC X Y` XY, `CC Y Z` YZ, `CC X Z` ZX; `CC` alone: the current X Y; `IX`…
//!   relative to the current position); `C` goes about it to the end point, `DR+`
//!   counter-clockwise (positive rotation about the plane's normal, as G3 under G17/G18/G19),
//!   `DR-` clockwise, an end point equal to the start a full circle; `CR X Y R± DR±` is the
//!   R arc of G2/G3 in the XY plane (R+ at most 180°, R− more); `CT X Y` the arc through the
//!   end point tangent to the line or arc just before it (in XY); `CP PA±a DR±` / `CP IPA±a`
//!   goes about the pole at the current radius to polar angle a (measured from the plane's
//!   first axis: +X in XY, +Y in YZ, +Z in ZX) or by a (turns included, a helix with `IZ`);
//!   `LP PR PA` is a line to polar coordinates about the pole. The axis normal to the arc
//!   plane moves linearly (a helix). Arcs are chords as in G-code ([`super`]).
//! * **Machine coordinates** `M91`: as G53. `M92`: relative to the machine builder's datum,
//!   the machine file's `axes.<X|Y|Z>.m92` (machine zero, with a warning, where it gives
//!   none). `CYCL DEF9.1` (the number against `DEF`, as some posts write it) is
//!   `CYCL DEF 9.1`. **Rotary** `M126`: an absolute rotary word goes
//!   the shorter way (`M127`: as written). **TCP** `M128`, `FUNCTION TCPM F TCP AXIS POS`:
//!   on; `M129`, `FUNCTION RESET TCPM`: off (`AXIS SPAT` and `REFPNT CENTER-CENTER` are
//!   errors; `F CONT` and `PATHCTRL VECTOR` are warnings: the tip feed and axis
//!   interpolation are what the toolpath carries).
//! * **Retract** `M140 MB d`: along the tool axis by d mm (at F if the block gives one, else
//!   at rapid); `M140 MB MAX`: up to the machine's Z travel limit (`axes.Z.max` of the machine
//!   file; an error when the machine or the field is missing, or the tool is tilted).
//! * **Frames**: `CYCL DEF 7` datum shift (`7.1 X+…`, `7.2 Y…`, `7.3 Z…`; `IX` adds to the
//!   shift; an omitted axis keeps its shift) and `PLANE` (the working plane: `SPATIAL SPA SPB
//!   SPC`, R = Rz(SPC)·Ry(SPB)·Rx(SPA) about the fixed axes; `EULER EULPR EULNU EULROT`,
//!   R = Rz(PR)·Rx(NU)·Rz(ROT); `VECTOR BX BY BZ NX NY NZ`; `RELATIV SPA/SPB/SPC` turns the
//!   active plane further; `RESET`) compose as p_workpiece = shift + R·p, the frames of
//!   [`super::frames`]: the plane turns about the shifted datum. A change of frame does
//!   not move the tool: its position is re-expressed in the new coordinates. Under a plane
//!   the tool points along the plane's Z. `TURN`/`MOVE` turn the tool there at once (a
//!   reorientation point; `MB` retracts first); `STAY` leaves the rotary axes where they
//!   are: the tool keeps its orientation until a block positions a rotary axis, e.g.
//!   `L A+Q120 C+Q122 FMAX` (Q120–Q122: the control's solution for the plane). Of the
//!   rotary axes' two solutions for the plane's tool axis the kinematics chooses
//!   ([`crate::kinematics::branch`]), but `SEQ+`/`SEQ-` selects the one whose master axis
//!   (the tilting axis: A of an A/C table) stands at a positive or negative angle, as the
//!   control does, and `SYM+`/`SYM-` (TNC7) the one whose master axis stands above or below
//!   its symmetry point, the centre of its travel (TNC7 user's manual, "Tilting solution"; an
//!   error where the machine file gives the master axis no travel): with the machine file's kinematics the reader computes those positions
//!   ([`crate::kinematics::Kinematics::sequence_positions`], C the shorter way from where it
//!   stands) and the block that positions the axes (`TURN`/`MOVE` itself, after `STAY` the
//!   `A+Q120 C+Q122` block) carries them; outside travel that is an error naming the line and
//!   SEQ (the control's too); read without a machine file, a warning. A block under a plane
//!   whose own words position rotary axes (`L A-90 C+270 R0 FMAX` after `STAY`, or after
//!   `TURN`/`MOVE`) moves them where it says, as the control does, the working plane staying
//!   the plane's: its points carry those positions. Outside tool-tip mode they must put the
//!   tool along the plane's tool axis (within 1e-4 rad, the posts' rounding), by the machine
//!   file's kinematics: otherwise the part would be machined at another angle than the plane
//!   its coordinates are given in, an error naming the line, the plane's line and both
//!   directions. After a `TURN`/`MOVE` or `L A+Q120 C+Q122` without SEQ the reader does not
//!   know the kinematics' choice: a block that then positions only some of the rotary axes is
//!   an error naming the others. Read without a machine file the words are run as programmed
//!   with a warning. Blocks without rotary words follow the plane's tool vector; Sinumerik's
//!   `CYCLE800` frame is not affected. `PLANE RESET TURN`/`MOVE` turns the rotary axes back
//!   to 0. A non-zero datum shift programmed while a
//!   plane is active is an error (feedopt reads shifts in the untilted system); `PLANE
//!   AXIAL`, `PROJECTED`, `POINTS`, cycles 8, 10, 11, 19, 26 are errors.
//! * **Cycles**: `CYCL DEF 200`, `201`, `202`, `203`, `207`, `209`, `241` define a drilling,
//!   reaming, boring or tapping cycle, `208` bore milling and `262` thread milling (helices
//!   whose radius needs the tool's diameter, [`super::Settings::tool_diameter`]).
//!   Its parameters `Q<n>=<value>` (spaces about `=` as posts write them, `Q208= MAX`; on the
//!   lines that follow a `~`, or as blocks of their own) are assigned when it is defined and
//!   read when it is called; a parameter that is not understood, or a word after the
//!   parameters that is none, is an error naming its own line. A feed parameter may be `MAX`
//!   (FMAX: rapid traverse) or `AUTO` (FAUTO: the `TOOL CALL`'s F), as the TNC 640 stores
//!   them ([`super::cycles`]). `CYCL CALL`, `M99` in a block (after its move) and `M89`
//!   (after every block that positions X or Y, until `M99` or a new `CYCL DEF`) call it at
//!   the current position; `CYCL CALL PAT` at every `PATTERN DEF POS1 (X Y Z)` point (Z adds
//!   to the surface Q203), rising first to Q203 + Z + max(Q200, Q204) and moving there at
//!   rapid; `CYCL CALL POS X Y Z` at that point alike. The moves: [`super::cycles::heidenhain_steps`].
//!   `CYCL DEF 9` is a dwell (`9.1 DWELL 1.5`: 1.5 s). Cycles active on definition that move
//!   nothing ([`super::cycles::HEIDENHAIN_DEFINITION_ONLY`]: 13 orientation, 14, 20 and 271
//!   contour data, 32 tolerance, the dynamics tuning cycles 332 TUNING and 392 ATC) are
//!   skipped: they are not the cycle a call runs, and their parameters (their own: 332's Q395
//!   is a tuning mode) are not assigned. The pattern cycles 220, 221 and 224 run the cycle defined
//!   before them when they are defined: an error. `247` (preset) is taken with a warning (the
//!   preset table is the control's), and an error if a later one names another preset. Other
//!   cycles may be defined (a warning); calling one is an error naming it.
//! * `BEGIN PGM … MM` (`INCH` is an error), `TOOL CALL n Z S… F…` (S and F remembered; a
//!   tool axis X or Y is an error), `BLK FORM`, `TOOL DEF`, `STOP` move nothing.
//! * `RND R…` and `CHF …` right after a straight feed move (`L`) round or chamfer the corner
//!   to the next move (the chamfer side length cut off each move; an F in the block is the
//!   corner's own feed), as G-code's `,R`/`,C` ([`super`]'s chamfers and roundings); after an
//!   arc or FMAX, before an arc or FMAX, or with no next move they are errors naming the line:
//!   post the contour with the arc or chamfer written out.

use super::dialect::{Action, Address, DialectSpec, Statement};
use super::expr::{self, Variables};
use super::lexer::{Item, Num, split_words};

/// Longest keyword, words (`FUNCTION RESET TCPM`).
const MAX_KEYWORD_WORDS: usize = 3;

/// `12 L X+0` → `L X+0`; `/12 L` → `/12 L` (the runner skips block-delete blocks first).
pub(super) fn strip_block_number(text: &str) -> &str {
    let t = text.trim_start();
    let digits = t.len() - t.trim_start_matches(|c: char| c.is_ascii_digit()).len();
    if digits == 0 {
        return t;
    }
    let rest = &t[digits..];
    if rest.is_empty() || rest.starts_with(char::is_whitespace) {
        rest.trim_start()
    } else {
        t
    }
}

/// A number as Klartext writes it: optional sign, digits with at most one decimal point or
/// comma.
fn number(text: &str) -> Option<f64> {
    let body = text.strip_prefix(['+', '-']).unwrap_or(text);
    let digits = body.chars().filter(char::is_ascii_digit).count();
    let points = body.chars().filter(|&c| c == '.' || c == ',').count();
    if digits == 0 || points > 1 || digits + points != body.len() {
        return None;
    }
    text.replace(',', ".")
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
}

/// A value: a number, or an expression over Q parameters (`+Q1`, `-Q5*2`).
pub(super) fn value(text: &str, vars: &Variables) -> Result<f64, String> {
    if let Some(v) = number(text) {
        return Ok(v);
    }
    if text.contains(',') && text.chars().any(|c| c.is_ascii_digit()) {
        return expr::eval(&comma_decimals(text), vars);
    }
    expr::eval(text, vars)
}

/// `1,5` → `1.5` where a comma stands between digits.
fn comma_decimals(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    chars
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let digit = |k: Option<&char>| k.is_some_and(char::is_ascii_digit);
            if c == ','
                && digit(i.checked_sub(1).and_then(|k| chars.get(k)))
                && digit(chars.get(i + 1))
            {
                '.'
            } else {
                c
            }
        })
        .collect()
}

/// The word a cycle's feed parameter may hold instead of a number, as the TNC 640 writes it
/// (`Q208=MAX`, `Q206=AUTO`) or as typed (`FMAX`, `FAUTO`): `MAX` or `AUTO`.
pub(super) fn feed_word(text: &str) -> Option<&'static str> {
    match text.trim().to_ascii_uppercase().as_str() {
        "MAX" | "FMAX" => Some("MAX"),
        "AUTO" | "FAUTO" => Some("AUTO"),
        _ => None,
    }
}

/// The mark that stands, in a `CYCL DEF` block joined from several lines, where a line ended
/// (`~`): so that a parameter's line can be named. A line break, which no line of the program
/// holds, so a `~` the program writes inside a line is not taken for it (the fuzz campaign's
/// `Q206=100 ~ M14` named a line past the file's end); [`split_words`] makes it a word of its
/// own.
const LINE_MARK: &str = "\n";

/// A block continued on the next line (this one ended in `~`): `first` and `next` as one
/// block. A `CYCL DEF` keeps a mark [`LINE_MARK`] where each line ended, read by
/// [`cycle_arguments`]; other blocks are joined with a space.
pub(super) fn join_continued(first: &str, next: &str) -> String {
    let first = first.trim_end();
    let first = first.strip_suffix('~').unwrap_or(first).trim_end();
    let body = strip_block_number(first);
    let cycle = body.len() >= 8 && body.is_char_boundary(8) && {
        let head = body[..8].to_ascii_uppercase();
        head == "CYCL DEF"
    };
    if cycle {
        format!("{first} {LINE_MARK} {}", next.trim())
    } else {
        format!("{first} {}", next.trim())
    }
}

/// One parameter of a `CYCL DEF`: `Q208= MAX` → name `Q208`, value `MAX`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct CycleParameter {
    /// Upper-cased (`Q208`).
    pub(super) name: String,
    /// As written after `=` (`+5`, `MAX`, `Q3`).
    pub(super) value: String,
    /// As written (`Q208= MAX`), for messages.
    pub(super) written: String,
    /// The line it is on, counted from the `CYCL DEF`'s (0).
    pub(super) line: usize,
}

/// The arguments of a `CYCL DEF` (after `CYCL DEF`): its other words (the number, the name,
/// `X+10` of cycle 7, `DWELL 1.5` of cycle 9) and its parameters `Q<n>=<value>` (spaces about
/// `=` allowed, as Fusion writes `Q208= MAX`). After the first parameter every word must be
/// one: another word is an error, with the line it is on (counted from the `CYCL DEF`'s).
pub(super) fn cycle_arguments(
    args: &str,
) -> Result<(Vec<String>, Vec<CycleParameter>), (usize, String)> {
    let mut words = Vec::new();
    let mut params: Vec<CycleParameter> = Vec::new();
    let mut line = 0;
    let all = split_words(args);
    let mut i = 0;
    while i < all.len() {
        let w = &all[i];
        i += 1;
        if w == LINE_MARK {
            line += 1;
            continue;
        }
        // `Q200=+5`, `Q208=` `MAX`, `Q208` `=MAX`, `Q208` `=` `MAX`.
        let (name, after) = match w.split_once('=') {
            Some((name, after)) => (name, Some(after)),
            None => (w.as_str(), None),
        };
        let next_is =
            |k: usize, f: &dyn Fn(&str) -> bool| all.get(k).is_some_and(|n| n != LINE_MARK && f(n));
        let is_param = expr::is_q_parameter(name)
            && (after.is_some() || next_is(i, &|n: &str| n.starts_with('=')));
        if !is_param {
            if let Some(p) = params.last() {
                return Err((
                    line,
                    format!(
                        "`{w}` after the parameter `{}`: a cycle's parameters are written \
                         `Q<n>=<value>`, and a word feedopt does not understand may change what \
                         the cycle does",
                        p.written
                    ),
                ));
            }
            words.push(w.clone());
            continue;
        }
        let mut written = w.clone();
        let mut value = match after {
            Some(a) => a.to_string(),
            None => {
                let eq = &all[i];
                i += 1;
                written.push(' ');
                written.push_str(eq);
                eq[1..].to_string()
            }
        };
        if value.is_empty() && next_is(i, &|_| true) {
            value = all[i].clone();
            written.push(' ');
            written.push_str(&value);
            i += 1;
        }
        if value.is_empty() {
            return Err((line, format!("`{written}`: the parameter has no value")));
        }
        params.push(CycleParameter {
            name: name.to_ascii_uppercase(),
            value,
            written,
            line,
        });
    }
    Ok((words, params))
}

/// `Q5 = expr` (spaces anywhere): the parameter and the expression, or `None`.
fn assignment(text: &str) -> Option<(String, &str)> {
    let (name, rest) = text.split_once('=')?;
    let name = name.trim();
    expr::is_q_parameter(name).then(|| (name.to_ascii_uppercase(), rest.trim()))
}

/// A keyword of the table that starts `words` (longest first): its length in words, text and
/// action.
fn keyword_at(spec: &DialectSpec, words: &[String]) -> Option<(usize, String, Action)> {
    for n in (1..=MAX_KEYWORD_WORDS.min(words.len())).rev() {
        let text = words[..n].join(" ").to_ascii_uppercase();
        if let Some(&(_, action)) = spec.keywords.iter().find(|(k, _)| *k == text) {
            return Some((n, text, action));
        }
    }
    None
}

/// Whether a keyword's action starts a block (a path function or statement) rather than
/// being a word inside one.
fn starts_block(action: Action) -> bool {
    matches!(
        action,
        Action::Motion(_) | Action::Path(_) | Action::Statement(_)
    )
}

/// A named word or letter of the table.
fn address(spec: &DialectSpec, name: &str) -> Option<Address> {
    let mut chars = name.chars();
    match (chars.next(), chars.next()) {
        (Some(c), None) => spec.letters.iter().find(|(l, _)| *l == c).map(|&(_, a)| a),
        _ => spec.named.iter().find(|(n, _)| *n == name).map(|&(_, a)| a),
    }
}

/// Reads one Klartext block (block number already removed or not) into items.
pub(super) fn lex(
    spec: &DialectSpec,
    block: &str,
    vars: &mut Variables,
) -> Result<Vec<Item>, String> {
    let text = strip_block_number(block).trim();
    let text = text.strip_suffix('~').unwrap_or(text).trim_end();
    if text.is_empty() || text.starts_with('*') {
        return Ok(Vec::new());
    }
    if let Some((name, expression)) = assignment(text) {
        // A cycle parameter on a line of its own (`Q208=MAX ;RETRACTION FEED RATE`).
        if let Some(word) = feed_word(expression) {
            vars.set_word(&name, word);
            return Ok(vec![Item::Skipped]);
        }
        let v = value(expression, vars).map_err(|e| format!("`{name} =`: {e}"))?;
        vars.set(&name, v);
        return Ok(vec![Item::Skipped]);
    }
    let mut words = split_words(text);
    // `FN0: Q1 = 25` (typed with the number against FN): `FN 0: Q1 = 25`.
    if words.first().is_some_and(|w| {
        w.len() > 2
            && w.is_char_boundary(2)
            && w[..2].eq_ignore_ascii_case("FN")
            && w[2..].starts_with(|c: char| c.is_ascii_digit())
    }) {
        let number = words[0][2..].to_string();
        words[0] = "FN".to_string();
        words.insert(1, number);
    }
    // `CYCL DEF9.1 …` (a post that writes the cycle number against DEF): `CYCL DEF 9.1 …`.
    if words.len() >= 2 && words[0].eq_ignore_ascii_case("CYCL") {
        let w = &words[1];
        if w.len() > 3
            && w.is_char_boundary(3)
            && w[..3].eq_ignore_ascii_case("DEF")
            && w[3..].starts_with(|c: char| c.is_ascii_digit())
        {
            let number = w[3..].to_string();
            words[1] = "DEF".to_string();
            words.insert(2, number);
        }
    }
    // `CP IPA+90 IZ-0.5 DR+FQ1` (hyperMILL's post for a DMU 100 P duoblock, round 28): the
    // next word joined to the direction. A direction is the sign alone, so a letter after
    // it can only start another word: `DR+ FQ1`.
    let mut k = 0;
    while k < words.len() {
        // Bytes, not `str` slices: a word may hold any character (an ASCII letter at byte 3
        // makes 3 a character boundary).
        let b = words[k].as_bytes();
        if b.len() > 3
            && b[..2].eq_ignore_ascii_case(b"DR")
            && matches!(b[2], b'+' | b'-')
            && b[3].is_ascii_alphabetic()
        {
            let rest = words[k][3..].to_string();
            words[k].truncate(3);
            words.insert(k + 1, rest);
        }
        k += 1;
    }
    let mut items = Vec::new();
    let mut i = 0;
    if let Some((n, key, action)) = keyword_at(spec, &words) {
        if let Action::Unsupported(message) = action {
            return Err(format!("{key}: {message}"));
        }
        if action == Action::Statement(Statement::Fn) {
            return fn_statement(&words[n..].join(" "), vars).map(|()| vec![Item::Skipped]);
        }
        let takes_rest = matches!(action, Action::Statement(_)) || key.contains(' ');
        if takes_rest {
            items.push(Item::Keyword {
                text: key,
                action,
                args: Some(words[n..].join(" ")),
            });
            return Ok(items);
        }
        items.push(Item::Keyword {
            text: key,
            action,
            args: None,
        });
        i = n;
    }
    let path = matches!(
        items.first(),
        Some(Item::Keyword { action, .. }) if starts_block(*action)
    );
    while i < words.len() {
        let word = words[i].to_ascii_uppercase();
        let next = words.get(i + 1).map(|w| w.to_ascii_uppercase());
        // Two-word keywords inside a block: `F MAX`, `F AUTO`, `MB MAX`.
        let pair = next.as_ref().map(|n| format!("{word} {n}"));
        let pair_key = match pair.as_deref() {
            Some("F MAX") => Some(("FMAX".to_string(), 2)),
            Some("F AUTO") => Some(("FAUTO".to_string(), 2)),
            Some("MB MAX") => Some(("MB MAX".to_string(), 2)),
            _ if word == "MBMAX" => Some(("MB MAX".to_string(), 1)),
            _ => None,
        };
        // `MB 50`: the retract distance as its own word.
        if word == "MB"
            && let Some(n) = next.as_deref()
            && n.starts_with(|c: char| c.is_ascii_digit() || matches!(c, '+' | '-' | '.' | 'Q'))
        {
            items.push(lex_word(
                spec,
                &format!("MB{}", words[i + 1]),
                &format!("MB{n}"),
                vars,
            )?);
            i += 2;
            continue;
        }
        let (key, used) = pair_key.unwrap_or((word.clone(), 1));
        if let Some(&(_, action)) = spec.keywords.iter().find(|(k, _)| *k == key) {
            if starts_block(action) {
                return Err(format!(
                    "`{}`: a path function or statement must start the block",
                    words[i]
                ));
            }
            if let Action::Unsupported(message) = action {
                return Err(format!("{key}: {message}"));
            }
            items.push(Item::Keyword {
                text: key,
                action,
                args: None,
            });
            i += used;
            continue;
        }
        // `L Z 25.000 FMAX` (an APT post's Klartext, aamorim1913/AptPostProcessor
        // `tests/parts-tools/boss/12.h`): a letter alone and then a number. The TNC writes
        // the value joined to its address, `Z+25.000` (its program format, as its editor
        // stores a block); feedopt does not guess that the number belongs to the letter.
        if word.len() == 1
            && word.chars().all(|c| c.is_ascii_alphabetic())
            && let Some(n) = next.as_deref()
            && n.starts_with(|c: char| c.is_ascii_digit() || matches!(c, '+' | '-' | '.'))
        {
            return Err(format!(
                "`{} {}`: the value stands apart from its address; a Klartext word is written \
                 joined, as the TNC stores it (`{}{}{}`): join them",
                words[i],
                words[i + 1],
                words[i],
                if n.starts_with(['+', '-']) { "" } else { "+" },
                words[i + 1]
            ));
        }
        items.push(lex_word(spec, &words[i], &word, vars)?);
        i += 1;
    }
    let moves = items.iter().any(|item| {
        matches!(
            item,
            Item::Word {
                address: Address::Axis(_)
                    | Address::IncrementalAxis(_)
                    | Address::PolarAngle(_)
                    | Address::PolarRadius(_)
                    | Address::ToolVector(_)
                    | Address::PlaneRotary(_),
                ..
            }
        )
    });
    if moves && !path {
        return Err(
            "axis words without a path function: start the block with L, LN, C, CR, CT, CP or \
             LP"
            .into(),
        );
    }
    Ok(items)
}

/// One word `NAME±value` (upper-cased in `upper`).
fn lex_word(
    spec: &DialectSpec,
    written: &str,
    upper: &str,
    vars: &mut Variables,
) -> Result<Item, String> {
    let alpha_len = upper.len()
        - upper
            .trim_start_matches(|c: char| c.is_ascii_alphabetic())
            .len();
    if alpha_len == 0 {
        return Err(format!("unexpected word `{written}`"));
    }
    // The longest known name, where a longer run of letters is a name and a Q parameter
    // (`FQ53`: F and Q53).
    let mut found = None;
    for k in (1..=alpha_len).rev() {
        let name = &upper[..k];
        if let Some(a) = address(spec, name)
            && (k == alpha_len || upper[k..].starts_with('Q'))
        {
            found = Some((name, a));
            break;
        }
    }
    let Some((name, address)) = found else {
        return Err(format!(
            "unknown word `{written}`: not a Klartext word feedopt knows (a word may move the \
             tool, so it is not skipped)"
        ));
    };
    let text = &upper[name.len()..];
    if let Address::Unsupported(message) = address {
        return Err(format!("`{written}`: {message}"));
    }
    if address == Address::ArcDirection {
        let v = match text {
            "+" => 1.0,
            "-" => -1.0,
            _ => return Err(format!("`{written}`: the direction is DR+ or DR-")),
        };
        return Ok(Item::Word {
            text: written.to_string(),
            address,
            num: Num {
                value: v,
                point: true,
            },
        });
    }
    if let Address::Axis(i @ 3..=5) = address {
        let q = ["Q120", "Q121", "Q122"][i - 3];
        let t = text.strip_prefix('+').unwrap_or(text);
        if t == q && !vars.is_set(q) {
            return Ok(Item::Word {
                text: written.to_string(),
                address: Address::PlaneRotary(i - 3),
                num: Num {
                    value: 0.0,
                    point: true,
                },
            });
        }
    }
    if text.is_empty() {
        return Err(format!("`{written}` has no value"));
    }
    let body = text.trim_start_matches(['+', '-']);
    if body.starts_with(|c: char| c.is_ascii_digit() || c == '.') && body.contains(['E', 'e']) {
        return Err(format!(
            "`{written}`: exponent notation is not part of Klartext; write the number in full"
        ));
    }
    let v = value(text, vars).map_err(|e| format!("`{written}`: {e}"))?;
    Ok(Item::Word {
        text: written.to_string(),
        address,
        num: Num {
            value: v,
            point: true,
        },
    })
}

/// `FN k: …` (the text after `FN`): assignments and arithmetic; `FN 9`–`FN 12` jumps never
/// reach here (the runner takes them).
fn fn_statement(text: &str, vars: &mut Variables) -> Result<(), String> {
    let (number, rest) = text
        .split_once(':')
        .ok_or_else(|| format!("`FN {text}`: expected `FN <number>: …`"))?;
    let number = number.trim();
    let k: u32 = number
        .parse()
        .map_err(|_| format!("`FN {number}`: not an FN function number"))?;
    let rest = rest.trim();
    match k {
        0..=5 => {}
        16 => return Ok(()), // F-PRINT: writes a file, moves nothing
        9..=12 => return Err(format!("FN {k}: a jump outside a program feedopt runs")),
        14 => {
            return Err(format!(
                "FN 14: the program raises an error here ({rest}); the control would stop"
            ));
        }
        18 => {
            return Err(
                "FN 18 (SYSREAD) reads the control's system data, which feedopt does not have"
                    .into(),
            );
        }
        _ => return Err(format!("FN {k} is not supported (FN 0–5, 9–12 and 16 are)")),
    }
    let Some((name, expression)) = assignment(rest) else {
        return Err(format!("`FN {k}: {rest}`: expected `Q<n> = …`"));
    };
    let upper = expression.to_ascii_uppercase();
    let v = match k {
        4 => {
            let (a, b) = upper
                .split_once("DIV")
                .ok_or_else(|| format!("`FN 4: {rest}`: expected `a DIV b`"))?;
            let (a, b) = (value(a.trim(), vars)?, value(b.trim(), vars)?);
            if b == 0.0 {
                return Err(format!("`FN 4: {rest}`: division by zero"));
            }
            a / b
        }
        5 => {
            let a = upper
                .trim()
                .strip_prefix("SQRT")
                .ok_or_else(|| format!("`FN 5: {rest}`: expected `SQRT a`"))?;
            let a = value(a.trim(), vars)?;
            if a < 0.0 {
                return Err(format!("`FN 5: {rest}`: the square root of {a}"));
            }
            a.sqrt()
        }
        // FN 0 assigns, FN 1–3 add, subtract, multiply: `+Q2 + +5` reads as an expression.
        _ => value(expression, vars).map_err(|e| format!("`FN {k}: {rest}`: {e}"))?,
    };
    if !v.is_finite() {
        return Err(format!("`FN {k}: {rest}` is not a finite number"));
    }
    vars.set(&name, v);
    Ok(())
}

/// A comparison of `FN 9`–`FN 12`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Compare {
    Equal,
    NotEqual,
    Greater,
    Less,
}

/// What a label block does; the runner ([`super::subprograms`]) carries it out.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum LabelOp {
    /// `LBL 1`, `LBL "NAME"`: a label (no effect when run through).
    Label(String),
    /// `LBL 0`: the end of a subprogram.
    End,
    /// `CALL LBL n [REP m]`.
    Call { name: String, repeats: Option<u64> },
    /// `FN 9: IF a EQU b GOTO LBL n` (and `FN 10`–`12`): jump when `a` compares to `b`.
    Jump {
        name: String,
        a: String,
        compare: Compare,
        b: String,
    },
}

/// A label name as written after `LBL`: a number (`5`, leading zeros dropped) or a quoted
/// name.
fn label_name(text: &str) -> Result<String, String> {
    let t = text.trim();
    if let Some(q) = t.strip_prefix('"') {
        let name = q
            .strip_suffix('"')
            .ok_or_else(|| format!("`LBL {t}`: unclosed `\"`"))?;
        if name.is_empty() {
            return Err("`LBL \"\"`: an empty label name".into());
        }
        return Ok(format!("\"{name}\""));
    }
    let n: u64 = t
        .parse()
        .map_err(|_| format!("`LBL {t}`: a label is a number or a quoted name"))?;
    Ok(n.to_string())
}

/// The label operation of a block (block number removed), if it is one.
pub(super) fn label_op(text: &str) -> Result<Option<LabelOp>, String> {
    let t = text.trim();
    let t = t.strip_suffix('~').unwrap_or(t).trim();
    // Most blocks are not label blocks: out before the copies and formats below (this runs
    // for every block, every pass of a loop).
    let head = t.as_bytes().get(..3).unwrap_or_default();
    if !(head.eq_ignore_ascii_case(b"LBL")
        || head.eq_ignore_ascii_case(b"CAL")
        || head.get(..2).is_some_and(|h| h.eq_ignore_ascii_case(b"FN")))
    {
        return Ok(None);
    }
    let upper = t.to_ascii_uppercase();
    if let Some(rest) = upper.strip_prefix("LBL")
        && (rest.starts_with([' ', '"']) || rest.is_empty())
    {
        let name = label_name(&t[3..])?;
        return Ok(Some(if name == "0" {
            LabelOp::End
        } else {
            LabelOp::Label(name)
        }));
    }
    if let Some(rest) = upper.strip_prefix("CALL LBL") {
        let rest_written = &t[t.len() - rest.len()..];
        let (name_part, reps) = match rest.find(" REP") {
            Some(k) => (&rest_written[..k], Some(rest[k + 4..].trim())),
            None => (rest_written, None),
        };
        let name = label_name(name_part)?;
        if name == "0" {
            return Err(
                "CALL LBL 0: label 0 marks the end of a subprogram and cannot be called".into(),
            );
        }
        let repeats = match reps {
            None => None,
            Some(r) => {
                let count = r.split('/').next().unwrap_or("").trim();
                let n: u64 = count.parse().map_err(|_| {
                    format!("`CALL LBL {name} REP {r}`: the repeat count is a whole number")
                })?;
                Some(n)
            }
        };
        return Ok(Some(LabelOp::Call { name, repeats }));
    }
    let compact: String = upper.split_whitespace().collect::<Vec<_>>().join(" ");
    for (k, compare) in [
        ("9", Compare::Equal),
        ("10", Compare::NotEqual),
        ("11", Compare::Greater),
        ("12", Compare::Less),
    ] {
        let Some(rest) = compact
            .strip_prefix(&format!("FN {k}:"))
            .or_else(|| compact.strip_prefix(&format!("FN{k}:")))
        else {
            continue;
        };
        let op = match compare {
            Compare::Equal => " EQU ",
            Compare::NotEqual => " NE ",
            Compare::Greater => " GT ",
            Compare::Less => " LT ",
        };
        let bad = || format!("`FN {k}:{rest}`: expected `IF a{op}b GOTO LBL n`");
        let body = rest.trim().strip_prefix("IF ").ok_or_else(bad)?;
        let (cond, _) = body.split_once(" GOTO LBL ").ok_or_else(bad)?;
        let (a, b) = cond.split_once(op).ok_or_else(bad)?;
        // The label as written (a quoted name keeps its case).
        let at = upper.rfind("LBL").ok_or_else(bad)?;
        return Ok(Some(LabelOp::Jump {
            name: label_name(&t[at + 3..])?,
            a: a.trim().to_string(),
            compare,
            b: b.trim().to_string(),
        }));
    }
    Ok(None)
}

/// Whether `a` compares to `b` (values of an `FN 9`–`FN 12` condition).
pub(super) fn holds(compare: Compare, a: f64, b: f64) -> bool {
    match compare {
        Compare::Equal => a == b,
        Compare::NotEqual => a != b,
        Compare::Greater => a > b,
        Compare::Less => a < b,
    }
}

/// The words `NAME±value` of a statement's arguments, upper-cased, with the values as
/// written (`SPA+45` → `("SPA", "+45")`); words without a value (`TURN`) have `""`.
pub(super) fn named_words(args: &str) -> Vec<(String, String)> {
    split_words(args)
        .into_iter()
        .map(|w| {
            let upper = w.to_ascii_uppercase();
            let k = upper.len()
                - upper
                    .trim_start_matches(|c: char| c.is_ascii_alphabetic())
                    .len();
            (upper[..k].to_string(), upper[k..].to_string())
        })
        .collect()
}

/// The statement's arguments split into words (outside parentheses and quotes).
pub(super) fn words(args: &str) -> Vec<String> {
    split_words(args)
}
