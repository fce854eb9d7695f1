//! The peer: the `splines` crate (Catmull-Rom; it has no TCB), one
//! `Spline<f32, f32>` per channel on the same keys.
//!
//! On even spacing with t = c = b = 0 Catmull-Rom and TCB are the same
//! curve inside the keys; [`SplinesPeer::agreement`] checks that before
//! anything is timed. Catmull-Rom needs a key on each side of a segment, so
//! each spline gets one extra key reflected past each end (only the timing
//! uses the end segments).

// Loops over component indices are the plain code these stand for.
#![allow(clippy::needless_range_loop)]

use splines::{Interpolation, Key, Spline};
use tcb_core::{TrackData, TrackKind};

/// Per-channel splines of a clip.
pub struct SplinesPeer {
    splines: Vec<Spline<f32, f32>>,
    /// Start channel of each rotation (normalized after sampling).
    quats: Vec<usize>,
    /// Inner time range, where both define the curve from the same keys.
    inner: (f64, f64),
}

impl SplinesPeer {
    /// Splines for every channel of `clip` (any track kind; rotations as
    /// four components, normalized).
    pub fn new(clip: &tcb_core::SourceClip) -> Self {
        let mut splines = Vec::new();
        let mut quats = Vec::new();
        let mut inner = (f64::NEG_INFINITY, f64::INFINITY);
        for t in clip.tracks() {
            let (times, values): (Vec<f64>, Vec<[f32; 4]>) = match &t.data {
                TrackData::Scalar(x) => (
                    x.times().to_vec(),
                    x.values().iter().map(|v| [*v, 0.0, 0.0, 0.0]).collect(),
                ),
                TrackData::Vec2(x) => (
                    x.times().to_vec(),
                    x.values().iter().map(|v| [v.x, v.y, 0.0, 0.0]).collect(),
                ),
                TrackData::Vec3(x) => (
                    x.times().to_vec(),
                    x.values().iter().map(|v| [v.x, v.y, v.z, 0.0]).collect(),
                ),
                TrackData::Vec4(x) => (
                    x.times().to_vec(),
                    x.values().iter().map(|v| v.to_array()).collect(),
                ),
                TrackData::Quat(r) => (
                    r.times().to_vec(),
                    r.values().iter().map(|q| q.to_array()).collect(),
                ),
            };
            let n = times.len();
            if n >= 4 {
                inner.0 = inner.0.max(times[1]);
                inner.1 = inner.1.min(times[n - 2]);
            }
            if t.data.kind() == TrackKind::Quat {
                quats.push(splines.len());
            }
            for c in 0..t.data.kind().dim() {
                let mut keys = Vec::with_capacity(n + 2);
                let (d0, d1) = (times[1] - times[0], times[n - 1] - times[n - 2]);
                keys.push(Key::new(
                    (times[0] - d0) as f32,
                    2.0 * values[0][c] - values[1][c],
                    Interpolation::CatmullRom,
                ));
                for k in 0..n {
                    keys.push(Key::new(
                        times[k] as f32,
                        values[k][c],
                        Interpolation::CatmullRom,
                    ));
                }
                keys.push(Key::new(
                    (times[n - 1] + d1) as f32,
                    2.0 * values[n - 1][c] - values[n - 2][c],
                    Interpolation::CatmullRom,
                ));
                keys.push(Key::new(
                    (times[n - 1] + 2.0 * d1) as f32,
                    2.0 * values[n - 1][c] - values[n - 2][c],
                    Interpolation::CatmullRom,
                ));
                splines.push(Spline::from_vec(keys));
            }
        }
        SplinesPeer {
            splines,
            quats,
            inner,
        }
    }

    /// Values per sample.
    pub fn channel_count(&self) -> usize {
        self.splines.len()
    }

    /// Sample every channel at `time` (a time outside the splines gives 0).
    #[inline]
    pub fn sample(&self, time: f64, out: &mut [f32]) {
        let t = time as f32;
        for (o, s) in out.iter_mut().zip(&self.splines) {
            *o = s.sample(t).unwrap_or(0.0);
        }
        for &q in &self.quats {
            let v = &mut out[q..q + 4];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]).sqrt();
            v.iter_mut().for_each(|x| *x /= l);
        }
    }

    /// Largest difference from `clip` (the reference) over `samples`
    /// times inside the inner keys, relative to max(1, |value|); rotations
    /// compared up to sign.
    pub fn agreement(&self, clip: &tcb_core::SourceClip, samples: usize) -> f64 {
        let (a, b) = self.inner;
        let mut want = vec![0.0f32; clip.channel_count()];
        let mut got = vec![0.0f32; self.channel_count()];
        let mut worst = 0.0f64;
        for i in 0..samples {
            let t = a + (b - a) * i as f64 / samples.max(2) as f64;
            clip.sample_into(t, &mut want, None);
            self.sample(t, &mut got);
            for q in &self.quats {
                let dot: f32 = (0..4).map(|c| want[q + c] * got[q + c]).sum();
                if dot < 0.0 {
                    got[*q..q + 4].iter_mut().for_each(|x| *x = -*x);
                }
            }
            for (w, g) in want.iter().zip(&got) {
                worst = worst.max(f64::from((w - g).abs() / w.abs().max(1.0)));
            }
        }
        worst
    }
}
