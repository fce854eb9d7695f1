//! With `Speed::NeverSlower`, a reduced clip plays no slower than its source
//! (issue 33, item 3): the reducer takes tracks off a shared key grid only
//! where the runtime's layout does not get dearer by `tcb_fit::cost`'s
//! estimate.

use tcb_core::RotationMode;
use tcb_fit::{ReduceOptions, cost};

const BVH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");

/// Track `name` of scalar keys `(time, value)`.
fn scalar(name: &str, keys: impl Iterator<Item = (f64, f64)>) -> String {
    let (times, values): (Vec<String>, Vec<String>) =
        keys.map(|(t, v)| (format!("{t}"), format!("{v}"))).unzip();
    format!(
        r#"{{"name": "{name}", "kind": "scalar", "times": [{}], "values": [{}]}}"#,
        times.join(","),
        values.join(",")
    )
}

fn reduce(doc: &tcb_io::ClipDoc, clip: &tcb_core::SourceClip) -> tcb_fit::Reduced {
    let input = tcb_fit::reduce::Input {
        doc,
        clip,
        skeleton: None,
    };
    let options = ReduceOptions::default().speed(tcb_fit::Speed::NeverSlower);
    tcb_fit::reduce(input, &options, &|_, _| {}).unwrap()
}

fn cost_of(clip: &tcb_core::SourceClip) -> f64 {
    cost::frame_cost(&tcb_runtime::Clip::compile(clip), clip)
}

/// Eight tracks of noise (nothing to reduce) and one sine on one grid of
/// 241 keys: the sine reduces to a few keys on times of its own, a loose
/// lane that costs more than its lane in the group's second block.
#[test]
fn a_track_that_would_leave_a_shared_grid_for_a_dearer_lane_stays_on_it() {
    let mut seed = 12345u64;
    let mut noise = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 40) as f64 / (1u64 << 24) as f64
    };
    let times: Vec<f64> = (0..=240).map(|i| f64::from(i) / 120.0).collect();
    let mut tracks: Vec<String> = (0..8)
        .map(|c| scalar(&format!("n{c}"), times.iter().map(|&t| (t, noise()))))
        .collect();
    tracks.push(scalar("sine", times.iter().map(|&t| (t, (3.0 * t).sin()))));
    let text = format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
        tracks.join(",")
    );
    let doc = tcb_io::ClipDoc::parse(&text).unwrap();
    let clip = doc.build().unwrap();
    let reduced = reduce(&doc, &clip);
    let compiled = tcb_runtime::Clip::compile(&reduced.clip);
    assert_eq!(
        compiled.loose_track_count(),
        0,
        "{}",
        reduced.summary_line()
    );
    assert!(cost_of(&reduced.clip) <= cost_of(&clip));
    assert!(reduced.worst.error <= 1e-4);
}

/// Tracks each on key times of its own play as loose lanes in the source
/// too: there the reduction keeps its fits, which cross fewer keys.
#[test]
fn tracks_already_on_key_times_of_their_own_are_reduced() {
    let tracks: Vec<String> = (0..3)
        .map(|c| {
            let offset = 0.001 * f64::from(c);
            let keys = (0..=240).map(move |i| {
                let t = f64::from(i) / 120.0 + offset;
                (t, (2.0 * t + f64::from(c)).sin())
            });
            scalar(&format!("s{c}"), keys)
        })
        .collect();
    let text = format!(
        r#"{{"format": "tcb-clip/1", "tracks": [{}]}}"#,
        tracks.join(",")
    );
    let doc = tcb_io::ClipDoc::parse(&text).unwrap();
    let clip = doc.build().unwrap();
    let reduced = reduce(&doc, &clip);
    assert!(reduced.kept.is_empty(), "{:?}", reduced.kept);
    assert!(reduced.after.keys * 4 < reduced.before.keys);
    assert!(cost_of(&reduced.clip) < cost_of(&clip));
}

/// The benchmark's `character-reduced`: the CMU clip (hermite) at the
/// contract's defaults. Its four constant rotations become 2 keys each
/// (docs/reduce.md), on key times of their own; compiled, they take the
/// grid's free lanes (issue 33, item 3). The fits of Head and the two
/// finger tracks, on key times of their own, would be a block of loose
/// lanes: the default (`Speed::Balanced`) puts them back, and the clip
/// plays at its source's estimated cost in its source's bytes.
#[test]
fn reduced_cmu_keeps_its_constant_tracks_at_two_keys_and_plays_no_slower() {
    let options = tcb_io::ImportOptions::default().rotation(RotationMode::Hermite);
    let loaded = tcb_io::load_with(BVH, &options).unwrap();
    let input = tcb_fit::reduce::Input {
        doc: &loaded.doc,
        clip: &loaded.clip,
        skeleton: loaded.skeleton.as_ref(),
    };
    let reduced = tcb_fit::reduce(input, &ReduceOptions::default(), &|_, _| {}).unwrap();
    let line = reduced.summary_line();
    for name in ["LHipJoint", "RHipJoint", "LeftShoulder", "RightShoulder"] {
        let name = format!("{name}.rotation");
        let t = reduced.doc.tracks.iter().find(|t| t.name == name).unwrap();
        assert_eq!(t.times.len(), 2, "{name}");
    }
    let compiled = tcb_runtime::Clip::compile(&reduced.clip);
    assert_eq!(compiled.loose_track_count(), 0, "{line}");
    assert!(reduced.after.bytes <= reduced.before.bytes, "{line}");
    assert!(reduced.after_cost <= reduced.before_cost, "{line}");
    assert_eq!(reduced.before_cost, cost_of(&loaded.clip));
    assert_eq!(reduced.after_cost, cost_of(&reduced.clip));
    // The fewest bytes were declined, and said.
    let (smallest, cost) = reduced.declined.as_ref().expect("declined");
    assert!(smallest.bytes < reduced.after.bytes && *cost > reduced.before_cost);
    assert!(reduced.worst.ratio <= 1.0);
}
