//! Lexing: comments, blocks and words, resolved through a dialect table.

use super::dialect::{Action, Address, DialectSpec, Semicolon, Spaces};

// ---------------------------------------------------------------------------------------------
// Lexing
// ---------------------------------------------------------------------------------------------

/// Removes comments and splits a line into block texts (more than one only where `;` ends a
/// block). Double-quoted strings are kept whole.
pub(super) fn split_blocks(
    spec: &DialectSpec,
    line: &str,
) -> std::result::Result<Vec<String>, String> {
    let mut blocks = Vec::new();
    let mut current = String::new();
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        match c {
            '(' if spec.paren_comments => {
                if !chars.by_ref().any(|c| c == ')') {
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
    /// Written with a decimal point (matters under [`DialectSpec::integer_increments`]).
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
    /// A keyword the table knows.
    Keyword { text: String, action: Action },
    /// A known word whose value is not a number and does not matter (Sinumerik `T="MILL"`).
    Skipped,
    /// A word the dialect does not know.
    Unknown { text: String },
}

/// Parses the number after a letter or `=`: optional sign, digits with at most one decimal
/// point, at least one digit (no exponents: `E` is a word letter in G-code).
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

fn letter_address(spec: &DialectSpec, letter: char) -> Option<Address> {
    spec.letters
        .iter()
        .find(|(l, _)| *l == letter)
        .map(|&(_, a)| a)
}

const EXPRESSIONS: &str = "parameters and expressions (`#`, `[ … ]`) are not supported";

/// Reads `LNUMBER LNUMBER …` (single-letter words, no spaces) into `items`.
fn lex_letters(
    spec: &DialectSpec,
    text: &str,
    items: &mut Vec<Item>,
) -> std::result::Result<(), String> {
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if !c.is_ascii_alphabetic() {
            return Err(match c {
                '#' | '[' | ']' => EXPRESSIONS.to_string(),
                _ => format!("unexpected character `{c}`"),
            });
        }
        let letter = c.to_ascii_uppercase();
        let address = letter_address(spec, letter);
        if let Some(Address::Unsupported(message)) = address {
            return Err(format!("`{letter}` word: {message}"));
        }
        let start = i + 1;
        let mut end = start;
        while end < chars.len() && (chars[end].is_ascii_digit() || "+-.".contains(chars[end])) {
            end += 1;
        }
        let value: String = chars[start..end].iter().collect();
        if end < chars.len() && matches!(chars[end], '#' | '[') {
            return Err(format!("`{letter}` word: {EXPRESSIONS}"));
        }
        let num = if value.is_empty() {
            return Err(format!("`{letter}` has no number"));
        } else {
            number(&value).ok_or_else(|| format!("malformed number `{value}` after `{letter}`"))?
        };
        let text = format!("{letter}{value}");
        items.push(match address {
            Some(address) => Item::Word { text, address, num },
            None => Item::Unknown { text },
        });
        i = end;
    }
    Ok(())
}

/// Splits a Sinumerik-style block at spaces outside `( )` and quotes.
fn split_words(text: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut current = String::new();
    let mut depth = 0usize;
    let mut quoted = false;
    for c in text.chars() {
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

fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Reads one block's words through the dialect table.
pub(super) fn lex(spec: &DialectSpec, block: &str) -> std::result::Result<Vec<Item>, String> {
    let mut items = Vec::new();
    match spec.spaces {
        Spaces::Ignored => {
            let compact: String = block.chars().filter(|c| !c.is_whitespace()).collect();
            lex_letters(spec, &compact, &mut items)?;
        }
        Spaces::Separate => {
            for word in split_words(block) {
                lex_separate_word(spec, &word, &mut items)?;
            }
        }
    }
    Ok(items)
}

/// One space-separated word: `NAME=value`, a keyword (two or more letters, optional `( … )`),
/// or letter words (`G1`, `X10`, `G1X10`).
fn lex_separate_word(
    spec: &DialectSpec,
    word: &str,
    items: &mut Vec<Item>,
) -> std::result::Result<(), String> {
    let upper = word.to_ascii_uppercase();
    if let Some((name, value)) = upper.split_once('=')
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
            items.push(Item::Unknown {
                text: format!("{name}="),
            });
            return Ok(());
        };
        match address {
            Address::Unsupported(message) => return Err(format!("`{name}=`: {message}")),
            Address::Ignored if number(value).is_none() => items.push(Item::Skipped),
            _ => {
                let num = if value.is_empty() {
                    return Err(format!("`{name}=` has no number"));
                } else {
                    number(value).ok_or_else(|| {
                        format!(
                            "malformed number `{value}` after `{name}=` (expressions are not \
                             supported)"
                        )
                    })?
                };
                items.push(Item::Word {
                    text: format!("{name}={value}"),
                    address,
                    num,
                });
            }
        }
        return Ok(());
    }
    let mut chars = upper.chars();
    let first_two_letters = chars.next().is_some_and(|c| c.is_ascii_alphabetic())
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
        match spec.keywords.iter().find(|(k, _)| *k == name) {
            Some(&(_, Action::Unsupported(message))) => return Err(format!("{name}: {message}")),
            Some(&(_, action)) => items.push(Item::Keyword {
                text: name.to_string(),
                action,
            }),
            None => items.push(Item::Unknown {
                text: name.to_string(),
            }),
        }
        return Ok(());
    }
    lex_letters(spec, &upper, items)
}
