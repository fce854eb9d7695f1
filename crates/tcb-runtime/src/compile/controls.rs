//! Step 1's pieces: each track's grid and its vector channels' controls.

use crate::grid::{KeyTimes, TimeGrid};
use tcb_core::ease::SegmentEase;
use tcb_core::{Extrapolation, Interp, Track, TrackData, Value};

/// Channel controls over the stored segments `0..=n`.
pub(crate) type Controls = Vec<[f32; 4]>;

pub(crate) fn vector_controls<V: Value>(t: &Track<V>) -> Vec<Controls> {
    let n = t.times().len();
    let segs = t.segments();
    let last = &segs[n - 2];
    let d = t.times()[n - 1] - t.times()[n - 2];
    let end_rate = (last.ease.apply(1.0).1 / d) as f32;
    let (first_v, last_v) = (t.values()[0].to_array(), t.values()[n - 1].to_array());
    let (to, ti) = (t.start_tangent().to_array(), t.end_tangent().to_array());
    (0..V::DIM)
        .map(|c| {
            let mut ctl = Vec::with_capacity(n + 1);
            ctl.push([first_v[c], first_v[c], to[c], 0.0]);
            for s in segs {
                ctl.push([
                    s.p0.to_array()[c],
                    s.p1.to_array()[c],
                    s.m0.to_array()[c],
                    s.m1.to_array()[c],
                ]);
            }
            let arrive = last.m1.to_array()[c] * end_rate;
            ctl.push([last_v[c], last_v[c], ti[c], arrive]);
            ctl
        })
        .collect()
}

pub(crate) fn grid_of(data: &TrackData) -> TimeGrid {
    fn segs<V: Value>(t: &Track<V>) -> (Vec<SegmentEase>, Vec<bool>) {
        let s = t.segments();
        (
            s.iter().map(|s| s.ease).collect(),
            s.iter().map(|s| s.interp == Interp::Step).collect(),
        )
    }
    let ((eases, steps), settings) = match data {
        TrackData::Scalar(t) => (segs(t), *t.settings()),
        TrackData::Vec2(t) => (segs(t), *t.settings()),
        TrackData::Vec3(t) => (segs(t), *t.settings()),
        TrackData::Vec4(t) => (segs(t), *t.settings()),
        TrackData::Quat(t) => {
            let n = t.times().len();
            let steps = t.interps()[..n - 1]
                .iter()
                .map(|i| *i == Interp::Step)
                .collect();
            ((t.eases().to_vec(), steps), *t.settings())
        }
    };
    TimeGrid {
        times: KeyTimes::Listed(data.times().to_vec()),
        eases,
        steps,
        pre: settings.pre,
        post: settings.post,
    }
    .compact()
}

pub(crate) type GridKey = (
    Vec<u64>,
    Vec<(u64, u64)>,
    Vec<bool>,
    Extrapolation,
    Extrapolation,
);

pub(crate) fn grid_key(g: &TimeGrid) -> GridKey {
    (
        g.times.listed().iter().map(|t| t.to_bits()).collect(),
        g.eases
            .iter()
            .map(|e| (e.from().to_bits(), e.to().to_bits()))
            .collect(),
        g.steps.clone(),
        g.pre,
        g.post,
    )
}
