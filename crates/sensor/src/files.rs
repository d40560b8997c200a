//! Reading the files a user names (meshes, configurations, a dataset's records) within bounds:
//! only regular files, so a FIFO or a device (`/dev/zero`) is refused at once instead of
//! blocking or filling memory, and no more than a limit of bytes.

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// The bytes of the regular file at `path`, at most `limit` of them.
///
/// # Errors
///
/// The error of opening or reading it; [`ErrorKind::InvalidInput`] "not a regular file" for a
/// folder, a FIFO, a socket or a device, and "larger than N MB" past `limit`.
pub fn read(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let regular = |m: std::fs::Metadata| {
        if m.is_file() {
            Ok(m.len())
        } else {
            Err(Error::new(ErrorKind::InvalidInput, "not a regular file"))
        }
    };
    regular(std::fs::metadata(path)?)?;
    // opened without waiting for a writer, should a FIFO take its place meanwhile
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let len = regular(file.metadata()?)?;
    let too_large = || {
        Error::new(
            ErrorKind::InvalidInput,
            format!("larger than {} MB", limit.div_ceil(1 << 20)),
        )
    };
    if len > limit {
        return Err(too_large());
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large());
    }
    Ok(bytes)
}

/// The text of the regular file at `path`, at most `limit` bytes of UTF-8, as [`read`] reads it.
///
/// # Errors
///
/// Those of [`read`], and [`ErrorKind::InvalidData`] "not UTF-8 text".
pub fn read_text(path: &Path, limit: u64) -> std::io::Result<String> {
    String::from_utf8(read(path, limit)?)
        .map_err(|_| Error::new(ErrorKind::InvalidData, "not UTF-8 text"))
}

/// The most bytes a configuration file (a dataset's, a sensor's, the motors') may hold.
pub const CONFIG_LIMIT: u64 = 16 << 20;
