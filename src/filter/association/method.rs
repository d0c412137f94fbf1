//! [`AssociationMethod`]: a configurable choice of association method, read from a
//! configuration file (serde, with a `method` tag) or a command-line string (`murty:500`),
//! with each method's defaults, and itself an [`Associator`] that hands the problem to the
//! chosen algorithm.
//!
//! Not for: the algorithms themselves (see the `murty`, `gibbs`, `lbp` and `exhaustive`
//! modules) or the problem and marginal types (see [`AssociationProblem`], [`Marginals`]).

use super::problem::{AssociationProblem, Associator, Marginals};
use super::{ExhaustiveAssociator, GibbsAssociator, LbpAssociator, MurtyAssociator};
use crate::rng::FilterRng;
use std::str::FromStr;

/// A configurable choice of association method.
///
/// Serialised with a `method` tag, e.g. `{"method": "murty", "k": 200}` or
/// `{"method": "lbp", "max_iterations": 100, "tolerance": 1e-9}`.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum AssociationMethod {
    /// Murty's k-best ranked assignment ([`MurtyAssociator`]).
    Murty {
        /// Number of best hypotheses kept (default 200).
        #[serde(default = "default_murty_k")]
        k: usize,
        /// Hypotheses lighter than this fraction of the best are not ranked (default 10⁻⁵;
        /// 0 ranks exactly `k`).
        #[serde(default = "default_murty_min_weight")]
        min_weight: f64,
    },
    /// Gibbs sampling of hypotheses ([`GibbsAssociator`]).
    Gibbs {
        /// Number of Gibbs sweeps (default 1000).
        #[serde(default = "default_gibbs_samples")]
        samples: usize,
    },
    /// Loopy belief propagation ([`LbpAssociator`]).
    Lbp {
        /// Iteration cap (default 100).
        #[serde(default = "default_lbp_iterations")]
        max_iterations: usize,
        /// Stop when no message changes by more than this (default 1e-9).
        #[serde(default = "default_lbp_tolerance")]
        tolerance: f64,
    },
    /// Exhaustive enumeration ([`ExhaustiveAssociator`] with its default cap).
    Exhaustive,
}

fn default_murty_k() -> usize {
    MurtyAssociator::default().k
}
fn default_murty_min_weight() -> f64 {
    MurtyAssociator::default().min_weight
}
fn default_gibbs_samples() -> usize {
    GibbsAssociator::default().samples
}
fn default_lbp_iterations() -> usize {
    LbpAssociator::default().max_iterations
}
fn default_lbp_tolerance() -> f64 {
    LbpAssociator::default().tolerance
}

impl Default for AssociationMethod {
    /// Loopy belief propagation with 100 iterations and tolerance 10⁻⁹: fast, deterministic
    /// and accurate for the small groups the filter produces.
    fn default() -> Self {
        let lbp = LbpAssociator::default();
        AssociationMethod::Lbp {
            max_iterations: lbp.max_iterations,
            tolerance: lbp.tolerance,
        }
    }
}

/// Largest Murty k (hypotheses kept) a configuration may ask for: each ranked hypothesis
/// costs an assignment problem, so 10⁵ already means minutes per step on a large group.
pub const MAX_MURTY_K: usize = 100_000;
/// Largest number of Gibbs sweeps a configuration may ask for (10⁷).
pub const MAX_GIBBS_SAMPLES: usize = 10_000_000;
/// Largest LBP iteration cap a configuration may ask for (10⁶).
pub const MAX_LBP_ITERATIONS: usize = 1_000_000;

impl AssociationMethod {
    /// Checks the method's settings: Murty k in 1..=[`MAX_MURTY_K`], Gibbs sweeps in
    /// 1..=[`MAX_GIBBS_SAMPLES`], LBP iterations in 1..=[`MAX_LBP_ITERATIONS`] with a finite,
    /// non-negative tolerance. Errors name the field.
    pub fn validate(&self) -> crate::Result<()> {
        let bounded = |field: &str, v: usize, max: usize| -> crate::Result<()> {
            if v == 0 || v > max {
                return Err(crate::Error::invalid(
                    format!("association {field}"),
                    format!("{v} outside 1..={max}"),
                ));
            }
            Ok(())
        };
        match *self {
            AssociationMethod::Murty { k, min_weight } => {
                bounded("k", k, MAX_MURTY_K)?;
                if !(0.0..1.0).contains(&min_weight) {
                    return Err(crate::Error::invalid(
                        "association min_weight",
                        format!("{min_weight} (must be in [0, 1))"),
                    ));
                }
                Ok(())
            }
            AssociationMethod::Gibbs { samples } => bounded("samples", samples, MAX_GIBBS_SAMPLES),
            AssociationMethod::Lbp {
                max_iterations,
                tolerance,
            } => {
                bounded("max_iterations", max_iterations, MAX_LBP_ITERATIONS)?;
                if !(tolerance >= 0.0 && tolerance.is_finite()) {
                    return Err(crate::Error::invalid(
                        "association tolerance",
                        format!("{tolerance} (must be finite and non-negative)"),
                    ));
                }
                Ok(())
            }
            AssociationMethod::Exhaustive => Ok(()),
        }
    }
}

impl Associator for AssociationMethod {
    fn marginals(&self, problem: &AssociationProblem, rng: &mut FilterRng) -> Marginals {
        match *self {
            AssociationMethod::Murty { k, min_weight } => {
                MurtyAssociator { k, min_weight }.marginals(problem, rng)
            }
            AssociationMethod::Gibbs { samples } => {
                GibbsAssociator { samples }.marginals(problem, rng)
            }
            AssociationMethod::Lbp {
                max_iterations,
                tolerance,
            } => LbpAssociator {
                max_iterations,
                tolerance,
            }
            .marginals(problem, rng),
            AssociationMethod::Exhaustive => {
                ExhaustiveAssociator::default().marginals(problem, rng)
            }
        }
    }
}

impl FromStr for AssociationMethod {
    type Err = crate::Error;

    /// Parses `murty`, `gibbs`, `lbp` or `exhaustive` (case-insensitive), each with its
    /// defaults (k = 200 with the weight floor 10⁻⁵, 1000 samples, 100 iterations with
    /// tolerance 10⁻⁹), optionally
    /// followed by `:N` to set k, the number of samples or the iteration cap, e.g. `murty:500`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim().to_ascii_lowercase();
        let (name, arg) = match s.split_once(':') {
            Some((n, a)) => (n.trim(), Some(a.trim())),
            None => (s.as_str(), None),
        };
        let number = |a: Option<&str>, default: usize| -> crate::Result<usize> {
            match a {
                None => Ok(default),
                Some(a) => a.parse::<usize>().map_err(|e| {
                    crate::Error::invalid("association method", format!("{name}:{a}: {e}"))
                }),
            }
        };
        let method = match name {
            "murty" => Ok(AssociationMethod::Murty {
                k: number(arg, MurtyAssociator::default().k)?,
                min_weight: MurtyAssociator::default().min_weight,
            }),
            "gibbs" => Ok(AssociationMethod::Gibbs {
                samples: number(arg, GibbsAssociator::default().samples)?,
            }),
            "lbp" => {
                let lbp = LbpAssociator::default();
                Ok(AssociationMethod::Lbp {
                    max_iterations: number(arg, lbp.max_iterations)?,
                    tolerance: lbp.tolerance,
                })
            }
            "exhaustive" if arg.is_none() => Ok(AssociationMethod::Exhaustive),
            _ => Err(crate::Error::invalid(
                "association method",
                format!("`{s}` (expected murty, gibbs, lbp or exhaustive, optionally `:N`)"),
            )),
        }?;
        method.validate()?;
        Ok(method)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_beyond_their_bounds_are_refused() {
        for bad in [
            "murty:0",
            "murty:100001",
            "gibbs:0",
            "gibbs:10000001",
            "lbp:0",
        ] {
            let err = bad.parse::<AssociationMethod>().unwrap_err().to_string();
            assert!(err.contains("outside 1..="), "{bad}: {err}");
        }
        assert!("murty:100000".parse::<AssociationMethod>().is_ok());
        for w in [-1e-3, 1.0, f64::NAN] {
            let m = AssociationMethod::Murty {
                k: 10,
                min_weight: w,
            };
            assert!(m.validate().unwrap_err().to_string().contains("min_weight"));
        }
        let lbp = AssociationMethod::Lbp {
            max_iterations: 10,
            tolerance: f64::NAN,
        };
        assert!(lbp
            .validate()
            .unwrap_err()
            .to_string()
            .contains("tolerance"));
        assert!(AssociationMethod::Exhaustive.validate().is_ok());
    }

    #[test]
    fn parse_names_and_defaults() {
        assert_eq!(
            "murty".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Murty {
                k: 200,
                min_weight: 1e-5
            }
        );
        assert_eq!(
            " Gibbs ".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Gibbs { samples: 1000 }
        );
        assert_eq!(
            "lbp".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Lbp {
                max_iterations: 100,
                tolerance: 1e-9
            }
        );
        assert_eq!(
            "exhaustive".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Exhaustive
        );
        assert_eq!(
            "murty:500".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Murty {
                k: 500,
                min_weight: 1e-5
            }
        );
        assert!("hungarian".parse::<AssociationMethod>().is_err());
        assert!("murty:x".parse::<AssociationMethod>().is_err());
        assert_eq!(AssociationMethod::default(), "lbp".parse().unwrap());
    }

    #[test]
    fn serde_round_trip_uses_method_tag() {
        let m = AssociationMethod::Murty {
            k: 7,
            min_weight: 0.0,
        };
        let s = serde_json::to_string(&m).unwrap();
        assert_eq!(s, r#"{"method":"murty","k":7,"min_weight":0.0}"#);
        let back: AssociationMethod = serde_json::from_str(&s).unwrap();
        assert_eq!(back, m);
        let floor: AssociationMethod = serde_json::from_str(r#"{"method":"murty","k":7}"#).unwrap();
        assert_eq!(
            floor,
            AssociationMethod::Murty {
                k: 7,
                min_weight: 1e-5
            }
        );
        let e: AssociationMethod = serde_json::from_str(r#"{"method":"exhaustive"}"#).unwrap();
        assert_eq!(e, AssociationMethod::Exhaustive);
        let l: AssociationMethod =
            serde_json::from_str(r#"{"method":"lbp","max_iterations":5,"tolerance":0.001}"#)
                .unwrap();
        assert_eq!(
            l,
            AssociationMethod::Lbp {
                max_iterations: 5,
                tolerance: 1e-3
            }
        );
    }
}
