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
    #[error("{key} = {} is not allowed: expected {allowed}", shown(value))]
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
        Error::Unknown {
            key: shown(key),
            hint: did_you_mean(key, crate::params::PARAMS.iter().map(|p| p.key)),
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

/// A value as a message shows it: at most 40 characters (the rest elided with `…`), control
/// characters escaped, so that a huge or binary value cannot flood a terminal.
pub fn shown(value: &str) -> String {
    cut(value, 40)
}

/// `text` with control characters escaped and at most `most` characters, the rest elided
/// with `…`.
pub fn cut(text: &str, most: usize) -> String {
    let mut out = String::new();
    for c in text.chars().take(most) {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    if text.chars().nth(most).is_some() {
        out.push('…');
    }
    out
}

/// `, did you mean `x`?` for the option closest to `given`, or nothing when none is close.
pub fn did_you_mean<'a>(given: &str, options: impl IntoIterator<Item = &'a str>) -> String {
    let best = options
        .into_iter()
        .map(|o| (strsim::jaro_winkler(given, o), o))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    match best {
        Some((score, near)) if score > 0.8 => format!(", did you mean `{near}`?"),
        _ => String::new(),
    }
}
