//! Refusing work that cannot fit in memory before anything is written.

use crate::error::{CliError, CliResult};

/// Bytes this process may still use: the smallest of the system's available memory, what its
/// control group allows (a container's limit) and what its address-space limit (`ulimit -v`,
/// `prlimit --as`) leaves; None where none is known.
fn available() -> Option<u64> {
    let system = proc_field("/proc/meminfo", "MemAvailable:").map(|kb| kb * 1024);
    let read = |name: &str| -> Option<u64> {
        std::fs::read_to_string(format!("/sys/fs/cgroup/{name}"))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    let group =
        read("memory.max").map(|max| max.saturating_sub(read("memory.current").unwrap_or(0)));
    // the address-space limit (bytes; "unlimited" is no number) less what is mapped now (kB)
    let address_space = proc_field("/proc/self/limits", "Max address space").map(|soft| {
        let mapped = proc_field("/proc/self/status", "VmSize:").unwrap_or(0);
        soft.saturating_sub(mapped * 1024)
    });
    [system, group, address_space].into_iter().flatten().min()
}

/// The number that follows `name` on its line of the /proc file `path`.
fn proc_field(path: &str, name: &str) -> Option<u64> {
    let text = std::fs::read_to_string(path).ok()?;
    let line = text.lines().find_map(|l| l.strip_prefix(name))?;
    line.split_whitespace().next()?.parse().ok()
}

/// Bytes in words: `1.5 GB`, `300 MB`.
pub fn size(bytes: u64) -> String {
    if bytes >= 1 << 30 {
        format!("{:.1} GB", bytes as f64 / (1u64 << 30) as f64)
    } else {
        format!("{} MB", bytes.div_ceil(1 << 20))
    }
}

/// A usage error unless `needed` bytes are available; `what` says what needs them and `fix` how
/// to need less.
pub fn ensure_fits(needed: u64, what: &str, fix: &str) -> CliResult<()> {
    match available() {
        Some(have) if needed > have => Err(CliError::Usage(format!(
            "{what} needs about {} of memory, but {} are available; {fix}",
            size(needed),
            size(have)
        ))),
        _ => Ok(()),
    }
}
