//! An edge-aware denoiser for frames of few paths per pixel: the à-trous wavelet filter
//! (Dammertz et al., "Edge-avoiding À-Trous wavelet transform for fast global illumination
//! filtering", 2010) with the edge stops of SVGF (Schied et al., "Spatiotemporal variance-guided
//! filtering", 2017) on a single frame. The light is divided by the first surface's albedo
//! before filtering and multiplied back after, so that textures and colour edges stay sharp;
//! the filter then spreads only over pixels of one surface (normals within a few degrees,
//! points on one plane) whose light differs by no more than its noise explains.

use glam::Vec3;
use rayon::prelude::*;

use super::bsdf::luminance;

/// What the first surface of a pixel's path shows the filter.
#[derive(Clone, Copy, Debug)]
pub(super) struct Guide {
    /// The surface's directional albedo (what the light is divided by).
    pub(super) albedo: Vec3,
    /// Its unit normal.
    pub(super) normal: Vec3,
    /// The surface point, world frame.
    pub(super) point: Vec3,
    /// Its distance from the camera.
    pub(super) distance: f32,
}

impl Guide {
    /// What the light is divided by before filtering: the albedo, kept from zero.
    pub(super) fn divisor(&self) -> Vec3 {
        self.albedo.max(Vec3::splat(MIN_ALBEDO))
    }
}

/// Levels of the filter: taps 1, 2, 4, 8 and 16 pixels apart (a footprint of 63 pixels).
const LEVELS: u32 = 5;
/// Tolerance of the luminance stop in standard deviations of the noise (SVGF's σl).
const SIGMA_LUMINANCE: f32 = 4.0;
/// Tolerance of the plane stop: how far from a pixel's plane a tap may lie, in pixel widths at
/// the pixel's distance (at any tap distance: a surface behind or before stays apart however
/// wide the filter).
pub(super) const SIGMA_PLANE: f32 = 1.0;
/// Smallest albedo the light is divided by.
const MIN_ALBEDO: f32 = 0.02;
/// The B-spline weights of a level's three taps along each axis.
const KERNEL: [f32; 3] = [0.25, 0.5, 0.25];

/// The frame's surfaces, one array per quantity (so that each level's loops run over
/// contiguous lanes).
struct Surfaces {
    width: usize,
    height: usize,
    /// Unit normal.
    normal: [Vec<f32>; 3],
    /// The surface point.
    point: [Vec<f32>; 3],
    /// normal · point: the plane's offset.
    offset: Vec<f32>,
    /// 1 / (the pixel's width at the surface × [`SIGMA_PLANE`]); 0 without a surface.
    reach: Vec<f32>,
    /// 1 with a surface, 0 without.
    valid: Vec<f32>,
}

/// The light during filtering: per channel, divided by the albedo, its luminance, and the
/// variance of that luminance.
struct Light {
    rgb: [Vec<f32>; 3],
    luminance: Vec<f32>,
    variance: Vec<f32>,
}

/// Filters `pixels` (`width` columns, linear RGB) guided by `guides` (`None` where the camera
/// ray met no surface: those pixels are kept as they are and never taps); `pixel_angle` is the
/// angle one pixel spans, radians.
pub(super) fn denoise(
    pixels: &mut [[f32; 3]],
    guides: &[Option<Guide>],
    width: usize,
    pixel_angle: f32,
) {
    let n = pixels.len();
    let mut surfaces = Surfaces {
        width,
        height: n / width.max(1),
        normal: std::array::from_fn(|_| vec![0.0; n]),
        point: std::array::from_fn(|_| vec![0.0; n]),
        offset: vec![0.0; n],
        reach: vec![0.0; n],
        valid: vec![0.0; n],
    };
    let mut light = Light::zeros(n);
    {
        let [nx, ny, nz] = &mut surfaces.normal;
        let [px, py, pz] = &mut surfaces.point;
        let [r, g, b] = &mut light.rgb;
        let (offset, reach, valid) = (
            &mut surfaces.offset,
            &mut surfaces.reach,
            &mut surfaces.valid,
        );
        let columns = [
            nx,
            ny,
            nz,
            px,
            py,
            pz,
            offset,
            reach,
            valid,
            r,
            g,
            b,
            &mut light.luminance,
        ]
        .map(|c| &mut c[..]);
        rows(columns, width)
            .into_par_iter()
            .enumerate()
            .for_each(|(y, mut row)| {
                for x in 0..width {
                    let i = y * width + x;
                    let Some(g) = &guides[i] else { continue };
                    let l = Vec3::from(pixels[i]) / g.divisor();
                    let reach = 1.0 / (g.distance * pixel_angle * SIGMA_PLANE).max(1e-12);
                    let values = [
                        g.normal.x,
                        g.normal.y,
                        g.normal.z,
                        g.point.x,
                        g.point.y,
                        g.point.z,
                        g.normal.dot(g.point),
                        reach,
                        1.0,
                        l.x,
                        l.y,
                        l.z,
                        luminance(l),
                    ];
                    for (c, v) in row.iter_mut().zip(values) {
                        c[x] = v;
                    }
                }
            });
    }
    light.variance = surfaces.variance(&light.luminance);
    let mut spare = Light::zeros(n);
    for level in 0..LEVELS {
        surfaces.a_trous(&light, &mut spare, 1 << level);
        std::mem::swap(&mut light, &mut spare);
    }
    pixels
        .par_iter_mut()
        .zip(guides)
        .enumerate()
        .for_each(|(i, (p, g))| {
            if let Some(g) = g {
                let l = Vec3::new(light.rgb[0][i], light.rgb[1][i], light.rgb[2][i]);
                *p = (l * g.divisor()).to_array();
            }
        });
}

/// `K` columns of a frame `width` pixels wide as rows, each row a slice of every column, for
/// filling them row by row in parallel.
fn rows<const K: usize>(columns: [&mut [f32]; K], width: usize) -> Vec<[&mut [f32]; K]> {
    let height = columns[0].len() / width.max(1);
    let mut chunks = columns.map(|c| c.chunks_mut(width));
    (0..height)
        .map(|_| {
            chunks
                .each_mut()
                .map(|c| c.next().expect("a row of every column"))
        })
        .collect()
}

impl Light {
    /// A frame of `n` pixels of no light.
    fn zeros(n: usize) -> Light {
        Light {
            rgb: std::array::from_fn(|_| vec![0.0; n]),
            luminance: vec![0.0; n],
            variance: vec![0.0; n],
        }
    }
}

impl Surfaces {
    /// The variance of the luminance over each pixel's 3×3 neighbourhood of pixels with a
    /// surface: the noise a frame of few paths shows.
    fn variance(&self, luminance: &[f32]) -> Vec<f32> {
        let mut out = vec![0.0; luminance.len()];
        out.par_chunks_mut(self.width)
            .enumerate()
            .for_each(|(y, out)| {
                let w = self.width;
                let (mut sum, mut sq, mut count) = (vec![0.0; w], vec![0.0; w], vec![0.0; w]);
                for (dy, dx, _) in self.taps(y, 1) {
                    let (xs, first) = self.span(y, dy, dx);
                    for (x, q) in xs.zip(first..) {
                        let (l, v) = (luminance[q], self.valid[q]);
                        sum[x] += v * l;
                        sq[x] += v * l * l;
                        count[x] += v;
                    }
                }
                for (x, o) in out.iter_mut().enumerate() {
                    let c = count[x].max(1.0);
                    let mean = sum[x] / c;
                    *o = (sq[x] / c - mean * mean).max(0.0);
                }
            });
        out
    }

    /// One level of the filter: 3×3 taps `step` pixels apart, B-spline weighted, stopped at
    /// edges (normals, planes, luminance against its noise); variances carried through with
    /// the squared weights, into `out`. Pixels without a surface keep their light.
    fn a_trous(&self, light: &Light, out: &mut Light, step: usize) {
        let w = self.width;
        let [r, g, b] = &mut out.rgb;
        let columns = [r, g, b, &mut out.luminance, &mut out.variance].map(|c| &mut c[..]);
        rows(columns, w)
            .into_par_iter()
            .enumerate()
            .for_each(|(y, mut acc)| {
                let p0 = y * w;
                for c in acc.iter_mut() {
                    c.fill(0.0);
                }
                let mut total = vec![0.0f32; w];
                let inv_sigma: Vec<f32> = (p0..p0 + w)
                    .map(|p| 1.0 / (SIGMA_LUMINANCE * light.variance[p].sqrt() + 1e-6))
                    .collect();
                let (n, pt) = (&self.normal, &self.point);
                for (dy, dx, k) in self.taps(y, step) {
                    let (xs, q) = self.span(y, dy, dx);
                    let (len, p) = (xs.len(), p0 + xs.start);
                    // every slice exactly `len` long: the loop below runs without bounds checks
                    fn at(v: &[f32], i: usize, len: usize) -> &[f32] {
                        &v[i..i + len]
                    }
                    let (rq, gq, bq) = (
                        at(&light.rgb[0], q, len),
                        at(&light.rgb[1], q, len),
                        at(&light.rgb[2], q, len),
                    );
                    let (vq, lq) = (at(&light.variance, q, len), at(&light.luminance, q, len));
                    let [acc_r, acc_g, acc_b, _, acc_v] =
                        acc.each_mut().map(|a| &mut a[xs.start..][..len]);
                    let acc_w = &mut total[xs.start..][..len];
                    if dy == 0 && dx == 0 {
                        for i in 0..len {
                            acc_r[i] += k * rq[i];
                            acc_g[i] += k * gq[i];
                            acc_b[i] += k * bq[i];
                            acc_v[i] += k * k * vq[i];
                            acc_w[i] += k;
                        }
                        continue;
                    }
                    let (nxp, nyp, nzp) = (at(&n[0], p, len), at(&n[1], p, len), at(&n[2], p, len));
                    let (nxq, nyq, nzq) = (at(&n[0], q, len), at(&n[1], q, len), at(&n[2], q, len));
                    let (xq, yq, zq) = (at(&pt[0], q, len), at(&pt[1], q, len), at(&pt[2], q, len));
                    let (offset, reach, lp) = (
                        at(&self.offset, p, len),
                        at(&self.reach, p, len),
                        at(&light.luminance, p, len),
                    );
                    let (valid, sigma) = (at(&self.valid, q, len), at(&inv_sigma, xs.start, len));
                    for i in 0..len {
                        let cos = nxp[i] * nxq[i] + nyp[i] * nyq[i] + nzp[i] * nzq[i];
                        let dist = nxp[i] * xq[i] + nyp[i] * yq[i] + nzp[i] * zq[i] - offset[i];
                        let plane = dist.abs() * reach[i];
                        let lum = (lq[i] - lp[i]).abs() * sigma[i];
                        let weight = k * valid[i] * pow128(cos.max(0.0)) * exp_neg(plane + lum);
                        acc_r[i] += weight * rq[i];
                        acc_g[i] += weight * gq[i];
                        acc_b[i] += weight * bq[i];
                        acc_v[i] += weight * weight * vq[i];
                        acc_w[i] += weight;
                    }
                }
                let [r, g, b, lum, var] = acc;
                for x in 0..w {
                    let p = p0 + x;
                    let rgb = if self.valid[p] == 0.0 {
                        Vec3::new(light.rgb[0][p], light.rgb[1][p], light.rgb[2][p])
                    } else {
                        let inv = 1.0 / total[x];
                        let rgb = Vec3::new(r[x], g[x], b[x]) * inv;
                        lum[x] = luminance(rgb);
                        var[x] *= inv * inv;
                        rgb
                    };
                    (r[x], g[x], b[x]) = (rgb.x, rgb.y, rgb.z);
                }
            });
    }

    /// The taps of row `y` a level `step` apart: (row offset, column offset, B-spline weight),
    /// rows outside the frame left out.
    fn taps(&self, y: usize, step: usize) -> impl Iterator<Item = (isize, isize, f32)> + '_ {
        let s = step as isize;
        (-1..=1)
            .zip(KERNEL)
            .filter(move |&(dy, _)| (0..self.height as isize).contains(&(y as isize + dy * s)))
            .flat_map(move |(dy, ky)| {
                (-1..=1)
                    .zip(KERNEL)
                    .map(move |(dx, kx)| (dy * s, dx * s, ky * kx))
            })
    }

    /// The columns of row `y` whose tap `dy` rows and `dx` columns away lies in the frame, and
    /// the pixel index of the first one's tap (the others' follow it).
    fn span(&self, y: usize, dy: isize, dx: isize) -> (std::ops::Range<usize>, usize) {
        let w = self.width as isize;
        let (lo, hi) = ((-dx).clamp(0, w), (w - dx).clamp(0, w));
        let first = (y as isize + dy) * w + lo + dx;
        (lo as usize..hi.max(lo) as usize, first.max(0) as usize)
    }
}

/// The normals' edge stop: the cosine to the 128th power (SVGF's σn), by squaring.
#[inline(always)]
pub(super) fn pow128(c: f32) -> f32 {
    (0..7).fold(c, |c, _| c * c)
}

/// e^-x for x ≥ 0, within 2e-5 relative: 2^(-x·log2 e) split into a whole power of two,
/// made from exponent bits, and a polynomial of the rest, in plain arithmetic without branches
/// (so that loops of it run in vector lanes, with the same bits on any machine).
#[inline(always)]
pub(super) fn exp_neg(x: f32) -> f32 {
    /// Adding 1.5 × 2^23 rounds a float of magnitude below 2^22 to a whole number, which
    /// its low mantissa bits then hold.
    const ROUND: f32 = 12_582_912.0;
    let y = (-x * std::f32::consts::LOG2_E).max(-126.0);
    let r = y + ROUND;
    let f = y - (r - ROUND); // in [-0.5, 0.5]
    let p = 1.0
        + f * (std::f32::consts::LN_2
            + f * (0.240_226_5 + f * (0.055_504_1 + f * (0.009_618_1 + f * 0.001_333_4))));
    let whole = r.to_bits().wrapping_sub(ROUND.to_bits());
    f32::from_bits(whole.wrapping_add(127) << 23) * p
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: usize = 64;
    const H: usize = 48;
    const PIXEL: f32 = 0.01;

    /// A frame of the plane z = `z` seen from 1 m above z = 0, one unit albedo.
    fn plane(z: f32) -> Vec<Option<Guide>> {
        (0..W * H)
            .map(|i| {
                let (x, y) = (
                    (i % W) as f32 - W as f32 / 2.0,
                    (i / W) as f32 - H as f32 / 2.0,
                );
                Some(Guide {
                    albedo: Vec3::ONE,
                    normal: Vec3::Z,
                    point: Vec3::new(x * PIXEL, y * PIXEL, z),
                    distance: 1.0 - z,
                })
            })
            .collect()
    }

    /// Uniform numbers in [-1, 1), one per pixel (a fixed sequence).
    fn noise() -> Vec<f32> {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        (0..W * H)
            .map(|_| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                (state >> 40) as f32 / (1u64 << 23) as f32 - 1.0
            })
            .collect()
    }

    fn grey(values: impl Iterator<Item = f32>) -> Vec<[f32; 3]> {
        values.map(|v| [v; 3]).collect()
    }

    fn mean_std(values: &[f32]) -> (f32, f32) {
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / values.len() as f32;
        (mean, var.sqrt())
    }

    #[test]
    fn a_flat_surfaces_noise_falls_and_its_mean_stays() {
        let guides = plane(0.0);
        let mut pixels = grey(noise().into_iter().map(|n| 0.5 + 0.4 * n));
        let before: Vec<f32> = pixels.iter().map(|p| p[0]).collect();
        denoise(&mut pixels, &guides, W, PIXEL);
        let after: Vec<f32> = pixels.iter().map(|p| p[0]).collect();
        let ((m0, s0), (m1, s1)) = (mean_std(&before), mean_std(&after));
        assert!((m1 - m0).abs() < 0.01 * m0, "mean {m0} -> {m1}");
        assert!(s1 < s0 / 8.0, "deviation {s0} -> {s1}");
    }

    #[test]
    fn light_does_not_cross_to_a_surface_behind_or_turned_away() {
        // left half: a lit floor; right half: ten pixel widths below it (a step), or a wall
        // facing +x
        for (name, other) in [
            (
                "step",
                Guide {
                    albedo: Vec3::ONE,
                    normal: Vec3::Z,
                    point: Vec3::new(0.0, 0.0, -0.1),
                    distance: 1.1,
                },
            ),
            (
                "wall",
                Guide {
                    albedo: Vec3::ONE,
                    normal: Vec3::X,
                    point: Vec3::ZERO,
                    distance: 1.0,
                },
            ),
        ] {
            let mut guides = plane(0.0);
            for (i, g) in guides.iter_mut().enumerate() {
                if i % W >= W / 2 {
                    let x = g.expect("a surface").point;
                    *g = Some(Guide {
                        point: Vec3::new(x.x, x.y, other.point.z),
                        ..other
                    });
                }
            }
            let lit = |i: usize| i % W < W / 2;
            let n = noise();
            let mut pixels = grey((0..W * H).map(|i| if lit(i) { 1.0 + 0.3 * n[i] } else { 0.0 }));
            denoise(&mut pixels, &guides, W, PIXEL);
            let dark = (0..W * H).filter(|&i| !lit(i)).map(|i| pixels[i][0]);
            let worst = dark.fold(0.0f32, f32::max);
            assert!(worst < 1e-3, "{name}: {worst} leaked into the dark side");
        }
    }

    #[test]
    fn an_albedo_texture_stays_sharp() {
        // 4-pixel squares of albedo 0.1 and 0.9 under one noisy light
        let square = |i: usize| ((i % W) / 4 + (i / W) / 4).is_multiple_of(2);
        let albedo = |i: usize| if square(i) { 0.1 } else { 0.9 };
        let mut guides = plane(0.0);
        for (i, g) in guides.iter_mut().enumerate() {
            g.as_mut().expect("a surface").albedo = Vec3::splat(albedo(i));
        }
        let n = noise();
        let mut pixels = grey((0..W * H).map(|i| albedo(i) * (1.0 + 0.3 * n[i])));
        denoise(&mut pixels, &guides, W, PIXEL);
        for (dark, want) in [(true, 0.1), (false, 0.9)] {
            let values: Vec<f32> = (0..W * H)
                .filter(|&i| square(i) == dark)
                .map(|i| pixels[i][0])
                .collect();
            let (mean, std) = mean_std(&values);
            assert!((mean - want).abs() < 0.02 * want, "{want}: mean {mean}");
            assert!(std < 0.05 * want, "{want}: deviation {std}");
        }
    }

    #[test]
    fn pixels_without_a_surface_are_kept_and_lend_nothing() {
        let mut guides = plane(0.0);
        for g in guides.iter_mut().skip(W * H / 2) {
            *g = None;
        }
        let mut pixels =
            grey((0..W * H).map(|i| if i < W * H / 2 { 0.5 } else { 100.0 + i as f32 }));
        denoise(&mut pixels, &guides, W, PIXEL);
        for (i, p) in pixels.iter().enumerate() {
            let want = if i < W * H / 2 { 0.5 } else { 100.0 + i as f32 };
            assert!(
                (p[0] - want).abs() < 1e-5,
                "pixel {i}: {} against {want}",
                p[0]
            );
        }
    }

    #[test]
    fn the_same_bits_for_any_number_of_threads() {
        let guides = plane(0.0);
        let n = noise();
        let frame = |threads: usize| {
            let mut pixels = grey(n.iter().map(|n| 0.5 + 0.4 * n));
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool")
                .install(|| denoise(&mut pixels, &guides, W, PIXEL));
            pixels
        };
        let one = frame(1);
        assert!(
            one.iter()
                .zip(frame(3))
                .all(|(a, b)| a.map(f32::to_bits) == b.map(f32::to_bits))
        );
    }

    #[test]
    fn exp_neg_is_e_to_the_minus_x() {
        for i in 0..=8000 {
            let x = i as f32 * 0.01;
            let (ours, exact) = (exp_neg(x), (-x).exp());
            assert!(
                (ours - exact).abs() <= 2e-5 * exact,
                "e^-{x}: {ours} against {exact}"
            );
        }
        assert_eq!(pow128(0.5), 0.5f32.powi(128));
    }
}
