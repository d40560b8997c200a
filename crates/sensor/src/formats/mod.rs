//! File formats for clouds and images: PLY, PCD (binary and ASCII), NPY, NPZ and PNG, each
//! written as a stream; see the README for the layouts.

mod image;
mod npy;
mod pcd;
mod ply;

pub use image::{
    DEPTH_PNG_METRES_PER_UNIT, write_depth_png, write_intensity_png, write_label_png,
    write_normal_png,
};
pub use npy::{write_depth_npy, write_npy_synmotor, write_npz};
pub use pcd::write_pcd;
pub use ply::write_ply;
