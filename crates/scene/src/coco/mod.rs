//! COCO instance annotations (`output.coco`): each view's colour image with a box, an area and
//! a mask per motor part in sight, kept in the sample's JSON and gathered into
//! `annotations/instances_{train,validation}.json` once every sample is made.

mod mask;
#[cfg(test)]
mod tests;

use std::collections::BTreeMap;
use std::path::Path;

use motorgen::Scheme;
use sensor::Scan;
use serde::{Deserialize, Serialize};

pub use mask::{Mask, compressed};

use crate::dataset::save;
use crate::error::{Error, Result};
use crate::silhouette::Silhouette;

/// How COCO annotations are written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CocoMasks {
    /// None.
    #[default]
    Off,
    /// Masks as polygons (`iscrowd` 0): one polygon per part whose even-odd fill is its mask.
    Polygons,
    /// Masks as compressed run-length encodings (`iscrowd` 0).
    Rle,
}

impl CocoMasks {
    /// Its name in a configuration.
    pub fn name(self) -> &'static str {
        match self {
            CocoMasks::Off => "off",
            CocoMasks::Polygons => "polygons",
            CocoMasks::Rle => "rle",
        }
    }
}

/// A COCO image: one view's colour image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Image {
    /// 1-based, unique in the dataset: the sample's index times its views plus the view's,
    /// plus 1.
    pub id: u64,
    /// The colour image, relative to the dataset folder.
    pub file_name: String,
    /// Pixels across.
    pub width: usize,
    /// Pixels down.
    pub height: usize,
}

/// A COCO annotation: one part instance in one image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Annotation {
    /// Unique in the dataset: the image's id times 65536 plus the instance's.
    pub id: u64,
    /// The image.
    pub image_id: u64,
    /// The part's class in the label scheme (1-based; background is not annotated).
    pub category_id: u32,
    /// The part's instance id, as in `instances.png`.
    pub instance: u32,
    /// Tight box `[x, y, width, height]`, pixels, from the image's top-left corner.
    pub bbox: [f64; 4],
    /// Pixels in the mask.
    pub area: f64,
    /// The mask.
    pub segmentation: Segmentation,
    /// Always 0: every annotation is one object.
    pub iscrowd: u8,
    /// The share of the part's silhouette (its pixels were nothing in front of it) that is in
    /// sight: `area` over the silhouette's pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visible_fraction: Option<f64>,
}

/// A COCO mask.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Segmentation {
    /// `[[x0, y0, x1, y1, …]]`: one polygon on pixel corners whose even-odd fill is the mask.
    Polygons(Vec<Vec<f64>>),
    /// `{"size": [h, w], "counts": …}`: pycocotools' compressed run-length encoding.
    Rle {
        /// Rows and columns of the image.
        size: [usize; 2],
        /// The compressed run lengths.
        counts: String,
    },
}

/// One view's COCO image and annotations, as a sample's JSON keeps them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CocoView {
    /// The image.
    pub image: Image,
    /// Its annotations, by instance id.
    pub annotations: Vec<Annotation>,
}

/// The annotations of `scan`'s image `image` (classes and instances of the surface under each
/// pixel's centre; class 0, the background, left out), masks written as `masks` says, each
/// part's visible fraction from its silhouette where `silhouette` gives one.
pub fn annotate<'s>(
    scan: &Scan,
    image: Image,
    masks: CocoMasks,
    silhouette: &dyn Fn(u32) -> Option<&'s Silhouette>,
) -> CocoView {
    let (w, h) = (scan.width as usize, scan.height as usize);
    // each instance's class and box
    let mut boxes: BTreeMap<u32, (u16, [usize; 4])> = BTreeMap::new();
    for (k, p) in scan.pixels.iter().enumerate() {
        if p.class == 0 {
            continue;
        }
        let (x, y) = (k % w, k / w);
        let b = &mut boxes.entry(p.instance).or_insert((p.class, [x, y, x, y])).1;
        *b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
    }
    let annotations = boxes
        .into_iter()
        .map(|(instance, (class, [x0, y0, x1, y1]))| {
            let (bw, bh) = (x1 - x0 + 1, y1 - y0 + 1);
            let inside: Vec<bool> = (0..bw * bh)
                .map(|k| scan.pixels[(y0 + k / bw) * w + x0 + k % bw].instance == instance)
                .collect();
            let mask = Mask {
                width: bw,
                height: bh,
                inside: &inside,
            };
            let segmentation = match masks {
                CocoMasks::Rle => Segmentation::Rle {
                    size: [h, w],
                    counts: compressed(&mask.runs_in(x0, y0, w, h)),
                },
                _ => {
                    let polygon: Vec<f64> = mask
                        .polygon()
                        .expect("an instance in sight has pixels")
                        .chunks(2)
                        .flat_map(|c| [c[0] + x0 as f64, c[1] + y0 as f64])
                        .collect();
                    Segmentation::Polygons(vec![polygon])
                }
            };
            // the silhouette and the visible pixels outside it (where a ray's rounding differs)
            let visible_fraction = silhouette(instance).map(|s| {
                let outside = (0..bw * bh)
                    .filter(|&k| inside[k])
                    .filter(|&k| !s.contains(x0 + k % bw, y0 + k / bw))
                    .count();
                mask.area() as f64 / (s.area() + outside) as f64
            });
            Annotation {
                id: image.id * 65536 + u64::from(instance),
                image_id: image.id,
                category_id: u32::from(class),
                instance,
                bbox: [x0, y0, bw, bh].map(|v| v as f64),
                area: mask.area() as f64,
                segmentation,
                iscrowd: 0,
                visible_fraction,
            }
        })
        .collect();
    CocoView { image, annotations }
}

/// A COCO instances file.
#[derive(Serialize)]
struct Instances<'a> {
    info: serde_json::Value,
    images: Vec<&'a Image>,
    annotations: Vec<&'a Annotation>,
    categories: Vec<serde_json::Value>,
}

/// Writes `annotations/instances_{split}.json` in `out` for each split of `views` (split name,
/// the view), images and annotations in id order, the categories `scheme`'s classes but the
/// background.
///
/// # Errors
///
/// [`Error::Io`] when a file cannot be written.
pub fn gather(out: &Path, scheme: Scheme, views: &[(String, CocoView)]) -> Result<()> {
    let folder = out.join("annotations");
    crate::claim::plain_dir(&folder)?;
    let categories: Vec<serde_json::Value> = scheme
        .classes()
        .iter()
        .filter(|c| c.id != 0)
        .map(|c| serde_json::json!({"id": c.id, "name": c.name, "supercategory": "motor"}))
        .collect();
    let mut splits: BTreeMap<&str, Vec<&CocoView>> = BTreeMap::new();
    for (split, view) in views {
        splits.entry(split).or_default().push(view);
    }
    for (split, mut views) in splits {
        views.sort_by_key(|v| v.image.id);
        let instances = Instances {
            info: serde_json::json!({
                "description": format!("motorfactory {split} split"),
                "version": env!("CARGO_PKG_VERSION"),
            }),
            images: views.iter().map(|v| &v.image).collect(),
            annotations: views.iter().flat_map(|v| &v.annotations).collect(),
            categories: categories.clone(),
        };
        let text = serde_json::to_string(&instances).map_err(|e| Error::Config(e.to_string()))?;
        save(&folder.join(format!("instances_{split}.json")), &|w| {
            w.write_all(text.as_bytes())
        })?;
    }
    Ok(())
}
