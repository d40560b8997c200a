//! Zivid's processing settings (`Settings.Processing`): the filters the model applies.

use serde::{Deserialize, Serialize};

/// Zivid's processing settings (`Settings.Processing`), those the model makes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Processing {
    /// `Processing.Filters`.
    pub filters: Filters,
}

/// `Processing.Filters`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Filters {
    /// `Processing.Filters.Noise`.
    pub noise: NoiseFilter,
    /// `Processing.Filters.Outlier`.
    pub outlier: OutlierFilter,
    /// `Processing.Filters.Reflection`.
    pub reflection: ReflectionFilter,
    /// `Processing.Filters.Cluster`.
    pub cluster: ClusterFilter,
    /// `Processing.Filters.Hole`.
    pub hole: HoleFilter,
    /// `Processing.Filters.Smoothing`.
    pub smoothing: Smoothing,
    /// `Processing.Filters.Experimental`.
    pub experimental: ExperimentalFilters,
}

/// `Processing.Filters.Experimental`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ExperimentalFilters {
    /// `Processing.Filters.Experimental.ContrastDistortion`.
    pub contrast_distortion: ContrastDistortion,
}

/// `Processing.Filters.Experimental.ContrastDistortion`: what Zivid does against the contrast
/// distortion (see [`Wings`](crate::noise::Wings)), on the points of a smooth surface pulled by
/// a step of brightness within the blur (no depth edge, no dark pixel within its reach). Zivid
/// estimates the pull from its images; the model takes it as the distance between the decoded
/// column and the point's own, in camera pixels of disparity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContrastDistortion {
    /// `...Correction`: moves each such point back towards its surface by `strength` (0 to 1)
    /// of its pull.
    pub correction: Correction,
    /// `...Removal`: removes the points whose pull is large; a higher `threshold` (0 to 1)
    /// removes more, as Zivid's: those pulled more than (1 − `threshold`) × the blur's σ
    /// (`noise.wings.psf_px`) pixels.
    pub removal: Removal,
}

/// `Processing.Filters.Experimental.ContrastDistortion.Correction`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Correction {
    /// Whether the filter runs.
    pub enabled: bool,
    /// The share of the pull taken back, 0 to 1.
    pub strength: f32,
}

impl ContrastDistortion {
    /// Whether either filter runs.
    pub fn is_on(&self) -> bool {
        self.correction.enabled || self.removal.enabled
    }

    /// The column a point pulled from its own column `own` to `decoded` keeps after the
    /// filters, or `None` where the removal takes it; `fx` is the camera's focal length in
    /// pixels (pixels per column), `blur_px` the blur's σ in pixels.
    #[inline]
    pub fn filter(&self, decoded: f32, own: f32, fx: f32, blur_px: f32) -> Option<f32> {
        let pull_px = (decoded - own).abs() * fx;
        if self.removal.enabled && pull_px > (1.0 - self.removal.threshold) * blur_px {
            return None;
        }
        let strength = if self.correction.enabled {
            self.correction.strength
        } else {
            0.0
        };
        Some(decoded + strength * (own - decoded))
    }
}

/// `Processing.Filters.Hole`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HoleFilter {
    /// `Processing.Filters.Hole.Repair`.
    pub repair: HoleRepair,
}

/// `Processing.Filters.Hole.Repair`: fills small holes. A pixel without a point gets one when
/// points lie, along its row and its column, on at least `strictness` of its four sides within
/// the widest hole filled, and on both sides along the row or the column: on its own ray at the
/// inverse depth interpolated between the two sides (exact on a plane; the mean of the row's
/// and the column's where both have two), with its own surface's labels, or the nearest side's
/// where it sees none, and the nearest side's colour. As Zivid's, the widest hole grows with
/// the distance: `hole_size` × [`HoleRepair::SCALE`] × the distance (12 mm at 0.6 m for 0.2),
/// the same number of pixels at any depth.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HoleRepair {
    /// Whether the filter runs.
    pub enabled: bool,
    /// The widest hole filled, relative to its distance (0 to 1: up to [`HoleRepair::SCALE`]
    /// of it).
    pub hole_size: f32,
    /// How many of the four sides must hold a point (1 to 4).
    pub strictness: u32,
}

impl HoleRepair {
    /// The widest hole `hole_size` 1 fills, as a share of its distance. Zivid states only that
    /// the size is relative and scales with the distance; a tenth is our assumption, which
    /// keeps the default's holes to a few millimetres at a Zivid's working distances.
    pub const SCALE: f32 = 0.1;

    /// The widest hole filled, in pixels of a camera of focal length `fx` pixels.
    pub fn widest_px(&self, fx: f64) -> usize {
        (f64::from(self.hole_size * Self::SCALE) * fx) as usize
    }
}

impl Default for HoleRepair {
    /// Zivid's values, off.
    fn default() -> HoleRepair {
        HoleRepair {
            enabled: false,
            hole_size: 0.2,
            strictness: 2,
        }
    }
}

/// `Processing.Filters.Cluster`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ClusterFilter {
    /// `Processing.Filters.Cluster.Removal`.
    pub removal: ClusterRemoval,
}

/// `Processing.Filters.Cluster.Removal`: removes the clusters of points whose area is below
/// `min_area`, a cluster being the points joined through neighbouring pixels (8 around each)
/// whose points lie within `max_neighbor_distance` of each other, a distance normalised as
/// Zivid's: in spacings of neighbouring pixels' points at the point's depth (its depth over the
/// focal length), so that it joins the same surfaces near and far; a point's area is its
/// pixel's footprint at its depth, as the camera sees it. It removes floating blobs (ghosts,
/// wings cut off from their surface) and keeps surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ClusterRemoval {
    /// Whether the filter runs.
    pub enabled: bool,
    /// The largest distance between neighbouring points of one cluster, in spacings of
    /// neighbouring pixels' points at the point's depth (Zivid's guide: 4 to 10).
    pub max_neighbor_distance: f32,
    /// The smallest area a cluster keeps, mm².
    pub min_area: f32,
}

impl Default for ClusterRemoval {
    /// Zivid's values, off.
    fn default() -> ClusterRemoval {
        ClusterRemoval {
            enabled: false,
            max_neighbor_distance: 10.0,
            min_area: 100.0,
        }
    }
}

/// `Processing.Filters.Reflection`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReflectionFilter {
    /// `Processing.Filters.Reflection.Removal`.
    pub removal: ReflectionRemoval,
}

/// `Processing.Filters.Reflection.Removal`: removes the points whose light came from more than
/// one surface (a surface's own light makes its patterns agree; the mirrored light of another
/// surface, or the light of both sides of an edge, does not), by the test of its `mode`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReflectionRemoval {
    /// Whether the filter runs.
    pub enabled: bool,
    /// Which test finds the mixed light.
    pub mode: ReflectionMode,
}

/// `Processing.Filters.Reflection.Removal.Mode`. Zivid describes what each mode keeps, not its
/// tests; those here key on what the patterns show of light from elsewhere and on where the
/// points lie, at thresholds assumed so that each mode behaves as Zivid describes it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReflectionMode {
    /// Zivid's default, over the whole frame: a point goes where light from elsewhere is
    /// more than half of what its pixel receives, or where its light shows other surfaces'
    /// and it lies in front of another point on the same ray of the projector's light, or
    /// behind one whose light is its own (had its surface been there, it would have shadowed
    /// the other, which the projector lit, or lain in its shadow). A ghost floating before the
    /// surfaces the projector lights behind it goes; one with nothing measured on its ray
    /// stays (Zivid: a smaller ghost plane), and so does the true surface.
    #[default]
    Global,
    /// Each pixel on its own: a point goes where more than a quarter of its light comes from
    /// elsewhere, or where its patterns' unwrapping is ambiguous. It removes the ghost plane,
    /// and with it more of a mirroring surface's points (Zivid: no ghost plane). What Zivid
    /// says it keeps better (thin and pointy objects) is not modelled.
    Local,
}

impl ReflectionRemoval {
    /// Whether the filter removes a point whose patterns' columns disagree by `mismatch`
    /// periods (0 to 0.5: how far the coarser pattern's column falls from the finer one's
    /// nearest solution, the ambiguity of the unwrapping) and whose own surface sends `direct`
    /// of its light (0 to 1). A camera sees the latter as the finest stripes' modulation
    /// against the coarsest pattern's: light from elsewhere arrives blurred (by a mirror's
    /// lobe, a bounce, the lens) and brings the coarse pattern without the finest stripes, as
    /// in the separation of direct and global light by high-frequency patterns.
    #[inline]
    pub fn removes(&self, mismatch: f32, direct: f32) -> bool {
        const AMBIGUOUS: f32 = 0.25;
        self.enabled
            && match self.mode {
                ReflectionMode::Global => direct < 0.5,
                ReflectionMode::Local => mismatch > AMBIGUOUS || direct < 0.75,
            }
    }

    /// Whether the filter also removes the points of mixed light that a point on the same ray
    /// of the projector's light contradicts (the global mode's test over the frame).
    pub fn removes_shadowing(&self) -> bool {
        self.enabled && self.mode == ReflectionMode::Global
    }
}

/// `Processing.Filters.Outlier`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutlierFilter {
    /// `Processing.Filters.Outlier.Removal`: removes the points none of whose 8 neighbours
    /// lies within `threshold` millimetres.
    pub removal: Removal,
}

/// `Processing.Filters.Smoothing`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Smoothing {
    /// `Processing.Filters.Smoothing.Gaussian`.
    pub gaussian: Gaussian,
}

/// `Processing.Filters.Smoothing.Gaussian`: each point's depth becomes the Gaussian-weighted
/// mean (σ `sigma` pixels, over the points within 2.5σ) of its neighbours', averaged as inverse
/// depth (exact on a plane), the point staying on its ray. It lowers the noise and rounds edges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Gaussian {
    /// Whether the filter runs.
    pub enabled: bool,
    /// σ of the weights, pixels.
    pub sigma: f32,
}

/// `Processing.Filters.Noise`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseFilter {
    /// `Processing.Filters.Noise.Removal`.
    pub removal: Removal,
    /// `Processing.Filters.Noise.Repair`.
    pub repair: Repair,
    /// `Processing.Filters.Noise.Suppression`.
    pub suppression: Suppression,
}

/// `Processing.Filters.Noise.Suppression`: smooths where the signal is weak. Each point whose
/// SNR is below [`Suppression::BELOW`] takes the mean inverse depth of the points in the 5×5
/// pixels around it that lie within 3σ of its depth (σ its SNR's range deviation, so a depth
/// step stays sharp), staying on its ray: a dark, far or grazing surface's noise falls by up
/// to 5×, a well lit one's is untouched. Zivid describes the filter (noise reduced in low-SNR
/// regions) but not its kernel; the window and the level are assumed. It needs the SNR model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Suppression {
    /// Whether the filter runs.
    pub enabled: bool,
}

impl Suppression {
    /// The SNR below which a point is smoothed (a white surface at the focus distance has
    /// about 75, Zivid's noise filter removes below 7).
    pub const BELOW: f32 = 20.0;
}

/// `Processing.Filters.Noise.Repair`: gives the points the noise filter removed back where
/// their neighbours are a surface: a pixel whose surface the projector lights, removed for its
/// SNR, with points in at least 6 of its 8 neighbours, gets a point on its own ray at their
/// mean inverse depth (their colour's mean). A removed region wider than a pixel stays empty
/// but for its rim.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Repair {
    /// Whether the filter runs.
    pub enabled: bool,
}

/// A filter that removes points by a threshold. `Processing.Filters.Noise.Removal` removes the
/// points whose SNR ([`Snr`](crate::noise::Snr)) is below `threshold` (on a sensor that measures an SNR: with the
/// SNR model off, it removes nothing); `Processing.Filters.Outlier.Removal` those farther than
/// `threshold` millimetres from all their neighbours.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Removal {
    /// Whether the filter runs.
    pub enabled: bool,
    /// The threshold.
    pub threshold: f32,
}

impl Removal {
    /// Whether the noise filter removes a point of SNR `value`.
    #[inline]
    pub fn removes(&self, value: f32) -> bool {
        self.enabled && value < self.threshold
    }
}
