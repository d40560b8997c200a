//! Configurations as TOML tables: the built-in ones, laying one over another, and dotted-key
//! overrides (`--set`).

use crate::error::{Error, Result};

/// Sets the dotted `key` (e.g. `camera.distance`) of `table` to `value`, creating tables on the
/// way.
///
/// # Errors
///
/// [`Error::Config`] when `key` is not a dotted key or passes through a value
/// that is not a table.
pub fn set_key(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<()> {
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().filter(|s| !s.is_empty());
    let (Some(last), true) = (last, parts.iter().all(|p| !p.is_empty())) else {
        return Err(Error::Config(format!(
            "`{key}` is not a dotted key such as camera.distance"
        )));
    };
    let mut t = table;
    for p in parts {
        let entry = t
            .entry(p)
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        t = entry
            .as_table_mut()
            .ok_or_else(|| Error::Config(format!("{key}: `{p}` is not a table")))?;
    }
    t.insert(last.into(), value);
    Ok(())
}

/// Lays `top` over `base`: tables merge key by key, any other value replaces.
pub fn overlay(base: &mut toml::Table, top: toml::Table) {
    for (key, value) in top {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(t)) => overlay(b, t),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

/// Parses the right-hand side of `--set key=value`: a TOML value, or a bare word as text.
pub fn parse_value(text: &str) -> toml::Value {
    toml::from_str::<toml::Table>(&format!("v = {text}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(text.to_string()))
}

/// The configurations shipped in `configs/` and built into the library: `(name, TOML)`, the
/// default first. Every other configuration is laid over the default with [`overlay`].
pub const BUILTIN: [(&str, &str); 10] = [
    ("default", crate::DEFAULT_CONFIG),
    ("synmotor", include_str!("../../configs/synmotor.toml")),
    ("zivid", include_str!("../../configs/zivid.toml")),
    (
        "registration",
        include_str!("../../configs/registration.toml"),
    ),
    (
        "sweep-pole-pot",
        include_str!("../../configs/sweep-pole-pot.toml"),
    ),
    (
        "sweep-noise",
        include_str!("../../configs/sweep-noise.toml"),
    ),
    (
        "transfer-unit",
        include_str!("../../configs/transfer-unit.toml"),
    ),
    ("handling", include_str!("../../configs/handling.toml")),
    ("armature", include_str!("../../configs/armature.toml")),
    ("hall", include_str!("../../configs/hall.toml")),
];

/// The default configuration as a TOML table, every key present: the base that configurations
/// are laid over.
pub fn default_table() -> toml::Table {
    toml::from_str(crate::DEFAULT_CONFIG).expect("configs/default.toml is valid TOML")
}

/// The built-in configuration `name` laid over the default, as a table to which overrides can
/// still be applied; `None` for a name not in [`BUILTIN`].
pub fn builtin_table(name: &str) -> Option<toml::Table> {
    let (_, text) = BUILTIN.iter().find(|(n, _)| *n == name)?;
    let mut table = default_table();
    overlay(
        &mut table,
        toml::from_str(text).expect("the built-in configurations are valid TOML"),
    );
    Some(table)
}

/// The configuration `name` names, as a table to which overrides can still be applied: a
/// built-in configuration, or else a TOML file laid over the default.
///
/// # Errors
///
/// [`Error::Config`] naming `name` when it is neither, or when the file
/// is not valid TOML (in words).
pub fn named_table(name: &str) -> Result<toml::Table> {
    if let Some(table) = builtin_table(name) {
        return Ok(table);
    }
    let shown = motorgen::shown(name);
    let text =
        sensor::files::read_text(name.as_ref(), sensor::files::CONFIG_LIMIT).map_err(|e| {
            let names: Vec<&str> = BUILTIN.iter().map(|(n, _)| *n).collect();
            Error::Config(match e.kind() {
                std::io::ErrorKind::NotFound => format!(
                    "{shown}: no such file, and no built-in configuration of that name (built-in: \
                 {}){}",
                    names.join(", "),
                    motorgen::did_you_mean(name, names.iter().copied())
                ),
                _ => format!("{shown}: {e}"),
            })
        })?;
    let top = toml::from_str(&text)
        .map_err(|e| Error::Config(format!("{shown}: {}", super::toml_in_words(&text, &e))))?;
    let mut table = default_table();
    overlay(&mut table, top);
    Ok(table)
}
