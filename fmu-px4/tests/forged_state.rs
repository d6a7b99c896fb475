//! A serialized FMU state is checked like values set by the host: a forged mission
//! parameter is refused with fmi2Error and a message naming it
//! ([`controller_fmu::testing::assert_forged_mission_parameter_is_refused`]).

#[test]
fn forged_mission_parameter_in_a_restored_state_is_refused() {
    controller_fmu::testing::assert_forged_mission_parameter_is_refused::<tailsitter_px4::Px4Model>();
}
