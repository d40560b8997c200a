//! Building the 4-wide tree: parry's binned (small meshes) or PLOC (large ones) binary tree,
//! flattened, then collapsed four children to a node with the leaves in traversal order.

use glam::Vec3;
use parry3d::bounding_volume::Aabb;
use parry3d::partitioning::{Bvh as ParryBvh, BvhBuildStrategy, TraversalAction};

use super::{Bvh, LEAF, Node4};

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

/// Triangles at or above this count are built with PLOC (better trees, slower build); smaller
/// meshes with binned SAH.
const PLOC_FROM: usize = 50_000;

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
