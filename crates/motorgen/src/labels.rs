//! Semantic label schemes: the SynMotor 7-class set (default), the WACV'23 6-class set and the
//! 10-class set with inner gears (cover removed), as data tables over [`PartKind`]; and two
//! sets of the image datasets: whole objects (motors, carriers, parts taken off) and the
//! armature's surfaces.

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
    /// Whole objects: an assembled motor one `motor`, a workpiece carrier, and the parts taken
    /// off a motor by kind (detection and instance segmentation for handling).
    #[serde(rename = "objects9")]
    Objects,
    /// The armature's surfaces: shaft, lamination stack, windings, commutator; everything else
    /// background.
    #[serde(rename = "armature5")]
    Armature,
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

static OBJECTS: [ClassInfo; 9] = [
    BG,
    ClassInfo {
        id: 1,
        name: "motor",
        color: [255, 140, 0],
    },
    ClassInfo {
        id: 2,
        name: "carrier",
        color: [70, 130, 180],
    },
    ClassInfo {
        id: 3,
        name: "cover",
        color: [0, 100, 0],
    },
    ClassInfo {
        id: 4,
        name: "gear_container",
        color: [0, 255, 0],
    },
    ClassInfo {
        id: 5,
        name: "pole_pot",
        color: [255, 165, 0],
    },
    ClassInfo {
        id: 6,
        name: "bolt",
        color: [255, 0, 0],
    },
    ClassInfo {
        id: 7,
        name: "gear",
        color: [224, 255, 255],
    },
    ClassInfo {
        id: 8,
        name: "armature",
        color: [184, 115, 51],
    },
];
static ARMATURE: [ClassInfo; 5] = [
    BG,
    ClassInfo {
        id: 1,
        name: "shaft",
        color: [192, 192, 192],
    },
    ClassInfo {
        id: 2,
        name: "lamination_stack",
        color: [70, 70, 90],
    },
    ClassInfo {
        id: 3,
        name: "windings",
        color: [184, 115, 51],
    },
    ClassInfo {
        id: 4,
        name: "commutator",
        color: [255, 215, 0],
    },
];

/// Label of each part kind, in [`PartKind::ALL`] order: pole pot, magnet, armature, electric
/// connection, gear container, cover, side bolt, cover bolt, lower, upper and single gear.
/// Magnets and armature sit inside the pot and take its label; with the cover on, the inner
/// gears are hidden under it and take the cover's label (as SynMotor did). Under `objects9` a
/// part taken off its motor (the pole pot with its magnets and connection); under `armature5`
/// no part: the armature's surfaces are labelled apart ([`Scheme::armature_surface`]).
static MAPS: [(Scheme, [u8; 11]); 5] = [
    (Scheme::SynMotor, [4, 4, 4, 3, 2, 1, 5, 6, 1, 1, 1]),
    (Scheme::Wacv, [4, 4, 4, 3, 2, 1, 5, 5, 1, 1, 1]),
    (Scheme::InnerParts, [4, 4, 4, 3, 2, 1, 5, 6, 8, 7, 9]),
    (Scheme::Objects, [5, 5, 8, 5, 4, 3, 6, 6, 7, 7, 7]),
    (Scheme::Armature, [0; 11]),
];

impl Scheme {
    /// All schemes.
    pub const ALL: [Scheme; 5] = [
        Scheme::SynMotor,
        Scheme::Wacv,
        Scheme::InnerParts,
        Scheme::Objects,
        Scheme::Armature,
    ];

    /// Its name in a configuration.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::SynMotor => "synmotor7",
            Scheme::Wacv => "wacv6",
            Scheme::InnerParts => "inner10",
            Scheme::Objects => "objects9",
            Scheme::Armature => "armature5",
        }
    }

    /// The classes, by id.
    pub fn classes(self) -> &'static [ClassInfo] {
        match self {
            Scheme::SynMotor => &SYNMOTOR,
            Scheme::Wacv => &WACV,
            Scheme::InnerParts => &INNER,
            Scheme::Objects => &OBJECTS,
            Scheme::Armature => &ARMATURE,
        }
    }

    /// The label of a part kind (under `objects9`, of the part taken off its motor).
    pub fn id(self, kind: PartKind) -> u8 {
        MAPS.iter()
            .find(|(s, _)| *s == self)
            .expect("every scheme has a map")
            .1[kind as usize]
    }

    /// The label of a part of kind `kind` on an assembled motor: `motor` under `objects9`, the
    /// part's own otherwise.
    pub fn assembled(self, kind: PartKind) -> u8 {
        match self {
            Scheme::Objects => 1,
            _ => self.id(kind),
        }
    }

    /// Whether a motor's parts are one instance, the whole motor (`objects9`).
    pub fn whole_motors(self) -> bool {
        self == Scheme::Objects
    }

    /// The label of a workpiece carrier: `carrier` under `objects9`, background otherwise.
    pub fn carrier(self) -> u8 {
        match self {
            Scheme::Objects => 2,
            _ => 0,
        }
    }

    /// The label of the armature's surface `k` (0 shaft, 1 lamination stack, 2 windings,
    /// 3 commutator): its own under `armature5`; otherwise the armature's.
    pub fn armature_surface(self, k: usize) -> u8 {
        match self {
            Scheme::Armature => k as u8 + 1,
            _ => self.id(PartKind::Armature),
        }
    }
}
