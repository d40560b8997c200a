//! File formats for clouds and images: PLY, PCD (binary and ASCII), NPY, NPZ and PNG, each
//! written as a stream; see the README for the layouts.

mod image;
mod lidar;
mod npy;
mod pcd;
mod ply;

use std::io::{Result, Write};

use serde::{Deserialize, Serialize};

use crate::cloud::PointCloud;
use crate::scan::Scan;

pub use image::{
    DEPTH_PNG_METRES_PER_UNIT, write_depth_png, write_intensity_png, write_label_png,
    write_mask_png, write_normal_png, write_rgb_jpeg, write_rgb_png, write_wear_png,
};
pub use lidar::{LidarFormat, write_blensor_numpy, write_blensor_pcd, write_las, write_lidar_npz};
pub use npy::{write_depth_npy, write_npy_i32, write_npy_synmotor, write_npz};
pub use pcd::write_pcd;
pub use ply::{write_ply, write_surface_ply};

/// A point-cloud file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CloudFormat {
    /// Binary PLY: x y z nx ny nz intensity snr red green blue class instance wear.
    Ply,
    /// Binary PCD v0.7 with a `label` field.
    Pcd,
    /// ASCII PCD v0.7 with a `label` field.
    PcdAscii,
    /// NPY float32 N×7 `x y z r g b label` (the SynMotor layout).
    Npy,
    /// NPZ with named arrays.
    Npz,
}

impl CloudFormat {
    /// Every format.
    pub const ALL: [CloudFormat; 5] = [
        CloudFormat::Ply,
        CloudFormat::Pcd,
        CloudFormat::PcdAscii,
        CloudFormat::Npy,
        CloudFormat::Npz,
    ];

    /// The name used in configs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CloudFormat::Ply => "ply",
            CloudFormat::Pcd => "pcd",
            CloudFormat::PcdAscii => "pcd-ascii",
            CloudFormat::Npy => "npy",
            CloudFormat::Npz => "npz",
        }
    }

    /// The format of a name, if any.
    pub fn parse(name: &str) -> Option<CloudFormat> {
        CloudFormat::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The file name for a cloud called `stem`.
    pub fn file_name(self, stem: &str) -> String {
        match self {
            CloudFormat::PcdAscii => format!("{stem}_ascii.pcd"),
            other => format!("{stem}.{}", other.name()),
        }
    }

    /// Writes `cloud`.
    ///
    /// # Errors
    ///
    /// Any error of writing to `w`.
    pub fn write(self, w: &mut dyn Write, cloud: &PointCloud) -> Result<()> {
        match self {
            CloudFormat::Ply => write_ply(w, cloud),
            CloudFormat::Pcd => write_pcd(w, cloud, true),
            CloudFormat::PcdAscii => write_pcd(w, cloud, false),
            CloudFormat::Npy => write_npy_synmotor(w, cloud),
            CloudFormat::Npz => write_npz(w, cloud),
        }
    }
}

/// Writes one image of a scan.
pub type ImageWriter = fn(&mut dyn Write, &Scan) -> Result<()>;

/// The images of a scan, as (file-name suffix, writer): depth as 16-bit PNG
/// ([`DEPTH_PNG_METRES_PER_UNIT`]) and float32 NPY (measured and clean), normals, labels,
/// instances, intensity, the colour image and the share of rust as PNG.
pub const IMAGES: [(&str, ImageWriter); 9] = [
    ("depth.png", |w, s| write_depth_png(w, s, false)),
    ("depth.npy", |w, s| depth_npy(w, s, false)),
    ("depth_clean.npy", |w, s| depth_npy(w, s, true)),
    ("normals.png", write_normal_png),
    ("labels.png", |w, s| write_label_png(w, s, false)),
    ("instances.png", |w, s| write_label_png(w, s, true)),
    ("intensity.png", write_intensity_png),
    ("rgb.png", write_rgb_png),
    ("wear.png", write_wear_png),
];

/// Writes `rows`, each appended to a buffer by `put(row, buffer)`, to `w` in blocks of about
/// 64 KiB: one call of the (dynamic) writer per block instead of one per field.
fn write_rows<T>(
    w: &mut dyn Write,
    rows: impl IntoIterator<Item = T>,
    mut put: impl FnMut(T, &mut Vec<u8>) -> Result<()>,
) -> Result<()> {
    const BLOCK: usize = 1 << 16;
    let mut buffer = Vec::with_capacity(2 * BLOCK);
    for row in rows {
        put(row, &mut buffer)?;
        if buffer.len() >= BLOCK {
            w.write_all(&buffer)?;
            buffer.clear();
        }
    }
    w.write_all(&buffer)
}

fn depth_npy(w: &mut dyn Write, s: &Scan, clean: bool) -> Result<()> {
    let z = s
        .pixels
        .iter()
        .map(|p| if clean { p.clean.z } else { p.point.z });
    write_depth_npy(w, s.width as usize, s.height as usize, z)
}
