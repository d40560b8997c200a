//! The light at the surface point a pixel sees: its label, incidence, signal and losses.

use glam::Vec3;

use super::Pixel;
use super::cast::{Capture, gap};
use crate::noise::{PixelRng, stream};
use crate::spec::SensorSpec;
use crate::world::SurfaceHit;

/// A pixel measured up to the projector's visibility: what [`measure`] needs once that is known.
#[derive(Clone, Copy)]
pub(super) struct LitPixel {
    /// The pixel's column and row.
    pub(super) pixel: [u32; 2],
    /// Its centre ray's direction (camera frame) and the distance to the surface along it.
    pub(super) centre: Vec3,
    pub(super) t: f32,
    /// Signal strength at the point.
    pub(super) signal: f32,
    /// The pattern's signal-to-noise ratio (0 without the SNR model).
    pub(super) snr: f32,
    /// The projector's (or the camera's) light at the point, 0 in the projector's shadow.
    pub(super) light: f32,
    /// The surface's diffuse reflectivity.
    pub(super) reflectivity: f32,
    /// The light the surface sends to the colour camera in the ambient light alone, if that
    /// camera sees the surface.
    pub(super) ambient: Option<Vec3>,
    /// The surface's specular share and the width of its lobe, radians.
    pub(super) specular: f32,
    pub(super) lobe: f32,
    /// The surface point the projector must reach (camera frame) and its distance from the
    /// projector (none for sensors that light from the camera).
    pub(super) shadow: Option<(Vec3, f32)>,
    pub(super) rng: PixelRng,
}

impl LitPixel {
    /// This pixel, `px`, with its surface point in the projector's shadow: its colour in the
    /// ambient light alone, and as [`LitPixel::shadowed`].
    #[inline]
    pub(super) fn in_shadow(self, setup: &Capture, px: &mut Pixel) -> Option<LitPixel> {
        if let Some(ambient) = self.ambient {
            px.rgb = setup.colour.record(ambient, self.pixel, self.rng);
        }
        self.shadowed(setup.sensor)
    }

    /// This pixel with its surface point in the projector's shadow: no light of its own, but a
    /// shiny surface still mirrors the lit surfaces around it, when `sensor` models that
    /// (interreflection); `None` when it can have no point.
    #[inline]
    pub(super) fn shadowed(self, sensor: &SensorSpec) -> Option<LitPixel> {
        (sensor.noise.interreflection.enabled && self.specular > 0.0).then_some(LitPixel {
            signal: 0.0,
            snr: 0.0,
            light: 0.0,
            shadow: None,
            ..self
        })
    }
}

/// Labels pixel `px`, whose centre ray (camera frame) hit `hit`, records its colour, and
/// measures it up to the projector's visibility: the light at the surface point it sees, its
/// signal and dropouts (which need no shadow test, so lost pixels have none); `None` when it
/// can have no point.
#[inline(always)]
pub(super) fn illuminate(
    setup: &Capture,
    col: usize,
    row: usize,
    centre: Vec3,
    hit: SurfaceHit,
    px: &mut Pixel,
) -> Option<LitPixel> {
    let Capture {
        sensor,
        ref projector,
        ref to_camera,
        seed,
        ..
    } = *setup;
    let k = &sensor.intrinsics;
    let noise = &sensor.noise;
    let rng = PixelRng::new(seed, (row * k.width as usize + col) as u64);
    let pixel = [col as u32, row as u32];
    let normal = Vec3::from(*to_camera * glam::Vec3A::from(hit.normal));
    *px = Pixel {
        clean: centre * hit.t,
        normal,
        class: hit.class,
        instance: hit.instance,
        wear: (hit.wear * 255.0).round() as u8,
        // the cosine for now: `finish_row` turns a row's cosines into angles in one tight loop
        incidence: normal.dot(-centre).clamp(-1.0, 1.0),
        ..Pixel::EMPTY
    };

    // illumination of the surface point the pixel sees (jitter moves where it is measured, not
    // where the light falls): the projector, or the camera itself
    let surface = px.clean;
    let material = hit.material;
    // the colour camera's view of the point: this camera's, or one beside it that may not see
    // it (then the pixel records black)
    let (wo, seen_by_colour) = match setup.colour.offset {
        None => (-centre, true),
        Some(offset) => {
            let to = offset - surface;
            let distance = to.length();
            let dir = setup.pose.transform_vector3(to / distance);
            let from = setup.pose.transform_point3(surface);
            let blocked = setup
                .world
                .occluded(from + dir * gap(distance), dir, distance);
            (to / distance, !blocked)
        }
    };
    let colour = |to_flash| setup.colour.light(&material, normal, wo, to_flash);
    let ((light_dir, light_range), shadow) = match projector {
        Some((frustum, centre)) => {
            let to_light = *centre - surface;
            let distance = to_light.length();
            let l = to_light / distance;
            // outside the projector's field or self-shadowed (the surface faces away from
            // it): the ambient light alone
            if !frustum.lights(surface) || normal.dot(l) <= 0.0 {
                if seen_by_colour {
                    px.rgb = setup.colour.record(colour(None).ambient, pixel, rng);
                }
                return None;
            }
            ((l, distance), Some((surface, distance)))
        }
        None => ((-centre, hit.t), None),
    };

    let falloff = (sensor.reference_range / light_range).powi(2);
    let cos_light = normal.dot(light_dir).max(0.0);
    let light = cos_light * falloff;
    // the colour as lit; a pixel the projector's shadow turns out to cover records the ambient
    // light alone ([`LitPixel::in_shadow`])
    let seen = colour(Some((light_dir, falloff)));
    if seen_by_colour {
        px.rgb = setup.colour.record(seen.ambient + seen.flash, pixel, rng);
    }
    // the diffuse reflection and the highlight about the mirror direction
    let highlight = if material.specular > 0.0 && noise.specular.saturation > 0.0 {
        let half = (light_dir - centre).normalize();
        noise.specular.highlight(&hit.lobe, normal.dot(half), light)
    } else {
        0.0
    };
    let signal = material.reflectivity * light + highlight;
    // a pixel lost from here on is lit: its signal stays, as its neighbours see it
    if rng.uniform(stream::DROPOUT) < noise.dropout.probability(signal)
        || noise.specular.saturates(signal)
    {
        px.intensity = signal;
        return None;
    }
    let snr = if noise.snr.is_on() {
        noise.snr.ratio(signal, material.reflectivity)
    } else {
        0.0
    };
    Some(LitPixel {
        pixel,
        centre,
        t: hit.t,
        signal,
        snr,
        light,
        reflectivity: material.reflectivity,
        ambient: seen_by_colour.then_some(seen.ambient),
        specular: material.specular,
        lobe: material.lobe,
        shadow,
        rng,
    })
}

/// arccos of `x` in [-1, 1], within 5e-7 rad: the polynomial of Abramowitz and Stegun 4.4.46
/// (error 2e-8 in exact arithmetic), a third of the cost of libm's `acosf`.
#[inline]
pub(super) fn acos(x: f32) -> f32 {
    const A: [f32; 8] = [
        std::f32::consts::FRAC_PI_2, // 1.5707963050 rounds to it
        -0.214_598_8,
        0.088_978_99,
        -0.050_174_3,
        0.030_891_88,
        -0.017_088_126,
        0.006_670_09,
        -0.001_262_491_1,
    ];
    let a = x.abs();
    let p = A.iter().rev().fold(0.0, |p, &c| p * a + c);
    let r = (1.0 - a).sqrt() * p;
    if x < 0.0 { std::f32::consts::PI - r } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acos_is_within_5e7_of_the_exact_angle() {
        let worst = (-1_000_000..=1_000_000)
            .map(|i| i as f32 / 1e6)
            .chain([-1.0, -0.0, 0.0, 1.0, f32::EPSILON, 1.0 - f32::EPSILON / 2.0])
            .map(|x| (acos(x) as f64 - (x as f64).acos()).abs())
            .fold(0.0, f64::max);
        assert!(worst < 5e-7, "worst error {worst}");
    }
}
