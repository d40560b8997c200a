//! SIGINT and SIGTERM stop a run cleanly: the first asks it to finish the work in flight and
//! stop; a second ends the process at once. Handlers are installed explicitly, so this holds
//! also as a container's first process (PID 1), which gets no default handlers.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use signal_hook::consts::{SIGINT, SIGTERM};

use crate::error::{CliError, CliResult};

/// The signal caught, if any.
pub struct Signals(Arc<AtomicUsize>);

impl Signals {
    /// Installs the handlers.
    pub fn install() -> CliResult<Signals> {
        let caught = Arc::new(AtomicUsize::new(0));
        let again = Arc::new(AtomicBool::new(false));
        for signal in [SIGINT, SIGTERM] {
            let failed = |e: std::io::Error| CliError::Runtime(format!("signal handler: {e}"));
            // the second signal exits with the shell's code for death by that signal
            signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, again.clone())
                .map_err(failed)?;
            signal_hook::flag::register(signal, again.clone()).map_err(failed)?;
            signal_hook::flag::register_usize(signal, caught.clone(), signal as usize)
                .map_err(failed)?;
        }
        Ok(Signals(caught))
    }

    /// The signal caught so far, if any.
    pub fn caught(&self) -> Option<i32> {
        match self.0.load(Ordering::Relaxed) {
            0 => None,
            s => Some(s as i32),
        }
    }
}
