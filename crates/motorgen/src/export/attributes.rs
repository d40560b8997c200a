//! Ground truth as JSON (parameters and attributes) and as SynMotor `motor_attr`-style CSV rows.

use serde_json::json;

use crate::model::{Motor, PartKind};
use crate::params::MotorType;

/// Parameters and attributes of a motor as one JSON document (metres, degrees).
pub fn motor_json(motor: &Motor) -> serde_json::Value {
    json!({ "params": motor.params, "attributes": motor.attributes })
}

/// Cover-bolt columns in the CSV (A has at most 5 cover bolts, B 4).
const CSV_BOLTS: usize = 5;

/// The CSV header: SynMotor's attribute columns (type, bolt_num, BL, sBL, dia_1, dia_2, gear
/// centres, cover-bolt head centres) in metres, then orientation, mirror and drive.
pub fn csv_header() -> String {
    let mut cols: Vec<String> = ["id", "type", "bolt_num", "BL", "sBL", "dia_1", "dia_2"]
        .map(String::from)
        .to_vec();
    for g in ["gear1", "gear2"] {
        cols.extend(["x", "y", "z"].map(|a| format!("{g}_{a}")));
    }
    for k in 1..=CSV_BOLTS {
        cols.extend(["x", "y", "z"].map(|a| format!("bolt{k}_{a}")));
    }
    cols.extend(["gearbox_orientation_deg", "mirror", "bolt_drive"].map(String::from));
    cols.join(",")
}

/// One CSV row (see [`csv_header`]); cells that do not apply (a second gear of type B, missing
/// bolts) are empty.
pub fn csv_row(id: &str, motor: &Motor) -> String {
    let p = &motor.params;
    let a = &motor.attributes;
    let cover_bolts: Vec<_> = a
        .bolts
        .iter()
        .filter(|b| b.kind == PartKind::CoverBolt)
        .collect();
    let mut cells: Vec<String> = vec![
        id.into(),
        a.variant.into(),
        cover_bolts.len().to_string(),
        p.pole_pot_length.to_string(),
        p.shaft_boss_length.to_string(),
        p.lower_gear_diameter.to_string(),
        if p.motor_type == MotorType::A {
            p.upper_gear_diameter.to_string()
        } else {
            String::new()
        },
    ];
    let xyz = |v: Option<glam::Vec3>| match v {
        Some(v) => v.to_array().map(|x| x.to_string()).to_vec(),
        None => vec![String::new(); 3],
    };
    for k in 0..2 {
        cells.extend(xyz(a.gears.get(k).map(|g| g.centre)));
    }
    for k in 0..CSV_BOLTS {
        cells.extend(xyz(cover_bolts.get(k).map(|b| b.head_centre)));
    }
    cells.extend([
        p.gearbox_orientation_deg.to_string(),
        p.mirror.to_string(),
        format!("{:?}", p.bolt_drive).to_lowercase(),
    ]);
    cells.join(",")
}
