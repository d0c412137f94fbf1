//! The ego vehicle's planar motion on the simulated street: constant speed along a route of
//! straight legs joined by smooth turns.
//!
//! A route is a list of [`LegSpec`]s, each a straight stretch followed by a turn; after the last
//! turn the vehicle drives straight on for ever. During a turn of angle θ lasting T seconds the
//! yaw rate follows a raised cosine, ω(τ) = (θ/T)·(1 − cos(2πτ/T)) for τ ∈ [0, T], so yaw rate
//! and yaw acceleration are continuous and the turn changes the heading by exactly θ. The
//! velocity always points along the heading (no side slip), which is the constant-turn vehicle
//! model with a slowly varying turn rate. Positions are integrated with composite Simpson's rule
//! (256 sub-intervals per turn), exact on the straight stretches.
//!
//! Positions are those of the reference point of the vehicle (the OXTS unit) in the world
//! frame's x (east) and y (north); height and the lidar mounting are handled by the caller.
//!
//! Not for: lidar geometry, the street's walls (see [`super::world`]) or writing OXTS packets.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// One leg of a route: drive `straight` metres, then turn by `turn_deg` degrees
/// (positive = left) over `turn_seconds`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LegSpec {
    /// Length of the straight stretch before the turn, metres.
    pub straight: f64,
    /// Heading change of the turn, degrees, positive counter-clockwise (left).
    pub turn_deg: f64,
    /// Duration of the turn, seconds.
    pub turn_seconds: f64,
}

/// The vehicle's planar state at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EgoState {
    /// Time since the start, seconds.
    pub time: f64,
    /// East position, metres.
    pub x: f64,
    /// North position, metres.
    pub y: f64,
    /// Heading, rad counter-clockwise from east, unwrapped (continuous).
    pub yaw: f64,
    /// Speed over ground, m/s.
    pub speed: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate: f64,
}

impl EgoState {
    /// Velocity (east, north), m/s.
    pub fn velocity(&self) -> (f64, f64) {
        (self.speed * self.yaw.cos(), self.speed * self.yaw.sin())
    }
}

/// A phase of the motion: straight (no turn) or one raised-cosine turn.
#[derive(Clone, Copy, Debug)]
struct Phase {
    /// Start time, seconds.
    start: f64,
    /// Duration, seconds (infinite for the last straight).
    duration: f64,
    /// Heading change over the phase (0 for straight), rad.
    turn: f64,
    /// State at the start of the phase.
    at_start: EgoState,
}

/// The whole ego trajectory, evaluated at any time ≥ 0.
#[derive(Clone, Debug)]
pub struct EgoTrajectory {
    phases: Vec<Phase>,
    speed: f64,
}

/// Simpson sub-intervals per turn phase (even).
const SIMPSON_STEPS: usize = 256;

impl EgoTrajectory {
    /// The trajectory starting at (x0, y0) with `heading` (rad), driving at `speed` along
    /// `legs`. Inputs are assumed validated (positive speed and durations, finite values).
    pub fn new(x0: f64, y0: f64, heading: f64, speed: f64, legs: &[LegSpec]) -> EgoTrajectory {
        let mut phases = Vec::with_capacity(2 * legs.len() + 1);
        let mut state = EgoState {
            time: 0.0,
            x: x0,
            y: y0,
            yaw: heading,
            speed,
            yaw_rate: 0.0,
        };
        for leg in legs {
            let straight = Phase {
                start: state.time,
                duration: leg.straight / speed,
                turn: 0.0,
                at_start: state,
            };
            state = straight.state_at(straight.duration, speed);
            phases.push(straight);
            let turn = Phase {
                start: state.time,
                duration: leg.turn_seconds,
                turn: leg.turn_deg.to_radians(),
                at_start: state,
            };
            state = turn.state_at(turn.duration, speed);
            phases.push(turn);
        }
        phases.push(Phase {
            start: state.time,
            duration: f64::INFINITY,
            turn: 0.0,
            at_start: state,
        });
        EgoTrajectory { phases, speed }
    }

    /// The state at time `t` (seconds, clamped below at 0).
    pub fn state_at(&self, t: f64) -> EgoState {
        let t = t.max(0.0);
        let phase = self
            .phases
            .iter()
            .rev()
            .find(|p| p.start <= t)
            .unwrap_or(&self.phases[0]);
        phase.state_at(t - phase.start, self.speed)
    }

    /// The straight stretches as (start point, unit direction): stretch `j` is the line the
    /// vehicle follows before turn `j` (the last one after the last turn).
    pub fn straight_lines(&self) -> Vec<([f64; 2], [f64; 2])> {
        self.phases
            .iter()
            .filter(|p| p.turn == 0.0)
            .map(|p| {
                let s = p.at_start;
                ([s.x, s.y], [s.yaw.cos(), s.yaw.sin()])
            })
            .collect()
    }
}

impl Phase {
    /// Heading and yaw rate `tau` seconds into the phase.
    fn yaw_at(&self, tau: f64) -> (f64, f64) {
        if self.turn == 0.0 {
            return (self.at_start.yaw, 0.0);
        }
        let t = self.duration;
        let tau = tau.clamp(0.0, t);
        let w = 2.0 * PI / t;
        let mean_rate = self.turn / t;
        let yaw = self.at_start.yaw + mean_rate * (tau - (w * tau).sin() / w);
        let rate = mean_rate * (1.0 - (w * tau).cos());
        (yaw, rate)
    }

    /// The state `tau` seconds into the phase.
    fn state_at(&self, tau: f64, speed: f64) -> EgoState {
        let s0 = self.at_start;
        let (x, y) = if self.turn == 0.0 {
            let d = speed * tau;
            (s0.x + d * s0.yaw.cos(), s0.y + d * s0.yaw.sin())
        } else if tau <= 0.0 {
            (s0.x, s0.y)
        } else {
            // Composite Simpson on [0, tau] for x' = v cos ψ, y' = v sin ψ.
            let tau = tau.min(self.duration);
            let h = tau / SIMPSON_STEPS as f64;
            let (mut sx, mut sy) = (0.0, 0.0);
            for i in 0..=SIMPSON_STEPS {
                let weight = if i == 0 || i == SIMPSON_STEPS {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                let (psi, _) = self.yaw_at(i as f64 * h);
                sx += weight * psi.cos();
                sy += weight * psi.sin();
            }
            (s0.x + speed * h / 3.0 * sx, s0.y + speed * h / 3.0 * sy)
        };
        let (yaw, yaw_rate) = self.yaw_at(tau);
        EgoState {
            time: self.start + tau,
            x,
            y,
            yaw,
            speed,
            yaw_rate,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn route() -> Vec<LegSpec> {
        vec![
            LegSpec {
                straight: 20.0,
                turn_deg: 90.0,
                turn_seconds: 4.0,
            },
            LegSpec {
                straight: 10.0,
                turn_deg: -45.0,
                turn_seconds: 3.0,
            },
        ]
    }

    #[test]
    fn turns_change_heading_by_the_given_angle() {
        let traj = EgoTrajectory::new(1.0, 2.0, 0.3, 10.0, &route());
        let end_first = traj.state_at(2.0 + 4.0);
        assert!((end_first.yaw - (0.3 + PI / 2.0)).abs() < 1e-12);
        assert!(end_first.yaw_rate.abs() < 1e-12);
        // Peak yaw rate at mid-turn: 2θ/T.
        let mid = traj.state_at(2.0 + 2.0);
        assert!((mid.yaw_rate - 2.0 * (PI / 2.0) / 4.0).abs() < 1e-12);
        let end = traj.state_at(100.0);
        assert!((end.yaw - (0.3 + PI / 4.0)).abs() < 1e-12);
        assert_eq!(traj.straight_lines().len(), 3);
    }

    #[test]
    fn positions_follow_the_velocity() {
        // Central differences of the positions reproduce v·(cos ψ, sin ψ) everywhere,
        // including inside the turns (independent check of the integration).
        let traj = EgoTrajectory::new(0.0, 0.0, -1.0, 10.0, &route());
        let h = 1e-3;
        for k in 0..120 {
            let t = 0.1 * k as f64 + 0.05;
            let (a, b, s) = (traj.state_at(t - h), traj.state_at(t + h), traj.state_at(t));
            let vx = (b.x - a.x) / (2.0 * h);
            let vy = (b.y - a.y) / (2.0 * h);
            let (ex, ey) = s.velocity();
            assert!((vx - ex).abs() < 1e-4 && (vy - ey).abs() < 1e-4, "t {t}");
            let rate = (b.yaw - a.yaw) / (2.0 * h);
            assert!((rate - s.yaw_rate).abs() < 1e-5, "t {t}");
        }
    }

    #[test]
    fn a_quarter_turn_ends_where_the_integral_says() {
        // Straight 0, 90° left turn over T at speed v: the displacement is
        // v·∫ (cos ψ, sin ψ) dτ; check it against a fine midpoint rule (independent).
        let legs = [LegSpec {
            straight: 0.0,
            turn_deg: 90.0,
            turn_seconds: 3.0,
        }];
        let traj = EgoTrajectory::new(0.0, 0.0, 0.0, 10.0, &legs);
        let end = traj.state_at(3.0);
        let n = 200_000;
        let (mut x, mut y) = (0.0, 0.0);
        for i in 0..n {
            let tau = (i as f64 + 0.5) * 3.0 / n as f64;
            let w = 2.0 * PI / 3.0;
            let psi = (PI / 2.0) / 3.0 * (tau - (w * tau).sin() / w);
            x += 10.0 * psi.cos() * 3.0 / n as f64;
            y += 10.0 * psi.sin() * 3.0 / n as f64;
        }
        assert!((end.x - x).abs() < 1e-6 && (end.y - y).abs() < 1e-6);
    }
}
