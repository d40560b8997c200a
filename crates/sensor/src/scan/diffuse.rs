//! Diffuse interreflection: the projector's light a surface receives by way of the lit surfaces
//! around it (see [`Interreflection`](crate::noise::Interreflection)), gathered over a binned
//! image of the scene.

use std::f32::consts::PI;

use glam::{Affine3A, Vec3};
use rayon::prelude::*;

use super::decode::{Light, MIDDLE, Stripes};
use super::{Region, Scan, floor, round, scan_pixels};
use crate::noise::{Noise, PixelRng, stream};
use crate::spec::{Calibration, Processing, SensorSpec};
use crate::world::World;

/// The binned image the light is gathered over has at most this many cells (camera pixels
/// binned 1×1, 2×2, 4×4, ...: 19.6k cells at Zivid's 612×512, 1224×1024 and 2448×2048).
const CELLS: u32 = 1 << 15;

/// Samples gathered per cell: one in each of as many rings, their radii in geometric
/// progression from `INNER` cells to the reach, on a spiral turned by the golden angle.
const SAMPLES: usize = 32;
const INNER: f32 = 0.5;

/// The spiral's directions: cos and sin of sample s × the golden angle.
static SPIRAL: std::sync::LazyLock<[[f32; 2]; SAMPLES]> = std::sync::LazyLock::new(|| {
    std::array::from_fn(|s| {
        let (sin, cos) = (s as f32 * 2.399_963).sin_cos();
        [cos, sin]
    })
});

/// Indirect light fainter than this share of a pixel's own changes nothing.
pub(super) const FAINT: f32 = 1e-3;

/// The light each cell of the binned image receives from the lit surfaces around it.
pub(super) struct Diffuse {
    /// Camera pixels per side of a cell.
    bin: u32,
    width: usize,
    height: usize,
    cells: Vec<Cell>,
}

/// A cell's surface point and normal (camera frame; NaN where it sees none) and the light it
/// receives per unit of its reflectivity.
struct Cell {
    point: Vec3,
    normal: Vec3,
    light: Option<Light>,
}

impl Diffuse {
    /// The light gathered by every cell of the binned image of the scan of `world` by `sensor`
    /// (its pixels within `region`), from what lies within the sensor's `diffuse_reach`.
    pub(super) fn new(
        world: &World,
        sensor: &SensorSpec,
        pose: &Affine3A,
        seed: u64,
        region: Option<&Region>,
        stripes: &Stripes,
    ) -> Diffuse {
        let (binned, bin) = binned(sensor);
        let image = scan_pixels(world, &binned, pose, seed, region, Scan::default());
        let (width, height) = (image.width as usize, image.height as usize);
        let reach = sensor.noise.interreflection.diffuse_reach;
        // each lit cell's light as it leaves it, its patterns at full contrast
        let frustum = &stripes.frustum;
        let sent: Vec<Light> = image
            .pixels
            .par_iter()
            .map(|q| {
                if q.intensity > 0.0 && !q.clean.x.is_nan() {
                    let column = frustum.column(q.clean);
                    let model = &sensor.noise.snr;
                    Light::new(q.intensity, 0.0, column, [1.0; 3], stripes, model)
                } else {
                    Light::default()
                }
            })
            .collect();
        // the finest pattern's blur over a patch is exp(-x) with x = 2 (π σ / period)², the
        // coarser ones' x falls with the square of their periods
        let (middle, coarse) = (
            MIDDLE.powi(-2),
            (stripes.period / (2.0 * frustum.half_width())).powi(2),
        );
        let fade = |x: f32| if x < 1e-4 { 1.0 - x } else { (-x).exp() };
        let cells = (0..width * height)
            .into_par_iter()
            .map(|i| {
                let p = &image.pixels[i];
                let mut sum = Light::default();
                let mut any = false;
                gather(&image, &binned, i, reach, seed, |q, weight, width| {
                    // the sample's patch blurs its stripes over its width in columns (σ of a
                    // uniform width: 0.29 of it)
                    let spread = 0.29 * width / frustum.depth(image.pixels[q].clean);
                    let x = 2.0 * (PI * spread / stripes.period).powi(2);
                    let contrast = [stripes.smooth * fade(x), fade(middle * x), fade(coarse * x)];
                    sum.add_blurred(&sent[q], weight, contrast);
                    any = true;
                });
                Cell {
                    point: p.clean,
                    normal: p.normal,
                    light: any.then_some(sum),
                }
            })
            .collect();
        Diffuse {
            bin,
            width,
            height,
            cells,
        }
    }

    /// The light per unit of reflectivity that a pixel (column, row) whose surface lies at
    /// `point` with `normal` receives: the bilinear blend of the four cells round it, of those
    /// that see the same surface; `None` where none does or they receive nothing.
    pub(super) fn at(&self, [col, row]: [u32; 2], point: Vec3, normal: Vec3) -> Option<Light> {
        // the pixel's centre in the binned image's pixel coordinates (see `Intrinsics::binned`)
        let bin = self.bin as f32;
        let (u, v) = (
            (col as f32 + 0.5) / bin - 0.5,
            (row as f32 + 0.5) / bin - 0.5,
        );
        let (c0, r0) = (floor(u), floor(v));
        let (fu, fv) = (u - c0, v - r0);
        let corners = [
            (0, 0, (1.0 - fu) * (1.0 - fv)),
            (1, 0, fu * (1.0 - fv)),
            (0, 1, (1.0 - fu) * fv),
            (1, 1, fu * fv),
        ]
        .map(|(dc, dr, weight)| {
            let (c, r) = (c0 as isize + dc, r0 as isize + dr);
            let inside =
                c >= 0 && r >= 0 && (c as usize) < self.width && (r as usize) < self.height;
            inside.then(|| (&self.cells[r as usize * self.width + c as usize], weight))
        });
        // most pixels have no light round them: nothing to blend
        if !corners
            .iter()
            .flatten()
            .any(|(cell, _)| cell.light.is_some())
        {
            return None;
        }
        let mut sum = Light::default();
        let mut total = 0.0;
        for (cell, weight) in corners.into_iter().flatten() {
            if cell.normal.dot(normal) > 0.9
                && (cell.point - point).length() < 0.02 * point.length()
            {
                total += weight;
                if let Some(light) = &cell.light {
                    sum.add(light, weight);
                }
            }
        }
        let mut blend = Light::default();
        blend.add(&sum, 1.0 / total);
        (total > 0.0 && sum.amplitude > 0.0).then_some(blend)
    }
}

/// The sensor that images the scene for the gathering, and its binning: its camera binned to
/// at most `CELLS` pixels, without noise, filters or calibration error, so that each pixel's
/// intensity is its surface's diffuse signal (reflectivity × the projector's light; 0 in a
/// shadow).
fn binned(sensor: &SensorSpec) -> (SensorSpec, u32) {
    let k = &sensor.intrinsics;
    let mut bin = 1;
    while (k.width / bin) * (k.height / bin) > CELLS {
        bin *= 2;
    }
    let binned = SensorSpec {
        intrinsics: k.binned(bin),
        noise: Noise::default(),
        processing: Processing::default(),
        calibration: Calibration::default(),
        ..sensor.clone()
    };
    (binned, bin)
}

/// Calls `f(q, weight, width)` for each lit pixel (index `q`) of `image` (taken by `sensor`) sampled
/// round pixel `i` within `reach` metres of its surface: `weight` is the share of `q`'s light
/// that reaches `i`'s surface per unit of its reflectivity (the form factor of the patch the
/// sample stands for, cos·cos·area / π r²), `width` that patch's width, m. The spiral of
/// samples is turned at random for each pixel (from `seed`).
pub(super) fn gather(
    image: &Scan,
    sensor: &SensorSpec,
    i: usize,
    reach: f32,
    seed: u64,
    mut f: impl FnMut(usize, f32, f32),
) {
    let k = &sensor.intrinsics;
    let (w, h) = (image.width as usize, image.height as usize);
    let p = &image.pixels[i];
    if p.clean.x.is_nan() {
        return;
    }
    let outer = reach * k.fx as f32 / p.clean.z;
    if outer <= INNER {
        return;
    }
    let (x, y) = ((i % w) as f32, (i / w) as f32);
    let ratio = (outer / INNER).powf(1.0 / SAMPLES as f32);
    let (sin, cos) = (2.0 * PI * PixelRng::new(seed, i as u64).uniform(stream::BOUNCE)).sin_cos();
    let pixel_solid_angle = 1.0 / (k.fx * k.fy) as f32;
    let mut inner = INNER;
    for s in 0..SAMPLES {
        let outer = inner * ratio;
        // the sample's ring, its middle radius and the image area it stands for
        let (radius, area_px) = (0.5 * (inner + outer), PI * (outer * outer - inner * inner));
        inner = outer;
        let [a, b] = SPIRAL[s];
        let (u, v) = (
            x + radius * (a * cos - b * sin),
            y + radius * (a * sin + b * cos),
        );
        if !(u >= -0.5 && v >= -0.5 && u < w as f32 - 0.5 && v < h as f32 - 0.5) {
            continue;
        }
        let index = round(v) as usize * w + round(u) as usize;
        let q = &image.pixels[index];
        if q.intensity <= 0.0 || q.clean.x.is_nan() {
            continue;
        }
        let d = q.clean - p.clean;
        let r2 = d.length_squared();
        // (the cosines × r; surfaces within a milliradian of each other's plane send nothing,
        // so that a plane does not light itself)
        let (cos_p, cos_q, r) = (p.normal.dot(d), -q.normal.dot(d), r2.sqrt());
        if cos_p <= 1e-3 * r || cos_q <= 1e-3 * r || r2 > reach * reach {
            continue;
        }
        // the patch on q's surface that the ring's share of the image shows
        let dist = q.clean.length();
        let ray = q.clean / dist;
        let facing = q.normal.dot(-ray).max(0.2);
        let area = area_px * pixel_solid_angle * ray.z.powi(3) * dist * dist / facing;
        // cos_p · cos_q · area / (π r²), the cosines from the unnormalised d; at most the
        // share a whole hemisphere gives
        let weight = (cos_p * cos_q * area / (PI * r2 * r2)).min(1.0);
        f(index, weight, area.sqrt());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Distortion, Intrinsics};
    use crate::materials::MATTE_GREY;
    use crate::{Target, shapes};

    /// The form factor the gathering finds from points of one wall of a 90° inside corner to
    /// the other wall matches a quadrature of cos·cos / (π r²) over that wall, within the reach.
    #[test]
    fn the_gathered_form_factor_is_the_walls() {
        // the walls x = 0 (z 0.6 to 0.72) and z = 0.72 (x -0.12 to 0), 0.3 m high, seen by a
        // camera looking along +z from 0.2 m aside
        let (back, height) = (0.72f32, 0.15f32);
        let side = shapes::rectangle(
            Vec3::new(0.0, 0.0, back - 0.06),
            Vec3::Z * 0.06,
            Vec3::Y * height,
        );
        let rear = shapes::rectangle(
            Vec3::new(-0.06, 0.0, back),
            Vec3::X * 0.06,
            Vec3::Y * height,
        );
        let world = World::new(&[
            Target::from_triangles(&side, 1, 1, MATTE_GREY),
            Target::from_triangles(&rear, 2, 2, MATTE_GREY),
        ]);
        let mut sensor = SensorSpec::preset("zivid-2plus-m60").unwrap();
        sensor.intrinsics = Intrinsics {
            width: 500,
            height: 400,
            fx: 800.0,
            fy: 800.0,
            cx: 249.5,
            cy: 199.5,
            distortion: Distortion::default(),
        };
        let pose = Affine3A::from_translation(Vec3::new(-0.2, 0.0, 0.0));
        let (image_sensor, _) = binned(&sensor);
        let image = scan_pixels(&world, &image_sensor, &pose, 1, None, Scan::default());
        let reach = 0.05;
        // the rear wall's form factor from a point of the side wall, by quadrature
        let quadrature = |p: Vec3| {
            let (n, steps) = (Vec3::NEG_X, 600);
            let (dx, dy) = (0.12 / steps as f32, 2.0 * height / steps as f32);
            let mut sum = 0.0;
            for i in 0..steps {
                for j in 0..steps {
                    let q = Vec3::new(
                        -0.12 + (i as f32 + 0.5) * dx,
                        -height + (j as f32 + 0.5) * dy,
                        back,
                    );
                    let d = q - p;
                    let r2 = d.length_squared();
                    if r2 < reach * reach {
                        sum += n.dot(d) * d.z / (PI * r2 * r2) * dx * dy;
                    }
                }
            }
            sum
        };
        let w = image.width as usize;
        let mut checked = 0;
        for (i, p) in image.pixels.iter().enumerate() {
            // points of the side wall near the image's middle rows, 5 to 40 mm from the edge
            let world_p = pose.transform_point3(p.clean);
            if p.class != 1 || (i / w).abs_diff(image.height as usize / 2) > 6 {
                continue;
            }
            let from_edge = back - world_p.z;
            if !(0.005..0.04).contains(&from_edge) {
                continue;
            }
            let seeds = 64;
            let mut sum = 0.0;
            for seed in 0..seeds {
                gather(&image, &image_sensor, i, reach, seed, |q, weight, _| {
                    assert_eq!(image.pixels[q].class, 2);
                    sum += weight;
                });
            }
            let found = sum / seeds as f32;
            let exact = quadrature(world_p);
            eprintln!("{from_edge:.4} m from the edge: {found:.4} against {exact:.4}");
            assert!(
                (found / exact - 1.0).abs() < 0.08,
                "{found} against {exact} at {from_edge}"
            );
            checked += 1;
        }
        assert!(checked > 5, "{checked}");
    }
}
