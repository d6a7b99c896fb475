//! The plant FMU's stick-slip gear contact: the anchors go through the FMU state, and the
//! static friction coefficient is validated.

use fmi2_export::test_host::assert_initialization_fails;
use fmi2_export::{FmuModel, Logger, StateReader, StateWriter, VariableStore};
use tailsitter_plant::{PlantModel, Variables};

/// On the gear in a gusty wind (stuck and slipping points): a state saved after 1 s and
/// restored into a new instance flies the next 3 s bit for bit; a truncated state is refused.
#[test]
fn the_anchors_are_part_of_the_fmu_state() {
    let mut v = Variables::with_start_values();
    v.initial_condition = 2;
    let mut m = PlantModel::new(&v);
    m.initialize(&mut v, 0.0, &mut Logger::null()).unwrap();
    let mut log = Logger::null();
    let gust = |v: &mut Variables, k: usize| {
        // 9 m/s from the north with a 4 m/s, 1 s oscillation: the gear holds and slips.
        v.wind_n = -9.0 - 4.0 * (k as f64 * 0.02 * std::f64::consts::TAU).sin();
        v.wind_e = 1.0;
    };
    let fly = |m: &mut PlantModel, v: &mut Variables, steps: std::ops::Range<usize>, log: &mut Logger<'_>| {
        for k in steps {
            gust(v, k);
            m.do_step(v, k as f64 * 0.02, 0.02, log).unwrap();
        }
        m.update_outputs(v).unwrap();
        [v.pos_n, v.pos_e, v.pos_d, v.q].map(f64::to_bits)
    };
    let start = fly(&mut m, &mut v, 0..50, &mut log);
    let mut w = StateWriter::new();
    m.write_state(&mut w);
    let bytes = w.into_bytes();
    let mut v2 = v.clone();
    let reference = fly(&mut m, &mut v, 50..200, &mut log);
    assert_ne!(reference[..2], start[..2], "the gusts moved the aircraft on its gear");
    let mut m2 = PlantModel::new(&v2);
    let mut r = StateReader::new(&bytes);
    m2.read_state(&mut r).unwrap();
    r.finish().unwrap();
    assert_eq!(fly(&mut m2, &mut v2, 50..200, &mut log), reference);
    // The anchors are the last 7 × (2 f64 + 1 byte): any cut into them is refused.
    for n in bytes.len() - 7 * 17..bytes.len() {
        assert!(PlantModel::new(&v2)
            .read_state(&mut StateReader::new(&bytes[..n]))
            .is_err());
    }
    // An unknown grip code is refused.
    let mut bad = bytes.clone();
    *bad.last_mut().unwrap() = 7;
    assert!(PlantModel::new(&v2).read_state(&mut StateReader::new(&bad)).is_err());
}

#[test]
fn bad_static_friction_is_refused() {
    assert_initialization_fails::<PlantModel>(|v| v.ground_static_friction = 0.3, "ground_static_friction");
    assert_initialization_fails::<PlantModel>(|v| v.ground_static_friction = f64::NAN, "ground_static_friction");
}
