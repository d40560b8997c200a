//! The crate's error type.

use std::fmt::Display;
use std::path::PathBuf;

/// What can go wrong in the scene crate.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A configuration that cannot be used; the message names the key, the value and what is
    /// allowed.
    #[error("{0}")]
    Config(String),
    /// An output location that cannot be used, found before anything is written.
    #[error("{0}")]
    Output(String),
    /// A failed write or read while working.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

impl Error {
    /// `key = value is not allowed: expected allowed`.
    pub fn invalid(key: &str, value: impl Display, allowed: impl Display) -> Error {
        Error::Config(format!(
            "{key} = {} is not allowed: expected {allowed}",
            motorgen::shown(&value.to_string())
        ))
    }

    /// A closure that wraps an I/O error with its path.
    pub fn io(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
        move |source| Error::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// Whether the error is the user's (configuration or output location) rather than a failure
    /// while working.
    pub fn is_usage(&self) -> bool {
        !matches!(self, Error::Io { .. })
    }
}

impl From<motorgen::Error> for Error {
    fn from(e: motorgen::Error) -> Error {
        Error::Config(e.to_string())
    }
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
