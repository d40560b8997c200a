//! A ray-casting BVH: built by parry (binned or PLOC), flattened into 32-byte nodes with
//! adjacent children and leaf triangles stored in traversal order, then traversed nearest child
//! first with a Möller–Trumbore triangle test that allocates nothing.

use glam::{Vec3, Vec4};
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh as ParryBvh, BvhBuildStrategy, TraversalAction};

/// A node of parry's binary tree as flattened: an internal node's children are at `child` and
/// `child + 1`; a leaf holds one triangle, `prim` (an input triangle index).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node {
    min: Vec3,
    child: u32,
    max: Vec3,
    prim: u32,
}

const INTERNAL: u32 = u32::MAX;

/// A node of the 4-wide tree: the boxes of up to four children as lanes (x, y, z minima, then
/// maxima), and each child's code: an internal node index, [`LEAF`] | triangle slot, or
/// [`EMPTY`] (whose box is inverted, +∞ to -∞, so that no ray enters it).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node4 {
    lo: [Vec4; 3],
    hi: [Vec4; 3],
    child: [u32; 4],
}

/// Child code bit of a leaf.
const LEAF: u32 = 1 << 31;
/// Child code of an unused lane.
const EMPTY: u32 = u32::MAX;

impl Node4 {
    const VACANT: Node4 = Node4 {
        lo: [Vec4::INFINITY; 3],
        hi: [Vec4::NEG_INFINITY; 3],
        child: [EMPTY; 4],
    };
}

/// A triangle's vertices.
type Tri = [Vec3; 3];

/// Triangles at or above this count are built with PLOC (better trees, slower build); smaller
/// meshes with binned SAH.
const PLOC_FROM: usize = 50_000;

/// Traversal stack depth: a 4-wide node pushes at most 3 entries per level, and parry's trees of
/// a few million leaves are well under 40 levels deep.
const STACK: usize = 128;

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

impl Hit {
    /// Takes `other` if it is nearer, or as near with a lower triangle slot (so that ties at
    /// shared edges resolve the same way in any traversal order); returns its distance if so.
    #[inline(always)]
    fn closer(&mut self, other: Hit) -> Option<f32> {
        let take = other.t < self.t
            || (other.t == self.t && self.triangle != u32::MAX && other.triangle < self.triangle);
        take.then(|| {
            *self = other;
            other.t
        })
    }
}

/// A bounding volume hierarchy over triangles.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node4>,
    /// Child code of the root: a node, a single leaf, or [`EMPTY`].
    root: u32,
    tris: Vec<Tri>,
    /// Input triangle index of each leaf-ordered triangle.
    order: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over triangles given by vertex positions.
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::new(),
            root: EMPTY,
            tris: Vec::new(),
            order: Vec::new(),
        };
        if triangles.is_empty() {
            return bvh;
        }
        let strategy = if triangles.len() >= PLOC_FROM {
            BvhBuildStrategy::Ploc
        } else {
            BvhBuildStrategy::Binned
        };
        let aabbs = triangles
            .iter()
            .map(|t| Aabb::from_points(t.iter().copied()));
        let binary = flatten(&ParryBvh::from_iter(strategy, aabbs.enumerate()));
        bvh.nodes.reserve(triangles.len() / 2);
        bvh.tris.reserve(triangles.len());
        bvh.order.reserve(triangles.len());
        bvh.root = bvh.collapse(&binary, 0, triangles);
        bvh
    }

    /// The child code of binary node `i`, building 4-wide nodes below it. Leaves take the next
    /// triangle slots, so triangles end up in traversal order.
    fn collapse(&mut self, binary: &[Node], i: usize, triangles: &[[Vec3; 3]]) -> u32 {
        let n = &binary[i];
        if n.prim != INTERNAL {
            self.order.push(n.prim);
            self.tris.push(triangles[n.prim as usize]);
            return LEAF | (self.tris.len() as u32 - 1);
        }
        // open the largest internal child until there are four
        let mut kids = vec![n.child as usize, n.child as usize + 1];
        while kids.len() < 4 {
            let area = |k: usize| {
                let e = binary[k].max - binary[k].min;
                e.x * e.y + e.y * e.z + e.z * e.x
            };
            let Some(open) = (0..kids.len())
                .filter(|&j| binary[kids[j]].prim == INTERNAL)
                .max_by(|&a, &b| area(kids[a]).total_cmp(&area(kids[b])))
            else {
                break;
            };
            let c = binary[kids[open]].child as usize;
            kids[open] = c;
            kids.push(c + 1);
        }
        let index = self.nodes.len();
        self.nodes.push(Node4::VACANT);
        let mut node = Node4::VACANT;
        for (lane, &k) in kids.iter().enumerate() {
            for axis in 0..3 {
                node.lo[axis][lane] = binary[k].min[axis];
                node.hi[axis][lane] = binary[k].max[axis];
            }
            node.child[lane] = self.collapse(binary, k, triangles);
        }
        self.nodes[index] = node;
        index as u32
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
        self.walk(origin, dir, t_max, |tri, _| {
            let (t, u, v) = ray.intersect(&self.tris[tri as usize], best.t.next_up())?;
            best.closer(Hit {
                t,
                triangle: tri,
                u,
                v,
            })
        });
        (best.triangle != u32::MAX).then(|| Hit {
            triangle: self.order[best.triangle as usize],
            ..best
        })
    }

    /// The closest hits of four rays from one origin (a 2×2 block of camera pixels, or shadow
    /// rays from one light), traced together through the tree: each node's boxes are tested
    /// against all four rays at once. Lanes with `t_max <= 0` are idle. Each lane gets exactly
    /// what [`Bvh::cast`] gives it.
    pub fn cast4(&self, origin: Vec3, dirs: &[Vec3; 4], t_max: [f32; 4]) -> [Option<Hit>; 4] {
        let mut best = t_max.map(|t| Hit {
            t,
            triangle: u32::MAX,
            u: 0.0,
            v: 0.0,
        });
        let rays = Rays4::new(origin, dirs);
        self.walk4(origin, dirs, t_max, |mask, slot, reach| {
            let limit = best.map(|b| b.t.next_up());
            rays.hits(&self.tris[slot as usize], mask, limit, |lane, (t, u, v)| {
                let hit = Hit {
                    t,
                    triangle: slot,
                    u,
                    v,
                };
                if let Some(t) = best[lane].closer(hit) {
                    reach[lane] = t;
                }
            });
        });
        best.map(|b| {
            (b.triangle != u32::MAX).then(|| Hit {
                triangle: self.order[b.triangle as usize],
                ..b
            })
        })
    }

    /// Whether anything lies on `origin + t·dir` for `t` in (0, `t_max`).
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let ray = ShearedRay::new(origin, dir);
        let mut hit = false;
        self.walk(origin, dir, t_max, |tri, best_t| {
            let blocked = ray.intersect(&self.tris[tri as usize], best_t).is_some();
            hit |= blocked;
            blocked.then_some(0.0) // a closest distance of 0 ends the walk
        });
        hit
    }

    /// [`Bvh::occluded`] for four rays from one origin, traced together; lanes with
    /// `t_max <= 0` are idle (and not occluded). A lane stops at its first hit.
    pub fn occluded4(&self, origin: Vec3, dirs: &[Vec3; 4], t_max: [f32; 4]) -> [bool; 4] {
        let rays = Rays4::new(origin, dirs);
        let mut blocked = [false; 4];
        self.walk4(origin, dirs, t_max, |mask, slot, reach| {
            rays.hits(&self.tris[slot as usize], mask, t_max, |lane, _| {
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
        let nodes = self.walk(origin, dir, t_max, |tri, best_t| {
            leaves += 1;
            ray.intersect(&self.tris[tri as usize], best_t).map(|h| h.0)
        });
        (nodes, leaves)
    }

    /// Visits the leaves along the ray, nearest box first; `leaf` returns the new closest
    /// distance when its triangle is hit nearer than the current one. Returns the nodes visited.
    #[inline(always)]
    fn walk(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        mut leaf: impl FnMut(u32, f32) -> Option<f32>,
    ) -> u32 {
        let mut best = t_max;
        if self.root == EMPTY {
            return 0;
        }
        if self.root & LEAF != 0 {
            leaf(self.root & !LEAF, best);
            return 0;
        }
        // no zero components: 0·∞ would poison the lanes with NaN
        let safe = |c: f32| {
            if c.abs() < 1e-20 {
                1e-20f32.copysign(c)
            } else {
                c
            }
        };
        let inv = Vec3::new(safe(dir.x), safe(dir.y), safe(dir.z)).recip();
        let neg = [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0];
        let o = [
            Vec4::splat(origin.x),
            Vec4::splat(origin.y),
            Vec4::splat(origin.z),
        ];
        let i = [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)];
        let widen = Vec4::splat(1.0 + 2.0 * GAMMA3);
        let mut stack = Stack::new();
        let mut visited = 0;
        let mut cur = self.root;
        loop {
            visited += 1;
            let n = &self.nodes[cur as usize];
            let mut near = Vec4::ZERO;
            let mut far = Vec4::splat(best);
            for axis in 0..3 {
                let (a, b) = if neg[axis] {
                    (n.hi[axis], n.lo[axis])
                } else {
                    (n.lo[axis], n.hi[axis])
                };
                near = near.max((a - o[axis]) * i[axis]);
                far = far.min((b - o[axis]) * i[axis] * widen);
            }
            let mut mask = near.cmple(far).bitmask();
            let near = near.to_array(); // array lanes: glam's Vec4 indexing is a branchy match
            // the entered children, nearest first; leaves are tested on the spot
            let mut entered = Entered::default();
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let (code, t) = (n.child[lane], near[lane]);
                if code & LEAF != 0 {
                    if let Some(hit) = leaf(code & !LEAF, best) {
                        best = hit;
                    }
                } else {
                    entered.insert(code, t);
                }
            }
            if best <= 0.0 {
                return visited;
            }
            match stack.next(&entered, best) {
                Some(code) => cur = code,
                None => return visited,
            }
        }
    }

    /// The four-ray walk of [`Bvh::cast4`]: visits each node once for the whole packet, testing
    /// its four boxes against the four rays; `leaf(lanes, slot, reach)` tests a leaf's triangle
    /// for the lanes (bit mask) whose rays enter its box and lowers their `reach` on hits.
    #[inline(always)]
    fn walk4(
        &self,
        origin: Vec3,
        dirs: &[Vec3; 4],
        t_max: [f32; 4],
        mut leaf: impl FnMut(u32, u32, &mut [f32; 4]),
    ) {
        let mut best = Vec4::from(t_max.map(|t| if t > 0.0 { t } else { -1.0 }));
        if self.root == EMPTY || best.max_element() <= 0.0 {
            return;
        }
        if self.root & LEAF != 0 {
            let mask = best.cmpgt(Vec4::ZERO).bitmask();
            leaf(mask, self.root & !LEAF, &mut best.to_array());
            return;
        }
        let safe = |c: f32| {
            if c.abs() < 1e-20 {
                1e-20f32.copysign(c)
            } else {
                c
            }
        };
        let inv = |axis: usize| Vec4::from(dirs.map(|d| 1.0 / safe(d.to_array()[axis])));
        let i = [inv(0), inv(1), inv(2)];
        let o = origin.to_array();
        let widen = Vec4::splat(1.0 + 2.0 * GAMMA3);
        let mut stack = Stack::new();
        let mut cur = self.root;
        loop {
            let n = &self.nodes[cur as usize];
            let mut entered = Entered::default();
            for c in 0..4 {
                let code = n.child[c];
                if code == EMPTY {
                    continue;
                }
                let mut near = Vec4::ZERO;
                let mut far = best;
                for axis in 0..3 {
                    let lo: &[f32; 4] = n.lo[axis].as_ref();
                    let hi: &[f32; 4] = n.hi[axis].as_ref();
                    let t0 = Vec4::splat(lo[c] - o[axis]) * i[axis];
                    let t1 = Vec4::splat(hi[c] - o[axis]) * i[axis];
                    near = near.max(t0.min(t1));
                    far = far.min(t0.max(t1) * widen);
                }
                let entering = near.cmple(far);
                let mask = entering.bitmask();
                if mask == 0 {
                    continue;
                }
                if code & LEAF != 0 {
                    let mut b = best.to_array();
                    leaf(mask, code & !LEAF, &mut b);
                    best = Vec4::from(b);
                } else {
                    entered.insert(
                        code,
                        Vec4::select(entering, near, Vec4::INFINITY).min_element(),
                    );
                }
            }
            match stack.next(&entered, best.max_element()) {
                Some(code) => cur = code,
                None => return,
            }
        }
    }
}

/// The children a walk entered at one node, nearest first: (child code, entry distance).
#[derive(Default)]
struct Entered {
    items: [(u32, f32); 4],
    count: usize,
}

impl Entered {
    #[inline(always)]
    fn insert(&mut self, code: u32, t: f32) {
        let mut j = self.count;
        while j > 0 && self.items[j - 1].1 > t {
            self.items[j] = self.items[j - 1];
            j -= 1;
        }
        self.items[j] = (code, t);
        self.count += 1;
    }
}

/// The nodes a walk deferred, with their entry distances.
struct Stack {
    items: [(u32, f32); STACK],
    len: usize,
}

impl Stack {
    fn new() -> Stack {
        Stack {
            items: [(0, 0.0); STACK],
            len: 0,
        }
    }

    /// The next node to visit: the nearest entered child within `reach` (the others deferred,
    /// the farthest deepest), else the latest deferred node still within `reach`; `None` when
    /// the walk is over.
    #[inline(always)]
    fn next(&mut self, entered: &Entered, reach: f32) -> Option<u32> {
        let mut next = None;
        for &(code, t) in entered.items[..entered.count].iter().rev() {
            if t > reach {
                continue;
            }
            if let Some(deferred) = next.replace((code, t)) {
                self.items[self.len] = deferred;
                self.len += 1;
            }
        }
        if let Some((code, _)) = next {
            return Some(code);
        }
        while self.len > 0 {
            self.len -= 1;
            let (code, t) = self.items[self.len];
            if t <= reach {
                return Some(code);
            }
        }
        None
    }
}

/// Copies parry's binary tree into adjacent-children order. Its topology is read through parry's
/// public depth-first traversal: it visits both children of a node as a pair, then descends left
/// first, deferring a right subtree on its stack; mirroring that order tells whose children each
/// pair is. Index 0 is the root.
fn flatten(parry: &ParryBvh) -> Vec<Node> {
    let root = parry.root_aabb();
    let mut nodes = vec![Node {
        min: root.mins,
        child: 1,
        max: root.maxs,
        prim: INTERNAL,
    }];
    let mut owner: Option<u32> = Some(0);
    let mut deferred: Vec<u32> = Vec::new();
    let mut pair: Vec<(u32, bool)> = Vec::with_capacity(2);
    let single_leaf = parry.leaf_count() == 1;
    parry.traverse(|node| {
        let index = nodes.len() as u32;
        if pair.is_empty() {
            let parent = owner.take().expect("every visited pair has a parent");
            nodes[parent as usize].child = index;
        }
        let aabb = node.aabb();
        let leaf = node.leaf_data();
        nodes.push(Node {
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
        // parry stores a lone leaf without a sibling: the root is that leaf
        nodes.swap(0, 1);
        nodes.truncate(1);
    }
    nodes
}

/// γ(3) = 3ε / (1 - 3ε): the relative error bound of three f32 operations.
const GAMMA3: f32 = 3.0 * f32::EPSILON / (1.0 - 3.0 * f32::EPSILON);

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
        let d = dir.to_array();
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = Vec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
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
        // arrays, not Vec3: glam's Vec3 indexing is a branchy match
        let [a, b, c] = tri.map(|v| (v - self.origin).to_array());
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

/// Four rays from one origin prepared for the watertight test, one by one and, where they share
/// their axes, together.
struct Rays4 {
    rays: [ShearedRay; 4],
    simd: Option<RayPacket>,
}

impl Rays4 {
    fn new(origin: Vec3, dirs: &[Vec3; 4]) -> Rays4 {
        let rays = dirs.map(|d| ShearedRay::new(origin, d));
        let simd = RayPacket::new(origin, &rays);
        Rays4 { rays, simd }
    }

    /// Calls `hit(lane, (t, u, v))` for each lane in `mask` whose ray hits `tri` with
    /// 0 < t < `limit[lane]`: all four lanes at once where the rays share their axes, else (and
    /// on edges) one by one.
    #[inline(always)]
    fn hits(
        &self,
        tri: &Tri,
        mut mask: u32,
        limit: [f32; 4],
        mut hit: impl FnMut(usize, (f32, f32, f32)),
    ) {
        let simd = self.simd.as_ref().map(|p| p.intersect(tri, mask));
        while mask != 0 {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let found = match &simd {
                Some((found, t, u, v, _)) if found & (1 << lane) != 0 => {
                    (t[lane] < limit[lane]).then(|| (t[lane], u[lane], v[lane]))
                }
                Some((.., exact)) if exact & (1 << lane) != 0 => None,
                _ => self.rays[lane].intersect(tri, limit[lane]),
            };
            if let Some(h) = found {
                hit(lane, h);
            }
        }
    }
}

/// Four rays from one origin whose sheared frames share their axes: the watertight test of one
/// triangle against all four in SIMD lanes, with the same operations as [`ShearedRay::intersect`]
/// so that each lane gets the same bits.
struct RayPacket {
    origin: Vec3,
    axes: [usize; 3],
    sx: Vec4,
    sy: Vec4,
    sz: Vec4,
}

impl RayPacket {
    /// The packet, if the four rays share their axes.
    fn new(origin: Vec3, rays: &[ShearedRay; 4]) -> Option<RayPacket> {
        rays.iter()
            .all(|r| r.axes == rays[0].axes)
            .then(|| RayPacket {
                origin,
                axes: rays[0].axes,
                sx: Vec4::from(rays.each_ref().map(|r| r.shear.x)),
                sy: Vec4::from(rays.each_ref().map(|r| r.shear.y)),
                sz: Vec4::from(rays.each_ref().map(|r| r.shear.z)),
            })
    }

    /// For the lanes in `mask`: (lanes hit with 0 < t, t, u, v, lanes decided here). Lanes on an
    /// edge to f32 precision are not decided here: the scalar test settles them in f64.
    #[inline(always)]
    fn intersect(&self, tri: &Tri, mask: u32) -> (u32, [f32; 4], [f32; 4], [f32; 4], u32) {
        let [kx, ky, kz] = self.axes;
        let [a, b, c] = tri.map(|v| (v - self.origin).to_array());
        let sheared = |p: [f32; 3]| {
            let z = Vec4::splat(p[kz]);
            (
                Vec4::splat(p[kx]) - self.sx * z,
                Vec4::splat(p[ky]) - self.sy * z,
            )
        };
        let ((ax, ay), (bx, by), (cx, cy)) = (sheared(a), sheared(b), sheared(c));
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = (u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero)).bitmask();
        let negative = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let positive = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        let outside = (negative & positive).bitmask();
        let det = u + v + w;
        let t_scaled = u * self.sz * Vec4::splat(a[kz])
            + v * self.sz * Vec4::splat(b[kz])
            + w * self.sz * Vec4::splat(c[kz]);
        let inv = Vec4::ONE / det;
        let t = t_scaled * inv;
        let found = (det.cmpne(zero) & t.cmpgt(zero)).bitmask() & !outside & !on_edge & mask;
        (
            found,
            t.to_array(),
            (v * inv).to_array(),
            (w * inv).to_array(),
            !on_edge & mask,
        )
    }
}
