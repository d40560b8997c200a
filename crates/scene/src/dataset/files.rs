//! A sample's files: where each goes in the folder's layout (`train/` and `validation/`, or a
//! folder per kind with the split in the name), and writing them with its manifest row.

use std::path::{Path, PathBuf};

use sensor::formats::CloudFormat;

use super::folder::{files_in, save};
use super::{Dataset, Row};
use crate::augment::Split;
use crate::bop;
use crate::claim::plain_dir;
use crate::config::{ImageFormat, ImageKind, Layout};
use crate::error::{Error, Result};
use crate::recipe::Recipe;
use crate::record::SampleJson;
use crate::sample::Sample;
use crate::yolo::{self, Yolo};

impl Dataset {
    /// Writes a sample's files and returns its manifest row.
    pub(super) fn write(&self, recipe: &Recipe, sample: &Sample) -> Result<Row> {
        let out = &recipe.config.output;
        let split = sample.split.name();
        let stem = sample.stem();
        let files = view_files(recipe, sample);
        let json_rel = placed(out.layout, sample.split, "json", &format!("{stem}.json"));
        let bop = if out.bop {
            bop::scene_files(sample, out)
        } else {
            Vec::new()
        };
        // every folder above every file, parents first
        let mut folders: Vec<&str> = files
            .iter()
            .flatten()
            .map(|(rel, _)| rel.as_str())
            .chain(bop.iter().map(|(rel, _)| rel.as_str()))
            .chain([json_rel.as_str()])
            .flat_map(|rel| rel.match_indices('/').map(|(i, _)| &rel[..i]))
            .collect();
        folders.sort_unstable();
        folders.dedup();
        for folder in folders {
            plain_dir(&self.out.join(folder))?;
        }
        let names: Vec<Vec<String>> = files
            .iter()
            .map(|files| files.iter().map(|(rel, _)| rel.clone()).collect())
            .collect();
        let doc = sample.json(recipe, &names);
        let mut class_counts = vec![0u64; out.scheme.classes().len()];
        for ((view, files), json) in sample.views.iter().zip(&files).zip(&doc.views) {
            // the colour image encoded once, for its file and the YOLO folder's
            let mut colour: Option<Vec<u8>> = None;
            for (rel, file) in files {
                let path = self.out.join(rel);
                match *file {
                    ViewFile::Cloud(f) => {
                        save(&path, &|w| f.write(w, &recipe.coloured(&view.cloud)))
                    }
                    ViewFile::SceneCloud(f) => {
                        let cloud = view
                            .scene_cloud
                            .as_ref()
                            .expect("a view with a scene cloud");
                        save(&path, &|w| f.write(w, &recipe.coloured(cloud)))
                    }
                    ViewFile::Image(k) => {
                        let scan = view.scan.as_ref().expect("a view with a scan");
                        save(&path, &|w| (sensor::formats::IMAGES[k].1)(w, scan))
                    }
                    ViewFile::Colour(format) => {
                        let bytes = match &mut colour {
                            Some(bytes) => bytes,
                            none => {
                                let scan = view.scan.as_ref().expect("a view with a scan");
                                let mut bytes = Vec::new();
                                format
                                    .write(&mut bytes, scan, out.jpeg_quality)
                                    .map_err(|e| Error::Output(e.to_string()))?;
                                none.insert(bytes)
                            }
                        };
                        save(&path, &|w| w.write_all(bytes))
                    }
                    ViewFile::YoloLabels(kind) => {
                        let scan = view.scan.as_ref().expect("a view with a scan");
                        let coco = json.coco.as_ref().map(|view| (view, out.coco));
                        let annotations = yolo::annotations(scan, coco, kind);
                        let size = (scan.width, scan.height);
                        save(&path, &|w| yolo::write_labels(w, size, &annotations, kind))
                    }
                }?;
            }
            for &c in &view.cloud.class {
                if let Some(n) = class_counts.get_mut(c as usize) {
                    *n += 1;
                }
            }
        }
        for (rel, body) in &bop {
            save(&self.out.join(rel), body)?;
        }
        save(&self.out.join(&json_rel), &|w| {
            w.write_all(doc.to_text().as_bytes())
        })?;
        Ok(Row {
            index: sample.index,
            split: split.into(),
            level: sample.level.name().into(),
            variant: sample.variant.map_or("motor".into(), |v| format!("{v:?}")),
            points: sample.views.iter().map(|v| v.cloud.len()).collect(),
            json: json_rel,
            files: [
                names.concat(),
                bop.into_iter().map(|(rel, _)| rel).collect(),
            ]
            .concat(),
            class_counts,
        })
    }
}

/// What one of a view's files holds.
#[derive(Clone, Copy)]
enum ViewFile {
    /// The cropped cloud in a format.
    Cloud(CloudFormat),
    /// The whole scene's cloud.
    SceneCloud(CloudFormat),
    /// An image of the scan ([`sensor::formats::IMAGES`], by index).
    Image(usize),
    /// The colour image in a format (beside the other images, or in the YOLO folder).
    Colour(ImageFormat),
    /// Its YOLO labels.
    YoloLabels(Yolo),
}

impl ViewFile {
    /// Its folder in the flat layout.
    fn folder(self) -> &'static str {
        match self {
            ViewFile::Cloud(CloudFormat::PcdAscii) => CloudFormat::Pcd.name(),
            ViewFile::Cloud(f) => f.name(),
            ViewFile::SceneCloud(_) => "scene",
            ViewFile::Image(_) | ViewFile::Colour(_) => "images",
            ViewFile::YoloLabels(_) => yolo::FOLDER,
        }
    }
}

/// Every folder a run writes files to besides the dataset folder, each before its parent: those
/// a sample's files may go to, in either layout, the YOLO folder's, the gathered annotations',
/// and the BOP folder's above its scenes.
pub(crate) const SAMPLE_FOLDERS: [&str; 22] = [
    "train",
    "validation",
    "ply",
    "pcd",
    "npy",
    "npz",
    "las",
    "numpy",
    "scene",
    "images",
    "json",
    "annotations",
    "yolo/images/train",
    "yolo/images/val",
    "yolo/labels/train",
    "yolo/labels/val",
    "yolo/images",
    "yolo/labels",
    "yolo",
    "bop/train_pbr",
    "bop/val_pbr",
    "bop",
];

/// The folders of the BOP scenes under `out` ([`SAMPLE_FOLDERS`] holds those above them):
/// each scene's (named by its sample's index) and its subfolders, those that exist.
pub(super) fn bop_folders(out: &Path) -> Result<Vec<PathBuf>> {
    let mut dirs = Vec::new();
    for split in [Split::Train, Split::Validation] {
        let parent = out.join(bop::FOLDER).join(bop::split_folder(split));
        for (scene, name) in files_in(&parent)? {
            let named = name.len() == 6 && name.bytes().all(|b| b.is_ascii_digit());
            if !named || !std::fs::symlink_metadata(&scene).is_ok_and(|m| m.is_dir()) {
                continue;
            }
            for sub in bop::SCENE_FOLDERS {
                let dir = scene.join(sub);
                if std::fs::symlink_metadata(&dir).is_ok() {
                    plain_dir(&dir)?;
                    dirs.push(dir);
                }
            }
            dirs.push(scene);
        }
    }
    Ok(dirs)
}

/// Where a file of a sample of `split` named `name` goes, relative to the dataset folder:
/// `train/` or `validation/`, or in the flat layout the folder of its kind (`folder`) with the
/// split at the start of its name, as AgiProbot's preparation names them.
pub(super) fn placed(layout: Layout, split: Split, folder: &str, name: &str) -> String {
    match (layout, split) {
        (Layout::SplitFolders, _) => format!("{}/{name}", split.name()),
        (Layout::Flat, Split::Train) => format!("{folder}/Training_{name}"),
        (Layout::Flat, Split::Validation) => format!("{folder}/Validation_{name}"),
    }
}

/// The files a dataset writes for each view of `sample`, each with its path relative to the
/// dataset's folder, in the order its JSON lists them.
fn view_files(recipe: &Recipe, sample: &Sample) -> Vec<Vec<(String, ViewFile)>> {
    let out = &recipe.config.output;
    let stem = sample.stem();
    let many = sample.views.len() > 1;
    sample
        .views
        .iter()
        .enumerate()
        .map(|(k, view)| {
            let view_stem = if many {
                format!("{stem}_v{k}")
            } else {
                stem.clone()
            };
            let mut files: Vec<(String, ViewFile)> = out
                .formats
                .iter()
                .map(|&f| (f.file_name(&view_stem), ViewFile::Cloud(f)))
                .collect();
            if view.scene_cloud.is_some() {
                let f = out.formats.first().copied().unwrap_or(CloudFormat::Ply);
                let name = f.file_name(&format!("{view_stem}_scene"));
                files.push((name, ViewFile::SceneCloud(f)));
            }
            if view.scan.is_some() {
                let images = sensor::formats::IMAGES.iter().enumerate();
                let written = images.filter(|(_, (name, _))| {
                    ImageKind::of_file(name).is_some_and(|kind| out.images.writes(kind))
                });
                for (k, &(name, _)) in written {
                    let file = if name == ImageFormat::Png.rgb_name() {
                        (
                            out.image_format.rgb_name(),
                            ViewFile::Colour(out.image_format),
                        )
                    } else {
                        (name, ViewFile::Image(k))
                    };
                    files.push((format!("{view_stem}_{}", file.0), file.1));
                }
            }
            let mut files: Vec<(String, ViewFile)> = files
                .into_iter()
                .map(|(name, file)| (placed(out.layout, sample.split, file.folder(), &name), file))
                .collect();
            if view.scan.is_some() && out.yolo != Yolo::Off {
                let split = yolo::split_folder(sample.split);
                let at = |kind: &str, ext: &str| {
                    format!("{}/{kind}/{split}/{view_stem}.{ext}", yolo::FOLDER)
                };
                let ext = out.image_format.extension();
                files.push((at("images", ext), ViewFile::Colour(out.image_format)));
                files.push((at("labels", "txt"), ViewFile::YoloLabels(out.yolo)));
            }
            files
        })
        .collect()
}

/// The JSON a dataset writes for `sample` of `recipe`, the files it lists included.
pub fn sample_json(recipe: &Recipe, sample: &Sample) -> SampleJson {
    let names: Vec<Vec<String>> = view_files(recipe, sample)
        .into_iter()
        .map(|files| files.into_iter().map(|(rel, _)| rel).collect())
        .collect();
    sample.json(recipe, &names)
}
