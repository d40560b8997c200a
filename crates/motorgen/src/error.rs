//! The crate's error type.

use std::path::PathBuf;

/// What can go wrong in motorgen: bad parameters or spaces, and failed writes.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A key that is not a parameter.
    #[error("unknown parameter `{key}`{hint}")]
    Unknown {
        /// The key given.
        key: String,
        /// ", did you mean `x`?" or empty.
        hint: String,
    },
    /// A value of the wrong type or out of range.
    #[error("{key} = {value} is not allowed: expected {allowed}")]
    Invalid {
        /// The parameter.
        key: String,
        /// The value given.
        value: String,
        /// What the parameter accepts.
        allowed: String,
    },
    /// A distribution that is malformed or can produce disallowed values.
    #[error("{key}: {message}")]
    Distribution {
        /// The parameter.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// Parameters that are allowed alone but not together.
    #[error("{0}")]
    Conflict(String),
    /// Unparseable input.
    #[error("{0}")]
    Parse(String),
    /// A failed write or read.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

impl Error {
    /// An unknown key, with the closest known key as a hint.
    pub fn unknown(key: &str) -> Error {
        let best = crate::params::PARAMS
            .iter()
            .map(|p| (strsim::jaro_winkler(key, p.key), p.key))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        let hint = match best {
            Some((score, near)) if score > 0.8 => format!(", did you mean `{near}`?"),
            _ => String::new(),
        };
        Error::Unknown {
            key: key.into(),
            hint,
        }
    }

    /// Wraps an I/O error with its path.
    pub fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Error {
        let path = path.into();
        move |source| Error::Io { path, source }
    }
}

/// Result with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
