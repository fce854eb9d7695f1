//! The sampling kernel on synthetic clips, against the tcb-core reference
//! in the same process. The full comparison on real data is tcb-bench's.
//!
//! `cargo bench -p tcb-runtime --bench kernel` (add
//! `RUSTFLAGS="-C target-cpu=native"` for AVX2/FMA builds of `wide`).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Quat, Vec3};
use std::hint::black_box;
use std::sync::Arc;
use tcb_core::{NamedTrack, RotationMode, RotationTrack, Track, TrackData, TrackSettings};
use tcb_runtime::{Clip, CompileOptions, Instance, Rig, blend};

fn times(n: usize, seed: u64) -> Vec<f64> {
    let mut x = seed;
    let mut t = vec![0.0];
    for _ in 1..n {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let gap = 0.05 + (x >> 40) as f64 / (1u64 << 24) as f64 * 0.2;
        t.push(t[t.len() - 1] + gap);
    }
    t
}

fn scalar_tracks(count: usize, keys: usize, shared: bool) -> tcb_core::SourceClip {
    let s = TrackSettings::default();
    let tracks = (0..count)
        .map(|i| {
            let t = times(keys, if shared { 1 } else { i as u64 + 1 });
            let v = (0..keys).map(|k| ((k * 7 + i) % 13) as f32 * 0.1).collect();
            NamedTrack {
                name: format!("c{i}"),
                data: TrackData::Scalar(Track::new(t, v, vec![], &s).unwrap()),
            }
        })
        .collect();
    tcb_core::SourceClip::new("synthetic", tracks).expect("unique track names")
}

/// `count` rotations, each on key times of its own.
fn sparse_rotations(count: usize, keys: usize, mode: RotationMode) -> tcb_core::SourceClip {
    let s = TrackSettings {
        rotation: mode,
        ..Default::default()
    };
    let tracks = (0..count)
        .map(|i| {
            let t = times(keys, i as u64 + 1);
            let q = (0..keys)
                .map(|k| {
                    Quat::from_euler(
                        glam::EulerRot::ZXY,
                        (k + i) as f32 * 0.05,
                        k as f32 * 0.03,
                        0.2,
                    )
                })
                .collect();
            NamedTrack {
                name: format!("r{i}"),
                data: TrackData::Quat(RotationTrack::new(t, q, vec![], &s).unwrap()),
            }
        })
        .collect();
    tcb_core::SourceClip::new("sparse-rotations", tracks).expect("unique track names")
}

fn skeleton(joints: usize, keys: usize, mode: RotationMode) -> tcb_core::SourceClip {
    skeleton_turning(joints, keys, mode, 1.0)
}

/// As `skeleton`, the rotation between keys `turn` times larger (large
/// turns put squad segments on the exact f64 path).
fn skeleton_turning(
    joints: usize,
    keys: usize,
    mode: RotationMode,
    turn: f32,
) -> tcb_core::SourceClip {
    let s = TrackSettings {
        rotation: mode,
        ..Default::default()
    };
    let t = times(keys, 1);
    let mut tracks = vec![NamedTrack {
        name: "root.translation".into(),
        data: TrackData::Vec3(
            Track::new(
                t.clone(),
                (0..keys)
                    .map(|k| Vec3::new(k as f32 * 0.1, 1.0, 0.0))
                    .collect(),
                vec![],
                &s,
            )
            .unwrap(),
        ),
    }];
    for j in 0..joints {
        let q = (0..keys)
            .map(|k| {
                Quat::from_euler(
                    glam::EulerRot::ZXY,
                    (k + j) as f32 * 0.05 * turn,
                    k as f32 * 0.03 * turn,
                    0.2,
                )
            })
            .collect();
        tracks.push(NamedTrack {
            name: format!("j{j}.rotation"),
            data: TrackData::Quat(RotationTrack::new(t.clone(), q, vec![], &s).unwrap()),
        });
    }
    tcb_core::SourceClip::new("skeleton", tracks).expect("unique track names")
}

fn play(c: &mut Criterion, group: &str, clip: &tcb_core::SourceClip, channels: u64) {
    play_with(c, group, clip, channels, &CompileOptions::default());
}

fn play_with(
    c: &mut Criterion,
    group: &str,
    clip: &tcb_core::SourceClip,
    channels: u64,
    options: &CompileOptions,
) {
    let compiled = Arc::new(Clip::compile_with(clip, options));
    let (a, b) = clip.time_range().unwrap();
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(channels));
    let mut inst = Instance::new(compiled);
    let mut frame = 0u64;
    g.bench_function(BenchmarkId::new("runtime", channels), |bench| {
        bench.iter(|| {
            frame += 1;
            let t = a + (frame as f64 / 60.0) % (b - a);
            black_box(inst.sample(black_box(t)));
        })
    });
    let mut row = vec![0.0f32; clip.channel_count()];
    g.bench_function(BenchmarkId::new("reference", channels), |bench| {
        bench.iter(|| {
            frame += 1;
            let t = a + (frame as f64 / 60.0) % (b - a);
            clip.sample_into(black_box(t), &mut row, None);
            black_box(&row);
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    play(c, "wide", &scalar_tracks(10_000, 64, true), 10_000);
    play(c, "sparse", &scalar_tracks(500, 64, false), 500);
    play(
        c,
        "skeleton_hermite",
        &skeleton(31, 200, RotationMode::Hermite),
        31,
    );
    play(
        c,
        "skeleton_squad",
        &skeleton(31, 200, RotationMode::Squad),
        31,
    );
    // Squad with large turns between keys: the exact f64 lanes.
    let turning = skeleton_turning(31, 200, RotationMode::Squad, 30.0);
    assert!(Clip::compile(&turning).stats().exact_segments > 1000);
    play(c, "skeleton_squad_exact", &turning, 31);
    let quantize = CompileOptions::default().quantize(true);
    play_with(
        c,
        "skeleton_hermite_quantized",
        &skeleton(31, 200, RotationMode::Hermite),
        31,
        &quantize,
    );
    play_with(
        c,
        "wide_quantized",
        &scalar_tracks(10_000, 64, true),
        10_000,
        &quantize,
    );
    for (name, mode) in [
        ("sparse_rotations_hermite", RotationMode::Hermite),
        ("sparse_rotations_squad", RotationMode::Squad),
    ] {
        play(c, name, &sparse_rotations(64, 64, mode), 64);
    }
    packed(c);
    rig_and_blend(c);
}

/// A packed clip (`tcb_runtime::pack`, what `tcb compress` writes): the
/// bundled CMU capture (hermite) in steps of 1/4096, decoded as playback
/// crosses keys (`packed/forward`, 60 fps; `packed/backward`, the same
/// backwards), at random times (`packed/seek`:
/// each a decode from the start of a block), and the same clip in f32
/// (`packed/f32`).
fn packed(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let options = tcb_io::ImportOptions::default().rotation(RotationMode::Hermite);
    let clip = tcb_io::load_with(path, &options).unwrap().clip;
    let steps = vec![1.0 / 4096.0; clip.tracks().len()];
    let source = tcb_runtime::PackSource::quantize(&clip, &steps).unwrap();
    let packed = Arc::new(tcb_runtime::Packed::encode(&source).unwrap());
    let compiled = Arc::new(Clip::from_packed(packed).unwrap());
    let dense = Arc::new(Clip::compile(&source.to_clip().unwrap()));
    let (a, b) = clip.time_range().unwrap();
    let mut g = c.benchmark_group("packed");
    g.throughput(Throughput::Elements(31));
    for (name, clip) in [("forward", &compiled), ("f32", &dense)] {
        let mut inst = Instance::new(clip.clone());
        let mut frame = 0u64;
        g.bench_function(name, |bench| {
            bench.iter(|| {
                frame += 1;
                let t = a + (frame as f64 / 60.0) % (b - a);
                black_box(inst.sample(black_box(t)));
            })
        });
    }
    // Backwards at 60 fps: each key crossed decodes from its block's start.
    let mut back = Instance::new(compiled.clone());
    let mut frame = 0u64;
    g.bench_function("backward", |bench| {
        bench.iter(|| {
            frame += 1;
            let t = b - (frame as f64 / 60.0) % (b - a);
            black_box(back.sample(black_box(t)));
        })
    });
    let mut x = 7u64;
    let seeks: Vec<f64> = (0..1024)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect();
    let mut inst = Instance::new(compiled);
    let mut at = 0usize;
    g.bench_function("seek", |bench| {
        bench.iter(|| {
            at = (at + 1) % seeks.len();
            let t = a + seeks[at] * (b - a);
            black_box(inst.sample(black_box(t)));
        })
    });
    g.finish();
}

/// Sampling through a rig (the copy into rig order), blending two rig
/// poses and adding an additive layer.
fn rig_and_blend(c: &mut Criterion) {
    let clip = skeleton(31, 200, RotationMode::Hermite);
    let compiled = Arc::new(Clip::compile(&clip));
    let rig = Arc::new(Rig::from_clip(&compiled).unwrap());
    let mut g = c.benchmark_group("rig");
    g.throughput(Throughput::Elements(31));
    let (mut a, mut b) = (
        Instance::with_rig(compiled.clone(), &rig).unwrap(),
        Instance::with_rig(compiled.clone(), &rig).unwrap(),
    );
    let mut plain = Instance::new(compiled);
    let mut frame = 0u64;
    g.bench_function("sample_plain", |bench| {
        bench.iter(|| {
            frame += 1;
            black_box(plain.sample(black_box(frame as f64 / 600.0 % 9.0)));
        })
    });
    g.bench_function("sample_through_rig", |bench| {
        bench.iter(|| {
            frame += 1;
            black_box(a.sample(black_box(frame as f64 / 600.0 % 9.0)));
        })
    });
    a.sample(1.0);
    b.sample(2.0);
    let mut out = rig.rest_pose();
    g.bench_function("blend_two", |bench| {
        bench.iter(|| blend(&mut out, &[(a.pose(), 0.3), (b.pose(), 0.7)], None).unwrap())
    });
    g.bench_function("add_layer", |bench| {
        bench.iter(|| tcb_runtime::blend::add(&mut out, a.pose(), b.pose(), 0.5, None).unwrap())
    });
    g.finish();
}

criterion_group!(kernel, benches);
criterion_main!(kernel);
