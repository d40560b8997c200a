//! One pass of a head over a world: its returns, fired from where the head is at each firing
//! when it moves, and where they lie in the head's frame, the world or Blensor's axes.

use glam::{Affine3A, Mat3A, Vec3, Vec3A};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::Lidar;
use super::beam::{Echo, Sample};
use crate::cloud::PointCloud;
use crate::noise::PixelRng;
use crate::world::World;

/// How the head moves during a pass: at a constant velocity, turning at a constant rate about
/// its axis (none: it stands still).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Motion {
    /// Velocity, metres a second along the world's axes.
    pub velocity: Vec3,
    /// Turn about the head's axis, degrees a second (counter-clockwise seen from above).
    pub turn: f32,
}

impl Motion {
    /// The pose `t` seconds into a pass that starts at `start`.
    pub fn pose(&self, start: &Affine3A, t: f32) -> Affine3A {
        let turn =
            Mat3A::from_axis_angle(start.matrix3.z_axis.into(), (self.turn * t).to_radians());
        Affine3A {
            matrix3: turn * start.matrix3,
            translation: start.translation + Vec3A::from(self.velocity * t),
        }
    }
}

/// Where a scan's points are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LidarFrame {
    /// The head's frame when the laser fired: as the sensor reports them (a moving head's
    /// pass shows its motion as skew).
    Head,
    /// The world.
    World,
    /// The head's frame in the axes of Blensor's scanner object (Blender's camera: x right, y
    /// up, z back).
    Blensor,
}

/// One return of a scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LidarReturn {
    /// Seconds from the scan's start at which the laser fired.
    pub time: f32,
    /// Yaw of the laser's column, degrees in [0, 360).
    pub yaw: f32,
    /// The laser (its ring).
    pub laser: u16,
    /// The ray's index: column × lasers + laser.
    pub ray: u32,
    /// Which of its beam's echoes, from 1, nearest first.
    pub echo: u8,
    /// How many echoes its beam returned.
    pub echoes: u8,
    /// Distance to the surface, metres.
    pub distance: f32,
    /// The measured distance: with bias and noise.
    pub measured: f32,
    /// The surface point in the head's frame.
    pub point: Vec3,
    /// The measured point in the head's frame: along the ray at the measured distance.
    pub noisy: Vec3,
    /// The surface's unit normal in the head's frame, facing the head.
    pub normal: Vec3,
    /// Semantic class.
    pub class: u16,
    /// Instance id.
    pub instance: u32,
    /// Diffuse colour of the surface, 8 bits a channel (Blensor's `int(255·colour)`).
    pub rgb: [u8; 3],
    /// Diffuse reflectivity of the surface (of the footprint's share it fills, for a beam
    /// that spreads).
    pub reflectivity: f32,
    /// Intensity, 0–1 (see [`Beam::intensity_reference`](super::Beam)).
    pub intensity: f32,
}

/// The returns of one pass of a head, in firing order.
#[derive(Clone, Debug, PartialEq)]
pub struct LidarScan {
    /// The head-to-world pose at the pass's start.
    pub pose: Affine3A,
    /// How the head moved.
    pub motion: Motion,
    /// Rays fired.
    pub rays: usize,
    /// The returns.
    pub returns: Vec<LidarReturn>,
}

/// One pass of `lidar` (valid: [`Lidar::validate`]) over `world` starting at `pose` (head to
/// world) and moving by `motion` (each laser fires from where the head is when it fires), noise
/// drawn from `seed`: the same returns for any number of threads.
pub fn scan_lidar(
    world: &World,
    lidar: &Lidar,
    pose: &Affine3A,
    motion: &Motion,
    seed: u64,
) -> LidarScan {
    let lasers = lidar.lasers.len();
    let returns = (0..lidar.columns())
        .into_par_iter()
        .map_init(
            || (Vec::<Sample>::new(), Vec::<Echo>::new()),
            |(samples, echoes), column| {
                let mut out = Vec::new();
                for laser in 0..lasers {
                    let local = lidar.direction(column, laser);
                    let origin = Vec3::Z * lidar.lasers[laser].offset;
                    let time = lidar.time(column, laser);
                    let at = motion.pose(pose, time);
                    let dir = at.transform_vector3(local).normalize();
                    let from = at.transform_point3(origin);
                    samples.clear();
                    for (ray, share) in lidar.beam.footprint(dir) {
                        if let Some((hit, distance)) =
                            cast_off_mirrors(world, from, ray, lidar.max_range)
                        {
                            samples.push(Sample {
                                distance,
                                share,
                                hit,
                            });
                        }
                    }
                    lidar.beam.echoes(samples, dir, echoes);
                    echoes.retain(|e| lidar.reflectivity.returns(e.reflectivity, e.distance));
                    let ray = (column * lasers + laser) as u32;
                    let rng = PixelRng::new(seed, u64::from(ray));
                    for (k, echo) in echoes.iter().enumerate() {
                        let distance = echo.distance;
                        let noise = lidar.noise.draw(distance, rng, k as u64);
                        let measured = distance + lidar.lasers[laser].bias + noise;
                        let hit = &echo.hit;
                        out.push(LidarReturn {
                            time,
                            yaw: lidar.yaw(column, laser).rem_euclid(360.0),
                            laser: laser as u16,
                            ray,
                            echo: k as u8 + 1,
                            echoes: echoes.len() as u8,
                            distance,
                            measured,
                            point: origin + local * distance,
                            noisy: origin + local * measured,
                            normal: at.matrix3.transpose() * hit.normal,
                            class: hit.class,
                            instance: hit.instance,
                            rgb: hit
                                .material
                                .colour
                                .map(|c| (c.clamp(0.0, 1.0) * 255.0) as u8),
                            reflectivity: echo.reflectivity,
                            intensity: lidar.beam.intensity(echo),
                        });
                    }
                }
                out
            },
        )
        .flatten_iter()
        .collect();
    LidarScan {
        pose: *pose,
        motion: *motion,
        rays: lidar.rays(),
        returns,
    }
}

/// A surface is a mirror to a LiDAR where it reflects at least this share of light specularly
/// ([`Material::specular`](crate::Material)) ...
const MIRROR_SPECULAR: f32 = 0.9;
/// ... in a lobe at most this wide, radians.
const MIRROR_LOBE: f32 = 0.05;
/// Mirrors a beam bounces off before it is given up.
const BOUNCES: usize = 8;
/// How far from a mirror a bounced beam starts, metres (clear of the mirror's own triangles).
const CLEAR: f32 = 1e-4;

/// The surface that returns a beam from `origin` along `dir` within `range` and the length of
/// its path: the first surface, or, where that is a mirror, what the reflected beam meets
/// (Blensor's mirror: no return from the mirror itself, the path's whole length measured).
fn cast_off_mirrors(
    world: &World,
    mut origin: Vec3,
    mut dir: Vec3,
    range: f32,
) -> Option<(crate::world::SurfaceHit, f32)> {
    let mut travelled = 0.0;
    for _ in 0..=BOUNCES {
        let hit = world.cast(origin, dir, range - travelled)?;
        travelled += hit.t;
        let m = &hit.material;
        if !(m.specular >= MIRROR_SPECULAR && m.lobe <= MIRROR_LOBE) {
            return Some((hit, travelled));
        }
        origin += dir * hit.t + hit.normal * CLEAR;
        dir = (dir - 2.0 * dir.dot(hit.normal) * hit.normal).normalize();
    }
    None
}

impl LidarScan {
    /// The transform from the head's frame when return `r` was fired to `frame`, its lengths
    /// multiplied by `scale` (1000 for millimetres).
    pub fn to_frame(&self, r: &LidarReturn, frame: LidarFrame, scale: f32) -> Affine3A {
        let to = match frame {
            LidarFrame::Head => Affine3A::IDENTITY,
            LidarFrame::World => self.motion.pose(&self.pose, r.time),
            LidarFrame::Blensor => Affine3A {
                matrix3: Mat3A::from_cols(-Vec3A::Z, -Vec3A::X, Vec3A::Y),
                translation: Vec3A::ZERO,
            },
        };
        Affine3A::from_scale(Vec3::splat(scale)) * to
    }

    /// The measured points as a cloud in `frame` scaled by `scale`: the normal, the
    /// intensity, the colour and the labels of each; no pattern SNR or rust.
    pub fn cloud(&self, frame: LidarFrame, scale: f32) -> PointCloud {
        let r = &self.returns;
        let to: Vec<Affine3A> = r.iter().map(|x| self.to_frame(x, frame, scale)).collect();
        PointCloud {
            xyz: r
                .iter()
                .zip(&to)
                .map(|(x, to)| to.transform_point3(x.noisy))
                .collect(),
            normal: r
                .iter()
                .zip(&to)
                .map(|(x, to)| to.transform_vector3(x.normal).normalize_or_zero())
                .collect(),
            intensity: r.iter().map(|x| x.intensity).collect(),
            rgb: r.iter().map(|x| x.rgb).collect(),
            snr: vec![0.0; r.len()],
            class: r.iter().map(|x| x.class).collect(),
            instance: r.iter().map(|x| x.instance).collect(),
            wear: vec![0.0; r.len()],
        }
    }
}
