//! `scan` with a LiDAR: Blensor's files and ours, the same bytes for any thread count, bad
//! input refused.

use super::*;

/// A 40 m floor and a 2 m box 4 m ahead of the origin, as OBJ files in `dir`.
fn hall(dir: &Path) -> [std::path::PathBuf; 2] {
    let floor = dir.join("floor.obj");
    std::fs::write(
        &floor,
        "v -20 -20 0\nv 20 -20 0\nv 20 20 0\nv -20 20 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let block = dir.join("box.obj");
    let mut obj = String::new();
    for z in [0, 2] {
        for (x, y) in [(4, -1), (6, -1), (6, 1), (4, 1)] {
            obj += &format!("v {x} {y} {z}\n");
        }
    }
    for f in [
        [1, 3, 2],
        [1, 4, 3],
        [5, 6, 7],
        [5, 7, 8],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 4, 8],
        [3, 8, 7],
        [4, 1, 5],
        [4, 5, 8],
    ] {
        obj += &format!("f {} {} {}\n", f[0], f[1], f[2]);
    }
    std::fs::write(&block, obj).unwrap();
    [floor, block]
}

/// `scan` of the hall with `sensor` from 1.5 m over the origin into `out`, with `args`.
fn scan_hall(dir: &Path, sensor: &str, out: &Path, threads: &str, args: &[&str]) -> Output {
    let [floor, block] = hall(dir);
    motorfactory()
        .env("RAYON_NUM_THREADS", threads)
        .args(["scan", "--mesh"])
        .arg(floor)
        .arg("--mesh")
        .arg(format!("{}@white-plastic", block.display()))
        .args(["--sensor", sensor, "--look-at", "0,0,1.5,1,0,1.5", "--out"])
        .arg(out)
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn a_lidar_scan_writes_blensors_files_and_ours_the_same_for_any_threads() {
    let dir = tempfile::tempdir().unwrap();
    let all = [
        "--format",
        "blensor-numpy,blensor-pcd,npz,las,ply,pcd",
        "--seed",
        "5",
    ];
    let scan_with = |threads: &str| {
        let out = dir.path().join(format!("s{threads}"));
        let o = scan_hall(dir.path(), "velodyne-vlp16", &out, threads, &all);
        assert!(o.status.success(), "{}", stderr(&o));
        files_below(&out)
    };
    let files = scan_with("1");
    let names: Vec<&str> = files.keys().map(String::as_str).collect();
    assert_eq!(
        names,
        [
            "cloud.pcd",
            "cloud.ply",
            "scan.json",
            "scan.las",
            "scan.npz",
            "scan.numpy",
            "scan.pcd",
            "scan_noisy.pcd"
        ]
    );
    let summary: serde_json::Value = serde_json::from_slice(&files["scan.json"]).unwrap();
    assert_eq!(summary["rays"], 16 * 1800);
    let returns = summary["returns"].as_u64().unwrap() as usize;
    // the floor within 20 m takes the lasers at -15° to -5° in every column, the box more
    assert!(returns > 6 * 1800, "{returns}");
    // Blensor's .numpy: a row of 16 numbers a return, as numpy.savetxt writes them
    let numpy = std::str::from_utf8(&files["scan.numpy"]).unwrap();
    assert_eq!(numpy.lines().count(), returns);
    for line in numpy.lines().take(100) {
        let columns: Vec<&str> = line.split(' ').collect();
        assert_eq!(columns.len(), 16, "{line}");
        assert!(
            columns.iter().all(|c| c.len() == 24 || c.len() == 25),
            "{line}"
        );
        assert!(columns.iter().all(|c| c.parse::<f64>().is_ok()), "{line}");
    }
    // Blensor's PCD pair: the same points, the noisy ones moved along their rays
    for name in ["scan.pcd", "scan_noisy.pcd"] {
        let text = std::str::from_utf8(&files[name]).unwrap();
        assert!(text.starts_with("# .PCD v0.7"), "{name}");
        assert!(text.contains("FIELDS x y z rgb label\n"), "{name}");
        assert!(
            text.contains(&format!("\nPOINTS {returns}\nDATA ascii\n")),
            "{name}"
        );
        assert_eq!(text.lines().count(), 11 + returns, "{name}");
    }
    assert_ne!(files["scan.pcd"], files["scan_noisy.pcd"]);
    // LAS 1.4 (read back by laspy in CI): its signature, version and point count
    let las = &files["scan.las"];
    assert_eq!(&las[..4], b"LASF");
    assert_eq!((las[24], las[25]), (1, 4));
    assert_eq!(
        u64::from_le_bytes(las[247..255].try_into().unwrap()),
        returns as u64
    );
    assert!(
        files == scan_with("2"),
        "LiDAR files differ between 1 and 2 threads"
    );
}

#[test]
fn a_lidar_refuses_what_it_cannot_take_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let lasers = dir.path().join("lasers.toml");
    let mut lidar = toml::to_string(&sensor::Lidar::preset("generic-lidar").unwrap()).unwrap();
    lidar = lidar.replace("resolution = 0.25", "resolution = -1.0");
    std::fs::write(&lasers, lidar).unwrap();
    for (sensor, args, message) in [
        (
            "velodyne-vlp16",
            &["--sampling", "by2x2"][..],
            "a LiDAR takes neither",
        ),
        ("velodyne-vlp16", &["--images"], "a LiDAR takes neither"),
        ("velodyne-vlp16", &["--format", "e57"], "--format"),
        ("velodyne-vlp16", &["--frame", "lens"], "--frame"),
        (
            lasers.to_str().unwrap(),
            &[],
            "resolution must be a positive number",
        ),
        ("velodyne-vlp-16", &[], "did you mean `velodyne-vlp16`?"),
        (
            "velodyne-vlp16",
            &["--velocity", "1,0"],
            "--velocity 1,0: expected 3",
        ),
        (
            "zivid-2plus-m60",
            &["--velocity", "1,0,0"],
            "a camera takes neither",
        ),
        ("ideal", &["--turn", "5"], "a camera takes neither"),
    ] {
        let o = scan_hall(dir.path(), sensor, &out, "1", args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{sensor} {args:?}: {}",
            stderr(&o)
        );
        assert!(
            stderr(&o).contains(message),
            "{sensor} {args:?}: {}",
            stderr(&o)
        );
        assert!(!out.exists(), "{sensor} {args:?} wrote output");
    }
    // pointed straight up, the head has no forward direction
    let [floor, _] = hall(dir.path());
    let o = run(&[
        "scan",
        "--mesh",
        floor.to_str().unwrap(),
        "--sensor",
        "velodyne-hdl32e",
        "--look-at",
        "0,0,1,0,0,5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--look-at"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn a_generic_lidar_toml_scans_its_own_lasers() {
    let dir = tempfile::tempdir().unwrap();
    let lasers = dir.path().join("two.toml");
    let mut lidar = sensor::Lidar::preset("generic-lidar").unwrap();
    lidar.name = "two-layer".into();
    lidar.lasers[0].elevation = -10.0;
    lidar.lasers.push(sensor::lidar::Laser {
        elevation: -20.0,
        bias: 0.0,
        delay: 0.0,
        offset: 0.0,
    });
    // a spreading beam's dual returns: where its footprint straddles the box's edges
    lidar.beam = sensor::lidar::Beam {
        divergence: 0.01,
        samples: 16,
        echoes: sensor::lidar::Echoes::Dual,
        ..Default::default()
    };
    std::fs::write(&lasers, toml::to_string(&lidar).unwrap()).unwrap();
    let out = dir.path().join("s");
    let o = scan_hall(
        dir.path(),
        lasers.to_str().unwrap(),
        &out,
        "2",
        &["--format", "las"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("scan.json")).unwrap()).unwrap();
    assert_eq!(summary["sensor"]["name"], "two-layer");
    assert_eq!(summary["sensor"]["beam"]["echoes"], "dual");
    assert_eq!(summary["rays"], 2 * 1080);
    // LAS 1.4's header: the point count, then the points by return number
    let las = std::fs::read(out.join("scan.las")).unwrap();
    let word = |at: usize| u64::from_le_bytes(las[at..at + 8].try_into().unwrap());
    let (all, first, second) = (word(247), word(255), word(263));
    assert_eq!(all, summary["returns"].as_u64().unwrap());
    assert_eq!(first + second, all);
    assert!(
        second > 0 && second < first / 4,
        "{first} first and {second} second returns"
    );
}

#[test]
fn the_documented_lidar_presets_are_the_presets() {
    let doc = std::fs::read_to_string("docs/sensors.md").unwrap();
    let section = doc.split("## LiDARs").nth(1).unwrap();
    let table = section.split("### Presets").nth(1).unwrap();
    let rows: Vec<Vec<String>> = table
        .lines()
        .skip_while(|l| !l.starts_with("| preset"))
        .take_while(|l| l.starts_with('|'))
        .filter(|l| l.starts_with("| `"))
        .map(|l| l.split('|').map(|c| c.trim().to_string()).collect())
        .collect();
    let names: Vec<String> = rows
        .iter()
        .map(|r| r[1].trim_matches('`').to_string())
        .collect();
    assert_eq!(names, sensor::LIDAR_PRESETS);
    for row in &rows {
        let lidar = sensor::Lidar::preset(row[1].trim_matches('`')).unwrap();
        let lasers: usize = row[2].split(',').next().unwrap().parse().unwrap();
        assert_eq!(lasers, lidar.lasers.len(), "{}", row[1]);
        assert!(
            row[3].contains(&format!("{}°", lidar.resolution)),
            "{}",
            row[1]
        );
        assert_eq!(row[4], format!("{} Hz", lidar.rotation), "{}", row[1]);
        assert_eq!(row[5], format!("{} m", lidar.max_range), "{}", row[1]);
        assert_eq!(row[6], format!("{} m", lidar.noise.sigma), "{}", row[1]);
        let r = lidar.reflectivity;
        assert!(
            row[8].starts_with(&format!("{} m, {}, ", r.distance, r.limit)),
            "{}",
            row[1]
        );
    }
}

#[test]
fn a_moving_lidar_fires_each_laser_from_where_the_head_is() {
    let dir = tempfile::tempdir().unwrap();
    let scan = |name: &str, args: &[&str]| {
        let out = dir.path().join(name);
        let all = [&["--format", "npz", "--frame", "world"][..], args].concat();
        let o = scan_hall(dir.path(), "velodyne-vlp16", &out, "2", &all);
        assert!(o.status.success(), "{}", stderr(&o));
        let summary: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("scan.json")).unwrap()).unwrap();
        (std::fs::read(out.join("scan.npz")).unwrap(), summary)
    };
    let (still, s) = scan("still", &[]);
    let (driving, d) = scan("driving", &["--velocity", "1.5,0,0", "--turn", "-20"]);
    assert_eq!(s["motion"]["velocity"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(d["motion"]["velocity"], serde_json::json!([1.5, 0.0, 0.0]));
    assert_eq!(d["motion"]["turn"], -20.0);
    assert_ne!(still, driving);
}

/// `generate --config hall` into `out` with `args`, which succeeds: VLP-16 passes, two a hall,
/// LAS and NPZ.
fn generate_hall(out: &Path, args: &[&str]) {
    let done = motorfactory()
        .args(["generate", "--config", "hall", "--quiet", "--out"])
        .arg(out)
        .args([
            "--set",
            "lidar.preset=velodyne-vlp16",
            "--set",
            "lidar.revolutions=2",
        ])
        .args(args)
        .output()
        .unwrap();
    assert!(done.status.success(), "{}", stderr(&done));
}

#[test]
fn a_hall_dataset_is_the_same_for_any_jobs_shards_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let (one, two, sharded) = (
        dir.path().join("1"),
        dir.path().join("2"),
        dir.path().join("s"),
    );
    generate_hall(&one, &["-n", "3", "--jobs", "1"]);
    generate_hall(&one, &["-n", "5", "--jobs", "1", "--resume"]);
    generate_hall(&two, &["-n", "5", "--jobs", "2"]);
    for part in ["0/2", "1/2"] {
        generate_hall(&sharded, &["-n", "5", "--shard", part]);
    }
    kit::assert_same_dataset(&one, &two);
    kit::assert_same_dataset(&one, &sharded);
    let files = files_below(&one);
    let las: Vec<&String> = files.keys().filter(|k| k.ends_with(".las")).collect();
    assert_eq!(las.len(), 5, "{:?}", files.keys());
    let card = String::from_utf8(files["dataset-card.md"].clone()).unwrap();
    assert!(
        card.contains("the LiDAR `velodyne-vlp16`, 16 lasers"),
        "{card}"
    );
}
