//! `[output]`: what each sample writes and how its files are laid out.

use motorgen::Scheme;
use sensor::formats::CloudFormat;
use sensor::{Frame, Units};
use serde::{Deserialize, Serialize};

use crate::coco::CocoMasks;
use crate::yolo::Yolo;

/// The most views a sample has (`camera.views`).
pub const MAX_VIEWS: u64 = 64;

/// `[output]`: what each sample writes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputConfig {
    /// Formats of the cropped cloud.
    pub formats: Vec<CloudFormat>,
    /// Frame of the written points.
    pub frame: Frame,
    /// Units of the written points.
    pub units: Units,
    /// Label scheme.
    pub scheme: Scheme,
    /// Write the exact (noise-free) points instead of the measured ones.
    pub clean: bool,
    /// Also write the whole scene's cloud (uncropped) in the first format.
    pub scene_cloud: bool,
    /// Also write depth, normal, label, instance and intensity images.
    pub images: bool,
    /// The colour image's file format.
    pub image_format: ImageFormat,
    /// JPEG's quality, 1 to 100.
    pub jpeg_quality: u8,
    /// COCO instance annotations of the colour images (with `images`): `off`, `polygons` or
    /// `rle`.
    pub coco: CocoMasks,
    /// Ultralytics YOLO labels of the colour images (with `images`): `off`, `detect` or
    /// `segment`.
    pub yolo: Yolo,
    /// BOP scenes of the colour images (with `images`): each object's pose, masks and model in
    /// `bop/`.
    pub bop: bool,
    /// What the points' rgb holds.
    pub colour: Colouring,
    /// Also record, for every pair of views, the share of each view's motor points whose
    /// surface the other view also measured (registration pairs' overlap).
    pub overlap: bool,
    /// How the samples' files are laid out in folders.
    pub layout: Layout,
}

/// How a dataset's sample files are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Layout {
    /// `train/` and `validation/`, every file of a sample in its split's folder.
    SplitFolders,
    /// A folder per kind of file (`npy/`, `ply/`, `pcd/`, `npz/` for the clouds, `scene/`,
    /// `images/`, `json/`), the split at the start of each name (`Training_…`,
    /// `Validation_…`), as KIT's AgiProbot loaders read a folder of clouds.
    Flat,
}

/// What the points' rgb holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Colouring {
    /// The colour the camera's colour image records.
    Camera,
    /// The class's colour of the label scheme, for looking at labels: it gives the label
    /// away, so a network must not be fed it.
    Class,
}

/// The colour image's file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ImageFormat {
    /// Lossless 8-bit PNG.
    Png,
    /// Baseline JPEG (4:2:0 chroma) of `output.jpeg_quality`.
    Jpeg,
}

impl ImageFormat {
    /// The colour image's file-name ending: `rgb.png` or `rgb.jpg`.
    pub fn rgb_name(self) -> &'static str {
        match self {
            ImageFormat::Png => "rgb.png",
            ImageFormat::Jpeg => "rgb.jpg",
        }
    }
}
