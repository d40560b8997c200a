//! Semantic label schemes: the SynMotor 7-class set (default), the WACV'23 6-class set and the
//! 10-class set with inner gears (cover removed), as data tables over [`PartKind`].

use serde::{Deserialize, Serialize};

use crate::model::PartKind;

/// A class of a scheme.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ClassInfo {
    /// Label id.
    pub id: u8,
    /// Name as in the original datasets.
    pub name: &'static str,
    /// Display colour (the AgiProbot colour map).
    pub color: [u8; 3],
}

/// A label scheme.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Scheme {
    /// SynMotor: background, cover, gear container, charger, bottom, side bolt, cover bolt.
    #[default]
    #[serde(rename = "synmotor7")]
    SynMotor,
    /// WACV'23: side and cover bolts merged into one bolt class.
    #[serde(rename = "wacv6")]
    Wacv,
    /// SynMotor plus upper gear A, lower gear A and gear B, for cover-removed scenes.
    #[serde(rename = "inner10")]
    InnerParts,
}

const BG: ClassInfo = ClassInfo {
    id: 0,
    name: "background",
    color: [0, 0, 128],
};
const COVER: ClassInfo = ClassInfo {
    id: 1,
    name: "cover",
    color: [0, 100, 0],
};
const CONTAINER: ClassInfo = ClassInfo {
    id: 2,
    name: "gear_container",
    color: [0, 255, 0],
};
const CHARGER: ClassInfo = ClassInfo {
    id: 3,
    name: "charger",
    color: [255, 255, 0],
};
const BOTTOM: ClassInfo = ClassInfo {
    id: 4,
    name: "bottom",
    color: [255, 165, 0],
};
const SIDE_BOLT: ClassInfo = ClassInfo {
    id: 5,
    name: "side_bolt",
    color: [255, 0, 255],
};
const COVER_BOLT: ClassInfo = ClassInfo {
    id: 6,
    name: "cover_bolt",
    color: [255, 0, 0],
};

static SYNMOTOR: [ClassInfo; 7] = [BG, COVER, CONTAINER, CHARGER, BOTTOM, SIDE_BOLT, COVER_BOLT];
static WACV: [ClassInfo; 6] = [
    BG,
    COVER,
    CONTAINER,
    CHARGER,
    BOTTOM,
    ClassInfo {
        id: 5,
        name: "bolt",
        color: [255, 0, 0],
    },
];
static INNER: [ClassInfo; 10] = [
    BG,
    COVER,
    CONTAINER,
    CHARGER,
    BOTTOM,
    SIDE_BOLT,
    COVER_BOLT,
    ClassInfo {
        id: 7,
        name: "upper_gear_a",
        color: [224, 255, 255],
    },
    ClassInfo {
        id: 8,
        name: "lower_gear_a",
        color: [255, 228, 255],
    },
    ClassInfo {
        id: 9,
        name: "gear_b",
        color: [230, 230, 255],
    },
];

/// Label of each part kind, in [`PartKind::ALL`] order: pole pot, magnet, armature, electric
/// connection, gear container, cover, side bolt, cover bolt, lower, upper and single gear.
/// Magnets and armature sit inside the pot and take its label; with the cover on, the inner
/// gears are hidden under it and take the cover's label (as SynMotor did).
static MAPS: [(Scheme, [u8; 11]); 3] = [
    (Scheme::SynMotor, [4, 4, 4, 3, 2, 1, 5, 6, 1, 1, 1]),
    (Scheme::Wacv, [4, 4, 4, 3, 2, 1, 5, 5, 1, 1, 1]),
    (Scheme::InnerParts, [4, 4, 4, 3, 2, 1, 5, 6, 8, 7, 9]),
];

impl Scheme {
    /// All schemes.
    pub const ALL: [Scheme; 3] = [Scheme::SynMotor, Scheme::Wacv, Scheme::InnerParts];

    /// Its name in a configuration.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::SynMotor => "synmotor7",
            Scheme::Wacv => "wacv6",
            Scheme::InnerParts => "inner10",
        }
    }

    /// The classes, by id.
    pub fn classes(self) -> &'static [ClassInfo] {
        match self {
            Scheme::SynMotor => &SYNMOTOR,
            Scheme::Wacv => &WACV,
            Scheme::InnerParts => &INNER,
        }
    }

    /// The label of a part kind.
    pub fn id(self, kind: PartKind) -> u8 {
        MAPS.iter()
            .find(|(s, _)| *s == self)
            .expect("every scheme has a map")
            .1[kind as usize]
    }
}
