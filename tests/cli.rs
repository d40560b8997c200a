//! The motorfactory binary end to end: outputs, exit codes, nothing written on bad input, and
//! the same bytes for any thread count.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_motorfactory"))
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Every file below `dir`, by relative path.
fn tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(
                    p.strip_prefix(dir).unwrap().display().to_string(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

#[test]
fn motor_with_settings_writes_meshes_and_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let o = run(&[
        "motor",
        "--seed",
        "7",
        "--set",
        "type=B",
        "--set",
        "pole_pot_length=0.07",
        "--format",
        "obj,glb",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let files = tree(&out);
    for f in [
        "motor.obj",
        "motor.glb",
        "materials.mtl",
        "attributes.json",
        "pole_pot.obj",
        "gear.glb",
        "cover_bolt_3.obj",
    ] {
        assert!(
            files.contains_key(f),
            "{f} missing: {:?}",
            files.keys().collect::<Vec<_>>()
        );
    }
    let json: serde_json::Value = serde_json::from_slice(&files["attributes.json"]).unwrap();
    assert_eq!(json["params"]["type"], "B");
    assert!((json["params"]["pole_pot_length"].as_f64().unwrap() - 0.07).abs() < 1e-6);
    // unset parameters keep their defaults
    assert_eq!(json["params"]["bolt_drive"], "torx");
    assert_eq!(json["params"]["gearbox_orientation_deg"], 0);
}

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
    for (args, message) in cases {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
        assert!(!out.exists(), "{args:?} wrote output");
    }
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
fn motors_are_identical_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let go = |jobs: &str, name: &str| {
        let out = dir.path().join(name);
        let o = run(&[
            "motors",
            "-n",
            "6",
            "--seed",
            "3",
            "--jobs",
            jobs,
            "--detail",
            "coarse",
            "--format",
            "ply,stl",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        tree(&out)
    };
    let (one, two) = (go("1", "a"), go("2", "b"));
    assert_eq!(
        one.keys().collect::<Vec<_>>(),
        two.keys().collect::<Vec<_>>()
    );
    assert!(one == two, "files differ between 1 and 2 threads");
    let csv = String::from_utf8(one["attributes.csv"].clone()).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 7);
    assert!(lines[1].starts_with("motor_000000,") && lines[6].starts_with("motor_000005,"));
    assert!(
        one.contains_key("motor_000005/motor.ply")
            && one.contains_key("motor_000005/attributes.json")
    );
}

#[test]
fn params_lists_every_parameter() {
    let o = run(&["params"]);
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    for p in motorgen::params::PARAMS {
        assert!(text.contains(&format!("{}\n", p.key)), "{}", p.key);
    }
}
