//! The rules every command follows: bad input exits 2 with a message in words and writes
//! nothing, work that cannot fit is refused first, a closed output ends quietly, nothing is
//! silent.

use super::*;

#[test]
fn bad_input_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o_str = out.to_str().unwrap();
    let bad_config = dir.path().join("bad.toml");
    std::fs::write(&bad_config, "seed = 1\nformatz = [\"obj\"]\n").unwrap();
    let bad_param = dir.path().join("bad_param.toml");
    std::fs::write(
        &bad_param,
        "[params]\nupper_gear_diameter = { uniform = [0.05, 0.09] }\n",
    )
    .unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["motor", "--set", "pole_pot_lenght=0.07", "--out", o_str],
            "did you mean `pole_pot_length`",
        ),
        (
            vec!["motor", "--set", "pole_pot_length=0.5", "--out", o_str],
            "pole_pot_length = 0.5 is not allowed: expected a number from 0.062 to 0.082",
        ),
        (
            vec!["motor", "--set", "mirror=maybe", "--out", o_str],
            "mirror = \"maybe\" is not allowed: expected true or false",
        ),
        (
            vec!["motor", "--set", "type", "--out", o_str],
            "expected KEY=VALUE",
        ),
        (
            vec!["motor", "--format", "fbx", "--out", o_str],
            "format = \"fbx\" is not allowed: expected obj, stl, ply or glb",
        ),
        (
            vec!["motor", "--detail", "ultra", "--out", o_str],
            "--detail \"ultra\"",
        ),
        (
            vec![
                "motors",
                "-n",
                "3",
                "--config",
                bad_config.to_str().unwrap(),
                "--out",
                o_str,
            ],
            "unknown field `formatz`",
        ),
        (
            vec![
                "motors",
                "-n",
                "3",
                "--config",
                bad_param.to_str().unwrap(),
                "--out",
                o_str,
            ],
            "upper_gear_diameter: uniform range [0.05, 0.09] leaves the allowed values",
        ),
        (
            vec![
                "motors",
                "-n",
                "3",
                "--config",
                "/no/such/file.toml",
                "--out",
                o_str,
            ],
            "/no/such/file.toml",
        ),
    ];
    assert_refused(&cases, &out);
    // an output path that cannot be a folder
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let o = run(&["motor", "--out", file.join("sub").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("cannot create output folder"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn work_that_cannot_fit_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o_str = out.to_str().unwrap();
    let mut spec = sensor::SensorSpec::preset("ideal").unwrap();
    spec.intrinsics.width = 16384;
    spec.intrinsics.height = 16384;
    let mut config = toml::Table::new();
    config.insert("sensor".into(), toml::toml! { sampling = "all" }.into());
    config["sensor"]
        .as_table_mut()
        .unwrap()
        .insert("spec".into(), toml::Value::try_from(&spec).unwrap());
    let huge_config = dir.path().join("huge-config.toml");
    std::fs::write(&huge_config, toml::to_string(&config).unwrap()).unwrap();
    let sweep = dir.path().join("sweep.toml");
    std::fs::write(
        &sweep,
        "[[sweep]]\nkey = \"camera.distance\"\nlinspace = [0, 10, 4294967295]\n",
    )
    .unwrap();
    let max_jobs = (4 * std::thread::available_parallelism().unwrap().get()).to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["generate", "-n", "9223372036854775807", "--out", o_str],
            "of memory",
        ),
        (
            vec!["generate", "-n", "1000000000", "--out", o_str],
            "lower --jobs, -n",
        ),
        (
            vec![
                "generate",
                "--config",
                sweep.to_str().unwrap(),
                "--out",
                o_str,
            ],
            "4294967295 values; a sweep takes 1 to 100000",
        ),
        (
            vec![
                "generate",
                "--jobs",
                &max_jobs,
                "--config",
                huge_config.to_str().unwrap(),
                "--out",
                o_str,
            ],
            "16384x16384",
        ),
        (
            vec!["generate", "--jobs", "100000", "--out", o_str],
            "--jobs",
        ),
        (
            vec!["motors", "-n", "2", "--jobs", "0", "--out", o_str],
            "--jobs",
        ),
    ];
    assert_refused(&cases, &out);
}

#[test]
fn messages_say_what_is_allowed_in_words_and_stay_short() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o_str = out.to_str().unwrap();
    let long = format!("camera.rig=\"{}\"", "x".repeat(100_000));
    let nul = dir.path().join("nul.toml");
    std::fs::write(&nul, b"seed = \"\0\0\0\"\n").unwrap();
    let set = |kv: &'static str| vec!["generate", "--set", kv, "--out", o_str];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            set("camera.distance=\"far\""),
            "expected a number or [min, max]",
        ),
        (set("camera.distance=[1, 2, 3]"), "a number or [min, max]"),
        (set("camera.views=\"two\""), "expected a whole number"),
        (set("seed=-1"), "expected a whole number from 0"),
        (set("motor=3"), "expected a table"),
        (set("motor.variants=\"A0\""), "expected a list"),
        (set("cell.clearance=[1]"), "expected a number"),
        (set("cell.wear.pole_pot=[0, 2]"), "cell.wear.pole_pot"),
        (set("cell.wear.rust=[0, 9]"), "rust types 1 to 9"),
        (set("cell.wear.variation=0.9"), "cell.wear.variation"),
        (set("cell.wear.mask=\"patchy\""), "unknown variant"),
        (set("augment.clean.occluders=1"), "expected true or false"),
        (set("camera.distanse=1"), "did you mean `distance`?"),
        (set("output.formats=[\"plyy\"]"), "did you mean `ply`?"),
        (
            set("sensor.preset=zivid-2plus-m6"),
            "did you mean `zivid-2plus-m60`?",
        ),
        (set("samples=0"), "samples = 0 is not allowed"),
        (
            vec!["generate", "--set", &long, "--out", o_str],
            "unknown variant",
        ),
        (
            vec![
                "generate",
                "--config",
                nul.to_str().unwrap(),
                "--out",
                o_str,
            ],
            "line 1, column 9",
        ),
        (
            vec!["generate", "--config", "synmtor", "--out", o_str],
            "did you mean `synmotor`?",
        ),
        (
            vec!["generate", "-n", "-1", "--out", o_str],
            "must be a positive whole number",
        ),
        (
            vec!["motors", "-n", "-5", "--out", o_str],
            "must be a positive whole number",
        ),
        (
            vec!["generate", "--seed", "-1", "--out", o_str],
            "a whole number from 0",
        ),
        (
            vec![
                "scan",
                "--sensor",
                "zivid-2plus-m13",
                "--mesh",
                "x.obj",
                "--look-at",
                "0,0,1,0,0,0",
                "--out",
                o_str,
            ],
            "did you mean `zivid-2plus-m130`?",
        ),
    ];
    for (args, says) in &cases {
        let o = run(args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(err.len() < 700, "{args:?}: {} bytes of message", err.len());
        assert!(!err.contains('\0'), "{args:?}: raw bytes");
        for rust in [
            "untagged", "u32", "u64", "f32", "struct ", "sequence", "enum ",
        ] {
            assert!(!err.contains(rust), "{args:?} names a Rust type: {err}");
        }
        assert!(!out.exists());
    }
}

#[test]
fn a_full_or_closed_standard_output_ends_the_command_without_a_panic() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    for args in [
        &["config", "--list"][..],
        &["config", "--print", "zivid"],
        &["params"],
    ] {
        let o = motorfactory()
            .args(args)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("cannot write to standard output"),
            "{}",
            stderr(&o)
        );
    }
    // a reader that stops early (`| head -1`): quiet, success
    let mut child = motorfactory()
        .arg("params")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(stderr(&o), "");
}

#[test]
fn empty_scans_and_samples_are_never_silent() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o_str = out.to_str().unwrap();
    let m = coarse_motor(dir.path(), &["--format", "ply", "--whole-only"]);
    let mesh = m.join("motor.ply");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        // the Kinect starts at 0.7 m; the default camera is 0.56-0.64 m away
        (
            vec![
                "generate",
                "--set",
                "sensor.preset=kinect-v1",
                "--set",
                "sensor.sampling=by2x2",
                "--out",
                o_str,
            ],
            "the sensor (kinect-v1) measures depths (camera z) from 0.7 to 6 m, and the nearest surface in view is 0.5",
        ),
        (
            vec![
                "generate",
                "--set",
                "camera.distance=[1.2, 1.3]",
                "--out",
                o_str,
            ],
            "measures depths (camera z) from 0.3 to 1.1 m, and the nearest surface in view is 1.",
        ),
        (
            vec![
                "scan",
                "--mesh",
                mesh.to_str().unwrap(),
                "--sensor",
                "zivid-2plus-m130",
                "--look-at",
                "0,0,0.7,0,0,0",
                "--out",
                o_str,
            ],
            "the scan holds no point: the sensor zivid-2plus-m130 measures depths (camera z) from 0.8 \
             to 2 m, and the nearest surface in view is 0.5",
        ),
        (
            vec![
                "scan",
                "--mesh",
                mesh.to_str().unwrap(),
                "--look-at",
                "0,0,-2,0,0,-3",
                "--out",
                o_str,
            ],
            "no surface is in view",
        ),
    ];
    assert_refused(&cases, &out);
    // later samples that come out empty are written, and said
    let o = run(&[
        "generate",
        "-n",
        "10",
        "--quiet",
        "--set",
        "camera.distance=[1.0, 1.25]",
        "--out",
        o_str,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning: 4 samples hold no point (the first: sample 2)"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn preview_and_scan_options_follow_the_common_rules() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("ds");
    let o = run(&[
        "generate",
        "-n",
        "2",
        "--quiet",
        "--out",
        ds.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let d = ds.to_str().unwrap();
    let missing = dir.path().join("missing/sheet.png");
    let jpg = dir.path().join("sheet.jpg");
    for (args, says) in [
        (
            vec!["preview", d, "--out", missing.to_str().unwrap()],
            "does not exist",
        ),
        (
            vec!["preview", d, "--out", jpg.to_str().unwrap()],
            "a PNG image",
        ),
        (
            vec!["preview", d, "--count", "0", "--out", "x.png"],
            "positive whole number",
        ),
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
    }
    assert!(!missing.exists() && !jpg.exists());
    // the configuration's unit names work for scan too
    let m = coarse_motor(dir.path(), &["--format", "ply", "--whole-only"]);
    let scan = dir.path().join("scan");
    let o = run(&[
        "scan",
        "--mesh",
        m.join("motor.ply").to_str().unwrap(),
        "--sampling",
        "blueSubsample4x4",
        "--look-at",
        "0.05,-1.2,0.6,0,0,0.09",
        "--units",
        "millimetres",
        "--out",
        scan.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(scan.join("scan.json")).unwrap()).unwrap();
    assert_eq!(summary["units"], "millimetres");
}
