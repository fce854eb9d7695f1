//! One panel of a figure: the tracks of one kind as the charts the plot's
//! mode asks for (a path; speeds; angle and axis; or channels against
//! time), built before anything is drawn so the figure can size their
//! legends alike.

use crate::chart::{Chart, Line, Marks};
use crate::plot::{MAX_MARKED_KEYS, Mode, NAMES, Plot};
use crate::sample::{Point, angle_axis, at, handles, sample_times, speed};
use crate::select::{Kind, Panel};
use tcb_core::{NamedTrack, TrackData};

/// A panel's tracks over the figure's time range, and how to mark them.
struct View<'a> {
    /// The tracks.
    tracks: &'a [&'a NamedTrack],
    /// The time range (shared by every panel of the figure).
    from: f64,
    to: f64,
    /// Where to sample the lines.
    times: Vec<f64>,
    /// Too many keys in range to mark (motion capture): a line only.
    dense: bool,
    /// Inbetween dots per segment (0 or 1: none).
    inbetweens: usize,
    /// The times outside the tracks' keys.
    shaded: [(f64, f64); 2],
}

impl<'a> View<'a> {
    /// `tracks` over `[from, to]` as `plot` asks.
    fn new(tracks: &'a [&'a NamedTrack], plot: &Plot, (from, to): (f64, f64)) -> Self {
        let first = tracks
            .iter()
            .map(|t| t.data.times()[0])
            .fold(f64::INFINITY, f64::min);
        let last = tracks
            .iter()
            .map(|t| *t.data.times().last().expect("tracks have keys"))
            .fold(f64::NEG_INFINITY, f64::max);
        // Dense clips (motion capture: a key per frame) are their own line:
        // marking every key and inbetween would only thicken it into a blob.
        let keys_in_range = tracks
            .iter()
            .map(|t| {
                let keys = t.data.times();
                keys.iter().filter(|k| (from..=to).contains(*k)).count()
            })
            .max()
            .unwrap_or(0);
        let dense = keys_in_range > MAX_MARKED_KEYS;
        let path = matches!(plot.mode, Mode::Path { .. });
        View {
            tracks,
            from,
            to,
            times: sample_times(tracks, from, to, 800),
            dense,
            inbetweens: plot
                .inbetweens
                .unwrap_or(if path && !dense { 8 } else { 0 }),
            shaded: [(f64::NEG_INFINITY, first), (last, f64::INFINITY)],
        }
    }

    /// The times of the inbetweens of the segment `[t0, t1]` inside the range.
    fn inbetween_times(&self, t0: f64, t1: f64) -> impl Iterator<Item = f64> + '_ {
        let n = self.inbetweens;
        (1..n)
            .map(move |j| t0 + (t1 - t0) * j as f64 / n as f64)
            .filter(|s| (self.from..=self.to).contains(s))
    }

    /// Keys inside the range, none when the view is dense.
    fn marked_keys<'k>(&self, keys: &'k [f64]) -> impl Iterator<Item = f64> + 'k {
        let (from, to, dense) = (self.from, self.to, self.dense);
        keys.iter()
            .copied()
            .filter(move |k| !dense && (from..=to).contains(k))
    }

    /// A chart of `lines` and `marks` over the view's time range, shaded
    /// outside the keys.
    fn over_time(
        &self,
        caption: Option<&str>,
        y_desc: &str,
        lines: Vec<Line>,
        marks: Marks,
    ) -> Chart {
        let shaded = self
            .shaded
            .iter()
            .map(|&(a, b)| (a.max(self.from), b.min(self.to)))
            .filter(|(a, b)| a < b)
            .collect();
        Chart {
            caption: caption.map(str::to_string),
            x_desc: "time (s)".into(),
            y_desc: y_desc.into(),
            x: Some((self.from, self.to)),
            shaded,
            lines,
            marks,
            weight: 1,
            ..Chart::default()
        }
    }

    /// Marks at the keys and inbetweens of each track, one per value `f`
    /// gives there, coloured from the track's first channel on.
    fn marks(&self, f: &dyn Fn(&TrackData, f64) -> Vec<f64>) -> Marks {
        let mut marks = Marks::default();
        let mut colour = 0;
        for t in self.tracks {
            let keys = t.data.times();
            for k in self.marked_keys(keys) {
                for (c, y) in f(&t.data, k).into_iter().enumerate() {
                    marks.keys.push((k, y, colour + c));
                }
            }
            for w in keys.windows(2) {
                for s in self.inbetween_times(w[0], w[1]) {
                    for (c, y) in f(&t.data, s).into_iter().enumerate() {
                        marks.inbetweens.push((s, y, colour + c));
                    }
                }
            }
            colour += f(&t.data, keys[0]).len();
        }
        marks
    }
}

/// The charts of `panel` of `plot` over `[from, to]`, the first under
/// `caption`, top to bottom.
pub(crate) fn charts(panel: &Panel, plot: &Plot, caption: &str, range: (f64, f64)) -> Vec<Chart> {
    let view = View::new(&panel.tracks, plot, range);
    match plot.mode {
        Mode::Path { components } => vec![path(&view, caption, components)],
        Mode::Speed => vec![speeds(&view, caption, panel.kind)],
        Mode::Value if panel.kind == Kind::Rotations => angles_and_axes(&view, caption),
        Mode::Value | Mode::Velocity | Mode::Components => {
            vec![channels(&view, caption, plot.mode, panel.kind)]
        }
    }
}

/// Component `b` against component `a` of each vector track, with keys,
/// inbetweens and tangent handles, on equal axes.
fn path(view: &View, caption: &str, [a, b]: [usize; 2]) -> Chart {
    let xy = |data: &TrackData, s: f64| -> Point {
        let v = at(data, s).0;
        (f64::from(v[a]), f64::from(v[b]))
    };
    let mut lines = Vec::new();
    let mut marks = Marks::default();
    for (i, t) in view.tracks.iter().enumerate() {
        lines.push(Line {
            label: t.name.clone(),
            colour: i,
            points: view.times.iter().map(|&s| xy(&t.data, s)).collect(),
        });
        let keys = t.data.times();
        for k in view.marked_keys(keys) {
            let p = xy(&t.data, k);
            marks.keys.push((p.0, p.1, i));
        }
        for w in keys.windows(2) {
            for s in view.inbetween_times(w[0], w[1]) {
                let p = xy(&t.data, s);
                marks.inbetweens.push((p.0, p.1, i));
            }
        }
        if !view.dense {
            let h = handles(&t.data, [a, b], view.from, view.to);
            marks.handles.extend(h.into_iter().map(|(p, q)| (p, q, i)));
        }
    }
    Chart {
        caption: Some(caption.to_string()),
        x_desc: format!("{} (component {})", NAMES[a], NAMES[a]),
        y_desc: format!("{} (component {})", NAMES[b], NAMES[b]),
        equal: true,
        lines,
        marks,
        weight: 1,
        ..Chart::default()
    }
}

/// The speed of each track against time (rotations: angular speed).
fn speeds(view: &View, caption: &str, kind: Kind) -> Chart {
    let lines: Vec<Line> = view
        .tracks
        .iter()
        .enumerate()
        .map(|(i, t)| Line {
            label: format!("speed of {}", t.name),
            colour: i,
            points: view.times.iter().map(|&s| (s, speed(&t.data, s))).collect(),
        })
        .collect();
    let marks = view.marks(&|d, s| vec![speed(d, s)]);
    let y = match kind {
        Kind::Rotations => "angular speed (degrees per second)",
        Kind::Vectors | Kind::Scalars => "speed (value units per second)",
    };
    view.over_time(Some(caption), y, lines, marks)
}

/// Each channel (or its d/dt) against time: vectors' and scalars' values,
/// rotations' four components.
fn channels(view: &View, caption: &str, mode: Mode, kind: Kind) -> Chart {
    let velocity = mode == Mode::Velocity;
    let mut lines = Vec::new();
    let mut colour = 0;
    for t in view.tracks {
        let dim = t.data.kind().dim();
        for c in 0..dim {
            let name = if dim == 1 {
                t.name.clone()
            } else {
                format!("{}.{}", t.name, NAMES[c])
            };
            let points = view
                .times
                .iter()
                .map(|&s| {
                    let (v, d) = at(&t.data, s);
                    (s, f64::from(if velocity { d[c] } else { v[c] }))
                })
                .collect();
            lines.push(Line {
                label: if velocity {
                    format!("d/dt {name}")
                } else {
                    name
                },
                colour: colour + c,
                points,
            });
        }
        colour += dim;
    }
    let marks = view.marks(&|d, s| {
        let (v, dv) = at(d, s);
        let src = if velocity { dv } else { v };
        src[..d.kind().dim()]
            .iter()
            .map(|x| f64::from(*x))
            .collect()
    });
    let y = match (velocity, kind == Kind::Rotations) {
        (true, false) => "d/dt (value units per second)",
        (true, true) => "d/dt of the components (per second)",
        (false, true) => "quaternion components",
        (false, false) => "value",
    };
    view.over_time(Some(caption), y, lines, marks)
}

/// Rotations as their angle (above) and unit axis (below) against time.
fn angles_and_axes(view: &View, caption: &str) -> Vec<Chart> {
    let mut angle = Vec::new();
    let mut axis = Vec::new();
    let n = view.tracks.len();
    for (i, t) in view.tracks.iter().enumerate() {
        let aa: Vec<(f64, (f64, [f64; 3]))> = view
            .times
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
                colour: n + 3 * i + c,
                points: aa.iter().map(|(s, (_, ax))| (*s, ax[c])).collect(),
            });
        }
    }
    let marks = view.marks(&|d, s| vec![angle_axis(at(d, s).0).0]);
    let angles = view.over_time(Some(caption), "rotation angle (degrees)", angle, marks);
    let axes = view.over_time(None, "rotation axis (unit vector)", axis, Marks::default());
    // The angle above, taller for its caption.
    vec![
        Chart {
            weight: 11,
            ..angles
        },
        Chart { weight: 9, ..axes },
    ]
}
