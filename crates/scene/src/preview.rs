//! Previews: a labelled cloud drawn from its camera's view in class colours, shaded by depth,
//! and contact sheets of several previews.

use std::io::Write;

use glam::Vec3;
use sensor::Intrinsics;

/// An 8-bit RGB image.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Row-major RGB bytes.
    pub rgb: Vec<u8>,
}

/// Background of previews and sheets.
const BACKGROUND: [u8; 3] = [24, 24, 28];

impl Image {
    /// A blank image.
    pub fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            rgb: BACKGROUND.repeat((width * height) as usize),
        }
    }

    /// Writes the image as PNG.
    ///
    /// # Errors
    ///
    /// Any error of writing to `w`.
    pub fn write_png(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let mut encoder = png::Encoder::new(w, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(&self.rgb)
            .map_err(std::io::Error::other)
    }
}

/// Draws `points` (camera frame, metres) with their `colors` as the camera `k` sees them, scaled
/// to `width` columns: nearest point wins, 2×2 splats, nearer points brighter.
pub fn render(points: &[Vec3], colors: &[[u8; 3]], k: &Intrinsics, width: u32) -> Image {
    let s = width as f64 / k.width as f64;
    let height = ((k.height as f64 * s).round() as u32).max(1);
    let mut image = Image::new(width, height);
    let mut depth = vec![f32::INFINITY; (width * height) as usize];
    let (near, far) = points.iter().fold((f32::INFINITY, 0.0f32), |(a, b), p| {
        (a.min(p.z), b.max(p.z))
    });
    let span = (far - near).max(1e-6);
    for (p, c) in points.iter().zip(colors) {
        let Some((u, v)) = k.project(*p) else {
            continue;
        };
        let (u, v) = ((u * s) as i64, (v * s) as i64);
        let shade = 1.0 - 0.55 * (p.z - near) / span;
        for (du, dv) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (x, y) = (u + du, v + dv);
            if x < 0 || y < 0 || x >= width as i64 || y >= height as i64 {
                continue;
            }
            let i = (y as u32 * width + x as u32) as usize;
            if p.z < depth[i] {
                depth[i] = p.z;
                for (dst, &src) in image.rgb[3 * i..3 * i + 3].iter_mut().zip(c) {
                    *dst = (src as f32 * shade).round() as u8;
                }
            }
        }
    }
    image
}

/// The images in a grid of `columns`, each cell as large as the largest image.
pub fn contact_sheet(images: &[Image], columns: usize) -> Image {
    let columns = columns.clamp(1, images.len().max(1));
    let rows = images.len().div_ceil(columns).max(1);
    let (cw, ch) = images
        .iter()
        .fold((1, 1), |(w, h), i| (w.max(i.width), h.max(i.height)));
    let gap = 4;
    let mut sheet = Image::new(
        columns as u32 * (cw + gap) + gap,
        rows as u32 * (ch + gap) + gap,
    );
    for (n, img) in images.iter().enumerate() {
        let (x0, y0) = (
            gap + (n % columns) as u32 * (cw + gap),
            gap + (n / columns) as u32 * (ch + gap),
        );
        for y in 0..img.height {
            let src = (y * img.width * 3) as usize;
            let dst = (((y0 + y) * sheet.width + x0) * 3) as usize;
            let len = (img.width * 3) as usize;
            sheet.rgb[dst..dst + len].copy_from_slice(&img.rgb[src..src + len]);
        }
    }
    sheet
}
