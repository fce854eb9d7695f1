//! `tcb compress`'s search (`tcb_fit::compress`) on the bundled CMU clip.

use tcb_core::{NamedTrack, RotationMode, Track, TrackData, TrackSettings};
use tcb_fit::CompressOptions;

const BVH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");

fn cmu() -> tcb_io::Loaded {
    let options = tcb_io::ImportOptions::default().rotation(RotationMode::Hermite);
    tcb_io::load_with(BVH, &options).unwrap()
}

/// A track no joint uses (a camera's field of view, 60 degrees) beside the
/// skeleton's: the shell metric does not see it, and it must not make the
/// search fail (it once took a step so fine that 60 had no integer).
#[test]
fn a_track_no_joint_uses_is_kept_finely() {
    let loaded = cmu();
    let times = loaded.clip.key_times();
    let fov = Track::new(
        times.clone(),
        times.iter().map(|t| 60.0 + (*t as f32).sin()).collect(),
        vec![],
        &TrackSettings::default(),
    )
    .unwrap();
    let mut tracks = loaded.clip.tracks().to_vec();
    tracks.push(NamedTrack {
        name: "camera.fov".into(),
        data: TrackData::Scalar(fov),
    });
    let clip = tcb_core::SourceClip::new("cmu+fov", tracks).unwrap();
    let c = tcb_fit::compress(
        &clip,
        loaded.skeleton.as_ref(),
        &CompressOptions::default(),
        &|_, _| {},
    )
    .unwrap();
    assert!(c.worst.ratio <= 1.0, "{:?}", c.worst);
    // The file reads back, and the field of view is kept within 1e-4
    // (the value metric's default), in steps of 2e-4.
    let bytes = c.packed.to_bytes();
    let back = tcb_runtime::Packed::from_bytes(&bytes).unwrap();
    let source = back.decode().unwrap();
    let fov = source
        .tracks
        .iter()
        .find(|t| t.name == "camera.fov")
        .unwrap();
    assert!(fov.step <= 2e-4, "{}", fov.step);
}
