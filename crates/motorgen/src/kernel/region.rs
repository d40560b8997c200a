//! Planar regions (polygons with holes) under union and difference, by Clipper2 (through
//! Manifold's cross-sections), extruded into plates.

use glam::Vec2;
use manifold_rust::cross_section::CrossSection;
use manifold_rust::linalg::Vec2 as V2;

use super::{Extrusion, extrude, mesh::Mesh, signed_area2};

/// A planar region: polygons with holes.
#[derive(Clone, Debug)]
pub struct Region(CrossSection);

impl Region {
    /// The inside of a simple polygon (either winding).
    pub fn polygon(points: &[Vec2]) -> Region {
        let mut p: Vec<V2> = points
            .iter()
            .map(|q| V2::new(q.x as f64, q.y as f64))
            .collect();
        if signed_area2(points) < 0.0 {
            p.reverse();
        }
        Region(CrossSection::new(vec![p]))
    }

    /// The union.
    pub fn union(&self, other: &Region) -> Region {
        Region(self.0.union(&other.0))
    }

    /// This less `other`.
    pub fn difference(&self, other: &Region) -> Region {
        Region(self.0.difference(&other.0))
    }

    /// Area.
    pub fn area(&self) -> f64 {
        self.0.area()
    }

    /// Whether the bounding boxes of the two regions overlap (a quick test before a boolean).
    pub fn may_meet(&self, other: &Region) -> bool {
        let (a, b) = (self.0.bounds(), other.0.bounds());
        a.min.x < b.max.x && b.min.x < a.max.x && a.min.y < b.max.y && b.min.y < a.max.y
    }

    /// The region extruded from `z0` to `z1`: a closed shell for each of its connected pieces.
    /// Corners closer than a ten-thousandth of the region's size to their neighbours' line
    /// and pieces or holes smaller than a millionth of its size squared (slivers a boolean
    /// leaves) are dropped first, so that no face degenerates; where a hole touches the
    /// outline, or two pieces touch, closer than that, the pinch is opened.
    pub fn extrude(&self, z0: f32, z1: f32) -> Mesh {
        let b = self.0.bounds();
        let size = (b.max.x - b.min.x).max(b.max.y - b.min.y);
        let mut m = Mesh::default();
        let tolerance = 1e-4 * size;
        let mut simple = self.0.simplify(tolerance);
        let contours = |cs: &CrossSection| -> Vec<Vec<Vec2>> {
            cs.to_polygons()
                .iter()
                .map(|c| {
                    c.iter()
                        .map(|p| Vec2::new(p.x as f32, p.y as f32))
                        .collect()
                })
                .collect()
        };
        let mut all = contours(&simple);
        if touching(&all, tolerance as f32) {
            // walls would meet along one edge where the loops touch: open the pinch (shrink,
            // then grow back, by the tolerance)
            let open = |cs: &CrossSection, by: f64| cs.offset_with_params(by, 2, 2.0, 0);
            simple = open(&open(&simple, -tolerance), tolerance).simplify(tolerance);
            all = contours(&simple);
        }
        // a sliver a boolean leaves, piece or hole (a millionth of the size squared), is none
        let sliver = |l: &Vec<Vec2>| f64::from(0.5 * signed_area2(l).abs()) < 1e-6 * size * size;
        all.retain(|l| !sliver(l));
        // one outer contour: one piece, without asking Clipper2 to split it
        let pieces = if all.iter().filter(|l| signed_area2(l) > 0.0).count() == 1 {
            vec![all]
        } else {
            simple.decompose().iter().map(contours).collect()
        };
        for mut loops in pieces {
            loops.retain(|l| !sliver(l));
            // nor is a piece that its holes leave as little of
            let area: f32 = 0.5 * loops.iter().map(|l| signed_area2(l)).sum::<f32>();
            if (area as f64) < 1e-6 * size * size {
                continue;
            }
            // the outer contour (the only counter-clockwise one) first
            loops.sort_by(|a, b| signed_area2(b).total_cmp(&signed_area2(a)));
            let mut loops = loops.into_iter();
            let Some(outer) = loops.next() else {
                continue;
            };
            let mut plate = extrude(&Extrusion {
                outer,
                holes: loops.collect(),
                z0,
                z1,
            });
            // a corner a hair off a long edge leaves a needle in the cap: flip it away
            plate.flip_needles((1e-6 * size) as f32);
            m.append(&plate);
        }
        m
    }
}

/// Whether a corner lies within `eps` of an edge it does not end (a hole touching its piece's
/// outline, two pieces touching, or a loop touching itself).
fn touching(loops: &[Vec<Vec2>], eps: f32) -> bool {
    // every corner, by x, to find those beside an edge
    let mut corners: Vec<Vec2> = loops.iter().flatten().copied().collect();
    corners.sort_unstable_by(|p, q| p.x.total_cmp(&q.x));
    loops.iter().flat_map(|l| edges(l)).any(|(a, b)| {
        let (lo, hi) = (a.min(b) - eps, a.max(b) + eps);
        let from = corners.partition_point(|p| p.x < lo.x);
        corners[from..]
            .iter()
            .take_while(|p| p.x <= hi.x)
            .any(|&p| {
                p.y >= lo.y && p.y <= hi.y && p != a && p != b && {
                    let ab = b - a;
                    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
                    p.distance(a + t * ab) < eps
                }
            })
    })
}

/// The edges of a closed loop.
fn edges(l: &[Vec2]) -> impl Iterator<Item = (Vec2, Vec2)> + '_ {
    (0..l.len()).map(move |k| (l[k], l[(k + 1) % l.len()]))
}
