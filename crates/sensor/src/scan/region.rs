//! The pixels a scan casts: those whose centre rays can cross a region of the world.

use std::ops::Range;

use glam::{Affine3A, DVec3, Vec3};

use crate::camera::Intrinsics;
use crate::epipolar::NEAR;

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
    pub(super) fn corners_in(&self, pose: &Affine3A) -> [DVec3; 8] {
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

    /// The pixels whose centre rays can cross the box: the bounding rectangle of its projected corners, widened by a pixel; `None` where that
    /// bounds nothing (a lens with distortion, or a corner not in front of the camera).
    pub fn pixel_window(&self, k: &Intrinsics, pose: &Affine3A) -> Option<Window> {
        if !k.distortion.is_none() {
            return None;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for corner in self.corners_in(pose) {
            let (u, v) = k.project(corner.as_vec3())?;
            (lo, hi) = ([lo[0].min(u), lo[1].min(v)], [hi[0].max(u), hi[1].max(v)]);
        }
        let clamp = |x: f64, n: u32| x.clamp(0.0, n as f64) as usize;
        Some(Window {
            cols: clamp(lo[0].floor() - 1.0, k.width)..clamp(hi[0].ceil() + 2.0, k.width),
            rows: clamp(lo[1].floor() - 1.0, k.height)..clamp(hi[1].ceil() + 2.0, k.height),
        })
    }
}

/// A rectangle of pixels: columns `cols` of rows `rows` (none by default).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Window {
    /// Columns.
    pub cols: Range<usize>,
    /// Rows.
    pub rows: Range<usize>,
}

impl Window {
    /// Every pixel of camera `k`.
    pub fn full(k: &Intrinsics) -> Window {
        Window {
            cols: 0..k.width as usize,
            rows: 0..k.height as usize,
        }
    }
}

/// The columns of `cols` in `row` of a pinhole camera `k` whose centre rays may cross the box
/// with camera-frame `corners` ([`Region::corners_in`]): those towards the cut of the box by
/// the row's plane, with a column to spare either side; all of `cols` where the cut reaches
/// behind the camera.
pub(super) fn row_columns(
    corners: &[DVec3; 8],
    k: &Intrinsics,
    row: usize,
    cols: &Range<usize>,
) -> Range<usize> {
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
