//! Bird's-eye plots: poly-lines, segments and dots on a metric x–y plane at equal scale,
//! written as SVG or PNG (chosen by the file extension) with `plotters`. A light 10 m grid
//! stands in for axes; there is no text, so no font is needed. [`text`] is a 5×7 pixel font for
//! the plots that need titles, legends and ticks (the people plot of
//! [`crate::pipeline::people_tracking`]).
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

/// What a bird's-eye plot shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BirdsEyePlot {
    /// Lines (paths, trajectories, wall segments), drawn in order.
    pub lines: Vec<Polyline>,
    /// Dots, drawn over the lines.
    pub dots: Vec<Dot>,
}

impl BirdsEyePlot {
    /// The smallest square (x range, y range) holding every point, with a 5 m margin; `None`
    /// without points.
    pub fn bounds(&self) -> Option<([f64; 2], [f64; 2])> {
        let pts = self
            .lines
            .iter()
            .flat_map(|l| l.points.iter())
            .chain(self.dots.iter().map(|d| &d.at))
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
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        let (xr, yr) = self.bounds().unwrap_or(([-10.0, 10.0], [-10.0, 10.0]));
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .build_cartesian_2d(xr[0]..xr[1], yr[0]..yr[1])
            .map_err(err)?;
        let grid = RGBColor(225, 225, 225);
        let step = 10.0;
        let mut g = (xr[0] / step).ceil() * step;
        while g <= xr[1] {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(g, yr[0]), (g, yr[1])],
                    grid.stroke_width(1),
                )))
                .map_err(err)?;
            g += step;
        }
        let mut g = (yr[0] / step).ceil() * step;
        while g <= yr[1] {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(xr[0], g), (xr[1], g)],
                    grid.stroke_width(1),
                )))
                .map_err(err)?;
            g += step;
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
        root.present().map_err(err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_square_with_margin() {
        let plot = BirdsEyePlot {
            lines: vec![Polyline {
                points: vec![[0.0, 0.0], [20.0, 4.0]],
                colour: [0, 0, 0],
                width: 1,
            }],
            dots: vec![],
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
