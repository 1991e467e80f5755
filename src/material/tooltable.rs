//! Tool tables: what the program's tool numbers and names (`T5 M6`, `T="MILL_D10"`,
//! `TOOL CALL 5`) stand for.
//!
//! Two formats, told apart by the file name (`.json`: JSON, anything else: LinuxCNC):
//!
//! * **LinuxCNC `.tbl`**, one tool per line: `T1 P1 D6.35 Z+12.5 ;comment`. Words are a letter
//!   and a number separated by blanks: `T` tool number (required), `P` pocket, `D` diameter,
//!   the offsets `X Y Z A B C U V W`, the lathe fields `I J Q`; `;` starts a comment, blank
//!   lines and comment lines are skipped. Only `T` and `D` matter here; the format has no
//!   corner radius, flute length or flutes, so those come from the machine file's `tool`, the
//!   options, or a JSON table. Values are mm.
//! * **JSON**: an object whose keys are tool numbers or names and whose values are tools,
//!   `{"1": {"diameter": 6, "corner_radius": 0, "flute_length": 20, "flutes": 3},
//!   "MILL_D10": {"diameter": 10}}`, the fields of the machine file's `tool` (each optional but
//!   the diameter). The machine file's `tools` section takes the same object inline.
//!
//! Errors name the file and line (or field) and what to write instead.

use std::path::{Path, PathBuf};

use super::ToolSpec;
use crate::error::{Error, Result};
use crate::toolpath::ToolSelect;

/// The most tools a table may hold.
pub const MAX_TOOLS: usize = 100_000;

/// How a table entry is found: by number or by name (names match case-insensitively).
#[derive(Debug, Clone, PartialEq)]
pub enum ToolKey {
    /// `T5`, `TOOL CALL 5`.
    Number(u32),
    /// `T="MILL_D10"`, `TOOL CALL "MILL_D10"` (stored upper case).
    Name(String),
}

/// One tool of a table.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Its number or name.
    pub key: ToolKey,
    /// Where it is written: the line (`.tbl`), 0 in JSON.
    pub line: usize,
    /// What the table says about it (a `.tbl` gives the diameter only).
    pub tool: ToolSpec,
}

/// A tool table read from a file or the machine file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ToolTable {
    /// The file it came from (the machine file for an inline `tools` section).
    pub source: PathBuf,
    /// The tools in the order written.
    pub entries: Vec<Entry>,
}

impl ToolTable {
    /// The entry a program's selection names, if the table has it (`None` too for a
    /// `CUTTER/`, which needs no table).
    pub fn lookup(&self, select: &ToolSelect) -> Option<&Entry> {
        let key = match select {
            ToolSelect::Number(n) => ToolKey::Number(*n),
            ToolSelect::Name(s) => match s.parse::<u32>() {
                // Sinumerik `T="5"` is tool 5 where the table numbers its tools.
                Ok(n) if !self.entries.iter().any(|e| e.key == key_of(s)) => ToolKey::Number(n),
                _ => key_of(s),
            },
            ToolSelect::Cutter { .. } => return None,
        };
        self.entries.iter().find(|e| e.key == key)
    }
}

/// The key a name stands for: a number if it is one, else the name in upper case.
fn key_of(s: &str) -> ToolKey {
    match s.trim().parse::<u32>() {
        Ok(n) => ToolKey::Number(n),
        Err(_) => ToolKey::Name(s.trim().to_ascii_uppercase()),
    }
}

/// Reads a tool table file (`.json`: JSON, else LinuxCNC `.tbl`; module doc), bounded like a
/// machine file.
pub fn read(path: &Path) -> Result<ToolTable> {
    let bytes =
        crate::files::read_bounded(path, crate::files::MAX_MACHINE_FILE_BYTES, "tool table")?;
    let text = crate::files::utf8(path, bytes)?;
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if json {
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| Error::Parse {
            file: path.to_path_buf(),
            line: e.line(),
            message: format!("invalid JSON: {e}"),
        })?;
        from_json(path, "", &value)
    } else {
        parse_tbl(path, &text)
    }
}

/// Parses LinuxCNC tool table text (`source` names it in errors).
pub fn parse_tbl(source: &Path, text: &str) -> Result<ToolTable> {
    let mut table = ToolTable {
        source: source.to_path_buf(),
        entries: Vec::new(),
    };
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let err = |m: String| Error::parse(source, line, m);
        let code = raw.split(';').next().unwrap_or("").trim();
        if code.is_empty() {
            continue;
        }
        let mut number: Option<u32> = None;
        let mut diameter: Option<f64> = None;
        for word in code.split_whitespace() {
            let mut chars = word.chars();
            let letter = chars.next().unwrap_or(' ').to_ascii_uppercase();
            let rest = chars.as_str();
            let value = rest.parse::<f64>().ok().filter(|v| v.is_finite());
            if !"TPDXYZABCUVWIJQ".contains(letter) || !letter.is_ascii_alphabetic() {
                return Err(err(format!(
                    "`{word}`: not a LinuxCNC tool table word (T P D X Y Z A B C U V W I J Q; \
                     `;` starts a comment)"
                )));
            }
            let Some(value) = value else {
                return Err(err(format!("`{word}`: {letter} needs a number")));
            };
            match letter {
                'T' => {
                    if number.is_some() {
                        return Err(err("two T words on one line: one tool per line".into()));
                    }
                    if !(value >= 0.0 && value.fract() == 0.0 && value <= u32::MAX as f64) {
                        return Err(err(format!(
                            "`{word}`: a tool number is a whole number from 0"
                        )));
                    }
                    number = Some(value as u32);
                }
                'D' => {
                    if !(0.0..=super::tool::MAX_TOOL_DIAMETER_MM).contains(&value) {
                        return Err(err(format!(
                            "`{word}`: the diameter must lie between 0 and {} mm",
                            super::tool::MAX_TOOL_DIAMETER_MM
                        )));
                    }
                    // LinuxCNC writes D0 (or nothing) for a tool whose diameter it does not use.
                    diameter = (value > 0.0).then_some(value);
                }
                _ => {}
            }
        }
        let Some(n) = number else {
            return Err(err(
                "a tool line without its T word (e.g. `T1 P1 D6 ;6 mm end mill`)".into(),
            ));
        };
        push(
            &mut table,
            Entry {
                key: ToolKey::Number(n),
                line,
                tool: ToolSpec {
                    diameter,
                    ..ToolSpec::default()
                },
            },
            err,
        )?;
    }
    Ok(table)
}

/// Adds `e` unless its key is taken or the table is full.
fn push(table: &mut ToolTable, e: Entry, err: impl Fn(String) -> Error) -> Result<()> {
    if let Some(first) = table.entries.iter().find(|x| x.key == e.key) {
        return Err(err(format!(
            "tool {} is listed twice{}",
            match &e.key {
                ToolKey::Number(n) => n.to_string(),
                ToolKey::Name(s) => format!("\"{s}\""),
            },
            if first.line > 0 {
                format!(" (first at line {})", first.line)
            } else {
                String::new()
            }
        )));
    }
    if table.entries.len() >= MAX_TOOLS {
        return Err(err(format!("more than {MAX_TOOLS} tools")));
    }
    table.entries.push(e);
    Ok(())
}

/// A JSON tool table (module doc); `field` is the prefix of the field names in errors
/// (`tools` for the machine file's section, empty for a file of its own).
pub fn from_json(source: &Path, field: &str, value: &serde_json::Value) -> Result<ToolTable> {
    let name = |k: &str| {
        if field.is_empty() {
            k.to_string()
        } else {
            format!("{field}.{k}")
        }
    };
    let obj = value.as_object().ok_or_else(|| {
        Error::field(
            source,
            if field.is_empty() {
                "(top level)"
            } else {
                field
            },
            "expected a JSON object of tools, e.g. {\"1\": {\"diameter\": 6, \"flutes\": 3}}",
        )
    })?;
    let mut table = ToolTable {
        source: source.to_path_buf(),
        entries: Vec::new(),
    };
    for (k, v) in obj {
        let f = name(k);
        if k.trim().is_empty() {
            return Err(Error::field(source, &f, "a tool needs a number or a name"));
        }
        let tool = super::tool_spec_from_json(source, &f, v)?;
        if tool.diameter.is_none() {
            return Err(Error::field(
                source,
                format!("{f}.diameter"),
                "missing: every tool of a table needs its diameter",
            ));
        }
        push(
            &mut table,
            Entry {
                key: key_of(k),
                line: 0,
                tool,
            },
            |m| Error::field(source, &f, m),
        )?;
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linuxcnc_lines() {
        let t = "; kop\nT1 P1 D+3.000 Z+0.000 ; x\n\nT40  P40  D+6.000  Z-1.200\n\
                 T99999 P99999 Z+0.100000 ;big tool number\nt7 p7 d10\n";
        let tab = parse_tbl(Path::new("a.tbl"), t).unwrap();
        let d: Vec<(ToolKey, usize, Option<f64>)> = tab
            .entries
            .iter()
            .map(|e| (e.key.clone(), e.line, e.tool.diameter))
            .collect();
        assert_eq!(
            d,
            vec![
                (ToolKey::Number(1), 2, Some(3.0)),
                (ToolKey::Number(40), 4, Some(6.0)),
                (ToolKey::Number(99999), 5, None),
                (ToolKey::Number(7), 6, Some(10.0)),
            ]
        );
        assert_eq!(tab.lookup(&ToolSelect::Number(40)).map(|e| e.line), Some(4));
        assert!(tab.lookup(&ToolSelect::Number(2)).is_none());
    }

    #[test]
    fn linuxcnc_errors_name_the_line() {
        for (text, line, what) in [
            ("T1 P1 D6\nT2 P2 R3\n", 2, "`R3`"),
            ("T1 P1 D6\n\nT2 P2 Dx\n", 3, "needs a number"),
            ("T1 P1 D6\nP2 D3\n", 2, "without its T word"),
            ("T1 D6\nT1 D8\n", 2, "listed twice (first at line 1)"),
            ("T1.5 D6\n", 1, "whole number"),
            ("T1 D-6\n", 1, "diameter"),
        ] {
            let e = parse_tbl(Path::new("t.tbl"), text).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("t.tbl:{line}:")) && e.contains(what),
                "{text:?}: {e}"
            );
        }
    }

    #[test]
    fn json_tables() {
        let v: serde_json::Value = serde_json::from_str(
            r#"{"1": {"diameter": 6, "corner_radius": 0.5, "flutes": 3},
                "mill_d10": {"diameter": 10, "flute_length": 25}}"#,
        )
        .unwrap();
        let tab = from_json(Path::new("m.json"), "tools", &v).unwrap();
        let e = tab.lookup(&ToolSelect::Number(1)).unwrap();
        assert_eq!(
            (e.tool.diameter, e.tool.corner_radius, e.tool.flutes),
            (Some(6.0), Some(0.5), Some(3))
        );
        let e = tab.lookup(&ToolSelect::Name("MILL_D10".into())).unwrap();
        assert_eq!(e.tool.flute_length, Some(25.0));
        let bad: serde_json::Value = serde_json::from_str(r#"{"3": {"flutes": 2}}"#).unwrap();
        let e = from_json(Path::new("m.json"), "tools", &bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("tools.3.diameter"), "{e}");
        let bad: serde_json::Value =
            serde_json::from_str(r#"{"3": {"diameter": 2, "nose": 1}}"#).unwrap();
        let e = from_json(Path::new("m.json"), "tools", &bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("tools.3.nose"), "{e}");
    }
}
