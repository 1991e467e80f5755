//! One error type for the whole pipeline.
//!
//! Every variant says *where*: the file and line of a toolpath record, the field of a machine
//! file, or the span / station / nearest CL line of a schedule that cannot be met. The CLI prints
//! the `Display` form as one line on stderr and exits with code 2.

use std::path::PathBuf;

/// Everything that can go wrong between reading the input and writing the schedule.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A toolpath (or other line-oriented) input file has a bad record.
    #[error("{}:{line}: {message}", file.display())]
    Parse {
        /// The file.
        file: PathBuf,
        /// 1-based line number of the record (its first line when `$`-continued).
        line: usize,
        /// What is wrong with the record and what to do.
        message: String,
    },
    /// A machine file has a missing, unknown or invalid field.
    #[error("{}: field `{field}`: {message}", file.display())]
    Field {
        /// The machine file.
        file: PathBuf,
        /// Dotted path of the field, e.g. `axes.C.velocity`.
        field: String,
        /// What is wrong with the field and what to do.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{}: {}", file.display(), io_reason(source))]
    Io {
        /// The file.
        file: PathBuf,
        #[source]
        /// What the operating system said.
        source: std::io::Error,
    },
    /// The request cannot be met by any schedule (names where on the path).
    #[error("infeasible: {0}")]
    Infeasible(String),
    /// The convex solver did not return a usable answer.
    #[error("solver: {0}")]
    Solver(String),
    /// A bad option or argument combination.
    #[error("{0}")]
    Usage(String),
    /// An option of a library call is out of its range (checked where it enters the library:
    /// see [`crate::validate`]).
    #[error("option `{field}`: {reason}")]
    InvalidOption {
        /// Dotted path of the option in its struct, e.g. `verify.period` of
        /// [`Options`](crate::optimize::Options), or the argument's name (`period`).
        field: String,
        /// What is wrong with the value and what to give instead.
        reason: String,
    },
    /// A [`Machine`](crate::machine::Machine) (built in code; a machine file's errors are
    /// [`Error::Field`]) has an invalid field ([`Machine::validate`](crate::machine::Machine::validate)).
    #[error("machine: field `{field}`: {reason}")]
    InvalidMachine {
        /// Dotted path of the field as a machine file names it, e.g. `axes.C.velocity`.
        field: String,
        /// What is wrong with the value and what to give instead.
        reason: String,
    },
}

/// Result alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub(crate) fn parse(file: impl Into<PathBuf>, line: usize, message: impl Into<String>) -> Self {
        Error::Parse {
            file: file.into(),
            line,
            message: message.into(),
        }
    }

    pub(crate) fn field(
        file: impl Into<PathBuf>,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Field {
            file: file.into(),
            field: field.into(),
            message: message.into(),
        }
    }

    /// An [`Error::InvalidOption`] for `field`.
    pub(crate) fn option(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::InvalidOption {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// The same error with `prefix.` before an [`Error::InvalidOption`]'s field (an option of
    /// a nested struct); any other error unchanged.
    pub(crate) fn within(self, prefix: &str) -> Self {
        match self {
            Error::InvalidOption { field, reason } => Error::InvalidOption {
                field: format!("{prefix}.{field}"),
                reason,
            },
            e => e,
        }
    }

    pub(crate) fn io(file: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            file: file.into(),
            source,
        }
    }
}

/// A number as a message shows it: plain where that is short (`150`, `0.25`), in exponent
/// notation where it is very large or small (`1e300`, `1e-12`), never hundreds of digits;
/// `infinity` and `not a number` in words.
pub fn number(x: f64) -> String {
    let a = x.abs();
    if x.is_nan() {
        "not a number".into()
    } else if x.is_infinite() {
        if x > 0.0 { "infinity" } else { "-infinity" }.into()
    } else if x != 0.0 && !(1e-4..1e6).contains(&a) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// What went wrong with a file, and what to do about the common cases.
fn io_reason(e: &std::io::Error) -> String {
    use std::io::ErrorKind;
    match e.kind() {
        ErrorKind::NotFound => "no such file: check the path".into(),
        ErrorKind::PermissionDenied => "permission denied: check the file's permissions".into(),
        ErrorKind::IsADirectory => "is a directory: name a file".into(),
        _ => e.to_string(),
    }
}
