//! Checks the kernel's test files share.

use motorgen::kernel::{Mesh, inspect};

/// `m` is a valid solid of `shells` closed shells.
pub fn assert_solid(m: &Mesh, shells: usize) {
    let rep = inspect(m);
    assert!(rep.is_valid_solid(), "{rep:?}");
    assert_eq!(rep.shells, shells, "{rep:?}");
}

/// `a` is within `rel` of `b`, relatively.
pub fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}
