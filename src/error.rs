//! The library's one error type.
//!
//! Every failure a user can cause (a malformed record file, an impossible parameter, a
//! degenerate polygon, a solver that cannot converge) is reported as an [`Error`] that says
//! *what* went wrong, *where* (file and line, block name, field or flag, simulated time)
//! and, where there is one, what would be accepted. The kinds a user meets: a scene
//! ([`Error::Scene`], [`Error::Parse`] of its TOML), a record ([`Error::Record`]), a
//! parameter or flag ([`Error::InvalidParameter`], [`Error::Unknown`]), an output or I/O
//! problem ([`Error::Output`], [`Error::Io`], which always name the file) and the solver
//! ([`Error::Solver`]). The library never panics on bad input; the binary adds context
//! with `anyhow`.

use std::path::PathBuf;

/// Result alias used throughout the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in slidebase.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },

    /// An output path that cannot be used (a file where a folder is wanted, a folder that
    /// cannot be created or written).
    #[error("output {path}: {message}")]
    Output {
        /// The path concerned.
        path: PathBuf,
        /// What is wrong and what would work.
        message: String,
    },

    /// A ground-motion record (file or built-in) that is malformed or outside the range a
    /// run can use.
    #[error("record {file}{}: {message}", at_line(*line))]
    Record {
        /// The file (or `<built-in NAME>`).
        file: String,
        /// 1-based line number; 0 when the problem concerns the whole record.
        line: usize,
        /// What is wrong, in words a user can act on.
        message: String,
    },

    /// A file (scene TOML, sweep table) was read but its contents are malformed.
    #[error("{file}{}: {message}", at_line(*line))]
    Parse {
        /// The file (or a label such as `<built-in el-centro>`).
        file: String,
        /// 1-based line number; 0 when the problem concerns the whole file.
        line: usize,
        /// What is wrong, in words a user can act on.
        message: String,
    },

    /// A parameter is outside its physical or numerical range.
    #[error("invalid {field}: {message}")]
    InvalidParameter {
        /// The parameter's name as the user wrote it (CLI flag, TOML key, struct field).
        field: String,
        /// Why the value is not acceptable.
        message: String,
    },

    /// The scene description is inconsistent (unknown block names, degenerate polygons…).
    #[error("scene error: {0}")]
    Scene(String),

    /// A name (scene, record, integrator…) that is not known.
    #[error("unknown {kind} '{name}' (known: {known})")]
    Unknown {
        /// What kind of thing was looked up ("scene", "record", …).
        kind: &'static str,
        /// The name that was given.
        name: String,
        /// The names that would have worked, comma-separated.
        known: String,
    },

    /// The platform cannot do what was asked (no display, no graphics adapter…).
    #[error("{0}")]
    Platform(String),

    /// The solver could not advance: it diverged, hit its Δt floor or produced a non-finite value.
    #[error("solver stopped at t = {time:.6} s: {reason}")]
    Solver {
        /// Simulated time at which the solver gave up.
        time: f64,
        /// Why, and what the user could change.
        reason: String,
    },
}

impl Error {
    /// Shorthand for [`Error::InvalidParameter`].
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::InvalidParameter {
            field: field.into(),
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Parse`].
    pub fn parse(file: impl Into<String>, line: usize, message: impl Into<String>) -> Self {
        Error::Parse {
            file: file.into(),
            line,
            message: message.into(),
        }
    }

    /// A record's error placed in `file` (the path a reader was given, where the record's
    /// own checks know only its name); other errors unchanged.
    pub fn in_file(self, file: &str) -> Self {
        match self {
            Error::Record { line, message, .. } => Error::Record {
                file: file.into(),
                line,
                message,
            },
            other => other,
        }
    }

    /// Shorthand for [`Error::Record`].
    pub fn record(file: impl Into<String>, line: usize, message: impl Into<String>) -> Self {
        Error::Record {
            file: file.into(),
            line,
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Output`].
    pub fn output(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Error::Output {
            path: path.into(),
            message: message.into(),
        }
    }

    /// A file named where a built-in name or a file is accepted that does not exist, as
    /// an [`Error::Io`] that also lists the built-in `kind`s (`builtins`).
    pub fn missing_file(kind: &str, name: &str, builtins: &str) -> Self {
        Error::io(
            name,
            std::io::Error::new(
                std::io::ErrorKind::NotFound,
                format!("no such {kind} file (the built-in {kind}s: {builtins})"),
            ),
        )
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// A number as a message shows it: plain for ordinary magnitudes, in exponent form for
/// very large or very small ones (so that 1e-300 is not three hundred zeros).
pub fn show(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `:LINE` after a file's name, or nothing for line 0 (a problem of the whole file).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}

/// Checks that a parameter is finite and strictly positive.
pub fn require_positive(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be a finite number > 0, got {}", show(value)),
        ))
    }
}

/// Checks that a parameter is finite and not negative.
pub fn require_non_negative(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be a finite number >= 0, got {}", show(value)),
        ))
    }
}

/// Checks that a parameter is finite and within `[lo, hi]`; the message gives the range
/// and its unit.
pub fn require_range(field: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<f64> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        Err(Error::invalid(
            field,
            format!(
                "must be a number in [{}, {}]{unit}, got {}",
                show(lo),
                show(hi),
                show(value)
            ),
        ))
    }
}

/// Whether `name`, given where a built-in name or a file path is accepted, was meant as a
/// path: it has an extension or a folder. For such a name a missing file is the error to
/// report, not an unknown built-in.
pub fn meant_as_path(name: &str) -> bool {
    let path = std::path::Path::new(name);
    path.extension().is_some() || path.parent().is_some_and(|p| !p.as_os_str().is_empty())
}
