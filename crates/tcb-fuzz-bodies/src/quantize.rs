//! The `quantize` target: a structured clip compiled with
//! [`CompileOptions::quantize`] against the same clip in f32.

use crate::edges::edge_times;
use crate::inputs::same;
use arbitrary::Unstructured;
use std::sync::Arc;
use tcb_core::TrackData;
use tcb_runtime::{CompileOptions, Instance};

/// A structured clip (as `runtime`'s) compiled with 16-bit keys and in
/// f32, played at edge times. Every track's stated bound
/// ([`tcb_runtime::Clip::quantization_error`], what `tcb info --quantize`
/// prints) is a finite number, and inside the track's keys the quantized
/// sample is within it of the f32 one (plus 2e-6 relative for f32
/// rounding; rotations up to sign) wherever the f32 one is finite;
/// quantized forward playback equals a seek bit for bit.
pub fn quantize(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(doc) = crate::inputs::arbitrary_doc(&mut u) else {
        return;
    };
    let Ok(clip) = doc.build() else {
        return;
    };
    let exact = u.ratio(1, 2u8).unwrap_or(false);
    let times = edge_times(&mut u, &clip.key_times(), 64);
    let base = CompileOptions::default().exact_velocities(exact);
    let plain = Arc::new(tcb_runtime::Clip::compile_with(&clip, &base));
    let small = Arc::new(tcb_runtime::Clip::compile_with(&clip, &base.quantize(true)));
    let ids: Vec<_> = small.layout().ids().collect();
    let bounds: Vec<f32> = ids
        .iter()
        .zip(clip.tracks())
        .map(|(&id, t)| {
            let b = small.quantization_error(id).expect("a track of the clip");
            assert!(
                b.is_finite() && b >= 0.0,
                "{}: stated quantization bound {b}",
                t.name
            );
            b
        })
        .collect();
    let n = clip.channel_count();
    let (mut got, mut want) = (vec![0.0f32; n], vec![0.0f32; n]);
    let mut playing = Instance::new(small.clone()).with_velocities();
    let mut f32_playing = Instance::new(plain.clone());
    for &t in &times {
        let pose = playing.sample(t).clone();
        let mut fresh = Instance::new(small.clone()).with_velocities();
        assert!(
            same(pose.as_slice(), fresh.sample(t).as_slice()),
            "quantized: forward playback differs from a seek at {t}"
        );
        pose.write_row(&mut got, None);
        f32_playing.sample(t).write_row(&mut want, None);
        let mut at = 0;
        for (track, &bound) in clip.tracks().iter().zip(&bounds) {
            let dim = track.data.kind().dim();
            let r = at..at + dim;
            at += dim;
            let times = track.data.times();
            let (lo, hi) = (times[0], times[times.len() - 1]);
            if !(lo..=hi).contains(&t) {
                continue;
            }
            let (g, w) = (&got[r.clone()], &want[r]);
            if w.iter().any(|x| !x.is_finite()) {
                continue;
            }
            let sign = if matches!(track.data, TrackData::Quat(_))
                && g.iter().zip(w).map(|(x, y)| x * y).sum::<f32>() < 0.0
            {
                -1.0
            } else {
                1.0
            };
            for c in 0..dim {
                let e = (g[c] - sign * w[c]).abs();
                assert!(
                    e <= bound + 2e-6 * w[c].abs().max(1.0),
                    "{} at {t} component {c}: quantized {g:?}, f32 {w:?}, off by {e}, \
                     stated bound {bound}",
                    track.name
                );
            }
        }
    }
}
