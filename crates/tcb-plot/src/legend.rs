//! Legends in a column of their own beside the chart, so they never cover
//! a curve (plotters draws its legend inside the plotting area).

use crate::plot::{PlotError, draw};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// How an entry is drawn before its label.
#[derive(Clone, Copy)]
pub(crate) enum Glyph {
    /// A line of this colour and width.
    Line(RGBColor, u32),
    /// A filled dot (keys).
    Dot,
    /// An open dot (inbetweens).
    Ring,
    /// A shaded box (the regions outside the keys).
    Shade(RGBColor),
}

/// One line of a legend.
pub(crate) struct Entry {
    /// What precedes the label.
    pub glyph: Glyph,
    /// The label.
    pub label: String,
}

/// The label's font size in pixels.
const FONT: u32 = 13;
/// One entry's height in pixels.
const ROW: i32 = 18;
/// Glyph width plus the gaps around it.
const GLYPH: i32 = 30;
/// A sans-serif character's width at [`FONT`], rounded up: plotters
/// writes size 13 as 10.5 pixels in SVG, and the viewer sets the text, so
/// this only sizes the column.
const CHAR: f64 = 6.4;

/// The column's width for `entries`: the longest label, at most `max`.
pub(crate) fn width(entries: &[Entry], max: u32) -> u32 {
    let chars = entries
        .iter()
        .map(|e| e.label.chars().count())
        .max()
        .unwrap_or(0);
    if chars == 0 {
        return 0;
    }
    ((chars as f64 * CHAR) as u32 + GLYPH as u32 + 12).min(max)
}

/// `label` cut to fit `px` pixels, with an ellipsis where it was cut.
fn fitted(label: &str, px: i32) -> String {
    let room = ((px - GLYPH).max(0) as f64 / CHAR) as usize;
    if label.chars().count() <= room {
        return label.to_string();
    }
    let mut out: String = label.chars().take(room.saturating_sub(1)).collect();
    out.push('…');
    out
}

/// Draw `entries` down `area` from `top` pixels, one a row; rows that do
/// not fit end in a line saying how many were left out.
pub(crate) fn draw_legend(
    area: &DrawingArea<SVGBackend, Shift>,
    entries: &[Entry],
    top: i32,
) -> Result<(), PlotError> {
    let (w, h) = area.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let rows = ((h - top) / ROW).max(1) as usize;
    let shown = if entries.len() > rows {
        rows - 1
    } else {
        entries.len()
    };
    let style = ("sans-serif", FONT)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (i, e) in entries.iter().take(shown).enumerate() {
        let y = top + ROW / 2 + ROW * i as i32;
        glyph(area, e.glyph, (4, y))?;
        let label = fitted(&e.label, w - 4);
        draw(area.draw(&Text::new(label, (GLYPH, y), style.clone())))?;
    }
    if shown < entries.len() {
        let y = top + ROW / 2 + ROW * shown as i32;
        let more = format!("… and {} more", entries.len() - shown);
        draw(area.draw(&Text::new(more, (GLYPH, y), style)))?;
    }
    Ok(())
}

/// One glyph, 20 pixels wide from `(x, y)` (its vertical middle).
fn glyph(
    area: &DrawingArea<SVGBackend, Shift>,
    g: Glyph,
    (x, y): (i32, i32),
) -> Result<(), PlotError> {
    match g {
        Glyph::Line(c, width) => draw(area.draw(&PathElement::new(
            vec![(x, y), (x + 20, y)],
            c.stroke_width(width),
        ))),
        Glyph::Dot => draw(area.draw(&Circle::new((x + 10, y), 4, BLACK.filled()))),
        Glyph::Ring => draw(area.draw(&Circle::new((x + 10, y), 2, BLACK.stroke_width(1)))),
        Glyph::Shade(c) => {
            draw(area.draw(&Rectangle::new([(x, y - 6), (x + 20, y + 6)], c.filled())))
        }
    }
}
