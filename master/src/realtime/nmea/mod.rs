//! NMEA 0183 (IEC 61162-1) sentences, in pure Rust: the frame `$TTSSS,f1,f2,...*HH<CR><LF>`
//! (talker TT, sentence SSS, the checksum HH the uppercase hex XOR of every byte between `$`
//! and `*`), the encoders of what a ship sends ([`encode`]: HDT, THS, ROT, RSA, HDG, GGA, RMC,
//! VTG, VHW, MWV), the parsers of the commands it takes ([`parse`]: HTC, HTD, ROR, APB, RMB),
//! the datum that maps the hull's north/east position onto WGS-84 ([`datum`]) and the
//! simulated time as UTC ([`utc`]).
//!
//! The field layouts follow IEC 61162-1 as the equipment manuals that reproduce it give them
//! (HTC/HTD: the Radio Holland RHRS-2014 manual, appendix 2, and the Furuno VR-3000 manual;
//! THS and ROT: the JRC JLN-720 manual, ch. 9) and, for the GPS and autopilot sentences, Eric
//! S. Raymond's "NMEA Revealed" (gpsd's documentation, <https://gpsd.gitlab.io/gpsd/NMEA.html>).
//! Each encoder and parser cites its layout field by field; the unit tests check them.
//!
//! Nothing here panics on input: a parser returns a classified [`Reject`].

pub mod datum;
pub mod encode;
pub mod parse;
pub mod utc;

pub use parse::{parse_sentence, Command, Field, Reject};

/// The longest sentence IEC 61162-1 allows: 82 characters from `$` to `<LF>`.
pub const MAX_SENTENCE: usize = 82;

/// The checksum of a sentence's body (the bytes between `$` and `*`): their XOR.
pub fn checksum(body: &[u8]) -> u8 {
    body.iter().fold(0, |c, b| c ^ b)
}

/// Appends one sentence `$` + `body` + `*HH\r\n` to `out` (body: `TTSSS,f1,...`).
pub fn frame(out: &mut String, body: &str) {
    use std::fmt::Write;
    let _ = write!(out, "${body}*{:02X}\r\n", checksum(body.as_bytes()));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checksum of a sentence from gpsd's "NMEA Revealed" (its GGA example) and the
    /// manuals' HDT example (`$RCHDT,335.2,T*34`, NAVIS NavDP 4000 manual).
    #[test]
    fn checksums_of_published_examples() {
        let body = "GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,";
        assert_eq!(checksum(body.as_bytes()), 0x47);
        let mut s = String::new();
        frame(&mut s, "RCHDT,335.2,T");
        assert_eq!(s, "$RCHDT,335.2,T*34\r\n");
    }
}
