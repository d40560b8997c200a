//! Interreflection: the light a shiny surface mirrors into a pixel from the surface it faces
//! (see [`Interreflection`](crate::noise::Interreflection)).

use std::f32::consts::PI;

use glam::{Vec3, Vec3A};

use super::Pixel;
use super::cast::{Capture, gap};
use super::decode::{Light, MIDDLE, Stripes};
use super::light::LitPixel;
use crate::bvh::Hit;
use crate::spec::Frustum;
use crate::world::SurfaceHit;

/// What a shiny pixel's mirror ray meets: the surface point (camera frame) and its hit, with
/// the projector's light there: its distance, the unit direction to it (camera frame) and the
/// cosine of its incidence.
#[derive(Clone, Copy)]
pub(super) struct Mirrored {
    q: Vec3,
    hit: SurfaceHit,
    distance: f32,
    to_light: Vec3,
    cos_light: f32,
}

/// For each pixel of a row (`lits` and their pixels `line`), what its mirror ray meets where
/// the projector lights it: none where it has no mirror ray (a dark or matte pixel, a sensor
/// without interreflection), the ray meets nothing, or the projector does not light what it
/// meets. The rays of neighbouring pixels on one smooth surface run side by side from nearby
/// points, and are cast together: runs of up to four consecutive shiny pixels whose rays stay
/// within [`COHERENT`] of the run's first, as one packet; so are the shadow rays from the
/// projector to the points they meet (within [`SHADOW_COHERENT`]).
pub(super) fn cast_mirrors(
    setup: &Capture,
    lits: &[Option<LitPixel>],
    line: &[Pixel],
    out: &mut Vec<Option<Mirrored>>,
) {
    out.clear();
    out.resize(lits.len(), None);
    let Some((frustum, projector)) = setup.projector else {
        return;
    };
    if !setup.sensor.noise.interreflection.enabled {
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
            cast_run(setup, projector, &run[..held], out);
            held = 0;
        }
        run[held] = ray;
        held += 1;
    }
    if held > 0 {
        cast_run(setup, projector, &run[..held], out);
    }
    shade(setup, &frustum, projector, out);
}

/// Drops from `mirrors` the points the projector does not light: outside its field, facing
/// away from it, or in a shadow (the shadow rays of consecutive points whose directions from
/// the projector stay within [`SHADOW_COHERENT`] of the first's cast as one packet).
fn shade(setup: &Capture, frustum: &Frustum, projector: Vec3, mirrors: &mut [Option<Mirrored>]) {
    let (pose, world) = (&setup.pose, setup.world);
    let lamp = pose.transform_point3(projector);
    // a run of shadow rays (pixel index, world direction from the projector, length) cast
    let cast = |run: &[(usize, Vec3, f32)], mirrors: &mut [Option<Mirrored>]| {
        if let [(i, dir, length)] = *run {
            if world.occluded(lamp, dir, length) {
                mirrors[i] = None;
            }
            return;
        }
        let (mut dirs, mut lengths) = ([Vec3::Z; 4], [0.0; 4]);
        for (k, &(_, dir, length)) in run.iter().enumerate() {
            (dirs[k], lengths[k]) = (dir, length);
        }
        let [blocked] = world
            .bvh()
            .occluded_packet(&[[lamp; 4]], &[dirs], &[lengths]);
        for (&(i, ..), blocked) in run.iter().zip(blocked) {
            if blocked {
                mirrors[i] = None;
            }
        }
    };
    let mut run = [(0, Vec3::ZERO, 0.0); 4];
    let mut held = 0;
    for i in 0..mirrors.len() {
        let Some(m) = mirrors[i] else {
            continue;
        };
        if !frustum.lights(m.q) || m.cos_light <= 0.0 {
            mirrors[i] = None; // outside the field, or facing away
            continue;
        }
        let ray = (
            i,
            pose.transform_vector3(-m.to_light),
            m.distance - gap(m.distance),
        );
        if held == run.len() || held > 0 && ray.1.dot(run[0].1) < SHADOW_COHERENT {
            cast(&run[..held], mirrors);
            held = 0;
        }
        run[held] = ray;
        held += 1;
    }
    if held > 0 {
        cast(&run[..held], mirrors);
    }
}

/// Mirror rays of one packet: the cosine of the largest angle between a ray and the packet's
/// first (3°), and the largest squared distance between their origins, m² (1 cm). At the
/// inspection station a packet takes 3.8 rays on average for the work of 2.2 single walks;
/// wider packets (four groups of four) and looser bounds cost more than they save, the mirror
/// rays of curved surfaces fanning out.
const COHERENT: (f32, f32) = (0.998_63, 1e-4);

/// Shadow rays of one packet, from the projector to the points mirror rays meet: the cosine of
/// the largest angle between a ray and the packet's first (0.3°). At the inspection station
/// half or twice that costs more instructions.
const SHADOW_COHERENT: f32 = 0.999_985;

/// Casts a run of mirror rays (pixel index, camera-frame origin and direction), into `out`:
/// one ray alone, more as a packet. `projector` is the projector's centre (camera frame).
fn cast_run(
    setup: &Capture,
    projector: Vec3,
    run: &[(usize, Vec3, Vec3)],
    out: &mut [Option<Mirrored>],
) {
    let (pose, world) = (&setup.pose, setup.world);
    let seen = |hit: &Hit, from: Vec3, dir: Vec3, world_dir: Vec3| {
        let (q, hit) = (
            from + hit.t * dir,
            world.surface(hit, pose.transform_point3(from), world_dir),
        );
        let to_light = projector - q;
        let distance = to_light.length();
        let l = to_light / distance;
        Mirrored {
            q,
            hit,
            distance,
            to_light: l,
            cos_light: Vec3::from(setup.to_camera * Vec3A::from(hit.normal)).dot(l),
        }
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
    let [hits] = world.cast_packet(&[origins], &[dirs], &[t_max]);
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
/// from `seen`, the surface there, which the projector lights: its diffuse signal × the
/// specular share, its stripes blurred by the lobe.
pub(super) fn mirrored(
    setup: &Capture,
    stripes: &Stripes,
    lit: &LitPixel,
    seen: &Mirrored,
) -> Light {
    let (frustum, sensor) = (&stripes.frustum, setup.sensor);
    let Mirrored {
        q,
        hit,
        distance,
        cos_light,
        ..
    } = *seen;
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
    Light::new(signal, 0.0, column, contrast, stripes, &sensor.noise.snr)
}
