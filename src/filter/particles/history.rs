//! The particles' ancestral states over the last steps, for fixed-lag smoothing: the
//! recording ([`ParticleSet::keep_history`], [`ParticleSet::push_history`]) and the lagged
//! estimates. Resampling (in the parent module) carries each particle's past along with it.
//!
//! Why the genealogy and not a backward pass (forward filtering, backward simulation): the
//! backward pass weighs every particle pair by the transition density, which a user's
//! [`crate::filter::TransitionModel`] does not provide and which is degenerate for the
//! motion models here (their noise drives fewer dimensions than the state has). The price of
//! the genealogy is path degeneracy: after many resamplings few distinct ancestors remain, so
//! the lag should stay short (a few steps).
//!
//! Not for: deciding which tracks exist (the smoother refines the states of the tracks the
//! filter reports; see [`crate::filter::smoothing`]).

use super::ParticleSet;

impl ParticleSet {
    /// Keeps the particles' states over the last `lag` steps from now on (0 stops keeping
    /// them). Changing the lag forgets what was kept.
    pub fn keep_history(&mut self, lag: usize) {
        if lag == self.history_lag {
            return;
        }
        self.history_lag = lag;
        self.history_depth = 0;
        self.history_head = 0;
        self.history = vec![0.0; lag * self.dim * self.len];
    }

    /// Steps of history kept ([`ParticleSet::keep_history`]).
    pub fn history_lag(&self) -> usize {
        self.history_lag
    }

    /// Steps of history recorded so far (at most the lag).
    pub fn history_depth(&self) -> usize {
        self.history_depth
    }

    /// Records the current states as every particle's state one step back, the older ones
    /// a step further (the oldest beyond the lag is dropped: its slot of the ring takes the
    /// current states, so nothing else moves). Called once per step, before the transition
    /// moves the particles. Does nothing unless history is kept.
    pub fn push_history(&mut self) {
        let lag = self.history_lag;
        if lag == 0 {
            return;
        }
        let block = self.dim * self.len;
        self.history_head = (self.history_head + lag - 1) % lag;
        let start = self.history_head * block;
        self.history[start..start + block].copy_from_slice(&self.states);
        self.history_depth = (self.history_depth + 1).min(lag);
    }

    /// Component `c` of every particle's ancestor `steps_back` steps ago (0: the current
    /// states); `None` beyond the recorded depth or for `c ≥ dim`.
    pub fn lagged_component(&self, steps_back: usize, c: usize) -> Option<&[f64]> {
        if c >= self.dim {
            return None;
        }
        if steps_back == 0 {
            return Some(self.component(c));
        }
        if steps_back > self.history_depth {
            return None;
        }
        let slot = (self.history_head + steps_back - 1) % self.history_lag;
        let start = (slot * self.dim + c) * self.len;
        Some(&self.history[start..start + self.len])
    }

    /// The weighted mean of the particles' ancestors `steps_back` steps ago, with today's
    /// weights: the fixed-lag smoothed estimate of that step's state. `None` beyond the
    /// recorded depth.
    pub fn lagged_mean(&self, steps_back: usize) -> Option<Vec<f64>> {
        (0..self.dim)
            .map(|c| {
                self.lagged_component(steps_back, c)
                    .map(|x| x.iter().zip(&self.weights).map(|(x, w)| x * w).sum::<f64>())
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::Jitter;
    use crate::rng::seeded;
    use rand_distr::{Distribution, StandardNormal};

    #[test]
    fn resampling_carries_each_particles_past_along() {
        let mut rng = seeded(5);
        let mut p = ParticleSet::zeroed(2, 6);
        p.keep_history(2);
        // Particle i starts at (i, −i); each step adds 10 to the first component.
        for (c, sign) in [(0, 1.0), (1, -1.0)] {
            for (i, v) in p.component_mut(c).iter_mut().enumerate() {
                *v = sign * i as f64;
            }
        }
        p.push_history();
        p.component_mut(0).iter_mut().for_each(|v| *v += 10.0);
        assert_eq!(p.history_depth(), 1);
        p.reweight(&[0.0, 0.0, 1.0, 0.0, 3.0, 0.0]);
        p.resample(8, Jitter::None, &mut rng);
        let now = p.component(0).to_vec();
        let back = p.lagged_component(1, 0).unwrap();
        let back_y = p.lagged_component(1, 1).unwrap();
        for i in 0..8 {
            // Only particles 2 and 4 survive; each keeps its own past.
            assert!(now[i] == 12.0 || now[i] == 14.0, "{now:?}");
            assert_eq!(back[i], now[i] - 10.0);
            assert_eq!(back_y[i], -(now[i] - 10.0));
        }
        assert!(p.lagged_component(2, 0).is_none());
        p.push_history();
        p.push_history();
        assert_eq!(p.history_depth(), 2);
        assert_eq!(p.lagged_component(2, 0).unwrap(), &now[..]);
        assert_eq!(p.lagged_mean(0).unwrap(), p.mean());
    }

    /// A random walk x_k = x_(k−1) + N(0, q) seen as y_k = x_k + N(0, r): the particles'
    /// weighted pasts give the fixed-lag smoothed mean, which the Rauch–Tung–Striebel
    /// smoother computes exactly (here by hand, independently of the particle code).
    #[test]
    fn lagged_means_match_the_rauch_tung_striebel_smoother_on_a_random_walk() {
        let (q, r, p0) = (1.0f64, 0.5f64, 4.0f64);
        let (steps, lag, n) = (12usize, 3usize, 40_000usize);
        let mut rng = seeded(21);
        let mut x = 0.0f64;
        let ys: Vec<f64> = (0..steps)
            .map(|k| {
                if k > 0 {
                    x += q.sqrt() * {
                        let e: f64 = StandardNormal.sample(&mut rng);
                        e
                    };
                }
                x + r.sqrt() * {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    e
                }
            })
            .collect();
        // Kalman filter forward, then RTS backward over all the measurements.
        let (mut m, mut v) = (vec![0.0; steps], vec![0.0; steps]);
        let (mut mp, mut vp) = (0.0, p0);
        for k in 0..steps {
            if k > 0 {
                mp = m[k - 1];
                vp = v[k - 1] + q;
            }
            let gain = vp / (vp + r);
            m[k] = mp + gain * (ys[k] - mp);
            v[k] = (1.0 - gain) * vp;
        }
        let mut smooth = m.clone();
        for k in (0..steps - 1).rev() {
            let c = v[k] / (v[k] + q);
            smooth[k] = m[k] + c * (smooth[k + 1] - m[k]);
        }
        // Bootstrap particle filter with its history.
        let mut set = ParticleSet::sampled(&[0.0], &[p0.sqrt()], n, &mut rng);
        set.keep_history(lag);
        for (k, &y) in ys.iter().enumerate() {
            if k > 0 {
                set.push_history();
                for v in set.component_mut(0) {
                    *v += q.sqrt() * {
                        let e: f64 = StandardNormal.sample(&mut rng);
                        e
                    };
                }
            }
            let log: Vec<f64> = set
                .component(0)
                .iter()
                .map(|x| -0.5 * (y - x) * (y - x) / r)
                .collect();
            set.reweight_log(&log);
            set.resample(n, Jitter::None, &mut rng);
        }
        // At the last step the RTS smoother of step steps−1−l uses every measurement, as the
        // particles' pasts do.
        for l in 0..=lag {
            let k = steps - 1 - l;
            let got = set.lagged_mean(l).unwrap()[0];
            assert!(
                (got - smooth[k]).abs() < 0.05,
                "lag {l}: particles {got}, RTS {} (filter {})",
                smooth[k],
                m[k]
            );
        }
        // The smoother is not the filter: the test would notice a history of filtered means.
        assert!((smooth[steps - 1 - lag] - m[steps - 1 - lag]).abs() > 0.1);
    }
}
