//! CLI errors and their exit codes.

/// A failure of a command: bad input (exit 2, nothing written) or a failure while working (exit 1).
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Bad arguments, configuration or output location, found before anything is written.
    #[error("{0}")]
    Usage(String),
    /// A failure after work began.
    #[error("{0}")]
    Runtime(String),
    /// Stopped by a signal (its number) after finishing the work in flight.
    #[error("stopped by signal {0}; {1}")]
    Stopped(i32, String),
}

impl CliError {
    /// The process exit code.
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::Usage(_) => 2,
            CliError::Runtime(_) => 1,
            CliError::Stopped(signal, _) => 128 + signal,
        }
    }
}

/// Library errors met while checking input are usage errors.
impl From<motorgen::Error> for CliError {
    fn from(e: motorgen::Error) -> Self {
        CliError::Usage(e.to_string())
    }
}

/// Result with [`CliError`].
pub type CliResult<T> = Result<T, CliError>;

/// The value of the option named `value` among `options`, or a usage error listing them.
pub fn choice<T: Copy>(flag: &str, value: &str, options: &[(&str, T)]) -> CliResult<T> {
    options
        .iter()
        .find(|(name, _)| *name == value)
        .map(|(_, v)| *v)
        .ok_or_else(|| {
            let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
            CliError::Usage(format!(
                "--{flag} \"{}\" is not allowed: expected one of {}{}",
                motorgen::shown(value),
                names.join(", "),
                motorgen::did_you_mean(value, names.iter().copied())
            ))
        })
}

/// Worker threads: a whole number from 1 to four times this machine's cores.
pub fn jobs(text: &str) -> Result<usize, String> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let most = 4 * cores;
    text.parse::<usize>()
        .ok()
        .filter(|n| (1..=most).contains(n))
        .ok_or_else(|| format!("expected a whole number from 1 to {most} (4 x {cores} cores)"))
}

/// A count (`-n`): a whole number from 1.
pub fn count(text: &str) -> Result<u64, String> {
    text.parse::<u64>()
        .ok()
        .filter(|&n| n >= 1)
        .ok_or_else(|| "must be a positive whole number (1, 2, 3, ...)".into())
}

/// A seed: a whole number from 0 to 2^64 - 1.
pub fn seed(text: &str) -> Result<u64, String> {
    text.parse::<u64>()
        .map_err(|_| "must be a whole number from 0 to 18446744073709551615".into())
}
