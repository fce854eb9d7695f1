//! One group of a compiled clip: channels sharing a time grid, sampled
//! together (one basis per frame, then the kernels over its planes).

use crate::exact::ExactTable;
use crate::grid::{Cursor, FrameBasis, TimeGrid};
use crate::kernel;
use crate::pack::store::{PackCache, PackedKeys};
use crate::segment::Segment;
use crate::store::{KeyCache, KeyStore};
use wide::f32x8;

/// Channels sharing one time grid.
#[derive(Clone, Debug)]
pub(crate) struct Group {
    pub grid: TimeGrid,
    /// Vector channels (lanes in use).
    pub vector_channels: usize,
    /// Rotations (lanes in use).
    pub rotations: usize,
    /// Vector blocks (one plane each), then rotation blocks (four planes
    /// each) from pose block `vec_out` on.
    pub vec_blocks: usize,
    pub hq_blocks: usize,
    pub vec_out: usize,
    /// Their controls per key, f32 or quantized.
    pub keys: KeyStore,
    /// `P_{n-1} - P_0` per vector block, when a side is `offset-repeat`.
    pub delta: Vec<f32x8>,
    /// Rotation blocks evaluated exactly on some stored segments.
    pub exact: ExactTable,
    /// Whether a vector channel stores a non-finite control (a tangent that
    /// overflowed f32): at a segment's end its value is then copied, not
    /// summed (`0 x inf`).
    pub unbounded: bool,
}

impl Group {
    /// Sample the group at `time` into its blocks of `values` (and
    /// `velocities`): the frame's basis from its grid (the cursor), the
    /// segment's controls from its store (the cache), then the kernels.
    #[inline(always)]
    pub fn sample(
        &self,
        time: f64,
        cursor: &mut Cursor,
        cache: &mut KeyCache,
        values: &mut [f32x8],
        velocities: Option<&mut [f32x8]>,
    ) {
        let f = self.grid.frame(time, cursor);
        let (ka, kb) = self.grid.key_pair(f.segment);
        let controls = self.keys.segment(ka, kb, cache);
        sample_segment(self, f, controls, values, velocities);
    }

    /// [`sample`](Self::sample) for a group whose keys are packed
    /// (`crate::pack`): its controls come from decoded keys. Inside the
    /// keys, where the group has the key form
    /// (`PackedKeys::play_keys`), its rotations play from their four
    /// keys with `key_row` of the frame's basis, without their tangents
    /// (unless a lane's `|p|^2` is at most `KEY_FORM_LOW`: then as
    /// elsewhere, from the tangents). Out of line, so that the f32 groups'
    /// loop stays as it was.
    #[inline(never)]
    pub fn sample_packed(
        &self,
        time: f64,
        cursor: &mut Cursor,
        cache: &mut KeyCache,
        values: &mut [f32x8],
        velocities: Option<&mut [f32x8]>,
    ) {
        let Some((keys, state)) = self.keys.packed(cache) else {
            unreachable!("every group of a packed clip is packed")
        };
        let f = self.grid.frame(time, cursor);
        let mut velocities = velocities;
        if !f.reset && f.cycles == 0.0 && !self.unbounded {
            debug_assert!(self.exact.entries.is_empty(), "packed clips have none");
            let planes = self.vec_out..self.vec_out + self.vec_blocks + 4 * self.hq_blocks;
            let vel = velocities.as_deref_mut().map(|v| &mut v[planes.clone()]);
            if keys.play_keys(&f, state, &mut values[planes], vel) {
                return;
            }
        }
        self.sample_packed_segment(f, keys, state, values, velocities);
    }

    /// [`sample_packed`](Self::sample_packed) from the segment's controls
    /// (the ends, the sentinels, and rows the key form does not take).
    /// Out of line: inlined, its kernels' stack and registers were set up
    /// on every frame (about 20 instructions).
    #[inline(never)]
    fn sample_packed_segment(
        &self,
        f: FrameBasis,
        keys: &PackedKeys,
        state: &mut PackCache,
        values: &mut [f32x8],
        velocities: Option<&mut [f32x8]>,
    ) {
        let (ka, kb) = self.grid.key_pair(f.segment);
        let controls = keys.segment(ka, kb, state);
        sample_segment(self, f, controls, values, velocities);
    }
}

/// One group's kernels on its segment's controls: vectors, then
/// rotations and exact squad lanes.
#[inline(always)]
fn sample_segment(
    g: &Group,
    f: FrameBasis,
    controls: Segment,
    values: &mut [f32x8],
    mut velocities: Option<&mut [f32x8]>,
) {
    let (h, dh, rate) = (f.h, f.dh, f.rate);
    let seg = f.segment;
    let (cv, cq) = controls.split_at(g.vec_blocks);
    if g.vec_blocks > 0 {
        let out = &mut values[g.vec_out..g.vec_out + g.vec_blocks];
        kernel::vectors(cv, h, out);
        if g.unbounded && f.h == [0.0, 1.0, 0.0, 0.0] {
            // At the segment's end the value is its key, as the reference
            // has it, even beside a tangent that overflowed f32 (0 x inf).
            out.copy_from_slice(&cv.p1[..out.len()]);
        }
        if f.cycles != 0.0 && !g.delta.is_empty() {
            kernel::offset(&g.delta, f32x8::splat(f.cycles), out);
        }
        if let Some(v) = velocities.as_deref_mut() {
            kernel::vector_velocities(cv, dh, rate, &mut v[g.vec_out..g.vec_out + g.vec_blocks]);
        }
    }
    if g.hq_blocks > 0 {
        let hq_out = g.vec_out + g.vec_blocks;
        let range = hq_out..hq_out + 4 * g.hq_blocks;
        if f.reset {
            kernel::identity(&mut values[range.clone()]);
            if let Some(v) = velocities.as_deref_mut() {
                v[range].fill(f32x8::ZERO);
            }
        } else {
            kernel::hermite_quats(
                cq,
                h,
                dh,
                rate,
                &mut values[range.clone()],
                velocities.as_deref_mut().map(|v| &mut v[range]),
            );
            for e in g.exact.on_segment(seg) {
                // Without velocities, lanes whose cubic misses only the
                // velocity keep the cubic.
                let mask = match velocities {
                    Some(_) => e.mask,
                    None if e.values => e.value_mask,
                    None => continue,
                };
                let at = hq_out + 4 * e.block as usize;
                let planes = at..at + 4;
                kernel::exact_quats(
                    e,
                    &g.exact.controls[e.controls as usize],
                    mask,
                    f.s,
                    f.rate,
                    &mut values[planes.clone()],
                    velocities.as_deref_mut().map(|v| &mut v[planes]),
                );
            }
        }
    }
}
