//! The motorfactory binary end to end: outputs, exit codes, nothing written on bad input, and
//! the same bytes for any thread count.

use std::path::Path;
use std::process::Output;

use kit::{documented_sensor, files_below, motorfactory, run, stderr};

mod kit;

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
    let files = files_below(&out);
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
        files_below(&out)
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
fn params_lists_every_parameter_with_its_range_default_and_meaning() {
    let o = run(&["params"]);
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    let entries: Vec<&str> = text.split_terminator("\n\n").collect();
    assert_eq!(entries.len(), motorgen::params::PARAMS.len());
    for (entry, p) in entries.iter().zip(motorgen::params::PARAMS) {
        let lines: Vec<&str> = entry.lines().collect();
        let allowed = format!("    {}; default {}", p.kind.allowed(), p.default.value());
        assert_eq!(lines, [p.key, &allowed, &format!("    {}", p.doc)]);
    }
}

#[test]
fn the_parameter_table_in_the_docs_is_what_params_prints() {
    let o = run(&["params", "--markdown"]);
    assert!(o.status.success());
    let table = String::from_utf8(o.stdout).unwrap();
    assert_eq!(table.lines().count(), motorgen::params::PARAMS.len() + 2);
    let doc = std::fs::read_to_string("docs/motors.md").unwrap();
    let (_, rest) = doc.split_once("<!-- params:begin -->\n").unwrap();
    let (documented, _) = rest.split_once("<!-- params:end -->").unwrap();
    assert_eq!(
        documented, table,
        "docs/motors.md: paste `motorfactory params --markdown` between the params markers"
    );
}

#[test]
fn the_cli_reference_lists_every_command_and_option() {
    let doc = std::fs::read_to_string("docs/cli.md").unwrap();
    let sections: Vec<&str> = doc.split("\n## `").skip(1).collect();
    let commands = [
        "motor", "motors", "params", "scan", "generate", "config", "preview", "coverage",
    ];
    let documented: Vec<&str> = sections
        .iter()
        .map(|s| s.split('`').next().unwrap())
        .collect();
    assert_eq!(documented, commands);
    for (command, section) in commands.iter().zip(&sections) {
        let help = String::from_utf8(run(&[command, "--help"]).stdout).unwrap();
        let options = help
            .split_whitespace()
            .filter_map(|w| w.strip_prefix("--"))
            .map(|w| w.trim_end_matches(|c: char| !c.is_ascii_alphanumeric()))
            .filter(|w| !w.is_empty() && *w != "help");
        for option in options {
            assert!(
                section.contains(&format!("--{option}")),
                "docs/cli.md, `{command}`: --{option} is not documented"
            );
        }
    }
}

#[test]
fn scan_of_a_motor_keeps_its_labels() {
    let dir = tempfile::tempdir().unwrap();
    let m = coarse_motor(dir.path(), &["--format", "ply,stl"]);
    let scan_to = |name: &str| {
        let out = dir.path().join(name);
        let o = run(&[
            "scan",
            "--mesh",
            m.join("motor.ply").to_str().unwrap(),
            "--mesh",
            m.join("cover_bolt_1.stl").to_str().unwrap(),
            "--sensor",
            "zivid-2plus-m130",
            "--sampling",
            "blueSubsample4x4",
            "--look-at",
            "0.05,-1.2,0.6,0,0,0.09",
            "--format",
            "ply,pcd,pcd-ascii,npy,npz",
            "--images",
            "--seed",
            "3",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        out
    };
    let out = scan_to("s");
    let files = files_below(&out);
    for f in [
        "cloud.ply",
        "cloud.pcd",
        "cloud_ascii.pcd",
        "cloud.npy",
        "cloud.npz",
        "depth.png",
        "depth.npy",
        "normals.png",
        "labels.png",
        "instances.png",
        "intensity.png",
        "rgb.png",
        "wear.png",
        "scan.json",
    ] {
        assert!(files.contains_key(f), "{f}");
    }
    let summary: serde_json::Value = serde_json::from_slice(&files["scan.json"]).unwrap();
    assert_eq!(summary["pixels"]["width"], 612);
    let points = summary["points"].as_u64().unwrap();
    assert!(points > 1000, "{points}");
    // N×7 float32 after a 128-byte header: every SynMotor class of the visible parts appears
    let npy = &files["cloud.npy"];
    assert_eq!(npy.len(), 128 + points as usize * 7 * 4);
    let labels: std::collections::BTreeSet<u32> = npy[128..]
        .chunks_exact(28)
        .map(|r| f32::from_le_bytes(r[24..28].try_into().unwrap()) as u32)
        .collect();
    assert!(
        [1, 2, 4, 6].iter().all(|c| labels.contains(c)),
        "{labels:?}"
    );
    // the same seed gives the same bytes
    let again = scan_to("s2");
    assert!(files_below(&again) == files);
}

#[test]
fn scan_meshes_take_their_material_from_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let m = coarse_motor(dir.path(), &["--format", "ply"]);
    let motor = m.join("motor.ply");
    // the motor's mean signal and SNR in black plastic and in white plastic
    let signal = |mesh: String, extra: &[&str]| {
        let out = dir.path().join(format!("s{}", extra.len() + mesh.len()));
        let mut args = vec!["scan", "--mesh", &mesh, "--sampling", "blueSubsample4x4"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--look-at", "0.05,-0.9,0.6,0,0,0.09", "--format", "ply"]);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let o = run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let ply = std::fs::read(out.join("cloud.ply")).unwrap();
        let body = ply
            .split_at(ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11)
            .1;
        // x y z nx ny nz intensity snr (float), rgb, class, instance, wear: 45 bytes a point
        let n = body.len() / 45;
        let mean = |at: usize| {
            body.chunks_exact(45)
                .map(|r| f32::from_le_bytes(r[at..at + 4].try_into().unwrap()) as f64)
                .sum::<f64>()
                / n as f64
        };
        (mean(24), mean(28))
    };
    let path = motor.to_str().unwrap();
    let dark = signal(format!("{path}@black-pa66"), &[]);
    let white = signal(format!("{path}@white-plastic"), &[]);
    let by_flag = signal(path.to_string(), &["--material", "black-pa66"]);
    assert_eq!(dark, by_flag);
    assert!(
        white.0 > 2.0 * dark.0 && white.1 > 1.3 * dark.1,
        "{white:?} vs {dark:?}"
    );
}

#[test]
fn scan_bad_input_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o_str = out.to_str().unwrap();
    let empty = dir.path().join("empty.obj");
    std::fs::write(&empty, "# nothing\n").unwrap();
    let garbage = dir.path().join("garbage.stl");
    std::fs::write(&garbage, "not an stl").unwrap();
    let bad_index = dir.path().join("bad_index.ply");
    std::fs::write(&bad_index, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").unwrap();
    let cube = dir.path().join("cube.obj");
    std::fs::write(&cube, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let bad_sensor = dir.path().join("bad.toml");
    let mut spec = toml::to_string(&sensor::SensorSpec::preset("ideal").unwrap()).unwrap();
    spec = spec.replace("fx = 2481.0", "fx = -1.0");
    std::fs::write(&bad_sensor, spec).unwrap();
    let cube_s = cube.to_str().unwrap();
    let cube_unobtainium = format!("{cube_s}@unobtainium");
    let la = "0,0,-2,0,0,0";
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "scan",
                "--mesh",
                bad_index.to_str().unwrap(),
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "a face uses vertex 7, but there are 3 vertices",
        ),
        (
            vec![
                "scan",
                "--mesh",
                "/no/such.obj",
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "cannot read mesh /no/such.obj",
        ),
        (
            vec![
                "scan",
                "--mesh",
                empty.to_str().unwrap(),
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "no triangles",
        ),
        (
            vec![
                "scan",
                "--mesh",
                garbage.to_str().unwrap(),
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "cannot read mesh",
        ),
        (
            vec![
                "scan",
                "--mesh",
                "mesh.fbx",
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "expected obj, stl or ply",
        ),
        (
            vec![
                "scan",
                "--mesh",
                &cube_unobtainium,
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "material = \"unobtainium\" is not allowed: expected one of black-pa66,",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--material",
                "chrome",
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "--material: material = \"chrome\" is not allowed",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--sensor",
                "zivid-9",
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "--sensor \"zivid-9\" is not allowed: expected a preset",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--sensor",
                bad_sensor.to_str().unwrap(),
                "--look-at",
                la,
                "--out",
                o_str,
            ],
            "intrinsics.fx = -1",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--look-at",
                "1,2,3",
                "--out",
                o_str,
            ],
            "expected 6 comma-separated numbers",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--look-at",
                "1,1,1,1,1,1",
                "--out",
                o_str,
            ],
            "eye and target must differ",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--look-at",
                la,
                "--format",
                "las",
                "--out",
                o_str,
            ],
            "--format \"las\"",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--look-at",
                la,
                "--sampling",
                "by3x3",
                "--out",
                o_str,
            ],
            "--sampling = \"by3x3\" is not allowed: expected one of all, by2x2, by4x4, blueSubsample2x2",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--look-at",
                la,
                "--sensor",
                "zivid-2plus-mr60",
                "--sampling",
                "blueSubsample2x2",
                "--out",
                o_str,
            ],
            "--sampling = \"blueSubsample2x2\" is not allowed: expected one of all, by2x2, by4x4 on zivid-2plus-mr60",
        ),
        (
            vec![
                "scan",
                "--mesh",
                cube_s,
                "--look-at",
                la,
                "--sampling",
                "by2x2",
                "--out",
                o_str,
            ],
            "--sampling = \"by2x2\" is not allowed: expected one of all, blueSubsample2x2, redSubsample2x2, blueSubsample4x4, redSubsample4x4 on zivid-2plus-m130",
        ),
    ];
    assert_refused(&cases, &out);
}

#[test]
fn the_documented_custom_sensor_is_a_valid_sensor() {
    let spec: sensor::SensorSpec = toml::from_str(&documented_sensor()).unwrap();
    spec.validate().unwrap();
    assert_eq!(spec.noise.axial.per_metre, 1.5e-4);
    assert!(matches!(spec.model, sensor::Model::StructuredLight { .. }));
}

#[test]
fn the_documented_materials_are_the_library() {
    let doc = std::fs::read_to_string("docs/sensors.md").unwrap();
    let table = doc.split("## Materials").nth(1).unwrap();
    let rows: Vec<Vec<String>> = table
        .lines()
        .filter(|l| l.starts_with("| `"))
        .map(|l| l.split('|').map(|c| c.trim().to_string()).collect())
        .collect();
    assert_eq!(rows.len(), sensor::MATERIALS.len());
    for (row, (name, m)) in rows.iter().zip(sensor::MATERIALS) {
        let colour = m.colour.map(|c| format!("{c:.2}")).join(", ");
        let values = [m.reflectivity, m.specular, m.lobe].map(|v| v.to_string());
        assert_eq!(row[1], format!("`{name}`"));
        assert_eq!(row[2..5], values, "{name}");
        assert_eq!(row[5], colour, "{name}");
    }
}

#[test]
fn scan_files_are_identical_for_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let m = coarse_motor(dir.path(), &["--format", "ply", "--whole-only"]);
    let scan_with = |threads: &str| {
        let out = dir.path().join(format!("s{threads}"));
        let o = motorfactory()
            .env("RAYON_NUM_THREADS", threads)
            .args([
                "scan",
                "--mesh",
                m.join("motor.ply").to_str().unwrap(),
                "--sensor",
                "zivid-2plus-m130",
                "--sampling",
                "blueSubsample4x4",
                "--look-at",
                "0.05,-1.2,0.6,0,0,0.09",
                "--format",
                "ply,pcd,npz",
                "--images",
                "--seed",
                "11",
                "--out",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        files_below(&out)
    };
    let (one, two) = (scan_with("1"), scan_with("2"));
    assert_eq!(one.len(), 13); // 3 clouds, 9 images, scan.json
    assert!(one == two, "scan files differ between 1 and 2 threads");
}

/// A `scan` of `mesh` from 1 m into `out`.
fn scan_mesh(mesh: &Path, out: &Path) -> Output {
    motorfactory()
        .args([
            "scan",
            "--sampling",
            "blueSubsample4x4",
            "--look-at",
            "0,0,-1,0,0,0",
            "--mesh",
        ])
        .arg(mesh)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

#[test]
fn meshes_are_read_only_from_regular_files_and_only_as_far_as_they_say() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    // an OBJ whose material library is an endless device: materials are never read
    let obj = dir.path().join("zero.obj");
    std::fs::write(
        &obj,
        "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let o = scan_mesh(&obj, &dir.path().join("zero"));
    assert!(o.status.success(), "{}", stderr(&o));
    // a FIFO is refused at once instead of waiting for a writer
    let fifo = dir.path().join("pipe.ply");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let o = scan_mesh(&fifo, &out);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
    // a binary STL that says 1 triangle but holds 2
    let mut stl = vec![0u8; 80];
    stl.extend(1u32.to_le_bytes());
    stl.extend(vec![0u8; 100]);
    let short = dir.path().join("short.stl");
    std::fs::write(&short, &stl).unwrap();
    let o = scan_mesh(&short, &out);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("a binary STL of 1 triangles has 134 bytes, but the file has 184"),
        "{}",
        stderr(&o)
    );
    // a truncated binary STL and a binary file posing as OBJ: in words, no raw bytes
    let cut = dir.path().join("cut.stl");
    std::fs::write(&cut, &stl[..120]).unwrap();
    let nul = dir.path().join("nul.obj");
    std::fs::write(&nul, b"v 0 0 0\n\0\0\xff\xfe binary\n").unwrap();
    // found by fuzzing: an element without properties, which a PLY reader would read forever
    let empty_element = dir.path().join("empty-element.ply");
    std::fs::write(
        &empty_element,
        b"ply\nformat binary_little_endian 1.0\nelement vfthdz\t11111111111\nend_header\ner\n\x01\0\0 \0",
    )
    .unwrap();
    let promises = dir.path().join("promises.ply");
    std::fs::write(
        &promises,
        "ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float x\nend_header\n0\n",
    )
    .unwrap();
    for (mesh, says) in [
        (&cut, "134 bytes"),
        (&nul, "it holds no triangles"),
        (&empty_element, "element vfthdz has no properties"),
        (&promises, "promises 1000000000 elements"),
    ] {
        let o = scan_mesh(mesh, &out);
        assert_eq!(o.status.code(), Some(2));
        let err = stderr(&o);
        assert!(err.contains(says), "{err}");
        assert!(!err.contains('\0') && err.len() < 300, "{err}");
    }
    assert!(!out.exists());
}

#[test]
fn a_ply_with_an_instance_per_face_keeps_each_instance_and_its_labels() {
    let dir = tempfile::tempdir().unwrap();
    // a strip of 2,000 triangles, each its own instance, sharing vertices with its neighbours
    let n = 2000;
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {n}\nproperty list uchar int vertex_indices\n\
         property ushort class\nproperty uint instance\nend_header\n",
        n + 2
    );
    for i in 0..n + 2 {
        ply += &format!(
            "{} {} 0\n",
            (i / 2) as f32 * 0.001 - 0.5,
            (i % 2) as f32 * 0.01
        );
    }
    for i in 0..n {
        ply += &format!("3 {i} {} {} {} {}\n", i + 1, i + 2, 1 + i % 5, i + 1);
    }
    let mesh = dir.path().join("strip.ply");
    std::fs::write(&mesh, ply).unwrap();
    let out = dir.path().join("scan");
    let o = motorfactory()
        .args([
            "scan",
            "--sensor",
            "ideal",
            "--look-at",
            "0,0,-1,0,0,0",
            "--format",
            "npz",
        ])
        .arg("--mesh")
        .arg(&mesh)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = stderr(&o);
    assert!(summary.contains(&format!("({n} triangles)")), "{summary}");
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

#[test]
fn an_earlier_motor_output_is_refused_unless_replaced_and_then_removed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m");
    let o = out.to_str().unwrap();
    let motor =
        |extra: &[&str]| run(&[&["motor", "--detail", "coarse", "--out", o][..], extra].concat());
    assert!(motor(&["--format", "obj,stl"]).status.success());
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let refused = motor(&["--format", "ply"]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(stderr(&refused).contains("already holds a motor; pass --replace"));
    let o2 = motor(&["--format", "ply", "--set", "type=B", "--replace"]);
    assert!(o2.status.success(), "{}", stderr(&o2));
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    // type B's parts in PLY, the user's file, nothing of the type A motor
    assert!(names.contains(&"gear.ply".to_string()) && names.contains(&"notes.txt".to_string()));
    assert!(
        !names
            .iter()
            .any(|n| n.ends_with(".obj") || n.ends_with(".stl") || n == "lower_gear.ply"),
        "{names:?}"
    );

    let many = dir.path().join("many");
    let m = many.to_str().unwrap();
    let motors = |n: &str, extra: &[&str]| {
        run(&[
            &[
                "motors", "-n", n, "--detail", "coarse", "--quiet", "--out", m,
            ][..],
            extra,
        ]
        .concat())
    };
    assert!(motors("3", &[]).status.success());
    assert_eq!(motors("2", &[]).status.code(), Some(2));
    assert!(motors("2", &["--replace"]).status.success());
    assert!(
        !many.join("motor_000002").exists(),
        "a motor beyond the new count is left"
    );
    assert_eq!(
        std::fs::read_to_string(many.join("attributes.csv"))
            .unwrap()
            .lines()
            .count(),
        3
    );
}

#[test]
fn coverage_writes_the_share_seen_per_view_and_per_sample() {
    let dir = tempfile::tempdir().unwrap();
    // three views of motor 2 standing, at 612×512, from 40° to 70° off the vertical
    let coverage = |out: &Path| {
        run(&[
            "coverage",
            "--views",
            "3",
            "--index",
            "2",
            "--clamping",
            "pole-pot-up",
            "--set",
            "sensor.sampling=blueSubsample4x4",
            "--set",
            "camera.tilt_deg=[40,70]",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let out = dir.path().join("c");
    let o = coverage(&out);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("coverage.json")).unwrap()).unwrap();
    assert_eq!(json["clamping"], "pole-pot-up");
    // the first view of each sample, as numpy's .npy: a 128-byte header, then int32s
    let npy = std::fs::read(out.join("first_view.npy")).unwrap();
    let first: Vec<i32> = npy[128..]
        .chunks(4)
        .map(|b| i32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    assert_eq!(
        first.len() as u64,
        json["surface"]["samples"].as_u64().unwrap()
    );
    // the surface samples' PLY: positions, normals, colour and labels, no measurement fields
    let ply = std::fs::read(out.join("surface.ply")).unwrap();
    let end = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&ply[..end]).unwrap();
    assert!(header.contains("property uint16 class\nproperty int instance\nend_header"));
    for unmeasured in ["intensity", "snr", "wear"] {
        assert!(!header.contains(unmeasured), "{header}");
    }
    assert_eq!(ply.len() - end, 33 * first.len());
    let views = json["views"].as_array().unwrap();
    assert_eq!(views.len(), 3);
    let mut last = 0.0;
    for (k, v) in views.iter().enumerate() {
        let seen = first.iter().filter(|&&f| f >= 0 && f <= k as i32).count();
        let coverage = v["coverage"].as_f64().unwrap();
        assert!((coverage - seen as f64 / first.len() as f64).abs() < 1e-6);
        assert!(coverage >= last && v["points"].as_u64().unwrap() > 1000);
        assert!(out.join(format!("view_{k}.ply")).exists());
        last = coverage;
    }
    assert!((json["coverage"].as_f64().unwrap() - last).abs() < 1e-9 && last > 0.2);
    for (part, c) in json["coverage_per_part"].as_object().unwrap() {
        assert!((0.0..=1.0).contains(&c.as_f64().unwrap()), "{part}");
    }
    // the same command, the same bytes
    let again = dir.path().join("d");
    assert!(coverage(&again).status.success());
    for name in [
        "coverage.json",
        "surface.ply",
        "first_view.npy",
        "view_2.ply",
    ] {
        assert_eq!(
            std::fs::read(out.join(name)).unwrap(),
            std::fs::read(again.join(name)).unwrap(),
            "{name}"
        );
    }
    let bad = dir.path().join("never");
    let b = bad.to_str().unwrap();
    assert_refused(
        &[
            (
                vec!["coverage", "--clamping", "sideways", "--out", b],
                "sideways",
            ),
            (
                vec!["coverage", "--density", "5", "--out", b],
                "density = 5 is not allowed",
            ),
            (
                vec!["coverage", "--max-angle", "120", "--out", b],
                "max_angle = 120 is not allowed",
            ),
            (vec!["coverage", "--views", "0", "--out", b], "--views"),
            (
                vec!["coverage", "--set", "cell.clamping=upside", "--out", b],
                "cell.clamping",
            ),
        ],
        &bad,
    );
}
