//! Line plots (stress–strain curves) as SVG and PNG, drawn once with plotters for both
//! backends. Text is laid out with the embedded DejaVu Sans font, so no system fonts are needed.

use crate::Error;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::Once;

/// A curve to draw.
#[derive(Clone, Debug)]
pub struct Series<'a> {
    /// (x, y) points in order.
    pub points: &'a [(f64, f64)],
    /// RGB colour.
    pub colour: (u8, u8, u8),
    /// Legend text (none when empty: e.g. the second of two lines that share one).
    pub label: &'a str,
}

/// A line plot: series, circled markers, axis labels.
#[derive(Clone, Debug)]
pub struct LinePlot<'a> {
    /// Title above the plot.
    pub title: &'a str,
    /// Horizontal axis label.
    pub x_label: &'a str,
    /// Vertical axis label.
    pub y_label: &'a str,
    /// The curves.
    pub series: &'a [Series<'a>],
    /// Points to circle (e.g. contact switches), with their legend label.
    pub markers: &'a [(f64, f64)],
    /// Legend label of the markers.
    pub marker_label: &'a str,
}

/// Size of the rendered plot (pixels; SVG user units).
pub const PLOT_SIZE: (u32, u32) = (800, 540);

const FONT: &str = "sans-serif";

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is a valid TrueType file; a failure would only drop the text.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
    });
}

/// Something plotters draws, on any backend.
trait Drawing {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>;
}

/// Renders to an SVG document of `size`.
fn render_svg(d: &impl Drawing, size: (u32, u32)) -> Result<String, Error> {
    register_font();
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
        d.draw(&root).map_err(|e| plot_error("svg plot", e))?;
        root.present().map_err(|e| plot_error("svg plot", e))?;
    }
    Ok(s)
}

/// Renders to a PNG image of `size`.
fn render_png(d: &impl Drawing, size: (u32, u32)) -> Result<Vec<u8>, Error> {
    register_font();
    let (w, h) = size;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        d.draw(&root).map_err(|e| plot_error("png plot", e))?;
        root.present().map_err(|e| plot_error("png plot", e))?;
    }
    encode_png(&rgb, w, h)
}

fn plot_error(what: &str, e: impl std::fmt::Display) -> Error {
    Error::Output {
        path: what.to_string(),
        message: e.to_string(),
    }
}

impl LinePlot<'_> {
    /// The plot as an SVG document.
    pub fn svg(&self) -> Result<String, Error> {
        render_svg(self, PLOT_SIZE)
    }

    /// The plot as a PNG image (8-bit RGB).
    pub fn png(&self) -> Result<Vec<u8>, Error> {
        render_png(self, PLOT_SIZE)
    }

    fn bounds(&self) -> ((f64, f64), (f64, f64)) {
        let (mut x0, mut x1, mut y0, mut y1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let all = self
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .chain(self.markers.iter());
        for &(x, y) in all.filter(|p| p.0.is_finite() && p.1.is_finite()) {
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
        let pad = |a: f64, b: f64| {
            let d = if b > a { 0.05 * (b - a) } else { 1.0 };
            (a - d, b + d)
        };
        (pad(x0, x1), pad(y0, y1))
    }
}

impl Drawing for LinePlot<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let ((x0, x1), (y0, y1)) = self.bounds();
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, (FONT, 18))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(90)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label)
            .y_desc(self.y_label)
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        for s in self.series {
            let colour = RGBColor(s.colour.0, s.colour.1, s.colour.2);
            let drawn = chart.draw_series(LineSeries::new(
                s.points
                    .iter()
                    .copied()
                    .filter(|p| p.0.is_finite() && p.1.is_finite()),
                colour.stroke_width(2),
            ))?;
            if !s.label.is_empty() {
                drawn.label(s.label).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(2))
                });
            }
        }
        if !self.markers.is_empty() {
            let crimson = RGBColor(220, 20, 60);
            chart
                .draw_series(
                    self.markers
                        .iter()
                        .map(|&p| Circle::new(p, 6, crimson.stroke_width(2))),
                )?
                .label(self.marker_label)
                .legend(move |(x, y)| Circle::new((x + 12, y), 5, crimson.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font((FONT, 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
        Ok(())
    }
}

/// An orientation rose: the length fraction of each angle bin over [0, π) drawn as a sector
/// of radius ∝ fraction, mirrored to [π, 2π) (fibers are axial).
#[derive(Clone, Debug)]
pub struct RosePlot<'a> {
    /// Title above the rose.
    pub title: &'a str,
    /// Fractions per bin over [0, π).
    pub fractions: &'a [f64],
}

impl RosePlot<'_> {
    /// The rose as an SVG document.
    pub fn svg(&self) -> Result<String, Error> {
        render_svg(self, ROSE_SIZE)
    }

    /// The rose as a PNG image (8-bit RGB).
    pub fn png(&self) -> Result<Vec<u8>, Error> {
        render_png(self, ROSE_SIZE)
    }
}

impl Drawing for RosePlot<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        use std::f64::consts::PI;
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(root)
            .caption(self.title, (FONT, 16))
            .margin(12)
            .build_cartesian_2d(-1.15..1.15, -1.15..1.15)?;
        let n = self.fractions.len().max(1);
        let peak = self.fractions.iter().cloned().fold(0.0, f64::max);
        let grey = RGBColor(200, 200, 200);
        for ring in [0.25, 0.5, 0.75, 1.0] {
            let pts: Vec<(f64, f64)> = (0..=72)
                .map(|k| {
                    let a = 2.0 * PI * k as f64 / 72.0;
                    (ring * a.cos(), ring * a.sin())
                })
                .collect();
            chart.draw_series(std::iter::once(PathElement::new(pts, grey)))?;
        }
        for (a, label) in [
            (0.0, "0°"),
            (0.5 * PI, "90°"),
            (PI, "180°"),
            (1.5 * PI, "270°"),
        ] {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(0.0, 0.0), (a.cos(), a.sin())],
                grey,
            )))?;
            chart.draw_series(std::iter::once(Text::new(
                label,
                (1.07 * a.cos() - 0.04, 1.07 * a.sin() + 0.02),
                (FONT, 13),
            )))?;
        }
        let fill = RGBColor(70, 130, 180);
        for (k, &f) in self.fractions.iter().enumerate() {
            if !(f > 0.0) || !(peak > 0.0) {
                continue;
            }
            let r = f / peak;
            for half in [0.0, PI] {
                let (a0, a1) = (
                    half + PI * k as f64 / n as f64,
                    half + PI * (k + 1) as f64 / n as f64,
                );
                let mut pts = vec![(0.0, 0.0)];
                for j in 0..=8 {
                    let a = a0 + (a1 - a0) * j as f64 / 8.0;
                    pts.push((r * a.cos(), r * a.sin()));
                }
                chart.draw_series(std::iter::once(Polygon::new(pts.clone(), fill.mix(0.75))))?;
                pts.push((0.0, 0.0));
                chart.draw_series(std::iter::once(PathElement::new(
                    pts,
                    BLACK.stroke_width(1),
                )))?;
            }
        }
        chart.draw_series(std::iter::once(Text::new(
            format!("outer ring: {:.1} % of the length per bin", 100.0 * peak),
            (-1.1, -1.12),
            (FONT, 12),
        )))?;
        Ok(())
    }
}

/// Size of the rose plot (pixels).
pub const ROSE_SIZE: (u32, u32) = (560, 600);

/// An axis tick: plain decimals between 10⁻² and 10⁴, otherwise scientific; trailing zeros cut.
fn tick(v: f64) -> String {
    let a = v.abs();
    if a < 1e-300 {
        return "0".into();
    }
    let trim = |s: String| -> String {
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            None if s.contains('.') => s.trim_end_matches('0').trim_end_matches('.').into(),
            _ => s,
        }
    };
    if (1e-2..1e4).contains(&a) {
        trim(format!("{v:.4}"))
    } else {
        trim(format!("{v:.3e}"))
    }
}

/// Encodes 8-bit RGB pixels as PNG.
pub(crate) fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, Error> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(|e| plot_error("png", e))?;
        w.write_image_data(rgb).map_err(|e| plot_error("png", e))?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plot<'a>(series: &'a [Series<'a>], markers: &'a [(f64, f64)]) -> LinePlot<'a> {
        LinePlot {
            title: "t <&>",
            x_label: "e11",
            y_label: "N11 (N/m)",
            series,
            markers,
            marker_label: "switch to slip",
        }
    }

    #[test]
    fn svg_and_png_hold_the_plot() {
        let pts = [(0.0, 0.0), (0.01, 2.0), (0.02, 3.0)];
        let series = [Series {
            points: &pts,
            colour: (70, 130, 180),
            label: "cell",
        }];
        let p = plot(&series, &[(0.01, 2.0)]);
        let svg = p.svg().unwrap();
        assert!(
            svg.starts_with("<svg") && svg.contains("N11 (N/m)") && svg.contains("&lt;&amp;&gt;")
        );
        assert!(svg.contains("<circle"), "the marker is drawn");
        let png = p.png().unwrap();
        assert_eq!(&png[1..4], b"PNG");
        // IHDR: width and height, big-endian, after the 8-byte signature and 8-byte chunk head.
        assert_eq!(
            u32::from_be_bytes([png[16], png[17], png[18], png[19]]),
            PLOT_SIZE.0
        );
        assert_eq!(
            u32::from_be_bytes([png[20], png[21], png[22], png[23]]),
            PLOT_SIZE.1
        );
    }

    #[test]
    fn the_rose_draws_both_halves() {
        let fr = [0.5, 0.25, 0.25, 0.0];
        let rose = RosePlot {
            title: "rose",
            fractions: &fr,
        };
        let svg = rose.svg().unwrap();
        // Three non-empty bins, each mirrored: six filled sectors.
        assert_eq!(svg.matches("<polygon").count(), 6, "{svg}");
        assert_eq!(&rose.png().unwrap()[1..4], b"PNG");
    }

    #[test]
    fn ticks_are_short() {
        assert_eq!(tick(0.0), "0");
        assert_eq!(tick(2.5), "2.5");
        assert_eq!(tick(-0.125), "-0.125");
        assert_eq!(tick(0.002), "2e-3");
        assert_eq!(tick(1.25e5), "1.25e5");
    }

    #[test]
    fn degenerate_and_non_finite_data_still_plot() {
        let pts = [(0.0, 0.0), (f64::NAN, 1.0)];
        let series = [Series {
            points: &pts,
            colour: (0, 0, 0),
            label: "flat",
        }];
        assert!(plot(&series, &[]).svg().is_ok());
        assert!(plot(&[], &[]).png().is_ok());
    }
}
