//! A MOOS `.alog` writer, so MOOS users can open plumetrace missions and onboard runs in their
//! own tools (`alogview`, `alogscan`, `aloggrep`, `alogclip`, ...).
//!
//! Layout, as pLogger writes it: header lines starting with `%%` (`LOG FILE`, `FILE OPENED ON`
//! with the start as a UTC date, `LOGSTART` with the start in Unix seconds to the microsecond),
//! then one line per posting, `TIME VARIABLE SOURCE VALUE`, columns padded with spaces (MOOS tools
//! split on white space), `TIME` in seconds since `LOGSTART` with five decimals, numbers written
//! with every digit they need to read back exactly (pLogger rounds them to five decimals). The
//! source is the process that posts the variable in a MOOS community: the vehicle's interface for
//! what it measures (`NAV_*`, `CPT_READING`; `iVehicle` unless the writer is told its name, as the
//! MOOS link learns it from the postings), the planner's process for the rest.
//!
//! Variables: `NAV_X`, `NAV_Y` (m, east and north), `NAV_HEADING` (deg), `NAV_SPEED` (m/s),
//! `NAV_DEPTH`, `NAV_ALTITUDE` (m), `DESIRED_HEADING`, `DESIRED_SPEED`, `DESIRED_DEPTH` (for an
//! altitude hold: the depth that leaves that altitude over the water depth measured, as the MOOS
//! and Iver links send it) and `DESIRED_ALTITUDE` (an altitude hold, as the Bluefin link sends
//! it); [`AltitudeHold`] says which of the two an altitude hold is logged as (a vehicle's log
//! has the one its link sends). Then the plume-tracing ones: `CPT_BEHAVIOUR` (when it changes), `CPT_READING` (every
//! chemical sample, at its time), `CPT_DETECTION` and `CPT_DECLARATION` (`x=..,y=..[,rule=..]`),
//! `CPT_STATUS` (when the plan finishes or aborts). Values never contain spaces.

use plumetrace_core::{
    Decision, PlanStatus, PlannerEvent, SensorSnapshot, VerticalCommand, variant_name, wrap_deg_360,
};
use std::io::Write;

/// Every variable the writer posts.
pub const VARIABLES: &[&str] = &[
    "NAV_X",
    "NAV_Y",
    "NAV_HEADING",
    "NAV_SPEED",
    "NAV_DEPTH",
    "NAV_ALTITUDE",
    "DESIRED_HEADING",
    "DESIRED_SPEED",
    "DESIRED_DEPTH",
    "DESIRED_ALTITUDE",
    "CPT_BEHAVIOUR",
    "CPT_READING",
    "CPT_DETECTION",
    "CPT_DECLARATION",
    "CPT_STATUS",
];

/// How an altitude hold is logged: as the link that flew it sent it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AltitudeHold {
    /// Both `DESIRED_DEPTH` (the depth that leaves the altitude) and `DESIRED_ALTITUDE`: a
    /// simulated mission, flown by no link.
    #[default]
    Both,
    /// `DESIRED_DEPTH` only (the MOOS and Iver links).
    AsDepth,
    /// `DESIRED_ALTITUDE` only (the Bluefin link).
    AsAltitude,
}

/// The name of the process posting the vehicle's measurements, shared with whatever learns it
/// while the log is written (empty: not known).
pub type SharedName = std::sync::Arc<std::sync::Mutex<String>>;

/// Writes one vehicle's postings.
pub struct AlogWriter<W: Write> {
    out: W,
    source: String,
    sensor_source: String,
    learned_source: Option<SharedName>,
    altitude_hold: AltitudeHold,
    last_time: f64,
}

fn clean(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_ascii_graphic() { c } else { '_' })
        .collect()
}

/// The start of a log when its caller gives none: `SOURCE_DATE_EPOCH` when set (for
/// reproducible files), else the wall clock.
fn start_now() -> f64 {
    if let Some(s) = std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v > 0.0)
    {
        return s;
    }
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// The start as pLogger writes `LOGSTART`: Unix seconds to the microsecond, without trailing
/// zeros.
fn logstart(unix_s: f64) -> String {
    let s = format!("{unix_s:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// `unix_s` as a UTC date, `Www Mmm dd hh:mm:ss yyyy` (as pLogger writes its opening time).
pub fn utc_date(unix_s: f64) -> String {
    let secs = unix_s.floor() as i64;
    let days = secs.div_euclid(86_400);
    let tod = secs.rem_euclid(86_400);
    // Civil date from days since 1970-01-01 (proleptic Gregorian).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    const WEEKDAYS: [&str; 7] = ["Thu", "Fri", "Sat", "Sun", "Mon", "Tue", "Wed"];
    const MONTHS: [&str; 12] = [
        "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
    ];
    format!(
        "{} {} {:02} {:02}:{:02}:{:02} {year}",
        WEEKDAYS[days.rem_euclid(7) as usize],
        MONTHS[(month - 1).clamp(0, 11) as usize],
        day,
        tod / 3600,
        tod / 60 % 60,
        tod % 60
    )
}

impl<W: Write> AlogWriter<W> {
    /// Starts a log: the header (`name` is the log's name, `logstart_unix_s` the start of
    /// mission time in Unix seconds; one that is not positive means "now": the wall clock, or
    /// `SOURCE_DATE_EPOCH` when set) and the source column's process name for the planner's
    /// postings (the vehicle's are `iVehicle` until [`AlogWriter::sensor_source`] names them).
    pub fn new(
        mut out: W,
        name: &str,
        logstart_unix_s: f64,
        source: &str,
    ) -> std::io::Result<Self> {
        let start = if logstart_unix_s.is_finite() && logstart_unix_s > 0.0 {
            logstart_unix_s
        } else {
            start_now()
        };
        let bar = "%".repeat(80);
        writeln!(out, "{bar}")?;
        writeln!(out, "%% LOG FILE:       {}", clean(name))?;
        writeln!(out, "%% FILE OPENED ON  {}", utc_date(start))?;
        writeln!(out, "%% LOGSTART        {:>20}", logstart(start))?;
        writeln!(out, "{bar}")?;
        Ok(AlogWriter {
            out,
            source: clean(source),
            sensor_source: "iVehicle".into(),
            learned_source: None,
            altitude_hold: AltitudeHold::Both,
            last_time: f64::NEG_INFINITY,
        })
    }

    /// The same writer with `source` in the source column of the vehicle's postings
    /// (`NAV_*`, `CPT_READING`).
    pub fn sensor_source(mut self, source: &str) -> Self {
        self.sensor_source = clean(source);
        self
    }

    /// The same writer taking the source column of the vehicle's postings from `name` whenever
    /// it is not empty (the MOOS link fills it with the process that posts `NAV_X`).
    pub fn learned_sensor_source(mut self, name: SharedName) -> Self {
        self.learned_source = Some(name);
        self
    }

    /// The same writer logging an altitude hold as `hold` says.
    pub fn altitude_hold(mut self, hold: AltitudeHold) -> Self {
        self.altitude_hold = hold;
        self
    }

    fn post_from(&mut self, t: f64, var: &str, sensor: bool, value: &str) -> std::io::Result<()> {
        // Lines stay in time order even if a sample's time ran ahead of its snapshot.
        let t = if t.is_finite() {
            t.max(self.last_time)
        } else {
            self.last_time.max(0.0)
        };
        self.last_time = t;
        let source = if sensor {
            &self.sensor_source
        } else {
            &self.source
        };
        writeln!(
            self.out,
            "{:<15} {var:<20} {source:<15} {}",
            format!("{t:.5}"),
            clean(value)
        )
    }

    fn post(&mut self, t: f64, var: &str, value: &str) -> std::io::Result<()> {
        self.post_from(t, var, false, value)
    }

    /// A number with every digit it needs to read back exactly.
    fn num_from(&mut self, t: f64, var: &str, sensor: bool, v: f64) -> std::io::Result<()> {
        if v.is_finite() {
            self.post_from(t, var, sensor, &format!("{v}"))
        } else {
            Ok(())
        }
    }

    fn num(&mut self, t: f64, var: &str, v: f64) -> std::io::Result<()> {
        self.num_from(t, var, false, v)
    }

    fn sensed(&mut self, t: f64, var: &str, v: f64) -> std::io::Result<()> {
        self.num_from(t, var, true, v)
    }

    /// Posts what one snapshot and its decision say.
    pub fn decision(&mut self, s: &SensorSnapshot, d: &Decision) -> std::io::Result<()> {
        if let Some(name) = &self.learned_source {
            let name = name.lock().map(|n| clean(&n)).unwrap_or_default();
            if !name.is_empty() {
                self.sensor_source = name;
            }
        }
        for c in &s.chem {
            self.sensed(c.time_s, "CPT_READING", c.reading)?;
        }
        let t = s.time_s;
        if let Some(p) = s.nav.pos_m {
            self.sensed(t, "NAV_X", p.x)?;
            self.sensed(t, "NAV_Y", p.y)?;
        }
        self.sensed(t, "NAV_HEADING", wrap_deg_360(s.nav.heading.deg()))?;
        self.sensed(t, "NAV_SPEED", s.nav.speed_mps)?;
        if let Some(v) = s.nav.depth_m {
            self.sensed(t, "NAV_DEPTH", v)?;
        }
        if let Some(v) = s.nav.altitude_m {
            self.sensed(t, "NAV_ALTITUDE", v)?;
        }
        self.num(t, "DESIRED_HEADING", wrap_deg_360(d.command.heading.deg()))?;
        self.num(t, "DESIRED_SPEED", d.command.speed_mps)?;
        match d.command.vertical {
            VerticalCommand::Depth(v) => self.num(t, "DESIRED_DEPTH", v)?,
            VerticalCommand::Altitude(v) => {
                let hold = self.altitude_hold;
                // The depth that leaves this altitude over the water depth measured.
                if let (Some(depth), Some(alt), AltitudeHold::Both | AltitudeHold::AsDepth) =
                    (s.nav.depth_m, s.nav.altitude_m, hold)
                {
                    self.num(t, "DESIRED_DEPTH", (depth + alt - v).max(0.0))?;
                }
                if hold != AltitudeHold::AsDepth {
                    self.num(t, "DESIRED_ALTITUDE", v)?;
                }
            }
            VerticalCommand::Surface => self.num(t, "DESIRED_DEPTH", 0.0)?,
        }
        self.events(t, &d.events)?;
        if d.status != PlanStatus::Running {
            self.post(t, "CPT_STATUS", variant_name(&d.status).unwrap_or("?"))?;
        }
        Ok(())
    }

    /// Posts a planner's events at `t` (a decision's, or what it reported as its run ended):
    /// behaviours, detections and declarations.
    pub fn events(&mut self, t: f64, events: &[PlannerEvent]) -> std::io::Result<()> {
        for e in events {
            match e {
                PlannerEvent::Behaviour { behaviour } => {
                    self.post(t, "CPT_BEHAVIOUR", variant_name(behaviour).unwrap_or("?"))?;
                }
                PlannerEvent::Detection { pos_m } => {
                    self.post(
                        t,
                        "CPT_DETECTION",
                        &format!("x={:.2},y={:.2}", pos_m.x, pos_m.y),
                    )?;
                }
                PlannerEvent::Declared { pos_m, rule } => self.post(
                    t,
                    "CPT_DECLARATION",
                    &format!("x={:.2},y={:.2},rule={}", pos_m.x, pos_m.y, rule.name()),
                )?,
                _ => {}
            }
        }
        Ok(())
    }

    /// Flushes and returns the output.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::{
        BehaviourKind, ChemSample, Command, DeclarationKind, Heading, NavEstimate, Vec2, VehicleId,
    };

    #[test]
    fn an_alog_reads_back_line_by_line_with_the_documented_layout() {
        let snap = |t: f64| SensorSnapshot {
            time_s: t,
            vehicle: VehicleId(0),
            nav: NavEstimate {
                pos_m: Some(Vec2::new(10.0 + t, -5.0)),
                heading: Heading::from_deg(-90.0),
                speed_mps: 1.5,
                altitude_m: Some(2.0),
                depth_m: Some(6.0),
                last_fix_s: None,
            },
            chem: vec![ChemSample {
                time_s: t - 0.05,
                reading: 1.2345678901234e-4,
            }],
            flow: None,
            ranges: None,
            inbox: Vec::new(),
        };
        let mut d = Decision::new(
            Command {
                heading: Heading::from_deg(45.0),
                speed_mps: 2.0,
                vertical: VerticalCommand::Altitude(2.5),
            },
            PlanStatus::Running,
        );
        let mut w = AlogWriter::new(Vec::new(), "test.alog", 1.7e9, "pPlumetrace")
            .unwrap_or_else(|e| panic!("{e}"));
        d.events = vec![PlannerEvent::Behaviour {
            behaviour: BehaviourKind::TrackIn,
        }];
        assert!(w.decision(&snap(0.1), &d).is_ok());
        d.events = vec![PlannerEvent::Declared {
            pos_m: Vec2::new(100.0, 0.5),
            rule: DeclarationKind::new("along_flow"),
        }];
        d.status = PlanStatus::Finished;
        assert!(w.decision(&snap(0.2), &d).is_ok());
        let text = String::from_utf8(w.finish().unwrap_or_default()).unwrap_or_default();
        let mut header = 0;
        let mut last = f64::NEG_INFINITY;
        let mut seen = std::collections::BTreeMap::new();
        for line in text.lines() {
            if line.starts_with("%%") {
                assert_eq!(seen.len(), 0, "header lines come first");
                header += 1;
                continue;
            }
            let f: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(f.len(), 4, "{line}");
            let t: f64 = f[0].parse().unwrap_or(f64::NAN);
            assert!(t >= last, "time order: {line}");
            last = t;
            assert!(VARIABLES.contains(&f[1]), "{line}");
            let sensor = f[1].starts_with("NAV_") || f[1] == "CPT_READING";
            assert_eq!(
                f[2],
                if sensor { "iVehicle" } else { "pPlumetrace" },
                "{line}"
            );
            seen.insert(f[1].to_string(), f[3].to_string());
        }
        assert_eq!(header, 5);
        // As pLogger: Unix seconds in a column of 20, to the microsecond without trailing zeros.
        assert!(
            text.contains("%% LOGSTART                  1700000000\n"),
            "{text}"
        );
        // Times with five decimals in a column of 15, as pLogger's.
        assert!(
            text.contains("\n0.10000         NAV_X                iVehicle        10.1\n"),
            "{text}"
        );
        assert!(
            text.contains("%% FILE OPENED ON  Tue Nov 14 22:13:20 2023\n"),
            "{text}"
        );
        assert_eq!(seen["NAV_HEADING"], "270");
        assert_eq!(seen["NAV_X"], "10.2");
        // The altitude hold as the depth a MOOS or Iver vehicle is sent (6 + 2 - 2.5 m).
        assert_eq!(seen["DESIRED_ALTITUDE"], "2.5");
        assert_eq!(seen["DESIRED_DEPTH"], "5.5");
        assert_eq!(seen["CPT_BEHAVIOUR"], "track_in");
        assert_eq!(seen["CPT_READING"], "0.00012345678901234");
        assert_eq!(seen["CPT_DECLARATION"], "x=100.00,y=0.50,rule=along_flow");
        assert_eq!(seen["CPT_STATUS"], "finished");
    }

    fn flown(hold: AltitudeHold, learned: Option<&str>) -> String {
        let snap = SensorSnapshot {
            time_s: 3.25,
            vehicle: VehicleId(0),
            nav: NavEstimate {
                pos_m: Some(Vec2::new(1.0, 2.0)),
                heading: Heading::from_deg(10.0),
                speed_mps: 1.0,
                altitude_m: Some(4.0),
                depth_m: Some(16.0),
                last_fix_s: None,
            },
            chem: Vec::new(),
            flow: None,
            ranges: None,
            inbox: Vec::new(),
        };
        let d = Decision::new(
            Command {
                heading: Heading::from_deg(0.0),
                speed_mps: 1.0,
                vertical: VerticalCommand::Altitude(2.0),
            },
            PlanStatus::Running,
        );
        let mut w = AlogWriter::new(Vec::new(), "v.alog", 1_796_430_583.214_037, "pPlumetrace")
            .unwrap_or_else(|e| panic!("{e}"))
            .altitude_hold(hold);
        if let Some(name) = learned {
            let shared = SharedName::default();
            w = w.learned_sensor_source(shared.clone());
            assert!(w.decision(&snap, &d).is_ok());
            if let Ok(mut n) = shared.lock() {
                *n = name.to_string();
            }
        }
        assert!(w.decision(&snap, &d).is_ok());
        String::from_utf8(w.finish().unwrap_or_default()).unwrap_or_default()
    }

    #[test]
    fn a_vehicle_log_has_the_set_point_its_link_sent_and_its_start_to_the_microsecond() {
        let moos = flown(AltitudeHold::AsDepth, None);
        assert!(
            moos.contains("%% LOGSTART           1796430583.214037\n"),
            "{moos}"
        );
        assert!(
            moos.contains("3.25000         DESIRED_DEPTH        pPlumetrace     18\n"),
            "{moos}"
        );
        assert!(!moos.contains("DESIRED_ALTITUDE"), "{moos}");
        let bluefin = flown(AltitudeHold::AsAltitude, None);
        assert!(
            bluefin.contains("DESIRED_ALTITUDE     pPlumetrace     2\n"),
            "{bluefin}"
        );
        assert!(!bluefin.contains("DESIRED_DEPTH"), "{bluefin}");
        let both = flown(AltitudeHold::Both, None);
        assert!(both.contains("DESIRED_DEPTH ") && both.contains("DESIRED_ALTITUDE "));
    }

    #[test]
    fn the_vehicle_postings_take_the_source_the_link_learned() {
        let text = flown(AltitudeHold::AsDepth, Some("uSim Marine"));
        let sources: Vec<&str> = text
            .lines()
            .filter(|l| l.contains(" NAV_X "))
            .filter_map(|l| l.split_whitespace().nth(2))
            .collect();
        // Before a name is known, iVehicle; then the name (white space cannot be in a column).
        assert_eq!(sources, ["iVehicle", "uSim_Marine"], "{text}");
        assert!(text.contains("DESIRED_DEPTH        pPlumetrace"), "{text}");
    }

    #[test]
    fn a_log_without_a_start_starts_now_and_dates_are_utc() {
        let w = AlogWriter::new(Vec::new(), "x.alog", 0.0, "p").unwrap_or_else(|e| panic!("{e}"));
        let text = String::from_utf8(w.finish().unwrap_or_default()).unwrap_or_default();
        let start: f64 = text
            .lines()
            .find_map(|l| l.strip_prefix("%% LOGSTART"))
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or(0.0);
        assert!(start > 1.7e9, "{text}");
        assert_eq!(utc_date(0.0), "Thu Jan 01 00:00:00 1970");
        assert_eq!(utc_date(951_782_400.0), "Tue Feb 29 00:00:00 2000");
    }
}
