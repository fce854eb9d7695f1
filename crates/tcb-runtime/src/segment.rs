//! The controls of one stored segment, as every store (f32, 16-bit,
//! packed) hands them to the kernels.

use wide::f32x8;

/// The four controls of one stored segment from key `a` to key `b`
/// (`planes` vectors each): `P0 = a.P`, `M0 = a.TO`, `P1 = b.P`,
/// `M1 = b.TI`.
#[derive(Clone, Copy)]
pub(crate) struct Segment<'a> {
    pub p0: &'a [f32x8],
    pub m0: &'a [f32x8],
    pub p1: &'a [f32x8],
    pub m1: &'a [f32x8],
}

impl<'a> Segment<'a> {
    /// The first `n` planes and the rest.
    #[inline(always)]
    pub fn split_at(self, n: usize) -> (Segment<'a>, Segment<'a>) {
        let (p0, q0) = self.p0.split_at(n);
        let (m0, n0) = self.m0.split_at(n);
        let (p1, q1) = self.p1.split_at(n);
        let (m1, n1) = self.m1.split_at(n);
        (
            Segment { p0, m0, p1, m1 },
            Segment {
                p0: q0,
                m0: n0,
                p1: q1,
                m1: n1,
            },
        )
    }
}
