//! Building the 4-wide tree: a binary tree by binned surface-area heuristic (SAH) splits of
//! the triangles' centroids down to leaves of at most [`LEAF_SIZE`] triangles, falling back to
//! median splits where SAH cannot split or the tree grows deep (equal centroids, coincident or
//! degenerate triangles), so that any input builds in O(n log n), the two halves of a large
//! range on two threads; then collapsed four children to a node (the largest opened first)
//! with the leaves' triangles in traversal order, a node's side by side.

use glam::Vec3;
use rayon::prelude::*;

use super::{Bvh, COUNT_SHIFT, DEEP, EMPTY, LEAF, LEAF_SIZE, Node4, SLOT, Tri, leaf_slots};

/// A node of the binary tree: an internal node's children are at `child` and `child + 1`; a
/// leaf holds `count` triangles, the build order's from `child` on.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node {
    min: Vec3,
    child: u32,
    max: Vec3,
    /// Triangles of a leaf; [`INTERNAL`] for an internal node.
    count: u32,
}

const INTERNAL: u32 = u32::MAX;

/// SAH bins per split.
const BINS: usize = 16;

/// Depth below which splits are by SAH; deeper ranges are split at their median, which bounds
/// the depth of any tree by this plus log2 of its size.
const SAH_DEPTH: u32 = 48;

/// Ranges of at least this many triangles build their two halves' trees on two threads.
const PARALLEL: usize = 4096;

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
        assert!(
            triangles.len() <= SLOT as usize,
            "a tree holds at most {SLOT} triangles"
        );
        let (binary, built) = binary_tree(triangles);
        bvh.nodes.reserve(triangles.len() / 8);
        bvh.order.reserve(triangles.len());
        let root = bvh.collapse(&binary, &built, 0);
        bvh.tris = bvh
            .order
            .par_iter()
            .map(|&i| triangles[i as usize])
            .collect();
        if root & LEAF != 0 {
            // a lone leaf: give it a node, so that every walk starts at node 0
            let mut node = Node4::VACANT;
            for axis in 0..3 {
                node.bounds[axis].x = binary[0].min[axis];
                node.bounds[axis + 3].x = binary[0].max[axis];
            }
            node.child[0] = root;
            bvh.nodes.push(node);
        }
        bvh.stack = 4 * bvh.levels(0);
        bvh
    }

    /// The child code of binary node `i`, building 4-wide nodes below it; `built` holds the
    /// binary leaves' triangles (input indices). Leaves take the next triangle slots, so
    /// triangles end up in traversal order.
    fn collapse(&mut self, binary: &[Node], built: &[u32], i: usize) -> u32 {
        let n = &binary[i];
        if n.count != INTERNAL {
            let slot = self.order.len() as u32;
            let first = n.child as usize;
            self.order
                .extend_from_slice(&built[first..first + n.count as usize]);
            return LEAF | (n.count - 1) << COUNT_SHIFT | slot;
        }
        // open the largest internal child (of equals, the first made) until there are four
        let mut lanes = [n.child as usize, n.child as usize + 1, 0, 0];
        let mut count = 2;
        while count < 4 {
            let kids = &mut lanes[..count];
            let area = |k: usize| {
                let e = binary[k].max - binary[k].min;
                e.x * e.y + e.y * e.z + e.z * e.x
            };
            let Some(open) = (0..kids.len())
                .filter(|&j| binary[kids[j]].count == INTERNAL)
                .max_by(|&a, &b| {
                    area(kids[a])
                        .total_cmp(&area(kids[b]))
                        .then(kids[b].cmp(&kids[a]))
                })
            else {
                break;
            };
            let c = binary[kids[open]].child as usize;
            kids[open] = c;
            lanes[count] = c + 1;
            count += 1;
        }
        let index = self.nodes.len();
        self.nodes.push(Node4::VACANT);
        let mut node = Node4::VACANT;
        for (lane, &k) in lanes[..count].iter().enumerate() {
            for axis in 0..3 {
                node.bounds[axis][lane] = binary[k].min[axis];
                node.bounds[axis + 3][lane] = binary[k].max[axis];
            }
        }
        // the leaves first, so that a node's triangles lie side by side
        for leaves in [true, false] {
            for (lane, &k) in lanes[..count].iter().enumerate() {
                if (binary[k].count != INTERNAL) == leaves {
                    node.child[lane] = self.collapse(binary, built, k);
                    if !leaves {
                        let c = node.child[lane];
                        node.leaves[lane] = self.leaf_lines(c);
                        // its first internal child, if any, was made right after it
                        let first = self.nodes[c as usize]
                            .child
                            .iter()
                            .find(|&&g| g & LEAF == 0);
                        if let Some(&first) = first {
                            debug_assert_eq!(first & !DEEP, c + 1);
                            node.child[lane] |= DEEP;
                        }
                    }
                }
            }
        }
        self.nodes[index] = node;
        index as u32
    }

    /// Where the triangles of node `i`'s leaves start and the cache lines they span, packed as
    /// [`Node4::leaves`] keeps them (none: 0).
    fn leaf_lines(&self, i: u32) -> u32 {
        let (mut first, mut end) = (u32::MAX, 0);
        for &code in &self.nodes[i as usize].child {
            if code & LEAF != 0 && code != EMPTY {
                let slots = leaf_slots(code);
                (first, end) = (first.min(slots.start), end.max(slots.end));
            }
        }
        if end == 0 {
            return 0;
        }
        let size = size_of::<Tri>();
        let lines = ((first as usize * size) % 64 + (end - first) as usize * size).div_ceil(64);
        first | (lines.min(7) as u32) << COUNT_SHIFT
    }

    /// Levels of the tree below and including node `i`.
    fn levels(&self, i: usize) -> usize {
        let inner = self.nodes[i].child.iter().filter(|&&c| c & LEAF == 0);
        1 + inner
            .map(|&c| self.levels((c & !DEEP) as usize))
            .max()
            .unwrap_or(0)
    }
}

/// A triangle's box and centroid, and its input index, as the binary build sorts them.
#[derive(Clone, Copy)]
struct Prim {
    min: Vec3,
    max: Vec3,
    centre: Vec3,
    index: u32,
}

/// The binary tree over `triangles`, its root at 0 and each node's children side by side, the
/// nodes in the order of a depth-first build whatever the threads (the descendants of a node
/// over k triangles take at most the 2k − 2 places from its two children on); and the input
/// indices of the triangles in the order the leaves hold them.
fn binary_tree(triangles: &[[Vec3; 3]]) -> (Vec<Node>, Vec<u32>) {
    let mut prims: Vec<Prim> = triangles
        .par_iter()
        .enumerate()
        .map(|(i, t)| {
            let (min, max) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
            Prim {
                min,
                max,
                centre: (min + max) * 0.5,
                index: i as u32,
            }
        })
        .collect();
    // the root first; the places after it that nodes take are each written once by `split`
    let root = leaf_or_box(&prims, 0);
    let mut nodes = vec![root; 2 * prims.len() - 1];
    if root.count == INTERNAL {
        nodes[0].child = 1;
        split(&mut nodes[1..], 1, &mut prims, 0, 0);
    }
    (nodes, prims.iter().map(|p| p.index).collect())
}

/// A leaf for at most [`LEAF_SIZE`] triangles, the build order's from `first` on, else an
/// internal node; either with the box of `prims`.
fn leaf_or_box(prims: &[Prim], first: u32) -> Node {
    let (min, max) = prims
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.min), hi.max(p.max))
        });
    let leaf = prims.len() <= LEAF_SIZE;
    Node {
        min,
        child: if leaf { first } else { 0 },
        max,
        count: if leaf { prims.len() as u32 } else { INTERNAL },
    }
}

/// Builds the descendants of a node holding `prims` (more than a leaf's), the build order's
/// from `first` on, at `depth` into `below` (2·len − 2 places, the first at index `base`): its
/// two children, then the left child's descendants, then the right's.
fn split(below: &mut [Node], base: u32, prims: &mut [Prim], first: u32, depth: u32) {
    let parallel = prims.len() >= PARALLEL;
    let mid = partition(prims, depth);
    let (left, right) = prims.split_at_mut(mid);
    let (pair, rest) = below.split_at_mut(2);
    let (left_below, right_below) = rest.split_at_mut(2 * left.len() - 2);
    let bases = [base + 2, base + 2 + left_below.len() as u32];
    let firsts = [first, first + mid as u32];
    let halves = [
        (left_below, bases[0], left, firsts[0]),
        (right_below, bases[1], right, firsts[1]),
    ];
    for (node, (_, base, prims, first)) in pair.iter_mut().zip(&halves) {
        *node = leaf_or_box(prims, *first);
        if node.count == INTERNAL {
            node.child = *base;
        }
    }
    let build = |(below, base, prims, first): (&mut [Node], u32, &mut [Prim], u32)| {
        if prims.len() > LEAF_SIZE {
            split(below, base, prims, first, depth + 1);
        }
    };
    if parallel {
        let [a, b] = halves;
        rayon::join(|| build(a), || build(b));
    } else {
        halves.into_iter().for_each(build);
    }
}

/// Reorders `prims` into two non-empty runs and returns where the second starts: the binned
/// SAH split along the centroids' longest extent, or the median along it where SAH cannot
/// split (all centroids in one bin, non-finite coordinates) or `depth` reached [`SAH_DEPTH`].
fn partition(prims: &mut [Prim], depth: u32) -> usize {
    let (lo, hi) = prims
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.centre), hi.max(p.centre))
        });
    let extent = hi - lo;
    let axis = (0..3)
        .max_by(|&a, &b| extent[a].total_cmp(&extent[b]))
        .expect("three axes");
    let median = |prims: &mut [Prim]| {
        let mid = prims.len() / 2;
        prims.select_nth_unstable_by(mid, |a, b| a.centre[axis].total_cmp(&b.centre[axis]));
        mid
    };
    let scale = BINS as f32 / extent[axis];
    if depth >= SAH_DEPTH || !(scale.is_finite() && scale > 0.0) {
        return median(prims);
    }
    let bin = |p: &Prim| (((p.centre[axis] - lo[axis]) * scale) as usize).min(BINS - 1);
    let mut boxes = [(Vec3::INFINITY, Vec3::NEG_INFINITY, 0u32); BINS];
    for p in prims.iter() {
        let b = &mut boxes[bin(p)];
        *b = (b.0.min(p.min), b.1.max(p.max), b.2 + 1);
    }
    let area = |(min, max): (Vec3, Vec3)| {
        let e = (max - min).max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    };
    // the cost of the boxes right of each plane, then the best plane sweeping from the left
    let mut right = [0.0f32; BINS];
    let mut acc = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0u32);
    for b in (1..BINS).rev() {
        acc = (
            acc.0.min(boxes[b].0),
            acc.1.max(boxes[b].1),
            acc.2 + boxes[b].2,
        );
        right[b] = area((acc.0, acc.1)) * acc.2 as f32;
    }
    let mut left = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0u32);
    let mut best: Option<(f32, usize)> = None;
    for b in 1..BINS {
        let k = &boxes[b - 1];
        left = (left.0.min(k.0), left.1.max(k.1), left.2 + k.2);
        let on_right = prims.len() as u32 - left.2;
        if left.2 == 0 || on_right == 0 {
            continue;
        }
        let cost = area((left.0, left.1)) * left.2 as f32 + right[b];
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, b));
        }
    }
    let Some((_, plane)) = best else {
        return median(prims);
    };
    // in place: those left of the plane first
    let mut mid = 0;
    for i in 0..prims.len() {
        if bin(&prims[i]) < plane {
            prims.swap(i, mid);
            mid += 1;
        }
    }
    mid
}
