//! Interreflection: the light a shiny surface mirrors into a pixel from the surface it faces
//! (see [`Interreflection`](crate::noise::Interreflection)).

use std::f32::consts::PI;

use glam::{Vec3, Vec3A};

use super::Pixel;
use super::cast::{Capture, gap};
use super::decode::{Light, MIDDLE, Stripes};
use super::light::LitPixel;
use crate::bvh::Hit;
use crate::world::SurfaceHit;

/// What a shiny pixel's mirror ray meets: the surface point (camera frame) and its hit.
#[derive(Clone, Copy)]
pub(super) struct Mirrored {
    q: Vec3,
    hit: SurfaceHit,
}

/// For each pixel of a row (`lits` and their pixels `line`), what its mirror ray meets: none
/// where it has no mirror ray (a dark or matte pixel, a sensor without interreflection) or the
/// ray meets nothing. The rays of neighbouring pixels on one smooth surface run side by side
/// from nearby points, and are cast together: runs of up to four consecutive shiny pixels whose
/// rays stay within [`COHERENT`] of the run's first, as one packet.
pub(super) fn cast_mirrors(
    setup: &Capture,
    lits: &[Option<LitPixel>],
    line: &[Pixel],
    out: &mut Vec<Option<Mirrored>>,
) {
    out.clear();
    out.resize(lits.len(), None);
    if setup.projector.is_none() || !setup.sensor.noise.interreflection.enabled {
        return;
    }
    let shiny = lits
        .iter()
        .zip(line)
        .enumerate()
        .filter_map(|(i, (lit, px))| {
            let lit = lit.as_ref().filter(|lit| lit.specular > 0.0)?;
            let (from, dir) = mirror_ray(lit, px.normal);
            Some((i, from, dir))
        });
    let mut run = [(0, Vec3::ZERO, Vec3::ZERO); 4];
    let mut held = 0;
    for ray in shiny {
        let (_, from, dir) = run[0];
        let (_, o, d) = ray;
        if held == run.len()
            || held > 0 && (d.dot(dir) < COHERENT.0 || o.distance_squared(from) > COHERENT.1)
        {
            cast_run(setup, &run[..held], out);
            held = 0;
        }
        run[held] = ray;
        held += 1;
    }
    if held > 0 {
        cast_run(setup, &run[..held], out);
    }
}

/// Mirror rays of one packet: the cosine of the largest angle between a ray and the packet's
/// first (3°), and the largest squared distance between their origins, m² (1 cm). At the
/// inspection station a packet takes 3.8 rays on average for the work of 2.2 single walks;
/// wider packets (four groups of four) and looser bounds cost more than they save, the mirror
/// rays of curved surfaces fanning out.
const COHERENT: (f32, f32) = (0.998_63, 1e-4);

/// Casts a run of mirror rays (pixel index, camera-frame origin and direction), into `out`:
/// one ray alone, more as a packet.
fn cast_run(setup: &Capture, run: &[(usize, Vec3, Vec3)], out: &mut [Option<Mirrored>]) {
    let (pose, world) = (&setup.pose, setup.world);
    let seen = |hit: &Hit, from: Vec3, dir: Vec3, world_dir: Vec3| Mirrored {
        q: from + hit.t * dir,
        hit: world.surface(hit, world_dir),
    };
    if let [(i, from, dir)] = *run {
        let world_dir = pose.transform_vector3(dir);
        let hit = world
            .bvh()
            .cast(pose.transform_point3(from), world_dir, f32::INFINITY);
        out[i] = hit.map(|hit| seen(&hit, from, dir, world_dir));
        return;
    }
    let (mut origins, mut dirs, mut t_max) = ([Vec3::ZERO; 4], [Vec3::Z; 4], [0.0; 4]);
    for (k, &(_, from, dir)) in run.iter().enumerate() {
        origins[k] = pose.transform_point3(from);
        dirs[k] = pose.transform_vector3(dir);
        t_max[k] = f32::INFINITY;
    }
    let [hits] = world.bvh().cast_packet(&[origins], &[dirs], &[t_max]);
    for (k, &(i, from, dir)) in run.iter().enumerate() {
        out[i] = hits[k].map(|hit| seen(&hit, from, dir, dirs[k]));
    }
}

/// The mirror ray (camera frame) of the pixel `lit` on a surface of normal `normal`: from just
/// off the surface, so that it does not meet itself, along its centre ray's mirror direction.
#[inline]
fn mirror_ray(lit: &LitPixel, normal: Vec3) -> (Vec3, Vec3) {
    let p = lit.centre * lit.t;
    let mirror = lit.centre - 2.0 * lit.centre.dot(normal) * normal;
    (p + gap(lit.t) * normal, mirror)
}

/// The light that pixel `lit`, on a shiny surface, receives along its ray's mirror direction
/// from `seen`, the surface there: where the projector lights it, its diffuse signal × the
/// specular share, its stripes blurred by the lobe; `None` where the projector does not.
pub(super) fn mirrored(
    setup: &Capture,
    stripes: &Stripes,
    lit: &LitPixel,
    seen: &Mirrored,
) -> Option<Light> {
    let (frustum, projector) = setup.projector?;
    let (pose, world, sensor) = (&setup.pose, setup.world, setup.sensor);
    let Mirrored { q, hit } = *seen;
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
