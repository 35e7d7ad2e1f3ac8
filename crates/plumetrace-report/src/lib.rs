//! Reports of plumetrace: everything drawn from what a run recorded, never inside the step loop.
//!
//! The mission runner records; this crate draws. Each figure reads a finished run (a
//! [`plumetrace_mission::MissionRun`], a built scenario's plume, a replayed log) and returns the
//! file's text; the caller writes it.
//!
//! - [`figure`]: the mission figure (`plot.svg`): the map of every track over the plume, the
//!   source maps, and the reading panel;
//! - [`mod@team_figure`]: the team figure (`team.svg`): readings, speeds, headings, scale and
//!   centroid against time;
//! - [`mod@plume_figure`]: the plume figure of a plume-only run (`plume.svg`);
//! - [`mod@replay_page`]: the self-contained replay page (`replay.html`), of a flown mission or a
//!   replayed log;
//! - [`run_dir`]: a flown mission's output directory (what `plumetrace run` and Python's
//!   `RunResult.save` write);
//! - [`inspect`]: measurable properties of a drawn figure (label boxes, overlaps, axes, a
//!   legend entry per series), read back from its SVG;
//! - [`marks`]: the groups a figure wraps its series and legend entries in, so that
//!   [`inspect`] can match each drawn series with its legend entry;
//! - [`chart`]: the map panel and dashed outlines every figure and chart shares;
//! - [`error`]: what can go wrong ([`ReportError`]).

pub mod chart;
pub mod decimal;
pub mod error;
pub mod figure;
pub mod geo_outputs;
pub mod inspect;
pub mod marks;
pub mod plume_figure;
pub mod replay_page;
pub mod run_dir;
pub mod team_figure;

pub use chart::{dashed, map_chart};
pub use error::ReportError;
pub use figure::{DETECTION_GAP_S, mission_figure};
pub use plume_figure::plume_figure;
pub use replay_page::{LogPageBuilder, PageData, replay_page};
pub use run_dir::{RunDirError, write_mission_outputs};
pub use team_figure::team_figure;
