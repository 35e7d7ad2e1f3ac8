//! Latitude and longitude to the local east/north frame and back, around a configured origin.
//!
//! The local frame is the azimuthal equidistant projection about the origin on the WGS-84
//! ellipsoid, computed with GeographicLib's geodesics (`geographiclib-rs`): a point's east and
//! north are its geodesic distance from the origin times the sine and cosine of the azimuth
//! there. Distances from the origin and bearings at it are exact; over a few kilometres the
//! frame differs from a flat tangent plane by millimetres. [`tm`] holds the transverse Mercator
//! (and UTM) that projected bathymetry and currents are placed by.

use crate::Vec2;
use geographiclib_rs::{DirectGeodesic, Geodesic, InverseGeodesic};
use serde::{Deserialize, Serialize};
pub use tm::{ProjectionError, TmParams, TransverseMercator};

/// The origin of the local frame (where `x = y = 0`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Origin {
    /// Latitude, deg (north positive), in `[-89, 89]`.
    pub lat_deg: f64,
    /// Longitude, deg (east positive), in `[-180, 180]`.
    pub lon_deg: f64,
}

/// Why an origin cannot have a local frame.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum OriginError {
    /// The latitude is not a finite number in `[-89, 89]` (the poles have no east).
    #[error("origin latitude {0} is not in [-89, 89] deg")]
    Latitude(f64),
    /// The longitude is not a finite number in `[-180, 180]`.
    #[error("origin longitude {0} is not in [-180, 180] deg")]
    Longitude(f64),
}

/// Converts between latitude/longitude and the local frame around an [`Origin`].
#[derive(Debug, Clone)]
pub struct LocalFrame {
    origin: Origin,
    geod: Geodesic,
}

impl LocalFrame {
    /// The frame around `origin`; an error if the origin is not a finite latitude in
    /// `[-89, 89]` and longitude in `[-180, 180]` (the poles have no east).
    pub fn new(origin: Origin) -> Result<Self, OriginError> {
        if !(origin.lat_deg.is_finite() && origin.lat_deg.abs() <= 89.0) {
            return Err(OriginError::Latitude(origin.lat_deg));
        }
        if !(origin.lon_deg.is_finite() && origin.lon_deg.abs() <= 180.0) {
            return Err(OriginError::Longitude(origin.lon_deg));
        }
        Ok(LocalFrame {
            origin,
            geod: Geodesic::wgs84(),
        })
    }

    /// The origin.
    pub fn origin(&self) -> Origin {
        self.origin
    }

    /// East and north of a latitude and longitude, m.
    pub fn to_local(&self, lat_deg: f64, lon_deg: f64) -> Vec2 {
        let (s12, azi1, _, _): (f64, f64, f64, f64) =
            self.geod
                .inverse(self.origin.lat_deg, self.origin.lon_deg, lat_deg, lon_deg);
        let a = azi1.to_radians();
        Vec2::new(s12 * a.sin(), s12 * a.cos())
    }

    /// Latitude and longitude of a local position, deg.
    pub fn to_geographic(&self, pos_m: Vec2) -> (f64, f64) {
        let s12 = pos_m.x.hypot(pos_m.y);
        let azi1 = pos_m.x.atan2(pos_m.y).to_degrees();
        self.geod
            .direct(self.origin.lat_deg, self.origin.lon_deg, azi1, s12)
    }
}

pub mod tm;

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> LocalFrame {
        LocalFrame::new(Origin {
            lat_deg: 36.18,
            lon_deg: -75.75,
        })
        .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn local_positions_round_trip_through_latitude_and_longitude() {
        let f = frame();
        for (x, y) in [
            (0.0, 0.0),
            (470.0, -60.0),
            (-1500.0, 2500.0),
            (10.0, 0.0),
            (0.0, -10.0),
        ] {
            let (lat, lon) = f.to_geographic(Vec2::new(x, y));
            let back = f.to_local(lat, lon);
            assert!(
                (back.x - x).abs() < 1e-6 && (back.y - y).abs() < 1e-6,
                "{x} {y}: {back:?}"
            );
        }
    }

    #[test]
    fn the_frame_agrees_with_known_distances() {
        let f = frame();
        // One minute of latitude is about 1849 m at 36 deg (WGS-84 meridian arc).
        let p = f.to_local(36.18 + 1.0 / 60.0, -75.75);
        assert!(p.x.abs() < 1e-6, "{p:?}");
        assert!((p.y - 1849.4).abs() < 1.0, "{p:?}");
        // East is east: a point at a larger longitude has a positive x.
        let e = f.to_local(36.18, -75.749);
        assert!(e.x > 89.0 && e.x < 91.0 && e.y.abs() < 0.01, "{e:?}");
    }

    #[test]
    fn bad_origins_are_errors() {
        for (lat, lon) in [(90.0, 0.0), (f64::NAN, 0.0), (0.0, 181.0)] {
            assert!(
                LocalFrame::new(Origin {
                    lat_deg: lat,
                    lon_deg: lon
                })
                .is_err()
            );
        }
        let e = LocalFrame::new(Origin {
            lat_deg: 95.0,
            lon_deg: 0.0,
        })
        .err();
        assert_eq!(
            e.map(|e| e.to_string()).as_deref(),
            Some("origin latitude 95 is not in [-89, 89] deg")
        );
    }
}
