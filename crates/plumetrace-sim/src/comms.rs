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
//!
//! A channel with `one_in_flight` (an acoustic modem) carries one packet per sender at a time:
//! a message sent while the sender's previous packet is still on its way to its farthest
//! recipient is lost (`modem_busy`). Each link kind draws its losses from its own random stream,
//! so radio traffic does not change which acoustic packets are lost.
//!
//! **Acoustic ranging.** A [`MessageBody::RangeRequest`] is heard by every vehicle in range;
//! its target answers with a [`MessageBody::RangeEcho`]. The world measures the range for the
//! requester, as its modem would from the round-trip time: the mean of the true slant distances
//! at the request's and the echo's sending (the two legs' travel times times the sound speed over
//! two; the target's known turnaround is taken off), plus the timing noise
//! `ranging.timing_noise_sd_s` times half the sound speed. The requester receives a
//! [`MessageBody::RangeReply`] with that range; the truth stays in the simulator. An echo
//! without a request on record is lost (`unsolicited`). The timing noise has its own stream.

use plumetrace_core::{Link, Message, MessageBody, Vec2, VehicleId};
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
    /// One packet per sender on the water at a time (an acoustic modem): what is sent while
    /// the previous packet travels is lost.
    #[serde(default)]
    pub one_in_flight: bool,
}

impl ChannelParams {
    /// No delay, no loss, any range.
    pub const IDEAL: ChannelParams = ChannelParams {
        latency_s: 0.0,
        sound_speed_mps: None,
        loss_probability: 0.0,
        max_range_m: None,
        one_in_flight: false,
    };

    /// Checks every parameter; errors name the field.
    pub fn validate(&self) -> Result<(), EnvError> {
        require_non_negative("latency_s", self.latency_s)?;
        if let Some(c) = self.sound_speed_mps {
            require_positive("sound_speed_mps", c)?;
        }
        if !(self.loss_probability.is_finite() && (0.0..=1.0).contains(&self.loss_probability)) {
            return Err(EnvError::invalid(
                "loss_probability",
                format!("must be in [0, 1], got {}", self.loss_probability),
            ));
        }
        if let Some(r) = self.max_range_m {
            require_positive("max_range_m", r)?;
        }
        Ok(())
    }
}

impl Default for ChannelParams {
    fn default() -> Self {
        ChannelParams::IDEAL
    }
}

/// How acoustic ranging measures a range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RangingParams {
    /// Standard deviation of the round-trip time measurement, s.
    pub timing_noise_sd_s: f64,
    /// Sound speed the modem assumes to turn time into range, m/s.
    pub sound_speed_mps: f64,
}

impl Default for RangingParams {
    fn default() -> Self {
        RangingParams {
            timing_noise_sd_s: 0.0,
            sound_speed_mps: 1500.0,
        }
    }
}

impl RangingParams {
    /// Checks every parameter; errors name the field.
    pub fn validate(&self) -> Result<(), EnvError> {
        require_non_negative("timing_noise_sd_s", self.timing_noise_sd_s)?;
        require_positive("sound_speed_mps", self.sound_speed_mps)
    }

    /// Standard deviation of a measured range, m.
    pub fn range_sd_m(&self) -> f64 {
        0.5 * self.sound_speed_mps * self.timing_noise_sd_s
    }
}

/// The channel models of a world.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CommsParams {
    /// Acoustic modems.
    pub acoustic: ChannelParams,
    /// Radio between surface craft.
    pub radio: ChannelParams,
    /// Acoustic ranging.
    #[serde(default)]
    pub ranging: RangingParams,
}

impl CommsParams {
    /// Checks every channel; errors name the channel's field (`acoustic.latency_s`).
    pub fn validate(&self) -> Result<(), EnvError> {
        self.acoustic.validate().map_err(|e| e.under("acoustic"))?;
        self.radio.validate().map_err(|e| e.under("radio"))?;
        self.ranging.validate().map_err(|e| e.under("ranging"))
    }

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
    /// The sender's modem was still carrying its previous packet.
    ModemBusy,
    /// The recipient could not hear (a deaf window of its modem).
    Deaf,
    /// A range echo answered no request on record.
    Unsolicited,
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

/// A ranging request on its way to (or answered by) its target.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PendingRange {
    requester: VehicleId,
    target: VehicleId,
    distance_m: f64,
}

/// The messages on their way and the channel models' random streams.
#[derive(Debug, Clone)]
pub struct Comms {
    params: CommsParams,
    rng_acoustic: SimRng,
    rng_radio: SimRng,
    rng_ranging: SimRng,
    in_flight: Vec<InFlight>,
    seq: u64,
    busy_until_s: Vec<(VehicleId, Link, f64)>,
    pending: Vec<PendingRange>,
}

impl Comms {
    /// Channels with `params`, their random streams derived from `seed` (one per link kind, one
    /// for the ranging noise).
    pub fn new(params: CommsParams, seed: u64) -> Self {
        use plumetrace_env::{StreamId, stream_rng};
        Comms {
            params,
            rng_acoustic: stream_rng(seed, StreamId::Custom(STREAM_ACOUSTIC)),
            rng_radio: stream_rng(seed, StreamId::Custom(STREAM_RADIO)),
            rng_ranging: stream_rng(seed, StreamId::Custom(STREAM_RANGING)),
            in_flight: Vec::new(),
            seq: 0,
            busy_until_s: Vec::new(),
            pending: Vec::new(),
        }
    }

    /// Whether `from`'s modem on `link` is still carrying a packet at `t_s` (only channels with
    /// `one_in_flight` are ever busy).
    pub fn busy(&self, from: VehicleId, link: Link, t_s: f64) -> bool {
        self.busy_until_s
            .iter()
            .any(|&(v, l, until)| v == from && l == link && t_s + 1e-9 < until)
    }

    fn occupy(&mut self, from: VehicleId, link: Link, until_s: f64) {
        match self
            .busy_until_s
            .iter_mut()
            .find(|(v, l, _)| *v == from && *l == link)
        {
            Some(e) => e.2 = e.2.max(until_s),
            None => self.busy_until_s.push((from, link, until_s)),
        }
    }

    /// Records that `requester`'s ranging request reached `target` from `distance_m` (true
    /// slant distance at sending); a later request to the same target replaces it.
    pub fn record_request(&mut self, requester: VehicleId, target: VehicleId, distance_m: f64) {
        self.pending
            .retain(|p| !(p.requester == requester && p.target == target));
        self.pending.push(PendingRange {
            requester,
            target,
            distance_m,
        });
    }

    /// The range `requester` measures from `target`'s echo sent from `distance_m` (true slant
    /// distance at the echo's sending): the mean of the two legs plus timing noise. `None` when
    /// no request of `requester` to `target` is on record (the record is used up).
    pub fn measure_range(
        &mut self,
        requester: VehicleId,
        target: VehicleId,
        distance_m: f64,
    ) -> Option<f64> {
        let k = self
            .pending
            .iter()
            .position(|p| p.requester == requester && p.target == target)?;
        let p = self.pending.swap_remove(k);
        let sd = self.params.ranging.range_sd_m();
        let noise = if sd > 0.0 {
            let n: f64 = rand_distr::Distribution::sample(
                &rand_distr::StandardNormal,
                &mut self.rng_ranging,
            );
            sd * n
        } else {
            0.0
        };
        let r = 0.5 * (p.distance_m + distance_m) + noise;
        Some(if r.is_finite() { r.max(0.0) } else { 0.0 })
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
        let travel = c.sound_speed_mps.map_or(0.0, |s| distance / s);
        let arrival_s = message.sent_s + c.latency_s + travel;
        if c.one_in_flight {
            // The packet is on the water until it reaches its farthest recipient, heard or not.
            self.occupy(message.from, message.link, arrival_s);
        }
        let rng = match message.link {
            Link::Acoustic => &mut self.rng_acoustic,
            Link::Radio => &mut self.rng_radio,
        };
        if c.loss_probability > 0.0 && rng.random::<f64>() < c.loss_probability {
            return Transmission::Lost(LossReason::Dropped);
        }
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

/// Whether a message body is a ranging echo (the world turns it into a measured range).
pub fn is_range_echo(body: &MessageBody) -> bool {
    matches!(body, MessageBody::RangeEcho { .. })
}

/// The `StreamId::Custom` numbers of the channels' streams.
const STREAM_ACOUSTIC: u64 = 0xC0_4441;
const STREAM_RADIO: u64 = 0xC0_4452;
const STREAM_RANGING: u64 = 0xC0_4447;

#[cfg(test)]
mod tests {
    use super::*;
    use plumetrace_core::Recipient;

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
                one_in_flight: false,
            },
            radio: ChannelParams::IDEAL,
            ranging: RangingParams::default(),
        };
        let mut c = Comms::new(params, 1);
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
            ranging: RangingParams::default(),
        };
        let count = |seed| {
            let mut c = Comms::new(params, seed);
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
