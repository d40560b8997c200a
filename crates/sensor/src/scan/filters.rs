//! Zivid's point-cloud filters on an organized scan (`Processing.Filters`): outlier removal and
//! Gaussian smoothing. The noise filter acts where each pixel is measured.

use glam::Vec3;
use rayon::prelude::*;

use super::{Scan, Window, gaussian};
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

/// Removes the points none of whose 8 neighbours lies within `threshold` metres.
fn remove_outliers(scan: &mut Scan, window: &Window, threshold: f32) {
    let (w, h) = (window.cols.len(), window.rows.len());
    let points = points(scan, window);
    let stride = scan.width as usize;
    let limit = threshold * threshold;
    scan.pixels[window.rows.start * stride..window.rows.end * stride]
        .par_chunks_mut(stride)
        .enumerate()
        .for_each(|(r, line)| {
            for c in 0..w {
                let p = points[r * w + c];
                if p.x.is_nan() {
                    continue;
                }
                let near = (r.saturating_sub(1)..(r + 2).min(h))
                    .flat_map(|rr| (c.saturating_sub(1)..(c + 2).min(w)).map(move |cc| (rr, cc)))
                    .filter(|&(rr, cc)| (rr, cc) != (r, c))
                    .any(|(rr, cc)| points[rr * w + cc].distance_squared(p) <= limit);
                if !near {
                    line[window.cols.start + c].point = Vec3::NAN;
                }
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
    let stride = scan.width as usize;
    scan.pixels[window.rows.start * stride..window.rows.end * stride]
        .par_chunks_mut(stride)
        .enumerate()
        .for_each(|(r, line)| {
            for c in 0..w {
                let own = inverse[r * w + c];
                if own.is_nan() {
                    continue;
                }
                let (mut sum, mut weights) = (0.0, 0.0);
                for rr in r.saturating_sub(radius)..(r + radius + 1).min(h) {
                    for cc in c.saturating_sub(radius)..(c + radius + 1).min(w) {
                        let v = inverse[rr * w + cc];
                        if !v.is_nan() {
                            let weight = taps[rr + radius - r] * taps[cc + radius - c];
                            sum += weight * v;
                            weights += weight;
                        }
                    }
                }
                line[window.cols.start + c].point *= own * weights / sum;
            }
        });
}
