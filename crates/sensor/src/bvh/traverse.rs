//! Walking the tree with a packet of rays: each node's four boxes tested once for the packet
//! against the cone its rays span from the box of their origins, nearest child first, on a
//! short stack.

use std::mem::MaybeUninit;

use glam::{BVec4A, Vec3, Vec4};

use super::triangle::{Rays4, WIDEN};
use super::{Bvh, COUNT_SHIFT, DEEP, EMPTY, LEAF, Node4, SLOT, leaf_slots};

/// Traversal stack entries kept on the call stack: trees of a few million triangles are
/// well under 20 four-wide levels deep, and a walk holds at most four entries per level.
const STACK: usize = 128;

impl Bvh {
    /// The walk of a packet: visits each node once for the whole packet, testing its four boxes
    /// at once against the cone the rays span (interval arithmetic over their origins and
    /// inverse directions, a superset of what each ray enters); `leaf(group, lanes, slot,
    /// reach)` tests a leaf's triangle (each in turn) for the lanes (bit mask) of a group still
    /// searching and lowers their `reach` on hits (a `reach` of 0 or less ends a lane). Returns
    /// the number of nodes visited.
    #[inline(always)]
    pub(super) fn walk<const G: usize>(
        &self,
        rays: &[Rays4; G],
        t_max: &[[f32; 4]; G],
        mut leaf: impl FnMut(usize, u32, u32, &mut [f32; 4]),
    ) -> u32 {
        let mut reach = t_max.map(|t| t.map(|t| if t > 0.0 { t } else { -1.0 }));
        let mut lanes = reach.map(live_lanes);
        if self.nodes.is_empty() || lanes.iter().all(|&l| l == 0) {
            return 0;
        }
        let span = |of: fn(&Rays4) -> Span| rays.iter().map(of).reduce(Span::union);
        let (from, inv) = (span(|r| r.from), span(|r| r.inv));
        let cone = Cone::new(from.expect("a packet has a group"), inv.expect("one"));
        // each group's own cone decides which leaves its rays test
        let groups: [Cone; G] = std::array::from_fn(|g| Cone::new(rays[g].from, rays[g].inv));
        let furthest = |reach: &[[f32; 4]; G]| {
            reach.iter().fold(f32::NEG_INFINITY, |m, r| {
                m.max(Vec4::from(*r).max_element())
            })
        };
        let mut reach_all = furthest(&reach);
        self.with_stack(|mut stack| {
            let mut cur = 0;
            let mut visited = 0;
            loop {
                visited += 1;
                let n = self.node(cur);
                let (mut mask, near) = cone.enters(n, reach_all);
                let base = stack.len;
                let mut leaves = 0;
                while mask != 0 {
                    let c = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let code = n.child[c];
                    if code & LEAF == 0 {
                        self.prefetch(code, true);
                        self.prefetch_leaves(n.leaves[c]);
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
                        'leaves: while tested != 0 {
                            let c = tested.trailing_zeros() as usize;
                            tested &= tested - 1;
                            for slot in leaf_slots(n.child[c]) {
                                leaf(g, lanes[g], slot, &mut reach[g]);
                                lanes[g] = live_lanes(reach[g]);
                                if lanes[g] == 0 {
                                    break 'leaves;
                                }
                            }
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
        })
    }
}

impl Bvh {
    /// The node of an internal child's code.
    #[inline(always)]
    fn node(&self, code: u32) -> &Node4 {
        &self.nodes[(code & !DEEP) as usize]
    }

    /// Asks for the node of an internal child's code to be brought into the cache while the walk
    /// goes on (most children a walk enters it visits later, from the stack), and with `first`
    /// its first internal child where it has one: the node a walk that visits it at once most
    /// often goes on to.
    #[inline(always)]
    fn prefetch(&self, code: u32, first: bool) {
        let (i, lines) = ((code & !DEEP) as usize, size_of::<Node4>() / 64);
        let next = usize::from(first && code & DEEP != 0);
        prefetch_lines(self.nodes.as_ptr().wrapping_add(i), lines * (1 + next));
    }

    /// Asks for the triangles of a node's leaves (`lines`: as [`Node4::leaves`] keeps them) to
    /// be brought into the cache with the node (a single ray's walk gains nothing from it).
    #[inline(always)]
    fn prefetch_leaves(&self, lines: u32) {
        let from = self.tris.as_ptr().wrapping_add((lines & SLOT) as usize);
        prefetch_lines(from, (lines >> COUNT_SHIFT) as usize);
    }

    /// Runs `walk` with a traversal stack of the size the tree needs: on the call stack for any
    /// tree a real mesh gives, on the heap beyond.
    #[inline(always)]
    fn with_stack<R>(&self, walk: impl FnOnce(Stack<'_>) -> R) -> R {
        // unwritten: a walk reads only the entries it pushed (zeroing them costs a single
        // ray's walk a few per cent)
        let (mut inline, mut heap) = ([const { MaybeUninit::uninit() }; STACK], Vec::new());
        let items: &mut [MaybeUninit<(u32, f32)>] = if self.stack <= STACK {
            &mut inline
        } else {
            heap.resize(self.stack, MaybeUninit::uninit());
            &mut heap
        };
        walk(Stack { items, len: 0 })
    }

    /// The walk of one ray from `origin` along `dir`: what [`Bvh::walk`] does for a packet with
    /// one live lane (the same box tests to the bit, in the same order), without a packet's
    /// bookkeeping; `leaf(slot, reach)` tests a leaf's triangle and lowers `reach` on
    /// a hit (to 0 or less to end the walk). Returns the number of nodes visited.
    #[inline(always)]
    pub(super) fn walk_one(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        mut leaf: impl FnMut(u32, &mut f32),
    ) -> u32 {
        let mut reach = t_max;
        if self.nodes.is_empty() || reach <= 0.0 {
            return 0;
        }
        let slab = Slab::new(origin, dir);
        self.with_stack(|mut stack| {
            let mut cur = 0;
            let mut visited = 0;
            loop {
                visited += 1;
                let n = self.node(cur);
                let (mut mask, near) = slab.enters(n, reach);
                let base = stack.len;
                while mask != 0 {
                    let c = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let code = n.child[c];
                    if code & LEAF == 0 {
                        self.prefetch(code, false);
                        stack.push_sorted(base, code, near[c]);
                    } else if code != EMPTY {
                        for slot in leaf_slots(code) {
                            leaf(slot, &mut reach);
                            if reach <= 0.0 {
                                return visited;
                            }
                        }
                    }
                }
                match stack.pop_within(reach * WIDEN.x) {
                    Some(code) => cur = code,
                    None => return visited,
                }
            }
        })
    }
}

/// Asks for the `lines` cache lines from `from` on to be brought into the cache.
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]
pub(crate) fn prefetch_lines<T>(from: *const T, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for line in 0..lines {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: prefetching has no effect on memory, whatever the address
        unsafe { _mm_prefetch::<_MM_HINT_T0>(from.cast::<i8>().wrapping_add(64 * line)) };
    }
}

/// Every (group, lane) of a packet of `G` groups of four rays.
pub(crate) fn lanes<const G: usize>() -> impl Iterator<Item = (usize, usize)> {
    // one flat range: a flat_map's nested state costs more than the work in some loops
    (0..4 * G).map(|i| (i / 4, i % 4))
}

/// The lanes (bit mask) whose reach or `t_max` is positive.
#[inline(always)]
pub(super) fn live_lanes(reach: [f32; 4]) -> u32 {
    Vec4::from(reach).cmpgt(Vec4::ZERO).bitmask()
}

/// The cone spanned by a packet of rays, as the range of their origins' coordinates and of
/// their inverse direction components per axis: a box test against it admits every box any of
/// the rays enters (products are monotonic in the inverse direction, differences in the origin,
/// rounding included).
struct Cone {
    axes: [ConeAxis; 3],
}

/// One axis of a [`Cone`].
struct ConeAxis {
    /// The origin coordinate (splat) that gives the earliest entry through the near bound, and
    /// the one that gives the latest exit through the far bound (the same for rays from one
    /// origin).
    near_origin: Vec4,
    far_origin: Vec4,
    /// Smallest and largest inverse direction component (splats).
    inv_lo: Vec4,
    inv_hi: Vec4,
    /// Which of a node's bounds the rays meet first and last (index into `Node4::bounds`).
    near: usize,
    far: usize,
}

/// The smallest and largest component per axis of some rays' origins or inverse directions
/// (none: the empty range, +∞ to -∞).
#[derive(Clone, Copy)]
pub(super) struct Span {
    lo: Vec3,
    hi: Vec3,
}

impl Span {
    /// The range over the rays in `lanes` (a bit mask) of vectors given per axis as lanes.
    #[inline(always)]
    pub(super) fn of(v: &[Vec4; 3], lanes: u32) -> Span {
        let live = BVec4A::new(
            lanes & 1 != 0,
            lanes & 2 != 0,
            lanes & 4 != 0,
            lanes & 8 != 0,
        );
        let [(xl, xh), (yl, yh), (zl, zh)] = v.map(|c| {
            (
                Vec4::select(live, c, Vec4::INFINITY).min_element(),
                Vec4::select(live, c, Vec4::NEG_INFINITY).max_element(),
            )
        });
        Span {
            lo: Vec3::new(xl, yl, zl),
            hi: Vec3::new(xh, yh, zh),
        }
    }

    fn union(self, other: Span) -> Span {
        Span {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }
}

/// The inverse of direction components, those smaller than [`TINY`] nudged to it (keeping
/// their sign).
#[inline(always)]
pub(super) fn inverse(c: Vec4) -> Vec4 {
    let tiny = c.abs().cmplt(Vec4::splat(TINY));
    Vec4::ONE / Vec4::select(tiny, Vec4::splat(TINY).copysign(c), c)
}

impl Cone {
    /// The cone of rays with origins in `from` and inverse directions in `inv`.
    #[inline(always)]
    fn new(from: Span, inv: Span) -> Cone {
        // rays both ways along an axis: the origin at -∞ makes it admit every finite box
        let both = inv.lo.cmplt(Vec3::ZERO) & inv.hi.cmpgt(Vec3::ZERO);
        let lo = Vec3::select(both, Vec3::NEG_ONE, inv.lo).to_array();
        let hi = Vec3::select(both, Vec3::ONE, inv.hi).to_array();
        let backwards = inv.hi.cmplt(Vec3::ZERO);
        // along +axis the earliest entry is from the furthest origin and the latest exit from
        // the nearest; along -axis the other way round
        let near_o = Vec3::select(backwards, from.lo, from.hi);
        let far_o = Vec3::select(backwards, from.hi, from.lo);
        let near_o = Vec3::select(both, Vec3::NEG_INFINITY, near_o).to_array();
        let far_o = Vec3::select(both, Vec3::NEG_INFINITY, far_o).to_array();
        let backwards = backwards.bitmask();
        let axes = std::array::from_fn(|axis| {
            let (near, far) = bound_order(backwards & (1 << axis) != 0, axis);
            ConeAxis {
                near_origin: Vec4::splat(near_o[axis]),
                far_origin: Vec4::splat(far_o[axis]),
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
            let d_near = n.bounds[a.near] - a.near_origin;
            let d_far = n.bounds[a.far] - a.far_origin;
            near = near.max((d_near * a.inv_lo).min(d_near * a.inv_hi));
            far = far.min((d_far * a.inv_lo).max(d_far * a.inv_hi));
        }
        (near.cmple(far * WIDEN).bitmask(), near.to_array())
    }
}

/// Which of a node's bounds (index into `Node4::bounds`) rays along `axis` meet first and last.
#[inline(always)]
fn bound_order(backwards: bool, axis: usize) -> (usize, usize) {
    if backwards {
        (axis + 3, axis)
    } else {
        (axis, axis + 3)
    }
}

/// One ray's box test: a [`Cone`] of one ray, whose interval products collapse to one product
/// per bound (the minimum and maximum of a value and itself are the value: the same result to
/// the bit, at half the arithmetic).
struct Slab {
    axes: [SlabAxis; 3],
}

/// One axis of a [`Slab`].
struct SlabAxis {
    /// The origin's coordinate and the inverse direction component (splats).
    origin: Vec4,
    inv: Vec4,
    /// Which of a node's bounds the ray meets first and last (index into `Node4::bounds`).
    near: usize,
    far: usize,
}

impl Slab {
    #[inline(always)]
    fn new(origin: Vec3, dir: Vec3) -> Slab {
        let inv = inverse(dir.extend(1.0)).truncate();
        let (o, inv_a) = (origin.to_array(), inv.to_array());
        let backwards = inv.cmplt(Vec3::ZERO).bitmask();
        let axes = std::array::from_fn(|axis| {
            let (near, far) = bound_order(backwards & (1 << axis) != 0, axis);
            SlabAxis {
                origin: Vec4::splat(o[axis]),
                inv: Vec4::splat(inv_a[axis]),
                near,
                far,
            }
        });
        Slab { axes }
    }

    /// As [`Cone::enters`].
    #[inline(always)]
    fn enters(&self, n: &Node4, reach: f32) -> (u32, [f32; 4]) {
        let mut near = Vec4::ZERO;
        let mut far = Vec4::splat(reach);
        for a in &self.axes {
            near = near.max((n.bounds[a.near] - a.origin) * a.inv);
            far = far.min((n.bounds[a.far] - a.origin) * a.inv);
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
    /// Entries below `len` are written.
    items: &'a mut [MaybeUninit<(u32, f32)>],
    len: usize,
}

impl Stack<'_> {
    /// Pushes a child of the node being visited, keeping the entries above `base` (its other
    /// children) nearest on top.
    #[inline(always)]
    fn push_sorted(&mut self, base: usize, code: u32, t: f32) {
        let mut j = self.len;
        self.len += 1;
        while j > base && self.get(j - 1).1 < t {
            self.items[j] = self.items[j - 1];
            j -= 1;
        }
        self.items[j].write((code, t));
    }

    /// Entry `i`, below `len`.
    #[inline(always)]
    fn get(&self, i: usize) -> (u32, f32) {
        debug_assert!(i < self.len);
        // SAFETY: entries below `len` were written by `push_sorted`, which moves them up only
        // into places below the new `len`
        unsafe { self.items[i].assume_init() }
    }

    /// The nearest pending node whose entry distance is within `reach`; `None` when the walk is
    /// over.
    #[inline(always)]
    fn pop_within(&mut self, reach: f32) -> Option<u32> {
        while self.len > 0 {
            let (code, t) = self.get(self.len - 1);
            self.len -= 1;
            if t <= reach {
                return Some(code);
            }
        }
        None
    }
}
