//! Groups the returns of one scan into person candidates and measures each candidate's centre
//! as [range, bearing] from the sensor.
//!
//! A person (a disc of radius ρ ≈ 0.2 m) seen through beam noise does not give one clean
//! segment: range noise σ_r breaks the outline at breakpoints, and bearing noise σ_b (the
//! beam leaves at its nominal bearing plus an error, the scan reports the nominal one) spreads
//! a far person's few hits over a lateral band of ±2 σ_b·r, interleaved with "no return"
//! beams. The grouping therefore works in two stages:
//!
//! 1. Breakpoint segments (seed 000, eq. 15) wider than `max_width` are structure (walls,
//!    furniture) and are set aside.
//! 2. The remaining returns are linked by single linkage in polar coordinates: two returns are
//!    one candidate when their ranges differ by at most 2ρ + 3√2·σ_r and their lateral
//!    distance r̄·|Δθ| is at most `merge_gap` + 2·σ_b·r̄ (r̄ their mean range).
//!
//! A candidate is kept when it has at least `min_points` returns, a lateral extent of at most
//! `max_width` + 4·σ_b·r̄ and a radial extent of at most 2ρ + 6·σ_r. A candidate too large
//! (people walking close together) is linked again with the bearing allowance lowered from
//! 2·σ_b·r̄ to 1·σ_b·r̄ and then to none, and the range allowance from 3√2·σ_r to 2·σ_r and
//! then σ_r (with the width allowance lowered alike); what is still too large but at most
//! three times `max_width` wide is kept as one candidate. Its
//! measurement is the mean range plus πρ/4 and the mean bearing: the returns lie on the near
//! half of the disc, and beams spread evenly across a disc of radius ρ end on average
//! ρ(1 − π/4) behind its nearest point (the mean of √(ρ² − u²) over u uniform in [−ρ, ρ] is
//! πρ/4), so the centre is πρ/4 beyond the mean return.
//!
//! Not for: telling people from other small objects (legs of furniture, bins), background
//! models, or tracking.

use super::{segment_scan, BreakpointConfig, Scan};
use crate::error::Result;

/// Parameters of the grouping (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PersonGrouping {
    /// Breakpoint segmentation (stage 1).
    pub breakpoint: BreakpointConfig,
    /// Person radius ρ (m).
    pub body_radius: f64,
    /// Segments wider than this (m) are structure; also the base of the candidate width test.
    pub max_width: f64,
    /// Candidates with fewer returns are dropped.
    pub min_points: usize,
    /// Base lateral linking distance (m).
    pub merge_gap: f64,
    /// Range noise σ_r of one beam (m).
    pub sigma_range: f64,
    /// Bearing noise σ_b of one beam (rad).
    pub sigma_bearing: f64,
}

/// One person candidate.
#[derive(Clone, Debug, PartialEq)]
pub struct PersonGroup {
    /// The returns, [x, y] in the sensor frame, in beam order.
    pub points: Vec<[f64; 2]>,
    /// Estimated centre: mean range + πρ/4 (m).
    pub range: f64,
    /// Estimated centre: mean bearing (rad).
    pub bearing: f64,
}

fn root(owner: &mut [usize], mut i: usize) -> usize {
    while owner[i] != i {
        owner[i] = owner[owner[i]];
        i = owner[i];
    }
    i
}

/// The person candidates of `scan`, in order of their first beam.
pub fn person_groups(scan: &Scan, g: &PersonGrouping) -> Result<Vec<PersonGroup>> {
    // (range, bearing) of every return on a narrow segment, in beam order.
    let mut pts: Vec<(f64, f64)> = Vec::with_capacity(scan.len());
    for s in segment_scan(scan, &g.breakpoint)? {
        if s.width > g.max_width {
            continue;
        }
        for i in s.beams.clone() {
            if let Some(r) = scan.range(i) {
                pts.push((r, scan.bearing(i)));
            }
        }
    }
    let mut out = Vec::new();
    let all: Vec<usize> = (0..pts.len()).collect();
    split(&pts, &all, g, 0, &mut out);
    out.sort_by_key(|a| a.0);
    Ok(out.into_iter().map(|(_, p)| p).collect())
}

/// Allowances per linking level: (bearing noise multiple, range noise multiple).
const LEVELS: [(f64, f64); 3] = [
    (2.0, 3.0 * std::f64::consts::SQRT_2),
    (1.0, 2.0),
    (0.0, 1.0),
];

/// Single linkage of the returns `idx` (increasing) at allowance level `level`; a candidate
/// that fails the size tests is linked again at the next, tighter level (people walking close
/// together). At the last level a candidate up to three times `max_width` wide is kept as it
/// is: a crowd is then one measurement rather than none.
fn split(
    pts: &[(f64, f64)],
    idx: &[usize],
    g: &PersonGrouping,
    level: usize,
    out: &mut Vec<(usize, PersonGroup)>,
) {
    let (k, kr) = LEVELS[level];
    let range_gate = 2.0 * g.body_radius + kr * g.sigma_range;
    let n = idx.len();
    let mut owner: Vec<usize> = (0..n).collect();
    for a in 0..n {
        let (ra, ta) = pts[idx[a]];
        // Linking needs |Δr| ≤ range_gate, so the pair's mean range is at least
        // ra − range_gate / 2, and r̄·|Δθ| ≤ merge_gap + k·σ_b·r̄ bounds |Δθ|; beams come in
        // bearing order, so the first return beyond the bound ends the search.
        let window = g.merge_gap / (ra - 0.5 * range_gate).max(1e-3) + k * g.sigma_bearing + 1e-12;
        for b in a + 1..n {
            let (rb, tb) = pts[idx[b]];
            let dtheta = (tb - ta).abs();
            if dtheta > window {
                break;
            }
            let mean = 0.5 * (ra + rb);
            if (ra - rb).abs() <= range_gate
                && mean * dtheta <= g.merge_gap + k * g.sigma_bearing * mean
            {
                let (x, y) = (root(&mut owner, a), root(&mut owner, b));
                owner[x.max(y)] = x.min(y);
            }
        }
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, &point) in idx.iter().enumerate() {
        let r = root(&mut owner, i);
        members[r].push(point);
    }
    for m in members.into_iter().filter(|m| m.len() >= g.min_points) {
        let count = m.len() as f64;
        let r_mean = m.iter().map(|&i| pts[i].0).sum::<f64>() / count;
        let t_mean = m.iter().map(|&i| pts[i].1).sum::<f64>() / count;
        let (mut rmin, mut rmax, mut tmin, mut tmax) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &i in &m {
            rmin = rmin.min(pts[i].0);
            rmax = rmax.max(pts[i].0);
            tmin = tmin.min(pts[i].1);
            tmax = tmax.max(pts[i].1);
        }
        let lateral = r_mean * (tmax - tmin);
        let too_large = lateral > g.max_width + 2.0 * k * g.sigma_bearing * r_mean
            || rmax - rmin > 2.0 * g.body_radius + 6.0 * g.sigma_range;
        if too_large && level + 1 < LEVELS.len() {
            split(pts, &m, g, level + 1, out);
            continue;
        }
        if too_large && lateral > 3.0 * g.max_width {
            continue;
        }
        out.push((
            m[0],
            PersonGroup {
                points: m
                    .iter()
                    .map(|&i| {
                        let (r, t) = pts[i];
                        [r * t.cos(), r * t.sin()]
                    })
                    .collect(),
                range: r_mean + std::f64::consts::FRAC_PI_4 * g.body_radius,
                bearing: t_mean,
            },
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grouping(sigma_range: f64, sigma_bearing: f64) -> PersonGrouping {
        PersonGrouping {
            breakpoint: BreakpointConfig {
                sigma_r: sigma_range.max(0.03),
                ..BreakpointConfig::default()
            },
            body_radius: 0.2,
            max_width: 0.8,
            min_points: 2,
            merge_gap: 0.6,
            sigma_range,
            sigma_bearing,
        }
    }

    /// 361 beams over 180°, no return except the listed (beam, range) pairs.
    fn scan(hits: &[(usize, f32)]) -> Scan {
        let mut ranges = vec![30.0f32; 361];
        for &(i, r) in hits {
            ranges[i] = r;
        }
        Scan::new(
            0.0,
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI / 360.0,
            ranges,
            0.0,
            30.0,
        )
        .unwrap()
    }

    #[test]
    fn the_centre_of_an_evenly_hit_disc_is_found() {
        // A disc of radius 0.2 m centred 6 m ahead, hit by every beam (0.5° apart) that
        // crosses it, ranges exact: the measured centre is within 1.5 cm of 6 m (adding ρ
        // instead of πρ/4 would be 3.5 cm off).
        let (rho, d) = (0.2f64, 6.0f64);
        let hits: Vec<(usize, f32)> = (0..361usize)
            .filter_map(|i| {
                let b = -std::f64::consts::FRAC_PI_2 + i as f64 * std::f64::consts::PI / 360.0;
                let (s, c) = b.sin_cos();
                // ray t·(c, s) against the circle |p − (d, 0)| = ρ
                let disc = (d * c).powi(2) - (d * d - rho * rho);
                (disc >= 0.0).then(|| (i, (d * c - disc.sqrt()) as f32))
            })
            .collect();
        assert!(hits.len() >= 3, "{hits:?}");
        let g = person_groups(&scan(&hits), &grouping(0.01, 0.0)).unwrap();
        assert_eq!(g.len(), 1, "{g:?}");
        assert!((g[0].range - d).abs() < 0.015, "{:?}", g[0]);
    }

    #[test]
    fn scattered_far_hits_form_one_person() {
        // a person at 25 m, bearing 0 (beam 180): four hits spread by bearing noise over
        // beams 176..=184 with gaps of "no return" between them
        let s = scan(&[(176, 24.9), (179, 25.1), (181, 24.8), (184, 25.0)]);
        let g = person_groups(&s, &grouping(0.2, 2f64.to_radians())).unwrap();
        assert_eq!(g.len(), 1, "{g:?}");
        // mean range 24.95 + 0.2·π/4; mean bearing of beams 176, 179, 181, 184 = beam 180 → 0
        assert!((g[0].range - 25.107_08).abs() < 1e-5, "{:?}", g[0]);
        assert!(g[0].bearing.abs() < 1e-9);
        // without bearing noise the same hits are 0.4–1.3 m apart laterally: the outer ones
        // no longer link to the middle pair across 0.87 m (> 0.6 m)
        let g = person_groups(&s, &grouping(0.02, 0.0)).unwrap();
        assert!(g.len() < 2 || g.iter().all(|p| p.points.len() < 4), "{g:?}");
    }

    #[test]
    fn people_at_different_ranges_and_walls_stay_apart() {
        // person A at 5 m (beams 100..=104), person B right behind at 8 m (beams 105..=107),
        // a wall at 3 m over beams 250..=330 (much wider than a person)
        let mut hits: Vec<(usize, f32)> = (100..=104).map(|i| (i, 5.0)).collect();
        hits.extend((105..=107).map(|i| (i, 8.0)));
        hits.extend((250..=330).map(|i| (i, 3.0)));
        let g = person_groups(&scan(&hits), &grouping(0.05, 0.005)).unwrap();
        assert_eq!(g.len(), 2, "{g:?}");
        assert_eq!(g[0].points.len(), 5);
        let behind = 0.2 * std::f64::consts::FRAC_PI_4;
        assert!((g[0].range - 5.0 - behind).abs() < 1e-6);
        assert!((g[1].range - 8.0 - behind).abs() < 1e-6);
        // a single isolated return is not a person
        let g = person_groups(&scan(&[(50, 4.0)]), &grouping(0.05, 0.005)).unwrap();
        assert!(g.is_empty());
    }
}
