//! Plays the bundled CMU capture (`data/cmu-01_01.bvh`) headless: bevy's
//! `MinimalPlugins` (no window, no renderer), 60 frames a second of
//! simulated time, a cross-fade halfway through, then exits and prints
//! where the hips and the left hand are.
//!
//! ```sh
//! cargo run --release -p tcb-bevy --example play -- --frames 240
//! ```

use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use std::time::Duration;
use tcb_bevy::{Playback, TcbClip, TcbPlayer, TcbPlugin, spawn_skeleton};

/// Frames to run (after the clip has loaded) and the clip.
#[derive(Resource)]
struct Run {
    frames: u32,
    clip: Handle<TcbClip>,
    root: Option<Entity>,
    played: u32,
}

fn main() {
    let mut frames = 240;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match (arg.as_str(), args.next().and_then(|n| n.parse().ok())) {
            ("--frames", Some(n)) => frames = n,
            _ => {
                eprintln!("usage: play [--frames N]");
                std::process::exit(2);
            }
        }
    }
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data");
    let exit = App::new()
        .add_plugins((
            MinimalPlugins,
            AssetPlugin {
                file_path: data.to_string(),
                ..default()
            },
            TransformPlugin,
            TcbPlugin,
        ))
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_nanos(
            16_666_667,
        )))
        .add_systems(
            Startup,
            move |mut commands: Commands, assets: Res<AssetServer>| {
                let clip = assets.load("cmu-01_01.bvh");
                commands.insert_resource(Run {
                    frames,
                    clip,
                    root: None,
                    played: 0,
                });
            },
        )
        .add_systems(Update, (spawn_when_loaded, count_and_exit))
        .run();
    if exit != AppExit::Success {
        std::process::exit(1);
    }
}

/// Once the clip has loaded: its skeleton as joint entities under a root
/// that plays it, ping-pong at 1.5 times its speed.
fn spawn_when_loaded(mut commands: Commands, clips: Res<Assets<TcbClip>>, mut run: ResMut<Run>) {
    if run.root.is_some() {
        return;
    }
    let Some(clip) = clips.get(&run.clip) else {
        return;
    };
    let skeleton = clip.skeleton().expect("a BVH file has a skeleton").clone();
    let player = TcbPlayer::new(run.clip.clone())
        .with_playback(Playback::PingPong)
        .with_speed(1.5);
    let root = commands.spawn((Transform::IDENTITY, player)).id();
    let joints = spawn_skeleton(&mut commands, &skeleton, root);
    println!(
        "{} joints, {} tracks",
        joints.len(),
        clip.clip().tracks().len()
    );
    run.root = Some(root);
}

/// Count frames played; cross-fade halfway (into the same clip from its
/// start); print and exit at the end.
fn count_and_exit(
    mut run: ResMut<Run>,
    mut players: Query<&mut TcbPlayer>,
    joints: Query<(&Name, &GlobalTransform)>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(root) = run.root else { return };
    let Ok(mut player) = players.get_mut(root) else {
        return;
    };
    if let Some(e) = player.error() {
        eprintln!("error: {e}");
        exit.write(AppExit::error());
        return;
    }
    if !player.is_bound() {
        return;
    }
    run.played += 1;
    if run.played == run.frames / 2 {
        let clip = run.clip.clone();
        player.cross_fade(clip, 0.5);
    }
    if run.played >= run.frames {
        println!(
            "{} frames: time {:.4} s, {} joints written a frame",
            run.played,
            player.time().unwrap_or(0.0),
            player.joint_count()
        );
        for (name, g) in &joints {
            if ["Hips", "LeftHand"].contains(&name.as_str()) {
                let p = g.translation();
                println!("{name} at ({:.4}, {:.4}, {:.4})", p.x, p.y, p.z);
            }
        }
        exit.write(AppExit::Success);
    }
}
