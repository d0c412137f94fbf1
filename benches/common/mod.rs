//! What the benchmarks share.

use smc_lmb::filter::birth::BirthEvidence;
use smc_lmb::filter::{BirthModel, BirthTrack, StaticBirth, StepContext};
use smc_lmb::FilterRng;

/// Births only at the first step: the tracks under test, and nothing new afterwards.
pub struct FirstStepOnly(pub StaticBirth);

impl BirthModel for FirstStepOnly {
    fn birth(
        &self,
        ctx: &StepContext,
        ev: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        if ctx.step == 0 {
            self.0.birth(ctx, ev, rng)
        } else {
            Vec::new()
        }
    }
}
