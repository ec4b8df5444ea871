//! A latency bound a robot expert states on a service implemented by a task
//! graph (`<Latency from="camera" to="wheels" max="50 MSEC"/>` inside a
//! `<Service graph="…">`): the longest time allowed from a task of the
//! graph's top level starting an iteration (a sensor's sample) to the task
//! it causes completing it (an actuator's command). The dataflow warnings
//! of missions (`crate::dataflow`) compare it with the graph's latency.
//!
//! The time is read exactly: `max` is a positive number (whole or with a
//! decimal fraction) and one of the units missions write (`MSEC`, `SEC`,
//! `MIN`, `HOUR`), kept as a fraction of milliseconds, the unit the
//! execution times of catalog service graphs count, so that no rounding
//! decides whether a bound holds.

use crate::span::Span;
use crate::syntax::ast::TimeUnit;

/// One stated bound.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LatencyBound {
    /// The source task's name and where it is written (the `from` value).
    pub from: (String, Span),
    /// The sink task's name and where it is written (the `to` value).
    pub to: (String, Span),
    pub max: BoundTime,
    /// The `<Latency>` element's start tag.
    pub span: Span,
}

/// A bound's time, exactly: `num / den` milliseconds, as written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoundTime {
    pub num: u64,
    pub den: u64,
    /// What the file says (`50 MSEC`), for messages.
    pub written: String,
}

/// Digits a number may have on either side of its point: enough for every
/// bound anyone states, few enough that no product below overflows 64 bits
/// (10^9 × 3.6·10^6 milliseconds per hour < 2^64).
const MAX_DIGITS: usize = 9;

/// Reads `N UNIT` (`50 MSEC`, `0.5 SEC`); why not, in words, otherwise.
pub fn parse_time(text: &str) -> Result<BoundTime, String> {
    let mut words = text.split_whitespace();
    let (Some(amount), Some(unit), None) = (words.next(), words.next(), words.next()) else {
        return Err(format!(
            "`max` must be a positive number and a unit (MSEC, SEC, MIN or HOUR), like \"50 MSEC\", not `{text}`"
        ));
    };
    let Some(unit) = TimeUnit::parse(unit) else {
        return Err(format!(
            "`{unit}` is not a unit of time: write MSEC, SEC, MIN or HOUR (\"50 MSEC\")"
        ));
    };
    let (whole, fraction) = amount.split_once('.').unwrap_or((amount, ""));
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if whole.len() + fraction.len() == 0 || !digits(whole) || !digits(fraction) {
        return Err(format!(
            "`max` must be a positive number (like 50 or 0.5), not `{amount}`"
        ));
    }
    if whole.len() > MAX_DIGITS || fraction.len() > MAX_DIGITS {
        return Err(format!(
            "`{amount}` has more than {MAX_DIGITS} digits before or after its point"
        ));
    }
    // Both parts have at most 9 digits: `value` < 10^18 and `den` ≤ 10^9.
    let den = 10u64.pow(u32::try_from(fraction.len()).unwrap_or(0));
    let parse = |s: &str| {
        if s.is_empty() {
            0
        } else {
            s.parse::<u64>().unwrap_or(0)
        }
    };
    let value = parse(whole) * den + parse(fraction);
    if value == 0 {
        return Err("`max` must be more than 0".to_string());
    }
    let num = u128::from(value) * u128::from(unit.whole_millis());
    let g = gcd(num, u128::from(den));
    Ok(BoundTime {
        num: u64::try_from(num / g).map_err(|_| format!("`{amount}` is too large"))?,
        den: u64::try_from(u128::from(den) / g).unwrap_or(1),
        written: format!("{amount} {}", unit.as_str()),
    })
}

fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a.max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(text: &str) -> (u64, u64) {
        let t = parse_time(text).unwrap();
        (t.num, t.den)
    }

    #[test]
    fn times_are_read_exactly_in_milliseconds() {
        assert_eq!(ms("50 MSEC"), (50, 1));
        assert_eq!(ms("50 msec"), (50, 1));
        assert_eq!(ms("0.5 SEC"), (500, 1));
        assert_eq!(ms("0.0005 SEC"), (1, 2));
        assert_eq!(ms("2.25 MSEC"), (9, 4));
        assert_eq!(ms("1 HOUR"), (3_600_000, 1));
        assert_eq!(ms("  3   MIN "), (180_000, 1));
        assert_eq!(parse_time("0.5 SEC").unwrap().written, "0.5 SEC");
        assert_eq!(ms("999999999.999999999 HOUR").1, 2_500);
    }

    #[test]
    fn bad_times_say_why() {
        for (text, why) in [
            ("50", "a positive number and a unit"),
            ("50ms", "a positive number and a unit"),
            ("50 ms 3", "a positive number and a unit"),
            ("50 FORTNIGHT", "is not a unit of time"),
            ("-5 MSEC", "a positive number (like 50 or 0.5), not `-5`"),
            ("1e3 MSEC", "a positive number"),
            (". MSEC", "a positive number"),
            ("0 MSEC", "more than 0"),
            ("0.000 SEC", "more than 0"),
            ("1234567890 MSEC", "more than 9 digits"),
            ("", "a positive number and a unit"),
        ] {
            let found = parse_time(text).unwrap_err();
            assert!(found.contains(why), "{text}: {found}");
        }
    }
}
