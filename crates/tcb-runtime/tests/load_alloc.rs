//! Loading a `.tcbc` file allocates nothing larger than the file for the
//! tracks on its grid: the key times are `start + k interval`, not a list,
//! and the block table is read from the file, so a small file cannot make
//! the reader allocate for the keys it claims. Tracks on key times of their
//! own are compiled to f32 at load, in a bounded multiple of their bytes.
//! Counted by a global allocator on the loading thread.

use std::sync::Arc;
use tcb_core::{Tcb, TrackKind, TrackSettings};
use tcb_runtime::{Clip, Instance, PackSource, PackTrack, Packed};
use tcb_test_support::{CountingAllocator, count_allocations};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// `Clip::from_bytes` of `bytes`, checked to make no allocation larger
/// than them.
fn load(bytes: &[u8]) -> Clip {
    let (clip, counted) = count_allocations(|| Clip::from_bytes(bytes));
    assert!(
        counted.largest <= bytes.len(),
        "an allocation of {} bytes for a file of {}",
        counted.largest,
        bytes.len()
    );
    clip.unwrap()
}

/// A scalar track `level` of `keys` keys, every one 0.75.
fn level(keys: usize) -> PackTrack {
    PackTrack {
        name: "level".into(),
        kind: TrackKind::Scalar,
        settings: TrackSettings::default(),
        tcb: Tcb::default(),
        rebuild_w: false,
        step: 0.25,
        center: None,
        values: vec![vec![3; keys]],
    }
}

#[test]
fn a_long_constant_clip_loads_in_less_than_its_file() {
    // The most keys a packed clip of one track may have, all one value: a
    // file of its block table and a few bytes, where a list of its key
    // times would take 32 MiB.
    let keys = tcb_runtime::pack::MAX_TRACK_KEYS;
    let track = level(keys);
    let source = PackSource {
        name: "long".into(),
        start: 0.0,
        interval: 1.0 / 120.0,
        keys,
        tracks: vec![track],
        scales: Default::default(),
        loose: Vec::new(),
    };
    let bytes = Packed::encode(&source).unwrap().to_bytes();
    let clip = load(&bytes);
    let level = clip.track("level").unwrap();
    let mut play = Instance::new(Arc::new(clip));
    for t in [0.0, 1.0 / 240.0, 9000.5, 34952.52] {
        assert_eq!(play.sample(t).scalar(level), Some(0.75), "at {t}");
    }
}

#[test]
fn capture_loads_in_less_than_its_file() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let options = tcb_io::ImportOptions::default().rotation(tcb_core::RotationMode::Hermite);
    let cmu = tcb_io::load_with(format!("{root}/data/cmu-01_01.bvh"), &options)
        .unwrap()
        .clip;
    let steps = vec![1.0 / 4096.0; cmu.tracks().len()];
    let source = PackSource::quantize(&cmu, &steps).unwrap();
    let bytes = Packed::encode(&source).unwrap().to_bytes();
    let clip = load(&bytes);
    clip.verify_packed().unwrap();
}

/// Tracks on key times of their own are decoded at load into the
/// reference's tracks and compiled to f32 controls: the largest allocation
/// is then a bounded multiple of the file (their f64 times take 8 bytes a
/// key in the file, their controls 12 bytes a key and component at run
/// time, the reference's segments more while compiling).
#[test]
fn tracks_on_their_own_key_times_load_in_a_bounded_multiple_of_their_file() {
    use tcb_runtime::pack::LooseTrack;
    let keys = 100_000;
    let grid = level(2);
    let own = LooseTrack {
        at: 0,
        name: "turn".into(),
        kind: TrackKind::Quat,
        settings: TrackSettings {
            rotation: tcb_core::RotationMode::Hermite,
            ..TrackSettings::default()
        },
        times: (0..keys).map(|k| k as f64 / 7.0).collect(),
        step: 0.5,
        values: vec![vec![0; keys], vec![0; keys], vec![0; keys], vec![2; keys]],
        tangents: None,
    };
    let source = PackSource {
        name: "own".into(),
        start: 0.0,
        interval: 1.0,
        keys: 2,
        tracks: vec![grid],
        scales: Default::default(),
        loose: vec![own],
    };
    let bytes = Packed::encode(&source).unwrap().to_bytes();
    let (clip, counted) = count_allocations(|| Clip::from_bytes(&bytes));
    let clip = clip.unwrap();
    assert!(
        counted.largest <= LOOSE_FACTOR * bytes.len(),
        "{} for {}",
        counted.largest,
        bytes.len()
    );
    let turn = clip.track("turn").unwrap();
    let q = Instance::new(Arc::new(clip))
        .sample(1234.5)
        .quat(turn)
        .unwrap();
    assert_eq!(q.to_array(), [0.0, 0.0, 0.0, 1.0]);
}

/// What a track on key times of its own may allocate at load, per byte of
/// file: measured 17.0 for a rotation of constant keys (8 bytes a key in
/// the file, 136 in the reference track's largest list while compiling).
const LOOSE_FACTOR: usize = 20;
