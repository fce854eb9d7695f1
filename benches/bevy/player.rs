//! Per-joint cost of `TcbPlayer`'s system against bevy_animation playing
//! the same clip, in one run: the CMU capture exported to one `.glb` by
//! tcb-io, loaded by bevy's own glTF loader (bevy_gltf, as an
//! `AnimationClip`) and by tcb-bevy's loader (as a `TcbClip`), each played
//! in a loop on 100 characters of 31 animated joints in an app of the same
//! plugins. What is timed is the animation system set alone, each frame:
//! `TcbSystems::Animate` (sample, write `Transform`s) against bevy's
//! `AnimationSystems` (advance players, evaluate the graph and curves,
//! write `Transform`s), between two systems ordered right before and after
//! it; transform propagation, the same for both, is not timed. bevy's
//! executor is single-threaded here (no `multi_threaded` feature), as is
//! tcb-bevy's system.
//!
//! ```sh
//! cd benches/bevy && cargo bench
//! ```
//!
//! A crate outside the tcb workspace, so that the workspace's builds do
//! not compile bevy's glTF import and animation.

use bevy::MinimalPlugins;
use bevy::app::{AnimationSystems, App, PostUpdate};
use bevy::asset::{AssetPlugin, AssetServer, Assets, Handle};
use bevy::ecs::entity::Entity;
use bevy::ecs::hierarchy::ChildOf;
use bevy::ecs::name::Name;
use bevy::ecs::resource::Resource;
use bevy::ecs::schedule::{IntoScheduleConfigs, SystemSet};
use bevy::ecs::system::ResMut;
use bevy::time::TimeUpdateStrategy;
use bevy::transform::components::Transform;
use bevy::transform::{TransformPlugin, TransformSystems};
use bevy_animation::graph::{AnimationGraph, AnimationGraphHandle};
use bevy_animation::{
    AnimatedBy, AnimationClip, AnimationPlayer, AnimationPlugin, AnimationTargetId,
};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use tcb_bevy::{TcbClip, TcbPlayer, TcbPlugin, TcbSystems, spawn_skeleton};
use tcb_core::skeleton::Skeleton;

const CHARACTERS: usize = 100;

/// The time spent in the timed set, summed over frames.
#[derive(Resource, Default)]
struct Stopwatch {
    started: Option<Instant>,
    total: Duration,
}

fn start(mut w: ResMut<Stopwatch>) {
    w.started = Some(Instant::now());
}

fn stop(mut w: ResMut<Stopwatch>) {
    if let Some(s) = w.started.take() {
        w.total += s.elapsed();
    }
}

/// The CMU clip as one `.glb`, twice (one file per loader), in a folder.
fn assets() -> (PathBuf, Skeleton) {
    let bvh = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let loaded = tcb_io::load(bvh).unwrap();
    let options = tcb_io::gltf_export::ExportOptions::default();
    let (glb, _) = tcb_io::gltf_export::export(
        &loaded.clip,
        loaded.skeleton.as_ref(),
        tcb_io::gltf_export::Container::Glb,
        &options,
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("tcb-bevy-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("cmu.glb"), &glb).unwrap();
    std::fs::write(dir.join("cmu-tcb.glb"), &glb).unwrap();
    (dir, loaded.skeleton.unwrap())
}

/// An app with every plugin both sides need (so both apps are alike),
/// timing `set`.
fn app(dir: &Path, set: impl SystemSet + Clone) -> App {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin {
            file_path: dir.display().to_string(),
            ..Default::default()
        },
        TransformPlugin,
        bevy_world_serialization::WorldSerializationPlugin,
        bevy_mesh::MeshPlugin,
        bevy_gltf::GltfPlugin::default(),
        AnimationPlugin,
        TcbPlugin,
    ))
    .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_nanos(
        16_666_667,
    )))
    .init_resource::<Stopwatch>()
    .add_systems(
        PostUpdate,
        (
            start.before(set.clone()),
            stop.after(set).before(TransformSystems::Propagate),
        ),
    );
    app.finish();
    app.cleanup();
    app
}

fn wait_for<A: bevy::asset::Asset>(app: &mut App, handle: &Handle<A>) {
    for _ in 0..10_000 {
        app.update();
        if app.world().resource::<Assets<A>>().contains(handle) {
            return;
        }
        if let bevy::asset::LoadState::Failed(e) =
            app.world().resource::<AssetServer>().load_state(handle)
        {
            panic!("{e}");
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    panic!("the clip did not load");
}

/// Characters played by tcb-bevy; returns one character's joints.
fn tcb_app(dir: &Path, skeleton: &Skeleton) -> (App, Vec<Entity>) {
    let mut app = app(dir, TcbSystems::Animate);
    let clip: Handle<TcbClip> = app.world().resource::<AssetServer>().load("cmu-tcb.glb");
    wait_for(&mut app, &clip);
    let mut first = Vec::new();
    for c in 0..CHARACTERS {
        let world = app.world_mut();
        let root = world
            .spawn((Transform::IDENTITY, TcbPlayer::new(clip.clone())))
            .id();
        let joints = spawn_skeleton(&mut world.commands(), skeleton, root);
        world.flush();
        if c == 0 {
            first = joints;
        }
    }
    (app, first)
}

/// Characters played by bevy_animation, their joints tagged as bevy_gltf
/// tags a glTF scene's nodes (`AnimationTargetId` of the names from the
/// root, `AnimatedBy` the root, which has the `AnimationPlayer`).
fn bevy_app(dir: &Path, skeleton: &Skeleton) -> (App, Vec<Entity>) {
    let mut app = app(dir, AnimationSystems);
    // Typed as `Gltf`: both plugins register `.glb`, and a labeled path
    // (`cmu.glb#Animation0`) would pick the last loader registered.
    let gltf: Handle<bevy_gltf::Gltf> = app.world().resource::<AssetServer>().load("cmu.glb");
    wait_for(&mut app, &gltf);
    let gltfs = app.world().resource::<Assets<bevy_gltf::Gltf>>();
    let clip: Handle<AnimationClip> = gltfs.get(&gltf).unwrap().animations[0].clone();
    wait_for(&mut app, &clip);
    let (graph, node) = AnimationGraph::from_clip(clip.clone());
    let graph = app
        .world_mut()
        .resource_mut::<Assets<AnimationGraph>>()
        .add(graph);
    let joints = skeleton.joints();
    // Each joint's path of names from its root.
    let paths: Vec<Vec<Name>> = (0..joints.len())
        .map(|mut j| {
            let mut path = vec![Name::new(joints[j].name.clone())];
            while let Some(p) = joints[j].parent {
                path.push(Name::new(joints[p].name.clone()));
                j = p;
            }
            path.reverse();
            path
        })
        .collect();
    let ids: Vec<AnimationTargetId> = paths
        .iter()
        .map(|p| AnimationTargetId::from_names(p.iter()))
        .collect();
    let animations = app.world().resource::<Assets<AnimationClip>>();
    let animated = ids
        .iter()
        .filter(|id| animations.get(&clip).unwrap().curves().contains_key(*id))
        .count();
    assert_eq!(
        animated, 31,
        "bevy_gltf's targets are the joints' name paths"
    );
    let mut first = Vec::new();
    for c in 0..CHARACTERS {
        let world = app.world_mut();
        let holder = world.spawn(Transform::IDENTITY).id();
        let entities = spawn_skeleton(&mut world.commands(), skeleton, holder);
        world.flush();
        let root = entities[0];
        for (&e, id) in entities.iter().zip(&ids) {
            world.entity_mut(e).insert((*id, AnimatedBy(root)));
        }
        let mut player = AnimationPlayer::default();
        player.play(node).repeat();
        world
            .entity_mut(root)
            .insert((player, AnimationGraphHandle(graph.clone())));
        if c == 0 {
            first = entities;
        }
    }
    (app, first)
}

/// Run `frames` frames; the timed set's total.
fn run(app: &mut App, frames: u64) -> Duration {
    app.world_mut().resource_mut::<Stopwatch>().total = Duration::ZERO;
    for _ in 0..frames {
        app.update();
    }
    app.world().resource::<Stopwatch>().total
}

fn bench(c: &mut Criterion) {
    let (dir, skeleton) = assets();
    let (mut tcb, tcb_joints) = tcb_app(&dir, &skeleton);
    let (mut bevy, bevy_joints) = bevy_app(&dir, &skeleton);
    // Same clip, same frames: the two agree on every joint (glTF LINEAR
    // keys, slerp on both sides).
    run(&mut tcb, 90);
    run(&mut bevy, 90);
    // bevy_animation's clock starts a frame earlier than the player's
    // (which shows time 0 on its first frame): compare at bevy's time.
    let bevy_time = {
        let player = bevy.world().get::<AnimationPlayer>(bevy_joints[0]).unwrap();
        f64::from(player.playing_animations().next().unwrap().1.seek_time())
    };
    let root = tcb.world().get::<ChildOf>(tcb_joints[0]).unwrap().parent();
    let step = Duration::from_nanos(16_666_667).as_secs_f64();
    let mut player = tcb.world_mut().get_mut::<TcbPlayer>(root).unwrap();
    let tcb_time = player.time().unwrap();
    player.seek(bevy_time - step);
    tcb.update();
    println!("after 90 frames: tcb-bevy at {tcb_time:.6} s, bevy_animation at {bevy_time:.6} s");
    let mut worst = 0.0f32;
    for (&a, &b) in tcb_joints.iter().zip(&bevy_joints) {
        let (a, b) = (
            tcb.world().get::<Transform>(a).unwrap(),
            bevy.world().get::<Transform>(b).unwrap(),
        );
        worst = worst
            .max(a.translation.distance(b.translation))
            .max(1.0 - a.rotation.dot(b.rotation).abs());
    }
    println!(
        "at bevy_animation's time: largest joint difference {worst:e} (translation distance, or 1 - |q.q'|)"
    );
    let joints = (CHARACTERS * 31) as u64;
    let mut group = c.benchmark_group(format!("animate {CHARACTERS} characters x 31 joints"));
    group.throughput(Throughput::Elements(joints));
    group.bench_function("tcb-bevy TcbSystems::Animate", |b| {
        b.iter_custom(|iters| run(&mut tcb, iters))
    });
    group.bench_function("bevy_animation AnimationSystems", |b| {
        b.iter_custom(|iters| run(&mut bevy, iters))
    });
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
