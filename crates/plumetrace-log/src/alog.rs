//! A MOOS `.alog` writer, so MOOS users can open plumetrace missions and onboard runs in their
//! own tools (`alogview`, `alogscan`, ...).
//!
//! Layout: header lines starting with `%%`, then one line per posting,
//! `TIME VARIABLE SOURCE VALUE`, separated by spaces, `TIME` in seconds since `LOGSTART`.
//! Variables: `NAV_X`, `NAV_Y` (m, east and north), `NAV_HEADING` (deg), `NAV_SPEED` (m/s),
//! `NAV_DEPTH`, `NAV_ALTITUDE` (m), `DESIRED_HEADING`, `DESIRED_SPEED`, `DESIRED_DEPTH` or
//! `DESIRED_ALTITUDE` (the vertical set-point the planner chose), and the plume-tracing ones:
//! `CPT_BEHAVIOUR` (when it changes), `CPT_READING` (every chemical sample, at its time),
//! `CPT_DETECTION` and `CPT_DECLARATION` (`x=..,y=..[,rule=..]`), `CPT_STATUS` (when the plan
//! finishes or aborts). Values never contain spaces.

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

/// Writes one vehicle's postings.
pub struct AlogWriter<W: Write> {
    out: W,
    source: String,
    last_time: f64,
}

fn clean(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_ascii_graphic() { c } else { '_' })
        .collect()
}

impl<W: Write> AlogWriter<W> {
    /// Starts a log: the header (`name` is the log's name, `logstart_unix_s` the start of
    /// mission time in Unix seconds) and the source column's process name.
    pub fn new(
        mut out: W,
        name: &str,
        logstart_unix_s: f64,
        source: &str,
    ) -> std::io::Result<Self> {
        let bar = "%".repeat(80);
        writeln!(out, "{bar}")?;
        writeln!(out, "%% LOG FILE:       {}", clean(name))?;
        writeln!(out, "%% FILE OPENED ON  plumetrace")?;
        writeln!(out, "%% LOGSTART               {logstart_unix_s:.2}")?;
        writeln!(out, "{bar}")?;
        Ok(AlogWriter {
            out,
            source: clean(source),
            last_time: f64::NEG_INFINITY,
        })
    }

    fn post(&mut self, t: f64, var: &str, value: &str) -> std::io::Result<()> {
        // Lines stay in time order even if a sample's time ran ahead of its snapshot.
        let t = if t.is_finite() {
            t.max(self.last_time)
        } else {
            self.last_time.max(0.0)
        };
        self.last_time = t;
        writeln!(self.out, "{t:.3} {var} {} {}", self.source, clean(value))
    }

    fn num(&mut self, t: f64, var: &str, v: f64) -> std::io::Result<()> {
        if v.is_finite() {
            self.post(t, var, &format!("{v:.3}"))
        } else {
            Ok(())
        }
    }

    /// Posts what one snapshot and its decision say.
    pub fn decision(&mut self, s: &SensorSnapshot, d: &Decision) -> std::io::Result<()> {
        for c in &s.chem {
            self.num(c.time_s, "CPT_READING", c.reading)?;
        }
        let t = s.time_s;
        if let Some(p) = s.nav.pos_m {
            self.num(t, "NAV_X", p.x)?;
            self.num(t, "NAV_Y", p.y)?;
        }
        self.num(t, "NAV_HEADING", wrap_deg_360(s.nav.heading.deg()))?;
        self.num(t, "NAV_SPEED", s.nav.speed_mps)?;
        if let Some(v) = s.nav.depth_m {
            self.num(t, "NAV_DEPTH", v)?;
        }
        if let Some(v) = s.nav.altitude_m {
            self.num(t, "NAV_ALTITUDE", v)?;
        }
        self.num(t, "DESIRED_HEADING", wrap_deg_360(d.command.heading.deg()))?;
        self.num(t, "DESIRED_SPEED", d.command.speed_mps)?;
        match d.command.vertical {
            VerticalCommand::Depth(v) => self.num(t, "DESIRED_DEPTH", v)?,
            VerticalCommand::Altitude(v) => self.num(t, "DESIRED_ALTITUDE", v)?,
            VerticalCommand::Surface => self.num(t, "DESIRED_DEPTH", 0.0)?,
        }
        for e in &d.events {
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
        if d.status != PlanStatus::Running {
            self.post(t, "CPT_STATUS", variant_name(&d.status).unwrap_or("?"))?;
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
                reading: 0.3,
            }],
            flow: None,
            ranges: None,
            inbox: Vec::new(),
        };
        let mut d = Decision::new(
            Command {
                heading: Heading::from_deg(45.0),
                speed_mps: 2.0,
                vertical: VerticalCommand::Altitude(2.0),
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
            let f: Vec<&str> = line.split(' ').collect();
            assert_eq!(f.len(), 4, "{line}");
            let t: f64 = f[0].parse().unwrap_or(f64::NAN);
            assert!(t >= last, "time order: {line}");
            last = t;
            assert!(VARIABLES.contains(&f[1]), "{line}");
            assert_eq!(f[2], "pPlumetrace");
            seen.insert(f[1].to_string(), f[3].to_string());
        }
        assert_eq!(header, 5);
        assert!(text.contains("%% LOGSTART"));
        assert_eq!(seen["NAV_HEADING"], "270.000");
        assert_eq!(seen["NAV_X"], "10.200");
        assert_eq!(seen["DESIRED_ALTITUDE"], "2.000");
        assert_eq!(seen["CPT_BEHAVIOUR"], "track_in");
        assert_eq!(seen["CPT_READING"], "0.300");
        assert_eq!(seen["CPT_DECLARATION"], "x=100.00,y=0.50,rule=along_flow");
        assert_eq!(seen["CPT_STATUS"], "finished");
    }
}
