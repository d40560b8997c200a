//! What a finished dataset shares, gathered from its samples: its card, the COCO instances
//! files and BOP's camera.

use std::path::Path;

use super::folder::{save, write_json};
use super::{Dataset, Row, card};
use crate::claim::plain_dir;
use crate::error::{Error, Result};
use crate::record::SampleJson;

impl Dataset {
    /// What the whole dataset (`rows`) shares: its card, and from its samples' JSON with
    /// `output.coco` the COCO instances files, from the annotations each keeps; with
    /// `output.bop` BOP's `camera.json`, the first sample's camera.
    pub(super) fn gather(&self, rows: &[Row]) -> Result<()> {
        save(&self.out.join(card::NAME), &|w| card::write(w, self, rows))?;
        let output = &self.base.config.output;
        let coco = output.coco != crate::coco::CocoMasks::Off;
        // every sample's JSON for COCO, the first's alone for BOP's camera
        let read = if coco {
            rows.len()
        } else {
            usize::from(output.bop).min(rows.len())
        };
        let mut views = Vec::new();
        for (k, row) in rows[..read].iter().enumerate() {
            let rel = Path::new(&row.json);
            let path = self.out.join(rel);
            let plain = rel
                .components()
                .all(|c| matches!(c, std::path::Component::Normal(_)));
            if !plain {
                return Err(Error::Config(format!(
                    "the manifest names {} for sample {}, outside the dataset folder",
                    motorgen::shown(&row.json),
                    row.index
                )));
            }
            let bytes = sensor::files::read(&path, sensor::files::CONFIG_LIMIT)
                .map_err(Error::io(&path))?;
            let doc: SampleJson = serde_json::from_slice(&bytes)
                .map_err(|e| Error::Config(format!("{}: {e}", path.display())))?;
            if k == 0 && output.bop {
                let camera = crate::bop::camera(&doc.sensor);
                let folder = self.out.join(crate::bop::FOLDER);
                plain_dir(&folder)?;
                save(&folder.join("camera.json"), &|w| write_json(w, &camera))?;
            }
            views.extend(
                doc.views
                    .into_iter()
                    .filter_map(|v| v.coco)
                    .map(|c| (row.split.clone(), c)),
            );
        }
        if !coco {
            return Ok(());
        }
        crate::coco::gather(&self.out, output.scheme, &views)
    }
}
