//! The 20-state plant: state derivatives (§2.2, §2.3, App. D.5), fixed-step Runge–Kutta
//! integration (Dormand–Prince 5 with checked steps, or RK4), outputs, trims and
//! linearisation.

use crate::numeric::central_differences;
use nalgebra::{SMatrix, Vector3, Vector4};

use crate::aero::{ForcesMoments, Surfaces};
use crate::airframe::Airframe;
use crate::attitude::{dcm_earth_to_body, euler_321_from_quat, quat_derivative, quat_from_euler_321};
use crate::error::PhysicsError;
use crate::global_aero::{AeroModel, AeroRegime, GlobalAero};
use crate::ground::{ContactAnchors, ContactState, Ground};
use crate::idx::{self, *};
use crate::{InputVector, StateVector, N_INPUTS, N_STATES};

/// Limits of the sane envelope checked by [`Plant::advance`] after every internal step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    /// Maximum inertial speed |(u, v, w)| and airspeed (m/s).
    pub max_speed: f64,
    /// Maximum |p|, |q|, |r| (rad/s).
    pub max_rate: f64,
    /// Maximum |position component| (m).
    pub max_position: f64,
}

impl Default for Envelope {
    fn default() -> Self {
        Self {
            max_speed: 200.0,
            max_rate: 50.0,
            max_position: 1e6,
        }
    }
}

/// Largest number of internal steps one [`Plant::advance`] takes (≈ 6700 s of flight at the
/// default step).
pub const MAX_SUBSTEPS: f64 = 1e6;

/// Default internal step of [`Plant::advance`] (s), 20/3 ms: three steps per 20 ms
/// communication step (the FMU parameter `integration_step`). Chosen with
/// [`Integrator::default`] by measured error (docs/PERFORMANCE.md, "the integrator").
pub const DEFAULT_INTEGRATION_STEP: f64 = 0.02 / 3.0;

/// Deepest halving of a checked internal step ([`Integrator::Dp5Checked`]) where a ground
/// contact point may touch (2⁻²⁰ of the step, 6 ns at the default step). The contact force
/// jumps at touchdown (its damping term), so the substep holding the onset is in error in
/// proportion to its length: 1.9 mm after a 15 m/s touchdown at the airborne depth (2⁻⁴),
/// 7 µm at 2⁻¹⁰, 8 nm at 2⁻²⁰ against a step 512 times finer. The halving descends only at
/// the onset (a few dozen extra substeps per touchdown or lift-off); airborne steps keep
/// their own `max_halvings`.
pub const CONTACT_HALVINGS: u32 = 20;

/// Most substeps one checked internal step ([`Integrator::Dp5Checked`]) makes before it
/// stops refining and accepts the rest at the level it has reached (climbing back to the
/// step's own grid): a bound on the work of one `fmi2DoStep`. Touchdowns and lift-offs take
/// a few hundred; an error estimate that never meets the tolerance (a non-finite one, or a
/// contact that keeps the estimate up) would otherwise take 2²⁰ substeps per internal step.
pub const MAX_CHECKED_SUBSTEPS: u64 = 8192;

/// Fixed-step explicit Runge–Kutta method of [`Plant::advance`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    /// Classical fourth-order Runge–Kutta: 4 right-hand sides per step.
    Rk4,
    /// The fifth-order solution of Dormand & Prince's embedded 5(4) pair at fixed step
    /// ([`dp5`]): 6 right-hand sides per step (the pair's seventh, first-same-as-last stage
    /// only feeds the embedded error estimate, which a fixed step does not use).
    Dp5,
    /// [`Integrator::Dp5`] with its embedded error estimate: a step whose estimate exceeds
    /// `tolerance` is taken again as two halves, each checked the same way, at most
    /// `max_halvings` times (a dyadic grid inside the internal step: the result depends only
    /// on the step's start state, commands and wind).
    Dp5Checked {
        /// Largest embedded error estimate accepted for one (sub)step: max over position (m),
        /// velocity (m/s), quaternion and rates (rad/s).
        tolerance: f64,
        /// Deepest halving of the internal step.
        max_halvings: u32,
    },
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator::Dp5Checked {
            tolerance: 1e-9,
            max_halvings: 4,
        }
    }
}

/// The Butcher tableau of Dormand & Prince's 5(4) pair, fifth-order solution (J.R. Dormand,
/// P.J. Prince, "A family of embedded Runge–Kutta formulae", J. Comput. Appl. Math. 6(1),
/// 19–26, 1980, the method RK5(4)7M; also Hairer, Nørsett & Wanner, *Solving Ordinary
/// Differential Equations I*, Table II.5.2). `A[i][j]` is a_(i+1)(j+1); the stage times
/// c_i = Σ_j a_ij. Its 17 order conditions up to order 5 are checked in the tests.
pub mod dp5 {
    /// Number of stages of the fifth-order solution.
    pub const STAGES: usize = 6;
    /// Stage coefficients a_ij (strictly lower triangular).
    pub const A: [[f64; STAGES]; STAGES] = [
        [0.0; STAGES],
        [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
            0.0,
        ],
        [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
            0.0,
        ],
    ];
    /// Weights b_i of the fifth-order solution.
    pub const B: [f64; STAGES] = [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ];
    /// Weights b̂_i of the embedded fourth-order solution; its seventh stage is f at the
    /// fifth-order result (a₇ⱼ = b_j).
    pub const B_HAT: [f64; STAGES + 1] = [
        5179.0 / 57600.0,
        0.0,
        7571.0 / 16695.0,
        393.0 / 640.0,
        -92097.0 / 339200.0,
        187.0 / 2100.0,
        1.0 / 40.0,
    ];
}

/// The nonlinear plant: airframe parameters and the integrator's maximum step.
#[derive(Debug, Clone, PartialEq)]
pub struct Plant {
    /// Airframe parameters.
    pub airframe: Airframe,
    /// Maximum internal integration step (s) (default [`DEFAULT_INTEGRATION_STEP`] = 20/3 ms).
    /// [`Plant::advance`] splits a communication step h into ⌈h / integration_step⌉ equal
    /// steps.
    pub integration_step: f64,
    /// The fixed-step method (default: [`Integrator::default`]).
    pub integrator: Integrator,
    /// Envelope checked after every substep.
    pub envelope: Envelope,
    /// Aerodynamic model selection and global-model parameters. [`Plant::new`] selects the
    /// thesis's model ([`AeroModel::Thesis`], the controllers' design model); the FMU's
    /// default (`aero_model` = 1) is the global model.
    pub aero: GlobalAero,
    /// Ground plane and contact points (default: [`Ground::none`]).
    pub ground: Ground,
}

/// Outputs of the plant beyond the raw states.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outputs {
    /// Inertial velocity in earth (NED) axes (m/s).
    pub vel_ned: Vector3<f64>,
    /// 3-2-1 Euler angles (φ, θ, ψ) (rad).
    pub euler_321: Vector3<f64>,
    /// Airspeed V̄ (m/s).
    pub airspeed: f64,
    /// Angle of attack α = atan2(w_a, u_a) (2.2.12) (rad); 0 when V̄ ≈ 0.
    pub alpha: f64,
    /// Sideslip β = asin(v_a / V̄) (2.2.13) (rad); 0 when V̄ ≈ 0.
    pub beta: f64,
    /// Specific force (aero + thrust)/m in body axes: what an accelerometer reads (m/s²).
    pub specific_force_body: Vector3<f64>,
    /// Propeller induced velocity w (2.3.21) (m/s).
    pub induced_velocity: f64,
    /// Slip-stream speed V̄ + 2w (m/s).
    pub slipstream_speed: f64,
    /// Share of the wing in post-stall flow (global model's stall weights, reported for
    /// either model) ∈ [0, 1]; 0 = the thesis's attached-flow model holds.
    pub stall_fraction: f64,
    /// Aerodynamic regime from `stall_fraction`.
    pub aero_regime: AeroRegime,
    /// Ground contact summary.
    pub ground: ContactState,
}

/// A trimmed (steady) flight condition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trim {
    /// The trimmed state (at the origin, heading north, wings level).
    pub state: StateVector,
    /// The commands holding it (thrust state = T_c, servos = commands).
    pub inputs: InputVector,
    /// Angle of attack (rad).
    pub alpha: f64,
    /// 3-2-1 pitch angle θ (rad) (π/2 in vertical flight with C_m0 = 0).
    pub theta: f64,
    /// Thrust (N).
    pub thrust: f64,
    /// Elevator deflection (rad).
    pub elevator: f64,
    /// Induced velocity w (m/s).
    pub induced_velocity: f64,
    /// Airspeed (m/s).
    pub airspeed: f64,
    /// max |ẋ| over every state except position at the trim.
    pub residual: f64,
}

impl Plant {
    /// Plant with the default integrator and step ([`Integrator::default`],
    /// [`DEFAULT_INTEGRATION_STEP`]), the default envelope, the thesis's aerodynamic model
    /// (set `aero.model` for the global one) and no ground.
    pub fn new(airframe: Airframe) -> Self {
        Self {
            airframe,
            integration_step: DEFAULT_INTEGRATION_STEP,
            integrator: Integrator::default(),
            envelope: Envelope::default(),
            aero: GlobalAero {
                model: AeroModel::Thesis,
                ..GlobalAero::default()
            },
            ground: Ground::none(),
        }
    }

    /// Surfaces of the state vector.
    #[inline]
    fn surfaces(x: &StateVector) -> Surfaces {
        Surfaces::from_array([
            x[ELEVATOR],
            x[AILERON],
            x[RUDDER],
            x[FLAP_COLLECTIVE],
            x[FLAP_DIFFERENTIAL],
            x[VERTICAL_FLAP],
        ])
    }

    /// Aerodynamic + thrust forces and moments (no gravity) at a plant state, see
    /// [`Airframe::forces_moments`].
    pub fn forces_moments(&self, x: &StateVector, wind_ned: &Vector3<f64>) -> ForcesMoments {
        self.eval(x, wind_ned).0
    }

    /// Forces/moments and DCM at a state.
    #[inline]
    fn eval(&self, x: &StateVector, wind_ned: &Vector3<f64>) -> (ForcesMoments, nalgebra::Matrix3<f64>) {
        self.eval_from(x, wind_ned, f64::NAN)
    }

    /// [`Plant::eval`] with the induced velocity warm-started from `w_start` (NaN: cold).
    /// Inlined into [`Plant::derivatives`] so the forces do not return through memory.
    #[inline(always)]
    fn eval_from(
        &self,
        x: &StateVector,
        wind_ned: &Vector3<f64>,
        w_start: f64,
    ) -> (ForcesMoments, nalgebra::Matrix3<f64>) {
        let q = Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]);
        let c = dcm_earth_to_body(&q);
        let v = Vector3::new(x[U], x[V], x[W]);
        let omega = Vector3::new(x[P], x[Q], x[R]);
        let v_air = v - c * wind_ned;
        let fm = match self.aero.model {
            AeroModel::Thesis => {
                self.airframe
                    .forces_moments_from(&v_air, &omega, x[THRUST], &Self::surfaces(x), w_start)
            }
            AeroModel::Global => {
                self.aero
                    .forces_moments_from(&self.airframe, &v_air, &omega, x[THRUST], &Self::surfaces(x), w_start)
                    .0
            }
        };
        (fm, c)
    }

    /// State derivatives ẋ = f(x, u, wind).
    ///
    /// * Position: Ṗ = (DCM^BE)ᵀ (u, v, w) (2.2.14 with the inertial velocity).
    /// * Velocity (2.2.19–2.2.21): u̇ = X/m + r v − q w, v̇ = Y/m + p w − r u,
    ///   ẇ = Z/m + q u − p v, with (X, Y, Z) = aero + thrust ([`Airframe::forces_moments`])
    ///   + gravity DCM^BE (0, 0, m g) (2.3.14).
    /// * Quaternion (2.2.3).
    /// * Rates (2.5.26): ω̇ = I⁻¹(M − ω × I ω), I diagonal (2.2.17), i.e. (2.2.22–2.2.24).
    /// * Thrust lag (2.3.16): Ṫ = (sat(T_c) − T)/τ_T, sat to thrust_min … thrust_max.
    /// * Servos (App. D.5): δ̇ = sat_rate((sat_δ(δ_c) − δ)/τ_s).
    ///
    /// Air-relative velocity = inertial velocity − DCM^BE·wind_ned. Pure: no allocation.
    #[inline]
    /// On the ground, every touching point counts as free ([`ContactAnchors::FREE`]: kinetic
    /// friction of the tangential damper, no stiction); [`Plant::derivatives_in_contact`]
    /// takes the anchors.
    pub fn derivatives(&self, x: &StateVector, u: &InputVector, wind_ned: &Vector3<f64>) -> StateVector {
        self.derivatives_in_contact(x, &ContactAnchors::FREE, u, wind_ned)
    }

    /// [`Plant::derivatives`] with the ground contact's anchors.
    #[inline]
    pub fn derivatives_in_contact(
        &self,
        x: &StateVector,
        anchors: &ContactAnchors,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
    ) -> StateVector {
        let mut w = f64::NAN;
        self.derivatives_from(x, u, wind_ned, anchors, &mut w)
    }

    /// [`Plant::derivatives`] with the induced velocity warm-started from `*w` (NaN: cold),
    /// which is then set to this evaluation's induced velocity (the start of the next stage).
    #[inline(always)]
    fn derivatives_from(
        &self,
        x: &StateVector,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
        anchors: &ContactAnchors,
        w: &mut f64,
    ) -> StateVector {
        let (fm, c) = self.eval_from(x, wind_ned, *w);
        *w = fm.induced_velocity;
        self.assemble(x, u, &fm, &c, anchors)
    }

    /// The right-hand side of [`Plant::derivatives`] from the forces and moments `fm` and the
    /// DCM^BE `c` at `x` (the ground contact is added here).
    #[inline(always)]
    fn assemble(
        &self,
        x: &StateVector,
        u: &InputVector,
        fm: &ForcesMoments,
        c: &nalgebra::Matrix3<f64>,
        anchors: &ContactAnchors,
    ) -> StateVector {
        let a = &self.airframe;
        let v = Vector3::new(x[U], x[V], x[W]);
        let omega = Vector3::new(x[P], x[Q], x[R]);
        let q = Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]);

        let g_body = Vector3::new(c[(0, 2)], c[(1, 2)], c[(2, 2)]) * a.gravity;
        let (f_ground, m_ground) = self.ground.contact(a, x, c, anchors);
        // Parameter-only reciprocals: hoisted out of the integration loop by the compiler (a
        // multiplication per evaluation instead of a division).
        let vdot = (fm.force_body + f_ground) * (1.0 / a.mass) + g_body - omega.cross(&v);
        let i = Vector3::new(a.i_xx, a.i_yy, a.i_zz);
        let i_inv = Vector3::new(1.0 / a.i_xx, 1.0 / a.i_yy, 1.0 / a.i_zz);
        let h = omega.component_mul(&i);
        let wdot = (fm.moment_body + m_ground - omega.cross(&h)).component_mul(&i_inv);
        let qdot = quat_derivative(&q, &omega);
        let pdot = c.tr_mul(&v);

        let mut dx = StateVector::zeros();
        dx[POS_N] = pdot.x;
        dx[POS_E] = pdot.y;
        dx[POS_D] = pdot.z;
        dx[U] = vdot.x;
        dx[V] = vdot.y;
        dx[W] = vdot.z;
        dx[Q1] = qdot[0];
        dx[Q2] = qdot[1];
        dx[Q3] = qdot[2];
        dx[Q4] = qdot[3];
        dx[P] = wdot.x;
        dx[Q] = wdot.y;
        dx[R] = wdot.z;
        let tc = u[THRUST_CMD].max(a.thrust_min).min(a.thrust_max);
        dx[THRUST] = (tc - x[THRUST]) * (1.0 / a.tau_thrust);
        let lim = a.deflection_limit;
        let rate = a.servo_rate_limit;
        let servo_inv = 1.0 / a.servo_tau;
        for k in 0..6 {
            let cmd = u[SURFACES_CMD + k].max(-lim).min(lim);
            dx[SURFACES + k] = ((cmd - x[SURFACES + k]) * servo_inv).max(-rate).min(rate);
        }
        dx
    }

    /// Advance the state by `h` seconds with the commands `u` and wind held constant, in
    /// n = ⌈h / integration_step⌉ equal internal steps of the [`Integrator`] (default
    /// [`Integrator::Dp5Checked`]: Dormand–Prince's fifth-order solution; a step whose
    /// embedded error estimate exceeds 1e-9 is taken again in halves, down to 1/16 of the
    /// step, which resolves the right-hand side's kinks — stall blending, the thesis's α
    /// clamp, ground contact). The internal steps, and so the trajectory, depend only on the
    /// grid: communication steps that are multiples of `integration_step` (20 and 40 ms at the
    /// default 20/3 ms; 5, 10 and 20 ms at a 5 ms step) give the same trajectory to rounding.
    /// After each internal step: quaternion renormalised, thrust clamped to its limits and
    /// deflections to ±deflection_limit, every state checked finite and inside the
    /// [`Envelope`]. On error `x` keeps the last good internal step. Does not allocate. Each
    /// stage's induced-velocity solve starts at the previous stage's value
    /// ([`Airframe::induced_velocity_from`]): the same root to rounding, fewer iterations.
    pub fn advance(
        &self,
        x: &mut StateVector,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
        h: f64,
    ) -> Result<(), PhysicsError> {
        self.advance_counting(x, u, wind_ned, h, &mut 0)
    }

    /// [`Plant::advance`] that adds to `evals` the number of right-hand-side evaluations it
    /// made (for measuring the integrator's cost).
    ///
    /// Without the ground contact's memory: each call anchors the points touching at its
    /// start where they are (no tangential preload), so a load held across calls re-deflects
    /// the gear every call. On the ground, carry [`ContactAnchors`] through
    /// [`Plant::advance_in_contact`].
    #[inline]
    pub fn advance_counting(
        &self,
        x: &mut StateVector,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
        h: f64,
        evals: &mut u64,
    ) -> Result<(), PhysicsError> {
        let mut anchors = ContactAnchors::FREE;
        anchors.update(&self.ground, &self.airframe, x);
        self.advance_counting_in_contact(x, &mut anchors, u, wind_ned, h, evals)
    }

    /// [`Plant::advance`] with the ground contact's anchors (the contact's memory, module
    /// [`crate::ground`]), updated after every accepted internal (sub)step. On error both keep
    /// the last good internal step.
    pub fn advance_in_contact(
        &self,
        x: &mut StateVector,
        anchors: &mut ContactAnchors,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
        h: f64,
    ) -> Result<(), PhysicsError> {
        self.advance_counting_in_contact(x, anchors, u, wind_ned, h, &mut 0)
    }

    /// [`Plant::advance_in_contact`] counting right-hand-side evaluations into `evals`.
    #[inline]
    pub fn advance_counting_in_contact(
        &self,
        x: &mut StateVector,
        contact: &mut ContactAnchors,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
        h: f64,
        evals: &mut u64,
    ) -> Result<(), PhysicsError> {
        for k in 0..N_INPUTS {
            if !u[k].is_finite() {
                return Err(PhysicsError::NonFiniteInput {
                    input: idx::INPUT_NAMES[k],
                    value: u[k],
                });
            }
        }
        const WIND: [&str; 3] = ["wind_n", "wind_e", "wind_d"];
        for k in 0..3 {
            if !wind_ned[k].is_finite() {
                return Err(PhysicsError::NonFiniteInput {
                    input: WIND[k],
                    value: wind_ned[k],
                });
            }
        }
        if !(h.is_finite() && h >= 0.0) {
            return Err(PhysicsError::InvalidArgument {
                name: "step size h",
                value: h,
                requirement: "finite, >= 0",
            });
        }
        let step = self.integration_step;
        if !(step.is_finite() && step > 0.0) {
            return Err(PhysicsError::InvalidArgument {
                name: "integration_step",
                value: step,
                requirement: "finite, > 0",
            });
        }
        self.check(x, wind_ned)?;
        if h == 0.0 {
            return Ok(());
        }
        let n = ((h / step) * (1.0 - 1e-12)).ceil().max(1.0);
        // At most 10⁶ substeps (≈ 1 s of computing): a host must never be blocked for minutes.
        if n > MAX_SUBSTEPS {
            return Err(PhysicsError::InvalidArgument {
                name: "step size h",
                value: h,
                requirement: "at most 1e6 integration steps per call",
            });
        }
        let n = n as u64;
        let dt = h / n as f64;
        let mut s = *x;
        let mut local = *contact;
        let anchors = &mut local;
        // Induced velocity of the previous stage: the next stage's solve starts there.
        let mut w = f64::NAN;
        // f at the start of the step (the previous step's last evaluation), if known.
        let mut k_start: Option<StateVector> = None;
        for _ in 0..n {
            match self.integrator {
                Integrator::Rk4 => {
                    *evals += 4;
                    self.rk4_step(&mut s, u, wind_ned, anchors, dt, &mut w);
                    self.project(&mut s);
                    anchors.update(&self.ground, &self.airframe, &s);
                }
                Integrator::Dp5 => {
                    *evals += 6;
                    let k1 = self.derivatives_from(&s, u, wind_ned, anchors, &mut w);
                    self.dp5_step(&mut s, &k1, u, wind_ned, anchors, dt, &mut w);
                    self.project(&mut s);
                    anchors.update(&self.ground, &self.airframe, &s);
                }
                Integrator::Dp5Checked {
                    tolerance,
                    max_halvings,
                } => {
                    let k1 = match k_start {
                        Some(k) => k,
                        None => {
                            *evals += 1;
                            self.derivatives_from(&s, u, wind_ned, anchors, &mut w)
                        }
                    };
                    let (y, k_end) = self.dp5_checked_step(
                        &s,
                        &k1,
                        u,
                        wind_ned,
                        anchors,
                        dt,
                        tolerance,
                        max_halvings.min(30),
                        &mut w,
                        evals,
                    );
                    s = y;
                    k_start = Some(k_end);
                }
            }
            self.check(&s, wind_ned)?;
            *x = s;
            *contact = *anchors;
        }
        Ok(())
    }

    /// One internal step of [`Integrator::Dp5Checked`] from `s` (where f = `k1`): the
    /// result and f there (at the projected state: the next step's first stage).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn dp5_checked_step(
        &self,
        s: &StateVector,
        k1: &StateVector,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
        anchors: &mut ContactAnchors,
        dt: f64,
        tolerance: f64,
        max_halvings: u32,
        w: &mut f64,
        evals: &mut u64,
    ) -> (StateVector, StateVector) {
        // Where a contact point may touch, the substeps go down to 2^-CONTACT_HALVINGS of
        // the step: the contact's stiffness and its kink at touchdown need them (a hard
        // landing otherwise ends millimetres off a finer step). Position and substep length
        // in units of dt / 2^depth; airborne, the levels stop at `max_halvings` as before.
        let depth = max_halvings.max(CONTACT_HALVINGS);
        let total = 1u64 << depth;
        let (mut done, mut level) = (0u64, 0u32);
        let mut substeps = 0u64;
        let (mut y, mut k) = (*s, *k1);
        while done < total {
            let h = dt / (1u64 << level) as f64;
            let mut y_new = y;
            let e = self.dp5_step(&mut y_new, &k, u, wind_ned, anchors, h, w);
            self.project(&mut y_new);
            let k_new = self.derivatives_from(&y_new, u, wind_ned, anchors, w);
            *evals += 6;
            let e = e - k_new * (dp5::B_HAT[6] * h);
            let estimate = e.rows(POS_N, R + 1 - POS_N).amax();
            let deepest = if estimate <= tolerance
                || self.ground.clearly_airborne(&self.airframe, &y)
                    && self.ground.clearly_airborne(&self.airframe, &y_new)
            {
                max_halvings
            } else {
                depth
            };
            substeps += 1;
            // A non-finite estimate is accepted as it is: the state check after the internal
            // step reports it, and refining cannot make it finite.
            if estimate <= tolerance || level >= deepest || !estimate.is_finite() || substeps >= MAX_CHECKED_SUBSTEPS {
                y = y_new;
                k = k_new;
                if anchors.update(&self.ground, &self.airframe, &y) {
                    // The contact force at y changed with its anchors.
                    *evals += 1;
                    k = self.derivatives_from(&y, u, wind_ned, anchors, w);
                }
                done += total >> level;
                // Back to the coarsest level the grid allows from here.
                while level > 0 && done % (total >> (level - 1)) == 0 {
                    level -= 1;
                }
            } else {
                level += 1;
            }
        }
        (y, k)
    }

    /// One classical RK4 step of `dt` from `s`.
    #[inline(always)]
    fn rk4_step(
        &self,
        s: &mut StateVector,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
        anchors: &ContactAnchors,
        dt: f64,
        w: &mut f64,
    ) {
        let k1 = self.derivatives_from(s, u, wind_ned, anchors, w);
        let k2 = self.derivatives_from(&(*s + k1 * (0.5 * dt)), u, wind_ned, anchors, w);
        let k3 = self.derivatives_from(&(*s + k2 * (0.5 * dt)), u, wind_ned, anchors, w);
        let k4 = self.derivatives_from(&(*s + k3 * dt), u, wind_ned, anchors, w);
        *s += (k1 + (k2 + k3) * 2.0 + k4) * (dt / 6.0);
    }

    /// One step of `dt` from `s` (where f = `k1`) with the fifth-order solution of [`dp5`]
    /// (the commands and the wind are held, so the stage times do not enter). Returns
    /// dt Σᵢ₌₁⁶ (bᵢ − b̂ᵢ) kᵢ: the embedded error estimate without its seventh stage.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn dp5_step(
        &self,
        s: &mut StateVector,
        k1: &StateVector,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
        anchors: &ContactAnchors,
        dt: f64,
        w: &mut f64,
    ) -> StateVector {
        use dp5::{A, B, B_HAT};
        let k1 = *k1;
        let k2 = self.derivatives_from(&(*s + k1 * (A[1][0] * dt)), u, wind_ned, anchors, w);
        let k3 = self.derivatives_from(&(*s + (k1 * A[2][0] + k2 * A[2][1]) * dt), u, wind_ned, anchors, w);
        let k4 = self.derivatives_from(
            &(*s + (k1 * A[3][0] + k2 * A[3][1] + k3 * A[3][2]) * dt),
            u,
            wind_ned,
            anchors,
            w,
        );
        let k5 = self.derivatives_from(
            &(*s + (k1 * A[4][0] + k2 * A[4][1] + k3 * A[4][2] + k4 * A[4][3]) * dt),
            u,
            wind_ned,
            anchors,
            w,
        );
        let k6 = self.derivatives_from(
            &(*s + (k1 * A[5][0] + k2 * A[5][1] + k3 * A[5][2] + k4 * A[5][3] + k5 * A[5][4]) * dt),
            u,
            wind_ned,
            anchors,
            w,
        );
        *s += (k1 * B[0] + k3 * B[2] + k4 * B[3] + k5 * B[4] + k6 * B[5]) * dt;
        (k1 * (B[0] - B_HAT[0])
            + k3 * (B[2] - B_HAT[2])
            + k4 * (B[3] - B_HAT[3])
            + k5 * (B[4] - B_HAT[4])
            + k6 * (B[5] - B_HAT[5]))
            * dt
    }

    /// Renormalise the quaternion, clamp thrust and deflections.
    #[inline]
    fn project(&self, s: &mut StateVector) {
        let a = &self.airframe;
        let n = (s[Q1] * s[Q1] + s[Q2] * s[Q2] + s[Q3] * s[Q3] + s[Q4] * s[Q4]).sqrt();
        if n > 0.0 && n.is_finite() {
            for k in Q1..=Q4 {
                s[k] /= n;
            }
        }
        s[THRUST] = s[THRUST].max(a.thrust_min).min(a.thrust_max);
        let lim = a.deflection_limit;
        for k in SURFACES..SURFACES + 6 {
            s[k] = s[k].max(-lim).min(lim);
        }
    }

    /// Every state finite, quaternion non-zero, speeds, rates and positions inside the envelope.
    fn check(&self, s: &StateVector, wind_ned: &Vector3<f64>) -> Result<(), PhysicsError> {
        for k in 0..N_STATES {
            if !s[k].is_finite() {
                return Err(PhysicsError::NonFiniteState {
                    state: idx::STATE_NAMES[k],
                    value: s[k],
                });
            }
        }
        let e = &self.envelope;
        let qn = (s[Q1] * s[Q1] + s[Q2] * s[Q2] + s[Q3] * s[Q3] + s[Q4] * s[Q4]).sqrt();
        if qn < 1e-6 {
            return Err(PhysicsError::Envelope {
                quantity: "quaternion norm",
                value: qn,
                limit: 1e-6,
                unit: "",
            });
        }
        let speed = (s[U] * s[U] + s[V] * s[V] + s[W] * s[W]).sqrt();
        if speed > e.max_speed {
            return Err(PhysicsError::Envelope {
                quantity: "speed",
                value: speed,
                limit: e.max_speed,
                unit: "m/s",
            });
        }
        // In still air the airspeed is the speed (v − DCM·0 = v exactly): no DCM needed.
        let airspeed = if *wind_ned == Vector3::zeros() {
            speed
        } else {
            let q = Vector4::new(s[Q1], s[Q2], s[Q3], s[Q4]);
            (Vector3::new(s[U], s[V], s[W]) - dcm_earth_to_body(&q) * wind_ned).norm()
        };
        if airspeed > e.max_speed {
            return Err(PhysicsError::Envelope {
                quantity: "airspeed",
                value: airspeed,
                limit: e.max_speed,
                unit: "m/s",
            });
        }
        for k in P..=R {
            if s[k].abs() > e.max_rate {
                return Err(PhysicsError::Envelope {
                    quantity: idx::STATE_NAMES[k],
                    value: s[k],
                    limit: e.max_rate,
                    unit: "rad/s",
                });
            }
        }
        for k in POS_N..=POS_D {
            if s[k].abs() > e.max_position {
                return Err(PhysicsError::Envelope {
                    quantity: idx::STATE_NAMES[k],
                    value: s[k],
                    limit: e.max_position,
                    unit: "m",
                });
            }
        }
        Ok(())
    }

    /// Outputs at a state. The commands `u` are not used (no direct feedthrough) but are
    /// part of the signature for symmetry with [`Plant::derivatives`].
    /// On the ground the specific force counts every touching point as free
    /// ([`ContactAnchors::FREE`]); [`Plant::outputs_in_contact`] takes the anchors.
    pub fn outputs(&self, x: &StateVector, u: &InputVector, wind_ned: &Vector3<f64>) -> Outputs {
        self.outputs_in_contact(x, &ContactAnchors::FREE, u, wind_ned)
    }

    /// [`Plant::outputs`] with the ground contact's anchors.
    pub fn outputs_in_contact(
        &self,
        x: &StateVector,
        anchors: &ContactAnchors,
        _u: &InputVector,
        wind_ned: &Vector3<f64>,
    ) -> Outputs {
        let (fm, stall_fraction, c) = self.eval_with_stall(x, wind_ned);
        self.outputs_from(x, &fm, stall_fraction, &c, anchors)
    }

    /// Forces (cold induced-velocity solve), stall fraction and DCM^BE at a state.
    fn eval_with_stall(
        &self,
        x: &StateVector,
        wind_ned: &Vector3<f64>,
    ) -> (ForcesMoments, f64, nalgebra::Matrix3<f64>) {
        let q = Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]);
        let c = dcm_earth_to_body(&q);
        let v_air = Vector3::new(x[U], x[V], x[W]) - c * wind_ned;
        let omega = Vector3::new(x[P], x[Q], x[R]);
        // The global model's evaluation carries its stall fraction; the thesis's model gets
        // it from the diagnostics (the same quantities, evaluated once).
        let (fm, stall_fraction) = match self.aero.model {
            AeroModel::Thesis => (
                self.airframe
                    .forces_moments(&v_air, &omega, x[THRUST], &Self::surfaces(x)),
                self.aero.diagnostics(&self.airframe, &v_air, x[THRUST]).stall_fraction,
            ),
            AeroModel::Global => {
                let (fm, d) = self
                    .aero
                    .forces_moments(&self.airframe, &v_air, &omega, x[THRUST], &Self::surfaces(x));
                (fm, d.stall_fraction)
            }
        };
        (fm, stall_fraction, c)
    }

    /// [`Plant::outputs`] from the forces `fm`, the stall fraction and the DCM^BE `c` at `x`.
    fn outputs_from(
        &self,
        x: &StateVector,
        fm: &ForcesMoments,
        stall_fraction: f64,
        c: &nalgebra::Matrix3<f64>,
        anchors: &ContactAnchors,
    ) -> Outputs {
        let q = Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4]);
        let (f_ground, _) = self.ground.contact(&self.airframe, x, c, anchors);
        Outputs {
            vel_ned: c.tr_mul(&Vector3::new(x[U], x[V], x[W])),
            euler_321: euler_321_from_quat(&q),
            airspeed: fm.airspeed,
            alpha: fm.alpha,
            beta: fm.beta,
            specific_force_body: (fm.force_body + f_ground) * (1.0 / self.airframe.mass),
            induced_velocity: fm.induced_velocity,
            slipstream_speed: fm.slipstream_speed,
            stall_fraction,
            aero_regime: AeroRegime::of(stall_fraction),
            ground: self.ground.contact_state(&self.airframe, x),
        }
    }

    /// [`Plant::outputs`] at `x` and [`Plant::derivatives`] at `x` with its quaternion
    /// normalised (what a Model Exchange host integrates: the attitude the state
    /// represents), equal to the two calls. When normalising leaves the quaternion
    /// unchanged or there is no wind (the air-relative velocity then does not depend on the
    /// attitude), the forces are evaluated once for both (a zero velocity component may then
    /// carry the other sign of zero, nothing else differs).
    pub fn outputs_and_derivatives(
        &self,
        x: &StateVector,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
    ) -> (Outputs, StateVector) {
        self.outputs_and_derivatives_in_contact(x, &ContactAnchors::FREE, u, wind_ned)
    }

    /// [`Plant::outputs_and_derivatives`] with the ground contact's anchors.
    pub fn outputs_and_derivatives_in_contact(
        &self,
        x: &StateVector,
        anchors: &ContactAnchors,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
    ) -> (Outputs, StateVector) {
        let (fm, stall_fraction, c) = self.eval_with_stall(x, wind_ned);
        let y = self.outputs_from(x, &fm, stall_fraction, &c, anchors);
        let mut xn = *x;
        let n = (x[Q1] * x[Q1] + x[Q2] * x[Q2] + x[Q3] * x[Q3] + x[Q4] * x[Q4]).sqrt();
        if n > 0.0 && n.is_finite() {
            for k in Q1..=Q4 {
                xn[k] /= n;
            }
        }
        let dx = if xn == *x {
            self.assemble(&xn, u, &fm, &c, anchors)
        } else if *wind_ned == Vector3::zeros() {
            // Same forces (v_air = v exactly), DCM of the normalised quaternion.
            let cn = dcm_earth_to_body(&Vector4::new(xn[Q1], xn[Q2], xn[Q3], xn[Q4]));
            self.assemble(&xn, u, &fm, &cn, anchors)
        } else {
            self.derivatives_in_contact(&xn, anchors, u, wind_ned)
        };
        (y, dx)
    }

    /// Whether the free stream at `x` is outside the attached-flow band (stall weight σ > 0,
    /// the same σ as the force models'): only then can the stall fraction of
    /// [`Plant::outputs`] be positive. Cheaper than the outputs (no forces).
    pub fn free_stream_separated(&self, x: &StateVector, wind_ned: &Vector3<f64>) -> bool {
        let v = Vector3::new(x[U], x[V], x[W]);
        let v_air = if *wind_ned == Vector3::zeros() {
            v
        } else {
            v - dcm_earth_to_body(&Vector4::new(x[Q1], x[Q2], x[Q3], x[Q4])) * wind_ned
        };
        self.aero.free_stream_stall_weight(&v_air) > 0.0
    }

    /// Jacobians (A, B) of [`Plant::derivatives`] at (x, u) by central differences
    /// (perturbation 1e-6·max(1, |value|)).
    pub fn linearise(
        &self,
        x: &StateVector,
        u: &InputVector,
        wind_ned: &Vector3<f64>,
    ) -> (SMatrix<f64, N_STATES, N_STATES>, SMatrix<f64, N_STATES, N_INPUTS>) {
        let mut a = SMatrix::<f64, N_STATES, N_STATES>::zeros();
        let mut b = SMatrix::<f64, N_STATES, N_INPUTS>::zeros();
        let step = |_, v: f64| Some(1e-6 * v.abs().max(1.0));
        central_differences(
            x,
            N_STATES,
            step,
            |xp| self.derivatives(xp, u, wind_ned),
            |j, col| a.set_column(j, &col),
        );
        central_differences(
            u,
            N_INPUTS,
            step,
            |up| self.derivatives(x, up, wind_ned),
            |j, col| b.set_column(j, &col),
        );
        (a, b)
    }

    /// Steady, wings-level, straight flight at `airspeed` heading north in still air:
    /// flight-path angle 0, solves θ (= α), δe and T (other surfaces 0).
    pub fn trim_level(&self, airspeed: f64) -> Result<Trim, PhysicsError> {
        if !(airspeed.is_finite() && airspeed > 0.0) {
            return Err(PhysicsError::InvalidArgument {
                name: "airspeed",
                value: airspeed,
                requirement: "positive",
            });
        }
        self.trim_steady(&Vector3::new(airspeed, 0.0, 0.0), 0.1)
    }

    /// Steady vertical climb at `climb_speed` ≥ 0 (0 = hover), nose up (θ = 90°), belly
    /// north (3-2-1 ψ = 0, φ = 0), still air: solves T, δe and the pitch attitude (exactly
    /// 90° when C_m0 = 0). The quaternion is built directly, not from Euler extraction.
    pub fn trim_vertical_climb(&self, climb_speed: f64) -> Result<Trim, PhysicsError> {
        if !(climb_speed.is_finite() && climb_speed >= 0.0) {
            return Err(PhysicsError::InvalidArgument {
                name: "climb_speed",
                value: climb_speed,
                requirement: "finite and >= 0",
            });
        }
        self.trim_steady(&Vector3::new(0.0, 0.0, -climb_speed), core::f64::consts::FRAC_PI_2)
    }

    /// Trim state for unknowns z = (θ, δe, T) with inertial velocity `v_ned`.
    fn trim_point(&self, v_ned: &Vector3<f64>, z: &[f64; 3]) -> (StateVector, InputVector) {
        let q = quat_from_euler_321(0.0, z[0], 0.0);
        let v = dcm_earth_to_body(&q) * v_ned;
        let mut x = StateVector::zeros();
        x[U] = v.x;
        x[V] = v.y;
        x[W] = v.z;
        x.fixed_rows_mut::<4>(Q1).copy_from(&q);
        x[THRUST] = z[2];
        x[ELEVATOR] = z[1];
        let mut u = InputVector::zeros();
        u[THRUST_CMD] = z[2];
        u[ELEVATOR_CMD] = z[1];
        (x, u)
    }

    fn trim_residual(&self, v_ned: &Vector3<f64>, z: &[f64; 3]) -> Vector3<f64> {
        let (x, u) = self.trim_point(v_ned, z);
        let d = self.derivatives(&x, &u, &Vector3::zeros());
        Vector3::new(d[U], d[W], d[Q])
    }

    /// Newton iteration with a central-difference Jacobian on (u̇, ẇ, q̇) = 0.
    fn trim_steady(&self, v_ned: &Vector3<f64>, theta0: f64) -> Result<Trim, PhysicsError> {
        self.airframe.validate()?;
        let a = &self.airframe;
        let mut z = [theta0, 0.0, a.mass * a.gravity];
        let mut converged = false;
        for _ in 0..100 {
            let r = self.trim_residual(v_ned, &z);
            if r.amax() < 1e-12 {
                converged = true;
                break;
            }
            let mut jac = nalgebra::Matrix3::<f64>::zeros();
            central_differences(
                &z,
                3,
                |_, v| Some(1e-6 * v.abs().max(1.0)),
                |zd| self.trim_residual(v_ned, zd),
                |j, col| jac.set_column(j, &col),
            );
            let Some(dz) = jac.lu().solve(&r) else {
                return Err(PhysicsError::Trim(format!(
                    "singular trim Jacobian at θ = {}, δe = {}, T = {}",
                    z[0], z[1], z[2]
                )));
            };
            // Damped step: at most 0.2 rad in θ and δe.
            let scale = (0.2 / dz[0].abs().max(dz[1].abs()).max(1e-300)).min(1.0);
            for k in 0..3 {
                z[k] -= scale * dz[k];
            }
            if !z.iter().all(|v| v.is_finite()) {
                return Err(PhysicsError::Trim("Newton iteration diverged".into()));
            }
            // Stagnation at round-off (e.g. tiny inertias amplify the moment
            // residual): converged; the final residual check below decides.
            if scale * dz.amax() < 1e-14 * z.iter().fold(1.0f64, |m, v| m.max(v.abs())) {
                converged = true;
                break;
            }
        }
        let (x, u) = self.trim_point(v_ned, &z);
        let d = self.derivatives(&x, &u, &Vector3::zeros());
        let residual = d.rows(U, N_STATES - U).amax();
        if !converged || residual > 1e-8 {
            return Err(PhysicsError::Trim(format!(
                "no convergence: residual {residual:e} (θ = {}, δe = {}, T = {})",
                z[0], z[1], z[2]
            )));
        }
        if z[2] < a.thrust_min || z[2] > a.thrust_max {
            return Err(PhysicsError::Trim(format!(
                "needs thrust {} N outside [{}, {}] N",
                z[2], a.thrust_min, a.thrust_max
            )));
        }
        if z[1].abs() > a.deflection_limit {
            return Err(PhysicsError::Trim(format!(
                "needs elevator {} rad beyond the deflection limit {} rad",
                z[1], a.deflection_limit
            )));
        }
        let y = self.outputs(&x, &u, &Vector3::zeros());
        Ok(Trim {
            state: x,
            inputs: u,
            alpha: y.alpha,
            theta: z[0],
            thrust: z[2],
            elevator: z[1],
            induced_velocity: y.induced_velocity,
            airspeed: y.airspeed,
            residual,
        })
    }
}
