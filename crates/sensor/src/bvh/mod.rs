//! A ray-casting BVH: built by binned SAH splits (median splits where SAH cannot split) and collapsed into a 4-wide tree whose
//! leaf triangles are stored in traversal order (`build`), and walked by packets of rays
//! (`traverse`): each node's four boxes are tested once per packet against the cone the rays
//! span from the box of their origins, nearest child first, and each triangle against four
//! rays at once with a watertight test (Woop et al. 2013; `triangle`). A single ray walks the
//! same box tests without a packet's bookkeeping, and tests each triangle alone.

mod build;
mod traverse;
mod triangle;

use glam::{Vec3, Vec4};

pub(crate) use traverse::{lanes, prefetch_lines};
use triangle::{Rays4, ShearedRay};

/// A node of the 4-wide tree: the boxes of up to four children as lanes (x, y, z minima, then
/// x, y, z maxima), and each child's code: an internal node index (| [`DEEP`] where that node
/// has internal children), a leaf ([`LEAF`] | (triangles − 1) << [`COUNT_SHIFT`] | first
/// triangle slot: a run of one to [`LEAF_SIZE`] consecutive slots), or [`EMPTY`] (whose box is
/// inverted, +∞ to -∞, so that no ray enters it).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct Node4 {
    bounds: [Vec4; 6],
    child: [u32; 4],
    /// For each internal child, where the triangles of its own leaves start (a slot, below
    /// [`COUNT_SHIFT`]) and, in the three bits above, how many cache lines they span (at most
    /// seven; for prefetching them with it).
    leaves: [u32; 4],
}

/// Child code bit of a leaf.
const LEAF: u32 = 1 << 31;
/// Most triangles in a leaf.
const LEAF_SIZE: usize = 4;
/// Where a leaf's code keeps its number of triangles less one (two bits); the slot is below.
const COUNT_SHIFT: u32 = 29;
/// The bits of a leaf's code that hold its first slot.
const SLOT: u32 = (1 << COUNT_SHIFT) - 1;
/// The bit of an internal child's code that says its node has internal children, the first of
/// them the next node (depth-first order): fetched with it, the walk that goes straight on down
/// finds it there. Node indices stay below it: there are fewer nodes than triangles.
const DEEP: u32 = 1 << 30;
/// Child code of an unused lane.
const EMPTY: u32 = u32::MAX;

/// The triangle slots of a leaf's code.
#[inline(always)]
fn leaf_slots(code: u32) -> std::ops::Range<u32> {
    let first = code & SLOT;
    first..first + ((code & !LEAF) >> COUNT_SHIFT) + 1
}

impl Node4 {
    const VACANT: Node4 = Node4 {
        bounds: [
            Vec4::INFINITY,
            Vec4::INFINITY,
            Vec4::INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::NEG_INFINITY,
            Vec4::NEG_INFINITY,
        ],
        child: [EMPTY; 4],
        leaves: [0; 4],
    };
}

/// A triangle's vertices.
type Tri = [Vec3; 3];

/// The closest intersection along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray direction.
    pub t: f32,
    /// Index of the triangle in the input order.
    pub triangle: u32,
    /// The triangle's slot in the tree (its place in leaf order): hits of nearby rays lie in
    /// nearby slots, so what a caller keeps per triangle is best kept by slot.
    pub slot: u32,
    /// Barycentric coordinate of the second vertex.
    pub u: f32,
    /// Barycentric coordinate of the third vertex.
    pub v: f32,
}

impl Hit {
    /// Takes `other` if it is nearer, or as near with a lower input index (`order` maps the
    /// slots both hold to input indices: so that ties at shared edges resolve the same way in
    /// any traversal order and whatever the tree); returns its distance if so. During a walk a
    /// hit has its slot only.
    #[inline(always)]
    fn closer(&mut self, other: Hit, order: &[u32]) -> Option<f32> {
        let take = other.t < self.t
            || (other.t == self.t
                && self.slot != u32::MAX
                && order[other.slot as usize] < order[self.slot as usize]);
        take.then(|| {
            *self = other;
            other.t
        })
    }
}

/// A bounding volume hierarchy over triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    /// The 4-wide nodes, the root first (none for no triangles).
    nodes: Vec<Node4>,
    /// The most entries a walk's stack can hold: four per level of the tree.
    stack: usize,
    tris: Vec<Tri>,
    /// Input triangle index of each leaf-ordered triangle.
    order: Vec<u32>,
}

impl Bvh {
    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// True when there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Levels of the 4-wide tree (0 for no triangles).
    pub fn depth(&self) -> usize {
        self.stack / 4
    }

    /// The bytes the tree holds: its nodes, its triangles' corners and their input indices.
    pub fn bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.nodes[..]) + size_of_val(&self.tris[..]) + size_of_val(&self.order[..])
    }

    /// The triangles by slot (leaf order).
    pub(crate) fn slots(&self) -> &[Tri] {
        &self.tris
    }

    /// The input index of the triangle in `slot`.
    #[inline]
    pub(crate) fn triangle(&self, slot: u32) -> u32 {
        self.order[slot as usize]
    }

    /// The closest hit along `origin + t·dir` with `t` in (0, `t_max`); `dir` must be unit length.
    #[inline]
    pub fn cast(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let ray = ShearedRay::new(origin, dir);
        let mut best = Hit {
            t: t_max,
            triangle: u32::MAX,
            slot: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let mut limit = t_max.next_up();
        self.walk_one(origin, dir, t_max, |slot, reach| {
            if let Some((t, u, v)) = ray.intersect(&self.tris[slot as usize], limit) {
                let hit = Hit {
                    t,
                    triangle: u32::MAX,
                    slot,
                    u,
                    v,
                };
                if let Some(t) = best.closer(hit, &self.order) {
                    *reach = t;
                    limit = t.next_up();
                }
            }
        });
        (best.slot != u32::MAX).then(|| Hit {
            triangle: self.triangle(best.slot),
            ..best
        })
    }

    /// The closest hits of a packet of rays, `G` groups of four, traced together through the
    /// tree: each node's boxes are tested once for the whole packet, each triangle against four
    /// rays at once. The rays pay off together where they run side by side: camera pixels or
    /// shadow rays from one light (one origin), the mirror rays of a surface's neighbouring
    /// points. Lanes with `t_max <= 0` are idle. Each lane gets exactly what [`Bvh::cast`]
    /// gives its ray.
    pub fn cast_packet<const G: usize>(
        &self,
        origins: &[[Vec3; 4]; G],
        dirs: &[[Vec3; 4]; G],
        t_max: &[[f32; 4]; G],
    ) -> [[Option<Hit>; 4]; G] {
        self.cast_packet_noting(origins, dirs, t_max, |_| {})
    }

    /// [`Bvh::cast_packet`], calling `noted(slot)` for each hit a lane takes during the walk:
    /// what the caller keeps by slot for the hits can be asked into the cache while the walk
    /// goes on.
    pub(crate) fn cast_packet_noting<const G: usize>(
        &self,
        origins: &[[Vec3; 4]; G],
        dirs: &[[Vec3; 4]; G],
        t_max: &[[f32; 4]; G],
        mut noted: impl FnMut(u32),
    ) -> [[Option<Hit>; 4]; G] {
        if idle(t_max) {
            return [[None; 4]; G];
        }
        let none = Hit {
            t: 0.0,
            triangle: u32::MAX,
            slot: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let mut best = [[none; 4]; G];
        let mut limit = [[0.0; 4]; G];
        for (g, k) in lanes::<G>() {
            (best[g][k].t, limit[g][k]) = (t_max[g][k], t_max[g][k].next_up());
        }
        let rays = Rays4::packet(origins, dirs, t_max);
        self.walk(&rays, t_max, |g, mask, slot, reach| {
            let limit = &mut limit[g];
            let best = &mut best[g];
            rays[g].hits(
                &self.tris[slot as usize],
                mask,
                *limit,
                |lane, (t, u, v)| {
                    let hit = Hit {
                        t,
                        triangle: u32::MAX,
                        slot,
                        u,
                        v,
                    };
                    if let Some(t) = best[lane].closer(hit, &self.order) {
                        reach[lane] = t;
                        limit[lane] = t.next_up();
                        // its input index, read when the walk is over, on its way meanwhile
                        prefetch_lines(self.order.as_ptr().wrapping_add(slot as usize), 1);
                        noted(slot);
                    }
                },
            );
        });
        let mut hits = [[None; 4]; G];
        for (hits, best) in hits.iter_mut().zip(&best) {
            for (hit, b) in hits.iter_mut().zip(best) {
                if b.slot != u32::MAX {
                    *hit = Some(Hit {
                        triangle: self.triangle(b.slot),
                        ..*b
                    });
                }
            }
        }
        hits
    }

    /// Whether anything lies on `origin + t·dir` for `t` in (0, `t_max`).
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        self.occluder(origin, dir, t_max).is_some()
    }

    /// The slot of a triangle on `origin + t·dir` for `t` in (0, `t_max`): the first the walk
    /// meets, not necessarily the nearest; `None` where [`Bvh::occluded`] is false.
    #[inline]
    pub fn occluder(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<u32> {
        let ray = ShearedRay::new(origin, dir);
        let mut found = None;
        self.walk_one(origin, dir, t_max, |slot, reach| {
            if ray.intersect(&self.tris[slot as usize], t_max).is_some() {
                found = Some(slot);
                *reach = -1.0; // done
            }
        });
        found
    }

    /// Whether the triangle in slot `slot` lies on `origin + t·dir` for `t` in (0, `t_max`),
    /// by the test the walks make: where it does, [`Bvh::occluded`] is true (an occluder found
    /// for one ray, tried first on its neighbours, spares their walks).
    #[inline]
    pub fn blocks(&self, slot: u32, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        ShearedRay::new(origin, dir)
            .intersect(&self.tris[slot as usize], t_max)
            .is_some()
    }

    /// [`Bvh::occluded`] for a packet of rays, `G` groups of four, traced together (see
    /// [`Bvh::cast_packet`]); lanes with `t_max <= 0` are idle (and not occluded). A lane stops
    /// at its first hit.
    pub fn occluded_packet<const G: usize>(
        &self,
        origins: &[[Vec3; 4]; G],
        dirs: &[[Vec3; 4]; G],
        t_max: &[[f32; 4]; G],
    ) -> [[bool; 4]; G] {
        let mut blocked = [[false; 4]; G];
        if idle(t_max) {
            return blocked;
        }
        let rays = Rays4::packet(origins, dirs, t_max);
        self.walk(&rays, t_max, |g, mask, slot, reach| {
            let blocked = &mut blocked[g];
            rays[g].hits(&self.tris[slot as usize], mask, t_max[g], |lane, _| {
                blocked[lane] = true;
                reach[lane] = -1.0; // done: the lane enters no more boxes
            });
        });
        blocked
    }

    /// (nodes visited, triangles tested) along a ray: traversal cost, for diagnostics.
    pub fn cost(&self, origin: Vec3, dir: Vec3, t_max: f32) -> (u32, u32) {
        let ray = ShearedRay::new(origin, dir);
        let mut leaves = 0;
        let mut limit = t_max.next_up();
        let nodes = self.walk_one(origin, dir, t_max, |slot, reach| {
            leaves += 1;
            if let Some((t, ..)) = ray.intersect(&self.tris[slot as usize], limit) {
                *reach = t;
                limit = t.next_up();
            }
        });
        (nodes, leaves)
    }
}

/// Whether every lane of a packet is idle (`t_max <= 0`): nothing to set up or walk.
fn idle<const G: usize>(t_max: &[[f32; 4]; G]) -> bool {
    t_max.iter().flatten().all(|&t| t <= 0.0)
}
