//! A constant rotation on key times of its own (what `tcb reduce` writes
//! for a still joint: 2 keys, the first and last) takes a free lane of a
//! group instead of a loose lane (issue 33, item 3), and plays as the
//! reference does.

use std::sync::Arc;
use tcb_runtime::{Clip, CompileOptions, Instance};

/// 3 rotations and a translation on 9 keys, then the tracks of `extra`.
fn clip(extra: &[&str]) -> tcb_core::SourceClip {
    let times = "[0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]";
    let turn = |axis: usize, rate: f64| {
        let values: Vec<String> = (0..9)
            .map(|k| {
                let a = rate * k as f64 + 0.1 * ((k * 7 % 5) as f64);
                let mut q = [0.0; 4];
                q[axis] = (a / 2.0).sin();
                q[3] = (a / 2.0).cos();
                format!("[{}, {}, {}, {}]", q[0], q[1], q[2], q[3])
            })
            .collect();
        values.join(", ")
    };
    let mut tracks = vec![
        format!(
            r#"{{"name": "root.translation", "kind": "vec3", "times": {times},
               "values": [[0,0,0],[1,0,0],[2,1,0],[3,1,0],[4,0,0],[5,0,1],[6,0,1],[7,2,1],[8,2,2]]}}"#
        ),
        format!(
            r#"{{"name": "a.rotation", "kind": "quat", "times": {times}, "values": [{}]}}"#,
            turn(0, 0.3)
        ),
        format!(
            r#"{{"name": "b.rotation", "kind": "quat", "times": {times}, "values": [{}]}}"#,
            turn(1, -0.2)
        ),
        format!(
            r#"{{"name": "c.rotation", "kind": "quat", "times": {times}, "values": [{}]}}"#,
            turn(2, 0.5)
        ),
    ];
    tracks.extend(extra.iter().map(|t| t.to_string()));
    let text = format!(
        r#"{{"format": "tcb-clip/1", "defaults": {{"rotation": "hermite"}}, "tracks": [{}]}}"#,
        tracks.join(",")
    );
    tcb_io::ClipDoc::parse(&text).unwrap().build().unwrap()
}

/// Every channel of `compiled` against the reference, at times across and
/// beyond the keys: vectors bit for bit, rotations within 1e-6 (both
/// within `quantized` when the clip is), velocities within 2e-4 of
/// `max(1, |v|)`.
fn plays_as_the_reference(source: &tcb_core::SourceClip, compiled: Clip, quantized: f32) {
    let compiled = Arc::new(compiled);
    let mut inst = Instance::new(compiled.clone()).with_velocities();
    let n = source.channel_count();
    let (mut want, mut want_v) = (vec![0.0f32; n], vec![0.0f32; n]);
    let (mut got, mut got_v) = (vec![0.0f32; n], vec![0.0f32; n]);
    let rotation_channels: Vec<bool> = source
        .tracks()
        .iter()
        .flat_map(|t| {
            let rot = t.data.kind() == tcb_core::TrackKind::Quat;
            std::iter::repeat_n(rot, t.data.kind().dim())
        })
        .collect();
    for i in -40..=140 {
        let t = f64::from(i) * 0.0077;
        source.sample_into(t, &mut want, Some(&mut want_v));
        inst.sample(t).write_row(&mut got, Some(&mut got_v));
        for c in 0..n {
            let at = format!("channel {c} at {t}: {} against {}", got[c], want[c]);
            if quantized > 0.0 {
                assert!((got[c] - want[c]).abs() <= quantized, "{at}");
            } else if rotation_channels[c] {
                assert!((got[c] - want[c]).abs() <= 1e-6, "{at}");
            } else {
                assert_eq!(got[c].to_bits(), want[c].to_bits(), "{at}");
            }
            let scale = want_v[c].abs().max(1.0);
            assert!(
                (got_v[c] - want_v[c]).abs() <= 2e-4 * scale,
                "velocity of {at}: {} against {}",
                got_v[c],
                want_v[c]
            );
        }
    }
}

const STILL: &str = r#"{"name": "still.rotation", "kind": "quat", "times": [0, 0.8], "values": [[0.1, 0.2, 0.3, 0.927362], [0.1, 0.2, 0.3, 0.927362]]}"#;

#[test]
fn constant_rotations_on_keys_of_their_own_join_a_group() {
    let identity = r#"{"name": "id.rotation", "kind": "quat", "times": [0, 0.8], "values": [[0, 0, 0, 1], [0, 0, 0, 1]]}"#;
    let still = r#"{"name": "still.rotation", "kind": "quat", "times": [0.05, 0.6, 0.75], "values": [[0.1, 0.2, 0.3, 0.927362], [0.1, 0.2, 0.3, 0.927362], [0.1, 0.2, 0.3, 0.927362]], "pre": "repeat", "post": "oscillate"}"#;
    let source = clip(&[identity, still]);
    let compiled = Clip::compile(&source);
    assert_eq!(compiled.loose_track_count(), 0);
    assert_eq!(compiled.stats().grids.len(), 1);
    plays_as_the_reference(&source, compiled, 0.0);
    plays_as_the_reference(
        &source,
        Clip::compile_with(&source, &CompileOptions::default().quantize(true)),
        1e-3,
    );
}

#[test]
fn what_is_not_constant_or_resets_stays_loose() {
    // (the track, loose tracks, groups)
    let cases = [
        // A turn on keys of its own: a loose lane.
        (
            r#"{"name": "x.rotation", "kind": "quat", "times": [0, 0.8], "values": [[0, 0, 0, 1], [0, 0, 0.1, 0.995]]}"#,
            1,
            1,
        ),
        // Still, but the identity before its first key: a group of its own
        // (as every rotation that resets).
        (
            r#"{"name": "x.rotation", "kind": "quat", "times": [0.1, 0.8], "values": [[0.1, 0.2, 0.3, 0.927362], [0.1, 0.2, 0.3, 0.927362]], "pre": "reset"}"#,
            0,
            2,
        ),
    ];
    for (case, loose, groups) in cases {
        let source = clip(&[case]);
        let compiled = Clip::compile(&source);
        assert_eq!(compiled.loose_track_count(), loose, "{case}");
        assert_eq!(compiled.stats().grids.len(), groups, "{case}");
        plays_as_the_reference(&source, compiled, 0.0);
    }
}

#[test]
fn a_full_rotation_block_has_no_lane_to_give() {
    // 8 rotations on the grid fill its block: the constant stays loose.
    let times = "[0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8]";
    let more: Vec<String> = (0..5)
        .map(|i| {
            format!(
                r#"{{"name": "m{i}.rotation", "kind": "quat", "times": {times}, "values": [{}]}}"#,
                (0..9)
                    .map(|k| format!("[0, {}, 0, 1]", 0.01 * (k * i) as f64))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        })
        .collect();
    let mut extra: Vec<&str> = more.iter().map(String::as_str).collect();
    extra.push(STILL);
    let source = clip(&extra);
    let compiled = Clip::compile(&source);
    assert_eq!(compiled.loose_track_count(), 1);
    plays_as_the_reference(&source, compiled, 0.0);
}

/// A packed clip's grid group keeps its lanes, the stream's, even a
/// constant rotation's where a group on other key times has a free lane.
#[test]
fn a_packed_grid_keeps_its_constant_lanes() {
    use glam::{Quat, Vec3};
    use tcb_core::{NamedTrack, RotationTrack, SourceClip, Track, TrackData, TrackSettings};
    use tcb_runtime::pack::{PackSource, Packed};
    let hermite = TrackSettings {
        rotation: tcb_core::RotationMode::Hermite,
        ..TrackSettings::default()
    };
    let grid: Vec<f64> = (0..40).map(|k| f64::from(k) / 30.0).collect();
    let own = [0.05, 0.2, 0.45, 0.9, 1.25];
    let quat = |times: &[f64], rate: f32| {
        let q = times
            .iter()
            .map(|t| Quat::from_rotation_y(rate * *t as f32) * Quat::from_rotation_x(0.3))
            .collect();
        TrackData::Quat(RotationTrack::new(times.to_vec(), q, vec![], &hermite).unwrap())
    };
    let v: Vec<Vec3> = own.iter().map(|t| Vec3::new(*t as f32, 1.0, 0.5)).collect();
    let named = |name: &str, data| NamedTrack {
        name: name.into(),
        data,
    };
    let clip = SourceClip::new(
        "packed",
        vec![
            named("still", quat(&grid, 0.0)),
            named("turn", quat(&grid, 0.8)),
            named(
                "v",
                TrackData::Vec3(Track::new(own.to_vec(), v, vec![], &hermite).unwrap()),
            ),
            named("w", quat(&own, -0.5)),
        ],
    )
    .unwrap();
    let source = PackSource::quantize(&clip, &[1.0 / 4096.0; 4]).unwrap();
    let names: Vec<&str> = source.tracks.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["still", "turn"]);
    let bytes = Packed::encode(&source).unwrap().to_bytes();
    let loaded = Clip::from_bytes(&bytes).unwrap();
    loaded.verify_packed().unwrap();
    let reference = source.to_clip().unwrap();
    plays_as_the_reference(&reference, loaded, 0.0);
}
