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
//!   ([`motorgen::export::writer_token`]); a writer is recorded there before it writes.
//!
//! They are `flock` locks: local file systems and NFS (version 4) honour them across hosts. A
//! lock file is removed only by a run holding it alone, and every run checks after locking that
//! the file it locked is still the one at its name (else it locks anew), so no two runs ever
//! hold the same lock through two files. Lock files and `.motorfactory/` are never reached
//! through a symbolic link.

use std::collections::HashMap;
use std::fs::{File, TryLockError};
use std::path::{Path, PathBuf};

use motorgen::export::{temporary_token, writer_token};

use crate::dataset::{SAMPLE_FOLDERS, Shard, files_in};
use crate::error::{Error, Result};

/// The locks a run holds on its output folder while it writes; dropping it releases them.
#[derive(Debug)]
pub struct Claim {
    out: PathBuf,
    dir: PathBuf,
    run: File,
    shard: (File, PathBuf),
    writer: File,
}

/// The setup lock, held while it lives.
pub(crate) struct Setup(File);

impl Drop for Setup {
    fn drop(&mut self) {
        let _ = self.0.unlock();
    }
}

/// How a lock file is locked.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// Exclusive, failing at once when held.
    Try,
    /// Shared, failing at once when held exclusively.
    TryShared,
    /// Exclusive, waiting for it.
    Wait,
}

/// Times a claim is taken anew when a run withdrawing from the folder removes what it locks.
const ATTEMPTS: usize = 8;

impl Claim {
    /// Claims `out` (a folder; made if missing) for `shard`.
    ///
    /// # Errors
    ///
    /// [`Error::Output`] when another run holds the folder: any run while an unsharded one
    /// writes, an unsharded run while shards write, a shard that another run is making; when
    /// `.motorfactory` or its `writers` is not a plain folder (a symbolic link, a file); or when
    /// the locks cannot be made.
    pub fn take(out: &Path, shard: Shard) -> Result<Claim> {
        let mut attempt = 0;
        loop {
            match Claim::try_take(out, shard) {
                // a run withdrawing from the folder removed it under this one: take it anew
                Err(Error::Io { source, .. })
                    if source.kind() == std::io::ErrorKind::NotFound && attempt < ATTEMPTS =>
                {
                    attempt += 1;
                }
                taken => return taken,
            }
        }
    }

    fn try_take(out: &Path, shard: Shard) -> Result<Claim> {
        // made again should a refused run that made it have removed it meanwhile
        match std::fs::create_dir(out) {
            Err(e) if e.kind() != std::io::ErrorKind::AlreadyExists => {
                return Err(Error::io(out)(e));
            }
            _ => {}
        }
        let dir = out.join(".motorfactory");
        plain_dir(&dir)?;
        let busy = |why: &str| {
            Error::Output(format!(
                "output folder {}: {why}; wait for it to end, or choose another --out",
                out.display()
            ))
        };
        let run_mode = if shard.count == 1 {
            Mode::Try
        } else {
            Mode::TryShared
        };
        let Some(run) = lock(&dir.join("run.lock"), run_mode)? else {
            return Err(busy(if shard.count == 1 {
                "another motorfactory run is writing into it"
            } else {
                "an unsharded motorfactory run is writing into it"
            }));
        };
        let shard_path = dir.join(format!("shard-{}-of-{}.lock", shard.part, shard.count));
        let Some(shard_lock) = lock(&shard_path, Mode::Try)? else {
            return Err(busy(&format!(
                "shard {}/{} is being made by another run",
                shard.part, shard.count
            )));
        };
        // made locked under another name, then renamed: a sweep never sees it unlocked
        let writers = dir.join("writers");
        plain_dir(&writers)?;
        let token = writer_token();
        let fresh = writers.join(format!("{token}.new"));
        let writer = open(&fresh)?;
        writer.lock().map_err(|e| lock_error(&fresh, e))?;
        let path = writers.join(format!("{token}.lock"));
        std::fs::rename(&fresh, &path).map_err(Error::io(&path))?;
        Ok(Claim {
            out: out.to_path_buf(),
            dir,
            run,
            shard: (shard_lock, shard_path),
            writer,
        })
    }

    /// Waits for the setup lock.
    pub(crate) fn setup(&self) -> Result<Setup> {
        let path = self.dir.join("setup.lock");
        let file = lock(&path, Mode::Wait)?.expect("a waiting lock is taken");
        Ok(Setup(file))
    }

    /// Removes the temporary files in `dirs` whose writers are recorded in `writers/` and gone
    /// (any run's, of any shard), and those writers' lock files. A temporary-like name without
    /// a recorded writer is not this program's and stays. Call under [`Claim::setup`].
    pub(crate) fn remove_stale_temporaries(&self, dirs: &[PathBuf]) -> Result<()> {
        let writers = self.dir.join("writers");
        let mut dead: HashMap<String, bool> = HashMap::new();
        let mut is_dead = |token: &str| -> Result<bool> {
            if token == writer_token() {
                return Ok(false);
            }
            if let Some(&known) = dead.get(token) {
                return Ok(known);
            }
            let lock = writers.join(format!("{token}.lock"));
            let is = is_file(&lock)? && !held(&lock)?;
            dead.insert(token.to_string(), is);
            Ok(is)
        };
        for dir in dirs {
            for (path, name) in files_in(dir)? {
                if let Some(token) = temporary_token(&name)
                    && is_dead(token)?
                {
                    remove(&path)?;
                }
            }
        }
        // the dead writers' lock files, and those a writer killed before its rename left
        for (path, name) in files_in(&writers)? {
            let token = name
                .strip_suffix(".lock")
                .or_else(|| name.strip_suffix(".new"));
            if token.is_some_and(|t| t != writer_token()) && is_file(&path)? && !held(&path)? {
                remove(&path)?;
            }
        }
        Ok(())
    }

    /// Releases the folder after a refused start, removing what this run made if it is alone
    /// in the folder: its lock files, then `.motorfactory/writers`, `.motorfactory`, the sample
    /// folders and the folder itself where each is then empty. Anything another run wrote,
    /// or a lock another run holds, keeps the folder.
    pub(crate) fn withdraw(self) {
        // alone: the run lock held exclusively (a shard's shared lock converted)
        if self.run.try_lock().is_err() {
            return;
        }
        let dir = self.dir.clone();
        let _ = unlink_held(&dir.join("run.lock"), &self.run);
        let _ = unlink_held(&self.shard.1, &self.shard.0);
        let setup = dir.join("setup.lock");
        if let Ok(Some(file)) = lock(&setup, Mode::Try) {
            let _ = unlink_held(&setup, &file);
        }
        let out = self.out.clone();
        drop(self);
        let samples = SAMPLE_FOLDERS.map(|f| out.join(f));
        for folder in [dir.join("writers"), dir].into_iter().chain(samples) {
            let _ = std::fs::remove_dir(folder);
        }
        let _ = std::fs::remove_dir(out);
    }
}

impl Drop for Claim {
    fn drop(&mut self) {
        let writers = self.dir.join("writers");
        let path = writers.join(format!("{}.lock", writer_token()));
        let _ = unlink_held(&path, &self.writer);
    }
}

/// Creates `path` as a folder unless it is one; refuses anything else at that name (a
/// symbolic link, even to a folder, or a file).
pub(crate) fn plain_dir(path: &Path) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(m) => Err(Error::Output(format!(
            "{} is not a plain folder (it is a {}); move it away or choose another --out",
            path.display(),
            if m.file_type().is_symlink() {
                "symbolic link"
            } else {
                "file"
            }
        ))),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => match std::fs::create_dir(path) {
            Err(e) if e.kind() != std::io::ErrorKind::AlreadyExists => Err(Error::io(path)(e)),
            _ => plain_dir_made(path),
        },
        Err(e) => Err(Error::io(path)(e)),
    }
}

/// Checks a folder just made (or made by another run at the same time) is a plain one.
fn plain_dir_made(path: &Path) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => plain_dir(path),
        Err(e) => Err(Error::io(path)(e)),
    }
}

/// Opens (creating) the lock file at `path`, never through a symbolic link.
fn open(path: &Path) -> Result<File> {
    let mut options = std::fs::OpenOptions::new();
    options.create(true).truncate(false).write(true);
    no_follow(&mut options);
    options.open(path).map_err(|e| refused_link(path, e))
}

/// Locks the lock file at `path` as `mode` says: None when it stays held for a moment (`Try`,
/// `TryShared`; a run withdrawing holds a lock for that long). Once locked, the file must still
/// be the one at `path` (a run holding it alone may have removed it meanwhile); else the new
/// one is locked.
fn lock(path: &Path, mode: Mode) -> Result<Option<File>> {
    let mut busy = 0;
    for _ in 0..ATTEMPTS {
        let file = open(path)?;
        let got = match mode {
            Mode::Try => file.try_lock(),
            Mode::TryShared => file.try_lock_shared(),
            Mode::Wait => file.lock().map_err(TryLockError::Error),
        };
        match got {
            Ok(()) if is_at(&file, path) => return Ok(Some(file)),
            Ok(()) => {}
            Err(TryLockError::WouldBlock) if busy + 1 < ATTEMPTS => {
                busy += 1;
                std::thread::sleep(std::time::Duration::from_millis(25));
            }
            Err(TryLockError::WouldBlock) => return Ok(None),
            Err(TryLockError::Error(e)) => return Err(lock_error(path, e)),
        }
    }
    Err(Error::Output(format!(
        "cannot lock {}: other runs keep removing it",
        path.display()
    )))
}

/// Whether `file` is the file at `path` (not a symbolic link to it).
fn is_at(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::symlink_metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Removes the lock file at `path` that `file`, locked by this run, is.
fn unlink_held(path: &Path, file: &File) -> std::io::Result<()> {
    if is_at(file, path) {
        std::fs::remove_file(path)
    } else {
        Ok(())
    }
}

/// Whether `path` is a regular file (not a symbolic link); false when missing.
fn is_file(path: &Path) -> Result<bool> {
    match std::fs::symlink_metadata(path) {
        Ok(m) => Ok(m.is_file()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(false),
        Err(e) => Err(Error::io(path)(e)),
    }
}

/// Whether a live process holds the lock file at `path` (a missing file is nobody's).
fn held(path: &Path) -> Result<bool> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true);
    no_follow(&mut options);
    let file = match options.open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(e) => return Err(refused_link(path, e)),
    };
    match file.try_lock() {
        Ok(()) => Ok(false),
        Err(TryLockError::WouldBlock) => Ok(true),
        Err(TryLockError::Error(e)) => Err(lock_error(path, e)),
    }
}

fn no_follow(options: &mut std::fs::OpenOptions) {
    use std::os::unix::fs::OpenOptionsExt;
    options.custom_flags(libc::O_NOFOLLOW);
}

/// The error of opening `path`, in words when it is a symbolic link.
fn refused_link(path: &Path, e: std::io::Error) -> Error {
    if e.raw_os_error() == Some(libc::ELOOP) {
        Error::Output(format!(
            "{} is a symbolic link; motorfactory's lock files are never followed through one: \
             remove it, or choose another --out",
            path.display()
        ))
    } else {
        Error::io(path)(e)
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
