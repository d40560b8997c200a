//! Makes one sample of a built-in dataset configuration in memory, as `motorfactory generate`
//! would write it, and prints its motor, level and points per class.
//!
//! Usage: `cargo run --release --example dataset_sample -- CONFIG INDEX`
//! (CONFIG is a name from `motorfactory config --list`, e.g. `default` or `synmotor`).

use scene::config::builtin_table;
use scene::{Dataset, Shard, make};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [name, index] = args.as_slice() else {
        return Err("usage: dataset_sample CONFIG INDEX".into());
    };
    let table = builtin_table(name).ok_or_else(|| format!("no built-in configuration {name}"))?;
    // the dataset is only planned: nothing is written until `prepare` and `run`
    let dataset = Dataset::new(table, None, None, Shard::ALL, "out/unused".as_ref())?;
    let index: u64 = index.parse()?;
    let recipe = dataset.recipe(index)?;
    let scheme = recipe.config.output.scheme;
    let sample = make(&recipe, index)?;
    println!(
        "sample {index}: motor {}, level {:?}, split {:?}",
        sample.motor.attributes.variant, sample.level, sample.split
    );
    for (v, view) in sample.views.iter().enumerate() {
        let mut counts = vec![0usize; scheme.classes().len()];
        for &class in &view.cloud.class {
            counts[class as usize] += 1;
        }
        println!("view {v}: {} points", view.cloud.len());
        for (class, count) in scheme.classes().iter().zip(counts) {
            println!("  {:<16} {count}", class.name);
        }
    }
    Ok(())
}
