//! Zivid's point-cloud filters on an organized scan (`Processing.Filters`): the reflection
//! filter's test over the frame, noise suppression and repair, outlier, hole and cluster
//! filters and Gaussian smoothing. The noise filter and the reflection filter's tests of each
//! pixel's light act where the pixel is decoded.

use glam::Vec3;
use rayon::prelude::*;

use super::{Pixel, Scan, Window, gaussian, reach};
use crate::spec::{Frustum, SensorSpec, Suppression};

/// Applies the enabled filters of `sensor`'s processing to the pixels of `window`: the global
/// reflection filter's shadowing points, the noise filter's suppression and repair, then
/// outliers, holes, clusters and smoothing.
pub(super) fn filter(scan: &mut Scan, window: &Window, sensor: &SensorSpec) {
    let filters = &sensor.processing.filters;
    if let Some(projector) = sensor.projector()
        && filters.reflection.removal.removes_shadowing()
    {
        remove_shadowing(scan, window, &projector.frustum(), sensor.intrinsics.fx);
    }
    if filters.noise.suppression.enabled && sensor.noise.snr.is_on() {
        suppress_noise(scan, window, sensor);
    }
    if filters.noise.repair.enabled && sensor.noise.snr.is_on() {
        repair_noise(scan, window, sensor);
    }
    let outlier = filters.outlier.removal;
    if outlier.enabled {
        remove_outliers(scan, window, outlier.threshold * 1e-3);
    }
    let holes = filters.hole.repair;
    let k = &sensor.intrinsics;
    if holes.enabled {
        let widest = holes.widest_px(k.fx);
        repair_holes(scan, window, sensor, widest, holes.strictness as usize);
    }
    let cluster = filters.cluster.removal;
    if cluster.enabled {
        // a neighbour's spacing and a pixel's footprint per metre of depth
        let spacing = cluster.max_neighbor_distance / k.fx as f32;
        let footprint = 1.0 / (k.fx * k.fy) as f32;
        remove_clusters(scan, window, spacing, cluster.min_area * 1e-6, footprint);
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

/// Gives each point of SNR below [`Suppression::BELOW`] the mean inverse depth of the points of
/// the 5×5 pixels around it within 3σ of its depth (σ its SNR's), keeping it on its ray.
fn suppress_noise(scan: &mut Scan, window: &Window, sensor: &SensorSpec) {
    const RADIUS: usize = 2;
    let (w, h) = (window.cols.len(), window.rows.len());
    let depth: Vec<f32> = points(scan, window).iter().map(|p| p.z).collect();
    let (snr, focal_baseline) = (sensor.noise.snr, sensor.focal_baseline());
    each_point(scan, window, |r, c, px| {
        if px.snr >= Suppression::BELOW {
            return;
        }
        let z = depth[r * w + c];
        let reach_z = 3.0 * snr.sigma_z(px.snr, z, focal_baseline);
        let (mut n, mut inverse) = (0.0, 0.0);
        for rr in reach(r, RADIUS, h) {
            for cc in reach(c, RADIUS, w) {
                let v = depth[rr * w + cc];
                if (v - z).abs() <= reach_z {
                    n += 1.0;
                    inverse += 1.0 / v;
                }
            }
        }
        px.point *= n / (inverse * z);
    });
}

/// Gives each pixel the noise filter removed (lit, its SNR below the filter's threshold, not
/// saturated) with points in at least 6 of its 8 neighbours a point on its own ray at their mean
/// inverse depth, if that lies in the working range.
fn repair_noise(scan: &mut Scan, window: &Window, sensor: &SensorSpec) {
    let (w, h) = (window.cols.len(), window.rows.len());
    let stride = scan.width as usize;
    let pixel = |r: usize, c: usize| (window.rows.start + r) * stride + window.cols.start + c;
    let before: Vec<f32> = (0..h)
        .flat_map(|r| (0..w).map(move |c| (r, c)))
        .map(|(r, c)| {
            let p = &scan.pixels[pixel(r, c)];
            if p.is_valid() {
                1.0 / p.point.z
            } else {
                f32::NAN
            }
        })
        .collect();
    let removed = |p: &Pixel| {
        !p.is_valid()
            && !p.clean.x.is_nan()
            && p.intensity > 0.0
            && p.snr > 0.0
            && sensor.filters_out(p.snr)
            && !sensor.noise.specular.saturates(p.intensity)
    };
    scan.pixels[window.rows.start * stride..window.rows.end * stride]
        .par_chunks_mut(stride)
        .enumerate()
        .for_each(|(r, line)| {
            for (c, px) in line[window.cols.clone()].iter_mut().enumerate() {
                if !removed(px) {
                    continue;
                }
                let around = reach(r, 1, h)
                    .flat_map(|rr| reach(c, 1, w).map(move |cc| (rr, cc)))
                    .filter(|&(rr, cc)| (rr, cc) != (r, c))
                    .map(|(rr, cc)| before[rr * w + cc])
                    .filter(|inverse| !inverse.is_nan());
                let (mut n, mut inverse) = (0, 0.0);
                for v in around {
                    n += 1;
                    inverse += v;
                }
                let z = n as f32 / inverse;
                if n < 6 || !sensor.in_range(z) {
                    continue;
                }
                let dir = px.clean.normalize();
                px.point = dir * (z / dir.z);
            }
        });
}

/// How far behind a point another must lie on its ray of the projector's light for the point
/// to shadow it, m: beyond the range noise of the least SNR the noise filter keeps (assumed).
const SHADOWED: f32 = 0.005;

/// The share of a pixel's light from other surfaces (of 255) above which its point can be
/// one they made, and the shadowing test applies (assumed).
const FROM_ELSEWHERE: u8 = 25;

/// Removes the points of `window` whose light shows other surfaces' (more than
/// [`FROM_ELSEWHERE`]) and that lie, by more than [`SHADOWED`], in front of another point on
/// the same ray of the projector's light (`frustum`), or behind one whose light is its own:
/// had their surface been there, it would have shadowed the other, which the projector lit,
/// or lain in its shadow. The rays are the cells of a grid over the projector's field a camera
/// pixel wide (the camera's focal length `fx`), each point tested against the farthest point
/// of its cell and the eight around it, and the nearest of those whose light is their own.
fn remove_shadowing(scan: &mut Scan, window: &Window, frustum: &Frustum, fx: f64) {
    let fx = fx as f32;
    let (half_w, half_h) = (frustum.half_width(), frustum.half_height());
    let [cols, rows] = [half_w, half_h].map(|half| (2.0 * half * fx).ceil() as usize + 1);
    // each point's cell and depth from the projector, row by row, and apart the points that
    // may be other surfaces' light
    let stride = scan.width as usize;
    type Located = (Vec<(u32, f32, bool)>, Vec<(usize, usize, f32)>);
    let located: Vec<Located> = scan.pixels[window.rows.start * stride..window.rows.end * stride]
        .par_chunks(stride)
        .enumerate()
        .map(|(r, line)| {
            let start = (window.rows.start + r) * stride + window.cols.start;
            let (mut points, mut mixed) = (Vec::with_capacity(window.cols.len()), Vec::new());
            for (c, px) in line[window.cols.clone()].iter().enumerate() {
                if !px.is_valid() {
                    continue;
                }
                let [column, row, depth] = frustum.locate(px.point);
                // the nearest cell (half a cell up, then truncated: no call to `round`)
                let [u, v] = [(column + half_w) * fx + 0.5, (row + half_h) * fx + 0.5];
                if u >= 0.0 && v >= 0.0 && (u as usize) < cols && (v as usize) < rows {
                    let cell = v as usize * cols + u as usize;
                    let own = px.indirect <= FROM_ELSEWHERE;
                    points.push((cell as u32, depth, own));
                    if !own {
                        mixed.push((start + c, cell, depth));
                    }
                }
            }
            (points, mixed)
        })
        .collect();
    let mixed: Vec<(usize, usize, f32)> =
        located.iter().flat_map(|l| l.1.iter().copied()).collect();
    if mixed.is_empty() {
        return;
    }
    // of each cell, the farthest point and the nearest of those whose light is their own
    let mut span = vec![[f32::NEG_INFINITY, f32::INFINITY]; rows * cols];
    for &(cell, depth, own) in located.iter().flat_map(|l| &l.0) {
        let [far, near_own] = &mut span[cell as usize];
        *far = far.max(depth);
        if own {
            *near_own = near_own.min(depth);
        }
    }
    let shadowing: Vec<usize> = mixed
        .par_iter()
        .filter(|&&(_, cell, depth)| {
            let (r, c) = (cell / cols, cell % cols);
            reach(r, 1, rows)
                .flat_map(|rr| reach(c, 1, cols).map(move |cc| rr * cols + cc))
                .any(|j| {
                    let [far, near_own] = span[j];
                    far > depth + SHADOWED || near_own < depth - SHADOWED
                })
        })
        .map(|m| m.0)
        .collect();
    for i in shadowing {
        scan.pixels[i].point = Vec3::NAN;
    }
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

/// Fills each pixel without a point that has points on at least `strictness` of its four sides
/// (along its row and column, within `widest` pixels) and on both sides along the row or the
/// column: on its own ray at the inverse depth interpolated linearly between the two sides
/// (the mean of the row's and the column's where both have two), with its own surface's labels
/// (or the nearest side's where it sees none).
fn repair_holes(
    scan: &mut Scan,
    window: &Window,
    sensor: &SensorSpec,
    widest: usize,
    strictness: usize,
) {
    let (w, h) = (window.cols.len(), window.rows.len());
    let stride = scan.width as usize;
    let inverse: Vec<f32> = points(scan, window).iter().map(|p| 1.0 / p.z).collect();
    let held = |r: usize, c: usize| !inverse[r * w + c].is_nan();
    // the nearest row with a point above and below each pixel, column by column
    let columns: Vec<[Vec<Option<usize>>; 2]> = (0..w)
        .into_par_iter()
        .map(|c| nearest_held(h, |r| held(r, c)))
        .collect();
    let source = &scan.pixels;
    let k = &sensor.intrinsics;
    let filled: Vec<Vec<(usize, Pixel)>> = (0..h)
        .into_par_iter()
        .map(|r| {
            // the nearest column with a point left and right of each pixel
            let [left, right] = nearest_held(w, |c| held(r, c));
            let mut out = Vec::new();
            for c in (0..w).filter(|&c| !held(r, c)) {
                let i = r * w + c;
                let [above, below] = &columns[c];
                // each side's (distance, window index), within reach
                let sides = [
                    left[c].map(|cc| (c - cc, r * w + cc)),
                    right[c].map(|cc| (cc - c, r * w + cc)),
                    above[r].map(|rr| (r - rr, rr * w + c)),
                    below[r].map(|rr| (rr - r, rr * w + c)),
                ]
                .map(|side| side.filter(|&(distance, _)| distance <= widest));
                if sides.iter().flatten().count() < strictness {
                    continue;
                }
                let between = |a: Option<(usize, usize)>, b: Option<(usize, usize)>| {
                    let ((da, ia), (db, ib)) = (a?, b?);
                    Some((db as f32 * inverse[ia] + da as f32 * inverse[ib]) / (da + db) as f32)
                };
                let spans = [between(sides[0], sides[1]), between(sides[2], sides[3])];
                let (n, sum) = spans
                    .iter()
                    .flatten()
                    .fold((0, 0.0), |(n, sum), v| (n + 1, sum + v));
                if n == 0 {
                    continue;
                }
                let z = n as f32 / sum;
                if !sensor.in_range(z) {
                    continue;
                }
                let Some(&(_, nearest)) = sides.iter().flatten().min() else {
                    continue;
                };
                let pixel =
                    |j: usize| (window.rows.start + j / w) * stride + window.cols.start + j % w;
                let (own, near) = (&source[pixel(i)], &source[pixel(nearest)]);
                let (col, row_in_image) = (window.cols.start + c, window.rows.start + r);
                let dir = k.ray(col as f64, row_in_image as f64);
                let labels = if own.clean.x.is_nan() { near } else { own };
                out.push((
                    pixel(i),
                    Pixel {
                        point: dir * (z / dir.z),
                        class: labels.class,
                        instance: labels.instance,
                        normal: labels.normal,
                        ..*own
                    },
                ));
            }
            out
        })
        .collect();
    for (i, px) in filled.into_iter().flatten() {
        scan.pixels[i] = px;
    }
}

/// Along a line of `len` cells, `held(k)` where cell k has a point: for each cell, the nearest
/// cell with a point at or before it, and at or after it.
fn nearest_held(len: usize, held: impl Fn(usize) -> bool) -> [Vec<Option<usize>>; 2] {
    let nearest = |order: &mut dyn Iterator<Item = usize>| {
        let mut line = vec![None; len];
        let mut last = None;
        for k in order {
            last = if held(k) { Some(k) } else { last };
            line[k] = last;
        }
        line
    };
    [nearest(&mut (0..len)), nearest(&mut (0..len).rev())]
}

/// Removes the clusters of points of less than `min_area` m², a cluster being the points joined
/// through 8-neighbours within `spacing` × their mean depth of each other, each point of
/// `footprint` × depth² m² (its pixel at its depth).
fn remove_clusters(scan: &mut Scan, window: &Window, spacing: f32, min_area: f32, footprint: f32) {
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
                let q = points[rr * w + cc];
                if q.distance_squared(p) <= (spacing * 0.5 * (p.z + q.z)).powi(2) {
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
