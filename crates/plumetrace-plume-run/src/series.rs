//! The time series of a plume run: concentrations at probe points (`probes.csv`) and snapshots
//! of every filament (`filament_series.csv`), recorded at their intervals while the plume runs
//! and written when it ends.
//!
//! Both are observers of the run: they read the plume after a step and never change it, so a run
//! with series gives the same plume as one without.

use plumetrace_core::Vec3;
use plumetrace_env::{ConcentrationField, FilamentPlume};
use plumetrace_scenario::limits::MAX_FILAMENT_ROWS;
use std::fmt::Write as _;

/// A sample of a series that is not a finite number.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SeriesError {
    /// A probe's concentration is not finite.
    #[error(
        "the concentration at output.probes[{probe}] at t = {t_s} s is not a finite number: \
         lower sources[].mass_rate_per_s or raise plume.init_radius_m"
    )]
    Probe {
        /// The probe's index in `output.probes`.
        probe: usize,
        /// Simulation time, s.
        t_s: f64,
    },
    /// A filament's position or radius is not finite.
    #[error("a filament at t = {t_s} s has a position or radius that is not finite")]
    Filament {
        /// Simulation time, s.
        t_s: f64,
    },
}

/// The header of `probes.csv`.
pub const PROBES_HEADER: &str = "t_s,probe,x_m,y_m,z_m,concentration\n";
/// The header of `filament_series.csv`.
pub const FILAMENT_SERIES_HEADER: &str = "t_s,x_m,y_m,z_m,radius_m\n";

/// Concentrations at fixed points, sampled every `every` steps.
#[derive(Debug)]
pub struct ProbeSeries {
    points: Vec<Vec3>,
    every: u64,
    times_s: Vec<f64>,
    /// Sample-major: probe `k` of sample `i` is at `i * points.len() + k`.
    values: Vec<f64>,
    scratch: Vec<f64>,
}

impl ProbeSeries {
    /// An empty series at `points`, sampled at every step that is a multiple of `every` (>= 1).
    pub fn new(points: Vec<Vec3>, every: u64) -> Self {
        let n = points.len();
        ProbeSeries {
            points,
            every: every.max(1),
            times_s: Vec::new(),
            values: Vec::new(),
            scratch: vec![0.0; n],
        }
    }

    /// Whether the series has probes.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Whether step `step` is sampled.
    pub fn is_due(&self, step: u64) -> bool {
        !self.points.is_empty() && step.is_multiple_of(self.every)
    }

    /// Samples `field` at every probe (one batch query); a concentration that is not finite is an
    /// error naming the probe and the time.
    pub fn sample(&mut self, t_s: f64, field: &dyn ConcentrationField) -> Result<(), SeriesError> {
        field.concentrations(&self.points, &mut self.scratch);
        if let Some(probe) = self.scratch.iter().position(|c| !c.is_finite()) {
            return Err(SeriesError::Probe { probe, t_s });
        }
        self.times_s.push(t_s);
        self.values.extend_from_slice(&self.scratch);
        Ok(())
    }

    /// The probe points.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// The sample times, s.
    pub fn times_s(&self) -> &[f64] {
        &self.times_s
    }

    /// The concentrations, sample-major (`samples x probes`).
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// `probes.csv`: one row per sample and probe, in time order, probes in the file's order;
    /// times with `t_decimals` decimals.
    pub fn csv(&self, t_decimals: usize) -> String {
        let mut csv = String::with_capacity(PROBES_HEADER.len() + 48 * self.values.len());
        csv.push_str(PROBES_HEADER);
        let n = self.points.len().max(1);
        for (i, row) in self.values.chunks(n).enumerate() {
            let t = self.times_s[i];
            for (k, (p, c)) in self.points.iter().zip(row).enumerate() {
                let _ = writeln!(
                    csv,
                    "{t:.t_decimals$},{k},{:.3},{:.3},{:.3},{c:.6e}",
                    p.x, p.y, p.z
                );
            }
        }
        csv
    }
}

/// Every filament's centre and radius, every `every` steps, kept as the text of
/// `filament_series.csv`. Once the file would pass [`MAX_FILAMENT_ROWS`] rows no more snapshots
/// are kept, so it holds whole snapshots from the start of the run.
#[derive(Debug)]
pub struct FilamentSeries {
    every: u64,
    t_decimals: usize,
    csv: String,
    rows: u64,
    snapshots: u32,
    skipped: u32,
}

impl FilamentSeries {
    /// An empty series taken at every step that is a multiple of `every` (>= 1); times with
    /// `t_decimals` decimals.
    pub fn new(every: u64, t_decimals: usize) -> Self {
        FilamentSeries {
            every: every.max(1),
            t_decimals,
            csv: String::from(FILAMENT_SERIES_HEADER),
            rows: 0,
            snapshots: 0,
            skipped: 0,
        }
    }

    /// Whether step `step` is recorded.
    pub fn is_due(&self, step: u64) -> bool {
        step.is_multiple_of(self.every)
    }

    /// Records every filament of `plume` at `t_s`; a filament that is not finite is an error.
    pub fn record(&mut self, t_s: f64, plume: &FilamentPlume) -> Result<(), SeriesError> {
        let live = plume.len() as u64;
        if self.skipped > 0 || self.rows + live > MAX_FILAMENT_ROWS {
            self.skipped += 1;
            return Ok(());
        }
        let d = self.t_decimals;
        for (p, r2) in plume.filaments() {
            let r = r2.sqrt();
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite() && r.is_finite()) {
                return Err(SeriesError::Filament { t_s });
            }
            let _ = writeln!(
                self.csv,
                "{t_s:.d$},{:.4},{:.4},{:.4},{r:.4}",
                p.x, p.y, p.z
            );
        }
        self.rows += live;
        self.snapshots += 1;
        Ok(())
    }

    /// Snapshots kept.
    pub fn snapshots(&self) -> u32 {
        self.snapshots
    }

    /// Snapshots not kept because the file reached [`MAX_FILAMENT_ROWS`] rows.
    pub fn skipped(&self) -> u32 {
        self.skipped
    }

    /// Rows kept (filaments over all snapshots).
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// The text of `filament_series.csv`.
    pub fn csv(&self) -> &str {
        &self.csv
    }
}

/// Decimals that write every multiple of `dt_s` exactly (0 for whole seconds, 1 for 0.1 s, ...;
/// at most 9).
pub fn time_decimals(dt_s: f64) -> usize {
    (0..9)
        .find(|&d| {
            let scaled = dt_s * 10f64.powi(d as i32);
            (scaled - scaled.round()).abs() <= 1e-6
        })
        .unwrap_or(9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_decimals_write_every_multiple_of_the_step() {
        for (dt, d) in [
            (1.0, 0),
            (60.0, 0),
            (0.1, 1),
            (0.5, 1),
            (0.01, 2),
            (0.25, 2),
            (0.001, 3),
        ] {
            assert_eq!(time_decimals(dt), d, "{dt}");
        }
        assert_eq!(time_decimals(1.0 / 3.0), 9);
    }

    /// A field that is `x + 10 t` at time `t`.
    struct Ramp(f64);
    impl ConcentrationField for Ramp {
        fn concentration(&self, p: Vec3) -> f64 {
            p.x + 10.0 * self.0
        }
    }

    #[test]
    fn probes_are_sampled_at_their_steps_and_written_sample_major() {
        let mut s = ProbeSeries::new(vec![Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 5.0, 6.0)], 5);
        for step in 1..=12u64 {
            if s.is_due(step) {
                let t = step as f64 * 0.1;
                assert!(s.sample(t, &Ramp(t)).is_ok());
            }
        }
        assert_eq!(s.times_s().len(), 2);
        assert_eq!(s.values(), &[6.0, 9.0, 11.0, 14.0]);
        assert_eq!(
            s.csv(1),
            "t_s,probe,x_m,y_m,z_m,concentration\n\
             0.5,0,1.000,2.000,3.000,6.000000e0\n\
             0.5,1,4.000,5.000,6.000,9.000000e0\n\
             1.0,0,1.000,2.000,3.000,1.100000e1\n\
             1.0,1,4.000,5.000,6.000,1.400000e1\n"
        );
        let e = s.sample(2.0, &Ramp(f64::INFINITY)).unwrap_err().to_string();
        assert!(
            e.contains("output.probes[0]") && e.contains("t = 2 s"),
            "{e}"
        );
        assert_eq!(s.times_s().len(), 2, "a failed sample is not kept");
        let none = ProbeSeries::new(Vec::new(), 1);
        assert!(none.is_empty() && !none.is_due(1));
    }
}
