//! An object's silhouette in a view: the pixels whose centre ray meets it, whatever lies in
//! front of it (the unoccluded mask that a part's visible pixels are a share of).

use glam::Vec3;
use sensor::{Scan, SensorSpec, Target, World};

/// The pixels of a window of an image where an object lies.
#[derive(Clone, Debug, PartialEq)]
pub struct Silhouette {
    /// The window's first column and row.
    pub origin: [usize; 2],
    /// The window's columns and rows.
    pub size: [usize; 2],
    /// Whether each pixel of the window (row-major) sees the object.
    pub inside: Vec<bool>,
}

impl Silhouette {
    /// The silhouette of `targets` (one object, in one or several pieces) in `scan` (taken by
    /// `sensor`): the pixels of the scan's window within their projected bounds whose centre
    /// ray meets one of them.
    pub fn of(targets: &[Target], scan: &Scan, sensor: &SensorSpec) -> Silhouette {
        let k = &sensor.intrinsics;
        let w = &scan.window;
        let from_world = scan.pose.inverse();
        let (lo, hi) = targets.iter().flat_map(|t| &t.positions).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        // the window about the projected corners of the target's box (all of the scan's window
        // when a corner lies behind the camera)
        let corners = (0..8).map(|c| {
            let pick = |bit: usize, a: f32, b: f32| if c >> bit & 1 == 0 { a } else { b };
            from_world.transform_point3(Vec3::new(
                pick(0, lo.x, hi.x),
                pick(1, lo.y, hi.y),
                pick(2, lo.z, hi.z),
            ))
        });
        let projected: Option<Vec<(f64, f64)>> = corners.map(|p| k.project(p)).collect();
        let (cols, rows) = match projected {
            Some(uv) => {
                let (u0, u1, v0, v1) = uv.iter().fold(
                    (
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                        f64::INFINITY,
                        f64::NEG_INFINITY,
                    ),
                    |(a, b, c, d), &(u, v)| (a.min(u), b.max(u), c.min(v), d.max(v)),
                );
                // a pixel or two of margin for the distortion's bend between the corners
                let clamp = |x: f64, r: &std::ops::Range<usize>| {
                    (x.max(r.start as f64) as usize).clamp(r.start, r.end)
                };
                (
                    clamp(u0.floor() - 2.0, &w.cols)..clamp(u1.ceil() + 3.0, &w.cols),
                    clamp(v0.floor() - 2.0, &w.rows)..clamp(v1.ceil() + 3.0, &w.rows),
                )
            }
            None => (w.cols.clone(), w.rows.clone()),
        };
        let world = World::new(targets);
        let origin = Vec3::from(scan.pose.translation);
        let (w, h) = (cols.len(), rows.len());
        let mut inside = vec![false; w * h];
        let centres = k.centre_rays();
        // 4×4 pixels at a time, their rays traced as one packet
        for top in (0..h).step_by(4) {
            for left in (0..w).step_by(4) {
                let mut dirs = [[Vec3::Z; 4]; 4];
                // idle lanes past the window's edge
                let mut reach = [[0.0f32; 4]; 4];
                for (r, c) in (0..4).flat_map(|r| (0..4).map(move |c| (r, c))) {
                    if top + r < h && left + c < w {
                        let ray = centres.ray(cols.start + left + c, rows.start + top + r);
                        dirs[r][c] = scan.pose.transform_vector3(ray);
                        reach[r][c] = sensor.reach(ray);
                    }
                }
                let met = world
                    .bvh()
                    .occluded_packet(&[[origin; 4]; 4], &dirs, &reach);
                for (r, met) in met.iter().enumerate().take(h - top) {
                    let row = (top + r) * w + left;
                    let n = (w - left).min(4);
                    inside[row..row + n].copy_from_slice(&met[..n]);
                }
            }
        }
        Silhouette {
            origin: [cols.start, rows.start],
            size: [cols.len(), rows.len()],
            inside,
        }
    }

    /// Whether the image's pixel (`x`, `y`) is in the silhouette.
    pub fn contains(&self, x: usize, y: usize) -> bool {
        let ([x0, y0], [w, h]) = (self.origin, self.size);
        (x0..x0 + w).contains(&x) && (y0..y0 + h).contains(&y) && self.inside[(y - y0) * w + x - x0]
    }

    /// Pixels in the silhouette.
    pub fn area(&self) -> usize {
        self.inside.iter().filter(|&&b| b).count()
    }

    /// The tight box of its pixels, [x, y, width, height]; None when it has none.
    pub fn bbox(&self) -> Option<[usize; 4]> {
        let mask = crate::coco::Mask {
            width: self.size[0],
            height: self.size[1],
            inside: &self.inside,
        };
        let [x, y, w, h] = mask.bbox()?;
        Some([x + self.origin[0], y + self.origin[1], w, h])
    }
}
