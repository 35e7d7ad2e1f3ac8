//! The MOOS wire format: messages, packets, the handshake's bytes, and a framer that cuts a
//! byte stream into packets.
//!
//! Written from the MOOS sources (github.com/themoos/core-moos, `Core/libMOOS/Comms`), not from
//! their code. Every integer is a 4-byte little-endian two's-complement `int`, every double an
//! 8-byte little-endian IEEE 754 number (`CopyToBufferAsLittleEndian` in `MOOSMsg.cpp`); a string
//! is its byte count (an `int`) then its bytes, with no terminator (`CMOOSMsg::operator<<` for
//! strings).
//!
//! A **message** (`CMOOSMsg::Serialize`, `MOOSMsg.cpp`), in order:
//!
//! | field | type | what |
//! | --- | --- | --- |
//! | length | int | bytes of the whole message, this field included |
//! | id | int | the sender's message counter (`-1` when not posted) |
//! | type | byte | `N` notify, `R` register, `U` unregister, `*` / `/` wildcard (un)register, `~` not set, `C` command, `A` anonymous, `.` null, `i` data (the handshake), `K` poison, `W` welcome, `Q` server request, `T` timing, `^` terminate (`MOOSMsg.h`) |
//! | data type | byte | `D` double, `S` string, `B` binary string |
//! | source | string | the posting application |
//! | source aux | string | extra source information |
//! | community | string | the originating community |
//! | key | string | the variable's name |
//! | time | double | the posting time, s since 1970 (MOOS time) |
//! | double | double | the double value |
//! | double 2 | double | a second double (the timing reply's consolidation period) |
//! | string | string | the string value (any bytes for `B`) |
//!
//! A **packet** (`CMOOSCommPkt::Serialize`, `MOOSCommPkt.cpp`) is an `int` with the bytes of
//! the whole packet (this header included), an `int` with the number of messages, one byte
//! saying whether the rest is compressed (always 0: MOOS never compresses) and the messages
//! back to back. A reader learns a packet's length from its first four bytes
//! (`CMOOSCommPkt::GetBytesRequired`).
//!
//! **Connecting** (`CMOOSCommClient::HandShake` in `MOOSCommClient.cpp`, `CheckProtocol` and
//! `CMOOSCommServer::HandShake` in `MOOSCommServer.cpp`): the client sends the protocol name
//! `ELKS CAN'T DANCE 2/8/10` padded with zero bytes to 32 (`MOOS_PROTOCOL_STRING` in
//! `MOOSCommPkt.h`), then a packet with one data message (`i`, string) whose key is
//! `asynchronous` (`MOOSAsyncCommClient::HandShakeKey`), whose string is the client's name and
//! whose time is the client's clock. The server answers with a welcome (`W`) whose double is the
//! skew it measured (its time minus the client's), whose string is `asynchronous`, whose source
//! aux is `hostname=...` and whose community is the community's name; or with a poison (`K`)
//! whose string says why (a name already taken) before it closes the connection.
//!
//! **Running** (`MOOSAsyncCommClient.cpp`, `ThreadedCommServer.cpp`, `MOOSDB.cpp`): the client
//! registers (`R`, double: the key is the variable, the double the minimum interval between
//! notifications, 0 for all) and publishes (`N`, double or string), each message with its
//! source set to the client's name and the next message id. At least once a second
//! (`TIMING_MESSAGE_PERIOD`) a packet starts with a timing message (`T`, key `_async_timing`,
//! double 0, time the client's clock, id -1); the server answers it at the front of a packet
//! with the same message, its double set to the server's clock and its second double to the
//! consolidation period. The server drops a client silent for longer than its timeout, so the
//! timing messages are also the heartbeat. Clock skew is estimated from the replies as MOOS does
//! (`CMOOSCommClient::UpdateMOOSSkew`): half the sum of (server - received) and
//! (server - sent), smoothed 0.9 / 0.1, the first reply left out and no estimate at all when the
//! welcome's `hostname=` is this computer's host name; times this client posts are its clock plus
//! the skew. The reply's second double (the DB's consolidation period) is the least time between
//! two outgoing packets (`MOOSAsyncCommClient::MonitorAndLimitWriteSpeed`).
//!
//! # Bounds on what arrives
//!
//! A packet shorter than its header, a negative or overlong string length, a message count the
//! packet cannot hold, a compressed packet or trailing bytes make the packet an error; inside a
//! message whose length fits its packet, an unknown type or data type, a non-UTF-8 name or fields
//! that disagree with the length make that message an error and leave the others
//! ([`decode_messages`]). Errors are counted by kind, written to the traffic log, never acted on.
//! A packet longer than [`MAX_PACKET`] (1 MiB; MOOS itself sets no limit) is skipped by the
//! [`Framer`] as its bytes arrive, never buffered, and the stream goes on after it. Nothing is
//! allocated from a length field before the bytes are there. A packet length that cannot be a
//! packet's loses the packet boundaries, so the connection is then dropped and made again.

use std::time::{Duration, SystemTime};

/// The protocol name a client sends first (`MOOS_PROTOCOL_STRING`).
pub const PROTOCOL: &str = "ELKS CAN'T DANCE 2/8/10";
/// Bytes the protocol name takes on the wire, zero-padded (`MOOS_PROTOCOL_STRING_BUFFER_SIZE`).
pub const PROTOCOL_LEN: usize = 32;
/// The largest packet read, bytes (1 MiB; a navigation packet is a few hundred bytes).
pub const MAX_PACKET: usize = 1 << 20;
/// A packet's header: length, message count, compression flag.
pub const PACKET_HEADER: usize = 9;
/// The smallest message: three ints, two bytes, five empty strings' lengths, three doubles.
pub const MIN_MESSAGE: usize = 4 + 4 + 1 + 1 + 5 * 4 + 3 * 8;
/// Period of the timing (heartbeat) messages (`TIMING_MESSAGE_PERIOD`).
pub const TIMING_PERIOD: Duration = Duration::from_secs(1);
/// The key of timing messages.
pub const TIMING_KEY: &str = "_async_timing";
/// The handshake's key for an asynchronous client.
pub const ASYNC_KEY: &str = "asynchronous";

/// Message types (`MOOSMsg.h`).
pub mod kind {
    /// A notification (a posting).
    pub const NOTIFY: u8 = b'N';
    /// A registration.
    pub const REGISTER: u8 = b'R';
    /// An unregistration.
    pub const UNREGISTER: u8 = b'U';
    /// A wildcard registration.
    pub const WILDCARD_REGISTER: u8 = b'*';
    /// A wildcard unregistration.
    pub const WILDCARD_UNREGISTER: u8 = b'/';
    /// Not set.
    pub const NOT_SET: u8 = b'~';
    /// A command.
    pub const COMMAND: u8 = b'C';
    /// Anonymous.
    pub const ANONYMOUS: u8 = b'A';
    /// The null message (an old server's timing).
    pub const NULL: u8 = b'.';
    /// Data (the handshake).
    pub const DATA: u8 = b'i';
    /// Poison: the server refuses the client.
    pub const POISON: u8 = b'K';
    /// The server's welcome.
    pub const WELCOME: u8 = b'W';
    /// A server request.
    pub const SERVER_REQUEST: u8 = b'Q';
    /// Timing.
    pub const TIMING: u8 = b'T';
    /// Terminate the connection.
    pub const TERMINATE: u8 = b'^';
    /// Every type above.
    pub const ALL: &[u8] = b"NRU*/~CA.iKWQT^";
}

/// Data types (`MOOSMsg.h`).
pub mod data {
    /// A double.
    pub const DOUBLE: u8 = b'D';
    /// A string.
    pub const STRING: u8 = b'S';
    /// A binary string.
    pub const BINARY: u8 = b'B';
}

/// One MOOS message (a `CMOOSMsg`), every field of the wire.
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    /// The sender's message id (`-1` when not posted).
    pub id: i32,
    /// The message type ([`kind`]).
    pub kind: u8,
    /// The data type ([`data`]).
    pub data_type: u8,
    /// The posting application.
    pub source: String,
    /// Extra source information.
    pub source_aux: String,
    /// The originating community.
    pub community: String,
    /// The variable's name.
    pub key: String,
    /// The posting time, MOOS seconds.
    pub time: f64,
    /// The double value.
    pub double: f64,
    /// The second double.
    pub double2: f64,
    /// The string value (any bytes for a binary string).
    pub string: Vec<u8>,
}

impl Message {
    fn new(kind: u8, data_type: u8, key: &str, time: f64) -> Self {
        Message {
            id: -1,
            kind,
            data_type,
            source: String::new(),
            source_aux: String::new(),
            community: String::new(),
            key: key.into(),
            time,
            double: -1.0,
            double2: -1.0,
            string: Vec::new(),
        }
    }

    /// A message carrying a double (the other value fields as MOOS leaves them: -1 and empty).
    pub fn with_double(kind: u8, key: &str, value: f64, time: f64) -> Self {
        Message {
            double: value,
            ..Message::new(kind, data::DOUBLE, key, time)
        }
    }

    /// A message carrying a string.
    pub fn with_string(kind: u8, key: &str, value: &str, time: f64) -> Self {
        Message {
            string: value.as_bytes().to_vec(),
            ..Message::new(kind, data::STRING, key, time)
        }
    }

    /// The handshake a client sends after the protocol name: its `name`, its clock `time`.
    pub fn handshake(name: &str, time: f64) -> Self {
        Message::with_string(kind::DATA, ASYNC_KEY, name, time)
    }

    /// A timing message sent at local `time`.
    pub fn timing(time: f64) -> Self {
        Message::with_double(kind::TIMING, TIMING_KEY, 0.0, time)
    }

    /// The string value, if it is text.
    pub fn text(&self) -> Option<&str> {
        std::str::from_utf8(&self.string).ok()
    }

    /// The value as a finite number: the double of a double message, the parsed text of a
    /// string one.
    pub fn number(&self) -> Option<f64> {
        let v = match self.data_type {
            data::DOUBLE => self.double,
            data::STRING => self.text()?.trim().parse().ok()?,
            _ => return None,
        };
        v.is_finite().then_some(v)
    }

    /// Bytes the message takes on the wire.
    pub fn wire_len(&self) -> usize {
        MIN_MESSAGE
            + self.source.len()
            + self.source_aux.len()
            + self.community.len()
            + self.key.len()
            + self.string.len()
    }

    fn encode_into(&self, out: &mut Vec<u8>) {
        let len = i32::try_from(self.wire_len()).unwrap_or(i32::MAX);
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(&self.id.to_le_bytes());
        out.push(self.kind);
        out.push(self.data_type);
        for s in [
            self.source.as_bytes(),
            self.source_aux.as_bytes(),
            self.community.as_bytes(),
            self.key.as_bytes(),
        ] {
            put_bytes(out, s);
        }
        for d in [self.time, self.double, self.double2] {
            out.extend_from_slice(&d.to_le_bytes());
        }
        put_bytes(out, &self.string);
    }

    /// A one-line summary for the traffic log (strings cut at 120 characters).
    pub fn summary(&self) -> String {
        let value = match self.data_type {
            data::DOUBLE => format!("{}", self.double),
            data::BINARY => format!("<{} bytes>", self.string.len()),
            _ => {
                let t: String = String::from_utf8_lossy(&self.string)
                    .chars()
                    .take(120)
                    .map(|c| if c.is_control() { '_' } else { c })
                    .collect();
                format!("\"{t}\"")
            }
        };
        format!(
            "{} {} {} {value} t={:.3} src={} id={}",
            char::from(self.kind),
            self.key,
            char::from(self.data_type),
            self.time,
            self.source,
            self.id
        )
    }
}

fn put_bytes(out: &mut Vec<u8>, b: &[u8]) {
    let n = i32::try_from(b.len()).unwrap_or(i32::MAX);
    out.extend_from_slice(&n.to_le_bytes());
    out.extend_from_slice(b);
}

/// Why bytes are not a packet.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MoosError {
    /// Fewer bytes than a field needs.
    #[error("truncated: {what} needs {need} bytes, {have} left")]
    Truncated {
        /// Which field.
        what: &'static str,
        /// Bytes it needs.
        need: usize,
        /// Bytes left.
        have: usize,
    },
    /// A length or count out of its bounds.
    #[error("bad length: {what} is {value}")]
    BadLength {
        /// Which length.
        what: &'static str,
        /// Its value.
        value: i64,
    },
    /// The compression flag is set (MOOS never compresses).
    #[error("a compressed packet (flag {0})")]
    Compressed(u8),
    /// An unknown message type.
    #[error("unknown message type 0x{0:02x}")]
    BadType(u8),
    /// An unknown data type.
    #[error("unknown data type 0x{0:02x}")]
    BadDataType(u8),
    /// A name that is not UTF-8.
    #[error("the {0} is not text")]
    NotText(&'static str),
    /// Bytes after the last message.
    #[error("{0} bytes after the last message")]
    Trailing(usize),
    /// A packet too large to send, or received and skipped.
    #[error("a packet of {0} bytes is larger than {MAX_PACKET}")]
    TooLarge(usize),
}

impl MoosError {
    /// A short name for counts.
    pub fn kind(&self) -> &'static str {
        match self {
            MoosError::Truncated { .. } => "truncated",
            MoosError::BadLength { .. } => "bad_length",
            MoosError::Compressed(_) => "compressed",
            MoosError::BadType(_) => "bad_type",
            MoosError::BadDataType(_) => "bad_data_type",
            MoosError::NotText(_) => "not_text",
            MoosError::Trailing(_) => "trailing",
            MoosError::TooLarge(_) => "too_large",
        }
    }
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn left(&self) -> usize {
        self.b.len() - self.at
    }

    fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], MoosError> {
        if n > self.left() {
            return Err(MoosError::Truncated {
                what,
                need: n,
                have: self.left(),
            });
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }

    fn i32(&mut self, what: &'static str) -> Result<i32, MoosError> {
        let s = self.take(4, what)?;
        Ok(i32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }

    fn u8(&mut self, what: &'static str) -> Result<u8, MoosError> {
        Ok(self.take(1, what)?[0])
    }

    fn f64(&mut self, what: &'static str) -> Result<f64, MoosError> {
        let s = self.take(8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(s);
        Ok(f64::from_le_bytes(a))
    }

    fn bytes(&mut self, what: &'static str) -> Result<&'a [u8], MoosError> {
        let n = self.i32(what)?;
        let n = usize::try_from(n).map_err(|_| MoosError::BadLength {
            what,
            value: i64::from(n),
        })?;
        self.take(n, what)
    }

    fn text(&mut self, what: &'static str) -> Result<String, MoosError> {
        let b = self.bytes(what)?;
        std::str::from_utf8(b)
            .map(str::to_owned)
            .map_err(|_| MoosError::NotText(what))
    }
}

/// Reads one message from the front of `r`'s bytes.
fn decode_message(r: &mut Reader<'_>) -> Result<Message, MoosError> {
    let start = r.at;
    let len = r.i32("the message length")?;
    let len_ok = usize::try_from(len)
        .ok()
        .filter(|l| *l >= MIN_MESSAGE && *l <= r.left() + 4);
    let Some(len) = len_ok else {
        r.at = start;
        return Err(MoosError::BadLength {
            what: "the message length",
            value: i64::from(len),
        });
    };
    let mut m = Reader {
        b: &r.b[start..start + len],
        at: 4,
    };
    // The message's bounds are known: whatever is wrong inside it, the packet goes on after it.
    r.at = start + len;
    let id = m.i32("the id")?;
    let kind = m.u8("the type")?;
    if !kind::ALL.contains(&kind) {
        return Err(MoosError::BadType(kind));
    }
    let data_type = m.u8("the data type")?;
    if ![data::DOUBLE, data::STRING, data::BINARY].contains(&data_type) {
        return Err(MoosError::BadDataType(data_type));
    }
    let source = m.text("source")?;
    let source_aux = m.text("source aux")?;
    let community = m.text("community")?;
    let key = m.text("key")?;
    let time = m.f64("the time")?;
    let double = m.f64("the double")?;
    let double2 = m.f64("the second double")?;
    let string = m.bytes("the string")?.to_vec();
    if m.left() != 0 {
        return Err(MoosError::BadLength {
            what: "the message length (longer than its fields)",
            value: len as i64,
        });
    }
    Ok(Message {
        id,
        kind,
        data_type,
        source,
        source_aux,
        community,
        key,
        time,
        double,
        double2,
        string,
    })
}

/// The packet of `messages`; an error if it would be larger than [`MAX_PACKET`].
pub fn encode_packet(messages: &[Message]) -> Result<Vec<u8>, MoosError> {
    let len = PACKET_HEADER + messages.iter().map(Message::wire_len).sum::<usize>();
    if len > MAX_PACKET {
        return Err(MoosError::TooLarge(len));
    }
    let mut out = Vec::with_capacity(len);
    out.extend_from_slice(&(len as i32).to_le_bytes());
    out.extend_from_slice(&(messages.len() as i32).to_le_bytes());
    out.push(0);
    for m in messages {
        m.encode_into(&mut out);
    }
    Ok(out)
}

/// The messages of one whole packet (`bytes` is exactly the packet); the first bad message
/// makes the whole packet an error.
pub fn decode_packet(bytes: &[u8]) -> Result<Vec<Message>, MoosError> {
    decode_messages(bytes)?.into_iter().collect()
}

/// The messages of one whole packet, each on its own: a message of an unknown type, with a name
/// that is not UTF-8 or fields that disagree with its length is an error of its own and the
/// others stand (as libMOOS reads a packet); an error in the packet's own framing (its length,
/// its message count, a message length it cannot hold, trailing bytes) is the whole packet's.
pub fn decode_messages(bytes: &[u8]) -> Result<Vec<Result<Message, MoosError>>, MoosError> {
    let mut r = Reader { b: bytes, at: 0 };
    let len = r.i32("the packet length")?;
    if usize::try_from(len).ok() != Some(bytes.len()) || bytes.len() > MAX_PACKET {
        return Err(MoosError::BadLength {
            what: "the packet length",
            value: i64::from(len),
        });
    }
    let n = r.i32("the message count")?;
    let flag = r.u8("the compression flag")?;
    let room = bytes.len().saturating_sub(PACKET_HEADER) / MIN_MESSAGE;
    let n = usize::try_from(n)
        .ok()
        .filter(|n| *n <= room)
        .ok_or(MoosError::BadLength {
            what: "the message count",
            value: i64::from(n),
        })?;
    if flag != 0 {
        return Err(MoosError::Compressed(flag));
    }
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let before = r.at;
        let m = decode_message(&mut r);
        if r.at == before {
            // Its length could not be read: the packet cannot be followed past it.
            return Err(m.err().unwrap_or(MoosError::Trailing(r.left())));
        }
        out.push(m);
    }
    if r.left() != 0 {
        return Err(MoosError::Trailing(r.left()));
    }
    Ok(out)
}

/// Cuts a byte stream into packets by their length fields. A packet longer than
/// [`MAX_PACKET`] (MOOS sets no limit) is skipped as its bytes arrive, never buffered: it is
/// reported once as [`MoosError::TooLarge`] and the stream goes on after it.
#[derive(Debug, Default)]
pub struct Framer {
    buf: Vec<u8>,
    // Bytes of a skipped packet still to come.
    skip: usize,
}

impl Framer {
    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        let skipped = self.skip.min(bytes.len());
        self.skip -= skipped;
        self.buf.extend_from_slice(&bytes[skipped..]);
    }

    /// The next whole packet, if its bytes are all there; an error if it is too large (skipped)
    /// or if its length field cannot be a packet's (the stream cannot be followed past it).
    pub fn next_packet(&mut self) -> Option<Result<Vec<u8>, MoosError>> {
        if self.buf.len() < 4 {
            return None;
        }
        let len = i32::from_le_bytes([self.buf[0], self.buf[1], self.buf[2], self.buf[3]]);
        match usize::try_from(len) {
            Ok(l) if (PACKET_HEADER..=MAX_PACKET).contains(&l) => {
                (self.buf.len() >= l).then(|| Ok(self.buf.drain(..l).collect()))
            }
            Ok(l) if l > MAX_PACKET => {
                let here = self.buf.len().min(l);
                self.buf.drain(..here);
                self.skip = l - here;
                Some(Err(MoosError::TooLarge(l)))
            }
            _ => Some(Err(MoosError::BadLength {
                what: "the packet length",
                value: i64::from(len),
            })),
        }
    }

    /// Forgets what is buffered.
    pub fn clear(&mut self) {
        self.buf.clear();
        self.skip = 0;
    }
}

/// The protocol name as sent: its bytes, zero-padded to [`PROTOCOL_LEN`].
pub fn protocol_bytes() -> [u8; PROTOCOL_LEN] {
    let mut b = [0u8; PROTOCOL_LEN];
    b[..PROTOCOL.len()].copy_from_slice(PROTOCOL.as_bytes());
    b
}

/// Seconds since 1970 on this computer's clock.
pub fn unix_now() -> f64 {
    SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bytes from hex written with spaces.
    fn hex(s: &str) -> Vec<u8> {
        let digits: Vec<u8> = s.bytes().filter(|b| b.is_ascii_hexdigit()).collect();
        digits
            .chunks(2)
            .map(|p| u8::from_str_radix(std::str::from_utf8(p).unwrap_or("00"), 16).unwrap_or(0))
            .collect()
    }

    // Doubles used below, little-endian: 1.0 = 00 00 00 00 00 00 f0 3f, -1.0 = .. f0 bf,
    // 0.0 = eight zeros, 2.5 = .. 04 40, 1.5 = .. f8 3f, 0.5 = .. e0 3f, 3.0 = .. 08 40.

    /// The handshake: 32 bytes of protocol name, then a packet of one `i` message.
    #[test]
    fn the_handshake_matches_its_golden_bytes() {
        let protocol = hex(
            "45 4c 4b 53 20 43 41 4e 27 54 20 44 41 4e 43 45 20 32 2f 38 2f 31 30 \
             00 00 00 00 00 00 00 00 00",
        );
        assert_eq!(protocol_bytes().to_vec(), protocol);
        let m = Message::handshake("pA", 1.0);
        let golden = hex(
            // packet: 77 bytes, 1 message, not compressed
            "4d 00 00 00  01 00 00 00  00 \
             44 00 00 00 \
             ff ff ff ff \
             69 53 \
             00 00 00 00  00 00 00 00  00 00 00 00 \
             0c 00 00 00  61 73 79 6e 63 68 72 6f 6e 6f 75 73 \
             00 00 00 00 00 00 f0 3f \
             00 00 00 00 00 00 f0 bf \
             00 00 00 00 00 00 f0 bf \
             02 00 00 00  70 41",
        );
        // message: 68 bytes (0x44), id -1, type 'i' (0x69), data 'S' (0x53), empty source,
        // source aux and community, key "asynchronous" (12 bytes), time 1.0, double -1,
        // double 2 -1, string "pA".
        assert_eq!(encode_packet(std::slice::from_ref(&m)), Ok(golden.clone()));
        assert_eq!(decode_packet(&golden), Ok(vec![m]));
    }

    #[test]
    fn a_registration_matches_its_golden_bytes() {
        let mut m = Message::with_double(kind::REGISTER, "NAV_X", 0.0, 2.5);
        m.source = "pA".into();
        m.id = 3;
        // 9 + 61 = 70 bytes; message 61 (0x3d), id 3, 'R' 'D', source "pA", key "NAV_X",
        // time 2.5, double (the interval) 0, double 2 -1, empty string.
        let golden = hex("46 00 00 00  01 00 00 00  00 \
             3d 00 00 00  03 00 00 00  52 44 \
             02 00 00 00  70 41  00 00 00 00  00 00 00 00 \
             05 00 00 00  4e 41 56 5f 58 \
             00 00 00 00 00 00 04 40 \
             00 00 00 00 00 00 00 00 \
             00 00 00 00 00 00 f0 bf \
             00 00 00 00");
        assert_eq!(encode_packet(std::slice::from_ref(&m)), Ok(golden.clone()));
        assert_eq!(decode_packet(&golden), Ok(vec![m]));
    }

    /// A packet of two notifications: a double and a string.
    #[test]
    fn notifications_match_their_golden_bytes() {
        let mut d = Message::with_double(kind::NOTIFY, "DESIRED_SPEED", 1.5, 1.0);
        d.source = "pA".into();
        d.id = 7;
        let mut s = Message::with_string(kind::NOTIFY, "CPT_PAUSED", "true", 1.0);
        s.source = "pA".into();
        s.id = 8;
        // 9 + 69 + 70 = 148 (0x94) bytes, 2 messages. The double: 69 (0x45) bytes, id 7,
        // 'N' 'D', key "DESIRED_SPEED" (13), time 1, double 1.5, double 2 -1, no string. The
        // string: 70 (0x46) bytes, id 8, 'N' 'S', key "CPT_PAUSED" (10), time 1, doubles -1,
        // string "true".
        let golden = hex("94 00 00 00  02 00 00 00  00 \
             45 00 00 00  07 00 00 00  4e 44 \
             02 00 00 00  70 41  00 00 00 00  00 00 00 00 \
             0d 00 00 00  44 45 53 49 52 45 44 5f 53 50 45 45 44 \
             00 00 00 00 00 00 f0 3f \
             00 00 00 00 00 00 f8 3f \
             00 00 00 00 00 00 f0 bf \
             00 00 00 00 \
             46 00 00 00  08 00 00 00  4e 53 \
             02 00 00 00  70 41  00 00 00 00  00 00 00 00 \
             0a 00 00 00  43 50 54 5f 50 41 55 53 45 44 \
             00 00 00 00 00 00 f0 3f \
             00 00 00 00 00 00 f0 bf \
             00 00 00 00 00 00 f0 bf \
             04 00 00 00  74 72 75 65");
        let both = [d, s];
        assert_eq!(encode_packet(&both), Ok(golden.clone()));
        assert_eq!(decode_packet(&golden), Ok(both.to_vec()));
    }

    /// The timing message and the server's reply to it.
    #[test]
    fn timing_messages_match_their_golden_bytes() {
        // 9 + 67 = 76 (0x4c); message 67 (0x43), id -1, 'T' 'D', key "_async_timing" (13),
        // time 2.5, double 0, double 2 -1, no string.
        let golden = hex("4c 00 00 00  01 00 00 00  00 \
             43 00 00 00  ff ff ff ff  54 44 \
             00 00 00 00  00 00 00 00  00 00 00 00 \
             0d 00 00 00  5f 61 73 79 6e 63 5f 74 69 6d 69 6e 67 \
             00 00 00 00 00 00 04 40 \
             00 00 00 00 00 00 00 00 \
             00 00 00 00 00 00 f0 bf \
             00 00 00 00");
        let t = Message::timing(2.5);
        assert_eq!(encode_packet(std::slice::from_ref(&t)), Ok(golden.clone()));
        assert_eq!(decode_packet(&golden), Ok(vec![t.clone()]));
        // The reply: the same message, double the server's clock (3.0), double 2 the
        // consolidation period (0).
        let reply = hex("4c 00 00 00  01 00 00 00  00 \
             43 00 00 00  ff ff ff ff  54 44 \
             00 00 00 00  00 00 00 00  00 00 00 00 \
             0d 00 00 00  5f 61 73 79 6e 63 5f 74 69 6d 69 6e 67 \
             00 00 00 00 00 00 04 40 \
             00 00 00 00 00 00 08 40 \
             00 00 00 00 00 00 00 00 \
             00 00 00 00");
        let want = Message {
            double: 3.0,
            double2: 0.0,
            ..t
        };
        assert_eq!(decode_packet(&reply), Ok(vec![want]));
    }

    /// What a server sends a client on connecting: the welcome, or the poison.
    #[test]
    fn the_welcome_and_the_poison_decode_from_their_golden_bytes() {
        // 9 + 79 = 88 (0x58); message 79 (0x4f), id -1, 'W' 'D', no source, source aux
        // "hostname=db" (11), community "#1" (2), no key, time 2.5, double (the skew) 0.5,
        // double 2 -1, string "asynchronous" (12).
        let welcome = hex("58 00 00 00  01 00 00 00  00 \
             4f 00 00 00  ff ff ff ff  57 44 \
             00 00 00 00 \
             0b 00 00 00  68 6f 73 74 6e 61 6d 65 3d 64 62 \
             02 00 00 00  23 31 \
             00 00 00 00 \
             00 00 00 00 00 00 04 40 \
             00 00 00 00 00 00 e0 3f \
             00 00 00 00 00 00 f0 bf \
             0c 00 00 00  61 73 79 6e 63 68 72 6f 6e 6f 75 73");
        let got = decode_packet(&welcome).unwrap_or_default();
        assert_eq!(got.len(), 1);
        let w = &got[0];
        assert_eq!((w.kind, w.data_type), (kind::WELCOME, data::DOUBLE));
        assert_eq!(w.source_aux, "hostname=db");
        assert_eq!(w.community, "#1");
        assert_eq!(w.double, 0.5);
        assert_eq!(w.text(), Some("asynchronous"));
        assert_eq!(encode_packet(&got), Ok(welcome));
        // 9 + 59 = 68 (0x44); message 59 (0x3b), 'K' 'S', string "taken".
        let poison = hex("44 00 00 00  01 00 00 00  00 \
             3b 00 00 00  ff ff ff ff  4b 53 \
             00 00 00 00  00 00 00 00  00 00 00 00  00 00 00 00 \
             00 00 00 00 00 00 04 40 \
             00 00 00 00 00 00 f0 bf \
             00 00 00 00 00 00 f0 bf \
             05 00 00 00  74 61 6b 65 6e");
        assert_eq!(
            decode_packet(&poison),
            Ok(vec![Message::with_string(kind::POISON, "", "taken", 2.5)])
        );
    }

    /// A binary notification: any bytes in the string, not text, no number.
    #[test]
    fn a_binary_notification_decodes_from_its_golden_bytes() {
        // 9 + 60 = 69 (0x45); message 60 (0x3c), id 0, 'N' 'B', source "s" (1), key "IMG"
        // (3), time 1, doubles -1, string of 2 bytes ff 10.
        let golden = hex("45 00 00 00  01 00 00 00  00 \
             3c 00 00 00  00 00 00 00  4e 42 \
             01 00 00 00  73  00 00 00 00  00 00 00 00 \
             03 00 00 00  49 4d 47 \
             00 00 00 00 00 00 f0 3f \
             00 00 00 00 00 00 f0 bf \
             00 00 00 00 00 00 f0 bf \
             02 00 00 00  ff 10");
        let got = decode_packet(&golden).unwrap_or_default();
        assert_eq!(got.len(), 1);
        assert_eq!(got[0].data_type, data::BINARY);
        assert_eq!(got[0].string, vec![0xff, 0x10]);
        assert_eq!(got[0].text(), None);
        assert_eq!(got[0].number(), None);
        assert_eq!(encode_packet(&got), Ok(golden));
    }

    #[test]
    fn numbers_come_from_doubles_and_from_numeric_strings_only() {
        let d = Message::with_double(kind::NOTIFY, "X", 2.0, 1.0);
        assert_eq!(d.number(), Some(2.0));
        let s = Message::with_string(kind::NOTIFY, "X", " 0.25 ", 1.0);
        assert_eq!(s.number(), Some(0.25));
        for bad in ["abc", "nan", "inf", ""] {
            assert_eq!(
                Message::with_string(kind::NOTIFY, "X", bad, 1.0).number(),
                None
            );
        }
        assert_eq!(
            Message::with_double(kind::NOTIFY, "X", f64::NAN, 1.0).number(),
            None
        );
    }

    #[test]
    fn bad_packets_are_named_errors() {
        let good = encode_packet(&[Message::timing(2.5)]).unwrap_or_default();
        let mut cases: Vec<(Vec<u8>, &str)> = Vec::new();
        cases.push((good[..good.len() - 1].to_vec(), "bad_length"));
        let mut compressed = good.clone();
        compressed[8] = 1;
        cases.push((compressed, "compressed"));
        let mut bad_type = good.clone();
        bad_type[17] = b'Z';
        cases.push((bad_type, "bad_type"));
        let mut bad_data = good.clone();
        bad_data[18] = b'X';
        cases.push((bad_data, "bad_data_type"));
        let mut count = good.clone();
        count[4] = 2;
        cases.push((count, "bad_length"));
        let mut negative = good.clone();
        negative[19..23].copy_from_slice(&(-4i32).to_le_bytes());
        cases.push((negative, "bad_length"));
        let mut overlong = good.clone();
        overlong[19..23].copy_from_slice(&1000i32.to_le_bytes());
        cases.push((overlong, "truncated"));
        let mut trailing = good.clone();
        trailing.extend_from_slice(&[0, 0, 0]);
        let n = trailing.len() as i32;
        trailing[..4].copy_from_slice(&n.to_le_bytes());
        cases.push((trailing, "trailing"));
        let mut not_text = good.clone();
        not_text[35] = 0xff;
        cases.push((not_text, "not_text"));
        for (bytes, want) in cases {
            let got = decode_packet(&bytes).map_err(|e| e.kind());
            assert_eq!(got, Err(want), "{bytes:02x?}");
        }
    }

    #[test]
    fn the_framer_waits_for_whole_packets_and_refuses_impossible_lengths() {
        let p = encode_packet(&[Message::timing(1.0), Message::timing(2.0)]).unwrap_or_default();
        let mut f = Framer::default();
        let mut got = Vec::new();
        for chunk in p.chunks(7).chain(p.chunks(100)) {
            f.push(chunk);
            while let Some(Ok(packet)) = f.next_packet() {
                got.push(packet);
            }
        }
        assert_eq!(got, vec![p.clone(), p]);
        for len in [-1i32, 0, 8, (MAX_PACKET + 1) as i32, i32::MAX] {
            let mut f = Framer::default();
            f.push(&len.to_le_bytes());
            assert!(matches!(f.next_packet(), Some(Err(_))), "{len}");
        }
    }

    #[test]
    fn a_packet_too_large_is_skipped_and_the_stream_goes_on() {
        let big = Message::with_string(kind::NOTIFY, "BIG", &"x".repeat(MAX_PACKET), 1.0);
        // Framed by hand: the encoder refuses to write it.
        let mut p = Vec::new();
        let len = PACKET_HEADER + big.wire_len();
        p.extend_from_slice(&(len as i32).to_le_bytes());
        p.extend_from_slice(&1i32.to_le_bytes());
        p.push(0);
        big.encode_into(&mut p);
        let small = encode_packet(&[Message::timing(2.0)]).unwrap_or_default();
        p.extend_from_slice(&small);
        let mut f = Framer::default();
        let mut got = Vec::new();
        for chunk in p.chunks(4096) {
            f.push(chunk);
            while let Some(r) = f.next_packet() {
                got.push(r.map_err(|e| e.kind()));
            }
        }
        assert_eq!(got, vec![Err("too_large"), Ok(small)]);
        assert!(f.buf.capacity() < 2 * 4096 + 64, "{}", f.buf.capacity());
    }

    #[test]
    fn one_bad_message_in_a_packet_leaves_the_others() {
        let good = Message::with_double(kind::NOTIFY, "NAV_X", 1.0, 2.0);
        let mut p = encode_packet(&[good.clone(), good.clone(), good.clone()]).unwrap_or_default();
        // The first message's type, and the second's key made non-UTF-8.
        p[PACKET_HEADER + 8] = b'Z';
        let second = PACKET_HEADER + good.wire_len();
        let key_at = second + 4 + 4 + 1 + 1 + 3 * 4 + 4;
        p[key_at] = 0xff;
        let got: Vec<Result<String, &str>> = decode_messages(&p)
            .unwrap_or_default()
            .into_iter()
            .map(|m| m.map(|m| m.key).map_err(|e| e.kind()))
            .collect();
        assert_eq!(
            got,
            vec![Err("bad_type"), Err("not_text"), Ok("NAV_X".into())]
        );
        assert_eq!(decode_packet(&p).map_err(|e| e.kind()), Err("bad_type"));
    }

    /// splitmix64: a deterministic stream for the fuzz pass (no random-number crate onboard).
    struct Mix(u64);
    impl Mix {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n.max(1) as u64) as usize
        }
    }

    /// Random and mutated packets: none panics, every one is counted, and whatever decodes
    /// encodes back to exactly its bytes.
    #[test]
    fn a_fuzz_pass_of_random_and_mutated_packets_never_panics() {
        let mut seeds: Vec<Vec<u8>> = Vec::new();
        let mut nav = Message::with_double(kind::NOTIFY, "NAV_X", 12.5, 1.7e9);
        nav.source = "uSimMarine".into();
        nav.community = "#1".into();
        let chem = Message::with_string(kind::NOTIFY, "CHEM_READING", "0.25", 1.7e9);
        for ms in [
            vec![Message::handshake("pPlumetrace", 1.7e9)],
            vec![Message::timing(1.7e9)],
            vec![nav.clone(), chem.clone()],
            vec![nav, chem, Message::timing(1.0)],
            Vec::new(),
        ] {
            seeds.push(encode_packet(&ms).unwrap_or_default());
        }
        let mut r = Mix(2026);
        let (mut ok, mut errs) = (0u64, std::collections::BTreeMap::<&str, u64>::new());
        let n = 200_000;
        for i in 0..n {
            let mut b = seeds[r.below(seeds.len())].clone();
            match i % 5 {
                0 => {
                    // random bytes, sometimes with a right length field
                    let len = r.below(200);
                    b = (0..len).map(|_| r.next() as u8).collect();
                    if len >= 4 && r.below(2) == 0 {
                        b[..4].copy_from_slice(&(len as i32).to_le_bytes());
                    }
                }
                1 => {
                    for _ in 0..1 + r.below(4) {
                        let k = r.below(b.len());
                        if let Some(x) = b.get_mut(k) {
                            *x ^= 1 << r.below(8);
                        }
                    }
                }
                2 => {
                    // an int field overwritten with an extreme value
                    let k = r.below(b.len().saturating_sub(4));
                    let v = [i32::MIN, -1, 0, 1, 54, 1 << 20, i32::MAX][r.below(7)];
                    if k + 4 <= b.len() {
                        b[k..k + 4].copy_from_slice(&v.to_le_bytes());
                    }
                }
                3 => {
                    let cut = r.below(b.len() + 1);
                    b.truncate(cut);
                }
                _ => {
                    let extra = r.below(16);
                    b.extend((0..extra).map(|_| r.next() as u8));
                    if r.below(2) == 0 && b.len() >= 4 {
                        let len = b.len() as i32;
                        b[..4].copy_from_slice(&len.to_le_bytes());
                    }
                }
            }
            match decode_packet(&b) {
                Ok(ms) => {
                    ok += 1;
                    assert_eq!(encode_packet(&ms).as_ref(), Ok(&b), "{b:02x?}");
                }
                Err(e) => *errs.entry(e.kind()).or_default() += 1,
            }
            let mut f = Framer::default();
            f.push(&b);
            let _ = f.next_packet();
        }
        let rejected: u64 = errs.values().sum();
        println!("{n} packets: {ok} decoded, {rejected} rejected {errs:?}");
        assert_eq!(ok + rejected, n);
        assert!(ok > 0 && rejected > 0);
    }
}
