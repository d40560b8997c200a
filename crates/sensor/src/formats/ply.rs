//! Binary little-endian PLY.

use std::io::{Result, Write};

use super::write_rows;
use crate::cloud::PointCloud;

/// Writes `x y z nx ny nz intensity snr` (float), `red green blue` (uchar, sRGB), `class`
/// (uint16), `instance` (int: 32 bits, signed) and `wear` (float, the share of rust) per vertex.
/// The labels' types are those Open3D's tensor reader keeps (it skips `ushort` and `uint`);
/// a cloud with an instance id of 2³¹ or more declares `instance` as `uint` (the same bytes),
/// which keeps every id.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_ply(w: &mut dyn Write, c: &PointCloud) -> Result<()> {
    write_vertices(w, c, true)
}

/// As [`write_ply`], for points sampled on a surface rather than measured: `x y z nx ny nz`,
/// `red green blue`, `class` and `instance`, without the measurement's `intensity`, `snr` and
/// `wear`.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_surface_ply(w: &mut dyn Write, c: &PointCloud) -> Result<()> {
    write_vertices(w, c, false)
}

/// The header and the vertices, with the measurement's fields or without them.
fn write_vertices(w: &mut dyn Write, c: &PointCloud, measured: bool) -> Result<()> {
    header(w, c, measured)?;
    write_rows(w, 0..c.len(), |i, row| {
        let [x, y, z] = c.xyz[i].to_array();
        let [nx, ny, nz] = c.normal[i].to_array();
        // one vertex's bytes, gathered in a fixed record and copied into the row at once
        let mut record = [0u8; 45];
        let mut at = 0;
        let mut put = |bytes: &[u8]| {
            record[at..at + bytes.len()].copy_from_slice(bytes);
            at += bytes.len();
        };
        put([x, y, z, nx, ny, nz].map(f32::to_le_bytes).as_flattened());
        if measured {
            put([c.intensity[i], c.snr[i]]
                .map(f32::to_le_bytes)
                .as_flattened());
        }
        put(&c.rgb[i]);
        put(&c.class[i].to_le_bytes());
        put(&c.instance[i].to_le_bytes());
        if measured {
            put(&c.wear[i].to_le_bytes());
        }
        row.extend_from_slice(&record[..at]);
        Ok(())
    })
}

/// The header of a cloud's vertices, with the measurement's fields or without them.
fn header(w: &mut dyn Write, c: &PointCloud, measured: bool) -> Result<()> {
    let instance = if c.instance.iter().any(|&i| i32::try_from(i).is_err()) {
        "uint"
    } else {
        "int"
    };
    let (what, signal, wear) = if measured {
        (
            "scan",
            "property float intensity\nproperty float snr\n",
            "property float wear\n",
        )
    } else {
        ("surface samples", "", "")
    };
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment motorfactory {what}\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n\
         property float nz\n{signal}property uchar red\nproperty uchar green\nproperty uchar blue\n\
         property uint16 class\nproperty {instance} instance\n{wear}end_header\n",
        c.len()
    )
}
