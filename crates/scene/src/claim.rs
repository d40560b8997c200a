//! A run's claim on a dataset folder: operating-system file locks, released by the kernel when
//! the process dies (so a killed run never blocks its `--resume`), that keep an unsharded run
//! alone in its folder, let the shards of one dataset write side by side, and tell a live
//! writer's temporary files from those a dead one left.
//!
//! The locks are files in `{out}/.motorfactory/`:
//! - `run.lock`: exclusive for an unsharded run, shared by shards;
//! - `shard-{i}-of-{n}.lock`: exclusive, so one run at a time makes a shard;
//! - `setup.lock`: exclusive while a run checks or writes the files every run of the folder
//!   shares (`config.toml`, `labels.json`, the merged manifest) and removes stale temporaries;
//! - `writers/{token}.lock`: held by the live process whose temporary files carry `token`
//!   ([`motorgen::export::writer_token`]).
//!
//! They are `flock` locks: local file systems and NFS (version 4) honour them across hosts.

use std::collections::HashMap;
use std::fs::{File, TryLockError};
use std::path::{Path, PathBuf};

use motorgen::export::{temporary_token, writer_token};

use crate::dataset::{Shard, files_in};
use crate::error::{Error, Result};

/// The locks a run holds on its output folder while it writes; dropping it releases them.
#[derive(Debug)]
pub struct Claim {
    dir: PathBuf,
    _run: File,
    _shard: File,
    _writer: File,
}

/// The setup lock, held while it lives.
pub(crate) struct Setup(File);

impl Drop for Setup {
    fn drop(&mut self) {
        let _ = self.0.unlock();
    }
}

impl Claim {
    /// Claims `out` (which exists) for `shard`.
    ///
    /// # Errors
    ///
    /// [`Error::Output`] when another run holds the folder: any run while an unsharded one
    /// writes, an unsharded run while shards write, a shard that another run is making; or when
    /// the locks cannot be made.
    pub fn take(out: &Path, shard: Shard) -> Result<Claim> {
        let dir = out.join(".motorfactory");
        let writers = dir.join("writers");
        std::fs::create_dir_all(&writers).map_err(Error::io(&writers))?;
        let busy = |why: &str| {
            Error::Output(format!(
                "output folder {}: {why}; wait for it to end, or choose another --out",
                out.display()
            ))
        };
        let run = open(&dir.join("run.lock"))?;
        let got = if shard.count == 1 {
            run.try_lock()
        } else {
            run.try_lock_shared()
        };
        match got {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) if shard.count == 1 => {
                return Err(busy("another motorfactory run is writing into it"));
            }
            Err(TryLockError::WouldBlock) => {
                return Err(busy("an unsharded motorfactory run is writing into it"));
            }
            Err(TryLockError::Error(e)) => return Err(lock_error(&dir.join("run.lock"), e)),
        }
        let name = format!("shard-{}-of-{}.lock", shard.part, shard.count);
        let shard_lock = open(&dir.join(&name))?;
        match shard_lock.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                return Err(busy(&format!(
                    "shard {}/{} is being made by another run",
                    shard.part, shard.count
                )));
            }
            Err(TryLockError::Error(e)) => return Err(lock_error(&dir.join(name), e)),
        }
        // made locked under another name, then renamed: a sweep never sees it unlocked
        let token = writer_token();
        let fresh = writers.join(format!("{token}.new"));
        let writer = open(&fresh)?;
        writer.lock().map_err(|e| lock_error(&fresh, e))?;
        let path = writers.join(format!("{token}.lock"));
        std::fs::rename(&fresh, &path).map_err(Error::io(&path))?;
        Ok(Claim {
            dir,
            _run: run,
            _shard: shard_lock,
            _writer: writer,
        })
    }

    /// Waits for the setup lock.
    pub(crate) fn setup(&self) -> Result<Setup> {
        let path = self.dir.join("setup.lock");
        let file = open(&path)?;
        file.lock().map_err(|e| lock_error(&path, e))?;
        Ok(Setup(file))
    }

    /// Removes the temporary files in `dirs` whose writers are gone (any run's, of any shard),
    /// and those writers' lock files. Call under [`Claim::setup`].
    pub(crate) fn remove_stale_temporaries(&self, dirs: &[PathBuf]) -> Result<()> {
        let writers = self.dir.join("writers");
        let mut live: HashMap<String, bool> = HashMap::new();
        let mut alive = |token: &str| -> Result<bool> {
            if token == writer_token() {
                return Ok(true);
            }
            if let Some(&known) = live.get(token) {
                return Ok(known);
            }
            let is = held(&writers.join(format!("{token}.lock")))?;
            live.insert(token.to_string(), is);
            Ok(is)
        };
        for dir in dirs {
            for (path, name) in files_in(dir)? {
                if let Some(token) = temporary_token(&name)
                    && !alive(token)?
                {
                    remove(&path)?;
                }
            }
        }
        // the dead writers' lock files
        for (path, name) in files_in(&writers)? {
            let token = name.strip_suffix(".lock").unwrap_or(writer_token());
            if token != writer_token() && !held(&path)? {
                remove(&path)?;
            }
        }
        Ok(())
    }
}

impl Drop for Claim {
    fn drop(&mut self) {
        let writers = self.dir.join("writers");
        let _ = std::fs::remove_file(writers.join(format!("{}.lock", writer_token())));
    }
}

fn open(path: &Path) -> Result<File> {
    std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(path)
        .map_err(Error::io(path))
}

/// Whether a live process holds the lock file at `path` (a missing file is nobody's).
fn held(path: &Path) -> Result<bool> {
    let file = match std::fs::OpenOptions::new().write(true).open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(Error::io(path)(e)),
    };
    match file.try_lock() {
        Ok(()) => Ok(false),
        Err(TryLockError::WouldBlock) => Ok(true),
        Err(TryLockError::Error(e)) => Err(lock_error(path, e)),
    }
}

fn remove(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::io(path)(e)),
        _ => Ok(()),
    }
}

fn lock_error(path: &Path, e: std::io::Error) -> Error {
    Error::Output(format!(
        "cannot lock {}: {e} (the output folder needs a file system with file locks)",
        path.display()
    ))
}
