//! `generate` and `config`: labelled datasets from TOML configurations.

use std::path::PathBuf;

use clap::Args;
use scene::config::{BUILTIN, named_table};
use scene::{Dataset, Shard, parse_value, set_key};

use crate::error::{CliError, CliResult, choice};
use crate::memory;
use crate::progress::Progress;
use crate::signals::Signals;

/// Generate a labelled dataset: motors in the work cell, scanned, cropped and augmented.
#[derive(Debug, Args)]
pub struct GenerateCmd {
    /// Dataset configuration (TOML); the built-in default when absent. A name from
    /// `motorfactory config --list` also works.
    #[arg(long)]
    config: Option<String>,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Number of samples (default: the config's `samples`).
    #[arg(short = 'n', long = "samples", allow_negative_numbers = true, value_parser = crate::error::count)]
    samples: Option<u64>,
    /// Global seed (default: the config's `seed`).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::error::seed)]
    seed: Option<u64>,
    /// Worker threads, 1 to 4 x the cores (default: all cores).
    #[arg(long, value_parser = crate::error::jobs)]
    jobs: Option<usize>,
    /// Make only samples with index % N == I (I/N), e.g. one task of a Slurm array.
    #[arg(long, default_value = "0/1")]
    shard: String,
    /// Finish a dataset a killed run left unfinished.
    #[arg(long)]
    resume: bool,
    /// Override a config key: `--set camera.distance=[0.5,0.6]`, `--set motor.params.type=B`
    /// (repeatable; the value is TOML, or a bare word as text).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// No progress output.
    #[arg(long)]
    quiet: bool,
}

/// Print or list the built-in configurations.
#[derive(Debug, Args)]
pub struct ConfigCmd {
    /// Print a built-in configuration (see --list).
    #[arg(long, value_name = "NAME")]
    print: Option<String>,
    /// List the built-in configurations.
    #[arg(long)]
    list: bool,
}

impl ConfigCmd {
    /// Runs the command.
    pub fn run(&self) -> CliResult<()> {
        match (&self.print, self.list) {
            (Some(name), _) => crate::print_out(choice("print", name, &BUILTIN)?),
            (None, true) => {
                let names: String = BUILTIN.iter().map(|(n, _)| format!("{n}\n")).collect();
                crate::print_out(&names)
            }
            (None, false) => Err(CliError::Usage("give --print NAME or --list".into())),
        }
    }
}

/// The configuration `--config` names (the default one when absent), `--set` applied.
pub(crate) fn config_table(config: Option<&str>, sets: &[String]) -> CliResult<toml::Table> {
    let name = config.unwrap_or("default");
    let mut table = named_table(name).map_err(|e| CliError::Usage(format!("--config {e}")))?;
    for s in sets {
        let (key, value) = s.split_once('=').ok_or_else(|| {
            CliError::Usage(format!(
                "--set {s}: expected KEY=VALUE, e.g. --set camera.views=2"
            ))
        })?;
        set_key(&mut table, key.trim(), parse_value(value.trim())).map_err(scene_error)?;
    }
    Ok(table)
}

/// A scene error as a CLI error: the user's (exit 2) or a failure while working.
pub(crate) fn scene_error(e: scene::Error) -> CliError {
    if e.is_usage() {
        CliError::Usage(e.to_string())
    } else {
        CliError::Runtime(e.to_string())
    }
}

impl GenerateCmd {
    /// Runs the command.
    pub fn run(&self) -> CliResult<()> {
        let signals = Signals::install()?;
        let shard = Shard::parse(&self.shard).map_err(scene_error)?;
        let dataset = Dataset::new(
            config_table(self.config.as_deref(), &self.sets)?,
            self.samples,
            self.seed,
            shard,
            &self.out,
        )
        .map_err(scene_error)?;
        let jobs = self.jobs.unwrap_or_else(rayon::current_num_threads);
        let sensor = &dataset.sensor().intrinsics;
        let (what, lower) = match dataset.lidar() {
            Some(lidar) => (
                format!("a {} of {} rays", lidar.name, lidar.rays()),
                "lower --jobs, -n or the modules of [cell.hall]",
            ),
            None => (
                format!("a {}x{} sensor", sensor.width, sensor.height),
                "lower --jobs, -n or the sensor's resolution (sensor.sampling)",
            ),
        };
        memory::ensure_fits(
            dataset.memory_needed(jobs),
            &format!(
                "this dataset ({} samples in this run, {jobs} jobs, {what})",
                dataset.shard_samples(),
            ),
            lower,
        )?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| CliError::Runtime(e.to_string()))?;
        // prepared in the pool: the first sample, made to check it, leaves its scan buffer with
        // a worker that reuses it
        let (summary, progress) = pool.install(|| {
            let prepared = dataset.prepare(self.resume).map_err(scene_error)?;
            let progress = Progress::new(dataset.shard_samples(), "samples", self.quiet);
            for _ in prepared.done() {
                progress.tick();
            }
            let summary = dataset
                .run(prepared, &|_| progress.tick(), &|| {
                    signals.caught().is_some()
                })
                .map_err(scene_error)?;
            Ok::<_, CliError>((summary, progress))
        })?;
        if let (true, Some(signal)) = (summary.stopped, signals.caught()) {
            progress.finish();
            return Err(CliError::Stopped(
                signal,
                format!(
                    "{} samples made; the same command with --resume finishes the dataset",
                    summary.made
                ),
            ));
        }
        let (_, seconds) = progress.finish();
        if let Some(first) = summary.empty.first() {
            note!(
                "warning: {} samples hold no point (the first: sample {first}); their camera \
                 poses put the motor out of the sensor's range or the crop box",
                summary.empty.len()
            );
        }
        if !self.quiet {
            let scheme = dataset.scheme();
            let seen: Vec<String> = scheme
                .classes()
                .iter()
                .zip(&summary.class_counts)
                .filter(|(_, n)| **n > 0)
                .map(|(c, n)| format!("{} {n}", c.name))
                .collect();
            note!(
                "{} samples made ({} already done) in {seconds:.1} s ({:.2} samples/s), {} points; \
                 classes: {}; written to {}",
                summary.made,
                summary.skipped,
                summary.made as f64 / seconds.max(1e-9),
                summary.points,
                seen.join(", "),
                self.out.display()
            );
        }
        Ok(())
    }
}
