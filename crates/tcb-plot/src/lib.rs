//! # tcb-plot
//!
//! SVG pictures of clips, drawn with `plotters` (pure Rust; text is left as
//! SVG `<text>` for the viewer to set, so no system fonts are needed):
//!
//! - value against time for each channel of the chosen tracks, keys marked
//!   and the extrapolation regions (outside the keys) shaded;
//! - velocity (d/dt per channel) or speed (the length of a vector track's
//!   velocity; angular speed for rotations);
//! - the 2D path of vector tracks (two chosen components), with keys,
//!   tangent handles and inbetween dots at equal time steps, so that their
//!   spacing shows speed, as in Kochanek and Bartels' figures;
//! - rotations as their angle and axis over time, or their 4 components.
//!
//! Any clip can be drawn: each kind of track (vectors, rotations, scalars)
//! gets a panel of its own, a mode skips the tracks it cannot draw
//! ([`Rendered::notes`] names them), and legends sit in a column beside
//! the charts, never over a curve.
//!
//! `tcb plot` and `tcb figures` are the command-line front ends; [`figures`]
//! lists the figures committed under `docs/figures/`.
//!
//! ```
//! let clip = tcb_io::ClipDoc::parse(r#"{"format": "tcb-clip/1", "tracks": [
//!   {"name": "ball.path", "kind": "vec2", "times": [0, 1, 2],
//!    "values": [[0, 0], [1, 2], [3, 0]]}]}"#)?.build()?;
//! let plot = tcb_plot::Plot {
//!     mode: tcb_plot::Mode::Path { components: [0, 1] },
//!     ..tcb_plot::Plot::new("ball")
//! };
//! let svg = tcb_plot::render(&clip, &plot)?;
//! assert!(svg.starts_with("<svg") && svg.contains("ball.path"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![forbid(unsafe_code)]

use plotters::prelude::*;
use std::fmt;
use tcb_core::Clip;
use tcb_core::skeleton::Skeleton;

mod chart;
mod figures;
mod legend;
mod panel;
mod sample;
mod select;
pub use figures::{Figure, figures};
use select::{Panel, Selection};

/// What to draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    /// Value against time (rotations: angle and axis).
    Value,
    /// Rotations: their 4 components against time.
    Components,
    /// d/dt of each channel against time.
    Velocity,
    /// Length of the velocity of each track (rotations: angular speed).
    Speed,
    /// Component `components[1]` against `components[0]` of each vector
    /// track, with keys, tangent handles and inbetweens.
    Path {
        /// The two components (0 = x, 1 = y, 2 = z, 3 = w).
        components: [usize; 2],
    },
}

/// A plot of some tracks of a clip.
#[derive(Clone, Debug)]
pub struct Plot {
    /// Track names; empty: of each kind (vectors, rotations, scalars) the
    /// first tracks up to 16 channels. Tracks the mode cannot draw are
    /// skipped ([`Rendered::notes`] says which); each kind gets a panel.
    pub tracks: Vec<String>,
    /// Start of the time range (default: the first key, minus 15% of the
    /// keys' span outside `Path`).
    pub from: Option<f64>,
    /// End of the time range (default: the last key, plus 15%).
    pub to: Option<f64>,
    /// What to draw.
    pub mode: Mode,
    /// Inbetween dots per segment, at equal time steps (default: 8 for
    /// `Path`, none otherwise; none for a track with more than
    /// [`MAX_MARKED_KEYS`] keys in range, whose keys are not marked either).
    pub inbetweens: Option<usize>,
    /// The title (for example the file's name).
    pub title: String,
    /// Whether the title goes on with the names of the tracks drawn.
    pub name_tracks: bool,
    /// Width and height of one panel in pixels (a figure of several
    /// panels stacks them under one title).
    pub size: (u32, u32),
}

impl Plot {
    /// Values against time of the default tracks, 900 x 560, titled `title`.
    pub fn new(title: impl Into<String>) -> Self {
        Plot {
            tracks: Vec::new(),
            from: None,
            to: None,
            mode: Mode::Value,
            inbetweens: None,
            title: title.into(),
            name_tracks: true,
            size: (900, 560),
        }
    }
}

/// A drawn plot and what the user should know about it.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendered {
    /// The SVG document.
    pub svg: String,
    /// One line each: tracks skipped because the mode cannot draw them,
    /// tracks left out of the default choice.
    pub notes: Vec<String>,
}

/// Why a plot cannot be drawn: one line for the user.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotError(pub String);

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PlotError {}

fn err<T>(m: impl Into<String>) -> Result<T, PlotError> {
    Err(PlotError(m.into()))
}

/// Component names, by index.
const NAMES: [&str; 4] = ["x", "y", "z", "w"];

/// Above this many keys of one track in the time range, keys are not
/// marked, tangent handles are not drawn and inbetweens are off by default
/// (motion capture).
pub const MAX_MARKED_KEYS: usize = 300;

/// Draw `plot` of `clip` as an SVG document ([`render_with_notes`] without
/// the notes).
pub fn render(clip: &Clip, plot: &Plot) -> Result<String, PlotError> {
    render_with_notes(clip, plot).map(|r| r.svg)
}

/// Draw `plot` of `clip`: choose the tracks and their panels, fix the time
/// range, draw each panel.
pub fn render_with_notes(clip: &Clip, plot: &Plot) -> Result<Rendered, PlotError> {
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
            let caption = if several { p.kind.caption() } else { &title };
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

/// The two components of a rig's ground plane, which `tcb plot --path`
/// draws by default: x and z for a Y-up rig (glTF's axes, and those of BVH
/// captures), x and y for a Z-up one. Up is whichever of y and z the rest
/// pose's joints spread along more (x runs across the body in both).
pub fn ground_plane(skeleton: &Skeleton) -> [usize; 2] {
    let n = skeleton.joints.len();
    let local: Vec<_> = skeleton.joints.iter().map(|j| j.rest).collect();
    let mut model = vec![glam::Affine3A::IDENTITY; n];
    skeleton.model_transforms(&local, &mut model);
    let extent = |axis: usize| {
        let v = model.iter().map(|m| m.translation[axis]);
        v.clone().fold(f32::NEG_INFINITY, f32::max) - v.fold(f32::INFINITY, f32::min)
    };
    if n > 0 && extent(2) > extent(1) {
        [0, 1]
    } else {
        [0, 2]
    }
}

/// The drawing errors of plotters, as ours.
fn draw<T, E: fmt::Debug>(r: Result<T, E>) -> Result<T, PlotError> {
    r.map_err(|e| PlotError(format!("drawing the plot: {e:?}")))
}

/// Components by name: `x,y`, `x,z`, ... for `--components`.
pub fn parse_components(s: &str) -> Result<[usize; 2], PlotError> {
    let idx = |c: &str| NAMES.iter().position(|n| *n == c.trim());
    match s.split_once(',') {
        Some((a, b)) => match (idx(a), idx(b)) {
            (Some(a), Some(b)) if a != b => Ok([a, b]),
            _ => err(format!(
                "--components {s}: two different components of x, y, z, w (for example x,z)"
            )),
        },
        None => err(format!(
            "--components {s}: two different components of x, y, z, w (for example x,z)"
        )),
    }
}
