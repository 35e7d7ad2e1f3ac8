//! Why a benchmark could not run. Messages name the `plumetrace bench` flag of a bad option.

use plumetrace_env::EnvError;
use plumetrace_mission::MissionError;
use plumetrace_scenario::ScenarioError;

/// What can go wrong in a benchmark.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A time option (`--dt`, `--duration`, `--warmup`), the release rate or the flow step is
    /// negative or not finite.
    #[error("{flag} must be a finite number >= 0, got {value}")]
    NotFiniteOrNegative {
        /// The flag.
        flag: &'static str,
        /// Its value.
        value: f64,
    },
    /// The time step is 0 or the timed window shorter than one step.
    #[error("--dt must be > 0 and --duration at least one step")]
    NoStep,
    /// `--flow-step` on a case without a Farrell flow.
    #[error("--flow-step needs a Farrell flow; the {case} case has none")]
    NoFarrellFlow {
        /// The case's preset.
        case: &'static str,
    },
    /// The plume benchmark's preset has no filament plume.
    #[error("the benchmark needs a filament plume")]
    NotFilaments,
    /// No runs or a thread count of 0.
    #[error("--runs and every --threads value must be at least 1")]
    NoRuns,
    /// The preset is not a mission.
    #[error("preset '{0}' is not a mission")]
    NotAMission(String),
    /// A `--set` override that could not be applied.
    #[error(transparent)]
    Set(#[from] plumetrace_scenario::overrides::SetError),
    /// The map's cell size is out of range.
    #[error("--resolution must be >= 0.5 and <= 1000, got {0}")]
    Resolution(f64),
    /// No map cell fits the op-area.
    #[error("no map cell fits the op-area at {0} m")]
    NoMapCell(f64),
    /// The grid world's emission rate is out of range.
    #[error("--rate must be > 0 and <= 1000, got {0}")]
    Rate(f64),
    /// A preset's text is not TOML.
    #[error(transparent)]
    Toml(#[from] toml::de::Error),
    /// The scenario could not be read or built.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// A mission failed.
    #[error(transparent)]
    Mission(#[from] MissionError),
    /// The environment failed to step.
    #[error(transparent)]
    Env(#[from] EnvError),
    /// A thread pool could not be made.
    #[error(transparent)]
    ThreadPool(#[from] rayon::ThreadPoolBuildError),
}
