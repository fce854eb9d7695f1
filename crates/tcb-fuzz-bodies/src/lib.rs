//! The bodies of the fuzz targets, shared by `fuzz/fuzz_targets/`
//! (cargo-fuzz, `RUSTC_BOOTSTRAP=1 cargo fuzz run NAME` in `fuzz/`) and by
//! the corpus replay test (`tests/corpus.rs`, stable `cargo test`), so the
//! findings stay guarded without nightly.
//!
//! Each body returns quietly on input the library rightly refuses and
//! panics on anything else that is wrong: a panic inside the library, or
//! the runtime disagreeing with the scalar reference (vector channels bit
//! for bit (as numbers: -0 equals 0), rotations within 1e-6, as `crates/tcb-runtime/tests/equivalence.rs`
//! holds them).

use arbitrary::{Arbitrary, Unstructured};
use std::sync::Arc;
use tcb_core::params::Tcb;
use tcb_core::{Ends, Extrapolation, Hemisphere, RotationMode, TangentRule, TrackData, TrackKind};
use tcb_io::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc};
use tcb_runtime::{BlendMask, Instance, PackSource, Packed, Playback};

mod edges;
mod export;
mod inputs;
mod playback;
mod quantize;
mod reduce_readback;
mod roundtrip;

pub use edges::{edge_time, edge_times, f32_ulps, ulps};
pub use export::{export, export_and_read_back, read_back_misses};
use inputs::*;
pub use inputs::{arbitrary_doc, arbitrary_time};
pub use playback::{clip_time, playback};
pub use quantize::quantize;
pub use reduce_readback::reduce_readback;
pub use roundtrip::roundtrip;

/// The instruction set an input runs on, from its last byte (read apart
/// from the rest, so that the corpus parses as before): bit 1 the
/// baseline kernels and decoder (`force_baseline_simd`), else bit 0 the
/// decoder's AVX2 instance where the CPU has AVX-512 (`force_no_avx512`),
/// so that one host fuzzes every instance it can run. Global switches:
/// every instance gives the same bits (`tcb-runtime/tests/isa.rs`), so an
/// input replayed beside another one (the corpus test's threads) checks
/// the same things whichever runs.
fn choose_simd(data: &[u8]) {
    let b = match FIXED_SIMD.load(std::sync::atomic::Ordering::Relaxed) {
        FROM_INPUT => data.last().copied().unwrap_or(0),
        fixed => fixed,
    };
    tcb_runtime::force_baseline_simd(b & 2 != 0);
    tcb_runtime::force_no_avx512(b & 1 != 0);
}

/// [`fix_simd`]'s "from the input".
const FROM_INPUT: u8 = u8::MAX;
static FIXED_SIMD: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(FROM_INPUT);

/// Play every input on one instruction set, `Some(b)` as an input whose
/// last byte is `b` would choose it (0 what the CPU has, 1 the AVX2
/// instance where it has AVX-512 too, 2 the baseline), or `None`: each
/// input's own choice again. For the corpus replay, which runs each
/// committed input on every instance whatever its last byte says.
pub fn fix_simd(mode: Option<u8>) {
    let m = mode.map_or(FROM_INPUT, |b| b & 3);
    FIXED_SIMD.store(m, std::sync::atomic::Ordering::Relaxed);
}

/// `tcb-clip/1` JSON: parse, build, then play what builds.
pub fn clip_json(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(doc) = ClipDoc::parse(text)
        && let Ok(clip) = doc.build()
    {
        play(&clip);
    }
}

/// BVH text: parse, convert in both rotation modes, build and play.
pub fn bvh(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(bvh) = tcb_io::bvh::Bvh::parse(text) else {
        return;
    };
    let _ = bvh.skeleton_with_end_sites();
    for mode in [RotationMode::Squad, RotationMode::Hermite] {
        if let Ok(doc) = bvh.to_clip_doc("fuzz", mode)
            && let Ok(clip) = doc.build()
        {
            play(&clip);
        }
    }
}

/// glTF or GLB bytes (no external buffers): import, build and play.
pub fn gltf(data: &[u8]) {
    if let Ok(g) = tcb_io::gltf_import::import(data, None, None, "fuzz")
        && let Ok(clip) = g.doc.build()
    {
        play(&clip);
    }
}

/// A structured clip (every kind, rule, end, ease, interpolation,
/// extrapolation and rotation mode, sane or not) and arbitrary times.
pub fn runtime(data: &[u8]) {
    choose_simd(data);
    let mut u = Unstructured::new(data);
    let Ok(doc) = arbitrary_doc(&mut u) else {
        return;
    };
    let Ok(clip) = doc.build() else {
        return;
    };
    let mut times = Vec::new();
    while let Ok(t) = arbitrary_time(&mut u) {
        if times.len() == 64 {
            break;
        }
        times.push(t);
    }
    // Half the inputs (by the number of times, so that the corpus reads as
    // before) compile with exact squad velocities.
    let options = tcb_runtime::CompileOptions::default().exact_velocities(times.len() % 2 == 1);
    check(&clip, &times, &options);
}

/// Blending and additive layers with arbitrary weights (NaN, infinite,
/// negative, summing to zero) and masks: never a panic.
pub fn blend(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(doc) = arbitrary_doc(&mut u) else {
        return;
    };
    let Ok(clip) = doc.build() else {
        return;
    };
    let clip = Arc::new(tcb_runtime::Clip::compile(&clip));
    let velocities = bool::arbitrary(&mut u).unwrap_or(false);
    let make = || {
        let i = Instance::new(clip.clone());
        if velocities { i.with_velocities() } else { i }
    };
    let (mut a, mut b) = (make(), make());
    let (Ok(ta), Ok(tb)) = (arbitrary_time(&mut u), arbitrary_time(&mut u)) else {
        return;
    };
    let mut out = a.sample(ta).clone();
    b.sample(tb);
    let weight = |u: &mut Unstructured| arbitrary_f32(u).unwrap_or(0.5);
    let (wa, wb) = (weight(&mut u), weight(&mut u));
    let mask_weights: Vec<f32> = (0..clip.tracks().len()).map(|_| weight(&mut u)).collect();
    let mask = BlendMask::new(&clip, |t| mask_weights[t.index()]);
    let layers = [(a.pose(), wa), (b.pose(), wb)];
    tcb_runtime::blend::blend(&mut out, &layers, None).expect("same layout");
    tcb_runtime::blend::blend(&mut out, &layers, Some(&[&mask, &mask])).expect("same layout");
    tcb_runtime::blend::add(&mut out, a.pose(), b.pose(), wa, Some(&mask)).expect("same layout");
    tcb_runtime::blend::add(&mut out, b.pose(), a.pose(), wb, None).expect("same layout");
    // A mask count that does not match is an error, not a panic.
    assert!(tcb_runtime::blend::blend(&mut out, &layers, Some(&[&mask])).is_err());
}

/// `tcb reduce`'s input: a structured clip, sometimes with a skeleton whose
/// joints its tracks animate (for the `shell` metric), and arbitrary
/// options. Never a panic; a reduction that succeeds is within its
/// tolerance by its own measurement, and what it writes reads back and
/// builds.
pub fn reduce(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Some((doc, clip, skeleton, options)) = reduce_input(&mut u) else {
        return;
    };
    let input = tcb_fit::reduce::Input {
        doc: &doc,
        clip: &clip,
        skeleton: skeleton.as_ref(),
    };
    if let Ok(r) = tcb_fit::reduce(input, &options, &|_, _| {}) {
        // The worst is the largest error over its own limit (`value`:
        // rotations against the rotation tolerance, in degrees).
        assert!(
            r.worst.ratio <= 1.0,
            "reduced beyond its tolerance: {:?} ({:?})",
            r.worst,
            r.settings
        );
        let back = ClipDoc::parse(&r.doc.to_json()).expect("the reduced clip reads back");
        back.build().expect("the reduced clip builds");
    }
}

/// `.tcbc` bytes, then (past the length their header gives) bytes that
/// choose the playback. Read as given and, if refused, resealed (magic,
/// version, length and checksum rewritten) so that mutations reach past
/// the checksum. What reads back writes the same bytes; what compiles plays
/// as its reference (the decoded integers' `to_clip`, compiled) does.
pub fn tcbc(data: &[u8]) {
    choose_simd(data);
    let claimed = data
        .get(12..20)
        .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")));
    let len = match claimed {
        Some(n) if (24..=data.len() as u64).contains(&n) => n as usize,
        _ => data.len(),
    };
    let (file, rest) = data.split_at(len);
    // The loader checks the structure, not every integer: whatever it
    // accepts, as given or resealed, plays without a panic.
    let candidates = if file.len() >= 24 {
        vec![file.to_vec(), reseal(file)]
    } else {
        vec![file.to_vec()]
    };
    for bytes in candidates {
        if let Ok(clip) = tcb_runtime::Clip::from_bytes(&bytes) {
            play_anything(clip, &mut Unstructured::new(rest));
        }
    }
    let (packed, read) = match Packed::from_bytes(file) {
        Ok(p) => (p, file.to_vec()),
        Err(_) if file.len() >= 24 => {
            let sealed = reseal(file);
            match Packed::from_bytes(&sealed) {
                Ok(p) => (p, sealed),
                Err(_) => return,
            }
        }
        Err(_) => return,
    };
    let bytes = packed.to_bytes();
    assert!(bytes == read, "a file read back writes other bytes");
    assert_eq!(
        Packed::from_bytes(&bytes).as_ref(),
        Ok(&packed),
        "the written bytes read back to another clip"
    );
    let packed = Arc::new(packed);
    let Ok(clip) = tcb_runtime::Clip::from_packed(packed.clone()) else {
        return;
    };
    assert!(
        tcb_runtime::Clip::from_bytes(&read).is_ok(),
        "the loader refuses a file whose clip compiles"
    );
    if let Err(e) = clip.verify_packed() {
        panic!("{e}: a file read and decoded in full");
    }
    let reference = packed
        .decode()
        .and_then(|s| s.to_clip())
        .expect("from_packed built the reference");
    play_packed(clip, &reference, &mut Unstructured::new(rest));
}

/// A structured clip on one even grid (1 to 12 tracks of every kind, 2 to
/// 200 keys, values from gentle to huge, rotations through w = 0 and
/// across hemispheres, every rule and end, tension, continuity and bias per
/// track, pre and post shared; a quarter of the tracks after the first on
/// key times of their own, some with explicit tangents) and quantization
/// steps: quantized, encoded,
/// compiled from the packed stream and played against its reference.
/// Refusals must be clean errors, except a compile whose decoded keys miss
/// the reference's controls: quantize and encode accepted the clip, so the
/// runtime's tangents or decoding disagree with the reference.
pub fn pack(data: &[u8]) {
    choose_simd(data);
    let mut u = Unstructured::new(data);
    let Ok(input) = arbitrary_pack(&mut u) else {
        return;
    };
    let Ok(clip) = input.doc.build() else {
        return;
    };
    let Ok(keys) = tcb_runtime::KeyValues::sample(&clip) else {
        return;
    };
    // Blocks of 32 or 64 keys, with a factor on the steps per block.
    let block = if u.arbitrary().unwrap_or(false) {
        32
    } else {
        64
    };
    let scales = match u.arbitrary::<bool>() {
        Ok(true) => {
            let blocks = keys.grid_keys().div_ceil(block);
            let codes = (0..blocks).map(|_| u.arbitrary::<u8>().unwrap_or(0));
            tcb_runtime::BlockScales {
                keys: block,
                codes: codes.collect(),
            }
        }
        _ => tcb_runtime::BlockScales::default(),
    };
    let Ok(mut source) = keys.quantize_scaled(&input.steps, &scales) else {
        return;
    };
    for (t, tcb) in source.tracks.iter_mut().zip(&input.tcb) {
        t.tcb = *tcb;
    }
    // Settings the format does not hold are refused when encoding.
    if let Some(i) = input.tamper {
        let n = source.tracks.len();
        let t = &mut source.tracks[i % n];
        match t.kind {
            TrackKind::Quat => t.settings.rotation = RotationMode::Squad,
            _ => t.settings.match_speed = true,
        }
        assert!(
            Packed::encode_with(&source, block).is_err(),
            "encoded a track the format cannot hold"
        );
        return;
    }
    let Ok(packed) = Packed::encode_with(&source, block) else {
        return;
    };
    assert_eq!(
        packed.decode().as_ref(),
        Ok(&source),
        "the stream decodes to other integers"
    );
    let bytes = packed.to_bytes();
    assert_eq!(
        Packed::from_bytes(&bytes).as_ref(),
        Ok(&packed),
        "the written bytes read back to another clip"
    );
    match tcb_runtime::Clip::from_packed(Arc::new(packed))
        .and_then(|c| c.verify_packed().map(|()| c))
    {
        Ok(compiled) => {
            assert_eq!(
                compiled.to_bytes(),
                Some(bytes),
                "the compiled clip's bytes"
            );
            let reference = source.to_clip().expect("from_packed built the reference");
            play_packed(compiled, &reference, &mut u);
        }
        Err(e) => assert!(
            !e.0.starts_with("packed keys miss their reference")
                && !e.0.starts_with("the tracks on key times of their own miss"),
            "{e}; quantize and encode accepted {}",
            describe(&source)
        ),
    }
}

/// The `compress` target: `tcb compress`'s search ([`tcb_fit::compress()`])
/// on a clip as the `pack` target draws it (one even grid of 2 to 200 keys,
/// every kind and rule, tracks on key times of their own), sometimes with
/// a skeleton its tracks animate, and arbitrary options (tolerance, shell,
/// metric, rotation tolerance, keys per block). A clip the search returns
/// was measured within its tolerance; its bytes load
/// (`Clip::from_bytes`), and measured again from them, at every check
/// time of the contract, it is within the tolerance too.
pub fn compress(data: &[u8]) {
    choose_simd(data);
    let mut u = Unstructured::new(data);
    let Ok(input) = arbitrary_pack(&mut u) else {
        return;
    };
    let mut doc = input.doc;
    let skeleton = arbitrary_skeleton(&mut u, &mut doc);
    let Ok(clip) = doc.build() else {
        return;
    };
    let options = tcb_fit::CompressOptions::default()
        .tolerance(option_number(&mut u))
        .shell(option_number(&mut u))
        .metric(
            *u.choose(&[
                None,
                Some(tcb_fit::Metric::Shell),
                Some(tcb_fit::Metric::Value),
            ])
            .unwrap_or(&None),
        )
        .rotation_tolerance(option_number(&mut u))
        .seek_keys(
            *u.choose(&[None, Some(32), Some(64), Some(1024)])
                .unwrap_or(&None),
        );
    let Ok(c) = tcb_fit::compress(&clip, skeleton.as_ref(), &options, &|_, _| {}) else {
        return;
    };
    assert!(
        c.worst.ratio <= 1.0,
        "compressed beyond its tolerance: {:?} ({:?})",
        c.worst,
        c.settings
    );
    let bytes = c.packed.to_bytes();
    assert_eq!(bytes.len(), c.bytes, "the bytes it reported");
    let loaded = Arc::new(tcb_runtime::Clip::from_bytes(&bytes).expect("its own file loads"));
    let again = measure_again(&clip, skeleton.as_ref(), &loaded, &c.settings);
    assert!(
        again.worst.ratio <= 1.0,
        "the file, loaded, is beyond the tolerance: {:?} (the search measured {:?}; {:?})",
        again.worst,
        c.worst,
        c.settings
    );
}

/// Play a clip that built at its key times, between them, beyond them and
/// at the awkward times, against the reference.
fn play(clip: &tcb_core::SourceClip) {
    let mut times = clip.key_times();
    times.truncate(200);
    if let Some((a, b)) = clip.time_range() {
        let mid: Vec<f64> = times.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        times.extend(mid);
        times.extend([a - 1.0, b + 1.0, b + 7.3 * (b - a)]);
    }
    times.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1e300, 1e300]);
    check(clip, &times, &tcb_runtime::CompileOptions::default());
}

/// The runtime against the reference at `times`, played forward as given
/// and by a fresh instance per time (a seek), which must agree bit for bit.
fn check(clip: &tcb_core::SourceClip, times: &[f64], options: &tcb_runtime::CompileOptions) {
    let compiled = Arc::new(tcb_runtime::Clip::compile_with(clip, options));
    let n = clip.channel_count();
    let mut playing = Instance::new(compiled.clone()).with_velocities();
    let (mut got, mut got_v) = (vec![0.0f32; n], vec![0.0f32; n]);
    let (mut want, mut want_v) = (vec![0.0f32; n], vec![0.0f32; n]);
    for &t in times {
        let pose = playing.sample(t).clone();
        let mut fresh = Instance::new(compiled.clone()).with_velocities();
        assert!(
            same(pose.as_slice(), fresh.sample(t).as_slice()),
            "forward playback differs from a seek at {t}"
        );
        pose.write_row(&mut got, Some(&mut got_v));
        clip.sample_into(t, &mut want, Some(&mut want_v));
        let mut at = 0;
        for track in clip.tracks() {
            let dim = track.data.kind().dim();
            let r = at..at + dim;
            at += dim;
            if let TrackData::Quat(_) = track.data {
                assert_rotation(&got[r.clone()], &want[r], &track.name, t);
                continue;
            }
            // Where the reference itself is not finite (tangents that
            // overflow f32 make its curve NaN), the runtime may be better.
            for (what, got, want) in [("value", &got, &want), ("velocity", &got_v, &want_v)] {
                let (g, w) = (&got[r.clone()], &want[r.clone()]);
                assert!(
                    w.iter().any(|x| !x.is_finite()) || same(g, w),
                    "{} {what} at {t}: runtime {g:?}, reference {w:?}",
                    track.name
                );
            }
        }
    }
}

/// `.tcbc` bytes with the magic, version, length and checksum of a good
/// file: the header as `Packed::to_bytes` writes it over the body given.
fn reseal(file: &[u8]) -> Vec<u8> {
    let mut b = file.to_vec();
    b[..8].copy_from_slice(&tcb_runtime::pack::MAGIC);
    b[8..12].copy_from_slice(&tcb_runtime::pack::VERSION.to_le_bytes());
    b[12..20].copy_from_slice(&(file.len() as u64).to_le_bytes());
    let crc = crc32fast::hash(&b[24..]);
    b[20..24].copy_from_slice(&crc.to_le_bytes());
    b
}

/// The `pack` target's input: a clip document on one even grid, a
/// quantization step and a tension, continuity and bias per track, and
/// perhaps a track to give settings the format refuses.
struct PackInput {
    doc: ClipDoc,
    steps: Vec<f32>,
    tcb: Vec<Tcb>,
    tamper: Option<usize>,
}

/// Draws a [`PackInput`]: the grid ([`pack_times`]), up to 12 track kinds,
/// one `pre` and `post` for all, then per track its document
/// ([`pack_track`]), tcb and quantization step ([`pack_step`]), and
/// sometimes a track to tamper with.
fn arbitrary_pack(u: &mut Unstructured) -> arbitrary::Result<PackInput> {
    let times = pack_times(u)?;
    let kinds: Vec<TrackKind> = (0..u.int_in_range(1..=12u8)?)
        .map(|_| u.choose(&TrackKind::ALL).copied())
        .collect::<arbitrary::Result<_>>()?;
    // One pre and one post for every track; rotations have neither
    // `linear` nor `offset-repeat`.
    let ends_modes: Vec<Extrapolation> = Extrapolation::ALL
        .iter()
        .copied()
        .filter(|e| {
            !kinds.contains(&TrackKind::Quat)
                || !matches!(e, Extrapolation::Linear | Extrapolation::OffsetRepeat)
        })
        .collect();
    let pre = *u.choose(&ends_modes)?;
    let post = *u.choose(&ends_modes)?;
    let mut tracks = Vec::with_capacity(kinds.len());
    let (mut steps, mut tcbs) = (Vec::new(), Vec::new());
    for (i, &kind) in kinds.iter().enumerate() {
        // A track after the first on key times of its own (a reduced
        // clip's), with its own pre and post, and sometimes explicit
        // tangents: kept on its keys beside the grid.
        if i > 0 && u.ratio(1, 4)? {
            let own = own_times(u, &times)?;
            let ends = (*u.choose(&ends_modes)?, *u.choose(&ends_modes)?);
            let mut doc = pack_track(u, i, kind, &own, ends)?;
            if kind != TrackKind::Quat && u.ratio(1, 2)? {
                doc.keys = (0..own.len())
                    .map(|_| {
                        Ok(KeyDoc {
                            tangent_in: Some(value(u)?),
                            tangent_out: Some(value(u)?),
                            ..KeyDoc::default()
                        })
                    })
                    .collect::<arbitrary::Result<_>>()?;
            }
            tracks.push(doc);
        } else {
            tracks.push(pack_track(u, i, kind, &times, (pre, post))?);
        }
        tcbs.push(match u.int_in_range(0..=3u8)? {
            0 => Tcb::DEFAULT,
            _ => Tcb::from_array(tcb3(u)?),
        });
        steps.push(pack_step(u)?);
    }
    let tamper = if u.ratio(1, 32)? {
        Some(usize::from(u8::arbitrary(u)?))
    } else {
        None
    };
    Ok(PackInput {
        doc: ClipDoc {
            name: "fuzz".into(),
            defaults: SettingsDoc::default(),
            tracks,
            skeleton: None,
        },
        steps,
        tcb: tcbs,
        tamper,
    })
}

/// 2 to 200 key times on one even grid: a start from anywhere (large,
/// tiny, awkward fractions) and an interval from 1e-9 to 1e300 (or any
/// positive f64).
fn pack_times(u: &mut Unstructured) -> arbitrary::Result<Vec<f64>> {
    let keys = u.int_in_range(2..=200usize)?;
    let start = match u.int_in_range(0..=7u8)? {
        0 => f64::arbitrary(u)?,
        1 => f64::from(i32::arbitrary(u)?) * 1e3 + 0.1,
        2 => *u.choose(&[1e6 + 0.1, 1e9 / 3.0, -1e7, 3.15e7, 1e-300])?,
        _ => f64::from(i16::arbitrary(u)?) / 64.0,
    };
    let interval = match u.int_in_range(0..=7u8)? {
        0 => f64::arbitrary(u)?.abs(),
        1 => *u.choose(&[1e-9, 1e-6, 1.0 / 3.0, 0.1, 1e3, 1e6, 1e12, 1e300])?,
        2 | 3 => 1.0 / f64::from(u.int_in_range(1..=240u16)?),
        _ => f64::from(u.int_in_range(1..=u16::MAX)?) / 4096.0,
    };
    Ok((0..keys).map(|k| start + k as f64 * interval).collect())
}

/// Key times of a track of its own beside the grid `times`: the first and
/// last, and each other one with even odds, sometimes moved 0.37 of the
/// way to the next.
fn own_times(u: &mut Unstructured, times: &[f64]) -> arbitrary::Result<Vec<f64>> {
    let n = times.len();
    let shift = if u.ratio(1, 3)? { 0.37 } else { 0.0 };
    let mut out = vec![times[0]];
    for k in 1..n - 1 {
        if bool::arbitrary(u)? {
            out.push(times[k] + shift * (times[k + 1] - times[k]));
        }
    }
    out.push(times[n - 1]);
    Ok(out)
}

/// Track `i` of `kind` on `times`: its values (rotations for 3 in 4
/// rotation tracks, else [`vectors`]; the last equal to the first for
/// cyclic ends), its ends, rotation mode (`hermite` for natural ends) and
/// settings, with the clip's `pre` and `post`.
fn pack_track(
    u: &mut Unstructured,
    i: usize,
    kind: TrackKind,
    times: &[f64],
    (pre, post): (Extrapolation, Extrapolation),
) -> arbitrary::Result<TrackDoc> {
    let keys = times.len();
    let ends = *u.choose(Ends::ALL)?;
    let mut values = if kind == TrackKind::Quat && u.ratio(3, 4)? {
        rotations(u, keys)?
    } else {
        vectors(u, keys)?
    };
    if ends == Ends::Cyclic {
        values[keys - 1] = values[0];
    }
    let rotation = match ends {
        Ends::Natural => RotationMode::Hermite,
        _ => *u.choose(RotationMode::ALL)?,
    };
    Ok(TrackDoc {
        name: format!("t{i}"),
        kind,
        times: times.to_vec(),
        values,
        keys: Vec::new(),
        settings: SettingsDoc {
            tangent_rule: Some(*u.choose(TangentRule::ALL)?),
            ends: Some(ends),
            match_speed: Some(bool::arbitrary(u)?),
            continuity_fade: Some(bool::arbitrary(u)?),
            tcb: None,
            pre: Some(pre),
            post: Some(post),
            rotation: Some(rotation),
            hemisphere: Some(*u.choose(Hemisphere::ALL)?),
        },
    })
}

/// A track's quantization step: mostly a power of two from 1 to 2^-24
/// times 1 to 2, sometimes any f32 or an extreme one (denormal, huge).
fn pack_step(u: &mut Unstructured) -> arbitrary::Result<f32> {
    Ok(match u.int_in_range(0..=15u8)? {
        0 => f32::arbitrary(u)?,
        1 => *u.choose(&[1e-45, f32::MIN_POSITIVE, 1e-30, 1e-12, 1e20, f32::MAX])?,
        _ => {
            let fine = 0.5f32.powi(u.int_in_range(0..=24i32)?);
            fine * (1.0 + f32::from(u8::arbitrary(u)?) / 256.0)
        }
    })
}

/// `keys` values of one track: each key arbitrary, a random walk, or a
/// quadratic, at a magnitude from 1 to 1e30.
fn vectors(u: &mut Unstructured, keys: usize) -> arbitrary::Result<Vec<[f32; 4]>> {
    let scale = *u.choose(&[1.0f32, 1.0, 1.0, 1e-3, 1e3, 1e6, 1e20, 1e30])?;
    Ok(match u.int_in_range(0..=3u8)? {
        0 => (0..keys)
            .map(|_| Ok(value(u)?.map(|x| x * scale)))
            .collect::<arbitrary::Result<_>>()?,
        1 => {
            let mut v = value(u)?;
            (0..keys)
                .map(|_| {
                    let d = value(u)?;
                    v = std::array::from_fn(|c| v[c] + d[c] * scale);
                    Ok(v)
                })
                .collect::<arbitrary::Result<_>>()?
        }
        _ => {
            let (a, b, c) = (value(u)?, value(u)?, value(u)?);
            (0..keys)
                .map(|k| {
                    let k = k as f32;
                    std::array::from_fn(|i| scale * (a[i] + b[i] * k + c[i] * k * k / 16.0))
                })
                .collect()
        }
    })
}

/// `keys` rotations about one axis, turning a constant angle per key (up
/// to and past a half turn, so `w` passes 0 and neighbours leave each
/// other's hemisphere), some keys negated.
fn rotations(u: &mut Unstructured, keys: usize) -> arbitrary::Result<Vec<[f32; 4]>> {
    use std::f64::consts::PI;
    let [x, y, z, _] = value(u)?.map(f64::from);
    let norm = (x * x + y * y + z * z).sqrt();
    let axis = if norm > 1e-6 {
        [x / norm, y / norm, z / norm]
    } else {
        [1.0, 0.0, 0.0]
    };
    let first = f64::from(i16::arbitrary(u)?) / 32768.0 * 2.0 * PI;
    let turn = match u.int_in_range(0..=5u8)? {
        0 => *u.choose(&[PI, PI / 2.0, PI - 1e-4, PI + 1e-4, 2.0 * PI - 1e-3])?,
        1 => f64::from(i16::arbitrary(u)?) / 32768.0 * 2.0 * PI,
        _ => f64::from(i8::arbitrary(u)?) / 128.0 * 0.3,
    };
    let negate = u8::arbitrary(u)?;
    Ok((0..keys)
        .map(|k| {
            let a = first + turn * k as f64;
            let (s, c) = (0.5 * a).sin_cos();
            let q = [axis[0] * s, axis[1] * s, axis[2] * s, c].map(|v| v as f32);
            if negate != 0 && k % usize::from(negate) == 0 {
                q.map(|v| -v)
            } else {
                q
            }
        })
        .collect())
}

/// A packed clip against its reference, compiled as usual: one instance
/// played forward over the keys, then at times the input chooses (seeks
/// back, across blocks, past the ends, NaN and infinities), then at block
/// boundaries; each row equal as numbers (values and velocities, rotations
/// included) to the reference instance's and to a fresh instance's (a
/// seek from nothing).
/// Play a clip the loader accepted from unchecked integers: forward over
/// its keys, then at times from `u`, with velocities; any values, no panic.
fn play_anything(clip: tcb_runtime::Clip, u: &mut Unstructured) {
    let head = clip.packed().expect("compiled from a packed clip").head();
    let (start, interval, keys) = (head.start, head.interval, head.keys);
    let mut times: Vec<f64> = (0..keys.min(300))
        .map(|k| start + (k as f64 + 0.5) * interval)
        .collect();
    for _ in 0..50 {
        match packed_time(u, start, interval, keys) {
            Ok(t) => times.push(t),
            Err(_) => break,
        }
    }
    let mut inst = Instance::new(Arc::new(clip)).with_velocities();
    for t in times {
        inst.sample(t);
    }
}

fn play_packed(clip: tcb_runtime::Clip, reference: &tcb_core::SourceClip, u: &mut Unstructured) {
    let head = clip.packed().expect("compiled from a packed clip").head();
    let (start, interval, keys) = (head.start, head.interval, head.keys);
    let at = |k: f64| start + k * interval;
    let mut times: Vec<f64> = (0..keys.min(150))
        .flat_map(|k| [at(k as f64), at(k as f64 + 0.37)])
        .collect();
    while times.len() < 400 {
        let Ok(t) = packed_time(u, start, interval, keys) else {
            break;
        };
        times.push(t);
    }
    for b in [63, 64, 65, 127, 128, 129, keys - 2, keys - 1, keys, 1, 0] {
        times.extend([at(b as f64 + 0.5), at(b as f64 - 0.25)]);
    }
    times.extend([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1e300, 1e300]);
    let mode = *u
        .choose(&[
            Playback::Clip,
            Playback::Loop,
            Playback::Clamp,
            Playback::PingPong,
        ])
        .unwrap_or(&Playback::Clip);
    let speed = match u.int_in_range(0..=3u8).unwrap_or(0) {
        0 => 1.0,
        1 => *u.choose(&[-1.0, 0.5, 2.0, 1e-3, 1e3]).unwrap_or(&1.0),
        _ => f64::from(i16::arbitrary(u).unwrap_or(1)) / 256.0,
    };
    let clip = Arc::new(clip);
    let reference = Arc::new(tcb_runtime::Clip::compile(reference));
    let make = |c: &Arc<tcb_runtime::Clip>| {
        let mut i = Instance::new(c.clone()).with_velocities();
        i.set_playback(mode, speed).expect("a finite speed");
        i
    };
    let (mut playing, mut against) = (make(&clip), make(&reference));
    // Rotations are held to the contract's 1e-6, as the runtime is against
    // the scalar reference: inside their keys a packed clip may play them
    // from their keys (`key_row`), and the reference compiled on its own
    // may lay its tracks out otherwise (a few rotations as loose lanes
    // where the packed clip has its grid's group). Vectors stay exact.
    let n = clip.channel_count();
    let row = |i: &mut Instance, t: f64| {
        let (mut v, mut d) = (vec![0.0f32; n], vec![0.0f32; n]);
        i.sample(t).write_row(&mut v, Some(&mut d));
        (v, d)
    };
    for &t in &times {
        let got = row(&mut playing, t);
        let seek = row(&mut make(&clip), t);
        assert!(
            same(&got.0, &seek.0) && same(&got.1, &seek.1),
            "packed: forward playback differs from a seek at {t}"
        );
        let want = row(&mut against, t);
        let mut c = 0;
        for slot in clip.tracks() {
            let r = c..c + slot.kind().dim();
            c = r.end;
            if slot.kind() == TrackKind::Quat {
                assert_rotation(&got.0[r.clone()], &want.0[r.clone()], slot.name(), t);
                assert_rotation_velocity(
                    [&got.0[r.clone()], &got.1[r.clone()]],
                    [&want.0[r.clone()], &want.1[r]],
                    speed.abs() / interval,
                    slot.name(),
                    t,
                );
                continue;
            }
            for (what, g, w) in [("value", &got.0, &want.0), ("velocity", &got.1, &want.1)] {
                let (g, w) = (&g[r.clone()], &w[r.clone()]);
                assert!(
                    same(g, w),
                    "packed {} {:?} {what} at {t} ({mode:?} x{speed}): packed {g:?}, reference {w:?}",
                    slot.name(),
                    slot.kind()
                );
            }
        }
    }
}

/// Mostly times on and between the keys, sometimes far past them or
/// anything at all.
fn packed_time(
    u: &mut Unstructured,
    start: f64,
    interval: f64,
    keys: usize,
) -> arbitrary::Result<f64> {
    if u.is_empty() {
        return Err(arbitrary::Error::NotEnoughData);
    }
    let last = u32::try_from(keys).unwrap_or(u32::MAX).saturating_add(1);
    Ok(match u.int_in_range(0..=7u8)? {
        0 => f64::arbitrary(u)?,
        1 => *u.choose(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -0.0])?,
        2 => start + interval * f64::from(i16::arbitrary(u)?) / 16.0,
        _ => {
            let k = f64::from(u.int_in_range(0..=last)?);
            start + interval * (k + f64::from(u8::arbitrary(u)?) / 256.0)
        }
    })
}

/// A packed clip's grid and each track's settings, in one line.
fn describe(s: &PackSource) -> String {
    let tracks: Vec<String> = s
        .tracks
        .iter()
        .map(|t| {
            let e = &t.settings;
            format!(
                "{} {} {} {} fade={} hemisphere={} tcb={:?} pre={} post={} step={} rebuild_w={}",
                t.name,
                t.kind.name(),
                e.tangent_rule,
                e.ends,
                e.continuity_fade,
                e.hemisphere,
                t.tcb.to_array(),
                e.pre,
                e.post,
                t.step,
                t.rebuild_w
            )
        })
        .collect();
    format!(
        "{} keys from {} every {}: {}",
        s.keys,
        s.start,
        s.interval,
        tracks.join("; ")
    )
}
