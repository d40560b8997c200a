//! Makes one sample of a shipped configuration (for profiling): `one_sample NAME INDEX`.

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let text = std::fs::read_to_string(format!("configs/{}.toml", a[1])).unwrap();
    let mut table: toml::Table = toml::from_str(scene::DEFAULT_CONFIG).unwrap();
    scene::overlay(&mut table, toml::from_str(&text).unwrap());
    let config = scene::Config::from_table(&table).unwrap();
    let recipe = scene::Recipe::new(config, Vec::new()).unwrap();
    let sample = scene::make(&recipe, a[2].parse().unwrap()).unwrap();
    println!("{} points", sample.views[0].cloud.len());
}
