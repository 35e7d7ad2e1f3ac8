//! Built-in scenarios: the one registry that `plumetrace presets`, the docs and the tests read.
//!
//! Each preset is a documented TOML file in `crates/plumetrace-scenario/presets/`, compiled into
//! the binary; copy one as a starting point for your own scenario.

/// A built-in scenario.
#[derive(Debug, Clone, Copy)]
pub struct Preset {
    /// Name used with `--preset`.
    pub name: &'static str,
    /// One line for `plumetrace presets`.
    pub summary: &'static str,
    /// The TOML text.
    pub toml: &'static str,
}

/// Every built-in scenario.
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "demo",
        summary: "small plume-tracing mission: the AMP flies an AUV up a 400 m plume (seconds to run)",
        toml: include_str!("../presets/demo.toml"),
    },
    Preset {
        name: "demo-survey",
        summary: "the demo site surveyed by a lawnmower, declaring at the strongest reading (the exhaustive baseline)",
        toml: include_str!("../presets/demo-survey.toml"),
    },
    Preset {
        name: "demo-infotaxis",
        summary: "the demo site searched by infotaxis on a source-likelihood map: 80 m legs within the turning limit, declaration once the map has held concentrated and a confirming pass agrees",
        toml: include_str!("../presets/demo-infotaxis.toml"),
    },
    Preset {
        name: "demo-surge-cast",
        summary: "the demo site searched by spiral-out then surge-cast: up-flow surges, widening casts, declaration at the most up-flow contact",
        toml: include_str!("../presets/demo-surge-cast.toml"),
    },
    Preset {
        name: "duck-2003-st",
        summary: "Duck 2003 single-source mission: 1094 m x 367 m op-area, 0.10-0.15 m/s, about 1 km of plume",
        toml: include_str!("../presets/duck-2003-st.toml"),
    },
    Preset {
        name: "duck-2003-mt",
        summary: "Duck 2003 multi-source mission: 4 subregions, 2 sources, 0.20-0.30 m/s",
        toml: include_str!("../presets/duck-2003-mt.toml"),
    },
    Preset {
        name: "li-zhang-open",
        summary: "moth-inspired tracing in Li and Zhang's set-up: 100 m x 100 m, Farrell flow of 1 m/s, no obstacles",
        toml: include_str!("../presets/li-zhang-open.toml"),
    },
    Preset {
        name: "li-zhang-kelp",
        summary: "moth-inspired tracing with obstacle avoidance: Li and Zhang's set-up with a band of kelp patches across the plume",
        toml: include_str!("../presets/li-zhang-kelp.toml"),
    },
    Preset {
        name: "plume-demo",
        summary: "plume only: small meandering plume from a bottom source, 200 m x 100 m, 10 min",
        toml: include_str!("../presets/plume-demo.toml"),
    },
    Preset {
        name: "pompy",
        summary: "pompy's own scenario in pompy-compatible mode (100 m, 1 m/s, dt 0.01 s, 5 puffs/s)",
        toml: include_str!("../presets/pompy.toml"),
    },
    Preset {
        name: "field-scale",
        summary: "1.1 km domain, 0.1 m/s, ~50,000 live filaments (a benchmark; minutes to run)",
        toml: include_str!("../presets/field-scale.toml"),
    },
    Preset {
        name: "freshwater",
        summary: "steady freshwater plume of the formation-tracing experiment (108 m x 40 m x 4 m)",
        toml: include_str!("../presets/freshwater.toml"),
    },
    Preset {
        name: "soares-freshwater",
        summary: "formation tracing: two surface leaders and an AUV follower on acoustic ranges trace the steady freshwater plume to its surface outlet",
        toml: include_str!("../presets/soares-freshwater.toml"),
    },
    Preset {
        name: "soares-filaments",
        summary: "the formation team on a meandering, intermittent filament plume from the same surface outlet (the harder case)",
        toml: include_str!("../presets/soares-filaments.toml"),
    },
];

/// The preset called `name`.
pub fn find_preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Origin, build, load_preset};

    #[test]
    fn every_preset_parses_builds_and_names_itself() {
        for p in PRESETS {
            let cfg = load_preset(p.name).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(cfg.name, p.name);
            let built =
                build(&cfg, &Origin::Preset(p.name.into()), None).unwrap_or_else(|e| panic!("{e}"));
            assert!(built.steps > 0);
            assert_eq!(built.warnings, [], "{}: keys with no effect", p.name);
        }
    }
}
