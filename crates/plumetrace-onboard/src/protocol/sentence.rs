//! The line rule every front-seat protocol here shares: `$`, comma-separated fields, `*`, the
//! checksum (XOR of every byte strictly between `$` and `*`, two upper-case hex digits), `\r\n`.
//!
//! [`frame`] writes a line from its body; [`Fields::parse`] checks a received line and splits its
//! body. Field readers ([`Fields::f64`], [`Fields::int`], ...) turn a bad field into a
//! [`SentenceError`] that names the sentence, the field and its text, so a codec never panics on
//! what a link delivers.

use std::fmt;

/// Longest line accepted, bytes (the sentences here are well under it).
pub const MAX_LINE: usize = 512;

/// Why a received line was not accepted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SentenceError {
    /// Nothing but white space.
    #[error("empty line")]
    Empty,
    /// Longer than [`MAX_LINE`].
    #[error("line of {0} bytes is longer than {MAX_LINE}")]
    TooLong(usize),
    /// A byte outside printable ASCII.
    #[error("byte 0x{0:02X} is not printable ASCII")]
    NotAscii(u8),
    /// The line does not start with `$`.
    #[error("the line does not start with '$'")]
    NoDollar,
    /// No `*hh` checksum at the end.
    #[error("no '*hh' checksum at the end")]
    NoChecksum,
    /// The checksum does not match the body.
    #[error("checksum {found} does not match the body's {expected:02X}")]
    BadChecksum {
        /// What the body gives.
        expected: u8,
        /// What the line says.
        found: String,
    },
    /// A sentence id this codec does not read.
    #[error("unknown sentence '{0}'")]
    Unknown(String),
    /// Too few or too many fields.
    #[error("{id}: {found} fields, expected {expected}")]
    FieldCount {
        /// Sentence id.
        id: &'static str,
        /// What the sentence needs (e.g. `12` or `at least 15`).
        expected: String,
        /// What the line has.
        found: usize,
    },
    /// A field that does not parse.
    #[error("{id}: field {index} ({name}) '{text}' is not {what}")]
    BadField {
        /// Sentence id.
        id: &'static str,
        /// 1-based field index after the id.
        index: usize,
        /// The field's name.
        name: &'static str,
        /// The text received.
        text: String,
        /// What was expected.
        what: &'static str,
    },
    /// A field that parses but is out of its range.
    #[error("{id}: {name} = {value} is outside {range}")]
    OutOfRange {
        /// Sentence id.
        id: &'static str,
        /// The field's name.
        name: &'static str,
        /// The value received.
        value: f64,
        /// The accepted range.
        range: &'static str,
    },
}

impl SentenceError {
    /// A short name of the kind of error, for counts.
    pub fn kind(&self) -> &'static str {
        match self {
            SentenceError::Empty => "empty",
            SentenceError::TooLong(_) => "too_long",
            SentenceError::NotAscii(_) => "not_ascii",
            SentenceError::NoDollar => "no_dollar",
            SentenceError::NoChecksum => "no_checksum",
            SentenceError::BadChecksum { .. } => "bad_checksum",
            SentenceError::Unknown(_) => "unknown",
            SentenceError::FieldCount { .. } => "field_count",
            SentenceError::BadField { .. } => "bad_field",
            SentenceError::OutOfRange { .. } => "out_of_range",
        }
    }
}

/// Lines accepted and rejected, by kind of error: what a link reports and logs.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct LineCounts {
    /// Lines accepted.
    pub accepted: u64,
    /// Lines rejected, by [`SentenceError::kind`].
    pub rejected: std::collections::BTreeMap<&'static str, u64>,
}

impl LineCounts {
    /// Counts one line's fate.
    pub fn count<T>(&mut self, r: &Result<T, SentenceError>) {
        match r {
            Ok(_) => self.accepted += 1,
            Err(e) => *self.rejected.entry(e.kind()).or_default() += 1,
        }
    }

    /// Lines rejected in all.
    pub fn rejected_total(&self) -> u64 {
        self.rejected.values().sum()
    }
}

/// XOR of the bytes of `body` (the part between `$` and `*`).
pub fn checksum(body: &[u8]) -> u8 {
    body.iter().fold(0, |a, b| a ^ b)
}

/// The full line for `body`: `$body*HH\r\n`.
pub fn frame(body: &str) -> String {
    format!("${body}*{:02X}\r\n", checksum(body.as_bytes()))
}

/// Text for a free-text field: the characters that would break the framing (`$`, `*`, `,`,
/// control characters, non-ASCII) become `_`.
pub fn clean_text(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_graphic() && !matches!(c, '$' | '*' | ',') || c == ' ' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A checked line's body split into its id and fields.
#[derive(Debug, Clone, PartialEq)]
pub struct Fields<'a> {
    /// The sentence id (`BFNVG`, `OSI`, ...).
    pub id: &'a str,
    fields: Vec<&'a str>,
}

impl<'a> Fields<'a> {
    /// Checks the framing and checksum of `line` (trailing `\r\n` optional) and splits it.
    pub fn parse(line: &'a str) -> Result<Self, SentenceError> {
        let body = checked_body(line)?;
        let mut parts = body.split(',');
        let id = parts.next().unwrap_or_default();
        Ok(Fields {
            id,
            fields: parts.collect(),
        })
    }

    /// Number of fields after the id.
    pub fn len(&self) -> usize {
        self.fields.len()
    }

    /// Whether there are no fields after the id.
    pub fn is_empty(&self) -> bool {
        self.fields.is_empty()
    }

    /// Fails unless there are exactly `n` fields.
    pub fn expect_len(&self, id: &'static str, n: usize) -> Result<(), SentenceError> {
        if self.fields.len() == n {
            Ok(())
        } else {
            Err(SentenceError::FieldCount {
                id,
                expected: n.to_string(),
                found: self.fields.len(),
            })
        }
    }

    /// Fails unless there are at least `n` fields.
    pub fn expect_at_least(&self, id: &'static str, n: usize) -> Result<(), SentenceError> {
        if self.fields.len() >= n {
            Ok(())
        } else {
            Err(SentenceError::FieldCount {
                id,
                expected: format!("at least {n}"),
                found: self.fields.len(),
            })
        }
    }

    /// Field `index` (1-based after the id) as text; empty when missing.
    pub fn text(&self, index: usize) -> &'a str {
        index
            .checked_sub(1)
            .and_then(|k| self.fields.get(k))
            .copied()
            .unwrap_or("")
    }

    fn bad(
        &self,
        id: &'static str,
        index: usize,
        name: &'static str,
        what: &'static str,
    ) -> SentenceError {
        SentenceError::BadField {
            id,
            index,
            name,
            text: self.text(index).to_string(),
            what,
        }
    }

    /// Field `index` as a finite number within `range` (inclusive).
    pub fn f64(
        &self,
        id: &'static str,
        index: usize,
        name: &'static str,
        range: Range,
    ) -> Result<f64, SentenceError> {
        let t = self.text(index);
        let v: f64 = plain_number(t)
            .then(|| t.parse().ok())
            .flatten()
            .ok_or_else(|| self.bad(id, index, name, "a number"))?;
        range.check(id, name, v)
    }

    /// Field `index` as a number, or `None` when empty.
    pub fn opt_f64(
        &self,
        id: &'static str,
        index: usize,
        name: &'static str,
        range: Range,
    ) -> Result<Option<f64>, SentenceError> {
        if self.text(index).is_empty() {
            Ok(None)
        } else {
            self.f64(id, index, name, range).map(Some)
        }
    }

    /// Field `index` as a non-negative integer no larger than `max`.
    pub fn int(
        &self,
        id: &'static str,
        index: usize,
        name: &'static str,
        max: u32,
    ) -> Result<u32, SentenceError> {
        let t = self.text(index);
        let v: u32 = (!t.is_empty() && t.len() <= 9 && t.bytes().all(|b| b.is_ascii_digit()))
            .then(|| t.parse().ok())
            .flatten()
            .ok_or_else(|| self.bad(id, index, name, "a non-negative integer"))?;
        if v > max {
            return Err(SentenceError::OutOfRange {
                id,
                name,
                value: f64::from(v),
                range: "its allowed codes",
            });
        }
        Ok(v)
    }

    /// Field `index` as one of `allowed` (exact text).
    pub fn one_of(
        &self,
        id: &'static str,
        index: usize,
        name: &'static str,
        allowed: &[&'static str],
    ) -> Result<usize, SentenceError> {
        let t = self.text(index);
        allowed
            .iter()
            .position(|a| *a == t)
            .ok_or_else(|| self.bad(id, index, name, "one of its allowed codes"))
    }

    /// Field `index` as a UTC time of day `hhmmss.sss`.
    pub fn time(
        &self,
        id: &'static str,
        index: usize,
        name: &'static str,
    ) -> Result<UtcTime, SentenceError> {
        UtcTime::parse(self.text(index))
            .ok_or_else(|| self.bad(id, index, name, "a time hhmmss.sss"))
    }

    /// Field `index` and the hemisphere letter after it as signed degrees: `ddmm.mmmm,N|S`
    /// (`lon = false`) or `dddmm.mmmm,E|W` (`lon = true`).
    pub fn deg_min(
        &self,
        id: &'static str,
        index: usize,
        name: &'static str,
        lon: bool,
    ) -> Result<f64, SentenceError> {
        let t = self.text(index);
        let split = if lon { 3 } else { 2 };
        let bad = || self.bad(id, index, name, "degrees and minutes (d)ddmm.mmmm");
        let dot = t.find('.').unwrap_or(t.len());
        if dot != split + 2 || !plain_number(t) || t.starts_with(['-', '+']) {
            return Err(bad());
        }
        let deg: f64 = t[..split].parse().map_err(|_| bad())?;
        let min: f64 = t[split..].parse().map_err(|_| bad())?;
        if min >= 60.0 {
            return Err(bad());
        }
        let value = deg + min / 60.0;
        let (pos, neg) = if lon { ("E", "W") } else { ("N", "S") };
        let sign = match self.text(index + 1) {
            s if s == pos => 1.0,
            s if s == neg => -1.0,
            _ => {
                return Err(self.bad(
                    id,
                    index + 1,
                    "hemisphere",
                    if lon { "E or W" } else { "N or S" },
                ));
            }
        };
        let limit = if lon { 180.0 } else { 90.0 };
        Range::new(
            -limit,
            limit,
            if lon {
                "[-180, 180] deg"
            } else {
                "[-90, 90] deg"
            },
        )
        .check(id, name, sign * value)
    }
}

/// The body of a line whose framing and checksum are right.
fn checked_body(line: &str) -> Result<&str, SentenceError> {
    let line = line.strip_suffix('\n').unwrap_or(line);
    let line = line.strip_suffix('\r').unwrap_or(line);
    if line.trim().is_empty() {
        return Err(SentenceError::Empty);
    }
    if line.len() > MAX_LINE {
        return Err(SentenceError::TooLong(line.len()));
    }
    if let Some(b) = line.bytes().find(|b| !(0x20..0x7f).contains(b)) {
        return Err(SentenceError::NotAscii(b));
    }
    let rest = line.strip_prefix('$').ok_or(SentenceError::NoDollar)?;
    let star = rest.rfind('*').ok_or(SentenceError::NoChecksum)?;
    let (body, sum) = (&rest[..star], &rest[star + 1..]);
    let expected = checksum(body.as_bytes());
    let well_formed = sum.len() == 2
        && sum
            .bytes()
            .all(|b| b.is_ascii_digit() || (b'A'..=b'F').contains(&b));
    if !well_formed {
        return Err(if sum.is_empty() {
            SentenceError::NoChecksum
        } else {
            SentenceError::BadChecksum {
                expected,
                found: sum.to_string(),
            }
        });
    }
    if u8::from_str_radix(sum, 16).ok() != Some(expected) {
        return Err(SentenceError::BadChecksum {
            expected,
            found: sum.to_string(),
        });
    }
    if body.contains(['$', '*']) {
        return Err(SentenceError::NoDollar);
    }
    Ok(body)
}

/// Whether `t` is a plain decimal number (sign, digits, at most one point): no exponent, no
/// `inf`/`nan` words, which `str::parse` would take.
fn plain_number(t: &str) -> bool {
    let digits = t.strip_prefix(['-', '+']).unwrap_or(t);
    !digits.is_empty()
        && digits.len() <= 24
        && digits.bytes().all(|b| b.is_ascii_digit() || b == b'.')
        && digits.bytes().filter(|b| *b == b'.').count() <= 1
        && digits.bytes().any(|b| b.is_ascii_digit())
}

/// An inclusive range a field must lie in, with its text for errors.
#[derive(Debug, Clone, Copy)]
pub struct Range {
    lo: f64,
    hi: f64,
    text: &'static str,
}

impl Range {
    /// `[lo, hi]`, written as `text` in errors.
    pub const fn new(lo: f64, hi: f64, text: &'static str) -> Self {
        Range { lo, hi, text }
    }

    /// `v` when it is finite and within the range; otherwise the error naming it.
    pub fn check(self, id: &'static str, name: &'static str, v: f64) -> Result<f64, SentenceError> {
        if v.is_finite() && v >= self.lo && v <= self.hi {
            Ok(v)
        } else {
            Err(SentenceError::OutOfRange {
                id,
                name,
                value: v,
                range: self.text,
            })
        }
    }
}

/// A heading or course: `[0, 360]` deg.
pub const HEADING: Range = Range::new(0.0, 360.0, "[0, 360] deg");
/// An angle that may be signed: `[-360, 360]` deg.
pub const ANGLE: Range = Range::new(-360.0, 360.0, "[-360, 360] deg");
/// A depth or altitude: `[-100, 12000]` m (slightly negative depths occur at the surface).
pub const DEPTH: Range = Range::new(-100.0, 12_000.0, "[-100, 12000]");
/// A speed or velocity component: `[-50, 50]` (m/s or knots).
pub const SPEED: Range = Range::new(-50.0, 50.0, "[-50, 50]");
/// A rate: `[-1000, 1000]` per s.
pub const RATE: Range = Range::new(-1000.0, 1000.0, "[-1000, 1000]");
/// A chemical reading: `[-1e6, 1e9]` in the sensor's unit (wide enough for any instrument's
/// scale, slightly negative offsets included; a reading beyond it is a corrupted number).
pub const READING: Range = Range::new(-1e6, 1e9, "[-1e6, 1e9]");
/// Anything finite.
pub const ANY: Range = Range::new(f64::MIN, f64::MAX, "the finite numbers");

/// A UTC time of day with millisecond resolution, as the sentences write it (`hhmmss.sss`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct UtcTime {
    /// Milliseconds since midnight, `< 86_400_000`.
    ms: u32,
}

impl UtcTime {
    /// Milliseconds in a day.
    pub const DAY_MS: u32 = 86_400_000;

    /// The time `s` seconds after midnight (wrapped into the day, rounded to the millisecond).
    pub fn from_seconds(s: f64) -> Self {
        let ms = if s.is_finite() {
            (s * 1000.0).round()
        } else {
            0.0
        };
        UtcTime {
            ms: ms.rem_euclid(f64::from(Self::DAY_MS)) as u32,
        }
    }

    /// Seconds since midnight.
    pub fn seconds(self) -> f64 {
        f64::from(self.ms) / 1000.0
    }

    /// Milliseconds since midnight.
    pub fn ms(self) -> u32 {
        self.ms
    }

    /// Seconds from `earlier` to `self`, taking a midnight between them into account (the
    /// result is in `[0, 86400)`).
    pub fn since(self, earlier: UtcTime) -> f64 {
        let d = (i64::from(self.ms) - i64::from(earlier.ms)).rem_euclid(i64::from(Self::DAY_MS));
        d as f64 / 1000.0
    }

    /// Milliseconds from `earlier` to `self` the short way round the day: in
    /// `[-43_200_000, 43_200_000)`, so a time stamped just before `earlier` is behind it, not a
    /// day ahead.
    pub fn offset_ms_from(self, earlier: UtcTime) -> i64 {
        let half = i64::from(Self::DAY_MS / 2);
        (i64::from(self.ms) - i64::from(earlier.ms) + half).rem_euclid(i64::from(Self::DAY_MS))
            - half
    }

    /// Reads `hhmmss` with an optional fraction (rounded to the millisecond).
    pub fn parse(t: &str) -> Option<Self> {
        let (whole, frac) = t.split_once('.').unwrap_or((t, ""));
        if whole.len() != 6 || !whole.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        if frac.len() > 9 || !frac.bytes().all(|b| b.is_ascii_digit()) {
            return None;
        }
        let n = |a: usize| whole[a..a + 2].parse::<u32>().ok();
        let (h, m, s) = (n(0)?, n(2)?, n(4)?);
        if h > 23 || m > 59 || s > 59 {
            return None;
        }
        let mut ms = 0u32;
        for (k, b) in frac.bytes().take(4).enumerate() {
            let d = u32::from(b - b'0');
            match k {
                0 => ms += 100 * d,
                1 => ms += 10 * d,
                2 => ms += d,
                _ => ms += u32::from(d >= 5),
            }
        }
        Some(UtcTime {
            ms: ((h * 3600 + m * 60 + s) * 1000 + ms) % Self::DAY_MS,
        })
    }
}

impl fmt::Display for UtcTime {
    /// `hhmmss.sss`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.ms / 1000;
        write!(
            f,
            "{:02}{:02}{:02}.{:03}",
            s / 3600,
            s / 60 % 60,
            s % 60,
            self.ms % 1000
        )
    }
}

/// Degrees as `ddmm.mmmm,H` (latitude, `lon = false`) or `dddmm.mmmm,H` (longitude), the
/// minutes rounded to four decimals.
pub fn write_deg_min(deg: f64, lon: bool) -> String {
    let units = (deg.abs() * 600_000.0).round() as u64;
    let (d, rem) = (units / 600_000, units % 600_000);
    let hemi = match (lon, deg < 0.0 && units > 0) {
        (false, false) => 'N',
        (false, true) => 'S',
        (true, false) => 'E',
        (true, true) => 'W',
    };
    if lon {
        format!("{d:03}{:02}.{:04},{hemi}", rem / 10_000, rem % 10_000)
    } else {
        format!("{d:02}{:02}.{:04},{hemi}", rem / 10_000, rem % 10_000)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_checksums_come_out() {
        let gga = "GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,";
        assert_eq!(checksum(gga.as_bytes()), 0x47);
        assert_eq!(checksum(b"C82.8P-3.89R-2.63T20.3D3.2"), 0x78);
        assert_eq!(frame("BPLOG,NVG,ON"), "$BPLOG,NVG,ON*08\r\n");
    }

    #[test]
    fn framing_errors_are_typed() {
        type Check = fn(&SentenceError) -> bool;
        let cases: &[(&str, Check)] = &[
            ("", |e| matches!(e, SentenceError::Empty)),
            ("BPLOG,NVG,ON*08", |e| matches!(e, SentenceError::NoDollar)),
            ("$BPLOG,NVG,ON", |e| matches!(e, SentenceError::NoChecksum)),
            ("$BPLOG,NVG,ON*", |e| matches!(e, SentenceError::NoChecksum)),
            ("$BPLOG,NVG,ON*09", |e| {
                matches!(e, SentenceError::BadChecksum { expected: 8, .. })
            }),
            ("$BPLOG,NVG,ON*08x", |e| {
                matches!(e, SentenceError::BadChecksum { .. })
            }),
            ("$BPLOG,NVG,ON*0a", |e| {
                matches!(e, SentenceError::BadChecksum { .. })
            }),
            ("$BPLOG,NV\u{e9},ON*08", |e| {
                matches!(e, SentenceError::NotAscii(_))
            }),
        ];
        for (line, ok) in cases {
            let e = Fields::parse(line).err();
            assert!(e.as_ref().is_some_and(ok), "{line:?}: {e:?}");
        }
        let long = frame(&"X".repeat(MAX_LINE));
        assert!(matches!(
            Fields::parse(&long),
            Err(SentenceError::TooLong(_))
        ));
    }

    #[test]
    fn times_read_and_write_to_the_millisecond() {
        let cases = [
            ("120000.000", 43_200_000),
            ("000000", 0),
            ("235959.999", 86_399_999),
            ("010203.4", 3_723_400),
            ("010203.12345", 3_723_123),
        ];
        for (text, ms) in cases {
            assert_eq!(UtcTime::parse(text).map(UtcTime::ms), Some(ms), "{text}");
        }
        for bad in [
            "",
            "240000.000",
            "126000",
            "12000.000",
            "120000.-1",
            "12000a.000",
            "120000.0000000000",
        ] {
            assert_eq!(UtcTime::parse(bad), None, "{bad}");
        }
        assert_eq!(UtcTime::from_seconds(43_200.0).to_string(), "120000.000");
        assert_eq!(UtcTime::from_seconds(86_400.5).to_string(), "000000.500");
        let late = UtcTime::from_seconds(86_399.0);
        assert_eq!(
            UtcTime::from_seconds(1.0).since(late),
            2.0,
            "across midnight"
        );
    }

    #[test]
    fn degrees_and_minutes_round_trip() {
        assert_eq!(write_deg_min(32.0 + 42.1234 / 60.0, false), "3242.1234,N");
        assert_eq!(
            write_deg_min(-(117.0 + 10.5678 / 60.0), true),
            "11710.5678,W"
        );
        assert_eq!(write_deg_min(-0.0, true), "00000.0000,E");
        assert_eq!(
            write_deg_min(10.999_999_999, false),
            "1100.0000,N",
            "no 60 minutes"
        );
        let f = Fields::parse("$X,3242.1234,N,11710.5678,W*00").err();
        assert!(matches!(f, Some(SentenceError::BadChecksum { .. })));
        let body = "X,3242.1234,N,11710.5678,W,4260.0000,N";
        let line = frame(body);
        let f = Fields::parse(&line).unwrap_or_else(|e| panic!("{e}"));
        let lat = f.deg_min("X", 1, "lat", false).unwrap_or(f64::NAN);
        assert!((lat - (32.0 + 42.1234 / 60.0)).abs() < 1e-12);
        let lon = f.deg_min("X", 3, "lon", true).unwrap_or(f64::NAN);
        assert!((lon + 117.0 + 10.5678 / 60.0).abs() < 1e-12);
        assert!(f.deg_min("X", 5, "lat", false).is_err(), "60 minutes");
        assert!(
            f.deg_min("X", 1, "lon", true).is_err(),
            "a latitude is not a longitude"
        );
    }

    #[test]
    fn numbers_are_plain_decimals() {
        let line = frame("X,1.5,-2,inf,NaN,1e3,,+0.25,1.2.3");
        let f = Fields::parse(&line).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(f.f64("X", 1, "a", ANY).ok(), Some(1.5));
        assert_eq!(f.f64("X", 2, "a", ANY).ok(), Some(-2.0));
        for k in [3, 4, 5, 6, 8, 9] {
            assert!(f.f64("X", k, "a", ANY).is_err(), "field {k}");
        }
        assert_eq!(f.f64("X", 7, "a", ANY).ok(), Some(0.25));
        assert!(matches!(
            f.f64("X", 1, "a", Range::new(0.0, 1.0, "[0, 1]")),
            Err(SentenceError::OutOfRange { .. })
        ));
    }
}
