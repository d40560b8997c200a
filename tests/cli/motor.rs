//! `motor`, `params` and the command reference: meshes and ground truth, the same bytes for
//! any thread count, an earlier output replaced only when asked.

use super::*;

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
