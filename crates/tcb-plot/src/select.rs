//! Which tracks a plot draws, and in which panel: the tracks asked for (or
//! by default the first of each kind), less those the mode cannot draw,
//! grouped by kind (vectors, rotations, scalars: one panel each).

use crate::plot::{Mode, NAMES, Plot, PlotError};
use tcb_core::{NamedTrack, SourceClip, TrackKind};

/// The kinds that share a panel: their values share units and a drawing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Kind {
    /// `vec2`, `vec3`, `vec4`.
    Vectors,
    /// `quat`.
    Rotations,
    /// `scalar`.
    Scalars,
}

impl Kind {
    /// The panel a track of `kind` goes to.
    fn of(kind: TrackKind) -> Kind {
        match kind {
            TrackKind::Quat => Kind::Rotations,
            TrackKind::Scalar => Kind::Scalars,
            TrackKind::Vec2 | TrackKind::Vec3 | TrackKind::Vec4 => Kind::Vectors,
        }
    }

    /// The panel's caption in a figure of several.
    pub(crate) fn caption(self) -> &'static str {
        match self {
            Kind::Vectors => "vector tracks",
            Kind::Rotations => "rotation tracks",
            Kind::Scalars => "scalar tracks",
        }
    }
}

/// One panel: tracks of one kind.
pub(crate) struct Panel<'a> {
    /// Their kind.
    pub kind: Kind,
    /// The tracks, in the order asked (or the clip's).
    pub tracks: Vec<&'a NamedTrack>,
}

/// What a plot draws, and what to tell the user about it.
pub(crate) struct Selection<'a> {
    /// The panels, vectors first, then rotations, then scalars.
    pub panels: Vec<Panel<'a>>,
    /// One line each: tracks skipped, tracks left out of a default choice.
    pub notes: Vec<String>,
}

/// Channels a panel draws when no track is named (a kind with more gets
/// its first tracks up to this many, at least one).
const DEFAULT_CHANNELS: usize = 16;

/// The tracks `plot` draws from `clip`, grouped into panels.
pub(crate) fn select<'a>(clip: &'a SourceClip, plot: &Plot) -> Result<Selection<'a>, PlotError> {
    if clip.tracks().is_empty() {
        return Err(PlotError("the clip has no tracks".into()));
    }
    let asked: Vec<&NamedTrack> = if plot.tracks.is_empty() {
        clip.tracks().iter().collect()
    } else {
        plot.tracks
            .iter()
            .map(|name| named(clip, name))
            .collect::<Result<_, _>>()?
    };
    let (drawable, skipped): (Vec<_>, Vec<_>) = asked
        .into_iter()
        .partition(|t| unfit(plot.mode, t).is_none());
    if drawable.is_empty() {
        return Err(PlotError(format!(
            "{}; {}",
            needs(plot.mode),
            reasons(plot.mode, &skipped)
        )));
    }
    let mut notes = Vec::new();
    if !skipped.is_empty() {
        notes.push(format!(
            "{}; skipping {}",
            needs(plot.mode),
            listed(&skipped)
        ));
    }
    let mut panels = by_kind(drawable);
    if plot.tracks.is_empty() {
        notes.extend(keep_first(&mut panels));
    }
    if matches!(plot.mode, Mode::Path { .. }) {
        panels = one_per_track(panels);
    }
    Ok(Selection { panels, notes })
}

/// The track called `name`, or an error listing what the clip has.
fn named<'a>(clip: &'a SourceClip, name: &str) -> Result<&'a NamedTrack, PlotError> {
    clip.tracks()
        .iter()
        .find(|t| t.name == name)
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
}

/// What `mode` draws, as the start of a message about tracks it cannot.
fn needs(mode: Mode) -> String {
    match mode {
        Mode::Path { components: [a, b] } => format!(
            "--path draws two components ({}, {}) of a vector track",
            NAMES[a], NAMES[b]
        ),
        Mode::Components => "--components draws rotation tracks".into(),
        Mode::Value | Mode::Velocity | Mode::Speed => "every track can be drawn".into(),
    }
}

/// Why `mode` cannot draw `track` (`None`: it can).
fn unfit(mode: Mode, track: &NamedTrack) -> Option<String> {
    let kind = track.data.kind();
    let dim = kind.dim();
    let fits = match mode {
        Mode::Path { components: [a, b] } => kind != TrackKind::Quat && a.max(b) < dim,
        Mode::Components => kind == TrackKind::Quat,
        Mode::Value | Mode::Velocity | Mode::Speed => true,
    };
    let s = if dim == 1 { "" } else { "s" };
    (!fits).then(|| format!("'{}' is {kind} ({dim} component{s})", track.name))
}

/// Why each of `tracks` cannot be drawn, the first three in full.
fn reasons(mode: Mode, tracks: &[&NamedTrack]) -> String {
    let mut out: Vec<String> = tracks
        .iter()
        .take(3)
        .filter_map(|t| unfit(mode, t))
        .collect();
    if tracks.len() > 3 {
        out.push(format!("and {} more", tracks.len() - 3));
    }
    out.join(", ")
}

/// `tracks` named (up to three) or counted by kind.
fn listed(tracks: &[&NamedTrack]) -> String {
    if tracks.len() <= 3 {
        let names: Vec<String> = tracks
            .iter()
            .map(|t| format!("'{}' ({})", t.name, t.data.kind()))
            .collect();
        return names.join(", ");
    }
    let mut counts: Vec<String> = Vec::new();
    for kind in TrackKind::ALL {
        let n = tracks.iter().filter(|t| t.data.kind() == kind).count();
        if n > 0 {
            counts.push(format!("{n} {kind} track{}", if n == 1 { "" } else { "s" }));
        }
    }
    counts.join(", ")
}

/// `tracks` as panels, one per kind present, in [`Kind`]'s order.
fn by_kind(tracks: Vec<&NamedTrack>) -> Vec<Panel<'_>> {
    let mut panels: Vec<Panel> = Vec::new();
    for t in tracks {
        let kind = Kind::of(t.data.kind());
        match panels.iter_mut().find(|p| p.kind == kind) {
            Some(p) => p.tracks.push(t),
            None => panels.push(Panel {
                kind,
                tracks: vec![t],
            }),
        }
    }
    panels.sort_by_key(|p| p.kind);
    panels
}

/// A panel per track (paths: several drawn on one pair of axes hide each
/// other where they run close, as the careen figure's three did).
fn one_per_track(panels: Vec<Panel<'_>>) -> Vec<Panel<'_>> {
    panels
        .into_iter()
        .flat_map(|p| {
            p.tracks.into_iter().map(move |t| Panel {
                kind: p.kind,
                tracks: vec![t],
            })
        })
        .collect()
}

/// Each panel's first tracks up to [`DEFAULT_CHANNELS`] channels (at
/// least one), and a note naming what was left out.
fn keep_first(panels: &mut [Panel]) -> Option<String> {
    let mut left_out = Vec::new();
    for p in panels {
        let total = p.tracks.len();
        let mut channels = 0;
        let keep = p
            .tracks
            .iter()
            .take_while(|t| {
                channels += t.data.kind().dim();
                channels <= DEFAULT_CHANNELS
            })
            .count()
            .max(1);
        if keep < total {
            p.tracks.truncate(keep);
            let kind = p.kind.caption();
            left_out.push(format!("the first {keep} of {total} {kind}"));
        }
    }
    (!left_out.is_empty()).then(|| {
        format!(
            "plotting {} (choose others with --track)",
            left_out.join(" and ")
        )
    })
}
