//! The time to make samples of a configuration in memory (one at a time on all threads), for
//! comparisons that must time the same samples close together (`bench/python_stream.py`).
//! With a count N, samples 1..=N, one line each, then their median and mean:
//!
//!     cargo bench -p scene --bench sample_times -- default 200
//!
//! with `-` in place of N, the samples whose indices arrive on standard input, one line each,
//! answered as they are made (so that another process can take turns with it).

use std::io::{BufRead, Write};
use std::time::Instant;

use scene::{Config, Recipe, make};

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let name = args.first().map_or("default", String::as_str);
    let count = args.get(1).map_or("200", String::as_str);
    let table = scene::config::builtin_table(name).expect("a built-in configuration");
    let recipe = Recipe::new(
        Config::from_table(&table).expect("a configuration"),
        Vec::new(),
    )
    .expect("a recipe");
    make(&recipe, 0).expect("sample 0");
    let time = |i: u64| {
        let t = Instant::now();
        std::hint::black_box(make(&recipe, i).expect("a sample"));
        let seconds = t.elapsed().as_secs_f64();
        println!("sample {i}: {seconds:.6} s");
        std::io::stdout().flush().expect("stdout");
        seconds
    };
    if count == "-" {
        for line in std::io::stdin().lock().lines() {
            time(line.expect("stdin").trim().parse().expect("a sample index"));
        }
        return;
    }
    let n: u64 = match count.parse() {
        Ok(n) if n > 0 => n,
        _ => {
            eprintln!("sample_times: the count {count:?} is not allowed: expected 1 or more, or -");
            std::process::exit(2);
        }
    };
    let mut times: Vec<f64> = (1..=n).map(time).collect();
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    times.sort_by(f64::total_cmp);
    println!(
        "{name}: median {:.6} s, mean {mean:.6} s over samples 1..={n}",
        times[times.len() / 2]
    );
}
