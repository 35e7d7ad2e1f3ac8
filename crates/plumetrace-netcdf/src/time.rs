//! CF time: units such as `hours since 2026-03-01 06:00:00` and dates such as
//! `2026-03-01T06:00:00Z`, as seconds since 1970-01-01 00:00:00 UTC in the proleptic Gregorian
//! calendar (CF's `standard` calendar after 1582, which is what ocean models write).

/// Why a time unit or date cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TimeError {
    /// The units are not `<unit> since <date>`.
    #[error(
        "time units {0:?} are not \"<seconds|minutes|hours|days> since <date>\" (CF time units)"
    )]
    Units(String),
    /// The date cannot be read.
    #[error("{0:?} is not a date (YYYY-MM-DD, optionally followed by hh:mm:ss, UTC)")]
    Date(String),
}

/// A time unit: seconds per unit and its reference date, seconds since 1970-01-01 UTC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeUnits {
    /// Seconds per unit.
    pub scale_s: f64,
    /// The reference date, seconds since 1970-01-01 00:00:00 UTC.
    pub epoch_s: f64,
}

impl TimeUnits {
    /// Reads CF time units: `seconds`, `minutes`, `hours` or `days` (or their abbreviations)
    /// `since` a date.
    pub fn parse(units: &str) -> Result<Self, TimeError> {
        let bad = || TimeError::Units(units.to_string());
        let lower = units.trim().to_ascii_lowercase();
        let (unit, date) = lower.split_once(" since ").ok_or_else(bad)?;
        let scale_s = match unit.trim() {
            "seconds" | "second" | "secs" | "sec" | "s" => 1.0,
            "minutes" | "minute" | "mins" | "min" => 60.0,
            "hours" | "hour" | "hrs" | "hr" | "h" => 3600.0,
            "days" | "day" | "d" => 86_400.0,
            _ => return Err(bad()),
        };
        let epoch_s = parse_date(date).map_err(|_| bad())?;
        Ok(TimeUnits { scale_s, epoch_s })
    }

    /// Seconds since 1970 of a value in these units.
    pub fn to_epoch_s(&self, value: f64) -> f64 {
        self.epoch_s + value * self.scale_s
    }
}

/// Seconds since 1970-01-01 00:00:00 UTC of a date: `YYYY-MM-DD`, then optionally `T` or a space
/// and `hh:mm[:ss[.fff]]`, then optionally `Z`, `UTC` or a zero offset (`+00:00`, `+0`).
pub fn parse_date(text: &str) -> Result<f64, TimeError> {
    let bad = || TimeError::Date(text.to_string());
    let s = text.trim();
    let (date, rest) = match s.find(['T', 't', ' ']) {
        Some(k) => (&s[..k], s[k + 1..].trim()),
        None => (s, ""),
    };
    let mut ymd = date.splitn(3, '-');
    let num = |p: Option<&str>| p.and_then(|p| p.trim().parse::<i64>().ok()).ok_or_else(bad);
    let (y, m, d) = (num(ymd.next())?, num(ymd.next())?, num(ymd.next())?);
    if !(1..=12).contains(&m) || d < 1 || d > days_in_month(y, m) || !(-9999..=9999).contains(&y) {
        return Err(bad());
    }
    let mut clock = rest;
    for zone in ["utc", "z", "+00:00", "+0000", "+00", "+0", "-00:00"] {
        if clock.to_ascii_lowercase().ends_with(zone) {
            clock = clock[..clock.len() - zone.len()].trim();
            break;
        }
    }
    let mut secs = 0.0;
    if !clock.is_empty() {
        let mut hms = clock.splitn(3, ':');
        let h = num(hms.next())?;
        let mi = num(hms.next())?;
        let sec: f64 = match hms.next() {
            Some(p) => p.trim().parse().map_err(|_| bad())?,
            None => 0.0,
        };
        if !(0..=23).contains(&h) || !(0..=59).contains(&mi) || !(0.0..61.0).contains(&sec) {
            return Err(bad());
        }
        secs = (h * 3600 + mi * 60) as f64 + sec;
    }
    Ok(days_from_civil(y, m, d) as f64 * 86_400.0 + secs)
}

fn days_in_month(y: i64, m: i64) -> i64 {
    match m {
        2 if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Days since 1970-01-01 of a proleptic Gregorian date (Howard Hinnant's algorithm).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_count_seconds_from_1970() {
        let cases = [
            ("1970-01-01", 0.0),
            ("1970-01-02 00:00:00", 86_400.0),
            ("2000-03-01T00:00:00Z", 951_868_800.0),
            ("2026-03-01 06:30:15", 1_772_346_615.0),
            ("1950-01-01", -631_152_000.0),
            ("2024-02-29T12:00", 1_709_208_000.0),
        ];
        for (text, want) in cases {
            assert_eq!(parse_date(text), Ok(want), "{text}");
        }
        for bad in [
            "2026-13-01",
            "2025-02-29",
            "yesterday",
            "2026-03-01 25:00",
            "",
        ] {
            assert!(parse_date(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn cf_units_scale_and_shift() {
        let u = TimeUnits::parse("hours since 1970-01-01 00:00:00").unwrap();
        assert_eq!(u.to_epoch_s(2.0), 7200.0);
        let u = TimeUnits::parse("days since 1950-01-01").unwrap();
        assert_eq!(u.to_epoch_s(1.0), -631_152_000.0 + 86_400.0);
        let e = TimeUnits::parse("m s-1").unwrap_err().to_string();
        assert!(e.contains("CF time units"), "{e}");
    }
}
