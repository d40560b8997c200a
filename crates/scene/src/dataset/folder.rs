//! The dataset folder on disk: made, written through temporaries and renames, its manifests
//! read back.

use std::collections::BTreeMap;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

use motorgen::export::write_atomic;

use super::Row;
use crate::error::{Error, Result};

/// Makes the output folder `out` (and the folders above it): whether this call made it. An
/// existing `out` must be a folder (a symbolic link to one is followed).
pub(super) fn make_out(out: &Path) -> Result<bool> {
    let cannot = |e: std::io::Error| {
        Error::Output(format!(
            "cannot make output folder {}: {e}; choose another --out",
            out.display()
        ))
    };
    let parent = out.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(parent) = parent {
        std::fs::create_dir_all(parent).map_err(cannot)?;
    }
    match std::fs::create_dir(out) {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => match std::fs::metadata(out) {
            Ok(m) if m.is_dir() => Ok(false),
            Ok(_) => Err(Error::Output(format!(
                "output folder {} is a file; choose another --out",
                out.display()
            ))),
            Err(_) => Err(Error::Output(format!(
                "output folder {} is a symbolic link to nothing; remove it or choose another --out",
                out.display()
            ))),
        },
        Err(e) => Err(cannot(e)),
    }
}

/// An output folder this process may not write into is the user's to fix, not a failure while
/// working: an [`Error::Output`].
pub(super) fn unwritable(out: &Path, e: Error) -> Error {
    match e {
        Error::Io { path, source }
            if matches!(
                source.kind(),
                std::io::ErrorKind::PermissionDenied | std::io::ErrorKind::ReadOnlyFilesystem
            ) =>
        {
            Error::Output(format!(
                "output folder {}: cannot write {} ({source}); choose another --out",
                out.display(),
                path.display()
            ))
        }
        e => e,
    }
}

/// Writes `body` to `path` through a temporary file and a rename.
pub(crate) fn save(
    path: &Path,
    body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    write_atomic(path, body).map_err(|e| match e {
        motorgen::Error::Io { path, source } => Error::Io { path, source },
        other => Error::Output(other.to_string()),
    })
}

pub(super) fn write_json(w: &mut dyn Write, value: &serde_json::Value) -> std::io::Result<()> {
    serde_json::to_writer_pretty(&mut *w, value)?;
    w.write_all(b"\n")
}

/// Writes a manifest.
pub(super) fn write_rows(path: &Path, rows: &[Row]) -> Result<()> {
    save(path, &|w| {
        for r in rows {
            serde_json::to_writer(&mut *w, r)?;
            w.write_all(b"\n")?;
        }
        Ok(())
    })
}

/// The rows of every manifest in `out` (the unsharded `manifest.jsonl` and each shard's), by
/// index; a torn last line (a run killed while appending) is dropped, and a sample listed twice
/// counts once.
pub(super) fn read_all_rows(out: &Path) -> Result<BTreeMap<u64, Row>> {
    let mut rows = BTreeMap::new();
    for (path, name) in files_in(out)? {
        if !(name.starts_with("manifest") && name.ends_with(".jsonl")) {
            continue;
        }
        let file = std::fs::File::open(&path).map_err(Error::io(&path))?;
        for line in std::io::BufReader::new(file).lines() {
            let line = line.map_err(Error::io(&path))?;
            if let Ok(row) = serde_json::from_str::<Row>(&line) {
                rows.insert(row.index, row);
            }
        }
    }
    Ok(rows)
}

/// The entries of `dir` with their names (none when `dir` does not exist).
pub(crate) fn files_in(dir: &Path) -> Result<Vec<(PathBuf, String)>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(Error::io(dir)(e)),
    };
    entries
        .map(|entry| {
            let path = entry.map_err(Error::io(dir))?.path();
            let name = path
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            Ok((path, name))
        })
        .collect()
}
