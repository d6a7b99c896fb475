use super::*;
use std::f64::consts::PI;

fn inputs(h: f64, v: f64) -> Inputs {
    Inputs {
        pos_ned: [3.0, -4.0, -h],
        airspeed: v,
    }
}

fn turbulent(w20: f64) -> Params {
    Params {
        turbulence_w20: w20,
        ..Params::default()
    }
}

#[test]
fn defaults_are_valid_and_quiet() {
    let p = Params::default();
    p.validate().unwrap();
    let mut a = Atmosphere::new(p).unwrap();
    assert_eq!(a.start(&inputs(10.0, 3.0), 0.0).unwrap(), [0.0; 3]);
    for k in 1..=1000 {
        assert_eq!(a.step(&inputs(10.0, 3.0), k as f64 * 0.02, 0.02).unwrap(), [0.0; 3]);
    }
}

#[test]
fn every_invalid_parameter_is_an_error_naming_it() {
    type Setter = Box<dyn Fn(&mut Params)>;
    let cases: Vec<(&str, Setter)> = vec![
        ("wind_speed", Box::new(|p| p.wind_speed = f64::NAN)),
        ("wind_speed", Box::new(|p| p.wind_speed = -1.0)),
        ("wind_from", Box::new(|p| p.wind_from = f64::INFINITY)),
        ("wind_ref_height", Box::new(|p| p.wind_ref_height = 0.0)),
        ("wind_profile_exponent", Box::new(|p| p.wind_profile_exponent = 1.5)),
        ("wind_roughness_length", Box::new(|p| p.wind_roughness_length = 0.0)),
        ("wind_min_height", Box::new(|p| p.wind_min_height = f64::NAN)),
        ("origin_height", Box::new(|p| p.origin_height = 1e9)),
        ("turbulence_w20", Box::new(|p| p.turbulence_w20 = -3.0)),
        ("turbulence_sample_time", Box::new(|p| p.turbulence_sample_time = 0.0)),
        ("turbulence_min_airspeed", Box::new(|p| p.turbulence_min_airspeed = 0.0)),
        ("gust_amplitude_e", Box::new(|p| p.gust_amplitude_e = f64::NAN)),
        ("gust_start", Box::new(|p| p.gust_start = f64::NEG_INFINITY)),
        ("gust_duration", Box::new(|p| p.gust_duration = -1.0)),
        ("wind_profile", Box::new(|p| p.wind_profile = 3)),
        ("turbulence_model", Box::new(|p| p.turbulence_model = 2)),
        ("turbulence_intensity", Box::new(|p| p.turbulence_intensity = -1)),
        (
            "wind_min_height",
            Box::new(|p| {
                p.wind_profile = 2;
                p.wind_roughness_length = 0.5;
            }),
        ),
        (
            "wind_ref_height",
            Box::new(|p| {
                p.wind_profile = 2;
                p.wind_roughness_length = 8.0;
                p.wind_min_height = 9.0;
            }),
        ),
    ];
    for (name, set) in cases {
        let mut p = Params::default();
        set(&mut p);
        let e = Atmosphere::new(p).expect_err(name);
        assert!(e.0.starts_with(name), "{name}: {e}");
    }
}

#[test]
fn profiles_give_the_set_speed_at_the_reference_height_and_follow_their_law() {
    for (law, z0) in [(0, 0.03), (1, 0.03), (2, 0.03), (2, 0.5)] {
        let p = Params {
            wind_speed: 8.0,
            wind_profile: law,
            wind_roughness_length: z0,
            wind_min_height: 1.0,
            ..Params::default()
        };
        let a = Atmosphere::new(p).unwrap();
        assert!((a.steady_speed(6.1) - 8.0).abs() < 1e-14, "law {law}");
        let at = |h: f64| a.steady_speed(h);
        let expected = |h: f64| match law {
            0 => 8.0,
            1 => 8.0 * (h / 6.1).powf(1.0 / 7.0),
            _ => 8.0 * (h / z0).ln() / (6.1 / z0).ln(),
        };
        for h in [1.0, 3.0, 30.0, 300.0] {
            assert!((at(h) - expected(h)).abs() < 1e-12 * expected(h), "law {law}, h {h}");
        }
        // Clamped below wind_min_height (on and under the ground too).
        for h in [0.5, 0.0, -2.0] {
            assert_eq!(at(h), at(1.0), "law {law}, h {h}");
        }
        assert_eq!(at(1e6), at(PROFILE_MAX_HEIGHT));
        assert!(at(1e300).is_finite());
    }
    // The power law at 1/7: doubling the height gives 2^(1/7) = 1.1041 times the speed.
    let a = Atmosphere::new(Params {
        wind_speed: 5.0,
        ..Params::default()
    })
    .unwrap();
    assert!((a.steady_speed(12.2) / a.steady_speed(6.1) - 2f64.powf(1.0 / 7.0)).abs() < 1e-14);
}

#[test]
fn the_wind_blows_from_wind_from_and_height_comes_from_pos_d_and_origin_height() {
    let speed = 6.0;
    for (from_deg, expected) in [
        (0.0, [-speed, 0.0]),
        (90.0, [0.0, -speed]),
        (180.0, [speed, 0.0]),
        (270.0, [0.0, speed]),
    ] {
        let p = Params {
            wind_speed: speed,
            wind_from: from_deg * PI / 180.0,
            ..Params::default()
        };
        let mut a = Atmosphere::new(p).unwrap();
        let w = a.start(&inputs(6.1, 0.0), 0.0).unwrap();
        for i in 0..2 {
            assert!((w[i] - expected[i]).abs() < 1e-13, "from {from_deg} deg: {w:?}");
        }
        assert_eq!(w[2], 0.0);
    }
    // origin_height shifts the height: pos_d = 0 at an origin 6.1 m above the ground.
    let p = Params {
        wind_speed: 4.0,
        origin_height: 6.1,
        ..Params::default()
    };
    let mut a = Atmosphere::new(p).unwrap();
    let w = a.start(&inputs(0.0, 0.0), 0.0).unwrap();
    assert!((w[0] + 4.0).abs() < 1e-14, "{w:?}");
}

#[test]
fn the_gust_peaks_at_its_middle_and_lasts_its_duration() {
    let p = Params {
        gust_amplitude_n: 2.0,
        gust_amplitude_e: -1.0,
        gust_amplitude_d: 0.5,
        gust_start: 1.0,
        gust_duration: 0.4,
        // The gust is evaluated on the internal sample grid: 1 ms here.
        turbulence_sample_time: 0.001,
        ..Params::default()
    };
    let mut a = Atmosphere::new(p).unwrap();
    let i = inputs(20.0, 10.0);
    a.start(&i, 0.0).unwrap();
    let h = 0.001;
    let mut peak = (0.0, 0.0);
    let mut nonzero = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 1..=3000 {
        let t = k as f64 * h;
        let w = a.step(&i, t, h).unwrap();
        // Same shape on every axis.
        assert!((w[1] + 0.5 * w[0]).abs() < 1e-15 && (w[2] - 0.25 * w[0]).abs() < 1e-15);
        assert!((0.0..=2.0).contains(&w[0]), "{w:?}");
        if w[0] > peak.0 {
            peak = (w[0], t);
        }
        if w[0] > 0.0 {
            nonzero = (nonzero.0.min(t), nonzero.1.max(t));
        }
    }
    assert!((peak.0 - 2.0).abs() < 1e-12 && (peak.1 - 1.2).abs() < 1e-9, "{peak:?}");
    assert!(
        (nonzero.0 - 1.001).abs() < 1e-9 && (nonzero.1 - 1.399).abs() < 1e-9,
        "{nonzero:?}"
    );
    // Exactly the half amplitude at a quarter of the duration.
    let g = a.gust(1.1);
    assert!((g[0] - 1.0).abs() < 1e-12);
}

#[test]
fn intensities_and_scale_lengths_follow_the_low_altitude_form() {
    // h = 100 ft: 0.177 + 0.0823 = 0.2593; σ_u/σ_w = 0.2593^-0.4, L_u = 100/0.2593^1.2 ft.
    let h = 100.0 * FOOT;
    let s = dryden::intensities(h, 10.0);
    assert!((s[2] - 1.0).abs() < 1e-15);
    assert!((s[0] - 0.2593f64.powf(-0.4)).abs() < 1e-12 && s[0] == s[1]);
    let l = dryden::scale_lengths(h);
    assert!((l[2] - h).abs() < 1e-12);
    assert!((l[0] / FOOT - 100.0 / 0.2593f64.powf(1.2)).abs() < 1e-9 && l[0] == l[1]);
    // At 1000 ft the form is isotropic: σ_u = σ_w, L_u = L_w = 1000 ft; held above.
    let s = dryden::intensities(1000.0 * FOOT, 10.0);
    assert!((s[0] - s[2]).abs() < 1e-12);
    assert_eq!(dryden::scale_lengths(2000.0), dryden::scale_lengths(1000.0 * FOOT));
    assert_eq!(dryden::scale_lengths(0.0), dryden::scale_lengths(10.0 * FOOT));
    // Presets: light 15 kt.
    let p = Params {
        turbulence_intensity: 1,
        ..Params::default()
    };
    assert!((p.w20() - 7.716_666_666_666_667).abs() < 1e-12);
    assert_eq!(turbulent(9.0).w20(), 9.0);
    let off = Params {
        turbulence_model: 0,
        ..turbulent(9.0)
    };
    assert_eq!(off.w20(), 0.0);
}

#[test]
fn the_discretisation_is_exact_its_covariance_stationary() {
    // Φ P Φᵀ + Q = P for P = [[1, 1], [1, 2]], over small and large steps (series and direct branches).
    for eta in [1e-6, 1e-3, 0.1, 0.49, 0.5, 0.51, 2.0, 20.0, 1e9] {
        let c = dryden::SecondOrder::new(eta);
        let mut p = [[0.0; 2]; 2];
        // Propagate the stationary covariance through one step by sampling the map on a basis.
        let phi = |x: [f64; 2]| {
            let mut y = x;
            c.advance_for_test(&mut y, 0.0, 0.0);
            y
        };
        let (a, b) = (phi([1.0, 0.0]), phi([0.0, 1.0]));
        let m = [[a[0], b[0]], [a[1], b[1]]];
        let p0 = [[1.0, 1.0], [1.0, 2.0]];
        for i in 0..2 {
            for j in 0..2 {
                for k in 0..2 {
                    for l in 0..2 {
                        p[i][j] += m[i][k] * p0[k][l] * m[j][l];
                    }
                }
            }
        }
        let ch = c.chol_for_test();
        let q = [
            [ch[0] * ch[0], ch[0] * ch[1]],
            [ch[0] * ch[1], ch[1] * ch[1] + ch[2] * ch[2]],
        ];
        for i in 0..2 {
            for j in 0..2 {
                assert!((p[i][j] + q[i][j] - p0[i][j]).abs() < 1e-14, "eta {eta}: {p:?} {q:?}");
            }
        }
        // Small steps: Q₁₁ ≈ (4/3) η³ to relative accuracy (no cancellation).
        if eta < 1e-2 {
            let q11 = ch[0] * ch[0];
            let series = 4.0 / 3.0 * eta.powi(3) * (1.0 - 1.5 * eta);
            assert!(
                (q11 / series - 1.0).abs() < 2.0 * eta * eta + 1e-12,
                "eta {eta}: {q11} vs {series}"
            );
        }
    }
}

fn run(params: Params, h: f64, v: f64, steps: &[f64], n: usize) -> Vec<[f64; 3]> {
    let mut a = Atmosphere::new(params).unwrap();
    let i = inputs(h, v);
    let mut out = vec![a.start(&i, 0.0).unwrap()];
    let mut t = 0.0;
    for k in 0..n {
        let dt = steps[k % steps.len()];
        t += dt;
        out.push(a.step(&i, t, dt).unwrap());
    }
    out
}

#[test]
fn the_seed_reproduces_bit_exactly_and_different_seeds_differ() {
    let p = turbulent(10.0);
    let a = run(p, 30.0, 12.0, &[0.02], 500);
    let b = run(p, 30.0, 12.0, &[0.02], 500);
    assert_eq!(a, b);
    let c = run(Params { seed: 2, ..p }, 30.0, 12.0, &[0.02], 500);
    let same = a.iter().zip(&c).filter(|(x, y)| x == y).count();
    assert_eq!(same, 0);
    // Negative seeds are distinct too.
    let d = run(Params { seed: -1, ..p }, 30.0, 12.0, &[0.02], 10);
    assert_ne!(d[3], a[3]);
}

#[test]
fn save_restore_mid_run_continues_bit_exactly() {
    let p = Params {
        wind_speed: 5.0,
        wind_from: 1.0,
        gust_amplitude_d: 3.0,
        gust_start: 0.5,
        ..turbulent(12.0)
    };
    let mut a = Atmosphere::new(p).unwrap();
    let input_at = |k: usize| inputs(5.0 + 0.1 * k as f64, 3.0 + 0.05 * k as f64);
    a.start(&input_at(0), 0.0).unwrap();
    let h = 0.02;
    for k in 1..=100 {
        a.step(&input_at(k), k as f64 * h, h).unwrap();
    }
    let mut words = Vec::new();
    a.state().save(&mut |w| words.push(w));
    assert_eq!(words.len(), STATE_WORDS);
    let reference: Vec<_> = (101..=300)
        .map(|k| a.step(&input_at(k), k as f64 * h, h).unwrap())
        .collect();
    // Into a fresh model of the same parameters (and into one that has run on).
    let mut b = Atmosphere::new(p).unwrap();
    let mut it = words.iter().copied();
    b.set_state(State::restore(&mut || it.next()).unwrap());
    let again: Vec<_> = (101..=300)
        .map(|k| b.step(&input_at(k), k as f64 * h, h).unwrap())
        .collect();
    assert_eq!(reference, again);
    let mut it = words.iter().copied();
    a.set_state(State::restore(&mut || it.next()).unwrap());
    let third: Vec<_> = (101..=300)
        .map(|k| a.step(&input_at(k), k as f64 * h, h).unwrap())
        .collect();
    assert_eq!(reference, third);
    // Truncated and corrupted states are refused.
    let mut it = words[..STATE_WORDS - 1].iter().copied();
    assert!(State::restore(&mut || it.next()).is_err());
    let mut bad = words.clone();
    bad[0..4].copy_from_slice(&[0; 4]);
    let mut it = bad.iter().copied();
    assert!(State::restore(&mut || it.next()).is_err());
    let mut bad = words.clone();
    bad[7] = f64::NAN.to_bits();
    let mut it = bad.iter().copied();
    assert!(State::restore(&mut || it.next()).is_err());
    let mut bad = words.clone();
    bad[STATE_WORDS - 1] = 2;
    let mut it = bad.iter().copied();
    assert!(State::restore(&mut || it.next()).is_err());
}

#[test]
fn the_output_at_common_instants_does_not_depend_on_the_communication_step() {
    // The internal clock (t0 + k·T) is independent of the step: with inputs constant,
    // the wind after a step to a common instant is the same to the bit.
    let p = Params {
        wind_speed: 7.0,
        wind_from: 2.0,
        gust_amplitude_n: 1.5,
        gust_start: 0.3,
        gust_duration: 0.5,
        ..turbulent(15.0)
    };
    let (h, v) = (15.0, 20.0);
    let n20 = 1000;
    let w5 = run(p, h, v, &[0.005], 4 * n20);
    let w10 = run(p, h, v, &[0.01], 2 * n20);
    let w20 = run(p, h, v, &[0.02], n20);
    for k in 0..=n20 {
        assert_eq!(w20[k], w10[2 * k], "k = {k}");
        assert_eq!(w20[k], w5[4 * k], "k = {k}");
    }
    // Uneven steps too (the clock's tolerance absorbs the rounding of the accumulated time).
    let wmix = run(p, h, v, &[0.005, 0.015, 0.01, 0.01], 4 * (n20 / 2));
    for k in 0..n20 / 2 {
        assert_eq!(wmix[4 * (k + 1)], w20[2 * (k + 1)], "k = {k}");
    }
    // A step longer than the sample time takes every sample it covers.
    let w100 = run(p, h, v, &[0.1], n20 / 5);
    for k in 0..=n20 / 5 {
        assert_eq!(w100[k], w20[5 * k], "k = {k}");
    }
}

#[test]
fn non_finite_inputs_and_steps_are_errors_and_huge_ones_stay_finite() {
    let mut a = Atmosphere::new(Params {
        wind_speed: 100.0,
        wind_profile_exponent: 1.0,
        ..turbulent(50.0)
    })
    .unwrap();
    assert!(a.step(&inputs(1.0, 1.0), 0.0, 0.01).is_err(), "step before start");
    a.start(&inputs(1.0, 1.0), 0.0).unwrap();
    let e = a.step(&inputs(f64::NAN, 1.0), 0.01, 0.01).unwrap_err();
    assert!(e.0.contains("pos_d"), "{e}");
    let e = a.step(&inputs(1.0, f64::INFINITY), 0.01, 0.01).unwrap_err();
    assert!(e.0.contains("airspeed"), "{e}");
    assert!(a.step(&inputs(1.0, 1.0), f64::NAN, 0.01).is_err());
    for (h, v) in [(1e300, 1e300), (-1e300, -1e300), (0.0, 0.0), (1e6, -5.0)] {
        let w = a.step(&inputs(h, v), 0.02, 0.01).unwrap();
        assert!(w.iter().all(|x| x.is_finite()), "h {h}, V {v}: {w:?}");
    }
    // Too many samples in one step: an error naming the fix, not a hang.
    let e = a.step(&inputs(1.0, 1.0), 1e6, 0.01).unwrap_err();
    assert!(e.0.contains("turbulence_sample_time"), "{e}");
}

#[test]
fn below_the_airspeed_floor_the_turbulence_is_that_at_the_floor() {
    let p = turbulent(10.0);
    let at_floor = run(p, 8.0, p.turbulence_min_airspeed, &[0.02], 300);
    for v in [0.0, 0.3, -2.0] {
        assert_eq!(run(p, 8.0, v, &[0.02], 300), at_floor, "V = {v}");
    }
    assert_ne!(run(p, 8.0, 1.5, &[0.02], 300), at_floor);
    // Hover at the floor: correlation time L_u / 1 m/s; the turbulence still varies.
    let w = run(p, 8.0, 0.0, &[0.02], 300);
    assert!(w.windows(2).all(|x| x[0] != x[1]));
}
