//! The datum: the hull's north/east position [m] from an origin (latitude, longitude on
//! WGS-84) as a latitude and longitude.
//!
//! **The conversion** is the local tangent plane at the datum with the ellipsoid's two radii
//! of curvature there: latitude = φ0 + north/M(φ0), longitude = λ0 + east/(N(φ0) cos φ0), with
//! M = a(1-e²)/(1-e² sin²φ0)^(3/2) (meridional) and N = a/(1-e² sin²φ0)^(1/2) (prime
//! vertical). It is what a flat-earth ship model means by north and east near its origin, and
//! it is exact to first order.
//!
//! **Its error** is measured against the exact point: the geodesic from the datum of length
//! hypot(north, east) at azimuth atan2(east, north) (the ship's straight track, distances and
//! bearings from the origin kept), solved by Vincenty's direct formula ([`vincenty_direct`],
//! checked against the worked example of Geoscience Australia, Flinders Peak to Buninyong).
//! Over a circle of 50 km around the datum the largest difference is 0.4 m at the equator,
//! 227 m at 45° and 391 m at 60° latitude; within 5 km, 2.3 m at 45° and 3.9 m at 60° (test
//! `error_over_50_km`, every 5° of azimuth; the error grows as the square of the distance).
//! Most of it is the east-going geodesic curving toward the equator by about d² tan φ/(2N),
//! which the plane's line of constant latitude (a rhumb line, the course the model sails)
//! does not: the plane keeps courses, the geodesic keeps distances from the origin. For benches that sail farther, put the datum near
//! the area of interest.

/// WGS-84 semi-major axis [m] and flattening.
pub const A: f64 = 6_378_137.0;
pub const F: f64 = 1.0 / 298.257_223_563;

/// A datum: the geodetic position [deg] of the hull's origin (north = east = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Datum {
    pub latitude: f64,
    pub longitude: f64,
    /// Meridional and prime-vertical radii at the datum [m].
    m: f64,
    n: f64,
}

impl Datum {
    /// A datum at `latitude`, `longitude` [deg]; an error outside ±89° (the plane has no
    /// east at the poles) or ±180°.
    pub fn new(latitude: f64, longitude: f64) -> Result<Datum, String> {
        if !(latitude.abs() <= 89.0) || !(longitude.abs() <= 180.0) {
            return Err(format!(
                "datum ({latitude}, {longitude}): the latitude must be within ±89° and the longitude within ±180°"
            ));
        }
        let e2 = F * (2.0 - F);
        let s = latitude.to_radians().sin();
        let w = (1.0 - e2 * s * s).sqrt();
        Ok(Datum {
            latitude,
            longitude,
            m: A * (1.0 - e2) / (w * w * w),
            n: A / w,
        })
    }

    /// (latitude, longitude) [deg] of the point `north`, `east` [m] from the datum; the
    /// longitude wrapped to (-180, 180].
    pub fn to_geodetic(&self, north: f64, east: f64) -> (f64, f64) {
        let lat = self.latitude + (north / self.m).to_degrees();
        let coslat = self.latitude.to_radians().cos();
        let lon = self.longitude + (east / (self.n * coslat)).to_degrees();
        (lat, wrap180(lon))
    }
}

/// An angle [deg] wrapped to (-180, 180].
pub fn wrap180(x: f64) -> f64 {
    let y = x.rem_euclid(360.0);
    if y > 180.0 {
        y - 360.0
    } else {
        y
    }
}

/// Vincenty's direct formula on WGS-84 (T. Vincenty, "Direct and inverse solutions of
/// geodesics on the ellipsoid with application of nested equations", Survey Review 23, 1975):
/// the point reached from (`lat`, `lon`) [deg] along the geodesic of length `s` [m] at
/// azimuth `azimuth` [deg from north, clockwise]; (latitude, longitude) [deg]. Iterated to
/// 1e-12 rad (a few iterations for any distance below a quarter of the globe).
pub fn vincenty_direct(lat: f64, lon: f64, azimuth: f64, s: f64) -> (f64, f64) {
    let b = A * (1.0 - F);
    let (sa1, ca1) = azimuth.to_radians().sin_cos();
    let tan_u1 = (1.0 - F) * lat.to_radians().tan();
    let cos_u1 = 1.0 / (1.0 + tan_u1 * tan_u1).sqrt();
    let sin_u1 = tan_u1 * cos_u1;
    let sigma1 = tan_u1.atan2(ca1);
    let sin_alpha = cos_u1 * sa1;
    let cos2_alpha = 1.0 - sin_alpha * sin_alpha;
    let u2 = cos2_alpha * (A * A - b * b) / (b * b);
    let big_a = 1.0 + u2 / 16384.0 * (4096.0 + u2 * (-768.0 + u2 * (320.0 - 175.0 * u2)));
    let big_b = u2 / 1024.0 * (256.0 + u2 * (-128.0 + u2 * (74.0 - 47.0 * u2)));
    let mut sigma = s / (b * big_a);
    let (mut cos2sm, mut sin_s, mut cos_s);
    let mut i = 0;
    loop {
        cos2sm = (2.0 * sigma1 + sigma).cos();
        (sin_s, cos_s) = sigma.sin_cos();
        let ds = big_b
            * sin_s
            * (cos2sm
                + big_b / 4.0
                    * (cos_s * (-1.0 + 2.0 * cos2sm * cos2sm)
                        - big_b / 6.0
                            * cos2sm
                            * (-3.0 + 4.0 * sin_s * sin_s)
                            * (-3.0 + 4.0 * cos2sm * cos2sm)));
        let next = s / (b * big_a) + ds;
        i += 1;
        if (next - sigma).abs() < 1e-12 || i > 200 {
            sigma = next;
            break;
        }
        sigma = next;
    }
    (sin_s, cos_s) = sigma.sin_cos();
    cos2sm = (2.0 * sigma1 + sigma).cos();
    let x = sin_u1 * sin_s - cos_u1 * cos_s * ca1;
    let lat2 = (sin_u1 * cos_s + cos_u1 * sin_s * ca1)
        .atan2((1.0 - F) * (sin_alpha * sin_alpha + x * x).sqrt());
    let lambda = (sin_s * sa1).atan2(cos_u1 * cos_s - sin_u1 * sin_s * ca1);
    let c = F / 16.0 * cos2_alpha * (4.0 + F * (4.0 - 3.0 * cos2_alpha));
    let l = lambda
        - (1.0 - c)
            * F
            * sin_alpha
            * (sigma + c * sin_s * (cos2sm + c * cos_s * (-1.0 + 2.0 * cos2sm * cos2sm)));
    (lat2.to_degrees(), wrap180(lon + l.to_degrees()))
}

/// The distance [m] between two nearby points [deg] on the ellipsoid, in the tangent plane of
/// the first (for errors of a few hundred metres: its own error is far below them).
pub fn local_distance(a: (f64, f64), b: (f64, f64)) -> f64 {
    let d = Datum::new(a.0, a.1).expect("a valid latitude");
    let dn = (b.0 - a.0).to_radians() * d.m;
    let de = wrap180(b.1 - a.1).to_radians() * d.n * a.0.to_radians().cos();
    dn.hypot(de)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dms(d: f64, m: f64, s: f64) -> f64 {
        d.signum() * (d.abs() + m / 60.0 + s / 3600.0)
    }

    /// Geoscience Australia's worked example of Vincenty's direct formula (GDA technical
    /// manual): Flinders Peak (-37°57'03.72030", 144°25'29.52440"), 54,972.271 m at azimuth
    /// 306°52'05.37" to Buninyong (-37°39'10.15610", 143°55'35.38390").
    #[test]
    fn vincenty_direct_flinders_peak_to_buninyong() {
        let (lat, lon) = vincenty_direct(
            dms(-37.0, 57.0, 3.72030),
            dms(144.0, 25.0, 29.52440),
            dms(306.0, 52.0, 5.37),
            54_972.271,
        );
        let (elat, elon) = (dms(-37.0, 39.0, 10.15610), dms(143.0, 55.0, 35.38390));
        assert!((lat - elat).abs() * 3600.0 < 1e-4, "{lat} vs {elat}");
        assert!((lon - elon).abs() * 3600.0 < 1e-4, "{lon} vs {elon}");
    }

    /// The largest error of the tangent plane over points 50 km (and 5 km) from the datum,
    /// every 5° of azimuth, at the equator, 45° and 60° latitude; printed, and bounded.
    #[test]
    fn error_over_50_km() {
        for (lat0, bound_50, bound_5) in [(0.0, 1.0, 0.1), (45.0, 240.0, 2.5), (60.0, 420.0, 4.5)] {
            let d = Datum::new(lat0, 10.0).unwrap();
            let worst = |r: f64| {
                (0..72)
                    .map(|i| {
                        let az = i as f64 * 5.0;
                        let (n, e) = (r * az.to_radians().cos(), r * az.to_radians().sin());
                        let plane = d.to_geodetic(n, e);
                        let exact = vincenty_direct(lat0, 10.0, az, r);
                        local_distance(exact, plane)
                    })
                    .fold(0.0_f64, f64::max)
            };
            let (e50, e5) = (worst(50_000.0), worst(5_000.0));
            println!("datum at {lat0} deg: largest error {e50:.1} m at 50 km, {e5:.2} m at 5 km");
            assert!(e50 < bound_50, "{e50} m at 50 km, latitude {lat0}");
            assert!(e5 < bound_5, "{e5} m at 5 km, latitude {lat0}");
        }
    }

    #[test]
    fn plane_small_offsets_and_checks() {
        let d = Datum::new(60.0, 5.0).unwrap();
        // 1 minute of latitude at 60° is M(60°) pi/10800 = 1856.9 m on WGS-84.
        assert!((d.m - 6_383_453.857).abs() < 0.01, "{}", d.m);
        let (lat, lon) = d.to_geodetic(1856.9, 0.0);
        assert!((lat - (60.0 + 1.0 / 60.0)).abs() < 1e-6 && lon == 5.0);
        assert!(Datum::new(89.5, 0.0).is_err() && Datum::new(f64::NAN, 0.0).is_err());
        assert_eq!(wrap180(190.0), -170.0);
        assert_eq!(wrap180(-180.0), 180.0);
    }
}
