//! Plates whose faces slope: a planar region between two planes, where the planes may change
//! along lines across it (a board that deepens in two slopes), trimmed by other regions, one
//! closed shell per piece that is left. Regions by Clipper2 (through Manifold's cross-sections).

use glam::{Vec2, Vec3};
use manifold_rust::cross_section::CrossSection;
use manifold_rust::linalg::Vec2 as V2;
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

/// A corner by the bits of its position.
type Key = (u32, u32);

use super::mesh::Mesh;

/// The plane z = a x + b y + c.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    a: f32,
    b: f32,
    c: f32,
}

impl Plane {
    /// The plane z = `z`.
    pub fn flat(z: f32) -> Plane {
        Plane {
            a: 0.0,
            b: 0.0,
            c: z,
        }
    }

    /// The plane through three points (not on one line).
    pub fn through(p: [Vec3; 3]) -> Plane {
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let (a, b) = (-n.x / n.z, -n.y / n.z);
        Plane {
            a,
            b,
            c: p[0].z - a * p[0].x - b * p[0].y,
        }
    }

    /// Its height over `p`.
    pub fn at(&self, p: Vec2) -> f32 {
        self.a * p.x + self.b * p.y + self.c
    }

    /// The plane `dz` higher.
    pub fn raised(self, dz: f32) -> Plane {
        Plane {
            c: self.c + dz,
            ..self
        }
    }
}

/// One slope of a wedge: where (a convex polygon) it lies between which planes.
#[derive(Clone, Debug)]
pub struct Slope {
    /// The part of the plane where these faces hold (convex).
    pub part: Vec<Vec2>,
    /// The face towards −z.
    pub front: Plane,
    /// The face towards +z.
    pub back: Plane,
}

/// A plate between sloping faces: the region of `outline` less every region of `less`, in
/// slopes that meet along shared sides (the faces of neighbouring slopes meet there).
pub struct Wedge {
    region: CrossSection,
    slopes: Vec<Slope>,
}

fn section(polygon: &[Vec2]) -> CrossSection {
    let mut p: Vec<V2> = polygon
        .iter()
        .map(|q| V2::new(q.x as f64, q.y as f64))
        .collect();
    if super::signed_area2(polygon) < 0.0 {
        p.reverse();
    }
    CrossSection::new(vec![p])
}

fn contours(cs: &CrossSection) -> Vec<Vec<Vec2>> {
    cs.to_polygons()
        .iter()
        .map(|c| {
            c.iter()
                .map(|p| Vec2::new(p.x as f32, p.y as f32))
                .collect()
        })
        .collect()
}

/// The region of `polygon` less those of `less`, as polygons (outer contours, holes clockwise).
pub fn difference(polygon: &[Vec2], less: &[Vec<Vec2>]) -> Vec<Vec<Vec2>> {
    let region = less
        .iter()
        .fold(section(polygon), |r, l| r.difference(&section(l)));
    contours(&region)
}

impl Wedge {
    /// The wedge over `outline` less `less`, in `slopes`.
    pub fn new(outline: &[Vec2], less: &[Vec<Vec2>], slopes: Vec<Slope>) -> Wedge {
        // corners closer than a micrometre (in centimetres) to their neighbours' line, as the
        // booleans leave, go
        let region = less
            .iter()
            .fold(section(outline), |r, l| r.difference(&section(l)))
            .simplify(1e-4);
        Wedge { region, slopes }
    }

    /// Its outline grown by `by` (mitred corners), as polygons: what stays `by` away from it.
    pub fn grown(&self, by: f32) -> Vec<Vec<Vec2>> {
        contours(&self.region.offset_with_params(by as f64, 2, 2.0, 0))
    }

    /// Closed shells, one per piece: walls round each slope's part of the region (but where
    /// two slopes meet), and each slope's front and back, corners shared by position.
    pub fn mesh(&self) -> Mesh {
        let mut m = Mesh::default();
        let mut index: HashMap<(u32, u32, bool), u32> = HashMap::default();
        // each slope's pieces of the region, each piece's outer contour first
        let parts: Vec<(Vec<Vec<Vec2>>, &Slope)> = self
            .slopes
            .iter()
            .flat_map(|s| {
                let mine = self.region.intersection(&section(&s.part));
                mine.decompose()
                    .into_iter()
                    // (a sliver the trimming leaves, under a hundredth of a square millimetre)
                    .filter(|piece| piece.area() > 1e-4)
                    .map(|piece| {
                        let mut c = contours(&piece);
                        c.sort_by(|a, b| super::signed_area2(b).total_cmp(&super::signed_area2(a)));
                        (c, s)
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        // corners within a tenth of a micrometre of each other (where the parts' booleans
        // found the same crossing twice) are one
        let mut seen: Vec<Vec2> = Vec::new();
        let parts: Vec<(Vec<Vec<Vec2>>, &Slope)> = parts
            .into_iter()
            .map(|(contours, s)| {
                let contours = contours
                    .into_iter()
                    .map(|c| {
                        let mut out: Vec<Vec2> = Vec::with_capacity(c.len());
                        for p in c {
                            let p = match seen.iter().find(|q| q.distance(p) < 1e-5) {
                                Some(&q) => q,
                                None => {
                                    seen.push(p);
                                    p
                                }
                            };
                            if out.last() != Some(&p) {
                                out.push(p);
                            }
                        }
                        while out.len() > 1 && out.first() == out.last() {
                            out.pop();
                        }
                        out
                    })
                    .filter(|c| c.len() >= 3)
                    .collect();
                (contours, s)
            })
            .collect();
        // the sides of every part's contours, by position: a side that another part has the
        // other way round is where two slopes meet
        let key = |p: Vec2| (p.x.to_bits(), p.y.to_bits());
        let mut sides: HashSet<(Key, Key)> = HashSet::default();
        for (contours, _) in &parts {
            for c in contours {
                for i in 0..c.len() {
                    sides.insert((key(c[i]), key(c[(i + 1) % c.len()])));
                }
            }
        }
        // a corner on the front or the back; the first slope to reach it sets its height
        let mut vertex = |m: &mut Mesh, p: Vec2, back: bool, s: &Slope| -> u32 {
            let (x, y) = key(p);
            *index.entry((x, y, back)).or_insert_with(|| {
                let z = if back { s.back.at(p) } else { s.front.at(p) };
                m.positions.push(p.extend(z));
                m.positions.len() as u32 - 1
            })
        };
        for (contours, s) in &parts {
            for c in contours {
                for i in 0..c.len() {
                    let (p, q) = (c[i], c[(i + 1) % c.len()]);
                    if sides.contains(&(key(q), key(p))) {
                        continue;
                    }
                    let (p0, q0, q1, p1) = (
                        vertex(&mut m, p, false, s),
                        vertex(&mut m, q, false, s),
                        vertex(&mut m, q, true, s),
                        vertex(&mut m, p, true, s),
                    );
                    m.quad(p0, q0, q1, p1);
                }
            }
            // the faces: one triangulation of the part for both
            let flat: Vec<[f64; 2]> = contours
                .iter()
                .flatten()
                .map(|p| [p.x as f64, p.y as f64])
                .collect();
            let mut holes = Vec::new();
            let mut start = 0u32;
            for c in &contours[..contours.len().saturating_sub(1)] {
                start += c.len() as u32;
                holes.push(start);
            }
            let corners: Vec<Vec2> = contours.iter().flatten().copied().collect();
            let mut tris: Vec<u32> = Vec::new();
            earcut::Earcut::new().earcut_slice(&flat, &holes, &mut tris);
            earcut::refine(&mut tris, &flat);
            for t in tris.chunks_exact(3) {
                let [a, b, c] = [0, 1, 2].map(|k| corners[t[k] as usize]);
                let (a, b, c) = if (b - a).perp_dot(c - a) < 0.0 {
                    (a, c, b)
                } else {
                    (a, b, c)
                };
                let front = [a, c, b].map(|p| vertex(&mut m, p, false, s));
                let back = [a, b, c].map(|p| vertex(&mut m, p, true, s));
                m.triangles.push(front);
                m.triangles.push(back);
            }
        }
        m
    }
}
