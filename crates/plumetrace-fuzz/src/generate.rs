//! Inputs from (pass seed, index): a seed of the corpus and one to three mutations, all drawn
//! from the input's own random stream, so the same seed and index always give the same bytes.

use crate::corpus::{Seed, Target, seeds};
use crate::mutate::{Applied, Kind, MAX_INPUT_BYTES, apply_raw, apply_tree, float_literals};
use crate::rng::input_rng;
use rand::Rng;
use std::borrow::Cow;

/// One generated input.
#[derive(Debug, Clone)]
pub struct Input {
    /// Its index in the pass.
    pub index: u64,
    /// The pass seed.
    pub seed: u64,
    /// The corpus seed it was made from.
    pub corpus: &'static str,
    /// What it is read as.
    pub target: Target,
    /// The mutations, in the order applied (tree ones first, then raw ones).
    pub mutations: Vec<Applied>,
    /// The file's bytes.
    pub bytes: Vec<u8>,
}

impl Input {
    /// Whether the bytes are UTF-8.
    pub fn is_utf8(&self) -> bool {
        std::str::from_utf8(&self.bytes).is_ok()
    }

    /// The text, invalid UTF-8 replaced.
    pub fn text_lossy(&self) -> Cow<'_, str> {
        String::from_utf8_lossy(&self.bytes)
    }

    /// A few lines on where the input came from.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "input {} of seed {}: {} file from '{}' ({} bytes{})\n",
            self.index,
            self.seed,
            self.target.name(),
            self.corpus,
            self.bytes.len(),
            if self.is_utf8() { "" } else { ", not UTF-8" }
        );
        for m in &self.mutations {
            s.push_str(&format!("  {}: {}\n", m.kind.name(), m.detail));
        }
        s
    }
}

/// Share of campaign mutations among the mutations of a campaign input.
const CAMPAIGN_SHARE: f64 = 0.5;
/// Share of raw mutations among the others.
const RAW_SHARE: f64 = 0.2;

/// Every this many indices, the last is a NetCDF input (the others are drawn as before it was
/// added): currents and bathymetry in turn (index 15 currents, 31 bathymetry, 47 currents, ...).
pub const NETCDF_EVERY: u64 = 16;

/// A NetCDF input (currents or bathymetry, `target`): a seed file with one to three raw
/// mutations or overwritten header words.
fn netcdf_input(seed: u64, index: u64, target: Target) -> Input {
    let (mut rng, seeds) = if target == Target::Seabed {
        (
            input_rng(seed ^ 0x7365_6162_6564, index),
            crate::corpus::seabed_seeds(),
        )
    } else {
        (
            input_rng(seed ^ 0x6e65_7463_6466, index),
            crate::corpus::netcdf_seeds(),
        )
    };
    let (corpus, mut bytes) = seeds[rng.random_range(0..seeds.len())].clone();
    let mut mutations = Vec::new();
    for _ in 0..rng.random_range(1..=3) {
        if rng.random_bool(0.5) {
            // A header word (count, length, type, offset) set to an edge value.
            let header = bytes.len().min(2048);
            let at = rng.random_range(0..header.max(4) - 3) & !3;
            let word: u32 = match rng.random_range(0..6) {
                0 => 0,
                1 => 1,
                2 => 0x7FFF_FFFF,
                3 => 0xFFFF_FFFF,
                4 => 0x8000_0000,
                _ => rng.random(),
            };
            if at + 4 <= bytes.len() {
                bytes[at..at + 4].copy_from_slice(&word.to_be_bytes());
            }
            mutations.push(Applied {
                kind: Kind::FlipBits,
                detail: format!("header word at byte {at} set to {word:#x}"),
            });
        } else {
            let raw: Vec<Kind> = Kind::ALL.into_iter().filter(|k| k.is_raw()).collect();
            let kind = raw[rng.random_range(0..raw.len())];
            let detail = apply_raw(kind, &mut bytes, &mut rng);
            mutations.push(Applied { kind, detail });
        }
    }
    bytes.truncate(MAX_INPUT_BYTES);
    Input {
        index,
        seed,
        corpus,
        target,
        mutations,
        bytes,
    }
}

/// The input at `index` of the pass seeded with `seed`.
pub fn generate(seed: u64, index: u64) -> Input {
    if index % NETCDF_EVERY == NETCDF_EVERY - 1 {
        let target = if (index / NETCDF_EVERY) % 2 == 1 {
            Target::Seabed
        } else {
            Target::Netcdf
        };
        return netcdf_input(seed, index, target);
    }
    let mut rng = input_rng(seed, index);
    let all = seeds();
    let scenarios: Vec<&Seed> = all
        .iter()
        .filter(|s| s.target == Target::Scenario)
        .collect();
    let campaigns: Vec<&Seed> = all
        .iter()
        .filter(|s| s.target == Target::Campaign)
        .collect();
    let families: Vec<&Seed> = all.iter().filter(|s| s.target == Target::Family).collect();
    let onboards: Vec<&Seed> = all.iter().filter(|s| s.target == Target::Onboard).collect();
    // About 50 % scenarios, 30 % campaigns, 10 % families, 10 % onboard files.
    let r: f64 = rng.random();
    let pool = if r < 0.3 && !campaigns.is_empty() {
        &campaigns
    } else if r < 0.4 && !families.is_empty() {
        &families
    } else if r < 0.5 && !onboards.is_empty() {
        &onboards
    } else {
        &scenarios
    };
    let Some(corpus) = pool.get(rng.random_range(0..pool.len().max(1))).copied() else {
        return Input {
            index,
            seed,
            corpus: "(none)",
            target: Target::Scenario,
            mutations: Vec::new(),
            bytes: Vec::new(),
        };
    };
    let choose = |rng: &mut rand_pcg::Pcg64Mcg, keep: &dyn Fn(Kind) -> bool| {
        let ks: Vec<Kind> = Kind::ALL.into_iter().filter(|k| keep(*k)).collect();
        ks[rng.random_range(0..ks.len())]
    };
    let n = rng.random_range(1..=3);
    let mut kinds = Vec::with_capacity(n);
    for _ in 0..n {
        let k = if corpus.target == Target::Campaign && rng.random_bool(CAMPAIGN_SHARE) {
            choose(&mut rng, &|k| k.campaign_only())
        } else if rng.random_bool(RAW_SHARE) {
            choose(&mut rng, &|k| k.is_raw())
        } else {
            choose(&mut rng, &|k| !k.is_raw() && !k.campaign_only())
        };
        kinds.push(k);
    }
    // Tree mutations first (on the parsed text), raw ones on the final text.
    kinds.sort_by_key(|k| k.is_raw());
    let mut mutations = Vec::new();
    let mut table: toml::Table = corpus.text.parse().unwrap_or_default();
    let mut tree_changed = false;
    for &k in kinds.iter().filter(|k| !k.is_raw()) {
        // A mutation with nothing to act on falls back to a type change, then to an unknown key
        // (always possible), so every input has as many mutations as drawn.
        for kind in [k, Kind::ChangeType, Kind::InsertUnknownKey] {
            if let Some(detail) = apply_tree(kind, &mut table, corpus.target, &mut rng) {
                mutations.push(Applied { kind, detail });
                tree_changed = true;
                break;
            }
        }
    }
    let mut bytes = if tree_changed {
        match toml::to_string(&table) {
            Ok(text) => float_literals(&text).into_bytes(),
            Err(e) => {
                mutations.push(Applied {
                    kind: Kind::ChangeType,
                    detail: format!("(the mutated tree did not serialise: {e}; seed text kept)"),
                });
                corpus.text.as_bytes().to_vec()
            }
        }
    } else {
        corpus.text.as_bytes().to_vec()
    };
    for &kind in kinds.iter().filter(|k| k.is_raw()) {
        let detail = apply_raw(kind, &mut bytes, &mut rng);
        mutations.push(Applied { kind, detail });
    }
    if bytes.len() > MAX_INPUT_BYTES {
        bytes.truncate(MAX_INPUT_BYTES);
        mutations.push(Applied {
            kind: Kind::Truncate,
            detail: format!("cut to the {MAX_INPUT_BYTES}-byte cap"),
        });
    }
    Input {
        index,
        seed,
        corpus: corpus.name,
        target: corpus.target,
        mutations,
        bytes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn same_seed_and_index_give_the_same_bytes() {
        for index in [0, 1, 17, 999, 123_456] {
            let a = generate(5, index);
            let b = generate(5, index);
            assert_eq!(a.bytes, b.bytes, "index {index}");
            assert_eq!(a.mutations, b.mutations, "index {index}");
            assert_eq!(a.corpus, b.corpus);
        }
        let differ = (0..20).filter(|i| generate(5, *i).bytes != generate(6, *i).bytes);
        assert!(differ.count() > 15, "other seeds give other inputs");
    }

    #[test]
    fn extreme_floats_are_written_in_exponent_form() {
        let mut exponents = 0;
        for index in 0..1_000 {
            let text = generate(2, index).text_lossy().into_owned();
            assert!(!text.contains("plumetrace-fuzz-float"), "index {index}");
            if ["e300", "e-300", "e18", "e308", "e-324"]
                .iter()
                .any(|e| text.contains(e))
            {
                exponents += 1;
                // Still TOML (unless a raw mutation broke it on purpose).
                let input = generate(2, index);
                if input.mutations.iter().all(|m| !m.kind.is_raw()) {
                    assert!(text.parse::<toml::Table>().is_ok(), "index {index}");
                }
            }
        }
        assert!(exponents > 10, "{exponents}");
    }

    #[test]
    fn every_mutation_kind_is_produced() {
        let mut seen = BTreeSet::new();
        let mut targets = BTreeSet::new();
        for index in 0..3_000 {
            let input = generate(1, index);
            assert!(input.bytes.len() <= MAX_INPUT_BYTES);
            assert!(!input.mutations.is_empty());
            targets.insert(input.target);
            seen.extend(input.mutations.iter().map(|m| m.kind));
            if seen.len() == Kind::ALL.len() && targets.len() == 6 {
                break;
            }
        }
        let missing: Vec<&str> = Kind::ALL
            .iter()
            .filter(|k| !seen.contains(k))
            .map(|k| k.name())
            .collect();
        assert!(missing.is_empty(), "never produced: {missing:?}");
        assert_eq!(
            targets.len(),
            6,
            "scenarios, campaigns, families, onboard files, NetCDF currents and bathymetry"
        );
    }
}
