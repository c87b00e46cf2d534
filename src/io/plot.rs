//! A small SVG line plot for stress–strain curves (hand-written: plotting crates need system
//! fonts for text layout, which the default build must not require).

use std::fmt::Write;

/// A curve to draw: points, colour and legend label.
pub struct Series<'a> {
    /// (x, y) points in order.
    pub points: &'a [(f64, f64)],
    /// SVG colour.
    pub colour: &'a str,
    /// Legend text.
    pub label: &'a str,
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// An SVG document with the series, circles at `markers`, axis labels and min/max ticks.
pub fn line_plot_svg(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series<'_>],
    markers: &[(f64, f64)],
) -> String {
    let (w, h, left, right, top, bottom) = (720.0, 480.0, 90.0, 20.0, 40.0, 60.0);
    let all = series
        .iter()
        .flat_map(|s| s.points.iter())
        .chain(markers.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in all.filter(|p| p.0.is_finite() && p.1.is_finite()) {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !(x0 < x1) {
        (x0, x1) = (x0.min(0.0) - 1.0, x1.max(0.0) + 1.0);
    }
    if !(y0 < y1) {
        (y0, y1) = (y0.min(0.0) - 1.0, y1.max(0.0) + 1.0);
    }
    let sx = |x: f64| left + (x - x0) / (x1 - x0) * (w - left - right);
    let sy = |y: f64| h - bottom - (y - y0) / (y1 - y0) * (h - top - bottom);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="13">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="15">{}</text>"#,
        w / 2.0,
        escape(title)
    );
    let (ax, ay) = (sx(x0), sy(y0));
    let _ = writeln!(
        s,
        r#"<path d="M{ax},{} L{ax},{ay} L{},{ay}" stroke="black" fill="none"/>"#,
        sy(y1),
        sx(x1)
    );
    if y0 < 0.0 && y1 > 0.0 {
        let _ = writeln!(
            s,
            r#"<line x1="{ax}" y1="{z}" x2="{}" y2="{z}" stroke="gray" stroke-dasharray="4 3"/>"#,
            sx(x1),
            z = sy(0.0)
        );
    }
    for (v, anchor) in [(x0, "start"), (x1, "end")] {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="{anchor}">{v:.3e}</text>"#,
            sx(v),
            ay + 18.0
        );
    }
    for v in [y0, y1] {
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="end">{v:.3e}</text>"#,
            ax - 6.0,
            sy(v) + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
        (ax + sx(x1)) / 2.0,
        h - 15.0,
        escape(x_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="18" y="{}" text-anchor="middle" transform="rotate(-90 18 {})">{}</text>"#,
        (top + ay) / 2.0,
        (top + ay) / 2.0,
        escape(y_label)
    );
    for (k, ser) in series.iter().enumerate() {
        let pts: Vec<String> = ser
            .points
            .iter()
            .map(|&(x, y)| format!("{:.2},{:.2}", sx(x), sy(y)))
            .collect();
        let _ = writeln!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="2"/>"#,
            pts.join(" "),
            ser.colour
        );
        let ly = top + 10.0 + 18.0 * k as f64;
        let _ = writeln!(
            s,
            r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{}" stroke-width="2"/><text x="{}" y="{}">{}</text>"#,
            left + 10.0,
            left + 35.0,
            ser.colour,
            left + 40.0,
            ly + 4.0,
            escape(ser.label)
        );
    }
    for &(x, y) in markers {
        let _ = writeln!(
            s,
            r#"<circle cx="{:.2}" cy="{:.2}" r="5" fill="none" stroke="crimson" stroke-width="2"/>"#,
            sx(x),
            sy(y)
        );
    }
    s.push_str("</svg>\n");
    s
}
