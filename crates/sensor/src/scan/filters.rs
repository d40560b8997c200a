//! Zivid's point-cloud filters on an organized scan (`Processing.Filters`): outlier and cluster
//! removal and Gaussian smoothing. The noise and reflection filters act where each pixel is
//! decoded.

use glam::Vec3;
use rayon::prelude::*;

use super::{Pixel, Scan, Window, gaussian, reach};
use crate::spec::SensorSpec;

/// Applies the enabled filters of `sensor`'s processing to the pixels of `window`: outliers
/// first, then clusters, then smoothing.
pub(super) fn filter(scan: &mut Scan, window: &Window, sensor: &SensorSpec) {
    let filters = &sensor.processing.filters;
    let outlier = filters.outlier.removal;
    if outlier.enabled {
        remove_outliers(scan, window, outlier.threshold * 1e-3);
    }
    let cluster = filters.cluster.removal;
    if cluster.enabled {
        let k = &sensor.intrinsics;
        let footprint = 1.0 / (k.fx * k.fy) as f32;
        let (distance, area) = (
            cluster.max_neighbor_distance * 1e-3,
            cluster.min_area * 1e-6,
        );
        remove_clusters(scan, window, distance, area, footprint);
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

/// Removes the clusters of points of less than `min_area` m², a cluster being the points joined
/// through 8-neighbours within `distance` m of each other, each point of `footprint` × depth²
/// m² (its pixel at its depth).
fn remove_clusters(scan: &mut Scan, window: &Window, distance: f32, min_area: f32, footprint: f32) {
    let (w, h) = (window.cols.len(), window.rows.len());
    let points = points(scan, window);
    // union-find over the window's pixels: each joined to its neighbours right and below
    let mut parent: Vec<u32> = (0..(w * h) as u32).collect();
    fn root(parent: &mut [u32], mut i: u32) -> u32 {
        while parent[i as usize] != i {
            parent[i as usize] = parent[parent[i as usize] as usize];
            i = parent[i as usize];
        }
        i
    }
    let limit = distance * distance;
    for r in 0..h {
        for c in 0..w {
            let p = points[r * w + c];
            if p.x.is_nan() {
                continue;
            }
            let below = (r + 1 < h).then_some(r + 1);
            let after = [
                (Some(r), c + 1),
                (below, c.wrapping_sub(1)),
                (below, c),
                (below, c + 1),
            ];
            for (rr, cc) in after {
                let Some(rr) = rr.filter(|_| cc < w) else {
                    continue;
                };
                if points[rr * w + cc].distance_squared(p) <= limit {
                    let (a, b) = (
                        root(&mut parent, (r * w + c) as u32),
                        root(&mut parent, (rr * w + cc) as u32),
                    );
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
    }
    let roots: Vec<u32> = (0..(w * h) as u32).map(|i| root(&mut parent, i)).collect();
    let mut area = vec![0.0f32; w * h];
    for (p, &k) in points.iter().zip(&roots) {
        if !p.x.is_nan() {
            area[k as usize] += footprint * p.z * p.z;
        }
    }
    each_point(scan, window, |r, c, px| {
        if area[roots[r * w + c] as usize] < min_area {
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
