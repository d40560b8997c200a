//! Parameter spaces: parsing, checks with clear errors, and deterministic sampling.

use motorgen::params::{Kind, PARAMS, Value, spec};
use motorgen::{Dist, Error, MotorParams, ParamSpace};

fn space(text: &str) -> Result<ParamSpace, Error> {
    ParamSpace::from_toml(&toml::from_str(text).unwrap())
}

#[test]
fn defaults_are_in_range_and_valid() {
    let p = MotorParams::default();
    for (key, value) in p.values() {
        spec(key).unwrap().check(&value).unwrap();
    }
    assert_eq!(p.variant(), "A1");
    assert_eq!(p.pole_pot_length, 0.068);
}

#[test]
fn bad_input_names_key_value_and_allowed() {
    let msg = |t: &str| space(t).unwrap_err().to_string();
    assert_eq!(
        msg("pole_pot_lenght = 0.07"),
        "unknown parameter `pole_pot_lenght`, did you mean `pole_pot_length`?"
    );
    assert_eq!(
        msg("pole_pot_length = 0.5"),
        "pole_pot_length = 0.5 is not allowed: expected a number from 0.062 to 0.082"
    );
    assert_eq!(
        msg("type = \"C\""),
        "type = \"C\" is not allowed: expected one of \"A\", \"B\""
    );
    assert_eq!(
        msg("mirror = 1"),
        "mirror = 1 is not allowed: expected true or false"
    );
    assert_eq!(
        msg("upper_bolt_count = 2.5"),
        "upper_bolt_count = 2.5 is not allowed: expected a whole number from 1 to 3"
    );
    assert_eq!(
        msg("gearbox_orientation_deg = 45"),
        "gearbox_orientation_deg = 45 is not allowed: expected one of 0 to 270 in steps of 90"
    );
    assert!(msg("pole_pot_length = { uniform = [0.07, 0.065] }").contains("min above max"));
    assert!(
        msg("pole_pot_length = { uniform = [0.05, 0.07] }").contains("leaves the allowed values")
    );
    assert!(msg("type = { uniform = [0, 1] }").contains("numeric parameter"));
    assert!(msg("type = { choice = [\"A\"], weights = [1, 2] }").contains("one weight per value"));
    assert!(msg("type = { choice = [\"A\", \"B\"], weights = [0, 0] }").contains("not all zero"));
    assert!(msg("type = { normal = 3 }").starts_with("type: expected a value"));
    assert!(msg("upper_bolt_1_deg = 30").contains("set all of"));
    assert!(
        msg("upper_bolt_1_deg = 30\nupper_bolt_2_deg = 35\nupper_bolt_3_deg = 100")
            .contains("at least 10°")
    );
}

#[test]
fn sampling_is_deterministic_and_per_key_independent() {
    let a = ParamSpace::addon();
    assert_eq!(a.sample(5).unwrap(), a.sample(5).unwrap());
    assert_ne!(a.sample(5).unwrap(), a.sample(6).unwrap());
    // fixing one parameter leaves every other draw as it was
    let b = space("pole_pot_length = 0.07").unwrap();
    let (pa, pb) = (a.sample(9).unwrap(), b.sample(9).unwrap());
    assert_eq!(pb.pole_pot_length, 0.07);
    for ((k, va), (_, vb)) in pa.values().into_iter().zip(pb.values()) {
        if k != "pole_pot_length" {
            assert_eq!(va, vb, "{k}");
        }
    }
}

#[test]
fn distributions_cover_their_ranges() {
    let s = space("pole_pot_length = { uniform = [0.065, 0.07] }\ntype = { choice = [\"A\", \"B\"], weights = [3, 1] }\nupper_bolt_count = { uniform = [2, 3] }").unwrap();
    let draws: Vec<MotorParams> = (0..4000).map(|i| s.sample(i).unwrap()).collect();
    let lengths: Vec<f32> = draws.iter().map(|p| p.pole_pot_length).collect();
    assert!(lengths.iter().all(|l| (0.065..=0.07).contains(l)));
    let mean = lengths.iter().sum::<f32>() / lengths.len() as f32;
    assert!((mean - 0.0675).abs() < 1e-4, "{mean}");
    let share_a = draws
        .iter()
        .filter(|p| p.motor_type == motorgen::params::MotorType::A)
        .count() as f64
        / 4000.0;
    assert!((share_a - 0.75).abs() < 0.03, "{share_a}");
    assert!(draws.iter().all(|p| (2..=3).contains(&p.upper_bolt_count)));
    assert!(
        draws.iter().any(|p| p.upper_bolt_count == 2)
            && draws.iter().any(|p| p.upper_bolt_count == 3)
    );
}

#[test]
fn auto_reproduces_the_addon_generator() {
    let draws: Vec<MotorParams> = (0..3000)
        .map(|i| ParamSpace::addon().sample(i).unwrap())
        .collect();
    for p in &draws {
        assert!(
            (0.062..=0.080).contains(&p.pole_pot_length),
            "SynMotor draws BL from U(6.2, 8) cm"
        );
        let area = 210.0 / p.upper_bolt_count as f32;
        let angles = p.upper_bolt_angles_deg();
        for (k, a) in angles.iter().enumerate() {
            let k = k as f32;
            let lo = if k > 0.0 { (k + 0.2) * area } else { 0.0 };
            assert!(
                *a >= lo && *a <= (k + 1.0) * area,
                "bolt {k} at {a} with {} bolts",
                p.upper_bolt_count
            );
        }
    }
    // every enumeration member and both mirror states occur
    for spec in PARAMS {
        if let Kind::Enum(names) = spec.kind {
            for n in names {
                assert!(
                    draws.iter().any(|p| p
                        .values()
                        .iter()
                        .any(|(k, v)| *k == spec.key && *v == Value::Text(n.to_string()))),
                    "{} {n}",
                    spec.key
                );
            }
        }
    }
    assert!(draws.iter().any(|p| p.mirror) && draws.iter().any(|p| !p.mirror));
    for deg in [0, 90, 180, 270] {
        assert!(draws.iter().any(|p| p.gearbox_orientation_deg == deg));
    }
    // upper bolt count follows SynMotor's list 1, 2, 2, 3
    let twos = draws.iter().filter(|p| p.upper_bolt_count == 2).count() as f64 / draws.len() as f64;
    assert!((twos - 0.5).abs() < 0.03, "{twos}");
}

#[test]
fn cli_values_parse_as_toml_or_bare_words() {
    assert_eq!(
        Dist::from_cli("type", "B").unwrap(),
        Dist::Fixed(Value::Text("B".into()))
    );
    assert_eq!(
        Dist::from_cli("mirror", "true").unwrap(),
        Dist::Fixed(Value::Bool(true))
    );
    assert_eq!(
        Dist::from_cli("pole_pot_length", "0.07").unwrap(),
        Dist::Fixed(Value::Num(0.07))
    );
    assert_eq!(
        Dist::from_cli("pole_pot_length", "{ uniform = [0.065, 0.07] }").unwrap(),
        Dist::Uniform(0.065, 0.07)
    );
    assert_eq!(Dist::from_cli("type", "auto").unwrap(), Dist::Auto);
}

#[test]
fn written_parameters_read_back_identically() {
    for seed in 0..200 {
        let p = ParamSpace::addon().sample(seed).unwrap();
        let again = MotorParams::from_values(
            &p.values()
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
        )
        .unwrap();
        assert_eq!(p, again);
        let json: MotorParams = serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap();
        assert_eq!(p, json);
    }
}

#[test]
fn huge_weights_draw_every_value_in_proportion() {
    // weights whose sum overflows f64 still mean equal shares
    let p = space(r#"type = { choice = ["A", "B"], weights = [1e308, 1e308] }"#).unwrap();
    let a = (0..400)
        .filter(|&s| p.sample(s).unwrap().variant().starts_with('A'))
        .count();
    assert!((150..250).contains(&a), "{a} of 400 are type A");
}

#[test]
fn only_the_bolts_in_use_are_checked() {
    let angles = "upper_bolt_1_deg = 40\nupper_bolt_2_deg = 198\nupper_bolt_3_deg = 200\n";
    // with two bolts the third angle is not used, so its 2° gap to the second does not matter
    let two = space(&format!("upper_bolt_count = 2\n{angles}")).unwrap();
    let p = two.sample(1).unwrap();
    assert_eq!(p.upper_bolt_angles_deg(), [40.0, 198.0]);
    let err = space(&format!("upper_bolt_count = 3\n{angles}"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("upper_bolt_3_deg"), "{err}");
    // and the angles of unused bolts need not be given
    assert!(space("upper_bolt_count = 1\nupper_bolt_1_deg = 90\n").is_ok());
}
