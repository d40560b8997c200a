//! Binary little-endian PLY with per-face semantic class and instance.

use std::io::{Result, Write};

use crate::labels::Scheme;
use crate::model::Part;

/// Writes parts as one PLY: vertices `x y z` (float), faces `vertex_indices` (uchar count, int
/// indices), `class` (uchar, the SynMotor 7-class id), `part_class` (uchar, [`PartKind`] order)
/// and `instance` (int).
///
/// [`PartKind`]: crate::PartKind
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) when writing to `w` fails.
pub fn write_ply(w: &mut dyn Write, parts: &[&Part]) -> Result<()> {
    let vertices: usize = parts.iter().map(|p| p.mesh.positions.len()).sum();
    let faces: usize = parts.iter().map(|p| p.mesh.triangle_count()).sum();
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment motorfactory motor mesh, metres\n\
         comment class: SynMotor 7-class id; part_class: motorgen part kind\n\
         element vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {faces}\nproperty list uchar int vertex_indices\nproperty uchar class\n\
         property uchar part_class\nproperty int instance\nend_header\n"
    )?;
    for p in parts {
        for v in &p.mesh.positions {
            for x in v.to_array() {
                w.write_all(&x.to_le_bytes())?;
            }
        }
    }
    let mut base = 0u32;
    for p in parts {
        let class = Scheme::SynMotor.id(p.kind);
        let kind = p.kind as u8;
        for t in &p.mesh.triangles {
            w.write_all(&[3])?;
            for i in t {
                w.write_all(&((i + base) as i32).to_le_bytes())?;
            }
            w.write_all(&[class, kind])?;
            w.write_all(&(p.instance as i32).to_le_bytes())?;
        }
        base += p.mesh.positions.len() as u32;
    }
    Ok(())
}
