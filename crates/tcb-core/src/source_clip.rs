//! The source clip: named tracks of any kind, as a clip file, BVH or glTF
//! describes them, sampled together into flat rows of `f32` channels (the
//! columns of `tcb sample`). What a game plays is the compiled clip,
//! `tcb_runtime::Clip`, built from one.

use crate::params::TrackSettings;
use crate::rotation::RotationTrack;
use crate::track::Track;
use crate::vector::Value;
use glam::{Vec2, Vec3, Vec4};
use std::fmt;

/// What a track's values are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TrackKind {
    /// One number.
    Scalar,
    /// Two components.
    Vec2,
    /// Three components.
    Vec3,
    /// Four components.
    Vec4,
    /// A rotation `[x, y, z, w]`.
    Quat,
}

impl TrackKind {
    /// Every kind.
    pub const ALL: [TrackKind; 5] = [
        TrackKind::Scalar,
        TrackKind::Vec2,
        TrackKind::Vec3,
        TrackKind::Vec4,
        TrackKind::Quat,
    ];

    /// Number of components (channels).
    pub const fn dim(self) -> usize {
        match self {
            TrackKind::Scalar => 1,
            TrackKind::Vec2 => 2,
            TrackKind::Vec3 => 3,
            TrackKind::Vec4 | TrackKind::Quat => 4,
        }
    }

    /// The clip file's name for it.
    pub const fn name(self) -> &'static str {
        match self {
            TrackKind::Scalar => "scalar",
            TrackKind::Vec2 => "vec2",
            TrackKind::Vec3 => "vec3",
            TrackKind::Vec4 => "vec4",
            TrackKind::Quat => "quat",
        }
    }

    /// From the clip file's name.
    pub fn from_name(name: &str) -> Option<Self> {
        TrackKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

impl fmt::Display for TrackKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A built track of any kind.
#[derive(Clone, Debug, PartialEq)]
pub enum TrackData {
    /// `scalar`.
    Scalar(Track<f32>),
    /// `vec2`.
    Vec2(Track<Vec2>),
    /// `vec3`.
    Vec3(Track<Vec3>),
    /// `vec4`.
    Vec4(Track<Vec4>),
    /// `quat`.
    Quat(RotationTrack),
}

impl TrackData {
    /// Its kind.
    pub fn kind(&self) -> TrackKind {
        match self {
            TrackData::Scalar(_) => TrackKind::Scalar,
            TrackData::Vec2(_) => TrackKind::Vec2,
            TrackData::Vec3(_) => TrackKind::Vec3,
            TrackData::Vec4(_) => TrackKind::Vec4,
            TrackData::Quat(_) => TrackKind::Quat,
        }
    }

    /// Key times.
    pub fn times(&self) -> &[f64] {
        match self {
            TrackData::Scalar(t) => t.times(),
            TrackData::Vec2(t) => t.times(),
            TrackData::Vec3(t) => t.times(),
            TrackData::Vec4(t) => t.times(),
            TrackData::Quat(t) => t.times(),
        }
    }

    /// Its settings.
    pub fn settings(&self) -> &TrackSettings {
        match self {
            TrackData::Scalar(t) => t.settings(),
            TrackData::Vec2(t) => t.settings(),
            TrackData::Vec3(t) => t.settings(),
            TrackData::Vec4(t) => t.settings(),
            TrackData::Quat(t) => t.settings(),
        }
    }

    /// Write the value (and velocity, if asked) at `time` into the first
    /// `kind().dim()` entries of `value` (and `velocity`).
    pub fn sample_into(&self, time: f64, value: &mut [f32], velocity: Option<&mut [f32]>) {
        fn put<V: Value>(t: &Track<V>, time: f64, value: &mut [f32], velocity: Option<&mut [f32]>) {
            let (v, d) = t.sample_with_velocity(time);
            value[..V::DIM].copy_from_slice(&v.to_array()[..V::DIM]);
            if let Some(out) = velocity {
                out[..V::DIM].copy_from_slice(&d.to_array()[..V::DIM]);
            }
        }
        match self {
            TrackData::Scalar(t) => put(t, time, value, velocity),
            TrackData::Vec2(t) => put(t, time, value, velocity),
            TrackData::Vec3(t) => put(t, time, value, velocity),
            TrackData::Vec4(t) => put(t, time, value, velocity),
            TrackData::Quat(t) => {
                let (q, d) = t.sample_with_velocity(time);
                value[..4].copy_from_slice(&q.to_array());
                if let Some(out) = velocity {
                    out[..4].copy_from_slice(&d.to_array());
                }
            }
        }
    }
}

/// A track with its name.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedTrack {
    /// Name, unique in its clip (`ball.position`).
    pub name: String,
    /// The track.
    pub data: TrackData,
}

/// The source clip: named, validated tracks sampled together by the scalar
/// reference. `tcb_io::load(path)?.clip` is one; `tcb_runtime::Clip::compile`
/// turns one into the compiled clip that instances play (ozz's raw
/// animation and animation).
///
/// ```
/// use tcb_core::{SourceClip, NamedTrack, Track, TrackData, TrackSettings};
/// let squash = Track::new(vec![0.0, 1.25], vec![1.0f32, 0.6], vec![], &TrackSettings::default()).unwrap();
/// let squash = NamedTrack { name: "ball.squash".into(), data: TrackData::Scalar(squash) };
/// let clip = SourceClip::new("bounce", vec![squash.clone()]).unwrap();
/// // Track names are unique in a clip.
/// assert!(SourceClip::new("bounce", vec![squash.clone(), squash]).is_err());
/// assert_eq!(clip.column_names(), ["ball.squash"]);
/// let mut row = vec![0.0; clip.channel_count()];
/// clip.sample_into(1.25, &mut row, None);
/// assert_eq!(row, [0.6]);
/// ```
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SourceClip {
    name: String,
    tracks: Vec<NamedTrack>,
}

/// A clip [`SourceClip::new`] refuses: two tracks have this name.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DuplicateTrack(pub String);

impl std::fmt::Display for DuplicateTrack {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "two tracks are named '{}'", self.0)
    }
}

impl std::error::Error for DuplicateTrack {}

impl SourceClip {
    /// A clip of `tracks` (file order), whose names must be unique.
    pub fn new(name: impl Into<String>, tracks: Vec<NamedTrack>) -> Result<Self, DuplicateTrack> {
        let mut seen = std::collections::HashSet::new();
        if let Some(t) = tracks.iter().find(|t| !seen.insert(t.name.as_str())) {
            return Err(DuplicateTrack(t.name.clone()));
        }
        Ok(SourceClip {
            name: name.into(),
            tracks,
        })
    }

    /// The clip's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its tracks, in file order.
    pub fn tracks(&self) -> &[NamedTrack] {
        &self.tracks
    }

    /// Its tracks, by value.
    pub fn into_tracks(self) -> Vec<NamedTrack> {
        self.tracks
    }

    /// Total number of `f32` channels (columns after `time`).
    pub fn channel_count(&self) -> usize {
        self.tracks.iter().map(|t| t.data.kind().dim()).sum()
    }

    /// Column names: `<name>` for scalars, `<name>.x` .. `<name>.w` otherwise.
    pub fn column_names(&self) -> Vec<String> {
        let mut out = Vec::with_capacity(self.channel_count());
        for t in &self.tracks {
            match t.data.kind() {
                TrackKind::Scalar => out.push(t.name.clone()),
                kind => {
                    for c in ["x", "y", "z", "w"].iter().take(kind.dim()) {
                        out.push(format!("{}.{c}", t.name));
                    }
                }
            }
        }
        out
    }

    /// Sample every track at `time` into `values` (and `velocities`), each
    /// [`SourceClip::channel_count`] long (shorter slices get the channels that
    /// fit; longer ones keep the rest).
    pub fn sample_into(&self, time: f64, values: &mut [f32], mut velocities: Option<&mut [f32]>) {
        let mut at = 0;
        for t in &self.tracks {
            let dim = t.data.kind().dim();
            let (mut v, mut d) = ([0.0f32; 4], [0.0f32; 4]);
            let want_d = velocities.as_ref().is_some_and(|d| d.len() > at);
            if values.len() <= at && !want_d {
                break;
            }
            t.data
                .sample_into(time, &mut v[..dim], want_d.then_some(&mut d[..dim]));
            let put = |out: Option<&mut [f32]>, from: &[f32]| {
                for (o, x) in out.unwrap_or_default().iter_mut().zip(from) {
                    *o = *x;
                }
            };
            put(values.get_mut(at..), &v[..dim]);
            put(
                velocities.as_deref_mut().and_then(|o| o.get_mut(at..)),
                &d[..dim],
            );
            at += dim;
        }
    }

    /// Heap bytes the clip owns: its tracks, their names and data.
    pub fn heap_bytes(&self) -> usize {
        self.name.len()
            + self
                .tracks
                .iter()
                .map(|t| {
                    std::mem::size_of::<NamedTrack>()
                        + t.name.len()
                        + match &t.data {
                            TrackData::Scalar(t) => t.heap_bytes(),
                            TrackData::Vec2(t) => t.heap_bytes(),
                            TrackData::Vec3(t) => t.heap_bytes(),
                            TrackData::Vec4(t) => t.heap_bytes(),
                            TrackData::Quat(t) => t.heap_bytes(),
                        }
                })
                .sum::<usize>()
    }

    /// The sorted union of every track's key times.
    pub fn key_times(&self) -> Vec<f64> {
        let mut all: Vec<f64> = self
            .tracks
            .iter()
            .flat_map(|t| t.data.times().iter().copied())
            .collect();
        all.sort_by(f64::total_cmp);
        all.dedup();
        all
    }

    /// The earliest first key and the latest last key (`None` without tracks).
    pub fn time_range(&self) -> Option<(f64, f64)> {
        let times = self.tracks.iter().map(|t| t.data.times());
        let start = times.clone().map(|t| t[0]).reduce(f64::min)?;
        let end = times.map(|t| t[t.len() - 1]).reduce(f64::max)?;
        Some((start, end))
    }
}
