//! The systems: binding a player to its joints once, then sampling,
//! blending and writing `Transform`s every frame without allocating.

use crate::asset::TcbClip;
use crate::player::{Bound, Layer, TcbPlayer, fade_weight};
use bevy_asset::Assets;
use bevy_ecs::entity::Entity;
use bevy_ecs::hierarchy::Children;
use bevy_ecs::name::Name;
use bevy_ecs::system::{Query, Res};
use bevy_math::{Quat, Vec3};
use bevy_time::Time;
use bevy_transform::components::Transform;
use std::collections::{HashSet, VecDeque};
use std::sync::Arc;
use tcb_core::TrackKind;
use tcb_core::skeleton::{Joint, Skeleton, Transform as TcbTransform};
use tcb_runtime::{Instance, Rig, RigTrack, SkeletonBinding, blend};

/// The parts of a joint, as track name suffixes.
const PARTS: [&str; 3] = ["translation", "rotation", "scale"];

/// Bind each player whose first clip has loaded and which is not bound
/// yet (retried every frame until it binds: joints may be spawned later).
pub(crate) fn bind_players(
    mut players: Query<(Entity, &mut TcbPlayer)>,
    clips: Res<Assets<TcbClip>>,
    children: Query<&Children>,
    joints: Query<(&Name, &Transform)>,
) {
    for (root, mut player) in &mut players {
        if player.bound.is_some() {
            continue;
        }
        let Some(asset) = clips.get(&player.clip) else {
            continue;
        };
        match bind(root, asset, &player, &children, &joints) {
            Ok(bound) => {
                player.bound = Some(Box::new(bound));
                player.error = None;
            }
            Err(e) => {
                if player.error.as_deref() != Some(e.as_str()) {
                    player.error = Some(e);
                }
            }
        }
    }
}

/// The joints under `root` (breadth first, by `Name`, the first of a name
/// only) that the rig (the player's, else one made from the clip) has
/// tracks for, the rig, and the clip's first layer.
fn bind(
    root: Entity,
    asset: &TcbClip,
    player: &TcbPlayer,
    children: &Query<&Children>,
    named: &Query<(&Name, &Transform)>,
) -> Result<Bound, String> {
    let clip = asset.clip();
    let animated = |name: &str| match &player.rig {
        Some(rig) => PARTS
            .iter()
            .any(|p| rig.track(&format!("{name}.{p}")).is_some()),
        None => PARTS
            .iter()
            .any(|p| clip.track(&format!("{name}.{p}")).is_some()),
    };
    let mut joints = Vec::new();
    let mut entities = Vec::new();
    let mut seen = HashSet::new();
    let mut queue = VecDeque::from([(root, None)]);
    while let Some((entity, parent)) = queue.pop_front() {
        let mut parent_of_children = parent;
        if let Ok((name, t)) = named.get(entity)
            && animated(name.as_str())
            && seen.insert(name.as_str().to_string())
        {
            parent_of_children = Some(joints.len());
            joints.push(Joint {
                name: name.as_str().to_string(),
                parent,
                rest: from_bevy(t),
            });
            entities.push(entity);
        }
        if let Ok(c) = children.get(entity) {
            queue.extend(c.iter().map(|&child| (child, parent_of_children)));
        }
    }
    if joints.is_empty() {
        return Err(format!(
            "no entity under {root} is named as a joint of clip '{}' (a track '<name>.translation|rotation|scale')",
            clip.name()
        ));
    }
    let skeleton = Skeleton::new(joints).map_err(|e| e.to_string())?;
    let rig = match &player.rig {
        Some(rig) => rig.clone(),
        None => Arc::new(rig_for(&skeleton, clip).map_err(|e| e.to_string())?),
    };
    let instance = Instance::with_rig(clip.clone(), &rig).map_err(|e| e.to_string())?;
    let joint_count = entities.len();
    Ok(Bound {
        binding: SkeletonBinding::for_layout(skeleton, rig.layout()),
        out: rig.rest_pose(),
        rig,
        joints: entities,
        locals: vec![TcbTransform::default(); joint_count],
        current: Layer::new(instance, player.playback),
        fading: None,
    })
}

/// Every joint's translation, rotation and scale, resting at the joint's
/// transform, then the clip's other tracks, resting at zero (rotations at
/// the identity).
fn rig_for(skeleton: &Skeleton, clip: &tcb_runtime::Clip) -> Result<Rig, tcb_runtime::RigError> {
    let mut tracks = Vec::new();
    for j in skeleton.joints() {
        let (t, r, s) = (j.rest.translation, j.rest.rotation, j.rest.scale);
        let rests = [
            (TrackKind::Vec3, [t.x, t.y, t.z, 0.0]),
            (TrackKind::Quat, r.to_array()),
            (TrackKind::Vec3, [s.x, s.y, s.z, 0.0]),
        ];
        for (part, (kind, rest)) in PARTS.iter().zip(rests) {
            tracks.push(RigTrack {
                name: format!("{}.{part}", j.name),
                kind,
                rest,
            });
        }
    }
    let names: HashSet<String> = tracks.iter().map(|t| t.name.clone()).collect();
    for t in clip.tracks() {
        if !names.contains(t.name()) {
            let rest = if t.kind() == TrackKind::Quat {
                [0.0, 0.0, 0.0, 1.0]
            } else {
                [0.0; 4]
            };
            tracks.push(RigTrack {
                name: t.name().to_string(),
                kind: t.kind(),
                rest,
            });
        }
    }
    Rig::new(tracks)
}

/// Start a requested clip once it has loaded (allocates its instance:
/// once per switch, not per frame).
fn start_requested(player: &mut TcbPlayer, clips: &Assets<TcbClip>) {
    let Some((handle, fade)) = &player.request else {
        return;
    };
    let Some(asset) = clips.get(handle) else {
        return;
    };
    let (handle, fade) = (handle.clone(), *fade);
    player.request = None;
    let Some(bound) = player.bound.as_deref_mut() else {
        return;
    };
    match Instance::with_rig(asset.clip().clone(), &bound.rig) {
        Ok(instance) => {
            let new = Layer::new(instance, player.playback);
            let old = std::mem::replace(&mut bound.current, new);
            bound.fading = (fade > 0.0).then_some((old, 0.0, fade));
            player.clip = handle;
        }
        Err(e) => player.error = Some(e.to_string()),
    }
}

/// Advance, sample, blend and write every bound player's joints.
pub(crate) fn animate(
    time: Res<Time>,
    clips: Res<Assets<TcbClip>>,
    mut players: Query<&mut TcbPlayer>,
    mut transforms: Query<&mut Transform>,
) {
    let dt = time.delta_secs_f64();
    for mut player in &mut players {
        let player = &mut *player;
        if player.bound.is_none() {
            continue;
        }
        if player.request.is_some() {
            start_requested(player, &clips);
        }
        let step = dt * player.speed;
        let Some(bound) = player.bound.as_deref_mut() else {
            continue;
        };
        let Bound {
            binding,
            joints,
            locals,
            out,
            current,
            fading,
            ..
        } = bound;
        let fade_step = if current.fresh { 0.0 } else { step.abs() };
        current.advance(step);
        current.instance.sample(current.time);
        let mut faded = false;
        let pose = match fading {
            Some((old, elapsed, total)) => {
                old.advance(step);
                *elapsed += fade_step;
                let w = fade_weight(*elapsed, *total);
                faded = w >= 1.0;
                let layers = [
                    (old.instance.sample(old.time), 1.0 - w),
                    (current.instance.pose(), w),
                ];
                if blend(out, &layers, None).is_ok() {
                    &*out
                } else {
                    current.instance.pose()
                }
            }
            None => current.instance.pose(),
        };
        if binding.local_transforms(pose, locals).is_ok() {
            for (&entity, local) in joints.iter().zip(locals.iter()) {
                if let Ok(mut t) = transforms.get_mut(entity) {
                    *t = to_bevy(local);
                }
            }
        }
        if faded {
            *fading = None;
        }
    }
}

/// tcb's transform (glam 0.34) from bevy's (glam 0.32): same components.
pub(crate) fn from_bevy(t: &Transform) -> TcbTransform {
    TcbTransform {
        translation: glam::Vec3::from_array(t.translation.to_array()),
        rotation: glam::Quat::from_array(t.rotation.to_array()),
        scale: glam::Vec3::from_array(t.scale.to_array()),
    }
}

/// bevy's transform from tcb's.
pub(crate) fn to_bevy(t: &TcbTransform) -> Transform {
    Transform {
        translation: Vec3::from_array(t.translation.to_array()),
        rotation: Quat::from_array(t.rotation.to_array()),
        scale: Vec3::from_array(t.scale.to_array()),
    }
}
