//! What the CLI tests share: the binary, and a folder's files.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output};

/// The `motorfactory` binary built for these tests.
pub fn motorfactory() -> Command {
    Command::new(env!("CARGO_BIN_EXE_motorfactory"))
}

/// Runs the binary with `args` to its end.
#[allow(dead_code)]
pub fn run(args: &[&str]) -> Output {
    motorfactory().args(args).output().unwrap()
}

/// What a run printed on standard error.
#[allow(dead_code)]
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The custom sensor's TOML that `docs/sensors.md` shows.
#[allow(dead_code)]
pub fn documented_sensor() -> String {
    let doc = std::fs::read_to_string("docs/sensors.md").unwrap();
    let after = doc.split("## Custom sensors").nth(1).unwrap();
    let block = after.split("```toml\n").nth(1).unwrap();
    block.split("```").next().unwrap().to_string()
}

/// Every file below `dir`, by path relative to it, with its bytes.
pub fn files_below(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let name = p.strip_prefix(dir).unwrap().display().to_string();
                out.insert(name, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// A dataset folder's files by relative path with their bytes, without the manifests and the
/// runs' lock files.
#[allow(dead_code)]
pub fn dataset_files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut files = files_below(dir);
    files.retain(|name, _| !name.starts_with("manifest") && !name.starts_with(".motorfactory"));
    files
}

/// Asserts that two dataset folders hold the same files, byte for byte, and the same
/// `manifest.jsonl`.
#[allow(dead_code)]
pub fn assert_same_dataset(a: &Path, b: &Path) {
    assert!(
        dataset_files(a) == dataset_files(b),
        "{} and {} differ",
        a.display(),
        b.display()
    );
    assert_eq!(
        std::fs::read(a.join("manifest.jsonl")).unwrap(),
        std::fs::read(b.join("manifest.jsonl")).unwrap(),
        "the manifests of {} and {} differ",
        a.display(),
        b.display()
    );
}
