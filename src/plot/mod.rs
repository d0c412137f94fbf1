//! Bird's-eye plots: point clouds, poly-lines, segments and dots on a metric x–y plane at equal scale,
//! written as SVG or PNG (chosen by the file extension) with `plotters`, with a grid of round
//! metre steps and tick labels, axis names, a scale bar, an optional title and legend. Text is
//! drawn with [`text`], a 5×7 pixel font, so no font engine is needed (it serves the people
//! plot of [`crate::pipeline::people_tracking`] too).
//!
//! Not for: deciding what to draw (the pipelines build a [`BirdsEyePlot`]) or interactive
//! viewing.

pub mod text;

use crate::error::{Error, Result};
use plotters::prelude::*;
use std::path::Path;

/// Something that draws itself on a plotters drawing area of any backend.
pub(crate) trait Draw {
    /// Draws everything on `root`; errors as text.
    fn draw_on<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, plotters::coord::Shift>,
    ) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static;
}

/// Writes `drawing` as an image of `size` (width, height) pixels: SVG for a `.svg` path, PNG
/// for a `.png` path, atomically (a temporary file beside `path` is renamed over it).
pub(crate) fn write_image(path: &Path, size: (u32, u32), drawing: &impl Draw) -> Result<()> {
    let what = || format!("plot file {}", path.display());
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("svg") => {
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                drawing
                    .draw_on(root)
                    .map_err(|e| Error::invalid(what(), e))?;
            }
            crate::atomic::write_bytes(path, svg.as_bytes())
        }
        Some("png") => {
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let tmp = path.with_file_name(format!(".{name}.{}.tmp.png", std::process::id()));
            let drawn = {
                let root = BitMapBackend::new(&tmp, size).into_drawing_area();
                drawing.draw_on(root)
            };
            if let Err(e) = drawn {
                let _ = std::fs::remove_file(&tmp);
                return Err(Error::io(path, std::io::Error::other(e)));
            }
            std::fs::rename(&tmp, path).map_err(|e| {
                let _ = std::fs::remove_file(&tmp);
                Error::io(path, e)
            })
        }
        _ => Err(Error::invalid(what(), "extension must be .svg or .png")),
    }
}

/// A connected line through `points` (m).
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline {
    /// Vertices in order (x, y), metres.
    pub points: Vec<[f64; 2]>,
    /// RGB colour.
    pub colour: [u8; 3],
    /// Stroke width in pixels.
    pub width: u32,
}

/// A filled dot.
#[derive(Clone, Debug, PartialEq)]
pub struct Dot {
    /// Centre (x, y), metres.
    pub at: [f64; 2],
    /// RGB colour.
    pub colour: [u8; 3],
    /// Radius in pixels.
    pub radius: u32,
}

/// Many points of one colour, drawn as single pixels under everything else (a point cloud
/// seen from above).
#[derive(Clone, Debug, PartialEq)]
pub struct PointLayer {
    /// The points (x, y), metres.
    pub points: Vec<[f64; 2]>,
    /// RGB colour.
    pub colour: [u8; 3],
}

/// How a legend entry shows its colour.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum LegendMark {
    /// A short line of this width in pixels.
    Line(u32),
    /// A dot of this radius in pixels.
    Dot(u32),
}

/// One legend entry.
#[derive(Clone, Debug, PartialEq)]
pub struct LegendEntry {
    /// What it names.
    pub label: String,
    /// RGB colour.
    pub colour: [u8; 3],
    /// Its mark.
    pub mark: LegendMark,
}

/// What a bird's-eye plot shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BirdsEyePlot {
    /// Title lines above the plot (none: no title band).
    pub title: Vec<String>,
    /// Legend entries, drawn in the top-right corner of the plot area (none: no legend).
    pub legend: Vec<LegendEntry>,
    /// Lines (paths, trajectories, wall segments), drawn in order.
    pub lines: Vec<Polyline>,
    /// Dots, drawn over the lines.
    pub dots: Vec<Dot>,
    /// Point layers, drawn first, in order.
    pub points: Vec<PointLayer>,
}

/// A round grid step (1, 2 or 5 × 10ⁿ) giving at most about `lines` lines over `span`.
pub(crate) fn grid_step(span: f64, lines: f64) -> f64 {
    let raw = (span / lines).max(1e-9);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}

/// The multiples of `step` in [a, b], ascending (each the previous plus `step`).
pub(crate) fn grid_ticks(a: f64, b: f64, step: f64) -> Vec<f64> {
    let mut v = Vec::new();
    let mut g = (a / step).ceil() * step;
    while g <= b {
        v.push(g);
        g += step;
    }
    v
}

/// Margins of the plot area in pixels: left (y tick labels), bottom (x tick labels and the
/// axis name), right, and the top without a title.
const LEFT: u32 = 56;
const BOTTOM: u32 = 40;
const RIGHT: u32 = 16;
const TOP: u32 = 16;
/// Pixel height of one title line (scale 2 glyphs and spacing).
const TITLE_LINE: u32 = 24;

impl BirdsEyePlot {
    /// The smallest square (x range, y range) holding every point, with a 5 m margin; `None`
    /// without points.
    pub fn bounds(&self) -> Option<([f64; 2], [f64; 2])> {
        let pts = self
            .lines
            .iter()
            .flat_map(|l| l.points.iter())
            .chain(self.dots.iter().map(|d| &d.at))
            .chain(self.points.iter().flat_map(|l| l.points.iter()))
            .filter(|p| p[0].is_finite() && p[1].is_finite());
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in pts {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        if !lo[0].is_finite() {
            return None;
        }
        let half = 0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + 5.0;
        let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        Some(([c[0] - half, c[0] + half], [c[1] - half, c[1] + half]))
    }

    /// Writes the plot as a square image of `size` pixels: SVG for a `.svg` path, PNG for a
    /// `.png` path, atomically (a temporary file beside `path` is renamed over it).
    pub fn write(&self, path: &Path, size: u32) -> Result<()> {
        let size = size.max(64);
        write_image(path, (size, size), self)
    }
}

impl Draw for BirdsEyePlot {
    fn draw_on<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, plotters::coord::Shift>,
    ) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        use text::{draw_text, text_width, HEIGHT};
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let ink = RGBColor(40, 40, 40);
        root.fill(&WHITE).map_err(err)?;
        let (w, h) = root.dim_in_pixel();
        let top = TOP + TITLE_LINE * self.title.len() as u32;
        for (k, line) in self.title.iter().enumerate() {
            let scale = if k == 0 { 2 } else { 1 };
            let y = 8 + (TITLE_LINE * k as u32) as i32;
            draw_text(&root, line, (LEFT as i32, y), scale, ink).map_err(err)?;
        }
        // The plot area: the largest square that fits inside the margins, at equal scale.
        let side = w
            .saturating_sub(LEFT + RIGHT)
            .min(h.saturating_sub(top + BOTTOM))
            .max(16);
        let area = root.margin(
            top,
            h.saturating_sub(top + side),
            LEFT,
            w.saturating_sub(LEFT + side),
        );
        let (xr, yr) = self.bounds().unwrap_or(([-10.0, 10.0], [-10.0, 10.0]));
        let mut chart = ChartBuilder::on(&area)
            .build_cartesian_2d(xr[0]..xr[1], yr[0]..yr[1])
            .map_err(err)?;
        let grid = RGBColor(225, 225, 225);
        let step = grid_step(xr[1] - xr[0], 10.0);
        let ticks = |a: f64, b: f64| grid_ticks(a, b, step);
        let label = |v: f64| format!("{:.0}", v + 0.0);
        for g in ticks(xr[0], xr[1]) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(g, yr[0]), (g, yr[1])],
                    grid.stroke_width(1),
                )))
                .map_err(err)?;
            let (px, _) = chart.backend_coord(&(g, yr[0]));
            let t = label(g);
            let x = px - text_width(&t, 1) / 2;
            draw_text(&root, &t, (x, (top + side) as i32 + 6), 1, ink).map_err(err)?;
        }
        for g in ticks(yr[0], yr[1]) {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(xr[0], g), (xr[1], g)],
                    grid.stroke_width(1),
                )))
                .map_err(err)?;
            let (_, py) = chart.backend_coord(&(xr[0], g));
            let t = label(g);
            let x = LEFT as i32 - 6 - text_width(&t, 1);
            draw_text(&root, &t, (x, py - HEIGHT / 2), 1, ink).map_err(err)?;
        }
        let names_y = (top + side) as i32 + 20;
        let xname = "X (M)";
        let xc = (LEFT + side / 2) as i32 - text_width(xname, 1) / 2;
        draw_text(&root, xname, (xc, names_y), 1, ink).map_err(err)?;
        draw_text(&root, "Y (M)", (4, top as i32 - 12), 1, ink).map_err(err)?;
        // Scale bar: one grid step, bottom left under the axis.
        let (p0, _) = chart.backend_coord(&(xr[0], yr[0]));
        let (p1, _) = chart.backend_coord(&(xr[0] + step, yr[0]));
        let bar_y = names_y + 3;
        root.draw(&PathElement::new(
            vec![(p0, bar_y), (p1, bar_y)],
            ink.stroke_width(3),
        ))
        .map_err(err)?;
        draw_text(
            &root,
            &format!("{} M", label(step)),
            (p1 + 6, bar_y - 3),
            1,
            ink,
        )
        .map_err(err)?;
        for layer in &self.points {
            let [r, gr, b] = layer.colour;
            let c = RGBColor(r, gr, b);
            chart
                .draw_series(
                    layer
                        .points
                        .iter()
                        .filter(|p| p[0].is_finite() && p[1].is_finite())
                        .map(|p| Pixel::new((p[0], p[1]), c)),
                )
                .map_err(err)?;
        }
        for l in &self.lines {
            let [r, gr, b] = l.colour;
            let pts: Vec<(f64, f64)> = l.points.iter().map(|p| (p[0], p[1])).collect();
            chart
                .draw_series(std::iter::once(PathElement::new(
                    pts,
                    RGBColor(r, gr, b).stroke_width(l.width.max(1)),
                )))
                .map_err(err)?;
        }
        for d in &self.dots {
            let [r, gr, b] = d.colour;
            chart
                .draw_series(std::iter::once(Circle::new(
                    (d.at[0], d.at[1]),
                    d.radius.max(1),
                    RGBColor(r, gr, b).filled(),
                )))
                .map_err(err)?;
        }
        if !self.legend.is_empty() {
            let rows = self.legend.len() as i32;
            let wide = self
                .legend
                .iter()
                .map(|e| text_width(&e.label, 1))
                .max()
                .unwrap_or(0);
            let (bw, bh) = (wide + 44, rows * 14 + 8);
            let x0 = (LEFT + side) as i32 - bw - 6;
            let y0 = top as i32 + 6;
            root.draw(&Rectangle::new(
                [(x0, y0), (x0 + bw, y0 + bh)],
                WHITE.mix(0.9).filled(),
            ))
            .map_err(err)?;
            root.draw(&Rectangle::new([(x0, y0), (x0 + bw, y0 + bh)], ink))
                .map_err(err)?;
            for (k, e) in self.legend.iter().enumerate() {
                let y = y0 + 4 + 14 * k as i32 + HEIGHT / 2;
                let [r, g, b] = e.colour;
                let c = RGBColor(r, g, b);
                match e.mark {
                    LegendMark::Line(width) => root.draw(&PathElement::new(
                        vec![(x0 + 6, y), (x0 + 30, y)],
                        c.stroke_width(width.max(1)),
                    )),
                    LegendMark::Dot(radius) => {
                        root.draw(&Circle::new((x0 + 18, y), radius.max(1), c.filled()))
                    }
                }
                .map_err(err)?;
                draw_text(&root, &e.label, (x0 + 38, y - HEIGHT / 2), 1, ink).map_err(err)?;
            }
        }
        root.present().map_err(err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_steps_are_round() {
        assert_eq!(grid_step(100.0, 10.0), 10.0);
        assert_eq!(grid_step(30.0, 10.0), 5.0);
        assert_eq!(grid_step(12.0, 10.0), 2.0);
        assert_eq!(grid_step(7.0, 10.0), 1.0);
        assert!((grid_step(3.0, 10.0) - 0.5).abs() < 1e-12);
    }

    /// Dark pixels of a plot drawn into a `w`×`h` buffer, as (x, y).
    fn dark_pixels(plot: &BirdsEyePlot, w: u32, h: u32) -> Vec<(u32, u32)> {
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            plot.draw_on(root).unwrap();
        }
        (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| buf[((y * w + x) * 3) as usize] < 100)
            .collect()
    }

    #[test]
    fn title_ticks_scale_and_legend_are_drawn() {
        let line = Polyline {
            points: vec![[0.0, 0.0], [90.0, 0.0]],
            colour: [230, 230, 0],
            width: 1,
        };
        let bare = BirdsEyePlot {
            lines: vec![line.clone()],
            ..Default::default()
        };
        let dressed = BirdsEyePlot {
            title: vec!["DRIVE 5".into(), "SECOND LINE".into()],
            legend: vec![LegendEntry {
                label: "WALLS".into(),
                colour: [0, 0, 0],
                mark: LegendMark::Line(4),
            }],
            lines: vec![line],
            ..Default::default()
        };
        // Bare, the plot area fills the height between the margins: (400 − 72) = (384 − 56).
        let (w, h) = (400, 384);
        let bare_px = dark_pixels(&bare, w, h);
        let dressed_px = dark_pixels(&dressed, w, h);
        // Tick labels and axis names: dark text below and left of the plot area even bare.
        assert!(bare_px.iter().any(|&(_, y)| y > h - BOTTOM));
        assert!(bare_px.iter().any(|&(x, _)| x < LEFT));
        // The title sits in its band above the plot area, at the left margin.
        let title_band = |&&(x, y): &&(u32, u32)| y < 2 * TITLE_LINE && x >= LEFT;
        assert!(dressed_px.iter().any(|p| title_band(&p)));
        assert!(!bare_px.iter().any(|p| title_band(&p)));
        // The legend box is in the top-right corner of the plot area.
        let corner = |&&(x, y): &&(u32, u32)| x > w / 2 && y > 2 * TITLE_LINE && y < h / 3;
        assert!(dressed_px.iter().filter(|p| corner(p)).count() > 50);
    }

    #[test]
    fn point_layers_are_pixels_inside_the_bounds() {
        // A 10 × 10 grid of points 1 m apart; the bounds hold them with the 5 m margin.
        let grid: Vec<[f64; 2]> = (0..100)
            .map(|k| [(k % 10) as f64, (k / 10) as f64])
            .collect();
        let plot = BirdsEyePlot {
            points: vec![PointLayer {
                points: grid,
                colour: [0, 0, 0],
            }],
            ..Default::default()
        };
        assert_eq!(plot.bounds().unwrap(), ([-5.0, 14.0], [-5.0, 14.0]));
        // Each point is one dark pixel inside the plot area: 100 of them (the 19 m span at
        // ≥ 10 px/m keeps them apart), and a plot without them has none there.
        let (w, h) = (400, 384);
        let inside = |px: &[(u32, u32)]| {
            px.iter()
                .filter(|&&(x, y)| {
                    x > LEFT + 2 && x < w - RIGHT - 2 && y > TOP + 2 && y < h - BOTTOM - 2
                })
                .count()
        };
        assert_eq!(inside(&dark_pixels(&plot, w, h)), 100);
        let empty = BirdsEyePlot {
            points: vec![PointLayer {
                points: Vec::new(),
                colour: [0, 0, 0],
            }],
            ..Default::default()
        };
        assert_eq!(inside(&dark_pixels(&empty, w, h)), 0);
    }

    #[test]
    fn bounds_are_square_with_margin() {
        let plot = BirdsEyePlot {
            lines: vec![Polyline {
                points: vec![[0.0, 0.0], [20.0, 4.0]],
                colour: [0, 0, 0],
                width: 1,
            }],
            ..Default::default()
        };
        let (x, y) = plot.bounds().unwrap();
        assert_eq!(x, [-5.0, 25.0]);
        assert_eq!(y, [-13.0, 17.0]);
        assert!(BirdsEyePlot::default().bounds().is_none());
    }

    #[test]
    fn writes_svg_and_png_and_refuses_other_extensions() {
        let dir = tempfile::tempdir().unwrap();
        let plot = BirdsEyePlot {
            lines: vec![Polyline {
                points: vec![[0.0, 0.0], [20.0, 4.0]],
                colour: [200, 0, 0],
                width: 2,
            }],
            dots: vec![Dot {
                at: [20.0, 4.0],
                colour: [0, 0, 200],
                radius: 3,
            }],
            ..Default::default()
        };
        let svg = dir.path().join("a.svg");
        plot.write(&svg, 200).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(
            text.starts_with("<svg") && text.contains("#C80000"),
            "{text}"
        );
        let png = dir.path().join("a.png");
        plot.write(&png, 200).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        assert!(plot.write(&dir.path().join("a.gif"), 200).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }
}
