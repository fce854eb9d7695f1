//! What a compiled clip costs to play: an estimate of the runtime's
//! instructions per frame, for [`crate::reduce()`] to keep a reduced clip
//! no slower than its source (`ReduceOptions::speed`).
//!
//! The runtime samples every channel every frame, so a clip's cost is set
//! by its layout, not by its keys: each group of tracks sharing a key grid
//! pays one cursor and one basis per frame and then its blocks of 8 lanes;
//! tracks on key times of their own (loose lanes) pay a time mapping and a
//! basis per lane, 8 lanes to a block, and a load each time playback
//! crosses one of their keys. Fewer keys make a clip smaller, but a track
//! taken off a shared grid moves its lane from a group block to a loose
//! one, which costs more than twice as much.
//!
//! ```text
//! cost = BASE
//!      + per group:  GROUP + VECTOR_BLOCK * ceil(v / 8) + ROTATION_BLOCK * ceil(r / 8)
//!      + loose vectors (if any):   LOOSE + LOOSE_VECTOR_BLOCK * blocks
//!      + loose rotations (if any): LOOSE + LOOSE_ROTATION_BLOCK * blocks
//!      + CROSSING * (keys of loose lanes crossed per frame, at 60 fps)
//! ```
//!
//! The constants are instructions per frame counted by `tcb-bench --icount`
//! (callgrind, the default x86-64 build) on variants of the CMU clip: the
//! dense clip (1084 per frame), it without 7 rotations (one rotation block
//! fewer: 150) or without its translation (61), with 8 tracks moved to a
//! second grid (a group: 318 and its block), with 6 or 10 rotations and 1
//! translation on key times of their own (loose blocks: 350 and 260, and
//! about 140 per key crossed). The model gives the counted reduced clip of
//! 2026-12 (1 group and 7 loose rotations) 1536 per frame; it counted 1514.
//! It is a guide for choosing between layouts, not a measurement: `tcb
//! reduce` also times both clips.

use tcb_core::SourceClip;

/// Per frame, whatever the clip: the instance's own work.
const BASE: f64 = 105.0;
/// Per group: its cursor, basis rows and key pair.
const GROUP: f64 = 318.0;
/// Per block of 8 vector channels in a group.
const VECTOR_BLOCK: f64 = 61.0;
/// Per block of 8 rotations in a group (4 planes, normalized).
const ROTATION_BLOCK: f64 = 150.0;
/// Per kind of loose lanes present (vectors, rotations).
const LOOSE: f64 = 40.0;
/// Per block of 8 loose vector lanes.
const LOOSE_VECTOR_BLOCK: f64 = 260.0;
/// Per block of 8 loose rotation lanes.
const LOOSE_ROTATION_BLOCK: f64 = 350.0;
/// Per key of a loose lane that playback crosses.
const CROSSING: f64 = 140.0;
/// The frame rate the cost is given at (the benchmarks' own).
const FPS: f64 = 60.0;

/// The estimated runtime instructions per frame of `compiled` (the runtime
/// clip compiled from `source`), played forward at 60 fps over its keys.
///
/// ```
/// let doc = tcb_io::ClipDoc::parse(r#"{"format": "tcb-clip/1", "tracks": [
///   {"name": "a", "kind": "scalar", "times": [0, 1, 2], "values": [0, 1, 0]},
///   {"name": "b", "kind": "scalar", "times": [0, 0.5, 2], "values": [0, 1, 0]}]}"#)?;
/// let source = doc.build()?;
/// let compiled = tcb_runtime::Clip::compile(&source);
/// // Two tracks on key times of their own: one block of loose lanes.
/// assert!(tcb_fit::cost::frame_cost(&compiled, &source) > 400.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn frame_cost(compiled: &tcb_runtime::Clip, source: &SourceClip) -> f64 {
    let stats = compiled.stats();
    let blocks = |n: usize| n.div_ceil(8) as f64;
    let groups: f64 = stats
        .grids
        .iter()
        .map(|g| {
            GROUP + VECTOR_BLOCK * blocks(g.vector_channels) + ROTATION_BLOCK * blocks(g.rotations)
        })
        .sum();
    let loose = |tracks: usize, per_block: f64| {
        if tracks == 0 {
            0.0
        } else {
            LOOSE + per_block * blocks(tracks)
        }
    };
    let frames = source
        .time_range()
        .map_or(1.0, |(a, b)| ((b - a) * FPS).floor() + 1.0);
    BASE + groups
        + loose(stats.loose_vector_tracks, LOOSE_VECTOR_BLOCK)
        + loose(stats.loose_rotation_tracks, LOOSE_ROTATION_BLOCK)
        + CROSSING * stats.loose_keys as f64 / frames
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clip(tracks: &[String]) -> SourceClip {
        let text = format!(
            r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
            tracks.join(",")
        );
        tcb_io::ClipDoc::parse(&text).unwrap().build().unwrap()
    }

    fn track(name: &str, kind: &str, times: &str, value: &str, keys: usize) -> String {
        let values = vec![value; keys].join(",");
        format!(
            r#"{{"name": "{name}", "kind": "{kind}", "times": [{times}], "values": [{values}]}}"#
        )
    }

    /// The compiler's count of loose lanes and their keys, which the cost
    /// model reads.
    #[test]
    fn loose_tracks_are_those_the_compiler_leaves_loose() {
        let cases: Vec<(Vec<String>, usize, usize)> = vec![
            // (tracks, loose tracks, their keys)
            // 9 scalars on one grid: a group.
            (
                (0..9)
                    .map(|i| track(&format!("s{i}"), "scalar", "0, 1, 2", "0", 3))
                    .collect(),
                0,
                0,
            ),
            // 7 scalars on one grid, 2 on another: all loose.
            (
                (0..9)
                    .map(|i| {
                        let times = if i < 7 { "0, 1, 2" } else { "0, 2" };
                        track(
                            &format!("s{i}"),
                            "scalar",
                            times,
                            "0",
                            3 - usize::from(i >= 7),
                        )
                    })
                    .collect(),
                9,
                7 * 3 + 2 * 2,
            ),
            // A vector and a rotation on one grid: a group.
            (
                vec![
                    track("t", "vec3", "0, 1", "[0, 0, 0]", 2),
                    track("r", "quat", "0, 1", "[0, 0, 0, 1]", 2),
                ],
                0,
                0,
            ),
            // 8 rotations on one grid, a ninth on its own: 1 loose.
            (
                (0..9)
                    .map(|i| {
                        let times = if i < 8 { "0, 1, 2" } else { "0, 1.5, 2" };
                        track(&format!("r{i}"), "quat", times, "[0, 0, 0, 1]", 3)
                    })
                    .collect(),
                1,
                3,
            ),
        ];
        for (tracks, loose, keys) in cases {
            let source = clip(&tracks);
            let compiled = tcb_runtime::Clip::compile(&source);
            assert_eq!(compiled.loose_track_count(), loose, "{tracks:?}");
            assert_eq!(compiled.stats().loose_keys, keys, "{tracks:?}");
        }
    }

    /// The model on the dense CMU clip: one group of 1 vector and 4
    /// rotation blocks, 1084 instructions a frame, as counted.
    #[test]
    fn the_dense_cmu_clip_costs_what_callgrind_counted() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
        let options = tcb_io::ImportOptions::default().rotation(tcb_core::RotationMode::Hermite);
        let source = tcb_io::load_with(path, &options).unwrap().clip;
        let compiled = tcb_runtime::Clip::compile(&source);
        assert_eq!(frame_cost(&compiled, &source), 1084.0);
    }
}
