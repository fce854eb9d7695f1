//! Eight `f32` lanes as a plain array, for kernels compiled for an
//! instruction set chosen at run time.
//!
//! `wide::f32x8` picks its instructions when `wide` is compiled: two SSE2
//! halves in a default x86-64 build, even inside a function compiled with
//! `#[target_feature(enable = "avx2")]`. [`W8`]'s operations are
//! element-wise loops over an array, which the compiler turns into one
//! vector instruction each for the features of the function they are
//! inlined into. The runtime's AVX2 instance of its kernels runs the same
//! formulas ([`crate::simd::basis::hermite`], [`crate::quat::normalize`])
//! on [`W8`] as its default instance runs on `wide::f32x8`: the same IEEE
//! operations per lane in the same order, so the same bits (no operation
//! is fused; Rust does not contract `a * b + c`).
//!
//! Inside a `#[target_feature]` function, build arrays of [`W8`] without
//! closures passed to generic functions (`std::array::from_fn`, `map`): such
//! a closure inherits the features and can then not be inlined into the
//! generic function, which has none, so each element becomes a call.
use crate::simd::basis::Real;
use crate::simd::lane::{Lane, Mask};
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

/// Eight `f32` lanes (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct W8(pub [f32; 8]);

/// Per-lane booleans of [`W8`]: all bits set or none.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct M8(pub [u32; 8]);

/// Eight `i32` lanes, as [`W8`] is eight `f32`: what a decoder of
/// integers runs on (wrapping arithmetic, as `wide::i32x8`'s).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct I8(pub [i32; 8]);

impl I8 {
    /// Each lane shifted right by `N` bits as an unsigned integer (zeros
    /// in from the left).
    #[inline(always)]
    pub fn shr_logical<const N: u32>(self) -> I8 {
        I8(self.0.map(|x| ((x as u32) >> N) as i32))
    }

    /// Each lane shifted left by the low 5 bits of the same lane of `n`
    /// (as `wide::u32x8`'s `<<` by a vector).
    #[inline(always)]
    pub fn shl_each(self, n: I8) -> I8 {
        I8(std::array::from_fn(|i| {
            self.0[i].wrapping_shl(n.0[i] as u32)
        }))
    }

    /// Each lane as the nearest `f32` (`x as f32`, as
    /// `wide::i32x8::round_float`).
    #[inline(always)]
    pub fn to_float(self) -> W8 {
        let x = self.0;
        // Written out: no closure (module docs).
        W8([
            x[0] as f32,
            x[1] as f32,
            x[2] as f32,
            x[3] as f32,
            x[4] as f32,
            x[5] as f32,
            x[6] as f32,
            x[7] as f32,
        ])
    }
}

/// `$t`'s operator `$tr` lane by lane (`$op`, or the method `.$m`).
macro_rules! elementwise {
    ($t:ident, $tr:ident, $f:ident, .$m:ident) => {
        impl $tr for $t {
            type Output = $t;
            #[inline(always)]
            fn $f(self, o: $t) -> $t {
                $t(std::array::from_fn(|i| self.0[i].$m(o.0[i])))
            }
        }
    };
    ($t:ident, $tr:ident, $f:ident, $op:tt) => {
        impl $tr for $t {
            type Output = $t;
            #[inline(always)]
            fn $f(self, o: $t) -> $t {
                $t(std::array::from_fn(|i| self.0[i] $op o.0[i]))
            }
        }
    };
}
elementwise!(W8, Add, add, +);
elementwise!(W8, Sub, sub, -);
elementwise!(W8, Mul, mul, *);
elementwise!(W8, Div, div, /);
impl Neg for W8 {
    type Output = W8;
    #[inline(always)]
    fn neg(self) -> W8 {
        W8(self.0.map(|x| -x))
    }
}
elementwise!(I8, Add, add, .wrapping_add);
elementwise!(I8, Sub, sub, .wrapping_sub);
elementwise!(I8, BitAnd, bitand, &);
elementwise!(I8, BitXor, bitxor, ^);
elementwise!(M8, BitAnd, bitand, &);
elementwise!(M8, BitOr, bitor, |);
impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8(self.0.map(|x| !x))
    }
}
impl Mask for M8 {
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(0, |a, &x| a | x) != 0
    }
    #[inline(always)]
    fn all(self) -> bool {
        self.0.iter().fold(u32::MAX, |a, &x| a & x) == u32::MAX
    }
}
impl Real for W8 {
    #[inline(always)]
    fn splat(x: f32) -> Self {
        W8([x; 8])
    }
}
#[inline(always)]
fn m(b: bool) -> u32 {
    if b { u32::MAX } else { 0 }
}
impl Lane for W8 {
    type Mask = M8;
    #[inline(always)]
    fn of(x: f64) -> Self {
        W8([x as f32; 8])
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M8 {
        M8(std::array::from_fn(|i| m(self.0[i] < o.0[i])))
    }
    #[inline(always)]
    fn le(self, o: Self) -> M8 {
        M8(std::array::from_fn(|i| m(self.0[i] <= o.0[i])))
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M8 {
        M8(std::array::from_fn(|i| m(self.0[i] == o.0[i])))
    }
    #[inline(always)]
    fn select(k: M8, a: Self, b: Self) -> Self {
        W8(std::array::from_fn(|i| {
            f32::from_bits((a.0[i].to_bits() & k.0[i]) | (b.0[i].to_bits() & !k.0[i]))
        }))
    }
    #[inline(always)]
    fn floor(self) -> Self {
        W8(self.0.map(f32::floor))
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        W8(self.0.map(f32::sqrt))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        W8(self.0.map(f32::abs))
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        (W8(self.0.map(f32::sin)), W8(self.0.map(f32::cos)))
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        W8(std::array::from_fn(|i| self.0[i].atan2(x.0[i])))
    }
}
