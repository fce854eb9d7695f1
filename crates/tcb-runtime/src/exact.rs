//! The exact-segment table: rotation blocks whose compiled cubic would
//! miss the reference on some stored segment, evaluated there by squad in
//! f64 ([`crate::kernel::exact_quats`]).

use wide::{f32x8, f64x4};

/// `q0 [x y z w], n01 [x y z], alpha01, a [x y z w], n_ab [x y z], alpha_ab`
/// of 4 quaternions in f64 ([`tcb_core::simd::squad::CONTROLS`]): the two outer
/// slerps of squad as start point, log axis and log angle.
pub(crate) const SQ_STRIDE: usize = tcb_core::simd::squad::CONTROLS;

/// One rotation block on one stored segment, evaluated exactly: the lanes
/// of `mask` take squad in f64 from `ExactTable::controls[controls]` (two
/// halves of 4 lanes; the other lanes hold the identity and are not used).
/// The lanes of `value_mask` are those whose cubic misses the values; the
/// others miss only the velocities, so an instance without velocities
/// leaves them to the cubic (and skips entries whose `value_mask` is
/// empty). `piece` (`[a, w]`) places the stored segment in the squad
/// segment, `s = a + w u`: `[0, 1]` but for a piece of a split segment
/// (`split_rotation`, which splits only the rotation of a group of one, so
/// one `piece` serves the block).
#[derive(Clone, Debug)]
pub(crate) struct Exact {
    pub mask: f32x8,
    pub value_mask: f32x8,
    pub piece: [f64; 2],
    pub block: u32,
    pub controls: u32,
    pub values: bool,
}

/// One group's exact entries per stored segment (empty when nothing is exact).
#[derive(Clone, Debug, Default)]
pub(crate) struct ExactTable {
    /// Per stored segment `k`, its entries: `at[k]..at[k + 1]` (empty when
    /// `entries` is).
    pub at: Vec<u32>,
    /// Rotation blocks evaluated exactly (squad in f64) on some segment.
    pub entries: Vec<Exact>,
    /// The squad controls entries read (`Exact::controls`): the pieces of a
    /// split segment share their segment's.
    pub controls: Vec<[f64x4; 2 * SQ_STRIDE]>,
}

impl ExactTable {
    /// The entries of stored segment `seg`.
    #[inline(always)]
    pub fn on_segment(&self, seg: usize) -> &[Exact] {
        match self.at.get(seg..seg + 2) {
            Some(at) => &self.entries[at[0] as usize..at[1] as usize],
            None => &[],
        }
    }

    /// Heap bytes.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(self.at.as_slice())
            + size_of_val(self.entries.as_slice())
            + size_of_val(self.controls.as_slice())
    }
}
