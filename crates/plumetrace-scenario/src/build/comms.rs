//! `[comms]`: the acoustic and radio channels and acoustic ranging.

use super::Invalid;
use crate::config::{ChannelConfig, CommsConfig};
use plumetrace_sim::{ChannelParams, CommsParams, RangingParams};

/// The message channels (absent keys: ideal channels, default ranging).
pub(super) fn comms(c: &CommsConfig) -> Result<CommsParams, Invalid> {
    let d = RangingParams::default();
    let comms = CommsParams {
        acoustic: channel(c.acoustic.as_ref()),
        radio: channel(c.radio.as_ref()),
        ranging: c.ranging.as_ref().map_or(d, |r| RangingParams {
            timing_noise_sd_s: r.timing_noise_sd_s.unwrap_or(d.timing_noise_sd_s),
            sound_speed_mps: r.sound_speed_mps.unwrap_or(d.sound_speed_mps),
        }),
    };
    comms.validate().map_err(|e| Invalid::env("comms", e))?;
    Ok(comms)
}

/// A channel model from its table (absent keys: ideal).
fn channel(c: Option<&ChannelConfig>) -> ChannelParams {
    let ideal = ChannelParams::IDEAL;
    c.map_or(ideal, |c| ChannelParams {
        latency_s: c.latency_s.unwrap_or(ideal.latency_s),
        sound_speed_mps: c.sound_speed_mps,
        loss_probability: c.loss_probability.unwrap_or(ideal.loss_probability),
        max_range_m: c.max_range_m,
        one_in_flight: c.one_in_flight.unwrap_or(ideal.one_in_flight),
    })
}
