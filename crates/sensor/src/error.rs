//! The crate's error type.

/// What can go wrong in the sensor crate.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A setting out of its allowed range.
    #[error("{key} = {value} is not allowed: expected {allowed}")]
    Invalid {
        /// The setting.
        key: String,
        /// The value given.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// A preset name that does not exist.
    #[error("unknown sensor preset \"{0}\": expected one of {presets}", presets = crate::spec::PRESETS.join(", "))]
    UnknownPreset(String),
    /// A mesh file that cannot be read.
    #[error("cannot read mesh {path}: {why}")]
    Mesh {
        /// The file.
        path: String,
        /// What is wrong, in words.
        why: String,
    },
}
