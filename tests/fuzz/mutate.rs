//! Deterministic mutations of an input, blind ones (bytes, lines, numbers) and ones that know
//! the input's structure (words of a G-code dialect, APT records, JSON keys, CSV columns), so
//! that mutated programs reach the readers' deeper paths instead of failing at the first token.

/// A small deterministic PRNG (SplitMix64): no dependency, the same cases on every machine.
pub struct Rng(u64);

impl Rng {
    /// A generator whose stream depends only on `seed`.
    pub fn new(seed: u64) -> Rng {
        Rng(seed ^ 0x9e37_79b9_7f4a_7c15)
    }

    /// The next 64 random bits.
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (0 when n is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    /// One of `items` (not empty).
    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    /// True once in `n` times.
    pub fn one_in(&mut self, n: usize) -> bool {
        self.below(n) == 0
    }
}

/// A stable 64-bit hash of a string (FNV-1a), to derive a target's stream of cases.
pub fn hash(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Numbers that break naive readers: overflow, underflow, signed zero, not-a-number words.
pub const EXTREMES: &[&str] = &[
    "1e308",
    "-1e308",
    "1e309",
    "1e-308",
    "1e-300",
    "4.9e-324",
    "0",
    "-0",
    "-1",
    "1e12",
    "1e6",
    "999999999999999999999",
    "NaN",
    "inf",
    "-inf",
    "0x10",
    "1e",
    "--1",
    ".",
    "1.2.3",
    "",
];

/// Plausible numbers, for the words a structure-aware mutation inserts.
pub const PLAIN: &[&str] = &[
    "0", "1", "-1", "2.5", "-10.", "10", "100", "0.001", "360", "1000", "5", "45", "-90", "3",
    "0.5", "20.", "-2", "7",
];

/// Bytes worth inserting: controls, a NUL, a byte that is not UTF-8, separators.
const ODD_BYTES: &[u8] = &[
    b'\r', b'\n', 0, 0x1b, b'\t', 0xff, 0xc3, b',', b'/', b'$', b'(', b')', b';', b'"', b'{', b'}',
    b'[', b']', b'e', b'-', b'.', b'=', b'#', b'%', b' ',
];

/// What a structure-aware mutation may insert into an input of one target: `words` go into
/// a line (`G83`, `X10`, `TURN=2`, `"jerk": 50`), `lines` become lines of their own (`MCALL
/// CYCLE83(…)`, `CIRCLE/…`). Either may be empty (only blind mutations then).
#[derive(Debug, Clone, Default)]
pub struct Vocabulary {
    /// Whole words; a word ending in `=` or a letter-only word that takes a number gets one.
    pub words: Vec<String>,
    /// Whole lines.
    pub lines: Vec<String>,
    /// The input is CSV: column mutations apply.
    pub csv: bool,
}

/// Byte ranges of the numbers in `text`.
pub fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let c = text[i];
        let starts = c.is_ascii_digit()
            || ((c == b'-' || c == b'.') && text.get(i + 1).is_some_and(u8::is_ascii_digit));
        if starts && (i == 0 || !text[i - 1].is_ascii_digit()) {
            let start = i;
            i += 1;
            while i < text.len()
                && (text[i].is_ascii_digit()
                    || text[i] == b'.'
                    || ((text[i] == b'e' || text[i] == b'E')
                        && text
                            .get(i + 1)
                            .is_some_and(|d| d.is_ascii_digit() || *d == b'-')))
            {
                i += if text[i] == b'e' || text[i] == b'E' {
                    2
                } else {
                    1
                };
            }
            out.push((start, i.min(text.len())));
        } else {
            i += 1;
        }
    }
    out
}

/// Byte ranges of the lines of `text`, each with its newline.
pub fn lines(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &b) in text.iter().enumerate() {
        if b == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < text.len() {
        out.push((start, text.len()));
    }
    out
}

/// Byte ranges of the words of `text`: a letter (not after a letter, digit or `_`), more
/// letters, digits or `_`, an optional `=`, then the characters of a number or expression
/// (`G43.4`, `X-12.5`, `TURN=2`, `CR=R1*2`, `#100=5.`, `"jerk"`).
pub fn words(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut i = 0;
    while i < text.len() {
        let after_ident = i > 0 && ident(text[i - 1]);
        let starts = (text[i].is_ascii_alphabetic() || text[i] == b'#') && !after_ident;
        if !starts {
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < text.len() && ident(text[i]) {
            i += 1;
        }
        if i < text.len() && text[i] == b'=' {
            i += 1;
        }
        while i < text.len() && matches!(text[i], b'0'..=b'9' | b'.' | b'-' | b'+' | b'#') {
            i += 1;
        }
        out.push((start, i));
    }
    out
}

/// A number related to `old`: a power of ten larger or smaller, negated, nudged, without its
/// decimal point (Fanuc reads `X10` as 0.010 mm) or with one added, many digits long.
fn related_number(rng: &mut Rng, old: &str) -> String {
    let x: f64 = old.parse().unwrap_or(1.0);
    match rng.below(8) {
        0 => format!("{}", x * 10f64.powi(rng.below(13) as i32 - 6)),
        1 => format!("{}", -x),
        2 => format!("{}", x + 1.0),
        3 => format!("{}", x * (1.0 + 1e-9)),
        4 => old.replace('.', ""),
        5 if !old.contains('.') => format!("{old}."),
        6 => format!("{x:.17}"),
        _ => rng.pick(PLAIN).to_string(),
    }
}

/// A word from the vocabulary, with a number where it takes one.
fn vocabulary_word(rng: &mut Rng, vocab: &Vocabulary) -> String {
    let w = rng.pick(&vocab.words).clone();
    let takes_number = w.ends_with('=')
        || (w.len() == 1 && w.as_bytes()[0].is_ascii_alphabetic())
        || w == "#"
        || w.starts_with('#') && w.len() > 1 && w[1..].bytes().all(|b| b.is_ascii_digit());
    if !takes_number {
        return w;
    }
    let n = if rng.one_in(6) {
        rng.pick(EXTREMES)
    } else {
        rng.pick(PLAIN)
    };
    if w.starts_with('#') && !w.ends_with('=') {
        format!("{w}={n}")
    } else {
        format!("{w}{n}")
    }
}

/// Applies one random mutation to `text`; returns its name. `others` are the other seeds of
/// the same target (for splicing lines across programs).
pub fn mutate_once(
    rng: &mut Rng,
    text: &mut Vec<u8>,
    vocab: &Vocabulary,
    others: &[&[u8]],
) -> &'static str {
    if text.is_empty() {
        text.extend_from_slice(rng.pick(EXTREMES).as_bytes());
        return "fill";
    }
    // Blind mutations and structure-aware ones about equally often when there is a vocabulary.
    let structured = !vocab.words.is_empty() || !vocab.lines.is_empty() || vocab.csv;
    let kind = if structured && rng.one_in(2) {
        10 + rng.below(9)
    } else {
        rng.below(10)
    };
    match kind {
        0 => {
            let i = rng.below(text.len());
            text[i] ^= 1 << rng.below(8);
            "bit flip"
        }
        1 => {
            let i = rng.below(text.len());
            text[i] = *rng.pick(ODD_BYTES);
            "byte set"
        }
        2 => {
            let i = rng.below(text.len() + 1);
            text.insert(i, *rng.pick(ODD_BYTES));
            "byte insert"
        }
        3 => {
            let ls = lines(text);
            let (a, b) = *rng.pick(&ls);
            text.drain(a..b);
            "line delete"
        }
        4 => {
            let ls = lines(text);
            let (a, b) = *rng.pick(&ls);
            let copy = text[a..b].to_vec();
            let times = if rng.one_in(4) { 1 + rng.below(50) } else { 1 };
            for _ in 0..times {
                text.splice(a..a, copy.iter().copied());
            }
            "line duplicate"
        }
        5 => {
            let ls = lines(text);
            let (i, j) = (rng.below(ls.len()), rng.below(ls.len()));
            let (i, j) = (i.min(j), i.max(j));
            if i != j {
                let (a, b) = (ls[i], ls[j]);
                let mut out = text[..a.0].to_vec();
                out.extend_from_slice(&text[b.0..b.1]);
                out.extend_from_slice(&text[a.1..b.0]);
                out.extend_from_slice(&text[a.0..a.1]);
                out.extend_from_slice(&text[b.1..]);
                *text = out;
            }
            "line swap"
        }
        6 => {
            let n = rng.below(text.len() + 1);
            text.truncate(n);
            "truncate"
        }
        7 => {
            // A few lines of another seed of the same target.
            if others.is_empty() {
                return mutate_once(rng, text, vocab, &[]);
            }
            let other = *rng.pick(others);
            let ls = lines(other);
            if ls.is_empty() {
                return "splice (empty)";
            }
            let from = rng.below(ls.len());
            let to = (from + 1 + rng.below(8)).min(ls.len());
            let mut piece = other[ls[from].0..ls[to - 1].1].to_vec();
            if piece.last() != Some(&b'\n') {
                piece.push(b'\n');
            }
            let at = *rng.pick(&lines(text));
            text.splice(at.0..at.0, piece);
            "splice"
        }
        8 => {
            let nums = numbers(text);
            if nums.is_empty() {
                text.extend_from_slice(rng.pick(EXTREMES).as_bytes());
                return "append extreme";
            }
            let (a, b) = *rng.pick(&nums);
            let old = String::from_utf8_lossy(&text[a..b]).into_owned();
            text.splice(a..b, related_number(rng, &old).into_bytes());
            "related number"
        }
        9 => {
            let nums = numbers(text);
            if nums.is_empty() {
                text.extend_from_slice(rng.pick(EXTREMES).as_bytes());
                return "append extreme";
            }
            // Several at once now and then: a whole record of extremes.
            let count = if rng.one_in(5) { 1 + rng.below(6) } else { 1 };
            let mut picks: Vec<(usize, usize)> = (0..count).map(|_| *rng.pick(&nums)).collect();
            picks.sort();
            picks.dedup();
            for (a, b) in picks.into_iter().rev() {
                let by = rng.pick(EXTREMES).as_bytes().to_vec();
                text.splice(a..b, by);
            }
            "extreme number"
        }
        // Structure-aware mutations.
        10 | 11 if !vocab.words.is_empty() => {
            // A word into a line: before a word, or at the end.
            let w = vocabulary_word(rng, vocab);
            let ws = words(text);
            let at = if ws.is_empty() || rng.one_in(3) {
                let (a, b) = *rng.pick(&lines(text));
                // Before the newline.
                if b > a && text[b - 1] == b'\n' {
                    b - 1
                } else {
                    b
                }
            } else {
                rng.pick(&ws).0
            };
            let mut piece = Vec::new();
            if at > 0 && text[at - 1] != b' ' && text[at - 1] != b'\n' {
                piece.push(b' ');
            }
            piece.extend_from_slice(w.as_bytes());
            if text.get(at).is_some_and(|c| *c != b'\n' && *c != b' ') {
                piece.push(b' ');
            }
            text.splice(at..at, piece);
            "word insert"
        }
        12 if !vocab.words.is_empty() => {
            let ws = words(text);
            if ws.is_empty() {
                return "word replace (no word)";
            }
            let (a, b) = *rng.pick(&ws);
            text.splice(a..b, vocabulary_word(rng, vocab).into_bytes());
            "word replace"
        }
        13 => {
            let ws = words(text);
            if ws.len() < 2 {
                return "word swap (too few)";
            }
            // Two words, near each other most of the time (the same or the next block).
            let i = rng.below(ws.len());
            let j = if rng.one_in(4) {
                rng.below(ws.len())
            } else {
                (i + 1 + rng.below(6)).min(ws.len() - 1)
            };
            let (i, j) = (i.min(j), i.max(j));
            if i == j {
                return "word swap (same)";
            }
            let ((a0, a1), (b0, b1)) = (ws[i], ws[j]);
            let mut out = text[..a0].to_vec();
            out.extend_from_slice(&text[b0..b1]);
            out.extend_from_slice(&text[a1..b0]);
            out.extend_from_slice(&text[a0..a1]);
            out.extend_from_slice(&text[b1..]);
            *text = out;
            "word swap"
        }
        14 => {
            let ws = words(text);
            if ws.is_empty() {
                return "word delete (no word)";
            }
            let (a, b) = *rng.pick(&ws);
            text.drain(a..b);
            "word delete"
        }
        15 => {
            // The number of one word changed, keeping its letter: `X12.5` → `X125`.
            let ws = words(text);
            let with_number: Vec<(usize, usize)> = ws
                .into_iter()
                .filter_map(|(a, b)| {
                    let n = numbers(&text[a..b]);
                    n.last().map(|&(x, y)| (a + x, a + y))
                })
                .collect();
            if with_number.is_empty() {
                return "word number (none)";
            }
            let (a, b) = *rng.pick(&with_number);
            let old = String::from_utf8_lossy(&text[a..b]).into_owned();
            let new = if rng.one_in(4) {
                rng.pick(EXTREMES).to_string()
            } else {
                related_number(rng, &old)
            };
            text.splice(a..b, new.into_bytes());
            "word number"
        }
        16 | 17 if !vocab.lines.is_empty() => {
            let line = rng.pick(&vocab.lines).clone() + "\n";
            let ls = lines(text);
            let at = rng.pick(&ls).0;
            text.splice(at..at, line.into_bytes());
            "line insert"
        }
        18 if vocab.csv => {
            // One column deleted or duplicated in every row.
            let duplicate = rng.one_in(2);
            let ls = lines(text);
            let width = ls.first().map_or(1, |&(a, b)| {
                text[a..b].iter().filter(|&&c| c == b',').count() + 1
            });
            let col = rng.below(width);
            let mut out = Vec::with_capacity(text.len() * 2);
            for (a, b) in ls {
                let line = String::from_utf8_lossy(&text[a..b]);
                let (body, nl) = match line.strip_suffix('\n') {
                    Some(s) => (s, "\n"),
                    None => (&*line, ""),
                };
                let mut cells: Vec<&str> = body.split(',').collect();
                if col < cells.len() {
                    if duplicate {
                        cells.insert(col, cells[col]);
                    } else {
                        cells.remove(col);
                    }
                }
                out.extend_from_slice(cells.join(",").as_bytes());
                out.extend_from_slice(nl.as_bytes());
            }
            *text = out;
            if duplicate {
                "column duplicate"
            } else {
                "column delete"
            }
        }
        _ => mutate_once(rng, text, &Vocabulary::default(), others),
    }
}

/// 1 to 4 mutations of `seed`; the mutated bytes and what was done.
pub fn mutate(
    rng: &mut Rng,
    seed: &[u8],
    vocab: &Vocabulary,
    others: &[&[u8]],
) -> (Vec<u8>, String) {
    let mut text = seed.to_vec();
    let n = 1 + rng.below(4);
    let names: Vec<&str> = (0..n)
        .map(|_| mutate_once(rng, &mut text, vocab, others))
        .collect();
    (text, names.join(" + "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_and_numbers_are_found_where_they_are() {
        let t = b"N10 G1 X-12.5 TURN=2 #100=5. \"jerk\": 50\n";
        let ws: Vec<&str> = words(t)
            .into_iter()
            .map(|(a, b)| std::str::from_utf8(&t[a..b]).unwrap())
            .collect();
        assert_eq!(ws, ["N10", "G1", "X-12.5", "TURN=2", "#100=5.", "jerk"]);
        let ns: Vec<&str> = numbers(t)
            .into_iter()
            .map(|(a, b)| std::str::from_utf8(&t[a..b]).unwrap())
            .collect();
        assert_eq!(ns, ["10", "1", "-12.5", "2", "100", "5.", "50"]);
    }
}
