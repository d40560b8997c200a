//! What a run may touch: only what it wrote, inside its folder, never through a symbolic link or
//! a name read from a file; refusals that leave nothing behind and never take another run's
//! files; files that are not regular refused at once; messages without Rust's words.

use std::os::unix::fs::symlink;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use kit::{documented_sensor, motorfactory, run, stderr};

mod kit;

/// Runs `command` to its end, or kills it after 20 s and fails.
fn within_20_s(mut command: Command) -> Output {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            panic!("{command:?} still runs after 20 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// `generate` arguments whose shard 1 of 8 is refused (its first sample is out of the M60's
/// range), while shards 3 and 4 make their samples.
fn far_shard(part: u32, out: &Path) -> Command {
    let mut c = motorfactory();
    c.args([
        "generate",
        "--set",
        "camera.distance=[0.3,4.0]",
        "--set",
        "sensor.sampling=blueSubsample4x4",
        "-n",
        "8",
        "--resume",
        "--quiet",
        "--shard",
        &format!("{part}/8"),
        "--out",
    ])
    .arg(out);
    c
}

#[test]
fn a_refused_shard_never_removes_what_live_shards_write() {
    let dir = tempfile::tempdir().unwrap();
    for trial in 0..4 {
        let out = dir.path().join(format!("d{trial}"));
        // the refused shard makes the folder; the others join while it makes its first sample
        let mut runs = vec![far_shard(1, &out).stderr(Stdio::null()).spawn().unwrap()];
        while !out.exists() {
            std::thread::sleep(Duration::from_micros(200));
        }
        for part in [3, 4] {
            runs.push(far_shard(part, &out).stderr(Stdio::null()).spawn().unwrap());
        }
        let codes: Vec<Option<i32>> = runs
            .into_iter()
            .map(|c| c.wait_with_output().unwrap().status.code())
            .collect();
        assert_eq!(codes, [Some(2), Some(0), Some(0)], "trial {trial}");
        for shard in ["manifest-3-of-8.jsonl", "manifest-4-of-8.jsonl"] {
            let rows = std::fs::read_to_string(out.join(shard)).unwrap();
            assert_eq!(rows.lines().count(), 1, "trial {trial}: {shard}");
        }
        assert!(out.join("config.toml").is_file());
    }
    // alone in a folder it made, a refused run leaves nothing
    let alone = dir.path().join("alone");
    let o = far_shard(1, &alone).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!alone.exists(), "a refused run left {}", alone.display());
}

#[test]
fn replace_removes_only_the_names_this_program_writes() {
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("m");
    let m_str = m.to_str().unwrap();
    let o = run(&[
        "motor", "--detail", "coarse", "--format", "obj,stl", "--out", m_str,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // an attributes.json naming files elsewhere, and files of the user's beside the motor's
    let victim = dir.path().join("victim");
    std::fs::create_dir(&victim).unwrap();
    for name in ["precious.obj", "precious.stl"] {
        std::fs::write(victim.join(name), b"keep").unwrap();
    }
    let absolute = victim.join("precious");
    let json = serde_json::json!({ "attributes": { "parts": [
        { "name": "../victim/precious" },
        { "name": absolute.to_str().unwrap() },
        { "name": "notes" },
    ] } });
    std::fs::write(m.join("attributes.json"), json.to_string()).unwrap();
    for name in ["notes.obj", "cover_01.stl", "bolt.obj"] {
        std::fs::write(m.join(name), b"mine").unwrap();
    }
    symlink(victim.join("precious.obj"), m.join("side_bolt_9.obj")).unwrap();
    let o = run(&[
        "motor",
        "--detail",
        "coarse",
        "--format",
        "ply",
        "--replace",
        "--out",
        m_str,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for name in ["precious.obj", "precious.stl"] {
        assert_eq!(std::fs::read(victim.join(name)).unwrap(), b"keep");
    }
    let left: std::collections::BTreeSet<String> = std::fs::read_dir(&m)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| !n.ends_with(".ply"))
        .collect();
    let expected = [
        "attributes.json",
        "bolt.obj",
        "cover_01.stl",
        "notes.obj",
        "side_bolt_9.obj",
    ];
    assert_eq!(left, expected.map(String::from).into());
}

#[test]
fn lock_files_and_temporaries_are_never_reached_through_links_or_guessed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d");
    let args = |out: &Path| {
        let mut c = motorfactory();
        c.args(["generate", "-n", "2", "--quiet", "--resume", "--set"])
            .args(["sensor.sampling=blueSubsample4x4", "--out"])
            .arg(out);
        c
    };
    let o = args(&out).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    // a writers folder linked to somewhere else: refused, the lock files there kept
    let elsewhere = dir.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    std::fs::write(elsewhere.join("0123456789abcdef.lock"), b"").unwrap();
    let writers = out.join(".motorfactory/writers");
    std::fs::remove_dir_all(&writers).unwrap();
    symlink(&elsewhere, &writers).unwrap();
    let o = args(&out).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("not a plain folder"), "{}", stderr(&o));
    assert!(elsewhere.join("0123456789abcdef.lock").exists());
    std::fs::remove_file(&writers).unwrap();
    std::fs::create_dir(&writers).unwrap();
    // a run lock that is a dangling link: refused, its target never made
    let run_lock = out.join(".motorfactory/run.lock");
    std::fs::remove_file(&run_lock).unwrap();
    symlink(dir.path().join("made"), &run_lock).unwrap();
    let o = args(&out).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("symbolic link"), "{}", stderr(&o));
    assert!(!dir.path().join("made").exists());
    std::fs::remove_file(&run_lock).unwrap();
    // a file of the user's named like a temporary, and a lock file a killed run left before
    // its rename: the first stays, the second goes
    let notes = out.join("train/notes.0123456789abcdef.tmp");
    std::fs::write(&notes, b"mine").unwrap();
    let stale = out.join(".motorfactory/writers/fedcba9876543210.new");
    std::fs::write(&stale, b"").unwrap();
    let o = args(&out).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&notes).unwrap(), b"mine");
    assert!(!stale.exists());
}

#[test]
fn every_sweep_value_is_checked_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("sweep.toml");
    // the 17th value of the second sweep is out of range; its combination comes late
    let distances: Vec<String> = (0..17)
        .map(|k| {
            if k < 16 {
                format!("{:.2}", 0.5 + 0.01 * k as f64)
            } else {
                "-1".into()
            }
        })
        .collect();
    std::fs::write(
        &config,
        format!(
            "samples = 40\n[[sweep]]\nkey = \"seed\"\nlist = [1, 2, 3]\n\
             [[sweep]]\nkey = \"camera.distance\"\nlist = [{}]\n",
            distances.join(", ")
        ),
    )
    .unwrap();
    let out = dir.path().join("d");
    for resume in [false, true] {
        let mut args = vec!["generate", "--config", config.to_str().unwrap()];
        args.extend(["--quiet", "--out", out.to_str().unwrap()]);
        if resume {
            args.push("--resume");
        }
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("camera.distance = -1"),
            "{}",
            stderr(&o)
        );
        assert!(!out.exists(), "a refused sweep wrote {}", out.display());
    }
}

#[test]
fn unusable_output_folders_are_refused_in_words_and_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    // a dangling link as --out: refused, the link kept
    let link = dir.path().join("link");
    symlink(dir.path().join("nowhere"), &link).unwrap();
    let o = run(&["generate", "-n", "1", "--out", link.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("symbolic link to nothing"),
        "{}",
        stderr(&o)
    );
    assert!(std::fs::symlink_metadata(&link).is_ok());
    // motors refused (more than memory holds) leave no folder
    let m = dir.path().join("m");
    let o = run(&[
        "motors",
        "-n",
        "18446744073709551615",
        "--out",
        m.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!m.exists());
    // a read-only folder, existing or to be made in it: exit 2 both (root writes anyway)
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::os::unix::fs::PermissionsExt::from_mode(0o555)).unwrap();
    if std::fs::write(ro.join("probe"), b"").is_err() {
        for out in [ro.clone(), ro.join("sub")] {
            let o = run(&[
                "generate",
                "-n",
                "1",
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ]);
            assert_eq!(
                o.status.code(),
                Some(2),
                "{}: {}",
                out.display(),
                stderr(&o)
            );
            assert!(stderr(&o).contains("cannot"), "{}", stderr(&o));
        }
    }
}

#[test]
fn the_memory_estimate_heeds_the_address_space_limit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d");
    // 20 M samples keep 10 GB of manifest rows: more than a 6 GiB address space
    let mut sh = Command::new("sh");
    sh.arg("-c").arg(format!(
        "ulimit -v 6291456 && exec {} generate -n 20000000 --out {}",
        env!("CARGO_BIN_EXE_motorfactory"),
        out.display()
    ));
    let o = within_20_s(sh);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("of memory"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn configurations_and_records_are_read_only_from_regular_files() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo.toml");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let zero = dir.path().join("zero.toml");
    symlink("/dev/zero", &zero).unwrap();
    let dataset = dir.path().join("dataset");
    std::fs::create_dir(&dataset).unwrap();
    assert!(
        Command::new("mkfifo")
            .arg(dataset.join("manifest.jsonl"))
            .status()
            .unwrap()
            .success()
    );
    let out = dir.path().join("never");
    let o_str = out.to_str().unwrap();
    for file in [&fifo, &zero] {
        let f = file.to_str().unwrap();
        for args in [
            vec!["generate", "--config", f, "--out", o_str],
            vec!["motors", "-n", "1", "--config", f, "--out", o_str],
            vec!["motor", "--config", f, "--out", o_str],
            vec![
                "scan",
                "--mesh",
                f,
                "--sensor",
                f,
                "--look-at",
                "0,-1,1,0,0,0",
                "--out",
                o_str,
            ],
        ] {
            let mut c = motorfactory();
            c.args(&args);
            let o = within_20_s(c);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
            assert!(
                stderr(&o).contains("not a regular file"),
                "{args:?}: {}",
                stderr(&o)
            );
            assert!(!out.exists());
        }
    }
    let mut c = motorfactory();
    c.args(["preview"])
        .arg(&dataset)
        .args(["--out", &format!("{o_str}.png")]);
    let o = within_20_s(c);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
}

#[test]
fn reading_errors_are_short_and_free_of_rust_words() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let long = format!("samples = 5\n[camera\nrig = \"{}\"\n", "x".repeat(2000));
    let syntax = write("syntax.toml", &long);
    let no_kind = write("model.toml", "name = \"x\"\nmodel = 5\n");
    let sensor = documented_sensor();
    assert!(sensor.contains("k1 = -0.1"));
    let distortion = write("lens.toml", &sensor.replace("k1 = -0.1", "k1 = 500.0"));
    let ply = write(
        "bad.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n3 0 1 q\n",
    );
    let out = dir.path().join("never");
    let o_str = out.to_str().unwrap();
    let look = ["--look-at", "0,-1,1,0,0,0"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["generate", "--config", &syntax, "--out", o_str],
            "line 2, column",
        ),
        (
            vec!["motors", "-n", "1", "--config", &syntax, "--out", o_str],
            "line 2, column",
        ),
        (
            vec!["generate", "--set", "seed=-1", "--out", o_str],
            "a whole number from 0",
        ),
        (
            [
                &["scan", "--mesh", &ply, "--sensor", &no_kind][..],
                &look,
                &["--out", o_str],
            ]
            .concat(),
            "a table with a `kind` key",
        ),
        (
            [&["scan", "--mesh", &ply][..], &look, &["--out", o_str]].concat(),
            "not a valid PLY file",
        ),
    ];
    let mut cases = cases;
    cases.push((
        [
            &["scan", "--mesh", &ply, "--sensor", &distortion][..],
            &look,
            &["--out", o_str],
        ]
        .concat(),
        "k1 = 500",
    ));
    for (args, message) in &cases {
        let o = run(args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains(message), "{args:?}: {e}");
        assert!(e.len() < 400, "{args:?}: {} characters: {e}", e.len());
        for rust in [
            "u64",
            "internally tagged",
            "Distortion {",
            "ParseError",
            "LineCol",
            "\n  |",
        ] {
            assert!(!e.contains(rust), "{args:?}: {e}");
        }
        assert!(!out.exists());
    }
}
