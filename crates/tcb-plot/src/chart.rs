//! One chart: its lines, key and inbetween marks, tangent handles and
//! shaded regions on axes fitted to them, with its legend beside it.

use crate::legend::{self, Entry, Glyph};
use crate::plot::{PlotError, draw};
use crate::sample::Point;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Distinct colours, in order.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];
const SHADE: RGBColor = RGBColor(232, 232, 232);
const HANDLE: RGBColor = RGBColor(110, 110, 110);

/// Colour number `i`, the palette repeating.
fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// One drawn line: label, colour index, points.
pub(crate) struct Line {
    /// The legend's label.
    pub label: String,
    /// Index into the palette.
    pub colour: usize,
    /// The points, in order.
    pub points: Vec<Point>,
}

/// Marks on a line: keys (filled) and inbetweens (open), each with its
/// line's colour index, and tangent handles.
#[derive(Default)]
pub(crate) struct Marks {
    /// Keys: x, y, colour.
    pub keys: Vec<(f64, f64, usize)>,
    /// Inbetweens: x, y, colour.
    pub inbetweens: Vec<(f64, f64, usize)>,
    /// Tangent handles: from, to, colour.
    pub handles: Vec<(Point, Point, usize)>,
}

/// One chart, ready to draw: its text, axes, lines and marks.
#[derive(Default)]
pub(crate) struct Chart {
    /// Caption above the chart, if any.
    pub caption: Option<String>,
    /// The x axis's description.
    pub x_desc: String,
    /// The y axis's description.
    pub y_desc: String,
    /// The x range (default: fitted to the data).
    pub x: Option<(f64, f64)>,
    /// Regions of x to shade (the times outside the keys), inside `x`.
    pub shaded: Vec<(f64, f64)>,
    /// The same scale on both axes, so a path keeps its shape.
    pub equal: bool,
    /// The lines.
    pub lines: Vec<Line>,
    /// Keys, inbetweens, handles.
    pub marks: Marks,
    /// Its share of its panel's height, against the panel's other charts.
    pub weight: u32,
}

/// Pixels around the plotting area: margin, x labels, y labels.
const MARGIN: u32 = 12;
const X_LABELS: u32 = 40;
const Y_LABELS: u32 = 62;

/// The x and y ranges that hold every point with a margin.
fn bounds(lines: &[Line], marks: &Marks, x: Option<(f64, f64)>) -> ((f64, f64), (f64, f64)) {
    let mut xs = (f64::INFINITY, f64::NEG_INFINITY);
    let mut ys = (f64::INFINITY, f64::NEG_INFINITY);
    let mut add = |p: Point| {
        if p.0.is_finite() && p.1.is_finite() {
            xs = (xs.0.min(p.0), xs.1.max(p.0));
            ys = (ys.0.min(p.1), ys.1.max(p.1));
        }
    };
    for l in lines {
        l.points.iter().copied().for_each(&mut add);
    }
    for (x, y, _) in marks.keys.iter().chain(&marks.inbetweens) {
        add((*x, *y));
    }
    for (a, b, _) in &marks.handles {
        add(*a);
        add(*b);
    }
    let pad = |(lo, hi): (f64, f64), frac: f64| {
        if !lo.is_finite() {
            return (-1.0, 1.0);
        }
        let span = hi - lo;
        if span <= 1e-9 * lo.abs().max(hi.abs()).max(1e-9) {
            (lo - 1.0, hi + 1.0)
        } else {
            (lo - frac * span, hi + frac * span)
        }
    };
    (x.unwrap_or_else(|| pad(xs, 0.04)), pad(ys, 0.08))
}

/// `(xr, yr)` widened so one unit is as many pixels on both axes of a
/// plotting area `w` by `h` pixels.
fn equal_scale(xr: (f64, f64), yr: (f64, f64), (w, h): (u32, u32)) -> ((f64, f64), (f64, f64)) {
    let (pw, ph) = (
        f64::from(w.saturating_sub(2 * MARGIN + Y_LABELS).max(1)),
        f64::from(h.saturating_sub(2 * MARGIN + X_LABELS).max(1)),
    );
    let s = ((xr.1 - xr.0) / pw).max((yr.1 - yr.0) / ph);
    let grow = |r: (f64, f64), px: f64| {
        let c = 0.5 * (r.0 + r.1);
        (c - 0.5 * s * px, c + 0.5 * s * px)
    };
    (grow(xr, pw), grow(yr, ph))
}

/// The legend's entries, in the order drawn: shade, lines, handles,
/// inbetweens, keys.
fn entries(lines: &[Line], marks: &Marks, shaded: bool) -> Vec<Entry> {
    let mut out = Vec::new();
    if shaded {
        out.push(Entry {
            glyph: Glyph::Shade(SHADE),
            label: "outside the keys (extrapolation)".into(),
        });
    }
    for l in lines {
        out.push(Entry {
            glyph: Glyph::Line(colour(l.colour), 2),
            label: l.label.clone(),
        });
    }
    if !marks.handles.is_empty() {
        out.push(Entry {
            glyph: Glyph::Line(HANDLE, 1),
            label: "tangent handles (tangent / 3)".into(),
        });
    }
    if !marks.inbetweens.is_empty() {
        out.push(Entry {
            glyph: Glyph::Ring,
            label: "inbetweens (equal time steps)".into(),
        });
    }
    if !marks.keys.is_empty() {
        out.push(Entry {
            glyph: Glyph::Dot,
            label: "keys".into(),
        });
    }
    out
}

impl Chart {
    /// Its legend's entries.
    pub(crate) fn legend(&self) -> Vec<Entry> {
        entries(&self.lines, &self.marks, !self.shaded.is_empty())
    }

    /// Draw it on `area`: the caption, then the plot with its legend in a
    /// column `legend_width` pixels wide at its right.
    pub(crate) fn draw(
        &self,
        area: &DrawingArea<SVGBackend, Shift>,
        legend_width: u32,
    ) -> Result<(), PlotError> {
        let area = match &self.caption {
            Some(c) => draw(area.titled(c, ("sans-serif", 18)))?,
            None => area.clone(),
        };
        let (w, _) = area.dim_in_pixel();
        let (plot_area, legend_area) = area.split_horizontally(w.saturating_sub(legend_width));
        let (xr, yr) = bounds(&self.lines, &self.marks, self.x);
        let (xr, yr) = if self.equal {
            equal_scale(xr, yr, plot_area.dim_in_pixel())
        } else {
            (xr, yr)
        };
        self.plot(&plot_area, (xr, yr))?;
        legend::draw_legend(&legend_area, &self.legend(), MARGIN as i32)
    }

    /// The plotting area itself: mesh, shaded regions, lines, handles, marks.
    fn plot(
        &self,
        area: &DrawingArea<SVGBackend, Shift>,
        (xr, yr): ((f64, f64), (f64, f64)),
    ) -> Result<(), PlotError> {
        let (lines, marks) = (&self.lines, &self.marks);
        let mut ch = draw(
            ChartBuilder::on(area)
                .margin(MARGIN)
                .x_label_area_size(X_LABELS)
                .y_label_area_size(Y_LABELS)
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1),
        )?;
        draw(
            ch.configure_mesh()
                .x_desc(&self.x_desc)
                .y_desc(&self.y_desc)
                .light_line_style(RGBColor(245, 245, 245))
                .draw(),
        )?;
        draw(
            ch.draw_series(
                self.shaded
                    .iter()
                    .map(|&(a, b)| Rectangle::new([(a, yr.0), (b, yr.1)], SHADE.mix(0.7).filled())),
            ),
        )?;
        for l in lines {
            let c = colour(l.colour);
            draw(ch.draw_series(LineSeries::new(l.points.iter().copied(), c.stroke_width(2))))?;
        }
        let faint = |c: usize| colour(c).mix(0.55);
        draw(
            ch.draw_series(
                marks
                    .handles
                    .iter()
                    .map(|(a, b, c)| PathElement::new(vec![*a, *b], faint(*c).stroke_width(1))),
            ),
        )?;
        draw(
            ch.draw_series(
                marks
                    .handles
                    .iter()
                    .map(|(_, b, c)| Circle::new(*b, 2, faint(*c).filled())),
            ),
        )?;
        draw(
            ch.draw_series(
                marks
                    .inbetweens
                    .iter()
                    .map(|&(x, y, c)| Circle::new((x, y), 2, colour(c).stroke_width(1))),
            ),
        )?;
        draw(
            ch.draw_series(
                marks
                    .keys
                    .iter()
                    .map(|&(x, y, c)| Circle::new((x, y), 4, colour(c).filled())),
            ),
        )?;
        Ok(())
    }
}
