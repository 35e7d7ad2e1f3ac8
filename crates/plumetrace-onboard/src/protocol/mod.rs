//! What the bytes on a vehicle's lines mean: the sentence codecs of the front-seat protocols and
//! the sensors, and the back seat's session of each protocol.
//!
//! - [`sentence`]: the line rule (framing and checksum) and field readers shared by the codecs;
//! - [`bluefin`]: the Bluefin standard payload interface sentences;
//! - [`iver`]: the Iver remote-helm sentences and their unit setting;
//! - [`chem`]: the chemical sensor's line input;
//! - [`current`]: the current meter's `$--CUR` sentences (measured flow);
//! - [`session`]: the back seat's side of the Bluefin and Iver protocols (subscriptions,
//!   acknowledgements and resends, polls, keep-alives) and of a sensor's own line.
//!
//! The codecs never panic on what a link delivers: a bad line is a typed
//! [`sentence::SentenceError`].

pub mod bluefin;
pub mod chem;
pub mod current;
pub mod iver;
pub mod sentence;
pub mod session;
