//! Messages between vehicles: one channel model per link kind, seeded.
//!
//! A message a planner sends at time `t` from true position `p` reaches each recipient (one
//! vehicle, or every other active vehicle for a broadcast) independently:
//! - beyond `max_range_m` of the sender's position at sending, it is lost (out of range);
//! - otherwise it is dropped with probability `loss_probability` (one draw per recipient);
//! - otherwise it arrives after `latency_s` plus, when `sound_speed_mps` is set, the distance
//!   over the sound speed (an acoustic modem's travel time).
//!
//! Messages are delivered in the communicate stage of the first step at or after their arrival,
//! in arrival order (ties in sending order), so a message sent with no delay reaches its recipient
//! at the next decision. The ideal channel (the default for both links) has no delay, no loss and
//! no range limit.

use plumetrace_core::{Link, Message, Vec2, VehicleId};
use plumetrace_env::error::{require_non_negative, require_positive};
use plumetrace_env::{EnvError, SimRng};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// One link's channel model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ChannelParams {
    /// Fixed delay (processing, turnaround), s.
    pub latency_s: f64,
    /// Propagation speed, m/s; `None`: no propagation delay.
    pub sound_speed_mps: Option<f64>,
    /// Probability that a message is lost on its way to one recipient.
    pub loss_probability: f64,
    /// Longest distance a message carries, m; `None`: any.
    pub max_range_m: Option<f64>,
}

impl ChannelParams {
    /// No delay, no loss, any range.
    pub const IDEAL: ChannelParams = ChannelParams {
        latency_s: 0.0,
        sound_speed_mps: None,
        loss_probability: 0.0,
        max_range_m: None,
    };

    /// Checks every parameter; `key` prefixes the names in errors.
    pub fn validate(&self, key: &str) -> Result<(), EnvError> {
        require_non_negative(&format!("{key}.latency_s"), self.latency_s)?;
        if let Some(c) = self.sound_speed_mps {
            require_positive(&format!("{key}.sound_speed_mps"), c)?;
        }
        if !(self.loss_probability.is_finite() && (0.0..=1.0).contains(&self.loss_probability)) {
            return Err(EnvError::invalid(
                format!("{key}.loss_probability"),
                format!("must be in [0, 1], got {}", self.loss_probability),
            ));
        }
        if let Some(r) = self.max_range_m {
            require_positive(&format!("{key}.max_range_m"), r)?;
        }
        Ok(())
    }
}

impl Default for ChannelParams {
    fn default() -> Self {
        ChannelParams::IDEAL
    }
}

/// The channel models of a world.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CommsParams {
    /// Acoustic modems.
    pub acoustic: ChannelParams,
    /// Radio between surface craft.
    pub radio: ChannelParams,
}

impl CommsParams {
    /// The model of one link.
    pub fn channel(&self, link: Link) -> &ChannelParams {
        match link {
            Link::Acoustic => &self.acoustic,
            Link::Radio => &self.radio,
        }
    }
}

/// Why a message did not arrive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LossReason {
    /// The recipient was beyond the link's range.
    OutOfRange,
    /// The channel dropped it.
    Dropped,
    /// The recipient was stopped (incident, finished or aborted) when it was sent or arrived.
    RecipientStopped,
    /// No vehicle has the recipient's index (the event is the sender's).
    NoSuchRecipient,
}

/// What became of one message for one recipient.
#[derive(Debug, Clone, PartialEq)]
pub enum Transmission {
    /// It will arrive at `arrival_s`.
    InFlight {
        /// Arrival time, s.
        arrival_s: f64,
    },
    /// It is lost.
    Lost(LossReason),
}

/// A message on its way.
#[derive(Debug, Clone, PartialEq)]
pub struct InFlight {
    /// Arrival time, s.
    pub arrival_s: f64,
    /// Sending order (ties in arrival time keep it).
    pub seq: u64,
    /// Recipient.
    pub to: VehicleId,
    /// The message.
    pub message: Message,
}

/// The messages on their way and the channel models' random stream.
#[derive(Debug, Clone)]
pub struct Comms {
    params: CommsParams,
    rng: SimRng,
    in_flight: Vec<InFlight>,
    seq: u64,
}

impl Comms {
    /// Channels with `params` drawing from `rng`.
    pub fn new(params: CommsParams, rng: SimRng) -> Self {
        Comms {
            params,
            rng,
            in_flight: Vec::new(),
            seq: 0,
        }
    }

    /// The channel models.
    pub fn params(&self) -> &CommsParams {
        &self.params
    }

    /// Sends `message` from `from_m` to the recipient `to` at `to_m` (true positions).
    pub fn transmit(
        &mut self,
        message: &Message,
        from_m: Vec2,
        to: VehicleId,
        to_m: Vec2,
    ) -> Transmission {
        let c = *self.params.channel(message.link);
        let distance = (to_m - from_m).norm();
        if c.max_range_m
            .is_some_and(|r| distance > r || !distance.is_finite())
        {
            return Transmission::Lost(LossReason::OutOfRange);
        }
        if c.loss_probability > 0.0 && self.rng.random::<f64>() < c.loss_probability {
            return Transmission::Lost(LossReason::Dropped);
        }
        let travel = c.sound_speed_mps.map_or(0.0, |s| distance / s);
        let arrival_s = message.sent_s + c.latency_s + travel;
        self.in_flight.push(InFlight {
            arrival_s,
            seq: self.seq,
            to,
            message: message.clone(),
        });
        self.seq += 1;
        Transmission::InFlight { arrival_s }
    }

    /// Takes the messages that have arrived by `t_s`, in arrival order.
    pub fn arrived(&mut self, t_s: f64) -> Vec<InFlight> {
        let (mut due, rest): (Vec<InFlight>, Vec<InFlight>) = std::mem::take(&mut self.in_flight)
            .into_iter()
            .partition(|m| m.arrival_s <= t_s + 1e-9);
        self.in_flight = rest;
        due.sort_by(|a, b| a.arrival_s.total_cmp(&b.arrival_s).then(a.seq.cmp(&b.seq)));
        due
    }

    /// Messages still on their way.
    pub fn in_flight(&self) -> usize {
        self.in_flight.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::{MessageBody, Recipient};
    use plumetrace_env::{StreamId, stream_rng};

    fn message(link: Link, sent_s: f64) -> Message {
        Message {
            from: VehicleId(0),
            to: Recipient::Broadcast,
            link,
            sent_s,
            body: MessageBody::Text { text: "hi".into() },
        }
    }

    #[test]
    fn acoustic_delay_is_latency_plus_travel_time_and_range_limits() {
        let params = CommsParams {
            acoustic: ChannelParams {
                latency_s: 0.5,
                sound_speed_mps: Some(1500.0),
                loss_probability: 0.0,
                max_range_m: Some(2000.0),
            },
            radio: ChannelParams::IDEAL,
        };
        let mut c = Comms::new(params, stream_rng(1, StreamId::Custom(9)));
        let m = message(Link::Acoustic, 10.0);
        let t = c.transmit(&m, Vec2::zeros(), VehicleId(1), Vec2::new(1500.0, 0.0));
        assert_eq!(t, Transmission::InFlight { arrival_s: 11.5 });
        assert_eq!(
            c.transmit(&m, Vec2::zeros(), VehicleId(2), Vec2::new(2000.1, 0.0)),
            Transmission::Lost(LossReason::OutOfRange)
        );
        let r = c.transmit(
            &message(Link::Radio, 10.0),
            Vec2::zeros(),
            VehicleId(1),
            Vec2::new(1e5, 0.0),
        );
        assert_eq!(r, Transmission::InFlight { arrival_s: 10.0 });
        assert_eq!(c.arrived(10.0).len(), 1, "the radio message only");
        assert!(c.arrived(11.4).is_empty());
        let due = c.arrived(11.5);
        assert_eq!(due.len(), 1);
        assert_eq!(due[0].to, VehicleId(1));
        assert_eq!(c.in_flight(), 0);
    }

    #[test]
    fn losses_follow_the_probability_and_the_seed() {
        let params = CommsParams {
            acoustic: ChannelParams {
                loss_probability: 0.2,
                ..ChannelParams::IDEAL
            },
            radio: ChannelParams::IDEAL,
        };
        let count = |seed| {
            let mut c = Comms::new(params, stream_rng(seed, StreamId::Custom(9)));
            (0..20_000)
                .filter(|_| {
                    matches!(
                        c.transmit(
                            &message(Link::Acoustic, 0.0),
                            Vec2::zeros(),
                            VehicleId(1),
                            Vec2::zeros()
                        ),
                        Transmission::Lost(LossReason::Dropped)
                    )
                })
                .count()
        };
        let lost = count(3);
        // 20,000 draws at p = 0.2: sd = 57; within 4 sd of 4,000.
        assert!((lost as f64 - 4000.0).abs() < 4.0 * 56.6, "{lost}");
        assert_eq!(lost, count(3), "same seed, same losses");
        assert_ne!(lost, count(4));
    }
}
