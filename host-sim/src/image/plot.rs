//! A small raster scatter plot written as PNG: SNR against bytes per voxel
//! for the precision study, and SNR against time per view with Pareto
//! fronts for the speed–accuracy trade. Text uses a built-in 3×5 pixel font (upper-case
//! letters, digits and a few signs), drawn at twice its size.

use std::path::Path;

/// An RGB image being drawn.
pub struct Canvas {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

/// An RGB colour.
pub type Rgb = [u8; 3];

impl Canvas {
    /// A white canvas.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            rgb: vec![255; width * height * 3],
        }
    }

    /// Set one pixel (ignored outside the canvas).
    pub fn set(&mut self, x: i64, y: i64, c: Rgb) {
        if x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height {
            let i = 3 * (y as usize * self.width + x as usize);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// Fill a rectangle.
    pub fn rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Rgb) {
        for yy in y..y + h {
            for xx in x..x + w {
                self.set(xx, yy, c);
            }
        }
    }

    /// A straight line (Bresenham); `dash` > 0 draws `dash` on, `dash` off.
    pub fn line(&mut self, (x0, y0): (i64, i64), (x1, y1): (i64, i64), c: Rgb, dash: i64) {
        let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
        let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
        let (mut x, mut y, mut err, mut step) = (x0, y0, dx + dy, 0i64);
        loop {
            if dash == 0 || (step / dash) % 2 == 0 {
                self.set(x, y, c);
            }
            step += 1;
            if x == x1 && y == y1 {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x += sx;
            }
            if e2 <= dx {
                err += dx;
                y += sy;
            }
        }
    }

    /// Text with its top-left corner at `(x, y)`, each font pixel drawn as a
    /// `scale × scale` square; lower-case letters are drawn as upper-case and
    /// characters without a glyph as blanks.
    pub fn text(&mut self, x: i64, y: i64, s: &str, scale: i64, c: Rgb) {
        for (i, ch) in s.chars().enumerate() {
            let glyph = glyph(ch.to_ascii_uppercase());
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..3 {
                    if bits & (4 >> col) != 0 {
                        self.rect(
                            x + (i as i64 * 4 + col) * scale,
                            y + row as i64 * scale,
                            scale,
                            scale,
                            c,
                        );
                    }
                }
            }
        }
    }

    /// Text written downwards, one character under the other.
    pub fn text_down(&mut self, x: i64, y: i64, s: &str, scale: i64, c: Rgb) {
        for (i, ch) in s.chars().enumerate() {
            self.text(x, y + i as i64 * 6 * scale, &ch.to_string(), scale, c);
        }
    }

    /// Width in pixels of `s` drawn at `scale`.
    pub fn text_width(s: &str, scale: i64) -> i64 {
        s.chars().count() as i64 * 4 * scale
    }

    /// Write as an 8-bit RGB PNG.
    ///
    /// # Errors
    /// File creation or encoding failure, with the path.
    pub fn write_png(&self, path: &Path) -> Result<(), String> {
        super::png::write(
            path,
            (self.width, self.height),
            png::ColorType::Rgb,
            png::BitDepth::Eight,
            &self.rgb,
        )
    }
}

/// Rows of a 3×5 glyph, top first, bit 2 leftmost.
fn glyph(c: char) -> [u8; 5] {
    match c {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 2, 2],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        'A' => [2, 5, 7, 5, 5],
        'B' => [6, 5, 6, 5, 6],
        'C' => [3, 4, 4, 4, 3],
        'D' => [6, 5, 5, 5, 6],
        'E' => [7, 4, 6, 4, 7],
        'F' => [7, 4, 6, 4, 4],
        'G' => [3, 4, 5, 5, 3],
        'H' => [5, 5, 7, 5, 5],
        'I' => [7, 2, 2, 2, 7],
        'J' => [1, 1, 1, 5, 2],
        'K' => [5, 5, 6, 5, 5],
        'L' => [4, 4, 4, 4, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'O' => [2, 5, 5, 5, 2],
        'P' => [6, 5, 6, 4, 4],
        'Q' => [2, 5, 5, 6, 3],
        'R' => [6, 5, 6, 5, 5],
        'S' => [3, 4, 2, 1, 6],
        'T' => [7, 2, 2, 2, 2],
        'U' => [5, 5, 5, 5, 7],
        'V' => [5, 5, 5, 5, 2],
        'W' => [5, 5, 7, 7, 5],
        'X' => [5, 5, 2, 5, 5],
        'Y' => [5, 5, 2, 2, 2],
        'Z' => [7, 1, 2, 4, 7],
        '-' => [0, 0, 7, 0, 0],
        '.' => [0, 0, 0, 0, 2],
        ',' => [0, 0, 0, 2, 4],
        '/' => [1, 1, 2, 4, 4],
        '(' => [2, 4, 4, 4, 2],
        ')' => [2, 1, 1, 1, 2],
        '@' => [7, 5, 7, 4, 7],
        '=' => [0, 7, 0, 7, 0],
        '>' => [4, 2, 1, 2, 4],
        '<' => [1, 2, 4, 2, 1],
        _ => [0; 5],
    }
}

/// One point of a scatter plot.
#[derive(Clone, Debug)]
pub struct Point {
    /// Horizontal position in data units.
    pub x: f64,
    /// Vertical position in data units.
    pub y: f64,
    /// Series index (colour).
    pub series: usize,
}

/// A scatter plot of `points` with a log₂ x axis.
pub struct Scatter<'a> {
    /// Title at the top.
    pub title: &'a str,
    /// Caption of the x axis.
    pub x_label: &'a str,
    /// Caption of the y axis.
    pub y_label: &'a str,
    /// `(min, max)` of the x axis (positive; drawn on a log₂ scale).
    pub x_range: (f64, f64),
    /// `(min, max)` of the y axis.
    pub y_range: (f64, f64),
    /// Major x ticks.
    pub x_ticks: &'a [f64],
    /// Step of the y ticks.
    pub y_step: f64,
    /// Dashed horizontal reference lines with their labels.
    pub y_lines: &'a [(f64, &'a str)],
    /// Series names and colours (legend).
    pub series: &'a [(&'a str, Rgb)],
    /// Labels written downwards under the plot area at data x positions.
    pub x_labels: &'a [(f64, String)],
    /// The points.
    pub points: &'a [Point],
}

/// Extras drawn over a [`Scatter`].
#[derive(Default)]
pub struct Overlay<'a> {
    /// Pareto fronts: a label and the front's points in data units, sorted
    /// by x. Each is drawn as a staircase (the best y reached by that x),
    /// its points ringed, and the label left of its first point.
    pub fronts: &'a [(String, Vec<(f64, f64)>)],
    /// Marker side in pixels per point (odd; default 7 where missing).
    pub marker_sizes: &'a [i64],
}

impl Scatter<'_> {
    /// Draw on a new `width × height` canvas.
    pub fn draw(&self, width: usize, height: usize) -> Canvas {
        self.draw_with(width, height, &Overlay::default())
    }

    /// Draw on a new `width × height` canvas, with `overlay` on top.
    pub fn draw_with(&self, width: usize, height: usize, overlay: &Overlay<'_>) -> Canvas {
        let mut c = Canvas::new(width, height);
        let black = [0, 0, 0];
        let grey = [200, 200, 200];
        let longest = self
            .x_labels
            .iter()
            .map(|(_, s)| s.len())
            .max()
            .unwrap_or(0) as i64;
        let (left, right, top) = (70i64, width as i64 - 20, 40i64);
        let bottom = height as i64 - 60 - longest * 12;
        let (x0, x1) = (self.x_range.0.log2(), self.x_range.1.log2());
        let px =
            |x: f64| left + ((x.log2() - x0) / (x1 - x0) * (right - left) as f64).round() as i64;
        let (y0, y1) = self.y_range;
        let py = |y: f64| bottom - ((y - y0) / (y1 - y0) * (bottom - top) as f64).round() as i64;
        c.text(left, 10, self.title, 2, black);
        // Grid, ticks and labels.
        let mut y = y0;
        while y <= y1 + 1e-9 {
            c.line((left, py(y)), (right, py(y)), grey, 0);
            let label = format!("{y:.0}");
            c.text(
                left - 8 - Canvas::text_width(&label, 2),
                py(y) - 5,
                &label,
                2,
                black,
            );
            y += self.y_step;
        }
        for &t in self.x_ticks {
            c.line((px(t), top), (px(t), bottom), grey, 0);
            let label = format!("{t}");
            c.text(
                px(t) - Canvas::text_width(&label, 2) / 2,
                bottom + 6,
                &label,
                2,
                black,
            );
        }
        for &(v, label) in self.y_lines {
            c.line((left, py(v)), (right, py(v)), [120, 120, 120], 4);
            c.text(
                right - Canvas::text_width(label, 2) - 4,
                py(v) - 12,
                label,
                2,
                [90, 90, 90],
            );
        }
        c.line((left, top), (left, bottom), black, 0);
        c.line((left, bottom), (right, bottom), black, 0);
        c.text(
            (left + right) / 2 - Canvas::text_width(self.x_label, 2) / 2,
            height as i64 - 16,
            self.x_label,
            2,
            black,
        );
        c.text_down(8, top + 20, self.y_label, 2, black);
        for (x, label) in self.x_labels {
            c.text_down(px(*x) - 3, bottom + 24, label, 2, [60, 60, 60]);
            c.line((px(*x), bottom), (px(*x), bottom + 4), black, 0);
        }
        // Legend.
        for (i, (name, col)) in self.series.iter().enumerate() {
            let ly = top + 8 + 16 * i as i64;
            c.rect(right - 150, ly, 10, 10, *col);
            c.text(right - 134, ly, name, 2, black);
        }
        // Points, clamped to the plot area.
        for (i, p) in self.points.iter().enumerate() {
            let (x, y) = (px(p.x), py(p.y.clamp(y0, y1)));
            let col = self.series.get(p.series).map_or(black, |s| s.1);
            let side = overlay.marker_sizes.get(i).copied().unwrap_or(7);
            c.rect(x - side / 2, y - side / 2, side, side, col);
        }
        for (label, front) in overlay.fronts {
            let at = |&(x, y): &(f64, f64)| (px(x), py(y.clamp(y0, y1)));
            for pair in front.windows(2) {
                let (a, b) = (at(&pair[0]), at(&pair[1]));
                c.line(a, (b.0, a.1), black, 0);
                c.line((b.0, a.1), b, black, 0);
            }
            for p in front {
                let (x, y) = at(p);
                let corners = [
                    (x - 6, y - 6),
                    (x + 6, y - 6),
                    (x + 6, y + 6),
                    (x - 6, y + 6),
                ];
                for k in 0..4 {
                    c.line(corners[k], corners[(k + 1) % 4], black, 0);
                }
            }
            if let Some(first) = front.first() {
                let (x, y) = at(first);
                c.text(
                    x - 10 - Canvas::text_width(label, 2),
                    y - 5,
                    label,
                    2,
                    black,
                );
            }
        }
        c
    }
}
