//! Scanning: one organized H×W grid of returns per scan, in the camera frame.

use std::ops::Range;

use glam::{Affine3A, DVec3, Mat3A, Vec3};
use rayon::prelude::*;

use crate::bvh::lanes;
use crate::camera::Intrinsics;
use crate::epipolar::{Epipolar, NEAR, Ray, RowCut};
use crate::noise::{PixelRng, stream};
use crate::spec::{Frustum, Model, SensorSpec};
use crate::world::{SurfaceHit, World};

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
    /// Signal strength: reflectivity × cos(incidence of the light) × (reference / range)².
    pub intensity: f32,
    /// Angle between the surface normal and the direction to the camera, radians.
    pub incidence: f32,
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
        incidence: f32::NAN,
    };

    /// Whether the sensor returned a point.
    pub fn is_valid(&self) -> bool {
        !self.point.x.is_nan()
    }
}

/// An organized scan.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Row-major pixels.
    pub pixels: Vec<Pixel>,
    /// Camera-to-world pose of the scan.
    pub pose: Affine3A,
}

impl Scan {
    /// Number of pixels with a point.
    pub fn valid_count(&self) -> usize {
        self.pixels.iter().filter(|p| p.is_valid()).count()
    }
}

/// An axis-aligned box in world coordinates that limits which pixels a scan casts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Smallest corner, m.
    pub min: Vec3,
    /// Largest corner, m.
    pub max: Vec3,
}

impl Region {
    /// Whether the ray from `origin` along `dir` passes through the box (slab test).
    pub fn crossed_by(&self, origin: Vec3, dir: Vec3) -> bool {
        let inv = dir.recip();
        let a = (self.min - origin) * inv;
        let b = (self.max - origin) * inv;
        let near = a.min(b).max_element().max(0.0);
        let far = a.max(b).min_element();
        near <= far
    }

    /// Its corners in the camera frame of a camera at camera-to-world `pose`: corner `i` takes
    /// x, y, z from `max` where bit 0, 1, 2 of `i` is set.
    fn corners_in(&self, pose: &Affine3A) -> [DVec3; 8] {
        let to_camera = pose.inverse();
        std::array::from_fn(|i| {
            let pick = |bit: usize, a: f32, b: f32| if i & bit == 0 { a } else { b };
            let world = Vec3::new(
                pick(1, self.min.x, self.max.x),
                pick(2, self.min.y, self.max.y),
                pick(4, self.min.z, self.max.z),
            );
            to_camera.transform_point3(world).as_dvec3()
        })
    }

    /// The pixels whose centre rays can cross the box, as columns `c0..c1` and rows `r0..r1`:
    /// the bounding rectangle of its projected corners, widened by a pixel; `None` where that
    /// bounds nothing (a lens with distortion, or a corner not in front of the camera).
    pub fn pixel_window(&self, k: &Intrinsics, pose: &Affine3A) -> Option<[usize; 4]> {
        if !k.distortion.is_none() {
            return None;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for corner in self.corners_in(pose) {
            let (u, v) = k.project(corner.as_vec3())?;
            (lo, hi) = ([lo[0].min(u), lo[1].min(v)], [hi[0].max(u), hi[1].max(v)]);
        }
        let clamp = |x: f64, n: u32| x.clamp(0.0, n as f64) as usize;
        Some([
            clamp(lo[0].floor() - 1.0, k.width),
            clamp(hi[0].ceil() + 2.0, k.width),
            clamp(lo[1].floor() - 1.0, k.height),
            clamp(hi[1].ceil() + 2.0, k.height),
        ])
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
    scan_pixels(world, sensor, pose, seed, None, Vec::new())
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
    scan_pixels(world, sensor, pose, seed, Some(region), Vec::new())
}

/// [`scan`], or [`scan_within`] a region, into the allocation of `buffer` (the pixels of an
/// earlier scan): a caller scanning frame after frame spares the mapping and page faults of a
/// fresh megapixel buffer each time. The result is the same whatever the buffer held.
pub fn scan_reusing(
    world: &World,
    sensor: &SensorSpec,
    pose: &Affine3A,
    seed: u64,
    region: Option<&Region>,
    buffer: Vec<Pixel>,
) -> Scan {
    scan_pixels(world, sensor, pose, seed, region, buffer)
}

fn scan_pixels(
    world: &World,
    sensor: &SensorSpec,
    pose: &Affine3A,
    seed: u64,
    region: Option<&Region>,
    mut pixels: Vec<Pixel>,
) -> Scan {
    let k = &sensor.intrinsics;
    let width = k.width as usize;
    let bias = {
        let rng = PixelRng::new(seed, u64::MAX);
        let b = sensor.noise.bias;
        (
            1.0 + b.scale_sigma * rng.normal(stream::BIAS),
            b.offset_sigma * rng.normal(stream::BIAS + 2),
        )
    };
    // whatever a reused buffer holds is overwritten below, band by band while it is in cache
    // (grown in parallel: a fresh buffer's pages are faulted in by both threads)
    let size = width * k.height as usize;
    pixels.truncate(size);
    if pixels.capacity() < size {
        pixels.reserve_exact(size - pixels.len());
        advise_huge_pages(&mut pixels);
    }
    pixels.par_extend(rayon::iter::repeat_n(Pixel::EMPTY, size - pixels.len()));
    let [c0, c1, r0, r1] = region.and_then(|reg| reg.pixel_window(k, pose)).unwrap_or([
        0,
        width,
        0,
        k.height as usize,
    ]);
    // the pixels the bands below may cast, and, for a pinhole camera, the world prepared to be
    // cut in their rows' planes: cutting a triangle costs a fraction of a ray's walk, so only a
    // few pixels on a large mesh are cast ray by ray
    let cols = c0 - c0 % BLOCK..(c1.div_ceil(BLOCK) * BLOCK).min(width);
    let rows = r0 - r0 % BLOCK..(r1.div_ceil(BLOCK) * BLOCK).min(k.height as usize);
    let cut = k.distortion.is_none() && 3 * cols.len() * rows.len() >= world.triangle_count();
    let baseline = sensor.projector().map_or(0.0, |p| p.baseline);
    let setup = Setup {
        world,
        sensor,
        projector: sensor.projector().map(|p| (p.frustum(), p.centre())),
        to_camera: pose.matrix3.transpose(),
        pinhole: k.distortion.is_none(),
        pose: *pose,
        origin: Vec3::from(pose.translation),
        region: region.copied(),
        region_in_camera: region.map(|reg| reg.corners_in(pose)),
        seed,
        bias,
        epipolar: cut.then(|| world.epipolar(k, pose, baseline, rows, BLOCK, sensor.max_range)),
    };
    pixels
        .par_chunks_mut(BLOCK * width)
        .enumerate()
        .for_each_init(Band::default, |scratch, (band, out)| {
            let rows = out.len() / width;
            if BLOCK * band + rows <= r0 || BLOCK * band >= r1 {
                out.fill(Pixel::EMPTY);
                return; // outside the region's window: nothing to cast
            }
            for line in out.chunks_mut(width) {
                line[..cols.start].fill(Pixel::EMPTY);
                line[cols.end..].fill(Pixel::EMPTY);
            }
            match &setup.epipolar {
                Some(epipolar) => setup.cut_rows(epipolar, band, &cols, out, scratch),
                None => {
                    let lits = &mut scratch.lits;
                    lits.resize(rows * cols.len(), None);
                    setup.cast_blocks(band, &cols, out, lits);
                    for (line, lits) in out.chunks_mut(width).zip(lits.chunks(cols.len())) {
                        setup.settle(&mut line[cols.clone()], lits);
                    }
                }
            }
        });
    let mut scan = Scan {
        width: k.width,
        height: k.height,
        pixels,
        pose: *pose,
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
    if sensor.noise.edges.probability > 0.0 {
        mixed_pixels(&mut scan, r0..r1, sensor, seed);
    }
    scan
}

/// Asks the kernel to back the spare capacity of `v` with huge pages (2 MiB) where it can: a
/// fresh megapixel buffer then takes hundreds of page faults instead of tens of thousands.
#[cfg(target_os = "linux")]
fn advise_huge_pages<T>(v: &mut Vec<T>) {
    const HUGE: usize = 2 << 20;
    let spare = v.spare_capacity_mut();
    let (start, len) = (spare.as_mut_ptr() as usize, size_of_val(spare));
    let (from, to) = (start.next_multiple_of(HUGE), (start + len) / HUGE * HUGE);
    if to > from {
        // SAFETY: advice on memory the vector owns and has not yet written; the kernel may
        // ignore it, and nothing depends on whether it does
        unsafe { libc::madvise(from as *mut libc::c_void, to - from, libc::MADV_HUGEPAGE) };
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages<T>(_: &mut Vec<T>) {}

/// What every pixel of one scan shares.
struct Setup<'a> {
    world: &'a World,
    sensor: &'a SensorSpec,
    /// The projector's frustum and centre (camera frame), for sensors that have one.
    projector: Option<(Frustum, Vec3)>,
    /// World-to-camera rotation.
    to_camera: Mat3A,
    /// Whether the camera has no distortion.
    pinhole: bool,
    pose: Affine3A,
    /// The camera's centre, world frame.
    origin: Vec3,
    /// Pixels whose centre ray misses this stay empty.
    region: Option<Region>,
    /// The region's corners in the camera frame.
    region_in_camera: Option<[DVec3; 8]>,
    seed: u64,
    /// Per-scan range scale and offset.
    bias: (f32, f32),
    /// The world prepared to be cut in the rows' epipolar planes (a pinhole camera).
    epipolar: Option<Epipolar>,
}

impl Setup<'_> {
    /// Whether the centre ray of a pixel, world frame, may hold a point.
    fn casts(&self, dir: Vec3) -> bool {
        self.region
            .is_none_or(|reg| reg.crossed_by(self.origin, dir))
    }

    /// The columns of `cols` in `row` (of a pinhole camera) whose centre rays may cross the
    /// region: those towards the cut of the region by the row's plane, with a column to spare
    /// either side; all of `cols` without a region or where the cut reaches behind the camera.
    fn region_columns(&self, row: usize, cols: &Range<usize>) -> Range<usize> {
        let Some(corners) = &self.region_in_camera else {
            return cols.clone();
        };
        let k = &self.sensor.intrinsics;
        // the plane's points are y = t·z; its cut of the box is a convex polygon whose corners
        // lie on the box's edges, and a centre ray (x / z, t, 1) meets it where x / z lies
        // between the smallest and largest x / z of those corners
        let t = (row as f64 - k.cy) / k.fy;
        let side = corners.map(|c| c.y - t * c.z);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (i, j) in BOX_EDGES {
            let (p, q, sp, sq) = (corners[i], corners[j], side[i], side[j]);
            if sp * sq > 0.0 {
                continue; // both corners on one side
            }
            let ends = if sp == sq {
                [p, q]
            } else {
                [p + (q - p) * (sp / (sp - sq)); 2]
            };
            for e in ends {
                if e.z <= NEAR {
                    return cols.clone();
                }
                (lo, hi) = (lo.min(e.x / e.z), hi.max(e.x / e.z));
            }
        }
        if lo > hi {
            return cols.start..cols.start; // the plane misses the box
        }
        let column = |x: f64, spare: f64| {
            (x * k.fx + k.cx + spare).clamp(cols.start as f64, cols.end as f64) as usize
        };
        column(lo, -1.0)..column(hi, 2.0) // casts round towards zero: a column more on the right
    }

    /// Measures the band's pixels over `cols` in its rows' epipolar planes, row by row: each
    /// pixel's first surface, its light, and the projector's shadows.
    fn cut_rows(
        &self,
        epipolar: &Epipolar,
        band: usize,
        cols: &Range<usize>,
        out: &mut [Pixel],
        scratch: &mut Band,
    ) {
        let k = &self.sensor.intrinsics;
        let Band {
            lits,
            hits,
            rays,
            cut,
        } = scratch;
        lits.resize(cols.len(), None); // one row's, each written before it is read
        for (r, line) in out.chunks_mut(k.width as usize).enumerate() {
            let row = BLOCK * band + r;
            let span = self.region_columns(row, cols);
            epipolar.cut(row, cut);
            epipolar.first_hits(cut, &span, hits);
            // every pixel and lit of the row written once: measured, or empty
            for (c, lit) in cols.clone().zip(lits.iter_mut()) {
                let hit = hits.get(c.wrapping_sub(span.start)).copied().flatten();
                let seen = hit.map(|(slot, t)| {
                    let centre = epipolar.centre_ray(cut, c);
                    let dir = self.pose.transform_vector3(centre);
                    (centre, self.world.describe_slot(slot, t, dir))
                });
                *lit = match seen {
                    Some((centre, hit)) => illuminate(self, c, row, centre, hit, &mut line[c]),
                    None => {
                        line[c] = Pixel::EMPTY;
                        None
                    }
                };
            }
            if self.projector.is_some() {
                shade(epipolar, cut, lits, rays);
            }
            self.settle(&mut line[cols.clone()], lits);
        }
    }

    /// Completes a row of pixels (the window's columns) measured up to their light: incidence
    /// angles from the cosines, in one tight loop, then the measurement of each lit pixel.
    fn settle(&self, line: &mut [Pixel], lits: &[Option<Lit>]) {
        for px in line.iter_mut() {
            px.incidence = acos(px.incidence);
        }
        for (lit, px) in lits.iter().zip(line) {
            if let Some(lit) = lit {
                finish(self, lit, px);
            }
        }
    }

    /// Measures the band's pixels over `cols` in BLOCK×BLOCK blocks, each cast as one packet of
    /// rays, then its shadow rays as another.
    fn cast_blocks(
        &self,
        band: usize,
        cols: &Range<usize>,
        out: &mut [Pixel],
        lits: &mut [Option<Lit>],
    ) {
        let k = &self.sensor.intrinsics;
        let (width, span) = (k.width as usize, cols.len());
        let rows = lits.len() / span;
        lits.fill(None);
        let projector = self.projector.map_or(Vec3::ZERO, |(_, centre)| centre);
        let from = self.pose.transform_point3(projector);
        for col in cols.clone().step_by(BLOCK) {
            for line in out.chunks_mut(width) {
                line[col..(col + BLOCK).min(width)].fill(Pixel::EMPTY);
            }
            // per lane of each 2×2 group: its pixel's (column, row in the band), or none past
            // the image's edge or outside the region
            let mut at = [[None; 4]; GROUPS];
            let mut centres = [[Vec3::Z; 4]; GROUPS];
            let mut dirs = [[Vec3::Z; 4]; GROUPS];
            let mut t_max = [[0.0; 4]; GROUPS];
            for (g, lane) in lanes::<GROUPS>() {
                let (c, r) = block_pixel(col, g, lane);
                if c >= width || r >= rows {
                    continue;
                }
                let centre = k.ray(c as f64, (BLOCK * band + r) as f64);
                let dir = self.pose.transform_vector3(centre);
                if self.casts(dir) {
                    at[g][lane] = Some((c, r));
                    (centres[g][lane], dirs[g][lane]) = (centre, dir);
                    t_max[g][lane] = self.sensor.max_range;
                }
            }
            if at.iter().flatten().all(Option::is_none) {
                continue; // nothing to cast: the pixels stay empty
            }
            let hits = self.world.cast_packet(self.origin, &dirs, &t_max);
            // the shadow rays, world frame, towards the lit surface points from the projector
            let mut shadow = [[Vec3::Z; 4]; GROUPS];
            let mut length = [[0.0; 4]; GROUPS];
            for (g, lane) in lanes::<GROUPS>() {
                if let (Some((c, r)), Some(hit)) = (at[g][lane], hits[g][lane]) {
                    let (row, px) = (BLOCK * band + r, &mut out[r * width + c]);
                    let lit = illuminate(self, c, row, centres[g][lane], hit, px);
                    if let Some(Lit {
                        shadow: Some((point, distance)),
                        ..
                    }) = lit
                    {
                        let dir = (point - projector) / distance;
                        shadow[g][lane] = self.pose.transform_vector3(dir);
                        length[g][lane] = distance - gap(distance);
                    }
                    lits[r * span + c - cols.start] = lit;
                }
            }
            let blocked = self.world.occluded_packet(from, &shadow, &length);
            for (g, lane) in lanes::<GROUPS>() {
                if blocked[g][lane] {
                    let (c, r) = block_pixel(col, g, lane);
                    lits[r * span + c - cols.start] = None;
                }
            }
        }
    }
}

/// What a task keeps from band to band.
#[derive(Default)]
struct Band {
    /// Pixels measured up to the projector's visibility, over the window's columns: one row's
    /// when rows are cut, the band's when blocks are cast.
    lits: Vec<Option<Lit>>,
    /// One row's first hits: slot and distance.
    hits: Vec<Option<(u32, f32)>>,
    /// One row's shadow rays, by position in the row.
    rays: Vec<(usize, Ray)>,
    cut: RowCut,
}

/// Drops the lit pixels of a cut row whose surface point the projector does not reach.
fn shade(
    epipolar: &Epipolar,
    cut: &mut RowCut,
    lits: &mut [Option<Lit>],
    rays: &mut Vec<(usize, Ray)>,
) {
    rays.clear();
    for (i, lit) in lits.iter().enumerate() {
        if let Some(Lit {
            shadow: Some((point, distance)),
            ..
        }) = lit
        {
            rays.push((i, epipolar.ray(*point, *distance, gap(*distance))));
        }
    }
    let shadows = epipolar.shadows(cut, rays.iter().map(|&(_, ray)| ray));
    for &(i, ray) in rays.iter() {
        if shadows.block(ray) {
            lits[i] = None;
        }
    }
}

/// How far short of its surface point a shadow ray at `distance` m ends, m: beyond the float32
/// rounding of the point, so that its own surface does not shadow it.
pub(crate) fn gap(distance: f32) -> f32 {
    (distance * 1e-4).max(1e-5)
}

/// The pixel of lane `lane` of group `g` of the block at column `col`: (column, row in the
/// band).
#[inline]
fn block_pixel(col: usize, g: usize, lane: usize) -> (usize, usize) {
    (
        col + 2 * (g % (BLOCK / 2)) + lane % 2,
        2 * (g / (BLOCK / 2)) + lane / 2,
    )
}

/// The edges of a box, as pairs of corners numbered as in [`Region::corners_in`].
const BOX_EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// Pixels per side of the blocks a scan casts as one packet.
const BLOCK: usize = 4;
/// 2×2 groups of four rays per block.
const GROUPS: usize = BLOCK * BLOCK / 4;

/// A pixel measured up to the projector's visibility: what [`finish`] needs once that is known.
#[derive(Clone, Copy)]
struct Lit {
    /// The pixel's column and row.
    pixel: [u32; 2],
    /// Its centre ray's direction (camera frame) and the distance to the surface along it.
    centre: Vec3,
    t: f32,
    /// Signal strength at the point.
    signal: f32,
    /// The surface point the projector must reach (camera frame) and its distance from the
    /// projector (none for sensors that light from the camera).
    shadow: Option<(Vec3, f32)>,
    rng: PixelRng,
}

/// Labels pixel `px`, whose centre ray (camera frame) hit `hit`, and measures it up to the
/// projector's visibility: the light at the surface point it sees, its signal and dropouts
/// (which need no shadow test, so lost pixels have none); `None` when it can have no point.
#[inline(always)]
fn illuminate(
    setup: &Setup,
    col: usize,
    row: usize,
    centre: Vec3,
    hit: SurfaceHit,
    px: &mut Pixel,
) -> Option<Lit> {
    let Setup {
        sensor,
        ref projector,
        ref to_camera,
        seed,
        ..
    } = *setup;
    let k = &sensor.intrinsics;
    let noise = &sensor.noise;
    let rng = PixelRng::new(seed, (row * k.width as usize + col) as u64);
    let normal = Vec3::from(*to_camera * glam::Vec3A::from(hit.normal));
    *px = Pixel {
        clean: centre * hit.t,
        normal,
        class: hit.class,
        instance: hit.instance,
        // the cosine for now: `settle` turns a row's cosines into angles in one tight loop
        incidence: normal.dot(-centre).clamp(-1.0, 1.0),
        ..Pixel::EMPTY
    };

    // illumination of the surface point the pixel sees (jitter moves where it is measured, not
    // where the light falls): the projector, or the camera itself
    let surface = px.clean;
    let ((light_dir, light_range), shadow) = match projector {
        Some((frustum, centre)) => {
            if !frustum.lights(surface) {
                return None;
            }
            let to_light = *centre - surface;
            let distance = to_light.length();
            let l = to_light / distance;
            if normal.dot(l) <= 0.0 {
                return None; // self-shadowed: the surface faces away from the projector
            }
            ((l, distance), Some((surface, distance)))
        }
        None => ((-centre, hit.t), None),
    };

    let material = hit.material;
    let cos_light = normal.dot(light_dir).max(0.0);
    let signal = material.reflectivity * cos_light * (sensor.reference_range / light_range).powi(2);
    if rng.uniform(stream::DROPOUT) < noise.dropout.probability(signal) {
        return None;
    }
    if noise.specular.probability > 0.0 && material.specular > 0.0 {
        // the half vector lies within the lobe: its angle to the normal is below `lobe`
        let half = (light_dir - centre).normalize();
        if normal.dot(half) > hit.lobe_cos
            && rng.uniform(stream::SPECULAR) < noise.specular.probability * material.specular
        {
            return None;
        }
    }
    Some(Lit {
        pixel: [col as u32, row as u32],
        centre,
        t: hit.t,
        signal,
        shadow,
        rng,
    })
}

/// arccos of `x` in [-1, 1], within 5e-7 rad: the polynomial of Abramowitz and Stegun 4.4.46
/// (error 2e-8 in exact arithmetic), a third of the cost of libm's `acosf`.
#[inline]
fn acos(x: f32) -> f32 {
    const A: [f32; 8] = [
        std::f32::consts::FRAC_PI_2, // 1.5707963050 rounds to it
        -0.214_598_8,
        0.088_978_99,
        -0.050_174_3,
        0.030_891_88,
        -0.017_088_126,
        0.006_670_09,
        -0.001_262_491_1,
    ];
    let a = x.abs();
    let p = A.iter().rev().fold(0.0, |p, &c| p * a + c);
    let r = (1.0 - a).sqrt() * p;
    if x < 0.0 { std::f32::consts::PI - r } else { r }
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

/// Measures labelled pixel `px` of a lit surface point (its shadow ray, if any, unblocked):
/// where it samples (its centre, or a laterally jittered position), range noise,
/// quantisation and the range limits.
fn finish(setup: &Setup, lit: &Lit, px: &mut Pixel) {
    let Setup {
        sensor,
        bias,
        pinhole,
        ..
    } = *setup;
    let k = &sensor.intrinsics;
    let noise = &sensor.noise;
    let Lit {
        pixel: [col, row],
        centre,
        t,
        signal,
        rng,
        ..
    } = *lit;
    // where this pixel actually samples: its centre, or a laterally jittered position on the
    // tangent plane of the surface it sees
    let (dir, mut range) = if noise.lateral_px > 0.0 {
        let du = noise.lateral_px * rng.normal(stream::LATERAL);
        let dv = noise.lateral_px * rng.normal(stream::LATERAL + 2);
        let d = if pinhole {
            // a pinhole's: the centre ray's image point, moved
            let shift = Vec3::new(du / k.fx as f32, dv / k.fy as f32, 0.0);
            (centre / centre.z + shift).normalize()
        } else {
            k.ray(col as f64 + du as f64, row as f64 + dv as f64)
        };
        let facing = px.normal.dot(d);
        if facing.abs() < 1e-6 {
            return; // grazing: the jittered ray runs along the surface
        }
        (d, px.normal.dot(px.clean) / facing)
    } else {
        (centre, t)
    };
    if range.is_nan() || range < sensor.min_range {
        return;
    }
    let sigma = noise.axial.sigma_at(range) * noise.incidence.factor(px.incidence);
    if sigma > 0.0 {
        range += sigma * rng.normal(stream::AXIAL);
    }
    if let Model::Kinect {
        projector,
        disparity_sigma_px,
        subpixel,
        ..
    } = sensor.model
    {
        let fb = k.fx as f32 * projector.baseline;
        let z = range * dir.z;
        let disparity = fb / z + disparity_sigma_px * rng.normal(stream::DISPARITY);
        let disparity = round(disparity * subpixel) / subpixel;
        if disparity <= 0.0 {
            return;
        }
        range = fb / disparity / dir.z;
    }
    range = range * bias.0 + bias.1;
    if noise.quantization > 0.0 {
        range = round(range / noise.quantization) * noise.quantization;
    }
    if !(sensor.min_range..=sensor.max_range).contains(&range) {
        return;
    }
    px.intensity = signal;
    px.point = dir * range;
}

/// Mixed pixels: an edge pixel may be pulled along its own ray towards its neighbour's depth.
/// Only `rows` can hold points.
fn mixed_pixels(scan: &mut Scan, rows: Range<usize>, sensor: &SensorSpec, seed: u64) {
    let w = scan.width as usize;
    let cast = &mut scan.pixels[rows.start * w..rows.end * w];
    // each pixel's range, NaN where it has no point
    let ranges: Vec<f32> = cast
        .par_iter()
        .map(|p| {
            if p.is_valid() {
                p.point.length()
            } else {
                f32::NAN
            }
        })
        .collect();
    let none = vec![f32::NAN; w]; // the rows beyond the first and last
    let edges = sensor.noise.edges;
    cast.par_chunks_mut(w).enumerate().for_each(|(r, out)| {
        let line = |r: usize| ranges.get(r * w..(r + 1) * w).unwrap_or(&none);
        let (here, below) = (line(r), line(r + 1));
        let above = r.checked_sub(1).map_or(&none[..], line);
        let beside = |c: usize| here.get(c).copied().unwrap_or(f32::NAN);
        for (col, px) in out.iter_mut().enumerate() {
            let range = here[col];
            let step = |other: f32| (other - range).abs();
            // the 4-neighbours' ranges (NaN: no point) and the largest difference to one,
            // found without branches (a NaN difference never compares greater: one `maxss`
            // each); the few edges then draw
            let neighbours = [
                beside(col.wrapping_sub(1)),
                beside(col + 1),
                above[col],
                below[col],
            ];
            let gap = neighbours
                .map(step)
                .into_iter()
                .fold(f32::NEG_INFINITY, |gap, s| if s > gap { s } else { gap });
            if gap <= edges.jump {
                continue; // no point, no neighbour with one, or no edge
            }
            let rng = PixelRng::new(seed, ((rows.start + r) * w + col) as u64);
            if rng.uniform(stream::EDGE) < edges.probability {
                // the neighbour whose range differs most (the last of equals)
                let other = neighbours
                    .into_iter()
                    .rev()
                    .find(|&n| step(n) == gap)
                    .unwrap_or(range);
                let blend = rng.uniform(stream::EDGE + 1);
                px.point *= (range + blend * (other - range)) / range;
            }
        }
    });
}

/// Kinect validity window: a pixel stays if enough of its window holds points within the
/// inlier distance of its depth.
fn window_filter(scan: &mut Scan, window: usize, fraction: f32, inlier: f32) {
    let (w, h) = (scan.width as usize, scan.height as usize);
    let depth: Vec<f32> = scan
        .pixels
        .iter()
        .map(|p| if p.is_valid() { p.point.z } else { f32::NAN })
        .collect();
    let half = window / 2;
    let needed = (fraction * (window * window) as f32).ceil() as usize;
    scan.pixels
        .par_chunks_mut(w)
        .enumerate()
        .for_each(|(row, out)| {
            for (col, px) in out.iter_mut().enumerate() {
                let z = depth[row * w + col];
                if z.is_nan() {
                    continue;
                }
                let agree = (row.saturating_sub(half)..(row + half + 1).min(h))
                    .flat_map(|r| {
                        (col.saturating_sub(half)..(col + half + 1).min(w)).map(move |c| r * w + c)
                    })
                    .filter(|&j| (depth[j] - z).abs() < inlier)
                    .count();
                if agree < needed {
                    px.point = Vec3::NAN;
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_is_f32_round() {
        let special = [
            0.5,
            -0.5,
            1.5,
            2.5,
            0.499_999_97,
            8_388_607.5,
            1e18,
            f32::MAX,
            -0.0,
        ];
        let values = (-200_000..200_000)
            .map(|i| i as f32 * 0.25 + 0.1 * (i % 7) as f32)
            .chain(special)
            .chain([f32::INFINITY, f32::NEG_INFINITY]);
        for x in values {
            assert_eq!(round(x).to_bits(), x.round().to_bits(), "{x}");
        }
        assert!(round(f32::NAN).is_nan());
    }

    #[test]
    fn acos_is_within_5e7_of_the_exact_angle() {
        let worst = (-1_000_000..=1_000_000)
            .map(|i| i as f32 / 1e6)
            .chain([-1.0, -0.0, 0.0, 1.0, f32::EPSILON, 1.0 - f32::EPSILON / 2.0])
            .map(|x| (acos(x) as f64 - (x as f64).acos()).abs())
            .fold(0.0, f64::max);
        assert!(worst < 5e-7, "worst error {worst}");
    }
}
