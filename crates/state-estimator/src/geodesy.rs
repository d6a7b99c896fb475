//! WGS-84 geodesy: geodetic (latitude, longitude, height) ↔ ECEF ↔ local NED about a
//! reference point. Exact transformations (no flat-earth approximation), so the estimator
//! and a sensor model using the same ellipsoid agree to rounding at any distance.
//!
//! WGS-84 defining constants: a = 6 378 137 m, 1/f = 298.257 223 563 (NIMA TR8350.2, §3).

use nalgebra::{Matrix3, Vector3};

/// WGS-84 semi-major axis a (m).
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS-84 flattening f.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// First eccentricity squared e² = f(2 − f).
pub const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);

/// Prime-vertical radius of curvature N(φ) = a / √(1 − e² sin²φ) (m).
#[inline]
pub fn prime_vertical_radius(latitude: f64) -> f64 {
    let s = latitude.sin();
    WGS84_A / (1.0 - WGS84_E2 * s * s).sqrt()
}

/// Meridian radius of curvature M(φ) = a(1 − e²) / (1 − e² sin²φ)^{3/2} (m).
#[inline]
pub fn meridian_radius(latitude: f64) -> f64 {
    let s = latitude.sin();
    WGS84_A * (1.0 - WGS84_E2) / (1.0 - WGS84_E2 * s * s).powf(1.5)
}

/// ECEF position (m) of a geodetic point (latitude, longitude (rad), height above the ellipsoid (m)).
#[inline]
pub fn geodetic_to_ecef(latitude: f64, longitude: f64, height: f64) -> Vector3<f64> {
    let n = prime_vertical_radius(latitude);
    let (sl, cl) = latitude.sin_cos();
    let (so, co) = longitude.sin_cos();
    Vector3::new(
        (n + height) * cl * co,
        (n + height) * cl * so,
        (n * (1.0 - WGS84_E2) + height) * sl,
    )
}

/// Geodetic (latitude, longitude (rad), height (m)) of an ECEF position: Bowring's start
/// and Newton-like fixed-point refinement of the latitude (converges to rounding in ≤ 5
/// iterations near the Earth's surface).
pub fn ecef_to_geodetic(r: &Vector3<f64>) -> (f64, f64, f64) {
    let longitude = r.y.atan2(r.x);
    let p = (r.x * r.x + r.y * r.y).sqrt();
    let b = WGS84_A * (1.0 - WGS84_F);
    let ep2 = (WGS84_A * WGS84_A - b * b) / (b * b);
    // Bowring (1976) start.
    let th = (r.z * WGS84_A).atan2(p * b);
    let (st, ct) = th.sin_cos();
    let mut lat = (r.z + ep2 * b * st * st * st).atan2(p - WGS84_E2 * WGS84_A * ct * ct * ct);
    let mut height = 0.0;
    for _ in 0..5 {
        let n = prime_vertical_radius(lat);
        let cl = lat.cos();
        height = if cl.abs() > 1e-10 {
            p / cl - n
        } else {
            r.z.abs() - n * (1.0 - WGS84_E2)
        };
        lat = r.z.atan2(p * (1.0 - WGS84_E2 * n / (n + height)));
    }
    (lat, longitude, height)
}

/// `DCM` from ECEF to NED components at (latitude, longitude).
#[inline]
pub fn dcm_ecef_to_ned(latitude: f64, longitude: f64) -> Matrix3<f64> {
    let (sl, cl) = latitude.sin_cos();
    let (so, co) = longitude.sin_cos();
    Matrix3::new(-sl * co, -sl * so, cl, -so, co, 0.0, -cl * co, -cl * so, -sl)
}

/// A local NED frame at a geodetic reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFrame {
    /// Reference latitude (rad).
    pub latitude: f64,
    /// Reference longitude (rad).
    pub longitude: f64,
    /// Reference height above the ellipsoid (m).
    pub height: f64,
    origin_ecef: Vector3<f64>,
    ecef_to_ned: Matrix3<f64>,
}

impl LocalFrame {
    /// Frame at (latitude, longitude (rad), height (m)).
    pub fn new(latitude: f64, longitude: f64, height: f64) -> Self {
        Self {
            latitude,
            longitude,
            height,
            origin_ecef: geodetic_to_ecef(latitude, longitude, height),
            ecef_to_ned: dcm_ecef_to_ned(latitude, longitude),
        }
    }

    /// NED position (m) of a geodetic point.
    #[inline]
    pub fn to_ned(&self, latitude: f64, longitude: f64, height: f64) -> Vector3<f64> {
        self.ecef_to_ned * (geodetic_to_ecef(latitude, longitude, height) - self.origin_ecef)
    }

    /// Geodetic point (latitude, longitude (rad), height (m)) of a NED position (m).
    pub fn to_geodetic(&self, ned: &Vector3<f64>) -> (f64, f64, f64) {
        ecef_to_geodetic(&(self.origin_ecef + self.ecef_to_ned.tr_mul(ned)))
    }

    /// Metres per radian of latitude and of longitude at a geodetic point,
    /// (M + h) and (N + h) cos φ: converts the GPS angle σ to metres.
    #[inline]
    pub fn metres_per_radian(latitude: f64, height: f64) -> (f64, f64) {
        (
            meridian_radius(latitude) + height,
            (prime_vertical_radius(latitude) + height) * latitude.cos(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ecef_of_known_points() {
        // Equator/prime meridian: (a, 0, 0); the pole: (0, 0, b), b = a(1 − f) = 6 356 752.3142 m
        // (NIMA TR8350.2 Table 3.1).
        let r = geodetic_to_ecef(0.0, 0.0, 0.0);
        assert!((r - Vector3::new(WGS84_A, 0.0, 0.0)).norm() < 1e-6);
        let r = geodetic_to_ecef(std::f64::consts::FRAC_PI_2, 0.0, 0.0);
        assert!((r.z - 6_356_752.314_2).abs() < 1e-3 && r.x.abs() < 1e-6);
    }

    #[test]
    fn round_trip_and_local_frame() {
        let f = LocalFrame::new((-33.93f64).to_radians(), 18.86f64.to_radians(), 0.0);
        for ned in [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1000.0, -500.0, -120.0),
            Vector3::new(-30_000.0, 20_000.0, 50.0),
        ] {
            let (la, lo, h) = f.to_geodetic(&ned);
            let back = f.to_ned(la, lo, h);
            assert!((back - ned).norm() < 1e-6, "{ned} -> {back}");
        }
        // 1 m north is dφ = 1/(M + h) rad; 1 m east dλ = 1/((N + h) cos φ).
        let (la, lo, h) = f.to_geodetic(&Vector3::new(1.0, 1.0, 0.0));
        let (mn, me) = LocalFrame::metres_per_radian(f.latitude, 0.0);
        assert!(((la - f.latitude) * mn - 1.0).abs() < 1e-6);
        assert!(((lo - f.longitude) * me - 1.0).abs() < 1e-6);
        assert!(h.abs() < 1e-6, "height of 1 m offsets {h}");
        // Mean radius check: the Table D.1 σ of 6.2832e-7 rad is ≈ 4 m north.
        assert!((6.2832e-7 * mn - 4.0).abs() < 0.02);
    }
}
