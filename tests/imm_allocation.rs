//! The IMM allocates nothing per step.

use crate::common;
use crate::common::counting_allocator;

use counting_allocator::count_allocations;
use glam::DVec2;
use primm_core::config::Config;
use primm_core::imm::Imm;
use primm_core::motion::{ModeModels, PredictContext};

#[test]
fn ten_thousand_imm_cycles_allocate_nothing() {
    let config = Config::default();
    let models = ModeModels::from_config(&config.classes.car);
    let imm = Imm::new(&config.imm);
    let mut state = imm.initiate(&models, &common::measurement(20.0, 1.0, 3.0));
    // The counter itself must work: a Vec allocates.
    assert!(count_allocations(|| drop(std::hint::black_box(vec![1u8; 16]))) >= 1);
    let allocations = count_allocations(|| {
        for step in 0..10_000u32 {
            let dt = 0.02 + 0.01 * f64::from(step % 5);
            let displacement = (step % 7 != 0).then_some(DVec2::new(0.2, 0.05));
            let prior = imm.predict(
                &models,
                &state,
                &PredictContext { dt_s: dt, displacement_m: displacement, displacement_covariance_m2: None },
            );
            let z = DVec2::new(20.0 + 0.2 * f64::from(step) * dt, 1.0);
            state = if step % 11 == 0 { imm.coast(&prior) } else { imm.update(&models, &prior, z).unwrap() };
            std::hint::black_box(imm.fuse_posterior(&state, prior.available));
        }
    });
    assert_eq!(allocations, 0);
}
