//! Parsers of numeric flags: a negative or out-of-range value is refused with a message about the
//! flag (the flags accept leading `-`, so `--seed -1` reaches the parser instead of being taken
//! for another flag).

/// A run seed: any whole number `0..=2^64 - 1`.
pub fn seed(s: &str) -> Result<u64, String> {
    s.trim()
        .parse()
        .map_err(|_| format!("must be a whole number from 0 to {}, got '{s}'", u64::MAX))
}

/// A whole number in `lo..=hi`.
fn whole(s: &str, lo: u64, hi: u64) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        _ => Err(format!(
            "must be a whole number from {lo} to {hi}, got '{s}'"
        )),
    }
}

/// Worker threads: 1 to 256 (more threads than that would only compete for the cores).
pub fn jobs(s: &str) -> Result<usize, String> {
    whole(s, 1, 256).map(|v| v as usize)
}

/// Seeds per campaign group: 1 to 1,000,000.
pub fn seeds(s: &str) -> Result<u64, String> {
    whole(s, 1, plumetrace_campaign::spec::MAX_SEEDS)
}

/// Missions per thread count of a benchmark: 1 to 100,000.
pub fn runs(s: &str) -> Result<u64, String> {
    whole(s, 1, 100_000)
}

/// Sites drawn by `plumetrace family`: 1 to 10,000.
pub fn sample(s: &str) -> Result<u64, String> {
    whole(s, 1, 10_000)
}

/// A vehicle index: 0 to 99.
pub fn vehicle(s: &str) -> Result<u32, String> {
    whole(s, 0, 99).map(|v| v as u32)
}

/// A finite number (its range is checked where it is used).
pub fn number(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("must be a finite number, got '{s}'")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_table() {
        assert_eq!(seed("7"), Ok(7));
        assert!(seed("-1").is_err_and(|e| e.contains("whole number from 0")));
        assert!(jobs("0").is_err() && jobs("5000").is_err() && jobs("2") == Ok(2));
        assert!(seeds("0").is_err() && seeds("100000000").is_err());
        assert!(number("nan").is_err() && number("-2.5") == Ok(-2.5));
    }
}
