//! The FMU binding: ports named like the plant/sensor/controller ports, the estimator
//! driven through `FmuModel` and through the C ABI (FMU state get/set/serialize continue
//! bit-identically, fmi2Reset mid-run, NaN and out-of-range inputs, GPS restart logged).

use fmi2_export::ffi;
use fmi2_export::fmi_sys::fmi2::*;
use fmi2_export::{FmuModel, Logger, StateReader, StateWriter, VariableStore};
use model_description::Causality;
use nalgebra::Vector3;
use state_estimator::{geodesy::LocalFrame, EstimatorParams};
use std::ffi::{c_char, c_void, CStr, CString};
use std::path::Path;
use std::sync::Mutex;
use tailsitter_ekf::{vr, EkfModel, Variables, GUID};
use tailsitter_physics::{dcm_earth_to_body, idx, Airframe, InputVector, Plant, StateVector};

fn load(id: &str) -> model_description::Model {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription");
    model_description::load(&dir, id, "0").unwrap()
}

fn names(m: &model_description::Model, c: Causality) -> Vec<(String, Option<String>)> {
    m.variables
        .iter()
        .filter(|v| v.decl.causality == c)
        .map(|v| (v.decl.name.clone(), v.decl.unit.clone()))
        .collect()
}

#[test]
fn ports_are_named_like_the_plant_sensor_and_controller_ports() {
    let ekf = load("tailsitter_ekf");
    let plant = load("tailsitter_plant");
    let outputs = names(&ekf, Causality::Output);
    let inputs = names(&ekf, Causality::Input);
    // Every plant output a controller reads, with its unit: a controller cannot tell the
    // estimator from the plant (plant diagnostics no controller reads, e.g. stall_fraction,
    // need no estimate).
    let read: Vec<_> = ["tailsitter_lqr", "tailsitter_tsd"]
        .iter()
        .flat_map(|id| names(&load(id), Causality::Input))
        .collect();
    for p in names(&plant, Causality::Output)
        .into_iter()
        .filter(|p| read.contains(p))
    {
        assert!(outputs.contains(&p), "plant output {p:?} missing from the estimator");
    }
    // Every controller input that is not a reference offset, and every command.
    for id in ["tailsitter_lqr", "tailsitter_tsd"] {
        let c = load(id);
        for i in names(&c, Causality::Input) {
            if !i.0.starts_with("ref_offset_") {
                assert!(outputs.contains(&i), "{id} input {i:?} is not an estimator output");
            }
        }
        for o in names(&c, Causality::Output).iter().filter(|o| o.0.ends_with("_cmd")) {
            assert!(inputs.contains(o), "{id} command {o:?} is not an estimator input");
        }
    }
    // The sensor outputs of the design contract (§7): every output of the sensor FMU.
    for (s, _) in names(&load("tailsitter_sensors"), Causality::Output) {
        assert!(
            inputs.iter().any(|i| i.0 == s),
            "sensor output {s} is not an estimator input"
        );
    }
    for d in [
        "est_std_pos",
        "est_std_vel",
        "est_std_att",
        "wind_est_n",
        "wind_est_e",
        "wind_est_d",
        "rejected_measurements",
    ] {
        assert!(outputs.iter().any(|o| o.0 == d), "diagnostic {d} missing");
    }
    // No direct feedthrough: a master may step the estimator in any order.
    assert!(ekf.variables.iter().all(|v| v.decl.depends_on.is_empty()));
}

#[test]
fn airframe_start_values_are_the_plants() {
    // The estimator's copy of the airframe parameters builds the plant's default airframe.
    let v = Variables::with_start_values();
    let p = <tailsitter_ekf::EkfBinding as controller_fmu::Binding>::config(&v).unwrap();
    assert_eq!(p.airframe, Airframe::default());
}

/// `app_d_configuration` selects [`EstimatorParams::app_d`] over the individual parameters.
#[test]
fn app_d_configuration_overrides_the_extras_and_the_sigmas() {
    let mut v = Variables::with_start_values();
    v.sigma_mag = 0.3;
    v.app_d_configuration = true;
    let p = <tailsitter_ekf::EkfBinding as controller_fmu::Binding>::config(&v).unwrap();
    assert_eq!(p.noise.sigma_mag, 0.02);
    assert!(!p.prediction.model && !p.tuning.relative_to_start);
    assert!(!p.filter.compensate && !p.tuning.sideslip_pseudo_measurement);
    let d = EstimatorParams::default().app_d();
    assert_eq!(
        (p.noise, p.filter, p.prediction, p.tuning),
        (d.noise, d.filter, d.prediction, d.tuning)
    );
}

/// Deterministic pseudo-noise for the binding tests (the statistics are tested in the library).
struct Noise(u64);
impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 3.4641 // unit variance, uniform
    }
}

/// The plant's default trimmed climb with the sensors a sensor model would output.
struct Sim {
    plant: Plant,
    x: StateVector,
    u: InputVector,
    frame: LocalFrame,
    noise: Noise,
    k: usize,
}

impl Sim {
    fn new() -> Self {
        let plant = Plant::new(Airframe::default());
        let trim = plant.trim_vertical_climb(3.0).unwrap();
        let e = EstimatorParams::default().earth;
        Self {
            plant,
            x: trim.state,
            u: trim.inputs,
            frame: LocalFrame::new(e.site.ref_latitude, e.site.ref_longitude, e.site.ref_height),
            noise: Noise(7),
            k: 0,
        }
    }

    fn set_inputs(&mut self, v: &mut Variables) {
        let y = self.plant.outputs(&self.x, &self.u, &Vector3::zeros());
        let c = dcm_earth_to_body(&self.x.fixed_rows::<4>(idx::Q1).into_owned());
        let n = &mut self.noise;
        let sf = y.specific_force_body;
        v.imu_accel_x = sf.x + 0.1414 * n.next();
        v.imu_accel_y = sf.y + 0.1414 * n.next();
        v.imu_accel_z = sf.z + 0.1414 * n.next();
        v.imu_gyro_p = self.x[idx::P] + 0.028 * n.next();
        v.imu_gyro_q = self.x[idx::Q] + 0.028 * n.next();
        v.imu_gyro_r = self.x[idx::R] + 0.028 * n.next();
        // The magnetometer σ the estimator assumes by default: the one the sensor model
        // delivers (Table D.1, 0.02 G); pitot ≈ 0.2 m/s.
        let m = c * EstimatorParams::default().earth.mag_ned();
        let sm = EstimatorParams::default().noise.sigma_mag;
        v.mag_x = m.x + sm * n.next();
        v.mag_y = m.y + sm * n.next();
        v.mag_z = m.z + sm * n.next();
        // Indicated airspeed along body x: the body-x air-relative velocity (still air).
        v.pitot_airspeed = self.x[idx::U] + 0.2 * n.next();
        if self.k.is_multiple_of(12) {
            let p = Vector3::new(self.x[idx::POS_N], self.x[idx::POS_E], self.x[idx::POS_D]);
            let (la, lo, h) = self.frame.to_geodetic(&p);
            v.gps_latitude = la + 6.2832e-7 * n.next();
            v.gps_longitude = lo + 6.2832e-7 * n.next();
            v.gps_height = h + 4.0 * n.next();
            v.gps_vel_n = y.vel_ned.x + 0.5 * n.next();
            v.gps_vel_e = y.vel_ned.y + 0.5 * n.next();
            v.gps_vel_d = y.vel_ned.z + 0.5 * n.next();
            v.gps_fix_count += 1;
            v.gps_valid = true;
        }
        v.thrust_cmd = self.u[idx::THRUST_CMD];
        // A gentle elevator doublet so the servo model moves.
        v.elevator_cmd = if (100..150).contains(&self.k) { 0.05 } else { 0.0 };
        self.u[idx::ELEVATOR_CMD] = v.elevator_cmd;
    }

    fn advance(&mut self) {
        self.plant
            .advance(&mut self.x, &self.u, &Vector3::zeros(), 0.02)
            .unwrap();
        self.k += 1;
    }
}

fn vars_bytes(v: &Variables) -> Vec<u8> {
    let mut w = StateWriter::new();
    v.write_state(&mut w);
    w.into_bytes()
}

#[test]
fn tracks_the_plant_and_fmu_state_round_trip_is_bit_identical() {
    let mut sim = Sim::new();
    let mut vars = Variables::with_start_values();
    let mut model = EkfModel::new(&vars);
    let mut log = Logger::null();
    sim.set_inputs(&mut vars);
    model.initialize(&mut vars, 0.0, &mut log).unwrap();
    let h = 0.02;
    let mut saved = None;
    let mut after = Vec::new();
    let mut inputs = Vec::new();
    for k in 0..400 {
        if k == 200 {
            let mut w = StateWriter::new();
            model.write_state(&mut w);
            saved = Some((w.into_bytes(), vars_bytes(&vars)));
        }
        sim.set_inputs(&mut vars);
        if k >= 200 {
            inputs.push(vars.clone());
        }
        model.do_step(&mut vars, k as f64 * h, h, &mut log).unwrap();
        sim.advance();
        if k >= 200 {
            after.push(vars_bytes(&vars));
        }
        // The estimate follows the truth of the trimmed climb.
        let x = &sim.x;
        let err = Vector3::new(
            vars.pos_n - x[idx::POS_N],
            vars.pos_e - x[idx::POS_E],
            vars.pos_d - x[idx::POS_D],
        );
        assert!(err.norm() < 3.0 * vars.est_std_pos, "k = {k}: position error {err}");
        assert!((vars.thrust - x[idx::THRUST]).abs() < 1e-6);
        assert!((vars.elevator - x[idx::ELEVATOR]).abs() < 1e-6);
    }
    // Restore into a brand-new instance and replay the same inputs.
    let (ms, vs) = saved.unwrap();
    let mut vars = Variables::with_start_values();
    vars.read_state(&mut StateReader::new(&vs)).unwrap();
    let mut model = EkfModel::new(&vars);
    model.read_state(&mut StateReader::new(&ms)).unwrap();
    for (i, k) in (200..400).enumerate() {
        vars = inputs[i].clone();
        model.do_step(&mut vars, k as f64 * h, h, &mut log).unwrap();
        assert_eq!(vars_bytes(&vars), after[i], "step {k} differs after restore");
    }
}

// ---- through the C ABI -------------------------------------------------------------------

static LOG: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Host logger: our layer always calls `logger(env, name, status, category, "%s", msg)`; a
/// 6-argument function receives those like the variadic type on x86_64 SysV.
unsafe extern "C" fn record(
    _env: fmi2ComponentEnvironment,
    _name: fmi2String,
    _status: fmi2Status,
    _category: fmi2String,
    _format: fmi2String,
    message: *const c_char,
) {
    // SAFETY: the layer passes a valid NUL-terminated message.
    let s = unsafe { CStr::from_ptr(message) }.to_string_lossy().into_owned();
    LOG.lock().unwrap().push(s);
}

fn callbacks() -> fmi2CallbackFunctions {
    let logger: fmi2CallbackLogger =
        // SAFETY: see `record`; the layer never passes more than one variadic argument.
        Some(unsafe { std::mem::transmute::<*const c_void, unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...)>(record as *const c_void) });
    fmi2CallbackFunctions {
        logger,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    }
}

/// Set every Real, Integer and Boolean input of `v` on the instance.
unsafe fn set_all_inputs(c: fmi2Component, v: &Variables) {
    let reals = [
        (vr::gps_latitude, v.gps_latitude),
        (vr::gps_longitude, v.gps_longitude),
        (vr::gps_height, v.gps_height),
        (vr::gps_vel_n, v.gps_vel_n),
        (vr::gps_vel_e, v.gps_vel_e),
        (vr::gps_vel_d, v.gps_vel_d),
        (vr::imu_accel_x, v.imu_accel_x),
        (vr::imu_accel_y, v.imu_accel_y),
        (vr::imu_accel_z, v.imu_accel_z),
        (vr::imu_gyro_p, v.imu_gyro_p),
        (vr::imu_gyro_q, v.imu_gyro_q),
        (vr::imu_gyro_r, v.imu_gyro_r),
        (vr::mag_x, v.mag_x),
        (vr::mag_y, v.mag_y),
        (vr::mag_z, v.mag_z),
        (vr::pitot_airspeed, v.pitot_airspeed),
        (vr::thrust_cmd, v.thrust_cmd),
        (vr::elevator_cmd, v.elevator_cmd),
    ];
    for (r, x) in reals {
        // SAFETY: live instance, one value.
        assert_eq!(unsafe { ffi::set_real::<EkfModel>(c, &r, 1, &x) }, fmi2Status_fmi2OK);
    }
    let fix = v.gps_fix_count;
    let valid = v.gps_valid as fmi2Boolean;
    // SAFETY: live instance, one value each.
    unsafe {
        assert_eq!(
            ffi::set_integer::<EkfModel>(c, &vr::gps_fix_count, 1, &fix),
            fmi2Status_fmi2OK
        );
        assert_eq!(
            ffi::set_boolean::<EkfModel>(c, &vr::gps_valid, 1, &valid),
            fmi2Status_fmi2OK
        );
    }
}

const OUT: [u32; 8] = [
    vr::pos_n,
    vr::pos_d,
    vr::vel_d,
    vr::quat_2,
    vr::quat_4,
    vr::est_std_pos,
    vr::thrust,
    vr::alpha,
];

unsafe fn outputs(c: fmi2Component) -> [f64; 8] {
    let mut out = [0.0; 8];
    // SAFETY: live instance; buffers of the right length.
    assert_eq!(
        unsafe { ffi::get_real::<EkfModel>(c, OUT.as_ptr(), OUT.len(), out.as_mut_ptr()) },
        fmi2Status_fmi2OK
    );
    out
}

unsafe fn start(c: fmi2Component, sim: &mut Sim, v: &mut Variables) {
    // SAFETY: live instance in Instantiated.
    unsafe {
        assert_eq!(
            ffi::setup_experiment::<EkfModel>(c, 0, 0.0, 0.0, 0, 0.0),
            fmi2Status_fmi2OK
        );
        assert_eq!(ffi::enter_initialization_mode::<EkfModel>(c), fmi2Status_fmi2OK);
        sim.set_inputs(v);
        set_all_inputs(c, v);
        assert_eq!(ffi::exit_initialization_mode::<EkfModel>(c), fmi2Status_fmi2OK);
    }
}

#[test]
fn c_abi_serialize_reset_nan_and_gps_restart() {
    let cb = callbacks();
    let name = CString::new("ekf").unwrap();
    let guid = CString::new(GUID).unwrap();
    // SAFETY: valid strings and callbacks outliving the instance; every call below is on a
    // live instance.
    unsafe {
        let c = ffi::instantiate::<EkfModel>(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            std::ptr::null(),
            &cb,
            0,
            1,
        );
        assert!(!c.is_null());
        let mut sim = Sim::new();
        let mut v = Variables::with_start_values();
        start(c, &mut sim, &mut v);
        let h = 0.02;
        let mut t = 0.0;
        let step = |sim: &mut Sim, v: &mut Variables, t: &mut f64| {
            sim.set_inputs(v);
            set_all_inputs(c, v);
            assert_eq!(ffi::do_step::<EkfModel>(c, *t, h, 1), fmi2Status_fmi2OK);
            sim.advance();
            *t += h;
        };
        for _ in 0..100 {
            step(&mut sim, &mut v, &mut t);
        }

        // Serialize, run on, deserialize, run the same inputs: bit-identical outputs.
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(ffi::get_fmu_state::<EkfModel>(c, &mut state), fmi2Status_fmi2OK);
        let mut size = 0usize;
        assert_eq!(
            ffi::serialized_fmu_state_size::<EkfModel>(c, state, &mut size),
            fmi2Status_fmi2OK
        );
        let mut bytes = vec![0 as fmi2Byte; size];
        assert_eq!(
            ffi::serialize_fmu_state::<EkfModel>(c, state, bytes.as_mut_ptr(), size),
            fmi2Status_fmi2OK
        );
        assert_eq!(ffi::free_fmu_state::<EkfModel>(c, &mut state), fmi2Status_fmi2OK);
        let (sim_at, v_at, t_at) = ((sim.x, sim.u, sim.k, sim.noise.0), v.clone(), t);
        let mut first = Vec::new();
        for _ in 0..50 {
            step(&mut sim, &mut v, &mut t);
            first.push(outputs(c));
        }
        let mut restored: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(
            ffi::deserialize_fmu_state::<EkfModel>(c, bytes.as_ptr(), size, &mut restored),
            fmi2Status_fmi2OK
        );
        assert_eq!(ffi::set_fmu_state::<EkfModel>(c, restored), fmi2Status_fmi2OK);
        assert_eq!(ffi::free_fmu_state::<EkfModel>(c, &mut restored), fmi2Status_fmi2OK);
        (sim.x, sim.u, sim.k, sim.noise.0) = sim_at;
        v = v_at;
        t = t_at;
        for (i, expected) in first.iter().enumerate() {
            step(&mut sim, &mut v, &mut t);
            let got = outputs(c);
            for j in 0..OUT.len() {
                assert_eq!(got[j].to_bits(), expected[j].to_bits(), "step {i} output {j}");
            }
        }

        assert!(
            !LOG.lock().unwrap().iter().any(|m| m.contains("rejected")),
            "no rejection in a clean run: {:?}",
            LOG.lock().unwrap()
        );
        // NaN and out-of-range-typed inputs: fmi2SetReal refuses a NaN with an error and a
        // log line; the estimator keeps its last value and stays finite.
        LOG.lock().unwrap().clear();
        let nan = f64::NAN;
        assert_eq!(
            ffi::set_real::<EkfModel>(c, &vr::imu_accel_x, 1, &nan),
            fmi2Status_fmi2Error
        );
        assert!(!LOG.lock().unwrap().is_empty(), "the refused NaN is logged");
        // An implausible (finite) value is rejected by the estimator, logged and counted.
        let mut rejected = 0;
        assert_eq!(
            ffi::get_integer::<EkfModel>(c, &vr::rejected_measurements, 1, &mut rejected),
            fmi2Status_fmi2OK
        );
        sim.set_inputs(&mut v);
        set_all_inputs(c, &v);
        let huge = 50.0;
        assert_eq!(ffi::set_real::<EkfModel>(c, &vr::mag_x, 1, &huge), fmi2Status_fmi2OK);
        assert_eq!(ffi::do_step::<EkfModel>(c, t, h, 1), fmi2Status_fmi2OK);
        sim.advance();
        t += h;
        let mut after = 0;
        ffi::get_integer::<EkfModel>(c, &vr::rejected_measurements, 1, &mut after);
        assert_eq!(after, rejected + 1, "{:?}", LOG.lock().unwrap());
        assert!(LOG
            .lock()
            .unwrap()
            .iter()
            .any(|m| m.contains("magnetometer measurement rejected")));
        assert!(outputs(c).iter().all(|x| x.is_finite()));

        // GPS restart: the fix counter goes back; logged, the fix is used.
        while !sim.k.is_multiple_of(12) {
            step(&mut sim, &mut v, &mut t);
        }
        v.gps_fix_count = -1; // set_inputs adds 1 at this fix: 0 < previous count
        LOG.lock().unwrap().clear();
        step(&mut sim, &mut v, &mut t);
        assert!(
            LOG.lock().unwrap().iter().any(|m| m.contains("receiver restart")),
            "{:?}",
            LOG.lock().unwrap()
        );
        for _ in 0..100 {
            step(&mut sim, &mut v, &mut t);
        }
        assert!(outputs(c).iter().all(|x| x.is_finite()));

        // fmi2Reset mid-run, then a new run from the current flight condition.
        assert_eq!(ffi::reset::<EkfModel>(c), fmi2Status_fmi2OK);
        let mut v2 = Variables::with_start_values();
        v2.gps_fix_count = 1000;
        start(c, &mut sim, &mut v2);
        let mut t2 = 0.0;
        for _ in 0..100 {
            sim.set_inputs(&mut v2);
            set_all_inputs(c, &v2);
            assert_eq!(ffi::do_step::<EkfModel>(c, t2, h, 1), fmi2Status_fmi2OK);
            sim.advance();
            t2 += h;
        }
        let out = outputs(c);
        assert!(out.iter().all(|x| x.is_finite()));
        assert!((out[0] - sim.x[idx::POS_N]).abs() < 3.0 * out[5] && (out[1] - sim.x[idx::POS_D]).abs() < 3.0 * out[5]);
        ffi::free_instance::<EkfModel>(c);
    }
}

#[test]
fn start_values_alone_give_the_plants_default_climb() {
    // Nothing connected: the start values are the sensors of the plant's default state
    // (trimmed 3 m/s climb, nose up, heading north, at the origin) — the outputs say so.
    let mut vars = Variables::with_start_values();
    let mut model = EkfModel::new(&vars);
    model.initialize(&mut vars, 0.0, &mut Logger::null()).unwrap();
    let plant = Plant::new(Airframe::default());
    let x = plant.trim_vertical_climb(3.0).unwrap().state;
    assert!(vars.pos_n.abs() < 1e-6 && vars.pos_d.abs() < 1e-6);
    assert!((vars.vel_d + 3.0).abs() < 1e-12);
    assert!(
        (vars.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-6,
        "theta {}",
        vars.theta
    );
    for (k, q) in [vars.quat_1, vars.quat_2, vars.quat_3, vars.quat_4].iter().enumerate() {
        assert!((q - x[idx::Q1 + k]).abs() < 1e-6, "quat_{}", k + 1);
    }
    assert!((vars.thrust - x[idx::THRUST]).abs() < 1e-9);
    assert!((vars.airspeed - 3.0).abs() < 1e-9 && vars.alpha.abs() < 1e-9);
}

/// The estimate after initialisation is that of the measurements alone: commands far from
/// the trim set in Initialization Mode change no output (bit for bit), so a master that
/// initialises the estimator and the controller together (OMSimulator) has no loop to solve.
/// The motor and servos start at `init_thrust`, `init_elevator` (the other surfaces at 0).
#[test]
fn initial_outputs_do_not_depend_on_the_commands() {
    let init = |set: &dyn Fn(&mut Variables)| {
        let mut sim = Sim::new();
        let mut vars = Variables::with_start_values();
        sim.set_inputs(&mut vars);
        set(&mut vars);
        let mut model = EkfModel::new(&vars);
        model.initialize(&mut vars, 0.0, &mut Logger::null()).unwrap();
        vars
    };
    let trim = init(&|_| {});
    let x = Plant::new(Airframe::default()).trim_vertical_climb(3.0).unwrap().state;
    assert!((trim.thrust - x[idx::THRUST]).abs() < 1e-9 && trim.elevator == 0.0);
    let off_trim = |v: &mut Variables| {
        v.thrust_cmd = 40.0;
        v.elevator_cmd = 0.3;
        v.aileron_cmd = -0.2;
        v.rudder_cmd = 0.1;
        v.flap_collective_cmd = 0.25;
        v.flap_differential_cmd = -0.15;
        v.vertical_flap_cmd = 0.05;
    };
    let moved = init(&off_trim);
    assert_eq!(moved.thrust_cmd, 40.0, "the commands were set");
    let outputs: Vec<_> = <Variables as VariableStore>::VARIABLES
        .iter()
        .filter(|s| s.causality == fmi2_export::Causality::Output && s.value_type == fmi2_export::ValueType::Real)
        .collect();
    assert!(outputs.len() > 30);
    for s in &outputs {
        let (a, b) = (
            trim.get_real(s.value_reference).unwrap(),
            moved.get_real(s.value_reference).unwrap(),
        );
        assert_eq!(
            a.to_bits(),
            b.to_bits(),
            "{} changed with the commands: {a} -> {b}",
            s.name
        );
    }
    // The parameters set the actuators' start, each within its limits.
    let started = init(&|v| {
        off_trim(v);
        v.init_thrust = 70.0;
        v.init_elevator = 0.1;
    });
    assert_eq!((started.thrust, started.elevator, started.aileron), (70.0, 0.1, 0.0));
    let limited = init(&|v| {
        v.init_thrust = 500.0;
        v.init_elevator = -1.0;
    });
    assert_eq!(limited.thrust, 150.0);
    assert_eq!(limited.elevator, -Airframe::default().deflection_limit);
}
