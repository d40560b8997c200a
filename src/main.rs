//! motorfactory: synthetic, labelled 3D training data of small electric gear motors.

/// Writes a line to standard error; a closed or full stderr is ignored (there is nowhere left to
/// say so).
macro_rules! note {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod coverage;
mod error;
mod generate;
mod memory;
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
    /// Measure how much of a motor's surface a configuration's views cover when it is clamped
    /// at the inspection station.
    Coverage(coverage::CoverageCmd),
}

fn main() {
    keep_freed_memory();
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Motor(cmd) => cmd.run(),
        Command::Motors(cmd) => cmd.run(),
        Command::Params(cmd) => cmd.run(),
        Command::Scan(cmd) => cmd.run(),
        Command::Generate(cmd) => cmd.run(),
        Command::Config(cmd) => cmd.run(),
        Command::Preview(cmd) => cmd.run(),
        Command::Coverage(cmd) => cmd.run(),
    };
    if let Err(e) = result {
        note!("error: {}", printable(&e.to_string()));
        std::process::exit(e.exit_code());
    }
}

/// Has the allocator serve every block from memory it keeps, rather than mapping blocks above
/// 32 MiB afresh and unmapping them when freed: a dataset frees and takes again frame-sized
/// buffers (a megapixel frame's rendering guides are ~60 MB) every sample, and each fresh
/// mapping is faulted in page by page (three quarters of a rendered dataset's system time).
/// A glibc that refuses so high a threshold keeps its own settings: the trim threshold alone
/// would stop it raising the mapping threshold as it goes.
fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets glibc's allocator parameters; called before any thread starts.
    unsafe {
        if libc::mallopt(libc::M_MMAP_THRESHOLD, i32::MAX) == 1 {
            libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
        }
    }
}

/// Writes `text` to standard output. A reader that went away (a closed pipe, as with `| head`)
/// ends the output quietly; any other failure (a full disk) is an error.
pub(crate) fn print_out(text: &str) -> error::CliResult<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other
            .map_err(|e| error::CliError::Runtime(format!("cannot write to standard output: {e}"))),
    }
}

/// An error message as printed: control characters but line breaks escaped, and each line at
/// most 400 characters, whatever the input quoted.
fn printable(message: &str) -> String {
    message
        .lines()
        .map(|line| motorgen::cut(line, 400))
        .collect::<Vec<_>>()
        .join("\n")
}
