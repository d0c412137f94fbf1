//! The rule by which the moving-object detector ([`super::moving`]) turns a cluster of
//! foreground returns into a moving target, and the stage at which a cluster that is not one
//! was turned down.
//!
//! Two rules are offered:
//!
//! * [`MovingRule::Voting`], seed 003 as written (Secs. III–IV): a cluster needs
//!   `min_points` returns, a local range minimum (eq. 7), a cluster of the previous scan
//!   within the association gate (when persistence is required) and a dominant Fuzzy ART
//!   category (eq. 8).
//! * [`MovingRule::Attenuation`]: the background attenuation is the moving evidence. Every
//!   cluster of at least `min_points` foreground returns — returns the propagated background
//!   does not explain and that lie off the static local map — is a moving target. With
//!   `veto`, the Fuzzy ART vote acts as a classifier that can only say no: a cluster whose
//!   category is not dominant is turned down. The local-minimum filter and persistence are
//!   not asked: on a scanner with a few degrees of bearing noise most people more than a few
//!   metres away fail the local-minimum test (their returns are shuffled among the wall's),
//!   and a person newly in view does not persist yet, while the tracker behind the detector
//!   already handles missed and false detections.
//!
//! Not for: computing the evidence (background, clustering, features, votes live in the
//! detector and its parts).

/// How clusters become moving targets; see the module documentation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MovingRule {
    /// Seed 003: size, local minimum, persistence, dominant vote.
    #[default]
    Voting,
    /// Background attenuation: size only, and with `veto` a dominant vote.
    Attenuation {
        /// Turn down clusters whose Fuzzy ART category is not dominant.
        veto: bool,
    },
}

/// Where a cluster of foreground returns ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClusterStage {
    /// Fewer returns than the smallest cluster.
    TooSmall,
    /// No local range minimum among its beams (Voting only).
    NoLocalMinimum,
    /// No cluster of the previous scan within the association gate (Voting with persistence).
    NotPersistent,
    /// Its Fuzzy ART category is not dominant.
    NotDominant,
    /// A moving target.
    Moving,
}

/// What is known about one cluster when the rule decides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClusterEvidence {
    /// Number of returns.
    pub points: usize,
    /// Whether one of its beams is a local range minimum.
    pub local_minimum: bool,
    /// Whether a cluster of the previous scan lay within the association gate.
    pub persistent: bool,
    /// Whether its Fuzzy ART category is dominant (eq. 8).
    pub dominant: bool,
}

impl MovingRule {
    /// Whether the rule needs the local-minimum test (the detector skips it otherwise).
    pub fn uses_local_minimum(&self) -> bool {
        matches!(self, MovingRule::Voting)
    }

    /// The stage at which `e` ends: [`ClusterStage::Moving`] for a moving target.
    /// `min_points` is the smallest cluster, `require_persistence` the Voting rule's
    /// persistence switch.
    pub fn decide(
        &self,
        e: &ClusterEvidence,
        min_points: usize,
        require_persistence: bool,
    ) -> ClusterStage {
        if e.points < min_points {
            return ClusterStage::TooSmall;
        }
        match *self {
            MovingRule::Voting => {
                if !e.local_minimum {
                    ClusterStage::NoLocalMinimum
                } else if require_persistence && !e.persistent {
                    ClusterStage::NotPersistent
                } else if !e.dominant {
                    ClusterStage::NotDominant
                } else {
                    ClusterStage::Moving
                }
            }
            MovingRule::Attenuation { veto } => {
                if veto && !e.dominant {
                    ClusterStage::NotDominant
                } else {
                    ClusterStage::Moving
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn evidence(
        points: usize,
        local_minimum: bool,
        persistent: bool,
        dominant: bool,
    ) -> ClusterEvidence {
        ClusterEvidence {
            points,
            local_minimum,
            persistent,
            dominant,
        }
    }

    #[test]
    fn voting_asks_every_stage_in_order() {
        let v = MovingRule::Voting;
        assert_eq!(
            v.decide(&evidence(2, true, true, true), 3, true),
            ClusterStage::TooSmall
        );
        assert_eq!(
            v.decide(&evidence(3, false, true, true), 3, true),
            ClusterStage::NoLocalMinimum
        );
        assert_eq!(
            v.decide(&evidence(3, true, false, true), 3, true),
            ClusterStage::NotPersistent
        );
        // Persistence not required: a new cluster with a dominant category is moving.
        assert_eq!(
            v.decide(&evidence(3, true, false, true), 3, false),
            ClusterStage::Moving
        );
        assert_eq!(
            v.decide(&evidence(3, true, true, false), 3, true),
            ClusterStage::NotDominant
        );
        assert_eq!(
            v.decide(&evidence(9, true, true, true), 3, true),
            ClusterStage::Moving
        );
    }

    #[test]
    fn attenuation_ignores_minima_and_persistence_and_vetoes_only_by_vote() {
        let plain = MovingRule::Attenuation { veto: false };
        let veto = MovingRule::Attenuation { veto: true };
        // Neither a local minimum nor persistence is needed.
        let new_far = evidence(3, false, false, true);
        assert_eq!(plain.decide(&new_far, 3, true), ClusterStage::Moving);
        assert_eq!(veto.decide(&new_far, 3, true), ClusterStage::Moving);
        // A non-dominant category: only the veto turns it down.
        let odd_shape = evidence(5, false, true, false);
        assert_eq!(plain.decide(&odd_shape, 3, true), ClusterStage::Moving);
        assert_eq!(veto.decide(&odd_shape, 3, true), ClusterStage::NotDominant);
        // Size still counts.
        assert_eq!(
            plain.decide(&evidence(2, true, true, true), 3, true),
            ClusterStage::TooSmall
        );
        assert!(!plain.uses_local_minimum() && MovingRule::Voting.uses_local_minimum());
    }
}
