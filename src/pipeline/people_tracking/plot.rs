//! Bird's-eye plot of a people run on a laser recording: the scan points faint grey, every
//! track that lasted long enough as a line in its label's colour — moving tracks bold with a
//! dot where they start, static ones thin and dark with a hollow square at their mean — the
//! sensor's path, a metre grid with tick labels, a title with the counts and a legend. Points
//! and tracks are drawn in the frame the tracker worked in (the scan's odometry pose, else
//! the sensor frame). A track's line is cut where it went unseen for a while. SVG or PNG by
//! extension, written atomically.
//!
//! Not for: running the tracker (see [`super::run`]) or plots of other
//! pipelines (see [`crate::plot::BirdsEyePlot`]).

use super::PeopleRun;
use crate::error::{Error, Result};
use crate::filter::Label;
use crate::laser2d::Scan;
use crate::plot::text::{draw_text, text_width, HEIGHT};
use crate::plot::{grid_step, grid_ticks};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// What to show.
#[derive(Clone, Debug, PartialEq)]
pub struct PeoplePlotOptions {
    /// Tracks visible in fewer scans are left out.
    pub min_scans: usize,
    /// A person counts as seen in a scan when its visibility is at least this.
    pub min_visibility: f64,
    /// A track is drawn as moving when the tracker classed it dynamic in at least this share
    /// of the scans in which it was seen.
    pub moving_fraction: f64,
    /// Scan points are drawn from at most this many scans, evenly spread over the recording.
    pub point_scans: usize,
    /// First title line (the recording); a second line with the counts is added.
    pub title: String,
    /// Image width in pixels; the height follows the aspect of the scene.
    pub width: u32,
}

impl Default for PeoplePlotOptions {
    fn default() -> Self {
        PeoplePlotOptions {
            min_scans: 8,
            min_visibility: 0.5,
            moving_fraction: 0.5,
            point_scans: 200,
            title: String::new(),
            width: 800,
        }
    }
}

/// What a plot showed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PeoplePlotCounts {
    /// Tracks drawn as moving.
    pub moving: usize,
    /// Tracks drawn as static.
    pub stationary: usize,
    /// Scan points drawn.
    pub points: usize,
}

struct TrackPath {
    label: Label,
    moving: bool,
    /// Visible positions, cut where the track went unseen for [`GAP_SCANS`] scans or more:
    /// a track that coasts unseen and is picked up again elsewhere is drawn as two pieces,
    /// not as a long straight line.
    pieces: Vec<Vec<(f64, f64)>>,
    last_seen: usize,
}

/// Scans a track may go unseen before its drawn path is cut.
const GAP_SCANS: usize = 5;

impl TrackPath {
    fn points(&self) -> impl Iterator<Item = &(f64, f64)> {
        self.pieces.iter().flatten()
    }
}

/// The pose a scan was tracked with: the one the run recorded (odometry, or the moving front
/// end's ICP-corrected pose), else the scan's odometry, else the logged sensor pose, else none.
fn frame_of(s: &Scan, used: Option<[f64; 3]>) -> (f64, f64, f64) {
    used.map(|p| (p[0], p[1], p[2])).unwrap_or_else(|| {
        s.odometry
            .or(s.laser_pose)
            .map_or((0.0, 0.0, 0.0), |p| (p.x, p.y, p.theta))
    })
}

/// Draws `run` over `scans` (the scans it was computed from, in the same order) to `path`.
pub fn write_people_plot(
    path: &Path,
    scans: &[Scan],
    run: &PeopleRun,
    options: &PeoplePlotOptions,
) -> Result<PeoplePlotCounts> {
    let what = || format!("plot file {}", path.display());
    if scans.is_empty() || run.scans.len() != scans.len() {
        return Err(Error::invalid(
            what(),
            format!(
                "{} scans but {} tracked scans (must be the same, at least one)",
                scans.len(),
                run.scans.len()
            ),
        ));
    }
    let every = scans.len().div_ceil(options.point_scans.max(1));
    let points: Vec<(f64, f64)> = scans
        .iter()
        .zip(&run.scans)
        .step_by(every)
        .flat_map(|(s, r)| {
            let (x0, y0, th) = frame_of(s, r.pose);
            let (sn, cs) = th.sin_cos();
            s.points()
                .map(move |(_, [x, y])| (x0 + cs * x - sn * y, y0 + sn * x + cs * y))
        })
        .collect();
    let sensor: Vec<(f64, f64)> = scans
        .iter()
        .zip(&run.scans)
        .map(|(s, r)| {
            let (x, y, _) = frame_of(s, r.pose);
            (x, y)
        })
        .collect();
    let mut tracks: Vec<TrackPath> = run
        .tracks_with(options.min_scans)
        .map(|t| TrackPath {
            label: t.label,
            moving: t.dynamic_fraction >= options.moving_fraction,
            pieces: Vec::new(),
            last_seen: 0,
        })
        .collect();
    for (k, s) in run.scans.iter().enumerate() {
        for p in s
            .people
            .iter()
            .filter(|p| p.visibility >= options.min_visibility)
        {
            if let Ok(i) = tracks.binary_search_by(|t| t.label.cmp(&p.label)) {
                let t = &mut tracks[i];
                if t.pieces.is_empty() || k >= t.last_seen + GAP_SCANS {
                    t.pieces.push(Vec::new());
                }
                t.last_seen = k;
                let piece = t.pieces.last_mut().expect("pushed above");
                piece.push((p.position[0], p.position[1]));
            }
        }
    }
    let counts = PeoplePlotCounts {
        moving: tracks.iter().filter(|t| t.moving).count(),
        stationary: tracks.iter().filter(|t| !t.moving).count(),
        points: points.len(),
    };
    let span = scans[scans.len() - 1].time - scans[0].time;
    let subtitle = format!(
        "{} scans over {:.0} s; {} tracks seen in ≥ {} scans: {} moving, {} static",
        scans.len(),
        span,
        tracks.len(),
        options.min_scans,
        counts.moving,
        counts.stationary
    );
    let legend = format!("scan points of every {every}. scan");
    let scene = Scene {
        title: &options.title,
        subtitle: &subtitle,
        legend: &legend,
        points: &points,
        sensor: &sensor,
        tracks: &tracks,
    };
    let (lo, hi) = scene.bounds();
    let width = options.width.max(300);
    let inner = f64::from(width - LEFT - RIGHT);
    let height =
        (inner * (hi.1 - lo.1) / (hi.0 - lo.0)).clamp(200.0, 3.0 * inner) as u32 + TOP + BOTTOM;
    crate::plot::write_image(path, (width, height), &Framed { scene, lo, hi })?;
    Ok(counts)
}

const LEFT: u32 = 56;
const RIGHT: u32 = 16;
const TOP: u32 = 56;
const BOTTOM: u32 = 92;
const INK: RGBColor = RGBColor(20, 20, 20);
const POINT: RGBColor = RGBColor(175, 175, 175);
const GRID: RGBColor = RGBColor(232, 232, 232);
const STATIC: RGBColor = RGBColor(60, 60, 60);

/// A scene with the bounds it is drawn in.
struct Framed<'a> {
    scene: Scene<'a>,
    lo: (f64, f64),
    hi: (f64, f64),
}

impl crate::plot::Draw for Framed<'_> {
    fn draw_on<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        self.scene.draw(&root, (self.lo, self.hi))
    }
}

struct Scene<'a> {
    title: &'a str,
    subtitle: &'a str,
    legend: &'a str,
    points: &'a [(f64, f64)],
    sensor: &'a [(f64, f64)],
    tracks: &'a [TrackPath],
}

/// A colour per label, spread over the palette so neighbouring labels differ.
fn label_colour(label: Label) -> RGBColor {
    let k = (label.birth_step as usize)
        .wrapping_mul(31)
        .wrapping_add(label.index as usize * 7);
    let c = Palette99::pick(k).to_rgba();
    RGBColor(c.0, c.1, c.2)
}

impl Scene<'_> {
    /// x and y ranges holding every track, the sensor and all but the farthest 0.5 % of the
    /// scan points on each side (lone far returns would squash the scene), with a margin.
    fn bounds(&self) -> ((f64, f64), (f64, f64)) {
        let quantiles = |mut v: Vec<f64>| -> Option<(f64, f64)> {
            if v.is_empty() {
                return None;
            }
            v.sort_by(f64::total_cmp);
            let k = v.len() / 200;
            Some((v[k], v[v.len() - 1 - k]))
        };
        let xs = quantiles(self.points.iter().map(|p| p.0).collect());
        let ys = quantiles(self.points.iter().map(|p| p.1).collect());
        let mut lo = (f64::INFINITY, f64::INFINITY);
        let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        if let (Some(x), Some(y)) = (xs, ys) {
            lo = (x.0, y.0);
            hi = (x.1, y.1);
        }
        let others = self
            .tracks
            .iter()
            .flat_map(|t| t.points())
            .chain(self.sensor.iter());
        for &(x, y) in others.filter(|p| p.0.is_finite() && p.1.is_finite()) {
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        let m = 0.03 * (hi.0 - lo.0).max(hi.1 - lo.1) + 0.5;
        ((lo.0 - m, lo.1 - m), (hi.0 + m, hi.1 + m))
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        (lo, hi): ((f64, f64), (f64, f64)),
    ) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        let (w, h) = root.dim_in_pixel();
        let plot_area = root.margin(TOP, BOTTOM, LEFT, RIGHT);
        // Equal scale: widen the shorter range to the pixel aspect.
        let (pw, ph) = plot_area.dim_in_pixel();
        let per_px = ((hi.0 - lo.0) / f64::from(pw)).max((hi.1 - lo.1) / f64::from(ph));
        let c = (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1));
        let (hx, hy) = (0.5 * per_px * f64::from(pw), 0.5 * per_px * f64::from(ph));
        let (x0, x1, y0, y1) = (c.0 - hx, c.0 + hx, c.1 - hy, c.1 + hy);
        let mut chart = ChartBuilder::on(&plot_area)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;

        // Grid and tick labels in metres.
        let step = grid_step((x1 - x0).max(y1 - y0), 12.0);
        let ticks = |a: f64, b: f64| grid_ticks(a, b, step);
        let fmt = |v: f64| {
            if step >= 1.0 {
                format!("{:.0}", v + 0.0)
            } else {
                format!("{:.1}", v + 0.0)
            }
        };
        for g in ticks(x0, x1) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(g, y0), (g, y1)],
                    GRID.stroke_width(1),
                )))
                .map_err(err)?;
            let (px, _) = chart.backend_coord(&(g, y0));
            let t = fmt(g);
            draw_text(
                root,
                &t,
                (px - text_width(&t, 1) / 2, (h - BOTTOM) as i32 + 5),
                1,
                INK,
            )
            .map_err(err)?;
        }
        for g in ticks(y0, y1) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x0, g), (x1, g)],
                    GRID.stroke_width(1),
                )))
                .map_err(err)?;
            let (_, py) = chart.backend_coord(&(x0, g));
            let t = fmt(g);
            draw_text(
                root,
                &t,
                (LEFT as i32 - 6 - text_width(&t, 1), py - HEIGHT / 2),
                1,
                INK,
            )
            .map_err(err)?;
        }
        let axis_x = "x (m)";
        draw_text(
            root,
            axis_x,
            (
                LEFT as i32 + (w - LEFT - RIGHT) as i32 / 2 - text_width(axis_x, 1) / 2,
                (h - BOTTOM) as i32 + 18,
            ),
            1,
            INK,
        )
        .map_err(err)?;
        draw_text(root, "y (m)", (4, TOP as i32 - 12), 1, INK).map_err(err)?;
        plot_area
            .draw(&Rectangle::new(
                [(0, 0), (pw as i32 - 1, ph as i32 - 1)],
                RGBColor(160, 160, 160).stroke_width(1),
            ))
            .map_err(err)?;

        // Scan points, the sensor, static tracks, moving tracks (drawn last, on top).
        chart
            .draw_series(self.points.iter().map(|&p| Pixel::new(p, POINT)))
            .map_err(err)?;
        if self.sensor.windows(2).any(|w| w[0] != w[1]) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    self.sensor.to_vec(),
                    INK.stroke_width(1),
                )))
                .map_err(err)?;
        }
        if let Some(&s) = self.sensor.first() {
            chart
                .draw_series(std::iter::once(TriangleMarker::new(s, 7, INK.filled())))
                .map_err(err)?;
        }
        for t in self.tracks.iter().filter(|t| !t.moving) {
            for piece in &t.pieces {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        piece.clone(),
                        STATIC.stroke_width(1),
                    )))
                    .map_err(err)?;
            }
            let n = t.points().count() as f64;
            let mean = t
                .points()
                .fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
            let (px, py) = chart.backend_coord(&mean);
            root.draw(&Rectangle::new(
                [(px - 3, py - 3), (px + 3, py + 3)],
                STATIC.stroke_width(1),
            ))
            .map_err(err)?;
        }
        for t in self.tracks.iter().filter(|t| t.moving) {
            let colour = label_colour(t.label);
            for piece in &t.pieces {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        piece.clone(),
                        colour.stroke_width(2),
                    )))
                    .map_err(err)?;
            }
            if let Some(&start) = t.points().next() {
                chart
                    .draw_series(std::iter::once(Circle::new(start, 3, colour.filled())))
                    .map_err(err)?;
            }
        }

        // Title and legend.
        draw_text(root, self.title, (LEFT as i32, 8), 2, INK).map_err(err)?;
        draw_text(root, self.subtitle, (LEFT as i32, 32), 1, INK).map_err(err)?;
        let y = (h - BOTTOM) as i32 + 38;
        let x = LEFT as i32;
        let line = |from: (i32, i32), to: (i32, i32), c: RGBColor, width: u32| {
            root.draw(&PathElement::new(vec![from, to], c.stroke_width(width)))
        };
        for (k, c) in [
            (0, label_colour(Label::new(3, 0))),
            (1, label_colour(Label::new(9, 1))),
        ] {
            line((x, y + 4 + 4 * k), (x + 28, y + 4 + 4 * k), c, 2).map_err(err)?;
        }
        root.draw(&Circle::new(
            (x, y + 4),
            3,
            label_colour(Label::new(3, 0)).filled(),
        ))
        .map_err(err)?;
        draw_text(
            root,
            "moving track: colour = label, dot = first seen",
            (x + 36, y + 2),
            1,
            INK,
        )
        .map_err(err)?;
        line((x, y + 26), (x + 28, y + 26), STATIC, 1).map_err(err)?;
        root.draw(&Rectangle::new(
            [(x + 11, y + 23), (x + 17, y + 29)],
            STATIC.stroke_width(1),
        ))
        .map_err(err)?;
        draw_text(
            root,
            "static track, square = its mean",
            (x + 36, y + 23),
            1,
            INK,
        )
        .map_err(err)?;
        let x2 = x + (w as i32 - LEFT as i32) / 2 + 20;
        for k in 0..6 {
            root.draw_pixel((x2 + 4 * k, y + 4), &POINT).map_err(err)?;
            root.draw_pixel((x2 + 2 + 4 * k, y + 6), &POINT)
                .map_err(err)?;
        }
        draw_text(root, self.legend, (x2 + 36, y + 2), 1, INK).map_err(err)?;
        root.draw(&TriangleMarker::new((x2 + 12, y + 26), 7, INK.filled()))
            .map_err(err)?;
        let sensor = if self.sensor.windows(2).any(|w| w[0] != w[1]) {
            "sensor at the first scan, line = its odometry path"
        } else {
            "sensor (stationary)"
        };
        draw_text(root, sensor, (x2 + 36, y + 23), 1, INK).map_err(err)?;
        root.present().map_err(err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::geometry::Pose2;
    use crate::pipeline::people_tracking::{PersonEstimate, PersonTrack, ScanPeople};

    /// Ten scans of a wall 5 m ahead; a walker (label (0, 0)) crossing at 1 m/s, unseen in
    /// scans 3–8; a standing person (label (1, 0)) seen throughout.
    fn story() -> (Vec<Scan>, PeopleRun) {
        let mut scans = Vec::new();
        let mut run = PeopleRun::default();
        let person = |label: Label, x: f64, moving: bool, visibility: f64| PersonEstimate {
            label,
            existence: 0.9,
            position: [x, 1.0],
            velocity: [if moving { 1.0 } else { 0.0 }, 0.0],
            p_moving: if moving { 0.9 } else { 0.1 },
            moving,
            visibility,
            age: 0,
        };
        for k in 0..10 {
            let mut s = Scan::new(k as f64, -0.5, 0.01, vec![5.0; 101], 0.0, 30.0).unwrap();
            s.odometry = Some(Pose2::new(0.0, 0.0, 0.0));
            scans.push(s);
            let seen = if (3..9).contains(&k) { 0.0 } else { 1.0 };
            run.scans.push(ScanPeople {
                scan: k,
                time: k as f64,
                pose: Some([0.0; 3]),
                people: vec![
                    person(Label::new(0, 0), k as f64, true, seen),
                    person(Label::new(1, 0), 2.0, false, 1.0),
                ],
                detections: Vec::new(),
                pose_fallback: None,
            });
        }
        let track = |label, scans, dynamic_fraction| PersonTrack {
            label,
            scans,
            first_time: 0.0,
            last_time: 9.0,
            mean_speed: 0.0,
            dynamic_fraction,
            displacement: 0.0,
        };
        run.tracks = vec![
            track(Label::new(0, 0), 4, 1.0),
            track(Label::new(1, 0), 10, 0.0),
        ];
        (scans, run)
    }

    #[test]
    fn writes_moving_and_static_tracks_and_cuts_unseen_stretches() {
        let (scans, run) = story();
        let dir = tempfile::tempdir().unwrap();
        let options = PeoplePlotOptions {
            min_scans: 4,
            title: "story".into(),
            ..PeoplePlotOptions::default()
        };
        let png = dir.path().join("p.png");
        let counts = write_people_plot(&png, &scans, &run, &options).unwrap();
        assert_eq!((counts.moving, counts.stationary), (1, 1));
        assert_eq!(counts.points, 10 * 101);
        assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
        let svg = dir.path().join("p.svg");
        write_people_plot(&svg, &scans, &run, &options).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.starts_with("<svg"));
        // the walker's line is cut at its six unseen scans: two polylines in its colour
        let [r, g, b] = {
            let c = label_colour(Label::new(0, 0));
            [c.0, c.1, c.2]
        };
        let colour = format!("#{r:02X}{g:02X}{b:02X}");
        let lines = text
            .lines()
            .filter(|l| l.contains("<polyline") && l.contains(&colour))
            .count();
        assert_eq!(lines, 2, "{colour}");
        // only .svg and .png, only matching scans and runs; the directory holds just the plots
        assert!(write_people_plot(&dir.path().join("p.gif"), &scans, &run, &options).is_err());
        assert!(write_people_plot(&png, &scans[..5], &run, &options).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
        // more scans required: the walker (seen in 4) drops out
        let strict = PeoplePlotOptions {
            min_scans: 5,
            ..options
        };
        let counts = write_people_plot(&png, &scans, &run, &strict).unwrap();
        assert_eq!((counts.moving, counts.stationary), (0, 1));
    }
}
