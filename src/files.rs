//! Reading input files safely: a bounded size, UTF-8 errors that name the line, and text from
//! the input made safe to echo in a one-line message.
//!
//! Every reader that takes a whole file into memory goes through [`read_bounded`], so a file
//! that never ends (`/dev/zero`, a runaway pipe) or one far larger than any toolpath is refused
//! with a clear message instead of being read until memory runs out.

use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// The largest toolpath (APT, G-code, joint CSV) feedopt reads: 64 MiB. The largest real
/// programs in `../shared` are under 0.3 MB; a 64 MiB program would already have more CL
/// points than the station limit allows.
pub const MAX_TOOLPATH_BYTES: u64 = 64 << 20;

/// The largest machine file feedopt reads: 1 MiB (a machine file is a few hundred bytes).
pub const MAX_MACHINE_FILE_BYTES: u64 = 1 << 20;

/// Reads at most `max` bytes of `path`; a longer file (or a device that never ends) is an
/// error naming the file and the limit. `what` names the kind of file in the message.
pub fn read_bounded(path: &Path, max: u64, what: &str) -> Result<Vec<u8>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if meta.is_dir() {
        return Err(Error::Usage(format!(
            "{}: is a directory, not a {what}",
            path.display()
        )));
    }
    let too_large = || {
        Error::Usage(format!(
            "{}: larger than {} MiB, the limit for a {what}: is it the right file? (split a \
             longer program into parts)",
            path.display(),
            max >> 20
        ))
    };
    // A regular file's length is known up front; a device or pipe is read up to the limit.
    if meta.is_file() && meta.len() > max {
        return Err(too_large());
    }
    let mut bytes = Vec::with_capacity(if meta.is_file() {
        meta.len() as usize
    } else {
        0
    });
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > max {
        return Err(too_large());
    }
    Ok(bytes)
}

/// The file's bytes as UTF-8 text; where they are not, an error naming the file, the line of
/// the first bad byte and what to do.
pub fn utf8(path: &Path, bytes: Vec<u8>) -> Result<String> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
        let column = 1 + at
            - bytes[..at]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1);
        Error::parse(
            path,
            line,
            format!(
                "byte {} (column {column}, 0x{:02x}) is not UTF-8 text: save the file as UTF-8 \
                 (plain ASCII is fine)",
                at + 1,
                bytes[at]
            ),
        )
    })
}

/// `text` with every control character (carriage return, newline, tab, escape, …) and every
/// bidirectional override written as an escape (`\r`, `\n`, `\t`, `\u{1b}`, `\u{202e}`), so
/// that text from an input file cannot break a one-line message, drive the terminal or reorder
/// what is shown.
pub fn escape_control(text: &str) -> String {
    let unsafe_char =
        |c: char| c.is_control() || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    if !text.chars().any(unsafe_char) {
        return text.to_string();
    }
    text.chars()
        .map(|c| {
            if unsafe_char(c) {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bad_byte_is_found_on_its_line() {
        let e = utf8(
            Path::new("m.json"),
            b"{\n  \"name\": \"ab\xe9\"\n}".to_vec(),
        )
        .unwrap_err();
        let text = e.to_string();
        assert!(
            text.starts_with("m.json:2: byte 16 (column 14, 0xe9)"),
            "{text}"
        );
        assert!(text.contains("UTF-8"), "{text}");
    }

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(escape_control("a\rb\n\t\u{1b}[2J"), "a\\rb\\n\\t\\u{1b}[2J");
        assert_eq!(escape_control("x\u{202e}y"), "x\\u{202e}y");
        assert_eq!(escape_control("X1 Y° ok"), "X1 Y° ok");
    }

    #[cfg(unix)]
    #[test]
    fn an_endless_device_is_refused_at_the_limit() {
        let e = read_bounded(Path::new("/dev/zero"), 1 << 20, "toolpath").unwrap_err();
        assert!(e.to_string().contains("larger than 1 MiB"), "{e}");
    }
}
