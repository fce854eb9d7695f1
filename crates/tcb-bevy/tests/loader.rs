//! The asset loader on every format it registers, through bevy's
//! `AssetServer` reading a folder: the clip it gives is the one tcb-io and
//! tcb-runtime give for the same file.

mod common;

use bevy::asset::Assets;
use bevy::transform::components::{GlobalTransform, Transform};
use common::{app, load};
use std::path::PathBuf;
use std::sync::Arc;
use tcb_bevy::{TcbClip, TcbPlayer, spawn_skeleton};
use tcb_runtime::{Clip, Instance, PackSource, Packed, Playback, SkeletonBinding};

/// A folder of the CMU clip in every format, and a damaged file.
/// (`test`: the folder's name, one per test, as tests run side by side.)
fn assets(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tcb-bevy-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bvh = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let loaded = tcb_io::load(bvh).unwrap();
    std::fs::copy(bvh, dir.join("cmu.bvh")).unwrap();
    std::fs::write(dir.join("cmu.json"), loaded.doc.to_json()).unwrap();
    for (name, container) in [
        ("cmu.glb", tcb_io::gltf_export::Container::Glb),
        ("cmu.gltf", tcb_io::gltf_export::Container::Gltf),
    ] {
        let options = tcb_io::gltf_export::ExportOptions::default();
        let (bytes, _) = tcb_io::gltf_export::export(
            &loaded.clip,
            loaded.skeleton.as_ref(),
            container,
            &options,
        )
        .unwrap();
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let steps = vec![1.0 / 4096.0; loaded.clip.tracks().len()];
    let mut packed = Packed::encode(&PackSource::quantize(&loaded.clip, &steps).unwrap()).unwrap();
    // Without a skeleton, then with it, as `tcb compress` writes it.
    std::fs::write(dir.join("bare.tcbc"), packed.to_bytes()).unwrap();
    packed.skeleton = loaded.skeleton.clone();
    std::fs::write(dir.join("cmu.tcbc"), packed.to_bytes()).unwrap();
    std::fs::write(dir.join("broken.bvh"), "HIERARCHY\nROOT").unwrap();
    dir
}

#[test]
fn every_format_loads_as_tcb_loads_it() {
    let dir = assets("formats");
    let mut app = app(&dir);
    let reference = tcb_io::load(dir.join("cmu.bvh")).unwrap();
    for name in ["cmu.bvh", "cmu.json", "cmu.glb", "cmu.gltf", "cmu.tcbc"] {
        let handle = load(&mut app, name).unwrap_or_else(|| panic!("{name} did not load"));
        let clips = app.world().resource::<Assets<TcbClip>>();
        let asset = clips.get(&handle).unwrap();
        let mut names: Vec<_> = asset
            .clip()
            .tracks()
            .iter()
            .map(|t| t.name().to_string())
            .collect();
        names.sort();
        let mut want: Vec<_> = reference
            .clip
            .tracks()
            .iter()
            .map(|t| t.name.clone())
            .collect();
        want.sort();
        assert_eq!(names, want, "{name}");
        // Every one carries a skeleton (glTF's joints in its node order);
        // the .tcbc the one it was written with.
        assert!(asset.skeleton().is_some(), "{name}");
        if name == "cmu.tcbc" {
            assert_eq!(asset.skeleton(), reference.skeleton.as_ref());
        }
    }
    let bare = load(&mut app, "bare.tcbc").unwrap();
    let clips = app.world().resource::<Assets<TcbClip>>();
    assert!(clips.get(&bare).unwrap().skeleton().is_none());
    assert!(load(&mut app, "broken.bvh").is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A `.tcbc` without a skeleton plays on joints spawned from the BVH's,
/// and the joints are where `SkeletonBinding` puts them on the packed clip.
#[test]
fn a_packed_clip_plays_on_joints_it_does_not_carry() {
    let dir = assets("packed");
    let mut app = app(&dir);
    let skeleton = tcb_io::load(dir.join("cmu.bvh")).unwrap().skeleton.unwrap();
    let handle = load(&mut app, "bare.tcbc").unwrap();
    let world = app.world_mut();
    let root = world
        .spawn((Transform::IDENTITY, TcbPlayer::new(handle)))
        .id();
    let joints = spawn_skeleton(&mut world.commands(), &skeleton, root);
    world.flush();
    for _ in 0..20 {
        app.update();
    }
    let time = app.world().get::<TcbPlayer>(root).unwrap().time().unwrap();
    let packed =
        Arc::new(Clip::from_bytes(&std::fs::read(dir.join("bare.tcbc")).unwrap()).unwrap());
    let binding = SkeletonBinding::new(skeleton, &packed);
    let mut instance = Instance::new(packed);
    instance.set_playback(Playback::Loop, 1.0).unwrap();
    let n = joints.len();
    let (mut local, mut model) = (
        vec![Default::default(); n],
        vec![glam::Affine3A::IDENTITY; n],
    );
    binding
        .model_transforms(instance.sample(time), &mut local, &mut model)
        .unwrap();
    for (&e, m) in joints.iter().zip(&model) {
        let g = app.world().get::<GlobalTransform>(e).unwrap().affine();
        let (a, b) = (g.translation.to_array(), m.translation.to_array());
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-5 * (1.0 + y.abs()), "{a:?} {b:?}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
