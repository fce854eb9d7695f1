//! The scalar baseline and the splines peer compute what the reference does.

use tcb_bench::Baseline;
use tcb_bench::peer::SplinesPeer;
use tcb_core::{RotationMode, TrackData};

fn clips() -> Vec<(String, tcb_core::SourceClip)> {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let mut out = Vec::new();
    for dir in ["examples/clips", "tools/check/clips"] {
        let mut paths: Vec<_> = std::fs::read_dir(format!("{root}/{dir}"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        paths.sort();
        for p in paths {
            out.push((p.display().to_string(), tcb_io::load_clip(&p).unwrap()));
        }
    }
    for mode in [RotationMode::Squad, RotationMode::Hermite] {
        let options = tcb_io::ImportOptions::default().rotation(mode);
        let path = format!("{root}/data/cmu-01_01.bvh");
        out.push((
            format!("cmu {mode:?}"),
            tcb_io::load_with(path, &options).unwrap().clip,
        ));
    }
    out
}

#[test]
fn baseline_equals_the_reference() {
    for (name, clip) in clips() {
        let baseline = Baseline::new(&clip);
        let (t0, t1) = clip.time_range().unwrap();
        let mut want = vec![0.0f32; clip.channel_count()];
        let mut got = vec![0.0f32; clip.channel_count()];
        let mut worst = 0.0f32;
        let n = 997;
        for i in 0..=n {
            let t = t0 - 1.3 + (t1 - t0 + 2.6) * i as f64 / n as f64;
            clip.sample_into(t, &mut want, None);
            baseline.sample(t, &mut got);
            let mut at = 0;
            for track in clip.tracks() {
                let dim = track.data.kind().dim();
                let (w, g) = (&want[at..at + dim], &got[at..at + dim]);
                let d = w
                    .iter()
                    .zip(g)
                    .map(|(a, b)| (a - b).abs() / a.abs().max(1.0))
                    .fold(0.0, f32::max);
                let d = if matches!(track.data, TrackData::Quat(_)) {
                    d.min(
                        w.iter()
                            .zip(g)
                            .map(|(a, b)| (a + b).abs())
                            .fold(0.0, f32::max),
                    )
                } else {
                    d
                };
                worst = worst.max(d);
                at += dim;
            }
        }
        assert!(worst <= 1e-5, "{name}: baseline differs by {worst}");
    }
}

#[test]
fn splines_agree_on_even_keys_with_tcb_zero() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let options = tcb_io::ImportOptions::default().rotation(RotationMode::Hermite);
    let clip = tcb_io::load_with(format!("{root}/data/cmu-01_01.bvh"), &options)
        .unwrap()
        .clip;
    let peer = SplinesPeer::new(&clip);
    let worst = peer.agreement(&clip, 2000);
    assert!(worst < 1e-4, "splines vs tcb: {worst}");
    // And it can fail: a non-zero tension is a different curve.
    let bounce = tcb_io::load_clip(format!("{root}/tools/check/clips/rules.json")).unwrap();
    assert!(SplinesPeer::new(&bounce).agreement(&bounce, 200) > 1e-3);
}
