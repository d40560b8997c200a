//! Unorganized, labelled point clouds as columns, cut from scans.

use glam::{Affine3A, Vec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::scan::{Pixel, Scan};

/// The frame a cloud is expressed in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Frame {
    /// OpenCV / Zivid camera frame: x right, y down, z forward.
    #[default]
    Camera,
    /// The frame of the scanned meshes.
    World,
    /// Blender / Blensor camera frame: x right, y up, z backward (the original datasets' frame).
    Blensor,
}

/// Length unit of written coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Units {
    /// Metres.
    #[default]
    Metres,
    /// Millimetres (Zivid's and the AgiProbot real data's unit).
    Millimetres,
}

impl Frame {
    /// The transform from the camera frame of a scan at camera-to-world `pose` into this frame.
    pub fn from_camera(self, pose: &Affine3A) -> Affine3A {
        match self {
            Frame::Camera => Affine3A::IDENTITY,
            Frame::World => *pose,
            Frame::Blensor => Affine3A::from_scale(Vec3::new(1.0, -1.0, -1.0)),
        }
    }
}

impl Units {
    /// Metres to this unit.
    pub fn scale(self) -> f32 {
        match self {
            Units::Metres => 1.0,
            Units::Millimetres => 1000.0,
        }
    }
}

/// Points with normals and labels, one entry per point in every column.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointCloud {
    /// Positions.
    pub xyz: Vec<Vec3>,
    /// Unit normals.
    pub normal: Vec<Vec3>,
    /// Signal strength.
    pub intensity: Vec<f32>,
    /// Colour, 8-bit sRGB.
    pub rgb: Vec<[u8; 3]>,
    /// Signal-to-noise ratio of the pattern (see [`Pixel::snr`]).
    pub snr: Vec<f32>,
    /// Semantic class.
    pub class: Vec<u16>,
    /// Instance id.
    pub instance: Vec<u32>,
    /// Share of rust under the point, 0..1 in steps of 1/255.
    pub wear: Vec<f32>,
}

impl PointCloud {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.xyz.len()
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.xyz.is_empty()
    }

    /// The cloud moved by `transform` (points and normals) with points scaled to `units`.
    pub fn transformed(mut self, transform: &Affine3A, units: Units) -> PointCloud {
        let scale = units.scale();
        self.xyz
            .par_iter_mut()
            .zip(&mut self.normal)
            .for_each(|(p, n)| {
                *p = transform.transform_point3(*p) * scale;
                *n = transform.transform_vector3(*n);
            });
        self
    }
}

impl Scan {
    /// The valid points of the scan (`clean`: the exact points instead of the measured ones), in
    /// `frame` and `units`, in pixel order.
    pub fn cloud(&self, clean: bool, frame: Frame, units: Units) -> PointCloud {
        let cloud = self.points_where(|p| {
            let point = if clean { p.clean } else { p.point };
            (!point.x.is_nan()).then_some(point)
        });
        cloud.transformed(&frame.from_camera(&self.pose), units)
    }

    /// The pixels for which `point` gives a point (camera frame), with their normals, signal
    /// and labels, in pixel order. Two parallel passes over the window's rows: the first counts
    /// each row's points, which places them; the second writes every column of them at once,
    /// into columns allocated to size.
    pub fn points_where(&self, point: impl Fn(&Pixel) -> Option<Vec3> + Sync) -> PointCloud {
        let counts: Vec<usize> = self
            .window_rows()
            .map(|row| row.iter().filter(|p| point(p).is_some()).count())
            .collect();
        let mut cloud = PointCloud::zeroed(counts.iter().sum());
        let (mut parts, mut rest) = (Vec::with_capacity(counts.len()), Columns::of(&mut cloud));
        for &n in &counts {
            let (part, after) = rest.split_at(n);
            parts.push(part);
            rest = after;
        }
        self.window_rows().zip(parts).for_each(|(row, mut part)| {
            let kept = row.iter().filter_map(|p| Some((p, point(p)?)));
            for (k, (p, q)) in kept.enumerate() {
                part.set(k, p, q);
            }
        });
        cloud
    }
}

impl PointCloud {
    /// `n` points at the origin with zero labels, the columns filled in parallel (so that both
    /// threads fault in the pages of a large cloud).
    fn zeroed(n: usize) -> PointCloud {
        fn column<T: Copy + Send + Sync>(n: usize, value: T) -> Vec<T> {
            let mut v = Vec::with_capacity(n);
            v.par_extend(rayon::iter::repeat_n(value, n));
            v
        }
        PointCloud {
            xyz: column(n, Vec3::ZERO),
            normal: column(n, Vec3::ZERO),
            intensity: column(n, 0.0),
            rgb: column(n, [0; 3]),
            snr: column(n, 0.0),
            class: column(n, 0),
            instance: column(n, 0),
            wear: column(n, 0.0),
        }
    }
}

/// A run of a cloud's points, every column of it.
struct Columns<'a> {
    xyz: &'a mut [Vec3],
    normal: &'a mut [Vec3],
    intensity: &'a mut [f32],
    rgb: &'a mut [[u8; 3]],
    snr: &'a mut [f32],
    class: &'a mut [u16],
    instance: &'a mut [u32],
    wear: &'a mut [f32],
}

impl<'a> Columns<'a> {
    fn of(c: &'a mut PointCloud) -> Columns<'a> {
        Columns {
            xyz: &mut c.xyz,
            normal: &mut c.normal,
            intensity: &mut c.intensity,
            rgb: &mut c.rgb,
            snr: &mut c.snr,
            class: &mut c.class,
            instance: &mut c.instance,
            wear: &mut c.wear,
        }
    }

    /// The first `n` points, and the rest.
    fn split_at(self, n: usize) -> (Columns<'a>, Columns<'a>) {
        let (xyz, xyz_rest) = self.xyz.split_at_mut(n);
        let (normal, normal_rest) = self.normal.split_at_mut(n);
        let (intensity, intensity_rest) = self.intensity.split_at_mut(n);
        let (rgb, rgb_rest) = self.rgb.split_at_mut(n);
        let (snr, snr_rest) = self.snr.split_at_mut(n);
        let (class, class_rest) = self.class.split_at_mut(n);
        let (instance, instance_rest) = self.instance.split_at_mut(n);
        let (wear, wear_rest) = self.wear.split_at_mut(n);
        (
            Columns {
                xyz,
                normal,
                intensity,
                rgb,
                snr,
                class,
                instance,
                wear,
            },
            Columns {
                xyz: xyz_rest,
                normal: normal_rest,
                intensity: intensity_rest,
                rgb: rgb_rest,
                snr: snr_rest,
                class: class_rest,
                instance: instance_rest,
                wear: wear_rest,
            },
        )
    }

    /// Point `k` of the run: `q`, with the normal, signal and labels of pixel `p`.
    #[inline]
    fn set(&mut self, k: usize, p: &Pixel, q: Vec3) {
        self.xyz[k] = q;
        self.normal[k] = p.normal;
        self.intensity[k] = p.intensity;
        self.rgb[k] = p.rgb;
        self.snr[k] = p.snr;
        self.class[k] = p.class;
        self.instance[k] = p.instance;
        self.wear[k] = f32::from(p.wear) / 255.0;
    }
}
