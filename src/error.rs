//! The library's one error type.
//!
//! Every failure a user can cause (a malformed record file, an impossible parameter, a
//! degenerate polygon, a solver that cannot converge) is reported as an [`Error`] that says
//! *what* went wrong and *where* (file and line, block name, field name, simulated time).
//! The library never panics on bad input; the binary adds context with `anyhow`.

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

    /// A file was read but its contents are malformed.
    #[error("{file}:{line}: {message}")]
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

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Checks that a parameter is finite and strictly positive.
pub fn require_positive(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be a finite number > 0, got {value}"),
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
            format!("must be a finite number >= 0, got {value}"),
        ))
    }
}
