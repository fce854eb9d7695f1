//! Drawing a plot: choose the tracks and their panels, fix the time range,
//! draw each panel.

use crate::plot::{Mode, Plot, PlotError, Rendered, draw, err};
use crate::select::{self, Panel, Selection};
use crate::{chart, legend, panel};
use plotters::prelude::*;
use tcb_core::SourceClip;

/// Draw `plot` of `clip` as an SVG document ([`render_with_notes`] without
/// the notes).
pub fn render(clip: &SourceClip, plot: &Plot) -> Result<String, PlotError> {
    render_with_notes(clip, plot).map(|r| r.svg)
}

/// Draw `plot` of `clip`: choose the tracks and their panels, fix the time
/// range, draw each panel.
pub fn render_with_notes(clip: &SourceClip, plot: &Plot) -> Result<Rendered, PlotError> {
    let Selection { panels, notes } = select::select(clip, plot)?;
    let range = time_range(&panels, plot)?;
    let svg = figure(&panels, plot, range)?;
    Ok(Rendered { svg, notes })
}

/// The time range every panel shares: `plot`'s, or the keys' (15% wider
/// each side but for paths).
fn time_range(panels: &[Panel], plot: &Plot) -> Result<(f64, f64), PlotError> {
    let tracks = panels.iter().flat_map(|p| &p.tracks);
    let first = tracks
        .clone()
        .map(|t| t.data.times()[0])
        .fold(f64::INFINITY, f64::min);
    let last = tracks
        .map(|t| *t.data.times().last().expect("tracks have keys"))
        .fold(f64::NEG_INFINITY, f64::max);
    let margin = match plot.mode {
        Mode::Path { .. } => 0.0,
        _ => 0.15 * (last - first),
    };
    let from = plot.from.unwrap_or(first - margin);
    let to = plot.to.unwrap_or(last + margin);
    if !(from.is_finite() && to.is_finite()) || from >= to {
        return err(format!(
            "the time range {from} to {to} is empty (--from must be below --to)"
        ));
    }
    Ok((from, to))
}

/// The figure's title: `plot`'s, then the tracks' names when it asks and
/// there is one panel (several are captioned by kind instead), or their
/// number where the names would not fit (about 9 pixels a character).
fn title(panels: &[Panel], plot: &Plot) -> String {
    match panels {
        [one] if plot.name_tracks => {
            let names: Vec<&str> = one.tracks.iter().map(|t| t.name.as_str()).collect();
            let named = format!("{}: {}", plot.title, names.join(", "));
            if named.chars().count() * 9 <= plot.size.0 as usize {
                named
            } else {
                format!("{}: {} tracks", plot.title, names.len())
            }
        }
        _ => plot.title.clone(),
    }
}

/// The SVG: one panel a kind, stacked under the title, every legend as
/// wide as the widest so the panels' axes line up.
fn figure(panels: &[Panel], plot: &Plot, range: (f64, f64)) -> Result<String, PlotError> {
    let (w, h) = plot.size;
    let title = title(panels, plot);
    let several = panels.len() > 1;
    let charts: Vec<Vec<chart::Chart>> = panels
        .iter()
        .map(|p| {
            // Small multiples (one track a panel, as paths are) are
            // captioned by their track.
            let caption = match (several, p.tracks.as_slice()) {
                (false, _) => title.as_str(),
                (true, [one]) if matches!(plot.mode, Mode::Path { .. }) => one.name.as_str(),
                (true, _) => p.kind.caption(),
            };
            panel::charts(p, plot, caption, range)
        })
        .collect();
    let legend_width = charts
        .iter()
        .flatten()
        .map(|c| legend::width(&c.legend(), w * 2 / 5))
        .max()
        .unwrap_or(0);
    let height = h * panels.len() as u32 + if several { 36 } else { 0 };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, height)).into_drawing_area();
        draw(root.fill(&WHITE))?;
        let body = if several {
            draw(root.titled(&title, ("sans-serif", 20)))?
        } else {
            root.clone()
        };
        for (area, charts) in body.split_evenly((panels.len(), 1)).iter().zip(&charts) {
            let total: u32 = charts.iter().map(|c| c.weight).sum();
            let (_, ph) = area.dim_in_pixel();
            let mut rest = area.clone();
            for c in charts {
                let (this, below) = rest.split_vertically(ph * c.weight / total.max(1));
                c.draw(&this, legend_width)?;
                rest = below;
            }
        }
        draw(root.present())?;
    }
    Ok(svg)
}
