//! What the tracking output looks like to a person: per-point track numbers for labelled LAS
//! and PLY exports of a frame, and the bird's-eye plot of a whole drive (ego path, cluster
//! trajectories coloured by track, wall segments).
//!
//! Not for: writing the files themselves (see [`crate::cloud::las_io`],
//! [`crate::cloud::ply_io`], [`crate::plot`]).

use super::detect::FrameDetections;
#[cfg(feature = "plot")]
use super::output::DriveTracks;
use super::output::TrackedFrame;
#[cfg(feature = "plot")]
use crate::cloud::label_colour;
#[cfg(feature = "plot")]
use crate::plot::{BirdsEyePlot, Dot, Polyline};

/// One track number per point of a frame's cloud of `len` points: the number of the wall or
/// cluster track matched to the detection the point belongs to, 0 for every other point
/// (ground, unmatched detections, unclustered points).
pub fn point_labels(len: usize, detections: &FrameDetections, tracked: &TrackedFrame) -> Vec<u32> {
    let mut labels = vec![0u32; len];
    let mut paint = |indices: &[u32], id: u32| {
        for &i in indices {
            if let Some(l) = labels.get_mut(i as usize) {
                *l = id;
            }
        }
    };
    for p in &tracked.planes {
        if let Some(w) = p.detection.and_then(|j| detections.walls.get(j)) {
            paint(&w.indices, p.id);
        }
    }
    for c in &tracked.clusters {
        if let Some(d) = c.detection.and_then(|j| detections.clusters.get(j)) {
            paint(&d.indices, c.id);
        }
    }
    labels
}

#[cfg(feature = "plot")]
/// The bird's-eye plot of a drive in world x–y: the ego path (black), each cluster track's
/// trajectory in its label colour with a dot at its last position, and each wall track's
/// last rectangle as a thick segment (its horizontal extent) in its label colour.
pub fn drive_plot(tracks: &DriveTracks) -> BirdsEyePlot {
    use std::collections::BTreeMap;
    let mut plot = BirdsEyePlot::default();
    let ego: Vec<[f64; 2]> = tracks
        .frames
        .iter()
        .map(|f| [f.ego_position[0], f.ego_position[1]])
        .collect();
    let mut trajectories: BTreeMap<u32, Vec<[f64; 2]>> = BTreeMap::new();
    let mut walls: BTreeMap<u32, [[f64; 3]; 4]> = BTreeMap::new();
    for f in &tracks.frames {
        for c in &f.clusters {
            trajectories
                .entry(c.id)
                .or_default()
                .push([c.position_world[0], c.position_world[1]]);
        }
        for p in &f.planes {
            if let Some(v) = p.vertices_world {
                walls.insert(p.id, v);
            }
        }
    }
    for (id, v) in walls {
        // The two corners farthest apart in x–y span the wall's footprint.
        let mut best = (0.0, 0, 0);
        for a in 0..4 {
            for b in a + 1..4 {
                let d = (v[a][0] - v[b][0]).hypot(v[a][1] - v[b][1]);
                if d > best.0 {
                    best = (d, a, b);
                }
            }
        }
        plot.lines.push(Polyline {
            points: vec![[v[best.1][0], v[best.1][1]], [v[best.2][0], v[best.2][1]]],
            colour: label_colour(id),
            width: 4,
        });
    }
    for (id, pts) in trajectories {
        let last = *pts.last().expect("a trajectory has a point");
        plot.lines.push(Polyline {
            points: pts,
            colour: label_colour(id),
            width: 2,
        });
        plot.dots.push(Dot {
            at: last,
            colour: label_colour(id),
            radius: 3,
        });
    }
    if let Some(&start) = ego.first() {
        plot.dots.push(Dot {
            at: start,
            colour: [0, 0, 0],
            radius: 4,
        });
    }
    plot.lines.push(Polyline {
        points: ego,
        colour: [0, 0, 0],
        width: 2,
    });
    plot
}
