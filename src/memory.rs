//! Refusing work that cannot fit in memory before anything is written.

use crate::error::{CliError, CliResult};

/// Bytes this process may still use: the smallest of the system's available memory, what its
/// control group allows (a container's limit) and what its address-space limit (`ulimit -v`,
/// `prlimit --as`) leaves; None where none is known.
fn available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
    let system = meminfo.as_deref().and_then(|m| {
        let line = m.lines().find(|l| l.starts_with("MemAvailable:"))?;
        let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kb * 1024)
    });
    let read = |name: &str| -> Option<u64> {
        std::fs::read_to_string(format!("/sys/fs/cgroup/{name}"))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    let group =
        read("memory.max").map(|max| max.saturating_sub(read("memory.current").unwrap_or(0)));
    [system, group, address_space()].into_iter().flatten().min()
}

/// What the address-space limit leaves this process: the soft limit less the address space it
/// maps now; None without a limit.
fn address_space() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let soft: u64 = limits
        .lines()
        .find_map(|l| l.strip_prefix("Max address space"))?
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmSize:"))?
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    Some(soft.saturating_sub(kb * 1024))
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
