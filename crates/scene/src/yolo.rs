//! Ultralytics YOLO labels (`output.yolo`): each view's colour image under
//! `yolo/images/{train,val}/` and its labels under `yolo/labels/{train,val}/`, one line per motor
//! part in sight, and `yolo/data.yaml` naming the classes.

use std::borrow::Cow;
use std::io::Write;

use motorgen::Scheme;
use sensor::Scan;
use serde::{Deserialize, Serialize};

use crate::augment::Split;
use crate::coco::{self, CocoMasks};

/// What YOLO labels hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Yolo {
    /// No YOLO folder.
    #[default]
    Off,
    /// Boxes: `class x_centre y_centre width height`, normalised by the image's size.
    Detect,
    /// Polygons: `class x0 y0 x1 y1 …`, normalised, whose even-odd fill is the part's mask.
    Segment,
}

impl Yolo {
    /// Its name in a configuration.
    pub fn name(self) -> &'static str {
        match self {
            Yolo::Off => "off",
            Yolo::Detect => "detect",
            Yolo::Segment => "segment",
        }
    }
}

/// The YOLO folder, relative to the dataset folder.
pub const FOLDER: &str = "yolo";

/// Ultralytics' name of a split's folder.
pub fn split_folder(split: Split) -> &'static str {
    match split {
        Split::Train => "train",
        Split::Validation => "val",
    }
}

/// The annotations YOLO's `kind` of labels needs of `scan`'s colour image: those of its COCO
/// view where COCO annotated it (with masks as the `CocoMasks` given) and they serve (their
/// boxes for `Detect`, polygons for `Segment`), otherwise the image annotated with polygons.
pub fn annotations<'a>(
    scan: &Scan,
    coco: Option<(&'a coco::CocoView, CocoMasks)>,
    kind: Yolo,
) -> Cow<'a, [coco::Annotation]> {
    match coco {
        Some((view, masks)) if kind == Yolo::Detect || masks == CocoMasks::Polygons => {
            Cow::Borrowed(&view.annotations)
        }
        _ => {
            let image = coco::Image {
                id: 0,
                file_name: String::new(),
                width: scan.width as usize,
                height: scan.height as usize,
            };
            Cow::Owned(coco::annotate(scan, image, CocoMasks::Polygons, &|_| None).annotations)
        }
    }
}

/// Writes the labels of a colour image of `width`×`height` pixels annotated with `annotations`
/// ([`annotations`]) as `kind` says: one line per part in sight, the class 0-based (the
/// scheme's id less one: the background has none), coordinates to six decimals.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_labels(
    w: &mut dyn Write,
    (width, height): (u32, u32),
    annotations: &[coco::Annotation],
    kind: Yolo,
) -> std::io::Result<()> {
    let (width, height) = (f64::from(width), f64::from(height));
    for a in annotations {
        write!(w, "{}", a.category_id - 1)?;
        match kind {
            Yolo::Segment => {
                let coco::Segmentation::Polygons(polygons) = &a.segmentation else {
                    unreachable!("annotated as polygons")
                };
                for (k, v) in polygons.iter().flatten().enumerate() {
                    let scale = if k % 2 == 0 { width } else { height };
                    write!(w, " {:.6}", v / scale)?;
                }
            }
            _ => {
                let [x, y, bw, bh] = a.bbox;
                let (cx, cy) = ((x + bw / 2.0) / width, (y + bh / 2.0) / height);
                write!(w, " {cx:.6} {:.6} {:.6} {:.6}", cy, bw / width, bh / height)?;
            }
        }
        writeln!(w)?;
    }
    Ok(())
}

/// `data.yaml` for the classes of `scheme` (its background left out): the image folders
/// relative to the file's own folder, which Ultralytics takes as the dataset's root.
pub fn data_yaml(scheme: Scheme, kind: Yolo) -> String {
    let mut s = format!(
        "# motorfactory: Ultralytics YOLO {} labels, classes of the {} scheme\n\
         train: images/train\nval: images/val\nnames:\n",
        kind.name(),
        scheme.name()
    );
    for c in scheme.classes().iter().filter(|c| c.id != 0) {
        s += &format!("  {}: {}\n", c.id - 1, c.name);
    }
    s
}
