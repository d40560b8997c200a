//! Who may write into a dataset folder, and what runs leave behind: one unsharded run at a
//! time, shards side by side (also in their own PID namespaces, as pods are), temporary files of
//! dead runs removed and live ones kept, SIGTERM, and the documented Slurm and Kubernetes
//! recipes run as written.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use kit::{assert_same_dataset, dataset_files, files_below, motorfactory};

mod kit;

/// Small and quick samples (a Zivid 2+ M130 binned 4x4 at 0.9-1 m).
const SMALL: [&str; 4] = [
    "--set",
    "sensor.preset=zivid-2plus-m130",
    "--set",
    "camera.distance=[0.9,1.0]",
];

fn generate(out: &Path, extra: &[&str]) -> Command {
    let mut c = motorfactory();
    c.args(["generate", "--quiet", "--out"])
        .arg(out)
        .args(SMALL)
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Every temporary file below `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    files_below(dir)
        .into_keys()
        .filter(|k| k.ends_with(".tmp"))
        .collect()
}

fn manifest_lines(path: &Path) -> usize {
    std::fs::read_to_string(path).map_or(0, |t| t.lines().count())
}

/// Waits until `path` holds `n` manifest lines, or the child ends.
fn wait_for_rows(child: &mut Child, path: &Path, n: usize) {
    let start = Instant::now();
    while manifest_lines(path) < n {
        assert!(child.try_wait().unwrap().is_none(), "the run ended early");
        assert!(start.elapsed() < Duration::from_secs(60), "no progress");
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_second_run_into_a_busy_folder_is_refused_and_the_first_finishes_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let mut first = generate(&out, &["-n", "40", "--seed", "7", "--jobs", "1"])
        .spawn()
        .unwrap();
    wait_for_rows(&mut first, &out.join("manifest.jsonl"), 1);
    for extra in [
        &["-n", "40", "--seed", "8"][..],
        &["-n", "40", "--seed", "7", "--resume"],
        &["-n", "40", "--seed", "7", "--shard", "1/2", "--resume"],
    ] {
        let o = generate(&out, extra).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains("writing into it"), "{err}");
    }
    ok(&first.wait_with_output().unwrap());
    let alone = dir.path().join("alone");
    ok(&generate(&alone, &["-n", "40", "--seed", "7"])
        .output()
        .unwrap());
    assert_same_dataset(&out, &alone);
}

#[test]
fn shards_merge_their_manifests_and_a_resume_reads_them() {
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one");
    ok(&generate(&one, &["-n", "6"]).output().unwrap());
    let shards = dir.path().join("shards");
    for s in ["2/3", "0/3", "1/3"] {
        ok(&generate(&shards, &["-n", "6", "--shard", s, "--resume"])
            .output()
            .unwrap());
        // the merged manifest comes with the last shard
        assert_eq!(shards.join("manifest.jsonl").exists(), s == "1/3");
    }
    assert_same_dataset(&one, &shards);
    // a shard run again, as a requeued task is, finds its work done
    let o = generate(&shards, &["-n", "6", "--shard", "1/3", "--resume"])
        .output()
        .unwrap();
    ok(&o);
    // an unsharded run needs --resume there, and then has nothing to make
    let o = generate(&shards, &["-n", "6"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("already holds 6 samples"));
    let before = dataset_files(&shards);
    let o = motorfactory()
        .args(["generate", "--out"])
        .arg(&shards)
        .args(SMALL)
        .args(["-n", "6", "--resume"])
        .output()
        .unwrap();
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("0 samples made (6 already done)"), "{err}");
    assert_eq!(before, dataset_files(&shards));
}

/// A token whose writer is gone, and a live one this test holds the lock of.
const DEAD: &str = "00000000deadbeef";
const LIVE: &str = "00000000a11ce000";

#[test]
fn a_resume_removes_dead_runs_temporaries_and_keeps_live_ones() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    ok(&generate(&out, &["-n", "2"]).output().unwrap());
    let live_lock = out.join(format!(".motorfactory/writers/{LIVE}.lock"));
    let held = File::create(&live_lock).unwrap();
    held.lock().unwrap();
    // a dead writer's lock file, not held, and temporaries of every file the tool renames
    File::create(out.join(format!(".motorfactory/writers/{DEAD}.lock"))).unwrap();
    let dead: Vec<PathBuf> = [
        "config.toml",
        "labels.json",
        "manifest.jsonl",
        "train/000001_A1_noisy.ply",
        "validation/000004_B0_clean.npy",
    ]
    .iter()
    .map(|f| out.join(format!("{f}.{DEAD}.tmp")))
    .collect();
    // named like a temporary, but its token is no writer recorded in the folder: not the tool's
    let unrecorded = out.join("train/000007_A1_noisy.ply.0123456789abcdef.tmp");
    let live = out.join(format!("train/000009_B1_noisy.ply.{LIVE}.tmp"));
    let foreign = out.join("train/notes.tmp");
    for f in dead.iter().chain([&unrecorded, &live, &foreign]) {
        std::fs::write(f, b"half").unwrap();
    }
    ok(&generate(&out, &["-n", "3", "--resume"]).output().unwrap());
    for f in &dead {
        assert!(!f.exists(), "{} left", f.display());
    }
    assert!(live.exists(), "a live writer's temporary file was removed");
    for f in [&foreign, &unrecorded] {
        assert!(f.exists(), "a file the tool does not write was removed");
    }
    assert!(
        !out.join(format!(".motorfactory/writers/{DEAD}.lock"))
            .exists()
    );
    drop(held);
    ok(&generate(&out, &["-n", "3", "--resume"]).output().unwrap());
    assert!(!live.exists(), "its writer is gone now");
    assert_eq!(
        temporaries(&out),
        [
            "train/000007_A1_noisy.ply.0123456789abcdef.tmp",
            "train/notes.tmp"
        ]
    );
}

#[test]
fn runs_killed_at_any_moment_resume_to_the_same_bytes_and_leave_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let args = ["-n", "10", "--jobs", "2"];
    ok(&generate(&whole, &args).output().unwrap());
    let part = dir.path().join("part");
    // kills spread over the whole run: before the first file, between files, at the end
    for delay_ms in [0u64, 3, 7, 12, 20, 30, 45, 60, 80, 110, 150, 200] {
        let mut child = generate(&part, &[&args[..], &["--resume"]].concat())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay_ms));
        child.kill().unwrap();
        child.wait().unwrap();
    }
    ok(&generate(&part, &[&args[..], &["--resume"]].concat())
        .output()
        .unwrap());
    assert_eq!(temporaries(&part), Vec::<String>::new());
    assert_same_dataset(&whole, &part);
}

#[test]
fn sigterm_finishes_the_samples_in_flight_and_a_resume_completes_the_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let args = ["-n", "30", "--jobs", "1"];
    ok(&generate(&whole, &args).output().unwrap());
    let part = dir.path().join("part");
    let mut child = generate(&part, &args).spawn().unwrap();
    wait_for_rows(&mut child, &part.join("manifest.jsonl"), 2);
    signal(child.id(), "TERM");
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(143), "{err}");
    assert!(err.contains("--resume finishes"), "{err}");
    // the manifest is whole and sorted, and lists exactly the samples on disk
    let text = std::fs::read_to_string(part.join("manifest.jsonl")).unwrap();
    let indices: Vec<u64> = text
        .lines()
        .map(|l| {
            serde_json::from_str::<serde_json::Value>(l).unwrap()["index"]
                .as_u64()
                .unwrap()
        })
        .collect();
    assert!(indices.len() < 30 && indices.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(temporaries(&part), Vec::<String>::new());
    ok(&generate(&part, &[&args[..], &["--resume"]].concat())
        .output()
        .unwrap());
    assert_eq!(dataset_files(&whole), dataset_files(&part));
}

fn signal(pid: u32, name: &str) {
    let s = Command::new("kill")
        .args([&format!("-{name}"), &pid.to_string()])
        .status()
        .unwrap();
    assert!(s.success());
}

/// `unshare --pid --fork --mount-proc` runs a command as PID 1 of a PID namespace of its own,
/// as a container runtime does; None where this user may not.
fn unshare() -> Option<Command> {
    let probe = Command::new("unshare")
        .args(["--pid", "--fork", "--mount-proc", "true"])
        .stderr(Stdio::null())
        .status();
    if !probe.is_ok_and(|s| s.success()) {
        eprintln!("skipped: unshare --pid --fork --mount-proc is not allowed here");
        return None;
    }
    let mut c = Command::new("unshare");
    c.args(["--pid", "--fork", "--mount-proc", "--kill-child"]);
    Some(c)
}

#[test]
fn four_shards_in_their_own_pid_namespaces_equal_a_single_run() {
    let Some(_) = unshare() else { return };
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one");
    ok(&generate(&one, &["-n", "8"]).output().unwrap());
    for round in 0..20 {
        let shared = dir.path().join(format!("shared{round}"));
        let children: Vec<Child> = (0..4)
            .map(|i| {
                let mut c = unshare().unwrap();
                c.arg(env!("CARGO_BIN_EXE_motorfactory"))
                    .args(["generate", "--quiet", "--out"])
                    .arg(&shared)
                    .args(SMALL)
                    .args(["-n", "8", "--jobs", "1", "--resume"])
                    .args(["--shard", &format!("{i}/4")])
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            ok(&c.wait_with_output().unwrap());
        }
        assert_same_dataset(&one, &shared);
    }
}

#[test]
fn as_pid_1_sigterm_still_stops_the_run() {
    let Some(mut c) = unshare() else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pod");
    let mut child = c
        .arg(env!("CARGO_BIN_EXE_motorfactory"))
        .args(["generate", "--quiet", "--out"])
        .arg(&out)
        .args(SMALL)
        .args(["-n", "40", "--jobs", "1"])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for_rows(&mut child, &out.join("manifest.jsonl"), 1);
    // the tool is the namespace's PID 1: unshare's only child
    let children =
        std::fs::read_to_string(format!("/proc/{0}/task/{0}/children", child.id())).unwrap();
    let pid1: u32 = children.trim().parse().unwrap();
    signal(pid1, "TERM");
    let start = Instant::now();
    let o = child.wait_with_output().unwrap();
    assert!(start.elapsed() < Duration::from_secs(10));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("stopped by signal 15"), "{err}");
    assert!(manifest_lines(&out.join("manifest.jsonl")) < 40);
}

/// The fenced block of `docs/datasets.md` that follows the line starting with `after`.
fn recipe(after: &str) -> String {
    let doc =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/datasets.md")).unwrap();
    let from = doc
        .find(after)
        .unwrap_or_else(|| panic!("{after} in datasets.md"));
    let block = &doc[from..];
    let start = block.find("```").unwrap();
    let body = &block[start..];
    let body = &body[body.find('\n').unwrap() + 1..];
    body[..body.find("```").unwrap()].to_string()
}

/// Runs a recipe's shell text with the test's binary on the PATH, `vars` set, and the dataset
/// made smaller and written to `out`.
fn run_recipe(script: &str, folder: &str, out: &Path, vars: &[(&str, String)]) -> Command {
    let script = script
        .replace("-n 100000", "-n 16")
        .replace(folder, out.to_str().unwrap());
    let bin = Path::new(env!("CARGO_BIN_EXE_motorfactory"))
        .parent()
        .unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
    let mut c = Command::new("sh");
    c.args(["-c", &script])
        .env("PATH", path)
        .envs(vars.iter().cloned())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

#[test]
fn the_slurm_and_kubernetes_recipes_finish_their_shards_when_requeued_or_restarted() {
    let dir = tempfile::tempdir().unwrap();
    let single = dir.path().join("single");
    ok(&motorfactory()
        .args([
            "generate", "--quiet", "--config", "synmotor", "-n", "16", "--out",
        ])
        .arg(&single)
        .output()
        .unwrap());

    // Slurm: every task of the array, then task 3 requeued after it finished
    let slurm = recipe("Slurm, 16 array tasks");
    let out = dir.path().join("slurm");
    for task in (0..16).chain([3]) {
        ok(&run_recipe(
            &slurm,
            "/shared/synmotor",
            &out,
            &[("SLURM_ARRAY_TASK_ID", task.to_string())],
        )
        .output()
        .unwrap());
    }
    assert_same_dataset(&single, &out);

    // Kubernetes: the container's command; pod 5 killed at once and restarted
    let job = recipe("Kubernetes, an indexed Job");
    let line = job.lines().find(|l| l.contains("command:")).unwrap();
    let script =
        line[line.find("\"sh\", \"-c\", \"").unwrap() + 13..line.rfind("\"]").unwrap()].to_string();
    let out = dir.path().join("k8s");
    let pod = |i: u32| {
        run_recipe(
            &script,
            "/data/synmotor",
            &out,
            &[("JOB_COMPLETION_INDEX", i.to_string())],
        )
    };
    let mut killed = pod(5).spawn().unwrap();
    std::thread::sleep(Duration::from_millis(30));
    killed.kill().unwrap();
    killed.wait().unwrap();
    for i in 0..16 {
        ok(&pod(i).output().unwrap());
    }
    assert_same_dataset(&single, &out);
}
