//! Primary visibility by rasterisation: which triangle each pixel centre ray of a pinhole
//! camera meets first, found by drawing every triangle into a buffer of pixels (nearest wins),
//! as a GPU's visibility buffer does, instead of walking the BVH once per ray. The edge tests
//! run in float64 with margins above the caster's float32 rounding, so the two nearest
//! triangles drawn at a pixel include the one the caster hits. Where the ray passes clear of
//! the nearest one's margins, the caster hits it too, and its distance comes from the drawing
//! (float64, rounded once); elsewhere the caster's own test confirms one of the two, and the
//! rare pixels neither confirms are cast. The hits are the caster's, but for distances closer
//! to exact and, at ties within rounding (an edge two triangles share), the other triangle.

use std::ops::Range;

use glam::{Affine3A, DVec3, Vec3};
use rayon::prelude::*;

use crate::camera::Intrinsics;

/// No triangle.
pub(crate) const NONE: u32 = u32::MAX;

/// Rows drawn together by one task.
const BAND: usize = 32;

/// Margin on the inside test, in float32 epsilons of the scale of an edge value's rounding in
/// the caster (see [`Camera::draw`]): generous, so that every triangle the caster hits is a
/// candidate.
const MARGIN: f64 = 64.0 * f32::EPSILON as f64;

/// What was drawn at one pixel: the two nearest triangles (slots of the caster), nearest
/// first, [`NONE`] for either missing; and, where the pixel's ray passes through the nearest
/// clear of its edges' margins (so that the caster hits it too), the distance along the ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Drawing {
    /// The nearest triangle, then the next.
    pub(crate) slots: [u32; 2],
    /// Distance to the nearest along the unit ray, where it is clear; else 0.
    pub(crate) clear_t: f32,
}

impl Drawing {
    const EMPTY: Drawing = Drawing {
        slots: [NONE; 2],
        clear_t: 0.0,
    };
}

/// The drawings of a window of pixels.
pub(crate) struct Visibility {
    cols: Range<usize>,
    rows: Range<usize>,
    drawings: Vec<Drawing>,
}

impl Visibility {
    /// The drawing at pixel (`col`, `row`), which must lie in the window.
    #[inline]
    pub(crate) fn at(&self, col: usize, row: usize) -> Drawing {
        let w = self.cols.len();
        self.drawings[(row - self.rows.start) * w + col - self.cols.start]
    }
}

/// The two nearest triangles drawn at a pixel so far, by inverse depth (0 for none), and
/// whether the pixel lies clear of the nearest one's margins.
#[derive(Clone, Copy)]
struct Nearest {
    depth: [f64; 2],
    slots: [u32; 2],
    clear: bool,
}

impl Nearest {
    const NONE: Nearest = Nearest {
        depth: [0.0; 2],
        slots: [NONE; 2],
        clear: false,
    };
}

/// A triangle as the camera sees it: the planes through the camera centre and each edge, and
/// what its depth needs.
struct Drawn {
    /// `edges[i]` · d for the pixel ray d = (x, y, 1) is the (scaled) signed distance of the
    /// ray from edge i, oriented so that a ray meets the triangle in front of the camera where
    /// all three are positive.
    edges: [DVec3; 3],
    /// How far below zero an edge value may be and still count as inside.
    margin: [f64; 3],
    /// 1 / |a · (b × c)|: the hit's inverse depth along d is the sum of the edge values times
    /// this.
    inv_volume: f64,
    /// Lower, then upper bounds on the columns inside, per edge (see [`column_bounds`]).
    columns: [[[f64; 2]; 3]; 2],
    /// Pixel columns and rows the triangle may cover.
    cols: Range<usize>,
    rows: Range<usize>,
}

impl Drawn {
    /// The columns of row `r` whose rays may pass within the margins: between the lines
    /// `columns` (see [`column_bounds`]), widened by more than their rounding.
    #[inline(always)]
    fn span(&self, r: usize) -> Range<usize> {
        let r = r as f64;
        let [lower, upper] = self.columns;
        let lo = lower
            .iter()
            .fold(f64::NEG_INFINITY, |m, [a, b]| m.max(a + b * r));
        let hi = upper
            .iter()
            .fold(f64::INFINITY, |m, [a, b]| m.min(a + b * r));
        // clamped to the (non-negative) columns, a cast rounds down
        let (first, end) = (self.cols.start as f64, self.cols.end as f64);
        let start = (lo - SLACK).clamp(first, end) as usize;
        let stop = (hi + SLACK + 1.0).clamp(first, end) as usize;
        start..stop.max(start)
    }
}

/// Columns by which a row's span is widened: far above the rounding of its bounds.
const SLACK: f64 = 1e-3;

/// Per edge, the column where its value reaches minus its margin, as a line a + b·row: a
/// lower bound on the columns inside where the value grows with the column, an upper one
/// where it falls; an edge parallel to the rows, or with a bound too steep to round well
/// (above 1e12), bounds nothing (the per-pixel test still applies).
fn column_bounds(
    edges: &[DVec3; 3],
    margin: &[f64; 3],
    k: &Intrinsics,
    rows: f64,
) -> [[[f64; 2]; 3]; 2] {
    let mut bounds = [[[f64::NEG_INFINITY, 0.0]; 3], [[f64::INFINITY, 0.0]; 3]];
    for (i, (e, m)) in edges.iter().zip(margin).enumerate() {
        // e.x·x + e.y·y + e.z = -m with x = (c - cx)/fx, y = (r - cy)/fy, solved for c
        let b = -k.fx * e.y / (e.x * k.fy);
        let a = k.cx + k.fx * (-m - e.z + e.y * k.cy / k.fy) / e.x;
        if e.x != 0.0 && a.abs() + b.abs() * rows < 1e12 {
            bounds[usize::from(e.x < 0.0)][i] = [a, b];
        }
    }
    bounds
}

/// Draws the triangles `tris` (world frame, indexed by slot) seen from the camera-to-world
/// `pose` with the pinhole camera `k` (no distortion) over the pixels `cols` × `rows`.
pub(crate) fn visibility(
    tris: &[[Vec3; 3]],
    k: &Intrinsics,
    pose: &Affine3A,
    cols: Range<usize>,
    rows: Range<usize>,
) -> Visibility {
    let (w, h) = (cols.len(), rows.len());
    // pixel rays as (x, y, 1): normalised image coordinates per column and row
    let xs: Vec<f64> = cols.clone().map(|c| (c as f64 - k.cx) / k.fx).collect();
    let ys: Vec<f64> = rows.clone().map(|r| (r as f64 - k.cy) / k.fy).collect();
    let camera = Camera::new(pose, k, cols.clone(), rows.clone());
    // each band's triangles, in slot order (a triangle is set up again in each band it
    // covers: that is cheap, and keeping millions of set-ups is not)
    let covered: Vec<Option<[usize; 2]>> = tris
        .par_iter()
        .map(|t| camera.draw(t).map(|d| [d.rows.start, d.rows.end]))
        .collect();
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); h.div_ceil(BAND)];
    for (slot, covered) in covered.iter().enumerate() {
        if let Some([start, end]) = covered {
            for band in &mut members[(start - rows.start) / BAND..=(end - 1 - rows.start) / BAND] {
                band.push(slot as u32);
            }
        }
    }
    let mut drawings = vec![Drawing::EMPTY; w * h];
    drawings
        .par_chunks_mut(BAND * w)
        .zip(members)
        .enumerate()
        .for_each(|(band, (out, members))| {
            let band_rows = rows.start + band * BAND..rows.start + band * BAND + out.len() / w;
            let mut nearest = vec![Nearest::NONE; out.len()];
            for slot in members {
                let d = camera
                    .draw(&tris[slot as usize])
                    .expect("members are drawn");
                // the sum of the edge values, the plane's: the depth, tested first
                let plane = d.edges[0] + d.edges[1] + d.edges[2];
                for r in d.rows.start.max(band_rows.start)..d.rows.end.min(band_rows.end) {
                    let y = ys[r - rows.start];
                    // edge values plus margins: all non-negative inside
                    let at_row = [0, 1, 2].map(|i| d.edges[i].y * y + d.edges[i].z + d.margin[i]);
                    let plane_at_row = plane.y * y + plane.z;
                    let span = d.span(r);
                    let (from, to) = (span.start - cols.start, span.end - cols.start);
                    let line = (r - band_rows.start) * w;
                    for (n, &x) in nearest[line + from..line + to]
                        .iter_mut()
                        .zip(&xs[from..to])
                    {
                        let inverse_depth = (plane.x * x + plane_at_row) * d.inv_volume;
                        if inverse_depth <= n.depth[1] {
                            continue; // behind the two nearest (most hidden pixels end here)
                        }
                        let e = [0, 1, 2].map(|i| d.edges[i].x * x + at_row[i]);
                        if e[0].min(e[1]).min(e[2]) >= 0.0 {
                            // slots arrive in increasing order: the lower of equals stays first
                            if inverse_depth > n.depth[0] {
                                n.depth = [inverse_depth, n.depth[0]];
                                n.slots = [slot, n.slots[0]];
                                n.clear = (0..3).all(|i| e[i] > 2.0 * d.margin[i]);
                            } else {
                                (n.depth[1], n.slots[1]) = (inverse_depth, slot);
                            }
                        }
                    }
                }
            }
            for (r, (out, nearest)) in out.chunks_mut(w).zip(nearest.chunks(w)).enumerate() {
                let y = ys[band * BAND + r];
                for ((drawing, n), x) in out.iter_mut().zip(nearest).zip(&xs) {
                    drawing.slots = n.slots;
                    if n.clear {
                        drawing.clear_t = ((1.0 + x * x + y * y).sqrt() / n.depth[0]) as f32;
                    }
                }
            }
        });
    Visibility {
        cols,
        rows,
        drawings,
    }
}

/// The world-to-camera transform in double precision, the camera and the pixels drawn.
struct Camera<'a> {
    origin: DVec3,
    /// Camera axes in world coordinates.
    axes: [DVec3; 3],
    k: &'a Intrinsics,
    cols: Range<usize>,
    rows: Range<usize>,
    /// Length of the longest pixel ray (x, y, 1) of the whole image (not the window, so that
    /// no drawing depends on it).
    longest_ray: f64,
}

impl<'a> Camera<'a> {
    fn new(
        pose: &Affine3A,
        k: &'a Intrinsics,
        cols: Range<usize>,
        rows: Range<usize>,
    ) -> Camera<'a> {
        let m = pose.matrix3;
        let far =
            |centre: f64, f: f64, n: u32| centre.abs().max((n as f64 - 1.0 - centre).abs()) / f;
        Camera {
            origin: Vec3::from(pose.translation).as_dvec3(),
            axes: [m.x_axis, m.y_axis, m.z_axis].map(|a| Vec3::from(a).as_dvec3()),
            k,
            cols,
            rows,
            longest_ray: (1.0
                + far(k.cx, k.fx, k.width).powi(2)
                + far(k.cy, k.fy, k.height).powi(2))
            .sqrt(),
        }
    }

    /// Sets triangle `t` up for drawing, or `None` where it covers no pixel of the window.
    fn draw(&self, t: &[Vec3; 3]) -> Option<Drawn> {
        let k = self.k;
        let world = t.map(|v| v.as_dvec3());
        let [a, b, c] = world.map(|v| {
            let p = v - self.origin;
            DVec3::new(
                p.dot(self.axes[0]),
                p.dot(self.axes[1]),
                p.dot(self.axes[2]),
            )
        });
        let volume = a.dot(b.cross(c));
        if volume == 0.0 || !volume.is_finite() || (a.z <= 0.0 && b.z <= 0.0 && c.z <= 0.0) {
            return None; // in a plane through the camera centre, behind it, or not finite
        }
        let orient = volume.signum();
        let edges = [b.cross(c), c.cross(a), a.cross(b)].map(|e| e * orient);
        // the pixels it may cover, and the largest angle between their rays and its corners
        let (cols, rows, angle) = if a.z > 0.0 && b.z > 0.0 && c.z > 0.0 {
            // in front: the projected corners' bounding box, a pixel wider
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for p in [a, b, c] {
                let (u, v) = (k.fx * p.x / p.z + k.cx, k.fy * p.y / p.z + k.cy);
                (lo, hi) = ([lo[0].min(u), lo[1].min(v)], [hi[0].max(u), hi[1].max(v)]);
            }
            let span = |lo: f64, hi: f64, range: &Range<usize>| {
                let start = (lo.floor() - 1.0).max(range.start as f64) as usize;
                let end = (hi.ceil() + 2.0).min(range.end as f64).max(start as f64) as usize;
                start..end
            };
            let diagonal = (hi[0] - lo[0] + 3.0).hypot(hi[1] - lo[1] + 3.0);
            (
                span(lo[0], hi[0], &self.cols),
                span(lo[1], hi[1], &self.rows),
                (diagonal / k.fx.min(k.fy)).min(1.0),
            )
        } else {
            // across the camera plane: anywhere
            (self.cols.clone(), self.rows.clone(), 1.0)
        };
        // The caster's float32 test rounds the corners relative to the camera (ε|v|) and then
        // works with their offsets from the ray (|v|·angle): an edge value's error is about
        // ε·|v_i|·|v_j|·angle, times the length of the pixel ray.
        let distance = [a, b, c].map(|v| v.length());
        let margin = [(1, 2), (2, 0), (0, 1)]
            .map(|(i, j)| MARGIN * distance[i] * distance[j] * angle * self.longest_ray);
        (!cols.is_empty() && !rows.is_empty()).then_some(Drawn {
            columns: column_bounds(&edges, &margin, k, rows.end as f64),
            edges,
            margin,
            inv_volume: 1.0 / volume.abs(),
            cols,
            rows,
        })
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;
    use proptest::prelude::*;

    use super::*;
    use crate::{Material, Scene, Target, look_at};

    fn scene_of(tris: &[[Vec3; 3]]) -> Scene {
        Scene::new(&[Target::from_triangles(tris, 1, 1, Material::default())])
    }

    /// Every pixel's first hit through the drawing against the caster's: (pixels hit, pixels
    /// that differ by more than a tie within rounding).
    fn compare(scene: &Scene, k: &Intrinsics, pose: &Affine3A) -> (usize, Vec<String>) {
        let (w, h) = (k.width as usize, k.height as usize);
        let drawn = scene.visibility(k, pose, 0..w, 0..h);
        let origin = Vec3::from(pose.translation);
        let (mut hits, mut differ) = (0, Vec::new());
        for r in 0..h {
            for c in 0..w {
                let dir = pose.transform_vector3(k.ray(c as f64, r as f64));
                let want = scene.cast(origin, dir, 50.0);
                let got = scene.first_hit(drawn.at(c, r), origin, dir, 50.0);
                hits += usize::from(want.is_some());
                let same = match (want, got) {
                    (None, None) => true,
                    // the same triangle (at grazing incidence the caster's float32 distance
                    // strays from the drawing's float64 one), or another at the same depth (an
                    // edge)
                    (Some(a), Some(b)) => {
                        let gap = (a.t - b.t).abs() / a.t;
                        gap <= 1e-5 || (a.triangle == b.triangle && gap <= 1e-3)
                    }
                    _ => false,
                };
                if !same {
                    differ.push(format!("pixel ({c}, {r}): caster {want:?}, drawn {got:?}"));
                }
            }
        }
        (hits, differ)
    }

    fn sphere_on_plane(n: usize) -> Vec<[Vec3; 3]> {
        let sphere = |i: usize, j: usize| {
            let (th, ph) = (
                std::f64::consts::PI * i as f64 / n as f64,
                std::f64::consts::TAU * j as f64 / n as f64,
            );
            (DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos() + 1.0) * 0.25).as_vec3()
        };
        let plane = |i: usize, j: usize| {
            Vec3::new(i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5, 0.0)
        };
        let mut tris = Vec::new();
        for p in [&sphere as &dyn Fn(usize, usize) -> Vec3, &plane] {
            for i in 0..n {
                for j in 0..n {
                    tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                    tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
                }
            }
        }
        tris
    }

    #[test]
    fn a_sphere_seen_over_its_pole_gives_the_casters_hits() {
        // the pole is a fan of slivers meeting at one point, seen head on
        let scene = scene_of(&sphere_on_plane(70));
        let k = Intrinsics::from_fov(320, 256, 40.0, 32.0);
        let eye = Vec3::new(0.1, -0.2, 1.28);
        let pose = look_at(eye, Vec3::new(0.0, 0.0, 0.1), Vec3::Y).unwrap();
        let (hits, differ) = compare(&scene, &k, &pose);
        assert!(hits > 50_000, "{hits} pixels hit");
        assert!(
            differ.is_empty(),
            "{} differ: {:?}",
            differ.len(),
            &differ[..3.min(differ.len())]
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Triangle soups around the camera (some behind it or across its plane, some
        /// intersecting) give the caster's hits at every pixel.
        #[test]
        fn triangle_soups_give_the_casters_hits(
            corners in prop::collection::vec(-1.0f32..1.0, 9..=360),
            eye in (-1.5f32..1.5, -1.5f32..1.5, 0.3f32..2.5),
            fov in 20.0f64..90.0,
        ) {
            let tris: Vec<[Vec3; 3]> = corners
                .chunks_exact(9)
                .map(|c| [0, 3, 6].map(|i| Vec3::from_slice(&c[i..i + 3])))
                .collect();
            let scene = scene_of(&tris);
            let k = Intrinsics::from_fov(48, 36, fov, fov * 0.75);
            let eye = Vec3::new(eye.0, eye.1, eye.2);
            let pose = look_at(eye, Vec3::ZERO, Vec3::Y).unwrap();
            let (_, differ) = compare(&scene, &k, &pose);
            prop_assert!(differ.is_empty(), "{} differ: {:?}", differ.len(), &differ[..3.min(differ.len())]);
        }
    }
}
