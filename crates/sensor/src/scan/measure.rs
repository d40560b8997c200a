//! A lit pixel measured as a point: where it samples, the working range, range noise,
//! disparity, bias and quantization; and the effects of neighbours (mixed pixels, the
//! Kinect window).

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use super::cast::Capture;
use super::decode::{Light, decode};
use super::diffuse::FAINT;
use super::light::LitPixel;
use super::mirror::{Mirrored, mirrored};
use super::{Pixel, Scan, round};
use crate::noise::{PixelRng, stream};
use crate::spec::{Model, SensorSpec};

/// Measures labelled pixel `px` of a lit surface point, or of a shiny one in the projector's
/// shadow: the light other surfaces send it (interreflection: what its mirror ray meets,
/// `mirror`, and the diffuse light), the noise
/// filter, where it samples (its centre, or a laterally jittered position), whether that
/// surface lies in the working range, range noise and quantisation.
pub(super) fn measure(setup: &Capture, lit: &LitPixel, mirror: Option<&Mirrored>, px: &mut Pixel) {
    let Capture {
        sensor, pinhole, ..
    } = *setup;
    let k = &sensor.intrinsics;
    let noise = &sensor.noise;
    let LitPixel {
        pixel: [col, row],
        centre,
        t,
        signal,
        snr,
        light,
        rng,
        ..
    } = *lit;
    (px.intensity, px.snr) = (signal, snr);
    // the light of other surfaces: the one a shiny surface mirrors, and the diffuse light of
    // those around it; the pixel decodes them and its own stripes together
    if let Some(stripes) = &setup.stripes {
        let mirrored = mirror.map(|seen| mirrored(setup, stripes, lit, seen));
        let diffuse = setup
            .diffuse
            .as_ref()
            .and_then(|d| d.at(lit.pixel, px.clean, px.normal))
            .filter(|d| d.amplitude * lit.reflectivity > FAINT * signal.max(0.0));
        if mirrored.is_some() || (light > 0.0 && diffuse.is_some()) {
            let column = stripes.frustum.column(px.clean);
            let contrast = [stripes.smooth, 1.0, 1.0];
            let mut sum = Light::new(signal, snr, column, contrast, stripes, &noise.snr);
            if let Some(mirrored) = &mirrored {
                sum.add(mirrored, 1.0);
            }
            if let Some(diffuse) = &diffuse {
                sum.add(diffuse, lit.reflectivity);
            }
            let own = *px;
            let at = [col as usize, row as usize];
            *px = decode(setup, stripes, &sum, at, &own, &own, false);
            return;
        }
    }
    // in the projector's shadow, only mirrored light makes a point
    if light == 0.0 || sensor.filters_out(snr) {
        return;
    }
    // where this pixel actually samples: its centre, or a laterally jittered position on the
    // tangent plane of the surface it sees
    let (dir, range) = if noise.lateral_px > 0.0 {
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
    // the working range bounds the surface's depth (camera z) before noise, so that noise
    // near a limit is not cut off
    if !sensor.in_range(range * dir.z) {
        return;
    }
    let Some(range) = noisy_range(setup, rng, [col, row], dir, range, snr, px.incidence) else {
        return;
    };
    px.point = dir * range;
}

/// The range a pixel at `pixel` (column, row) measures along camera direction `dir` of a
/// surface at `range`, with signal-to-noise ratio `snr` and incidence `incidence`: range noise
/// (axial and from the SNR, white or correlated), the camera's calibration error, a Kinect's
/// disparity steps, the per-scan bias and quantisation; `None` where no range results.
pub(super) fn noisy_range(
    setup: &Capture,
    rng: PixelRng,
    [col, row]: [u32; 2],
    dir: Vec3,
    mut range: f32,
    snr: f32,
    incidence: f32,
) -> Option<f32> {
    let Capture {
        sensor,
        bias,
        ref calibration,
        focal_baseline,
        lattice,
        ..
    } = *setup;
    let k = &sensor.intrinsics;
    let noise = &sensor.noise;
    let axial = noise.axial.sigma_at(range) * noise.incidence.factor(incidence);
    let sigma = if noise.snr.is_on() {
        let z = range * dir.z;
        let decoded = noise.snr.sigma_z(snr, z, focal_baseline) / dir.z;
        (axial * axial + decoded * decoded).sqrt()
    } else {
        axial
    };
    if sigma > 0.0 {
        let white = rng.normal(stream::AXIAL);
        let width = k.width as usize;
        let draw = noise
            .correlated
            .draw(white, lattice, col as usize, row as usize, width);
        range += sigma * draw;
    }
    if let Some(error) = calibration {
        range *= error.factor(dir);
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
            return None;
        }
        range = fb / disparity / dir.z;
    }
    range = range * bias.0 + bias.1;
    if noise.quantization > 0.0 {
        range = round(range / noise.quantization) * noise.quantization;
    }
    (range > 0.0).then_some(range) // (NaN is not)
}

/// Mixed pixels: an edge pixel may be pulled along its own ray towards its neighbour's depth.
/// Only `rows` can hold points.
pub(super) fn mixed_pixels(scan: &mut Scan, rows: Range<usize>, sensor: &SensorSpec, seed: u64) {
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
pub(super) fn window_filter(scan: &mut Scan, window: usize, fraction: f32, inlier: f32) {
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
