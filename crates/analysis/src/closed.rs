//! Closed-loop poles by one method for every controller (thesis §3.4.2 Fig. 3.16/3.17,
//! §4.4.1 Tables 4.3/4.4): the Jacobian of the closed-loop **sampled map**
//!
//! (x_k, c_k) ↦ (x_{k+1}, c_{k+1}): controller update at t_k on the measurement of x_k
//! (giving the command and its next internal state c_{k+1}), then the nonlinear plant
//! over one `sample_time` with that command held (Gauss–Seidel, docs/DESIGN.md §2),
//!
//! at the operating point the closed loop itself reaches on the default mission at the
//! analysis time (e.g. t = 18 s, late in level flight, or t = 4 s in the 3 m/s vertical
//! climb): the loop is flown from the vertical trim up to that time, so integrators hold
//! their trimmed values. The map's state is the plant's minimal state (position, body
//! velocity, a 3-component attitude error, rates, thrust, six servos: 19; the quaternion's
//! redundant norm direction is removed by the chart q = q* ⊗ exp(δθ/2)) plus the
//! controller's *dynamic* internal states (integrators), which are perturbed through the
//! controllers' own `save`/`restore` serialisation ([`Analysable`]). Eigenvalues z of the
//! Jacobian are mapped to the s-plane by s = ln(z)/T.
//!
//! Gain-scheduling is part of the map: a controller that reschedules on the perturbed
//! measurement contributes (∂K/∂x)(x − x_ref), which vanishes on the reference.

use closed_loop::{fly, measure, plant_inputs, Scenario};
use flight_mission::{ControllerInput, FlightController, MissionParams};
use nalgebra::{DMatrix, DVector, Vector3, Vector4};
use tailsitter_physics::{idx, InputVector, Plant, StateVector};

use crate::linalg::{eigen, z_to_s, Eigen, C64};

/// A controller whose internal state ([`flight_mission::SampledUnit::save`]) can be
/// perturbed, with the indices of the continuous dynamic states (integrators) in it.
pub trait Analysable: FlightController + std::fmt::Debug + Sync {
    /// The controller's complete internal state.
    fn save_state(&self) -> Vec<f64> {
        let mut v = Vec::new();
        self.save(&mut |x| v.push(x));
        v
    }
    /// Restore what [`Analysable::save_state`] wrote.
    fn load_state(&mut self, s: &[f64]) {
        let mut it = s.iter().copied();
        self.restore(&mut || it.next())
            .expect("a controller state restores what save wrote");
    }
    /// Indices of the continuous dynamic states in the saved vector, with their names.
    fn dynamic_states(&self) -> Vec<(usize, &'static str)>;
}

impl Analysable for lqr_control::LqrController {
    /// Layout of `LqrController::save`: [has_origin, origin(3), integrator, …, ∫ΔN, ∫ΔE, ∫Δh]:
    /// the airspeed integrator (3.2.12–3.2.14) and, with `position_integral = 1`, the three
    /// position integrators are the continuous states.
    fn dynamic_states(&self) -> Vec<(usize, &'static str)> {
        self.dynamic_state_layout()
    }
}

impl Analysable for tsd_control::TsdController {
    /// Layout of `TsdController::save`: [initialized, thrust, normal, roll, directional
    /// integrators, saturation mask]: the four inner-loop integrators (§4.2).
    fn dynamic_states(&self) -> Vec<(usize, &'static str)> {
        vec![(1, "I_axial"), (2, "I_normal"), (3, "I_roll"), (4, "I_directional")]
    }
}

/// Offset of the PX4 loops' states in `Px4Controller::save`, which writes the VTOL mode
/// logic, then [vel_int(3), MC rate integral(3), MC saturation flags(3), FW rate
/// integral(3), FW saturation flags(3), TECS throttle and pitch integrators, the previous
/// body rates(3), the surface saturation mask], then the ground phases: 21 values between.
fn px4_loops_offset() -> usize {
    px4_control::STATE_LEN - guidance::GroundPhases::SAVED_LEN - 21
}

impl Analysable for px4_control::Px4Controller {
    /// The states of the loops active in the mode of the last sample: in multicopter flight
    /// and the transitions the velocity integrator (PX4 `PositionControl`) and the MC rate
    /// integrator (`RateControl`); in fixed-wing flight the FW rate integrator and TECS's
    /// two integrators. Both modes also carry the previous body rates (the D terms'
    /// finite-difference angular acceleration): a one-sample delay, a state of the sampled
    /// map (its eigenvalue near z = 0 maps to a large negative s). Inactive integrators
    /// are left out (they would add poles at s = 0 that no input reaches).
    fn dynamic_states(&self) -> Vec<(usize, &'static str)> {
        let o = px4_loops_offset();
        let mut v = match self.mode() {
            px4_control::VtolMode::FixedWing => vec![
                (o + 9, "I_fw_p"),
                (o + 10, "I_fw_q"),
                (o + 11, "I_fw_r"),
                (o + 15, "I_tecs_thr"),
                (o + 16, "I_tecs_pitch"),
            ],
            _ => vec![
                (o, "I_vel_n"),
                (o + 1, "I_vel_e"),
                (o + 2, "I_vel_d"),
                (o + 3, "I_mc_x"),
                (o + 4, "I_mc_y"),
                (o + 5, "I_mc_z"),
            ],
        };
        v.extend([(o + 17, "p_prev"), (o + 18, "q_prev"), (o + 19, "r_prev")]);
        v
    }
}

/// Names of the 19 minimal plant coordinates of the map.
pub const PLANT_COORDS: [&str; 19] = [
    "pos_n", "pos_e", "pos_d", "u", "v", "w", "δθx", "δθy", "δθz", "p", "q", "r", "thrust", "δe", "δa", "δr", "δfc",
    "δfd", "δv",
];

/// Perturbation sizes of the central differences per minimal plant coordinate.
const PLANT_STEPS: [f64; 19] = [
    1e-5, 1e-5, 1e-5, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-4, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6,
];

/// Hamilton product of quaternions stored (x, y, z, w) (scalar last, A.2.8).
pub fn quat_mul(a: &Vector4<f64>, b: &Vector4<f64>) -> Vector4<f64> {
    let (av, aw) = (Vector3::new(a[0], a[1], a[2]), a[3]);
    let (bv, bw) = (Vector3::new(b[0], b[1], b[2]), b[3]);
    let v = bv * aw + av * bw + av.cross(&bv);
    Vector4::new(v.x, v.y, v.z, aw * bw - av.dot(&bv))
}

/// Conjugate (inverse of a unit quaternion).
fn quat_conj(a: &Vector4<f64>) -> Vector4<f64> {
    Vector4::new(-a[0], -a[1], -a[2], a[3])
}

/// Chart x*(δ): plant state from the base state and 19 minimal deviations.
pub fn plant_from_chart(base: &StateVector, d: &[f64]) -> StateVector {
    let mut x = *base;
    for k in 0..6 {
        x[idx::POS_N + k] += d[k];
    }
    let th = Vector3::new(d[6], d[7], d[8]);
    let a = th.norm();
    let e = if a > 0.0 {
        let s = (0.5 * a).sin() / a;
        Vector4::new(th.x * s, th.y * s, th.z * s, (0.5 * a).cos())
    } else {
        Vector4::new(0.0, 0.0, 0.0, 1.0)
    };
    let q0 = base.fixed_rows::<4>(idx::Q1).into_owned();
    let q = quat_mul(&q0, &e);
    x.fixed_rows_mut::<4>(idx::Q1).copy_from(&(q / q.norm()));
    for k in 0..10 {
        x[idx::P + k] += d[9 + k];
    }
    x
}

/// Inverse chart: the 19 minimal deviations of `x` from `base`.
pub fn chart_of_plant(base: &StateVector, x: &StateVector) -> [f64; 19] {
    let mut d = [0.0; 19];
    for k in 0..6 {
        d[k] = x[idx::POS_N + k] - base[idx::POS_N + k];
    }
    let q0 = base.fixed_rows::<4>(idx::Q1).into_owned();
    let q = x.fixed_rows::<4>(idx::Q1).into_owned();
    let mut e = quat_mul(&quat_conj(&q0), &q);
    if e[3] < 0.0 {
        e = -e;
    }
    let v = Vector3::new(e[0], e[1], e[2]);
    let s = v.norm();
    let th = if s > 0.0 {
        v * (2.0 * s.atan2(e[3]) / s)
    } else {
        Vector3::zeros()
    };
    d[6] = th.x;
    d[7] = th.y;
    d[8] = th.z;
    for k in 0..10 {
        d[9 + k] = x[idx::P + k] - base[idx::P + k];
    }
    d
}

/// The closed loop at an operating point: plant state, controller (with its state) and
/// time, all *before* the controller's update at `t`.
#[derive(Debug, Clone)]
pub struct OperatingPoint<C> {
    /// Sample time t_k (s).
    pub t: f64,
    /// Plant state at t_k.
    pub x: StateVector,
    /// Controller before its update at t_k.
    pub controller: C,
}

/// Fly the default-mission closed loop (Gauss–Seidel, comm step = sample time) from `x0`
/// up to time `t` (a multiple of the sample time): the operating point. `Err` if the
/// flight fails first.
pub fn operating_point<C: Analysable>(
    plant: &Plant,
    x0: StateVector,
    mut controller: C,
    mission: &MissionParams,
    t: f64,
) -> Result<OperatingPoint<C>, String> {
    let ts = mission.sample_time;
    let mut sc = Scenario::mission(*mission);
    sc.stop_time = t - ts;
    let trace = fly(plant, x0, &mut controller, &sc);
    if let Some(f) = trace.failure {
        return Err(f);
    }
    let last = trace.samples.last().ok_or("empty trace")?;
    let mut x = last.x;
    plant
        .advance(&mut x, &plant_inputs(&last.command), &Vector3::zeros(), ts)
        .map_err(|e| e.to_string())?;
    Ok(OperatingPoint {
        t: last.t + ts,
        x,
        controller,
    })
}

/// One step of the sampled map from the operating point perturbed by `z` (19 plant
/// chart coordinates, then the dynamic controller states), returned in the chart about
/// `base_next` (the unperturbed successor; `None` = about the operating point itself).
fn step<C: Analysable>(
    plant: &Plant,
    op: &OperatingPoint<C>,
    dyn_idx: &[usize],
    z: &DVector<f64>,
    ts: f64,
    base_next: Option<&(StateVector, Vec<f64>)>,
) -> (DVector<f64>, StateVector, Vec<f64>) {
    let x = plant_from_chart(&op.x, &z.as_slice()[..19]);
    let mut c = op.controller.clone();
    let mut s = c.save_state();
    for (k, i) in dyn_idx.iter().enumerate() {
        s[*i] += z[19 + k];
    }
    c.load_state(&s);
    let wind = Vector3::zeros();
    let m = measure(plant, &x, &InputVector::zeros(), &wind);
    let input = ControllerInput {
        t: op.t,
        measurement: m,
        ref_offset_ned: Vector3::zeros(),
    };
    let mut xn = x;
    let mut sn = s;
    if let Ok(out) = c.sample(&input) {
        let _ = plant.advance(&mut xn, &plant_inputs(&out.command), &wind, ts);
        sn = c.save_state();
    }
    let (bx, bs) = match base_next {
        Some((bx, bs)) => (*bx, bs.clone()),
        None => (op.x, op.controller.save_state()),
    };
    let d = chart_of_plant(&bx, &xn);
    let mut out = DVector::zeros(19 + dyn_idx.len());
    out.as_mut_slice()[..19].copy_from_slice(&d);
    for (k, i) in dyn_idx.iter().enumerate() {
        out[19 + k] = sn[*i] - bs[*i];
    }
    (out, xn, sn)
}

/// Closed-loop poles at an operating point.
#[derive(Debug, Clone)]
pub struct ClosedLoopPoles {
    /// Jacobian of the sampled map (19 + n_c square).
    pub jacobian: DMatrix<f64>,
    /// Eigen-pairs of the Jacobian (discrete poles z).
    pub discrete: Vec<Eigen>,
    /// s = ln(z)/T, same order as `discrete`.
    pub poles: Vec<C64>,
    /// Names of the map's coordinates.
    pub coords: Vec<String>,
}

/// The method on any sampled map: `f` maps deviations at step k to deviations at step k+1
/// (sample time `ts`); returns its central-difference Jacobian at `z0` (steps `h`), the
/// eigen-pairs (discrete poles z) and the s-plane poles ln(z)/T in the same order.
pub fn poles_of_map(
    f: impl Fn(&DVector<f64>) -> DVector<f64>,
    z0: &DVector<f64>,
    h: &[f64],
    ts: f64,
) -> (DMatrix<f64>, Vec<Eigen>, Vec<C64>) {
    let jac = crate::linalg::jacobian(f, z0, h);
    let discrete = eigen(&jac);
    let poles = discrete.iter().map(|e| z_to_s(e.value, ts)).collect();
    (jac, discrete, poles)
}

/// Jacobian of the closed-loop sampled map at `op` and its poles.
pub fn closed_loop_poles<C: Analysable>(plant: &Plant, op: &OperatingPoint<C>, ts: f64) -> ClosedLoopPoles {
    let dyn_states = op.controller.dynamic_states();
    let dyn_idx: Vec<usize> = dyn_states.iter().map(|d| d.0).collect();
    let n = 19 + dyn_idx.len();
    let z0 = DVector::zeros(n);
    let (_, xn, sn) = step(plant, op, &dyn_idx, &z0, ts, None);
    let base = (xn, sn.clone());
    let mut h: Vec<f64> = PLANT_STEPS.to_vec();
    for i in &dyn_idx {
        h.push(1e-6 * sn[*i].abs().max(1.0));
    }
    let (jac, discrete, poles) = poles_of_map(|z| step(plant, op, &dyn_idx, z, ts, Some(&base)).0, &z0, &h, ts);
    let mut coords: Vec<String> = PLANT_COORDS.iter().map(|s| s.to_string()).collect();
    coords.extend(dyn_states.iter().map(|d| d.1.to_string()));
    ClosedLoopPoles {
        jacobian: jac,
        discrete,
        poles,
        coords,
    }
}

/// The analysis flight conditions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Condition {
    /// Late in level flight at `v_level` (t = end of level flight − 2 s).
    Level,
    /// Vertical climb at `v_vertical` (t = end of the first vertical phase − 1 s).
    Vertical,
}

impl Condition {
    /// Both conditions.
    pub const ALL: [Condition; 2] = [Condition::Level, Condition::Vertical];

    /// Analysis time in `mission` (a multiple of the sample time).
    pub fn time(self, mission: &MissionParams) -> f64 {
        let s = mission.phase_starts();
        let t = match self {
            Condition::Level => s[3] - 2.0_f64.min(0.5 * mission.t_level),
            Condition::Vertical => s[1] - 1.0_f64.min(0.5 * mission.t_vertical_1),
        };
        (t / mission.sample_time).round() * mission.sample_time
    }

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Condition::Level => "level",
            Condition::Vertical => "vertical",
        }
    }
}

/// Closed-loop poles of `controller` flying `plant` at `cond` of `mission`, from the
/// vertical-climb trim of the plant (`Err` if the trim or the flight up to the
/// operating point fails).
pub fn poles_at<C: Analysable>(
    plant: &Plant,
    controller: C,
    mission: &MissionParams,
    cond: Condition,
) -> Result<ClosedLoopPoles, String> {
    let x0 = plant
        .trim_vertical_climb(mission.v_vertical)
        .map_err(|e| format!("vertical trim: {e}"))?
        .state;
    let op = operating_point(plant, x0, controller, mission, cond.time(mission))?;
    Ok(closed_loop_poles(plant, &op, mission.sample_time))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chart_round_trip() {
        let plant = Plant::new(tailsitter_physics::Airframe::default());
        let x = plant.trim_level(25.0).unwrap().state;
        let d: Vec<f64> = (0..19).map(|i| 1e-3 * (i as f64 - 9.0)).collect();
        let y = plant_from_chart(&x, &d);
        let back = chart_of_plant(&x, &y);
        for i in 0..19 {
            assert!((back[i] - d[i]).abs() < 1e-12, "{i}: {} vs {}", back[i], d[i]);
        }
    }
}
