//! Prints a 64-bit FNV-1a digest of every output bit of a 60 s run per seed, to compare
//! platforms: the same seed must give the same digest on Linux and Windows
//! (`cargo run --example digest`; cross-check e.g. with the x86_64-pc-windows-gnu build under wine).

use nalgebra::Vector3;
use sensor_model::{Params, SensorModel, Truth};

fn main() {
    for seed in [1u64, 2, 12345] {
        let truth = Truth {
            pos_ned: Vector3::new(100.0, -50.0, -30.0),
            vel_ned: Vector3::new(20.0, 1.0, -0.5),
            rates: Vector3::new(0.1, -0.05, 0.02),
            quat: tailsitter_physics::quat_from_euler_321(0.2, 0.3, -1.0),
            airspeed: 22.0,
            alpha: 0.08,
            beta: -0.02,
            specific_force: Vector3::new(1.0, 0.2, -9.5),
        };
        let mut m = SensorModel::new(Params {
            seed,
            accel_rate: 1000.0,
            ..Params::default()
        })
        .expect("default parameters are valid");
        let mut digest: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |x: u64| {
            for b in x.to_le_bytes() {
                digest = (digest ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
            }
        };
        m.start(&truth, 0.0).expect("finite truth");
        for k in 0..3000 {
            let out = m.step(&truth, k as f64 * 0.02, 0.02).expect("finite truth");
            out.analog.iter().for_each(|x| eat(x.to_bits()));
            for x in [out.gps_latitude, out.gps_longitude, out.gps_height] {
                eat(x.to_bits());
            }
            out.gps_vel.iter().for_each(|x| eat(x.to_bits()));
            eat(u64::from(out.gps_fix_count));
        }
        println!("seed {seed}: {digest:016x}");
    }
}
