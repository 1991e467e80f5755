//! Lexing: comments, blocks and words, resolved through a dialect table; variables and
//! expressions ([`super::expr`]) are evaluated here, left to right, as the block is read.

use super::dialect::{Action, Address, DialectSpec, Semicolon, Spaces, Subprograms};
use super::expr::{self, Variables};

/// Removes comments and splits a line into block texts (more than one only where `;` ends a
/// block). Double-quoted strings are kept whole. `( … )` comments may nest (Haas writes
/// `((NAME))`).
pub(super) fn split_blocks(
    spec: &DialectSpec,
    line: &str,
) -> std::result::Result<Vec<String>, String> {
    // A Klartext structure comment (`12 * - 1/2" DRILL`) is all comment, quotes included.
    if spec.spaces == Spaces::Klartext
        && super::klartext::strip_block_number(line)
            .trim_start()
            .starts_with('*')
    {
        return Ok(vec![String::new()]);
    }
    let mut blocks = Vec::new();
    let mut current = String::new();
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        match c {
            '(' if spec.paren_comments => {
                let mut depth = 1usize;
                for c in chars.by_ref() {
                    match c {
                        '(' => depth += 1,
                        ')' => depth -= 1,
                        _ => {}
                    }
                    if depth == 0 {
                        break;
                    }
                }
                if depth > 0 {
                    return Err("unclosed `(` comment".to_string());
                }
            }
            ';' => match spec.semicolon {
                Semicolon::Comment => break,
                Semicolon::EndOfBlock => blocks.push(std::mem::take(&mut current)),
            },
            '"' => {
                current.push(c);
                let mut closed = false;
                for q in chars.by_ref() {
                    current.push(q);
                    if q == '"' {
                        closed = true;
                        break;
                    }
                }
                if !closed {
                    return Err("unclosed `\"` string".to_string());
                }
            }
            _ => current.push(c),
        }
    }
    blocks.push(current);
    Ok(blocks)
}

/// A number as written after a letter or `=`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Num {
    pub(super) value: f64,
    /// Written with a decimal point, or computed (matters under
    /// [`DialectSpec::integer_increments`]).
    pub(super) point: bool,
}

/// One word of a block, resolved through the dialect table.
#[derive(Debug, Clone)]
pub(super) enum Item {
    /// A letter or named word with a number.
    Word {
        text: String,
        address: Address,
        num: Num,
    },
    /// A keyword the table knows, with its `( … )` arguments as written (without the
    /// parentheses).
    Keyword {
        text: String,
        action: Action,
        args: Option<String>,
    },
    /// A known word whose value is not a number and does not matter.
    Skipped,
    /// Sinumerik `T="MILL"`: a tool selected by name (as written between the quotes, upper
    /// case).
    ToolName(String),
    /// A word the dialect does not know; `call`: written with an argument list, `NAME(…)`
    /// (Sinumerik: a call of a cycle or subprogram, which may move the tool).
    Unknown { text: String, call: bool },
}

/// Parses the number after a letter or `=`: optional sign, digits with at most one decimal
/// point, at least one digit.
fn number(text: &str) -> Option<Num> {
    let body = text.strip_prefix(['+', '-']).unwrap_or(text);
    let digits = body.chars().filter(char::is_ascii_digit).count();
    let points = body.chars().filter(|&c| c == '.').count();
    if digits == 0 || points > 1 || digits + points != body.len() {
        return None;
    }
    let value: f64 = text.parse().ok()?;
    value.is_finite().then_some(Num {
        value,
        point: points == 1,
    })
}

/// A number, or an expression evaluated with `vars`.
fn value(text: &str, vars: &Variables) -> std::result::Result<Num, String> {
    if let Some(n) = number(text) {
        return Ok(n);
    }
    expr::eval(text, vars).map(|value| Num { value, point: true })
}

fn letter_address(spec: &DialectSpec, letter: char) -> Option<Address> {
    spec.letters
        .iter()
        .find(|(l, _)| *l == letter)
        .map(|&(_, a)| a)
}

/// The end of a value starting at `i`: a sign, then a number, a `#` parameter or a `[ … ]`
/// group, then (for parameters and groups) more operators and operands up to the next
/// letter outside brackets. `assignment`: the right side of `#n=`, an expression from its
/// start (Fanuc macro B: `#4=63./2.`, `#5=SIN[30.]*2.`), whose functions are read with it.
fn scan_value(chars: &[char], mut i: usize, assignment: bool) -> usize {
    let mut depth = 0usize;
    let mut expression = assignment;
    while i < chars.len() {
        if assignment && depth == 0 && chars[i].is_ascii_alphabetic() {
            // A function name followed by `[`: part of the expression.
            let end = (i..chars.len())
                .find(|&k| !chars[k].is_ascii_alphabetic())
                .unwrap_or(chars.len());
            let name: String = chars[i..end].iter().collect();
            if chars.get(end) == Some(&'[') && expr::is_function(&name) {
                i = end;
                continue;
            }
        }
        let c = chars[i];
        match c {
            '[' => {
                depth += 1;
                expression = true;
            }
            ']' => depth = depth.saturating_sub(1),
            // `N10#1=…`: a `#` right after a number starts the next word (an assignment).
            '#' if depth == 0
                && i > 0
                && (chars[i - 1].is_ascii_digit() || chars[i - 1] == '.') =>
            {
                break;
            }
            '#' => expression = true,
            '<' if expression => {
                // LinuxCNC #<name>
                while i < chars.len() && chars[i] != '>' {
                    i += 1;
                }
            }
            _ if depth > 0 => {}
            c if c.is_ascii_digit() || c == '.' || c == '+' || c == '-' => {}
            '*' | '/' if expression => {}
            _ => break,
        }
        i += 1;
    }
    i.min(chars.len())
}

/// Marks, in a block whose spaces are removed, a space that stood between a number and an `E`
/// word (`G187 P1 E0.05`): without it the two read as exponent notation (`P1E0.05`), which is
/// an error. [`lex_letters`] skips it.
const WORD_BREAK: char = '\u{1f}';

/// `block` without its spaces (a dialect where they mean nothing: `G1  X  16.339` is
/// `G1X16.339`), with a [`WORD_BREAK`] where a space separated a number from an `E` word
/// (outside `[ … ]`).
fn compact(block: &str) -> String {
    let chars: Vec<char> = block.chars().collect();
    let mut out = String::with_capacity(block.len());
    let (mut depth, mut space) = (0i32, false);
    for (k, &c) in chars.iter().enumerate() {
        if c.is_whitespace() {
            space = true;
            continue;
        }
        let e_word = matches!(c, 'E' | 'e')
            && chars
                .get(k + 1)
                .is_some_and(|n| n.is_ascii_digit() || matches!(n, '+' | '-' | '.'));
        if space && depth == 0 && e_word && out.ends_with(|p: char| p.is_ascii_digit() || p == '.')
        {
            out.push(WORD_BREAK);
        }
        space = false;
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            _ => {}
        }
        out.push(c);
    }
    out
}

/// Reads `LNUMBER LNUMBER …` (single-letter words, no spaces), `#n=expr` assignments and
/// expression values into `items`.
fn lex_letters(
    spec: &DialectSpec,
    text: &str,
    vars: &mut Variables,
    items: &mut Vec<Item>,
) -> std::result::Result<(), String> {
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        if chars[i] == WORD_BREAK {
            i += 1;
            continue;
        }
        let c = chars[i];
        if c == '#' {
            // An assignment `#100=…` (Fanuc macro B, LinuxCNC parameters).
            let name_end = scan_name(&chars, i + 1);
            let name: String = chars[i..name_end].iter().collect();
            let Some(key) = expr::hash_name(&name) else {
                return Err(format!("malformed parameter `{name}`"));
            };
            if chars.get(name_end) != Some(&'=') {
                return Err(format!(
                    "`{name}` without `=`: a parameter must be assigned"
                ));
            }
            let end = scan_value(&chars, name_end + 1, true);
            let text: String = chars[name_end + 1..end].iter().collect();
            let v = expr::eval(&text, vars).map_err(|e| format!("`{name}=`: {e}"))?;
            vars.set(&key, v);
            items.push(Item::Skipped);
            i = end;
            continue;
        }
        if c == ',' && spec.comma_corners {
            // Fanuc's chamfering and corner R: `G1 X50 ,C3` / `G1 X50 ,R5` (Haas too).
            let letter = chars.get(i + 1).map(char::to_ascii_uppercase);
            let word = match letter {
                Some('R') => super::dialect::CornerWord::Round,
                Some('C') => super::dialect::CornerWord::ChamferLeg,
                _ => {
                    return Err(
                        "`,` not followed by C or R: `,C` (a chamfer) and `,R` (a corner \
                                rounding) are the only words written with a comma"
                            .to_string(),
                    );
                }
            };
            let letter = letter.unwrap_or('R');
            let end = scan_value(&chars, i + 2, false);
            let text_value: String = chars[i + 2..end].iter().collect();
            if text_value.is_empty() {
                return Err(format!("`,{letter}` has no number"));
            }
            let num = if text_value.contains(['#', '[']) {
                value(&text_value, vars).map_err(|e| format!("`,{letter}{text_value}`: {e}"))?
            } else {
                number(&text_value)
                    .ok_or_else(|| format!("malformed number `{text_value}` after `,{letter}`"))?
            };
            items.push(Item::Word {
                text: format!(",{letter}{text_value}"),
                address: Address::Corner(word),
                num,
            });
            i = end;
            continue;
        }
        if !c.is_ascii_alphabetic() {
            return Err(match c {
                '[' | ']' => "an expression `[ … ]` must follow a letter or `=`".to_string(),
                // Fanuc's chamfer and corner rounding in a dialect that has none.
                ',' if chars
                    .get(i + 1)
                    .is_some_and(|n| matches!(n.to_ascii_uppercase(), 'C' | 'R')) =>
                {
                    format!(
                        "`,{}`: {} has no comma words; `,C` (a chamfer) and `,R` (a corner \
                         rounding) are Fanuc's and Haas': if this is their program, read it \
                         with --dialect fanuc",
                        chars[i + 1].to_ascii_uppercase(),
                        spec.name
                    )
                }
                // Block delete `/` is read at the start of a block (`super::interp`); a second
                // one or one further in is not G-code (MillMaster Pro programs comment with
                // `//`).
                '/' => "`/` inside a block: block delete `/` (or `/1` … `/9`) is read only at \
                        the start of a block, and `//` does not start a comment in G-code: \
                        write comments in `( … )` or after `;`"
                    .to_string(),
                // ISO code's program number (`:1234` for `O1234`) is read where it heads a
                // Fanuc program (`super::program_header`); anywhere else it is not taken for
                // one, since a program number there would start a subprogram.
                ':' => {
                    let digits: String = chars[i + 1..]
                        .iter()
                        .take_while(|c| c.is_ascii_digit())
                        .collect();
                    format!(
                        "`:{digits}`: a `:` word inside the program; feedopt reads `:` only as \
                         the program number heading a Fanuc program (ISO code's `:1234` for \
                         `O1234`). If it numbers this block (a post's mark at a tool change), \
                         write `N{digits}`"
                    )
                }
                // Siemens' older controls (Sinumerik 3, 8, 810/820 M, 850/880) program their
                // macro functions, jumps and parameter arithmetic as `@` codes with `K`/`R`
                // operands (`@430 K1 K1 K0 K1525`, `@714`), a language the 840D replaced.
                '@' => {
                    let digits: String = chars[i + 1..]
                        .iter()
                        .take_while(|c| c.is_ascii_digit())
                        .collect();
                    format!(
                        "`@{digits}`: an `@` code of the older Siemens languages (Sinumerik 3, \
                         8, 810/820, 850/880: jumps, parameter arithmetic and machine functions), \
                         which feedopt does not read: it reads the Sinumerik 840D language \
                         (`--dialect sinumerik`). Post the program for an 840D, or as plain \
                         G0/G1/G2/G3 moves"
                    )
                }
                // A line that does not start as a block is text, not G-code: NX writes its
                // posted programs into an "Information listing" whose header is a rule of
                // `=` and `Name : value` lines.
                _ if chars[..i].iter().all(|c| c.is_whitespace()) => format!(
                    "unexpected character `{c}` at the start of a block: a block starts with an \
                     address letter (N, G, X, …), a comment `( … )` or `;`, or `/`; a line of \
                     text (a listing's header, as NX's \"Information listing\" writes with \
                     `====`) is not G-code: remove it"
                ),
                _ => format!("unexpected character `{c}`"),
            });
        }
        let letter = c.to_ascii_uppercase();
        let address = letter_address(spec, letter);
        let end = scan_value(&chars, i + 1, false);
        let text_value: String = chars[i + 1..end].iter().collect();
        if letter == 'O' && text_value.is_empty() {
            return Err(match spec.subprograms {
                Subprograms::OWordSub => "`O` without a number or name: an O-word is written \
                                          `o100 …` or `o<name> …` (a post's placeholder such \
                                          as `O ENTER …` needs the program number filled in)"
                    .to_string(),
                _ => "`O` without a program number: a program is headed `O1234` (a post's \
                      placeholder such as `O ENTER …` needs the program number filled in)"
                    .to_string(),
            });
        }
        if let Some(Address::Unsupported(message)) = address {
            // An O word after other words (NX's DeVlieg post: `T00O00`) is no O-word statement,
            // whose `o…` starts its block: say so rather than naming control flow.
            let before: String = chars[..i].iter().collect::<String>().trim().to_string();
            // A Fanuc macro call's arguments are letters A–Z (`G65 P9001 A.125 V10100.`:
            // V is #22, no axis): name the call, which is what feedopt does not read.
            if let Some(call) = macro_call(&before) {
                return Err(format!(
                    "{call}: a macro call (its letters are the macro's arguments:                      `{letter}{text_value}` is no axis word here); macro calls (G65/G66) are                      not supported: post the program with the macro's moves written out"
                ));
            }
            let numbered = before.strip_prefix(['N', 'n']).is_some_and(|rest| {
                rest.trim().chars().all(|c| c.is_ascii_digit()) && !rest.trim().is_empty()
            });
            if letter == 'O' && !before.is_empty() && !numbered {
                return Err(format!(
                    "`{letter}{text_value}` after `{before}` in the same block: an O word starts \
                     its block (an O-word statement `o100 sub|call|if|…`, or a program number on \
                     a line of its own), so this one is neither: remove it or give it its own \
                     line"
                ));
            }
            return Err(format!("`{letter}{text_value}`: {message}"));
        }
        if end < chars.len()
            && matches!(chars[end], 'E' | 'e')
            && chars
                .get(end + 1)
                .is_some_and(|c| c.is_ascii_digit() || *c == '+' || *c == '-')
            && !text_value.is_empty()
        {
            let mut stop = end + 1;
            while stop < chars.len()
                && (chars[stop].is_ascii_digit() || "+-.".contains(chars[stop]))
            {
                stop += 1;
            }
            let written: String = chars[i..stop].iter().collect();
            return Err(format!(
                "`{written}`: exponent notation is not part of G-code; write the number in full"
            ));
        }
        if text_value.is_empty() {
            return Err(format!("`{letter}` has no number"));
        }
        let num = if text_value.contains(['#', '[']) {
            value(&text_value, vars).map_err(|e| format!("`{letter}{text_value}`: {e}"))?
        } else {
            number(&text_value)
                .ok_or_else(|| format!("malformed number `{text_value}` after `{letter}`"))?
        };
        let text = format!("{letter}{text_value}");
        items.push(match address {
            Some(address) => Item::Word { text, address, num },
            None => Item::Unknown { text, call: false },
        });
        i = end;
    }
    Ok(())
}

/// The `G65`/`G66` word (a Fanuc macro call) among the compacted words `before`, if any.
fn macro_call(before: &str) -> Option<String> {
    let upper = before.to_ascii_uppercase();
    let chars: Vec<char> = upper.chars().collect();
    (0..chars.len()).find_map(|k| {
        if chars[k] != 'G' || (k > 0 && chars[k - 1].is_ascii_digit()) {
            return None;
        }
        let digits: String = chars[k + 1..]
            .iter()
            .take_while(|c| c.is_ascii_digit() || **c == '.')
            .collect();
        let n: f64 = digits.parse().ok()?;
        (n == 65.0 || n == 66.0).then(|| format!("G{digits}"))
    })
}

/// End of a parameter name after `#`: digits, `<name>` or `[ … ]`.
fn scan_name(chars: &[char], mut i: usize) -> usize {
    if chars.get(i) == Some(&'<') {
        while i < chars.len() && chars[i] != '>' {
            i += 1;
        }
        return (i + 1).min(chars.len());
    }
    while i < chars.len() && chars[i].is_ascii_digit() {
        i += 1;
    }
    i
}

/// Splits a Sinumerik-style (or Klartext) block at spaces outside `( )` and quotes; a line
/// break (only a joined Klartext cycle definition holds one) is a word `"\n"` of its own.
pub(super) fn split_words(text: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut current = String::new();
    let mut depth = 0usize;
    let mut quoted = false;
    for c in text.chars() {
        if c == '\n' {
            // A line break joined into a block (a Klartext `CYCL DEF` continued on `~` lines,
            // `super::klartext::join_continued`): a word of its own, and a new line's start.
            if !current.is_empty() {
                words.push(std::mem::take(&mut current));
            }
            words.push("\n".to_string());
            (depth, quoted) = (0, false);
            continue;
        }
        match c {
            '"' => quoted = !quoted,
            '(' if !quoted => depth += 1,
            ')' if !quoted => depth = depth.saturating_sub(1),
            _ => {}
        }
        if c.is_whitespace() && depth == 0 && !quoted {
            if !current.is_empty() {
                words.push(std::mem::take(&mut current));
            }
        } else {
            current.push(c);
        }
    }
    if !current.is_empty() {
        words.push(current);
    }
    words
}

/// Words split at blanks that Siemens allows inside a statement, joined again: after an
/// address letter (`X 100` is `X100`), around `=` (`R1 = 100`, `X= 10`) and between the terms
/// of a value (`R1 = R2 + 3`: a word that starts with an operator, or follows one, continues
/// the value before it), and between a name and its argument list (`CYCLE81 (10,0,2,-5)`). A
/// lone letter followed by a number, an `=` word, operators and a `( … )` are never words of
/// their own, so nothing that was read before reads differently.
fn join_blanks(words: Vec<String>) -> Vec<String> {
    let op = |c: char| matches!(c, '+' | '-' | '*' | '/');
    let mut out: Vec<String> = Vec::with_capacity(words.len());
    // Whether the last word is an assignment whose value may continue.
    let mut in_value = false;
    for w in words {
        let joined = match out.last_mut() {
            // `NAME` `=…`, or `NAME=` `value`.
            Some(last) if w.starts_with('=') && !last.contains('=') => {
                last.push_str(&w);
                true
            }
            Some(last) if last.ends_with('=') => {
                last.push_str(&w);
                true
            }
            // `X` `100`: a lone letter and a number.
            Some(last)
                if last.len() == 1
                    && last.chars().all(|c| c.is_ascii_alphabetic())
                    && w.starts_with(|c: char| {
                        c.is_ascii_digit() || matches!(c, '.' | '-' | '+')
                    }) =>
            {
                last.push_str(&w);
                true
            }
            // `CYCLE81` `(10,0,2,-5)`: a name and its argument list (NX's Huron post).
            Some(last) if w.starts_with('(') && is_identifier(last) => {
                last.push_str(&w);
                true
            }
            // `R1=R2` `+` `3`: the value goes on.
            Some(last) if in_value && (w.starts_with(op) || last.ends_with(op)) => {
                last.push_str(&w);
                true
            }
            _ => false,
        };
        if !joined {
            out.push(w);
        }
        in_value = out
            .last()
            .and_then(|l| l.split_once('='))
            .is_some_and(|(name, _)| !name.contains('('));
    }
    out
}

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Reads one block's words through the dialect table.
pub(super) fn lex(
    spec: &DialectSpec,
    block: &str,
    vars: &mut Variables,
) -> std::result::Result<Vec<Item>, String> {
    let mut items = Vec::new();
    match spec.spaces {
        Spaces::Klartext => return super::klartext::lex(spec, block, vars),
        Spaces::Ignored => {
            lex_letters(spec, &compact(block), vars, &mut items)?;
        }
        Spaces::Separate => {
            let words = split_words(block);
            // `N10 DEF REAL _A, _B=2`: declarations.
            let first = words.iter().position(|w| {
                !(w.len() > 1
                    && w.starts_with(['N', 'n'])
                    && w[1..].chars().all(|c| c.is_ascii_digit()))
            });
            if let Some(k) = first
                && words[k].eq_ignore_ascii_case("DEF")
            {
                return declare(&words[k + 1..], vars).map(|()| Vec::new());
            }
            for word in join_blanks(words) {
                lex_separate_word(spec, &word, vars, &mut items)?;
            }
        }
    }
    Ok(items)
}

/// `DEF REAL _A, _B=2, _C`: declares the names (0, or the value given).
fn declare(words: &[String], vars: &mut Variables) -> std::result::Result<(), String> {
    let Some((kind, rest)) = words.split_first() else {
        return Err("DEF without a type and a name".into());
    };
    let kind = kind.to_ascii_uppercase();
    if !matches!(
        kind.as_str(),
        "REAL" | "INT" | "BOOL" | "CHAR" | "STRING" | "AXIS" | "FRAME"
    ) && !kind.starts_with("STRING[")
    {
        return Err(format!("DEF {kind}: unknown variable type"));
    }
    let text = rest.join(" ");
    for part in text.split(',') {
        let part = part.trim();
        if part.is_empty() {
            continue;
        }
        let (name, init) = match part.split_once('=') {
            Some((n, v)) => (n.trim(), Some(v.trim())),
            None => (part, None),
        };
        let name = name.split('[').next().unwrap_or(name);
        if !is_identifier(name) {
            return Err(format!("DEF: `{name}` is not a variable name"));
        }
        vars.declare(name);
        if let Some(init) = init
            && matches!(kind.as_str(), "REAL" | "INT")
        {
            let v = expr::eval(init, vars).map_err(|e| format!("DEF {name}: {e}"))?;
            vars.set(name, v);
        }
    }
    Ok(())
}

/// One space-separated word: `NAME=value` (an address or an assignment), a keyword (two or
/// more letters, optional `( … )`), or letter words (`G1`, `X10`, `G1X10`, `M202(0.0059)`).
fn lex_separate_word(
    spec: &DialectSpec,
    word: &str,
    vars: &mut Variables,
    items: &mut Vec<Item>,
) -> std::result::Result<(), String> {
    let upper = word.to_ascii_uppercase();
    if let Some((name, text)) = upper.split_once('=')
        && !name.contains('(')
    {
        if !is_identifier(name) {
            return Err(format!("malformed word `{word}`"));
        }
        let address = if name.len() == 1 {
            letter_address(spec, name.chars().next().unwrap_or(' '))
        } else {
            spec.named.iter().find(|(n, _)| *n == name).map(|&(_, a)| a)
        };
        let Some(address) = address else {
            if vars.assignable(name) {
                let v = expr::eval(text, vars).map_err(|e| format!("`{name}=`: {e}"))?;
                vars.set(name, v);
                items.push(Item::Skipped);
            } else {
                items.push(Item::Unknown {
                    text: format!("{name}="),
                    call: false,
                });
            }
            return Ok(());
        };
        match address {
            Address::Unsupported(message) => return Err(format!("`{name}=`: {message}")),
            Address::Ignored
                if name == "T"
                    && text.len() >= 2
                    && text.starts_with('"')
                    && text.ends_with('"') =>
            {
                items.push(Item::ToolName(text[1..text.len() - 1].to_string()))
            }
            Address::Ignored if value(text, vars).is_err() => items.push(Item::Skipped),
            _ => {
                if text.is_empty() {
                    return Err(format!("`{name}=` has no number"));
                }
                if let (Address::ArcCentre(i), Some(inner)) = (
                    address,
                    text.strip_prefix("AC(")
                        .or_else(|| text.strip_prefix("IC("))
                        .and_then(|t| t.strip_suffix(')')),
                ) {
                    let num = value(inner, vars).map_err(|e| format!("`{name}={text}`: {e}"))?;
                    items.push(Item::Word {
                        text: format!("{name}={text}"),
                        address: Address::ArcCentreAs(i, text.starts_with("AC(")),
                        num,
                    });
                    return Ok(());
                }
                // `X=AC(…)`, `X=IC(…)`: absolute or incremental for this word; a rotary axis's
                // `C=DC(…)`, `C=ACP(…)`, `C=ACN(…)`: absolute the shorter way, or turning
                // positive or negative (NX's 840D posts write `C=DC(0.0)`).
                if let Address::Axis(i) = address {
                    let modes: [(&str, Option<i8>); 5] = [
                        ("AC(", None),
                        ("IC(", None),
                        ("DC(", Some(0)),
                        ("ACP(", Some(1)),
                        ("ACN(", Some(-1)),
                    ];
                    for (prefix, way) in modes {
                        let Some(inner) =
                            text.strip_prefix(prefix).and_then(|t| t.strip_suffix(')'))
                        else {
                            continue;
                        };
                        let num =
                            value(inner, vars).map_err(|e| format!("`{name}={text}`: {e}"))?;
                        let address = match (prefix, way) {
                            ("AC(", _) => Address::AbsoluteAxis(i),
                            ("IC(", _) => Address::IncrementalAxis(i),
                            (_, Some(way)) if i >= 3 => Address::RotaryTo(i, way),
                            _ => {
                                return Err(format!(
                                    "`{name}={text}`: {} positions a rotary axis (the shorter \
                                     way, or turning one way); {name} is a linear axis",
                                    &prefix[..prefix.len() - 1]
                                ));
                            }
                        };
                        items.push(Item::Word {
                            text: format!("{name}={text}"),
                            address,
                            num,
                        });
                        return Ok(());
                    }
                }
                if text.starts_with("IC(") || text.starts_with("AC(") {
                    return Err(format!(
                        "`{name}={text}`: IC( )/AC( ) (incremental or absolute for one word) is \
                         read on axis words and arc centres, closed by `)`, not here; program \
                         G90/G91"
                    ));
                }
                let num = value(text, vars).map_err(|e| format!("`{name}={text}`: {e}"))?;
                items.push(Item::Word {
                    text: format!("{name}={text}"),
                    address,
                    num,
                });
            }
        }
        return Ok(());
    }
    let mut chars = upper.chars();
    let first_two_letters = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    if first_two_letters {
        let name_end = upper
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(upper.len());
        let (name, rest) = upper.split_at(name_end);
        if !(rest.is_empty() || (rest.starts_with('(') && rest.ends_with(')'))) {
            return Err(format!("malformed word `{word}`"));
        }
        let args = rest
            .strip_prefix('(')
            .and_then(|r| r.strip_suffix(')'))
            .map(str::to_string);
        match spec.keywords.iter().find(|(k, _)| *k == name) {
            Some(&(_, Action::Unsupported(message))) => return Err(format!("{name}: {message}")),
            Some(&(_, action)) => items.push(Item::Keyword {
                text: name.to_string(),
                action,
                args,
            }),
            None => items.push(Item::Unknown {
                text: name.to_string(),
                call: args.is_some(),
            }),
        }
        return Ok(());
    }
    // `M202(0.0059)`: an M function with an argument (the argument does not move the tool).
    if upper.starts_with('M')
        && let Some(open) = upper.find('(')
        && upper.ends_with(')')
    {
        return lex_letters(spec, &upper[..open], vars, items);
    }
    lex_letters(spec, &upper, vars, items)
}
