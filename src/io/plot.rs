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
    /// Legend text.
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

fn plot_error(what: &str, e: impl std::fmt::Display) -> Error {
    Error::Output {
        path: what.to_string(),
        message: e.to_string(),
    }
}

impl LinePlot<'_> {
    /// The plot as an SVG document.
    pub fn svg(&self) -> Result<String, Error> {
        register_font();
        let mut s = String::new();
        {
            let root = SVGBackend::with_string(&mut s, PLOT_SIZE).into_drawing_area();
            self.draw(&root).map_err(|e| plot_error("svg plot", e))?;
            root.present().map_err(|e| plot_error("svg plot", e))?;
        }
        Ok(s)
    }

    /// The plot as a PNG image (8-bit RGB).
    pub fn png(&self) -> Result<Vec<u8>, Error> {
        register_font();
        let (w, h) = PLOT_SIZE;
        let mut rgb = vec![0u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, PLOT_SIZE).into_drawing_area();
            self.draw(&root).map_err(|e| plot_error("png plot", e))?;
            root.present().map_err(|e| plot_error("png plot", e))?;
        }
        encode_png(&rgb, w, h)
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
            chart
                .draw_series(LineSeries::new(
                    s.points
                        .iter()
                        .copied()
                        .filter(|p| p.0.is_finite() && p.1.is_finite()),
                    colour.stroke_width(2),
                ))?
                .label(s.label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(2))
                });
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
