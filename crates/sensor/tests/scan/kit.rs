//! Scenes, cameras and statistics the scan tests share.

use ::sensor::*;
use glam::{Affine3A, Vec3};

/// A rectangle in the plane through `c` spanned by `a` and `b` (half extents), as a target.
pub fn quad(c: Vec3, a: Vec3, b: Vec3, class: u16, instance: u32) -> Target {
    let tris = shapes::rectangle(c, a, b);
    Target::from_triangles(&tris, class, instance, Material::default())
}

/// A sphere of class 3, instance 7.
pub fn sphere(c: Vec3, r: f32, n: usize) -> Target {
    Target::from_triangles(&shapes::sphere(c, r, n), 3, 7, Material::default())
}

pub fn small_camera(w: u32, h: u32, f: f64) -> Intrinsics {
    Intrinsics {
        width: w,
        height: h,
        fx: f,
        fy: f,
        cx: (w as f64 - 1.0) / 2.0,
        cy: (h as f64 - 1.0) / 2.0,
        distortion: Distortion::default(),
    }
}

pub fn ideal(intrinsics: Intrinsics) -> SensorSpec {
    SensorSpec {
        intrinsics,
        ..SensorSpec::preset("ideal").unwrap()
    }
}

pub fn facing_plane(z: f32) -> Target {
    quad(Vec3::new(0.0, 0.0, z), Vec3::X * 5.0, Vec3::Y * 5.0, 1, 1)
}

/// A 500×400 time-of-flight camera (200k pixels) with the given noise.
pub fn tof_camera(noise: Noise) -> SensorSpec {
    let k = small_camera(500, 400, 800.0);
    SensorSpec {
        intrinsics: k,
        model: Model::TimeOfFlight,
        noise,
        ..ideal(k)
    }
}

/// [`tof_camera`] facing a plane at `z` with the given noise.
pub fn noisy_plane(z: f32, noise: Noise, seed: u64) -> Scan {
    let tof = tof_camera(noise);
    scan(
        &World::new(&[facing_plane(z)]),
        &tof,
        &Affine3A::IDENTITY,
        seed,
    )
}

pub fn range_errors(s: &Scan) -> Vec<f64> {
    s.pixels
        .iter()
        .filter(|p| p.is_valid())
        .map(|p| (p.point.length() - p.clean.length()) as f64)
        .collect()
}

pub fn mean_std(v: &[f64]) -> (f64, f64) {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (
        m,
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt(),
    )
}

pub fn pool_free(world: &World, spec: &SensorSpec, seed: u64) -> Scan {
    scan(world, spec, &Affine3A::IDENTITY, seed)
}

/// A 500×400 structured-light camera (200k pixels) with a projector 0.1 m beside it, converging
/// at 0.6 m, and the given noise; nothing else.
pub fn structured(noise: Noise) -> SensorSpec {
    let k = small_camera(500, 400, 800.0);
    SensorSpec {
        intrinsics: k,
        model: Model::StructuredLight {
            projector: Projector {
                baseline: 0.1,
                convergence: 0.6,
                hfov_deg: 60.0,
                vfov_deg: 50.0,
            },
        },
        noise,
        reference_range: 0.6,
        ..ideal(k)
    }
}

/// Zivid's SNR model as the presets have it, and nothing else.
pub fn snr_noise() -> Noise {
    Noise {
        snr: SensorSpec::preset("zivid-2plus-m60").unwrap().noise.snr,
        ..Noise::default()
    }
}

/// Every field of every pixel as bits (NaN equal to NaN), to compare scans exactly.
pub fn bits(s: &Scan) -> Vec<u32> {
    s.pixels.iter().flat_map(bits_of).collect()
}

/// Every field of a pixel as bits.
pub fn bits_of(p: &Pixel) -> Vec<u32> {
    [p.point.to_array(), p.clean.to_array(), p.normal.to_array()]
        .concat()
        .into_iter()
        .map(f32::to_bits)
        .chain([
            p.class as u32,
            p.instance,
            p.intensity.to_bits(),
            u32::from_le_bytes([p.rgb[0], p.rgb[1], p.rgb[2], 0]),
            p.snr.to_bits(),
            p.incidence.to_bits(),
            u32::from_le_bytes([p.wear, p.indirect, 0, 0]),
        ])
        .collect()
}

/// A plane facing the camera at depth `z`, of `reflectivity`.
pub fn plane(z: f32, reflectivity: f32) -> World {
    let mut p = facing_plane(z);
    p.material.reflectivity = reflectivity;
    World::new(&[p])
}

/// Depth errors (camera z) of the valid pixels, each divided by `sigma(pixel)`.
pub fn z_scores(s: &Scan, sigma: impl Fn(&Pixel) -> f64) -> Vec<f64> {
    s.pixels
        .iter()
        .filter(|p| p.is_valid())
        .map(|p| (p.point.z - p.clean.z) as f64 / sigma(p))
        .collect()
}
