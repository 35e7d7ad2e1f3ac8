//! The Iver remote-helm sentences (text lines over a serial line).
//!
//! The payload polls navigation with `$OSD,G,C,S,P,,,,` and the vehicle answers `$OSI`; the
//! payload commands with `$OMS` (heading, depth, maximum pitch, speed in knots, and a timeout
//! after which the vehicle takes control back) and stops the vehicle with `$OMSTOP,0`. The
//! depth of `$OMS` is in feet below remote-helm major version 5 and in metres from 5: the version
//! is an explicit setting ([`Units`]). `$OSI` reports altitude and depth in feet, speed in knots.

use crate::protocol::sentence::{Fields, HEADING, Range, SPEED, SentenceError, clean_text, frame};

/// Metres per foot.
pub const M_PER_FT: f64 = 0.3048;
/// Metres per second per knot.
pub const MPS_PER_KN: f64 = 1852.0 / 3600.0;

/// The unit setting of a remote-helm link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Units {
    /// The vehicle's remote-helm major version (the `$OMS` depth is in feet below 5, metres
    /// from 5).
    pub remote_helm_major: u32,
}

impl Units {
    /// Whether `$OMS` depths are in feet.
    pub fn depth_in_feet(self) -> bool {
        self.remote_helm_major < 5
    }

    /// A depth in metres as `$OMS` writes it.
    pub fn depth_to_wire(self, depth_m: f64) -> f64 {
        if self.depth_in_feet() {
            depth_m / M_PER_FT
        } else {
            depth_m
        }
    }

    /// A `$OMS` depth in metres.
    pub fn depth_from_wire(self, depth: f64) -> f64 {
        if self.depth_in_feet() {
            depth * M_PER_FT
        } else {
            depth
        }
    }
}

/// `$OMS`: a command, in wire units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Oms {
    /// Heading, deg.
    pub heading_deg: f64,
    /// Depth, feet or metres ([`Units`]).
    pub depth: f64,
    /// Maximum pitch, deg.
    pub max_pitch_deg: f64,
    /// Speed, knots.
    pub speed_kn: f64,
    /// The vehicle takes control back this long after the last `$OMS`, s.
    pub timeout_s: u32,
}

/// The vehicle's mode character in `$OSI`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// `N`: normal (remote helm in control).
    Normal,
    /// `S`: stopped.
    Stopped,
    /// `P`: parking.
    Parking,
    /// `M`: manual.
    Manual,
    /// `A`: servo.
    Servo,
    /// `W`: its own mission.
    Mission,
}

const MODES: [(&str, Mode); 6] = [
    ("N", Mode::Normal),
    ("S", Mode::Stopped),
    ("P", Mode::Parking),
    ("M", Mode::Manual),
    ("A", Mode::Servo),
    ("W", Mode::Mission),
];

/// `$OSI`: the answer to a navigation poll (the first 15 fields; later ones differ between
/// versions and are ignored).
#[derive(Debug, Clone, PartialEq)]
pub struct Osi {
    /// Fin and motor state (free text).
    pub fin_motor: String,
    /// Mode.
    pub mode: Mode,
    /// Next waypoint number.
    pub next_waypoint: u32,
    /// Latitude, decimal degrees.
    pub lat_deg: f64,
    /// Longitude, decimal degrees.
    pub lon_deg: f64,
    /// Speed, knots.
    pub speed_kn: f64,
    /// Distance to the next waypoint (as the vehicle reports it).
    pub distance_next: f64,
    /// Error field (free text).
    pub error: String,
    /// Altimeter, feet.
    pub altitude_ft: f64,
    /// Park time (free text).
    pub park_time: String,
    /// Magnetic declination, deg.
    pub declination_deg: f64,
    /// Mission name (free text).
    pub mission: String,
    /// Remaining time (free text).
    pub remaining: String,
    /// True heading, deg.
    pub heading_deg: f64,
    /// Depth, feet.
    pub depth_ft: f64,
}

/// An Iver remote-helm sentence.
#[derive(Debug, Clone, PartialEq)]
pub enum Sentence {
    /// `$OSD,G,C,S,P,,,,`: the navigation poll.
    Osd,
    /// `$OSI`: the vehicle's answer.
    Osi(Osi),
    /// `$OMS`: a command.
    Oms(Oms),
    /// `$OMSTOP,0`: stop.
    Omstop,
}

const OSD_FIELDS: [&str; 8] = ["G", "C", "S", "P", "", "", "", ""];
const FEET: Range = Range::new(-400.0, 40_000.0, "[-400, 40000] ft");
const PITCH: Range = Range::new(0.0, 90.0, "[0, 90] deg");
const LAT: Range = Range::new(-90.0, 90.0, "[-90, 90] deg");
const LON: Range = Range::new(-180.0, 180.0, "[-180, 180] deg");

impl Sentence {
    /// Reads one line (framing, checksum, fields and their ranges).
    pub fn parse(line: &str) -> Result<Self, SentenceError> {
        let f = Fields::parse(line)?;
        Ok(match f.id {
            "OSD" => {
                f.expect_len("OSD", 8)?;
                for (k, want) in OSD_FIELDS.iter().enumerate() {
                    if f.text(k + 1) != *want {
                        return Err(SentenceError::BadField {
                            id: "OSD",
                            index: k + 1,
                            name: "poll",
                            text: f.text(k + 1).to_string(),
                            what: "the poll G,C,S,P,,,,",
                        });
                    }
                }
                Sentence::Osd
            }
            "OSI" => {
                const ID: &str = "OSI";
                f.expect_at_least(ID, 15)?;
                let mode = MODES[f.one_of(ID, 2, "mode", &MODES.map(|m| m.0))?].1;
                Sentence::Osi(Osi {
                    fin_motor: f.text(1).to_string(),
                    mode,
                    next_waypoint: f.int(ID, 3, "next waypoint", 1_000_000)?,
                    lat_deg: f.f64(ID, 4, "latitude", LAT)?,
                    lon_deg: f.f64(ID, 5, "longitude", LON)?,
                    speed_kn: f.f64(ID, 6, "speed", SPEED)?,
                    distance_next: f.f64(
                        ID,
                        7,
                        "distance to next",
                        Range::new(0.0, 1e9, "[0, 1e9]"),
                    )?,
                    error: f.text(8).to_string(),
                    altitude_ft: f.f64(ID, 9, "altimeter", FEET)?,
                    park_time: f.text(10).to_string(),
                    declination_deg: f.f64(
                        ID,
                        11,
                        "magnetic declination",
                        Range::new(-180.0, 180.0, "[-180, 180] deg"),
                    )?,
                    mission: f.text(12).to_string(),
                    remaining: f.text(13).to_string(),
                    heading_deg: f.f64(ID, 14, "true heading", HEADING)?,
                    depth_ft: f.f64(ID, 15, "depth", FEET)?,
                })
            }
            "OMS" => {
                const ID: &str = "OMS";
                f.expect_len(ID, 5)?;
                Sentence::Oms(Oms {
                    heading_deg: f.f64(ID, 1, "heading", HEADING)?,
                    depth: f.f64(ID, 2, "depth", Range::new(0.0, DEPTH_MAX_FT, "[0, 40000]"))?,
                    max_pitch_deg: f.f64(ID, 3, "max pitch", PITCH)?,
                    speed_kn: f.f64(ID, 4, "speed", Range::new(0.0, 50.0, "[0, 50] kn"))?,
                    timeout_s: f.int(ID, 5, "timeout", 3600)?,
                })
            }
            "OMSTOP" => {
                f.expect_len("OMSTOP", 1)?;
                f.one_of("OMSTOP", 1, "argument", &["0"])?;
                Sentence::Omstop
            }
            other => return Err(SentenceError::Unknown(other.to_string())),
        })
    }

    /// The line (with checksum and `\r\n`).
    pub fn encode(&self) -> String {
        let body = match self {
            Sentence::Osd => "OSD,G,C,S,P,,,,".to_string(),
            Sentence::Oms(o) => format!(
                "OMS,{:.1},{:.1},{:.1},{:.1},{}",
                o.heading_deg, o.depth, o.max_pitch_deg, o.speed_kn, o.timeout_s
            ),
            Sentence::Omstop => "OMSTOP,0".to_string(),
            Sentence::Osi(o) => format!(
                "OSI,{},{},{},{:.7},{:.7},{:.2},{:.1},{},{:.1},{},{:.1},{},{},{:.1},{:.1}",
                clean_text(&o.fin_motor),
                MODES.iter().find(|m| m.1 == o.mode).map_or("N", |m| m.0),
                o.next_waypoint,
                o.lat_deg,
                o.lon_deg,
                o.speed_kn,
                o.distance_next,
                clean_text(&o.error),
                o.altitude_ft,
                clean_text(&o.park_time),
                o.declination_deg,
                clean_text(&o.mission),
                clean_text(&o.remaining),
                o.heading_deg,
                o.depth_ft
            ),
        };
        frame(&body)
    }
}

const DEPTH_MAX_FT: f64 = 40_000.0;
