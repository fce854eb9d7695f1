//! Packed clips (`tcb_runtime::pack`): the runtime's decoded keys against
//! the reference, forward and with seeks; the file round trip; bad files.

use std::sync::Arc;
use tcb_core::RotationMode;
use tcb_runtime::{Clip, Instance, PackSource, Packed};

mod common;

fn cmu() -> (tcb_core::SourceClip, PackSource) {
    common::quantized_cmu()
}

/// Values then velocities, in the clip's columns.
fn rows_and_velocities(inst: &mut Instance, t: f64, n: usize) -> Vec<f32> {
    let mut row = vec![0.0; 2 * n];
    let (v, d) = row.split_at_mut(n);
    inst.sample(t).write_row(v, Some(d));
    row
}

#[test]
fn packed_cmu_plays_its_reference() {
    let (_, source) = cmu();
    // The root turns past w = 0: it is kept relative to its center, and
    // every rotation rebuilds w (the root's center is the decoder's path
    // that multiplies a block by its centers, checked bit for bit below).
    let rotations = source.tracks.iter().filter(|t| t.kind.dim() == 4);
    assert!(rotations.clone().all(|t| t.rebuild_w));
    let centered: Vec<&str> = rotations
        .filter(|t| t.center.is_some())
        .map(|t| t.name.as_str())
        .collect();
    assert_eq!(centered, ["Hips.rotation"]);
    for block in [32, 64, 1024] {
        let worst = plays_its_reference(&source, block);
        // Played from its keys, not bit for bit (`key_row`), but close.
        assert!(worst > 0.0 && worst < 3e-7, "{worst}");
    }
    assert!(Packed::encode_with(&source, 24).is_err());
    assert!(Packed::encode_with(&source, 2048).is_err());
}

#[test]
fn blocks_with_step_factors_play_their_reference() {
    let (clip, plain) = cmu();
    let keys = tcb_runtime::KeyValues::sample(&clip).unwrap();
    // `cmu`'s steps.
    let steps: Vec<f32> = plain.tracks.iter().map(|t| t.step).collect();
    for block in [32, 64] {
        // Every code somewhere (0 and 255 too), in no order.
        let blocks = clip.key_times().len().div_ceil(block);
        let scales = tcb_runtime::BlockScales {
            keys: block,
            codes: (0..blocks).map(|b| (b * 97 % 256) as u8).collect(),
        };
        assert!(scales.codes.contains(&0) && scales.codes.iter().any(|c| *c > 200));
        let source = keys.quantize_scaled(&steps, &scales).unwrap();
        assert_eq!(source.scales, scales);
        plays_its_reference(&source, block);
        // The factors are in the file, and blocks of another size refuse them.
        let packed = Packed::encode_with(&source, block).unwrap();
        assert_eq!(Packed::from_bytes(&packed.to_bytes()).unwrap(), packed);
        assert_eq!(packed.decode().unwrap().scales, scales);
        let e = Packed::encode_with(&source, 2 * block).unwrap_err();
        assert!(e.to_string().contains("step factors per"), "{e}");
    }
    // Coarser steps where the factor is larger: fewer bytes than without.
    let plain = Packed::encode(&keys.quantize(&steps).unwrap()).unwrap();
    let coarse = tcb_runtime::BlockScales {
        keys: 64,
        codes: vec![64; clip.key_times().len().div_ceil(64)],
    };
    let scaled = Packed::encode(&keys.quantize_scaled(&steps, &coarse).unwrap()).unwrap();
    assert!(scaled.to_bytes().len() < plain.to_bytes().len());
    // Factors that do not match the keys are refused.
    let wrong = tcb_runtime::BlockScales {
        keys: 64,
        codes: vec![1; 3],
    };
    let e = keys.quantize_scaled(&steps, &wrong).unwrap_err();
    assert!(e.to_string().contains("3 step factors for"), "{e}");
    // Every code 0 is no factors, in any block size.
    let zeros = tcb_runtime::BlockScales {
        keys: 64,
        codes: vec![0; clip.key_times().len().div_ceil(64)],
    };
    let source = keys.quantize_scaled(&steps, &zeros).unwrap();
    assert_eq!(source.scales, tcb_runtime::BlockScales::default());
    assert!(Packed::encode_with(&source, 32).is_ok());
    // A step whose integers, times the largest factor, would leave f32.
    let mut huge = source.clone();
    huge.tracks[0].step = 1e31;
    let e = Packed::encode(&huge).unwrap_err().to_string();
    assert!(e.contains("step 1e31 is above 4e30"), "{e}");
}

/// The packed clip in blocks of `block` keys against its reference: vectors
/// bit for bit, rotations within 1e-6 (their velocities 1e-4) of the
/// reference's magnitude, at least 1, as the runtime is held to the scalar
/// reference (inside their keys the packed clip plays rotations from
/// their four keys, `key_row`: the same curve, rounded otherwise).
/// Returns the largest difference of a rotation's value.
fn plays_its_reference(source: &PackSource, block: usize) -> f32 {
    let packed = Arc::new(Packed::encode_with(source, block).unwrap());
    assert_eq!(packed.block_keys(), block);
    let clip = Arc::new(Clip::from_packed(packed.clone()).unwrap());
    clip.verify_packed().unwrap();
    let reference = Arc::new(Clip::compile(&source.to_clip().unwrap()));
    let n = clip.channel_count();
    let (mut a, mut b) = (
        Instance::new(clip.clone()).with_velocities(),
        Instance::new(reference.clone()).with_velocities(),
    );
    let mut rotation = vec![false; 2 * n];
    let mut c = 0;
    for t in clip.tracks() {
        let dim = t.kind().dim();
        if t.kind() == tcb_core::TrackKind::Quat {
            rotation[c..c + dim].fill(true);
            rotation[n + c..n + c + dim].fill(true);
        }
        c += dim;
    }
    let mut worst = 0.0f32;
    // Forward at 60 fps, then random access (seeks back and across blocks),
    // then past both ends: the f32 clip of the reference's values (above),
    // and a fresh instance's (a seek) bit for bit.
    let (t0, t1) = clip.time_range().unwrap();
    let mut times: Vec<f64> = (0..)
        .map(|f| t0 + f as f64 / 60.0)
        .take_while(|t| *t <= t1)
        .collect();
    // Backward at 60 fps, forward at 240 fps (several frames a key) and at
    // 24 fps (several keys a frame, crossing segments), in short runs.
    let span = (t1 - t0).min(3.0);
    times.extend(
        (0..)
            .map(|f| t1 - f as f64 / 60.0)
            .take_while(|t| *t >= t1 - span),
    );
    times.extend(
        (0..)
            .map(|f| t0 + f as f64 / 240.0)
            .take_while(|t| *t <= t0 + span),
    );
    times.extend(
        (0..)
            .map(|f| t0 + 0.7 + f as f64 / 24.0)
            .take_while(|t| *t <= t1),
    );
    let mut x = 12345u64;
    for _ in 0..500 {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        times.push(t0 - 0.5 + (x >> 11) as f64 / (1u64 << 53) as f64 * (t1 - t0 + 1.0));
    }
    times.extend([t1, t0, t1 + 1.0, f64::NAN, f64::INFINITY, t0 + 0.3]);
    for t in times {
        let (ra, rb) = (
            rows_and_velocities(&mut a, t, n),
            rows_and_velocities(&mut b, t, n),
        );
        let seek = rows_and_velocities(&mut Instance::new(clip.clone()).with_velocities(), t, n);
        let same = ra
            .iter()
            .zip(&seek)
            .all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "at {t}: forward playback differs from a seek");
        for (i, (x, y)) in ra.iter().zip(&rb).enumerate() {
            if rotation[i] && y.is_finite() {
                let off = (x - y).abs() / y.abs().max(1.0);
                let velocity = i >= n;
                if !velocity {
                    worst = worst.max(off);
                }
                let tolerance = if velocity { 1e-4 } else { 1e-6 };
                assert!(off <= tolerance, "at {t}, column {i}: {x} vs {y}");
            } else {
                assert!(x.to_bits() == y.to_bits(), "at {t}, column {i}: {x} vs {y}");
            }
        }
    }
    // Several times smaller than the f32 clip.
    assert!(
        packed.to_bytes().len() * 4 < reference.memory_bytes(),
        "{}",
        packed.to_bytes().len()
    );
    worst
}

#[test]
fn file_round_trip() {
    let (_, source) = cmu();
    let mut packed = Packed::encode(&source).unwrap();
    packed.note = "tolerance 1e-3".into();
    let bytes = packed.to_bytes();
    let back = Packed::from_bytes(&bytes).unwrap();
    assert_eq!(back, packed);
    assert_eq!(back.decode().unwrap(), source);
    let clip = Clip::from_bytes(&bytes).unwrap();
    clip.verify_packed().unwrap();
    assert_eq!(clip.to_bytes().unwrap(), bytes);
    assert!(
        Clip::compile(&source.to_clip().unwrap())
            .to_bytes()
            .is_none()
    );
}

/// The skeleton a file keeps reads back; a file of an older version
/// (1: no skeleton section; 2: zigzag residuals; 3: a stored segment
/// table, no centers, no header-less lanes; 4: no block table; 5: no tracks
/// on key times of their own) or a newer one is refused
/// in one line that says so; a skeleton whose joint names a later parent,
/// or whose rest is not finite, is refused in one line.
#[test]
fn skeleton_round_trip_and_other_versions() {
    let bvh = include_str!("../../../data/cmu-01_01.bvh");
    let skeleton = tcb_io::bvh::Bvh::parse(bvh).unwrap().skeleton().clone();
    let (_, source) = cmu();
    let mut packed = Packed::encode(&source).unwrap();
    packed.skeleton = Some(skeleton.clone());
    let bytes = packed.to_bytes();
    let back = Packed::from_bytes(&bytes).unwrap();
    assert_eq!(back.skeleton.as_ref(), Some(&skeleton));
    let clip = Clip::from_bytes(&bytes).unwrap();
    let kept = clip.packed().and_then(|p| p.skeleton.as_ref());
    assert_eq!(
        kept.map(|s| s.joints().len()),
        Some(skeleton.joints().len())
    );

    let reseal = |mut b: Vec<u8>| {
        let len = b.len() as u64;
        b[12..20].copy_from_slice(&len.to_le_bytes());
        let crc = crc32fast::hash(&b[24..]);
        b[20..24].copy_from_slice(&crc.to_le_bytes());
        b
    };
    packed.skeleton = None;
    for (version, says) in [
        (1u32, "older"),
        (2, "older"),
        (3, "older"),
        (4, "older"),
        (5, "older"),
        (6, "older"),
        (7, "older"),
        (9, "newer"),
    ] {
        let mut b = packed.to_bytes();
        b[8..12].copy_from_slice(&version.to_le_bytes());
        let msg = Packed::from_bytes(&reseal(b)).unwrap_err().to_string();
        assert!(
            msg.starts_with(&format!(
                ".tcbc version {version}; this build reads version 8"
            )) && msg.contains(says)
                && !msg.contains('\n'),
            "{msg}"
        );
    }

    // A file of another segment length (16-key segments, as before
    // 2026-12-07): the body's name and note, start, interval, keys and
    // keys per block come first.
    let mut b = packed.to_bytes();
    let mut at = 24;
    for _ in 0..2 {
        at += 4 + u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize;
    }
    at += 8 + 8 + 4 + 4;
    assert_eq!(b[at..at + 4], 32u32.to_le_bytes());
    b[at..at + 4].copy_from_slice(&16u32.to_le_bytes());
    let msg = Packed::from_bytes(&reseal(b)).unwrap_err().to_string();
    assert!(
        msg.starts_with("segments of 16 keys; this build reads 32") && !msg.contains('\n'),
        "{msg}"
    );

    // The first joint's parent set to itself, then its rest's x to NaN.
    let first = bytes.len() - skeleton_bytes(&skeleton);
    let name = skeleton.joints()[0].name.len();
    let mut b = bytes.clone();
    b[first + 4 + name..first + 8 + name].copy_from_slice(&0u32.to_le_bytes());
    let msg = Packed::from_bytes(&reseal(b)).unwrap_err().to_string();
    assert!(
        msg.starts_with("skeleton: ") && !msg.contains('\n'),
        "{msg}"
    );
    let mut b = bytes.clone();
    b[first + 9 + name..first + 13 + name].copy_from_slice(&f32::NAN.to_le_bytes());
    let msg = Packed::from_bytes(&reseal(b)).unwrap_err().to_string();
    assert!(msg.contains("not finite"), "{msg}");
}

/// Bytes of a skeleton section's joints (after its count).
fn skeleton_bytes(s: &tcb_core::skeleton::Skeleton) -> usize {
    s.joints()
        .iter()
        .map(|j| 4 + j.name.len() + 4 + 1 + 12)
        .sum()
}

#[test]
fn bad_files_are_one_line_errors() {
    let (_, source) = cmu();
    let bytes = Packed::encode(&source).unwrap().to_bytes();
    let e = |b: &[u8]| Packed::from_bytes(b).unwrap_err().to_string();
    assert!(e(b"").contains("not a .tcbc file"), "{}", e(b""));
    assert!(e(b"{\"format\": \"tcb-clip/1\"}").contains("not a .tcbc file"));
    // The magic number, then less than a header: said to be cut short.
    let short = e(b"TCBC\0\r\n\x1a\x08\x00");
    assert!(
        short.contains("10 bytes, shorter than a .tcbc header (24)"),
        "{short}"
    );
    // Every truncation is refused, none panics.
    for cut in (0..bytes.len()).step_by(997) {
        let msg = e(&bytes[..cut]);
        assert!(!msg.contains('\n'), "{msg}");
    }
    // A flipped bit anywhere is caught by the checksum (or the header).
    for at in (0..bytes.len()).step_by(1009) {
        let mut b = bytes.clone();
        b[at] ^= 0x10;
        let msg = e(&b);
        assert!(!msg.contains('\n'), "{msg}");
    }
    let mut b = bytes.clone();
    b[8] = 9;
    assert!(e(&b).contains("version 9"), "{}", e(&b));
}

/// A file whose checksum is right but whose contents lie: the counts and
/// widths are checked against the bytes there are.
#[test]
fn lying_files_are_refused() {
    let (_, source) = cmu();
    let bytes = Packed::encode(&source).unwrap().to_bytes();
    let reseal = |mut b: Vec<u8>| {
        let crc = crc32fast::hash(&b[24..]);
        b[20..24].copy_from_slice(&crc.to_le_bytes());
        b
    };
    // The key count (after the name "cmu", the empty note and two f64s).
    let at = 24 + 4 + 3 + 4 + 16;
    for keys in [0u32, 1, 2753, 100_000, u32::MAX] {
        let mut b = bytes.clone();
        b[at..at + 4].copy_from_slice(&keys.to_le_bytes());
        let msg = Packed::from_bytes(&reseal(b)).unwrap_err().to_string();
        assert!(msg.contains("keys"), "{keys}: {msg}");
    }
    // Every byte after the header, changed and resealed: an error or a
    // clip, never a panic.
    for at in (24..bytes.len()).step_by(211) {
        let mut b = bytes.clone();
        b[at] = b[at].wrapping_add(77);
        let _ = Packed::from_bytes(&reseal(b));
    }
}

/// Files the encoder writes read back, however small their tracks (a
/// check once assumed 55 bytes a track; the least is 42); a clip of no
/// tracks is refused.
#[test]
fn small_tracks_read_back_and_no_tracks_is_refused() {
    use tcb_core::{Tcb, TrackKind, TrackSettings};
    let track = |i: usize| tcb_runtime::PackTrack {
        name: format!("{i}"),
        kind: TrackKind::Scalar,
        settings: TrackSettings::default(),
        tcb: Tcb::DEFAULT,
        step: 0.5,
        rebuild_w: false,
        center: None,
        values: vec![vec![1, 1]],
    };
    let mut source = PackSource {
        name: String::new(),
        start: 0.0,
        interval: 1.0,
        keys: 2,
        tracks: (0..7).map(track).collect(),
        scales: Default::default(),
        loose: Vec::new(),
    };
    let bytes = Packed::encode(&source).unwrap().to_bytes();
    Packed::from_bytes(&bytes).unwrap();
    Clip::from_bytes(&bytes).unwrap().verify_packed().unwrap();
    source.tracks.clear();
    let e = Packed::encode(&source).unwrap_err().to_string();
    assert!(e.contains("no tracks"), "{e}");

    // One component more than a packed clip holds (the decoder keeps a
    // component's first bit in 25 bits): refused in one line.
    let four = tcb_runtime::PackTrack {
        kind: TrackKind::Vec4,
        values: vec![vec![1, 1]; 4],
        ..track(0)
    };
    let lanes = tcb_runtime::pack::MAX_LANES;
    source.tracks = vec![four; lanes / 4];
    source.tracks.push(track(0));
    for (i, t) in source.tracks.iter_mut().enumerate() {
        t.name = format!("{i}");
    }
    let e = Packed::encode(&source).unwrap_err().to_string();
    assert!(
        e.contains(&format!("{} stored components", lanes + 1)) && !e.contains('\n'),
        "{e}"
    );
}

/// A component whose every segment is on the line (a constant track) has
/// no headers: a clip of constant zeros is a stream of no bits at all, and
/// plays its value; a lane table that claims a base width above 32 is
/// refused, and a center that is not a unit quaternion too.
#[test]
fn constant_tracks_have_no_headers_and_centers_are_unit() {
    use tcb_core::{Tcb, TrackKind, TrackSettings};
    let track = |name: &str, kind: TrackKind, value: i32| tcb_runtime::PackTrack {
        name: name.into(),
        kind,
        settings: TrackSettings::default(),
        tcb: Tcb::DEFAULT,
        step: 0.25,
        rebuild_w: false,
        center: None,
        values: vec![vec![value; 100]; kind.dim()],
    };
    let zeros = PackSource {
        name: "flat".into(),
        start: 0.0,
        interval: 0.5,
        keys: 100,
        tracks: vec![
            track("a", TrackKind::Vec3, 0),
            track("b", TrackKind::Scalar, 0),
        ],
        scales: Default::default(),
        loose: Vec::new(),
    };
    let packed = Packed::encode(&zeros).unwrap();
    assert_eq!(packed.stream_bits(), 0);
    let mut ones = zeros.clone();
    ones.tracks[1] = track("b", TrackKind::Scalar, 4);
    let bytes = Packed::encode(&ones).unwrap().to_bytes();
    let clip = Arc::new(Clip::from_bytes(&bytes).unwrap());
    clip.verify_packed().unwrap();
    let b = clip.track("b").unwrap();
    assert_eq!(Instance::new(clip).sample(17.3).scalar(b), Some(1.0));

    let reseal = |mut b: Vec<u8>| {
        let crc = crc32fast::hash(&b[24..]);
        b[20..24].copy_from_slice(&crc.to_le_bytes());
        b
    };
    // The lane table is the three rows of 4 lanes before the block table
    // (2 blocks of 64 keys), the stream's length (0 bytes of stream), the
    // count of tracks on their own key times (0) and the joint count (0).
    let base = bytes.len() - 4 - 8 - 4 - 4 - 4;
    let mut lying = bytes.clone();
    lying[base] = 33;
    let msg = Packed::from_bytes(&reseal(lying)).unwrap_err().to_string();
    assert!(msg.contains("base width of 33"), "{msg}");

    let mut turned = ones.clone();
    let mut q = track("q", TrackKind::Quat, 0);
    q.settings.rotation = RotationMode::Hermite;
    q.settings.hemisphere = tcb_core::Hemisphere::Keep;
    q.values = vec![vec![0; 100], vec![0; 100], vec![0; 100]];
    q.rebuild_w = true;
    q.step = 1.0 / 1024.0;
    q.center = Some([0.0, 0.6, 0.0, 0.8]);
    turned.tracks.push(q.clone());
    let clip = Clip::from_packed(Arc::new(Packed::encode(&turned).unwrap())).unwrap();
    clip.verify_packed().unwrap();
    q.center = Some([0.0, 0.6, 0.0, 0.7]);
    turned.tracks[2] = q;
    let msg = Packed::encode(&turned).unwrap_err().to_string();
    assert!(msg.contains("not a unit quaternion"), "{msg}");
}

/// A reduced clip's shape: tracks on the capture's grid, and beside them
/// tracks on key times of their own (a vector with explicit tangents, a
/// `hermite` rotation with the rule's, a constant scalar of two keys, a
/// vector whose `post` differs from the grid's). The grid's tracks are
/// packed, the others keep their keys; the file reads back, loads,
/// verifies, and plays its reference bit for bit, forward and seeking.
#[test]
fn tracks_on_their_own_key_times_keep_their_keys() {
    use glam::{Quat, Vec3};
    use tcb_core::params::{Extrapolation, KeyParams};
    use tcb_core::{NamedTrack, RotationTrack, SourceClip, Track, TrackData, TrackSettings};
    let hermite = TrackSettings {
        rotation: RotationMode::Hermite,
        ..TrackSettings::default()
    };
    let grid: Vec<f64> = (0..100).map(|k| k as f64 / 30.0).collect();
    let own = [0.0, 0.2, 0.45, 1.0, 1.6, 2.9, 3.3];
    let wave = |t: f64, f: f64| Vec3::new((t * f).sin() as f32, (t * 1.3).cos() as f32, 0.25);
    let turn = |t: f64| Quat::from_rotation_y((0.8 * t) as f32) * Quat::from_rotation_x(0.3);
    let vec3 = |times: &[f64], f: f64, keys: Vec<KeyParams<Vec3>>, s: &TrackSettings| {
        let v = times.iter().map(|t| wave(*t, f)).collect();
        TrackData::Vec3(Track::new(times.to_vec(), v, keys, s).unwrap())
    };
    let tangents = own
        .iter()
        .map(|t| KeyParams {
            tangent_in: Some(wave(*t, 2.0) * 0.5),
            tangent_out: Some(wave(*t, 0.5)),
            ..KeyParams::default()
        })
        .collect();
    let quat = |times: &[f64]| {
        let q = times.iter().map(|t| turn(*t)).collect();
        TrackData::Quat(RotationTrack::new(times.to_vec(), q, vec![], &hermite).unwrap())
    };
    let level = Track::new(vec![0.0, 3.3], vec![0.5f32, 0.5], vec![], &hermite).unwrap();
    let cycle = TrackSettings {
        post: Extrapolation::Repeat,
        ..hermite
    };
    let named = |name: &str, data| NamedTrack {
        name: name.into(),
        data,
    };
    let clip = SourceClip::new(
        "reduced",
        vec![
            named("b", vec3(&own, 1.0, tangents, &hermite)),
            named("a", vec3(&grid, 2.0, vec![], &hermite)),
            named("c", quat(&own[1..])),
            named("r", quat(&grid)),
            named("d", TrackData::Scalar(level)),
            named("e", vec3(&grid, 3.0, vec![], &cycle)),
        ],
    )
    .unwrap();
    let steps = vec![1.0 / 4096.0; 6];
    let source = PackSource::quantize(&clip, &steps).unwrap();
    let grid_names: Vec<&str> = source.tracks.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(grid_names, ["a", "r"]);
    let places: Vec<(usize, &str, bool)> = source
        .loose
        .iter()
        .map(|t| (t.at, t.name.as_str(), t.tangents.is_some()))
        .collect();
    assert_eq!(
        places,
        [
            (0, "b", true),
            (2, "c", false),
            (4, "d", false),
            (5, "e", false)
        ]
    );
    assert_eq!(
        source.to_clip().unwrap().column_names(),
        clip.column_names()
    );
    for block in [32, 64] {
        plays_its_reference(&source, block);
    }
    let packed = Packed::encode(&source).unwrap();
    let bytes = packed.to_bytes();
    assert_eq!(Packed::from_bytes(&bytes).unwrap(), packed);
    assert_eq!(packed.decode().unwrap(), source);
    let loaded = Clip::from_bytes(&bytes).unwrap();
    loaded.verify_packed().unwrap();
    assert_eq!(loaded.to_bytes().unwrap(), bytes);
    // A track of its own on the grid's times and ends belongs on the grid.
    let mut on_grid = source.clone();
    let times = on_grid.times();
    let own = &mut on_grid.loose[1];
    own.times = times;
    own.values = vec![vec![0; 100]; 4];
    let e = Packed::encode(&on_grid).unwrap_err().to_string();
    assert!(e.contains("belongs on the grid"), "{e}");
    // The loose tracks' keys stay within half a step (and what normalizing
    // a rotation adds).
    let back = source.to_clip().unwrap();
    let loose = clip.tracks().iter().zip(back.tracks());
    for (t, b) in loose.filter(|(t, _)| !["a", "r"].contains(&t.name.as_str())) {
        for k in 0..t.data.times().len() {
            let time = t.data.times()[k];
            let (mut x, mut y) = ([0.0f32; 4], [0.0f32; 4]);
            t.data
                .sample_into(time, &mut x[..t.data.kind().dim()], None);
            b.data
                .sample_into(time, &mut y[..t.data.kind().dim()], None);
            let off = x
                .iter()
                .zip(&y)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f32::max);
            assert!(
                off <= 1.0 / 8192.0 + 1e-6,
                "{} key {k}: {x:?} {y:?}",
                t.name
            );
        }
    }
}

/// Keys longer than the key form's bound (`|q|^2` above 1.02: components
/// of 64 times a unit quaternion's, `w` rebuilt as 0) play from their
/// tangents, as the reference does: every column bit for bit.
#[test]
fn long_rotation_keys_play_from_their_tangents() {
    let (_, mut source) = cmu();
    source.keys = 129;
    for t in &mut source.tracks {
        for v in &mut t.values {
            v.truncate(129);
            if t.kind.dim() == 4 {
                v.iter_mut().for_each(|x| *x *= 64);
            }
        }
    }
    let packed = Arc::new(Packed::encode(&source).unwrap());
    let clip = Arc::new(Clip::from_packed(packed).unwrap());
    clip.verify_packed().unwrap();
    let reference = Arc::new(Clip::compile(&source.to_clip().unwrap()));
    let n = clip.channel_count();
    let (mut a, mut b) = (
        Instance::new(clip.clone()).with_velocities(),
        Instance::new(reference).with_velocities(),
    );
    let (t0, t1) = clip.time_range().unwrap();
    let times = (0..).map(|f| t0 + f as f64 / 60.0).take_while(|t| *t <= t1);
    for t in times {
        let (ra, rb) = (
            rows_and_velocities(&mut a, t, n),
            rows_and_velocities(&mut b, t, n),
        );
        let same = ra.iter().zip(&rb).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "at {t}");
    }
}
