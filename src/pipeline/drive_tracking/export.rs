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
/// The colour of walls in the plots.
const WALL: [u8; 3] = [44, 160, 44];

#[cfg(feature = "plot")]
/// A wall rectangle's footprint in x–y: its two corners farthest apart.
fn footprint(v: &[[f64; 3]; 4]) -> [[f64; 2]; 2] {
    let mut best = (0.0, 0, 0);
    for a in 0..4 {
        for b in a + 1..4 {
            let d = (v[a][0] - v[b][0]).hypot(v[a][1] - v[b][1]);
            if d > best.0 {
                best = (d, a, b);
            }
        }
    }
    [[v[best.1][0], v[best.1][1]], [v[best.2][0], v[best.2][1]]]
}

#[cfg(feature = "plot")]
/// The colour of a cluster class in the drive plot (`None` for a name it does not know).
fn class_colour(class: &str) -> Option<[u8; 3]> {
    Some(match class {
        "Car" => [31, 119, 180],
        "Van" => [23, 160, 190],
        "Truck" => [148, 103, 189],
        "Pedestrian" => [214, 39, 40],
        "Cyclist" => [255, 127, 14],
        "Other" => [150, 150, 150],
        _ => return None,
    })
}

#[cfg(feature = "plot")]
/// The bird's-eye plot of a drive in world x–y, titled with the drive, its frame range and
/// the ego source: the ego path (black, a dot where it starts), each wall track's last
/// rectangle as a thick green segment (its horizontal extent), and each cluster track's
/// trajectory with a dot at its last position, coloured by its last class when it has one
/// (else by label); a legend names them.
pub fn drive_plot(tracks: &DriveTracks) -> BirdsEyePlot {
    use crate::plot::{LegendEntry, LegendMark};
    use std::collections::{BTreeMap, BTreeSet};
    let mut plot = BirdsEyePlot::default();
    let ego: Vec<[f64; 2]> = tracks
        .frames
        .iter()
        .map(|f| [f.ego_position[0], f.ego_position[1]])
        .collect();
    let mut trajectories: BTreeMap<u32, (Vec<[f64; 2]>, Option<String>)> = BTreeMap::new();
    let mut walls: BTreeMap<u32, [[f64; 3]; 4]> = BTreeMap::new();
    for f in &tracks.frames {
        for c in &f.clusters {
            let t = trajectories.entry(c.id).or_default();
            t.0.push([c.position_world[0], c.position_world[1]]);
            if c.class.is_some() {
                t.1.clone_from(&c.class);
            }
        }
        for p in &f.planes {
            if let Some(v) = p.vertices_world {
                walls.insert(p.id, v);
            }
        }
    }
    let wall_count = walls.len();
    for v in walls.into_values() {
        plot.lines.push(Polyline {
            points: footprint(&v).to_vec(),
            colour: WALL,
            width: 4,
        });
    }
    let cluster_count = trajectories.len();
    let mut classes: BTreeSet<String> = BTreeSet::new();
    let mut unclassed = false;
    for (id, (pts, class)) in trajectories {
        let colour = match class.as_deref().and_then(class_colour) {
            Some(c) => {
                classes.insert(class.unwrap_or_default());
                c
            }
            None => {
                unclassed = true;
                label_colour(id)
            }
        };
        let last = *pts.last().expect("a trajectory has a point");
        plot.lines.push(Polyline {
            points: pts,
            colour,
            width: 2,
        });
        plot.dots.push(Dot {
            at: last,
            colour,
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

    let (first, last) = (
        tracks.frames.first().map_or(0, |f| f.frame),
        tracks.frames.last().map_or(0, |f| f.frame),
    );
    plot.title = vec![
        format!("{}, frames {first}-{last}", tracks.drive),
        format!(
            "{wall_count} wall tracks, {cluster_count} cluster tracks; ego motion: {}",
            tracks.ego
        ),
    ];
    let entry = |label: &str, colour: [u8; 3], mark: LegendMark| LegendEntry {
        label: label.to_string(),
        colour,
        mark,
    };
    plot.legend.push(entry("walls", WALL, LegendMark::Line(4)));
    for class in &classes {
        let colour = class_colour(class).expect("classes kept have a colour");
        plot.legend.push(entry(class, colour, LegendMark::Line(2)));
    }
    if unclassed {
        plot.legend.push(entry(
            "clusters (by label)",
            [120, 120, 200],
            LegendMark::Line(2),
        ));
    }
    plot.legend
        .push(entry("last position", [90, 90, 90], LegendMark::Dot(3)));
    plot.legend
        .push(entry("ego path", [0, 0, 0], LegendMark::Line(2)));
    plot.legend
        .push(entry("ego start", [0, 0, 0], LegendMark::Dot(4)));
    plot
}

#[cfg(feature = "plot")]
/// The bird's-eye plot of one frame in its sensor frame (x forward, y left), out to
/// `max_range` metres: the cloud's points coloured by what they became (ground, wall inliers,
/// points of a tracked cluster in its class colour, of an untracked cluster, the rest), each
/// tracked wall's rectangle as a thick green segment, each tracked cluster's oriented box,
/// and the sensor at the origin; `name` heads the title.
pub fn frame_plot(view: &super::FrameView<'_>, name: &str, max_range: f64) -> BirdsEyePlot {
    use crate::plot::{LegendEntry, LegendMark, PointLayer};
    const GROUND: [u8; 3] = [205, 205, 205];
    const REST: [u8; 3] = [150, 150, 150];
    const UNTRACKED: [u8; 3] = [90, 90, 90];
    const WALL_POINTS: [u8; 3] = [130, 205, 130];
    let (cloud, det, tracked) = (view.cloud, view.detections, view.tracked);
    // One colour per point: what it became.
    let mut colour = vec![REST; cloud.len()];
    let mut paint = |indices: &[u32], c: [u8; 3]| {
        for &i in indices {
            if let Some(slot) = colour.get_mut(i as usize) {
                *slot = c;
            }
        }
    };
    paint(&det.ground, GROUND);
    for w in &det.walls {
        paint(&w.indices, WALL_POINTS);
    }
    for c in &det.clusters {
        paint(&c.indices, UNTRACKED);
    }
    let cluster_colour = |c: &super::output::TrackedCluster| {
        c.class
            .as_deref()
            .and_then(class_colour)
            .unwrap_or_else(|| label_colour(c.id))
    };
    for c in &tracked.clusters {
        if let Some(d) = c.detection.and_then(|j| det.clusters.get(j)) {
            paint(&d.indices, cluster_colour(c));
        }
    }
    // Layers by colour, the ground first so that everything else is drawn over it.
    let mut layers: Vec<PointLayer> = Vec::new();
    let (xs, ys) = (cloud.xs(), cloud.ys());
    let mut shown = 0usize;
    for i in 0..cloud.len() {
        let (x, y) = (xs[i] as f64, ys[i] as f64);
        let range = x.hypot(y);
        if range.is_nan() || range > max_range {
            continue;
        }
        shown += 1;
        match layers.iter_mut().find(|l| l.colour == colour[i]) {
            Some(l) => l.points.push([x, y]),
            None => layers.push(PointLayer {
                points: vec![[x, y]],
                colour: colour[i],
            }),
        }
    }
    layers.sort_by_key(|l| l.colour != GROUND);
    let mut plot = BirdsEyePlot {
        points: layers,
        ..Default::default()
    };
    for p in &tracked.planes {
        if let Some(v) = &p.vertices {
            plot.lines.push(Polyline {
                points: footprint(v).to_vec(),
                colour: WALL,
                width: 4,
            });
        }
    }
    let mut classes = std::collections::BTreeSet::new();
    for c in &tracked.clusters {
        let Some(b) = &c.box_sensor else { continue };
        let mut corners = b.to_box3().bev_corners().to_vec();
        corners.push(corners[0]);
        plot.lines.push(Polyline {
            points: corners,
            colour: cluster_colour(c),
            width: 2,
        });
        if let Some(class) = c.class.as_deref().filter(|k| class_colour(k).is_some()) {
            classes.insert(class.to_string());
        }
    }
    plot.dots.push(Dot {
        at: [0.0, 0.0],
        colour: [0, 0, 0],
        radius: 4,
    });
    plot.title = vec![
        format!("{name}, frame {} (sensor frame)", tracked.frame),
        format!(
            "{shown} points within {max_range:.0} m; {} walls and {} clusters tracked",
            tracked.planes.len(),
            tracked.clusters.len()
        ),
    ];
    let entry = |label: &str, colour: [u8; 3], mark: LegendMark| LegendEntry {
        label: label.to_string(),
        colour,
        mark,
    };
    plot.legend = vec![
        entry("ground", GROUND, LegendMark::Dot(2)),
        entry("wall points, tracked walls", WALL, LegendMark::Line(4)),
    ];
    for class in &classes {
        let colour = class_colour(class).expect("classes kept have a colour");
        plot.legend.push(entry(class, colour, LegendMark::Line(2)));
    }
    plot.legend.extend([
        entry("untracked clusters", UNTRACKED, LegendMark::Dot(2)),
        entry("other points", REST, LegendMark::Dot(2)),
        entry("sensor", [0, 0, 0], LegendMark::Dot(4)),
    ]);
    plot
}
