//! Flow read from a file: a regular grid, optionally with several time frames.
//!
//! The CSV file has a header and the columns `x_m,y_m,u_mps,v_mps` (East, North position; East,
//! North velocity), plus an optional `t_s` column for time-varying fields. Every frame must cover
//! the same regular grid (all combinations of its distinct `x_m` and `y_m` values, in any row
//! order). Velocities are bilinear in space and linear in time; outside the grid the nearest edge
//! value is used and outside the time span the nearest frame is held. The file format is kept
//! behind [`GriddedFlow::from_csv`]; [`GriddedFlow::from_netcdf`] (module `cf`) fills the same grid
//! from an ocean model's CF NetCDF file.

use super::{FarrellFlow, FarrellParams, FlowField, MeanFlow, axis_weight};
use crate::csv_grid::{read_columns, regular_axis};
use crate::{EnvError, Rect, SimRng};
use plumetrace_core::Vec2;
use std::collections::BTreeMap;
use std::path::Path;

/// One time frame: `u` and `v` row-major `ny x nx`.
#[derive(Debug, Clone)]
pub(super) struct Frame {
    pub(super) t_s: f64,
    pub(super) u: Vec<f64>,
    pub(super) v: Vec<f64>,
}

/// A regular-grid flow field, possibly time-varying.
#[derive(Debug, Clone)]
pub struct GriddedFlow {
    x0_m: f64,
    y0_m: f64,
    inv_dx: f64,
    inv_dy: f64,
    nx: usize,
    ny: usize,
    frames: Vec<Frame>,
    time_s: f64,
    /// Index of the frame at or before the current time, and the blend towards the next one.
    frame: usize,
    blend: f64,
    /// The Farrell meander added to the grid, if any.
    meander: Option<Box<Meander>>,
}

/// A Farrell field's departure from its mean, scaled, added to the grid so that filaments still
/// meander below the grid's resolution.
#[derive(Debug, Clone)]
struct Meander {
    field: FarrellFlow,
    mean_mps: Vec2,
    strength: f64,
}

impl GriddedFlow {
    /// Reads a gridded flow from a CSV file (see the module docs for the format).
    pub fn from_csv(path: &Path) -> Result<Self, EnvError> {
        let file_err = |message: String| EnvError::File {
            path: path.to_path_buf(),
            message,
        };
        // Columns: x, y, u, v, then t (NaN when absent: one frame at t = 0).
        let (table, _) = read_columns(path, &["x_m", "y_m", "u_mps", "v_mps"], &["t_s"])?;
        // Ocean currents stay below 10 m/s; a larger value is a unit or typing mistake, and a
        // huge one would move a vehicle out of any domain in one step.
        for (k, r) in table.iter().enumerate() {
            for (v, name) in [(r[2], "u_mps"), (r[3], "v_mps")] {
                if v.abs() > 10.0 {
                    return Err(file_err(format!(
                        "line {}: {name} = {v:?} m/s; at most 10 m/s in magnitude",
                        k + 2
                    )));
                }
            }
            if r[4].is_finite() && r[4].abs() > 1e7 {
                return Err(file_err(format!(
                    "line {}: t_s = {:?} s; at most 1e7 s in magnitude",
                    k + 2,
                    r[4]
                )));
            }
        }
        let rows: Vec<[f64; 5]> = table
            .iter()
            .map(|r| {
                [
                    if r[4].is_nan() { 0.0 } else { r[4] },
                    r[0],
                    r[1],
                    r[2],
                    r[3],
                ]
            })
            .collect();
        let (x0, dx, nx) = regular_axis(rows.iter().map(|r| r[1]), "x_m", path)?;
        let (y0, dy, ny) = regular_axis(rows.iter().map(|r| r[2]), "y_m", path)?;
        // Group by time; BTreeMap over the bit pattern of a non-negative-normalised time keeps order.
        let mut by_time: BTreeMap<i64, Vec<[f64; 5]>> = BTreeMap::new();
        for r in rows {
            // Times are keyed in microseconds so that equal times written differently group together.
            by_time
                .entry((r[0] * 1e6).round() as i64)
                .or_default()
                .push(r);
        }
        let mut frames = Vec::with_capacity(by_time.len());
        for (_, rows) in by_time {
            let t_s = rows[0][0];
            let mut u = vec![f64::NAN; nx * ny];
            let mut v = vec![f64::NAN; nx * ny];
            for r in &rows {
                let i = ((r[1] - x0) / dx).round() as usize;
                let j = ((r[2] - y0) / dy).round() as usize;
                let k = j * nx + i;
                if !u[k].is_nan() {
                    return Err(file_err(format!(
                        "t_s = {t_s}: node ({}, {}) appears twice",
                        r[1], r[2]
                    )));
                }
                u[k] = r[3];
                v[k] = r[4];
            }
            if let Some(k) = u.iter().position(|x| x.is_nan()) {
                return Err(file_err(format!(
                    "t_s = {t_s}: grid node ({}, {}) is missing ({} x {} grid expected)",
                    x0 + (k % nx) as f64 * dx,
                    y0 + (k / nx) as f64 * dy,
                    nx,
                    ny
                )));
            }
            frames.push(Frame { t_s, u, v });
        }
        Ok(GriddedFlow::from_frames_unchecked(
            x0, dx, nx, y0, dy, ny, frames,
        ))
    }

    pub(super) fn from_frames_unchecked(
        x0: f64,
        dx: f64,
        nx: usize,
        y0: f64,
        dy: f64,
        ny: usize,
        frames: Vec<Frame>,
    ) -> Self {
        let mut f = GriddedFlow {
            x0_m: x0,
            y0_m: y0,
            inv_dx: 1.0 / dx,
            inv_dy: 1.0 / dy,
            nx,
            ny,
            frames,
            time_s: 0.0,
            frame: 0,
            blend: 0.0,
            meander: None,
        };
        f.set_time(0.0);
        f
    }

    /// The grid with the meander of a Farrell field over `region` added: the field's departure
    /// from its mean times `strength` (> 0). The field is driven by the grid's mean velocity at
    /// time 0 (its nodes' average); it draws its noise from the flow's stream and brings its
    /// stable step, which the environment sub-steps within. Errors name the field's parameter.
    pub fn with_meander(
        mut self,
        region: Rect,
        params: FarrellParams,
        strength: f64,
    ) -> Result<Self, EnvError> {
        if !(strength.is_finite() && strength > 0.0) {
            return Err(EnvError::invalid(
                "meander",
                format!("must be a number > 0, got {strength:?}"),
            ));
        }
        let f = &self.frames[0];
        let n = f.u.len().max(1) as f64;
        let mean_mps = Vec2::new(f.u.iter().sum::<f64>() / n, f.v.iter().sum::<f64>() / n);
        let mean = MeanFlow::Steady {
            speed_mps: mean_mps.norm(),
            // Compass degrees: clockwise from North (atan2(0, 0) = 0 for still water).
            toward_deg: mean_mps.x.atan2(mean_mps.y).to_degrees(),
        };
        let field = FarrellFlow::substepped(region, mean, params)?;
        self.meander = Some(Box::new(Meander {
            field,
            mean_mps,
            strength,
        }));
        Ok(self)
    }

    /// Number of time frames.
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Grid size `(nx, ny)`.
    pub fn grid_size(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    fn set_time(&mut self, t_s: f64) {
        self.time_s = t_s;
        let n = self.frames.len();
        let k = self.frames.partition_point(|f| f.t_s <= t_s);
        if k == 0 {
            (self.frame, self.blend) = (0, 0.0);
        } else if k >= n {
            (self.frame, self.blend) = (n - 1, 0.0);
        } else {
            let (a, b) = (&self.frames[k - 1], &self.frames[k]);
            (self.frame, self.blend) = (k - 1, (t_s - a.t_s) / (b.t_s - a.t_s));
        }
    }

    #[inline]
    fn sample(&self, frame: &Frame, i: usize, j: usize, tx: f64, ty: f64) -> (f64, f64) {
        let k00 = j * self.nx + i;
        let (k10, k01, k11) = (k00 + 1, k00 + self.nx, k00 + self.nx + 1);
        let (w00, w10, w01, w11) = (
            (1.0 - tx) * (1.0 - ty),
            tx * (1.0 - ty),
            (1.0 - tx) * ty,
            tx * ty,
        );
        (
            w00 * frame.u[k00] + w10 * frame.u[k10] + w01 * frame.u[k01] + w11 * frame.u[k11],
            w00 * frame.v[k00] + w10 * frame.v[k10] + w01 * frame.v[k01] + w11 * frame.v[k11],
        )
    }
}

impl FlowField for GriddedFlow {
    fn name(&self) -> &'static str {
        "gridded"
    }
    fn time_s(&self) -> f64 {
        self.time_s
    }
    fn velocity(&self, pos_m: Vec2) -> Vec2 {
        let (i, tx) = axis_weight(pos_m.x, self.x0_m, self.inv_dx, self.nx);
        let (j, ty) = axis_weight(pos_m.y, self.y0_m, self.inv_dy, self.ny);
        let (u0, v0) = self.sample(&self.frames[self.frame], i, j, tx, ty);
        let grid = if self.blend > 0.0 {
            let (u1, v1) = self.sample(&self.frames[self.frame + 1], i, j, tx, ty);
            let b = self.blend;
            Vec2::new(u0 + b * (u1 - u0), v0 + b * (v1 - v0))
        } else {
            Vec2::new(u0, v0)
        };
        match &self.meander {
            None => grid,
            Some(m) => grid + (m.field.velocity(pos_m) - m.mean_mps) * m.strength,
        }
    }
    fn advance(&mut self, t_new_s: f64, dt_s: f64, rng: &mut SimRng) -> Result<(), EnvError> {
        self.set_time(t_new_s);
        if let Some(m) = &mut self.meander {
            m.field.advance(t_new_s, dt_s, rng)?;
        }
        Ok(())
    }
    fn max_stable_dt_s(&self) -> Option<f64> {
        self.meander
            .as_ref()
            .and_then(|m| m.field.max_stable_dt_s())
    }
    fn nodes(&self) -> usize {
        self.meander
            .as_ref()
            .map_or(1, |m| FlowField::nodes(&m.field))
    }
    fn own_step_s(&self) -> Option<f64> {
        self.meander.as_ref().and_then(|m| m.field.own_step_s())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{StreamId, stream_rng};
    use std::io::Write;

    fn write_tmp(name: &str, text: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("plumetrace-gridded-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("flow.csv");
        let mut f = std::fs::File::create(&p).unwrap();
        f.write_all(text.as_bytes()).unwrap();
        p
    }

    #[test]
    fn reads_grid_and_interpolates_in_space_and_time() {
        let mut text = String::from("t_s,x_m,y_m,u_mps,v_mps\n");
        for (t, scale) in [(0.0, 1.0), (10.0, 3.0)] {
            for y in [0.0, 10.0] {
                for x in [0.0, 10.0, 20.0] {
                    text += &format!("{t},{x},{y},{},{}\n", scale * x / 10.0, -y / 10.0);
                }
            }
        }
        let p = write_tmp("ok", &text);
        let mut f = GriddedFlow::from_csv(&p).unwrap();
        assert_eq!(f.frame_count(), 2);
        assert_eq!(f.grid_size(), (3, 2));
        let v = f.velocity(Vec2::new(5.0, 5.0));
        assert!(
            (v.x - 0.5).abs() < 1e-12 && (v.y + 0.5).abs() < 1e-12,
            "{v:?}"
        );
        let mut rng = stream_rng(0, StreamId::Flow);
        f.advance(5.0, 5.0, &mut rng).unwrap();
        let v = f.velocity(Vec2::new(15.0, 0.0));
        assert!((v.x - 1.5 * 2.0).abs() < 1e-12, "{v:?}");
        f.advance(50.0, 45.0, &mut rng).unwrap();
        let v = f.velocity(Vec2::new(15.0, 0.0));
        assert!((v.x - 4.5).abs() < 1e-12, "held last frame: {v:?}");
    }

    #[test]
    fn the_meander_adds_a_departure_that_moves_and_the_grid_alone_draws_nothing() {
        let mut text = String::from("x_m,y_m,u_mps,v_mps\n");
        for y in [0.0, 100.0] {
            for x in [0.0, 100.0] {
                text += &format!("{x},{y},0.2,0.0\n");
            }
        }
        let p = write_tmp("meander", &text);
        let plain = GriddedFlow::from_csv(&p).unwrap();
        let region = Rect::new(0.0, 100.0, 0.0, 100.0).unwrap();
        let params = FarrellParams {
            nx: 11,
            ny: 11,
            noise_gain: 2.0,
            ..FarrellParams::default()
        };
        let e = plain
            .clone()
            .with_meander(region, params, 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("meander"), "{e}");
        let mut m = plain.clone().with_meander(region, params, 1.0).unwrap();
        assert!(m.max_stable_dt_s().is_some() && m.nodes() > 1);
        let mut rng = stream_rng(3, StreamId::Flow);
        let dt = m.max_stable_dt_s().unwrap().min(1.0) * 0.5;
        for k in 1..=400 {
            m.advance(k as f64 * dt, dt, &mut rng).unwrap();
        }
        let a = m.velocity(Vec2::new(50.0, 50.0));
        let b = plain.velocity(Vec2::new(50.0, 50.0));
        assert!((a - b).norm() > 1e-6, "{a:?} {b:?}");
        // Without a meander the grid draws nothing from the flow's stream.
        let mut r1 = stream_rng(3, StreamId::Flow);
        let mut g = plain.clone();
        g.advance(1.0, 1.0, &mut r1).unwrap();
        let mut r2 = stream_rng(3, StreamId::Flow);
        use rand::Rng as _;
        assert_eq!(r1.random::<u64>(), r2.random::<u64>());
    }

    #[test]
    fn missing_node_and_bad_numbers_are_located() {
        let p = write_tmp(
            "missing",
            "x_m,y_m,u_mps,v_mps\n0,0,1,0\n10,0,1,0\n0,10,1,0\n",
        );
        let e = GriddedFlow::from_csv(&p).unwrap_err().to_string();
        assert!(e.contains("missing") && e.contains("flow.csv"), "{e}");
        let p = write_tmp("nan", "x_m,y_m,u_mps,v_mps\n0,0,1,0\n10,0,abc,0\n");
        let e = GriddedFlow::from_csv(&p).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("u_mps"), "{e}");
        let p = write_tmp("hdr", "a,b\n1,2\n");
        let e = GriddedFlow::from_csv(&p).unwrap_err().to_string();
        assert!(e.contains("header"), "{e}");
    }
}
