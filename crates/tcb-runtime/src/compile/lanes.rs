//! Laying per-lane rows into blocks of 8 (or 4) lanes, and the padding
//! lanes of loose rotations.

use super::controls::Controls;
use crate::grid::{KeyTimes, TimeGrid};
use crate::loose::LooseLane;
use crate::store::HQ_STRIDE;
use tcb_core::Extrapolation;
use tcb_core::ease::SegmentEase;
use wide::f32x8;

/// Lay per-lane control rows into blocks of `N` lanes (`f32x8`: 8,
/// `f64x4`: 4), `blocks` of them:
/// `out[(seg * blocks + b) * width + j]` lane `l` = `rows[b * N + l][seg][j]`;
/// lanes past the last row get `pad`.
pub(crate) fn pack_lanes<T: Copy + Default, L: Clone, const N: usize, const W: usize>(
    rows: &[Vec<[T; W]>],
    segments: usize,
    blocks: usize,
    pad: [T; W],
    make: fn([T; N]) -> L,
) -> Vec<L> {
    let mut out = Vec::with_capacity(segments * blocks * W);
    for seg in 0..segments {
        for b in 0..blocks {
            for j in 0..W {
                let lanes: [T; N] =
                    std::array::from_fn(|l| rows.get(b * N + l).map_or(pad[j], |r| r[seg][j]));
                out.push(make(lanes));
            }
        }
    }
    out
}

/// [`pack_lanes`] into `f32x8` blocks.
pub(crate) fn pack<const W: usize>(
    rows: &[Vec<[f32; W]>],
    segments: usize,
    pad: [f32; W],
) -> Vec<f32x8> {
    pack_lanes(rows, segments, rows.len().div_ceil(8), pad, f32x8::new)
}

/// Controls of an unused rotation lane: the identity (`P.w = 1`), so that
/// padding lanes normalize to a finite value, not 0/0.
pub(crate) const IDENTITY_PAD: [f32; HQ_STRIDE] = {
    let mut pad = [0.0; HQ_STRIDE];
    pad[3] = 1.0;
    pad
};

/// A padding lane of loose rotations: the identity at all times.
pub(crate) fn identity_lane() -> LooseLane {
    let grid = TimeGrid {
        times: KeyTimes::Listed(vec![-crate::loose::PAD_SPAN, crate::loose::PAD_SPAN]),
        eases: vec![SegmentEase::default()],
        steps: vec![false],
        pre: Extrapolation::Constant,
        post: Extrapolation::Constant,
    };
    let zero: Controls = vec![[0.0; 4]; 3];
    let w: Controls = vec![[1.0, 1.0, 0.0, 0.0]; 3];
    LooseLane::new(grid, &[&zero, &zero, &zero, &w])
}
