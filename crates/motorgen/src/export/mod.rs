//! Mesh export: OBJ with MTL, binary STL, binary PLY with per-face labels, and glTF binary, per
//! part and for the whole motor, plus the ground truth as JSON and CSV.
//!
//! The writers of these simple formats are hand-written streams (a few lines each, no
//! intermediate copies); the tests read every file back with an independent reader crate.

mod attributes;
mod glb;
mod obj;
mod ply;
mod stl;

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use attributes::{csv_header, csv_row, motor_json};
pub use glb::write_glb;
pub use obj::{write_mtl, write_obj};
pub use ply::write_ply;
pub use stl::write_stl;

use crate::model::{Motor, Part, PartKind};
use crate::{Error, Result};

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// Wavefront OBJ with an MTL of the add-on's materials.
    Obj,
    /// Binary STL.
    Stl,
    /// Binary little-endian PLY with per-face `class` and `instance`.
    Ply,
    /// glTF 2.0 binary, one named node per part.
    Glb,
}

impl Format {
    /// All formats.
    pub const ALL: [Format; 4] = [Format::Obj, Format::Stl, Format::Ply, Format::Glb];

    /// File extension.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Stl => "stl",
            Format::Ply => "ply",
            Format::Glb => "glb",
        }
    }

    /// Parses a format name.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a name other than `obj`, `stl`, `ply` or
    /// `glb`.
    pub fn parse(name: &str) -> Result<Format> {
        Format::ALL
            .into_iter()
            .find(|f| f.extension() == name)
            .ok_or_else(|| Error::Invalid {
                key: "format".into(),
                value: format!("\"{name}\""),
                allowed: "obj, stl, ply or glb".into(),
            })
    }
}

/// Writes `motor` into `dir`: for each format the whole motor (`motor.<ext>`) and, when
/// `per_part`, each part (`<part name>.<ext>`); plus `attributes.json`. Every file is written to
/// a temporary name and renamed, so a crash never leaves half a file. Returns the paths written.
///
/// # Example
///
/// ```
/// use motorgen::{Detail, Format, MotorParams, build, export::write_motor};
///
/// let motor = build(&MotorParams::default(), Detail::Coarse);
/// let dir = std::env::temp_dir().join("write-motor-doc-example");
/// let files = write_motor(&motor, &dir, &[Format::Obj, Format::Ply], true)?;
/// // the whole motor and every part in each format, the OBJ materials and the ground truth
/// assert_eq!(files.len(), 2 * (1 + motor.parts.len()) + 2);
/// # Ok::<(), motorgen::Error>(())
/// ```
///
/// # Errors
///
/// [`Error::Io`], naming the path, when the folder cannot be made or a file
/// cannot be written.
pub fn write_motor(
    motor: &Motor,
    dir: &Path,
    formats: &[Format],
    per_part: bool,
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(Error::io(dir))?;
    let mut written = Vec::new();
    let mut save =
        |name: String, body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>| -> Result<()> {
            let path = dir.join(name);
            write_atomic(&path, body)?;
            written.push(path);
            Ok(())
        };
    let everything: Vec<&Part> = motor.parts.iter().collect();
    for &format in formats {
        let ext = format.extension();
        let mut groups: Vec<(String, Vec<&Part>)> = vec![("motor".into(), everything.clone())];
        if per_part {
            groups.extend(motor.parts.iter().map(|p| (p.name.clone(), vec![p])));
        }
        for (stem, parts) in &groups {
            save(format!("{stem}.{ext}"), &|w| match format {
                Format::Obj => write_obj(w, parts, Some("materials.mtl")),
                Format::Stl => write_stl(w, parts),
                Format::Ply => write_ply(w, parts),
                Format::Glb => write_glb(w, parts),
            })?;
        }
        if format == Format::Obj {
            save("materials.mtl".into(), &|w| write_mtl(w))?;
        }
    }
    save("attributes.json".into(), &|w| {
        serde_json::to_writer_pretty(&mut *w, &motor_json(motor))?;
        w.write_all(b"\n")
    })?;
    Ok(written)
}

/// What an earlier `motor` (`many` false: the mesh files this program names, `motor.{ext}` and
/// a part's `{name}.{ext}` in every mesh format, `materials.mtl` and `attributes.json`) or
/// `motors` (`attributes.csv` and the `motor_NNNNNN` folders) wrote in `out`: plain files and
/// folders only, found by the names this program writes (never names read from a file).
///
/// # Errors
///
/// [`Error::Parse`] when `out` holds an `attributes.json` that is not a motor's.
pub fn earlier_output(out: &Path, many: bool) -> Result<Vec<PathBuf>> {
    let entries = || {
        std::fs::read_dir(out)
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|e| {
                let kind = e.file_type().ok()?;
                let name = e.file_name().into_string().ok()?;
                Some((e.path(), name, kind))
            })
    };
    let mut found = Vec::new();
    if many {
        for (path, name, kind) in entries() {
            let numbered = name
                .strip_prefix("motor_")
                .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
            if (name == "attributes.csv" && kind.is_file()) || (numbered && kind.is_dir()) {
                found.push(path);
            }
        }
        found.sort();
        return Ok(found);
    }
    let json = out.join("attributes.json");
    let Ok(text) = std::fs::read_to_string(&json) else {
        return Ok(found);
    };
    if serde_json::from_str::<serde_json::Value>(&text).is_err() {
        return Err(Error::Parse(format!(
            "{} is not a motor's: choose another folder",
            json.display()
        )));
    }
    for (path, name, kind) in entries() {
        let ours = match name.rsplit_once('.') {
            _ if name == "materials.mtl" || name == "attributes.json" => true,
            Some((stem, ext)) => {
                Format::ALL.iter().any(|f| f.extension() == ext)
                    && (stem == "motor" || PartKind::is_file_stem(stem))
            }
            None => false,
        };
        if ours && kind.is_file() {
            found.push(path);
        }
    }
    found.sort();
    Ok(found)
}

/// This process's token in temporary file names: 16 hex digits drawn from the operating
/// system's randomness once per process, so writers on other hosts or in other PID namespaces
/// (where process ids repeat) never pick the same temporary name.
pub fn writer_token() -> &'static str {
    static TOKEN: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TOKEN.get_or_init(|| {
        use std::hash::{BuildHasher, RandomState};
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let token = RandomState::new().hash_one((std::process::id(), now));
        format!("{token:016x}")
    })
}

/// The writer token of a temporary file name `{name}.{token}.tmp` that [`write_atomic`] makes.
pub fn temporary_token(file_name: &str) -> Option<&str> {
    let stem = file_name.strip_suffix(".tmp")?;
    let (_, token) = stem.rsplit_once('.')?;
    (token.len() == 16 && token.bytes().all(|b| b.is_ascii_hexdigit())).then_some(token)
}

/// Writes a file through a buffered temporary file in the same folder, then renames it: a killed
/// process leaves the old file or the new one, never a part. (No fsync: that would add
/// power-loss durability at about thirty times the cost of a motor's files.) The temporary file
/// is `{name}.{token}.tmp` with this process's [`writer_token`].
///
/// # Errors
///
/// [`Error::Io`], naming `path`, when the temporary file cannot be made, `body`
/// fails, or the rename fails; the temporary file is removed.
pub fn write_atomic(
    path: &Path,
    body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(format!(".{}.tmp", writer_token()));
    let tmp = path.with_file_name(name);
    let result = (|| {
        let mut w = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        body(&mut w)?;
        w.into_inner().map_err(|e| e.into_error())?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path)(e)
    })
}
