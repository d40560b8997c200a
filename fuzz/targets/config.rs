//! A dataset configuration file, as `generate --config FILE` reads it: laid over the default,
//! checked, its sweeps resolved and its memory estimated. Any input may be refused; none may
//! panic.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        let Ok(top) = toml::from_str::<toml::Table>(text) else {
            return;
        };
        let mut table = scene::config::default_table();
        scene::overlay(&mut table, top);
        let out = std::path::Path::new("/nonexistent/fuzz");
        if let Ok(dataset) = scene::Dataset::new(table, None, None, scene::Shard::ALL, out) {
            dataset.memory_needed(2);
            let _ = dataset.recipe(dataset.samples.saturating_sub(1));
        }
    });
}
