//! The Bluefin "standard payload interface" sentences (text lines over TCP).
//!
//! From the front seat (vehicle) to the payload: `$BFNVG` (navigation: position in degrees and
//! minutes, altitude, depth, attitude), `$BFNVR` (velocities, completing a navigation record),
//! `$BFACK` (the answer to a command) and `$BFCTL` (whether the vehicle accepts payload
//! commands). From the payload: `$BPRMB` (the command: heading, depth or altitude, speed),
//! `$BPLOG` (subscribe to a sentence), `$BPSTS` (the payload's status, every second) and
//! `$BPABT` (abort). Numbers are written with the decimals the interface uses (one for angles,
//! depths and speeds, two for velocities).

use crate::protocol::sentence::{
    ANGLE, DEPTH, Fields, HEADING, RATE, Range, SPEED, SentenceError, UtcTime, clean_text, frame,
    write_deg_min,
};

/// `$BFNVG`: the start of a navigation record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nvg {
    /// Time of the record.
    pub time: UtcTime,
    /// Latitude, deg (north positive).
    pub lat_deg: f64,
    /// Longitude, deg (east positive).
    pub lon_deg: f64,
    /// Position quality (1 = GPS).
    pub quality: u32,
    /// Height above the seabed, m.
    pub altitude_m: f64,
    /// Depth, m.
    pub depth_m: f64,
    /// Compass heading, deg.
    pub heading_deg: f64,
    /// Roll, deg.
    pub roll_deg: f64,
    /// Pitch, deg.
    pub pitch_deg: f64,
    /// When the front seat computed it.
    pub computed: UtcTime,
}

/// `$BFNVR`: the velocities completing a navigation record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nvr {
    /// Time of the record.
    pub time: UtcTime,
    /// Eastward velocity, m/s.
    pub east_mps: f64,
    /// Northward velocity, m/s.
    pub north_mps: f64,
    /// Downward velocity, m/s.
    pub down_mps: f64,
    /// Pitch rate, deg/s.
    pub pitch_rate_dps: f64,
    /// Roll rate, deg/s.
    pub roll_rate_dps: f64,
    /// Yaw rate, deg/s.
    pub yaw_rate_dps: f64,
}

/// The vertical field of `$BPRMB`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VerticalMode {
    /// Hold a depth (code 0).
    Depth,
    /// Hold an altitude above the seabed (code 1).
    Altitude,
    /// Hold a pitch (code 2).
    Pitch,
}

/// The speed field of `$BPRMB`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpeedMode {
    /// Propeller rpm (code 0).
    Rpm,
    /// Metres per second (code 1).
    Mps,
}

/// The horizontal field of `$BPRMB`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HorizontalMode {
    /// A compass heading (code 0).
    Heading,
    /// A rudder angle (code 1).
    Rudder,
}

/// `$BPRMB`: a command to the vehicle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rmb {
    /// When it was sent (acknowledgements quote it).
    pub time: UtcTime,
    /// Heading, deg (or rudder angle).
    pub heading_deg: f64,
    /// Depth, altitude (m) or pitch (deg), as `vertical_mode` says.
    pub vertical: f64,
    /// What `vertical` is.
    pub vertical_mode: VerticalMode,
    /// Speed, m/s (or rpm).
    pub speed: f64,
    /// What `speed` is.
    pub speed_mode: SpeedMode,
    /// What `heading_deg` is.
    pub horizontal_mode: HorizontalMode,
}

impl Rmb {
    /// The interface's stop: rudder 0, pitch 0, rpm 0.
    pub fn stop(time: UtcTime) -> Self {
        Rmb {
            time,
            heading_deg: 0.0,
            vertical: 0.0,
            vertical_mode: VerticalMode::Pitch,
            speed: 0.0,
            speed_mode: SpeedMode::Rpm,
            horizontal_mode: HorizontalMode::Rudder,
        }
    }
}

/// What the vehicle says of a command in `$BFACK`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AckStatus {
    /// Code 0: the command was invalid.
    Invalid,
    /// Code 1: it failed.
    Failed,
    /// Code 2: accepted.
    Ok,
    /// Code 3: pending.
    Pending,
}

/// `$BFACK`: the vehicle's answer to a command.
#[derive(Debug, Clone, PartialEq)]
pub struct Ack {
    /// When the vehicle answered.
    pub time: UtcTime,
    /// The sentence acknowledged (`RMB`).
    pub acked: String,
    /// The time field of the acknowledged command.
    pub command_time: UtcTime,
    /// The vehicle's behaviour id (free text).
    pub behaviour: String,
    /// The verdict.
    pub status: AckStatus,
    /// Reserved field (free text).
    pub reserved: String,
    /// Description (free text).
    pub description: String,
}

/// A Bluefin sentence.
#[derive(Debug, Clone, PartialEq)]
pub enum Sentence {
    /// `$BFNVG`.
    Nvg(Nvg),
    /// `$BFNVR`.
    Nvr(Nvr),
    /// `$BFACK`.
    Ack(Ack),
    /// `$BFCTL,time,1|0`: whether the vehicle accepts payload commands.
    Ctl {
        /// Time.
        time: UtcTime,
        /// Accepting commands.
        accepting: bool,
    },
    /// `$BPRMB`.
    Rmb(Rmb),
    /// `$BPLOG,ID,ON|OFF`: (un)subscribe to a front-seat sentence.
    Log {
        /// The three-letter sentence id (`NVG`, `ACK`, ...).
        id: String,
        /// Subscribe (`ON`) or not.
        on: bool,
    },
    /// `$BPSTS,time,1|0,text`: the payload's status.
    Sts {
        /// Time.
        time: UtcTime,
        /// Whether the payload is well.
        ok: bool,
        /// Free text.
        text: String,
    },
    /// `$BPABT,time,text`: the payload aborts the mission.
    Abt {
        /// Time.
        time: UtcTime,
        /// Why (free text).
        text: String,
    },
}

const VEL: Range = SPEED;

fn flag(
    f: &Fields<'_>,
    id: &'static str,
    k: usize,
    name: &'static str,
) -> Result<bool, SentenceError> {
    Ok(f.one_of(id, k, name, &["0", "1"])? == 1)
}

fn bit(b: bool) -> u8 {
    u8::from(b)
}

/// The fields of a `$BFACK`.
fn read_ack(f: &Fields<'_>) -> Result<Ack, SentenceError> {
    const ID: &str = "BFACK";
    f.expect_len(ID, 7)?;
    let status = match f.int(ID, 5, "status", 3)? {
        0 => AckStatus::Invalid,
        1 => AckStatus::Failed,
        2 => AckStatus::Ok,
        _ => AckStatus::Pending,
    };
    Ok(Ack {
        time: f.time(ID, 1, "time")?,
        acked: f.text(2).to_string(),
        command_time: f.time(ID, 3, "command time")?,
        behaviour: f.text(4).to_string(),
        status,
        reserved: f.text(6).to_string(),
        description: f.text(7).to_string(),
    })
}

/// The fields of a `$BPRMB` (the ranges of its set-points depend on its modes).
fn read_rmb(f: &Fields<'_>) -> Result<Rmb, SentenceError> {
    const ID: &str = "BPRMB";
    f.expect_len(ID, 7)?;
    let vertical_mode = match f.int(ID, 4, "vertical mode", 2)? {
        0 => VerticalMode::Depth,
        1 => VerticalMode::Altitude,
        _ => VerticalMode::Pitch,
    };
    let speed_mode = match f.int(ID, 6, "speed mode", 1)? {
        0 => SpeedMode::Rpm,
        _ => SpeedMode::Mps,
    };
    let horizontal_mode = match f.int(ID, 7, "horizontal mode", 1)? {
        0 => HorizontalMode::Heading,
        _ => HorizontalMode::Rudder,
    };
    let vertical_range = match vertical_mode {
        VerticalMode::Pitch => ANGLE,
        _ => DEPTH,
    };
    let speed_range = match speed_mode {
        SpeedMode::Mps => SPEED,
        SpeedMode::Rpm => Range::new(-10_000.0, 10_000.0, "[-10000, 10000] rpm"),
    };
    Ok(Rmb {
        time: f.time(ID, 1, "time")?,
        heading_deg: f.f64(ID, 2, "heading", ANGLE)?,
        vertical: f.f64(ID, 3, "depth, altitude or pitch", vertical_range)?,
        vertical_mode,
        speed: f.f64(ID, 5, "speed", speed_range)?,
        speed_mode,
        horizontal_mode,
    })
}

impl Sentence {
    /// Reads one line (framing, checksum, fields and their ranges).
    pub fn parse(line: &str) -> Result<Self, SentenceError> {
        let f = Fields::parse(line)?;
        Ok(match f.id {
            "BFNVG" => {
                const ID: &str = "BFNVG";
                f.expect_len(ID, 12)?;
                Sentence::Nvg(Nvg {
                    time: f.time(ID, 1, "time")?,
                    lat_deg: f.deg_min(ID, 2, "latitude", false)?,
                    lon_deg: f.deg_min(ID, 4, "longitude", true)?,
                    quality: f.int(ID, 6, "position quality", 9)?,
                    altitude_m: f.f64(ID, 7, "altitude", DEPTH)?,
                    depth_m: f.f64(ID, 8, "depth", DEPTH)?,
                    heading_deg: f.f64(ID, 9, "heading", HEADING)?,
                    roll_deg: f.f64(ID, 10, "roll", ANGLE)?,
                    pitch_deg: f.f64(ID, 11, "pitch", ANGLE)?,
                    computed: f.time(ID, 12, "computed time")?,
                })
            }
            "BFNVR" => {
                const ID: &str = "BFNVR";
                f.expect_len(ID, 7)?;
                Sentence::Nvr(Nvr {
                    time: f.time(ID, 1, "time")?,
                    east_mps: f.f64(ID, 2, "east velocity", VEL)?,
                    north_mps: f.f64(ID, 3, "north velocity", VEL)?,
                    down_mps: f.f64(ID, 4, "down velocity", VEL)?,
                    pitch_rate_dps: f.f64(ID, 5, "pitch rate", RATE)?,
                    roll_rate_dps: f.f64(ID, 6, "roll rate", RATE)?,
                    yaw_rate_dps: f.f64(ID, 7, "yaw rate", RATE)?,
                })
            }
            "BFACK" => Sentence::Ack(read_ack(&f)?),
            "BFCTL" => {
                const ID: &str = "BFCTL";
                f.expect_len(ID, 2)?;
                Sentence::Ctl {
                    time: f.time(ID, 1, "time")?,
                    accepting: flag(&f, ID, 2, "accepting commands")?,
                }
            }
            "BPRMB" => Sentence::Rmb(read_rmb(&f)?),
            "BPLOG" => {
                const ID: &str = "BPLOG";
                f.expect_len(ID, 2)?;
                let id = f.text(1);
                if id.len() != 3 || !id.bytes().all(|b| b.is_ascii_uppercase()) {
                    return Err(SentenceError::BadField {
                        id: ID,
                        index: 1,
                        name: "sentence",
                        text: id.to_string(),
                        what: "a three-letter sentence id",
                    });
                }
                Sentence::Log {
                    id: id.to_string(),
                    on: f.one_of(ID, 2, "switch", &["OFF", "ON"])? == 1,
                }
            }
            "BPSTS" => {
                const ID: &str = "BPSTS";
                f.expect_len(ID, 3)?;
                Sentence::Sts {
                    time: f.time(ID, 1, "time")?,
                    ok: flag(&f, ID, 2, "status")?,
                    text: f.text(3).to_string(),
                }
            }
            "BPABT" => {
                const ID: &str = "BPABT";
                f.expect_len(ID, 2)?;
                Sentence::Abt {
                    time: f.time(ID, 1, "time")?,
                    text: f.text(2).to_string(),
                }
            }
            other => return Err(SentenceError::Unknown(other.to_string())),
        })
    }

    /// The line (with checksum and `\r\n`).
    pub fn encode(&self) -> String {
        let body = match self {
            Sentence::Nvg(n) => format!(
                "BFNVG,{},{},{},{},{:.1},{:.1},{:.1},{:.1},{:.1},{}",
                n.time,
                write_deg_min(n.lat_deg, false),
                write_deg_min(n.lon_deg, true),
                n.quality,
                n.altitude_m,
                n.depth_m,
                n.heading_deg,
                n.roll_deg,
                n.pitch_deg,
                n.computed
            ),
            Sentence::Nvr(v) => format!(
                "BFNVR,{},{:.2},{:.2},{:.2},{:.1},{:.1},{:.1}",
                v.time,
                v.east_mps,
                v.north_mps,
                v.down_mps,
                v.pitch_rate_dps,
                v.roll_rate_dps,
                v.yaw_rate_dps
            ),
            Sentence::Ack(a) => format!(
                "BFACK,{},{},{},{},{},{},{}",
                a.time,
                clean_text(&a.acked),
                a.command_time,
                clean_text(&a.behaviour),
                match a.status {
                    AckStatus::Invalid => 0,
                    AckStatus::Failed => 1,
                    AckStatus::Ok => 2,
                    AckStatus::Pending => 3,
                },
                clean_text(&a.reserved),
                clean_text(&a.description)
            ),
            Sentence::Ctl { time, accepting } => format!("BFCTL,{time},{}", bit(*accepting)),
            Sentence::Rmb(r) => format!(
                "BPRMB,{},{:.1},{:.1},{},{:.1},{},{}",
                r.time,
                r.heading_deg,
                r.vertical,
                match r.vertical_mode {
                    VerticalMode::Depth => 0,
                    VerticalMode::Altitude => 1,
                    VerticalMode::Pitch => 2,
                },
                r.speed,
                match r.speed_mode {
                    SpeedMode::Rpm => 0,
                    SpeedMode::Mps => 1,
                },
                match r.horizontal_mode {
                    HorizontalMode::Heading => 0,
                    HorizontalMode::Rudder => 1,
                }
            ),
            Sentence::Log { id, on } => {
                format!(
                    "BPLOG,{},{}",
                    clean_text(id),
                    if *on { "ON" } else { "OFF" }
                )
            }
            Sentence::Sts { time, ok, text } => {
                format!("BPSTS,{time},{},{}", bit(*ok), clean_text(text))
            }
            Sentence::Abt { time, text } => format!("BPABT,{time},{}", clean_text(text)),
        };
        frame(&body)
    }
}
