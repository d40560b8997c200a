//! A BOP scene's annotated objects: each instance with a class, its model (its mesh in its own
//! frame, millimetres, about its box's centre) and the model's pose in the world.

use std::io::{Result, Write};

use glam::{Affine3A, Vec3};
use motorgen::Scheme;
use motorgen::kernel::Mesh;

use crate::cell::Object;

/// Metres to the millimetres of BOP's models and translations.
pub const MM: f32 = 1000.0;

/// An annotated object of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// Its instance id under the scheme (the instance image's value).
    pub instance: u32,
    /// BOP's `obj_id`: its class under the scheme (1-based; the background has none).
    pub obj_id: u8,
    /// The model's origin in its first piece's model frame ([`Object::pose`]), metres.
    pub centre: Vec3,
    /// The model, mm, its box centred on the origin.
    pub mesh: Mesh,
}

impl Model {
    /// Its model frame (in metres) to the world of `objects` (its cell, or the same pieces
    /// placed otherwise: the cell reclamped) under `scheme`.
    pub fn to_world(&self, objects: &[Object], scheme: Scheme) -> Affine3A {
        let first = pieces(objects, scheme, self.instance)
            .next()
            .expect("a model's cell holds its pieces");
        first.pose * Affine3A::from_translation(self.centre)
    }
}

/// The pieces of annotated instance `instance` in `objects`, in order.
fn pieces(objects: &[Object], scheme: Scheme, instance: u32) -> impl Iterator<Item = &Object> {
    (objects.iter()).filter(move |o| o.class(scheme) != 0 && o.instance_in(scheme) == instance)
}

/// The annotated objects of `objects` under `scheme`, by instance id: each instance whose
/// class is not the background, its pieces (an assembled motor's parts) one model in the
/// frame of its first piece's pose, moved to its box's centre.
pub fn models(objects: &[Object], scheme: Scheme) -> Vec<Model> {
    let mut instances: Vec<(u32, u8)> = objects
        .iter()
        .filter(|o| o.class(scheme) != 0)
        .map(|o| (o.instance_in(scheme), o.class(scheme)))
        .collect();
    instances.sort_unstable();
    instances.dedup_by_key(|(i, _)| *i);
    instances
        .into_iter()
        .map(|(instance, obj_id)| {
            let mut pieces = pieces(objects, scheme, instance);
            let first = pieces.next().expect("an instance has a piece");
            let from_world = first.pose.inverse();
            let mut mesh = first.mesh.clone().transformed(&from_world);
            for o in pieces {
                mesh.append(&o.mesh.clone().transformed(&from_world));
            }
            let centre = mesh.bounds().centre();
            let to_model =
                Affine3A::from_scale(Vec3::splat(MM)) * Affine3A::from_translation(-centre);
            Model {
                instance,
                obj_id,
                centre,
                mesh: mesh.transformed(&to_model),
            }
        })
        .collect()
}

/// Writes `model` as binary little-endian PLY: vertices `x y z` and their normals `nx ny nz`
/// (area-weighted sums of their faces'), faces `vertex_indices`; millimetres.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_ply(w: &mut dyn Write, model: &Model) -> Result<()> {
    let Mesh {
        positions,
        triangles,
    } = &model.mesh;
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for i in t {
            normals[*i as usize] += n;
        }
    }
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment motorfactory BOP model, mm\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        positions.len(),
        triangles.len()
    )?;
    let mut buf = Vec::with_capacity(positions.len() * 24 + triangles.len() * 13);
    for (p, n) in positions.iter().zip(&normals) {
        for x in p
            .to_array()
            .into_iter()
            .chain(n.normalize_or_zero().to_array())
        {
            buf.extend_from_slice(&x.to_le_bytes());
        }
    }
    for t in triangles {
        buf.push(3);
        for i in t {
            buf.extend_from_slice(&(*i as i32).to_le_bytes());
        }
    }
    w.write_all(&buf)
}

/// Directions over the sphere whose extreme vertices are the candidates for a model's diameter.
const DIAMETER_DIRECTIONS: usize = 512;

/// The model's diameter, mm: the largest distance between two of its vertices, searched among
/// the vertices extreme along 512 directions of a Fibonacci sphere (the
/// diameter's two ends are extreme along it; along a direction θ from it, two vertices at
/// least cos θ of it apart are: short by under 0.3 % for these, about 9° apart).
pub fn diameter(mesh: &Mesh) -> f32 {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let mut extreme: Vec<Vec3> = (0..DIAMETER_DIRECTIONS)
        .filter_map(|k| {
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / DIAMETER_DIRECTIONS as f32;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (golden * k as f32).sin_cos();
            let d = Vec3::new(r * c, r * s, z);
            mesh.positions
                .iter()
                .copied()
                .max_by(|a, b| a.dot(d).total_cmp(&b.dot(d)))
        })
        .collect();
    extreme.sort_unstable_by(|a, b| a.to_array().partial_cmp(&b.to_array()).expect("finite"));
    extreme.dedup();
    let mut best = 0.0f32;
    for (i, a) in extreme.iter().enumerate() {
        for b in &extreme[i + 1..] {
            best = best.max(a.distance(*b));
        }
    }
    best
}

/// BOP's `models_info` entry of `model`: its diameter and box, mm.
pub fn info(model: &Model) -> serde_json::Value {
    let b = model.mesh.bounds();
    let size = b.size();
    serde_json::json!({
        "diameter": diameter(&model.mesh),
        "min_x": b.min.x,
        "min_y": b.min.y,
        "min_z": b.min.z,
        "size_x": size.x,
        "size_y": size.y,
        "size_z": size.z,
    })
}
