//! The current meter's line input: NMEA 0183 `$--CUR` (water current layer) sentences, the
//! sentence ADCPs and DVLs write for the current they measure. A reading gives the direction
//! the water goes towards (its set, degrees true or relative to the vehicle's heading) and its
//! speed in knots for one layer at a depth; it becomes a velocity `(east, north)` in m/s, the
//! [`plumetrace_core::FlowSample`] a simulated vehicle's flow sensor gives its planner.
//!
//! `$--CUR,A,s,l,d.d,c.c,T,v.v,r.r,h.h,T,B*hh`, fields after the id:
//!
//! | # | field | accepted |
//! | - | --- | --- |
//! | 1 | validity | `A` (`V`, a reading the instrument marks invalid, is rejected) |
//! | 2 | data set number | 0 to 9 |
//! | 3 | layer number | 0 to 99 |
//! | 4 | layer depth, m | empty or [0, 12000] |
//! | 5 | direction the current goes towards, deg | [0, 360] |
//! | 6 | direction reference | `T` true, `R` relative to the heading of field 9 |
//! | 7 | speed, knots | [0, 20] |
//! | 8 | reference layer depth, m | empty or [0, 12000] |
//! | 9 | heading, deg | empty or [0, 360] (required with `R`) |
//! | 10 | heading reference | `T`, `M` or empty (`R` needs `T`: no declination is known) |
//! | 11 | speed reference | `B` bottom track or `P` positioning system (`W`, relative to a water layer, is rejected: it is not the current over the ground) |
//!
//! The talker (the two letters before `CUR`) is any.

use crate::protocol::sentence::{Fields, HEADING, Range, SentenceError, frame};
use plumetrace_core::{Heading, Vec2};

/// Metres per second per knot.
const MPS_PER_KN: f64 = 1852.0 / 3600.0;
const SPEED_KN: Range = Range::new(0.0, 20.0, "[0, 20] kn");
const DEPTH_M: Range = Range::new(0.0, 12_000.0, "[0, 12000] m");
const ID: &str = "CUR";

/// How the direction of a reading is referenced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DirectionRef {
    /// Degrees true.
    True,
    /// Degrees clockwise from the vehicle's heading (field 9).
    Relative,
}

/// A `$--CUR` reading, in wire units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cur {
    /// Data set number (0 to 9).
    pub data_set: u32,
    /// Layer number (0 to 99).
    pub layer: u32,
    /// Depth of the layer, m.
    pub depth_m: Option<f64>,
    /// Direction the current goes towards, deg.
    pub direction_deg: f64,
    /// Its reference.
    pub reference: DirectionRef,
    /// Speed, knots.
    pub speed_kn: f64,
    /// Reference layer depth, m.
    pub ref_layer_depth_m: Option<f64>,
    /// The vehicle's heading, deg true.
    pub heading_deg: Option<f64>,
    /// Speed reference: `true` bottom track (`B`), `false` positioning system (`P`).
    pub bottom_track: bool,
}

impl Cur {
    /// Whether `line` is a `$--CUR` sentence (any talker), so a link can route it.
    pub fn claims(line: &str) -> bool {
        line.strip_prefix('$')
            .and_then(|r| r.get(2..))
            .and_then(|r| r.strip_prefix(ID))
            .is_some_and(|r| r.starts_with([',', '*']))
            && line
                .as_bytes()
                .get(1..3)
                .is_some_and(|t| t.iter().all(u8::is_ascii_uppercase))
    }

    /// Reads one line (framing, checksum, fields and their ranges).
    pub fn parse(line: &str) -> Result<Self, SentenceError> {
        let f = Fields::parse(line)?;
        if !(f.id.len() == 5 && f.id.ends_with(ID)) {
            return Err(SentenceError::Unknown(f.id.to_string()));
        }
        f.expect_len(ID, 11)?;
        f.one_of(ID, 1, "validity", &["A"])?;
        let reference = [DirectionRef::True, DirectionRef::Relative]
            [f.one_of(ID, 6, "direction reference", &["T", "R"])?];
        let heading_deg = f.opt_f64(ID, 9, "heading", HEADING)?;
        let heading_ref = f.one_of(ID, 10, "heading reference", &["T", "M", ""])?;
        if reference == DirectionRef::Relative && (heading_deg.is_none() || heading_ref != 0) {
            return Err(SentenceError::BadField {
                id: ID,
                index: 9,
                name: "heading",
                text: f.text(9).to_string(),
                what: "a true heading (a relative direction needs one)",
            });
        }
        let bottom_track = f.one_of(ID, 11, "speed reference", &["B", "P"])? == 0;
        Ok(Cur {
            data_set: f.int(ID, 2, "data set", 9)?,
            layer: f.int(ID, 3, "layer", 99)?,
            depth_m: f.opt_f64(ID, 4, "layer depth", DEPTH_M)?,
            direction_deg: f.f64(ID, 5, "direction", HEADING)?,
            reference,
            speed_kn: f.f64(ID, 7, "speed", SPEED_KN)?,
            ref_layer_depth_m: f.opt_f64(ID, 8, "reference layer depth", DEPTH_M)?,
            heading_deg,
            bottom_track,
        })
    }

    /// The current's velocity `(east, north)`, m/s.
    pub fn velocity_mps(&self) -> Vec2 {
        let toward = match self.reference {
            DirectionRef::True => self.direction_deg,
            DirectionRef::Relative => self.direction_deg + self.heading_deg.unwrap_or(0.0),
        };
        Heading::from_deg(toward).unit() * (self.speed_kn * MPS_PER_KN)
    }

    /// A true-referenced, bottom-tracked reading of `velocity_mps` at `depth_m` (what a
    /// simulated front seat sends); talker `VD`.
    pub fn of_velocity(velocity_mps: Vec2, depth_m: Option<f64>, layer: u32) -> Self {
        let speed = velocity_mps.norm();
        let direction_deg = Heading::of_vector(velocity_mps)
            .map_or(0.0, |h| plumetrace_core::wrap_deg_360(h.deg()));
        Cur {
            data_set: 0,
            layer: layer.min(99),
            depth_m: depth_m.map(|d| d.clamp(0.0, 12_000.0)),
            // 360.0 after rounding to 0.1 deg reads back as 0 deg.
            direction_deg: if direction_deg >= 359.95 {
                0.0
            } else {
                direction_deg
            },
            reference: DirectionRef::True,
            speed_kn: (speed / MPS_PER_KN).min(20.0),
            ref_layer_depth_m: None,
            heading_deg: None,
            bottom_track: true,
        }
    }

    /// The line (talker `VD`, checksum, `\r\n`).
    pub fn encode(&self) -> String {
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.1}"));
        frame(&format!(
            "VDCUR,A,{},{},{},{:.1},{},{:.3},{},{},{},{}",
            self.data_set.min(9),
            self.layer.min(99),
            opt(self.depth_m),
            self.direction_deg,
            match self.reference {
                DirectionRef::True => "T",
                DirectionRef::Relative => "R",
            },
            self.speed_kn,
            opt(self.ref_layer_depth_m),
            opt(self.heading_deg),
            if self.heading_deg.is_some() { "T" } else { "" },
            if self.bottom_track { "B" } else { "P" },
        ))
    }
}

/// Which `$--CUR` readings a flow input uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FlowFormat {
    /// Only this layer's readings (`None`: every reading).
    pub layer: Option<u32>,
}

impl FlowFormat {
    /// Whether `line` is for this input (a `$--CUR` sentence).
    pub fn claims(&self, line: &str) -> bool {
        Cur::claims(line)
    }

    /// The velocity in `line`, or `None` for a good reading of another layer.
    pub fn parse(&self, line: &str) -> Result<Option<Vec2>, SentenceError> {
        let c = Cur::parse(line)?;
        Ok(self
            .layer
            .is_none_or(|l| l == c.layer)
            .then(|| c.velocity_mps()))
    }
}
