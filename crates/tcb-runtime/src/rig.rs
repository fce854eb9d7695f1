//! Poses in rig order: one layout per rig, whatever a clip's key times.
//!
//! A [`Clip`]'s own pose layout follows its key grids (channels that share
//! key times are packed together), so two clips of one character, say a
//! dense walk and a reduced run, lay their poses out differently. A [`Rig`]
//! fixes the layout instead: its tracks in its order, each vector track one
//! lane of four component planes, each rotation one lane of the x/y/z/w
//! planes, eight lanes a block. An [`Instance`](crate::Instance) made with
//! [`Instance::with_rig`](crate::Instance::with_rig) samples its clip as
//! usual and then copies each channel to the rig's lane (one precomputed
//! index pair per component, no allocation). Tracks the clip lacks keep the
//! rig's rest values. Every pose of a rig shares its layout, so poses of any
//! clips of the rig blend ([`crate::blend()`]), and a pose of another rig is
//! refused.
//!
//! ```
//! use std::sync::Arc;
//! use tcb_runtime::{Clip, Instance, Rig, blend};
//! # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
//! # /*
//! let path = "data/cmu-01_01.bvh"; // from the repository's root
//! # */
//! let loaded = tcb_io::load(path).unwrap();
//! let rig = Arc::new(Rig::from_skeleton(loaded.skeleton.as_ref().unwrap()).unwrap());
//! let clip = Arc::new(Clip::compile(&loaded.clip));
//! let mut walk = Instance::with_rig(clip.clone(), &rig).unwrap();
//! let mut later = Instance::with_rig(clip, &rig).unwrap();
//! let mut out = rig.rest_pose();
//! walk.sample(1.0);
//! later.sample(2.0);
//! blend(&mut out, &[(walk.pose(), 0.5), (later.pose(), 0.5)], None).unwrap();
//! let hips = rig.track("Hips.rotation").unwrap();
//! assert!((out.quat(hips).unwrap().length() - 1.0).abs() < 1e-6);
//! ```

use crate::clip::Clip;
use crate::layout::{PoseLayout, TrackId, TrackSlot, plane_slots};
use crate::pose::Pose;
use std::collections::HashMap;
use std::fmt;
use std::sync::Arc;
use tcb_core::TrackKind;
use tcb_core::skeleton::Skeleton;
use wide::f32x8;

/// One track of a rig: its name, kind and the value it has where no clip
/// animates it.
#[derive(Clone, Debug, PartialEq)]
pub struct RigTrack {
    /// Name, as clips call it (`Hips.rotation`).
    pub name: String,
    /// Kind; a clip's track of this name must have it.
    pub kind: TrackKind,
    /// Rest value (`kind.dim()` components used; rotations `[x, y, z, w]`).
    pub rest: [f32; 4],
}

/// Why a rig or a clip's binding to it was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum RigError {
    /// Two rig tracks have this name.
    Duplicate(String),
    /// A rest value is not finite, or a rest rotation has zero length.
    BadRest(String),
    /// The clip's track has another kind than the rig's track of that name.
    Kind {
        /// Track name.
        track: String,
        /// The kind in the clip.
        clip: TrackKind,
        /// The kind in the rig.
        rig: TrackKind,
    },
    /// The clip has a track the rig does not.
    NotInRig(String),
}

impl fmt::Display for RigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RigError::Duplicate(n) => write!(f, "rig track {n:?} appears twice"),
            RigError::BadRest(n) => write!(
                f,
                "rig track {n:?}: rest value is not finite (or a zero rotation)"
            ),
            RigError::Kind { track, clip, rig } => write!(
                f,
                "track {track:?} is {} in the clip but {} in the rig",
                clip.name(),
                rig.name()
            ),
            RigError::NotInRig(n) => write!(f, "the clip's track {n:?} is not in the rig"),
        }
    }
}

impl std::error::Error for RigError {}

/// A fixed set of tracks and the pose layout they share (see the module docs).
#[derive(Clone, Debug)]
pub struct Rig {
    tracks: Vec<RigTrack>,
    layout: Arc<PoseLayout>,
    /// The rest pose's values, every lane (padding rotations: identity).
    rest: Vec<f32x8>,
    by_name: HashMap<String, usize>,
}

impl Rig {
    /// A rig of `tracks`, in that order. Rest rotations are normalized.
    pub fn new(tracks: Vec<RigTrack>) -> Result<Self, RigError> {
        let mut by_name = HashMap::new();
        let mut tracks = tracks;
        for (i, t) in tracks.iter_mut().enumerate() {
            if by_name.insert(t.name.clone(), i).is_some() {
                return Err(RigError::Duplicate(t.name.clone()));
            }
            let dim = t.kind.dim();
            if t.rest[..dim].iter().any(|x| !x.is_finite()) {
                return Err(RigError::BadRest(t.name.clone()));
            }
            if t.kind == TrackKind::Quat {
                let len = t
                    .rest
                    .iter()
                    .map(|x| f64::from(*x).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if len == 0.0 || !len.is_finite() {
                    return Err(RigError::BadRest(t.name.clone()));
                }
                t.rest = t.rest.map(|x| (f64::from(x) / len) as f32);
            }
        }
        let (rot, vec): (Vec<usize>, Vec<usize>) =
            (0..tracks.len()).partition(|&i| tracks[i].kind == TrackKind::Quat);
        let vec_blocks = 4 * vec.len().div_ceil(8);
        let rot_blocks = 4 * rot.len().div_ceil(8);
        let mut slots: Vec<TrackSlot> = tracks
            .iter()
            .map(|t| TrackSlot {
                name: t.name.clone(),
                kind: t.kind,
                index: [0; 4],
            })
            .collect();
        let mut flat = vec![0.0f32; 8 * (vec_blocks + rot_blocks)];
        for (out, ids) in [(0, &vec), (vec_blocks, &rot)] {
            for (lane, &i) in ids.iter().enumerate() {
                slots[i].index = plane_slots(out, lane);
                for c in 0..4 {
                    flat[slots[i].index[c]] = tracks[i].rest[c];
                }
            }
        }
        // Padding rotation lanes: the identity, so blending and
        // normalizing them stays finite.
        for lane in rot.len()..rot.len().div_ceil(8) * 8 {
            flat[plane_slots(vec_blocks, lane)[3]] = 1.0;
        }
        let quat_blocks = (0..rot_blocks / 4).map(|b| vec_blocks + 4 * b).collect();
        let rest = flat
            .chunks_exact(8)
            .map(|c| f32x8::new(c.try_into().expect("8 lanes")))
            .collect();
        Ok(Rig {
            layout: Arc::new(PoseLayout::new(slots, vec_blocks + rot_blocks, quat_blocks)),
            tracks,
            rest,
            by_name,
        })
    }

    /// `<joint>.translation` (vec3), `<joint>.rotation` (quat) and
    /// `<joint>.scale` (vec3) of every joint, rest values from the
    /// skeleton's rest transforms. Fails only on a hand-built skeleton with
    /// two joints of one name or a non-finite rest (tcb-io refuses both).
    pub fn from_skeleton(skeleton: &Skeleton) -> Result<Self, RigError> {
        let mut tracks = Vec::with_capacity(3 * skeleton.joints().len());
        for j in skeleton.joints() {
            let (t, r, s) = (j.rest.translation, j.rest.rotation, j.rest.scale);
            tracks.push(RigTrack {
                name: format!("{}.translation", j.name),
                kind: TrackKind::Vec3,
                rest: [t.x, t.y, t.z, 0.0],
            });
            tracks.push(RigTrack {
                name: format!("{}.rotation", j.name),
                kind: TrackKind::Quat,
                rest: r.to_array(),
            });
            tracks.push(RigTrack {
                name: format!("{}.scale", j.name),
                kind: TrackKind::Vec3,
                rest: [s.x, s.y, s.z, 0.0],
            });
        }
        Rig::new(tracks)
    }

    /// The tracks of `clip`, in file order, resting at zero (rotations at
    /// the identity). Fails when two tracks share a name (a hand-built
    /// `tcb_core::SourceClip`; the clip file and the importers refuse that).
    pub fn from_clip(clip: &Clip) -> Result<Self, RigError> {
        let tracks = clip
            .tracks()
            .iter()
            .map(|t| RigTrack {
                name: t.name.clone(),
                kind: t.kind,
                rest: if t.kind == TrackKind::Quat {
                    [0.0, 0.0, 0.0, 1.0]
                } else {
                    [0.0; 4]
                },
            })
            .collect();
        Rig::new(tracks)
    }

    /// The tracks, in rig order ([`TrackId`]s of rig poses index them).
    pub fn tracks(&self) -> &[RigTrack] {
        &self.tracks
    }

    /// The rig track called `name`, to read rig poses with.
    pub fn track(&self, name: &str) -> Option<TrackId> {
        self.by_name.get(name).map(|&i| self.layout.id(i))
    }

    /// The layout every pose of this rig has.
    pub fn layout(&self) -> &Arc<PoseLayout> {
        &self.layout
    }

    /// A pose holding every track's rest value, without velocities (add
    /// zero ones with [`Pose::with_velocities`]).
    pub fn rest_pose(&self) -> Pose {
        Pose {
            layout: self.layout.clone(),
            values: self.rest.clone(),
            velocities: None,
        }
    }

    /// Which clip channel goes to which rig lane.
    pub(crate) fn map(&self, clip: &Clip) -> Result<RigMap, RigError> {
        let mut copy = Vec::new();
        let mut covered = vec![false; self.tracks.len()];
        for slot in clip.tracks() {
            let Some(&r) = self.by_name.get(&slot.name) else {
                return Err(RigError::NotInRig(slot.name.clone()));
            };
            let rig = &self.layout.slots[r];
            if rig.kind != slot.kind {
                return Err(RigError::Kind {
                    track: slot.name.clone(),
                    clip: slot.kind,
                    rig: rig.kind,
                });
            }
            covered[r] = true;
            for c in 0..slot.kind.dim() {
                copy.push((slot.index[c] as u32, rig.index[c] as u32));
            }
        }
        copy.sort_unstable_by_key(|&(_, dst)| dst);
        Ok(RigMap { copy, covered })
    }
}

/// A clip's channels in a rig's pose.
#[derive(Clone, Debug)]
pub(crate) struct RigMap {
    /// (flat index in the clip's pose, flat index in the rig's pose).
    copy: Vec<(u32, u32)>,
    /// Per rig track: whether the clip animates it.
    pub covered: Vec<bool>,
}

impl RigMap {
    /// Copy the clip pose's channels (and velocities) into the rig pose.
    #[inline]
    pub fn apply(&self, from: &Pose, to: &mut Pose) {
        fn scatter(copy: &[(u32, u32)], from: &[f32x8], to: &mut [f32x8]) {
            let src: &[f32] = bytemuck::cast_slice(from);
            let dst: &mut [f32] = bytemuck::cast_slice_mut(to);
            for &(s, d) in copy {
                dst[d as usize] = src[s as usize];
            }
        }
        scatter(&self.copy, &from.values, &mut to.values);
        if let (Some(f), Some(t)) = (&from.velocities, to.velocities.as_mut()) {
            scatter(&self.copy, f, t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(name: &str, kind: TrackKind, rest: [f32; 4]) -> RigTrack {
        RigTrack {
            name: name.into(),
            kind,
            rest,
        }
    }

    #[test]
    fn refuses_bad_rigs() {
        let q = TrackKind::Quat;
        assert_eq!(
            Rig::new(vec![track("a", q, [0.0; 4]), track("b", q, [0.0; 4])]).err(),
            Some(RigError::BadRest("a".into()))
        );
        let one = [0.0, 0.0, 0.0, 1.0];
        assert_eq!(
            Rig::new(vec![track("a", q, one), track("a", TrackKind::Scalar, one)]).err(),
            Some(RigError::Duplicate("a".into()))
        );
        let nan = [f32::NAN, 0.0, 0.0, 0.0];
        assert!(Rig::new(vec![track("s", TrackKind::Scalar, nan)]).is_err());
        // The unused components of a scalar do not matter.
        assert!(
            Rig::new(vec![track(
                "s",
                TrackKind::Scalar,
                [1.0, f32::NAN, 0.0, 0.0]
            )])
            .is_ok()
        );
    }

    /// A hand-built clip with two tracks of one name: `from_clip` used to
    /// panic on it. Such a clip can no longer be made: `tcb_core::SourceClip::new`
    /// refuses it (its fields are private).
    #[test]
    fn a_clip_with_a_repeated_name_is_refused() {
        let track = |v: f32| tcb_core::NamedTrack {
            name: "x".into(),
            data: tcb_core::TrackData::Scalar(
                tcb_core::Track::new(
                    vec![0.0, 1.0],
                    vec![v, v],
                    vec![Default::default(); 2],
                    &Default::default(),
                )
                .unwrap(),
            ),
        };
        let twice = tcb_core::SourceClip::new("twice", vec![track(1.0), track(2.0)]);
        assert_eq!(twice, Err(tcb_core::DuplicateTrack("x".into())));
        let once = Clip::compile(&tcb_core::SourceClip::new("once", vec![track(1.0)]).unwrap());
        assert_eq!(Rig::from_clip(&once).unwrap().tracks().len(), 1);
    }

    #[test]
    fn rest_pose_in_rig_order() {
        let rig = Rig::new(vec![
            track("r", TrackKind::Quat, [0.0, 0.0, 0.0, 2.0]),
            track("p", TrackKind::Vec3, [1.0, 2.0, 3.0, 0.0]),
        ])
        .unwrap();
        let pose = rig.rest_pose().with_velocities();
        let (r, p) = (rig.track("r").unwrap(), rig.track("p").unwrap());
        assert_eq!((r.index(), p.index()), (0, 1));
        assert_eq!(pose.quat(r), Some(glam::Quat::IDENTITY));
        assert_eq!(pose.vec3(p), Some(glam::Vec3::new(1.0, 2.0, 3.0)));
        // Of another kind, or of another layout: no answer.
        assert_eq!(pose.vec3(r), None);
        assert_eq!(pose.quat(p), None);
        let other = Rig::new(vec![track("p", TrackKind::Vec3, [0.0; 4])]).unwrap();
        assert_eq!(pose.vec3(other.track("p").unwrap()), None);
        assert_eq!(other.rest_pose().vec3(p), None);
        // Padding rotation lanes are the identity.
        let w = pose.as_slice()[rig.layout().quat_blocks[0] * 8 + 24 + 7];
        assert_eq!(w, 1.0);
    }
}
