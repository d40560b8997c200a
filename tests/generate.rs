//! `motorfactory generate` end to end: a small dataset checked file by file, identical bytes for
//! any --jobs and for shards, kill and resume, and every kind of bad configuration refused.

use std::path::Path;
use std::process::{Output, Stdio};

use glam::{Affine3A, Mat4, Vec3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use kit::{assert_same_dataset, dataset_files, motorfactory};

mod kit;

fn generate(out: &Path, extra: &[&str]) -> Output {
    motorfactory()
        .args(["generate", "--quiet", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

/// Small and quick: a Zivid 2+ M130 binned 4x4 (612x512) at 0.9-1 m.
fn small(n: &str, extra: &[&str]) -> Vec<String> {
    let base = [
        "-n",
        n,
        "--set",
        "sensor.preset=zivid-2plus-m130",
        "--set",
        "camera.distance=[0.9,1.0]",
    ];
    base.iter().chain(extra).map(|s| s.to_string()).collect()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Manifest rows of every manifest in `dir`, sorted.
fn rows(dir: &Path) -> Vec<String> {
    let mut rows: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_str()
                .unwrap()
                .starts_with("manifest")
        })
        .flat_map(|p| {
            std::fs::read_to_string(p)
                .unwrap()
                .lines()
                .map(String::from)
                .collect::<Vec<_>>()
        })
        .collect();
    rows.sort();
    rows
}

fn args(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

fn read_ply(path: &Path) -> Vec<(Vec3, u16)> {
    let mut f = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let ply = Parser::<DefaultElement>::new().read_ply(&mut f).unwrap();
    ply.payload["vertex"]
        .iter()
        .map(|v| {
            let f = |k: &str| match v[k] {
                Property::Float(x) => x,
                ref p => panic!("{k}: {p:?}"),
            };
            let class = match v["class"] {
                Property::UShort(c) => c,
                ref p => panic!("class: {p:?}"),
            };
            (Vec3::new(f("x"), f("y"), f("z")), class)
        })
        .collect()
}

#[test]
fn small_dataset_is_complete_labelled_cropped_and_listed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    let a = small(
        "10",
        &["--set", r#"output.formats=["ply","npy","npz","pcd"]"#],
    );
    ok(&generate(&out, &args(&a)));
    let manifest = std::fs::read_to_string(out.join("manifest.jsonl")).unwrap();
    let rows: Vec<serde_json::Value> = manifest
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(rows.len(), 10);
    let mut seen = [0u64; 7];
    let mut listed = std::collections::BTreeSet::new();
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row["index"], i as u64, "sorted by index");
        let json_path = out.join(row["json"].as_str().unwrap());
        let doc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
        listed.insert(row["json"].as_str().unwrap().to_string());
        assert_eq!(doc["index"], row["index"]);
        assert_eq!(doc["split"], row["split"]);
        for f in row["files"].as_array().unwrap() {
            assert!(out.join(f.as_str().unwrap()).is_file(), "{f}");
            listed.insert(f.as_str().unwrap().to_string());
        }
        let ply = row["files"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_str().unwrap())
            .find(|f| f.ends_with(".ply"))
            .unwrap();
        let points = read_ply(&out.join(ply));
        assert_eq!(points.len() as u64, row["points"][0].as_u64().unwrap());
        assert!(points.len() > 5_000, "{} points", points.len());
        // every point inside the crop box (world), up to the jitter after cropping
        let m: [[f32; 4]; 4] =
            serde_json::from_value(doc["views"][0]["camera_to_world"].clone()).unwrap();
        let pose = Affine3A::from_mat4(Mat4::from_cols_array_2d(&m).transpose());
        let lo: Vec3 = serde_json::from_value(doc["crop"]["min"].clone()).unwrap();
        let hi: Vec3 = serde_json::from_value(doc["crop"]["max"].clone()).unwrap();
        let jitter: Vec3 = serde_json::from_value(doc["jitter"].clone()).unwrap();
        let slack = jitter.length() + 1e-5;
        for (p, class) in &points {
            let w = pose.transform_point3(*p);
            assert!(
                w.cmpge(lo - slack).all() && w.cmple(hi + slack).all(),
                "{w} outside {lo}..{hi}"
            );
            seen[*class as usize] += 1;
        }
        let counts: Vec<u64> = serde_json::from_value(row["class_counts"].clone()).unwrap();
        assert_eq!(counts.iter().sum::<u64>(), points.len() as u64);
    }
    assert!(seen.iter().all(|&n| n > 0), "classes seen: {seen:?}");
    // the manifest lists every sample file, and nothing else is there
    let on_disk: std::collections::BTreeSet<String> = dataset_files(&out)
        .into_keys()
        .filter(|k| k.starts_with("train") || k.starts_with("validation"))
        .collect();
    assert_eq!(on_disk, listed);
    // labels and the resolved config
    let labels: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("labels.json")).unwrap()).unwrap();
    assert_eq!(labels["classes"].as_array().unwrap().len(), 7);
    assert_eq!(labels["classes"][6]["name"], "cover_bolt");
    let config = std::fs::read_to_string(out.join("config.toml")).unwrap();
    assert!(config.contains("samples = 10"), "{config}");
    // the card: each class's share of the points and of the samples, as the manifest counts
    let card = std::fs::read_to_string(out.join("dataset-card.md")).unwrap();
    assert!(card.starts_with("# Dataset card\n\n10 samples"), "{card}");
    let counts: Vec<Vec<u64>> = rows
        .iter()
        .map(|r| serde_json::from_value(r["class_counts"].clone()).unwrap())
        .collect();
    let total: u64 = counts.iter().flatten().sum();
    for (id, name) in ["background", "cover", "gear_container", "charger", "bottom"]
        .iter()
        .enumerate()
    {
        let of: u64 = counts.iter().filter_map(|c| c.get(id)).sum();
        let holding = counts.iter().filter(|c| c.get(id) > Some(&0)).count();
        let line = format!(
            "| {id} | `{name}` | {:.2} % | {holding} of 10 |",
            100.0 * of as f64 / total as f64
        );
        assert!(card.contains(&line), "{line} not in\n{card}");
    }
    // the preview draws it
    let png = dir.path().join("sheet.png");
    let o = motorfactory()
        .args(["preview", out.to_str().unwrap(), "--width", "96", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    ok(&o);
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
}

#[test]
fn same_bytes_for_any_jobs_and_for_the_union_of_shards() {
    let dir = tempfile::tempdir().unwrap();
    // with images and their COCO annotations, gathered by the shard that completes the set
    let a = small(
        "6",
        &[
            "--set",
            "output.images=true",
            "--set",
            "output.coco=polygons",
            "--set",
            "output.yolo=segment",
        ],
    );
    let one = dir.path().join("one");
    ok(&generate(&one, &[&args(&a)[..], &["--jobs", "1"]].concat()));
    let two = dir.path().join("two");
    ok(&generate(&two, &[&args(&a)[..], &["--jobs", "2"]].concat()));
    assert_same_dataset(&one, &two);
    let shards = dir.path().join("shards");
    for s in ["0/3", "1/3", "2/3"] {
        ok(&generate(
            &shards,
            &[&args(&a)[..], &["--shard", s]].concat(),
        ));
    }
    assert_same_dataset(&one, &shards);
    assert!(shards.join("manifest-2-of-3.jsonl").is_file());
    for split in ["train", "validation"] {
        let coco = std::fs::read_to_string(one.join(format!("annotations/instances_{split}.json")));
        assert!(coco.unwrap().contains("\"segmentation\":[["), "{split}");
    }
    let yaml = std::fs::read_to_string(one.join("yolo/data.yaml")).unwrap();
    assert!(
        yaml.contains("val: images/val\nnames:\n  0: cover\n"),
        "{yaml}"
    );
}

#[test]
fn images_writes_the_kinds_it_names_and_the_colour_image_once_encoded() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    let a = small(
        "1",
        &[
            "--set",
            "output.images=[\"rgb\", \"depth\"]",
            "--set",
            "output.yolo=detect",
        ],
    );
    ok(&generate(&out, &args(&a)));
    let names: Vec<String> = std::fs::read_dir(out.join("train"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    let stem = names.iter().find_map(|n| n.strip_suffix(".json")).unwrap();
    let mut images: Vec<&str> = names
        .iter()
        .filter_map(|n| n.strip_prefix(stem)?.strip_prefix('_'))
        .collect();
    images.sort();
    assert_eq!(images, ["depth.npy", "depth.png", "rgb.png"]);
    let rgb = std::fs::read(out.join(format!("train/{stem}_rgb.png"))).unwrap();
    let yolo = std::fs::read(out.join(format!("yolo/images/train/{stem}.png"))).unwrap();
    assert!(rgb.starts_with(b"\x89PNG") && rgb == yolo);
}

#[test]
fn killed_run_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let a = small("16", &["--jobs", "1"]);
    let whole = dir.path().join("whole");
    ok(&generate(&whole, &args(&a)));

    let part = dir.path().join("part");
    let mut child = motorfactory()
        .args(["generate", "--quiet", "--out"])
        .arg(&part)
        .args(args(&a))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let manifest = part.join("manifest.jsonl");
    let count = || {
        std::fs::read_to_string(&manifest)
            .map(|t| t.lines().count())
            .unwrap_or(0)
    };
    while count() < 3 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done = count();
    assert!(done < 16, "the run finished before it was killed");
    // what a kill can leave: a torn manifest line and a temporary file
    let mut m = std::fs::OpenOptions::new()
        .append(true)
        .open(&manifest)
        .unwrap();
    std::io::Write::write_all(&mut m, b"{\"index\":15,\"spl").unwrap();
    std::fs::write(
        part.join("train/000015_B0_noisy.npy.0000000000004242.tmp"),
        b"half",
    )
    .unwrap();
    std::fs::write(
        part.join(".motorfactory/writers/0000000000004242.lock"),
        b"",
    )
    .unwrap();

    let refused = generate(&part, &args(&a));
    assert_eq!(
        refused.status.code(),
        Some(2),
        "a second run needs --resume"
    );
    ok(&generate(&part, &[&args(&a)[..], &["--resume"]].concat()));
    assert_same_dataset(&whole, &part);
}

#[test]
fn a_dataset_extended_with_resume_equals_one_made_at_its_final_size() {
    let dir = tempfile::tempdir().unwrap();
    let grown = dir.path().join("grown");
    ok(&generate(&grown, &args(&small("3", &[]))));
    ok(&generate(&grown, &args(&small("5", &["--resume"]))));
    let fresh = dir.path().join("fresh");
    ok(&generate(&fresh, &args(&small("5", &[]))));
    assert_eq!(dataset_files(&grown), dataset_files(&fresh));
    assert_eq!(rows(&grown), rows(&fresh));
    // shrinking below what is there is refused
    let o = generate(&grown, &args(&small("2", &["--resume"])));
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("beyond the 2"));
}

#[test]
fn bad_configurations_are_refused_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let bad_file = dir.path().join("bad.toml");
    std::fs::write(&bad_file, "[camera]\ndistanse = [0.5, 0.6]\n").unwrap();
    let syntax = dir.path().join("syntax.toml");
    std::fs::write(&syntax, "[camera\n").unwrap();
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, "").unwrap();
    let under_file = blocker.join("ds");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--config", bad_file.to_str().unwrap()], "distanse"),
        (vec!["--config", syntax.to_str().unwrap()], "syntax.toml"),
        (vec!["--config", "nonexistent.toml"], "nonexistent.toml"),
        (
            vec!["--set", "camera.distance=[0.9, 0.1]"],
            "camera.distance",
        ),
        (vec!["--set", "camera.views=\"two\""], "camera.views"),
        (vec!["--set", "sensor.preset=zivid-9"], "zivid-9"),
        (vec!["--set", "sensor.sampling=by3x3"], "sensor.sampling"),
        (
            vec!["--set", "sensor.noise.dropout.rate=2.0"],
            "dropout.rate",
        ),
        (
            vec!["--set", "motor.params.pole_pot_length=0.5"],
            "pole_pot_length",
        ),
        (vec!["--set", "motor.params.colour=red"], "colour"),
        (vec!["--set", "motor.variants=[\"C3\"]"], "C3"),
        (vec!["--set", "augment.clean.share=0.5"], "share"),
        (vec!["--set", "motor.cover_removed=0.5"], "inner10"),
        (vec!["--set", "output.formats=[\"las\"]"], "las"),
        (
            vec!["--set", "output.coco=\"rle\""],
            "output.coco = \"rle\" is not allowed: expected \"off\" unless output.images writes rgb",
        ),
        (
            vec![
                "--set",
                "output.images=[\"labels\"]",
                "--set",
                "output.coco=rle",
            ],
            "expected \"off\" unless output.images writes rgb",
        ),
        (
            vec!["--set", "output.images=[\"rgb\", \"colour\"]"],
            "output.images: true, false or a list of image kinds (depth, depth_clean, normals",
        ),
        (
            vec!["--set", "output.images=true", "--set", "output.coco=masks"],
            "output.coco",
        ),
        (
            vec!["--set", "output.yolo=detect"],
            "output.yolo = \"detect\" is not allowed: expected \"off\" unless output.images writes images",
        ),
        (vec!["--set", "nonsense"], "KEY=VALUE"),
        (vec!["--shard", "4/4"], "--shard"),
        (vec!["--jobs", "0"], "--jobs"),
    ];
    for (extra, message) in &cases {
        let o = generate(&out, extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(message), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?} wrote output");
    }
    let o = generate(&under_file, &["-n", "1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("output folder"));
    // a folder holding another dataset is refused too
    let ds = dir.path().join("ds");
    ok(&generate(&ds, &args(&small("1", &[]))));
    let o = generate(&ds, &args(&small("1", &["--seed", "5", "--resume"])));
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("another configuration"));
}

#[test]
fn built_in_configs_print_and_sweeps_vary_their_key() {
    let o = motorfactory()
        .args(["config", "--print", "default"])
        .output()
        .unwrap();
    ok(&o);
    assert_eq!(String::from_utf8_lossy(&o.stdout), scene::DEFAULT_CONFIG);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let a = small("4", &["--config", "sweep-pole-pot"]);
    ok(&generate(&out, &args(&a)));
    let lengths: Vec<f64> = rows(&out)
        .iter()
        .map(|r| {
            let row: serde_json::Value = serde_json::from_str(r).unwrap();
            let doc: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(out.join(row["json"].as_str().unwrap())).unwrap(),
            )
            .unwrap();
            let swept = doc["sweep"]["motor.params.pole_pot_length"]
                .as_f64()
                .unwrap();
            let built = doc["motor"]["params"]["pole_pot_length"].as_f64().unwrap();
            assert!((swept - built).abs() < 1e-6);
            built
        })
        .collect();
    let expected = [0.062, 0.067, 0.072, 0.077];
    for (l, e) in lengths.iter().zip(expected) {
        assert!((l - e).abs() < 1e-6, "{lengths:?}");
    }
}

#[test]
fn a_sweep_of_100000_combinations_starts_at_once_and_gives_each_sample_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("sweep.toml");
    std::fs::write(
        &config,
        "[[sweep]]\nkey = \"camera.distance\"\nlinspace = [0.55, 0.65, 1000]\n\n\
         [[sweep]]\nkey = \"camera.tilt_deg\"\nlinspace = [0, 9.9, 100]\n",
    )
    .unwrap();
    let out = dir.path().join("ds");
    ok(&generate(
        &out,
        &["--config", config.to_str().unwrap(), "-n", "102"],
    ));
    // the last sweep runs fastest: sample 101 takes distance 2 of 1000 and tilt 1 of 100
    let manifest = std::fs::read_to_string(out.join("manifest.jsonl")).unwrap();
    let row: serde_json::Value = serde_json::from_str(manifest.lines().last().unwrap()).unwrap();
    let doc: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join(row["json"].as_str().unwrap())).unwrap(),
    )
    .unwrap();
    assert_eq!(doc["index"], 101);
    let d = doc["sweep"]["camera.distance"].as_f64().unwrap();
    let t = doc["sweep"]["camera.tilt_deg"].as_f64().unwrap();
    assert!((d - (0.55 + 0.1 / 999.0)).abs() < 1e-9, "{d}");
    assert!((t - 0.1).abs() < 1e-9, "{t}");
}

#[test]
fn the_flat_layout_writes_the_same_files_under_names_that_carry_the_split() {
    let dir = tempfile::tempdir().unwrap();
    let (nested, flat) = (dir.path().join("nested"), dir.path().join("flat"));
    let a = small("12", &["--set", "output.formats=[\"npy\",\"ply\"]"]);
    ok(&generate(&nested, &args(&a)));
    ok(&generate(
        &flat,
        &args(&[&a[..], &["--set".into(), "output.layout=flat".into()]].concat()),
    ));
    let rows = |dir: &Path| -> Vec<serde_json::Value> {
        std::fs::read_to_string(dir.join("manifest.jsonl"))
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    let (n, f) = (rows(&nested), rows(&flat));
    assert_eq!(n.len(), 12);
    assert!(f.iter().any(|r| r["split"] == "validation"));
    for (n, f) in n.iter().zip(&f) {
        let prefix = if n["split"] == "train" {
            "Training_"
        } else {
            "Validation_"
        };
        let (nj, fj) = (n["json"].as_str().unwrap(), f["json"].as_str().unwrap());
        assert_eq!(
            fj,
            format!("json/{prefix}{}", nj.split_once('/').unwrap().1)
        );
        let files = |r: &serde_json::Value| -> Vec<String> {
            r["files"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| f.as_str().unwrap().into())
                .collect()
        };
        for (nf, ff) in files(n).iter().zip(files(f)) {
            let (_, name) = nf.split_once('/').unwrap();
            let ext = name.rsplit_once('.').unwrap().1;
            assert_eq!(ff, format!("{ext}/{prefix}{name}"));
            assert_eq!(
                std::fs::read(nested.join(nf)).unwrap(),
                std::fs::read(flat.join(&ff)).unwrap()
            );
        }
    }
    let mut folders: Vec<String> = std::fs::read_dir(&flat)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| !n.contains('.'))
        .collect();
    folders.sort();
    assert_eq!(folders, ["json", "npy", "ply"]);
}
