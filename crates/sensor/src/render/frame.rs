//! A frame's paths: the pixels in tiles whose camera rays are cast together as one packet,
//! and, with light blocks ([`Settings::light_block`]), which pixel of each block traces the
//! block's light.

use glam::{Affine3A, Vec3};

use super::denoise::Guide;
use super::path::Scene;
use super::{CAMERA_DRAWS, Settings};
use crate::bvh::lanes;
use crate::camera::RayGrid;
use crate::noise::PixelRng;

/// Side of the square tiles of pixels whose camera rays are cast as one packet.
pub(super) const TILE: usize = 4;

/// A frame being rendered: the scene, the camera, and which pixels trace light.
pub(super) struct Frame<'a> {
    pub(super) scene: Scene<'a>,
    /// Camera to world.
    pub(super) pose: Affine3A,
    pub(super) rays: RayGrid,
    pub(super) width: usize,
    /// The camera's travel over the exposure, its frame.
    pub(super) motion: Vec3,
    /// Side of the light blocks (1: every pixel traces light).
    pub(super) block: usize,
    /// The pixel of each light block that traces its light ([`choices`]).
    pub(super) choices: Vec<usize>,
}

/// For each block of pixels `block` wide, row by row, the pixel (index into the frame) that
/// traces the block's light: drawn per block, among its pixels within the frame.
pub(super) fn choices(width: usize, height: usize, block: usize, seed: u64) -> Vec<usize> {
    let (across, down) = (width.div_ceil(block), height.div_ceil(block));
    (0..across * down)
        .map(|b| {
            let (left, top) = ((b % across) * block, (b / across) * block);
            let (w, h) = (block.min(width - left), block.min(height - top));
            let corner = (top * width + left) as u64;
            let draw = PixelRng::new(seed, corner * 65536).uniform(CAMERA_DRAWS + 3);
            let k = ((draw * (w * h) as f32) as usize).min(w * h - 1);
            (top + k / w) * width + left + k % w
        })
        .collect()
}

impl Frame<'_> {
    /// Renders the band of rows `band` (of [`TILE`] rows) into `out`, and, with the denoiser,
    /// their pixels' guides (`guides` as long as `out`; one placeholder without it). A pixel
    /// that traces no light gets only what its camera ray meets before any surface, and its
    /// guide.
    pub(super) fn band(&self, band: usize, out: &mut [[f32; 3]], guides: &mut [Option<Guide>]) {
        let (width, settings) = (self.width, &self.scene.settings);
        let rows = out.len() / width;
        let top = band * TILE;
        let world = self.scene.world;
        // the band's pixels that trace light
        let sparse = self.block > 1;
        let mut traces = vec![!sparse; out.len()];
        if sparse {
            let across = width.div_ceil(self.block);
            let band_pixels = top * width..(top + rows) * width;
            for by in top / self.block..=(top + rows - 1) / self.block {
                for &i in &self.choices[by * across..(by + 1) * across] {
                    if band_pixels.contains(&i) {
                        traces[i - band_pixels.start] = true;
                    }
                }
            }
        }
        for left in (0..width).step_by(TILE) {
            let mut sums = [[Vec3::ZERO; TILE]; TILE];
            for s in 0..settings.samples {
                let mut origins = [[Vec3::ZERO; TILE]; TILE];
                let mut dirs = [[Vec3::Z; TILE]; TILE];
                let mut t_max = [[0.0f32; TILE]; TILE];
                let mut rngs = [[PixelRng::new(0, 0); TILE]; TILE];
                for (g, lane) in lanes::<TILE>() {
                    let (r, c) = tile_pixel(g, lane);
                    let col = left + c;
                    // past the frame's edge, or a pixel that sees its surface once: an idle lane
                    if r >= rows || col >= width || (s > 0 && !traces[r * width + col]) {
                        continue;
                    }
                    let index = ((top + r) * width + col) as u64;
                    let rng = PixelRng::new(settings.seed, index * 65536 + u64::from(s));
                    rngs[g][lane] = rng;
                    let (u, v) = (
                        col as f64 - 0.5 + f64::from(rng.uniform(0)),
                        (top + r) as f64 - 0.5 + f64::from(rng.uniform(1)),
                    );
                    let (origin, dir) = camera_ray(self.rays.ray(u, v), settings, self.motion, rng);
                    origins[g][lane] = self.pose.transform_point3(origin);
                    dirs[g][lane] = self.pose.transform_vector3(dir).normalize();
                    t_max[g][lane] = f32::INFINITY;
                }
                let hits = world.cast_packet(&origins, &dirs, &t_max);
                for (g, lane) in lanes::<TILE>() {
                    if t_max[g][lane] == 0.0 {
                        continue;
                    }
                    let (r, c) = tile_pixel(g, lane);
                    let (origin, dir, i) = (origins[g][lane], dirs[g][lane], r * width + left + c);
                    let first = hits[g][lane].map(|h| world.surface(&h, origin, dir));
                    let (radiance, guide) = if traces[i] {
                        self.scene.path(origin, dir, first, rngs[g][lane])
                    } else {
                        self.scene.seen(origin, dir, first)
                    };
                    sums[r][c] += radiance;
                    if s == 0 && settings.denoise {
                        guides[i] = guide;
                    }
                }
            }
            for (r, c) in lanes::<TILE>() {
                if r < rows && left + c < width {
                    let i = r * width + left + c;
                    let paths = if traces[i] { settings.samples } else { 1 };
                    out[i] = (sums[r][c] / paths as f32).to_array();
                }
            }
        }
    }
}

/// The pixel (row, column in the tile) of lane `lane` of group `g`: each group of four lanes
/// a 2×2 square, whose rays run closer together than a row's.
#[inline]
fn tile_pixel(g: usize, lane: usize) -> (usize, usize) {
    (2 * (g / 2) + lane / 2, 2 * (g % 2) + lane % 2)
}

/// A camera ray in the camera's frame for the pinhole ray `pinhole` (unit): from a point of a
/// thin lens's aperture through the pinhole ray's point on the plane in focus, and from where
/// the camera is at a moment of the exposure.
#[inline]
fn camera_ray(pinhole: Vec3, settings: &Settings, motion: Vec3, rng: PixelRng) -> (Vec3, Vec3) {
    let mut origin = Vec3::ZERO;
    let mut dir = pinhole;
    if settings.aperture > 0.0 {
        // a uniform point of the aperture's disc
        let r = settings.aperture * rng.uniform(CAMERA_DRAWS).sqrt();
        let phi = std::f32::consts::TAU * rng.uniform(CAMERA_DRAWS + 1);
        let lens = Vec3::new(r * phi.cos(), r * phi.sin(), 0.0);
        let focused = pinhole * (settings.focus / pinhole.z);
        origin = lens;
        dir = (focused - lens).normalize();
    }
    if motion != Vec3::ZERO {
        origin += motion * (rng.uniform(CAMERA_DRAWS + 2) - 0.5);
    }
    (origin, dir)
}
