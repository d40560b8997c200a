//! What a sensor scans: labelled triangle meshes with materials, in one BVH.

use std::ops::Range;

use glam::{Affine3A, Vec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::bvh::{Bvh, Hit, prefetch_lines};
use crate::camera::Intrinsics;
use crate::epipolar::Epipolar;
use crate::noise::Lobe;
use crate::wear::Wear;

/// How a surface returns light, as the noise models read it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Material {
    /// Diffuse reflectance 0..1 (signal strength; dark surfaces drop out first).
    pub reflectivity: f32,
    /// Share of specular, mirror-like reflection 0..1 (polished metal: bolt heads, pole pot).
    pub specular: f32,
    /// Width of the specular lobe, radians, 0 to π (small = mirror).
    pub lobe: f32,
    /// Diffuse colour: linear red, green and blue albedo 0..1, what the camera's colour image
    /// sees (the signal reads `reflectivity`, at the projector's light), and the base colour
    /// of the colour renderer's surface model.
    pub colour: [f32; 3],
    /// Metalness 0..1 of the colour renderer's surface model (Blender's Principled BSDF):
    /// 1 reflects only specularly, tinted by `colour`.
    pub metallic: f32,
    /// Microfacet roughness 0..1 of the specular reflection (α = roughness²).
    pub roughness: f32,
    /// Strength of a non-metal's specular reflection 0..1, Blender's "Specular IOR Level":
    /// 0.5 reflects 4 % at normal incidence (index 1.5), 1 twice that.
    pub ior_level: f32,
}

impl Default for Material {
    fn default() -> Material {
        Material {
            reflectivity: 0.6,
            specular: 0.0,
            lobe: 0.2,
            colour: [0.6; 3],
            metallic: 0.0,
            roughness: 0.5,
            ior_level: 0.5,
        }
    }
}

/// A triangle mesh with its labels.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    /// Vertex positions in world coordinates, metres.
    pub positions: Vec<Vec3>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Semantic class of every triangle, or one class for the whole mesh.
    pub classes: Classes,
    /// Instance id.
    pub instance: u32,
    /// Surface material.
    pub material: Material,
    /// Corrosion on the surface, if any.
    pub wear: Option<Wear>,
}

impl Target {
    /// A target of separate triangles (a soup, as STL stores them), all of one class.
    pub fn from_triangles(
        triangles: &[[Vec3; 3]],
        class: u16,
        instance: u32,
        material: Material,
    ) -> Target {
        Target {
            positions: triangles.iter().flatten().copied().collect(),
            triangles: (0..triangles.len() as u32)
                .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect(),
            classes: Classes::Uniform(class),
            instance,
            material,
            wear: None,
        }
    }
}

/// The semantic class of a target's triangles.
#[derive(Clone, Debug, PartialEq)]
pub enum Classes {
    /// All triangles one class.
    Uniform(u16),
    /// One class per triangle.
    PerTriangle(Vec<u16>),
}

/// Per-triangle data the sensor needs after a hit, beside its corners (the tree's).
#[derive(Clone, Copy, Debug)]
struct TriInfo {
    class: u16,
    target: u32,
}

/// The scanned world: one BVH over every target's triangles.
#[derive(Clone, Debug)]
pub struct World {
    bvh: Bvh,
    /// What a hit carries, per triangle by slot (the tree's leaf order: nearby hits read
    /// nearby entries).
    by_slot: Vec<TriInfo>,
    /// Per target, what its hits carry.
    surfaces: Vec<Surface>,
}

/// A target's instance and material, with the material's specular lobe worked out once.
#[derive(Clone, Copy, Debug)]
struct Surface {
    instance: u32,
    material: Material,
    lobe: Lobe,
    wear: Option<Wear>,
}

/// A ray's hit with everything the sensor models need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Distance along the ray.
    pub t: f32,
    /// Triangle in the world (targets' triangles in order).
    pub triangle: u32,
    /// Unit geometric normal, facing the ray's origin.
    pub normal: Vec3,
    /// Semantic class.
    pub class: u16,
    /// Instance id.
    pub instance: u32,
    /// Surface material.
    pub material: Material,
    /// The material's specular lobe.
    pub lobe: Lobe,
    /// Share of rust at the hit, 0..1 (the material is the surface's worn by it).
    pub wear: f32,
}

impl World {
    /// Builds the world. Triangles with repeated vertices or zero area cannot be hit and are
    /// kept only for numbering.
    pub fn new(targets: &[Target]) -> World {
        let (corners, tris): (Vec<[Vec3; 3]>, Vec<TriInfo>) = targets
            .par_iter()
            .enumerate()
            .flat_map(|(k, t)| {
                t.triangles.par_iter().enumerate().map(move |(i, tri)| {
                    let c = tri.map(|v| t.positions[v as usize]);
                    let class = match &t.classes {
                        Classes::Uniform(c) => *c,
                        Classes::PerTriangle(v) => v[i],
                    };
                    let info = TriInfo {
                        class,
                        target: k as u32,
                    };
                    (c, info)
                })
            })
            .unzip();
        let bvh = Bvh::build(&corners);
        let by_slot = (0..tris.len() as u32)
            .into_par_iter()
            .map(|slot| tris[bvh.triangle(slot) as usize])
            .collect();
        World {
            bvh,
            by_slot,
            surfaces: targets
                .iter()
                .map(|t| Surface {
                    instance: t.instance,
                    material: t.material,
                    lobe: Lobe::of(&t.material),
                    wear: t.wear,
                })
                .collect(),
        }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.by_slot.len()
    }

    /// The closest surface along a unit ray within `t_max`.
    #[inline]
    pub fn cast(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<SurfaceHit> {
        self.bvh
            .cast(origin, dir, t_max)
            .map(|h| self.describe_slot(h.slot, h.t, origin, dir))
    }

    /// What a ray from `origin` in direction `dir` finds at `hit` (a hit of [`World::bvh`]'s
    /// casts): the surface's normal facing the ray, its class, instance and material.
    #[inline]
    pub fn surface(&self, hit: &Hit, origin: Vec3, dir: Vec3) -> SurfaceHit {
        self.describe_slot(hit.slot, hit.t, origin, dir)
    }

    /// The closest hits of a packet of rays ([`Bvh::cast_packet`]), what [`World::surface`]
    /// reads of each hit's triangle asked into the cache as the walk takes the hit.
    pub fn cast_packet<const G: usize>(
        &self,
        origins: &[[Vec3; 4]; G],
        dirs: &[[Vec3; 4]; G],
        t_max: &[[f32; 4]; G],
    ) -> [[Option<Hit>; 4]; G] {
        self.bvh.cast_packet_noting(origins, dirs, t_max, |slot| {
            prefetch_lines(self.by_slot.as_ptr().wrapping_add(slot as usize), 1);
        })
    }

    /// The BVH over every target's triangles, for packets of occlusion tests
    /// ([`Bvh::occluded_packet`]) and casts whose hits are not described ([`World::cast_packet`]
    /// for those that are).
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Whether any surface lies on the unit ray within `t_max`.
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        self.bvh.occluded(origin, dir, t_max)
    }

    /// The world prepared to be cut in the epipolar planes of a pinhole camera's rows `rows`
    /// (see [`crate::epipolar`]), for surfaces no deeper than `max_depth` and a projector at
    /// `baseline` m along camera +x.
    pub(crate) fn epipolar(
        &self,
        k: &Intrinsics,
        pose: &Affine3A,
        baseline: f32,
        rows: Range<usize>,
        max_depth: f32,
    ) -> Epipolar {
        Epipolar::new(self.bvh.slots(), pose, k, baseline, rows, max_depth)
    }

    /// The hit at distance `t` along unit ray `dir` from `origin` on the triangle in BVH slot
    /// `slot`.
    pub(crate) fn describe_slot(&self, slot: u32, t: f32, origin: Vec3, dir: Vec3) -> SurfaceHit {
        let info = self.by_slot[slot as usize];
        let triangle = self.bvh.triangle(slot);
        let surface = &self.surfaces[info.target as usize];
        // from the corners the hit has just brought into the cache
        let c = &self.bvh.slots()[slot as usize];
        let normal = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
        let normal = if normal.dot(dir) > 0.0 {
            -normal
        } else {
            normal
        };
        let mut hit = SurfaceHit {
            t,
            triangle,
            normal,
            class: info.class,
            instance: surface.instance,
            material: surface.material,
            lobe: surface.lobe,
            wear: 0.0,
        };
        if let Some(wear) = &surface.wear
            && let Some((share, material)) = wear.at(&surface.material, origin + t * dir)
        {
            hit.wear = share;
            hit.material = material;
            hit.lobe = Lobe::of(&material);
        }
        hit
    }
}
