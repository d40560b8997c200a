//! Light blocks ([`Settings::light_block`](super::Settings::light_block)): the light of the
//! one pixel of each block that traced it, denoised, spread to every pixel of the frame from
//! the four blocks nearest it: their light divided by their albedo, weighted by distance and
//! by the denoiser's normal and plane stops (so that it crosses no edge), times the pixel's own
//! albedo.

use glam::Vec3;
use rayon::prelude::*;

use super::denoise::{Guide, SIGMA_PLANE, exp_neg, pow128};

/// Share of the weight a pixel's like neighbours must hold for it to take their light alone;
/// below it (a surface no traced pixel lies on) it takes that of every neighbour.
const LIKE: f32 = 1e-3;

/// A block's traced pixel: where it is, its surface, and its light divided by its albedo.
struct Traced {
    x: f32,
    y: f32,
    guide: Guide,
    light: Vec3,
}

/// Gives each pixel of `pixels` (`width` columns) with a surface in `guides` the light of the
/// four blocks whose middles are nearest it, each `block` pixels wide: `light[b]` traced at
/// pixel `choices[b]` of block `b` (blocks row by row); `pixel_angle` is the angle one pixel
/// spans, radians. Pixels without a surface keep what they have.
pub(super) fn fill(
    pixels: &mut [[f32; 3]],
    guides: &[Option<Guide>],
    width: usize,
    (light, choices): (&[[f32; 3]], &[usize]),
    block: usize,
    pixel_angle: f32,
) {
    let traced: Vec<Option<Traced>> = choices
        .par_iter()
        .zip(light)
        .map(|(&i, &l)| {
            guides[i].map(|guide| Traced {
                x: (i % width) as f32,
                y: (i / width) as f32,
                guide,
                light: Vec3::from(l) / guide.divisor(),
            })
        })
        .collect();
    let across = width.div_ceil(block);
    let down = traced.len() / across.max(1);
    // the distance weight: a Gaussian of σ one block
    let spread = 1.0 / (2.0 * (block * block) as f32);
    pixels
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, row)| {
            let rows = nearest(y, block, down);
            for (x, px) in row.iter_mut().enumerate() {
                let Some(g) = &guides[y * width + x] else {
                    continue;
                };
                let reach = 1.0 / (g.distance * pixel_angle * SIGMA_PLANE).max(1e-12);
                let offset = g.normal.dot(g.point);
                let cols = nearest(x, block, across);
                let (mut like, mut any) = ((Vec3::ZERO, 0.0), (Vec3::ZERO, 0.0));
                for by in rows.clone() {
                    let blocks = by * across + cols.start..by * across + cols.end;
                    for t in traced[blocks].iter().flatten() {
                        let (dx, dy) = (t.x - x as f32, t.y - y as f32);
                        let near = exp_neg((dx * dx + dy * dy) * spread);
                        let plane = (g.normal.dot(t.guide.point) - offset).abs() * reach;
                        let stop = pow128(g.normal.dot(t.guide.normal).max(0.0)) * exp_neg(plane);
                        like = (like.0 + t.light * (near * stop), like.1 + near * stop);
                        any = (any.0 + t.light * near, any.1 + near);
                    }
                }
                let (sum, weight) = if like.1 > LIKE * any.1 { like } else { any };
                if weight > 0.0 {
                    *px = (sum / weight * g.divisor()).to_array();
                }
            }
        });
}

/// The two blocks along one axis (of `count`) whose middles are nearest either side of pixel
/// `at`'s (one at the frame's edges).
fn nearest(at: usize, block: usize, count: usize) -> std::ops::Range<usize> {
    // the block whose middle is at or before the pixel's: (at + ½) / block - ½, floored
    let before = (2 * at + 1).saturating_sub(block) / (2 * block);
    before.min(count - 1)..(before + 2).min(count)
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: usize = 48;
    const H: usize = 36;
    const PIXEL: f32 = 0.01;
    const BLOCK: usize = 3;

    /// A frame 1 m from a lit plane (z = 0, light 1) on its left half and, on its right, a
    /// dark surface (light 0) `other` gives for a point of the plane; each block's light traced
    /// at its middle pixel; returns the frame filled.
    fn step(other: impl Fn(Vec3) -> Guide) -> Vec<[f32; 3]> {
        let lit = |i: usize| i % W < W / 2;
        let guides: Vec<Option<Guide>> = (0..W * H)
            .map(|i| {
                let x = ((i % W) as f32 - W as f32 / 2.0 + 0.5) * PIXEL;
                let y = ((i / W) as f32 - H as f32 / 2.0) * PIXEL;
                let point = Vec3::new(x, y, 0.0);
                let plane = Guide {
                    albedo: Vec3::ONE,
                    normal: Vec3::Z,
                    point,
                    distance: 1.0,
                };
                Some(if lit(i) { plane } else { other(point) })
            })
            .collect();
        let across = W / BLOCK;
        let choices: Vec<usize> = (0..across * (H / BLOCK))
            .map(|b| ((b / across) * BLOCK + 1) * W + (b % across) * BLOCK + 1)
            .collect();
        let light: Vec<[f32; 3]> = choices
            .iter()
            .map(|&i| if lit(i) { [1.0; 3] } else { [0.0; 3] })
            .collect();
        let mut pixels = vec![[0.5; 3]; W * H];
        fill(&mut pixels, &guides, W, (&light, &choices), BLOCK, PIXEL);
        pixels
    }

    #[test]
    fn light_stays_on_its_surface() {
        // a step ten pixel widths down, and a wall facing away: the lit plane's light reaches
        // neither, and the plane keeps it to the step's edge
        let down = |p: Vec3| Guide {
            albedo: Vec3::ONE,
            normal: Vec3::Z,
            point: p - Vec3::Z * 10.0 * PIXEL,
            distance: 1.1,
        };
        let wall = |p: Vec3| Guide {
            albedo: Vec3::ONE,
            normal: Vec3::X,
            point: Vec3::new(0.0, p.y, -p.x),
            distance: 1.0,
        };
        for (name, pixels) in [("step", step(down)), ("wall", step(wall))] {
            for (i, p) in pixels.iter().enumerate() {
                let want = if i % W < W / 2 { 1.0 } else { 0.0 };
                assert!((p[0] - want).abs() < 1e-3, "{name}: pixel {i}: {}", p[0]);
            }
        }
    }

    #[test]
    fn pixels_take_their_own_albedo_and_keep_no_surface_as_it_was() {
        // one plane under uniform light 0.5 (its albedo 0.5 at the traced pixels, whose light
        // is 0.25): a pixel of albedo 0.9 shows 0.45; a pixel without a surface keeps its own
        let mut guides: Vec<Option<Guide>> = (0..W * H)
            .map(|i| {
                Some(Guide {
                    albedo: Vec3::splat(0.5),
                    normal: Vec3::Z,
                    point: Vec3::new((i % W) as f32 * PIXEL, (i / W) as f32 * PIXEL, 0.0),
                    distance: 1.0,
                })
            })
            .collect();
        let (bright, none) = (10 * W + 10, 20 * W + 20);
        guides[bright].as_mut().expect("a surface").albedo = Vec3::splat(0.9);
        guides[none] = None;
        let choices: Vec<usize> = (0..(W / BLOCK) * (H / BLOCK))
            .map(|b| (b / (W / BLOCK)) * BLOCK * W + (b % (W / BLOCK)) * BLOCK)
            .collect();
        let light = vec![[0.25; 3]; choices.len()];
        let mut pixels = vec![[7.0; 3]; W * H];
        fill(&mut pixels, &guides, W, (&light, &choices), BLOCK, PIXEL);
        assert!(
            (pixels[bright][0] - 0.45).abs() < 1e-5,
            "{}",
            pixels[bright][0]
        );
        assert!((pixels[0][0] - 0.25).abs() < 1e-5);
        assert_eq!(pixels[none], [7.0; 3]);
    }
}
