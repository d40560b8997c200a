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
    /// The scene's world frame.
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
    /// Semantic class.
    pub class: Vec<u16>,
    /// Instance id.
    pub instance: Vec<u32>,
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
    /// and labels, in pixel order: the kept pixels found in parallel, then each column filled
    /// in parallel, allocated to size.
    pub fn points_where(&self, point: impl Fn(&Pixel) -> Option<Vec3> + Sync) -> PointCloud {
        let kept: Vec<(u32, Vec3)> = (0u32..self.pixels.len() as u32)
            .into_par_iter()
            .zip(&self.pixels)
            .filter_map(|(i, p)| Some((i, point(p)?)))
            .collect();
        let pixels = &self.pixels;
        PointCloud {
            xyz: column(pixels, &kept, |_, q| q),
            normal: column(pixels, &kept, |p, _| p.normal),
            intensity: column(pixels, &kept, |p, _| p.intensity),
            class: column(pixels, &kept, |p, _| p.class),
            instance: column(pixels, &kept, |p, _| p.instance),
        }
    }
}

/// One field of the kept pixels (by index) and their points, as a column.
fn column<T: Send>(
    pixels: &[Pixel],
    kept: &[(u32, Vec3)],
    field: impl Fn(&Pixel, Vec3) -> T + Sync,
) -> Vec<T> {
    kept.par_iter()
        .map(|&(i, q)| field(&pixels[i as usize], q))
        .collect()
}
