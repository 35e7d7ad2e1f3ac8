//! Messages between vehicles (acoustic modem, radio) as the onboard side sees them.
//!
//! A planner puts [`Outgoing`] messages in its decision; whatever carries them (the simulated
//! world's channel models, or a real modem) stamps sender and time and hands the receiver a
//! [`Message`] in its next snapshot, or loses it.

use crate::{Heading, Vec2, VehicleId};
use serde::{Deserialize, Serialize};

/// Who a message is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Recipient {
    /// One vehicle.
    Vehicle(VehicleId),
    /// Every vehicle in range.
    Broadcast,
}

/// The physical link a message travels over; each has its own channel model (delay, loss,
/// range).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Link {
    /// Underwater acoustic modem: slow (sound speed), lossy, limited range.
    Acoustic,
    /// Radio between surface craft: fast, usually reliable.
    Radio,
}

/// What a message carries. New kinds are added as variants so that the link code stays exhaustive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum MessageBody {
    /// An acoustic range measurement to the sender, with the sender's heading piggybacked: what
    /// the requester's modem makes of a [`MessageBody::RangeEcho`] answering its
    /// [`MessageBody::RangeRequest`] (the round-trip time less the known turnaround, times half
    /// the sound speed).
    RangeReply {
        /// Measured slant range, m.
        range_m: f64,
        /// Sender's compass heading at transmission.
        sender_heading: Heading,
        /// The sender's cross-flow formation scale, when it sends one.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        scale_cw: Option<f64>,
    },
    /// An acoustic ranging request (broadcast: every modem in range hears it); only `target`
    /// answers, with a [`MessageBody::RangeEcho`] at once. The requester's filtered chemical
    /// reading is piggybacked.
    RangeRequest {
        /// The vehicle asked to answer.
        target: crate::VehicleId,
        /// The requester's filtered chemical reading (sensor units).
        reading: f64,
    },
    /// The answer to a [`MessageBody::RangeRequest`] as its target sends it: the payload only.
    /// The requester receives it as a [`MessageBody::RangeReply`] with the measured range.
    RangeEcho {
        /// The sender's compass heading.
        heading: Heading,
        /// The sender's cross-flow formation scale, when it shares it.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        scale_cw: Option<f64>,
    },
    /// A formation member's state for its neighbours (surface craft, over the radio).
    FormationState {
        /// Position `(east, north)`, m (GPS).
        pos_m: Vec2,
        /// Filtered chemical reading (sensor units).
        reading: f64,
        /// Cross-flow formation scale.
        scale_cw: f64,
    },
    /// A position report (e.g. a surface vehicle's GPS fix).
    Position {
        /// Reported position `(east, north)`, m.
        pos_m: Vec2,
    },
    /// A chemical detection report.
    Detection {
        /// Where the sender detected chemical `(east, north)`, m.
        pos_m: Vec2,
        /// The reading that triggered it.
        reading: f64,
    },
    /// Free text (operator notes, debugging).
    Text {
        /// The text.
        text: String,
    },
}

/// A message as a planner sends it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outgoing {
    /// Recipient.
    pub to: Recipient,
    /// Link to send it over.
    pub link: Link,
    /// Content.
    pub body: MessageBody,
}

/// One message between vehicles, as delivered.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Message {
    /// Sender.
    pub from: VehicleId,
    /// Recipient.
    pub to: Recipient,
    /// Link it travelled over.
    pub link: Link,
    /// Transmission time, s.
    pub sent_s: f64,
    /// Content.
    pub body: MessageBody,
}
