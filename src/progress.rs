//! Progress reporting: a bar with rate and ETA on a terminal, periodic plain lines otherwise,
//! nothing when quiet.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Reports finished items; shareable across threads.
pub struct Progress {
    bar: Option<ProgressBar>,
    plain: Option<Mutex<Instant>>,
    done: AtomicU64,
    total: u64,
    start: Instant,
    what: &'static str,
}

/// Seconds between plain progress lines.
const PLAIN_EVERY: Duration = Duration::from_secs(5);

impl Progress {
    /// A reporter for `total` items of `what` (e.g. "motors").
    pub fn new(total: u64, what: &'static str, quiet: bool) -> Progress {
        let terminal = std::io::stderr().is_terminal();
        let bar = (!quiet && terminal).then(|| {
            let style =
                ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} {per_sec} ETA {eta}")
                    .expect("the template is valid");
            ProgressBar::new(total).with_style(style).with_message(what)
        });
        let plain = (!quiet && !terminal).then(|| Mutex::new(Instant::now()));
        Progress {
            bar,
            plain,
            done: AtomicU64::new(0),
            total,
            start: Instant::now(),
            what,
        }
    }

    /// Counts one finished item.
    pub fn tick(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(bar) = &self.bar {
            bar.inc(1);
        }
        if let Some(last) = &self.plain {
            let mut last = last.lock().expect("progress lock");
            if last.elapsed() >= PLAIN_EVERY {
                *last = Instant::now();
                note!(
                    "{done}/{} {} ({:.1}/s)",
                    self.total,
                    self.what,
                    self.rate(done)
                );
            }
        }
    }

    /// Items per second so far.
    fn rate(&self, done: u64) -> f64 {
        done as f64 / self.start.elapsed().as_secs_f64().max(1e-9)
    }

    /// Ends the bar and returns (items, seconds).
    pub fn finish(&self) -> (u64, f64) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
        (
            self.done.load(Ordering::Relaxed),
            self.start.elapsed().as_secs_f64(),
        )
    }
}
