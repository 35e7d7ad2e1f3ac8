//! Monte Carlo campaigns: many missions, compared fairly, summarised with intervals.
//!
//! A campaign file ([`spec::CampaignFile`]) names scenarios, planner configurations, a sweep and
//! a number of seeds. [`Campaign::runs`] expands it into runs in a fixed order; run seeds come
//! from the campaign seed and the seed index only, so every configuration meets the same plume
//! realisations (common random numbers). [`run_campaign`] flies the runs in parallel, appends
//! each row to `runs.csv` the moment it finishes (a killed campaign loses only the runs in
//! flight; the next call skips what is recorded), and at the end sorts `runs.csv` into the
//! canonical order and writes `summary.csv`, `summary.md` and the charts. Runs of one seed whose
//! environments are built from the same settings fly in one world by default
//! ([`execute::share_groups`], [`Share`]): one plume for all of them, the same rows as alone.
//! Results do not depend on the thread count or on sharding: [`merge::merge`] of the shards of a campaign gives the
//! same `runs.csv` as one unsharded call.
//!
//! Files of a campaign directory:
//!
//! | file | what |
//! | --- | --- |
//! | `runs.csv` | one row per run ([`runs::columns`]): keys, outcome, the mission's metrics ([`plumetrace_mission::RunMetrics`]), the drawn site, the failure message |
//! | `summary.csv`, `summary.md` | per group: success rate with Wilson 95 % interval, error quantiles, times, path |
//! | `success.svg`, `errors.svg`, `trajectories.svg` | charts |
//! | `examples/*.json` | the example run (seed index 0) of each group, for the trajectory chart |
//! | `examples/*.html` | the replay page of each group's example run |
//! | `campaign.json`, `campaign.toml` | the fingerprint that ties the directory to its campaign, and a copy of the file |
//! | `runs.parquet` | with the `parquet` feature: the sorted runs as Parquet |

pub mod benchmark;
pub mod charts;
pub mod error;
pub mod example;
pub mod execute;
pub mod finish;
pub mod merge;
#[cfg(feature = "parquet")]
pub mod parquet_out;
pub mod runs;
pub mod spec;
pub mod stats;

pub use error::CampaignError;
pub use execute::{
    CampaignReport, ExternalError, ExternalPlanners, RunOptions, Share, run_campaign,
    run_campaign_with,
};
pub use merge::{MergeReport, merge};
pub use runs::{RUNS_FILE, RunRow};
pub use spec::{Campaign, RunKey, Shard, TestSeeds};
pub use stats::{GroupSummary, wilson};
