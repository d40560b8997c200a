//! The dataset card written beside a finished dataset (`dataset-card.md`): what it holds (its
//! samples by split, augmentation level and motor variant, their points, the sensor), each
//! class's share of the points and of the samples, and its intended use and licence.

use std::collections::BTreeMap;
use std::io::{Result, Write};

use super::{Dataset, Row};

/// The card's file name, in the dataset folder.
pub(super) const NAME: &str = "dataset-card.md";

/// Writes the card of `dataset`, whose samples are `rows` (all of them, by index).
pub(super) fn write(w: &mut dyn Write, dataset: &Dataset, rows: &[Row]) -> Result<()> {
    let c = &dataset.base.config;
    let sensor = dataset.sensor();
    let k = &sensor.intrinsics;
    writeln!(w, "# Dataset card\n")?;
    writeln!(
        w,
        "{} samples made by motorfactory {} (`motorfactory generate`), seed {}. `config.toml` \
         holds every key of the configuration (`motorfactory generate --config config.toml` \
         makes the same bytes again), `labels.json` the label scheme, `manifest.jsonl` each \
         sample's files and points per class.\n",
        rows.len(),
        env!("CARGO_PKG_VERSION"),
        c.seed
    )?;
    writeln!(w, "## Samples\n")?;
    let what = match dataset.lidar() {
        Some(lidar) => {
            writeln!(
                w,
                "- Sensor: the LiDAR `{}`, {} lasers × {} columns, on a robot driving along the \
                 hall's aisle; a sample is one revolution, {} in a row a hall.",
                lidar.name,
                lidar.lasers.len(),
                lidar.columns(),
                c.lidar.revolutions
            )?;
            "Returns a pass"
        }
        None => {
            writeln!(
                w,
                "- Sensor: `{}`, {}×{} pixels; views a sample: {}.",
                sensor.name, k.width, k.height, c.camera.views
            )?;
            "Points a sample (cropped clouds, every view)"
        }
    };
    let mut points: Vec<usize> = rows.iter().map(|r| r.points.iter().sum()).collect();
    points.sort_unstable();
    if let (Some(lo), Some(hi)) = (points.first(), points.last()) {
        writeln!(
            w,
            "- {what}: median {}, {lo} to {hi}.",
            points[points.len() / 2]
        )?;
    }
    for (what, of) in [
        ("Splits", (|r: &Row| r.split.as_str()) as fn(&Row) -> &str),
        ("Augmentation levels", |r| r.level.as_str()),
        ("Motor variants", |r| r.variant.as_str()),
    ] {
        let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
        for r in rows {
            *counts.entry(of(r)).or_default() += 1;
        }
        let listed: Vec<String> = counts.iter().map(|(k, n)| format!("`{k}` {n}")).collect();
        writeln!(w, "- {what}: {}.", listed.join(", "))?;
    }
    let scheme = dataset.scheme();
    writeln!(w, "\n## Labels\n")?;
    writeln!(
        w,
        "The `{}` scheme: each class's share of all points, and the samples holding it.\n",
        scheme.name()
    )?;
    writeln!(w, "| id | class | share of points | samples with it |")?;
    writeln!(w, "|---|---|---|---|")?;
    let total: u64 = rows.iter().flat_map(|r| &r.class_counts).sum();
    for class in scheme.classes() {
        let id = usize::from(class.id);
        let count: u64 = rows.iter().filter_map(|r| r.class_counts.get(id)).sum();
        let holding = rows
            .iter()
            .filter(|r| r.class_counts.get(id).is_some_and(|&n| n > 0))
            .count();
        writeln!(
            w,
            "| {id} | `{}` | {:.2} % | {holding} of {} |",
            class.name,
            100.0 * count as f64 / total.max(1) as f64,
            rows.len()
        )?;
    }
    writeln!(
        w,
        "\nA class that dominates the points (the background, as in real crops) calls for a \
         loss or a point sampling weighted by class, and per-class IoU rather than accuracy.\n"
    )?;
    writeln!(w, "## Intended use\n")?;
    writeln!(
        w,
        "Training and pre-training perception for the robotic inspection, handling and \
         disassembly of small electric gear motors, before fine-tuning or testing on real \
         captures. The motors are the parametric gear motors of the MotorFactory add-on, within \
         its ranges; the sensor is simulated. Not for measuring real motors or claims about a \
         real sensor's accuracy; see motorfactory's docs/dataset-card.md for the known gaps.\n"
    )?;
    writeln!(w, "## Licence\n")?;
    writeln!(
        w,
        "Made from motorfactory's own procedural models and sensor simulation (MIT OR \
         Apache-2.0), with no third-party meshes, textures or captures in it: whoever generated \
         it chooses the licence it is published under."
    )
}
