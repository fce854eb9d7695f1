//! Issue 29, class 2: edges of time, the runtime against the scalar
//! reference. Each test plays a small clip at times a few ulps from where
//! a rounding decides something (a final `step` key, a key after an
//! infinite tangent, -f64::MAX, a squad segment a few ulps long) and holds
//! the runtime to the reference as `tests/equivalence.rs` does: vector
//! channels equal as numbers (-0 equals 0) wherever the reference is
//! finite, rotations within 1e-6 up to sign. Every mismatch is collected
//! and the first few shown.

use std::sync::Arc;
use tcb_core::TrackData;
use tcb_runtime::{Clip, Instance};

/// `x` moved by `n` ulps (up for positive `n`).
fn ulps(x: f64, n: i32) -> f64 {
    let mut x = x;
    for _ in 0..n.unsigned_abs() {
        x = if n > 0 { x.next_up() } else { x.next_down() };
    }
    x
}

fn clip(text: &str) -> tcb_core::SourceClip {
    tcb_io::ClipDoc::parse(text)
        .expect("the test's clip parses")
        .build()
        .expect("the test's clip builds")
}

/// Where the runtime (forward playback over `times`, and a fresh instance
/// per time, with velocities) and the reference disagree.
fn mismatches(clip: &tcb_core::SourceClip, times: &[f64]) -> Vec<String> {
    let compiled = Arc::new(Clip::compile(clip));
    let n = clip.channel_count();
    let (mut got, mut want) = (vec![0.0f32; n], vec![0.0f32; n]);
    let mut playing = Instance::new(compiled.clone()).with_velocities();
    let mut bad = Vec::new();
    for &t in times {
        for fresh in [false, true] {
            let pose = if fresh {
                let mut i = Instance::new(compiled.clone()).with_velocities();
                i.sample(t).clone()
            } else {
                playing.sample(t).clone()
            };
            pose.write_row(&mut got, None);
            clip.sample_into(t, &mut want, None);
            let mut at = 0;
            for track in clip.tracks() {
                let dim = track.data.kind().dim();
                let (g, w) = (&got[at..at + dim], &want[at..at + dim]);
                at += dim;
                let ok = if let TrackData::Quat(_) = track.data {
                    let close = |s: f32| g.iter().zip(w).all(|(a, b)| (s * a - b).abs() <= 1e-6);
                    w.iter().any(|x| x.is_nan()) || close(1.0) || close(-1.0)
                } else {
                    // Where the reference is not finite (tangents that
                    // overflow f32 make its curve NaN), the runtime may be better.
                    w.iter().any(|x| !x.is_finite())
                        || g.iter()
                            .zip(w)
                            .all(|(a, b)| a == b || (a.is_nan() && b.is_nan()))
                };
                if !ok {
                    let how = if fresh { "seek" } else { "forward" };
                    bad.push(format!(
                        "{} at {t:e} ({how}): runtime {g:?}, reference {w:?}",
                        track.name
                    ));
                }
            }
        }
    }
    bad
}

fn assert_none(bad: &[String]) {
    assert!(
        bad.is_empty(),
        "{} mismatches, first: {:#?}",
        bad.len(),
        &bad[..bad.len().min(6)]
    );
}

/// Times from 64 ulps before to 4 after each of `keys`.
fn around(keys: &[f64]) -> Vec<f64> {
    keys.iter()
        .flat_map(|&k| (-64..=4).map(move |n| ulps(k, n)))
        .collect()
}

/// A final `step` segment holds its first key until the last key's time,
/// then the last key: at a time that rounds (in f32, or in the segment
/// parameter) to just before the final key, the runtime must hold the same
/// key as the reference. Key times where f32 is coarse (1e6, 3.15e7) or
/// not representable (0.1), played directly and through `repeat`, so
/// that the wrapped time lands a hair before the final key.
#[test]
fn a_time_just_before_a_final_step_key() {
    let mut bad = Vec::new();
    for (a, b, c) in [
        (0.0, 0.1, 0.3),
        (1e6, 1e6 + 0.1, 1e6 + 0.3),
        (3.15e7, 3.15e7 + 0.125, 3.15e7 + 0.2),
        (-2.0, 1.0 / 3.0, 2.0 / 3.0),
        (0.0, 1.0, 1.0 + 1e-9),
    ] {
        let text = format!(
            r#"{{"format": "tcb-clip/1", "tracks": [
          {{"name": "s", "kind": "scalar", "times": [{a:?}, {b:?}, {c:?}], "values": [1, 2, 3],
           "keys": [{{}}, {{"interp": "step"}}, {{}}], "post": "repeat"}},
          {{"name": "v", "kind": "vec3", "times": [{a:?}, {b:?}, {c:?}],
           "values": [[1, 0, 0], [0, 2, 0], [0, 0, 3]],
           "keys": [{{"interp": "step"}}, {{"interp": "step"}}, {{}}], "pre": "repeat", "post": "oscillate"}},
          {{"name": "r", "kind": "quat", "times": [{a:?}, {b:?}, {c:?}],
           "values": [[0, 0, 0, 1], [0, 0.7071068, 0, 0.7071068], [1, 0, 0, 0]],
           "keys": [{{}}, {{"interp": "step"}}, {{}}], "post": "repeat"}}]}}"#
        );
        let clip = clip(&text);
        let d = c - a;
        let mut times = around(&[b, c]);
        // Through the extrapolation: the final key a cycle (or ten) later.
        for cycles in [1.0, 2.0, 10.0, 1e3] {
            times.extend(around(&[c + cycles * d, a - cycles * d]));
        }
        // f32 neighbours of the final key.
        let f = c as f32;
        times.extend([f.next_down(), f, f.next_up()].map(f64::from));
        bad.extend(mismatches(&clip, &times));
    }
    assert_none(&bad);
}

/// A key before the last whose outgoing tangent is infinite (a bias of
/// -1e300 or a tension of 1.6e80 makes it overflow f32; the contract
/// allows any finite tcb): at
/// and just before the last key the Hermite basis row of that tangent is
/// 0, and 0 x inf is NaN. The reference snaps to the key there; so must
/// the runtime.
#[test]
fn an_infinite_tangent_just_before_the_last_key() {
    let mut bad = Vec::new();
    for (a, b, c) in [
        (0.0, 1.0, 2.0),
        (0.0, 0.1, 0.3),
        (1e6, 1e6 + 0.1, 1e6 + 0.3),
    ] {
        for (rotation, tcb) in [
            ("hermite", "[0, 0, -1e300]"),
            ("squad", "[0, 0, -1e300]"),
            ("hermite", "[1.6e80, 0, 0]"),
        ] {
            let text = format!(
                r#"{{"format": "tcb-clip/1", "tracks": [
              {{"name": "s", "kind": "scalar", "times": [{a:?}, {b:?}, {c:?}], "values": [1, 2, 3],
               "keys": [{{}}, {{"tcb": {tcb}}}, {{}}]}},
              {{"name": "v", "kind": "vec3", "times": [{a:?}, {b:?}, {c:?}],
               "values": [[1, 0, 0], [0, 2, 0], [0, 0, 3]],
               "keys": [{{}}, {{"tcb": {tcb}}}, {{}}], "post": "linear"}},
              {{"name": "r", "kind": "quat", "rotation": "{rotation}", "times": [{a:?}, {b:?}, {c:?}],
               "values": [[0, 0, 0, 1], [0, 0.7071068, 0, 0.7071068], [1, 0, 0, 0]],
               "keys": [{{}}, {{"tcb": {tcb}}}, {{}}]}}]}}"#
            );
            let clip = clip(&text);
            // Inside the keys the infinite tangent makes the reference NaN
            // too; at and just before the last key it snaps to the key.
            let mut times = around(&[c]);
            times.extend([c + 1.0, c + 1e300, f64::INFINITY]);
            bad.extend(mismatches(&clip, &times));
        }
    }
    // Found by the `playback` fuzz target
    // (`fuzz/open/playback-infinite-tangent-one-ulp-before-last-key`): a
    // tension of 1.6e80, one ulp before the last key.
    let found = clip(
        r#"{"format": "tcb-clip/1", "tracks": [
      {"name": "t0", "kind": "scalar", "times": [-5.5, -4.4609375, -3.734375, -2.3515625, 1.421875],
       "values": [-4.4870107e-38, -6.11499, 4.5739746, 0.017578125, -7.093994],
       "ends": "copy", "match_speed": true, "continuity_fade": false,
       "tcb": [1.5909326897655337e80, 1.19, 0.03], "pre": "linear", "post": "constant"}]}"#,
    );
    bad.extend(mismatches(&found, &around(&[1.421875])));
    // The same track nine times over: one group on a shared grid, not a
    // loose lane.
    let track = |i: usize| {
        format!(
            r#"{{"name": "t{i}", "kind": "scalar", "times": [-5.5, -4.4609375, -3.734375, -2.3515625, 1.421875],
       "values": [-4.4870107e-38, -6.11499, 4.5739746, 0.017578125, -7.093994],
       "ends": "copy", "match_speed": true, "continuity_fade": false,
       "tcb": [1.5909326897655337e80, 1.19, 0.03], "pre": "linear", "post": "constant"}}"#
        )
    };
    let tracks: Vec<String> = (0..9).map(track).collect();
    let grouped = clip(&format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
        tracks.join(",")
    ));
    assert_eq!(Clip::compile(&grouped).loose_track_count(), 0);
    bad.extend(mismatches(&grouped, &around(&[1.421875])));
    // The same ten times over: one group of the kernels instead of loose
    // lanes (both gave NaN there).
    let varied = |i: usize| {
        format!(
            r#"{{"name": "t{i}", "kind": "scalar", "times": [-5.5, -4.4609375, -3.734375, -2.3515625, 1.421875],
           "values": [1, 2, 3, 4, {i}], "ends": "copy", "match_speed": true, "continuity_fade": false,
           "tcb": [1.5909326897655337e80, 1.19, 0.03], "pre": "linear", "post": "constant"}}"#
        )
    };
    let ten: Vec<String> = (0..10).map(varied).collect();
    let group = clip(&format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
        ten.join(", ")
    ));
    assert_eq!(Clip::compile(&group).group_count(), 1);
    bad.extend(mismatches(&group, &around(&[1.421875])));
    assert_none(&bad);
}

/// Finite times near -f64::MAX (and +f64::MAX) under every `pre` (and
/// `post`) mode: the wrapped time's arithmetic (`t - t0` overflows to
/// -inf there) must give what the reference gives.
#[test]
fn finite_times_near_the_ends_of_f64() {
    let mut bad = Vec::new();
    for mode in [
        "constant",
        "linear",
        "reset",
        "repeat",
        "oscillate",
        "offset-repeat",
    ] {
        for (a, b, c) in [(0.0, 1.0, 2.5), (-3.0, 0.1, 7.0), (1e300, 2e300, 3e300)] {
            let text = format!(
                r#"{{"format": "tcb-clip/1", "defaults": {{"pre": "{mode}", "post": "{mode}"}}, "tracks": [
              {{"name": "s", "kind": "scalar", "times": [{a:?}, {b:?}, {c:?}], "values": [1, 2, 4]}},
              {{"name": "v", "kind": "vec2", "times": [{a:?}, {b:?}, {c:?}], "values": [[1, 0], [0, 2], [5, 3]],
               "keys": [{{"interp": "linear"}}, {{"interp": "step"}}, {{}}]}}]}}"#
            );
            let clip = clip(&text);
            let mut times = Vec::new();
            for edge in [-f64::MAX, f64::MAX, -1e308, 1e308, -f64::MAX / 2.0] {
                times.extend((-8..=8).map(|n| ulps(edge, n)).filter(|t| t.is_finite()));
            }
            for t in mismatches(&clip, &times) {
                bad.push(format!("{mode} [{a:e}, {b:e}, {c:e}]: {t}"));
            }
        }
    }
    // A rotation under the modes rotations have.
    for mode in ["constant", "reset", "repeat", "oscillate"] {
        let text = format!(
            r#"{{"format": "tcb-clip/1", "defaults": {{"pre": "{mode}", "post": "{mode}"}}, "tracks": [
          {{"name": "r", "kind": "quat", "times": [0, 1, 2.5],
           "values": [[0, 0, 0, 1], [0, 0.7071068, 0, 0.7071068], [1, 0, 0, 0]]}}]}}"#
        );
        let clip = clip(&text);
        let times: Vec<f64> = [-f64::MAX, f64::MAX]
            .iter()
            .flat_map(|&e| (-8..=8).map(move |n| ulps(e, n)))
            .filter(|t| t.is_finite())
            .collect();
        for t in mismatches(&clip, &times) {
            bad.push(format!("rotation {mode}: {t}"));
        }
    }
    assert_none(&bad);
}

/// A squad rotation whose middle segment is a few ulps long: the runtime
/// splits squad segments into pieces played between split times rounded
/// to f64 (equal to the ends, or to each other, on a segment this short,
/// and up to half an ulp off their nominal place on any segment). Each
/// piece must be built for the part of the segment those rounded times
/// cover, not for its nominal `[j/m, (j+1)/m]`: built at the nominal
/// parameters, a 17-ulp segment was 0.02 off. Inside and around that
/// segment the runtime must stay within 1e-6 of the reference.
#[test]
fn squad_on_a_segment_a_few_ulps_long() {
    let mut bad = Vec::new();
    for start in [1.0, 0.1, 1e3 + 0.1, 1e6 / 3.0] {
        for len in [1, 2, 3, 5, 8, 17, 33, 100, 1000] {
            let b = ulps(start, len);
            let text = format!(
                r#"{{"format": "tcb-clip/1", "tracks": [
              {{"name": "r", "kind": "quat", "rotation": "squad", "times": [{:?}, {start:?}, {b:?}, {:?}],
               "values": [[0, 0, 0, 1], [0, 0.7071068, 0, 0.7071068], [0.5, 0.5, 0.5, 0.5], [1, 0, 0, 0]]}}]}}"#,
                start - 1.0,
                b + 1.0,
            );
            let clip = clip(&text);
            let times: Vec<f64> = (-4..=len + 4).map(|n| ulps(start, n)).collect();
            for t in mismatches(&clip, &times) {
                bad.push(format!("segment of {len} ulps at {start}: {t}"));
            }
        }
    }
    assert_none(&bad);
}

/// A final `step` segment (from a key of 1.5e37, after an eased segment)
/// one ulp before its last key (`fuzz/open/playback-final-step-reference-early-*`,
/// the `playback` target's 20-minute run of 2026-12-05): the runtime holds
/// the step's key (math.md: it "stays P_k"), the reference gives the last
/// key [2.63, 0.094, 6.41] a hair early: `tcb_core::Track::evaluate`
/// snapped to the last key where the segment parameter `u` is 1, and here
/// `(t - t_k) / (t_k+1 - t_k)` rounds to 1. The reference now gives the
/// last key where the time reaches the last key's, as the runtime does.
#[test]
fn a_final_step_one_ulp_before_its_last_key() {
    let clip = clip(
        r#"{"format": "tcb-clip/1", "defaults": {"tangent_rule": "uniform", "continuity_fade": false, "post": "linear"},
          "tracks": [{"name": "t0", "kind": "vec3", "times": [-6.75, -4.1640625, -1.046875],
            "values": [[0.017578125, -7.099121, -0.34570312], [7.531006, 1.5488568e+37, 2.2719727], [2.631836, 0.09399414, 6.411377]],
            "keys": [{"ease": [0.7890625, 0.7265625], "interp": "linear", "out": [1.942627, -4.963135, -5.998291]},
              {"tcb": [-0.54, 0.47, -1.02], "interp": "step", "in": [-4.022949, 0, 0]}, {}],
            "rotation": "squad", "hemisphere": "keep"}]}"#,
    );
    assert_none(&mismatches(&clip, &around(&[-6.75, -4.1640625, -1.046875])));
}

/// Where the reference and the runtime disagree at `times`, or where the
/// reference is not finite: each of these times is at a segment's end
/// (its `s` rounds to 1 in f32), where the value is the segment's key
/// whatever its tangents, so the answer must be finite there.
fn key_at_segment_end(clip: &tcb_core::SourceClip, times: &[f64]) -> Vec<String> {
    let n = clip.channel_count();
    let mut want = vec![0.0f32; n];
    let mut bad = mismatches(clip, times);
    for &t in times {
        clip.sample_into(t, &mut want, None);
        if want.iter().any(|x| !x.is_finite()) {
            bad.push(format!("reference at {t:e}: {want:?}"));
        }
    }
    bad
}

/// Tracks whose tangents overflow f32 (a bias of 8.1e270, a continuity of
/// -7.6e135 with a bias of -8.4e187, a tension of 1.6e80), one ulp before
/// a key, where `s` rounds to 1 and the value is the key: in a loose block
/// whose lanes are not all inside their keys (another track's keys end
/// before), directly and through `offset-repeat` from before the first
/// key, as hermite rotations in a group and in such a block, and played at
/// speed -f64::MAX. The `playback` fuzz target's run of 2026-12-05
/// (`fuzz/open/playback-nan-an-ulp-from-a-key-*`,
/// `playback-nan-at-speed-minus-max-*`): the runtime gave NaN (0 x inf)
/// where the reference gave the key.
#[test]
fn an_overflowing_tangent_one_ulp_before_a_key_gives_the_key() {
    let mut bad = Vec::new();
    // A vec2 beside a scalar whose keys start after its last.
    let beside = clip(
        r#"{"format": "tcb-clip/1", "defaults": {"tcb": [-4.741725518223423e-182, 0.07, 8.109918638818106e270], "post": "repeat"},
        "tracks": [{"name": "t0", "kind": "scalar", "times": [-0.125, -0.1171875, 3.875, 7.8671875], "values": [1.4405e-41, 0, -1.8198242, -1.8198242]},
          {"name": "t1", "kind": "vec2", "times": [-3.75, -0.2109375], "values": [[-1.8198242, -1.8198242], [9.334581e-15, 9.334581e-15]]}]}"#,
    );
    bad.extend(key_at_segment_end(&beside, &[ulps(-0.2109375, -1)]));
    // Alone, wrapped from before its first key by `offset-repeat`.
    let wrapped = clip(
        r#"{"format": "tcb-clip/1", "defaults": {"tangent_rule": "parabolic", "continuity_fade": false,
          "tcb": [-0.78, 0, -1.7366082074772295e168], "pre": "offset-repeat"},
        "tracks": [{"name": "t0", "kind": "scalar", "times": [-0.125, -0.124999999, 0.601562501, 1.734375001], "values": [1.0144043, 0, 5.231201, -6.211914]}]}"#,
    );
    bad.extend(key_at_segment_end(&wrapped, &[ulps(-0.125, -6)]));
    // A scalar beside a vec2 whose keys end before, also played at speed
    // -f64::MAX.
    let fast = clip(
        r#"{"format": "tcb-clip/1", "defaults": {"tcb": [-0.79, -7.634988870360329e135, -8.395468232477215e187]},
        "tracks": [{"name": "t0", "kind": "scalar", "times": [-7.5, -6.1015625, -3.125, -2.2265625, -0.78125, -0.4609375, 0.125],
            "values": [-2.1594238, 1.8127441, -5.255371, -6.211914, -6.211914, 1.1005859, -6.211914]},
          {"name": "t1", "kind": "vec2", "times": [-12.5, -12.499999999, -10.398437499, -9.109374999],
            "values": [[1.6987305, -3.8486328], [2.5273438, 5.4802246], [7.951172, 5.6835938], [-0.4284668, 2.5375977]], "pre": "linear"}]}"#,
    );
    let before = ulps(0.125, -1);
    bad.extend(key_at_segment_end(&fast, &[before]));
    let mut playing = Instance::new(Arc::new(Clip::compile(&fast)));
    playing
        .set_playback(tcb_runtime::Playback::Clip, -f64::MAX)
        .expect("a finite speed");
    let t = before / -f64::MAX;
    assert_eq!(t * -f64::MAX, before, "the clip time of {t:e}");
    let mut got = [0.0f32; 3];
    playing.sample(t).write_row(&mut got, None);
    if got[0] != -6.211914 {
        bad.push(format!("at speed -f64::MAX, {t:e}: {got:?}"));
    }
    // Hermite rotations: in a group (beside a scalar on the same keys) and
    // as a loose lane beside a rotation whose keys start after its last.
    for other in [
        r#"{"name": "s", "kind": "scalar", "times": [0, 1, 2], "values": [1, 2, 3]}"#,
        r#"{"name": "q", "kind": "quat", "times": [5, 6], "values": [[0, 0, 0, 1], [0, 1, 0, 0]]}"#,
    ] {
        let text = format!(
            r#"{{"format": "tcb-clip/1", "tracks": [{other},
              {{"name": "r", "kind": "quat", "rotation": "hermite", "times": [0, 1, 2],
               "values": [[0, 0, 0, 1], [0, 0.7071068, 0, 0.7071068], [1, 0, 0, 0]],
               "keys": [{{}}, {{"tcb": [1.6e80, 0, 0]}}, {{}}]}}]}}"#
        );
        let rotations = clip(&text);
        let times = [ulps(1.0, -1), ulps(2.0, -1), ulps(2.0, -64)];
        bad.extend(key_at_segment_end(&rotations, &times));
    }
    assert_none(&bad);
}
