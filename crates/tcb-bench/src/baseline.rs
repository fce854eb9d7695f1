//! The scalar baseline: what a careful, straightforward implementation does.
//!
//! Each track is an array of structs, one per segment, with the tangents
//! precomputed at load (so the comparison is about layout and evaluation,
//! not about recomputing TCB tangents). Every sample, every track does its
//! own extrapolation and binary search, and every channel recomputes the
//! eased parameter and the Hermite basis. Rotations use f32 `glam`
//! quaternions; squad with its own (non-flipping) slerp.

// Loops over component indices are the plain code these stand for.
#![allow(clippy::needless_range_loop)]

use glam::{Quat, Vec4};
use tcb_core::ease::SegmentEase;
use tcb_core::simd::basis::{hermite, hermite_basis};
use tcb_core::simd::extrapolate::{Mapped, map_time};
use tcb_core::{Extrapolation, Interp, Track, TrackData, Value};

/// One segment of a vector track (or of a hermite rotation's components).
#[derive(Clone, Copy, Debug)]
struct Segment {
    t0: f64,
    t1: f64,
    p0: [f32; 4],
    p1: [f32; 4],
    m0: [f32; 4],
    m1: [f32; 4],
    ease: SegmentEase,
    interp: Interp,
}

/// One segment of a squad rotation.
#[derive(Clone, Copy, Debug)]
struct QuatSegment {
    t0: f64,
    t1: f64,
    q0: Quat,
    q1: Quat,
    a: Quat,
    b: Quat,
    ease: SegmentEase,
    interp: Interp,
}

#[derive(Clone, Debug)]
enum Shape {
    /// Vector track of `dim` components; `hermite` rotations are 4
    /// components, normalized.
    Curve {
        dim: usize,
        normalize: bool,
        segments: Vec<Segment>,
    },
    Squad(Vec<QuatSegment>),
}

/// One track: its segments and what to do outside them.
#[derive(Clone, Debug)]
struct BaselineTrack {
    shape: Shape,
    pre: Extrapolation,
    post: Extrapolation,
    first: [f32; 4],
    last: [f32; 4],
    start_tangent: [f32; 4],
    end_tangent: [f32; 4],
    is_rotation: bool,
}

/// A clip as the baseline stores it.
#[derive(Clone, Debug)]
pub struct Baseline {
    tracks: Vec<BaselineTrack>,
    channels: usize,
}

fn pad<V: Value>(v: V) -> [f32; 4] {
    let mut out = [0.0; 4];
    out[..V::DIM].copy_from_slice(&v.to_array()[..V::DIM]);
    out
}

fn curve<V: Value>(t: &Track<V>, normalize: bool) -> BaselineTrack {
    let times = t.times();
    let segments = t
        .segments()
        .iter()
        .enumerate()
        .map(|(k, s)| Segment {
            t0: times[k],
            t1: times[k + 1],
            p0: pad(s.p0),
            p1: pad(s.p1),
            m0: pad(s.m0),
            m1: pad(s.m1),
            ease: s.ease,
            interp: s.interp,
        })
        .collect();
    let n = t.values().len();
    BaselineTrack {
        shape: Shape::Curve {
            dim: V::DIM,
            normalize,
            segments,
        },
        pre: t.settings().pre,
        post: t.settings().post,
        first: pad(t.values()[0]),
        last: pad(t.values()[n - 1]),
        start_tangent: pad(t.start_tangent()),
        end_tangent: pad(t.end_tangent()),
        is_rotation: normalize,
    }
}

impl Baseline {
    /// Build from a validated clip (tangents and inner quaternions come from
    /// tcb-core, computed once).
    pub fn new(clip: &tcb_core::SourceClip) -> Self {
        let tracks = clip
            .tracks()
            .iter()
            .map(|t| match &t.data {
                TrackData::Scalar(t) => curve(t, false),
                TrackData::Vec2(t) => curve(t, false),
                TrackData::Vec3(t) => curve(t, false),
                TrackData::Vec4(t) => curve(t, false),
                TrackData::Quat(r) => {
                    let n = r.values().len();
                    let (pre, post) = (r.settings().pre, r.settings().post);
                    let first = r.values()[0].to_array();
                    let last = r.values()[n - 1].to_array();
                    match (r.squad_segments(), r.hermite_track()) {
                        (Some(segs), _) => BaselineTrack {
                            shape: Shape::Squad(
                                segs.iter()
                                    .enumerate()
                                    .map(|(k, s)| QuatSegment {
                                        t0: r.times()[k],
                                        t1: r.times()[k + 1],
                                        q0: s.q0.as_quat(),
                                        q1: s.q1.as_quat(),
                                        a: s.a.as_quat(),
                                        b: s.b.as_quat(),
                                        ease: s.ease,
                                        interp: s.interp,
                                    })
                                    .collect(),
                            ),
                            pre,
                            post,
                            first,
                            last,
                            start_tangent: [0.0; 4],
                            end_tangent: [0.0; 4],
                            is_rotation: true,
                        },
                        (None, Some(h)) => curve::<Vec4>(h, true),
                        (None, None) => unreachable!("a rotation is squad or hermite"),
                    }
                }
            })
            .collect();
        Baseline {
            tracks,
            channels: clip.channel_count(),
        }
    }

    /// Values per sample.
    pub fn channel_count(&self) -> usize {
        self.channels
    }

    /// Sample every track at `time` into `out` (the clip's column order).
    pub fn sample(&self, time: f64, out: &mut [f32]) {
        let mut at = 0;
        for track in &self.tracks {
            at += track.sample(time, &mut out[at..]);
        }
    }
}

impl BaselineTrack {
    fn range(&self) -> (f64, f64) {
        match &self.shape {
            Shape::Curve { segments, .. } => (segments[0].t0, segments[segments.len() - 1].t1),
            Shape::Squad(s) => (s[0].t0, s[s.len() - 1].t1),
        }
    }

    /// Write this track's values; returns how many. Kept whole: it is the
    /// timed scalar baseline, and every `x baseline` ratio is its time.
    fn sample(&self, time: f64, out: &mut [f32]) -> usize {
        let dim = match &self.shape {
            Shape::Curve { dim, .. } => *dim,
            Shape::Squad(_) => 4,
        };
        let (t0, tn) = self.range();
        match map_time(time, t0, tn, self.pre, self.post) {
            Mapped::Inside { time, cycles, .. } => {
                match &self.shape {
                    // The last key itself.
                    _ if time >= tn => out[..dim].copy_from_slice(&self.last[..dim]),
                    Shape::Curve {
                        dim,
                        normalize,
                        segments,
                    } => {
                        let k = segments
                            .partition_point(|s| s.t1 <= time)
                            .min(segments.len() - 1);
                        let s = &segments[k];
                        if *normalize && s.interp == Interp::Linear {
                            let u = local(s.t0, s.t1, &s.ease, time);
                            let q = slerp(Quat::from_array(s.p0), Quat::from_array(s.p1), u);
                            out[..4].copy_from_slice(&q.to_array());
                        } else {
                            for c in 0..*dim {
                                // The basis, recomputed for every channel.
                                let u = local(s.t0, s.t1, &s.ease, time);
                                out[c] = if s.interp == Interp::Step {
                                    s.p0[c]
                                } else {
                                    hermite(&hermite_basis(u), s.p0[c], s.p1[c], s.m0[c], s.m1[c])
                                };
                            }
                            if *normalize {
                                let q = Quat::from_slice(out).normalize();
                                out[..4].copy_from_slice(&q.to_array());
                            }
                        }
                        if cycles != 0.0 {
                            for c in 0..*dim {
                                out[c] += (self.last[c] - self.first[c]) * cycles as f32;
                            }
                        }
                    }
                    Shape::Squad(segments) => {
                        let k = segments
                            .partition_point(|s| s.t1 <= time)
                            .min(segments.len() - 1);
                        let s = &segments[k];
                        let u = local(s.t0, s.t1, &s.ease, time);
                        let q = match s.interp {
                            Interp::Step => s.q0,
                            Interp::Linear => slerp(s.q0, s.q1, u),
                            _ => slerp(
                                slerp(s.q0, s.q1, u),
                                slerp(s.a, s.b, u),
                                2.0 * u * (1.0 - u),
                            )
                            .normalize(),
                        };
                        out[..4].copy_from_slice(&q.to_array());
                    }
                }
            }
            Mapped::Hold { last } => {
                out[..dim].copy_from_slice(&(if last { self.last } else { self.first })[..dim]);
            }
            Mapped::Reset => {
                out[..dim].fill(0.0);
                if self.is_rotation {
                    out[3] = 1.0;
                }
            }
            Mapped::Line { last, dt } => {
                let (p, m) = if last {
                    (self.last, self.end_tangent)
                } else {
                    (self.first, self.start_tangent)
                };
                for c in 0..dim {
                    out[c] = p[c] + m[c] * dt as f32;
                }
            }
        }
        dim
    }
}

/// The eased local parameter of `time` in `[t0, t1]`, as f32.
#[inline]
fn local(t0: f64, t1: f64, ease: &SegmentEase, time: f64) -> f32 {
    let u = ((time - t0) / (t1 - t0)).clamp(0.0, 1.0);
    ease.apply(u).0 as f32
}

/// Slerp without a hemisphere flip (the spec's plain slerp).
#[inline]
fn slerp(a: Quat, b: Quat, t: f32) -> Quat {
    let d = a.dot(b).clamp(-1.0, 1.0);
    if d > 0.9995 {
        return (a * (1.0 - t) + b * t).normalize();
    }
    let th = d.acos();
    let inv = 1.0 / th.sin();
    a * (((1.0 - t) * th).sin() * inv) + b * ((t * th).sin() * inv)
}
