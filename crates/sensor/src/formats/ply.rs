//! Binary little-endian PLY.

use std::io::{Result, Write};

use super::write_rows;
use crate::cloud::PointCloud;

/// Writes `x y z nx ny nz intensity snr` (float), `red green blue` (uchar, sRGB), `class` (ushort),
/// `instance` (uint) and `wear` (float, the share of rust) per vertex.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_ply(w: &mut dyn Write, c: &PointCloud) -> Result<()> {
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment motorfactory scan\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n\
         property float nz\nproperty float intensity\nproperty float snr\nproperty uchar red\nproperty uchar green\n\
         property uchar blue\nproperty ushort class\nproperty uint instance\nproperty float wear\nend_header\n",
        c.len()
    )?;
    write_rows(w, 0..c.len(), |i, row| {
        let [x, y, z] = c.xyz[i].to_array();
        let [nx, ny, nz] = c.normal[i].to_array();
        let floats = [x, y, z, nx, ny, nz, c.intensity[i], c.snr[i]].map(f32::to_le_bytes);
        let mut record = [0u8; 45];
        record[..32].copy_from_slice(floats.as_flattened());
        record[32..35].copy_from_slice(&c.rgb[i]);
        record[35..37].copy_from_slice(&c.class[i].to_le_bytes());
        record[37..41].copy_from_slice(&c.instance[i].to_le_bytes());
        record[41..].copy_from_slice(&c.wear[i].to_le_bytes());
        row.extend_from_slice(&record);
        Ok(())
    })
}
