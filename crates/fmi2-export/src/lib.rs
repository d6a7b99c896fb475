//! Generic FMI 2.0 export layer: Co-Simulation, and Model Exchange for models
//! with continuous states.
//!
//! A model implements [`FmuModel`] (its equations) on top of a generated
//! [`VariableStore`] (its variables); `export_fmu!(MyModel);` then emits every
//! FMI 2.0 function as a `#[no_mangle] extern "C"` symbol. This crate owns the
//! state machine, argument and range checks, logging, FMU state
//! (get/set/serialize) and panic safety. See the crate README for the state
//! table.

pub mod ffi;
pub mod instance;
pub mod logger;
pub mod model;
pub mod state;
pub mod structure_probe;
pub mod test_host;
pub mod testing;
pub mod variables;

#[doc(hidden)]
pub use fmi_sys;

pub use instance::{Fmi2Error, Fmi2Result, FmiState, Instance, Snapshot};
pub use logger::{Level, LogSink, Logger};
pub use model::{FmuModel, ModelError};
pub use state::{StateError, StateReader, StateWriter};
pub use variables::{Causality, ContinuousState, ValueType, Variability, VariableSpec, VariableStore};

/// Log categories of every FMU built on this layer (name, description), in
/// the order of `<LogCategories>` in modelDescription.xml.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    (
        "logStatusWarning",
        "Warnings: saturation, fallbacks, recoverable problems",
    ),
    ("logStatusError", "Errors: illegal calls, bad arguments, failed steps"),
    ("logAll", "Everything, including debug messages"),
];

/// Export model type `$model` (implementing [`FmuModel`]) as an FMI 2.0
/// Co-Simulation FMU, and also as Model Exchange when its variables declare
/// continuous states: emits every FMI 2.0 function of both interfaces with its exact C
/// signature, checked at compile time against the `fmi-sys` `…TYPE` aliases.
/// Each body delegates to the generic function of [`ffi`].
///
/// Use once per `cdylib` (the symbols are global).
#[macro_export]
macro_rules! export_fmu {
    ($model:ty) => {
        $crate::__export_fmu_fns! { $model;
            fmi2GetTypesPlatform [fmi2GetTypesPlatformTYPE] () -> *const ::std::os::raw::c_char
                => $crate::ffi::get_types_platform();
            fmi2GetVersion [fmi2GetVersionTYPE] () -> *const ::std::os::raw::c_char
                => $crate::ffi::get_version();
            fmi2SetDebugLogging [fmi2SetDebugLoggingTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, logging_on: $crate::fmi_sys::fmi2::fmi2Boolean,
                n: usize, categories: *const $crate::fmi_sys::fmi2::fmi2String) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::set_debug_logging::<$model>(c, logging_on, n, categories);
            fmi2FreeInstance [fmi2FreeInstanceTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component) -> ()
                => $crate::ffi::free_instance::<$model>(c);
            fmi2SetupExperiment [fmi2SetupExperimentTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, tolerance_defined: $crate::fmi_sys::fmi2::fmi2Boolean,
                tolerance: $crate::fmi_sys::fmi2::fmi2Real, start: $crate::fmi_sys::fmi2::fmi2Real,
                stop_defined: $crate::fmi_sys::fmi2::fmi2Boolean, stop: $crate::fmi_sys::fmi2::fmi2Real) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::setup_experiment::<$model>(c, tolerance_defined, tolerance, start, stop_defined, stop);
            fmi2EnterInitializationMode [fmi2EnterInitializationModeTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::enter_initialization_mode::<$model>(c);
            fmi2ExitInitializationMode [fmi2ExitInitializationModeTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::exit_initialization_mode::<$model>(c);
            fmi2Terminate [fmi2TerminateTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::terminate::<$model>(c);
            fmi2Reset [fmi2ResetTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::reset::<$model>(c);
            fmi2GetReal [fmi2GetRealTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, nvr: usize,
                value: *mut $crate::fmi_sys::fmi2::fmi2Real) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_real::<$model>(c, vr, nvr, value);
            fmi2GetInteger [fmi2GetIntegerTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, nvr: usize,
                value: *mut $crate::fmi_sys::fmi2::fmi2Integer) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_integer::<$model>(c, vr, nvr, value);
            fmi2GetBoolean [fmi2GetBooleanTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, nvr: usize,
                value: *mut $crate::fmi_sys::fmi2::fmi2Boolean) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_boolean::<$model>(c, vr, nvr, value);
            fmi2GetString [fmi2GetStringTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, nvr: usize,
                value: *mut $crate::fmi_sys::fmi2::fmi2String) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_string::<$model>(c, vr, nvr, value);
            fmi2SetReal [fmi2SetRealTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, nvr: usize,
                value: *const $crate::fmi_sys::fmi2::fmi2Real) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::set_real::<$model>(c, vr, nvr, value);
            fmi2SetInteger [fmi2SetIntegerTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, nvr: usize,
                value: *const $crate::fmi_sys::fmi2::fmi2Integer) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::set_integer::<$model>(c, vr, nvr, value);
            fmi2SetBoolean [fmi2SetBooleanTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, nvr: usize,
                value: *const $crate::fmi_sys::fmi2::fmi2Boolean) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::set_boolean::<$model>(c, vr, nvr, value);
            fmi2SetString [fmi2SetStringTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, nvr: usize,
                value: *const $crate::fmi_sys::fmi2::fmi2String) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::set_string::<$model>(c, vr, nvr, value);
            fmi2GetFMUstate [fmi2GetFMUstateTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, state: *mut $crate::fmi_sys::fmi2::fmi2FMUstate)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_fmu_state::<$model>(c, state);
            fmi2SetFMUstate [fmi2SetFMUstateTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, state: $crate::fmi_sys::fmi2::fmi2FMUstate)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::set_fmu_state::<$model>(c, state);
            fmi2FreeFMUstate [fmi2FreeFMUstateTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, state: *mut $crate::fmi_sys::fmi2::fmi2FMUstate)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::free_fmu_state::<$model>(c, state);
            fmi2SerializedFMUstateSize [fmi2SerializedFMUstateSizeTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, state: $crate::fmi_sys::fmi2::fmi2FMUstate,
                size: *mut usize) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::serialized_fmu_state_size::<$model>(c, state, size);
            fmi2SerializeFMUstate [fmi2SerializeFMUstateTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, state: $crate::fmi_sys::fmi2::fmi2FMUstate,
                bytes: *mut $crate::fmi_sys::fmi2::fmi2Byte, size: usize) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::serialize_fmu_state::<$model>(c, state, bytes, size);
            fmi2DeSerializeFMUstate [fmi2DeSerializeFMUstateTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, bytes: *const $crate::fmi_sys::fmi2::fmi2Byte,
                size: usize, state: *mut $crate::fmi_sys::fmi2::fmi2FMUstate) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::deserialize_fmu_state::<$model>(c, bytes, size, state);
            fmi2GetDirectionalDerivative [fmi2GetDirectionalDerivativeTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component,
                _unknown: *const $crate::fmi_sys::fmi2::fmi2ValueReference, _n_unknown: usize,
                _known: *const $crate::fmi_sys::fmi2::fmi2ValueReference, _n_known: usize,
                _dv_known: *const $crate::fmi_sys::fmi2::fmi2Real, _dv_unknown: *mut $crate::fmi_sys::fmi2::fmi2Real)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::not_supported::<$model>(c, "fmi2GetDirectionalDerivative",
                    "providesDirectionalDerivative=\"false\"");
            fmi2SetRealInputDerivatives [fmi2SetRealInputDerivativesTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component,
                _vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, _nvr: usize,
                _order: *const $crate::fmi_sys::fmi2::fmi2Integer, _value: *const $crate::fmi_sys::fmi2::fmi2Real)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::not_supported::<$model>(c, "fmi2SetRealInputDerivatives", "canInterpolateInputs=\"false\"");
            fmi2GetRealOutputDerivatives [fmi2GetRealOutputDerivativesTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component,
                _vr: *const $crate::fmi_sys::fmi2::fmi2ValueReference, _nvr: usize,
                _order: *const $crate::fmi_sys::fmi2::fmi2Integer, _value: *mut $crate::fmi_sys::fmi2::fmi2Real)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::not_supported::<$model>(c, "fmi2GetRealOutputDerivatives",
                    "maxOutputDerivativeOrder=\"0\"");
            fmi2DoStep [fmi2DoStepTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, t: $crate::fmi_sys::fmi2::fmi2Real,
                h: $crate::fmi_sys::fmi2::fmi2Real, no_set_prior: $crate::fmi_sys::fmi2::fmi2Boolean)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::do_step::<$model>(c, t, h, no_set_prior);
            fmi2CancelStep [fmi2CancelStepTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::cancel_step::<$model>(c);
            fmi2GetStatus [fmi2GetStatusTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, s: $crate::fmi_sys::fmi2::fmi2StatusKind,
                value: *mut $crate::fmi_sys::fmi2::fmi2Status) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_status::<$model>(c, s, value);
            fmi2GetRealStatus [fmi2GetRealStatusTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, s: $crate::fmi_sys::fmi2::fmi2StatusKind,
                value: *mut $crate::fmi_sys::fmi2::fmi2Real) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_real_status::<$model>(c, s, value);
            fmi2GetIntegerStatus [fmi2GetIntegerStatusTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, s: $crate::fmi_sys::fmi2::fmi2StatusKind,
                value: *mut $crate::fmi_sys::fmi2::fmi2Integer) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_integer_status::<$model>(c, s, value);
            fmi2GetBooleanStatus [fmi2GetBooleanStatusTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, s: $crate::fmi_sys::fmi2::fmi2StatusKind,
                value: *mut $crate::fmi_sys::fmi2::fmi2Boolean) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_boolean_status::<$model>(c, s, value);
            fmi2GetStringStatus [fmi2GetStringStatusTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, s: $crate::fmi_sys::fmi2::fmi2StatusKind,
                value: *mut $crate::fmi_sys::fmi2::fmi2String) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_string_status::<$model>(c, s, value);
            // Model Exchange.
            fmi2EnterEventMode [fmi2EnterEventModeTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::enter_event_mode::<$model>(c);
            fmi2NewDiscreteStates [fmi2NewDiscreteStatesTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, info: *mut $crate::fmi_sys::fmi2::fmi2EventInfo)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::new_discrete_states::<$model>(c, info);
            fmi2EnterContinuousTimeMode [fmi2EnterContinuousTimeModeTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::enter_continuous_time_mode::<$model>(c);
            fmi2CompletedIntegratorStep [fmi2CompletedIntegratorStepTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, no_set_prior: $crate::fmi_sys::fmi2::fmi2Boolean,
                enter_event_mode: *mut $crate::fmi_sys::fmi2::fmi2Boolean,
                terminate: *mut $crate::fmi_sys::fmi2::fmi2Boolean) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::completed_integrator_step::<$model>(c, no_set_prior, enter_event_mode, terminate);
            fmi2SetTime [fmi2SetTimeTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, time: $crate::fmi_sys::fmi2::fmi2Real)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::set_time::<$model>(c, time);
            fmi2SetContinuousStates [fmi2SetContinuousStatesTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, x: *const $crate::fmi_sys::fmi2::fmi2Real, nx: usize)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::set_continuous_states::<$model>(c, x, nx);
            fmi2GetDerivatives [fmi2GetDerivativesTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, dx: *mut $crate::fmi_sys::fmi2::fmi2Real, nx: usize)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_derivatives::<$model>(c, dx, nx);
            fmi2GetEventIndicators [fmi2GetEventIndicatorsTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, z: *mut $crate::fmi_sys::fmi2::fmi2Real, ni: usize)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_event_indicators::<$model>(c, z, ni);
            fmi2GetContinuousStates [fmi2GetContinuousStatesTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component, x: *mut $crate::fmi_sys::fmi2::fmi2Real, nx: usize)
                -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_continuous_states::<$model>(c, x, nx);
            fmi2GetNominalsOfContinuousStates [fmi2GetNominalsOfContinuousStatesTYPE] (c: $crate::fmi_sys::fmi2::fmi2Component,
                x_nominal: *mut $crate::fmi_sys::fmi2::fmi2Real, nx: usize) -> $crate::fmi_sys::fmi2::fmi2Status
                => $crate::ffi::get_nominals_of_continuous_states::<$model>(c, x_nominal, nx);
        }

        /// FMI 2.0 `fmi2Instantiate` (see `fmi2_export::ffi::instantiate`).
        ///
        /// # Safety
        /// Called by an FMI host with the arguments of the C function.
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn fmi2Instantiate(
            instance_name: $crate::fmi_sys::fmi2::fmi2String,
            fmu_type: $crate::fmi_sys::fmi2::fmi2Type,
            guid: $crate::fmi_sys::fmi2::fmi2String,
            resource_location: $crate::fmi_sys::fmi2::fmi2String,
            functions: *const $crate::fmi_sys::fmi2::fmi2CallbackFunctions,
            visible: $crate::fmi_sys::fmi2::fmi2Boolean,
            logging_on: $crate::fmi_sys::fmi2::fmi2Boolean,
        ) -> $crate::fmi_sys::fmi2::fmi2Component {
            unsafe {
                $crate::ffi::instantiate::<$model>(
                    instance_name, fmu_type, guid, resource_location, functions, visible, logging_on,
                )
            }
        }
        const _: $crate::fmi_sys::fmi2::fmi2InstantiateTYPE = Some(fmi2Instantiate);
    };
}

/// Implementation detail of [`export_fmu!`]: one `extern "C"` function per
/// entry plus its compile-time signature check against `fmi-sys`.
#[doc(hidden)]
#[macro_export]
macro_rules! __export_fmu_fns {
    ($model:ty; $( $name:ident [$alias:ident] ( $($arg:ident : $ty:ty),* $(,)? ) -> $ret:ty => $body:expr ; )* ) => {
        $(
            const _: $crate::fmi_sys::fmi2::$alias = Some($name);
            #[doc = concat!("FMI 2.0 `", stringify!($name), "`, generated by `fmi2_export::export_fmu!`.")]
            ///
            /// # Safety
            /// Called by an FMI host with the arguments of the C function.
            #[allow(non_snake_case, clippy::missing_safety_doc, clippy::unused_unit, unused_unsafe)]
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name($($arg: $ty),*) -> $ret {
                unsafe { $body }
            }
        )*
    };
}
