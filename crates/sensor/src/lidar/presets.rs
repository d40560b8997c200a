//! The LiDAR presets: Blensor's scanners with Blensor's tables and defaults, and the Velodyne
//! VLP-16 from Velodyne's manual.

use super::{Beam, Laser, Lidar, RangeNoise, ReflectivityLimit};
use crate::Error;

/// Names of the LiDAR presets.
pub const LIDAR_PRESETS: [&str; 5] = [
    "velodyne-hdl64e-s2",
    "velodyne-hdl32e",
    "velodyne-vlp16",
    "ibeo-lux",
    "generic-lidar",
];

/// Elevations of the HDL-64E S2's lasers, degrees, in Blensor's order (`blendodyne.py`).
const HDL64E_ELEVATION: [f64; 64] = [
    -7.1143909,
    -6.8259001,
    0.33287099,
    0.66078597,
    -6.4908152,
    -6.0973902,
    -8.5282297,
    -8.1613369,
    -5.8425112,
    -5.4713659,
    -7.8512449,
    -7.5291781,
    -3.049051,
    -2.7686839,
    -5.053277,
    -4.7975101,
    -2.382966,
    -2.114002,
    -4.4367881,
    -4.0757122,
    -1.727937,
    -1.447062,
    -3.7842851,
    -3.4226439,
    1.023782,
    1.339875,
    -0.99049801,
    -0.69775897,
    1.690992,
    1.971796,
    -0.346425,
    -0.041912999,
    -22.617477,
    -22.217125,
    -11.351527,
    -10.776211,
    -21.743774,
    -21.196053,
    -24.893286,
    -24.263714,
    -20.664749,
    -20.016045,
    -23.745707,
    -23.065102,
    -16.414013,
    -16.014454,
    -19.424471,
    -19.10091,
    -15.493717,
    -15.014058,
    -18.650002,
    -18.154394,
    -14.466367,
    -13.827651,
    -17.592127,
    -16.994211,
    -10.334768,
    -9.8352394,
    -13.229812,
    -12.896399,
    -9.3798056,
    -8.8888798,
    -12.372269,
    -11.969375,
];

/// Elevations of the HDL-32E's lasers, degrees, in Blensor's order.
const HDL32E_ELEVATION: [f64; 32] = [
    -30.67, -9.33, -29.33, -8.00, -28.00, -6.66, -26.66, -5.33, -25.33, -4.00, -24.00, -2.67,
    -22.67, -1.33, -21.33, 0.00, -20.00, 1.33, -18.67, 2.67, -17.33, 4.00, -16.00, 5.33, -14.67,
    6.67, -13.33, 8.00, -12.00, 9.33, -10.67, 10.67,
];

/// Blensor's fixed per-laser distance bias of the Velodynes, metres (`laser_noise` in
/// `blendodyne.py`, drawn once and kept "to increase reproducibility"); the HDL-32E takes the
/// first 32.
pub const BLENSOR_VELODYNE_BIAS: [f64; 64] = [
    0.023188431056485468,
    0.018160539830319688,
    -0.08285723360737558,
    -0.06452469832091855,
    -0.09327124611469362,
    0.04352764310036168,
    0.02964170651252759,
    0.022130151884228375,
    0.05714245613479812,
    -0.002290238031712285,
    0.0067235936679492184,
    -0.036271973173879445,
    0.017223035592365758,
    -0.07756703783267055,
    -0.04521253001832192,
    -0.07140735548884795,
    -0.044010545427414234,
    -0.13100196824243787,
    0.06562213285464942,
    0.07287654541774659,
    0.02948486101287804,
    -0.0549980634164711,
    0.001721507479775233,
    0.011024793340907989,
    -0.031627028532767984,
    -0.0015734962901194415,
    -0.03601332165911542,
    0.10758083132777119,
    -0.08155406184051478,
    0.04264361386913222,
    -0.008450715931720207,
    -0.1350968035459306,
    -0.01162640766314254,
    -0.016650248443238872,
    -0.0893909190933353,
    0.058944202109090765,
    -0.0017922326055001933,
    0.17981608947109032,
    -0.08508532554265108,
    0.07314373637204877,
    -0.04811541098744136,
    -0.04270486123969266,
    0.03508649681745952,
    0.06494360761118374,
    0.010321640735410247,
    -0.08802728578853733,
    0.06492791261718271,
    -0.006307354405539431,
    0.009423603609125905,
    -0.012188267349634907,
    -0.030570059320519608,
    -0.02288379575521943,
    -0.01536736072143652,
    0.09157097246582177,
    -0.09083766812058082,
    0.14380982060713934,
    0.01373428104250375,
    -0.014464880110123654,
    -0.031761209027541266,
    -0.01571113598069827,
    -0.14107381715154735,
    -0.06493675076477023,
    0.03491182077008233,
    0.06568249229806342,
];

/// Blensor's per-laser bias of the Ibeo LUX's four layers, metres.
const IBEO_BIAS: [f64; 4] = [
    0.015798891682948433,
    0.03028971193744648,
    0.04483226389561547,
    0.02262836122311112,
];

/// Blensor's bias of the generic LiDAR's one laser, metres.
const GENERIC_BIAS: f64 = 0.015798891682948433;

/// The VLP-16's elevations in firing order, degrees (Velodyne's VLP-16 manual, table 9-1).
const VLP16_ELEVATION: [f64; 16] = [
    -15.0, 1.0, -13.0, 3.0, -11.0, 5.0, -9.0, 7.0, -7.0, 9.0, -5.0, 11.0, -3.0, 13.0, -1.0, 15.0,
];

/// Vertical corrections of the VLP-16's lasers, in firing order, millimetres: each laser's
/// origin above the head's centre (its manual's table of laser angles).
const VLP16_OFFSET_MM: [f64; 16] = [
    11.2, -0.7, 9.7, -2.2, 8.1, -3.7, 6.6, -5.1, 5.1, -6.6, 3.7, -8.1, 2.2, -9.7, 0.7, -11.2,
];

/// Time between two of the VLP-16's firings, seconds (its manual: 2.304 µs).
const VLP16_FIRING: f32 = 2.304e-6;

/// Blensor's reflectivity limit: 0.1 from 50 m on, growing by `slope` a metre.
const fn blensor_limit(slope: f32) -> ReflectivityLimit {
    ReflectivityLimit {
        distance: 50.0,
        limit: 0.1,
        slope,
    }
}

impl Lidar {
    /// The preset called `name` (see [`LIDAR_PRESETS`]).
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] naming the presets if there is none of that name.
    pub fn preset(name: &str) -> Result<Lidar, Error> {
        let lasers = |elevations: &[f64], bias: &[f64], delay: f32| -> Vec<Laser> {
            elevations
                .iter()
                .enumerate()
                .map(|(i, &elevation)| Laser {
                    elevation: elevation as f32,
                    bias: bias.get(i).map_or(0.0, |&b| b as f32),
                    delay: i as f32 * delay,
                    offset: 0.0,
                })
                .collect()
        };
        let gaussian = |sigma: f32| RangeNoise {
            mu: 0.0,
            sigma,
            table: Vec::new(),
        };
        // Blensor's Velodyne defaults (`blendodyne.py`): 0.1728° steps at 10 Hz to 120 m
        let velodyne = |name: &str, lasers: Vec<Laser>| Lidar {
            name: name.into(),
            lasers,
            start: 0.0,
            end: 360.0,
            resolution: 0.1728,
            rotation: 10.0,
            max_range: 120.0,
            noise: gaussian(0.01),
            reflectivity: blensor_limit(0.01),
            beam: Beam::default(),
        };
        Ok(match name {
            "velodyne-hdl64e-s2" => {
                velodyne(name, lasers(&HDL64E_ELEVATION, &BLENSOR_VELODYNE_BIAS, 0.0))
            }
            "velodyne-hdl32e" => {
                velodyne(name, lasers(&HDL32E_ELEVATION, &BLENSOR_VELODYNE_BIAS, 0.0))
            }
            // Velodyne's figures: 0.2° steps at 10 Hz, 100 m, ±3 cm; Blensor's Velodyne limit
            "velodyne-vlp16" => Lidar {
                resolution: 0.2,
                max_range: 100.0,
                noise: gaussian(0.03),
                ..velodyne(name, {
                    let mut lasers = lasers(&VLP16_ELEVATION, &[], VLP16_FIRING);
                    for (laser, mm) in lasers.iter_mut().zip(VLP16_OFFSET_MM) {
                        laser.offset = (mm * 1e-3) as f32;
                    }
                    lasers
                })
            },
            // Blensor's `ibeo.py`: four layers 0.8° apart, -50° to 35° in 0.25° steps, 12.5 Hz
            "ibeo-lux" => Lidar {
                name: name.into(),
                lasers: lasers(&[1.6, 0.8, -0.8, -1.6], &IBEO_BIAS, 0.0),
                start: -50.0,
                end: 35.0,
                resolution: 0.25,
                rotation: 12.5,
                max_range: 90.0,
                noise: gaussian(0.03),
                reflectivity: blensor_limit(0.005_333_333),
                beam: Beam::default(),
            },
            // Blensor's `generic_lidar.py`, preconfigured as a Hokuyo UTM-30LX
            "generic-lidar" => Lidar {
                name: name.into(),
                lasers: lasers(&[0.0], &[GENERIC_BIAS], 0.0),
                start: -135.0,
                end: 135.0,
                resolution: 0.25,
                rotation: 40.0,
                max_range: 30.0,
                noise: gaussian(0.03),
                reflectivity: blensor_limit(0.005_333_333),
                beam: Beam::default(),
            },
            _ => {
                return Err(Error::Invalid {
                    key: "sensor".into(),
                    value: name.into(),
                    allowed: format!("a LiDAR preset: {}", LIDAR_PRESETS.join(", ")),
                });
            }
        })
    }
}
