//! WGS-84 Earth model: geodetic ↔ ECEF ↔ NED, radii of curvature, normal gravity, Earth rate,
//! transport rate and the position-error helpers of the shared contract.
//!
//! Conventions (shared with `sighting-model`, see the crate doc):
//! navigation frame n = NED (north, east, down) at the vehicle; ECEF e is WGS-84; latitudes and
//! longitudes in radians, altitudes in metres above the ellipsoid.
//!
//! # Equations
//!
//! * Radii of curvature (meridian R_N, prime vertical R_E):
//!   R_N = a(1 − e²)/(1 − e² sin²L)^{3/2},  R_E = a/√(1 − e² sin²L).
//! * Geodetic → ECEF: x = (R_E + h) cosL cosλ, y = (R_E + h) cosL sinλ, z = (R_E(1 − e²) + h) sinL.
//! * C_e^n (ECEF → NED):
//!   ```text
//!   [ −sinL cosλ  −sinL sinλ   cosL ]
//!   [ −sinλ        cosλ        0    ]
//!   [ −cosL cosλ  −cosL sinλ  −sinL ]
//!   ```
//! * Normal gravity (magnitude, along the ellipsoid normal, pointing down): Somigliana on the
//!   ellipsoid, γ₀ = γ_e (1 + k sin²L)/√(1 − e² sin²L), then the WGS-84 second-order free-air
//!   reduction γ(h) = γ₀ [1 − (2/a)(1 + f + m − 2f sin²L) h + 3h²/a²]
//!   (NIMA TR8350.2 eq. 4-3). Its vertical gradient is ∂γ/∂h ≈ −2γ/R, the source of the INS
//!   vertical-channel instability (τ = 1/√(2g/R) ≈ 571 s at −23.2°, 6000 m).
//! * Earth rate in NED: Ω = ω_ie (cosL, 0, −sinL).
//! * Transport rate in NED: ρ = (v_E/(R_E + h), −v_N/(R_N + h), −v_E tanL/(R_E + h)).
//! * Position rates: L̇ = v_N/(R_N + h), λ̇ = v_E/((R_E + h) cosL), ḣ = −v_D.
//!
//! The position error in metres (contract): δp_N = (R_N + h) δL, δp_E = (R_E + h) cosL δλ,
//! δp_D = −δh; [`pos_err_ned_m`] computes it exactly as C_e^n(truth)·(ecef(computed) − ecef(truth)),
//! which equals that formula to first order. The local-level frame tilt between the computed and
//! true positions is δθ = (δp_E/(R_E + h), −δp_N/(R_N + h), −δp_E tanL/(R_E + h))
//! ([`frame_tilt_rad`]), with C_t^c = I − [δθ×].

use nalgebra::{Matrix3, Vector3};

/// WGS-84 semi-major axis a, metres.
pub const WGS84_A_M: f64 = 6_378_137.0;
/// WGS-84 flattening f (dimensionless).
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS-84 first eccentricity squared e² = f(2 − f).
pub const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);
/// WGS-84 semi-minor axis b = a(1 − f), metres.
pub const WGS84_B_M: f64 = WGS84_A_M * (1.0 - WGS84_F);
/// Earth rotation rate ω_ie, rad/s.
pub const EARTH_RATE_RADPS: f64 = 7.292_115e-5;
/// WGS-84 normal gravity at the equator γ_e, m/s².
pub const WGS84_GAMMA_E_MPS2: f64 = 9.780_325_335_9;
/// WGS-84 Somigliana constant k = (b γ_p)/(a γ_e) − 1 (dimensionless).
pub const WGS84_SOMIGLIANA_K: f64 = 0.001_931_852_652_41;
/// WGS-84 m = ω² a² b / GM (dimensionless).
pub const WGS84_M: f64 = 0.003_449_786_506_84;

/// Geodetic position on the WGS-84 ellipsoid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geodetic {
    /// Geodetic latitude L, radians (north positive).
    pub lat_rad: f64,
    /// Longitude λ, radians (east positive).
    pub lon_rad: f64,
    /// Height above the ellipsoid h, metres.
    pub alt_m: f64,
}

impl Geodetic {
    /// Builds a position from degrees and metres.
    pub fn from_deg(lat_deg: f64, lon_deg: f64, alt_m: f64) -> Self {
        Self {
            lat_rad: lat_deg.to_radians(),
            lon_rad: lon_deg.to_radians(),
            alt_m,
        }
    }
}

/// Radii of curvature `(R_N meridian, R_E prime vertical)` in metres at geodetic latitude `lat_rad`.
#[inline]
pub fn radii_of_curvature_m(lat_rad: f64) -> (f64, f64) {
    let s = lat_rad.sin();
    let w2 = 1.0 - WGS84_E2 * s * s;
    let w = w2.sqrt();
    let r_e = WGS84_A_M / w;
    let r_n = WGS84_A_M * (1.0 - WGS84_E2) / (w2 * w);
    (r_n, r_e)
}

/// Geodetic → ECEF position, metres.
pub fn geodetic_to_ecef(g: &Geodetic) -> Vector3<f64> {
    let (_, r_e) = radii_of_curvature_m(g.lat_rad);
    let (sl, cl) = g.lat_rad.sin_cos();
    let (so, co) = g.lon_rad.sin_cos();
    Vector3::new(
        (r_e + g.alt_m) * cl * co,
        (r_e + g.alt_m) * cl * so,
        (r_e * (1.0 - WGS84_E2) + g.alt_m) * sl,
    )
}

/// ECEF → geodetic (fixed-point iteration on latitude, converged to < 1e-15 rad for any point
/// outside a few km of the Earth's centre; height from h = p cosL + z sinL − a√(1 − e² sin²L),
/// which is well conditioned at the poles too).
pub fn ecef_to_geodetic(p_ecef_m: &Vector3<f64>) -> Geodetic {
    let (x, y, z) = (p_ecef_m.x, p_ecef_m.y, p_ecef_m.z);
    let p = x.hypot(y);
    let lon = y.atan2(x);
    let mut lat = z.atan2(p * (1.0 - WGS84_E2));
    for _ in 0..20 {
        let (sl, cl) = lat.sin_cos();
        let w = (1.0 - WGS84_E2 * sl * sl).sqrt();
        let n = WGS84_A_M / w;
        let h = p * cl + z * sl - WGS84_A_M * w;
        let new_lat = z.atan2(p * (1.0 - WGS84_E2 * n / (n + h)));
        let done = (new_lat - lat).abs() < 1e-15;
        lat = new_lat;
        if done {
            break;
        }
    }
    let (sl, cl) = lat.sin_cos();
    let w = (1.0 - WGS84_E2 * sl * sl).sqrt();
    let alt_m = p * cl + z * sl - WGS84_A_M * w;
    Geodetic {
        lat_rad: lat,
        lon_rad: lon,
        alt_m,
    }
}

/// Direction cosine matrix C_e^n (ECEF → NED) at the given latitude and longitude.
pub fn ned_from_ecef(lat_rad: f64, lon_rad: f64) -> Matrix3<f64> {
    let (sl, cl) = lat_rad.sin_cos();
    let (so, co) = lon_rad.sin_cos();
    Matrix3::new(
        -sl * co,
        -sl * so,
        cl,
        -so,
        co,
        0.0,
        -cl * co,
        -cl * so,
        -sl,
    )
}

/// WGS-84 normal gravity magnitude γ(L, h), m/s² (Somigliana + second-order free-air term;
/// see module doc). Acts along +D of the NED frame.
#[inline]
pub fn normal_gravity_mps2(lat_rad: f64, alt_m: f64) -> f64 {
    let s2 = lat_rad.sin().powi(2);
    let g0 = WGS84_GAMMA_E_MPS2 * (1.0 + WGS84_SOMIGLIANA_K * s2) / (1.0 - WGS84_E2 * s2).sqrt();
    let a = WGS84_A_M;
    g0 * (1.0 - 2.0 / a * (1.0 + WGS84_F + WGS84_M - 2.0 * WGS84_F * s2) * alt_m
        + 3.0 * alt_m * alt_m / (a * a))
}

/// Partial derivatives of [`normal_gravity_mps2`]: (∂γ/∂L in m/s² per rad, ∂γ/∂h in s⁻²).
/// ∂γ/∂h ≈ −2γ/R is the vertical-channel instability gradient.
pub fn normal_gravity_partials(lat_rad: f64, alt_m: f64) -> (f64, f64) {
    let s2 = lat_rad.sin().powi(2);
    let a = WGS84_A_M;
    let w2 = 1.0 - WGS84_E2 * s2;
    let g0 = WGS84_GAMMA_E_MPS2 * (1.0 + WGS84_SOMIGLIANA_K * s2) / w2.sqrt();
    let dg0_ds2 = WGS84_GAMMA_E_MPS2
        * (WGS84_SOMIGLIANA_K / w2.sqrt()
            + (1.0 + WGS84_SOMIGLIANA_K * s2) * 0.5 * WGS84_E2 / (w2 * w2.sqrt()));
    let c1 = 2.0 / a * (1.0 + WGS84_F + WGS84_M - 2.0 * WGS84_F * s2);
    let dc1_ds2 = 2.0 / a * (-2.0 * WGS84_F);
    let fac = 1.0 - c1 * alt_m + 3.0 * alt_m * alt_m / (a * a);
    let dgam_ds2 = dg0_ds2 * fac - g0 * dc1_ds2 * alt_m;
    let dgam_dlat = dgam_ds2 * (2.0 * lat_rad).sin();
    let dgam_dh = g0 * (-c1 + 6.0 * alt_m / (a * a));
    (dgam_dlat, dgam_dh)
}

/// Normal gravity vector in NED, m/s²: (0, 0, γ(L, h)).
#[inline]
pub fn gravity_ned_mps2(lat_rad: f64, alt_m: f64) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, normal_gravity_mps2(lat_rad, alt_m))
}

/// Navigation-frame quantities at one (latitude, altitude), computed with a single sin/cos and a
/// single square root (the hot-path form of [`radii_of_curvature_m`], [`earth_rate_ned_radps`],
/// [`normal_gravity_mps2`], [`transport_rate_ned_radps`] and [`geodetic_rates`]; same values).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalFrame {
    /// Latitude at which the quantities were evaluated, rad.
    pub lat_rad: f64,
    /// Anchor latitude with exactly evaluated sin/cos, used by [`LocalFrame::near`].
    anchor: (f64, f64, f64),
    /// Meridian radius of curvature plus altitude R_N + h, m.
    pub r_n_plus_h_m: f64,
    /// Prime-vertical radius of curvature plus altitude R_E + h, m.
    pub r_e_plus_h_m: f64,
    /// sin L.
    pub sin_lat: f64,
    /// cos L.
    pub cos_lat: f64,
    /// Earth rate in NED, rad/s.
    pub earth_rate_ned_radps: Vector3<f64>,
    /// Normal gravity γ(L, h), m/s² (along +D).
    pub gravity_mps2: f64,
}

impl LocalFrame {
    /// Evaluates the quantities at `lat_rad`, `alt_m`.
    #[inline]
    pub fn new(lat_rad: f64, alt_m: f64) -> Self {
        let (sl, cl) = lat_rad.sin_cos();
        Self::from_sin_cos(lat_rad, sl, cl, alt_m)
    }

    /// Same as [`LocalFrame::new`] (to ≤ 1e-21 in sin/cos), cheaper: sin/cos from a third-order
    /// Taylor step off an exactly evaluated anchor latitude (error ≤ Δ⁴/24 ≤ 4e-22 for
    /// |Δ| ≤ 1e-5 rad ≈ 64 m); beyond that a new anchor is evaluated. No error accumulates
    /// (every value is one step from an exact anchor). Used by the 100 Hz loops.
    #[inline]
    pub fn near(&self, lat_rad: f64, alt_m: f64) -> Self {
        let (a_lat, a_s, a_c) = self.anchor;
        let d = lat_rad - a_lat;
        if d.abs() > 1e-5 {
            return Self::new(lat_rad, alt_m);
        }
        let d2 = d * d;
        let even = 1.0 - 0.5 * d2;
        let odd = d * (1.0 - d2 / 6.0);
        let sl = a_s * even + a_c * odd;
        let cl = a_c * even - a_s * odd;
        let mut f = Self::from_sin_cos(lat_rad, sl, cl, alt_m);
        f.anchor = self.anchor;
        f
    }

    #[inline]
    fn from_sin_cos(lat_rad: f64, sl: f64, cl: f64, alt_m: f64) -> Self {
        let s2 = sl * sl;
        let w2 = 1.0 - WGS84_E2 * s2;
        let w = w2.sqrt();
        let r_e = WGS84_A_M / w;
        let r_n = WGS84_A_M * (1.0 - WGS84_E2) / (w2 * w);
        let a = WGS84_A_M;
        let g0 = WGS84_GAMMA_E_MPS2 * (1.0 + WGS84_SOMIGLIANA_K * s2) / w;
        let gamma = g0
            * (1.0 - 2.0 / a * (1.0 + WGS84_F + WGS84_M - 2.0 * WGS84_F * s2) * alt_m
                + 3.0 * alt_m * alt_m / (a * a));
        Self {
            lat_rad,
            anchor: (lat_rad, sl, cl),
            r_n_plus_h_m: r_n + alt_m,
            r_e_plus_h_m: r_e + alt_m,
            sin_lat: sl,
            cos_lat: cl,
            earth_rate_ned_radps: Vector3::new(EARTH_RATE_RADPS * cl, 0.0, -EARTH_RATE_RADPS * sl),
            gravity_mps2: gamma,
        }
    }

    /// Transport rate ρ in NED for the NED velocity `vel_ned_mps`, rad/s.
    #[inline]
    pub fn transport_rate_ned_radps(&self, vel_ned_mps: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(
            vel_ned_mps.y / self.r_e_plus_h_m,
            -vel_ned_mps.x / self.r_n_plus_h_m,
            -vel_ned_mps.y * self.sin_lat / (self.cos_lat * self.r_e_plus_h_m),
        )
    }

    /// Geodetic rates (L̇, λ̇, ḣ) for the NED velocity `vel_ned_mps`.
    #[inline]
    pub fn geodetic_rates(&self, vel_ned_mps: &Vector3<f64>) -> Vector3<f64> {
        Vector3::new(
            vel_ned_mps.x / self.r_n_plus_h_m,
            vel_ned_mps.y / (self.r_e_plus_h_m * self.cos_lat),
            -vel_ned_mps.z,
        )
    }
}

/// Skew-symmetric (cross-product) matrix [v×], so that `skew(v) * w == v.cross(w)`.
#[inline]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Earth rate ω_ie expressed in NED, rad/s: Ω = ω_ie (cosL, 0, −sinL).
#[inline]
pub fn earth_rate_ned_radps(lat_rad: f64) -> Vector3<f64> {
    let (sl, cl) = lat_rad.sin_cos();
    Vector3::new(EARTH_RATE_RADPS * cl, 0.0, -EARTH_RATE_RADPS * sl)
}

/// Transport rate ω_en expressed in NED, rad/s:
/// ρ = (v_E/(R_E + h), −v_N/(R_N + h), −v_E tanL/(R_E + h)).
#[inline]
pub fn transport_rate_ned_radps(
    lat_rad: f64,
    alt_m: f64,
    vel_ned_mps: &Vector3<f64>,
) -> Vector3<f64> {
    let (r_n, r_e) = radii_of_curvature_m(lat_rad);
    let re_h = r_e + alt_m;
    Vector3::new(
        vel_ned_mps.y / re_h,
        -vel_ned_mps.x / (r_n + alt_m),
        -vel_ned_mps.y * lat_rad.tan() / re_h,
    )
}

/// Geodetic position rates (L̇ rad/s, λ̇ rad/s, ḣ m/s) from the NED velocity.
#[inline]
pub fn geodetic_rates(lat_rad: f64, alt_m: f64, vel_ned_mps: &Vector3<f64>) -> Vector3<f64> {
    let (r_n, r_e) = radii_of_curvature_m(lat_rad);
    Vector3::new(
        vel_ned_mps.x / (r_n + alt_m),
        vel_ned_mps.y / ((r_e + alt_m) * lat_rad.cos()),
        -vel_ned_mps.z,
    )
}

/// Position error `computed − truth` in metres, NED at the truth:
/// C_e^n(truth)·(ecef(computed) − ecef(truth)). To first order this is
/// ((R_N + h)δL, (R_E + h) cosL δλ, −δh).
pub fn pos_err_ned_m(computed: &Geodetic, truth: &Geodetic) -> Vector3<f64> {
    let d = geodetic_to_ecef(computed) - geodetic_to_ecef(truth);
    ned_from_ecef(truth.lat_rad, truth.lon_rad) * d
}

/// Inverse of [`pos_err_ned_m`] to first order: the computed position obtained by displacing
/// `truth` by `pos_err_ned_m` (δL = δp_N/(R_N + h), δλ = δp_E/((R_E + h) cosL), δh = −δp_D),
/// refined by one Newton step through [`pos_err_ned_m`] so that the round trip is exact to
/// well below a millimetre for errors up to tens of kilometres.
pub fn displace_by_ned_m(truth: &Geodetic, pos_err_ned_m_in: &Vector3<f64>) -> Geodetic {
    let step = |base: &Geodetic, d: &Vector3<f64>| {
        let (r_n, r_e) = radii_of_curvature_m(truth.lat_rad);
        Geodetic {
            lat_rad: base.lat_rad + d.x / (r_n + truth.alt_m),
            lon_rad: base.lon_rad + d.y / ((r_e + truth.alt_m) * truth.lat_rad.cos()),
            alt_m: base.alt_m - d.z,
        }
    };
    let mut g = step(truth, pos_err_ned_m_in);
    for _ in 0..3 {
        let resid = pos_err_ned_m_in - pos_err_ned_m(&g, truth);
        g = step(&g, &resid);
    }
    g
}

/// Local-level frame tilt δθ (rad) between the computed and the true position for a position
/// error `pos_err_ned_m` (contract): δθ = (δp_E/(R_E + h), −δp_N/(R_N + h), −δp_E tanL/(R_E + h)),
/// C_t^c = I − [δθ×].
#[inline]
pub fn frame_tilt_rad(pos_err_ned_m: &Vector3<f64>, lat_rad: f64, alt_m: f64) -> Vector3<f64> {
    let (r_n, r_e) = radii_of_curvature_m(lat_rad);
    let re_h = r_e + alt_m;
    Vector3::new(
        pos_err_ned_m.y / re_h,
        -pos_err_ned_m.x / (r_n + alt_m),
        -pos_err_ned_m.y * lat_rad.tan() / re_h,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn paper_start() -> Geodetic {
        Geodetic::from_deg(-(23.0 + 12.0 / 60.0), -(45.0 + 52.0 / 60.0), 6000.0)
    }

    #[test]
    fn ecef_round_trip_over_globe() {
        for &lat in &[-89.9, -60.0, -23.2, 0.0, 10.0, 45.0, 89.99] {
            for &lon in &[-179.0, -45.87, 0.0, 120.0] {
                for &h in &[-100.0, 0.0, 6000.0, 400_000.0] {
                    let g = Geodetic::from_deg(lat, lon, h);
                    let back = ecef_to_geodetic(&geodetic_to_ecef(&g));
                    assert!(
                        (back.lat_rad - g.lat_rad).abs() < 1e-12,
                        "lat {lat} {lon} {h}"
                    );
                    assert!((back.lon_rad - g.lon_rad).abs() < 1e-12);
                    assert!((back.alt_m - g.alt_m).abs() < 1e-6, "alt {lat} {lon} {h}");
                }
            }
        }
    }

    #[test]
    fn ecef_of_known_points() {
        // Equator/prime meridian at h = 0 is (a, 0, 0); north pole is (0, 0, b).
        let p = geodetic_to_ecef(&Geodetic::from_deg(0.0, 0.0, 0.0));
        assert_relative_eq!(p, Vector3::new(WGS84_A_M, 0.0, 0.0), epsilon = 1e-9);
        let p = geodetic_to_ecef(&Geodetic::from_deg(90.0, 0.0, 0.0));
        assert!((p.z - WGS84_B_M).abs() < 1e-6 && p.x.abs() < 1e-6);
    }

    #[test]
    fn ned_dcm_is_rotation_and_down_points_to_normal() {
        let g = paper_start();
        let c = ned_from_ecef(g.lat_rad, g.lon_rad);
        assert_relative_eq!(c * c.transpose(), Matrix3::identity(), epsilon = 1e-14);
        assert_relative_eq!(c.determinant(), 1.0, epsilon = 1e-14);
        // Moving 1 m up along the ellipsoid normal changes ECEF by −(down axis).
        let up = Geodetic {
            alt_m: g.alt_m + 1.0,
            ..g
        };
        let d = geodetic_to_ecef(&up) - geodetic_to_ecef(&g);
        assert_relative_eq!(c * d, Vector3::new(0.0, 0.0, -1.0), epsilon = 1e-9);
    }

    #[test]
    fn radii_match_ecef_finite_differences() {
        let g = paper_start();
        let (r_n, r_e) = radii_of_curvature_m(g.lat_rad);
        let c = ned_from_ecef(g.lat_rad, g.lon_rad);
        let dl = 1e-6;
        let n = Geodetic {
            lat_rad: g.lat_rad + dl,
            ..g
        };
        let s = Geodetic {
            lat_rad: g.lat_rad - dl,
            ..g
        };
        let dn = c * (geodetic_to_ecef(&n) - geodetic_to_ecef(&s)) / (2.0 * dl);
        assert_relative_eq!(dn.x, r_n + g.alt_m, max_relative = 1e-9);
        let e = Geodetic {
            lon_rad: g.lon_rad + dl,
            ..g
        };
        let w = Geodetic {
            lon_rad: g.lon_rad - dl,
            ..g
        };
        let de = c * (geodetic_to_ecef(&e) - geodetic_to_ecef(&w)) / (2.0 * dl);
        assert_relative_eq!(de.y, (r_e + g.alt_m) * g.lat_rad.cos(), max_relative = 1e-9);
    }

    #[test]
    fn gravity_sanity_figures_of_ins_sd() {
        let g = paper_start();
        let gamma = normal_gravity_mps2(g.lat_rad, g.alt_m);
        assert!((gamma - 9.770).abs() < 1e-3, "gamma {gamma}");
        // Equator and pole values of the WGS-84 normal gravity formula.
        assert_relative_eq!(
            normal_gravity_mps2(0.0, 0.0),
            9.780_325_335_9,
            epsilon = 1e-10
        );
        assert!(
            (normal_gravity_mps2(std::f64::consts::FRAC_PI_2, 0.0) - 9.832_184_937_8).abs() < 1e-8
        );
        // Vertical gradient by central difference ≈ −2g/R ≈ −3.07e-6 s^-2; τ ≈ 571 s.
        let dh = 1.0;
        let grad = (normal_gravity_mps2(g.lat_rad, g.alt_m + dh)
            - normal_gravity_mps2(g.lat_rad, g.alt_m - dh))
            / (2.0 * dh);
        assert!((grad + 3.07e-6).abs() < 0.01e-6, "grad {grad}");
        let tau = 1.0 / (-grad).sqrt();
        assert!((tau - 571.0).abs() < 2.0, "tau {tau}");
    }

    #[test]
    fn gravity_partials_match_central_differences() {
        for &(lat, h) in &[(-23.2_f64, 6000.0), (45.0, 0.0), (-70.0, 20_000.0)] {
            let l = lat.to_radians();
            let (dl, dh) = normal_gravity_partials(l, h);
            let e = 1e-5;
            let fl = (normal_gravity_mps2(l + e, h) - normal_gravity_mps2(l - e, h)) / (2.0 * e);
            let fh = (normal_gravity_mps2(l, h + 1.0) - normal_gravity_mps2(l, h - 1.0)) / 2.0;
            assert!((dl - fl).abs() < 1e-8, "{dl} {fl}");
            assert!((dh - fh).abs() < 1e-12, "{dh} {fh}");
        }
    }

    #[test]
    fn pos_err_matches_first_order_formula() {
        let t = paper_start();
        let (r_n, r_e) = radii_of_curvature_m(t.lat_rad);
        let c = Geodetic {
            lat_rad: t.lat_rad + 1e-5,
            lon_rad: t.lon_rad - 2e-5,
            alt_m: t.alt_m + 3.0,
        };
        let d = pos_err_ned_m(&c, &t);
        let lin = Vector3::new(
            (r_n + t.alt_m) * 1e-5,
            -(r_e + t.alt_m) * t.lat_rad.cos() * 2e-5,
            -3.0,
        );
        // Second-order terms are ~ (100 m)²/R ≈ 2 mm.
        assert_relative_eq!(d, lin, epsilon = 5e-3);
        let back = displace_by_ned_m(&t, &d);
        assert!((back.lat_rad - c.lat_rad).abs() < 1e-13);
        assert!((back.lon_rad - c.lon_rad).abs() < 1e-13);
        assert!((back.alt_m - c.alt_m).abs() < 1e-6);
    }

    #[test]
    fn frame_tilt_equals_rotation_between_ned_frames() {
        // C_t^c = C_e^c C_e^tᵀ ≈ I − [δθ×].
        let t = paper_start();
        let c = Geodetic {
            lat_rad: t.lat_rad + 2e-6,
            lon_rad: t.lon_rad + 3e-6,
            ..t
        };
        let dp = pos_err_ned_m(&c, &t);
        let dth = frame_tilt_rad(&dp, t.lat_rad, t.alt_m);
        let ctc =
            ned_from_ecef(c.lat_rad, c.lon_rad) * ned_from_ecef(t.lat_rad, t.lon_rad).transpose();
        let lin = Matrix3::identity() - skew(&dth);
        assert_relative_eq!(ctc, lin, epsilon = 1e-10);
    }

    #[test]
    fn transport_rate_is_ned_frame_rotation_rate() {
        // ω_en = rate of the NED frame w.r.t. ECEF, in NED: Ċ_e^n = −[ω_en×] C_e^n.
        let g = paper_start();
        let v = Vector3::new(20.0, -25.0, 3.0);
        let rho = transport_rate_ned_radps(g.lat_rad, g.alt_m, &v);
        let rates = geodetic_rates(g.lat_rad, g.alt_m, &v);
        let dt = 1e-3;
        let at = |s: f64| ned_from_ecef(g.lat_rad + rates.x * s, g.lon_rad + rates.y * s);
        let cdot = (at(dt) - at(-dt)) / (2.0 * dt);
        // Ċ_e^n = −[ω_en×] C_e^n.
        let w = -cdot * at(0.0).transpose();
        assert_relative_eq!(w, skew(&rho), epsilon = 1e-12);
    }

    #[test]
    fn local_frame_equals_individual_functions() {
        let g = paper_start();
        let v = Vector3::new(21.0, -17.0, 1.5);
        let lf = LocalFrame::new(g.lat_rad, g.alt_m);
        let (r_n, r_e) = radii_of_curvature_m(g.lat_rad);
        assert_relative_eq!(lf.r_n_plus_h_m, r_n + g.alt_m, max_relative = 1e-15);
        assert_relative_eq!(lf.r_e_plus_h_m, r_e + g.alt_m, max_relative = 1e-15);
        assert_relative_eq!(
            lf.gravity_mps2,
            normal_gravity_mps2(g.lat_rad, g.alt_m),
            max_relative = 1e-15
        );
        assert_relative_eq!(
            lf.earth_rate_ned_radps,
            earth_rate_ned_radps(g.lat_rad),
            max_relative = 1e-15
        );
        assert_relative_eq!(
            lf.transport_rate_ned_radps(&v),
            transport_rate_ned_radps(g.lat_rad, g.alt_m, &v),
            max_relative = 1e-14
        );
        assert_relative_eq!(
            lf.geodetic_rates(&v),
            geodetic_rates(g.lat_rad, g.alt_m, &v),
            max_relative = 1e-14
        );
    }

    #[test]
    fn local_frame_taylor_step_matches_direct_over_a_long_chain() {
        // 90 000 steps of 6e-8 rad (≈ 0.4 m at 100 Hz): chained `near` vs direct `new`.
        let g = paper_start();
        let mut lf = LocalFrame::new(g.lat_rad, g.alt_m);
        let mut lat = g.lat_rad;
        for k in 0..90_000 {
            lat += 6e-8 * (1.0 + (k as f64 * 1e-3).sin());
            lf = lf.near(lat, g.alt_m);
        }
        let direct = LocalFrame::new(lat, g.alt_m);
        assert!(
            (lf.sin_lat - direct.sin_lat).abs() < 1e-15,
            "{}",
            lf.sin_lat - direct.sin_lat
        );
        assert!(
            (lf.cos_lat - direct.cos_lat).abs() < 1e-15,
            "{}",
            lf.cos_lat - direct.cos_lat
        );
        assert!((lf.gravity_mps2 / direct.gravity_mps2 - 1.0).abs() < 1e-15);
    }

    #[test]
    fn skew_is_cross_product() {
        let a = Vector3::new(1.0, -2.0, 3.5);
        let b = Vector3::new(-0.3, 0.7, 2.0);
        assert_relative_eq!(skew(&a) * b, a.cross(&b), epsilon = 1e-15);
        assert_relative_eq!(
            skew(&a) + skew(&a).transpose(),
            Matrix3::zeros(),
            epsilon = 0.0
        );
    }

    #[test]
    fn earth_rate_is_earth_axis_in_ned() {
        let g = paper_start();
        let c = ned_from_ecef(g.lat_rad, g.lon_rad);
        let w = c * Vector3::new(0.0, 0.0, EARTH_RATE_RADPS);
        assert_relative_eq!(w, earth_rate_ned_radps(g.lat_rad), epsilon = 1e-18);
    }
}
