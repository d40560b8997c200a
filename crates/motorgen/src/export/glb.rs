//! glTF 2.0 binary (.glb): one named node and mesh per part, the add-on's materials.

use std::collections::BTreeMap;
use std::io::{Result, Write};

use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

use crate::model::{MATERIALS, Part};

/// Writes parts as a GLB scene with a node named after each part.
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) when writing to `w` fails.
pub fn write_glb(w: &mut dyn Write, parts: &[&Part]) -> Result<()> {
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some("motorfactory".into()),
            ..Default::default()
        },
        ..Default::default()
    };
    let mut bin: Vec<u8> = Vec::new();
    let buffer = root.push(json::Buffer {
        byte_length: USize64(0),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    // the materials the parts use, in table order
    let used: Vec<_> = MATERIALS
        .iter()
        .filter(|m| parts.iter().any(|p| p.kind.material().name == m.name))
        .collect();
    let materials: Vec<_> = used
        .iter()
        .map(|m| {
            root.push(json::Material {
                name: Some(m.name.into()),
                pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                    base_color_factor: json::material::PbrBaseColorFactor(m.base_color),
                    metallic_factor: json::material::StrengthFactor(m.metallic),
                    roughness_factor: json::material::StrengthFactor(m.roughness),
                    ..Default::default()
                },
                ..Default::default()
            })
        })
        .collect();
    let mut nodes = Vec::new();
    for p in parts {
        let bounds = p.mesh.bounds();
        let positions = view(
            &mut root,
            &mut bin,
            buffer,
            bytes_of(p.mesh.positions.iter().flat_map(|v| v.to_array())),
            json::buffer::Target::ArrayBuffer,
        );
        let indices = view(
            &mut root,
            &mut bin,
            buffer,
            bytes_of(
                p.mesh
                    .triangles
                    .iter()
                    .flatten()
                    .copied()
                    .map(f32::from_bits),
            ),
            json::buffer::Target::ElementArrayBuffer,
        );
        let accessor = |root: &mut json::Root,
                        view,
                        count: usize,
                        kind,
                        component,
                        minmax: Option<[[f32; 3]; 2]>| {
            root.push(json::Accessor {
                buffer_view: Some(view),
                byte_offset: None,
                count: USize64::from(count),
                component_type: Valid(json::accessor::GenericComponentType(component)),
                extensions: None,
                extras: Default::default(),
                type_: Valid(kind),
                min: minmax.map(|m| json::Value::from(m[0].to_vec())),
                max: minmax.map(|m| json::Value::from(m[1].to_vec())),
                name: None,
                normalized: false,
                sparse: None,
            })
        };
        let pos = accessor(
            &mut root,
            positions,
            p.mesh.positions.len(),
            json::accessor::Type::Vec3,
            json::accessor::ComponentType::F32,
            Some([bounds.min.to_array(), bounds.max.to_array()]),
        );
        let idx = accessor(
            &mut root,
            indices,
            p.mesh.triangles.len() * 3,
            json::accessor::Type::Scalar,
            json::accessor::ComponentType::U32,
            None,
        );
        let material = used
            .iter()
            .position(|m| m.name == p.kind.material().name)
            .map(|i| materials[i]);
        let mesh = root.push(json::Mesh {
            name: Some(p.name.clone()),
            primitives: vec![json::mesh::Primitive {
                attributes: BTreeMap::from([(Valid(json::mesh::Semantic::Positions), pos)]),
                extensions: None,
                extras: Default::default(),
                indices: Some(idx),
                material,
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            extensions: None,
            extras: Default::default(),
            weights: None,
        });
        nodes.push(root.push(json::Node {
            mesh: Some(mesh),
            name: Some(p.name.clone()),
            ..Default::default()
        }));
    }
    root.buffers[buffer.value()].byte_length = USize64::from(bin.len());
    // glTF is Y-up: a root node turns the motor's Z-up frame by −90° about x, so that importers
    // (Blender's among them) stand it upright
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let upright = root.push(json::Node {
        children: Some(nodes),
        name: Some("motor".into()),
        rotation: Some(json::scene::UnitQuaternion([-h, 0.0, 0.0, h])),
        ..Default::default()
    });
    let scene = root.push(json::Scene {
        nodes: vec![upright],
        name: None,
        extensions: None,
        extras: Default::default(),
    });
    root.scene = Some(scene);

    let mut text = root.to_vec().map_err(std::io::Error::other)?;
    text.resize(text.len().next_multiple_of(4), b' ');
    let total = 12 + 8 + text.len() + 8 + bin.len();
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&(total as u32).to_le_bytes())?;
    w.write_all(&(text.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&text)?;
    w.write_all(&(bin.len() as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(&bin)
}

/// Little-endian bytes of 4-byte values.
fn bytes_of(values: impl Iterator<Item = f32>) -> Vec<u8> {
    values.flat_map(f32::to_le_bytes).collect()
}

/// Appends `data` to the binary chunk (4-byte aligned) and adds a buffer view of it.
fn view(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    buffer: json::Index<json::Buffer>,
    data: Vec<u8>,
    target: json::buffer::Target,
) -> json::Index<json::buffer::View> {
    let offset = bin.len();
    bin.extend_from_slice(&data);
    bin.resize(bin.len().next_multiple_of(4), 0);
    root.push(json::buffer::View {
        buffer,
        byte_length: USize64::from(data.len()),
        byte_offset: Some(USize64::from(offset)),
        byte_stride: None,
        name: None,
        target: Some(Valid(target)),
        extensions: None,
        extras: Default::default(),
    })
}
