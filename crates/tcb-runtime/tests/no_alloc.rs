//! Steady playback allocates nothing: sampling, velocities, the reference
//! fallbacks and blending, counted by a global allocator on the sampling
//! thread only (the test harness's own threads may allocate meanwhile: one
//! run in CI-like conditions saw 4 such allocations).

use std::sync::Arc;
use tcb_test_support::{CountingAllocator, count_allocations};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn steady_playback_and_blending_allocate_nothing() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    // Every layout: vectors, hermite and squad rotations, a mixed hermite
    // rotation sampled by the reference, offset-repeat, several groups.
    let mut clips = Vec::new();
    for name in [
        "examples/clips/bounce.json",
        "tools/check/clips/rotations.json",
        "tools/check/clips/extrapolation.json",
        "examples/clips/spin.json",
    ] {
        let clip = tcb_io::load_clip(format!("{root}/{name}")).unwrap();
        clips.push(Arc::new(tcb_runtime::Clip::compile(&clip)));
        let quantize = tcb_runtime::CompileOptions::default().quantize(true);
        clips.push(Arc::new(tcb_runtime::Clip::compile_with(&clip, &quantize)));
    }
    // A packed clip (decoded as playback crosses keys, seeks included).
    let options = tcb_io::ImportOptions::default().rotation(tcb_core::RotationMode::Hermite);
    let cmu = tcb_io::load_with(format!("{root}/data/cmu-01_01.bvh"), &options)
        .unwrap()
        .clip;
    let source = tcb_runtime::PackSource::quantize(&cmu, &vec![1.0 / 4096.0; cmu.tracks().len()]);
    let packed = tcb_runtime::Packed::encode(&source.unwrap()).unwrap();
    clips.push(Arc::new(
        tcb_runtime::Clip::from_packed(Arc::new(packed)).unwrap(),
    ));
    for clip in clips {
        let mut a = tcb_runtime::Instance::new(clip.clone()).with_velocities();
        let mut b = tcb_runtime::Instance::new(clip.clone()).with_velocities();
        // Playback at the instance: ping-pong at 1.5x, velocities scaled.
        b.set_playback(tcb_runtime::Playback::PingPong, 1.5)
            .unwrap();
        let mut out = a.pose().clone();
        let mask =
            tcb_runtime::BlendMask::new(&clip, |t| if t.index() % 2 == 0 { 1.0 } else { 0.25 });
        // Through a rig (every track, plus one the clip lacks).
        let mut tracks = tcb_runtime::Rig::from_clip(&clip)
            .unwrap()
            .tracks()
            .to_vec();
        tracks.push(tcb_runtime::RigTrack {
            name: "extra".into(),
            kind: tcb_core::TrackKind::Quat,
            rest: [0.0, 0.0, 0.0, 1.0],
        });
        let rig = Arc::new(tcb_runtime::Rig::new(tracks).unwrap());
        let mut r = tcb_runtime::Instance::with_rig(clip.clone(), &rig)
            .unwrap()
            .with_velocities();
        let mut rest = rig.rest_pose().with_velocities();
        r.sample(0.0);
        // Warm up once.
        a.sample(0.0);
        b.sample(0.0);
        let ((), counted) = count_allocations(|| {
            for frame in 0..2000 {
                let t = -3.0 + frame as f64 / 120.0;
                a.sample(t);
                b.sample(t * 0.5 + 1e6);
                tcb_runtime::blend(&mut out, &[(a.pose(), 0.7), (b.pose(), 0.3)], None).unwrap();
                tcb_runtime::blend(
                    &mut out,
                    &[(a.pose(), 1.0), (b.pose(), 1.0)],
                    Some(&[&mask, &mask]),
                )
                .unwrap();
                r.sample(t * 0.25);
                tcb_runtime::blend::add(&mut rest, r.pose(), r.pose(), 0.5, None).unwrap();
                tcb_runtime::blend::add(&mut out, a.pose(), b.pose(), 0.5, Some(&mask)).unwrap();
            }
        });
        assert_eq!(
            counted.count,
            0,
            "{} allocations in 2000 frames of {}",
            counted.count,
            clip.name()
        );
    }
}

/// Loading a packed clip allocates its stream, its grid's times and, per
/// track, what a few keys take, but nothing per key beyond the grid:
/// `Clip::from_bytes` of CMU 01_01 (2752 keys of 124 stored components,
/// 1.4 MB as 32-bit integers, about 3 MB compiled in f32) asks for no more
/// over its first 688 keys than their stream and three times their grid.
#[test]
fn loading_a_packed_clip_allocates_no_keys() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let options = tcb_io::ImportOptions::default().rotation(tcb_core::RotationMode::Hermite);
    let cmu = tcb_io::load_with(format!("{root}/data/cmu-01_01.bvh"), &options)
        .unwrap()
        .clip;
    let full =
        tcb_runtime::PackSource::quantize(&cmu, &vec![1.0 / 4096.0; cmu.tracks().len()]).unwrap();
    let mut short = full.clone();
    short.keys = 688;
    for t in &mut short.tracks {
        t.values.iter_mut().for_each(|v| v.truncate(short.keys));
    }
    let asked = |source: &tcb_runtime::PackSource| {
        let bytes = tcb_runtime::Packed::encode(source).unwrap().to_bytes();
        let (clip, counted) = count_allocations(|| tcb_runtime::Clip::from_bytes(&bytes).unwrap());
        let asked = counted.bytes;
        // The full check is apart, and holds.
        clip.verify_packed().unwrap();
        (asked, bytes.len())
    };
    let ((a_full, b_full), (a_short, b_short)) = (asked(&full), asked(&short));
    let more_keys = full.keys - short.keys;
    let limit = (b_full - b_short) + 3 * 8 * more_keys + 4096;
    assert!(
        a_full - a_short <= limit,
        "{a_full} bytes asked for {} keys, {a_short} for {}: {} more, limit {limit}",
        full.keys,
        short.keys,
        a_full - a_short
    );
}
