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
    /// Also write each view's images: `true` every kind, `false` none, or the kinds named.
    pub images: Images,
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

/// Which of each view's images a dataset writes (`output.images`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "true, false or a list of image kinds (depth, depth_clean, normals, labels, \
                 instances, intensity, rgb, wear)"
)]
pub enum Images {
    /// `true`: every kind; `false`: none.
    Every(bool),
    /// The kinds named.
    Only(Vec<ImageKind>),
}

impl Images {
    /// Whether any image is written (the views keep their scans).
    pub fn any(&self) -> bool {
        match self {
            Images::Every(every) => *every,
            Images::Only(kinds) => !kinds.is_empty(),
        }
    }

    /// Whether images of `kind` are written.
    pub fn writes(&self, kind: ImageKind) -> bool {
        match self {
            Images::Every(every) => *every,
            Images::Only(kinds) => kinds.contains(&kind),
        }
    }
}

/// A kind of a view's image: what its pixels hold, its files named after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ImageKind {
    /// Measured depth: `depth.png` (16-bit) and `depth.npy` (float).
    Depth,
    /// Exact depth: `depth_clean.npy`.
    DepthClean,
    /// Normals: `normals.png`.
    Normals,
    /// Semantic classes: `labels.png`.
    Labels,
    /// Instance ids: `instances.png`.
    Instances,
    /// Signal strength: `intensity.png`.
    Intensity,
    /// The colour image: `rgb.png` or `rgb.jpg`.
    Rgb,
    /// Share of rust: `wear.png`.
    Wear,
}

impl ImageKind {
    /// Every kind, in the order a view's files list them.
    pub const ALL: [ImageKind; 8] = [
        ImageKind::Depth,
        ImageKind::DepthClean,
        ImageKind::Normals,
        ImageKind::Labels,
        ImageKind::Instances,
        ImageKind::Intensity,
        ImageKind::Rgb,
        ImageKind::Wear,
    ];

    /// Its name in the configuration and its files' names.
    pub fn name(self) -> &'static str {
        match self {
            ImageKind::Depth => "depth",
            ImageKind::DepthClean => "depth_clean",
            ImageKind::Normals => "normals",
            ImageKind::Labels => "labels",
            ImageKind::Instances => "instances",
            ImageKind::Intensity => "intensity",
            ImageKind::Rgb => "rgb",
            ImageKind::Wear => "wear",
        }
    }

    /// The kind of the image file named `name` (`depth.png`, `depth.npy`, …): its name up to
    /// the extension.
    pub fn of_file(name: &str) -> Option<ImageKind> {
        let stem = name.split('.').next()?;
        ImageKind::ALL.into_iter().find(|k| k.name() == stem)
    }
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
    /// Its files' extension.
    pub fn extension(self) -> &'static str {
        match self {
            ImageFormat::Png => "png",
            ImageFormat::Jpeg => "jpg",
        }
    }

    /// Writes `scan`'s colour image in this format (JPEG at `quality`).
    ///
    /// # Errors
    ///
    /// Any error of writing to `w`.
    pub fn write(
        self,
        w: &mut dyn std::io::Write,
        scan: &sensor::Scan,
        quality: u8,
    ) -> std::io::Result<()> {
        match self {
            ImageFormat::Png => sensor::formats::write_rgb_png(w, scan),
            ImageFormat::Jpeg => sensor::formats::write_rgb_jpeg(w, scan, quality),
        }
    }

    /// The colour image's file-name ending: `rgb.png` or `rgb.jpg`.
    pub fn rgb_name(self) -> &'static str {
        match self {
            ImageFormat::Png => "rgb.png",
            ImageFormat::Jpeg => "rgb.jpg",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_image_file_has_its_kind_and_every_kind_a_file() {
        let kinds: Vec<ImageKind> = sensor::formats::IMAGES
            .iter()
            .map(|(name, _)| ImageKind::of_file(name).unwrap_or_else(|| panic!("{name}")))
            .collect();
        for kind in ImageKind::ALL {
            assert!(kinds.contains(&kind), "{kind:?} names no file");
            let named: ImageKind = toml::Value::String(kind.name().into()).try_into().unwrap();
            assert_eq!(named, kind);
        }
    }

    #[test]
    fn images_are_all_none_or_those_named() {
        let parse = |text: &str| -> Images {
            let table: toml::Table = toml::from_str(&format!("images = {text}")).unwrap();
            table["images"].clone().try_into().unwrap()
        };
        assert!(ImageKind::ALL.iter().all(|&k| parse("true").writes(k)));
        assert!(!parse("false").any() && !parse("[]").any());
        let some = parse(r#"["rgb", "depth_clean"]"#);
        assert!(some.any() && some.writes(ImageKind::Rgb) && some.writes(ImageKind::DepthClean));
        assert!(!some.writes(ImageKind::Depth) && !some.writes(ImageKind::Labels));
        let text = toml::to_string(&toml::Table::from_iter([(
            "images".to_string(),
            toml::Value::try_from(&some).unwrap(),
        )]))
        .unwrap();
        assert_eq!(text.trim(), r#"images = ["rgb", "depth_clean"]"#);
    }
}
