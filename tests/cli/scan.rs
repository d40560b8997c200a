//! `scan`: labels kept, materials from the library, meshes read safely, the same bytes for any
//! thread count, bad input refused.

use super::*;

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
