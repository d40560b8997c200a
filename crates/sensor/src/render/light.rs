//! The lights of a rendered scene, in Blender's units so that a scene set up in Blender renders
//! alike: a point light of power P watts has the intensity P / 4π W/sr, a rectangle of power P
//! and area A the radiance P / (π A) on its front.

use std::f32::consts::PI;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::Error;

/// A light of a rendered scene.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum Light {
    /// A point (Blender's point light of radius 0).
    Point {
        /// Position, metres.
        position: [f32; 3],
        /// Power, watts (Blender's convention).
        power: f32,
        /// Linear RGB colour the power is given in.
        #[serde(default = "white")]
        colour: [f32; 3],
    },
    /// A rectangle emitting from its front (Blender's rectangular area light).
    Rect {
        /// Centre, metres.
        centre: [f32; 3],
        /// Half of one side, as a vector, metres.
        half_u: [f32; 3],
        /// Half of the other side; the light shines towards `half_u × half_v`.
        half_v: [f32; 3],
        /// Power, watts (Blender's convention).
        power: f32,
        /// Linear RGB colour the power is given in.
        #[serde(default = "white")]
        colour: [f32; 3],
    },
}

fn white() -> [f32; 3] {
    [1.0; 3]
}

/// The lights of a scene and the environment's uniform radiance around it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Lighting {
    /// The lights.
    pub lights: Vec<Light>,
    /// Linear RGB radiance of the environment (Blender's world colour × strength).
    pub environment: [f32; 3],
}

impl Lighting {
    /// Checks that every light can exist.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a negative or non-finite power, colour or environment, or a
    /// rectangle whose sides are not perpendicular or span no area.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |key: &str, value: String, allowed: &str| {
            Err(Error::Invalid {
                key: key.into(),
                value,
                allowed: allowed.into(),
            })
        };
        let colour_ok = |c: &[f32; 3]| c.iter().all(|v| v.is_finite() && *v >= 0.0);
        if !colour_ok(&self.environment) {
            return bad(
                "lighting.environment",
                format!("{:?}", self.environment),
                "three radiances of 0 or more",
            );
        }
        for light in &self.lights {
            let (power, colour) = match light {
                Light::Point { power, colour, .. } | Light::Rect { power, colour, .. } => {
                    (*power, colour)
                }
            };
            if !(power.is_finite() && power >= 0.0) {
                return bad("lights.power", power.to_string(), "watts, 0 or more");
            }
            if !colour_ok(colour) {
                return bad(
                    "lights.colour",
                    format!("{colour:?}"),
                    "three values of 0 or more",
                );
            }
            if let Light::Rect { half_u, half_v, .. } = light {
                let (a, b) = (Vec3::from(*half_u), Vec3::from(*half_v));
                let area = a.cross(b).length();
                if !(area.is_finite() && area > 0.0 && a.dot(b).abs() <= 1e-4 * area) {
                    return bad(
                        "lights.half_u/half_v",
                        format!("{half_u:?} {half_v:?}"),
                        "two perpendicular sides spanning a rectangle",
                    );
                }
            }
        }
        Ok(())
    }
}

/// A light prepared for sampling.
#[derive(Clone, Copy)]
pub(super) enum Emitter {
    Point {
        position: Vec3,
        /// Radiant intensity, W/sr.
        intensity: Vec3,
    },
    Rect {
        corner: Vec3,
        u: Vec3,
        v: Vec3,
        normal: Vec3,
        area: f32,
        radiance: Vec3,
    },
}

/// Light arriving at a point from one sample of an emitter: its direction, distance, radiance
/// (or for a point, irradiance on a surface facing it) and the pdf per solid angle (0 for a
/// point).
pub(super) struct Incoming {
    pub(super) wi: Vec3,
    pub(super) distance: f32,
    pub(super) value: Vec3,
    pub(super) pdf: f32,
}

impl Emitter {
    pub(super) fn new(light: &Light) -> Emitter {
        match *light {
            Light::Point {
                position,
                power,
                colour,
            } => Emitter::Point {
                position: position.into(),
                intensity: Vec3::from(colour) * (power / (4.0 * PI)),
            },
            Light::Rect {
                centre,
                half_u,
                half_v,
                power,
                colour,
            } => {
                let (c, a, b) = (Vec3::from(centre), Vec3::from(half_u), Vec3::from(half_v));
                let cross = (2.0 * a).cross(2.0 * b);
                let area = cross.length();
                Emitter::Rect {
                    corner: c - a - b,
                    u: 2.0 * a,
                    v: 2.0 * b,
                    normal: cross / area,
                    area,
                    radiance: Vec3::from(colour) * (power / (PI * area)),
                }
            }
        }
    }

    /// Light from this emitter at `x`, sampled with the uniform numbers `u`.
    pub(super) fn sample(&self, x: Vec3, u: [f32; 2]) -> Option<Incoming> {
        match *self {
            Emitter::Point {
                position,
                intensity,
            } => {
                let d = position - x;
                let distance = d.length();
                (distance > 0.0).then(|| Incoming {
                    wi: d / distance,
                    distance,
                    value: intensity / (distance * distance),
                    pdf: 0.0,
                })
            }
            Emitter::Rect {
                corner,
                u: a,
                v: b,
                normal,
                area,
                radiance,
            } => {
                let d = corner + a * u[0] + b * u[1] - x;
                let distance = d.length();
                let wi = d / distance;
                let cos = -wi.dot(normal);
                (cos > 0.0).then(|| Incoming {
                    wi,
                    distance,
                    value: radiance,
                    pdf: distance * distance / (area * cos),
                })
            }
        }
    }

    /// Where a ray from `origin` along unit `dir` meets this emitter's front nearer than
    /// `t_max`: the distance, radiance and the pdf per solid angle [`Emitter::sample`] gives that
    /// direction.
    pub(super) fn hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<(f32, Vec3, f32)> {
        let Emitter::Rect {
            corner,
            u,
            v,
            normal,
            area,
            radiance,
        } = *self
        else {
            return None;
        };
        let cos = -dir.dot(normal);
        if cos <= 0.0 {
            return None;
        }
        let t = (corner - origin).dot(normal) / dir.dot(normal);
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let p = origin + dir * t - corner;
        let (s, r) = (p.dot(u) / u.length_squared(), p.dot(v) / v.length_squared());
        ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&r))
            .then(|| (t, radiance, t * t / (area * cos)))
    }
}
