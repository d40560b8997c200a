//! A ray-casting BVH: built by parry (binned or PLOC), flattened into 32-byte nodes with
//! adjacent children and leaf triangles stored in traversal order, then traversed nearest child
//! first with a Möller–Trumbore triangle test that allocates nothing.

use glam::Vec3;
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh as ParryBvh, BvhBuildStrategy, TraversalAction};

/// A node: an internal node's children are at `child` and `child + 1`; a leaf holds one
/// triangle, `prim`, an index into the leaf-ordered triangle arrays.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node {
    min: Vec3,
    child: u32,
    max: Vec3,
    prim: u32,
}

const INTERNAL: u32 = u32::MAX;

/// A triangle's vertices.
type Tri = [Vec3; 3];

/// Triangles at or above this count are built with PLOC (better trees, slower build); smaller
/// meshes with binned SAH.
const PLOC_FROM: usize = 50_000;

/// Traversal stack depth; parry's trees of a few million leaves stay far below it.
const STACK: usize = 96;

/// The closest intersection along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray direction.
    pub t: f32,
    /// Index of the triangle in the input order.
    pub triangle: u32,
    /// Barycentric coordinate of the second vertex.
    pub u: f32,
    /// Barycentric coordinate of the third vertex.
    pub v: f32,
}

/// A bounding volume hierarchy over triangles.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
    /// Input triangle index of each leaf-ordered triangle.
    order: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over triangles given by vertex positions.
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        if triangles.is_empty() {
            return Bvh {
                nodes: Vec::new(),
                tris: Vec::new(),
                order: Vec::new(),
            };
        }
        let strategy = if triangles.len() >= PLOC_FROM {
            BvhBuildStrategy::Ploc
        } else {
            BvhBuildStrategy::Binned
        };
        let aabbs = triangles
            .iter()
            .map(|t| Aabb::from_points(t.iter().copied()));
        let parry = ParryBvh::from_iter(strategy, aabbs.enumerate());
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * triangles.len()),
            tris: Vec::new(),
            order: Vec::new(),
        };
        bvh.flatten(&parry);
        bvh.order = bvh
            .nodes
            .iter()
            .filter(|n| n.prim != INTERNAL)
            .map(|n| n.prim)
            .collect();
        // renumber leaves in traversal order so that neighbouring leaves share cache lines
        for (slot, n) in bvh
            .nodes
            .iter_mut()
            .filter(|n| n.prim != INTERNAL)
            .enumerate()
        {
            n.prim = slot as u32;
        }
        bvh.tris = bvh.order.iter().map(|&i| triangles[i as usize]).collect();
        bvh
    }

    /// Copies parry's tree, whose topology is read through its public depth-first traversal:
    /// it visits both children of a node as a pair, then descends left first, deferring a right
    /// subtree on its stack; mirroring that order tells whose children each pair is.
    fn flatten(&mut self, parry: &ParryBvh) {
        let root = parry.root_aabb();
        self.nodes.push(Node {
            min: root.mins,
            child: 1,
            max: root.maxs,
            prim: INTERNAL,
        });
        let mut owner: Option<u32> = Some(0);
        let mut deferred: Vec<u32> = Vec::new();
        let mut pair: Vec<(u32, bool)> = Vec::with_capacity(2);
        let single_leaf = parry.leaf_count() == 1;
        parry.traverse(|node| {
            let index = self.nodes.len() as u32;
            if pair.is_empty() {
                let parent = owner.take().expect("every visited pair has a parent");
                self.nodes[parent as usize].child = index;
            }
            let aabb = node.aabb();
            let leaf = node.leaf_data();
            self.nodes.push(Node {
                min: aabb.mins,
                child: 0,
                max: aabb.maxs,
                prim: leaf.unwrap_or(INTERNAL),
            });
            pair.push((index, leaf.is_none()));
            if pair.len() == 2 || single_leaf {
                match (pair[0], pair.get(1).copied().unwrap_or((0, false))) {
                    ((l, true), (r, true)) => {
                        owner = Some(l);
                        deferred.push(r);
                    }
                    ((l, true), _) => owner = Some(l),
                    (_, (r, true)) => owner = Some(r),
                    _ => owner = deferred.pop(),
                }
                pair.clear();
            }
            TraversalAction::Continue
        });
        if single_leaf {
            // parry stores a lone leaf without a sibling: make the root that leaf
            let leaf = self.nodes[1];
            self.nodes = vec![leaf];
        }
    }

    /// (nodes visited, leaves tested) along a ray: traversal cost, for diagnostics.
    pub fn cost(&self, origin: Vec3, dir: Vec3, t_max: f32) -> (u32, u32) {
        let ray = ShearedRay::new(origin, dir);
        let mut leaves = 0;
        let nodes = self.walk(origin, dir, t_max, |tri, best_t| {
            leaves += 1;
            ray.intersect(&self.tris[tri as usize], best_t).map(|h| h.0)
        });
        (nodes, leaves)
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// True when there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The closest hit along `origin + t·dir` with `t` in (0, `t_max`); `dir` must be unit length.
    #[inline]
    pub fn cast(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let mut best = Hit {
            t: t_max,
            triangle: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let ray = ShearedRay::new(origin, dir);
        self.walk(origin, dir, t_max, |tri, best_t| {
            if let Some((t, u, v)) = ray.intersect(&self.tris[tri as usize], best_t) {
                best = Hit {
                    t,
                    triangle: tri,
                    u,
                    v,
                };
                return Some(t);
            }
            None
        });
        (best.triangle != u32::MAX).then(|| Hit {
            triangle: self.order[best.triangle as usize],
            ..best
        })
    }

    /// Whether anything lies on `origin + t·dir` for `t` in (0, `t_max`).
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let mut hit = false;
        let ray = ShearedRay::new(origin, dir);
        self.walk(origin, dir, t_max, |tri, best_t| {
            if ray.intersect(&self.tris[tri as usize], best_t).is_some() {
                hit = true;
                return Some(0.0); // shrinks the interval to nothing: stop
            }
            None
        });
        hit
    }

    /// Visits leaves along the ray nearest first; `leaf` returns a new closest distance when
    /// the triangle is hit closer than the current one.
    #[inline(always)]
    fn walk(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        mut leaf: impl FnMut(u32, f32) -> Option<f32>,
    ) -> u32 {
        let mut visited = 0;
        if self.nodes.is_empty() {
            return visited;
        }
        let inv = dir.recip();
        let mut best = t_max;
        let mut stack = [(0u32, 0.0f32); STACK];
        let mut sp = 0;
        let root = &self.nodes[0];
        let Some(t0) = slab(root, origin, inv, best) else {
            return visited;
        };
        stack[0] = (0, t0);
        sp += 1;
        while sp > 0 {
            sp -= 1;
            let (mut cur, t_enter) = stack[sp];
            if t_enter >= best {
                continue;
            }
            loop {
                visited += 1;
                let n = &self.nodes[cur as usize];
                if n.prim != INTERNAL {
                    if let Some(t) = leaf(n.prim, best) {
                        best = t;
                    }
                    break;
                }
                let (a, b) = (n.child, n.child + 1);
                let ta = slab(&self.nodes[a as usize], origin, inv, best);
                let tb = slab(&self.nodes[b as usize], origin, inv, best);
                cur = match (ta, tb) {
                    (Some(ta), Some(tb)) => {
                        let (near, far, t_far) = if ta <= tb { (a, b, tb) } else { (b, a, ta) };
                        stack[sp] = (far, t_far);
                        sp += 1;
                        near
                    }
                    (Some(_), None) => a,
                    (None, Some(_)) => b,
                    (None, None) => break,
                };
            }
        }
        visited
    }
}

/// γ(3) = 3ε / (1 - 3ε): the relative error bound of three f32 operations.
const GAMMA3: f32 = 3.0 * f32::EPSILON / (1.0 - 3.0 * f32::EPSILON);

/// Entry distance of the ray into the node's box, if it enters before `best`.
#[inline(always)]
fn slab(n: &Node, origin: Vec3, inv: Vec3, best: f32) -> Option<f32> {
    // (min - origin)·inv, not min·inv - origin·inv: the latter is ∞ - ∞ for axis-parallel rays
    let t1 = (n.min - origin) * inv;
    let t2 = (n.max - origin) * inv;
    let near = t1.min(t2).max_element().max(0.0);
    // widened by 2γ(3) so that rounding never drops a box the ray grazes (Ize, JCGT 2013)
    let far = (t1.max(t2).min_element() * (1.0 + 2.0 * GAMMA3)).min(best);
    (near <= far).then_some(near)
}

/// A ray prepared for the watertight test: its dominant axis becomes z, and a shear maps the
/// direction onto +z.
struct ShearedRay {
    origin: Vec3,
    axes: [usize; 3],
    shear: Vec3,
}

impl ShearedRay {
    #[inline(always)]
    fn new(origin: Vec3, dir: Vec3) -> ShearedRay {
        let kz = dir.abs().max_position();
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = Vec3::new(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        ShearedRay {
            origin,
            axes: [kx, ky, kz],
            shear,
        }
    }

    /// (t, u, v) when the ray hits the triangle with 0 < t < `t_max`; u and v are the
    /// barycentric weights of the second and third vertex.
    #[inline(always)]
    fn intersect(&self, tri: &Tri, t_max: f32) -> Option<(f32, f32, f32)> {
        let [kx, ky, kz] = self.axes;
        let s = self.shear;
        let [a, b, c] = tri.map(|v| v - self.origin);
        let (ax, ay) = (a[kx] - s.x * a[kz], a[ky] - s.y * a[kz]);
        let (bx, by) = (b[kx] - s.x * b[kz], b[ky] - s.y * b[kz]);
        let (cx, cy) = (c[kx] - s.x * c[kz], c[ky] - s.y * c[kz]);
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // on an edge to f32 precision: decide in f64, as the paper does
            let d =
                |p: f32, q: f32, r: f32, t: f32| (p as f64 * q as f64 - r as f64 * t as f64) as f32;
            u = d(cx, by, cy, bx);
            v = d(ax, cy, ay, cx);
            w = d(bx, ay, by, ax);
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = u * s.z * a[kz] + v * s.z * b[kz] + w * s.z * c[kz];
        let inv = 1.0 / det;
        let t = t_scaled * inv;
        (t > 0.0 && t < t_max).then_some((t, v * inv, w * inv))
    }
}
