//! Acceptance tests of the sensor model (issue 14, part 1): noise statistics of
//! every channel against its parameter, the Butterworth's −3 dB point, sample and
//! hold at each rate, faults, reproducibility and bit-exact state restore, bad input.

use nalgebra::{Matrix3, Vector3, Vector4};
use sensor_model::{FaultMode, Measurements, Params, SensorModel, Site, State, Truth, RHO_0, STATE_WORDS};
use std::f64::consts::PI;

/// A constant, non-trivial true state: banked, pitched, yawed, rolling, flying at 25 m/s.
fn still_truth() -> Truth {
    Truth {
        pos_ned: Vector3::new(120.0, -45.0, -30.0),
        vel_ned: Vector3::new(20.0, -3.0, 1.5),
        rates: Vector3::new(0.05, -0.02, 0.1),
        quat: tailsitter_physics::quat_from_euler_321(0.1, 0.2, 0.3),
        airspeed: 25.0,
        alpha: 0.1,
        beta: 0.05,
        specific_force: Vector3::new(0.4, -0.3, -9.7),
    }
}

/// Earth-to-body DCM of Euler 3-2-1 angles, built from elementary rotations
/// (independent of the quaternion code under test).
fn dcm_321(phi: f64, theta: f64, psi: f64) -> Matrix3<f64> {
    let r1 = Matrix3::new(1.0, 0.0, 0.0, 0.0, phi.cos(), phi.sin(), 0.0, -phi.sin(), phi.cos());
    let r2 = Matrix3::new(
        theta.cos(),
        0.0,
        -theta.sin(),
        0.0,
        1.0,
        0.0,
        theta.sin(),
        0.0,
        theta.cos(),
    );
    let r3 = Matrix3::new(psi.cos(), psi.sin(), 0.0, -psi.sin(), psi.cos(), 0.0, 0.0, 0.0, 1.0);
    r1 * r2 * r3
}

/// WMM2025 field at −33.93°, 18.86°, 0 m, epoch 2025.0 (X, Y, Z in Gauss; NOAA/BGS model,
/// evaluated with the published WMM2025 coefficients).
const WMM_XYZ_GAUSS: [f64; 3] = [0.095_905, -0.048_040, -0.227_275];

/// Filtered-to-raw σ ratio of a 2nd-order Butterworth, −3 dB at `fc`, bilinear with
/// prewarping at `fs`, for white input: σ_out² / σ² = (1/π) ∫₀^π |H(e^{jω})|² dω with
/// |H(e^{jω})|² = 1 / (1 + (tan(ω/2) / tan(π fc/fs))⁴) (the analogue Butterworth magnitude
/// seen through the bilinear frequency map). Composite Simpson quadrature.
fn filtered_noise_gain(fc: f64, fs: f64) -> f64 {
    let k = (PI * fc / fs).tan();
    let h2 = |w: f64| {
        if w >= PI {
            0.0
        } else {
            1.0 / (1.0 + ((w / 2.0).tan() / k).powi(4))
        }
    };
    let n = 200_000;
    let dw = PI / n as f64;
    let mut s = h2(0.0) + h2(PI);
    for i in 1..n {
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * h2(i as f64 * dw);
    }
    (s * dw / 3.0 / PI).sqrt()
}

struct Stats {
    n: usize,
    sum: f64,
    sum2: f64,
}

impl Stats {
    fn new() -> Self {
        Self {
            n: 0,
            sum: 0.0,
            sum2: 0.0,
        }
    }
    fn push(&mut self, x: f64) {
        self.n += 1;
        self.sum += x;
        self.sum2 += x * x;
    }
    fn mean(&self) -> f64 {
        self.sum / self.n as f64
    }
    fn std(&self) -> f64 {
        let m = self.mean();
        ((self.sum2 - self.n as f64 * m * m) / (self.n as f64 - 1.0)).sqrt()
    }
}

/// Run `steps` communication steps of `h` with the truth held, collecting the analogue
/// outputs after every step and the GPS outputs at every new fix.
fn still_run(params: Params, h: f64, steps: usize) -> (Vec<Stats>, Vec<Stats>) {
    let truth = still_truth();
    let mut m = SensorModel::new(params).unwrap();
    m.start(&truth, 0.0).unwrap();
    let mut analog: Vec<Stats> = (0..10).map(|_| Stats::new()).collect();
    let mut gps: Vec<Stats> = (0..6).map(|_| Stats::new()).collect();
    let mut fixes = 1;
    // Skip the first second (filter start-up).
    for k in 0..steps {
        let out = m.step(&truth, k as f64 * h, h).unwrap();
        if k as f64 * h < 1.0 {
            fixes = out.gps_fix_count;
            continue;
        }
        for (s, x) in analog.iter_mut().zip(out.analog) {
            s.push(x);
        }
        if out.gps_fix_count != fixes {
            assert_eq!(out.gps_fix_count, fixes + 1);
            fixes = out.gps_fix_count;
            let g = [
                out.gps_latitude,
                out.gps_longitude,
                out.gps_height,
                out.gps_vel.x,
                out.gps_vel.y,
                out.gps_vel.z,
            ];
            for (s, x) in gps.iter_mut().zip(g) {
                s.push(x);
            }
        }
    }
    (analog, gps)
}

/// True value of every channel: analogue outputs and GPS (independent derivations).
fn expected(p: &Params) -> ([f64; 10], [f64; 6]) {
    let t = still_truth();
    let c = dcm_321(0.1, 0.2, 0.3);
    let m = c * Vector3::from(WMM_XYZ_GAUSS);
    let u_r = t.airspeed * t.alpha.cos() * t.beta.cos();
    // Radii of curvature at the reference latitude (WGS-84).
    let (a, f) = (6_378_137.0, 1.0 / 298.257_223_563);
    let e2 = f * (2.0 - f);
    let s2 = p.site.ref_latitude.sin().powi(2);
    let r_m = a * (1.0 - e2) / (1.0 - e2 * s2).powf(1.5);
    let r_n = a / (1.0 - e2 * s2).sqrt();
    (
        [
            t.specific_force.x,
            t.specific_force.y,
            t.specific_force.z,
            t.rates.x,
            t.rates.y,
            t.rates.z,
            m.x,
            m.y,
            m.z,
            u_r,
        ],
        [
            p.site.ref_latitude + t.pos_ned.x / r_m,
            p.site.ref_longitude + t.pos_ned.y / (r_n * p.site.ref_latitude.cos()),
            p.site.ref_height - t.pos_ned.z,
            t.vel_ned.x,
            t.vel_ned.y,
            t.vel_ned.z,
        ],
    )
}

#[test]
fn default_earth_field_matches_the_world_magnetic_model() {
    let f = Params::default().field_ned();
    for i in 0..3 {
        // D and I are rounded to 0.01° (1.7e-4 rad × 0.25 G ≈ 5e-5 G).
        assert!(
            (f[i] - WMM_XYZ_GAUSS[i]).abs() < 1e-4,
            "{i}: {} vs {}",
            f[i],
            WMM_XYZ_GAUSS[i]
        );
    }
}

/// Noise measured before the filter (filter disabled): each σ within 5 % of its parameter,
/// each mean within 3σ/√n of the truth.
#[test]
fn unfiltered_noise_matches_table_d1_and_means_are_unbiased() {
    let p = Params {
        filter_enabled: false,
        seed: 11,
        ..Params::default()
    };
    // 2000 s at 20 ms: 100 000 samples per analogue channel, 8000 GPS fixes.
    let (analog, gps) = still_run(p, 0.02, 100_000);
    let (truth_analog, truth_gps) = expected(&p);
    // Pitot: σ_V = σ_Δp / (ρ₀ u_r) to first order in σ_Δp/Δp (here 1 Pa / 376 Pa).
    let sigma_analog = delivered_sigma(&p, truth_analog[9]);
    for c in 0..10 {
        let sigma = sigma_analog[c];
        assert_noise(
            &format!("unfiltered channel {c}"),
            &analog[c],
            sigma,
            truth_analog[c],
            sigma,
        );
    }
    let sigma_gps = gps_sigma(&p);
    for c in 0..6 {
        assert!(gps[c].n >= 7_900, "{} fixes", gps[c].n);
        assert_noise(&format!("gps {c}"), &gps[c], sigma_gps[c], truth_gps[c], sigma_gps[c]);
    }
}

/// The sample `s` of a noisy channel has the standard deviation `sigma` within 5 % and its
/// mean within 3 `mean_sigma`/√n of `truth` (`mean_sigma`: the σ of the white noise behind
/// it, whose long-run variance the mean's is).
fn assert_noise(what: &str, s: &Stats, sigma: f64, truth: f64, mean_sigma: f64) {
    let n = s.n as f64;
    println!(
        "{what}: n = {}, σ = {:.5e}, σ/σ_param = {:.4}, (mean − truth)·√n/σ = {:+.2}",
        s.n,
        s.std(),
        s.std() / sigma,
        (s.mean() - truth) * n.sqrt() / mean_sigma
    );
    assert!((s.std() / sigma - 1.0).abs() < 0.05, "{what}: σ {} vs {sigma}", s.std());
    assert!(
        (s.mean() - truth).abs() < 3.0 * mean_sigma / n.sqrt(),
        "{what}: mean {} vs truth {truth}",
        s.mean()
    );
}

/// Table D.1 σ of the GPS's latitude, longitude, height and NED velocity.
fn gps_sigma(p: &Params) -> [f64; 6] {
    [
        p.gps_latlon_std,
        p.gps_latlon_std,
        p.gps_height_std,
        p.gps_vel_std,
        p.gps_vel_std,
        p.gps_vel_std,
    ]
}

/// Table D.1 σ per delivered analogue channel (accel x/y/z, gyro p/q/r, mag x/y/z) and the
/// pitot airspeed's σ_Δp/(ρ₀ u_r) at `u_r` (first order in σ_Δp/Δp).
fn delivered_sigma(p: &Params, u_r: f64) -> [f64; 10] {
    [
        p.accel_std,
        p.accel_std,
        p.accel_std,
        p.gyro_std,
        p.gyro_std,
        p.gyro_std,
        p.mag_std,
        p.mag_std,
        p.mag_std,
        p.pitot_std / (RHO_0 * u_r),
    ]
}

/// With the Butterworth (defaults: accelerometer 1 kHz, gyro 200 Hz, magnetometer and pitot
/// 50 Hz): the model's noise gains equal an independent quadrature, and the *delivered*
/// output carries the parameter's σ (Table D.1) within 5 %: 100 000 outputs per channel at
/// 20 ms (the filtered noise is correlated over ≈ 20 ms: ≈ 47 000 independent samples,
/// statistical error of σ ≈ 0.3 %); each mean within 3σ/√n of the truth with the white
/// noise's σ (DC gain 1: the long-run variance of the filtered mean is the white noise's).
#[test]
fn delivered_noise_is_table_d1_after_the_filter() {
    let p = Params {
        seed: 12,
        ..Params::default()
    };
    assert_eq!(p.accel_rate, 1000.0, "App. D.3: accelerometers at up to 1 kHz");
    let model = SensorModel::new(p).unwrap();
    let gains = model.noise_gains();
    let g_acc = filtered_noise_gain(8.0, 1000.0);
    let g_gyro = filtered_noise_gain(8.0, 200.0);
    let g_50 = filtered_noise_gain(8.0, 50.0);
    // The model's Σh² against the independent quadrature.
    for (g, expected) in gains.iter().zip([g_acc, g_gyro, g_50, g_50]) {
        assert!((g / expected - 1.0).abs() < 1e-6, "{g} vs {expected}");
    }
    // For fc ≪ fs the gain tends to √(2 B_n / fs) with the analogue Butterworth's noise
    // bandwidth B_n = ∫₀^∞ df / (1 + (f/fc)⁴) = π fc / (2√2).
    let b_n = PI * 8.0 / (2.0 * 2f64.sqrt());
    assert!((g_gyro / (2.0 * b_n / 200.0).sqrt() - 1.0).abs() < 0.02, "{g_gyro}");
    assert!((g_acc / (2.0 * b_n / 1000.0).sqrt() - 1.0).abs() < 0.005, "{g_acc}");
    println!("noise gains: 1 kHz {g_acc}, 200 Hz {g_gyro}, 50 Hz {g_50}");
    let (analog, gps) = still_run(p, 0.02, 100_000);
    let (truth_analog, truth_gps) = expected(&p);
    let sigma = delivered_sigma(&p, truth_analog[9]);
    let gain = [g_acc, g_acc, g_acc, g_gyro, g_gyro, g_gyro, g_50, g_50, g_50, g_50];
    for c in 0..10 {
        let white = sigma[c] / gain[c];
        assert_noise(
            &format!("delivered channel {c}"),
            &analog[c],
            sigma[c],
            truth_analog[c],
            white,
        );
    }
    // GPS (digital, unfiltered): Table D.1 on each fix.
    let sigma_gps = gps_sigma(&p);
    for c in 0..6 {
        assert_noise(
            &format!("delivered gps {c}"),
            &gps[c],
            sigma_gps[c],
            truth_gps[c],
            sigma_gps[c],
        );
    }
}

/// On a steady trajectory (a level turn at 25 m/s: position, heading and so the field in body
/// axes change every step) the delivered noise — output minus the same run without noise (the
/// filter is linear) — is Table D.1's σ within 5 %: 50 000 outputs per channel, 4000 fixes
/// (statistical error of σ ≈ 0.5 % and 1.1 %).
#[test]
fn delivered_noise_is_table_d1_on_a_steady_trajectory() {
    let noisy = Params {
        seed: 21,
        ..Params::default()
    };
    let clean = Params {
        accel_std: 0.0,
        gyro_std: 0.0,
        mag_std: 0.0,
        pitot_std: 0.0,
        gps_latlon_std: 0.0,
        gps_height_std: 0.0,
        gps_vel_std: 0.0,
        ..noisy
    };
    let (mut a, mut b) = (SensorModel::new(noisy).unwrap(), SensorModel::new(clean).unwrap());
    let (h, steps, r) = (0.02, 50_000, 0.05);
    let truth_at = |t: f64| {
        let psi = r * t;
        Truth {
            pos_ned: Vector3::new(500.0 * psi.sin(), 500.0 * (1.0 - psi.cos()), -100.0),
            vel_ned: Vector3::new(25.0 * psi.cos(), 25.0 * psi.sin(), 0.0),
            rates: Vector3::new(0.0, 0.0, r),
            quat: tailsitter_physics::quat_from_euler_321(0.127, 0.05, psi),
            airspeed: 25.0,
            alpha: 0.05,
            beta: 0.0,
            specific_force: Vector3::new(0.3, 0.0, -9.89),
        }
    };
    a.start(&truth_at(0.0), 0.0).unwrap();
    b.start(&truth_at(0.0), 0.0).unwrap();
    let mut analog: Vec<Stats> = (0..10).map(|_| Stats::new()).collect();
    let mut gps: Vec<Stats> = (0..6).map(|_| Stats::new()).collect();
    let mut fixes = 0;
    for k in 0..steps {
        let t = k as f64 * h;
        let (ya, yb) = (a.step(&truth_at(t), t, h).unwrap(), b.step(&truth_at(t), t, h).unwrap());
        if t < 1.0 {
            fixes = ya.gps_fix_count;
            continue;
        }
        for (s, (xa, xb)) in analog.iter_mut().zip(ya.analog.iter().zip(yb.analog)) {
            s.push(xa - xb);
        }
        if ya.gps_fix_count != fixes {
            fixes = ya.gps_fix_count;
            let d = [
                ya.gps_latitude - yb.gps_latitude,
                ya.gps_longitude - yb.gps_longitude,
                ya.gps_height - yb.gps_height,
                ya.gps_vel.x - yb.gps_vel.x,
                ya.gps_vel.y - yb.gps_vel.y,
                ya.gps_vel.z - yb.gps_vel.z,
            ];
            for (s, x) in gps.iter_mut().zip(d) {
                s.push(x);
            }
        }
    }
    let u_r = 25.0 * 0.05f64.cos();
    let sigma = delivered_sigma(&noisy, u_r);
    for c in 0..10 {
        let ratio = analog[c].std() / sigma[c];
        println!(
            "steady turn, channel {c}: n = {}, σ/σ_Table D.1 = {ratio:.4}",
            analog[c].n
        );
        assert!((ratio - 1.0).abs() < 0.05, "channel {c}: {ratio}");
    }
    for (c, sg) in gps_sigma(&noisy).iter().enumerate() {
        let ratio = gps[c].std() / sg;
        println!("steady turn, gps {c}: n = {}, σ/σ_Table D.1 = {ratio:.4}", gps[c].n);
        assert!((ratio - 1.0).abs() < 0.05, "gps {c}: {ratio}");
    }
}

/// Amplitude ratio of the gyro output to a sine of frequency `f` on `p`, stepping at the
/// gyro's own period (one sample per step), noise off.
fn sine_gain(rate: f64, f: f64) -> f64 {
    let p = Params {
        gyro_rate: rate,
        gyro_std: 0.0,
        ..Params::default()
    };
    let mut m = SensorModel::new(p).unwrap();
    let mut truth = Truth::default();
    m.start(&truth, 0.0).unwrap();
    let h = 1.0 / rate;
    let periods = 40.0;
    let n = (periods * rate / f).round() as usize;
    let (mut sc, mut ss, mut cc, mut s2, mut c2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for k in 0..2 * n {
        let t = k as f64 * h;
        truth.rates.x = (2.0 * PI * f * t).sin();
        let y = m.step(&truth, t, h).unwrap().analog[3];
        // Second half only: the start-up transient has died out (time constant ≈ 28 ms).
        if k >= n {
            let (s, c) = ((2.0 * PI * f * t).sin(), (2.0 * PI * f * t).cos());
            ss += y * s;
            sc += y * c;
            s2 += s * s;
            c2 += c * c;
            cc += s * c;
        }
    }
    // Least-squares amplitude of y ≈ a sin + b cos (over whole periods cc ≈ 0).
    assert!(cc.abs() < 1e-6 * s2);
    ((ss / s2).powi(2) + (sc / c2).powi(2)).sqrt()
}

#[test]
fn butterworth_minus_3_db_point_is_at_8_hz() {
    for rate in [200.0, 50.0, 1000.0] {
        let g8 = sine_gain(rate, 8.0);
        println!("{rate} Hz: |H(8 Hz)| = {g8:.5} (−3 dB = 0.70711)");
        assert!((g8 - 0.5f64.sqrt()).abs() < 0.005, "{rate} Hz: |H(8 Hz)| = {g8}");
        // Maximally flat below, −12 dB/octave above (second order): |H(32 Hz)| ≈ 1/16.
        assert!(sine_gain(rate, 1.0) > 0.999);
        if rate >= 200.0 {
            let g32 = sine_gain(rate, 32.0);
            assert!(
                (g32 - 1.0 / 257f64.sqrt()).abs() < 0.01,
                "{rate} Hz: |H(32 Hz)| = {g32}"
            );
        }
    }
}

/// Sample and hold: with noise and filter off, after doStep(t, h) each output equals the
/// truth held over the step that contained its latest sample instant k/rate < t + h.
#[test]
fn outputs_hold_the_latest_sample_at_each_rate() {
    let h = 0.02;
    for (accel_rate, mag_rate, gps_rate, pitot_rate) in [
        (200.0, 50.0, 4.0, 50.0),
        (30.0, 7.0, 1.5, 100.0),
        (1000.0, 3.0, 10.0, 13.0),
    ] {
        let p = Params {
            accel_rate,
            mag_rate,
            gps_rate,
            pitot_rate,
            filter_enabled: false,
            accel_std: 0.0,
            mag_std: 0.0,
            pitot_std: 0.0,
            gps_height_std: 0.0,
            ..Params::default()
        };
        let mut m = SensorModel::new(p).unwrap();
        // The start time's truth: the time-carrying values below at t = 0.
        let mut truth = Truth {
            airspeed: 10.0,
            ..Truth::default()
        };
        m.start(&truth, 0.0).unwrap();
        for k in 0..500 {
            let t = k as f64 * h;
            // The truth carries the time of its step: accel_x = t, height = t.
            truth.specific_force.x = t;
            truth.pos_ned.z = -t;
            // Heading ψ = t (rad) and airspeed 10 + t (m/s) carry it to the magnetometer and pitot.
            truth.quat = tailsitter_physics::quat_from_euler_321(0.0, 0.0, t);
            truth.airspeed = 10.0 + t;
            let out = m.step(&truth, t, h).unwrap();
            // Latest sample instant before t + h, and the step that contains it.
            let held = |rate: f64| {
                let k_last = ((t + h) * rate - 1e-9).ceil() - 1.0;
                let t_sample = k_last / rate;
                ((t_sample / h) + 1e-9).floor() * h
            };
            let expect_accel = held(accel_rate);
            assert!(
                (out.analog[0] - expect_accel).abs() < 1e-9,
                "{accel_rate} Hz at t = {t}"
            );
            // GPS: count = number of instants k/rate < t + h; height = that step's time.
            let fixes = ((t + h) * gps_rate - 1e-9).ceil() as u32;
            assert_eq!(out.gps_fix_count, fixes, "{gps_rate} Hz at t = {t}");
            assert!((out.gps_height - held(gps_rate)).abs() < 1e-9, "GPS at t = {t}");
            // Magnetometer: the WMM field rotated by the heading of the held step.
            let m_expected = dcm_321(0.0, 0.0, held(mag_rate)) * Vector3::from(WMM_XYZ_GAUSS);
            assert!((out.mag() - m_expected).norm() < 1e-4, "{mag_rate} Hz at t = {t}");
            // Pitot: indicated = true airspeed at ρ₀ (α = β = 0) of the held step.
            assert!(
                (out.pitot_airspeed() - (10.0 + held(pitot_rate))).abs() < 1e-9,
                "{pitot_rate} Hz at t = {t}"
            );
        }
    }
}

#[test]
fn noise_is_reproducible_independent_of_the_step_size_and_differs_between_seeds() {
    let truth = still_truth();
    let run = |seed: u64, h: f64| {
        let mut m = SensorModel::new(Params {
            seed,
            ..Params::default()
        })
        .unwrap();
        m.start(&truth, 0.0).unwrap();
        let n = (1.0 / h).round() as usize;
        let mut out = m.measurements();
        for k in 0..n {
            out = m.step(&truth, k as f64 * h, h).unwrap();
        }
        out
    };
    let a = run(5, 0.02);
    assert_eq!(a, run(5, 0.02));
    // Each sensor has its own stream: after 1 s the same samples were drawn whatever h.
    let b = run(5, 0.005);
    for c in 0..10 {
        assert_eq!(a.analog[c].to_bits(), b.analog[c].to_bits(), "channel {c}");
    }
    assert_eq!(a.gps_latitude.to_bits(), b.gps_latitude.to_bits());
    let other = run(6, 0.02);
    assert!((0..10).all(|c| a.analog[c] != other.analog[c]));
}

#[test]
fn saved_state_continues_bit_identically() {
    let truth = still_truth();
    let p = Params {
        seed: 99,
        ..Params::default()
    };
    let mut a = SensorModel::new(p).unwrap();
    a.start(&truth, 0.0).unwrap();
    for k in 0..37 {
        a.step(&truth, k as f64 * 0.02, 0.02).unwrap();
    }
    let mut words = Vec::new();
    a.state().save(&mut |w| words.push(w));
    assert_eq!(words.len(), STATE_WORDS);
    let mut it = words.clone().into_iter();
    let restored = State::restore(&mut || it.next()).unwrap();
    assert_eq!(&restored, a.state());
    let mut b = SensorModel::new(p).unwrap();
    b.set_state(restored);
    for k in 37..300 {
        let t = k as f64 * 0.02;
        let (x, y) = (a.step(&truth, t, 0.02).unwrap(), b.step(&truth, t, 0.02).unwrap());
        assert_eq!(x, y);
        assert!((0..10).all(|c| x.analog[c].to_bits() == y.analog[c].to_bits()));
    }
    // Every truncation is an error, never a panic; a corrupted flag too.
    for n in 0..words.len() {
        let mut it = words[..n].iter().copied();
        assert!(State::restore(&mut || it.next()).is_err(), "{n}");
    }
    let mut bad = words.clone();
    bad[..4].fill(0); // the first stream's state: the generator's fixed point
    let mut it = bad.into_iter();
    assert!(State::restore(&mut || it.next()).is_err());
    let mut bad = words.clone();
    bad[STATE_WORDS - 3] = 7; // the stuck flag
    let mut it = bad.into_iter();
    assert!(State::restore(&mut || it.next()).is_err());
    let mut bad = words.clone();
    bad[STATE_WORDS - 1] = 2; // the fed flag
    let mut it = bad.into_iter();
    assert!(State::restore(&mut || it.next()).is_err());
}

#[test]
fn gps_dropout_holds_the_fix_and_clears_valid() {
    let p = Params {
        gps_dropout_start: 2.0,
        gps_dropout_duration: 1.0,
        ..Params::default()
    };
    let truth = still_truth();
    let mut m = SensorModel::new(p).unwrap();
    m.start(&truth, 0.0).unwrap();
    let mut before: Option<Measurements> = None;
    for k in 0..250 {
        let t = k as f64 * 0.02;
        let out = m.step(&truth, t, 0.02).unwrap();
        // Fix instants 0, 0.25, …: those in [2, 3) are missed (2.0, 2.25, 2.5, 2.75).
        let instants = ((t + 0.02) * 4.0 - 1e-9).ceil() as u32;
        let missed = instants.saturating_sub(8).min(4);
        assert_eq!(out.gps_fix_count, instants - missed, "t = {t}");
        let in_gap = (2.0..3.0).contains(&(((t + 0.02) * 4.0 - 1e-9).ceil() / 4.0 - 0.25));
        assert_eq!(out.gps_valid, !in_gap, "t = {t}");
        if in_gap {
            let b = before.unwrap();
            assert_eq!(out.gps_latitude, b.gps_latitude);
            assert_eq!(out.gps_vel, b.gps_vel);
        } else {
            before = Some(out);
        }
    }
}

#[test]
fn stuck_and_offset_faults_act_only_inside_their_window() {
    let truth = still_truth();
    let run = |mode: FaultMode| {
        let p = Params {
            fault_channel: 5, // imu_gyro_q
            fault_mode: mode,
            fault_start: 1.0,
            fault_duration: 0.5,
            fault_magnitude: 0.3,
            ..Params::default()
        };
        let mut m = SensorModel::new(p).unwrap();
        m.start(&truth, 0.0).unwrap();
        (0..150)
            .map(|k| m.step(&truth, k as f64 * 0.02, 0.02).unwrap().analog[4])
            .collect::<Vec<_>>()
    };
    let clean = run(FaultMode::None);
    let stuck = run(FaultMode::Stuck);
    let offset = run(FaultMode::Offset);
    for k in 0..150 {
        let t = k as f64 * 0.02;
        // Gyro samples at 200 Hz: the window [1, 1.5) holds the samples of steps t ∈ [1, 1.48].
        let inside = (1.0 - 1e-9..1.5 - 1e-9).contains(&t);
        if inside {
            assert_eq!(
                stuck[k], clean[49],
                "stuck at the last value before the window, t = {t}"
            );
            assert!((offset[k] - clean[k] - 0.3).abs() < 1e-12);
        } else {
            assert_eq!(stuck[k], clean[k], "t = {t}");
            assert_eq!(offset[k], clean[k], "t = {t}");
        }
    }
}

#[test]
fn bad_truth_is_rejected_without_changing_the_state() {
    let mut m = SensorModel::new(Params::default()).unwrap();
    m.start(&still_truth(), 0.0).unwrap();
    let before = *m.state();
    for (what, truth) in [
        (
            "pos_n",
            Truth {
                pos_ned: Vector3::new(f64::NAN, 0.0, 0.0),
                ..still_truth()
            },
        ),
        (
            "accel_z",
            Truth {
                specific_force: Vector3::new(0.0, 0.0, f64::INFINITY),
                ..still_truth()
            },
        ),
        (
            "norm",
            Truth {
                quat: Vector4::zeros(),
                ..still_truth()
            },
        ),
        (
            "negative",
            Truth {
                airspeed: -1.0,
                ..still_truth()
            },
        ),
        (
            "plausible",
            Truth {
                vel_ned: Vector3::new(0.0, 1e300, 0.0),
                ..still_truth()
            },
        ),
    ] {
        let e = m.step(&truth, 0.0, 0.02).unwrap_err();
        assert!(e.0.contains(what), "{e}");
        assert_eq!(m.state(), &before);
    }
    assert!(m.step(&still_truth(), f64::NAN, 0.02).is_err());
    assert!(m.step(&still_truth(), 0.0, -0.02).is_err());
    // A huge step is capped, finite and fast.
    let out = m.step(&still_truth(), 0.0, 1e9).unwrap();
    assert!(out.analog.iter().all(|x| x.is_finite()));
}

#[test]
fn out_of_range_parameters_are_refused_with_their_name() {
    let cases: [(&str, Params); 9] = [
        (
            "gyro_rate",
            Params {
                gyro_rate: 0.0,
                ..Params::default()
            },
        ),
        (
            "accel_rate",
            Params {
                accel_rate: f64::NAN,
                ..Params::default()
            },
        ),
        (
            "mag_std",
            Params {
                mag_std: -0.1,
                ..Params::default()
            },
        ),
        (
            "filter_bandwidth",
            Params {
                filter_bandwidth: 30.0, // above 0.45 × 50 Hz of the magnetometer
                ..Params::default()
            },
        ),
        (
            "reference point",
            Params {
                site: Site {
                    ref_latitude: 1.6,
                    ..Site::default()
                },
                ..Params::default()
            },
        ),
        (
            "mag_field_total",
            Params {
                site: Site {
                    mag_field_total: 0.0,
                    ..Site::default()
                },
                ..Params::default()
            },
        ),
        (
            "fault_channel",
            Params {
                fault_channel: 11,
                ..Params::default()
            },
        ),
        (
            "gps_dropout_duration",
            Params {
                gps_dropout_duration: -1.0,
                ..Params::default()
            },
        ),
        (
            "accel_bias",
            Params {
                accel_bias: Vector3::new(f64::NAN, 0.0, 0.0),
                ..Params::default()
            },
        ),
    ];
    for (name, p) in cases {
        let e = SensorModel::new(p).unwrap_err();
        assert!(e.0.contains(name), "{name}: {e}");
    }
    // With the filter disabled its bandwidth is not checked.
    assert!(SensorModel::new(Params {
        filter_enabled: false,
        filter_bandwidth: 30.0,
        ..Params::default()
    })
    .is_ok());
}

/// An all-zero true state before any sampled step (a master whose connections start at 0.0,
/// fmpy's `simulate_ssp`) is "no plant sample yet": outputs of the start held, nothing
/// sampled, the schedule not advanced, so the run continues exactly as one that never saw
/// it. After a sampled step the same input is refused.
#[test]
fn all_zero_truth_before_the_first_sample_is_held_and_refused_after() {
    let zero = Truth {
        pos_ned: Vector3::zeros(),
        vel_ned: Vector3::zeros(),
        rates: Vector3::zeros(),
        quat: Vector4::zeros(),
        airspeed: 0.0,
        alpha: 0.0,
        beta: 0.0,
        specific_force: Vector3::zeros(),
    };
    assert!(zero.is_all_zero() && !still_truth().is_all_zero());
    let mut held = SensorModel::new(Params::default()).unwrap();
    let start = held.start(&still_truth(), 0.0).unwrap();
    let state = *held.state();
    let (out, was_held) = held.step_or_hold(&zero, 0.0, 0.02).unwrap();
    assert!(was_held);
    assert_eq!(out, start);
    assert_eq!(held.state(), &state);
    // The next steps equal those of a run that never saw the zero input.
    let mut plain = SensorModel::new(Params::default()).unwrap();
    plain.start(&still_truth(), 0.0).unwrap();
    for k in 0..10 {
        let t = k as f64 * 0.02;
        let (a, h) = held.step_or_hold(&still_truth(), t, 0.02).unwrap();
        assert!(!h);
        assert_eq!(a, plain.step(&still_truth(), t, 0.02).unwrap());
    }
    // Now a plant sample has been seen: all zero is an invalid state (zero quaternion).
    let e = held.step_or_hold(&zero, 0.2, 0.02).unwrap_err();
    assert!(e.0.contains("norm"), "{e}");
    // The flag is part of the saved state.
    let mut words = Vec::new();
    held.state().save(&mut |w| words.push(w));
    assert_eq!(words.len(), STATE_WORDS);
    let mut it = words.into_iter();
    assert!(State::restore(&mut || it.next()).unwrap().fed);
}
