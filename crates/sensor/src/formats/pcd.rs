//! PCD v0.7, as PCL writes it: binary or ASCII, with PCL's `label` field.

use std::io::{Result, Write};

use super::write_rows;
use crate::cloud::PointCloud;

/// Writes fields `x y z normal_x normal_y normal_z intensity snr` (F4), `rgb` (F4 holding the sRGB
/// bytes as `0x00RRGGBB`, PCL's packing), `label` (U4, the class), `instance` (U4) and `wear`
/// (F4, the share of rust), as an unorganized cloud (HEIGHT 1).
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_pcd(w: &mut dyn Write, c: &PointCloud, binary: bool) -> Result<()> {
    write!(
        w,
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n\
         FIELDS x y z normal_x normal_y normal_z intensity snr rgb label instance wear\n\
         SIZE 4 4 4 4 4 4 4 4 4 4 4 4\nTYPE F F F F F F F F F U U F\nCOUNT 1 1 1 1 1 1 1 1 1 1 1 1\n\
         WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {}\n",
        if binary { "binary" } else { "ascii" },
        n = c.len()
    )?;
    write_rows(w, 0..c.len(), |i, row| {
        let [x, y, z] = c.xyz[i].to_array();
        let [nx, ny, nz] = c.normal[i].to_array();
        let (intensity, snr) = (c.intensity[i], c.snr[i]);
        let (label, instance, wear) = (c.class[i] as u32, c.instance[i], c.wear[i]);
        let [r, g, b] = c.rgb[i].map(u32::from);
        let rgb = (r << 16) | (g << 8) | b;
        if binary {
            let [x, y, z, nx, ny, nz, intensity, snr] =
                [x, y, z, nx, ny, nz, intensity, snr].map(f32::to_bits);
            let wear = wear.to_bits();
            let words = [
                x, y, z, nx, ny, nz, intensity, snr, rgb, label, instance, wear,
            ];
            row.extend_from_slice(words.map(u32::to_le_bytes).as_flattened());
            Ok(())
        } else {
            writeln!(
                row,
                "{x} {y} {z} {nx} {ny} {nz} {intensity} {snr} {rgb_float:e} {label} {instance} {wear}",
                rgb_float = f32::from_bits(rgb)
            )
        }
    })
}
