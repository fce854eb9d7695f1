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

use plotters::coord::Shift;
use plotters::prelude::*;
use std::fmt;
use tcb_core::{Clip, NamedTrack, TrackData, TrackKind};

mod figures;
pub use figures::{Figure, figures};

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
    /// Track names; empty: every track if they have at most 16 channels,
    /// else the first.
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
    /// Width and height in pixels.
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

/// The drawing errors of plotters, as ours.
fn draw<T, E: fmt::Debug>(r: Result<T, E>) -> Result<T, PlotError> {
    r.map_err(|e| PlotError(format!("drawing the plot: {e:?}")))
}

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
const NAMES: [&str; 4] = ["x", "y", "z", "w"];

/// Above this many keys of one track in the time range, keys are not
/// marked, tangent handles are not drawn and inbetweens are off by default
/// (motion capture).
pub const MAX_MARKED_KEYS: usize = 300;

/// The tracks a plot draws, checked.
fn chosen<'a>(clip: &'a Clip, plot: &Plot) -> Result<Vec<&'a NamedTrack>, PlotError> {
    if clip.tracks().is_empty() {
        return err("the clip has no tracks");
    }
    if plot.tracks.is_empty() {
        let channels: usize = clip.tracks().iter().map(|t| t.data.kind().dim()).sum();
        return Ok(if channels <= 16 {
            clip.tracks().iter().collect()
        } else {
            vec![&clip.tracks()[0]]
        });
    }
    plot.tracks
        .iter()
        .map(|name| {
            clip.tracks()
                .iter()
                .find(|t| t.name == *name)
                .ok_or_else(|| {
                    let all: Vec<&str> = clip
                        .tracks()
                        .iter()
                        .take(12)
                        .map(|t| t.name.as_str())
                        .collect();
                    let more = if clip.tracks().len() > 12 {
                        ", ..."
                    } else {
                        ""
                    };
                    PlotError(format!(
                        "no track '{name}' (the clip has: {}{more})",
                        all.join(", ")
                    ))
                })
        })
        .collect()
}

/// Sample times over `[a, b]`: `n` even steps plus every key inside, so
/// corners (continuity -1, steps) are drawn sharp.
fn sample_times(tracks: &[&NamedTrack], a: f64, b: f64, n: usize) -> Vec<f64> {
    let mut t: Vec<f64> = (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
    for tr in tracks {
        for &k in tr.data.times() {
            if k > a && k < b {
                // Both sides of a key, for steps.
                t.push(k);
                t.push(k - (b - a) * 1e-7);
            }
        }
    }
    t.sort_by(f64::total_cmp);
    t.dedup();
    t
}

/// Value and velocity of a track at `t` (4 slots; `dim` used).
fn at(data: &TrackData, t: f64) -> ([f32; 4], [f32; 4]) {
    let (mut v, mut d) = ([0.0f32; 4], [0.0f32; 4]);
    let dim = data.kind().dim();
    data.sample_into(t, &mut v[..dim], Some(&mut d[..dim]));
    (v, d)
}

/// A rotation's angle (degrees, 0 to 180) and unit axis, from its `log`
/// on the `w >= 0` hemisphere (`v th/2`).
fn angle_axis(q: [f32; 4]) -> (f64, [f64; 3]) {
    let q = glam::Quat::from_array(q).as_dquat();
    let log = tcb_core::rotation::quat_log(if q.w < 0.0 { -q } else { q });
    let half = log.length();
    let axis = if half > 1e-12 {
        (log / half).to_array()
    } else {
        [0.0; 3]
    };
    ((2.0 * half).to_degrees(), axis)
}

/// Angular speed (degrees per second) of a unit quaternion with component
/// derivative `d` ([`tcb_core::quat::angular_velocity`]).
fn angular_speed(q: [f32; 4], d: [f32; 4]) -> f64 {
    let w = tcb_core::quat::angular_velocity(&q.map(f64::from), &d.map(f64::from));
    glam::DVec3::from_array(w).length().to_degrees()
}

/// The speed of a track at `t`: the length of its velocity, or for a
/// rotation its angular speed in degrees per second.
fn speed(data: &TrackData, t: f64) -> f64 {
    let (v, d) = at(data, t);
    if data.kind() == TrackKind::Quat {
        angular_speed(v, d)
    } else {
        d.iter().map(|x| f64::from(*x).powi(2)).sum::<f64>().sqrt()
    }
}

/// One drawn line: label, colour index, points.
struct Line {
    label: String,
    colour: usize,
    points: Vec<(f64, f64)>,
}

/// A point of a chart.
type Point = (f64, f64);

/// Marks on a line: keys (filled) and inbetweens (open).
#[derive(Default)]
struct Marks {
    keys: Vec<(f64, f64, usize)>,
    inbetweens: Vec<(f64, f64, usize)>,
    /// Tangent handles: from, to, colour.
    handles: Vec<(Point, Point, usize)>,
}

fn bounds(
    lines: &[Line],
    marks: &Marks,
    x: Option<(f64, f64)>,
    legend: usize,
) -> ((f64, f64), (f64, f64)) {
    let mut xs = (f64::INFINITY, f64::NEG_INFINITY);
    let mut ys = (f64::INFINITY, f64::NEG_INFINITY);
    let mut add = |p: (f64, f64)| {
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
    // Room above the data for the legend (about 4% of the height a line).
    let ys = pad(ys, 0.08);
    let room = (0.04 * legend as f64).min(0.6);
    let ys = (ys.0, ys.1 + (ys.1 - ys.0) * room / (1.0 - room));
    (x.unwrap_or_else(|| pad(xs, 0.04)), ys)
}

/// One chart: lines, marks, shaded time regions, on `area`.
#[allow(clippy::too_many_arguments)]
fn chart(
    area: &DrawingArea<SVGBackend, Shift>,
    caption: Option<&str>,
    x_desc: &str,
    y_desc: &str,
    lines: &[Line],
    marks: &Marks,
    x: Option<(f64, f64)>,
    shaded: &[(f64, f64)],
    equal_axes: bool,
) -> Result<(), PlotError> {
    let legend = lines.len()
        + usize::from(!marks.keys.is_empty())
        + usize::from(!marks.inbetweens.is_empty())
        + usize::from(!marks.handles.is_empty())
        + usize::from(!shaded.is_empty());
    let (mut xr, mut yr) = bounds(lines, marks, x, legend);
    if equal_axes {
        // The same scale on both axes, so a path keeps its shape.
        let (w, h) = area.dim_in_pixel();
        let (sx, sy) = (
            (xr.1 - xr.0) / f64::from(w - 80),
            (yr.1 - yr.0) / f64::from(h - 70),
        );
        let s = sx.max(sy);
        let grow = |r: (f64, f64), px: f64| {
            let c = 0.5 * (r.0 + r.1);
            (c - 0.5 * s * px, c + 0.5 * s * px)
        };
        xr = grow(xr, f64::from(w - 80));
        yr = grow(yr, f64::from(h - 70));
    }
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(62);
    if let Some(c) = caption {
        builder.caption(c, ("sans-serif", 18));
    }
    let mut ch = draw(builder.build_cartesian_2d(xr.0..xr.1, yr.0..yr.1))?;
    draw(
        ch.configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .light_line_style(RGBColor(245, 245, 245))
            .draw(),
    )?;
    let mut labelled = false;
    for &(a, b) in shaded {
        let (a, b) = (a.max(xr.0), b.min(xr.1));
        if a < b {
            let s = draw(ch.draw_series(std::iter::once(Rectangle::new(
                [(a, yr.0), (b, yr.1)],
                SHADE.mix(0.7).filled(),
            ))))?;
            if !labelled {
                s.label("outside the keys (extrapolation)")
                    .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], SHADE.filled()));
                labelled = true;
            }
        }
    }
    for l in lines {
        let c = PALETTE[l.colour % PALETTE.len()];
        draw(ch.draw_series(LineSeries::new(l.points.iter().copied(), c.stroke_width(2))))?
            .label(l.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2)));
    }
    if !marks.handles.is_empty() {
        let style = |c: usize| PALETTE[c % PALETTE.len()].mix(0.55).stroke_width(1);
        for (i, (a, b, c)) in marks.handles.iter().enumerate() {
            let s =
                draw(ch.draw_series(std::iter::once(PathElement::new(vec![*a, *b], style(*c)))))?;
            if i == 0 {
                s.label("tangent handles (a third of each Hermite tangent)")
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 16, y)], HANDLE.stroke_width(1))
                    });
            }
        }
        draw(
            ch.draw_series(marks.handles.iter().map(|(_, b, c)| {
                Circle::new(*b, 2, PALETTE[c % PALETTE.len()].mix(0.55).filled())
            })),
        )?;
    }
    if !marks.inbetweens.is_empty() {
        draw(ch.draw_series(marks.inbetweens.iter().map(|&(x, y, c)| {
            Circle::new((x, y), 2, PALETTE[c % PALETTE.len()].stroke_width(1))
        })))?
        .label("inbetweens (equal time steps)")
        .legend(|(x, y)| Circle::new((x + 8, y), 2, BLACK.stroke_width(1)));
    }
    if !marks.keys.is_empty() {
        draw(
            ch.draw_series(
                marks
                    .keys
                    .iter()
                    .map(|&(x, y, c)| Circle::new((x, y), 4, PALETTE[c % PALETTE.len()].filled())),
            ),
        )?
        .label("keys")
        .legend(|(x, y)| Circle::new((x + 8, y), 4, BLACK.filled()));
    }
    draw(
        ch.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(200, 200, 200))
            .draw(),
    )?;
    Ok(())
}

/// Draw `plot` of `clip` as an SVG document.
pub fn render(clip: &Clip, plot: &Plot) -> Result<String, PlotError> {
    let tracks = chosen(clip, plot)?;
    let first = tracks
        .iter()
        .map(|t| t.data.times()[0])
        .fold(f64::INFINITY, f64::min);
    let last = tracks
        .iter()
        .map(|t| *t.data.times().last().expect("tracks have keys"))
        .fold(f64::NEG_INFINITY, f64::max);
    let path = matches!(plot.mode, Mode::Path { .. });
    let margin = if path { 0.0 } else { 0.15 * (last - first) };
    let from = plot.from.unwrap_or(first - margin);
    let to = plot.to.unwrap_or(last + margin);
    if !(from.is_finite() && to.is_finite()) || from >= to {
        return err(format!(
            "the time range {from} to {to} is empty (--from must be below --to)"
        ));
    }
    let rotations = tracks
        .iter()
        .filter(|t| t.data.kind() == TrackKind::Quat)
        .count();
    let names: Vec<&str> = tracks.iter().map(|t| t.name.as_str()).collect();
    let title = if plot.name_tracks {
        format!("{}: {}", plot.title, names.join(", "))
    } else {
        plot.title.clone()
    };
    let times = sample_times(&tracks, from, to, 800);
    // Dense clips (motion capture: a key per frame) are their own line:
    // marking every key and inbetween would only thicken it into a blob.
    let keys_in_range = tracks
        .iter()
        .map(|t| {
            t.data
                .times()
                .iter()
                .filter(|k| (from..=to).contains(*k))
                .count()
        })
        .max()
        .unwrap_or(0);
    let dense = keys_in_range > MAX_MARKED_KEYS;
    let inbetweens = plot
        .inbetweens
        .unwrap_or(if path && !dense { 8 } else { 0 });
    let key_marks = |f: &dyn Fn(&TrackData, f64) -> Vec<f64>, marks: &mut Marks| {
        let mut colour = 0;
        for t in &tracks {
            let keys = t.data.times();
            let n = f(&t.data, keys[0]).len();
            for &k in keys.iter().filter(|k| !dense && (from..=to).contains(*k)) {
                for (c, y) in f(&t.data, k).into_iter().enumerate() {
                    marks.keys.push((k, y, colour + c));
                }
            }
            for w in keys.windows(2) {
                for j in 1..inbetweens {
                    let x = w[0] + (w[1] - w[0]) * j as f64 / inbetweens as f64;
                    if (from..=to).contains(&x) {
                        for (c, y) in f(&t.data, x).into_iter().enumerate() {
                            marks.inbetweens.push((x, y, colour + c));
                        }
                    }
                }
            }
            colour += n;
        }
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, plot.size).into_drawing_area();
        draw(root.fill(&WHITE))?;
        let shaded = [(f64::NEG_INFINITY, first), (last, f64::INFINITY)];
        match plot.mode {
            Mode::Path { components } => {
                let [a, b] = components;
                let mut lines = Vec::new();
                let mut marks = Marks::default();
                for (i, t) in tracks.iter().enumerate() {
                    let dim = t.data.kind().dim();
                    if t.data.kind() == TrackKind::Quat || dim < 2 || a.max(b) >= dim {
                        return err(format!(
                            "--path draws two components of a vector track; '{}' is {} ({} component{})",
                            t.name,
                            t.data.kind(),
                            dim,
                            if dim == 1 { "" } else { "s" }
                        ));
                    }
                    let xy = |v: [f32; 4]| (f64::from(v[a]), f64::from(v[b]));
                    lines.push(Line {
                        label: t.name.clone(),
                        colour: i,
                        points: times.iter().map(|&s| xy(at(&t.data, s).0)).collect(),
                    });
                    let keys = t.data.times();
                    for &k in keys.iter().filter(|k| !dense && (from..=to).contains(*k)) {
                        let p = xy(at(&t.data, k).0);
                        marks.keys.push((p.0, p.1, i));
                    }
                    for w in keys.windows(2) {
                        for j in 1..inbetweens {
                            let s = w[0] + (w[1] - w[0]) * j as f64 / inbetweens as f64;
                            if (from..=to).contains(&s) {
                                let p = xy(at(&t.data, s).0);
                                marks.inbetweens.push((p.0, p.1, i));
                            }
                        }
                    }
                    if !dense {
                        marks.handles.extend(
                            handles(&t.data, a, b, from, to)
                                .into_iter()
                                .map(|(p, q)| (p, q, i)),
                        );
                    }
                }
                let x_desc = format!("{} (component {})", NAMES[a], NAMES[a]);
                let y_desc = format!("{} (component {})", NAMES[b], NAMES[b]);
                chart(
                    &root,
                    Some(&title),
                    &x_desc,
                    &y_desc,
                    &lines,
                    &marks,
                    None,
                    &[],
                    true,
                )?;
            }
            // Channels against time: vectors' components, or (velocity,
            // --components) a rotation's four.
            Mode::Value | Mode::Velocity | Mode::Components
                if rotations == 0 || (rotations == tracks.len() && plot.mode != Mode::Value) =>
            {
                let velocity = plot.mode == Mode::Velocity;
                if plot.mode == Mode::Components && rotations == 0 {
                    return err("--components is for rotation tracks");
                }
                let mut lines = Vec::new();
                let mut colour = 0;
                for t in &tracks {
                    let dim = t.data.kind().dim();
                    for c in 0..dim {
                        let label = if dim == 1 {
                            t.name.clone()
                        } else {
                            format!("{}.{}", t.name, NAMES[c])
                        };
                        let points = times
                            .iter()
                            .map(|&s| {
                                let (v, d) = at(&t.data, s);
                                (s, f64::from(if velocity { d[c] } else { v[c] }))
                            })
                            .collect();
                        lines.push(Line {
                            label: if velocity {
                                format!("d/dt {label}")
                            } else {
                                label
                            },
                            colour: colour + c,
                            points,
                        });
                    }
                    colour += dim;
                }
                let mut marks = Marks::default();
                key_marks(
                    &|d, s| {
                        let (v, dv) = at(d, s);
                        let src = if velocity { dv } else { v };
                        src[..d.kind().dim()]
                            .iter()
                            .map(|x| f64::from(*x))
                            .collect()
                    },
                    &mut marks,
                );
                let y = match (velocity, rotations > 0) {
                    (true, false) => "d/dt (value units per second)",
                    (true, true) => "d/dt of the components (per second)",
                    (false, true) => "quaternion components",
                    (false, false) => "value",
                };
                chart(
                    &root,
                    Some(&title),
                    "time (s)",
                    y,
                    &lines,
                    &marks,
                    Some((from, to)),
                    &shaded,
                    false,
                )?;
            }
            Mode::Speed => {
                let mut lines = Vec::new();
                for (i, t) in tracks.iter().enumerate() {
                    let rotation = t.data.kind() == TrackKind::Quat;
                    if rotations > 0 && !rotation {
                        return err("--speed: plot rotations and vectors separately");
                    }
                    lines.push(Line {
                        label: format!("speed of {}", t.name),
                        colour: i,
                        points: times.iter().map(|&s| (s, speed(&t.data, s))).collect(),
                    });
                }
                let mut marks = Marks::default();
                key_marks(&|d, s| vec![speed(d, s)], &mut marks);
                let y = if rotations > 0 {
                    "angular speed (degrees per second)"
                } else {
                    "speed (value units per second)"
                };
                chart(
                    &root,
                    Some(&title),
                    "time (s)",
                    y,
                    &lines,
                    &marks,
                    Some((from, to)),
                    &shaded,
                    false,
                )?;
            }
            Mode::Value | Mode::Velocity | Mode::Components => {
                if rotations != tracks.len() {
                    return err("plot rotations and vectors separately (choose with --track)");
                }
                // Angle above, axis below.
                {
                    let h = plot.size.1;
                    let (top, bottom) = root.split_vertically(h * 11 / 20);
                    let mut angle = Vec::new();
                    let mut axis = Vec::new();
                    for (i, t) in tracks.iter().enumerate() {
                        let aa: Vec<(f64, (f64, [f64; 3]))> = times
                            .iter()
                            .map(|&s| (s, angle_axis(at(&t.data, s).0)))
                            .collect();
                        angle.push(Line {
                            label: format!("angle of {}", t.name),
                            colour: i,
                            points: aa.iter().map(|(s, (a, _))| (*s, *a)).collect(),
                        });
                        for c in 0..3 {
                            axis.push(Line {
                                label: format!("axis.{} of {}", NAMES[c], t.name),
                                colour: tracks.len() + 3 * i + c,
                                points: aa.iter().map(|(s, (_, ax))| (*s, ax[c])).collect(),
                            });
                        }
                    }
                    let mut marks = Marks::default();
                    key_marks(&|d, s| vec![angle_axis(at(d, s).0).0], &mut marks);
                    chart(
                        &top,
                        Some(&title),
                        "time (s)",
                        "rotation angle (degrees)",
                        &angle,
                        &marks,
                        Some((from, to)),
                        &shaded,
                        false,
                    )?;
                    chart(
                        &bottom,
                        None,
                        "time (s)",
                        "rotation axis (unit vector)",
                        &axis,
                        &Marks::default(),
                        Some((from, to)),
                        &shaded,
                        false,
                    )?;
                }
            }
        }
        draw(root.present())?;
    }
    Ok(svg)
}

/// Tangent handles of a vector track's segments inside `[from, to]`, as
/// Bezier control points: `P_k + M0 / 3` and `P_k+1 - M1 / 3`.
fn handles(
    data: &TrackData,
    a: usize,
    b: usize,
    from: f64,
    to: f64,
) -> Vec<((f64, f64), (f64, f64))> {
    fn of<V: tcb_core::Value>(
        t: &tcb_core::Track<V>,
        a: usize,
        b: usize,
        from: f64,
        to: f64,
    ) -> Vec<(Point, Point)> {
        let xy = |v: V| {
            let v = v.to_array();
            (f64::from(v[a]), f64::from(v[b]))
        };
        let mut out = Vec::new();
        for (k, s) in t.segments().iter().enumerate() {
            if s.interp != tcb_core::Interp::Curve {
                continue;
            }
            let (t0, t1) = (t.times()[k], t.times()[k + 1]);
            let (p0, p1, m0, m1) = (xy(s.p0), xy(s.p1), xy(s.m0), xy(s.m1));
            if (from..=to).contains(&t0) {
                out.push((p0, (p0.0 + m0.0 / 3.0, p0.1 + m0.1 / 3.0)));
            }
            if (from..=to).contains(&t1) {
                out.push((p1, (p1.0 - m1.0 / 3.0, p1.1 - m1.1 / 3.0)));
            }
        }
        out
    }
    match data {
        TrackData::Vec2(t) => of(t, a, b, from, to),
        TrackData::Vec3(t) => of(t, a, b, from, to),
        TrackData::Vec4(t) => of(t, a, b, from, to),
        _ => Vec::new(),
    }
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
