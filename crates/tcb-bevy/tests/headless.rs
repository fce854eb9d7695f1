//! Frames of a headless app (`MinimalPlugins`) against tcb-runtime: each
//! joint's `GlobalTransform` is `SkeletonBinding`'s model-space transform
//! of the same clip at the same time, in every playback mode and through
//! a cross-fade.

mod common;

use bevy::app::App;
use bevy::asset::{Assets, Handle};
use bevy::ecs::entity::Entity;
use bevy::transform::components::{GlobalTransform, Transform};
use common::{DT, app, data_dir, load};
use std::path::Path;
use std::sync::Arc;
use tcb_bevy::{Playback, TcbClip, TcbPlayer, spawn_skeleton};
use tcb_core::skeleton::Skeleton;
use tcb_runtime::{Instance, SkeletonBinding, blend};

const BVH: &str = "cmu-01_01.bvh";

/// A player of `clip` on the root of its skeleton's joint entities.
fn spawn_player(app: &mut App, clip: &Handle<TcbClip>, player: TcbPlayer) -> (Entity, Vec<Entity>) {
    let skeleton = skeleton_of(app, clip);
    let world = app.world_mut();
    let root = world.spawn((Transform::IDENTITY, player)).id();
    let joints = spawn_skeleton(&mut world.commands(), &skeleton, root);
    world.flush();
    (root, joints)
}

fn skeleton_of(app: &App, clip: &Handle<TcbClip>) -> Skeleton {
    let clips = app.world().resource::<Assets<TcbClip>>();
    clips.get(clip).unwrap().skeleton().unwrap().clone()
}

fn player(app: &App, root: Entity) -> &TcbPlayer {
    app.world().get::<TcbPlayer>(root).unwrap()
}

/// The largest distance between the joints' `GlobalTransform`s and
/// `model` (as affine matrices, relative to 1 + the matrix's size).
fn largest_error(app: &App, joints: &[Entity], model: &[glam::Affine3A]) -> f32 {
    let mut worst = 0.0f32;
    for (&e, m) in joints.iter().zip(model) {
        let g = app.world().get::<GlobalTransform>(e).unwrap().affine();
        let (a, b) = (g.to_cols_array(), m.to_cols_array());
        for (x, y) in a.iter().zip(&b) {
            worst = worst.max((x - y).abs() / (1.0 + y.abs()));
        }
    }
    worst
}

/// The reference: `SkeletonBinding` on the clip's own layout.
struct Reference {
    binding: SkeletonBinding,
    instance: Instance,
    local: Vec<tcb_core::skeleton::Transform>,
    model: Vec<glam::Affine3A>,
}

impl Reference {
    fn new(app: &App, clip: &Handle<TcbClip>, mode: Playback) -> Self {
        let compiled = app
            .world()
            .resource::<Assets<TcbClip>>()
            .get(clip)
            .unwrap()
            .clip()
            .clone();
        let binding = SkeletonBinding::new(skeleton_of(app, clip), &compiled);
        let mut instance = Instance::new(compiled);
        instance.set_playback(mode, 1.0).unwrap();
        let n = binding.skeleton().joints().len();
        Reference {
            binding,
            instance,
            local: vec![Default::default(); n],
            model: vec![glam::Affine3A::IDENTITY; n],
        }
    }

    fn at(&mut self, time: f64) -> &[glam::Affine3A] {
        let pose = self.instance.sample(time);
        self.binding
            .model_transforms(pose, &mut self.local, &mut self.model)
            .unwrap();
        &self.model
    }
}

#[test]
fn global_transforms_match_skeleton_binding_in_every_mode() {
    let dir = data_dir();
    // Fast enough to go past the clip's 22.9 s end in 80 frames.
    for (mode, speed) in [
        (Playback::Loop, 20.0),
        (Playback::Clamp, 20.0),
        (Playback::PingPong, 20.0),
        (Playback::Loop, -7.5),
    ] {
        let mut app = app(Path::new(&dir));
        let clip = load(&mut app, BVH).unwrap();
        let (root, joints) = spawn_player(
            &mut app,
            &clip,
            TcbPlayer::new(clip.clone())
                .with_playback(mode)
                .with_speed(speed),
        );
        let mut reference = Reference::new(&app, &clip, mode);
        let mut worst = 0.0f32;
        for frame in 0..80 {
            app.update();
            let time = player(&app, root).time().expect("bound on its first frame");
            // Time 0 on the first frame, then speed * dt more a frame.
            assert!((time - speed * DT * frame as f64).abs() < 1e-9, "{time}");
            worst = worst.max(largest_error(&app, &joints, reference.at(time)));
        }
        println!("{mode:?} at speed {speed}: largest relative error {worst:e}");
        assert!(worst < 1e-5, "{mode:?}: {worst}");
        // The 31 animated joints; the 7 End Sites keep their spawned transforms.
        assert_eq!(player(&app, root).joint_count(), 31);
        assert!(player(&app, root).error().is_none());
    }
}

#[test]
fn a_cross_fade_blends_the_two_clips_in_the_rig() {
    let dir = data_dir();
    let mut app = app(Path::new(&dir));
    let clip = load(&mut app, BVH).unwrap();
    let (root, joints) = spawn_player(&mut app, &clip, TcbPlayer::new(clip.clone()));
    for _ in 0..30 {
        app.update();
    }
    let before = player(&app, root).time().unwrap();
    // The same clip again, from its start: the fade blends two times of it.
    let fade = 0.5;
    app.world_mut()
        .get_mut::<TcbPlayer>(root)
        .unwrap()
        .cross_fade(clip.clone(), fade);

    let rig = player(&app, root).rig().unwrap().clone();
    let compiled = app
        .world()
        .resource::<Assets<TcbClip>>()
        .get(&clip)
        .unwrap()
        .clip()
        .clone();
    let mut old = Instance::with_rig(compiled.clone(), &rig).unwrap();
    let mut new = Instance::with_rig(compiled, &rig).unwrap();
    old.set_playback(Playback::Loop, 1.0).unwrap();
    new.set_playback(Playback::Loop, 1.0).unwrap();
    let binding = SkeletonBinding::for_layout(skeleton_of(&app, &clip), rig.layout());
    let mut out = rig.rest_pose();
    let n = joints.len();
    let (mut local, mut model) = (
        vec![Default::default(); n],
        vec![glam::Affine3A::IDENTITY; n],
    );

    let mut worst = 0.0f32;
    for frame in 1..=40 {
        app.update();
        let p = player(&app, root);
        // The new clip starts at 0 on the first frame after the request
        // (weight 0), the old one goes on.
        let t = (frame - 1) as f64 * DT;
        let w = (t / fade).min(1.0) as f32;
        assert!(
            (p.weight() - w).abs() < 1e-6,
            "frame {frame}: {} {w}",
            p.weight()
        );
        assert!((p.time().unwrap() - t).abs() < 1e-9);
        if w < 1.0 {
            let layers = [
                (old.sample(before + frame as f64 * DT), 1.0 - w),
                (new.sample(t), w),
            ];
            blend(&mut out, &layers, None).unwrap();
            binding
                .model_transforms(&out, &mut local, &mut model)
                .unwrap();
        } else {
            binding
                .model_transforms(new.sample(t), &mut local, &mut model)
                .unwrap();
        }
        worst = worst.max(largest_error(&app, &joints, &model));
    }
    println!("cross-fade: largest relative error {worst:e}");
    assert!(worst < 1e-5, "{worst}");
    assert_eq!(player(&app, root).weight(), 1.0);
}

#[test]
fn speed_and_seek_change_the_time_without_a_jump() {
    let dir = data_dir();
    let mut app = app(Path::new(&dir));
    let clip = load(&mut app, BVH).unwrap();
    let (root, _) = spawn_player(&mut app, &clip, TcbPlayer::new(clip.clone()));
    for _ in 0..10 {
        app.update();
    }
    let t0 = player(&app, root).time().unwrap();
    let mut p = app.world_mut().get_mut::<TcbPlayer>(root).unwrap();
    p.set_speed(2.0);
    p.set_speed(f64::NAN); // ignored
    app.update();
    let t1 = player(&app, root).time().unwrap();
    assert!((t1 - t0 - 2.0 * DT).abs() < 1e-12);
    app.world_mut()
        .get_mut::<TcbPlayer>(root)
        .unwrap()
        .seek(5.0);
    app.update();
    assert!((player(&app, root).time().unwrap() - (5.0 + 2.0 * DT)).abs() < 1e-12);
}

#[test]
fn a_player_with_no_joints_says_so_and_binds_when_they_come() {
    let dir = data_dir();
    let mut app = app(Path::new(&dir));
    let clip = load(&mut app, BVH).unwrap();
    let root = app
        .world_mut()
        .spawn((Transform::IDENTITY, TcbPlayer::new(clip.clone())))
        .id();
    app.update();
    let message = player(&app, root).error().unwrap().to_string();
    assert!(message.contains("no entity under"), "{message}");
    assert!(!player(&app, root).is_bound());
    let skeleton = skeleton_of(&app, &clip);
    let world = app.world_mut();
    spawn_skeleton(&mut world.commands(), &skeleton, root);
    world.flush();
    app.update();
    assert!(player(&app, root).is_bound());
    assert!(player(&app, root).error().is_none());
}

#[test]
fn a_clip_whose_tracks_the_rig_lacks_is_refused_and_play_goes_on() {
    let dir = data_dir();
    let mut app = app(Path::new(&dir));
    let clip = load(&mut app, BVH).unwrap();
    let (root, _) = spawn_player(&mut app, &clip, TcbPlayer::new(clip.clone()));
    app.update();
    let text = r#"{"format": "tcb-clip/1", "tracks": [
        {"name": "Tail.rotation", "kind": "quat", "times": [0, 1],
         "values": [[0, 0, 0, 1], [0, 0, 0, 1]]}]}"#;
    let other = tcb_runtime::Clip::compile(&tcb_io::ClipDoc::parse(text).unwrap().build().unwrap());
    let other = app
        .world_mut()
        .resource_mut::<Assets<TcbClip>>()
        .add(TcbClip::new(Arc::new(other), None));
    app.world_mut()
        .get_mut::<TcbPlayer>(root)
        .unwrap()
        .play(other);
    let t = player(&app, root).time().unwrap();
    app.update();
    let p = player(&app, root);
    assert!(
        p.error().unwrap().contains("Tail.rotation"),
        "{:?}",
        p.error()
    );
    assert_eq!(p.clip(), &clip);
    assert!(p.time().unwrap() > t);
}
