//! Pinhole cameras with Brown–Conrady distortion (OpenCV's k1, k2, p1, p2, k3, as Zivid reports
//! them), binning and poses. Camera frame as OpenCV and Zivid: x right (towards the projector),
//! y down, z forward. Pixel (u, v) = (column, row) has its centre at integer coordinates.

use std::sync::{Arc, Mutex};

use glam::{Affine3A, Mat3A, Vec3, Vec3A};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Error;

/// Brown–Conrady lens distortion in normalised image coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Distortion {
    /// Radial r² coefficient.
    pub k1: f64,
    /// Radial r⁴ coefficient.
    pub k2: f64,
    /// Radial r⁶ coefficient.
    pub k3: f64,
    /// Tangential coefficient 1.
    pub p1: f64,
    /// Tangential coefficient 2.
    pub p2: f64,
}

/// The coefficients as a sensor TOML gives them: `{ k1 = …, k2 = …, p1 = …, p2 = …, k3 = … }`.
impl std::fmt::Display for Distortion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let Distortion { k1, k2, p1, p2, k3 } = self;
        write!(
            f,
            "{{ k1 = {k1}, k2 = {k2}, p1 = {p1}, p2 = {p2}, k3 = {k3} }}"
        )
    }
}

impl Distortion {
    /// Whether all coefficients are zero.
    #[inline]
    pub fn is_none(&self) -> bool {
        [self.k1, self.k2, self.k3, self.p1, self.p2] == [0.0; 5]
    }

    /// The radial factor at squared radius `r2` and its derivative by `r2`.
    #[inline]
    fn radial(&self, r2: f64) -> (f64, f64) {
        let Distortion { k1, k2, k3, .. } = *self;
        (
            1.0 + r2 * (k1 + r2 * (k2 + r2 * k3)),
            k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3),
        )
    }

    /// Whether the distorted radius grows with the radius out to squared radius `r2` (the
    /// image does not fold over itself there).
    fn monotonic_to(&self, r2: f64) -> bool {
        (0..=100).all(|k| {
            let r2 = r2 * f64::from(k) / 100.0;
            let (radial, slope) = self.radial(r2);
            radial + 2.0 * r2 * slope > 0.0
        })
    }

    /// Distorts ideal normalised coordinates (x, y) = (X/Z, Y/Z).
    pub fn distort(&self, x: f64, y: f64) -> (f64, f64) {
        let r2 = x * x + y * y;
        let (radial, _) = self.radial(r2);
        let dx = 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x);
        let dy = self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y;
        (x * radial + dx, y * radial + dy)
    }

    /// Inverts [`Distortion::distort`] by Newton's method from the distorted point, to a step
    /// of 1e-12 or 20 iterations (three or four for a lens's distortion: it converges
    /// quadratically where OpenCV's fixed-point iteration gains a constant factor a step).
    pub fn undistort(&self, xd: f64, yd: f64) -> (f64, f64) {
        if self.is_none() {
            return (xd, yd);
        }
        let (p1, p2) = (self.p1, self.p2);
        let (mut x, mut y) = (xd, yd);
        for _ in 0..20 {
            let (radial, slope) = self.radial(x * x + y * y);
            let (fx, fy) = self.distort(x, y);
            let (ex, ey) = (fx - xd, fy - yd);
            let j11 = radial + 2.0 * x * x * slope + 2.0 * p1 * y + 6.0 * p2 * x;
            let j12 = 2.0 * x * y * slope + 2.0 * p1 * x + 2.0 * p2 * y;
            let j22 = radial + 2.0 * y * y * slope + 6.0 * p1 * y + 2.0 * p2 * x;
            let det = j11 * j22 - j12 * j12;
            if det.abs() < 1e-12 {
                break;
            }
            let (sx, sy) = ((j22 * ex - j12 * ey) / det, (j11 * ey - j12 * ex) / det);
            (x, y) = (x - sx, y - sy);
            if sx.abs().max(sy.abs()) < 1e-12 {
                break;
            }
        }
        (x, y)
    }
}

/// Image size, focal lengths and principal point in pixels, and lens distortion.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Intrinsics {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point column.
    pub cx: f64,
    /// Principal point row.
    pub cy: f64,
    /// Lens distortion.
    #[serde(default)]
    pub distortion: Distortion,
}

impl Intrinsics {
    /// An undistorted camera with the principal point at the image centre and the given full
    /// horizontal and vertical fields of view, degrees.
    pub fn from_fov(width: u32, height: u32, hfov_deg: f64, vfov_deg: f64) -> Intrinsics {
        let f = |n: u32, fov: f64| n as f64 / 2.0 / (fov.to_radians() / 2.0).tan();
        Intrinsics {
            width,
            height,
            fx: f(width, hfov_deg),
            fy: f(height, vfov_deg),
            cx: (width as f64 - 1.0) / 2.0,
            cy: (height as f64 - 1.0) / 2.0,
            distortion: Distortion::default(),
        }
    }

    /// Checks that the camera can exist: a non-empty image, positive finite focal lengths, the
    /// principal point on the image, finite distortion that keeps the image one-to-one.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a size of zero or above 16384, a focal length
    /// that is not positive and finite, a principal point outside the image, or distortion that
    /// does not map the image one to one.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |what: &str, value: String, allowed: &str| {
            Err(Error::Invalid {
                key: format!("intrinsics.{what}"),
                value,
                allowed: allowed.into(),
            })
        };
        if self.width == 0 || self.height == 0 || self.width > 16384 || self.height > 16384 {
            return bad(
                "width/height",
                format!("{}x{}", self.width, self.height),
                "1 to 16384 pixels each",
            );
        }
        for (name, f) in [("fx", self.fx), ("fy", self.fy)] {
            if !(f.is_finite() && f > 0.0) {
                return bad(name, f.to_string(), "a positive focal length in pixels");
            }
        }
        if !(self.cx >= -0.5 && self.cx <= self.width as f64 - 0.5) {
            return bad("cx", self.cx.to_string(), "a column on the image");
        }
        if !(self.cy >= -0.5 && self.cy <= self.height as f64 - 0.5) {
            return bad("cy", self.cy.to_string(), "a row on the image");
        }
        let d = self.distortion;
        if ![d.k1, d.k2, d.k3, d.p1, d.p2]
            .iter()
            .all(|c| c.is_finite() && c.abs() < 100.0)
        {
            return bad(
                "distortion",
                d.to_string(),
                "finite coefficients below 100 in magnitude",
            );
        }
        // the distortion must map the image corners back consistently
        for (u, v) in [
            (0.0, 0.0),
            (self.width as f64 - 1.0, self.height as f64 - 1.0),
            (0.0, self.height as f64 - 1.0),
        ] {
            let (x, y) = d.undistort((u - self.cx) / self.fx, (v - self.cy) / self.fy);
            let (xd, yd) = d.distort(x, y);
            let err = ((xd * self.fx + self.cx - u).abs()).max((yd * self.fy + self.cy - v).abs());
            // and never fold the image over itself out to the corner
            let folds = !d.monotonic_to(x * x + y * y);
            if err.is_nan() || err >= 1e-3 || folds {
                return bad(
                    "distortion",
                    d.to_string(),
                    "coefficients whose distortion can be inverted over the image",
                );
            }
        }
        Ok(())
    }

    /// The camera with `factor`×`factor` pixels binned into one (1, 2 or 4 on Zivid cameras):
    /// each new pixel centred on its block.
    pub fn binned(&self, factor: u32) -> Intrinsics {
        self.sampled(factor, (factor as f64 - 1.0) / 2.0)
    }

    /// The camera that keeps one pixel position of each `factor`×`factor` block: the one
    /// `offset` pixels from the block's first along each axis (Zivid's pixel mapping: 0 for the
    /// blue pixel of a 2×2 Bayer block, 1 for the red one, ½ for the block's centre).
    pub fn sampled(&self, factor: u32, offset: f64) -> Intrinsics {
        let f = factor as f64;
        Intrinsics {
            width: self.width / factor,
            height: self.height / factor,
            fx: self.fx / f,
            fy: self.fy / f,
            cx: (self.cx - offset) / f,
            cy: (self.cy - offset) / f,
            distortion: self.distortion,
        }
    }

    /// The camera's image resized to `width`×`height`: scaled to cover it, square pixels kept,
    /// and the excess cut off evenly on both sides (a network's input size); the scale is the
    /// second value.
    pub fn resized(&self, width: u32, height: u32) -> (Intrinsics, f64) {
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let scale = (f64::from(width) / w).max(f64::from(height) / h);
        // pixel centres: the old edge at -0.5 stays at -0.5 before the cut
        let at = |c: f64, old: f64, new: u32| {
            (c + 0.5) * scale - 0.5 - (old * scale - f64::from(new)) / 2.0
        };
        let k = Intrinsics {
            width,
            height,
            fx: self.fx * scale,
            fy: self.fy * scale,
            cx: at(self.cx, w, width),
            cy: at(self.cy, h, height),
            distortion: self.distortion,
        };
        (k, scale)
    }

    /// Unit direction, in the camera frame, of the ray through pixel coordinates (u, v).
    #[inline]
    pub fn ray(&self, u: f64, v: f64) -> Vec3 {
        let (x, y) = self
            .distortion
            .undistort((u - self.cx) / self.fx, (v - self.cy) / self.fy);
        Vec3::new(x as f32, y as f32, 1.0).normalize()
    }

    /// The rays through the centres of its pixels: exactly [`Intrinsics::ray`] at whole
    /// coordinates, with distortion undistorted once per camera and shared (the last few
    /// cameras' are kept).
    pub fn centre_rays(&self) -> CentreRays {
        CentreRays {
            k: *self,
            table: centre_rays(self),
        }
    }

    /// Pixel coordinates (u, v) of a camera-frame point in front of the camera.
    pub fn project(&self, p: Vec3) -> Option<(f64, f64)> {
        if p.z <= 0.0 {
            return None;
        }
        let (x, y) = self
            .distortion
            .distort(p.x as f64 / p.z as f64, p.y as f64 / p.z as f64);
        Some((x * self.fx + self.cx, y * self.fy + self.cy))
    }

    /// Full horizontal and vertical fields of view through the principal point, degrees
    /// (ignoring distortion).
    pub fn fov_deg(&self) -> (f64, f64) {
        let half = |n: f64, c: f64, f: f64| ((c + 0.5) / f).atan() + ((n - c - 0.5) / f).atan();
        (
            half(self.width as f64, self.cx, self.fx).to_degrees(),
            half(self.height as f64, self.cy, self.fy).to_degrees(),
        )
    }
}

/// The rays through the pixels' centres of the cameras that cast them last: each camera's
/// undistorted once (a frame's rays every frame otherwise).
static CENTRES: Mutex<Vec<(Intrinsics, Arc<[Vec3]>)>> = Mutex::new(Vec::new());
/// Cameras whose centre rays [`centre_rays`] keeps.
const CAMERAS_KEPT: usize = 4;

/// The rays through the pixels' centres of a camera ([`Intrinsics::centre_rays`]).
#[derive(Clone, Debug)]
pub struct CentreRays {
    k: Intrinsics,
    /// Each pixel's ray, row by row, for a camera with distortion (a camera without makes its
    /// rays for less than reading them costs).
    table: Option<Arc<[Vec3]>>,
}

impl CentreRays {
    /// Unit direction, camera frame, of the ray through the centre of pixel (`col`, `row`).
    #[inline]
    pub fn ray(&self, col: usize, row: usize) -> Vec3 {
        match &self.table {
            Some(rays) => rays[row * self.k.width as usize + col],
            None => self.k.ray(col as f64, row as f64),
        }
    }
}

/// The table of [`CentreRays`] of `k`, kept or made; None without distortion.
fn centre_rays(k: &Intrinsics) -> Option<Arc<[Vec3]>> {
    if k.distortion.is_none() {
        return None;
    }
    let kept = || {
        CENTRES
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    };
    if let Some((_, rays)) = kept().iter().find(|(other, _)| other == k) {
        return Some(rays.clone());
    }
    // made without the lock: a thread waiting here may be the one a parallel loop inside
    // another thread's making runs a task on
    let width = k.width as usize;
    let rays: Arc<[Vec3]> = (0..width * k.height as usize)
        .into_par_iter()
        .map(|i| k.ray((i % width) as f64, (i / width) as f64))
        .collect::<Vec<_>>()
        .into();
    let mut kept = kept();
    if !kept.iter().any(|(other, _)| other == k) {
        if kept.len() == CAMERAS_KEPT {
            kept.remove(0);
        }
        kept.push((*k, rays.clone()));
    }
    Some(rays)
}

/// A camera's rays through any point of its image, for casting many rays per pixel: without
/// distortion [`Intrinsics::ray`] itself; with it, the normalised coordinates undistorted once on
/// a grid every [`RayGrid::STEP`] pixels and interpolated bilinearly between (the inverse
/// distortion is smooth: within 0.001 pixel of [`Intrinsics::ray`] for the industrial preset's
/// lens, 0.003 for one three times as strong).
pub(crate) struct RayGrid {
    k: Intrinsics,
    /// Grid points per row.
    cols: usize,
    /// Undistorted normalised coordinates (x, y) of the grid's points, row by row, from pixel
    /// (-1, -1).
    points: Vec<(f64, f64)>,
}

impl RayGrid {
    /// Pixels between grid points.
    pub(crate) const STEP: f64 = 8.0;

    /// The grid of `k`, covering its image and a pixel beyond each edge.
    pub(crate) fn new(k: &Intrinsics) -> RayGrid {
        if k.distortion.is_none() {
            return RayGrid {
                k: *k,
                cols: 0,
                points: Vec::new(),
            };
        }
        let count = |n: u32| ((f64::from(n) + 1.0) / Self::STEP).ceil() as usize + 2;
        let (cols, rows) = (count(k.width), count(k.height));
        let points = (0..rows)
            .flat_map(|r| (0..cols).map(move |c| (c, r)))
            .map(|(c, r)| {
                let (u, v) = (c as f64 * Self::STEP - 1.0, r as f64 * Self::STEP - 1.0);
                k.distortion.undistort((u - k.cx) / k.fx, (v - k.cy) / k.fy)
            })
            .collect();
        RayGrid {
            k: *k,
            cols,
            points,
        }
    }

    /// Unit direction, in the camera frame, of the ray through pixel coordinates (u, v), for
    /// u and v from -1 to the width and height.
    #[inline]
    pub(crate) fn ray(&self, u: f64, v: f64) -> Vec3 {
        if self.points.is_empty() {
            return self.k.ray(u, v);
        }
        let (gu, gv) = ((u + 1.0) / Self::STEP, (v + 1.0) / Self::STEP);
        let rows = self.points.len() / self.cols;
        let (c, r) = (
            (gu as usize).min(self.cols - 2),
            (gv as usize).min(rows - 2),
        );
        let (fu, fv) = (gu - c as f64, gv - r as f64);
        let at = |c: usize, r: usize| self.points[r * self.cols + c];
        let lerp =
            |a: (f64, f64), b: (f64, f64), f: f64| (a.0 + (b.0 - a.0) * f, a.1 + (b.1 - a.1) * f);
        let top = lerp(at(c, r), at(c + 1, r), fu);
        let bottom = lerp(at(c, r + 1), at(c + 1, r + 1), fu);
        let (x, y) = lerp(top, bottom, fv);
        Vec3::new(x as f32, y as f32, 1.0).normalize()
    }
}

/// The camera-to-world pose of a camera at `eye` looking at `target`, with image "up" as close
/// to `up` as possible (x right, y down, z forward). Looking along `up` itself, world +y (or +x)
/// serves as up.
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Option<Affine3A> {
    let forward = (target - eye).try_normalize()?;
    let right = [up, Vec3::Y, Vec3::X].into_iter().find_map(|u| {
        let r = forward.cross(u);
        (r.length() > 1e-3).then(|| r.normalize())
    })?;
    let down = forward.cross(right);
    Some(Affine3A {
        matrix3: Mat3A::from_cols(right.into(), down.into(), forward.into()),
        translation: Vec3A::from(eye),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_grid_follows_the_lens_within_thousandths_of_a_pixel() {
        // the industrial preset's lens and one bent three times as hard, at pixel coordinates
        // across the image and a pixel beyond its edges
        let mut k = Intrinsics::from_fov(1280, 1024, 40.0, 32.0);
        for (k1, k2, p, within) in [(-0.10, 0.15, 1e-4, 1e-3), (-0.30, 0.45, 3e-4, 3e-3)] {
            k.distortion = Distortion {
                k1,
                k2,
                p1: p,
                p2: -p,
                ..Distortion::default()
            };
            let grid = RayGrid::new(&k);
            let mut worst: f64 = 0.0;
            for i in 0..=200 {
                for j in 0..=160 {
                    let (u, v) = (i as f64 * 6.405 - 1.0, j as f64 * 6.4 - 1.0);
                    let (got, want) = (grid.ray(u, v), k.ray(u, v));
                    let (gu, gv) = k.project(got).expect("in front");
                    let (wu, wv) = k.project(want).expect("in front");
                    worst = worst.max((gu - wu).hypot(gv - wv));
                }
            }
            assert!(worst < within, "k1 {k1}: {worst} px");
        }
        // without distortion the grid is the camera's own ray
        k.distortion = Distortion::default();
        assert_eq!(RayGrid::new(&k).ray(3.25, 7.5), k.ray(3.25, 7.5));
    }

    #[test]
    fn centre_rays_are_the_cameras_own_made_once() {
        let mut k = Intrinsics::from_fov(64, 48, 40.0, 30.0);
        assert!(k.centre_rays().table.is_none());
        k.distortion.k1 = -0.2;
        let rays = k.centre_rays();
        let table = rays.table.clone().expect("a lens with distortion");
        for i in 0..64 * 48 {
            let (col, row) = (i % 64, i / 64);
            assert_eq!(table[i], k.ray(col as f64, row as f64));
            assert_eq!(rays.ray(col, row), table[i]);
        }
        assert!(Arc::ptr_eq(&table, &k.centre_rays().table.expect("kept")));
        k.distortion.k1 = -0.1;
        assert_ne!(k.centre_rays().ray(0, 0), table[0]);
    }
}
