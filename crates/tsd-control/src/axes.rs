//! Measurement stage (Fig. 4.1, the fed-back signals of the inner loop): the frame the specific
//! accelerations are resolved in — the wind axes of the thesis (A.2.7) above
//! `wind_frame_speed_high`, the reference-path frame below `wind_frame_speed_low`, blended
//! between with the weight κ — and the measured A_W, B_W, C_W (2.5.25–2.5.28), the gravity
//! direction cosines e_i3 (4.2.17) and the stability-axis rates.

use crate::deviations::Deviations;
use crate::{band_weight, TsdController, HOVER_LOW_AIRSPEED_ALPHA, HOVER_WIND_CROSSFLOW, PATH_AIR_WIND_BAND};
use flight_mission::{Measurement, Phase};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// The air flow over the aircraft as the schedule and the frame blend see it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Airflow {
    /// Axial airspeed V̄ cos α cos β (m/s): the variable of the frame blend κ.
    pub axial_airspeed: f64,
    /// Crossflow V̄ √(1 − cos²α cos²β) (m/s).
    pub crossflow: f64,
    /// Crossflow of the loop design (m/s): in hover (not the take-off and landing phases) at
    /// least the measured horizontal wind, up to the top of [`HOVER_WIND_CROSSFLOW`].
    pub design_crossflow: f64,
    /// Weight (0–1) of the hover-in-wind design condition: the larger of the crossflow's and
    /// the measured wind's, in the take-off and landing phases the measured wind's.
    pub hover_wind: f64,
    /// Weight (0–1) of the measured α in the loop design: in hover below
    /// [`HOVER_LOW_AIRSPEED_ALPHA`] the design is at α = 0.
    pub alpha_weight: f64,
    /// Weight κ of the wind axes against the reference-path frame.
    pub kappa: f64,
}

impl TsdController {
    /// The air flow of the sample and the frame weight κ. `reference_airspeed` is the
    /// reference path's airspeed; `ground_phase` the take-off and landing phases.
    ///
    /// κ blends the wind axes (thesis) and the reference-path axes in the axial airspeed
    /// V̄ cos α cos β (not V̄: a crosswind in hover must not blend in wind axes that point along
    /// the span), and also scales the path-rotation terms of the loop models (a11 C_W, the
    /// gravity terms g₁/V̄, g₂/V̄ and their feedback linearisation): at low speed the wind axes
    /// turn as fast as the body and the time-scale separation fails.
    pub(crate) fn airflow(
        &self,
        meas: &Measurement,
        reference_airspeed: f64,
        ground_phase: bool,
        dev: Deviations,
    ) -> Airflow {
        let axial_airspeed = meas.airspeed * meas.alpha.cos() * meas.beta.cos();
        let crossflow = (meas.airspeed * meas.airspeed - axial_airspeed * axial_airspeed)
            .max(0.0)
            .sqrt();
        let hover = dev.hover_wind_design && reference_airspeed <= self.mission.v_vertical + 1.0;
        let alpha_weight = if hover && !ground_phase {
            band_weight(meas.airspeed, HOVER_LOW_AIRSPEED_ALPHA)
        } else {
            1.0
        };
        // Hover in wind (README, "Missions in wind", hover design): the crossflow follows the
        // attitude (a 3 m/s wind in the 3 m/s climb leaves 1–3 m/s of it, inside
        // HOVER_WIND_CROSSFLOW), so a schedule on it alone fed the pitch back into the pitch
        // loop's gains; under Jacobi the elevator went bang-bang. The design's crossflow is at
        // least the measured horizontal wind, which the attitude does not move (for the
        // normal poles' band at most HOVER_WIND_CROSSFLOW.1: uncapped, the slower normal poles
        // lost the 5–10 m/s tailwinds under Jacobi), once the mission logic's 1 s air-data
        // wind reaches the weathervane's release speed (1 m/s; 0.4 s after a 3 m/s step): the
        // avionics' air-data wind of a single sample in still air is noisy enough to move the
        // design (a 0 m/s cell under Jacobi 3.2 → 5.9 m). Still air: 0.
        let windy = self.wind_mission.wind_speed() >= self.weathervane.params().release_speed;
        let wind_speed = if hover && !ground_phase && windy {
            let w = guidance::weathervane::air_data_wind(meas);
            w.x.hypot(w.y)
        } else {
            0.0
        };
        let design_crossflow = crossflow.max(wind_speed.min(HOVER_WIND_CROSSFLOW.1));
        let hover_wind = if !hover {
            0.0
        } else if ground_phase {
            // Take-off and landing phases: weighted with the measured wind, not the crossflow
            // (the approach translates at up to 3 m/s in still air, with its own hover design).
            let w = guidance::weathervane::air_data_wind(meas);
            band_weight(w.x.hypot(w.y), HOVER_WIND_CROSSFLOW)
        } else {
            band_weight(crossflow.max(wind_speed), HOVER_WIND_CROSSFLOW)
        };
        // Tuned configuration, hover in wind: the reference-path frame is kept, κ scaled by
        // 1 − hover_wind (README, "Hover in a span-wise wind"): with the nose tilted into a
        // strong wind the air comes along the nose, the axial airspeed passes 4 m/s and the
        // blend turned the loops to wind axes that pointed 50–75° off the vertical; the axial
        // command Σ·i^W then fell to nothing (thrust to 0 N) and the aircraft fell.
        // Also in the take-off and landing phases, there with the measured wind's weight
        // (README, "Take-off and landing in wind").
        let kappa = self.frame_weight(axial_airspeed) * (1.0 - hover_wind);
        Airflow {
            axial_airspeed,
            crossflow,
            design_crossflow,
            hover_wind,
            alpha_weight,
            kappa,
        }
    }
}

impl TsdController {
    /// The frame weight κ of [`Self::airflow`] (`kappa`) limited, in wind, by the air
    /// velocity along the reference path in the front transition (tuned configuration; README,
    /// "Missions in wind"): κ_path = the same `wind_frame_speed_low/high` band applied to V̄ (i^W·t̂),
    /// the measured air velocity along the path's tangent t̂, and κ = min(κ, κ_path), blended
    /// in with the mission logic's 1 s air-data wind over [`PATH_AIR_WIND_BAND`].
    ///
    /// The axial airspeed measures the air along the nose, not along the path. With the wind
    /// behind the track the nose leans into the air flow (a 10 m/s quartering tailwind: 55°
    /// from the vertical, 10 m/s of axial airspeed) while the front transition's path climbs
    /// away from it, so at the end of the hover's design band (the reference at 4 m/s) the
    /// loops switched at once to wind axes 67–79° from the path (2–4.5 m/s of air along it):
    /// the axial command Σ·i^W and the normal command Σ·k^W split the path's thrust and lift
    /// anew (150 N and the collective flaps at their limit within a sample) and the aircraft
    /// departed (10 m/s from 135°, 225°: lost at 10.7 s). Along the path the air speed is what the
    /// wing flies on: the loops stay in the path frame (thrust-borne) until it builds, as the
    /// airspeed-scheduled transitions of PX4 and ArduPilot. Still air (no wind estimate) and
    /// the other phases: `kappa` unchanged (in the last vertical phase the limit cost a Jacobi
    /// turbulent handover cell, 3 m/s from 135°: 1.2 → 4.0 m).
    pub(crate) fn path_air_frame_weight(
        &self,
        meas: &Measurement,
        r: &crate::reference::ReferenceSignals,
        kappa: f64,
        dev: Deviations,
    ) -> f64 {
        if !dev.hover_wind_design || r.reference.phase != Phase::TransitionToLevel {
            return kappa;
        }
        let wind = self.wind_mission.wind_speed();
        if !wind.is_finite() {
            return kappa;
        }
        let windy = band_weight(wind, PATH_AIR_WIND_BAND);
        if windy == 0.0 {
            return kappa;
        }
        let q = &meas.quat;
        let att = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
        let (sa, ca) = meas.alpha.sin_cos();
        let (sb, cb) = meas.beta.sin_cos();
        let along = meas.airspeed * (att * Vector3::new(ca * cb, sb, sa * cb)).dot(&r.reference.tangent());
        let p = &self.params;
        let path = band_weight(along, (p.wind_frame_speed_low, p.wind_frame_speed_high));
        kappa + (kappa.min(path) - kappa) * windy
    }
}

/// The loop frame (i^W, j^W, k^W) and the signals measured in it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LoopAxes {
    /// Loop-frame axes in earth (NED) components.
    pub iw: Vector3<f64>,
    pub jw: Vector3<f64>,
    pub kw: Vector3<f64>,
    /// Measured A_W, B_W, C_W (m/s²).
    pub a_w: f64,
    pub b_w: f64,
    pub c_w: f64,
    /// Gravity direction cosines e_i3 = (axis i)·(down) (4.2.17).
    pub e13: f64,
    pub e23: f64,
    pub e33: f64,
    /// Stability-axis roll and yaw rates P, R (≈ P_W of (2.5.27) for small β) and the body
    /// pitch rate Q (rad/s).
    pub p_s: f64,
    pub q: f64,
    pub r_s: f64,
}

impl LoopAxes {
    /// The loop frame at weight `kappa` between the measured wind axes and the reference
    /// path's `tangent`, and the measurements resolved in it (rows of DCM^WB, (A.2.7)).
    pub fn measure(meas: &Measurement, tangent: &Vector3<f64>, kappa: f64) -> Self {
        let q = &meas.quat;
        let att = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
        // Body → earth.
        let r_eb = att.to_rotation_matrix();
        let (fa, fb) = {
            let (sa, ca) = meas.alpha.sin_cos();
            let (sb, cb) = meas.beta.sin_cos();
            let iw_e = r_eb * Vector3::new(ca * cb, sb, sa * cb);
            let blend = iw_e * kappa + tangent * (1.0 - kappa);
            let i_f = r_eb.transpose() * (if blend.norm() > 1e-6 { blend.normalize() } else { iw_e });
            (i_f.z.atan2(i_f.x), i_f.y.clamp(-1.0, 1.0).asin())
        };
        let (sa, ca) = fa.sin_cos();
        let (sb, cb) = fb.sin_cos();
        // Rows of DCM^WB (A.2.7): wind axes in body components.
        let iw_b = Vector3::new(ca * cb, sb, sa * cb);
        let jw_b = Vector3::new(-ca * sb, cb, -sa * sb);
        let kw_b = Vector3::new(-sa, 0.0, ca);
        let iw = r_eb * iw_b;
        let jw = r_eb * jw_b;
        let kw = r_eb * kw_b;
        let f = meas.specific_force_body;
        let (pr, qr, rr) = (meas.rates.x, meas.rates.y, meas.rates.z);
        Self {
            iw,
            jw,
            kw,
            a_w: iw_b.dot(&f),
            b_w: jw_b.dot(&f),
            c_w: kw_b.dot(&f),
            e13: iw.z,
            e23: jw.z,
            e33: kw.z,
            p_s: pr * ca + rr * sa,
            q: qr,
            r_s: rr * ca - pr * sa,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::deviations::Deviations;
    use crate::{TsdController, HOVER_WIND_CROSSFLOW};
    use flight_mission::{Measurement, MissionParams};
    use nalgebra::{UnitQuaternion, Vector3};

    /// Climbing at 3 m/s with the nose leaned `lean_deg` towards the north into a wind of
    /// `wind` m/s from the north: the airflow of the hover's design.
    fn climb(lean_deg: f64, wind: f64) -> Measurement {
        let r = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), (90.0 - lean_deg).to_radians());
        let v = Vector3::new(0.0, 0.0, -3.0);
        let w = Vector3::new(-wind, 0.0, 0.0);
        Measurement {
            vel_ned: v,
            ..Measurement::still_in_air(&r, &(r.inverse() * (v - w)))
        }
    }

    /// A 3 m/s wind in the 3 m/s climb, the nose leaned 24° into it (the Gauss-Seidel trim):
    /// 1.5 m/s of crossflow, a quarter of the hover-in-wind weight on the crossflow alone; the
    /// measured wind makes it whole whatever the lean (no gain schedule on the pitch) and
    /// lifts the normal poles' crossflow to 3 m/s, never above. Not before the mission logic's
    /// 1 s estimate reaches the release speed (1 m/s); still air: none.
    #[test]
    fn hover_design_weight_follows_the_measured_wind_not_the_attitude() {
        let mut c = TsdController::with_mission(MissionParams::default()).unwrap();
        let dev = Deviations::of(c.params());
        let v_ref = c.mission().v_vertical;
        // The logic's estimate: 3 m/s from the north.
        c.wind_mission.restore(&[-3.0, 0.0, 0.0, 0.0]);
        for lean in [10.0, 24.0, 40.0] {
            let air = c.airflow(&climb(lean, 3.0), v_ref, false, dev);
            assert!(
                air.crossflow < HOVER_WIND_CROSSFLOW.1 - 0.5,
                "{lean}: {}",
                air.crossflow
            );
            assert!((air.hover_wind - 1.0).abs() < 1e-9, "{lean}: {}", air.hover_wind);
            assert!(
                (air.design_crossflow - 3.0).abs() < 1e-9,
                "{lean}: {}",
                air.design_crossflow
            );
            assert_eq!(air.kappa, 0.0);
        }
        let air = c.airflow(&climb(24.0, 3.0), v_ref, false, dev);
        assert!((air.crossflow - 1.52).abs() < 0.01, "{}", air.crossflow);
        let air = c.airflow(&climb(24.0, 8.0), v_ref, false, dev);
        assert_eq!(air.design_crossflow, air.crossflow.max(3.0));
        // The estimate below 1 m/s (just after the step, or the avionics' noise in still air):
        // the crossflow's weight alone.
        c.wind_mission.restore(&[-0.9, 0.0, 0.0, 0.0]);
        let air = c.airflow(&climb(24.0, 3.0), v_ref, false, dev);
        assert!(
            (air.hover_wind - (air.crossflow - 1.0) / 2.0).abs() < 1e-9,
            "{}",
            air.hover_wind
        );
        assert_eq!(air.design_crossflow, air.crossflow);
        c.wind_mission.restore(&[0.0, 0.0, 0.0, 0.0]);
        let calm = c.airflow(&climb(0.0, 0.0), v_ref, false, dev);
        assert_eq!((calm.hover_wind, calm.design_crossflow), (0.0, calm.crossflow));
    }
}

#[cfg(test)]
mod path_air_tests {
    use crate::deviations::Deviations;
    use crate::reference::ReferenceSignals;
    use crate::{Reference, TsdController, TsdParams};
    use flight_mission::{Measurement, MissionParams, Phase};
    use nalgebra::{UnitQuaternion, Vector3};
    use tailsitter_physics::Airframe;

    /// The reference signals of a path with flight-path angle `gamma` (rad), northbound.
    fn path(gamma: f64) -> ReferenceSignals {
        ReferenceSignals {
            t_mission: 6.0,
            reference: Reference {
                phase: Phase::TransitionToLevel,
                pos: Vector3::zeros(),
                vel: Vector3::zeros(),
                specific_accel: Vector3::new(0.0, 0.0, -9.81),
                airspeed: 5.0,
                gamma,
            },
            ref_pos: Vector3::zeros(),
            sigma_ground: None,
            heading: 0.0,
        }
    }

    /// The front transition; the nose level towards the north, held still in a 10 m/s wind
    /// from the north: the air flows along the nose (10 m/s of axial airspeed). Along a level
    /// northbound path the wind axes keep the weight they have; up a vertical path (the air
    /// across it) the loops keep the path frame. No wind estimate (still air), the other phases
    /// and the thesis configuration: unchanged.
    #[test]
    fn wind_axes_need_the_air_along_the_path() {
        let mut c = TsdController::with_mission(MissionParams::default()).unwrap();
        let dev = Deviations::of(c.params());
        let m = Measurement::still_in_air(&UnitQuaternion::identity(), &Vector3::new(10.0, 0.0, 0.0));
        let up = path(core::f64::consts::FRAC_PI_2);
        let level = path(0.0);
        // Still air: the logic's estimate 0 (and none before its first sample).
        c.wind_mission.restore(&[0.0, 0.0, 0.0, 0.0]);
        assert_eq!(c.path_air_frame_weight(&m, &up, 0.8, dev), 0.8);
        c.wind_mission.restore(&[f64::NAN, f64::NAN, 0.0, 0.0]);
        assert_eq!(c.path_air_frame_weight(&m, &up, 0.8, dev), 0.8);
        // 10 m/s estimated: the air across a vertical path, along a level one.
        c.wind_mission.restore(&[-10.0, 0.0, 1.0, 0.0]);
        assert_eq!(c.path_air_frame_weight(&m, &up, 0.8, dev), 0.0);
        assert_eq!(c.path_air_frame_weight(&m, &level, 0.8, dev), 0.8);
        // Half-way up (45°): 7.1 m/s along the path, half-way through the 4–10 m/s band.
        let w = c.path_air_frame_weight(&m, &path(core::f64::consts::FRAC_PI_4), 0.8, dev);
        assert!((w - (10.0 * 0.5f64.sqrt() - 4.0) / 6.0).abs() < 1e-12, "{w}");
        // 2 m/s estimated: half the limit.
        c.wind_mission.restore(&[-2.0, 0.0, 0.0, 0.0]);
        assert!((c.path_air_frame_weight(&m, &up, 0.8, dev) - 0.4).abs() < 1e-12);
        // Other phases (the vertical ones, the take-off and landing phases) and the thesis
        // configuration.
        c.wind_mission.restore(&[-10.0, 0.0, 1.0, 0.0]);
        for phase in [
            Phase::Vertical1,
            Phase::Level,
            Phase::TransitionToVertical,
            Phase::Vertical2,
            Phase::TakeOff,
        ] {
            let mut other = up;
            other.reference.phase = phase;
            assert_eq!(c.path_air_frame_weight(&m, &other, 0.8, dev), 0.8, "{phase:?}");
        }
        let thesis = TsdParams {
            configuration: 1,
            ..TsdParams::default()
        };
        let mut t = TsdController::new(Airframe::default(), MissionParams::default(), thesis).unwrap();
        t.wind_mission.restore(&[-10.0, 0.0, 1.0, 0.0]);
        assert_eq!(t.path_air_frame_weight(&m, &up, 0.8, Deviations::of(t.params())), 0.8);
    }
}
