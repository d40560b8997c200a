//! Wavefront OBJ and MTL.

use std::io::{Result, Write};

use crate::model::{MATERIALS, Part};

/// Writes parts as one OBJ, an `o` object per part with its material; `mtllib` names the MTL.
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) when writing to `w` fails.
pub fn write_obj(w: &mut dyn Write, parts: &[&Part], mtllib: Option<&str>) -> Result<()> {
    writeln!(w, "# motorfactory motor mesh, metres")?;
    if let Some(lib) = mtllib {
        writeln!(w, "mtllib {lib}")?;
    }
    let mut base = 1;
    for p in parts {
        writeln!(w, "o {}", p.name)?;
        writeln!(w, "usemtl {}", p.kind.material().name)?;
        for v in &p.mesh.positions {
            writeln!(w, "v {} {} {}", v.x, v.y, v.z)?;
        }
        for t in &p.mesh.triangles {
            writeln!(w, "f {} {} {}", t[0] + base, t[1] + base, t[2] + base)?;
        }
        base += p.mesh.positions.len() as u32;
    }
    Ok(())
}

/// Writes the add-on's materials as an MTL (diffuse colour; metalness and roughness as the PBR
/// extension keys `Pm` and `Pr`).
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) when writing to `w` fails.
pub fn write_mtl(w: &mut dyn Write) -> Result<()> {
    for m in MATERIALS {
        let [r, g, b, a] = m.base_color;
        writeln!(
            w,
            "newmtl {}\nKd {r} {g} {b}\nd {a}\nPm {}\nPr {}\n",
            m.name, m.metallic, m.roughness
        )?;
    }
    Ok(())
}
