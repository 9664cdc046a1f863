//! A small SVG writer: the few elements gonio's figures need, written as text. PNGs are made from the
//! same text by [`super::raster`], so both formats show one picture.

use std::fmt::Write;

/// An SVG document being written; coordinates in pixels, y down.
pub struct Svg {
    pub width: f64,
    pub height: f64,
    body: String,
}

/// Round to 0.01 px: enough for any screen, and it keeps the files small.
fn n(v: f64) -> String {
    let r = (v * 100.0).round() / 100.0;
    if r == 0.0 {
        "0".into()
    } else {
        format!("{r}")
    }
}

/// Text with the five XML special characters escaped.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;").replace('\'', "&apos;")
}

/// How text is anchored at its point.
#[derive(Clone, Copy)]
pub enum Anchor {
    Start,
    Middle,
    End,
}

impl Svg {
    pub fn new(width: f64, height: f64) -> Self {
        let mut svg = Svg { width, height, body: String::new() };
        svg.rect(0.0, 0.0, width, height, "white", None);
        svg
    }

    /// A straight line: two end points and the pen.
    #[allow(clippy::too_many_arguments)]
    pub fn line(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, stroke: &str, width: f64, dash: Option<&str>) {
        let dash = dash.map(|d| format!(r#" stroke-dasharray="{d}""#)).unwrap_or_default();
        let _ = writeln!(
            self.body,
            r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{stroke}" stroke-width="{}"{dash}/>"#,
            n(x0),
            n(y0),
            n(x1),
            n(y1),
            n(width)
        );
    }

    /// A polyline through `points` (an empty or one-point list draws nothing).
    pub fn polyline(&mut self, points: &[(f64, f64)], stroke: &str, width: f64, dash: Option<&str>) {
        if points.len() < 2 {
            return;
        }
        let dash = dash.map(|d| format!(r#" stroke-dasharray="{d}""#)).unwrap_or_default();
        let pts: Vec<String> = points.iter().map(|&(x, y)| format!("{},{}", n(x), n(y))).collect();
        let _ = writeln!(
            self.body,
            r#"<polyline points="{}" fill="none" stroke="{stroke}" stroke-width="{}" stroke-linejoin="round"{dash}/>"#,
            pts.join(" "),
            n(width)
        );
    }

    /// A filled polygon with an optional outline (colour, width).
    pub fn polygon(&mut self, points: &[(f64, f64)], fill: &str, opacity: f64, stroke: Option<(&str, f64)>) {
        let pts: Vec<String> = points.iter().map(|&(x, y)| format!("{},{}", n(x), n(y))).collect();
        let stroke = stroke.map(|(c, w)| format!(r#" stroke="{c}" stroke-width="{}" stroke-linejoin="round""#, n(w))).unwrap_or_default();
        let _ = writeln!(self.body, r#"<polygon points="{}" fill="{fill}" fill-opacity="{}"{stroke}/>"#, pts.join(" "), n(opacity));
    }

    /// A rectangle, filled, with an optional outline colour.
    pub fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, fill: &str, stroke: Option<&str>) {
        let stroke = stroke.map(|c| format!(r#" stroke="{c}" stroke-width="1""#)).unwrap_or_default();
        let _ = writeln!(self.body, r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{fill}"{stroke}/>"#, n(x), n(y), n(w), n(h));
    }

    /// A circular arc of radius `r` about (cx, cy) from angle `a0` to `a1` (radians, measured from "up",
    /// clockwise on screen), as a polyline.
    #[allow(clippy::too_many_arguments)]
    pub fn arc(&mut self, cx: f64, cy: f64, r: f64, a0: f64, a1: f64, stroke: &str, width: f64, dash: Option<&str>) {
        let steps = 96;
        let pts: Vec<(f64, f64)> = (0..=steps)
            .map(|k| {
                let a = a0 + (a1 - a0) * k as f64 / steps as f64;
                (cx + r * a.sin(), cy - r * a.cos())
            })
            .collect();
        self.polyline(&pts, stroke, width, dash);
    }

    /// A filled circle.
    pub fn circle(&mut self, cx: f64, cy: f64, r: f64, fill: &str) {
        let _ = writeln!(self.body, r#"<circle cx="{}" cy="{}" r="{}" fill="{fill}"/>"#, n(cx), n(cy), n(r));
    }

    /// Text at (x, y) (the baseline), `size` px, optionally rotated by `rotate` degrees about its point.
    pub fn text(&mut self, x: f64, y: f64, s: &str, size: f64, anchor: Anchor, rotate: f64) {
        let anchor = match anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        let rot = if rotate != 0.0 { format!(r#" transform="rotate({} {} {})""#, n(rotate), n(x), n(y)) } else { String::new() };
        let _ = writeln!(
            self.body,
            r#"<text x="{}" y="{}" font-size="{}" text-anchor="{anchor}"{rot}>{}</text>"#,
            n(x),
            n(y),
            n(size),
            escape(s)
        );
    }

    /// A PNG image stretched over the rectangle, drawn with nearest-neighbour sampling (a data image).
    pub fn png_image(&mut self, x: f64, y: f64, w: f64, h: f64, png: &[u8]) {
        let _ = writeln!(
            self.body,
            r#"<image x="{}" y="{}" width="{}" height="{}" preserveAspectRatio="none" image-rendering="optimizeSpeed" style="image-rendering:pixelated" href="data:image/png;base64,{}"/>"#,
            n(x),
            n(y),
            n(w),
            n(h),
            base64(png)
        );
    }

    /// The document.
    pub fn finish(self) -> String {
        format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"DejaVu Sans, Verdana, sans-serif\" fill=\"black\">\n{}</svg>\n",
            self.body,
            w = n(self.width),
            h = n(self.height)
        )
    }
}

/// Standard base64 (RFC 4648 §4, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let v = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((v >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (plain, coded) in
            [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foob", "Zm9vYg=="), ("fooba", "Zm9vYmE="), ("foobar", "Zm9vYmFy")]
        {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }

    #[test]
    fn text_is_escaped() {
        let mut svg = Svg::new(10.0, 10.0);
        svg.text(1.0, 2.0, "a<b & \"c\"", 12.0, Anchor::Start, 0.0);
        let doc = svg.finish();
        assert!(doc.contains("a&lt;b &amp; &quot;c&quot;"), "{doc}");
    }
}
