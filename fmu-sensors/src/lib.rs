//! `tailsitter_sensors`: binds the pure-Rust sensor model ([`sensor_model`]) to the
//! generic FMI 2.0 Co-Simulation export layer ([`fmi2_export`]). Only the mapping
//! between FMU variables and the model lives here; the variables are declared in
//! `modelDescription/tailsitter_sensors.json`.
//!
//! Timing: `initialize` takes every sensor's first sample at the start time from
//! the inputs set then (outputs after fmi2ExitInitializationMode hold them);
//! `doStep(t, h)` takes each sensor's samples due at instants in [t, t + h) from the
//! inputs set for t (held over the step), and the outputs then hold each sensor's
//! latest sample.

use fmi2_export::{FmuModel, Logger, ModelError, StateError, StateReader, StateWriter};
use nalgebra::{Vector3, Vector4};
use sensor_model::{FaultMode, Measurements, Params, SensorModel, State, Truth, STATE_WORDS};

/// Generated from the declaration: `Variables`, `vr`, `GUID`, `MODEL_IDENTIFIER`, `MODEL_DESCRIPTION_XML`.
#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/variables.rs"));
}
pub use generated::{vr, Variables, GUID, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};

/// One sensor-model instance.
#[derive(Debug, Clone)]
pub struct SensorsModel {
    model: Option<SensorModel>,
    /// State read from an FMU state: the model is rebuilt from the restored parameters before use.
    pending: Option<State>,
}

/// The model parameters from the FMU parameters.
pub fn params_from(v: &Variables) -> Result<Params, ModelError> {
    let fault_mode = match v.fault_mode {
        0 => FaultMode::None,
        1 => FaultMode::Stuck,
        2 => FaultMode::Offset,
        other => {
            return Err(ModelError::new(format!(
                "fault_mode = {other}: expected 0 (none), 1 (stuck) or 2 (offset)"
            )))
        }
    };
    let p = Params {
        // Every i32 maps to a distinct 64-bit seed.
        seed: v.seed as i64 as u64,
        accel_rate: v.accel_rate,
        gyro_rate: v.gyro_rate,
        mag_rate: v.mag_rate,
        pitot_rate: v.pitot_rate,
        gps_rate: v.gps_rate,
        gps_latlon_std: v.gps_latlon_std,
        gps_height_std: v.gps_height_std,
        gps_vel_std: v.gps_vel_std,
        accel_std: v.accel_std,
        gyro_std: v.gyro_std,
        mag_std: v.mag_std,
        pitot_std: v.pitot_std,
        accel_bias: Vector3::new(v.accel_bias_x, v.accel_bias_y, v.accel_bias_z),
        gyro_bias: Vector3::new(v.gyro_bias_p, v.gyro_bias_q, v.gyro_bias_r),
        mag_bias: Vector3::new(v.mag_bias_x, v.mag_bias_y, v.mag_bias_z),
        pitot_bias: v.pitot_bias,
        ref_latitude: v.ref_latitude,
        ref_longitude: v.ref_longitude,
        ref_height: v.ref_height,
        mag_field_total: v.mag_field_total,
        mag_declination: v.mag_declination,
        mag_inclination: v.mag_inclination,
        air_density: v.air_density,
        filter_enabled: v.filter_enabled,
        filter_bandwidth: v.filter_bandwidth,
        gps_dropout_start: v.gps_dropout_start,
        gps_dropout_duration: v.gps_dropout_duration,
        fault_channel: v.fault_channel,
        fault_mode,
        fault_start: v.fault_start,
        fault_duration: v.fault_duration,
        fault_magnitude: v.fault_magnitude,
    };
    p.validate()
        .map_err(|e| ModelError::new(format!("invalid sensor parameter: {e}")))?;
    Ok(p)
}

/// The true state from the inputs.
pub fn truth_from(v: &Variables) -> Truth {
    Truth {
        pos_ned: Vector3::new(v.pos_n, v.pos_e, v.pos_d),
        vel_ned: Vector3::new(v.vel_n, v.vel_e, v.vel_d),
        rates: Vector3::new(v.p, v.q, v.r),
        quat: Vector4::new(v.quat_1, v.quat_2, v.quat_3, v.quat_4),
        airspeed: v.airspeed,
        alpha: v.alpha,
        beta: v.beta,
        specific_force: Vector3::new(v.accel_x, v.accel_y, v.accel_z),
    }
}

fn write_outputs(v: &mut Variables, m: &Measurements) {
    v.gps_latitude = m.gps_latitude;
    v.gps_longitude = m.gps_longitude;
    v.gps_height = m.gps_height;
    v.gps_vel_n = m.gps_vel.x;
    v.gps_vel_e = m.gps_vel.y;
    v.gps_vel_d = m.gps_vel.z;
    // The count wraps like the i32 of FMI after 2³¹ fixes (17 years at 4 Hz).
    v.gps_fix_count = m.gps_fix_count as i32;
    v.gps_valid = m.gps_valid;
    let a = &m.analog;
    v.imu_accel_x = a[0];
    v.imu_accel_y = a[1];
    v.imu_accel_z = a[2];
    v.imu_gyro_p = a[3];
    v.imu_gyro_q = a[4];
    v.imu_gyro_r = a[5];
    v.mag_x = a[6];
    v.mag_y = a[7];
    v.mag_z = a[8];
    v.pitot_airspeed = a[9];
}

impl SensorsModel {
    /// The model, rebuilt from the (restored) parameters if an FMU state is pending.
    fn model(&mut self, vars: &Variables) -> Result<&mut SensorModel, ModelError> {
        if let Some(state) = self.pending.take() {
            let mut m = SensorModel::new(params_from(vars)?).map_err(|e| ModelError::new(e.to_string()))?;
            m.set_state(state);
            self.model = Some(m);
        }
        self.model
            .as_mut()
            .ok_or_else(|| ModelError::new("sensor model not initialised"))
    }
}

impl FmuModel for SensorsModel {
    type Vars = Variables;
    const MODEL_IDENTIFIER: &'static str = MODEL_IDENTIFIER;
    const GUID: &'static str = GUID;

    fn new(_vars: &Variables) -> Self {
        Self {
            model: None,
            pending: None,
        }
    }

    fn initialize(&mut self, vars: &mut Variables, start_time: f64, _log: &mut Logger<'_>) -> Result<(), ModelError> {
        // Idempotent: a fresh model (noise streams from the seed) every time.
        let mut m = SensorModel::new(params_from(vars)?).map_err(|e| ModelError::new(e.to_string()))?;
        let out = m
            .start(&truth_from(vars), start_time)
            .map_err(|e| ModelError::new(format!("at the start time {start_time} s: {e}")))?;
        let [a, g, mg, p] = m.noise_gains();
        vars.accel_noise_gain = a;
        vars.gyro_noise_gain = g;
        vars.mag_noise_gain = mg;
        vars.pitot_noise_gain = p;
        write_outputs(vars, &out);
        self.model = Some(m);
        self.pending = None;
        Ok(())
    }

    fn update_outputs(&mut self, vars: &mut Variables) -> Result<(), ModelError> {
        let out = self.model(vars)?.measurements();
        write_outputs(vars, &out);
        Ok(())
    }

    fn do_step(&mut self, vars: &mut Variables, t: f64, h: f64, log: &mut Logger<'_>) -> Result<(), ModelError> {
        let truth = truth_from(vars);
        let (out, held) = self
            .model(vars)?
            .step_or_hold(&truth, t, h)
            .map_err(|e| ModelError::new(format!("step from t = {t} s: {e}")))?;
        if held {
            log.warning(format_args!(
                "step from t = {t} s: every true-state input is 0 (the zero quaternion included) before any plant sample: \
                 taken as no plant sample yet (a master that starts its connections at 0, e.g. fmpy simulate_ssp); \
                 nothing sampled, the outputs of the start held"
            ));
        }
        write_outputs(vars, &out);
        Ok(())
    }

    fn write_state(&self, w: &mut StateWriter) {
        let state = self.pending.as_ref().or(self.model.as_ref().map(|m| m.state()));
        w.bool(state.is_some());
        if let Some(s) = state {
            s.save(&mut |x| w.u64(x));
        }
    }

    fn read_state(&mut self, r: &mut StateReader<'_>) -> Result<(), StateError> {
        if !r.bool()? {
            self.model = None;
            self.pending = None;
            return Ok(());
        }
        let mut words = [0u64; STATE_WORDS];
        for x in words.iter_mut() {
            *x = r.u64()?;
        }
        let mut it = words.into_iter();
        let state = State::restore(&mut || it.next()).map_err(StateError::invalid)?;
        // The parameters come back with the variables: rebuild the model from them before use.
        self.pending = Some(state);
        self.model = None;
        Ok(())
    }
}

fmi2_export::export_fmu!(SensorsModel);
