//! `motor`, `motors` and `params`: motor meshes from parameters, one or many.

use std::path::{Path, PathBuf};

use clap::Args;
use rayon::prelude::*;
use serde::Deserialize;

use motorgen::export::{csv_header, csv_row, earlier_output, write_atomic, write_motor};
use motorgen::params::PARAMS;
use motorgen::{Detail, Dist, Format, Motor, ParamSpace, build, derive_seed};

use crate::error::{CliError, CliResult};
use crate::progress::Progress;

/// The default batch configuration, also shipped as `configs/motors.toml`.
pub const DEFAULT_MOTORS_CONFIG: &str = include_str!("../configs/motors.toml");

/// A batch configuration file.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct MotorsConfig {
    seed: Option<u64>,
    detail: Option<Detail>,
    formats: Option<Vec<Format>>,
    per_part: Option<bool>,
    exploded: Option<f32>,
    params: Option<toml::Table>,
}

impl MotorsConfig {
    fn read(path: Option<&Path>) -> CliResult<MotorsConfig> {
        let (text, name) = match path {
            Some(p) => (
                sensor::files::read_text(p, sensor::files::CONFIG_LIMIT)
                    .map_err(|e| CliError::Usage(format!("{}: {e}", p.display())))?,
                p.display().to_string(),
            ),
            None => (
                DEFAULT_MOTORS_CONFIG.to_string(),
                "built-in configs/motors.toml".into(),
            ),
        };
        toml::from_str(&text).map_err(|e| {
            CliError::Usage(format!(
                "{name}: {}",
                scene::config::toml_in_words(&text, &e)
            ))
        })
    }
}

/// Options shared by `motor` and `motors`.
#[derive(Debug, Args)]
pub struct MeshArgs {
    /// Parameter override `key=value` (repeatable); the value may be a TOML value such as
    /// `{ uniform = [0.062, 0.07] }` or "auto". See `motorfactory params`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// Configuration file (`[params]` distributions and export options).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Global seed.
    #[arg(long, allow_negative_numbers = true, value_parser = crate::error::seed)]
    seed: Option<u64>,
    /// Mesh formats, comma-separated: obj, stl, ply, glb.
    #[arg(long, value_delimiter = ',')]
    format: Vec<String>,
    /// Tessellation: coarse, normal or fine.
    #[arg(long)]
    detail: Option<String>,
    /// Exploded view: 0 assembled, 1 the add-on's exploded spacing, up to 10 for wider.
    #[arg(long)]
    exploded: Option<f32>,
    /// Write only the whole motor, not one file per part.
    #[arg(long)]
    whole_only: bool,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Replace an earlier output in the folder: its files are removed first.
    #[arg(long)]
    replace: bool,
}

/// What to build and how to write it, checked.
struct Plan {
    space: ParamSpace,
    seed: u64,
    detail: Detail,
    formats: Vec<Format>,
    per_part: bool,
    exploded: f32,
    out: PathBuf,
    /// What an earlier run wrote in `out`, removed by [`Plan::make_out`] (`--replace`).
    earlier: Vec<PathBuf>,
}

impl MeshArgs {
    /// Resolves config and arguments into a plan; `base` gives the space before `[params]` and
    /// `--set` apply. Writes nothing: refuses an output folder holding what an earlier run of
    /// `motor` (`many` false) or `motors` wrote, unless `--replace`.
    fn plan(&self, base: ParamSpace, many: bool) -> CliResult<Plan> {
        let config = MotorsConfig::read(self.config.as_deref())?;
        let mut space = base;
        for (key, value) in config.params.iter().flatten() {
            space.set(key, Dist::from_toml(key, value.clone())?)?;
        }
        for s in &self.sets {
            let (key, value) = s.split_once('=').ok_or_else(|| {
                CliError::Usage(format!("--set {s}: expected KEY=VALUE, e.g. --set type=B"))
            })?;
            space.set(key.trim(), Dist::from_cli(key.trim(), value.trim())?)?;
        }
        space.check()?;
        let formats = if self.format.is_empty() {
            config.formats.unwrap_or_else(|| vec![Format::Obj])
        } else {
            self.format
                .iter()
                .map(|f| Format::parse(f.trim()))
                .collect::<Result<_, _>>()?
        };
        let detail = match self.detail.as_deref() {
            None => config.detail.unwrap_or_default(),
            Some(d) => {
                serde_json::from_value(serde_json::Value::String(d.into())).map_err(|_| {
                    CliError::Usage(format!(
                        "--detail \"{d}\" is not allowed: expected coarse, normal or fine"
                    ))
                })?
            }
        };
        let exploded = self.exploded.or(config.exploded).unwrap_or(0.0);
        if !(0.0..=10.0).contains(&exploded) {
            return Err(CliError::Usage(format!(
                "exploded = {exploded} is not allowed: expected a number from 0 to 10"
            )));
        }
        let earlier =
            earlier_output(&self.out, many).map_err(|e| CliError::Usage(e.to_string()))?;
        if !earlier.is_empty() && !self.replace {
            return Err(CliError::Usage(format!(
                "output folder {} already holds {}; pass --replace to replace it, or choose \
                 another --out",
                self.out.display(),
                if many { "motors" } else { "a motor" }
            )));
        }
        Ok(Plan {
            space,
            seed: self.seed.or(config.seed).unwrap_or(0),
            detail,
            formats,
            per_part: !self.whole_only && config.per_part.unwrap_or(true),
            exploded,
            out: self.out.clone(),
            earlier,
        })
    }
}

impl Plan {
    /// Once the command's checks pass: removes what an earlier run wrote (`--replace`) and
    /// creates the output folder, the first writes.
    fn make_out(&self) -> CliResult<()> {
        for path in &self.earlier {
            let removed = if path.is_dir() {
                std::fs::remove_dir_all(path)
            } else {
                std::fs::remove_file(path)
            };
            removed.map_err(|e| CliError::Runtime(format!("{}: {e}", path.display())))?;
        }
        std::fs::create_dir_all(&self.out).map_err(|e| {
            CliError::Usage(format!(
                "cannot create output folder {}: {e}",
                self.out.display()
            ))
        })
    }

    fn motor(&self, seed: u64) -> CliResult<Motor> {
        let motor = build(&self.space.sample(seed)?, self.detail);
        Ok(if self.exploded > 0.0 {
            motor.exploded(self.exploded)
        } else {
            motor
        })
    }

    fn write(&self, motor: &Motor, dir: &Path) -> CliResult<()> {
        write_motor(motor, dir, &self.formats, self.per_part)
            .map_err(|e| CliError::Runtime(e.to_string()))?;
        Ok(())
    }
}

/// `motorfactory motor`: one motor.
#[derive(Debug, Args)]
pub struct MotorCmd {
    #[command(flatten)]
    mesh: MeshArgs,
    /// Draw unset parameters from the add-on's generator instead of using their defaults.
    #[arg(long)]
    random: bool,
}

impl MotorCmd {
    /// Runs the command.
    pub fn run(&self) -> CliResult<()> {
        let base = if self.random || self.mesh.config.is_some() {
            ParamSpace::addon()
        } else {
            ParamSpace::defaults()
        };
        let plan = self.mesh.plan(base, false)?;
        let motor = plan.motor(plan.seed)?;
        plan.make_out()?;
        plan.write(&motor, &plan.out)?;
        let triangles: usize = motor.parts.iter().map(|p| p.mesh.triangle_count()).sum();
        note!(
            "motor {} ({} parts, {triangles} triangles) written to {}",
            motor.attributes.variant,
            motor.parts.len(),
            plan.out.display()
        );
        Ok(())
    }
}

/// `motorfactory motors`: many motors in parallel.
#[derive(Debug, Args)]
pub struct MotorsCmd {
    #[command(flatten)]
    mesh: MeshArgs,
    /// Number of motors.
    #[arg(short = 'n', long, allow_negative_numbers = true, value_parser = crate::error::count)]
    count: u64,
    /// Worker threads, 1 to 4 x the cores (default: all cores).
    #[arg(long, value_parser = crate::error::jobs)]
    jobs: Option<usize>,
    /// No progress output.
    #[arg(long)]
    quiet: bool,
}

impl MotorsCmd {
    /// Runs the command: `motor_NNNNNN/` folders and `attributes.csv` with one row per motor.
    pub fn run(&self) -> CliResult<()> {
        let plan = self.mesh.plan(ParamSpace::addon(), true)?;
        plan.space.sample(derive_seed(plan.seed, 0))?;
        // a CSV row (about 300 bytes) per motor until the end, and a motor in flight per job
        let jobs = self.jobs.unwrap_or_else(rayon::current_num_threads);
        crate::memory::ensure_fits(
            self.count
                .saturating_mul(512)
                .saturating_add(jobs as u64 * (64 << 20)),
            &format!("{} motors", self.count),
            "lower -n and make the rest with another --seed",
        )?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs)
            .build()
            .map_err(|e| CliError::Usage(format!("--jobs {:?}: {e}", self.jobs)))?;
        plan.make_out()?;
        let progress = Progress::new(self.count, "motors", self.quiet);
        let rows: Vec<String> = pool.install(|| {
            (0..self.count)
                .into_par_iter()
                .map(|i| {
                    let id = format!("motor_{i:06}");
                    let motor = plan.motor(derive_seed(plan.seed, i))?;
                    plan.write(&motor, &plan.out.join(&id))?;
                    progress.tick();
                    Ok(csv_row(&id, &motor))
                })
                .collect::<CliResult<_>>()
        })?;
        let csv = plan.out.join("attributes.csv");
        write_atomic(&csv, &|w| {
            writeln!(w, "{}", csv_header())?;
            rows.iter().try_for_each(|r| writeln!(w, "{r}"))
        })
        .map_err(|e| CliError::Runtime(e.to_string()))?;
        let (done, secs) = progress.finish();
        if !self.quiet {
            note!(
                "{done} motors in {secs:.1} s ({:.1}/s) written to {}",
                done as f64 / secs.max(1e-9),
                plan.out.display()
            );
        }
        Ok(())
    }
}

/// `params`: every motor parameter.
#[derive(Debug, Args)]
pub struct ParamsCmd {
    /// Print a Markdown table (as in docs/motors.md) instead of plain text
    #[arg(long)]
    markdown: bool,
}

impl ParamsCmd {
    /// Prints the parameter table: key, allowed values, default and meaning. A closed pipe (as
    /// with `| head`) ends the listing quietly.
    pub fn run(&self) -> CliResult<()> {
        let mut text = String::new();
        if self.markdown {
            text.push_str("| key | allowed | default | meaning |\n|---|---|---|---|\n");
        }
        for p in PARAMS {
            let (key, allowed, default, doc) = (p.key, p.kind.allowed(), p.default.value(), p.doc);
            text.push_str(&if self.markdown {
                format!("| `{key}` | {allowed} | {default} | {doc} |\n")
            } else {
                format!("{key}\n    {allowed}; default {default}\n    {doc}\n\n")
            });
        }
        crate::print_out(&text)
    }
}
