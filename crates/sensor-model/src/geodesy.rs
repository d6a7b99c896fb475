//! Local NED position → WGS-84 geodetic coordinates (flat-Earth approximation
//! about a reference point).
//!
//! With the WGS-84 ellipsoid (a = 6 378 137 m, f = 1/298.257 223 563,
//! e² = f(2 − f); NIMA TR8350.2), the meridian and prime-vertical radii of
//! curvature at the reference latitude φ₀ are
//! R_M = a(1 − e²)/(1 − e² sin²φ₀)^{3/2} and R_N = a/(1 − e² sin²φ₀)^{1/2}, and
//!
//! φ = φ₀ + n/(R_M + h₀),  λ = λ₀ + e/((R_N + h₀) cos φ₀),  h = h₀ − d.
//!
//! This is the first-order expansion of the exact transformation; its error grows
//! with the square of the distance: at 1 km from the reference the position error
//! is below 0.1 m, far under the GPS noise (σ ≈ 4 m), which covers every flight of
//! the thesis (a few hundred metres). Heights are above the ellipsoid.

/// WGS-84 semi-major axis (m).
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS-84 flattening (–).
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// Reference point and its radii of curvature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalTangent {
    /// Reference latitude φ₀ (rad).
    pub lat0: f64,
    /// Reference longitude λ₀ (rad).
    pub lon0: f64,
    /// Reference height h₀ above the ellipsoid (m).
    pub h0: f64,
    /// 1/(R_M + h₀) (rad/m).
    lat_per_m: f64,
    /// 1/((R_N + h₀) cos φ₀) (rad/m).
    lon_per_m: f64,
}

/// Largest |reference latitude| (rad): 89°, away from the pole where λ is undefined.
pub const MAX_REF_LATITUDE: f64 = 89.0 * std::f64::consts::PI / 180.0;

impl LocalTangent {
    /// `None` unless the reference is finite, |φ₀| ≤ 89° and |h₀| ≤ 100 km.
    pub fn new(lat0: f64, lon0: f64, h0: f64) -> Option<Self> {
        if !(lat0.is_finite() && lon0.is_finite() && h0.is_finite())
            || lat0.abs() > MAX_REF_LATITUDE
            || h0.abs() > 100_000.0
        {
            return None;
        }
        let e2 = WGS84_F * (2.0 - WGS84_F);
        let s = libm::sin(lat0);
        let w2 = 1.0 - e2 * s * s;
        let r_n = WGS84_A / w2.sqrt();
        let r_m = WGS84_A * (1.0 - e2) / (w2 * w2.sqrt());
        Some(Self {
            lat0,
            lon0,
            h0,
            lat_per_m: 1.0 / (r_m + h0),
            lon_per_m: 1.0 / ((r_n + h0) * libm::cos(lat0)),
        })
    }

    /// (latitude (rad), longitude (rad), height (m)) of the NED position `(n, e, d)` (m).
    #[inline]
    pub fn geodetic(&self, n: f64, e: f64, d: f64) -> (f64, f64, f64) {
        (
            self.lat0 + n * self.lat_per_m,
            self.lon0 + e * self.lon_per_m,
            self.h0 - d,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radii_match_published_wgs84_values() {
        // At the equator R_M = a(1 − e²) = 6 335 439.327 m and R_N = a; at the pole both are
        // a/(1 − f) = 6 399 593.626 m (NIMA TR8350.2, Table 3.1 derived constants: b, c).
        let eq = LocalTangent::new(0.0, 0.0, 0.0).unwrap();
        assert!((1.0 / eq.lat_per_m - 6_335_439.327).abs() < 1e-3);
        assert!((1.0 / eq.lon_per_m - 6_378_137.0).abs() < 1e-6);
        // One arc-minute of latitude at 45° is 1852.2 m (close to the nautical mile).
        let mid = LocalTangent::new(45f64.to_radians(), 0.0, 0.0).unwrap();
        let (lat, _, _) = mid.geodetic(1852.0, 0.0, 0.0);
        let arcmin = (lat - mid.lat0).to_degrees() * 60.0;
        assert!((arcmin - 1.0).abs() < 2e-4, "{arcmin}");
    }

    #[test]
    fn height_is_up_and_rejects_bad_references() {
        let lt = LocalTangent::new(-0.59, 0.33, 100.0).unwrap();
        assert_eq!(lt.geodetic(0.0, 0.0, -20.0), (-0.59, 0.33, 120.0));
        assert!(LocalTangent::new(f64::NAN, 0.0, 0.0).is_none());
        assert!(LocalTangent::new(1.56, 0.0, 0.0).is_none());
        assert!(LocalTangent::new(0.0, 0.0, 1e6).is_none());
    }
}
