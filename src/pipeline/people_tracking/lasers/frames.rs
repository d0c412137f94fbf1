//! Frames of asynchronous lasers: which scans of the lasers go together ([`group_scans`]) and
//! where a laser is between two odometry readings ([`extrapolate`]).
//!
//! Not for: the tracker that steps through the frames (the parent module).

use super::*;

/// One frame of [`group_scans`]: its time (the anchor scan's) and, per laser that reported,
/// `(laser, scan index)` in laser order.
#[derive(Clone, Debug, PartialEq)]
pub struct LaserFrame {
    /// The anchor scan's time (s).
    pub time: f64,
    /// The anchor laser's scan index.
    pub anchor: usize,
    /// `(laser, scan index)` of every laser in the frame, by laser.
    pub scans: Vec<(usize, usize)>,
}

/// Groups the scan times of several lasers (`times[j]`: laser j's, not decreasing) into frames:
/// one per scan of the anchor laser (the one with the most scans, the first of equals), with
/// each other laser's scan nearest to it, taken when within half the anchor's median period
/// (a scan midway between two anchor scans goes to the later one, so that no frame takes a
/// scan made after it more than half a period; each scan goes to at most one frame, and of
/// two scans of one laser near one anchor scan the nearer). Returns the anchor laser and
/// the frames.
pub fn group_scans(times: &[Vec<f64>]) -> Result<(usize, Vec<LaserFrame>)> {
    for (j, t) in times.iter().enumerate() {
        if t.iter().any(|v| !v.is_finite()) || t.windows(2).any(|w| w[1] < w[0]) {
            return Err(Error::invalid(
                format!("scan times of laser {j}"),
                "not finite or not in order",
            ));
        }
    }
    let Some(anchor) =
        (0..times.len()).max_by(|&a, &b| times[a].len().cmp(&times[b].len()).then(b.cmp(&a)))
    else {
        return Err(Error::invalid("scan grouping", "no laser"));
    };
    let at = &times[anchor];
    let mut gaps: Vec<f64> = at.windows(2).map(|w| w[1] - w[0]).collect();
    gaps.sort_by(f64::total_cmp);
    let half = gaps.get(gaps.len() / 2).map_or(f64::INFINITY, |g| 0.5 * g);
    // per anchor scan, per other laser: (distance, scan)
    let mut chosen: Vec<BTreeMap<usize, (f64, usize)>> = vec![BTreeMap::new(); at.len()];
    for (j, tj) in times.iter().enumerate() {
        if j == anchor {
            continue;
        }
        for (k, &t) in tj.iter().enumerate() {
            let after = at.partition_point(|&a| a < t);
            let candidates = [after.checked_sub(1), (after < at.len()).then_some(after)];
            // the later one on a tie
            let best = candidates
                .into_iter()
                .flatten()
                .map(|i| ((at[i] - t).abs(), i))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
            let Some((d, i)) = best else { continue };
            if d > half + 1e-9 {
                continue;
            }
            let slot = chosen[i].entry(j).or_insert((d, k));
            if d < slot.0 {
                *slot = (d, k);
            }
        }
    }
    let frames = at
        .iter()
        .zip(chosen)
        .enumerate()
        .map(|(i, (&time, others))| {
            let mut scans: Vec<(usize, usize)> =
                others.into_iter().map(|(j, (_, k))| (j, k)).collect();
            scans.push((anchor, i));
            scans.sort_unstable();
            LaserFrame {
                time,
                anchor: i,
                scans,
            }
        })
        .collect();
    Ok((anchor, frames))
}

/// The pose `pose` (at `time`) moved on to `t` at the velocity it moved with from
/// `previous` (at its time); `pose` itself without a previous pose or time step.
pub fn extrapolate(pose: Pose2, time: f64, previous: Option<(Pose2, f64)>, t: f64) -> Pose2 {
    let Some((before, t0)) = previous else {
        return pose;
    };
    let dt = time - t0;
    if dt.is_nan() || dt <= 1e-6 || t == time {
        return pose;
    }
    let d = between(before, pose);
    let a = (t - time) / dt;
    compose(pose, Pose2::new(a * d.x, a * d.y, a * wrap_angle(d.theta)))
}
