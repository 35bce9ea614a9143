//! The simulated time as UTC: a start date (an RFC 3339 UTC instant such as
//! `2024-06-01T12:00:00Z`) plus the simulated seconds, as the sentences write it (`hhmmss.ss`
//! and `ddmmyy`). Civil dates from day numbers by H. Hinnant's `civil_from_days` algorithm
//! ("chrono-Compatible Low-Level Date Algorithms"), proleptic Gregorian calendar, no leap
//! seconds (as NMEA time is written).

/// An instant in UTC: days since 1970-01-01 and seconds into that day.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Utc {
    /// Seconds since 1970-01-01T00:00:00Z.
    pub epoch: f64,
}

/// The date of day number `z` (days since 1970-01-01): (year, month 1-12, day 1-31).
pub fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (if m <= 2 { y + 1 } else { y }, m, d)
}

/// The day number of a date (the inverse of [`civil_from_days`]).
pub fn days_from_civil(y: i64, m: u32, d: u32) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y.rem_euclid(400);
    let m = i64::from(m);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(d) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

impl Utc {
    /// Parses `YYYY-MM-DDTHH:MM:SS[.fff]Z` (or a date alone, midnight).
    pub fn parse(text: &str) -> Result<Utc, String> {
        let bad = || format!("start date '{text}': expected YYYY-MM-DDTHH:MM:SSZ (UTC)");
        let t = text.trim();
        let (date, time) = match t.split_once(['T', ' ']) {
            Some((d, tm)) => (d, tm.strip_suffix('Z').ok_or_else(bad)?),
            None => (t, "00:00:00"),
        };
        let num = |s: &str| s.parse::<i64>().map_err(|_| bad());
        let d: Vec<&str> = date.split('-').collect();
        let tm: Vec<&str> = time.split(':').collect();
        if d.len() != 3 || tm.len() != 3 {
            return Err(bad());
        }
        let (y, mo, da) = (num(d[0])?, num(d[1])?, num(d[2])?);
        let (h, mi) = (num(tm[0])?, num(tm[1])?);
        let s: f64 = tm[2].parse().map_err(|_| bad())?;
        let valid = (1..=12).contains(&mo)
            && (1..=31).contains(&da)
            && (0..24).contains(&h)
            && (0..60).contains(&mi)
            && (0.0..60.0).contains(&s);
        if !valid {
            return Err(bad());
        }
        let days = days_from_civil(y, mo as u32, da as u32);
        if civil_from_days(days) != (y, mo as u32, da as u32) {
            return Err(bad());
        }
        Ok(Utc {
            epoch: days as f64 * 86_400.0 + (h * 3600 + mi * 60) as f64 + s,
        })
    }

    /// This instant plus `seconds`.
    pub fn plus(self, seconds: f64) -> Utc {
        Utc {
            epoch: self.epoch + seconds,
        }
    }

    /// (day number, hundredths of a second into the day), rounded to the hundredth.
    fn split(self) -> (i64, i64) {
        let cs = (self.epoch * 100.0).round() as i64;
        (cs.div_euclid(8_640_000), cs.rem_euclid(8_640_000))
    }

    /// `hhmmss.ss`.
    pub fn hhmmss(self) -> String {
        let (_, cs) = self.split();
        let (h, m) = (cs / 360_000, cs / 6000 % 60);
        format!("{h:02}{m:02}{:02}.{:02}", cs / 100 % 60, cs % 100)
    }

    /// `ddmmyy`.
    pub fn ddmmyy(self) -> String {
        let (y, m, d) = civil_from_days(self.split().0);
        format!("{d:02}{m:02}{:02}", y.rem_euclid(100))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_round_trip_and_known_days() {
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(2000, 3, 1), 11_017);
        assert_eq!(civil_from_days(19_723), (2024, 1, 1));
        for z in (-800_000..800_000).step_by(97) {
            let (y, m, d) = civil_from_days(z);
            assert_eq!(days_from_civil(y, m, d), z);
        }
    }

    #[test]
    fn nmea_time_fields() {
        let t = Utc::parse("2024-02-29T23:59:59Z").unwrap();
        assert_eq!(t.hhmmss(), "235959.00");
        assert_eq!(t.ddmmyy(), "290224");
        let u = t.plus(1.25);
        assert_eq!(
            (u.hhmmss().as_str(), u.ddmmyy().as_str()),
            ("000000.25", "010324")
        );
        // 1,700,000,000 s after the epoch: 2023-11-14T22:13:20Z.
        let v = Utc { epoch: 1.7e9 };
        assert_eq!(
            (v.hhmmss().as_str(), v.ddmmyy().as_str()),
            ("221320.00", "141123")
        );
        assert!(Utc::parse("2023-02-29T00:00:00Z").is_err());
        assert!(Utc::parse("2024-06-01T12:00:00").is_err());
        assert_eq!(Utc::parse("2024-06-01").unwrap().hhmmss(), "000000.00");
    }
}
