//! A ray-casting BVH: built by parry (binned or PLOC), collapsed into a 4-wide tree whose leaf
//! triangles are stored in traversal order, and walked by packets of rays from one origin: each
//! node's four boxes are tested once per packet against the cone the rays span, nearest child
//! first, and each triangle against four rays at once with a watertight test (Woop et al. 2013).
//! A single ray is a packet with one live lane.

use glam::{BVec4A, Vec3, Vec4};
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
/// x, y, z maxima), and each child's code: an internal node index, [`LEAF`] | triangle slot, or
/// [`EMPTY`] (whose box is inverted, +∞ to -∞, so that no ray enters it).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node4 {
    bounds: [Vec4; 6],
    child: [u32; 4],
}

/// Child code bit of a leaf.
const LEAF: u32 = 1 << 31;
/// Child code of an unused lane.
const EMPTY: u32 = u32::MAX;

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
    };
}

/// A triangle's vertices.
type Tri = [Vec3; 3];

/// Triangles at or above this count are built with PLOC (better trees, slower build); smaller
/// meshes with binned SAH.
const PLOC_FROM: usize = 50_000;

/// Traversal stack entries kept on the call stack: parry's trees of a few million triangles are
/// well under 20 four-wide levels deep, and a walk holds at most four entries per level.
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
    /// The 4-wide nodes, the root first (none for no triangles).
    nodes: Vec<Node4>,
    /// The most entries a walk's stack can hold: four per level of the tree.
    stack: usize,
    tris: Vec<Tri>,
    /// Input triangle index of each leaf-ordered triangle.
    order: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over triangles given by vertex positions.
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::new(),
            stack: 0,
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
        let root = bvh.collapse(&binary, 0, triangles);
        if root & LEAF != 0 {
            // a lone triangle: give it a node, so that every walk starts at node 0
            let mut node = Node4::VACANT;
            for axis in 0..3 {
                node.bounds[axis].x = binary[0].min[axis];
                node.bounds[axis + 3].x = binary[0].max[axis];
            }
            node.child[0] = root;
            bvh.nodes.push(node);
        }
        bvh.stack = 4 * bvh.depth(0);
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
                node.bounds[axis][lane] = binary[k].min[axis];
                node.bounds[axis + 3][lane] = binary[k].max[axis];
            }
            node.child[lane] = self.collapse(binary, k, triangles);
        }
        self.nodes[index] = node;
        index as u32
    }

    /// Levels of the tree below and including node `i`.
    fn depth(&self, i: usize) -> usize {
        let inner = self.nodes[i].child.iter().filter(|&&c| c & LEAF == 0);
        1 + inner.map(|&c| self.depth(c as usize)).max().unwrap_or(0)
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// True when there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
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
        self.cast_packet(origin, &[[dir; 4]], &[[t_max, 0.0, 0.0, 0.0]])[0][0]
    }

    /// The closest hits of a packet of rays from one origin (camera pixels, or shadow rays from
    /// one light), `G` groups of four, traced together through the tree: each node's boxes are
    /// tested once for the whole packet, each triangle against four rays at once. Lanes with
    /// `t_max <= 0` are idle. Each lane gets exactly what [`Bvh::cast`] gives its ray.
    pub fn cast_packet<const G: usize>(
        &self,
        origin: Vec3,
        dirs: &[[Vec3; 4]; G],
        t_max: &[[f32; 4]; G],
    ) -> [[Option<Hit>; 4]; G] {
        let none = Hit {
            t: 0.0,
            triangle: u32::MAX,
            u: 0.0,
            v: 0.0,
        };
        let mut best = [[none; 4]; G];
        let mut limit = [[0.0; 4]; G];
        for (g, k) in lanes::<G>() {
            (best[g][k].t, limit[g][k]) = (t_max[g][k], t_max[g][k].next_up());
        }
        let rays = Rays4::packet(origin, dirs, t_max);
        self.walk(origin, &rays, t_max, |g, mask, slot, reach| {
            let limit = &mut limit[g];
            let best = &mut best[g];
            rays[g].hits(
                &self.tris[slot as usize],
                mask,
                *limit,
                |lane, (t, u, v)| {
                    let hit = Hit {
                        t,
                        triangle: slot,
                        u,
                        v,
                    };
                    if let Some(t) = best[lane].closer(hit) {
                        reach[lane] = t;
                        limit[lane] = t.next_up();
                    }
                },
            );
        });
        let mut hits = [[None; 4]; G];
        for (hits, best) in hits.iter_mut().zip(&best) {
            for (hit, b) in hits.iter_mut().zip(best) {
                if b.triangle != u32::MAX {
                    *hit = Some(Hit {
                        triangle: self.triangle(b.triangle),
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
        self.occluded_packet(origin, &[[dir; 4]], &[[t_max, 0.0, 0.0, 0.0]])[0][0]
    }

    /// [`Bvh::occluded`] for a packet of rays from one origin, `G` groups of four, traced
    /// together; lanes with `t_max <= 0` are idle (and not occluded). A lane stops at its first
    /// hit.
    pub fn occluded_packet<const G: usize>(
        &self,
        origin: Vec3,
        dirs: &[[Vec3; 4]; G],
        t_max: &[[f32; 4]; G],
    ) -> [[bool; 4]; G] {
        let rays = Rays4::packet(origin, dirs, t_max);
        let mut blocked = [[false; 4]; G];
        self.walk(origin, &rays, t_max, |g, mask, slot, reach| {
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
        let (dirs, t_max) = (&[[dir; 4]], &[[t_max, 0.0, 0.0, 0.0]]);
        let rays = Rays4::packet(origin, dirs, t_max);
        let mut leaves = 0;
        let mut limit = t_max[0].map(f32::next_up);
        let nodes = self.walk(origin, &rays, t_max, |_, mask, slot, reach| {
            leaves += 1;
            rays[0].hits(&self.tris[slot as usize], mask, limit, |lane, (t, ..)| {
                reach[lane] = t;
                limit[lane] = t.next_up();
            });
        });
        (nodes, leaves)
    }

    /// The walk of a packet: visits each node once for the whole packet, testing its four boxes
    /// at once against the cone the rays span (interval arithmetic over their inverse
    /// directions, a superset of what each ray enters); `leaf(group, lanes, slot, reach)` tests
    /// a leaf's triangle for the lanes (bit mask) of a group still searching and lowers their
    /// `reach` on hits (a `reach` of 0 or less ends a lane). Returns the number of nodes visited.
    #[inline(always)]
    fn walk<const G: usize>(
        &self,
        origin: Vec3,
        rays: &[Rays4; G],
        t_max: &[[f32; 4]; G],
        mut leaf: impl FnMut(usize, u32, u32, &mut [f32; 4]),
    ) -> u32 {
        let mut reach = t_max.map(|t| t.map(|t| if t > 0.0 { t } else { -1.0 }));
        let mut lanes = reach.map(live_lanes);
        if self.nodes.is_empty() || lanes.iter().all(|&l| l == 0) {
            return 0;
        }
        let all = rays.iter().map(|r| r.inv).reduce(InvRange::union);
        let cone = Cone::new(origin, all.expect("a packet has a group"));
        // each group's own cone decides which leaves its rays test
        let groups: [Cone; G] = std::array::from_fn(|g| Cone::new(origin, rays[g].inv));
        let furthest = |reach: &[[f32; 4]; G]| {
            reach.iter().fold(f32::NEG_INFINITY, |m, r| {
                m.max(Vec4::from(*r).max_element())
            })
        };
        let mut reach_all = furthest(&reach);
        // on the call stack for any tree a real mesh gives, on the heap beyond
        let (mut inline, mut heap) = ([(0, 0.0); STACK], Vec::new());
        let items: &mut [(u32, f32)] = if self.stack <= STACK {
            &mut inline
        } else {
            heap.resize(self.stack, (0, 0.0));
            &mut heap
        };
        let mut stack = Stack { items, len: 0 };
        let mut cur = 0;
        let mut visited = 0;
        loop {
            visited += 1;
            let n = &self.nodes[cur as usize];
            let (mut mask, near) = cone.enters(n, reach_all);
            let base = stack.len;
            let mut leaves = 0;
            while mask != 0 {
                let c = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let code = n.child[c];
                if code & LEAF == 0 {
                    stack.push_sorted(base, code, near[c]);
                } else if code != EMPTY {
                    leaves |= 1 << c;
                }
            }
            if leaves != 0 {
                for g in 0..G {
                    if lanes[g] == 0 {
                        continue;
                    }
                    let mut tested = if G == 1 {
                        leaves
                    } else {
                        let reach = Vec4::from(reach[g]).max_element();
                        groups[g].enters(n, reach).0 & leaves
                    };
                    while tested != 0 && lanes[g] != 0 {
                        let c = tested.trailing_zeros() as usize;
                        tested &= tested - 1;
                        leaf(g, lanes[g], n.child[c] & !LEAF, &mut reach[g]);
                        lanes[g] = live_lanes(reach[g]);
                    }
                }
                if lanes.iter().all(|&l| l == 0) {
                    return visited;
                }
                reach_all = furthest(&reach);
            }
            match stack.pop_within(reach_all * WIDEN.x) {
                Some(code) => cur = code,
                None => return visited,
            }
        }
    }
}

/// Every (group, lane) of a packet of `G` groups of four rays.
pub(crate) fn lanes<const G: usize>() -> impl Iterator<Item = (usize, usize)> {
    // one flat range: a flat_map's nested state costs more than the work in some loops
    (0..4 * G).map(|i| (i / 4, i % 4))
}

/// The lanes (bit mask) whose reach or `t_max` is positive.
#[inline(always)]
fn live_lanes(reach: [f32; 4]) -> u32 {
    Vec4::from(reach).cmpgt(Vec4::ZERO).bitmask()
}

/// The cone spanned by a packet of rays from one origin, as the range of their inverse
/// direction components per axis: a box test against it admits every box any of the rays
/// enters (products are monotonic in the inverse direction, rounding included).
struct Cone {
    axes: [ConeAxis; 3],
}

/// One axis of a [`Cone`].
struct ConeAxis {
    /// The origin's coordinate (splat).
    origin: Vec4,
    /// Smallest and largest inverse direction component (splats).
    inv_lo: Vec4,
    inv_hi: Vec4,
    /// Which of a node's bounds the rays meet first and last (index into `Node4::bounds`).
    near: usize,
    far: usize,
}

/// The smallest and largest inverse direction component per axis of some rays (none: the
/// empty range, +∞ to -∞).
#[derive(Clone, Copy)]
struct InvRange {
    lo: Vec3,
    hi: Vec3,
}

impl InvRange {
    /// The range of the rays in `lanes` (a bit mask), given their direction components per
    /// axis as lanes.
    #[inline(always)]
    fn of(d: &[Vec4; 3], lanes: u32) -> InvRange {
        let live = BVec4A::new(
            lanes & 1 != 0,
            lanes & 2 != 0,
            lanes & 4 != 0,
            lanes & 8 != 0,
        );
        let [(xl, xh), (yl, yh), (zl, zh)] = d.map(|c| {
            let tiny = c.abs().cmplt(Vec4::splat(TINY));
            let inv = Vec4::ONE / Vec4::select(tiny, Vec4::splat(TINY).copysign(c), c);
            (
                Vec4::select(live, inv, Vec4::INFINITY).min_element(),
                Vec4::select(live, inv, Vec4::NEG_INFINITY).max_element(),
            )
        });
        InvRange {
            lo: Vec3::new(xl, yl, zl),
            hi: Vec3::new(xh, yh, zh),
        }
    }

    fn union(self, other: InvRange) -> InvRange {
        InvRange {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }
}

impl Cone {
    /// The cone of rays from `origin` with inverse directions in `range`.
    #[inline(always)]
    fn new(origin: Vec3, range: InvRange) -> Cone {
        // rays both ways along an axis: the origin at -∞ makes it admit every finite box
        let both = range.lo.cmplt(Vec3::ZERO) & range.hi.cmpgt(Vec3::ZERO);
        let o = Vec3::select(both, Vec3::NEG_INFINITY, origin).to_array();
        let lo = Vec3::select(both, Vec3::NEG_ONE, range.lo).to_array();
        let hi = Vec3::select(both, Vec3::ONE, range.hi).to_array();
        let backwards = range.hi.cmplt(Vec3::ZERO).bitmask();
        let axes = std::array::from_fn(|axis| {
            let (near, far) = if backwards & (1 << axis) != 0 {
                (axis + 3, axis)
            } else {
                (axis, axis + 3)
            };
            ConeAxis {
                origin: Vec4::splat(o[axis]),
                inv_lo: Vec4::splat(lo[axis]),
                inv_hi: Vec4::splat(hi[axis]),
                near,
                far,
            }
        });
        Cone { axes }
    }

    /// The children of `n` some ray of the cone enters before `reach` (bit mask), and the
    /// nearest entry distance per child.
    #[inline(always)]
    fn enters(&self, n: &Node4, reach: f32) -> (u32, [f32; 4]) {
        let mut near = Vec4::ZERO;
        let mut far = Vec4::splat(reach);
        for a in &self.axes {
            let d_near = n.bounds[a.near] - a.origin;
            let d_far = n.bounds[a.far] - a.origin;
            near = near.max((d_near * a.inv_lo).min(d_near * a.inv_hi));
            far = far.min((d_far * a.inv_lo).max(d_far * a.inv_hi));
        }
        (near.cmple(far * WIDEN).bitmask(), near.to_array())
    }
}

/// Direction components smaller than this are nudged to it (keeping their sign): 0·∞ would
/// poison box tests with NaN.
const TINY: f32 = 1e-20;

/// The nodes a walk has yet to visit, with their entry distances, the nearest on top, in
/// storage of the size the tree needs.
struct Stack<'a> {
    items: &'a mut [(u32, f32)],
    len: usize,
}

impl Stack<'_> {
    /// Pushes a child of the node being visited, keeping the entries above `base` (its other
    /// children) nearest on top.
    #[inline(always)]
    fn push_sorted(&mut self, base: usize, code: u32, t: f32) {
        let mut j = self.len;
        self.len += 1;
        while j > base && self.items[j - 1].1 < t {
            self.items[j] = self.items[j - 1];
            j -= 1;
        }
        self.items[j] = (code, t);
    }

    /// The nearest pending node whose entry distance is within `reach`; `None` when the walk is
    /// over.
    #[inline(always)]
    fn pop_within(&mut self, reach: f32) -> Option<u32> {
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

/// The factor that makes a box test's far distance (and the current closest hit it is compared
/// with) conservative: 1 + 2γ(3) (Ize, "Robust BVH ray traversal", 2013). Scaling the closest
/// hit too means every box holding a triangle hit at exactly that distance is entered, so ties
/// resolve the same way (lowest slot) in any traversal order.
const WIDEN: Vec4 = Vec4::splat(1.0 + 2.0 * GAMMA3);

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
        let axes = ShearedRay::axes(dir);
        let [kx, ky, kz] = axes;
        let d = dir.to_array();
        let shear = Vec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        ShearedRay {
            origin,
            axes,
            shear,
        }
    }

    /// The permutation that makes the dominant axis of `dir` z (keeping the winding).
    #[inline(always)]
    fn axes(dir: Vec3) -> [usize; 3] {
        let kz = dir.abs().max_position();
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if dir.to_array()[kz] < 0.0 {
            [ky, kx, kz]
        } else {
            [kx, ky, kz]
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

/// Four rays from one origin prepared for the watertight test: together in SIMD lanes where the
/// live rays share their sheared axes (nearly always), else one by one.
struct Rays4 {
    origin: Vec3,
    /// Direction components per axis (x, y, z), a ray per lane.
    dirs: [Vec4; 3],
    /// The range of the live rays' inverse directions.
    inv: InvRange,
    /// The sheared frame of the live rays, if they share its axes.
    shared: Option<Shear4>,
}

/// The sheared frame four rays share: the axes (see [`ShearedRay`]) and each ray's shear.
struct Shear4 {
    axes: [usize; 3],
    sx: Vec4,
    sy: Vec4,
    sz: Vec4,
}

impl Rays4 {
    /// The groups of a packet; lanes with `t_max <= 0` are idle and never tested.
    fn packet<const G: usize>(
        origin: Vec3,
        dirs: &[[Vec3; 4]; G],
        t_max: &[[f32; 4]; G],
    ) -> [Rays4; G] {
        std::array::from_fn(|g| Rays4::new(origin, &dirs[g], live_lanes(t_max[g])))
    }

    /// The rays in `lanes` (a bit mask).
    #[inline(always)]
    fn new(origin: Vec3, dirs: &[Vec3; 4], lanes: u32) -> Rays4 {
        let [a, b, c, e] = dirs;
        let d = [
            Vec4::new(a.x, b.x, c.x, e.x),
            Vec4::new(a.y, b.y, c.y, e.y),
            Vec4::new(a.z, b.z, c.z, e.z),
        ];
        let [dx, dy, dz] = d;
        // the dominant axis per lane, as `Vec3::max_position` picks it (first on ties)
        let (ax, ay, az) = (dx.abs(), dy.abs(), dz.abs());
        let is_z = az.cmpgt(ax.max(ay)).bitmask() & lanes;
        let is_y = ay.cmpgt(ax).bitmask() & !is_z & lanes;
        let uniform = |m: u32| m == 0 || m == lanes;
        let kz = if is_z != 0 { 2 } else { usize::from(is_y != 0) };
        let negative = d[kz].cmplt(Vec4::ZERO).bitmask() & lanes;
        let shared = (uniform(is_z) && uniform(is_y) && uniform(negative)).then(|| {
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            let axes = if negative != 0 {
                [ky, kx, kz]
            } else {
                [kx, ky, kz]
            };
            let [x, y, z] = [d[axes[0]], d[axes[1]], d[axes[2]]];
            Shear4 {
                axes,
                sx: x / z,
                sy: y / z,
                sz: Vec4::ONE / z,
            }
        });
        Rays4 {
            origin,
            dirs: d,
            inv: InvRange::of(&d, lanes),
            shared,
        }
    }

    /// Lane `lane` as a single ray.
    fn ray(&self, lane: usize) -> ShearedRay {
        let [x, y, z] = self.dirs.map(|c| c.to_array()[lane]);
        ShearedRay::new(self.origin, Vec3::new(x, y, z))
    }

    /// Calls `hit(lane, (t, u, v))` for each lane in `mask` whose ray hits `tri` with
    /// 0 < t < `limit[lane]`: all four lanes at once where the rays share their axes, else (and
    /// on edges, in f64) one by one.
    #[inline(always)]
    fn hits(
        &self,
        tri: &Tri,
        mask: u32,
        limit: [f32; 4],
        mut hit: impl FnMut(usize, (f32, f32, f32)),
    ) {
        let (found, t, u, v, mut todo) = match &self.shared {
            Some(shear) => shear.intersect(self.origin, tri, mask, Vec4::from(limit)),
            None => (0, [0.0; 4], [0.0; 4], [0.0; 4], mask),
        };
        todo |= found;
        while todo != 0 {
            let lane = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            if found & (1 << lane) != 0 {
                hit(lane, (t[lane], u[lane], v[lane]));
            } else if let Some(h) = self.ray(lane).intersect(tri, limit[lane]) {
                hit(lane, h);
            }
        }
    }
}

impl Shear4 {
    /// The watertight test of one triangle against the four rays from `origin`, with the same
    /// operations as [`ShearedRay::intersect`] so that each lane gets the same bits. For the
    /// lanes in `mask`: (lanes hit with 0 < t < `limit`, t, u, v, lanes on an edge to f32
    /// precision, which the scalar test settles in f64).
    #[inline(always)]
    fn intersect(
        &self,
        origin: Vec3,
        tri: &Tri,
        mask: u32,
        limit: Vec4,
    ) -> (u32, [f32; 4], [f32; 4], [f32; 4], u32) {
        let [kx, ky, kz] = self.axes;
        let [a, b, c] = tri.map(|v| (v - origin).to_array());
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
        let on_edge = (u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero)).bitmask() & mask;
        let negative = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let positive = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        let inside = !(negative & positive).bitmask() & !on_edge & mask;
        if inside == 0 {
            return (0, [0.0; 4], [0.0; 4], [0.0; 4], on_edge); // most tests miss
        }
        let det = u + v + w;
        let t_scaled = u * self.sz * Vec4::splat(a[kz])
            + v * self.sz * Vec4::splat(b[kz])
            + w * self.sz * Vec4::splat(c[kz]);
        let inv = Vec4::ONE / det;
        let t = t_scaled * inv;
        let valid = det.cmpne(zero) & t.cmpgt(zero) & t.cmplt(limit);
        let found = valid.bitmask() & inside;
        (
            found,
            t.to_array(),
            (v * inv).to_array(),
            (w * inv).to_array(),
            on_edge,
        )
    }
}
