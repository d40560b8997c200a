//! The motorfactory binary end to end: outputs, exit codes, nothing written on bad input, and
//! the same bytes for any thread count.

use std::path::Path;
use std::process::Output;

use kit::{documented_sensor, files_below, motorfactory, run, stderr};

#[path = "../kit/mod.rs"]
mod kit;

mod coverage;
mod lidar;
mod motor;
mod rules;
mod scan;

/// Each command exits 2 with a message containing its text, and `out` is never created.
fn assert_refused(cases: &[(Vec<&str>, &str)], out: &Path) {
    for (args, message) in cases {
        let o = run(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
        assert!(!out.exists(), "{args:?} wrote output");
    }
}

/// A coarse default motor written by `motor` with `args` into `parent/m`.
fn coarse_motor(parent: &Path, args: &[&str]) -> std::path::PathBuf {
    let m = parent.join("m");
    let o = run(&[
        &["motor", "--detail", "coarse", "--out", m.to_str().unwrap()],
        args,
    ]
    .concat());
    assert!(o.status.success(), "{}", stderr(&o));
    m
}
