//! Mounting estimation (`laser2d::mounting`) on the simulated people world with three lasers
//! (`sim::people2d::lasers`): the lobby of the second experiment of Bahraini, Bozorg & Rad (2018), people walking, the
//! robot driving at up to 2 m/s, the lasers at 8, 8 and 5 Hz with time offsets. The estimated
//! poses of the front-right and rear lasers in the front-left laser's frame must be the true
//! ones within the tolerances below.

use smc_lmb::geometry::pose2::between;
use smc_lmb::geometry::wrap_angle;
use smc_lmb::laser2d::mounting::{estimate_mounting, MountingConfig};
use smc_lmb::sim::people2d::lasers::LaserRig;
use smc_lmb::sim::{PeopleScenario, ScannerSpec};

/// A scanner of the kind on real robots (Hokuyo UTM-30LX class): 2 cm range noise and a
/// bearing error of a tenth of a degree, 30 m range; the preset narrows its field of view.
fn real_scanner() -> ScannerSpec {
    ScannerSpec {
        sigma_range: 0.02,
        sigma_bearing: 0.1f64.to_radians(),
        ..ScannerSpec::default()
    }
}

#[test]
fn recovers_the_three_laser_rig_in_the_lobby() {
    let scenario = PeopleScenario::two();
    let rig = LaserRig::three_lasers(real_scanner());
    let run = scenario.generate_lasers(&rig, 11).unwrap();
    let reference = &run.lasers[0];
    // The lobby is 30 m × 20 m and the scanners reach 30 m: returns out to 15 m are used (the
    // default 8 m suits rooms).
    let config = MountingConfig {
        max_range: 15.0,
        ..MountingConfig::default()
    };
    for sensor in &run.lasers[1..] {
        let truth = between(reference.mounting, sensor.mounting);
        let est = estimate_mounting(&reference.scans, &sensor.scans, &config).unwrap();
        let m = est.mounting;
        let d = (m.x - truth.x).hypot(m.y - truth.y);
        let dh = wrap_angle(m.theta - truth.theta).abs();
        eprintln!(
            "{}: truth [{:.4}, {:.4}, {:.4}] estimate [{:.4}, {:.4}, {:.4}] error {:.4} m {:.5} rad; kept {} of {}, votes {}/{}, robust std {:?}, residual line rms {:.4} m",
            sensor.name, truth.x, truth.y, truth.theta, m.x, m.y, m.theta, d, dh,
            est.pairs_kept, est.pairs_tried, est.coarse_votes, est.coarse_tried,
            est.spread.robust_std, est.residuals.line_rms_median
        );
        // Tolerances: 3 cm and 0.5° — about one range-noise σ (2 cm) plus the motion
        // interpolation error at 2 m/s, far below what matters to people tracking (a person
        // is ~0.4 m across) and ten times below the error of a wrong coarse solution (≥ 0.3 m
        // or several degrees).
        assert!(d < 0.03, "{}: position error {d} m", sensor.name);
        assert!(
            dh < 0.5f64.to_radians(),
            "{}: heading error {dh} rad",
            sensor.name
        );
        // People crossing the narrow shared wedges and open floor leave many single pairs
        // unusable; a quarter must register.
        assert!(
            est.pairs_kept * 4 >= est.pairs_tried,
            "{}: {est:?}",
            sensor.name
        );
    }
}
