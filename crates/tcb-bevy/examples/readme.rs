//! The bevy lines of tcb-bevy's README, compiled (tests/readme.rs checks
//! that the README shows them as they are here). With `default-features = false`
//! bevy's `DefaultPlugins` has no window: this builds but is not run.

use bevy::prelude::*;
use tcb_bevy::{Playback, TcbClip, TcbPlayer, TcbPlugin};

fn main() {
    App::new()
        .add_plugins((DefaultPlugins, TcbPlugin))
        .add_systems(Startup, setup)
        .run();
}

fn setup(mut commands: Commands, assets: Res<AssetServer>) {
    // .json, .bvh, .gltf/.glb or .tcbc; it plays on the descendants named as its joints.
    let walk: Handle<TcbClip> = assets.load("walk.bvh");
    let player = TcbPlayer::new(walk)
        .with_playback(Playback::PingPong)
        .with_speed(1.5);
    commands.spawn((Transform::default(), player)); // then the character's joints as children
}
