//! NumPy `.npy` (format 1.0) and `.npz` (a stored zip of `.npy` files).

use std::io::{Cursor, Result, Write};

use super::write_rows;
use crate::cloud::PointCloud;

/// Writes an NPY header for a C-order array of `dtype` (e.g. `<f4`) and `shape`.
fn header(w: &mut dyn Write, dtype: &str, shape: &[usize]) -> Result<()> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let tuple = if dims.len() == 1 {
        format!("({},)", dims[0])
    } else {
        format!("({})", dims.join(", "))
    };
    let mut dict = format!("{{'descr': '{dtype}', 'fortran_order': False, 'shape': {tuple}, }}");
    // magic (6) + version (2) + length (2) + dict + newline, padded to a multiple of 64
    let total = (10 + dict.len() + 1).next_multiple_of(64);
    dict.push_str(&" ".repeat(total - 10 - dict.len() - 1));
    dict.push('\n');
    w.write_all(b"\x93NUMPY\x01\x00")?;
    w.write_all(&(dict.len() as u16).to_le_bytes())?;
    w.write_all(dict.as_bytes())
}

/// Writes an NPY array of little-endian values.
pub(super) fn array<T: Copy, const N: usize>(
    w: &mut dyn Write,
    dtype: &str,
    shape: &[usize],
    values: impl Iterator<Item = T>,
    bytes: impl Fn(T) -> [u8; N],
) -> Result<()> {
    header(w, dtype, shape)?;
    write_rows(w, values, |v, row| {
        row.extend_from_slice(&bytes(v));
        Ok(())
    })
}

/// Writes a 1-D NPY array of int32 `values`.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_npy_i32(w: &mut dyn Write, values: &[i32]) -> Result<()> {
    array(
        w,
        "<i4",
        &[values.len()],
        values.iter().copied(),
        i32::to_le_bytes,
    )
}

/// Writes the SynMotor training layout: float32 N×7 `x y z r g b label`, the points' colours
/// 0..1.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_npy_synmotor(w: &mut dyn Write, c: &PointCloud) -> Result<()> {
    let rows = (0..c.len()).flat_map(|i| {
        let rgb = c.rgb[i].map(|x| x as f32 / 255.0);
        let p = c.xyz[i];
        [p.x, p.y, p.z, rgb[0], rgb[1], rgb[2], c.class[i] as f32]
    });
    array(w, "<f4", &[c.len(), 7], rows, f32::to_le_bytes)
}

/// Writes an NPZ with arrays `xyz` (N×3 float32), `normal` (N×3 float32), `intensity` (N
/// float32), `snr` (N float32), `rgb` (N×3 uint8, sRGB), `label` (N uint16, the class), `instance` (N
/// uint32) and `wear` (N float32, the share of rust). Entries are stored uncompressed with a fixed timestamp, so the bytes are
/// reproducible.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_npz(w: &mut dyn Write, c: &PointCloud) -> Result<()> {
    let n = c.len();
    npz(
        w,
        n * 12,
        &[
            ("xyz", &|w| vec3s(w, &c.xyz)),
            ("normal", &|w| vec3s(w, &c.normal)),
            ("intensity", &|w| f32s(w, &c.intensity)),
            ("snr", &|w| f32s(w, &c.snr)),
            ("rgb", &|w| rgbs(w, &c.rgb)),
            ("label", &|w| {
                array(w, "<u2", &[n], c.class.iter().copied(), u16::to_le_bytes)
            }),
            ("instance", &|w| {
                array(w, "<u4", &[n], c.instance.iter().copied(), u32::to_le_bytes)
            }),
            ("wear", &|w| f32s(w, &c.wear)),
        ],
    )
}

/// An NPZ entry: its array's name and the writer of its NPY.
pub(super) type Entry<'a> = (&'a str, &'a dyn Fn(&mut dyn Write) -> Result<()>);

/// Writes an NPZ of `entries`, stored uncompressed with a fixed timestamp so that the bytes are
/// reproducible; `largest` is the largest entry's size in bytes (ZIP64 past 2 GiB).
pub(super) fn npz(w: &mut dyn Write, largest: usize, entries: &[Entry<'_>]) -> Result<()> {
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .last_modified_time(zip::DateTime::default())
        .large_file(largest > u32::MAX as usize / 2);
    for (name, body) in entries {
        zip.start_file(format!("{name}.npy"), options)
            .map_err(std::io::Error::other)?;
        body(&mut zip)?;
    }
    let bytes = zip.finish().map_err(std::io::Error::other)?.into_inner();
    w.write_all(&bytes)
}

/// Writes an N×3 float32 NPY of `v`.
pub(super) fn vec3s(w: &mut dyn Write, v: &[glam::Vec3]) -> Result<()> {
    let components = v.iter().flat_map(|p| p.to_array());
    array(w, "<f4", &[v.len(), 3], components, f32::to_le_bytes)
}

/// Writes an N float32 NPY of `v`.
pub(super) fn f32s(w: &mut dyn Write, v: &[f32]) -> Result<()> {
    array(w, "<f4", &[v.len()], v.iter().copied(), f32::to_le_bytes)
}

/// Writes an N×3 uint8 NPY of colours.
pub(super) fn rgbs(w: &mut dyn Write, v: &[[u8; 3]]) -> Result<()> {
    array(w, "|u1", &[v.len(), 3], v.iter().flatten().copied(), |v| {
        [v]
    })
}

/// Writes a float32 H×W depth image in metres (z in the camera frame), NaN where no data.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_depth_npy(
    w: &mut dyn Write,
    width: usize,
    height: usize,
    depth: impl Iterator<Item = f32>,
) -> Result<()> {
    array(w, "<f4", &[height, width], depth, f32::to_le_bytes)
}
