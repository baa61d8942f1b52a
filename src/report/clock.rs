//! Wall-clock time as text: UTC timestamps for manifests and for the names
//! of kept tables; and what the machine says about the time a benchmark
//! gets (the load average, a thread's own CPU time). No time-zone database is needed: the civil date follows
//! from the days since 1970-01-01 by the proleptic Gregorian calendar
//! (400-year cycles of 146 097 days, years from March so the leap day is
//! last).

use std::time::{SystemTime, UNIX_EPOCH};

/// `(year, month, day)` of the civil date `days` after 1970-01-01.
pub fn civil_from_days(days: i64) -> (i64, u32, u32) {
    // Shift the epoch to 0000-03-01 so each era (400 years) starts on a
    // March 1st: 719 468 days from 0000-03-01 to 1970-01-01.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097); // day of era, 0..=146096
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365; // 0..=399
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100); // day of the March-based year
    let mp = (5 * doy + 2) / 153; // month from March, 0..=11
    let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let year = yoe + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

/// Seconds since the Unix epoch (0 if the clock is before it).
pub fn unix_seconds(t: SystemTime) -> u64 {
    t.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs())
}

/// `2026-11-25T12:28:39Z` for `t`.
pub fn iso_utc(t: SystemTime) -> String {
    let s = unix_seconds(t) as i64;
    let (y, mo, d) = civil_from_days(s.div_euclid(86_400));
    let r = s.rem_euclid(86_400);
    format!(
        "{y:04}-{mo:02}-{d:02}T{:02}:{:02}:{:02}Z",
        r / 3600,
        (r / 60) % 60,
        r % 60
    )
}

/// `20261125T122839Z` for `t`: the same, safe in a file name.
pub fn compact_utc(t: SystemTime) -> String {
    iso_utc(t).replace(['-', ':'], "")
}

/// The 1-minute load average (Linux `/proc/loadavg`), if readable: other
/// processes distort wall-clock timings.
pub fn load_average() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// CPU time the calling thread has run so far \[s\] (Linux
/// `/proc/thread-self/schedstat`, nanoseconds on the CPU), if readable.
/// Unlike wall time it leaves out the time the thread waited while other
/// processes ran, so a benchmark on a busy machine still measures its own
/// work (cache and memory contention remain).
pub fn thread_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn known_dates() {
        // Epoch, a leap day, the day after a century non-leap February,
        // and 2000-03-01 (leap century): reference dates from the
        // Gregorian calendar (`date -u -d @<s>`).
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(11_017), (2000, 3, 1));
        assert_eq!(civil_from_days(-25_508), (1900, 3, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
        let t = UNIX_EPOCH + Duration::from_secs(1_795_696_119);
        assert_eq!(iso_utc(t), "2026-11-26T12:28:39Z");
        assert_eq!(compact_utc(t), "20261126T122839Z");
    }
}
