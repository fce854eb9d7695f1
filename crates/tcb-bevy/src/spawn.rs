//! Joint entities for a skeleton, for clips that bring their own (BVH,
//! glTF imported by tcb) and scenes that have none.

use crate::systems::to_bevy;
use bevy_ecs::entity::Entity;
use bevy_ecs::hierarchy::ChildOf;
use bevy_ecs::name::Name;
use bevy_ecs::system::Commands;
use tcb_core::skeleton::Skeleton;

/// Spawn one entity per joint of `skeleton` (its `Name`, its rest
/// `Transform`, its parent's `ChildOf`; root joints children of
/// `parent`), and return them in the skeleton's joint order.
///
/// ```
/// use bevy_ecs::prelude::*;
/// # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
/// let skeleton = tcb_io::load(path).unwrap().skeleton.unwrap();
/// let mut world = World::new();
/// let root = world.spawn_empty().id();
/// let joints = tcb_bevy::spawn_skeleton(&mut world.commands(), &skeleton, root);
/// world.flush();
/// assert_eq!(joints.len(), 38);
/// assert_eq!(world.get::<Name>(joints[0]).unwrap().as_str(), "Hips");
/// ```
pub fn spawn_skeleton(commands: &mut Commands, skeleton: &Skeleton, parent: Entity) -> Vec<Entity> {
    let mut entities: Vec<Entity> = Vec::with_capacity(skeleton.joints().len());
    for joint in skeleton.joints() {
        // A skeleton lists parents before their children.
        let up = joint.parent.map_or(parent, |p| entities[p]);
        let id = commands
            .spawn((
                Name::new(joint.name.clone()),
                to_bevy(&joint.rest),
                ChildOf(up),
            ))
            .id();
        entities.push(id);
    }
    entities
}
