//! Scanning: one organized H×W grid of returns per scan, in the camera frame.
//!
//! A scan is made in steps, a module each: [`region`] limits the pixels cast to those
//! that can see a region; `cast` finds each pixel's first surface and the projector's shadows,
//! along one of two paths (rows cut in their epipolar planes, or blocks of rays cast as packets
//! through the BVH); `light` labels a pixel and decides its signal and losses; `measure` turns a
//! lit pixel into a point with noise and makes the neighbour effects (mixed pixels, the Kinect
//! window); `mirror` finds the light a shiny surface mirrors into a pixel, `diffuse` the light
//! the surfaces around it send it, `wings` the light of a pixel's neighbours near edges, and
//! `decode` decodes a pixel's stripes from such mixed light; `filters` applies Zivid's
//! point-cloud filters.

mod cast;
mod colour;
mod decode;
mod diffuse;
mod filters;
mod light;
mod measure;
mod mirror;
pub mod region;
mod wings;

use std::ops::Range;

use glam::{Affine3A, Vec3};
use rayon::prelude::*;

use crate::spec::{Model, SensorSpec};
use crate::world::World;

#[cfg(test)]
pub(crate) use cast::gap;
use cast::{BLOCK, Band, Capture};
use diffuse::Diffuse;
use measure::{mixed_pixels, window_filter};
pub use region::{Region, Window};

/// One pixel of a scan, in the camera frame (x right, y down, z forward), metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pixel {
    /// The measured point, noise included; NaN where the sensor returns nothing.
    pub point: Vec3,
    /// The exact surface point on the pixel's centre ray; NaN where that ray hits nothing.
    pub clean: Vec3,
    /// Unit normal of the surface the point (or, without a point, the clean point) lies on.
    pub normal: Vec3,
    /// Semantic class of that surface (0 where nothing was hit).
    pub class: u16,
    /// Instance id of that surface (0 where nothing was hit).
    pub instance: u32,
    /// Signal strength: reflectivity × cos(incidence of the light) × (reference / range)², plus
    /// a shiny surface's highlight; 0 where the pixel's surface is not lit (a projector's
    /// shadow, or no surface).
    pub intensity: f32,
    /// Colour as the camera's colour image records it at this pixel, sRGB: the surface its
    /// centre ray meets, with or without a point (black where it meets none).
    pub rgb: [u8; 3],
    /// Signal-to-noise ratio of the decoded pattern, 0 to 255 as Zivid's (0 where the pixel's
    /// surface is not lit, or the sensor has no SNR model).
    pub snr: f32,
    /// Angle between the surface normal and the direction to the camera, radians.
    pub incidence: f32,
    /// Share of rust on the surface the centre ray meets, 0..255 for 0..1 (0 where it meets
    /// none): a byte, which keeps a pixel within 60 bytes.
    pub wear: u8,
    /// Share of the light the pixel decoded that came from other surfaces (mirrored, bounced
    /// or blurred in), as its patterns show it (the finest stripes' modulation against the
    /// coarsest pattern's), 0..255 for 0..1: 0 where all of it is its own surface's.
    pub indirect: u8,
}

impl Pixel {
    /// A pixel that saw nothing.
    pub const EMPTY: Pixel = Pixel {
        point: Vec3::NAN,
        clean: Vec3::NAN,
        normal: Vec3::NAN,
        class: 0,
        instance: 0,
        intensity: 0.0,
        rgb: [0; 3],
        snr: 0.0,
        incidence: f32::NAN,
        wear: 0,
        indirect: 0,
    };

    /// Whether the sensor returned a point.
    pub fn is_valid(&self) -> bool {
        !self.point.x.is_nan()
    }
}

/// An organized scan. (`Scan::default()` has no pixels: a buffer for [`scan_reusing`] to grow.)
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scan {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Row-major pixels.
    pub pixels: Vec<Pixel>,
    /// Camera-to-world pose of the scan.
    pub pose: Affine3A,
    /// The pixels that can see a surface: the whole image, or those a scan within a region
    /// casts; every pixel outside is [`Pixel::EMPTY`].
    pub window: Window,
}

impl Scan {
    /// Number of pixels with a point.
    pub fn valid_count(&self) -> usize {
        self.window_rows()
            .map(|row| row.iter().filter(|p| p.is_valid()).count())
            .sum()
    }

    /// The window's pixels, row by row (each row's window columns), in parallel.
    pub fn window_rows(&self) -> impl IndexedParallelIterator<Item = &[Pixel]> {
        let w = self.width as usize;
        let Window { cols, rows } = self.window.clone();
        self.pixels[rows.start * w..rows.end * w]
            .par_chunks(w)
            .map(move |row| &row[cols.clone()])
    }
}

/// Scans `world` with `sensor` from the camera-to-world `pose`. Every random draw is keyed by
/// (seed, pixel), so the result is the same for any number of threads.
///
/// # Example
///
/// ```
/// use glam::Vec3;
/// use sensor::{Material, SensorSpec, Target, World, look_at, scan};
///
/// // a triangle soup (as an STL holds it): one big triangle 2 m in front of the camera
/// let tri = [[Vec3::new(-2.0, -2.0, 0.0), Vec3::new(2.0, -2.0, 0.0), Vec3::new(0.0, 2.0, 0.0)]];
/// let world = World::new(&[Target::from_triangles(&tri, 1, 7, Material::default())]);
/// let mut tof = SensorSpec::preset("blensor-tof")?;
/// tof.noise = Default::default(); // exact depth, to check it
/// let pose = look_at(Vec3::new(0.0, 0.0, 1.5), Vec3::ZERO, Vec3::Y).unwrap();
/// let s = scan(&world, &tof, &pose, 0);
/// let centre = &s.pixels[s.pixels.len() / 2 + tof.intrinsics.width as usize / 2];
/// assert!((centre.point.z - 1.5).abs() < 1e-4); // camera z, metres
/// assert_eq!(centre.instance, 7);
/// # Ok::<(), sensor::Error>(())
/// ```
pub fn scan(world: &World, sensor: &SensorSpec, pose: &Affine3A, seed: u64) -> Scan {
    scan_pixels(world, sensor, pose, seed, None, Scan::default())
}

/// The depth (camera z) of the nearest surface that a sparse grid of the camera's rays (every
/// 8th pixel of every 8th row, and the last) meets at any range; None when they meet nothing.
/// It tells a user whose scan came out empty how far the scene really is.
///
/// # Example
///
/// ```
/// use glam::Vec3;
/// use sensor::{Material, SensorSpec, Target, World, look_at, nearest_surface, scan, shapes};
///
/// let plate = shapes::rectangle(Vec3::ZERO, Vec3::X, Vec3::Y);
/// let world = World::new(&[Target::from_triangles(&plate, 1, 1, Material::default())]);
/// let kinect = SensorSpec::preset("kinect-v1")?; // 0.7 to 6 m
/// let pose = look_at(Vec3::new(0.0, 0.0, 0.4), Vec3::ZERO, Vec3::Y).unwrap();
/// assert_eq!(scan(&world, &kinect, &pose, 0).valid_count(), 0);
/// let d = nearest_surface(&world, &kinect, &pose).unwrap();
/// assert!((d - 0.4).abs() < 1e-3);
/// # Ok::<(), sensor::Error>(())
/// ```
pub fn nearest_surface(world: &World, sensor: &SensorSpec, pose: &Affine3A) -> Option<f32> {
    let k = &sensor.intrinsics;
    let along = |n: u32| (0..n).step_by(8).chain([n - 1]);
    let origin = Vec3::from(pose.translation);
    along(k.height)
        .flat_map(|v| along(k.width).map(move |u| (u, v)))
        .filter_map(|(u, v)| {
            let ray = k.ray(f64::from(u), f64::from(v));
            let dir = pose.transform_vector3(ray);
            world.cast(origin, dir, f32::INFINITY).map(|h| h.t * ray.z)
        })
        .min_by(f32::total_cmp)
}

/// As [`scan`], but pixels whose centre ray misses `region` stay empty without being cast
/// (with a pinhole camera, each row casts the columns towards the region's cut by the row's
/// plane, and a column either side, whose rays may miss it). A point can only lie in a box its
/// ray crosses, so cropping to `region` gives what a full scan would; neighbour effects (mixed
/// pixels, the Kinect window) and lateral jitter reach [`SensorSpec::reach_px`] pixels beyond
/// it, so callers crop to a box smaller by that many pixel footprints.
pub fn scan_within(
    world: &World,
    sensor: &SensorSpec,
    pose: &Affine3A,
    seed: u64,
    region: &Region,
) -> Scan {
    scan_pixels(world, sensor, pose, seed, Some(region), Scan::default())
}

/// [`scan`], or [`scan_within`] a region, into the allocation of `earlier`, a scan made before
/// (with any sensor, or [`Scan::default`]): a caller scanning frame after frame spares the
/// mapping and page faults of a fresh megapixel buffer each time, and, as the earlier scan's
/// pixels outside its window are empty, a region scan rewrites only the two windows' pixels.
/// The result is the same whatever scan it reuses.
pub fn scan_reusing(
    world: &World,
    sensor: &SensorSpec,
    pose: &Affine3A,
    seed: u64,
    region: Option<&Region>,
    earlier: Scan,
) -> Scan {
    scan_pixels(world, sensor, pose, seed, region, earlier)
}

fn scan_pixels(
    world: &World,
    sensor: &SensorSpec,
    pose: &Affine3A,
    seed: u64,
    region: Option<&Region>,
    earlier: Scan,
) -> Scan {
    let k = &sensor.intrinsics;
    let width = k.width as usize;
    // an earlier scan of this size left its pixels outside its window empty: those within it
    // are rewritten band by band while they are in cache (cast, or emptied); any other buffer
    // is emptied whole, grown in parallel (a fresh buffer's pages faulted in by both threads)
    let size = width * k.height as usize;
    let Scan {
        mut pixels,
        window: stale,
        ..
    } = earlier;
    let same = (earlier.width, earlier.height) == (k.width, k.height) && pixels.len() == size;
    let stale = if same {
        stale
    } else {
        pixels.clear();
        if pixels.capacity() < size {
            pixels = crate::pages::huge_vec(size);
        }
        pixels.par_extend(rayon::iter::repeat_n(Pixel::EMPTY, size));
        Window::default()
    };
    let window = region
        .and_then(|reg| reg.pixel_window(k, pose))
        .unwrap_or_else(|| Window::full(k));
    let mut capture = Capture::new(world, sensor, pose, seed, region, &window, stale);
    if sensor.noise.interreflection.diffuse_reach > 0.0 {
        capture.diffuse = capture
            .stripes
            .map(|stripes| Diffuse::new(world, sensor, pose, seed, region, &stripes));
    }
    // a task per band: a region fills few of them, and rayon's halving of the range left one
    // thread a run of busy bands while the other idled
    pixels
        .par_chunks_mut(BLOCK * width)
        .enumerate()
        .with_max_len(1)
        .for_each_init(Band::default, |scratch, (band, out)| {
            capture.band(band, out, scratch);
        });
    let mut scan = Scan {
        width: k.width,
        height: k.height,
        pixels,
        pose: *pose,
        window: capture.cast.clone(),
    };
    if let Model::Kinect {
        window,
        window_fraction,
        inlier_distance,
        ..
    } = sensor.model
        && window > 0
    {
        window_filter(&mut scan, window as usize, window_fraction, inlier_distance);
    }
    if sensor.noise.wings.psf_px > 0.0 {
        wings::wings(&mut scan, &window, &capture);
    }
    if sensor.noise.edges.probability > 0.0 {
        mixed_pixels(&mut scan, window.rows.clone(), sensor, seed);
    }
    filters::filter(&mut scan, &window, sensor);
    scan
}

/// The weights of a Gaussian of σ `sigma` at offsets -`radius`..=`radius` (unnormalised).
fn gaussian(sigma: f32, radius: usize) -> Vec<f32> {
    (0..=2 * radius)
        .map(|k| (-0.5 * ((k as f32 - radius as f32) / sigma).powi(2)).exp())
        .collect()
}

/// The rows (or columns) of `0..len` within `radius` of `at`.
fn reach(at: usize, radius: usize, len: usize) -> Range<usize> {
    at.saturating_sub(radius)..(at + radius + 1).min(len)
}

/// `f32::round` (halves away from zero) without its libm call (baseline x86-64 has no rounding
/// instruction): the integer part by a cast, then the fraction decides, without a branch (with
/// noise under the quantum, it is as good as random).
#[inline]
fn round(x: f32) -> f32 {
    let a = x.abs();
    if a.is_nan() || a >= 1e18 {
        return x; // NaN, infinite, or already whole
    }
    let whole = a as i64 as f32;
    let rounded = whole + f32::from(u8::from(a - whole >= 0.5));
    rounded.copysign(x)
}

/// `f32::floor` without its libm call: the cast truncates towards zero, one less below a
/// negative fraction.
#[inline]
fn floor(x: f32) -> f32 {
    if x.is_nan() || x.abs() >= 1e18 {
        return x; // NaN, infinite, or already whole
    }
    let whole = x as i64 as f32;
    if x == whole {
        x // whole (and -0 stays -0)
    } else if x < whole {
        whole - 1.0
    } else {
        whole
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_and_floor_are_f32s() {
        let special = [
            0.5,
            -0.5,
            1.5,
            2.5,
            0.499_999_97,
            -0.999_999_94,
            8_388_607.5,
            1e18,
            f32::MAX,
            -0.0,
        ];
        let values = (-200_000..200_000)
            .map(|i| i as f32 * 0.25 + 0.1 * (i % 7) as f32)
            .chain(special)
            .chain(special.map(|x| -x))
            .chain([f32::INFINITY, f32::NEG_INFINITY]);
        for x in values {
            assert_eq!(round(x).to_bits(), x.round().to_bits(), "{x}");
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "{x}");
        }
        assert!(round(f32::NAN).is_nan() && floor(f32::NAN).is_nan());
    }
}
