//! What a plot is asked for, and why it cannot be drawn.

use std::fmt;
use tcb_core::skeleton::Skeleton;

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

pub(crate) fn err<T>(m: impl Into<String>) -> Result<T, PlotError> {
    Err(PlotError(m.into()))
}

/// Component names, by index.
pub(crate) const NAMES: [&str; 4] = ["x", "y", "z", "w"];

/// Above this many keys of one track in the time range, keys are not
/// marked, tangent handles are not drawn and inbetweens are off by default
/// (motion capture).
pub const MAX_MARKED_KEYS: usize = 300;

/// The two components of a rig's ground plane, which `tcb plot --path`
/// draws by default: x and z for a Y-up rig (glTF's axes, and those of BVH
/// captures), x and y for a Z-up one. Up is whichever of y and z the rest
/// pose's joints spread along more (x runs across the body in both).
pub fn ground_plane(skeleton: &Skeleton) -> [usize; 2] {
    let n = skeleton.joints().len();
    let local: Vec<_> = skeleton.joints().iter().map(|j| j.rest).collect();
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
pub(crate) fn draw<T, E: fmt::Debug>(r: Result<T, E>) -> Result<T, PlotError> {
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
