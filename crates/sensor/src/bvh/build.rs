//! Building the 4-wide tree: a binary tree by binned surface-area heuristic (SAH) splits of
//! the triangles' centroids, falling back to median splits where SAH cannot split or the tree
//! grows deep (equal centroids, coincident or degenerate triangles), so that any input builds in
//! O(n log n), the two halves of a large range on two threads; then collapsed four children to
//! a node with the leaves in traversal order.

use glam::Vec3;
use rayon::prelude::*;

use super::{Bvh, LEAF, Node4};

/// A node of the binary tree: an internal node's children are at `child` and `child + 1`; a
/// leaf holds one triangle, `prim` (an input triangle index).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Node {
    min: Vec3,
    child: u32,
    max: Vec3,
    prim: u32,
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
        let binary = binary_tree(triangles);
        bvh.nodes.reserve(triangles.len() / 2);
        bvh.order.reserve(triangles.len());
        let root = bvh.collapse(&binary, 0);
        bvh.tris = bvh
            .order
            .par_iter()
            .map(|&i| triangles[i as usize])
            .collect();
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
        bvh.stack = 4 * bvh.levels(0);
        bvh
    }

    /// The child code of binary node `i`, building 4-wide nodes below it. Leaves take the next
    /// triangle slots, so triangles end up in traversal order.
    fn collapse(&mut self, binary: &[Node], i: usize) -> u32 {
        let n = &binary[i];
        if n.prim != INTERNAL {
            self.order.push(n.prim);
            return LEAF | (self.order.len() as u32 - 1);
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
                .filter(|&j| binary[kids[j]].prim == INTERNAL)
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
            node.child[lane] = self.collapse(binary, k);
        }
        self.nodes[index] = node;
        index as u32
    }

    /// Levels of the tree below and including node `i`.
    fn levels(&self, i: usize) -> usize {
        let inner = self.nodes[i].child.iter().filter(|&&c| c & LEAF == 0);
        1 + inner.map(|&c| self.levels(c as usize)).max().unwrap_or(0)
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
/// over k triangles take the 2k − 2 places from its two children on).
fn binary_tree(triangles: &[[Vec3; 3]]) -> Vec<Node> {
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
    // the root first; the places after it are each written once by `split`
    let root = leaf_or_box(&prims);
    let mut nodes = vec![root; 2 * prims.len() - 1];
    if prims.len() > 1 {
        nodes[0].child = 1;
        split(&mut nodes[1..], 1, &mut prims, 0);
    }
    nodes
}

/// A leaf for a lone triangle, else an internal node with the box of `prims`.
fn leaf_or_box(prims: &[Prim]) -> Node {
    let (min, max) = prims
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.min), hi.max(p.max))
        });
    Node {
        min,
        child: 0,
        max,
        prim: if prims.len() == 1 {
            prims[0].index
        } else {
            INTERNAL
        },
    }
}

/// Builds the descendants of a node holding `prims` (two or more) at `depth` into `below`
/// (2·len − 2 places, the first at index `base`): its two children, then the left child's
/// descendants, then the right's.
fn split(below: &mut [Node], base: u32, prims: &mut [Prim], depth: u32) {
    let parallel = prims.len() >= PARALLEL;
    let mid = partition(prims, depth);
    let (left, right) = prims.split_at_mut(mid);
    let (pair, rest) = below.split_at_mut(2);
    let (left_below, right_below) = rest.split_at_mut(2 * left.len() - 2);
    let bases = [base + 2, base + 2 + left_below.len() as u32];
    let halves = [(left_below, bases[0], left), (right_below, bases[1], right)];
    for (node, (_, base, prims)) in pair.iter_mut().zip(&halves) {
        *node = leaf_or_box(prims);
        if prims.len() > 1 {
            node.child = *base;
        }
    }
    let build = |(below, base, prims): (&mut [Node], u32, &mut [Prim])| {
        if prims.len() > 1 {
            split(below, base, prims, depth + 1);
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
