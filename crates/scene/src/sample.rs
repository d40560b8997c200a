//! One sample: a motor in a cell, scanned from one or more views, cropped and augmented, all in
//! memory and a pure function of (configuration, sample index).

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::OnceLock;

use glam::{Affine3A, Mat4, Vec3};
use motorgen::kernel::Aabb;
use motorgen::{Motor, Scheme};
use rand::{Rng, RngExt};
use rayon::prelude::*;
use sensor::render::Lighting;
use sensor::{
    ColourCapture, Pixel, PointCloud, Region, Scan, SensorSpec, Target, World, scan_reusing,
};

use crate::augment::{Level, Split};
use crate::cell::{
    Cell, Variation, bench, compose, handling, transfer_unit, transform_box, turned_with_motor,
};
use crate::coco::{self, CocoMasks, CocoView};
use crate::config::{Clamping, CropConfig, MAX_VIEWS, OutputConfig, SceneKind, Variant};
use crate::coverage::{Surface, overlap};
use crate::error::{Error, Result};
use crate::recipe::Recipe;
use crate::record::{CropJson, ObjectJson, SampleJson, ViewJson};
use crate::rendered;
use crate::rig::camera_poses;
use crate::seed::Seed;
use crate::silhouette::Silhouette;

thread_local! {
    /// This thread's last region scan, whose buffer its next reuses: a megapixel buffer mapped
    /// afresh per sample costs more in page faults than the scan spends filling it.
    static EARLIER: std::cell::Cell<Scan> = std::cell::Cell::new(Scan::default());
}

/// One view of a sample.
#[derive(Clone, Debug)]
pub struct View {
    /// Camera-to-world pose.
    pub pose: Affine3A,
    /// Taken of the cell in the other clamping (`cell.reclamp`, odd views).
    pub reclamped: bool,
    /// Seed of the scan's per-pixel noise.
    pub noise_seed: u64,
    /// Points inside the crop box, in the output frame and units.
    pub cloud: PointCloud,
    /// Every point of the scan, when the config asks for it.
    pub scene_cloud: Option<PointCloud>,
    /// The organized scan, when images are asked for.
    pub scan: Option<Scan>,
    /// The silhouettes of the annotated instances, once asked for ([`Sample::silhouettes`]).
    silhouettes: OnceLock<BTreeMap<u32, Silhouette>>,
}

/// A finished sample in memory.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Index in the dataset.
    pub index: u64,
    /// Seed derived from the global seed and the index.
    pub seed: u64,
    /// Motor variant, if the config lists variants.
    pub variant: Option<Variant>,
    /// Augmentation level.
    pub level: Level,
    /// Split.
    pub split: Split,
    /// The motor.
    pub motor: Motor,
    /// The cell it lies in.
    pub cell: Cell,
    /// The cell of the other clamping, the odd views' (`cell.reclamp`).
    pub reclamped: Option<Cell>,
    /// Whether cover and cover bolts were removed.
    pub cover_removed: bool,
    /// Crop box, world.
    pub crop: Aabb,
    /// The sensor as used (noise scaled).
    pub sensor: SensorSpec,
    /// Factor applied to the sensor's axial noise.
    pub noise_scale: f32,
    /// The views.
    pub views: Vec<View>,
    /// Per view, the share of its motor points whose surface each view measured
    /// (`output.overlap`; see [`overlap`]).
    pub overlap: Option<Vec<Vec<f32>>>,
    /// The lights of its rendered colour images (`render.enabled`).
    pub lighting: Option<Lighting>,
}

/// The crop box around `centre`, each face drawn from its span.
fn crop_box(c: &CropConfig, centre: Vec3, rng: &mut impl Rng) -> Aabb {
    let min = Vec3::new(
        c.x_min.sample(rng),
        c.y_min.sample(rng),
        c.z_min.sample(rng),
    );
    let max = Vec3::new(
        c.x_max.sample(rng),
        c.y_max.sample(rng),
        c.z_max.sample(rng),
    );
    Aabb {
        min: centre + min,
        max: centre + max,
    }
}

/// Makes sample `index` of `recipe`: the bytes `motorfactory generate` writes for it come from
/// this sample.
///
/// # Example
///
/// ```
/// use scene::{Config, Recipe, make};
///
/// let recipe = Recipe::new(Config::default(), Vec::new())?;
/// let sample = make(&recipe, 12)?;
/// let view = &sample.views[0];
/// // a function of the configuration and the index alone
/// assert_eq!(view.cloud, make(&recipe, 12)?.views[0].cloud);
/// println!("{:?} {:?}: {} points", sample.level, sample.split, view.cloud.len());
/// # Ok::<(), scene::Error>(())
/// ```
///
/// # Errors
///
/// [`Error::Config`] when the motor's parameters drawn for this sample do not
/// form a valid motor.
pub fn make(recipe: &Recipe, index: u64) -> Result<Sample> {
    let config = &recipe.config;
    let (seed, motor) = recipe.motor(index)?;
    let (variant, level, split) = recipe.placement(index);
    let cover_removed = Seed::Cover.rng(seed).random::<f32>() < config.motor.cover_removed;
    let lc = level.config(&config.augment);
    let vary = Variation {
        occluders: lc.occluders,
        fixture_shift: lc.fixture_shift,
        cover_removed,
        clamping: config.cell.clamping,
    };
    let rng = &mut Seed::Cell.rng(seed);
    let more = |k: usize| recipe.extra_motor(index, k);
    let cell = match config.cell.scene {
        SceneKind::Station => compose(&motor, &config.cell, vary, rng),
        SceneKind::TransferUnit => transfer_unit(&motor, &more, &config.cell, rng)?,
        SceneKind::Handling => handling(&motor, &more, &config.cell, rng)?,
        SceneKind::Armature => bench(&motor, &config.cell, rng),
        SceneKind::Hall => {
            return Err(Error::Config(
                "cell.scene = \"hall\" is scanned by the LiDAR, not a camera: motorfactory \
                 generate writes its passes"
                    .into(),
            ));
        }
    };
    let reclamped = config.cell.reclamp.then(|| {
        let other = Clamping::ALL.into_iter().find(|&c| c != vary.clamping);
        let vary = Variation {
            clamping: other.expect("two clampings"),
            ..vary
        };
        compose(&motor, &config.cell, vary, &mut Seed::Reclamp.rng(seed))
    });
    // the crop's offsets are the lying motor's: in another clamping the box turns with it
    let crop = crop_box(&config.crop, cell.motor_centre, &mut Seed::Crop.rng(seed));
    let crop = match vary.clamping {
        Clamping::GearContainerUp => crop,
        standing => turned_with_motor(&crop, &motor, standing, cell.motor_centre),
    };
    let poses = camera_poses(
        &config.camera,
        cell.motor_centre,
        index,
        &mut Seed::Camera.rng(seed),
    );
    let noise_scale = lc.noise_scale.sample(&mut Seed::NoiseScale.rng(seed));
    let mut sensor = recipe.sensor().clone();
    sensor.noise = sensor.noise.scaled(noise_scale);
    sensor.calibration.seed = match config.sensor.cameras {
        0 => Seed::Calibration.of(seed),
        n => {
            let unit = Seed::Calibration.rng(seed).random_range(0..n);
            sensor.calibration.seed.wrapping_add(unit)
        }
    };
    // a rendered colour image replaces the scan's own: the scan shades none
    let scanned = if config.render.enabled {
        let mut s = sensor.clone();
        s.colour.capture = ColourCapture::ThreeD;
        Cow::Owned(s)
    } else {
        Cow::Borrowed(&sensor)
    };

    let cells: Vec<&Cell> = std::iter::once(&cell).chain(&reclamped).collect();
    let worlds: Vec<World> = cells
        .iter()
        .map(|c| World::new(&c.targets(config.output.scheme)))
        .collect();
    let out = &config.output;
    // a rendered colour image covers the frame
    let whole = out.scene_cloud || out.images.any() || config.render.enabled;
    let lighting = config.render.enabled.then(|| {
        let centre = cell.motor_centre.with_z(0.0);
        config.lighting.draw(centre, &mut Seed::Lighting.rng(seed))
    });
    let views = poses
        .into_iter()
        .enumerate()
        .map(|(v, pose)| {
            let noise_seed = Seed::Scan(v as u64).of(seed);
            // a reclamped view: the pose moved with the motor's centre, the crop box with the
            // motor (the box round the first box turned as the motor turned)
            let k = v % cells.len();
            let moved = cells[k].motor_to_world * cell.motor_to_world.inverse();
            let shift = cells[k].motor_centre - cell.motor_centre;
            let pose = Affine3A::from_translation(shift) * pose;
            let crop = if k == 0 {
                crop
            } else {
                transform_box(&crop, &moved)
            };
            let world = &worlds[k];
            // unless the whole scene is wanted, only pixels whose rays cross the crop box, so
            // cropping loses nothing
            let region = (!whole).then(|| region_around(&crop, &pose, &sensor));
            let earlier = EARLIER.take();
            let mut s = scan_reusing(world, &scanned, &pose, noise_seed, region.as_ref(), earlier);
            if let Some(lighting) = &lighting {
                let mut draws = Seed::Render(v as u64).rng(seed);
                rendered::colour(&mut s, world, &sensor, lighting, &config.render, &mut draws)?;
            }
            let mut jitter = Seed::Jitter(v as u64).rng(seed);
            let cloud = cropped(&s, &crop, out.clean, lc.jitter, &mut jitter);
            // exact points in the first cell's frame, the motor moved back
            let to_first = cell.motor_to_world * cells[k].motor_to_world.inverse();
            let exact = out
                .overlap
                .then(|| cropped_exact(&s, &crop, out.clean, &to_first));
            let to_frame = out.frame.from_camera(&pose);
            let scene_cloud = out
                .scene_cloud
                .then(|| s.cloud(out.clean, out.frame, out.units));
            let scan = if out.images.any() {
                Some(s)
            } else {
                EARLIER.set(s);
                None
            };
            let view = View {
                pose,
                reclamped: k == 1,
                noise_seed,
                cloud: cloud.transformed(&to_frame, out.units),
                scene_cloud,
                scan,
                silhouettes: OnceLock::new(),
            };
            Ok((view, exact))
        })
        .collect::<Result<Vec<_>>>()?;
    let (views, exact): (Vec<View>, Vec<Option<Vec<Vec3>>>) = views.into_iter().unzip();
    let overlap = out.overlap.then(|| {
        let surface = Surface::sample_all(&cell.objects, OVERLAP_DENSITY, Seed::Surface.of(seed));
        let exact: Vec<Vec<Vec3>> = exact.into_iter().flatten().collect();
        overlap(&surface, &exact, OVERLAP_RADIUS)
    });
    Ok(Sample {
        index,
        seed,
        variant,
        level,
        split,
        motor,
        cell,
        reclamped,
        cover_removed,
        crop,
        sensor,
        noise_scale,
        views,
        overlap,
        lighting,
    })
}

/// The region of pixels a scan from `pose` needs to measure the points in `b` (world) as a
/// whole scan would: the box grown beyond the reach of the sensor's neighbour effects, in pixel
/// footprints at the box's far corner (than which no corner is farther).
pub(crate) fn region_around(b: &Aabb, pose: &Affine3A, sensor: &SensorSpec) -> Region {
    let far = b.centre().distance(Vec3::from(pose.translation)) + b.size().length() / 2.0;
    let k = &sensor.intrinsics;
    let margin = sensor.reach_px() * far / k.fx.min(k.fy) as f32;
    Region {
        min: b.min - margin,
        max: b.max + margin,
    }
}

/// The scan's points that lie in `crop` (world), in the camera frame, each moved by a uniform
/// jitter of ± `jitter` per camera axis after cropping (as the original datasets did).
fn cropped(
    scan: &Scan,
    crop: &Aabb,
    clean: bool,
    jitter: [f32; 3],
    rng: &mut impl Rng,
) -> PointCloud {
    let mut out = scan.points_where(|p| {
        in_crop(scan, crop, clean, p).then_some(if clean { p.clean } else { p.point })
    });
    if jitter.iter().any(|&j| j > 0.0) {
        let j = Vec3::from(jitter);
        for q in &mut out.xyz {
            let u = Vec3::new(rng.random(), rng.random(), rng.random());
            *q += (u * 2.0 - 1.0) * j;
        }
    }
    out
}

/// Whether pixel `p`'s point (the measured one, or the exact one with `clean`) lies in `crop`
/// (world).
fn in_crop(scan: &Scan, crop: &Aabb, clean: bool, p: &Pixel) -> bool {
    let q = if clean { p.clean } else { p.point };
    let w = scan.pose.transform_point3(q);
    !q.x.is_nan() && w.cmpge(crop.min).all() && w.cmple(crop.max).all()
}

/// The exact surface points of the pixels whose points `cropped` keeps, in pixel order: in the
/// world, then moved by `moved`.
fn cropped_exact(scan: &Scan, crop: &Aabb, clean: bool, moved: &Affine3A) -> Vec<Vec3> {
    scan.window_rows()
        .flat_map_iter(|row| row.iter())
        .filter(|p| in_crop(scan, crop, clean, p) && !p.clean.x.is_nan())
        .map(|p| moved.transform_point3(scan.pose.transform_point3(p.clean)))
        .collect()
}

/// Surface samples per m² and the radius, m, of the views' overlap (`output.overlap`).
const OVERLAP_DENSITY: f32 = 4e5;
const OVERLAP_RADIUS: f32 = 0.0025;

/// Row-major 4×4 matrix.
pub fn matrix(t: &Affine3A) -> [[f32; 4]; 4] {
    Mat4::from(*t).transpose().to_cols_array_2d()
}

impl Sample {
    /// Hands the buffer of this sample's last scan to the next scan made on this thread, its
    /// pages already mapped.
    pub(crate) fn recycle(self) {
        if let Some(scan) = self.views.into_iter().rev().find_map(|v| v.scan) {
            EARLIER.set(scan);
        }
    }

    /// The cell `view` was taken of.
    pub fn cell_of(&self, view: &View) -> &Cell {
        match (&self.reclamped, view.reclamped) {
            (Some(other), true) => other,
            _ => &self.cell,
        }
    }

    /// The file-name stem: index, variant and level, e.g. `000012_A1_noisy`.
    pub fn stem(&self) -> String {
        let variant = self.variant.map_or("motor".into(), |v| format!("{v:?}"));
        format!("{:06}_{variant}_{}", self.index, self.level.name())
    }

    /// The silhouettes in view `k` (which kept its scan) of the instances with a class under
    /// `scheme` (the sample's own), by instance id: made on the first call.
    pub fn silhouettes(&self, k: usize, scheme: Scheme) -> &BTreeMap<u32, Silhouette> {
        let view = &self.views[k];
        view.silhouettes.get_or_init(|| {
            let Some(scan) = view.scan.as_ref() else {
                return BTreeMap::new();
            };
            let cell = self.cell_of(view);
            // each annotated instance's pieces (an assembled motor's parts under objects9)
            let mut pieces: BTreeMap<u32, Vec<Target>> = (cell.objects.iter())
                .filter(|o| o.class(scheme) != 0)
                .map(|o| (o.instance_in(scheme), Vec::new()))
                .collect();
            for t in cell.targets(scheme) {
                if let Some(p) = pieces.get_mut(&t.instance) {
                    p.push(t);
                }
            }
            pieces
                .into_par_iter()
                .map(|(id, pieces)| (id, Silhouette::of(&pieces, scan, &self.sensor)))
                .collect()
        })
    }

    /// View `k`'s COCO image (its colour image among `files`) and annotations, when `output`
    /// asks for them and the view kept its scan.
    fn coco(&self, k: usize, files: &[String], output: &OutputConfig) -> Option<CocoView> {
        if output.coco == CocoMasks::Off {
            return None;
        }
        let view = &self.views[k];
        let scan = view.scan.as_ref()?;
        let rgb = output.image_format.rgb_name();
        let file_name = files.iter().find(|f| f.ends_with(rgb))?.clone();
        let silhouettes = self.silhouettes(k, output.scheme);
        let silhouette = |instance: u32| silhouettes.get(&instance);
        let image = coco::Image {
            id: self.index * MAX_VIEWS + k as u64 + 1,
            file_name,
            width: scan.width as usize,
            height: scan.height as usize,
        };
        Some(coco::annotate(scan, image, output.coco, &silhouette))
    }

    /// Ground truth and provenance as a sample's JSON: motor parameters and attributes (motor
    /// frame), motor, fixture and camera poses, the sensor, crop box, level, split and seeds;
    /// `files` are each view's files.
    pub fn json(&self, recipe: &Recipe, files: &[Vec<String>]) -> SampleJson {
        let out = &recipe.config.output;
        let first = self.views[0].pose;
        let views = self
            .views
            .iter()
            .zip(files)
            .enumerate()
            .map(|(k, (v, files))| ViewJson {
                camera_to_world: matrix(&v.pose),
                motor_to_camera: matrix(&(v.pose.inverse() * self.cell_of(v).motor_to_world)),
                clamping: self.reclamped.as_ref().map(|_| self.cell_of(v).clamping),
                motor_to_world: self
                    .reclamped
                    .as_ref()
                    .map(|_| matrix(&self.cell_of(v).motor_to_world)),
                camera_to_first_camera: matrix(&(first.inverse() * v.pose)),
                noise_seed: v.noise_seed,
                points: v.cloud.len(),
                overlap: self.overlap.as_ref().map(|o| o[k].clone()),
                files: files.clone(),
                coco: self.coco(k, files, out),
            })
            .collect();
        let objects = self
            .cell
            .objects
            .iter()
            .map(|o| ObjectJson::of(o, out.scheme))
            .collect();
        SampleJson {
            index: self.index,
            seed: self.seed,
            variant: self.variant,
            level: self.level,
            split: self.split,
            sweep: recipe.sweep.iter().cloned().collect(),
            cover_removed: self.cover_removed,
            motor: motorgen::export::motor_json(&self.motor),
            motor_to_world: matrix(&self.cell.motor_to_world),
            fixture_shift: self.cell.fixture.iter().cloned().collect(),
            objects,
            crop: CropJson {
                min: self.crop.min,
                max: self.crop.max,
            },
            noise_scale: self.noise_scale,
            jitter: self.level.config(&recipe.config.augment).jitter,
            sensor: self.sensor.clone(),
            lighting: self.lighting.clone(),
            frame: out.frame,
            units: out.units,
            scheme: out.scheme,
            views,
        }
    }
}
