//! Binary STL.

use std::io::{Result, Write};

use crate::model::Part;

/// Writes parts as one binary STL with facet normals.
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) when writing to `w` fails.
pub fn write_stl(w: &mut dyn Write, parts: &[&Part]) -> Result<()> {
    let mut header = [0u8; 80];
    let title = b"motorfactory motor mesh, metres";
    header[..title.len()].copy_from_slice(title);
    w.write_all(&header)?;
    let count: usize = parts.iter().map(|p| p.mesh.triangle_count()).sum();
    w.write_all(&(count as u32).to_le_bytes())?;
    for p in parts {
        for t in &p.mesh.triangles {
            let [a, b, c] = t.map(|i| p.mesh.positions[i as usize]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            for v in [n, a, b, c] {
                for x in v.to_array() {
                    w.write_all(&x.to_le_bytes())?;
                }
            }
            w.write_all(&[0, 0])?;
        }
    }
    Ok(())
}
