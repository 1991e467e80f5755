//! Variables and arithmetic in address values, as posts write them.
//!
//! * Sinumerik: `DEF REAL _X_HOME, _Y_HOME=2` (user variables, 0 until assigned), R parameters
//!   `R1`…`R999` (0 until assigned), assignments `R1=R2+5`, `_Z=_Z_HOME`, and expressions after
//!   `=` in any address: `Z=_Z_HOME`, `X=R1*2`, `X=(R1+1)/2`.
//! * Fanuc and LinuxCNC: numbered parameters `#100` (`#[expr]`), LinuxCNC named parameters
//!   `#<name>`, assignments `#100=5.`, values `X#100`, `X-#100`, `X[#1+2]`; brackets group.
//! * Heidenhain: Q parameters `Q1`, `QL1`, `QR1` (`Q1 = Q2 + 5`, `X+Q1`; see
//!   [`super::klartext`]), unset until assigned. A cycle's feed parameter may hold a word
//!   instead of a number (`Q208=MAX`, `Q206=AUTO`, [`Variables::set_word`]): the cycle reads
//!   it, an expression that reads it is an error naming it.
//!
//! Operators `+ - * /` with the usual precedence, unary minus, parentheses (Sinumerik) or
//! brackets (Fanuc, LinuxCNC), and the functions `SIN COS TAN` (degrees), `SQRT ABS ATAN`
//! (`ATAN[y]/[x]` as Fanuc writes it is not read: an error), `ROUND TRUNC`. A variable read
//! before it has a value (Fanuc `#100` never assigned, a name never declared) is an error
//! naming it (a system variable, `#1000` and up, with a word on what it is: the control's
//! value, which a program cannot be followed without); so is a result that is not a finite number. Expressions are at most
//! [`MAX_EXPRESSION_LEN`] characters and nest at most [`MAX_DEPTH`] deep, so evaluation is
//! bounded.

use std::collections::HashMap;

/// Longest expression read, characters.
pub const MAX_EXPRESSION_LEN: usize = 1000;
/// Deepest nesting of brackets and unary operators.
pub const MAX_DEPTH: usize = 64;

/// The program's variables: names upper-cased (`_X_HOME`, `R1`, `#100`, `#<DEPTH>`).
#[derive(Debug, Default, Clone)]
pub struct Variables {
    values: HashMap<String, f64>,
    /// Variables that hold a word instead of a number (upper-cased): Heidenhain's `Q208=MAX`.
    words: HashMap<String, String>,
    /// Declared with `DEF` (value 0 until assigned).
    declared: HashMap<String, ()>,
    /// Changes so far ([`Variables::changes`]).
    changes: u64,
    /// The source line being run, set by the reader before each block: where a read of an
    /// unset R parameter is noted ([`Variables::take_assumed_zero`]).
    pub line: usize,
    /// Sinumerik R parameters read before the program set them, each with the line of its
    /// first such read: taken as 0 (a read does not change the variables, so this notes it
    /// through a shared reference).
    assumed_zero: std::cell::RefCell<AssumedZero>,
}

/// [`Variables`]' unset R parameters read: (name, line) in the order first read, and the names.
type AssumedZero = (Vec<(String, usize)>, std::collections::HashSet<String>);

impl Variables {
    /// Declares a Sinumerik user variable (value 0).
    pub fn declare(&mut self, name: &str) {
        let name = name.to_ascii_uppercase();
        if !self.values.contains_key(&name) {
            self.changes += 1;
            self.values.insert(name.clone(), 0.0);
        }
        self.declared.insert(name, ());
    }

    /// The R parameters read before the program set them (taken as 0), each with the line of
    /// its first such read, in the order they were first read; emptied.
    pub fn take_assumed_zero(&mut self) -> Vec<(String, usize)> {
        std::mem::take(&mut self.assumed_zero.get_mut().0)
    }

    /// How many times a value has changed so far (a new variable, or a different value
    /// assigned; assigning the value a variable has is no change). The same count at two
    /// moments of a run means the same values: the subprogram runner uses it to tell a jump
    /// that loops for ever.
    pub fn changes(&self) -> u64 {
        self.changes
    }

    /// Whether `name` is a variable an assignment may set: a declared name, an R parameter
    /// (`R` and digits), a Fanuc `#n`, a LinuxCNC `#<name>` or a Heidenhain Q parameter.
    pub fn assignable(&self, name: &str) -> bool {
        let name = name.to_ascii_uppercase();
        self.declared.contains_key(&name)
            || is_r_parameter(&name)
            || name.starts_with('#')
            || is_q_parameter(&name)
    }

    /// The value of `name`, if it has one.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.values.get(&name.to_ascii_uppercase()).copied()
    }

    /// Whether `name` has a value (assigned, or declared) or a word.
    pub fn is_set(&self, name: &str) -> bool {
        let name = name.to_ascii_uppercase();
        self.values.contains_key(&name) || self.words.contains_key(&name)
    }

    pub fn set(&mut self, name: &str, value: f64) {
        let name = name.to_ascii_uppercase();
        let had_word = self.words.remove(&name).is_some();
        // Bit for bit: -0 after 0 is a change (1/-0 is not 1/0).
        let old = self.values.insert(name, value);
        if had_word || old.map(f64::to_bits) != Some(value.to_bits()) {
            self.changes += 1;
        }
    }

    /// Gives `name` a word instead of a number: a Heidenhain cycle's feed parameter written
    /// `Q208=MAX` (FMAX) or `Q206=AUTO` (FAUTO). The cycle reads it ([`Variables::word`]); an
    /// expression that reads it is an error.
    pub fn set_word(&mut self, name: &str, word: &str) {
        let name = name.to_ascii_uppercase();
        let word = word.to_ascii_uppercase();
        let had_value = self.values.remove(&name).is_some();
        let old = self.words.insert(name, word.clone());
        if had_value || old.as_deref() != Some(word.as_str()) {
            self.changes += 1;
        }
    }

    /// The word `name` holds, if it holds one ([`Variables::set_word`]).
    pub fn word(&self, name: &str) -> Option<&str> {
        self.words
            .get(&name.to_ascii_uppercase())
            .map(String::as_str)
    }

    /// Gives `name` back the value it had (`None`: no value), as a LinuxCNC call's return
    /// does for `#1`–`#30`.
    pub fn restore(&mut self, name: &str, value: Option<f64>) {
        match value {
            Some(v) => self.set(name, v),
            None => {
                let name = name.to_ascii_uppercase();
                let had_word = self.words.remove(&name).is_some();
                if self.values.remove(&name).is_some() || had_word {
                    self.changes += 1;
                }
            }
        }
    }

    fn get(&self, name: &str) -> Result<f64, String> {
        let name = name.to_ascii_uppercase();
        if let Some(v) = self.values.get(&name) {
            return Ok(*v);
        }
        if let Some(word) = self.words.get(&name) {
            return Err(format!(
                "parameter `{name}` holds `{word}` (a cycle's feed keyword), not a number"
            ));
        }
        if is_r_parameter(&name) {
            // Sinumerik R parameters are 0 after the control's reset, but they keep their
            // values from one program to the next: noted, for the reader to say.
            let (order, seen) = &mut *self.assumed_zero.borrow_mut();
            if seen.insert(name.clone()) {
                order.push((name, self.line));
            }
            return Ok(0.0);
        }
        Err(if let Some(n) = system_variable(&name) {
            let which = if n >= 5000 {
                "one of the control's system variables (#1000 and up on Fanuc and Haas, #5000 \
                 and up on LinuxCNC: positions, offsets, tool data)"
            } else {
                "on Fanuc and Haas controls one of the system variables (#1000 and up: tool \
                 data, alarms, modal states, positions)"
            };
            format!(
                "parameter `{name}` is read before it is set: #{n} is {which}, whose value is \
                 the machine's, not the program's. Set it earlier in the program, or remove \
                 the test or move that reads it"
            )
        } else if let Some(n) = name
            .strip_prefix('#')
            .and_then(|d| d.parse::<u32>().ok())
            .filter(|n| (1..=33).contains(n))
        {
            // Round 8: a Fanuc macro program (Brown-Industries' O9250) tests its arguments
            // `IF [#1 EQ #0]` first: run on its own, they are unset.
            format!(
                "parameter `{name}` is read before it is set: #{n} is a local variable, which \
                 a macro call's arguments set (Fanuc G65 P… A… B…: A is #1, B #2; LinuxCNC \
                 `o… call [..]`); a macro program does not run on its own: solve the program \
                 that calls it, or set #{n} before it is read"
            )
        } else if name.starts_with('#') || is_q_parameter(&name) {
            format!("parameter `{name}` is read before it is set")
        } else {
            format!("`{name}` is not a number nor a variable the program defines (DEF)")
        })
    }
}

/// The number of a Fanuc/LinuxCNC numbered parameter `#n` with n ≥ 1000: a system variable,
/// which the control sets (Fanuc: #1000– interface signals, #2000– tool offsets, #3000 alarm,
/// #4000– modal information, #5000– positions; Haas: #5401– tool timers and the like;
/// LinuxCNC: #5061– probe results, #5161– G28 home, #5221– work offsets).
fn system_variable(name: &str) -> Option<u64> {
    let n: u64 = name.strip_prefix('#')?.parse().ok()?;
    (n >= 1000).then_some(n)
}

/// `R` followed by 1–3 digits (Sinumerik R parameters).
pub fn is_r_parameter(name: &str) -> bool {
    let upper = name.to_ascii_uppercase();
    upper.len() >= 2
        && upper.len() <= 4
        && upper.starts_with('R')
        && upper[1..].chars().all(|c| c.is_ascii_digit())
}

/// `Q`, `QL` or `QR` followed by digits (Heidenhain Q parameters).
pub fn is_q_parameter(name: &str) -> bool {
    let u = name.to_ascii_uppercase();
    let digits = u
        .strip_prefix("QL")
        .or_else(|| u.strip_prefix("QR"))
        .or_else(|| u.strip_prefix('Q'));
    digits.is_some_and(|d| !d.is_empty() && d.chars().all(|c| c.is_ascii_digit()))
}

/// Evaluates `text` with `vars`.
pub fn eval(text: &str, vars: &Variables) -> Result<f64, String> {
    if text.len() > MAX_EXPRESSION_LEN {
        return Err(format!(
            "expression longer than {MAX_EXPRESSION_LEN} characters"
        ));
    }
    let chars: Vec<char> = text.chars().filter(|c| !c.is_whitespace()).collect();
    let mut p = Parser {
        chars: &chars,
        at: 0,
        vars,
        depth: 0,
    };
    let v = p.sum()?;
    if p.at != chars.len() {
        return Err(format!("cannot read `{text}` as a number or expression"));
    }
    if !v.is_finite() {
        return Err(format!("`{text}` is not a finite number"));
    }
    Ok(v)
}

struct Parser<'a> {
    chars: &'a [char],
    at: usize,
    vars: &'a Variables,
    depth: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<char> {
        self.chars.get(self.at).copied()
    }

    fn deeper(&mut self) -> Result<(), String> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(format!("expression nested deeper than {MAX_DEPTH}"));
        }
        Ok(())
    }

    fn sum(&mut self) -> Result<f64, String> {
        let mut v = self.product()?;
        while let Some(c @ ('+' | '-')) = self.peek() {
            self.at += 1;
            let r = self.product()?;
            v = if c == '+' { v + r } else { v - r };
        }
        Ok(v)
    }

    fn product(&mut self) -> Result<f64, String> {
        let mut v = self.unary()?;
        while let Some(c @ ('*' | '/')) = self.peek() {
            self.at += 1;
            let r = self.unary()?;
            if c == '/' && r == 0.0 {
                return Err("division by zero".into());
            }
            v = if c == '*' { v * r } else { v / r };
        }
        Ok(v)
    }

    fn unary(&mut self) -> Result<f64, String> {
        match self.peek() {
            Some(c @ ('-' | '+')) => {
                self.at += 1;
                self.deeper()?;
                let v = self.unary()?;
                self.depth -= 1;
                Ok(if c == '-' { -v } else { v })
            }
            _ => self.atom(),
        }
    }

    fn group(&mut self, close: char) -> Result<f64, String> {
        self.deeper()?;
        let v = self.sum()?;
        if self.peek() != Some(close) {
            return Err(format!("missing `{close}` in expression"));
        }
        self.at += 1;
        self.depth -= 1;
        Ok(v)
    }

    fn atom(&mut self) -> Result<f64, String> {
        match self.peek() {
            None => Err("expression ends too early".into()),
            Some('(') => {
                self.at += 1;
                self.group(')')
            }
            Some('[') => {
                self.at += 1;
                self.group(']')
            }
            Some('#') => {
                self.at += 1;
                let name = match self.peek() {
                    Some('<') => {
                        let start = self.at;
                        while self.peek().is_some_and(|c| c != '>') {
                            self.at += 1;
                        }
                        if self.peek() != Some('>') {
                            return Err("unclosed `#<` parameter name".into());
                        }
                        self.at += 1;
                        let n: String = self.chars[start..self.at].iter().collect();
                        format!("#{n}")
                    }
                    Some('[') => {
                        self.at += 1;
                        let n = self.group(']')?;
                        format!("#{}", parameter_number(n)?)
                    }
                    _ => {
                        let start = self.at;
                        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                            self.at += 1;
                        }
                        if start == self.at {
                            return Err("`#` without a parameter number".into());
                        }
                        let n: String = self.chars[start..self.at].iter().collect();
                        format!("#{}", n.trim_start_matches('0'))
                    }
                };
                self.vars.get(&name)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => {
                let start = self.at;
                while self.peek().is_some_and(|c| c.is_ascii_digit() || c == '.') {
                    self.at += 1;
                }
                let text: String = self.chars[start..self.at].iter().collect();
                if self.peek().is_some_and(|c| c == 'E' || c == 'e') {
                    return Err(format!(
                        "`{text}E…`: exponent notation is not part of G-code; write the number \
                         in full"
                    ));
                }
                text.parse::<f64>()
                    .map_err(|_| format!("malformed number `{text}`"))
            }
            Some(c) if c.is_ascii_alphabetic() || c == '_' || c == '$' => {
                let start = self.at;
                while self
                    .peek()
                    .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$')
                {
                    self.at += 1;
                }
                let name: String = self.chars[start..self.at].iter().collect();
                let upper = name.to_ascii_uppercase();
                let function = function(&upper);
                if let Some(f) = function
                    && matches!(self.peek(), Some('(' | '['))
                {
                    let close = if self.peek() == Some('(') { ')' } else { ']' };
                    self.at += 1;
                    let x = self.group(close)?;
                    return Ok(f(x));
                }
                if upper.starts_with('$') {
                    return Err(format!(
                        "system variable `{name}` is not known to feedopt (its value is the \
                         controller's)"
                    ));
                }
                self.vars.get(&upper)
            }
            Some(c) => Err(format!("unexpected `{c}` in expression")),
        }
    }
}

/// The function `name` (upper case) names, if any.
fn function(name: &str) -> Option<fn(f64) -> f64> {
    match name {
        "SIN" => Some(|x: f64| x.to_radians().sin()),
        "COS" => Some(|x: f64| x.to_radians().cos()),
        "TAN" => Some(|x: f64| x.to_radians().tan()),
        "SQRT" => Some(f64::sqrt),
        "ABS" => Some(f64::abs),
        "ATAN" => Some(|x: f64| x.atan().to_degrees()),
        "ROUND" => Some(f64::round),
        "TRUNC" | "FIX" => Some(f64::trunc),
        _ => None,
    }
}

/// Whether `name` (any case) is a function an expression may call (`SIN[30.]`).
pub fn is_function(name: &str) -> bool {
    function(&name.to_ascii_uppercase()).is_some()
}

/// A parameter number from an expression value: a whole number 1…99999.
fn parameter_number(n: f64) -> Result<u32, String> {
    if n.fract() != 0.0 || !(1.0..=99999.0).contains(&n) {
        return Err(format!("`#[{n}]` is not a parameter number"));
    }
    Ok(n as u32)
}

/// The normalised name of a Fanuc `#n` (leading zeros dropped), or `None`.
pub fn hash_name(text: &str) -> Option<String> {
    let digits = text.strip_prefix('#')?;
    if let Some(named) = digits.strip_prefix('<') {
        return named
            .ends_with('>')
            .then(|| format!("#<{}", named.to_ascii_uppercase()));
    }
    (!digits.is_empty() && digits.chars().all(|c| c.is_ascii_digit()))
        .then(|| format!("#{}", digits.trim_start_matches('0')))
}
