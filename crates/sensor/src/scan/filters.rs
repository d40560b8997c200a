//! Zivid's point-cloud filters on an organized scan (`Processing.Filters`): outlier removal and
//! Gaussian smoothing. The noise filter acts where each pixel is measured.

use glam::Vec3;
use rayon::prelude::*;

use super::{Pixel, Scan, Window, gaussian, reach};
use crate::spec::Filters;

/// Applies the enabled filters of `filters` to the pixels of `window`: outliers first, then
/// smoothing.
pub(super) fn filter(scan: &mut Scan, window: &Window, filters: &Filters) {
    let outlier = filters.outlier.removal;
    if outlier.enabled {
        remove_outliers(scan, window, outlier.threshold * 1e-3);
    }
    let gaussian = filters.smoothing.gaussian;
    if gaussian.enabled && gaussian.sigma > 0.0 {
        smooth(scan, window, gaussian.sigma);
    }
}

/// The points of `window`, row by row (NaN where there is none).
fn points(scan: &Scan, window: &Window) -> Vec<Vec3> {
    let stride = scan.width as usize;
    window
        .rows
        .clone()
        .flat_map(|r| &scan.pixels[r * stride + window.cols.start..r * stride + window.cols.end])
        .map(|p| p.point)
        .collect()
}

/// `f` of each pixel of `window` with a point, in parallel by rows: its row and column in the
/// window, and the pixel.
fn each_point(scan: &mut Scan, window: &Window, f: impl Fn(usize, usize, &mut Pixel) + Sync) {
    let stride = scan.width as usize;
    scan.pixels[window.rows.start * stride..window.rows.end * stride]
        .par_chunks_mut(stride)
        .enumerate()
        .for_each(|(r, line)| {
            for (c, px) in line[window.cols.clone()].iter_mut().enumerate() {
                if px.is_valid() {
                    f(r, c, px);
                }
            }
        });
}

/// Removes the points none of whose 8 neighbours lies within `threshold` metres.
fn remove_outliers(scan: &mut Scan, window: &Window, threshold: f32) {
    let (w, h) = (window.cols.len(), window.rows.len());
    let points = points(scan, window);
    let limit = threshold * threshold;
    each_point(scan, window, |r, c, px| {
        let near = reach(r, 1, h)
            .flat_map(|rr| reach(c, 1, w).map(move |cc| (rr, cc)))
            .filter(|&(rr, cc)| (rr, cc) != (r, c))
            .any(|(rr, cc)| points[rr * w + cc].distance_squared(px.point) <= limit);
        if !near {
            px.point = Vec3::NAN;
        }
    });
}

/// Replaces each point's depth with the Gaussian-weighted mean (σ `sigma` pixels, within 2.5σ)
/// of the inverse depths of the points around it, keeping it on its ray.
fn smooth(scan: &mut Scan, window: &Window, sigma: f32) {
    let (w, h) = (window.cols.len(), window.rows.len());
    let inverse: Vec<f32> = points(scan, window).iter().map(|p| 1.0 / p.z).collect();
    let radius = (2.5 * sigma).ceil() as usize;
    let taps = gaussian(sigma, radius);
    each_point(scan, window, |r, c, px| {
        let (mut sum, mut weights) = (0.0, 0.0);
        for rr in reach(r, radius, h) {
            for cc in reach(c, radius, w) {
                let v = inverse[rr * w + cc];
                if !v.is_nan() {
                    let weight = taps[rr + radius - r] * taps[cc + radius - c];
                    sum += weight * v;
                    weights += weight;
                }
            }
        }
        px.point *= inverse[r * w + c] * weights / sum;
    });
}
