//! Transverse Mercator and UTM on an ellipsoid (WGS 84 unless said), forward and inverse, by
//! Krüger's series in the third flattening `n` to order `n^6` (as Karney, "Transverse Mercator
//! with an accuracy of a few nanometers", J. Geodesy 85, 2011, gives them).
//!
//! The map goes through the conformal latitude: a point's conformal latitude and its longitude
//! from the central meridian give the spherical transverse Mercator coordinates `(ξ', η')`, and
//! six sine and hyperbolic sine terms carry those to the ellipsoid's `(ξ, η)`; the inverse runs
//! the other six terms backwards and finds the latitude from the conformal one by Newton's
//! method. Within 3900 km of the central meridian the series' own error is a few nanometres;
//! rounding in `f64` leaves a few tenths of a micrometre, so a UTM zone and several zones either
//! side of it are far inside a millimetre. Points more than [`MAX_FROM_MERIDIAN_DEG`] from the
//! central meridian are refused rather than given less accurate numbers.

use std::f64::consts::FRAC_PI_2;

/// The farthest a point may be from the central meridian, deg (the series is accurate to
/// nanometres out to about 3900 km from it; 30 deg of longitude is 3340 km at the equator).
pub const MAX_FROM_MERIDIAN_DEG: f64 = 30.0;

/// The latitudes UTM is used over, deg: 80 deg S to 84 deg N, with the half degree of overlap
/// the grid's definition allows beyond each (the poles are UPS's).
pub const UTM_LATITUDES_DEG: (f64, f64) = (-80.5, 84.5);

/// WGS 84's semi-major axis, m, and flattening.
pub const WGS84_A_M: f64 = 6_378_137.0;
/// WGS 84's flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// Why a point or a projection cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProjectionError {
    /// A UTM zone outside 1 to 60.
    #[error("UTM zone {0} does not exist (zones are 1 to 60)")]
    Zone(i64),
    /// A parameter of a transverse Mercator that cannot be.
    #[error("transverse Mercator {name} = {value} {why}")]
    Parameter {
        /// The parameter's name (as CF names it).
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// A latitude beyond the projection's limits.
    #[error(
        "latitude {lat_deg} deg is outside {projection}'s limits ({} to {} deg)",
        limits.0, limits.1
    )]
    Latitude {
        /// The latitude, deg.
        lat_deg: f64,
        /// The projection, named (`UTM zone 18N`).
        projection: String,
        /// Its limits, deg, south then north.
        limits: (f64, f64),
    },
    /// A longitude too far from the central meridian.
    #[error(
        "longitude {lon_deg} deg is {:.1} deg from {projection}'s central meridian \
         ({central_deg} deg); more than {MAX_FROM_MERIDIAN_DEG} deg away the projection is not \
         used",
        crate::wrap_deg_180(lon_deg - central_deg).abs()
    )]
    Longitude {
        /// The longitude, deg.
        lon_deg: f64,
        /// The central meridian, deg.
        central_deg: f64,
        /// The projection, named.
        projection: String,
    },
    /// A coordinate that is not a finite number.
    #[error("{what} {value} is not a finite number")]
    NotFinite {
        /// Which coordinate (`latitude`, `easting`).
        what: &'static str,
        /// Its value.
        value: f64,
    },
}

/// The parameters of a transverse Mercator (CF's names for a `transverse_mercator` grid
/// mapping).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TmParams {
    /// `longitude_of_central_meridian`, deg.
    pub central_meridian_deg: f64,
    /// `latitude_of_projection_origin`, deg (where the northing is the false northing).
    pub origin_lat_deg: f64,
    /// `scale_factor_at_central_meridian`.
    pub scale: f64,
    /// `false_easting`, m.
    pub false_easting_m: f64,
    /// `false_northing`, m.
    pub false_northing_m: f64,
}

/// A transverse Mercator projection: latitude and longitude to easting and northing and back.
#[derive(Debug, Clone, PartialEq)]
pub struct TransverseMercator {
    p: TmParams,
    /// The name messages give it (`UTM zone 18N`, `the transverse Mercator`).
    name: String,
    /// Latitudes allowed, deg.
    limits: (f64, f64),
    /// First eccentricity.
    e: f64,
    /// `k0` times the rectifying radius, m.
    k0_a: f64,
    /// Krüger's forward (`alpha`) and inverse (`beta`) coefficients, orders 1 to 6.
    alpha: [f64; 6],
    beta: [f64; 6],
    /// The northing of the projection's origin latitude before the false northing, m.
    y_origin_m: f64,
}

/// Krüger's forward coefficients `alpha_1` to `alpha_6`, each a polynomial in `n` from `n^1` to
/// `n^6` (Karney 2011, eq. 35).
#[rustfmt::skip]
const ALPHA: [[f64; 6]; 6] = [
    [1.0 / 2.0, -2.0 / 3.0, 5.0 / 16.0, 41.0 / 180.0, -127.0 / 288.0, 7891.0 / 37800.0],
    [0.0, 13.0 / 48.0, -3.0 / 5.0, 557.0 / 1440.0, 281.0 / 630.0, -1_983_433.0 / 1_935_360.0],
    [0.0, 0.0, 61.0 / 240.0, -103.0 / 140.0, 15061.0 / 26880.0, 167_603.0 / 181_440.0],
    [0.0, 0.0, 0.0, 49561.0 / 161_280.0, -179.0 / 168.0, 6_601_661.0 / 7_257_600.0],
    [0.0, 0.0, 0.0, 0.0, 34729.0 / 80640.0, -3_418_889.0 / 1_995_840.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 212_378_941.0 / 319_334_400.0],
];

/// Krüger's inverse coefficients `beta_1` to `beta_6` (Karney 2011, eq. 36).
#[rustfmt::skip]
const BETA: [[f64; 6]; 6] = [
    [1.0 / 2.0, -2.0 / 3.0, 37.0 / 96.0, -1.0 / 360.0, -81.0 / 512.0, 96199.0 / 604_800.0],
    [0.0, 1.0 / 48.0, 1.0 / 15.0, -437.0 / 1440.0, 46.0 / 105.0, -1_118_711.0 / 3_870_720.0],
    [0.0, 0.0, 17.0 / 480.0, -37.0 / 840.0, -209.0 / 4480.0, 5569.0 / 90720.0],
    [0.0, 0.0, 0.0, 4397.0 / 161_280.0, -11.0 / 504.0, -830_251.0 / 7_257_600.0],
    [0.0, 0.0, 0.0, 0.0, 4583.0 / 161_280.0, -108_847.0 / 3_991_680.0],
    [0.0, 0.0, 0.0, 0.0, 0.0, 20_648_693.0 / 638_668_800.0],
];

/// Evaluates a polynomial in `n` given its coefficients from `n^1` up.
fn poly(n: f64, c: &[f64]) -> f64 {
    c.iter().rev().fold(0.0, |acc, k| acc * n + k) * n
}

impl TransverseMercator {
    /// A transverse Mercator on WGS 84 (limited to latitudes within 90 deg).
    pub fn new(p: TmParams) -> Result<Self, ProjectionError> {
        Self::on_ellipsoid(
            WGS84_A_M,
            WGS84_F,
            p,
            "the transverse Mercator",
            (-90.0, 90.0),
        )
    }

    /// UTM zone `zone` (1 to 60) of the northern or southern hemisphere, on WGS 84.
    pub fn utm(zone: i64, north: bool) -> Result<Self, ProjectionError> {
        if !(1..=60).contains(&zone) {
            return Err(ProjectionError::Zone(zone));
        }
        let p = TmParams {
            central_meridian_deg: -183.0 + 6.0 * zone as f64,
            origin_lat_deg: 0.0,
            scale: 0.9996,
            false_easting_m: 500_000.0,
            false_northing_m: if north { 0.0 } else { 10_000_000.0 },
        };
        let name = format!("UTM zone {zone}{}", if north { 'N' } else { 'S' });
        Self::on_ellipsoid(WGS84_A_M, WGS84_F, p, &name, UTM_LATITUDES_DEG)
    }

    /// The UTM zone of an EPSG code of WGS 84 / UTM (32601 to 32660 north, 32701 to 32760
    /// south): `Some(Ok)` for one of those, `Some(Err)` naming zone 0 or 61 to 99 of the two
    /// series (32600, 32661 and up: not UTM zones), `None` for any other code.
    pub fn utm_from_epsg(code: u32) -> Option<Result<Self, ProjectionError>> {
        match code {
            32600..=32699 => Some(Self::utm(i64::from(code - 32600), true)),
            32700..=32799 => Some(Self::utm(i64::from(code - 32700), false)),
            _ => None,
        }
    }

    /// A transverse Mercator on the ellipsoid of semi-major axis `a_m` and flattening `f`.
    pub fn on_ellipsoid(
        a_m: f64,
        f: f64,
        p: TmParams,
        name: &str,
        limits: (f64, f64),
    ) -> Result<Self, ProjectionError> {
        let bad = |name, value, why| Err(ProjectionError::Parameter { name, value, why });
        if !(a_m.is_finite() && a_m > 0.0) {
            return bad("semi_major_axis", a_m, "is not a length above 0 m");
        }
        if !(f.is_finite() && (0.0..0.1).contains(&f)) {
            return bad("flattening", f, "is not in [0, 0.1)");
        }
        if !(p.scale.is_finite() && p.scale > 0.0) {
            return bad(
                "scale_factor_at_central_meridian",
                p.scale,
                "is not a number above 0",
            );
        }
        if !(p.central_meridian_deg.is_finite() && p.central_meridian_deg.abs() <= 360.0) {
            return bad(
                "longitude_of_central_meridian",
                p.central_meridian_deg,
                "is not a longitude",
            );
        }
        if !(p.origin_lat_deg.is_finite() && p.origin_lat_deg.abs() <= 90.0) {
            return bad(
                "latitude_of_projection_origin",
                p.origin_lat_deg,
                "is not a latitude",
            );
        }
        for (name, v) in [
            ("false_easting", p.false_easting_m),
            ("false_northing", p.false_northing_m),
        ] {
            if !v.is_finite() {
                return bad(name, v, "is not a finite number");
            }
        }
        let n = f / (2.0 - f);
        let n2 = n * n;
        // The rectifying radius: a / (1 + n) * (1 + n^2/4 + n^4/64 + n^6/256).
        let rect = a_m / (1.0 + n) * (1.0 + n2 / 4.0 + n2 * n2 / 64.0 + n2 * n2 * n2 / 256.0);
        let alpha = ALPHA.map(|c| poly(n, &c));
        let beta = BETA.map(|c| poly(n, &c));
        let mut tm = TransverseMercator {
            p,
            name: name.to_string(),
            limits,
            e: (f * (2.0 - f)).sqrt(),
            k0_a: p.scale * rect,
            alpha,
            beta,
            y_origin_m: 0.0,
        };
        tm.y_origin_m = tm.xy(p.origin_lat_deg, p.central_meridian_deg).1;
        Ok(tm)
    }

    /// The projection named `name` in messages.
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.to_string();
        self
    }

    /// The projection's name in messages (`UTM zone 18N`).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its parameters.
    pub fn params(&self) -> TmParams {
        self.p
    }

    /// Whether a latitude and longitude are inside the projection's limits.
    fn check(&self, lat_deg: f64, lon_deg: f64) -> Result<(), ProjectionError> {
        // A nanodegree's slack, so that an inverse lands inside what the forward took.
        if !(lat_deg >= self.limits.0 - 1e-9 && lat_deg <= self.limits.1 + 1e-9) {
            return Err(ProjectionError::Latitude {
                lat_deg,
                projection: self.name.clone(),
                limits: self.limits,
            });
        }
        if crate::wrap_deg_180(lon_deg - self.p.central_meridian_deg).abs()
            > MAX_FROM_MERIDIAN_DEG + 1e-9
        {
            return Err(ProjectionError::Longitude {
                lon_deg,
                central_deg: self.p.central_meridian_deg,
                projection: self.name.clone(),
            });
        }
        Ok(())
    }

    /// Easting and northing of a latitude and longitude, m; an error outside the limits.
    pub fn forward(&self, lat_deg: f64, lon_deg: f64) -> Result<(f64, f64), ProjectionError> {
        for (what, value) in [("latitude", lat_deg), ("longitude", lon_deg)] {
            if !value.is_finite() {
                return Err(ProjectionError::NotFinite { what, value });
            }
        }
        self.check(lat_deg, lon_deg)?;
        let (x, y) = self.xy(lat_deg, lon_deg);
        Ok((
            self.p.false_easting_m + x,
            self.p.false_northing_m + y - self.y_origin_m,
        ))
    }

    /// `(x, y)` from the central meridian and the equator, m (no false origin).
    fn xy(&self, lat_deg: f64, lon_deg: f64) -> (f64, f64) {
        let lam = crate::wrap_deg_180(lon_deg - self.p.central_meridian_deg).to_radians();
        let tau = lat_deg.to_radians().tan();
        let tau_c = self.conformal_tau(tau);
        let (sl, cl) = lam.sin_cos();
        let xi_c = tau_c.atan2(cl);
        let eta_c = (sl / tau_c.hypot(cl)).asinh();
        let (mut xi, mut eta) = (xi_c, eta_c);
        for (j, a) in self.alpha.iter().enumerate() {
            let k = 2.0 * (j + 1) as f64;
            xi += a * (k * xi_c).sin() * (k * eta_c).cosh();
            eta += a * (k * xi_c).cos() * (k * eta_c).sinh();
        }
        (self.k0_a * eta, self.k0_a * xi)
    }

    /// The tangent of the conformal latitude of a latitude of tangent `tau`.
    fn conformal_tau(&self, tau: f64) -> f64 {
        let sigma = (self.e * (self.e * tau / tau.hypot(1.0)).atanh()).sinh();
        tau * sigma.hypot(1.0) - sigma * tau.hypot(1.0)
    }

    /// Latitude and longitude of an easting and northing, deg; an error outside the limits.
    pub fn inverse(&self, easting_m: f64, northing_m: f64) -> Result<(f64, f64), ProjectionError> {
        for (what, value) in [("easting", easting_m), ("northing", northing_m)] {
            if !value.is_finite() {
                return Err(ProjectionError::NotFinite { what, value });
            }
        }
        let xi = (northing_m - self.p.false_northing_m + self.y_origin_m) / self.k0_a;
        let eta = (easting_m - self.p.false_easting_m) / self.k0_a;
        let (mut xi_c, mut eta_c) = (xi, eta);
        for (j, b) in self.beta.iter().enumerate() {
            let k = 2.0 * (j + 1) as f64;
            xi_c -= b * (k * xi).sin() * (k * eta).cosh();
            eta_c -= b * (k * xi).cos() * (k * eta).sinh();
        }
        let (sh, cx) = (eta_c.sinh(), xi_c.cos());
        let lam = sh.atan2(cx);
        let lat = if xi_c.abs() >= FRAC_PI_2 && sh == 0.0 {
            FRAC_PI_2.copysign(xi_c).to_degrees()
        } else {
            self.tau_of_conformal(xi_c.sin() / sh.hypot(cx))
                .atan()
                .to_degrees()
        };
        let lon = crate::wrap_deg_180(self.p.central_meridian_deg + lam.to_degrees());
        self.check(lat, lon)?;
        Ok((lat, lon))
    }

    /// The tangent of the latitude whose conformal latitude has tangent `tau_c` (Newton's
    /// method, from `tau_c` itself; two or three steps reach `f64`'s precision).
    fn tau_of_conformal(&self, tau_c: f64) -> f64 {
        let e2m = 1.0 - self.e * self.e;
        let mut tau = tau_c;
        for _ in 0..8 {
            let t = self.conformal_tau(tau);
            let dtau =
                (tau_c - t) / t.hypot(1.0) * (1.0 + e2m * tau * tau) / (e2m * tau.hypot(1.0));
            tau += dtau;
            if dtau.abs() <= 1e-15 * tau.abs().max(1.0) {
                break;
            }
        }
        tau
    }
}

#[cfg(test)]
mod tests;
