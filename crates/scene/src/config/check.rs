//! Every value of a configuration checked against what it allows, before anything is written.

use motorgen::Scheme;

use super::{Config, ImageKind, MAX_VIEWS, Rig, sweep};
use crate::coco::CocoMasks;
use crate::error::{Error, Result};
use crate::yolo::Yolo;

impl Config {
    /// Checks every value against what it allows.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] naming the first value that is not allowed, with
    /// what is.
    pub fn check(&self) -> Result<()> {
        let m = &self.motor;
        if self.samples == 0 {
            return Err(Error::invalid("samples", 0, "a positive whole number"));
        }
        self.param_spaces()?;
        share("motor.cover_removed", m.cover_removed)?;
        if m.cover_removed > 0.0
            && !matches!(self.output.scheme, Scheme::InnerParts | Scheme::Objects)
        {
            return Err(Error::invalid(
                "motor.cover_removed",
                m.cover_removed,
                "0 unless output.scheme = \"inner10\" or \"objects9\" (the other schemes have no gear classes)",
            ));
        }
        let c = &self.cell;
        for (i, j) in c.pose_jitter_deg.iter().enumerate() {
            if !(0.0..=90.0).contains(j) {
                return Err(Error::invalid(
                    &format!("cell.pose_jitter_deg[{i}]"),
                    j,
                    "0 to 90 degrees",
                ));
            }
        }
        if !(0.0..=0.2).contains(&c.clearance) {
            return Err(Error::invalid("cell.clearance", c.clearance, "0 to 0.2 m"));
        }
        let f = &c.fixture;
        for (name, shift) in [
            ("fixed_jaw", &f.fixed_jaw),
            ("sliding_jaw", &f.sliding_jaw),
            ("pillar", &f.pillar),
            ("cylinder", &f.cylinder),
        ] {
            for (axis, s) in ["x", "y", "z"].iter().zip(shift) {
                s.check(&format!("cell.fixture.{name}.{axis}"), -0.2, 0.2)?;
            }
        }
        let o = &c.occluders;
        super::scenes::check_count("cell.occluders.count", o.count, 20)?;
        o.size.check("cell.occluders.size", 1e-3, 0.5)?;
        o.height.check("cell.occluders.height", -0.1, 0.5)?;
        if !(0.0..=0.5).contains(&o.spread) {
            return Err(Error::invalid(
                "cell.occluders.spread",
                o.spread,
                "0 to 0.5 m",
            ));
        }
        if !(0.0..=90.0).contains(&o.tilt_deg) {
            return Err(Error::invalid(
                "cell.occluders.tilt_deg",
                o.tilt_deg,
                "0 to 90 degrees",
            ));
        }
        let w = &c.wear;
        for (key, s) in [
            ("cell.wear.bolts", &w.bolts),
            ("cell.wear.pole_pot", &w.pole_pot),
            ("cell.wear.electric_connection", &w.electric_connection),
            ("cell.wear.screw_seats", &w.screw_seats),
            ("cell.wear.dust", &w.dust),
            ("cell.wear.grease", &w.grease),
        ] {
            s.check(key, 0.0, 1.0)?;
        }
        if !(0.0..=0.5).contains(&w.variation) {
            return Err(Error::invalid(
                "cell.wear.variation",
                w.variation,
                "0 to 0.5",
            ));
        }
        if !(1 <= w.rust[0] && w.rust[0] <= w.rust[1] && w.rust[1] <= 9) {
            return Err(Error::invalid(
                "cell.wear.rust",
                format!("{:?}", w.rust),
                "[first, last] of the rust types 1 to 9, first <= last",
            ));
        }
        let t = &c.table;
        for (key, value) in t.colour.iter().flatten().map(|v| ("cell.table.colour", *v)) {
            if !(0.0..=1.0).contains(&value) {
                return Err(Error::invalid(key, value, "linear RGB channels of 0 to 1"));
            }
        }
        share("cell.table.tint", t.tint)?;
        c.transfer.check()?;
        c.handling.check()?;
        c.armature.check()?;
        c.hall.check()?;
        self.check_hall()?;
        t.roughness.check("cell.table.roughness", 0.0, 1.0)?;
        self.check_camera()?;
        let sensor = self.sensor.resolve()?;
        if self.render.enabled && sensor.colour.offset != [0.0; 3] {
            return Err(Error::invalid(
                "render.enabled",
                true,
                format!(
                    "false on {}, whose colour camera is not its depth camera (render with a colour camera preset)",
                    sensor.name
                ),
            ));
        }
        let k = &self.crop;
        for (key, s, lo, hi) in [
            ("crop.x_min", &k.x_min, -1.0, 0.0),
            ("crop.x_max", &k.x_max, 0.0, 1.0),
            ("crop.y_min", &k.y_min, -1.0, 0.0),
            ("crop.y_max", &k.y_max, 0.0, 1.0),
            ("crop.z_min", &k.z_min, -1.0, 0.0),
            ("crop.z_max", &k.z_max, 0.0, 1.0),
        ] {
            s.check(key, lo, hi)?;
        }
        let a = &self.augment;
        share("augment.validation", a.validation)?;
        for (name, l) in [
            ("clean", &a.clean),
            ("occluded", &a.occluded),
            ("noisy", &a.noisy),
        ] {
            share(&format!("augment.{name}.share"), l.share)?;
            l.noise_scale
                .check(&format!("augment.{name}.noise_scale"), 0.0, 100.0)?;
            for (axis, j) in ["x", "y", "z"].iter().zip(l.jitter) {
                if !(0.0..=0.1).contains(&j) {
                    return Err(Error::invalid(
                        &format!("augment.{name}.jitter.{axis}"),
                        j,
                        "0 to 0.1 m",
                    ));
                }
            }
        }
        let total = a.clean.share + a.occluded.share + a.noisy.share;
        if (total - 1.0).abs() > 1e-4 {
            return Err(Error::invalid(
                "augment.{clean,occluded,noisy}.share",
                total,
                "shares that add up to 1",
            ));
        }
        let hall = self.cell.scene == super::SceneKind::Hall;
        if self.output.formats.is_empty() && !self.output.images.any() && !hall {
            return Err(Error::invalid(
                "output.formats",
                "[]",
                "at least one of ply, pcd, pcd-ascii, npy, npz (or output.images)",
            ));
        }
        if self.output.coco != CocoMasks::Off && !self.output.images.writes(ImageKind::Rgb) {
            return Err(Error::invalid(
                "output.coco",
                format!("\"{}\"", self.output.coco.name()),
                "\"off\" unless output.images writes rgb (COCO annotates the colour images)",
            ));
        }
        if self.output.yolo != Yolo::Off && !self.output.images.any() {
            return Err(Error::invalid(
                "output.yolo",
                format!("\"{}\"", self.output.yolo.name()),
                "\"off\" unless output.images writes images (YOLO labels the colour images)",
            ));
        }
        if self.output.bop && !self.output.images.any() {
            return Err(Error::invalid(
                "output.bop",
                "true",
                "false unless output.images writes images (BOP annotates the colour images)",
            ));
        }
        if !(1..=100).contains(&self.output.jpeg_quality) {
            return Err(Error::invalid(
                "output.jpeg_quality",
                self.output.jpeg_quality,
                "1 to 100",
            ));
        }
        self.render.check()?;
        self.lighting.check()?;
        sweep::Combinations::new(&self.sweep)?;
        Ok(())
    }

    fn check_camera(&self) -> Result<()> {
        let c = &self.camera;
        if !(1..=MAX_VIEWS).contains(&u64::from(c.views)) {
            return Err(Error::invalid("camera.views", c.views, "1 to 64"));
        }
        if self.cell.reclamp && c.views < 2 {
            return Err(Error::invalid(
                "camera.views",
                c.views,
                "2 or more with cell.reclamp = true (odd views in the other clamping)",
            ));
        }
        c.distance.check("camera.distance", 0.05, 20.0)?;
        c.tilt_deg.check("camera.tilt_deg", 0.0, 90.0)?;
        c.azimuth_deg.check("camera.azimuth_deg", -720.0, 720.0)?;
        c.roll_deg.check("camera.roll_deg", -360.0, 360.0)?;
        let distinct = |p: &[f32; 6]| {
            p.iter().all(|x| x.is_finite())
                && (glam::Vec3::from_slice(&p[..3]) - glam::Vec3::from_slice(&p[3..])).length()
                    > 1e-6
        };
        match c.rig {
            Rig::Fixed if !distinct(&c.look_at) => Err(Error::invalid(
                "camera.look_at",
                format!("{:?}", c.look_at),
                "[eye x, y, z, target x, y, z] with eye != target",
            )),
            Rig::List if c.poses.is_empty() || !c.poses.iter().all(distinct) => {
                Err(Error::invalid(
                    "camera.poses",
                    format!("{:?}", c.poses),
                    "a non-empty list of [eye x, y, z, target x, y, z] with eye != target",
                ))
            }
            _ if !c.up.iter().all(|x| x.is_finite()) || glam::Vec3::from(c.up).length() < 1e-6 => {
                Err(Error::invalid(
                    "camera.up",
                    format!("{:?}", c.up),
                    "a non-zero direction",
                ))
            }
            _ => Ok(()),
        }
    }
}

pub(super) fn share(key: &str, x: f32) -> Result<()> {
    if (0.0..=1.0).contains(&x) {
        Ok(())
    } else {
        Err(Error::invalid(key, x, "a share from 0 to 1"))
    }
}
