//! motorfactory: synthetic, labelled 3D training data of small electric gear motors.

mod error;
mod generate;
mod memory;
mod meshio;
mod motors;
mod preview;
mod progress;
mod scan;
mod signals;

use clap::{Parser, Subcommand};

/// Synthetic, labelled 3D data of small DC gear motors.
#[derive(Debug, Parser)]
#[command(name = "motorfactory", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Build one motor and write its meshes and ground truth.
    Motor(motors::MotorCmd),
    /// Build many motors in parallel from a parameter space.
    Motors(motors::MotorsCmd),
    /// List every motor parameter with its range, default and meaning.
    Params(motors::ParamsCmd),
    /// Scan meshes with a simulated depth sensor.
    Scan(scan::ScanCmd),
    /// Generate a labelled point-cloud dataset from a TOML configuration.
    Generate(generate::GenerateCmd),
    /// Print or list the built-in dataset configurations.
    Config(generate::ConfigCmd),
    /// Draw a sample, or a contact sheet of a dataset, coloured by class.
    Preview(preview::PreviewCmd),
}

fn main() {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Motor(cmd) => cmd.run(),
        Command::Motors(cmd) => cmd.run(),
        Command::Params(cmd) => cmd.run(),
        Command::Scan(cmd) => cmd.run(),
        Command::Generate(cmd) => cmd.run(),
        Command::Config(cmd) => cmd.run(),
        Command::Preview(cmd) => cmd.run(),
    };
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(e.exit_code());
    }
}
