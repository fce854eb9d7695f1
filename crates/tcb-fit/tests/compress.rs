//! `tcb compress`'s search (`tcb_fit::compress`) on the bundled CMU clip.

use std::sync::Arc;
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
    // Its step holds in every block: no block has a factor on the steps.
    assert!(source.scales.codes.is_empty(), "{:?}", source.scales);
}

/// At ACL's target (docs/tcbc.md), the blocks' factors on the steps: some
/// above 1, the file smaller than with every factor 1, and the file read
/// back and measured again within the tolerance at every check time.
#[test]
fn blocks_take_coarser_steps_where_the_error_has_room() {
    let loaded = cmu();
    let skeleton = loaded.skeleton.as_ref();
    let options = CompressOptions::default()
        .tolerance(Some(1.509e-3))
        .shell(Some(0.4527));
    let c = tcb_fit::compress(&loaded.clip, skeleton, &options, &|_, _| {}).unwrap();
    assert!(c.worst.ratio <= 1.0, "{:?}", c.worst);
    let bytes = c.packed.to_bytes();
    let back = Arc::new(tcb_runtime::Packed::from_bytes(&bytes).unwrap());
    let source = back.decode().unwrap();
    let codes = &source.scales.codes;
    assert_eq!(codes.len(), loaded.clip.key_times().len().div_ceil(64));
    assert!(
        codes.iter().filter(|c| **c > 0).count() > codes.len() / 2,
        "{codes:?}"
    );
    // Every factor 1, the same steps: more bytes.
    let mut plain = source.clone();
    plain.scales = Default::default();
    let keys = tcb_runtime::KeyValues::sample(&loaded.clip).unwrap();
    let steps: Vec<f32> = plain.tracks.iter().map(|t| t.step).collect();
    let unscaled = tcb_runtime::Packed::encode(&keys.quantize(&steps).unwrap()).unwrap();
    assert!(
        bytes.len() < unscaled.to_bytes().len(),
        "{} against {}",
        bytes.len(),
        unscaled.to_bytes().len()
    );
    // Measured again from the file's bytes.
    let played = Arc::new(tcb_runtime::Clip::from_packed(back).unwrap());
    let reference = Arc::new(tcb_runtime::Clip::compile(&loaded.clip));
    let times = tcb_fit::metric::check_times(&loaded.clip);
    let m = tcb_fit::metric::shell_error(
        skeleton.unwrap(),
        &reference,
        &played,
        &times,
        0.4527,
        1.509e-3,
    );
    assert!(m.worst.ratio <= 1.0, "{:?}", m.worst);
    assert_eq!(m.at_time.len(), times.len());
    assert_eq!(m.worst.ratio, m.at_time.iter().copied().fold(0.0, f64::max));
}

/// Values near 1e10 (a track whose finest step, its largest value over
/// 2^22, is above the coarsest the search tries, 1e3): the search once
/// panicked (`clamp` with its minimum above its maximum). Found by the
/// `compress` fuzz target.
#[test]
fn huge_values_are_compressed_or_refused_without_a_panic() {
    let times: Vec<f64> = (0..40).map(|k| f64::from(k) / 30.0).collect();
    let values = times
        .iter()
        .map(|t| 8e9 + 1e6 * (*t as f32).sin())
        .collect();
    let track = Track::new(times, values, vec![], &TrackSettings::default()).unwrap();
    let clip = tcb_core::SourceClip::new(
        "huge",
        vec![NamedTrack {
            name: "x".into(),
            data: TrackData::Scalar(track),
        }],
    )
    .unwrap();
    let c = tcb_fit::compress(&clip, None, &CompressOptions::default(), &|_, _| {});
    if let Ok(c) = c {
        assert!(c.worst.ratio <= 1.0, "{:?}", c.worst);
    }
}
