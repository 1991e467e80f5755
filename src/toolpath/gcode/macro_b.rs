//! Fanuc custom macro B control flow (the subprogram runner, [`super::subprograms`], runs it):
//!
//! * `WHILE [condition] DO m` … `END m`: the blocks between run while the condition holds; a
//!   false condition goes on after `END m`. `DO m` without `WHILE` loops until a `GOTO` leaves.
//!   The loop number m names the pair (`END m` closes the nearest `DO m` before it); nested
//!   loops take different numbers, as on the control.
//! * `IF [condition] GOTO n` jumps to the block numbered `N n` in the same (sub)program when
//!   the condition holds; `GOTO n` always does (`n` may be `#1` or `[#1+10]`).
//! * `IF [condition] THEN statement` runs the statement (`#1=5.`) when the condition holds.
//!
//! A condition compares two expressions with `EQ NE GT GE LT LE` and joins comparisons with
//! `AND`, `OR` and `XOR` (`[#1 GT 0] AND [#2 LT 5]`), `AND` binding closer. Every block a loop
//! runs counts against [`super::subprograms::MAX_EXPANDED_BLOCKS`], so a loop that never ends
//! is an error naming its line; one whose variables have not changed since its last pass is
//! an error at once (it would run the same pass for ever).

use super::expr::{self, Variables};

/// A macro statement that steers the program.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Statement {
    /// `WHILE [condition] DO m`.
    While { condition: String, id: u32 },
    /// `DO m` without a condition.
    Do { id: u32 },
    /// `END m`.
    End { id: u32 },
    /// `IF [condition] GOTO n`.
    IfGoto { condition: String, target: String },
    /// `IF [condition] THEN statement`.
    IfThen { condition: String, then: String },
    /// `GOTO n`.
    Goto { target: String },
}

/// `text` without blanks, upper-cased, without a block delete mark or block number.
fn body(text: &str) -> String {
    let compact: String = text
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_uppercase();
    let rest = compact.strip_prefix('/').unwrap_or(&compact);
    let rest = match rest.strip_prefix('N') {
        Some(r) if r.starts_with(|c: char| c.is_ascii_digit()) => {
            r.trim_start_matches(|c: char| c.is_ascii_digit())
        }
        _ => rest,
    };
    rest.to_string()
}

/// The block number `N n` a block starts with (after a block delete mark).
pub(super) fn sequence_number(text: &str) -> Option<u64> {
    let compact: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    let rest = compact.strip_prefix('/').unwrap_or(&compact);
    let rest = rest.strip_prefix(['N', 'n'])?;
    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// The end (exclusive) of the `[ … ]` group opening at `chars[0]`.
fn group_end(chars: &[char]) -> Option<usize> {
    let mut depth = 0usize;
    for (k, &c) in chars.iter().enumerate() {
        match c {
            '[' => depth += 1,
            ']' => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(k + 1);
                }
            }
            _ => {}
        }
    }
    None
}

/// A loop number after `DO` / `END`.
fn loop_id(word: &str, digits: &str) -> Result<u32, String> {
    // `WHILE [#1 GT #2] DO1 #1=#1-#3`: a statement after the loop number in the same block.
    // A Fanuc reads one macro statement in a block; which of them the loop would run is not
    // for feedopt to guess.
    let number: String = digits.chars().take_while(char::is_ascii_digit).collect();
    if !number.is_empty() && number.len() < digits.len() {
        let rest = &digits[number.len()..];
        return Err(format!(
            "`{word}{number}` is followed by `{rest}` in the same block: a Fanuc reads one \
             macro statement in a block (`WHILE [...] DO{number}`, `END{number}` alone); put \
             what follows it on lines of its own, one statement a line (after the \
             `{word}{number}` line to run them in the loop)"
        ));
    }
    if digits.is_empty() || !digits.chars().all(|c| c.is_ascii_digit()) {
        return Err(format!(
            "`{word}{digits}`: {word} takes a loop number (`{word} 1`)"
        ));
    }
    digits
        .parse()
        .map_err(|_| format!("`{word}{digits}`: loop number too large"))
}

/// The macro statement `text` is, if it is one (`Err`: one, malformed).
pub(super) fn statement(text: &str) -> Option<Result<Statement, String>> {
    let b = body(text);
    if let Some(rest) = b.strip_prefix("WHILE") {
        return Some(
            condition_then(rest, "WHILE").and_then(|(condition, after)| {
                match after.strip_prefix("DO") {
                    Some(d) => Ok(Statement::While {
                        condition,
                        id: loop_id("DO", d)?,
                    }),
                    None => Err(format!(
                        "`WHILE [{condition}]{after}`: WHILE takes `DO m` after its condition"
                    )),
                }
            }),
        );
    }
    if b.starts_with("IF[") {
        return Some(condition_then(&b[2..], "IF").and_then(|(condition, after)| {
            if let Some(target) = after.strip_prefix("GOTO") {
                if target.is_empty() {
                    return Err(format!("`IF [{condition}] GOTO`: GOTO takes a block number"));
                }
                Ok(Statement::IfGoto {
                    condition,
                    target: target.to_string(),
                })
            } else if let Some(then) = after.strip_prefix("THEN") {
                if then.is_empty() {
                    return Err(format!("`IF [{condition}] THEN`: THEN takes a statement"));
                }
                Ok(Statement::IfThen {
                    condition,
                    then: then.to_string(),
                })
            } else {
                Err(format!(
                    "`IF [{condition}]{after}`: IF takes `GOTO n` or `THEN statement` after its \
                     condition"
                ))
            }
        }));
    }
    if let Some(target) = b.strip_prefix("GOTO") {
        return Some(if target.is_empty() {
            Err("GOTO takes a block number (`GOTO 100`)".to_string())
        } else {
            Ok(Statement::Goto {
                target: target.to_string(),
            })
        });
    }
    if let Some(d) = b.strip_prefix("END")
        && (d.is_empty() || d.starts_with(|c: char| c.is_ascii_digit()))
    {
        return Some(loop_id("END", d).map(|id| Statement::End { id }));
    }
    if let Some(d) = b.strip_prefix("DO")
        && (d.is_empty() || d.starts_with(|c: char| c.is_ascii_digit()))
    {
        return Some(loop_id("DO", d).map(|id| Statement::Do { id }));
    }
    None
}

/// `[condition]` at the start of `rest` (after `word`), and what follows it.
fn condition_then(rest: &str, word: &str) -> Result<(String, String), String> {
    let chars: Vec<char> = rest.chars().collect();
    if chars.first() != Some(&'[') {
        return Err(format!(
            "`{word}{rest}`: {word} takes a condition in brackets, `{word} [#1 LT 10]`"
        ));
    }
    let end = group_end(&chars).ok_or_else(|| format!("`{word}{rest}`: missing `]`"))?;
    let condition: String = chars[1..end - 1].iter().collect();
    let after: String = chars[end..].iter().collect();
    Ok((condition, after))
}

/// The block number a `GOTO` names: a whole number 1…99999 (an expression is evaluated).
pub(super) fn target(text: &str, vars: &Variables) -> Result<u64, String> {
    let n = expr::eval(text, vars).map_err(|e| format!("`GOTO {text}`: {e}"))?;
    if n.fract() != 0.0 || !(1.0..=99999.0).contains(&n) {
        return Err(format!(
            "`GOTO {text}`: {n} is not a block number (1 to 99999)"
        ));
    }
    Ok(n as u64)
}

/// The operators of a condition, longest first where one is a prefix of another.
const OPERATORS: [&str; 9] = ["XOR", "AND", "OR", "EQ", "NE", "GE", "GT", "LE", "LT"];

/// A condition's pieces at the top level (outside brackets): operands and operators.
enum Piece {
    Operand(String),
    Operator(&'static str),
}

fn pieces(chars: &[char]) -> Result<Vec<Piece>, String> {
    let mut out = Vec::new();
    let mut current = String::new();
    let mut depth = 0usize;
    let mut k = 0;
    while k < chars.len() {
        let c = chars[k];
        match c {
            '[' => depth += 1,
            ']' => depth = depth.saturating_sub(1),
            _ => {}
        }
        if depth == 0 && c.is_ascii_alphabetic() {
            let end = (k..chars.len())
                .find(|&j| !chars[j].is_ascii_alphabetic())
                .unwrap_or(chars.len());
            let run: String = chars[k..end].iter().collect();
            if chars.get(end) == Some(&'[') && expr::is_function(&run) {
                current.push_str(&run);
                k = end;
                continue;
            }
            let Some(op) = OPERATORS.iter().find(|op| run.starts_with(**op)) else {
                return Err(format!(
                    "`{run}` is not an operator of a condition (EQ NE GT GE LT LE AND OR XOR)"
                ));
            };
            out.push(Piece::Operand(std::mem::take(&mut current)));
            out.push(Piece::Operator(op));
            // The rest of the run starts the next operand (a function: `LTSIN[30]`).
            k += op.len();
            continue;
        }
        current.push(c);
        k += 1;
    }
    out.push(Piece::Operand(current));
    Ok(out)
}

/// Evaluates a condition (the text inside `IF [ … ]` / `WHILE [ … ]`) with `vars`.
pub(super) fn condition(text: &str, vars: &Variables) -> Result<bool, String> {
    let chars: Vec<char> = text.chars().filter(|c| !c.is_whitespace()).collect();
    evaluate(&chars, vars, 0)
}

fn evaluate(chars: &[char], vars: &Variables, depth: usize) -> Result<bool, String> {
    let text: String = chars.iter().collect();
    if depth > expr::MAX_DEPTH {
        return Err(format!("condition `{text}` nested too deep"));
    }
    let pieces = pieces(chars)?;
    // OR / XOR, then AND, then one comparison.
    for level in [&["OR", "XOR"][..], &["AND"][..]] {
        let splits: Vec<usize> = pieces
            .iter()
            .enumerate()
            .filter_map(|(k, p)| match p {
                Piece::Operator(op) if level.contains(op) => Some(k),
                _ => None,
            })
            .collect();
        if splits.is_empty() {
            continue;
        }
        // Operand texts between the splits, rebuilt from the pieces.
        let mut parts: Vec<(Option<&str>, String)> = Vec::new();
        let mut op = None;
        let mut current = String::new();
        for (k, p) in pieces.iter().enumerate() {
            match p {
                Piece::Operator(o) if splits.contains(&k) => {
                    parts.push((op, std::mem::take(&mut current)));
                    op = Some(*o);
                }
                Piece::Operator(o) => current.push_str(o),
                Piece::Operand(s) => current.push_str(s),
            }
        }
        parts.push((op, current));
        let mut value = false;
        for (op, part) in parts {
            let chars: Vec<char> = part.chars().collect();
            let v = evaluate(&chars, vars, depth + 1)?;
            value = match op {
                None => v,
                Some("OR") => value || v,
                Some("XOR") => value != v,
                _ => value && v,
            };
        }
        return Ok(value);
    }
    match pieces.as_slice() {
        [Piece::Operand(a), Piece::Operator(op), Piece::Operand(b)] => {
            let side =
                |s: &str| expr::eval(s, vars).map_err(|e| format!("condition `{text}`: {e}"));
            let (a, b) = (side(a)?, side(b)?);
            Ok(match *op {
                "EQ" => a == b,
                "NE" => a != b,
                "GT" => a > b,
                "GE" => a >= b,
                "LT" => a < b,
                _ => a <= b,
            })
        }
        [Piece::Operand(only)]
            if only.starts_with('[') && group_end(chars) == Some(chars.len()) =>
        {
            evaluate(&chars[1..chars.len() - 1], vars, depth + 1)
        }
        _ => Err(format!(
            "`{text}` is not a condition: compare two values with EQ NE GT GE LT or LE"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vars() -> Variables {
        let mut v = Variables::default();
        v.set("#1", 2.0);
        v.set("#2", 5.0);
        v
    }

    #[test]
    fn conditions() {
        let v = vars();
        let c = |t: &str| condition(t, &v).unwrap();
        assert!(c("#1LT3."));
        assert!(c("#1 LT #2"));
        assert!(!c("#1 GT #2"));
        assert!(c("#1 GE 2") && c("#1 LE 2") && c("#1 EQ 2") && !c("#1 NE 2"));
        assert!(c("[#1 GT 0] AND [#2 LT 6]"));
        assert!(!c("[#1 GT 0] AND [#2 LT 5]"));
        assert!(c("[#1 GT 3] OR [#2 EQ 5]"));
        assert!(!c("[#1 GT 0] XOR [#2 EQ 5]"));
        assert!(c("[#1 + 3] EQ #2"));
        assert!(c("#1 LT SIN[90.] * 3"));
        assert!(c("[[#1 LT 3]]"));
        assert!(condition("#1 FOO 3", &v).is_err());
        assert!(condition("#1", &v).is_err());
        assert!(condition("#9 LT 3", &v).is_err());
    }

    #[test]
    fn statements() {
        assert_eq!(
            statement("WHILE [#1 LT 3.] DO1"),
            Some(Ok(Statement::While {
                condition: "#1LT3.".into(),
                id: 1
            }))
        );
        assert_eq!(statement("N20 END 1"), Some(Ok(Statement::End { id: 1 })));
        assert_eq!(statement("DO2"), Some(Ok(Statement::Do { id: 2 })));
        assert_eq!(
            statement("IF [#1 LT 3.] THEN #1=5."),
            Some(Ok(Statement::IfThen {
                condition: "#1LT3.".into(),
                then: "#1=5.".into()
            }))
        );
        assert_eq!(
            statement("if[#1eq0]goto100"),
            Some(Ok(Statement::IfGoto {
                condition: "#1EQ0".into(),
                target: "100".into()
            }))
        );
        assert_eq!(
            statement("GOTO #5"),
            Some(Ok(Statement::Goto {
                target: "#5".into()
            }))
        );
        assert!(matches!(statement("WHILE #1 LT 3 DO1"), Some(Err(_))));
        // A shop's `WHILE [...] DO1 #1=#1-#3 IF [...] THEN #1=#2` on one line: named, with
        // what to do, instead of "DO takes a loop number".
        let Some(Err(e)) = statement("WHILE [ #1 GT #2 ] DO1 #1= #1 - #3") else {
            panic!("a statement after DO1 must be an error")
        };
        assert!(e.contains("`DO1` is followed by `#1=#1-#3`"), "{e}");
        assert!(
            e.contains("on lines of its own, one statement a line"),
            "{e}"
        );
        let Some(Err(e)) = statement("END1 G0 X5.") else {
            panic!("a word after END1 must be an error")
        };
        assert!(e.contains("`END1` is followed by `G0X5.`"), "{e}");
        assert!(matches!(statement("IF [#1 LT 3]"), Some(Err(_))));
        assert!(matches!(statement("END"), Some(Err(_))));
        assert_eq!(statement("G1 X10. F100."), None);
        assert_eq!(statement("D01"), None);
        assert_eq!(sequence_number("N100 G1 X1"), Some(100));
        assert_eq!(sequence_number("/N0020"), Some(20));
        assert_eq!(sequence_number("G1"), None);
    }
}
