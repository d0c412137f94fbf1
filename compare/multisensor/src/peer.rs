//! The peer's filters, built exactly as its `bench_utils::create_filter` builds them from its
//! `bench_utils::preprocess` of the scenario file, stepped as its `AnyFilter::run` steps them
//! (`SimpleRng::new(42)`; single-sensor LMB on sensor 0's points with the file's step index,
//! the multi-sensor filters on every sensor's points with the step's position as time).

use crate::{timed, Runner, StepOut};
use multisensor_lmb_filters_rs::bench_utils::{
    create_filter, load_scenario, preprocess, AnyFilter, PreprocessedScenario,
};
use multisensor_lmb_filters_rs::lmb::{SimpleRng, StateEstimate};
use multisensor_lmb_filters_rs::Filter;
use std::path::Path;

/// The peer crate's version this runner is written against.
pub const VERSION: &str = "0.3.2";

pub struct PeerRunner {
    filter: AnyFilter,
    prep: PreprocessedScenario,
    rng: SimpleRng,
}

impl PeerRunner {
    pub fn new(path: &Path, name: &str) -> Result<PeerRunner, String> {
        let path = path.to_str().ok_or("scenario path is not UTF-8")?;
        let prep = preprocess(&load_scenario(path));
        let filter = create_filter(name, &prep)?;
        Ok(PeerRunner {
            filter,
            prep,
            rng: SimpleRng::new(42),
        })
    }
}

fn positions(e: StateEstimate) -> Vec<[f64; 2]> {
    // The peer's state is [x, y, vx, vy].
    e.tracks.iter().map(|t| [t.mean[0], t.mean[1]]).collect()
}

impl Runner for PeerRunner {
    fn step(&mut self, k: usize) -> Result<StepOut, String> {
        let rng = &mut self.rng;
        let single = &self.prep.steps;
        let multi = &self.prep.multi_steps;
        let filter = &mut self.filter;
        let (est, ms, cpu_ms) = timed(|| match filter {
            AnyFilter::Lmb(f) => Some(f.step(rng, &single[k].1, single[k].0)),
            AnyFilter::IcLmb(f) => Some(f.step(rng, &multi[k], k)),
            AnyFilter::PuLmb(f) => Some(f.step(rng, &multi[k], k)),
            AnyFilter::GaLmb(f) => Some(f.step(rng, &multi[k], k)),
            AnyFilter::AaLmb(f) => Some(f.step(rng, &multi[k], k)),
            _ => None,
        });
        let est = est
            .ok_or("only the LMB filters are compared")?
            .map_err(|e| format!("peer step {k}: {e:?}"))?;
        Ok(StepOut {
            ms,
            cpu_ms,
            estimates: positions(est),
        })
    }
}
