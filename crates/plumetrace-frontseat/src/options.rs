//! What a rehearsal is asked for: the protocol and where it is spoken, lock-step or real time,
//! the navigation period, the local frame's origin, how long to wait for the back seat, the
//! faults to inject. [`FrontSeatOptions::check`] names a bad option by its `plumetrace frontseat`
//! flag.

use crate::FrontSeatError;
use plumetrace_onboard::geo::{LocalFrame, Origin};

/// The protocol a front seat speaks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Protocol {
    /// Bluefin standard payload interface on a TCP port.
    Bluefin,
    /// Iver remote helm on a pseudo-terminal.
    Iver,
}

/// Faults to inject.
#[derive(Debug, Clone, PartialEq)]
pub struct Faults {
    /// Drop each outgoing line with this probability.
    pub drop: f64,
    /// Send a garbage line before a navigation record with this probability.
    pub garbage: f64,
    /// Wait this long (wall time, s) before each navigation record.
    pub delay_s: f64,
    /// No navigation from this mission time on, s ...
    pub silent_at: Option<f64>,
    /// ... for this long, s.
    pub silent_for: f64,
    /// Restart the front seat at this mission time, s (Bluefin: the connection and the listening
    /// socket closed; Iver: the serial line silent, what arrives lost, then a line of boot
    /// text) ...
    pub restart_at: Option<f64>,
    /// ... for this long (wall time), s.
    pub restart_for: f64,
    /// Seed of the fault draws.
    pub seed: u64,
}

impl Default for Faults {
    /// No faults.
    fn default() -> Self {
        Faults {
            drop: 0.0,
            garbage: 0.0,
            delay_s: 0.0,
            silent_at: None,
            silent_for: 30.0,
            restart_at: None,
            restart_for: 2.0,
            seed: 1,
        }
    }
}

/// Everything a rehearsal is asked for (the defaults are `plumetrace frontseat`'s).
#[derive(Debug, Clone, PartialEq)]
pub struct FrontSeatOptions {
    /// The protocol.
    pub protocol: Protocol,
    /// Bluefin: where to listen (`host:port`; port 0 picks a free one).
    pub listen: String,
    /// Iver: the remote-helm major version the simulated vehicle has (depth in feet below 5).
    pub remote_helm_major: u32,
    /// Wait for the answer to each navigation record before stepping on (deterministic).
    pub lock_step: bool,
    /// Navigation record period, s of mission time.
    pub nav_period_s: f64,
    /// The local frame's origin.
    pub origin: Origin,
    /// How long to wait for the back seat (to connect, or to answer in lock-step), s of wall
    /// time; a back seat that does not answer in time leaves the vehicle on its last command.
    pub wait_s: f64,
    /// Faults to inject.
    pub faults: Faults,
    /// End the mission at this time instead of the scenario's limit, s.
    pub time_limit_s: Option<f64>,
    /// Send the vehicle's current readings (`$VDCUR`); without them the onboard file has no
    /// `[flow]` table and the planner keeps the prior flow.
    pub flow: bool,
}

impl Default for FrontSeatOptions {
    fn default() -> Self {
        FrontSeatOptions {
            protocol: Protocol::Bluefin,
            listen: "127.0.0.1:29500".into(),
            remote_helm_major: 5,
            lock_step: false,
            nav_period_s: 0.1,
            origin: Origin {
                lat_deg: 36.18,
                lon_deg: -75.75,
            },
            wait_s: 30.0,
            faults: Faults::default(),
            time_limit_s: None,
            flow: true,
        }
    }
}

fn bad(option: &'static str, message: String) -> FrontSeatError {
    FrontSeatError::Option { option, message }
}

impl FrontSeatOptions {
    /// Checks every option that needs no scenario (the time limit is checked against the
    /// scenario's by [`crate::Rehearsal::prepare`]).
    pub fn check(&self) -> Result<(), FrontSeatError> {
        let p = self.nav_period_s;
        if !(p.is_finite() && p > 0.0 && p <= 60.0) {
            return Err(bad("--nav-period-s", format!("{p} is outside (0, 60]")));
        }
        let f = &self.faults;
        for (name, p) in [("--drop", f.drop), ("--garbage", f.garbage)] {
            if !(0.0..=1.0).contains(&p) {
                return Err(bad(name, format!("{p} is not a probability in [0, 1]")));
            }
        }
        for (name, v) in [
            ("--delay-s", f.delay_s),
            ("--wait-s", self.wait_s),
            ("--silent-for", f.silent_for),
            ("--restart-for", f.restart_for),
        ] {
            if !(v.is_finite() && (0.0..=3600.0).contains(&v)) {
                return Err(bad(name, format!("{v} is outside [0, 3600]")));
            }
        }
        if self.protocol == Protocol::Iver && self.lock_step && f.silent_at.is_some() {
            return Err(bad(
                "--silent-at",
                "Iver sentences carry no time, so in lock-step a back seat cannot see navigation missing for a span of mission time; use --restart-at (the serial line silent for a span of wall time)".into(),
            ));
        }
        LocalFrame::new(self.origin).map_err(|e| bad("--origin", e.to_string()))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_pass_and_each_bad_option_is_named_by_its_flag() {
        assert!(FrontSeatOptions::default().check().is_ok());
        let cases: Vec<(&str, FrontSeatOptions)> = vec![
            (
                "--nav-period-s",
                FrontSeatOptions {
                    nav_period_s: 0.0,
                    ..Default::default()
                },
            ),
            (
                "--drop",
                FrontSeatOptions {
                    faults: Faults {
                        drop: 1.5,
                        ..Default::default()
                    },
                    ..Default::default()
                },
            ),
            (
                "--garbage",
                FrontSeatOptions {
                    faults: Faults {
                        garbage: f64::NAN,
                        ..Default::default()
                    },
                    ..Default::default()
                },
            ),
            (
                "--wait-s",
                FrontSeatOptions {
                    wait_s: 4000.0,
                    ..Default::default()
                },
            ),
            (
                "--restart-for",
                FrontSeatOptions {
                    faults: Faults {
                        restart_for: -1.0,
                        ..Default::default()
                    },
                    ..Default::default()
                },
            ),
            (
                "--silent-at",
                FrontSeatOptions {
                    protocol: Protocol::Iver,
                    lock_step: true,
                    faults: Faults {
                        silent_at: Some(300.0),
                        ..Default::default()
                    },
                    ..Default::default()
                },
            ),
            (
                "--origin",
                FrontSeatOptions {
                    origin: Origin {
                        lat_deg: 95.0,
                        lon_deg: 0.0,
                    },
                    ..Default::default()
                },
            ),
        ];
        for (flag, options) in cases {
            let e = options.check().err().map(|e| e.to_string());
            assert!(
                e.as_deref()
                    .is_some_and(|e| e.starts_with(&format!("{flag}: "))),
                "{flag}: {e:?}"
            );
        }
        let origin = FrontSeatOptions {
            origin: Origin {
                lat_deg: 95.0,
                lon_deg: 0.0,
            },
            ..Default::default()
        };
        assert_eq!(
            origin.check().err().map(|e| e.to_string()).as_deref(),
            Some("--origin: origin latitude 95 is not in [-89, 89] deg")
        );
    }
}
