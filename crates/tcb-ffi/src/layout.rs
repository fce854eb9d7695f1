//! The float row a sample is written into, and the track queries that tell
//! where each track lives in it (shared by clips and rigs).

use crate::error::{Failure, Result, TcbStatus};
use tcb_core::TrackKind;
use tcb_runtime::PoseLayout;

/// The kind of a track: how many floats it takes in a row.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TcbTrackKind {
    /// One float.
    #[default]
    Scalar = 1,
    /// Two floats, `x y`.
    Vec2 = 2,
    /// Three floats, `x y z` (translations, scales).
    Vec3 = 3,
    /// Four floats, `x y z w`.
    Vec4 = 4,
    /// A unit quaternion, four floats `x y z w` (rotations).
    Quat = 5,
}

impl From<TrackKind> for TcbTrackKind {
    fn from(k: TrackKind) -> Self {
        match k {
            TrackKind::Scalar => TcbTrackKind::Scalar,
            TrackKind::Vec2 => TcbTrackKind::Vec2,
            TrackKind::Vec3 => TcbTrackKind::Vec3,
            TrackKind::Vec4 => TcbTrackKind::Vec4,
            TrackKind::Quat => TcbTrackKind::Quat,
        }
    }
}

/// Where a track lives in a sampled row of floats.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TcbTrackInfo {
    /// The track's index (0 to the track count - 1).
    pub index: usize,
    /// Its kind.
    pub kind: TcbTrackKind,
    /// The index of its first float in a row.
    pub offset: usize,
    /// Its number of floats (1 to 4), consecutive from `offset`.
    pub components: usize,
}

/// Floats in a row of `layout`.
pub(crate) fn channel_count(layout: &PoseLayout) -> usize {
    layout.tracks().iter().map(|s| s.kind().dim()).sum()
}

/// Track `index` of `layout`.
pub(crate) fn info(layout: &PoseLayout, index: usize) -> Result<TcbTrackInfo> {
    let tracks = layout.tracks();
    let Some(slot) = tracks.get(index) else {
        return Err(Failure::invalid(format!(
            "track index {index} is past the last track ({} tracks)",
            tracks.len()
        )));
    };
    let offset = tracks[..index].iter().map(|s| s.kind().dim()).sum();
    Ok(TcbTrackInfo {
        index,
        kind: slot.kind().into(),
        offset,
        components: slot.kind().dim(),
    })
}

/// The track called `name` in `layout`.
pub(crate) fn find(layout: &PoseLayout, name: &str) -> Result<TcbTrackInfo> {
    let id = layout
        .track(name)
        .ok_or_else(|| Failure::new(TcbStatus::NotFound, format!("no track {name:?}")))?;
    info(layout, id.index())
}

/// The name of track `index` of `layout`.
pub(crate) fn name(layout: &PoseLayout, index: usize) -> Result<&str> {
    info(layout, index)?;
    Ok(layout.tracks()[index].name())
}
