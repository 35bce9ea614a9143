//! The parsers field by field, on sentences framed here (so each checksum is right unless a
//! test spoils it) and on published examples.

use super::*;
use crate::realtime::nmea::frame;

fn framed(body: &str) -> Vec<u8> {
    let mut s = String::new();
    frame(&mut s, body);
    s.into_bytes()
}

fn ok(body: &str) -> Command {
    parse_sentence(&framed(body)).unwrap_or_else(|e| panic!("{body}: {e}"))
}

fn kind(body: &str) -> &'static str {
    parse_sentence(&framed(body)).unwrap_err().kind()
}

#[test]
fn htc_heading_control_with_null_rudder_fields() {
    // Override off, no rudder order, heading control, turn not controlled, rudder limit 20,
    // heading to steer 123.4 true.
    let c = ok("APHTC,V,,,H,N,20.0,,,,123.4,,,T");
    assert_eq!(c.sentence, "HTC");
    assert_eq!(c.get(Field::HeadingToSteer), Some(123.4));
    assert_eq!(c.get(Field::SteeringMode), Some(2.0));
    assert_eq!(c.get(Field::Override), Some(0.0));
    assert_eq!(c.get(Field::RudderLimit), Some(20.0));
    assert_eq!(c.get(Field::RudderOrder), None);
    // Stand-alone (S) is heading control too.
    assert_eq!(
        ok("APHTC,,,,S,,,,,,5,,,").get(Field::HeadingToSteer),
        Some(5.0)
    );
}

#[test]
fn htc_modes_require_their_fields() {
    assert_eq!(kind("APHTC,V,,,H,N,,,,,,,,T"), "missing required field");
    assert_eq!(kind("APHTC,V,,,T,N,,,,,90,,,T"), "missing required field");
    assert_eq!(kind("APHTC,V,,,,N,,,,,90,,,T"), "missing required field");
    let t = ok("APHTC,V,,,T,N,,,,,,,45.0,T");
    assert_eq!(t.get(Field::Track), Some(45.0));
    // Rudder control: 10 deg to port is -10.
    let r = ok("APHTC,A,10.0,L,R,N,,,,,,,,");
    assert_eq!(r.get(Field::RudderOrder), Some(-10.0));
    assert_eq!(r.get(Field::Override), Some(1.0));
    // Manual: nothing required.
    assert_eq!(
        ok("APHTC,V,,,M,,,,,,,,,").fields,
        vec![(Field::Override, 0.0), (Field::SteeringMode, 0.0)]
    );
}

#[test]
fn htd_carries_status_and_vessel_heading() {
    let c = ok("APHTD,V,,,H,N,,,,,270.0,,,T,A,A,A,268.5");
    assert_eq!(c.sentence, "HTD");
    assert_eq!(c.get(Field::HeadingToSteer), Some(270.0));
    assert_eq!(
        kind("APHTD,V,,,H,N,,,,,270.0,,,T,A,A,A,400"),
        "out of range"
    );
}

#[test]
fn htc_rejections_are_classified() {
    assert_eq!(kind("APHTC,V,,,H,N,,,,,NaN,,,T"), "not a number");
    assert_eq!(kind("APHTC,V,,,H,N,,,,,inf,,,T"), "not a number");
    assert_eq!(kind("APHTC,V,,,H,N,,,,,361,,,T"), "out of range");
    assert_eq!(kind("APHTC,V,,,H,N,,,,,1e2,,,T"), "malformed");
    assert_eq!(kind("APHTC,V,,,X,N,,,,,10,,,T"), "malformed");
    assert_eq!(kind("APHTC,V,,,H,N,,,,,10,,,M"), "magnetic bearing");
    assert_eq!(kind("APHTC,V,,,H"), "malformed");
}

#[test]
fn ror_single_rudder() {
    let c = ok("ECROR,-15.5,A,,V,B");
    assert_eq!(c.fields, vec![(Field::RudderOrder, -15.5)]);
    assert_eq!(kind("ECROR,5,V,,V,B"), "not valid (status V)");
    assert_eq!(kind("ECROR,,A,,V,B"), "missing required field");
    assert_eq!(kind("ECROR,95,A,,V,B"), "out of range");
    assert_eq!(ok("ECROR,5,A,4,A,B").get(Field::PortRudderOrder), Some(4.0));
}

/// APB as OpenCPN writes it when it follows a route (talker EC, true bearings, XTE in nmi)
/// and "NMEA Revealed"'s example.
#[test]
fn apb_as_opencpn_sends_it() {
    let c = ok("ECAPB,A,A,0.012,L,N,V,V,263.3,T,002,265.1,T,264.0,T,A");
    assert_eq!(c.get(Field::HeadingToSteer), Some(264.0));
    assert_eq!(c.get(Field::CrossTrackError), Some(-0.012));
    assert_eq!(c.get(Field::BearingOriginToDestination), Some(263.3));
    assert_eq!(c.get(Field::BearingToDestination), Some(265.1));
    assert_eq!(c.get(Field::Arrived), Some(0.0));
    // Without the NMEA 2.3 mode field, XTE in km.
    let k = ok("GPAPB,A,A,1.852,R,K,V,V,011,T,DEST,011,T,011,T");
    assert!((k.get(Field::CrossTrackError).unwrap() - 1.0).abs() < 1e-12);
    // "NMEA Revealed": $GPAPB,A,A,0.10,R,N,V,V,011,M,DEST,011,M,011,M*3C (magnetic).
    let revealed = b"$GPAPB,A,A,0.10,R,N,V,V,011,M,DEST,011,M,011,M*3C\r\n";
    assert_eq!(
        parse_sentence(revealed).unwrap_err().kind(),
        "magnetic bearing"
    );
    assert_eq!(
        kind("ECAPB,V,A,0.0,L,N,V,V,1,T,2,3,T,4,T,A"),
        "not valid (status V)"
    );
    assert_eq!(
        kind("ECAPB,A,A,0.0,L,N,V,V,1,T,2,3,T,4,T,N"),
        "not valid (status V)"
    );
    assert_eq!(
        kind("ECAPB,A,A,0.0,L,N,V,V,1,T,2,3,T,,T,A"),
        "missing required field"
    );
}

/// RMB: "NMEA Revealed"'s example, $GPRMB,A,0.66,L,003,004,4917.24,N,12309.57,W,001.3,052.5,000.5,V*20.
#[test]
fn rmb_revealed_example() {
    let c =
        parse_sentence(b"$GPRMB,A,0.66,L,003,004,4917.24,N,12309.57,W,001.3,052.5,000.5,V*20\r\n")
            .unwrap();
    assert_eq!(c.get(Field::CrossTrackError), Some(-0.66));
    assert_eq!(c.get(Field::BearingToDestination), Some(52.5));
    assert_eq!(c.get(Field::RangeToDestination), Some(1.3));
    assert!((c.get(Field::DestinationLatitude).unwrap() - (49.0 + 17.24 / 60.0)).abs() < 1e-12);
    assert!((c.get(Field::DestinationLongitude).unwrap() + (123.0 + 9.57 / 60.0)).abs() < 1e-12);
    assert_eq!(c.get(Field::Arrived), Some(0.0));
    assert_eq!(
        kind("GPRMB,V,0.66,L,003,004,,,,,1.3,52.5,0.5,V"),
        "not valid (status V)"
    );
    assert_eq!(
        kind("GPRMB,A,0.66,L,003,004,4917.24,N,12309.57,W,1.3,,0.5,V"),
        "missing required field"
    );
    assert_eq!(
        kind("GPRMB,A,0.66,L,003,004,4977.24,N,12309.57,W,1.3,5,0.5,V"),
        "out of range"
    );
}

#[test]
fn frames_and_garbage() {
    let mut bad = framed("APHTC,V,,,H,N,,,,,10,,,T");
    let n = bad.len();
    bad[n - 3] = if bad[n - 3] == b'0' { b'1' } else { b'0' };
    assert_eq!(parse_sentence(&bad).unwrap_err().kind(), "bad checksum");
    assert_eq!(kind("GPGGA,1,2,3"), "unknown sentence");
    assert_eq!(kind("PGRME,1,2,3"), "unknown sentence");
    for junk in [
        &b""[..],
        b"$",
        b"*",
        b"$*",
        b"$GPHTC,1*ZZ",
        b"\xff\xfe\x00garbage",
        b"$APHTC,V,,,H,N,,,,,10,,,T",
        &[b'$'; 200][..],
        b"$,,,,,,,,*00",
    ] {
        assert!(parse_sentence(junk).is_err(), "{junk:?}");
    }
    // Lowercase checksum digits are accepted; CR LF and spaces trimmed.
    let lower = String::from_utf8(framed("APHTC,V,,,H,N,,,,,10,,,T"))
        .unwrap()
        .to_lowercase();
    let (head, sum) = lower.split_at(lower.len() - 4);
    let s = format!("{}{}", head.to_uppercase(), sum);
    assert!(parse_sentence(s.as_bytes()).is_ok());
}

#[test]
fn bindings_name_sentence_and_field() {
    assert_eq!(
        Field::parse_binding("APB.heading_to_steer"),
        Some(("APB", Field::HeadingToSteer))
    );
    assert_eq!(Field::parse_binding("RMB.heading_to_steer"), None);
    assert_eq!(
        Field::parse_binding("ROR.rudder_order"),
        Some(("ROR", Field::RudderOrder))
    );
    assert_eq!(Field::RateOfTurn.unit(), "deg/min");
}

/// No input panics: every prefix of valid sentences and a fixed pseudo-random byte soup.
#[test]
fn no_panics_on_prefixes_and_noise() {
    let good = framed("ECAPB,A,A,0.012,L,N,V,V,263.3,T,002,265.1,T,264.0,T,A");
    for i in 0..good.len() {
        let _ = parse_sentence(&good[..i]);
    }
    let mut state = 0x2545_F491_4F6C_DD1D_u64;
    for _ in 0..20_000 {
        let mut b = vec![b'$'];
        for _ in 0..(state % 90) {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            b.push(b",*$.-0123456789ANVLRHTCPBROMD\r\n\xff"[(state % 32) as usize]);
        }
        let _ = parse_sentence(&b);
    }
}
