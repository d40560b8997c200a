//! PNG images of a scan.

use std::io::{Result, Write};

use crate::scan::Scan;

/// Depth PNG unit: one 16-bit step is 0.1 mm, so 0..6.5535 m; 0 means no data.
pub const DEPTH_PNG_METRES_PER_UNIT: f32 = 1e-4;

fn png(
    w: &mut dyn Write,
    scan: &Scan,
    color: png::ColorType,
    depth: png::BitDepth,
    data: &[u8],
) -> Result<()> {
    png_sized(w, (scan.width, scan.height), color, depth, data)
}

fn png_sized(
    w: &mut dyn Write,
    (width, height): (u32, u32),
    color: png::ColorType,
    depth: png::BitDepth,
    data: &[u8],
) -> Result<()> {
    let mut e = png::Encoder::new(w, width, height);
    // fdeflate: several times faster than the default level, files a little larger
    e.set_compression(png::Compression::Fast);
    e.set_color(color);
    e.set_depth(depth);
    let mut writer = e.write_header().map_err(std::io::Error::other)?;
    writer.write_image_data(data).map_err(std::io::Error::other)
}

/// A 16-bit grey PNG of one value per pixel (PNG stores them big-endian).
fn grey16(w: &mut dyn Write, scan: &Scan, values: impl Iterator<Item = u16>) -> Result<()> {
    let data: Vec<u8> = values.flat_map(u16::to_be_bytes).collect();
    png(
        w,
        scan,
        png::ColorType::Grayscale,
        png::BitDepth::Sixteen,
        &data,
    )
}

/// 16-bit grey depth (camera z) in steps of [`DEPTH_PNG_METRES_PER_UNIT`]; `clean` uses the
/// exact depth instead of the measured one.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_depth_png(w: &mut dyn Write, scan: &Scan, clean: bool) -> Result<()> {
    let depth = scan.pixels.iter().map(|p| {
        let z = if clean { p.clean.z } else { p.point.z };
        if z.is_nan() {
            0
        } else {
            (z / DEPTH_PNG_METRES_PER_UNIT).round().clamp(1.0, 65535.0) as u16
        }
    });
    grey16(w, scan, depth)
}

/// An 8-bit grey mask of `width` × `height`: 255 where `inside(x, y)`, else 0.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_mask_png(
    w: &mut dyn Write,
    (width, height): (u32, u32),
    inside: &dyn Fn(usize, usize) -> bool,
) -> Result<()> {
    let data: Vec<u8> = (0..height as usize)
        .flat_map(|y| (0..width as usize).map(move |x| (x, y)))
        .map(|(x, y)| if inside(x, y) { 255 } else { 0 })
        .collect();
    png_sized(
        w,
        (width, height),
        png::ColorType::Grayscale,
        png::BitDepth::Eight,
        &data,
    )
}

/// 8-bit RGB normals, (n + 1) / 2 · 255 in the camera frame; black where nothing was hit.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_normal_png(w: &mut dyn Write, scan: &Scan) -> Result<()> {
    let data: Vec<u8> = scan
        .pixels
        .iter()
        .flat_map(|p| {
            if p.normal.x.is_nan() {
                [0; 3]
            } else {
                p.normal
                    .to_array()
                    .map(|c| ((c + 1.0) * 127.5).round() as u8)
            }
        })
        .collect();
    png(w, scan, png::ColorType::Rgb, png::BitDepth::Eight, &data)
}

/// 16-bit grey labels: the class (or, with `instance`, the instance id) of each pixel's surface.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_label_png(w: &mut dyn Write, scan: &Scan, instance: bool) -> Result<()> {
    let labels = scan.pixels.iter().map(|p| {
        if instance {
            p.instance.min(65535) as u16
        } else {
            p.class
        }
    });
    grey16(w, scan, labels)
}

/// 8-bit grey signal strength, clamped to 0..1; 0 where no point.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_intensity_png(w: &mut dyn Write, scan: &Scan) -> Result<()> {
    let data: Vec<u8> = scan
        .pixels
        .iter()
        .map(|p| {
            if p.is_valid() {
                (p.intensity.clamp(0.0, 1.0) * 255.0).round() as u8
            } else {
                0
            }
        })
        .collect();
    png(
        w,
        scan,
        png::ColorType::Grayscale,
        png::BitDepth::Eight,
        &data,
    )
}

/// The camera's colour image: 8-bit sRGB of every pixel, black where it sees no surface (see
/// [`ColourCamera`](crate::ColourCamera)); a point's rgb is its pixel's.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_rgb_png(w: &mut dyn Write, scan: &Scan) -> Result<()> {
    let data: Vec<u8> = scan.pixels.iter().flat_map(|p| p.rgb).collect();
    png(w, scan, png::ColorType::Rgb, png::BitDepth::Eight, &data)
}

/// The camera's colour image as a baseline JPEG of `quality` (1 to 100; 4:2:0 chroma), as
/// [`write_rgb_png`] holds it losslessly.
///
/// # Errors
///
/// Any error of writing to `w`, and a size JPEG cannot hold (above 65535 pixels a side).
pub fn write_rgb_jpeg(w: &mut dyn Write, scan: &Scan, quality: u8) -> Result<()> {
    let data: Vec<u8> = scan.pixels.iter().flat_map(|p| p.rgb).collect();
    let size = |n: u32| u16::try_from(n).map_err(std::io::Error::other);
    let mut bytes = Vec::new();
    jpeg_encoder::Encoder::new(&mut bytes, quality.clamp(1, 100))
        .encode(
            &data,
            size(scan.width)?,
            size(scan.height)?,
            jpeg_encoder::ColorType::Rgb,
        )
        .map_err(std::io::Error::other)?;
    w.write_all(&bytes)
}

/// 8-bit grey share of rust, 0..1 as 0..255, on the surface each pixel's centre ray meets.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_wear_png(w: &mut dyn Write, scan: &Scan) -> Result<()> {
    let data: Vec<u8> = scan.pixels.iter().map(|p| p.wear).collect();
    png(
        w,
        scan,
        png::ColorType::Grayscale,
        png::BitDepth::Eight,
        &data,
    )
}
