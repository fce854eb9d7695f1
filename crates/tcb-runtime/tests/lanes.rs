//! Issue 29, class 3: lanes of a block are independent whatever their
//! neighbours hold. Beside tracks whose `offset-repeat` climbs to inf, a
//! track that repeats without an offset (last key = first), holds or
//! extrapolates a line plays the reference's value wherever that is
//! finite, in a group (one basis for 9 tracks) and on loose lanes.

use std::sync::Arc;
use tcb_runtime::{Clip, Instance};

fn check(shared_times: bool) {
    // Track 0 repeats without an offset (first = last); the others climb.
    let tracks: Vec<String> = (0..9)
        .map(|i| {
            let times = if shared_times {
                "[0, 0.5, 1]".to_string()
            } else {
                format!("[0, {}, 1]", 0.3 + 0.05 * i as f64)
            };
            // A group shares its modes; loose lanes mix them.
            let (last, mode) = match i {
                0 => ("1".to_string(), "offset-repeat"),
                1 if !shared_times => ("5".to_string(), "constant"),
                2 if !shared_times => ("7".to_string(), "linear"),
                _ => (format!("{i}e37"), "offset-repeat"),
            };
            format!(
                r#"{{"name": "t{i}", "kind": "scalar", "times": {times}, "values": [1, 3, {last}], "post": "{mode}", "pre": "{mode}"}}"#
            )
        })
        .collect();
    let text = format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
        tracks.join(",")
    );
    let source = tcb_io::ClipDoc::parse(&text).unwrap().build().unwrap();
    let clip = Arc::new(Clip::compile(&source));
    assert_eq!(clip.loose_track_count() == 0, shared_times);
    let mut inst = Instance::new(clip.clone());
    let mut row = vec![0.0f32; source.channel_count()];
    let mut out = vec![0.0f32; source.channel_count()];
    for t in [
        2.5,
        1e3 + 0.25,
        1e30,
        1e300,
        -1e300,
        1e38 + 0.25,
        f64::MAX / 3.0,
    ] {
        source.sample_into(t, &mut row, None);
        inst.sample_to(t, &mut out).unwrap();
        for (i, (want, got)) in row.iter().zip(&out).enumerate() {
            // Where the reference is finite, the runtime gives it.
            if want.is_finite() {
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "t{i} at {t}: {got}, reference {want}"
                );
            }
        }
    }
}

#[test]
fn a_group_lane_without_offset_is_not_its_neighbours_nan() {
    check(true);
}

#[test]
fn a_loose_lane_without_offset_is_not_its_neighbours_nan() {
    check(false);
}
