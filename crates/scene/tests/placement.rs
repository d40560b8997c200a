//! Where samples fall: variants, levels and splits hold their shares in every prefix and every
//! shard, validation comes spread, and each variant gets its exact share over a full period.

use std::collections::HashMap;

use scene::augment::{Level, Split};
use scene::config::default_table;
use scene::{Config, Recipe};

fn recipe(sets: &[(&str, toml::Value)]) -> Recipe {
    let mut t = default_table();
    for (k, v) in sets {
        scene::set_key(&mut t, k, v.clone()).unwrap();
    }
    Recipe::new(Config::from_table(&t).unwrap(), Vec::new()).unwrap()
}

fn shares(c: f64, o: f64, z: f64, v: f64, variants: Option<usize>) -> Recipe {
    let mut sets = vec![
        ("augment.clean.share", c.into()),
        ("augment.occluded.share", o.into()),
        ("augment.noisy.share", z.into()),
        ("augment.validation", v.into()),
    ];
    if let Some(n) = variants {
        let all = ["A0", "A1", "A2", "B0", "B1"];
        let list = (0..n).map(|k| toml::Value::from(all[k % 5])).collect();
        sets.push(("motor.variants", toml::Value::Array(list)));
    }
    recipe(&sets)
}

fn validation_share(r: &Recipe) -> f64 {
    f64::from(r.config.augment.validation)
}

fn level_share(r: &Recipe, l: Level) -> f64 {
    f64::from(l.config(&r.config.augment).share)
}

/// The largest distance, over every prefix of the first `n` samples, of the validation count
/// and of each level's count from their shares; and of each variant's count, as a share of one
/// over the variants.
fn worst_prefix(r: &Recipe, n: u64) -> (f64, f64, f64) {
    let (mut validation, mut levels) = (0.0, HashMap::new());
    let mut variants: HashMap<String, f64> = HashMap::new();
    let slots = r.config.motor.variants.len().max(1) as f64;
    let (mut worst_split, mut worst_level, mut worst_variant) = (0f64, 0f64, 0f64);
    for i in 0..n {
        let (variant, level, split) = r.placement(i);
        let t = (i + 1) as f64;
        if split == Split::Validation {
            validation += 1.0;
        }
        *levels.entry(level).or_insert(0.0) += 1.0;
        *variants.entry(format!("{variant:?}")).or_insert(0.0) += 1.0;
        worst_split = worst_split.max((validation - t * validation_share(r)).abs());
        for l in Level::ALL {
            let c = levels.get(&l).copied().unwrap_or(0.0);
            worst_level = worst_level.max((c - t * level_share(r, l)).abs());
        }
        for c in variants.values() {
            worst_variant = worst_variant.max((c - t / slots).abs());
        }
    }
    (worst_split, worst_level, worst_variant)
}

#[test]
fn each_split_and_level_holds_its_share_in_every_prefix() {
    let cases = [
        recipe(&[]),
        shares(0.3, 0.3, 0.4, 0.15, None),
        shares(1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.1, Some(3)),
        shares(1.0, 0.0, 0.0, 0.2, Some(4)),
        shares(0.2, 0.2, 0.6, 0.0, Some(5)),
        shares(0.2, 0.2, 0.6, 0.5, Some(1)),
        shares(0.2, 0.2, 0.6, 0.25, Some(3)),
        recipe(&[("motor.variants", toml::Value::Array(Vec::new()))]),
    ];
    for r in &cases {
        let (split, level, variant) = worst_prefix(r, 3000);
        let a = &r.config.augment;
        assert!(
            split < 1.0,
            "{a:?}: validation {split} samples off its share"
        );
        assert!(level < 1.0, "{a:?}: a level {level} samples off its share");
        assert!(
            variant <= 2.0,
            "{a:?}: a variant {variant} samples off its share"
        );
    }
    // shares without a small common period (10,000 steps): the levels within 1.5
    let odd = shares(0.123, 0.456, 0.421, 0.333, Some(2));
    let (split, level, _) = worst_prefix(&odd, 3000);
    assert!(split < 1.0 && level < 1.5, "{split}, {level}");
}

#[test]
fn each_variant_gets_its_exact_share_of_every_level_and_split_per_period() {
    // the default: 5 variants, cells of 25 (4/4/12 train, 1/1/3 validation of every 25)
    let r = recipe(&[]);
    let per_25 = |l: Level, s: Split| match (l, s) {
        (Level::Noisy, Split::Train) => 12,
        (Level::Noisy, Split::Validation) => 3,
        (_, Split::Train) => 4,
        (_, Split::Validation) => 1,
    };
    for block in 0..8u64 {
        let mut counts: HashMap<(String, Level, Split), u64> = HashMap::new();
        for i in block * 125..(block + 1) * 125 {
            let (variant, level, split) = r.placement(i);
            *counts
                .entry((format!("{variant:?}"), level, split))
                .or_default() += 1;
        }
        assert_eq!(counts.len(), 30, "block {block}: {counts:?}");
        for ((variant, l, s), n) in counts {
            assert_eq!(n, per_25(l, s), "block {block}: {variant} {l:?} {s:?}");
        }
    }
}

#[test]
fn validation_comes_early_spread_and_at_every_level() {
    let r = recipe(&[]);
    let placements: Vec<_> = (0..3000).map(|i| r.placement(i)).collect();
    let validation = |n: usize| placements[..n].iter().filter(|p| p.2 == Split::Validation);
    // small datasets: at least their share less one, from the first five samples on
    for (n, least) in [(5, 1), (10, 2), (12, 2), (20, 4), (30, 6), (100, 20)] {
        assert!(validation(n).count() >= least, "{n} samples");
    }
    let levels = |n: usize| {
        let mut l: Vec<Level> = validation(n).map(|p| p.1).collect();
        l.sort_by_key(|l| l.name());
        l.dedup();
        l.len()
    };
    assert!(levels(20) >= 2);
    assert_eq!(levels(25), 3, "validation covers every level by sample 25");
    // never more than two validation samples in a row
    let longest = placements
        .split(|p| p.2 != Split::Validation)
        .map(<[_]>::len)
        .max()
        .unwrap();
    assert!(longest <= 2, "{longest} validation samples in a row");
}

#[test]
fn every_shard_holds_validation() {
    let r = recipe(&[]);
    for count in 2..=8u64 {
        for part in 0..count {
            let shard: Vec<Split> = (part..200)
                .step_by(count as usize)
                .map(|i| r.placement(i).2)
                .collect();
            let v = shard.iter().filter(|&&s| s == Split::Validation).count() as f64;
            let expected = shard.len() as f64 * 0.2;
            assert!(
                v >= 1.0 && (v - expected).abs() <= 3.0 * expected.sqrt() + 1.0,
                "shard {part}/{count}: {v} validation samples of {}",
                shard.len()
            );
        }
    }
}
