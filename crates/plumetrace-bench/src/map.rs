//! The source-likelihood map's update cost over a mission preset's op-area (`plumetrace bench
//! map`).

use crate::BenchError;
use cpu_time::ProcessTime;
use plumetrace_planner::estimate::{MapModel, SourceMap};
use serde::Serialize;

/// What to time.
#[derive(Debug, Clone, PartialEq)]
pub struct MapBenchOptions {
    /// Mission preset whose op-area the map covers.
    pub preset: String,
    /// Map cell size, m (0.5 to 1000).
    pub resolution: f64,
    /// Samples to time (at 10 Hz, along a line across the area, one in five a detection).
    pub samples: u64,
}

/// The map benchmark's result.
#[derive(Debug, Clone, Serialize)]
pub struct MapBench {
    /// The preset.
    pub preset: String,
    /// Map cell size, m.
    pub resolution_m: f64,
    /// Cells of the map.
    pub candidate_cells: usize,
    /// Samples timed.
    pub samples: u64,
    /// CPU microseconds per update, every sample.
    pub us_per_update: f64,
    /// Per update with a detection.
    pub us_per_update_detection: f64,
    /// Per update without.
    pub us_per_update_non_detection: f64,
    /// One candidate move's hit model (a footprint and the dense fill).
    pub us_per_hit_model: f64,
    /// One normalisation (paid by the first read after samples).
    pub us_per_normalisation: f64,
}

/// Times the map's update: samples along a line through the op-area, in a 0.12 m/s current
/// along the area's long axis, at 2 m altitude, the map's default model.
pub fn map(a: &MapBenchOptions) -> Result<MapBench, BenchError> {
    if !(a.resolution >= 0.5 && a.resolution <= 1000.0) {
        return Err(BenchError::Resolution(a.resolution));
    }
    let cfg = plumetrace_scenario::load_preset(&a.preset)?;
    let origin = plumetrace_scenario::Origin::Preset(a.preset.clone());
    let Some(mission) = plumetrace_scenario::build(&cfg, &origin, None)?.mission else {
        return Err(BenchError::NotAMission(a.preset.clone()));
    };
    let v = mission.op_area.clone();
    let model = MapModel {
        resolution_m: a.resolution,
        ..MapModel::default()
    };
    let Some(mut m) = SourceMap::from_vertices(&v, model) else {
        return Err(BenchError::NoMapCell(a.resolution));
    };
    let (p0, p1) = (v[0], v[2]);
    let flow = (v[1] - v[0]).normalize() * 0.12;
    let (mut t_det, mut t_non, mut n_det) = (0.0, 0.0, 0u64);
    for k in 0..a.samples {
        let t = k as f64 * 0.1;
        if k % 10 == 0 {
            m.add_flow(t, flow);
        }
        let f = (k as f64 / a.samples as f64) * 0.9 + 0.05;
        let pos = p0 + (p1 - p0) * f;
        let detected = k % 5 == 0;
        let started = ProcessTime::now();
        m.observe(pos, t, Some(2.0), detected);
        let dt = started.elapsed().as_secs_f64();
        if detected {
            t_det += dt;
            n_det += 1;
        } else {
            t_non += dt;
        }
    }
    let mut out = Vec::new();
    let reps = 200;
    let started = ProcessTime::now();
    for k in 0..reps {
        let pos = p0 + (p1 - p0) * (0.3 + 0.002 * k as f64);
        m.hit_probabilities(
            pos,
            a.samples as f64 * 0.1 + 15.0,
            Some(2.0),
            15.0,
            &mut out,
        );
    }
    let t_hit = started.elapsed().as_secs_f64();
    // A read after each sample: the normalisation a reading of the map pays.
    let started = ProcessTime::now();
    let mut mass = 0.0;
    for k in 0..reps {
        let t = a.samples as f64 * 0.1 + 0.1 * f64::from(k);
        m.observe(p0 + (p1 - p0) * 0.5, t, Some(2.0), false);
        mass += m.probabilities()[0];
    }
    let t_norm =
        started.elapsed().as_secs_f64() - f64::from(reps) * (t_det + t_non) / a.samples as f64;
    std::hint::black_box(mass);
    let n_non = a.samples - n_det;
    Ok(MapBench {
        preset: a.preset.clone(),
        resolution_m: a.resolution,
        candidate_cells: m.len(),
        samples: a.samples,
        us_per_update: (t_det + t_non) / a.samples as f64 * 1e6,
        us_per_update_detection: t_det / n_det.max(1) as f64 * 1e6,
        us_per_update_non_detection: t_non / n_non.max(1) as f64 * 1e6,
        us_per_hit_model: t_hit / f64::from(reps) * 1e6,
        us_per_normalisation: t_norm / f64::from(reps) * 1e6,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(preset: &str, resolution: f64) -> MapBenchOptions {
        MapBenchOptions {
            preset: preset.to_string(),
            resolution,
            samples: 50,
        }
    }

    #[test]
    fn the_map_of_a_mission_preset_is_timed() {
        let r = map(&options("duck-2003-st", 20.0)).unwrap_or_else(|e| panic!("{e}"));
        assert!(r.candidate_cells > 0);
        assert_eq!(r.samples, 50);
        assert!(r.us_per_update.is_finite() && r.us_per_hit_model.is_finite());
    }

    #[test]
    fn a_bad_resolution_or_a_plume_preset_is_refused() {
        let refused = |o: MapBenchOptions| map(&o).err().map(|e| e.to_string());
        assert_eq!(
            refused(options("duck-2003-st", 0.1)).as_deref(),
            Some("--resolution must be >= 0.5 and <= 1000, got 0.1")
        );
        assert_eq!(
            refused(options("pompy", 5.0)).as_deref(),
            Some("preset 'pompy' is not a mission")
        );
    }
}
