//! Makes one sample of a built-in configuration, for profiling: `one_sample NAME INDEX`
//! (`valgrind --tool=callgrind target/release/examples/one_sample zivid 3`).

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let table = scene::config::builtin_table(&a[1]).expect("a built-in configuration");
    let recipe =
        scene::Recipe::new(scene::Config::from_table(&table).unwrap(), Vec::new()).unwrap();
    let sample = scene::make(&recipe, a[2].parse().unwrap()).unwrap();
    println!("{} points", sample.views[0].cloud.len());
}
