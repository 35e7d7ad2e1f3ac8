//! The windy grid world of the published infotaxis benchmark (the OTTO project's windy case).
//!
//! A lattice of `nx x ny` cells with a mean wind along `+x`. A source in cell `s` gives a
//! searcher in cell `r` a hit in one step with probability `1 - exp(-mu)`, where the mean hit
//! rate of the advection-diffusion model is
//!
//! `mu = R / d * exp(V (x - x_s) / 2 - d / lambda)`, `lambda = sqrt((tau / V^2) / (1 + tau / 4))`,
//!
//! with `d` the Euclidean distance in cells (no hit on the source cell itself), `R` the
//! dimensionless emission rate, `V` the wind speed and `tau` the particle lifetime in lattice
//! units. The searcher moves one cell per step along `+-x` or `+-y` (moves off the lattice are not
//! possible); it starts at `start` after a first hit, so its prior is uniform over the other cells
//! weighed by the probability of that hit; the search ends when it steps onto the source. The
//! benchmark's defaults: 81 x 41 cells, start (65, 20), `V = 2`, `tau = 150`, `R = 2.5` or `0.25`.
//!
//! This module is the model the searcher knows (the hit table, the moves, the prior); drawing
//! sources and hits is the benchmark driver's job.

/// The windy grid world's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindyGrid {
    /// Cells along the wind.
    pub nx: usize,
    /// Cells across the wind.
    pub ny: usize,
    /// The searcher's first cell `(x, y)`.
    pub start: (usize, usize),
    /// Dimensionless emission rate `R`.
    pub rate: f64,
    /// Dimensionless wind speed `V`.
    pub wind: f64,
    /// Dimensionless particle lifetime `tau`.
    pub lifetime: f64,
}

impl WindyGrid {
    /// The benchmark's lattice with emission rate `rate`.
    pub fn benchmark(rate: f64) -> Self {
        WindyGrid {
            nx: 81,
            ny: 41,
            start: (65, 20),
            rate,
            wind: 2.0,
            lifetime: 150.0,
        }
    }

    /// Number of cells.
    pub fn cells(&self) -> usize {
        self.nx * self.ny
    }

    /// The index of cell `(x, y)`.
    pub fn index(&self, x: usize, y: usize) -> usize {
        y * self.nx + x
    }

    /// The cell of index `i`.
    pub fn cell(&self, i: usize) -> (usize, usize) {
        (i % self.nx, i / self.nx)
    }

    /// The dispersion length `lambda`, cells.
    pub fn lambda(&self) -> f64 {
        ((self.lifetime / (self.wind * self.wind)) / (1.0 + self.lifetime / 4.0)).sqrt()
    }

    /// The table of hit probabilities by offset: entry `(dx + nx - 1, dy + ny - 1)` is the
    /// probability of a hit for a searcher `(dx, dy)` from the source (0 at the source).
    pub fn hit_table(&self) -> HitTable {
        let (w, h) = (2 * self.nx - 1, 2 * self.ny - 1);
        let lambda = self.lambda();
        let mut p = vec![0.0; w * h];
        for j in 0..h {
            for i in 0..w {
                let dx = i as f64 - (self.nx - 1) as f64;
                let dy = j as f64 - (self.ny - 1) as f64;
                if dx == 0.0 && dy == 0.0 {
                    continue;
                }
                let d = (dx * dx + dy * dy).sqrt().max(1.0);
                let mu = self.rate / d * (self.wind * dx / 2.0 - d / lambda).exp();
                p[j * w + i] = 1.0 - (-mu).exp();
            }
        }
        HitTable { grid: *self, p }
    }

    /// The cell one move from `(x, y)`: move 0 is `-x` (upwind), 1 `+x`, 2 `-y`, 3 `+y`; `None`
    /// off the lattice.
    pub fn step(&self, (x, y): (usize, usize), mv: usize) -> Option<(usize, usize)> {
        match mv {
            0 => x.checked_sub(1).map(|x| (x, y)),
            1 => (x + 1 < self.nx).then_some((x + 1, y)),
            2 => y.checked_sub(1).map(|y| (x, y)),
            3 => (y + 1 < self.ny).then_some((x, y + 1)),
            _ => None,
        }
    }

    /// The searcher's prior after its first hit at `start`: uniform over the other cells,
    /// weighed by the probability of that hit, normalised.
    pub fn prior(&self, table: &HitTable) -> Vec<f64> {
        let mut p = vec![1.0; self.cells()];
        let (sx, sy) = self.start;
        let hit = table.hits_at(sx, sy);
        crate::estimate::infotaxis::bayes_update(&mut p, &hit, true, Some(self.index(sx, sy)));
        p
    }
}

/// Hit probabilities by offset between searcher and source.
#[derive(Debug, Clone, PartialEq)]
pub struct HitTable {
    grid: WindyGrid,
    p: Vec<f64>,
}

impl HitTable {
    /// The probability of a hit for a searcher in `(x, y)` if the source is in `(sx, sy)`.
    pub fn hit(&self, (x, y): (usize, usize), (sx, sy): (usize, usize)) -> f64 {
        let g = &self.grid;
        let i = x + g.nx - 1 - sx;
        let j = y + g.ny - 1 - sy;
        self.p[j * (2 * g.nx - 1) + i]
    }

    /// For a searcher in `(x, y)`: the probability of a hit for every source cell, by index.
    pub fn hits_at(&self, x: usize, y: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.grid.cells()];
        self.fill_hits_at(x, y, &mut out);
        out
    }

    /// [`HitTable::hits_at`] into `out` (resized to the number of cells).
    pub fn fill_hits_at(&self, x: usize, y: usize, out: &mut Vec<f64>) {
        let g = &self.grid;
        out.resize(g.cells(), 0.0);
        let w = 2 * g.nx - 1;
        for sy in 0..g.ny {
            let row = (y + g.ny - 1 - sy) * w + x + g.nx - 1;
            // Source x from 0 to nx - 1: table column from row's x down to x - nx + 1.
            for sx in 0..g.nx {
                out[sy * g.nx + sx] = self.p[row - sx];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_benchmark_lambda_and_the_downwind_plume() {
        let g = WindyGrid::benchmark(2.5);
        assert!((g.lambda() - 0.9867).abs() < 1e-3, "{}", g.lambda());
        let t = g.hit_table();
        let src = (20, 20);
        assert_eq!(t.hit(src, src), 0.0);
        // Downwind hits are likelier than upwind or across at the same distance.
        let down = t.hit((30, 20), src);
        let up = t.hit((10, 20), src);
        let across = t.hit((20, 30), src);
        assert!(down > across && across > up, "{down} {across} {up}");
        // mu = 2.5 / 10 * exp(10 - 10 / lambda) downwind at 10 cells.
        let mu: f64 = 0.25 * (10.0 - 10.0 / g.lambda()).exp();
        assert!((down - (1.0 - (-mu).exp())).abs() < 1e-12);
        let row = t.hits_at(30, 20);
        assert_eq!(row[g.index(20, 20)], down);
    }

    #[test]
    fn moves_stay_on_the_lattice_and_the_prior_is_normalised() {
        let g = WindyGrid::benchmark(0.25);
        assert_eq!(g.step((0, 5), 0), None);
        assert_eq!(g.step((80, 5), 1), None);
        assert_eq!(g.step((3, 0), 2), None);
        assert_eq!(g.step((3, 40), 3), None);
        assert_eq!(g.step((3, 4), 3), Some((3, 5)));
        let p = g.prior(&g.hit_table());
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert_eq!(p[g.index(65, 20)], 0.0);
        // The first hit puts the source upwind.
        assert!(p[g.index(60, 20)] > p[g.index(70, 20)]);
    }
}
