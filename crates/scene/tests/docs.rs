//! The configuration reference (`docs/configuration.md`) lists exactly the keys the code reads.

use std::collections::BTreeSet;

use scene::config::{Config, default_table};

/// Dotted keys of every leaf of `table`; `motor.params` is one key (its entries are motor
/// parameters, documented in docs/motors.md).
fn leaves(table: &toml::Table, prefix: &str, out: &mut BTreeSet<String>) {
    for (key, value) in table {
        let path = format!("{prefix}{key}");
        match value {
            toml::Value::Table(t) if path != "motor.params" => leaves(t, &format!("{path}."), out),
            _ => {
                out.insert(path);
            }
        }
    }
}

#[test]
fn the_configuration_reference_lists_every_key() {
    let text = std::fs::read_to_string("../../docs/configuration.md").unwrap();
    let documented: BTreeSet<String> = text
        .lines()
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split_once('`').map(|(key, _)| key.to_string()))
        .collect();
    let mut keys = BTreeSet::new();
    leaves(&default_table(), "", &mut keys);
    // the keys the default leaves out: optional ones
    let optional = [
        "sensor.spec",
        "sensor.noise",
        "sensor.colour",
        "sensor.calibration",
        "sensor.resolution",
        "sweep",
    ];
    keys.extend(optional.map(String::from));
    assert_eq!(documented, keys);
    // each optional key is one the configuration accepts
    let mut table = default_table();
    let spec = toml::Value::try_from(sensor::SensorSpec::preset("ideal").unwrap()).unwrap();
    scene::set_key(&mut table, "sensor.spec", spec).unwrap();
    scene::set_key(&mut table, "sensor.sampling", "by2x2".into()).unwrap();
    scene::set_key(
        &mut table,
        "sensor.noise",
        toml::from_str("lateral_px = 0.1")
            .map(toml::Value::Table)
            .unwrap(),
    )
    .unwrap();
    let sweep: toml::Value =
        toml::from_str::<toml::Table>("s = [{ key = \"seed\", list = [1, 2] }]").unwrap()["s"]
            .clone();
    scene::set_key(&mut table, "sweep", sweep).unwrap();
    let focus = toml::from_str("focus = 0.3").map(toml::Value::Table);
    scene::set_key(&mut table, "sensor.colour", focus.unwrap()).unwrap();
    let seed = toml::from_str("seed = 7").map(toml::Value::Table);
    scene::set_key(&mut table, "sensor.calibration", seed.unwrap()).unwrap();
    let config = Config::from_table(&table).unwrap();
    assert!(config.sensor.spec.is_some() && config.sensor.noise.is_some());
    let sensor = config.sensor.resolve().unwrap();
    assert_eq!(sensor.colour.focus, 0.3);
    assert_eq!(sensor.calibration.seed, 7);
    // an unknown colour key is refused, named
    let typo = toml::from_str("fokus = 0.3").map(toml::Value::Table);
    scene::set_key(&mut table, "sensor.colour", typo.unwrap()).unwrap();
    let e = Config::from_table(&table).unwrap_err().to_string();
    assert!(e.contains("sensor.colour") && e.contains("fokus"), "{e}");
    assert_eq!(config.sweep.len(), 1);
}
