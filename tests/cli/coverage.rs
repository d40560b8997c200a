//! `coverage`: the share seen per view and per sample.

use super::*;

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
