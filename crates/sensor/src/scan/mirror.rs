//! Interreflection: the light a shiny surface mirrors into a pixel from the surface it faces
//! (see [`Interreflection`](crate::noise::Interreflection)).

use std::f32::consts::PI;

use glam::{Vec3, Vec3A};

use super::cast::{Capture, gap};
use super::decode::{Light, MIDDLE, Stripes};
use super::light::LitPixel;

/// The light that pixel `lit`, on a shiny surface of normal `normal` (camera frame), receives
/// along its ray's mirror direction: the first surface there, where the projector lights it,
/// its diffuse signal × the specular share, its stripes blurred by the lobe; `None` where the
/// mirror shows nothing the projector lights.
pub(super) fn mirrored(
    setup: &Capture,
    stripes: &Stripes,
    lit: &LitPixel,
    normal: Vec3,
) -> Option<Light> {
    let (frustum, projector) = setup.projector?;
    let (pose, world, sensor) = (&setup.pose, setup.world, setup.sensor);
    let p = lit.centre * lit.t;
    let mirror = lit.centre - 2.0 * lit.centre.dot(normal) * normal;
    // from just off the surface, so that it does not meet itself
    let from = p + gap(lit.t) * normal;
    let hit = world.cast(
        pose.transform_point3(from),
        pose.transform_vector3(mirror),
        f32::INFINITY,
    )?;
    let q = from + hit.t * mirror;
    if !frustum.lights(q) {
        return None;
    }
    let to_light = projector - q;
    let distance = to_light.length();
    let l = to_light / distance;
    let cos_light = Vec3::from(setup.to_camera * Vec3A::from(hit.normal)).dot(l);
    if cos_light <= 0.0 {
        return None; // it faces away from the projector
    }
    let lamp = pose.transform_point3(projector);
    let length = distance - gap(distance);
    if world.occluded(lamp, pose.transform_vector3(-l), length) {
        return None; // in a shadow
    }
    let light = cos_light * (sensor.reference_range / distance).powi(2);
    let signal = lit.specular * hit.material.reflectivity * light;
    // the lobe spreads the mirror's image over σ 2·lobe radians: 2·lobe·t across at the
    // surface, in projector columns over its distance from the projector
    let spread = 2.0 * lit.lobe * hit.t / distance;
    let blur = |period: f32| (-2.0 * (PI * spread / period).powi(2)).exp();
    let contrast = [
        stripes.smooth * blur(stripes.period),
        blur(MIDDLE * stripes.period),
        blur(2.0 * frustum.half_width()),
    ];
    let column = frustum.column(q);
    Some(Light::new(
        signal,
        0.0,
        column,
        contrast,
        stripes,
        &sensor.noise.snr,
    ))
}
