//! The AVX2 instance of the kernels (`tcb_runtime::simd`) against the
//! build's own, bit for bit: the CMU capture in both rotation modes and
//! with 16-bit controls, every bundled clip, tracks on key times of their
//! own (loose lanes) of every kind, and tangents beyond f32 (the
//! out-of-range redo), at keys, between them and beyond them, with and
//! without velocities; and the packed decoder's instances on packed
//! clips. One test in its own binary: it switches the process-wide
//! choice. In builds with AVX2 enabled (`-C target-cpu=native`), the group
//! kernels, the 16-bit expansion and the loose blocks are `wide`'s own
//! AVX2 already: there the comparisons are of one instance with itself.

use std::sync::Arc;
use tcb_core::params::RotationMode;
use tcb_runtime::{Clip, Instance, Simd};

mod common;

/// Rows of `clip` at `times` with the instance `force_baseline` picks.
fn rows(clip: &tcb_core::SourceClip, times: &[f64], baseline: bool) -> Vec<u32> {
    tcb_runtime::force_baseline_simd(baseline);
    compiled_rows(Arc::new(Clip::compile(clip)), times)
}

/// [`rows`] of `clip` compiled with 16-bit controls.
fn quantized_rows(clip: &tcb_core::SourceClip, times: &[f64], baseline: bool) -> Vec<u32> {
    tcb_runtime::force_baseline_simd(baseline);
    let mut options = tcb_runtime::CompileOptions::default();
    options.quantize = true;
    compiled_rows(Arc::new(Clip::compile_with(clip, &options)), times)
}

/// Rows of a compiled clip at `times`, without and with velocities.
fn compiled_rows(compiled: Arc<Clip>, times: &[f64]) -> Vec<u32> {
    let n = compiled.channel_count();
    let (mut v, mut dv) = (vec![0.0f32; n], vec![0.0f32; n]);
    let mut plain = Instance::new(compiled.clone());
    let mut with_v = Instance::new(compiled).with_velocities();
    let mut out = Vec::new();
    for &t in times {
        plain.sample(t).write_row(&mut v, None);
        out.extend(v.iter().map(|x| x.to_bits()));
        with_v.sample(t).write_row(&mut v, Some(&mut dv));
        out.extend(v.iter().chain(&dv).map(|x| x.to_bits()));
    }
    out
}

fn same_bits(name: &str, clip: &tcb_core::SourceClip, times: &[f64]) {
    let avx2 = rows(clip, times, false);
    let base = rows(clip, times, true);
    compare(name, &avx2, &base);
}

fn compare(name: &str, avx2: &[u32], base: &[u32]) {
    if let Some(i) = (0..base.len()).find(|&i| avx2[i] != base[i]) {
        panic!(
            "{name}: value {i} is {} with AVX2 and {} without",
            f32::from_bits(avx2[i]),
            f32::from_bits(base[i])
        );
    }
}

/// 32 tracks, each on key times of its own: 16 vector tracks (scalars
/// and 3-vectors) and 16 `hermite` rotations, loose lanes in two blocks of
/// each, with eases, steps, every extrapolation mode and, on one
/// scalar, tangents beyond f32 (its block is `unbounded`: at a segment's
/// end the key is selected).
fn loose_clip() -> tcb_core::SourceClip {
    let modes = [
        "constant",
        "linear",
        "repeat",
        "offset-repeat",
        "oscillate",
        "reset",
    ];
    let tracks: Vec<String> = (0..32)
        .map(|i| {
            let d = 0.05 * i as f64;
            let times = format!("[{d}, {}, {}, {}]", 0.4 + d, 1.1 + d, 1.7 + 2.0 * d);
            let (mut pre, mut post) = (modes[i % 6], modes[(i / 6) % 6]);
            let keys = match i % 3 {
                0 => r#", "keys": [{}, {"ease": [0.5, 0.25]}, {"tcb": [0.5, -0.5, 0.25]}, {}]"#,
                1 => r#", "keys": [{}, {"interp": "step"}, {}, {}]"#,
                _ => "",
            };
            let (kind, values) = match i % 4 {
                // Chords of 6e38: tangents beyond f32.
                0 if i == 4 => ("scalar", "[0, 3e38, -3e38, 3e38]".to_string()),
                0 => ("scalar", format!("[{i}, 3, -1, 2.5]")),
                1 => (
                    "vec3",
                    format!("[[{i}, 0, 1], [1, 2, 3], [-1, 0.5, 2], [0, 0, {d}]]"),
                ),
                _ => {
                    // Rotations have neither `linear` nor `offset-repeat`.
                    for m in [&mut pre, &mut post] {
                        if *m == "linear" || *m == "offset-repeat" {
                            *m = "oscillate";
                        }
                    }
                    (
                        "quat",
                        format!(
                            "[[0, 0, 0, 1], [0.2, 0.1, 0, 0.97], [0.{i}, -0.3, 0.1, 0.9], [0, 0.7, 0, 0.7]]"
                        ),
                    )
                }
            };
            format!(
                r#"{{"name": "t{i}", "kind": "{kind}", "times": {times}, "values": {values}, "pre": "{pre}", "post": "{post}", "rotation": "hermite"{keys}}}"#
            )
        })
        .collect();
    let text = format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
        tracks.join(",")
    );
    tcb_io::ClipDoc::parse(&text).unwrap().build().unwrap()
}

/// 12 `vec3` tracks on one key grid: a group of 36 vector channels in five
/// blocks (the AVX2 instance runs vector blocks from two on).
fn shared_vectors_clip() -> tcb_core::SourceClip {
    let tracks: Vec<String> = (0..12)
        .map(|i| {
            format!(
                r#"{{"name": "v{i}", "kind": "vec3", "times": [0, 0.4, 1.1, 1.7], "values": [[{i}, 0, 1], [1, 2.{i}, 3], [-1, 0.5, 2], [0, 0, 0.{i}]], "post": "offset-repeat", "keys": [{{}}, {{"tcb": [0.5, -0.5, 0.25]}}, {{}}, {{}}]}}"#
            )
        })
        .collect();
    let text = format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
        tracks.join(",")
    );
    tcb_io::ClipDoc::parse(&text).unwrap().build().unwrap()
}

/// Keys, a quarter and three quarters between them, and beyond both ends.
fn times_of(clip: &tcb_core::SourceClip) -> Vec<f64> {
    let keys = clip.key_times();
    let mut t: Vec<f64> = keys
        .windows(2)
        .flat_map(|w| {
            [
                w[0],
                w[0] + 0.25 * (w[1] - w[0]),
                w[0] + 0.75 * (w[1] - w[0]),
            ]
        })
        .collect();
    if let (Some(&a), Some(&b)) = (keys.first(), keys.last()) {
        t.extend([a - 1.0, b, b + 0.5, b + 7.25]);
    }
    t
}

#[test]
fn the_avx2_kernels_give_the_baselines_bits() {
    tcb_runtime::force_baseline_simd(false);
    if tcb_runtime::simd() == Simd::Baseline {
        eprintln!("skipped: this CPU or build runs no AVX2 instance");
        return;
    }
    let bvh = include_str!("../../../data/cmu-01_01.bvh");
    let bvh = tcb_io::bvh::Bvh::parse(bvh).unwrap();
    for mode in [RotationMode::Squad, RotationMode::Hermite] {
        let clip = bvh.to_clip_doc("cmu", mode).unwrap().build().unwrap();
        same_bits(&format!("cmu {mode:?}"), &clip, &times_of(&clip));
    }
    // 16-bit controls: the groups expand them with an AVX2 instance too.
    let clip = bvh
        .to_clip_doc("cmu", RotationMode::Hermite)
        .unwrap()
        .build()
        .unwrap();
    let times = times_of(&clip);
    tcb_runtime::force_baseline_simd(false);
    let mut options = tcb_runtime::CompileOptions::default();
    options.quantize = true;
    let bytes = Clip::compile_with(&clip, &options).memory_bytes();
    assert!(
        bytes < Clip::compile(&clip).memory_bytes() * 2 / 3,
        "quantized"
    );
    let avx2 = quantized_rows(&clip, &times, false);
    compare("cmu quantized", &avx2, &quantized_rows(&clip, &times, true));
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let mut loose = 0;
    for dir in ["examples/clips", "tools/check/clips"] {
        for entry in std::fs::read_dir(format!("{root}/{dir}")).unwrap() {
            let path = entry.unwrap().path();
            let clip = tcb_io::load_clip(&path).unwrap();
            loose += Clip::compile(&clip).loose_track_count();
            same_bits(&path.display().to_string(), &clip, &times_of(&clip));
        }
    }
    // The loose tracks' kernel has an AVX2 instance too: the bundled clips
    // play some on loose lanes, and so does this one, of every kind.
    assert!(loose > 0, "the bundled clips have loose tracks");
    let clip = loose_clip();
    let stats = Clip::compile(&clip).stats();
    // Two blocks of each (some rotations take a group of their own).
    assert_eq!(stats.loose_vector_tracks, 16);
    assert!(stats.loose_rotation_tracks > 8, "{stats:?}");
    let mut times = times_of(&clip);
    times.extend([-3.3, -0.5, 9.75, 33.1, 1e300]);
    same_bits("loose lanes", &clip, &times);
    // Alone, the rotation with tangents of 2.3e36 is a loose lane.
    let clip = common::huge_tangent_rotations(1, 0);
    assert_eq!(Clip::compile(&clip).loose_track_count(), 1);
    same_bits(
        "huge tangents, loose",
        &clip,
        &[0.25, 0.5, 0.9, 1.0, 1.5, 2.0],
    );
    // Tangents of 2.3e36 on one of 9 `hermite` rotations on one grid: its
    // |p|^2 overflows f32, and the group kernel redoes the block scaled.
    let clip = common::huge_tangent_rotations(9, 5);
    let times = [0.25, 0.5, 0.9, 0.999, 1.0001, 1.0, 1.5, 2.0];
    same_bits("huge tangents", &clip, &times);
    // Nine rotation blocks on one grid (the AVX2 kernel's loop once ran
    // eight blocks at a time from eight on): all in range, then with the
    // last block's lane rescaled.
    for at in [70, 66] {
        let clip = common::huge_tangent_rotations(70, at);
        same_bits(&format!("nine rotation blocks, {at}"), &clip, &times);
    }
    let clip = shared_vectors_clip();
    assert_eq!(Clip::compile(&clip).loose_track_count(), 0);
    same_bits("vector blocks on one grid", &clip, &times_of(&clip));
    packed_clips_decode_to_the_same_bits();
    tcb_runtime::force_baseline_simd(false);
}

/// The packed decoder's instances: the CMU capture quantized (the AVX2
/// instance gathers the residuals from the stream, 64 bits a lane for
/// several keys), and with the
/// root translation's integers alternating between +-(2^24 - 1), whose
/// residuals are 27 bits wide (too wide for the gather: that segment
/// unpacks as the baseline does), forward, backward and with seeks.
fn packed_clips_decode_to_the_same_bits() {
    let (clip, mut source) = common::quantized_cmu();
    let (t0, t1) = clip.time_range().unwrap();
    let mut times: Vec<f64> = (0..)
        .map(|f| t0 + f as f64 / 60.0)
        .take_while(|t| *t <= t1)
        .collect();
    times.extend((0..200).map(|f| t1 - f as f64 / 60.0));
    times.extend((0..300).map(|f| t0 + ((f * 7919) % 1000) as f64 / 1000.0 * (t1 - t0)));
    for wide in [false, true] {
        if wide {
            let root = &mut source.tracks[0];
            assert_eq!(root.name, "Hips.translation");
            for (k, x) in root.values[1].iter_mut().enumerate().skip(100).take(40) {
                *x = if k % 2 == 0 {
                    (1 << 24) - 1
                } else {
                    1 - (1 << 24)
                };
            }
        }
        packed_same_bits(
            &format!("packed cmu (wide residuals: {wide})"),
            &source,
            &times,
        );
    }
    // Residuals of assorted widths, each lane its own and changing from
    // segment to segment (noise of 0 to 23 bits), so that a plane's lanes
    // differ (its widest lane is 15 or 17 to 24 bits here).
    let (_, mut noisy) = common::quantized_cmu();
    add_noise(&mut noisy, 0x9e37_79b9, false, |l, k| {
        (l * 7 + k / 32 * 5) % 24
    });
    packed_same_bits("packed cmu, residuals of many widths", &noisy, &times);
    // Every width the gathers take, plane by plane (a segment's noise of
    // 0 to 24 bits, about the same in every lane, and every 26th segment
    // constant: widest 0 and 2 to 25), and short last segments (4, 17 and
    // 21 keys).
    for keys in [100, 2741, 2707] {
        let (_, mut sweep) = common::quantized_cmu();
        sweep.keys = keys;
        for t in &mut sweep.tracks {
            t.values.iter_mut().for_each(|v| v.truncate(keys));
        }
        add_noise(&mut sweep, 0x1234_5679, true, |l, k| match k / 32 {
            s if s % 26 == 25 => 0,
            s => (s * 3 + l % 3) % 25,
        });
        let times: Vec<f64> = (0..=2 * keys)
            .map(|f| sweep.start + f as f64 * 0.5 * sweep.interval)
            .collect();
        packed_same_bits(
            &format!("packed, widths 0 to 25, {keys} keys"),
            &sweep,
            &times,
        );
    }
    // Blocks with step factors (every third block at 1 + 40 / 64).
    let (clip, plain) = common::quantized_cmu();
    let steps: Vec<f32> = plain.tracks.iter().map(|t| t.step).collect();
    let blocks = plain.keys.div_ceil(64);
    let scales = tcb_runtime::BlockScales {
        keys: 64,
        codes: (0..blocks)
            .map(|b| if b % 3 == 1 { 40 } else { 0 })
            .collect(),
    };
    let scaled = tcb_runtime::KeyValues::sample(&clip)
        .unwrap()
        .quantize_scaled(&steps, &scales)
        .unwrap();
    packed_same_bits("packed cmu, step factors", &scaled, &times);
    // A last block of one key (2 blocks of 64 and key 128): its start
    // value without the delta after it.
    let (_, mut short) = common::quantized_cmu();
    short.keys = 129;
    for t in &mut short.tracks {
        t.values.iter_mut().for_each(|v| v.truncate(short.keys));
    }
    // Every key and half-way, past the end, then backwards.
    let mut times: Vec<f64> = (0..=260)
        .map(|f| short.start + f as f64 * 0.5 * short.interval)
        .collect();
    times.extend(times.clone().into_iter().rev());
    packed_same_bits("packed cmu, 129 keys", &short, &times);
}

/// Noise of `bits(lane, key)` bits (0: none; xorshift from `seed`) added
/// to each stored lane's integers, or with `flat` to its first one, kept
/// below 2^24 in magnitude.
fn add_noise(
    source: &mut tcb_runtime::PackSource,
    mut seed: u32,
    flat: bool,
    bits: impl Fn(usize, usize) -> usize,
) {
    let lanes = source.tracks.iter_mut().flat_map(|t| t.values.iter_mut());
    for (l, v) in lanes.enumerate() {
        let first = v[0];
        for (k, x) in v.iter_mut().enumerate() {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            let noise = match bits(l, k) {
                0 => 0,
                b => (seed >> (32 - b)) as i32 - (1 << (b - 1)),
            };
            let base = if flat { first } else { *x };
            *x = (base + noise).clamp(1 - (1 << 24), (1 << 24) - 1);
        }
    }
}

/// The decoder's instances on `source`, packed, at `times`: AVX2, and
/// AVX-512 where the CPU has it, against the baseline.
fn packed_same_bits(name: &str, source: &tcb_runtime::PackSource, times: &[f64]) {
    let packed = Arc::new(tcb_runtime::Packed::encode(source).unwrap());
    let clip = Arc::new(Clip::from_packed(packed).unwrap());
    tcb_runtime::force_baseline_simd(false);
    tcb_runtime::force_no_avx512(true);
    assert_eq!(tcb_runtime::simd(), Simd::Avx2);
    let avx2 = compiled_rows(clip.clone(), times);
    tcb_runtime::force_no_avx512(false);
    let avx512 = (tcb_runtime::simd() == Simd::Avx512).then(|| compiled_rows(clip.clone(), times));
    tcb_runtime::force_baseline_simd(true);
    let base = compiled_rows(clip, times);
    compare(name, &avx2, &base);
    match avx512 {
        Some(rows) => compare(&format!("{name}, AVX-512"), &rows, &base),
        None => eprintln!("{name}: this CPU runs no AVX-512 instance of the decoder"),
    }
    tcb_runtime::force_baseline_simd(false);
}
