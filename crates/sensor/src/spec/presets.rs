//! The sensor presets: Zivid's cameras, Blensor's scanners and an ideal camera, with their
//! sources.

use super::{
    Calibration, ClusterFilter, ClusterRemoval, ColourCamera, ColourCapture, ContrastDistortion,
    Correction, ExperimentalFilters, Filters, Gaussian, HoleFilter, HoleRepair, Model, NoiseFilter,
    OutlierFilter, Processing, Projector, ReflectionFilter, ReflectionMode, ReflectionRemoval,
    Removal, Repair, Sampling, SensorSpec, Smoothing, Suppression,
};
use crate::Error;
use crate::camera::{Distortion, Intrinsics};
use crate::noise::{Axial, Correlated, Interreflection, Noise, Snr, Specular, Wings};

/// The preset names.
pub const PRESETS: [&str; 14] = [
    "zivid-one-plus-m",
    "zivid-2-m70",
    "zivid-2-l100",
    "zivid-2plus-m60",
    "zivid-2plus-m130",
    "zivid-2plus-l110",
    "zivid-2plus-mr60",
    "zivid-2plus-mr130",
    "zivid-2plus-lr110",
    "blensor-tof",
    "kinect-v1",
    "realsense-d435-rgb",
    "industrial-5mp",
    "ideal",
];

/// A colour camera's image: lit by the room (it has no light of its own), the lens's
/// vignetting and aperture, the imager's pixel pitch; focused at `focus`.
const fn room_lit(
    noise: f32,
    vignetting: f32,
    f_number: f32,
    focus: f32,
    pixel_um: f32,
) -> ColourCamera {
    ColourCamera {
        capture: ColourCapture::TwoDThreeD,
        monochrome: false,
        exposure: 0.0,
        ambient: 0.5,
        ambient_kelvin: 4000.0,
        gain: 1.0,
        white_balance: [1.0, 1.0],
        noise,
        offset: [0.0; 3],
        flash: false,
        vignetting,
        f_number,
        focus,
        pixel_um,
    }
}

/// The Kinect v1's RGB camera, registered to its depth: 2.5 cm from the infrared camera towards
/// the projector, lit by the room (the infrared pattern does not show), noisier than a Zivid's.
const KINECT_RGB: ColourCamera = ColourCamera {
    offset: [0.025, 0.0, 0.0],
    ..room_lit(0.02, 0.0, 0.0, 1.0, 5.2)
};

/// Zivid 2: the camera's and the projector's full resolution.
const ZIVID_2: ([u32; 2], [f32; 2]) = ([1944, 1200], [1280.0, 720.0]);
/// Zivid 2+: the camera's and the projector's full resolution.
const ZIVID_2PLUS: ([u32; 2], [f32; 2]) = ([2448, 2048], [1000.0, 720.0]);

/// The camera and projector of a Zivid of `line` (its resolutions), as Zivid's own simulation
/// describes them: a camera lens of `focal_px` (principal point at the centre), the projector
/// `baseline_mm` along camera +x turned `toe` radians towards the camera's axis, its lens of
/// `projector_focal_px` in 4×4-binned projector pixels giving its field.
fn zivid2(
    line: ([u32; 2], [f32; 2]),
    focal_px: f64,
    baseline_mm: f32,
    toe: f32,
    projector_focal_px: f32,
) -> (Intrinsics, Projector) {
    let ([width, height], [pw, ph]) = line;
    let field = |pixels: f32| 2.0 * (pixels / 8.0 / projector_focal_px).atan().to_degrees();
    let baseline = baseline_mm * 1e-3;
    (
        Intrinsics {
            width,
            height,
            fx: focal_px,
            fy: focal_px,
            cx: f64::from(width / 2),
            cy: f64::from(height / 2),
            distortion: Distortion::default(),
        },
        Projector {
            baseline,
            convergence: baseline / toe.tan(),
            hfov_deg: field(pw),
            vfov_deg: field(ph),
        },
    )
}

/// Zivid-like noise: range noise from the pattern's SNR, half its variance correlated along
/// the stripes over 4 pixels (assumed: Zivid publishes no correlation length), highlights that
/// saturate at 4 times a white surface's signal (an exposure that puts white at a quarter of
/// the range: assumed), wings at edges from a blur of σ 1.5 px (assumed) with 64 stripes across the
/// projector's field. A pixel collects 4000 electrons of modulation from a white
/// surface facing the projector at the focus distance, over 15 % ambient light and 10 electrons
/// of read noise (SNR 58), and its disparity errs by 3.57 px / SNR: on the Zivid 2+ M60 at
/// 0.6 m that is 0.080 mm, Zivid's point precision for the M60.
fn zivid_noise() -> Noise {
    Noise {
        snr: Snr {
            electrons: 4000.0,
            ambient: 0.15,
            read_electrons: 10.0,
            disparity_px: 3.57,
        },
        correlated: Correlated {
            share: 0.5,
            length_px: 4.0,
        },
        specular: Specular { saturation: 4.0 },
        wings: Wings {
            psf_px: 1.5,
            stripes: 64.0,
        },
        interreflection: Interreflection {
            enabled: true,
            diffuse_reach: 0.05,
        },
        ..Noise::default()
    }
}

/// Zivid's calibration error: scale within its dimension trueness (< 0.2 %: σ 0.05 %), warp
/// within its global planarity (0.10 mm at 0.6 m: σ 0.004 % of the depth a coefficient).
const ZIVID_CALIBRATION: Calibration = Calibration {
    seed: 0,
    scale: 5e-4,
    warp: 4e-5,
};

/// Zivid's noise filter at the SNR Zivid names as the least for good precision (7), its
/// reflection filter on and its contrast-distortion correction on at strength 0.3 (removal off
/// at 0.2), its cluster filter off at 10 mm and 100 mm² and its hole repair off at 0.2 and
/// strictness 2, as Zivid's settings data model
/// has them (`zivid/zivid-python`, `test/test_data/datamodels/Settings.yml`). Zivid's outlier
/// filter and Gaussian smoothing are configured at Zivid's recommended values (5 mm; σ 1.5 px,
/// "for most conditions") but left off, and so are the noise filter's repair and suppression:
/// the noise model is calibrated to Zivid's published point precision, which does not say
/// whether it was filtered.
const ZIVID_PROCESSING: Processing = Processing {
    filters: Filters {
        noise: NoiseFilter {
            removal: Removal {
                enabled: true,
                threshold: 7.0,
            },
            repair: Repair { enabled: false },
            suppression: Suppression { enabled: false },
        },
        outlier: OutlierFilter {
            removal: Removal {
                enabled: false,
                threshold: 5.0,
            },
        },
        reflection: ReflectionFilter {
            removal: ReflectionRemoval {
                enabled: true,
                mode: ReflectionMode::Global,
            },
        },
        cluster: ClusterFilter {
            removal: ClusterRemoval {
                enabled: false,
                max_neighbor_distance: 10.0,
                min_area: 100.0,
            },
        },
        hole: HoleFilter {
            repair: HoleRepair {
                enabled: false,
                hole_size: 0.2,
                strictness: 2,
            },
        },
        smoothing: Smoothing {
            gaussian: Gaussian {
                enabled: false,
                sigma: 1.5,
            },
        },
        experimental: ExperimentalFilters {
            contrast_distortion: ContrastDistortion {
                correction: Correction {
                    enabled: true,
                    strength: 0.3,
                },
                removal: Removal {
                    enabled: false,
                    threshold: 0.2,
                },
            },
        },
    },
};

fn structured(projector: Projector) -> Model {
    Model::StructuredLight { projector }
}

impl SensorSpec {
    /// A preset by name (see [`PRESETS`]).
    ///
    /// Sources and assumptions:
    /// - Zivid 2 and 2+ (M70, L100, M60, L110, M130 and the R line's MR60, LR110, MR130, which
    ///   share the optics of M60, L110 and M130 and record a grey 2D image, Zivid's
    ///   `Settings2D` colour sampling `grayscale`): Zivid's own simulation of its cameras,
    ///   `zivid/zivid-isaac-sim` (`camera/camera_calibration.py`, `resolution.py`): the
    ///   camera's focal length (M70 1785, L100 1784, M60 2481, L110 2479, M130 4028 px) with
    ///   the principal point at the image centre and no distortion; the projector
    ///   111.2-111.9 mm along camera +x, turned 0.069-0.113 rad about camera y towards the
    ///   camera's axis, its focal length in 4×4-binned projector pixels (292, 292, 233, 232, 351)
    ///   over 1280×720 (Zivid 2) or 1000×720 (2+) pixels, which gives its field. Zivid also
    ///   places the projector 2.8-10.3 mm forward along camera z; this model keeps it in the
    ///   camera's plane (at 0.6 m that changes a shadow's width by about 1 %).
    /// - Working ranges: the recommended working distances in Zivid's sample
    ///   `auto_2d_settings.py` (`zivid/zivid-python-samples`): M60 0.3-1.1 m, M70 0.3-1.3 m,
    ///   L100 0.6-1.6 m, M130 0.8-2.0 m, L110 0.7-1.7 m (as its message states; the sample's own
    ///   check uses 0.8-2.0 m). `reference_range` is the model's focus distance.
    /// - `zivid-one-plus-m`: factory intrinsics found in public ZividUtils code (fx 2776.6,
    ///   cx 952.4, cy 597.9, k1 -0.28, k2 0.41, k3 -0.51); its projector and range are assumed
    ///   (0.15 m baseline, 45°×30°, 0.6-1.6 m).
    /// - Zivid noise: the SNR model calibrated to Zivid's point precision for the 2+ M60
    ///   (0.08 mm at 0.6 m, a third-party transcription of its datasheet); the noise filter at
    ///   SNR 7 ("SNR should be above 7 to yield good precision", Zivid's knowledge base); the
    ///   calibration error within Zivid's dimension trueness (< 0.2 %) and global planarity
    ///   (0.10 mm); the correlation along the stripes (half the variance over 4 pixels), the
    ///   lens's blur (σ 1.5 px, 64 stripes across the projector's field), the three unwrapping
    ///   steps (1, 8 and 64 periods across the field) and the reflection filter's tolerance (a
    ///   quarter of a period) are assumed; the mirror bounce follows each material's specular
    ///   share and lobe, the diffuse bounce each material's reflectivity, gathered within 5 cm
    ///   (assumed: the places it matters, inside corners and parts on the table, lie within it).
    /// - `blensor-tof`: Blensor's `tof` scanner as the MotorFactory datasets used it: 1280×960,
    ///   43.6°×34.6°, Gaussian range noise (0.6 mm, the middle of SynMotor's 0.2-1.2 mm); its
    ///   colour each material's own, unlit, as Blensor records it.
    /// - `kinect-v1`: Blensor's `kinect` parameters: 640×480, 55.64°×43.18°, baseline 0.075 m,
    ///   0.7-6 m, 1/8 px disparity, 9×9 window; disparity noise 1/6 px as SimKinect (Handa 2014);
    ///   the RGB camera 2.5 cm beside the infrared one, registered to its pixels, lit by the room.
    /// - `realsense-d435-rgb`: the Intel RealSense D435's colour camera (its datasheet: an
    ///   OmniVision OV2740, 1920×1080 pixels of 1.4 µm, 69.4°×42.5°, f/2.0, fixed focus,
    ///   distortion ≤ 1.5 %, rolling shutter): the fields give its focal length, the principal
    ///   point at the centre and no distortion (Intel calibrates each unit); its focus at 1 m,
    ///   its vignetting (a quarter of the light at the corners) and its noise (σ 0.015) are
    ///   assumed. Its depth is exact (the colour camera, not the stereo pair).
    /// - `industrial-5mp`: a generic industrial 5 MP C-mount camera, a 2/3" imager of
    ///   2448×2048 pixels of 3.45 µm (Sony IMX250/264 class) behind a 12 mm lens at f/4
    ///   (fx 3478 px, 38.8°×33.0°) focused at 0.8 m; its Brown–Conrady distortion (k1 -0.10,
    ///   k2 0.15, p1 1e-4, p2 -1e-4: about -1.5 % at the corners), vignetting (15 %) and noise
    ///   (σ 0.008) are assumed, typical of such lenses and imagers. Its depth is exact.
    /// - `ideal`: the Zivid 2+ M60 camera with no noise and no projector.
    ///
    /// # Errors
    ///
    /// [`Error::UnknownPreset`] for a name not in [`PRESETS`].
    ///
    /// # Example
    ///
    /// ```
    /// use sensor::{Model, SensorSpec};
    ///
    /// let m60 = SensorSpec::preset("zivid-2plus-m60")?;
    /// assert_eq!((m60.intrinsics.width, m60.intrinsics.height), (2448, 2048));
    /// assert!(matches!(m60.model, Model::StructuredLight { .. }));
    /// // Zivid's samplings for the M60; `by4x4` (4×4 binning) is the R line's
    /// assert_eq!(m60.sampled(sensor::Sampling::BlueSubsample4x4)?.intrinsics.width, 612);
    /// assert!(m60.sampled(sensor::Sampling::By4x4).is_err());
    /// assert!(SensorSpec::preset("zivid-3").is_err());
    /// # Ok::<(), sensor::Error>(())
    /// ```
    pub fn preset(name: &str) -> Result<SensorSpec, Error> {
        let spec =
            |name: &str, intrinsics, model, noise, range: (f32, f32), reference| SensorSpec {
                name: name.into(),
                intrinsics,
                model,
                noise,
                min_range: range.0,
                max_range: range.1,
                reference_range: reference,
                colour: ColourCamera::default(),
                calibration: Calibration::default(),
                processing: Processing::default(),
                samplings: Vec::new(),
            };
        let zivid = |(camera, projector), range, focus| SensorSpec {
            calibration: ZIVID_CALIBRATION,
            processing: ZIVID_PROCESSING,
            ..spec(
                name,
                camera,
                structured(projector),
                zivid_noise(),
                range,
                focus,
            )
        };
        let offering = |s: SensorSpec, samplings: &[Sampling]| SensorSpec {
            samplings: samplings.to_vec(),
            ..s
        };
        // the R line: a monochrome imager that bins
        let monochrome = |s: SensorSpec| SensorSpec {
            colour: ColourCamera {
                monochrome: true,
                ..s.colour
            },
            samplings: vec![Sampling::All, Sampling::By2x2, Sampling::By4x4],
            ..s
        };
        let plus = [
            Sampling::All,
            Sampling::BlueSubsample2x2,
            Sampling::RedSubsample2x2,
            Sampling::BlueSubsample4x4,
            Sampling::RedSubsample4x4,
        ];
        let m70 = || zivid2(ZIVID_2, 1785.0, 111.2, 0.113, 292.0);
        let l100 = || zivid2(ZIVID_2, 1784.0, 111.3, 0.112, 292.0);
        let m60 = || zivid2(ZIVID_2PLUS, 2481.0, 111.2, 0.085, 233.0);
        let m130 = || zivid2(ZIVID_2PLUS, 4028.0, 111.9, 0.069, 351.0);
        let l110 = || zivid2(ZIVID_2PLUS, 2479.0, 111.6, 0.087, 232.0);
        Ok(match name {
            "zivid-one-plus-m" => offering(
                zivid(
                    (
                        Intrinsics {
                            width: 1920,
                            height: 1200,
                            fx: 2776.6,
                            fy: 2776.6,
                            cx: 952.4,
                            cy: 597.9,
                            distortion: Distortion {
                                k1: -0.28,
                                k2: 0.41,
                                k3: -0.51,
                                p1: 0.0,
                                p2: 0.0,
                            },
                        },
                        Projector {
                            baseline: 0.15,
                            convergence: 1.0,
                            hfov_deg: 45.0,
                            vfov_deg: 30.0,
                        },
                    ),
                    (0.6, 1.6),
                    1.0,
                ),
                &[Sampling::All],
            ),
            "zivid-2-m70" => offering(zivid(m70(), (0.3, 1.3), 0.7), &plus[..3]),
            "zivid-2-l100" => offering(zivid(l100(), (0.6, 1.6), 1.0), &plus[..3]),
            "zivid-2plus-m60" => offering(zivid(m60(), (0.3, 1.1), 0.6), &plus),
            "zivid-2plus-m130" => offering(zivid(m130(), (0.8, 2.0), 1.3), &plus),
            "zivid-2plus-l110" => offering(zivid(l110(), (0.7, 1.7), 1.1), &plus),
            // the R line: the optics of M60, M130 and L110, a monochrome 2D imager
            "zivid-2plus-mr60" => monochrome(zivid(m60(), (0.3, 1.1), 0.6)),
            "zivid-2plus-mr130" => monochrome(zivid(m130(), (0.8, 2.0), 1.3)),
            "zivid-2plus-lr110" => monochrome(zivid(l110(), (0.7, 1.7), 1.1)),
            "blensor-tof" => SensorSpec {
                colour: ColourCamera {
                    capture: ColourCapture::Flat,
                    ..ColourCamera::default()
                },
                ..spec(
                    name,
                    Intrinsics::from_fov(1280, 960, 43.6, 34.6),
                    Model::TimeOfFlight,
                    Noise {
                        axial: Axial {
                            sigma: 6e-4,
                            ..Axial::default()
                        },
                        ..Noise::default()
                    },
                    (0.0, 2.0),
                    1.0,
                )
            },
            "kinect-v1" => SensorSpec {
                colour: KINECT_RGB,
                ..spec(
                    name,
                    Intrinsics::from_fov(640, 480, 55.64, 43.18),
                    Model::Kinect {
                        projector: Projector {
                            baseline: 0.075,
                            convergence: 2.0,
                            hfov_deg: 60.0,
                            vfov_deg: 47.0,
                        },
                        disparity_sigma_px: 1.0 / 6.0,
                        subpixel: 8.0,
                        window: 9,
                        window_fraction: 1.0 / 1.5,
                        inlier_distance: 0.1,
                    },
                    Noise::default(),
                    (0.7, 6.0),
                    1.5,
                )
            },
            "realsense-d435-rgb" => SensorSpec {
                colour: room_lit(0.015, 0.25, 2.0, 1.0, 1.4),
                ..spec(
                    name,
                    Intrinsics::from_fov(1920, 1080, 69.4, 42.5),
                    Model::Ideal,
                    Noise::default(),
                    (0.05, 20.0),
                    1.0,
                )
            },
            "industrial-5mp" => SensorSpec {
                colour: room_lit(0.008, 0.15, 4.0, 0.8, 3.45),
                ..spec(
                    name,
                    Intrinsics {
                        width: 2448,
                        height: 2048,
                        fx: 12.0 / 3.45e-3,
                        fy: 12.0 / 3.45e-3,
                        cx: 1223.5,
                        cy: 1023.5,
                        distortion: Distortion {
                            k1: -0.10,
                            k2: 0.15,
                            k3: 0.0,
                            p1: 1e-4,
                            p2: -1e-4,
                        },
                    },
                    Model::Ideal,
                    Noise::default(),
                    (0.05, 20.0),
                    0.8,
                )
            },
            "ideal" => spec(
                name,
                m60().0,
                Model::Ideal,
                Noise::default(),
                (0.0, 100.0),
                1.0,
            ),
            other => return Err(Error::UnknownPreset(other.into())),
        })
    }
}
