//! A library of named materials, for scanned meshes and the work cell.

use crate::Error;
use crate::world::Material;

/// A material of the depth model's `reflectivity`, `specular` share and `lobe`, and the colour
/// renderer's base `colour`, `metallic` and `roughness` (specular level 0.5).
pub(crate) const fn mat(
    reflectivity: f32,
    specular: f32,
    lobe: f32,
    colour: [f32; 3],
    metallic: f32,
    roughness: f32,
) -> Material {
    Material {
        reflectivity,
        specular,
        lobe,
        colour,
        metallic,
        roughness,
        ior_level: 0.5,
    }
}

/// Glass-filled black polyamide of motor housings: dark, a broad faint sheen.
pub const BLACK_PA66: Material = mat(0.12, 0.15, 0.3, [0.12; 3], 0.0, 0.45);
/// White or natural plastic (gears, plates).
pub const WHITE_PLASTIC: Material = mat(0.8, 0.05, 0.3, [0.8, 0.8, 0.78], 0.0, 0.5);
/// Light grey plastic (connectors).
pub const GREY_PLASTIC: Material = mat(0.6, 0.0, 0.2, [0.6; 3], 0.0, 0.6);
/// Bright zinc plating of screws: a narrow, strong highlight.
pub const ZINC_PLATED_STEEL: Material = mat(0.7, 0.8, 0.1, [0.7, 0.7, 0.72], 1.0, 0.2);
/// Drawn or polished stainless steel (pole pots).
pub const STAINLESS_STEEL: Material = mat(0.45, 0.6, 0.1, [0.45, 0.45, 0.47], 1.0, 0.25);
/// Bare, brushed aluminium.
pub const ALUMINIUM: Material = mat(0.6, 0.4, 0.15, [0.6, 0.6, 0.62], 1.0, 0.3);
/// Blue anodised aluminium (fixture jaws).
pub const ANODISED_ALUMINIUM: Material = mat(0.3, 0.1, 0.25, [0.06, 0.16, 0.45], 0.0, 0.4);
/// Electrical steel of an armature's lamination stack: grey, a dull sheen.
pub const ELECTRICAL_STEEL: Material = mat(0.35, 0.3, 0.25, [0.36, 0.36, 0.38], 1.0, 0.4);
/// Enamelled copper windings.
pub const COPPER: Material = mat(0.5, 0.5, 0.2, [0.66, 0.42, 0.26], 1.0, 0.3);
/// Rusted steel: dark brown and matte.
pub const RUST: Material = mat(0.15, 0.02, 0.5, [0.25, 0.11, 0.06], 0.0, 0.9);
/// Sintered ferrite magnets.
pub const FERRITE: Material = mat(0.1, 0.0, 0.2, [0.1; 3], 0.0, 0.8);
/// A light grey laminate table top.
pub const LAMINATE: Material = mat(0.55, 0.0, 0.2, [0.55; 3], 0.0, 0.6);
/// Matte grey paint.
pub const MATTE_GREY: Material = mat(0.5, 0.0, 0.2, [0.5; 3], 0.0, 0.8);

/// A front-surface mirror: almost all light reflected specularly in a narrow lobe (a LiDAR's
/// beam bounces off it, see `sensor::lidar`).
pub const MIRROR: Material = mat(0.04, 0.95, 0.02, [0.9; 3], 1.0, 0.02);

/// The named materials: the library `scan --mesh FILE@NAME` and [`Material::named`] draw on.
pub const MATERIALS: [(&str, Material); 14] = [
    ("black-pa66", BLACK_PA66),
    ("white-plastic", WHITE_PLASTIC),
    ("grey-plastic", GREY_PLASTIC),
    ("zinc-plated-steel", ZINC_PLATED_STEEL),
    ("stainless-steel", STAINLESS_STEEL),
    ("aluminium", ALUMINIUM),
    ("anodised-aluminium", ANODISED_ALUMINIUM),
    ("copper", COPPER),
    ("electrical-steel", ELECTRICAL_STEEL),
    ("rust", RUST),
    ("ferrite", FERRITE),
    ("laminate", LAMINATE),
    ("matte-grey", MATTE_GREY),
    ("mirror", MIRROR),
];

impl Material {
    /// The library's material `name` (see [`MATERIALS`]).
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a name not in the library, listing those that are.
    ///
    /// # Example
    ///
    /// ```
    /// let steel = sensor::Material::named("stainless-steel")?;
    /// assert!(steel.specular > 0.5);
    /// assert!(sensor::Material::named("unobtainium").is_err());
    /// # Ok::<(), sensor::Error>(())
    /// ```
    pub fn named(name: &str) -> Result<Material, Error> {
        MATERIALS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, m)| m)
            .ok_or_else(|| Error::Invalid {
                key: "material".into(),
                value: format!("\"{name}\""),
                allowed: format!("one of {}", MATERIALS.map(|(n, _)| n).join(", ")),
            })
    }
}
