//! Once bound, the player's systems allocate nothing per frame: playing,
//! and cross-fading once the incoming clip has started. Counted by a
//! global allocator on the app's thread only, between two systems that
//! run right before and right after `TcbSystems::Animate`.

mod common;

use bevy::app::PostUpdate;
use bevy::ecs::schedule::IntoScheduleConfigs;
use bevy::transform::TransformSystems;
use bevy::transform::components::Transform;
use common::{app, data_dir, load};
use std::path::Path;
use tcb_bevy::{TcbPlayer, TcbSystems, spawn_skeleton};
use tcb_test_support::{CountingAllocator, start_counting, stop_counting, take_counted};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn playing_and_cross_fading_allocate_nothing_per_frame() {
    let dir = data_dir();
    let mut app = app(Path::new(&dir));
    app.add_systems(
        PostUpdate,
        (
            start_counting.before(TcbSystems::Animate),
            stop_counting
                .after(TcbSystems::Animate)
                .before(TransformSystems::Propagate),
        ),
    );
    let clip = load(&mut app, "cmu-01_01.bvh").unwrap();
    let skeleton = app
        .world()
        .resource::<bevy::asset::Assets<tcb_bevy::TcbClip>>()
        .get(&clip)
        .unwrap()
        .skeleton()
        .unwrap()
        .clone();
    let world = app.world_mut();
    let root = world
        .spawn((Transform::IDENTITY, TcbPlayer::new(clip.clone())))
        .id();
    spawn_skeleton(&mut world.commands(), &skeleton, root);
    world.flush();
    app.update(); // binds: allocates, once (and shows that the count counts)
    assert!(take_counted().count > 0);
    for _ in 0..30 {
        app.update();
    }
    assert_eq!(take_counted().count, 0, "playing");
    app.world_mut()
        .get_mut::<TcbPlayer>(root)
        .unwrap()
        .cross_fade(clip, 0.25);
    app.update(); // starts the incoming clip: its instance is allocated, once
    assert!(take_counted().count > 0);
    for _ in 0..10 {
        app.update();
    }
    assert!(app.world().get::<TcbPlayer>(root).unwrap().weight() < 1.0);
    assert_eq!(take_counted().count, 0, "cross-fading");
}
