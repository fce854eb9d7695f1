//! Lanes: the arithmetic every per-sample formula is written in, once.
//!
//! [`Lane`] extends [`Real`] with division, comparisons, selects and a few
//! functions. It is implemented for `f32` and `f64` (one lane: the scalar
//! reference), for `wide::f32x8` and `wide::f64x4` (the runtime's
//! kernels) and for [`crate::simd::w8::W8`] and [`crate::simd::w8::D4`]
//! (their AVX2 instance), so time
//! mapping, ease, normalization and the Hermite basis run the same
//! operations in the same order on one lane and on eight (as
//! ultraviolet and wide do). Branches become selects: every side of a
//! choice is computed and the mask picks, so a formula has no branch that
//! depends on a lane's data.

use crate::simd::basis::Real;
use std::ops::{BitAnd, BitOr, Div, Neg, Not};

/// Per-lane booleans of a [`Lane`] type.
pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    /// Whether any lane is set.
    fn any(self) -> bool;
    /// Whether every lane is set.
    fn all(self) -> bool;
}

impl Mask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
    #[inline(always)]
    fn all(self) -> bool {
        self
    }
}

/// A lane of arithmetic with comparisons and selects (see the module docs).
pub trait Lane: Real + Div<Output = Self> + Neg<Output = Self> {
    /// Its per-lane booleans.
    type Mask: Mask;
    /// Every lane set to `x` (rounded to the lane's precision).
    fn of(x: f64) -> Self;
    /// `self < o` per lane.
    fn lt(self, o: Self) -> Self::Mask;
    /// `self <= o` per lane.
    fn le(self, o: Self) -> Self::Mask;
    /// `self == o` per lane (NaN is equal to nothing).
    fn eq(self, o: Self) -> Self::Mask;
    /// `m ? a : b` per lane.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// Round down.
    fn floor(self) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Absolute value.
    fn abs(self) -> Self;
    /// `(sin, cos)`.
    fn sin_cos(self) -> (Self, Self);
    /// The angle of `(x, self)`, as `f64::atan2`.
    fn atan2(self, x: Self) -> Self;

    /// `self > o` per lane.
    #[inline(always)]
    fn gt(self, o: Self) -> Self::Mask {
        o.lt(self)
    }
    /// `self >= o` per lane.
    #[inline(always)]
    fn ge(self, o: Self) -> Self::Mask {
        o.le(self)
    }
    /// `self` limited to `[lo, hi]` (a select each side, so NaN stays NaN
    /// and `lo <= hi` is not required to avoid a panic).
    #[inline(always)]
    fn clamp_to(self, lo: Self, hi: Self) -> Self {
        let x = Self::select(self.lt(lo), lo, self);
        Self::select(x.gt(hi), hi, x)
    }
}

/// `floor`, `sqrt`, `abs`, `sin_cos` and `atan2`, forwarded to the type's own.
macro_rules! functions {
    ($t:ty) => {
        #[inline(always)]
        fn floor(self) -> Self {
            <$t>::floor(self)
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            <$t>::sqrt(self)
        }
        #[inline(always)]
        fn abs(self) -> Self {
            <$t>::abs(self)
        }
        #[inline(always)]
        fn sin_cos(self) -> (Self, Self) {
            <$t>::sin_cos(self)
        }
        #[inline(always)]
        fn atan2(self, x: Self) -> Self {
            <$t>::atan2(self, x)
        }
    };
}

macro_rules! scalar_lane {
    ($t:ty) => {
        impl Lane for $t {
            type Mask = bool;
            #[inline(always)]
            fn of(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn lt(self, o: Self) -> bool {
                self < o
            }
            #[inline(always)]
            fn le(self, o: Self) -> bool {
                self <= o
            }
            #[inline(always)]
            fn eq(self, o: Self) -> bool {
                self == o
            }
            #[inline(always)]
            fn select(m: bool, a: Self, b: Self) -> Self {
                if m { a } else { b }
            }
            functions!($t);
        }
    };
}

scalar_lane!(f32);
scalar_lane!(f64);

macro_rules! simd_lane {
    ($t:ty, $e:ty) => {
        impl Mask for $t {
            #[inline(always)]
            fn any(self) -> bool {
                <$t>::any(self)
            }
            #[inline(always)]
            fn all(self) -> bool {
                <$t>::all(self)
            }
        }

        impl Lane for $t {
            type Mask = $t;
            #[inline(always)]
            fn of(x: f64) -> Self {
                <$t>::splat(x as $e)
            }
            #[inline(always)]
            fn lt(self, o: Self) -> Self {
                self.simd_lt(o)
            }
            #[inline(always)]
            fn le(self, o: Self) -> Self {
                self.simd_le(o)
            }
            #[inline(always)]
            fn eq(self, o: Self) -> Self {
                self.simd_eq(o)
            }
            #[inline(always)]
            fn select(m: Self, a: Self, b: Self) -> Self {
                m.select(a, b)
            }
            functions!($t);
        }
    };
}

simd_lane!(wide::f32x8, f32);
simd_lane!(wide::f64x4, f64);

#[cfg(test)]
mod tests {
    use super::*;
    use wide::{f32x8, f64x4};

    /// Each lane of a SIMD select, compare and function equals the scalar one.
    #[test]
    fn simd_lanes_agree_with_scalar_lanes() {
        let xs = [-2.5, -0.0, 0.0, 0.5, 1.0, 3.75, 1e300, f64::NAN];
        let ys = [1.0, 0.0, -0.0, 0.5, 2.0, -3.0, 1.0, 0.0];
        for h in 0..2 {
            let a: [f64; 4] = std::array::from_fn(|i| xs[4 * h + i]);
            let b: [f64; 4] = std::array::from_fn(|i| ys[4 * h + i]);
            let (va, vb) = (f64x4::new(a), f64x4::new(b));
            let sel = f64x4::select(va.lt(vb), va.floor(), vb.abs()).to_array();
            let clamp = va.clamp_to(f64x4::ZERO, vb.abs()).to_array();
            for i in 0..4 {
                let want = f64::select(a[i].lt(b[i]), a[i].floor(), b[i].abs());
                assert_eq!(sel[i].to_bits(), want.to_bits());
                let want = a[i].clamp_to(0.0, b[i].abs());
                assert!(
                    clamp[i].to_bits() == want.to_bits() || (want.is_nan() && clamp[i].is_nan())
                );
            }
        }
        let a: [f32; 8] = std::array::from_fn(|i| xs[i] as f32);
        let v = f32x8::new(a);
        let got = (v / f32x8::of(3.0)).sqrt().to_array();
        for i in 0..8 {
            let want = (a[i] / 3.0).sqrt();
            assert!(got[i].to_bits() == want.to_bits() || (want.is_nan() && got[i].is_nan()));
        }
    }

    /// Each lane of `W8`'s operations equals `f32x8`'s, bit for bit.
    #[test]
    fn w8_lanes_agree_with_wide() {
        use crate::simd::w8::W8;
        let xs = [-2.5f32, -0.0, 0.0, 0.5, 1.0, 3.75, 1e30, f32::NAN];
        let ys = [1.0f32, 0.0, -0.0, 0.5, 2.0, -3.0, 1e-30, 0.0];
        let (wa, wb) = (W8(xs), W8(ys));
        let (va, vb) = (f32x8::new(xs), f32x8::new(ys));
        let same = |w: W8, v: f32x8| {
            for (x, y) in w.0.iter().zip(v.to_array()) {
                assert!(
                    x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
                    "{x} {y}"
                );
            }
        };
        same(wa + wb, va + vb);
        same(wa - wb, va - vb);
        same(wa * wb, va * vb);
        same(wa / wb, va / vb);
        same(-wa, -va);
        same((wa / W8::of(3.0)).sqrt(), (va / f32x8::of(3.0)).sqrt());
        same(wa.abs(), va.abs());
        same(wa.floor(), va.floor());
        same(
            W8::select(wa.lt(wb), wa, wb),
            f32x8::select(va.lt(vb), va, vb),
        );
        same(
            W8::select(wa.le(wb), wa, wb),
            f32x8::select(va.le(vb), va, vb),
        );
        same(
            W8::select(wa.eq(wb), wa, wb),
            f32x8::select(va.eq(vb), va, vb),
        );
        same(
            wa.clamp_to(W8::of(0.0), wb.abs()),
            va.clamp_to(f32x8::of(0.0), vb.abs()),
        );
        let m = wa.lt(wb);
        assert_eq!(m.any(), va.lt(vb).any());
        assert_eq!(m.all(), va.lt(vb).all());
        assert!(!(m & !m).any());
        assert!((m | !m).all());
    }

    #[test]
    fn d4_lanes_agree_with_wide() {
        use crate::simd::w8::D4;
        let xs = [-2.5, 1e300, f64::NAN, -0.0];
        let ys = [1.0, -0.0, 0.0, 0.5];
        let (da, db) = (D4(xs), D4(ys));
        let (va, vb) = (f64x4::new(xs), f64x4::new(ys));
        let same = |d: D4, v: f64x4| {
            for (x, y) in d.0.iter().zip(v.to_array()) {
                assert!(
                    x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
                    "{x} {y}"
                );
            }
        };
        same(da + db, va + vb);
        same(da - db, va - vb);
        same(da * db, va * vb);
        same(da / db, va / vb);
        same(-da, -va);
        same(D4::splat(0.1), <f64x4 as Real>::splat(0.1));
        same((da / D4::of(3.0)).sqrt(), (va / f64x4::of(3.0)).sqrt());
        same(da.abs(), va.abs());
        same(da.floor(), va.floor());
        for (d, v) in [
            (
                D4::select(da.lt(db), da, db),
                f64x4::select(va.lt(vb), va, vb),
            ),
            (
                D4::select(da.le(db), da, db),
                f64x4::select(va.le(vb), va, vb),
            ),
            (
                D4::select(da.eq(db), da, db),
                f64x4::select(va.eq(vb), va, vb),
            ),
        ] {
            same(d, v);
        }
        same(
            da.clamp_to(D4::of(0.0), db.abs()),
            va.clamp_to(f64x4::of(0.0), vb.abs()),
        );
        for (x, y) in [(da, db), (db, db), (da + D4::of(1e301), db)] {
            let (vx, vy) = (f64x4::new(x.0), f64x4::new(y.0));
            assert_eq!(x.le(y).any(), vx.le(vy).any());
            assert_eq!(x.le(y).all(), vx.le(vy).all());
        }
        let m = da.le(db);
        assert_eq!(m.any(), va.le(vb).any());
        assert_eq!(m.all(), va.le(vb).all());
        assert!(!(m & !m).any());
        assert!((m | !m).all());
    }

    #[test]
    fn i8_lanes_agree_with_wide() {
        use crate::simd::w8::I8;
        use wide::i32x8;
        let xs = [i32::MAX, i32::MIN, -1, 0, 1, 1 << 24, (1 << 24) + 1, -77];
        let ys = [1, -1, i32::MIN, 5, -5, 3, 0x0f0f_0f0f, 99];
        let (ia, ib) = (I8(xs), I8(ys));
        let (va, vb) = (i32x8::new(xs), i32x8::new(ys));
        assert_eq!((ia + ib).0, (va + vb).to_array());
        assert_eq!((ia - ib).0, (va - vb).to_array());
        assert_eq!((ia & ib).0, (va & vb).to_array());
        assert_eq!((ia ^ ib).0, (va ^ vb).to_array());
        let logical: wide::u32x8 = wide::u32x8::new(xs.map(|x| x as u32)) >> 1_u32;
        let want = logical.to_array().map(|x| x as i32);
        assert_eq!(ia.shr_logical::<1>().0, want);
        // Per-lane shifts by the low 5 bits (32 is 0, 33 is 1).
        let ns = [0, 1, 31, 5, 32, 33, 7, 30];
        let each = wide::u32x8::new(xs.map(|x| x as u32)) << wide::u32x8::new(ns.map(|n| n as u32));
        let want = each.to_array().map(|x| x as i32);
        assert_eq!(ia.shl_each(I8(ns)).0, want);
        assert_eq!(want[2], i32::MIN, "31 shifts a 1 to the sign bit");
        let (f, g) = (ia.to_float().0, va.round_float().to_array());
        assert_eq!(f.map(f32::to_bits), g.map(f32::to_bits));
    }
}
