//! Finding each pixel's first surface and the projector's shadows, along one of two paths:
//! with a pinhole camera, each row cut in its epipolar plane ([`Path::Rows`]); otherwise
//! BLOCK×BLOCK blocks of rays cast as packets through the BVH ([`Path::Blocks`]).

use std::ops::Range;

use glam::{Affine3A, DVec3, Mat3A, Vec3};

use super::Pixel;
use super::colour::Response;
use super::decode::Stripes;
use super::diffuse::Diffuse;
use super::light::{LitPixel, acos, illuminate};
use super::measure::measure;
use super::mirror::{Mirrored, cast_mirrors};
use super::region::{Region, Window, row_columns};
use crate::bvh::lanes;
use crate::camera::CentreRays;
use crate::epipolar::{Epipolar, Ray, RowCut};
use crate::noise::{Correlated, PixelRng, stream};
use crate::spec::{CalibrationError, Frustum, SensorSpec};
use crate::world::World;

/// What every pixel of one scan shares.
pub(super) struct Capture<'a> {
    pub(super) world: &'a World,
    pub(super) sensor: &'a SensorSpec,
    /// The projector's frustum and centre (camera frame), for sensors that have one.
    pub(super) projector: Option<(Frustum, Vec3)>,
    /// World-to-camera rotation.
    pub(super) to_camera: Mat3A,
    /// Whether the camera has no distortion.
    pub(super) pinhole: bool,
    /// The rays through the pixels' centres.
    centres: CentreRays,
    pub(super) pose: Affine3A,
    /// The camera's centre, world frame.
    pub(super) origin: Vec3,
    /// Pixels whose centre ray misses this stay empty.
    pub(super) region: Option<Region>,
    /// The region's corners in the camera frame.
    pub(super) region_in_camera: Option<[DVec3; 8]>,
    pub(super) seed: u64,
    /// Per-scan range scale and offset.
    pub(super) bias: (f32, f32),
    /// The camera's calibration error, if it has one.
    pub(super) calibration: Option<CalibrationError>,
    /// The camera's focal length × the projector's baseline (pixel·m).
    pub(super) focal_baseline: f32,
    /// The key of the correlated noise's lattice.
    pub(super) lattice: u64,
    /// The projector's stripes, for sensors that have one.
    pub(super) stripes: Option<Stripes>,
    /// The light each pixel's surface receives from the lit surfaces around it, with the
    /// diffuse bounce.
    pub(super) diffuse: Option<Diffuse>,
    /// The pixels cast: the window's columns in whole blocks, its rows in whole bands.
    pub(super) cast: Window,
    /// The colour camera's response.
    pub(super) colour: Response,
    /// The pixels an earlier scan may have left in the buffer (all others are empty).
    stale: Window,
    pub(super) path: Path,
}

/// How a scan finds its pixels' first surfaces and the projector's shadows.
pub(super) enum Path {
    /// Each row cut in its epipolar plane (a pinhole camera): triangles become segments, and
    /// cutting a triangle costs a fraction of a ray's walk through the tree.
    Rows(Epipolar),
    /// BLOCK×BLOCK blocks of rays cast as packets through the BVH: a lens with distortion, or
    /// a few pixels on a large mesh.
    Blocks,
}

impl<'a> Capture<'a> {
    /// Prepares the scan of the pixels of `window` whose centre rays may cross `region`, into
    /// a buffer whose pixels outside `stale` are empty.
    pub(super) fn new(
        world: &'a World,
        sensor: &'a SensorSpec,
        pose: &Affine3A,
        seed: u64,
        region: Option<&Region>,
        window: &Window,
        stale: Window,
    ) -> Capture<'a> {
        let k = &sensor.intrinsics;
        let bias = {
            let rng = PixelRng::new(seed, u64::MAX);
            let b = sensor.noise.bias;
            (
                1.0 + b.scale_sigma * rng.normal(stream::BIAS),
                b.offset_sigma * rng.normal(stream::BIAS + 2),
            )
        };
        let (c0, c1) = (window.cols.start, window.cols.end);
        let (r0, r1) = (window.rows.start, window.rows.end);
        let cols = c0 - c0 % BLOCK..(c1.div_ceil(BLOCK) * BLOCK).min(k.width as usize);
        let band_rows = r0 - r0 % BLOCK..(r1.div_ceil(BLOCK) * BLOCK).min(k.height as usize);
        let pinhole = k.distortion.is_none();
        let path = if pinhole && 3 * cols.len() * band_rows.len() >= world.triangle_count() {
            let baseline = sensor.projector().map_or(0.0, |p| p.baseline);
            let far = sensor.far_depth();
            let epipolar = world.epipolar(k, pose, baseline, band_rows.clone(), far);
            Path::Rows(epipolar)
        } else {
            Path::Blocks
        };
        let projector = sensor.projector().map(|p| (p.frustum(), p.centre()));
        Capture {
            world,
            sensor,
            projector,
            to_camera: pose.matrix3.transpose(),
            pinhole,
            centres: k.centre_rays(),
            pose: *pose,
            origin: Vec3::from(pose.translation),
            region: region.copied(),
            region_in_camera: region.map(|reg| reg.corners_in(pose)),
            seed,
            bias,
            calibration: sensor.calibration_error(),
            focal_baseline: sensor.focal_baseline(),
            lattice: Correlated::key(seed),
            stripes: projector.map(|(frustum, _)| Stripes::new(sensor, frustum)),
            diffuse: None,
            cast: Window {
                cols,
                rows: band_rows,
            },
            colour: Response::new(&sensor.colour, &sensor.intrinsics),
            stale,
            path,
        }
    }

    /// Measures band `band` (BLOCK rows, `out`) up to the neighbour effects; pixels outside
    /// the cast window are left empty.
    pub(super) fn band(&self, band: usize, out: &mut [Pixel], scratch: &mut Band) {
        let width = self.sensor.intrinsics.width as usize;
        let (rows, cols) = (out.len() / width, &self.cast.cols);
        // the cast window's rows are whole bands: this band's are cast, or none of them
        let first = BLOCK * band;
        let cast = first < self.cast.rows.end && first + rows > self.cast.rows.start;
        let kept = if cast { cols.clone() } else { 0..0 };
        let stale = &self.stale.cols;
        for (row, line) in (first..).zip(out.chunks_mut(width)) {
            if self.stale.rows.contains(&row) {
                // the stale columns either side of those cast
                line[stale.start..stale.end.min(kept.start).max(stale.start)].fill(Pixel::EMPTY);
                line[stale.start.max(kept.end).min(stale.end)..stale.end].fill(Pixel::EMPTY);
            }
        }
        if !cast {
            return; // outside the region's window: nothing to cast
        }
        match &self.path {
            Path::Rows(epipolar) => self.cut_rows(epipolar, band, cols, out, scratch),
            Path::Blocks => {
                let lits = &mut scratch.lits;
                lits.resize(rows * cols.len(), None);
                self.cast_blocks(band, cols, out, lits);
                for (line, lits) in out.chunks_mut(width).zip(lits.chunks(cols.len())) {
                    self.finish_row(&mut line[cols.clone()], lits, &mut scratch.mirrors);
                }
            }
        }
    }

    /// Whether the centre ray of a pixel, world frame, may hold a point.
    fn casts(&self, dir: Vec3) -> bool {
        self.region
            .is_none_or(|reg| reg.crossed_by(self.origin, dir))
    }

    /// The columns of `cols` in `row` (of a pinhole camera) whose centre rays may cross the
    /// region (see [`row_columns`]); all of `cols` without a region.
    fn region_columns(&self, row: usize, cols: &Range<usize>) -> Range<usize> {
        match &self.region_in_camera {
            Some(corners) => row_columns(corners, &self.sensor.intrinsics, row, cols),
            None => cols.clone(),
        }
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
            mirrors,
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
                    (centre, self.world.describe_slot(slot, t, self.origin, dir))
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
                shade(self, epipolar, cut, lits, &mut line[cols.clone()], rays);
            }
            self.finish_row(&mut line[cols.clone()], lits, mirrors);
        }
    }

    /// Completes a row of pixels (the window's columns) measured up to their light: incidence
    /// angles from the cosines, in one tight loop, what the shiny pixels' mirror rays meet
    /// (`mirrors`, the row's), then the measurement of each lit pixel.
    fn finish_row(
        &self,
        line: &mut [Pixel],
        lits: &[Option<LitPixel>],
        mirrors: &mut Vec<Option<Mirrored>>,
    ) {
        for px in line.iter_mut() {
            px.incidence = acos(px.incidence);
        }
        cast_mirrors(self, lits, line, mirrors);
        for ((lit, px), mirror) in lits.iter().zip(line).zip(mirrors.iter()) {
            if let Some(lit) = lit {
                measure(self, lit, mirror.as_ref(), px);
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
        lits: &mut [Option<LitPixel>],
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
                let centre = self.centres.ray(c, BLOCK * band + r);
                let dir = self.pose.transform_vector3(centre);
                if self.casts(dir) {
                    at[g][lane] = Some((c, r));
                    (centres[g][lane], dirs[g][lane]) = (centre, dir);
                    t_max[g][lane] = self.sensor.reach(centre);
                }
            }
            if at.iter().flatten().all(Option::is_none) {
                continue; // nothing to cast: the pixels stay empty
            }
            let hits = self
                .world
                .cast_packet(&[[self.origin; 4]; GROUPS], &dirs, &t_max);
            // the shadow rays, world frame, towards the lit surface points from the projector
            let mut shadow = [[Vec3::Z; 4]; GROUPS];
            let mut length = [[0.0; 4]; GROUPS];
            for (g, lane) in lanes::<GROUPS>() {
                if let (Some((c, r)), Some(hit)) = (at[g][lane], &hits[g][lane]) {
                    let hit = self.world.surface(hit, self.origin, dirs[g][lane]);
                    let (row, px) = (BLOCK * band + r, &mut out[r * width + c]);
                    let lit = illuminate(self, c, row, centres[g][lane], hit, px);
                    if let Some(LitPixel {
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
            let blocked = self
                .world
                .bvh()
                .occluded_packet(&[[from; 4]; GROUPS], &shadow, &length);
            for (g, lane) in lanes::<GROUPS>() {
                if blocked[g][lane] {
                    let (c, r) = block_pixel(col, g, lane);
                    let lit = &mut lits[r * span + c - cols.start];
                    let px = &mut out[r * width + c];
                    *lit = lit.and_then(|lit| lit.in_shadow(self, px));
                }
            }
        }
    }
}

/// What a task keeps from band to band.
#[derive(Default)]
pub(super) struct Band {
    /// Pixels measured up to the projector's visibility, over the window's columns: one row's
    /// when rows are cut, the band's when blocks are cast.
    lits: Vec<Option<LitPixel>>,
    /// One row's first hits: slot and distance.
    hits: Vec<Option<(u32, f32)>>,
    /// One row's shadow rays, by position in the row.
    rays: Vec<(usize, Ray)>,
    cut: RowCut,
    /// What one row's mirror rays meet.
    mirrors: Vec<Option<Mirrored>>,
}

/// Puts the lit pixels of a cut row whose surface point the projector does not reach in its
/// shadow ([`LitPixel::in_shadow`]); `line` holds their pixels.
fn shade(
    setup: &Capture,
    epipolar: &Epipolar,
    cut: &mut RowCut,
    lits: &mut [Option<LitPixel>],
    line: &mut [Pixel],
    rays: &mut Vec<(usize, Ray)>,
) {
    rays.clear();
    for (i, lit) in lits.iter().enumerate() {
        if let Some(LitPixel {
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
            lits[i] = lits[i].and_then(|lit| lit.in_shadow(setup, &mut line[i]));
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

/// Pixels per side of the blocks a scan casts as one packet.
pub(super) const BLOCK: usize = 4;
/// 2×2 groups of four rays per block.
const GROUPS: usize = BLOCK * BLOCK / 4;
