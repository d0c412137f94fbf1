//! Seed 000's second simulated scenario, the lobby (walls, pillars, ten people who enter, turn
//! round and leave), behind the moving-object front end: the LMB people tracker against the
//! GNN and ML-RANSAC baselines on the same measurements, scored by the same harness (odometry
//! pose, robot frame), as `examples/laser2d.rs --scenario two` does.

use smc_lmb::models::RangeBearing;
use smc_lmb::pipeline::people_tracking::evaluate::{evaluate_run, EvalConfig, RunMetrics};
use smc_lmb::pipeline::people_tracking::front_end::{adapt_tracker_config, FrontEnd};
use smc_lmb::pipeline::people_tracking::tracker::centre_noise;
use smc_lmb::pipeline::people_tracking::{PeopleTracker, PeopleTrackerConfig};
use smc_lmb::sim::PeopleScenario;
use smc_lmb::trackers::{GnnConfig, GnnTracker, MlRansacConfig, MlRansacTracker, PointTracker};

fn lobby_config(scenario: &PeopleScenario, seed: u64) -> PeopleTrackerConfig {
    let s = &scenario.scanner;
    let mut cfg = PeopleTrackerConfig::for_scanner(
        s.sigma_range,
        s.sigma_bearing,
        s.range_max,
        s.fov / 2.0,
        scenario.mount,
    );
    cfg.filter.seed = seed;
    adapt_tracker_config(&mut cfg, FrontEnd::Moving);
    cfg
}

/// Mean OSPA(2) and summed label switches of the three trackers over `seeds`.
fn scores(seeds: std::ops::RangeInclusive<u64>) -> [(f64, usize); 3] {
    let scenario = PeopleScenario::two();
    let s = &scenario.scanner;
    let (sr, sb) = centre_noise(s.sigma_range, s.sigma_bearing);
    let sensor = RangeBearing::new(sr, sb)
        .unwrap()
        .with_offset(scenario.mount[0], scenario.mount[1])
        .unwrap();
    let eval = EvalConfig {
        front_end: FrontEnd::Moving,
        ..EvalConfig::default()
    };
    let detector = lobby_config(&scenario, 0);
    let mut out = [(0.0, 0); 3];
    let n = seeds.clone().count() as f64;
    for seed in seeds {
        let run = scenario.generate(seed).unwrap();
        let mut ml_ransac = MlRansacConfig::new(sensor);
        ml_ransac.seed = seed;
        let trackers: [Box<dyn PointTracker>; 3] = [
            Box::new(PeopleTracker::new(lobby_config(&scenario, seed)).unwrap()),
            Box::new(GnnTracker::new(GnnConfig::new(sensor)).unwrap()),
            Box::new(MlRansacTracker::new(ml_ransac).unwrap()),
        ];
        for (slot, mut tracker) in out.iter_mut().zip(trackers) {
            let m: RunMetrics = evaluate_run(tracker.as_mut(), &run, &detector, &eval).unwrap();
            eprintln!("seed {seed} {}: {m:?}", tracker.name());
            slot.0 += m.ospa2 / n;
            slot.1 += m.label_switches;
        }
    }
    out
}

/// The target for the lobby: the LMB's OSPA(2) (c = 2 m, p = 1) below both GNN's and
/// ML-RANSAC's. Seeds 1–2 (`docs/laser2d.md` reports seeds 1–8 and 11–18); a tracker that splits
/// people into many labels or loses them sits near the cut-off.
#[test]
fn in_the_lobby_the_lmb_beats_gnn_and_ml_ransac_on_ospa2() {
    let [lmb, gnn, ml_ransac] = scores(1..=2);
    eprintln!("OSPA(2), switches: lmb {lmb:?}, gnn {gnn:?}, ml_ransac {ml_ransac:?}");
    assert!(lmb.0 < gnn.0, "LMB {lmb:?} vs GNN {gnn:?}");
    assert!(
        lmb.0 < ml_ransac.0,
        "LMB {lmb:?} vs ML-RANSAC {ml_ransac:?}"
    );
    assert!(lmb.0 < 1.4, "LMB {lmb:?}");
    assert!(
        lmb.1 <= ml_ransac.1,
        "LMB {lmb:?} vs ML-RANSAC {ml_ransac:?}"
    );
}
