//! The plant's Model Exchange declaration matches its physics: the continuous-state
//! vector (fmi2GetContinuousStates) is the physics state in `tailsitter_physics::idx`
//! order, each with its `der_<state>` derivative and a positive nominal.

use fmi2_export::VariableStore;
use tailsitter_physics::{idx::STATE_NAMES, N_STATES};
use tailsitter_plant::Variables;

#[test]
fn continuous_states_are_the_physics_state_in_index_order() {
    let states = Variables::CONTINUOUS_STATES;
    assert_eq!(states.len(), N_STATES);
    for (k, cs) in states.iter().enumerate() {
        let state = Variables::spec(cs.state).expect("state declared");
        let der = Variables::spec(cs.derivative).expect("derivative declared");
        assert_eq!(state.name, STATE_NAMES[k]);
        assert_eq!(der.name, format!("der_{}", STATE_NAMES[k]));
        assert!(cs.nominal > 0.0 && cs.nominal.is_finite());
    }
}
