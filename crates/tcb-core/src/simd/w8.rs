//! Eight `f32` (and four `f64`) lanes as a plain array, for kernels
//! compiled for an instruction set chosen at run time.
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
//!
//! Count the instructions of a loop over blocks of [`W8`]: LLVM's loop
//! vectorizer may vectorize it a second time, several blocks at once with
//! a transpose per operand (the runtime's 16-bit expansion took 2.1x the
//! instructions so, and its rotation kernel set up a 4.7 KB frame on
//! every call). Loading and storing each block through an AVX vector
//! (`__m256`) keeps it one loop; a simple loop may instead lose its
//! unrolling so, and is better on arrays (the runtime's vector kernel).
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

/// Four `f64` lanes, as [`W8`] is eight `f32`: what the AVX2 instance of
/// the loose tracks' kernel computes times in (`wide::f64x4`'s two SSE2
/// halves in a default build). Its arithmetic, square root, compares and
/// selects give `wide::f64x4`'s bits; its `sin_cos` and `atan2` are
/// `std`'s, not `wide`'s polynomials (as [`W8`]'s).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct D4(pub [f64; 4]);

/// Per-lane booleans of [`D4`]: all bits set or none.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct M4(pub [u64; 4]);

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
elementwise!(I8, Add, add, .wrapping_add);
elementwise!(I8, Sub, sub, .wrapping_sub);
elementwise!(I8, BitAnd, bitand, &);
elementwise!(I8, BitXor, bitxor, ^);

/// Float lanes `$t` of `$n` elements `$e`, with masks `$m` of the
/// unsigned integers `$u` of the same width: arithmetic, [`Real`] and
/// [`Lane`], each an element-wise loop.
macro_rules! float_lanes {
    ($t:ident, $m:ident, $e:ty, $u:ty) => {
        elementwise!($t, Add, add, +);
        elementwise!($t, Sub, sub, -);
        elementwise!($t, Mul, mul, *);
        elementwise!($t, Div, div, /);
        impl Neg for $t {
            type Output = $t;
            #[inline(always)]
            fn neg(self) -> $t {
                $t(self.0.map(|x| -x))
            }
        }
        elementwise!($m, BitAnd, bitand, &);
        elementwise!($m, BitOr, bitor, |);
        impl Not for $m {
            type Output = $m;
            #[inline(always)]
            fn not(self) -> $m {
                $m(self.0.map(|x| !x))
            }
        }
        impl Mask for $m {
            #[inline(always)]
            fn any(self) -> bool {
                self.0.iter().fold(0, |a, &x| a | x) != 0
            }
            #[inline(always)]
            fn all(self) -> bool {
                self.0.iter().fold(<$u>::MAX, |a, &x| a & x) == <$u>::MAX
            }
        }
        impl Real for $t {
            #[inline(always)]
            fn splat(x: f32) -> Self {
                $t([<$e>::from(x); _])
            }
        }
        impl Lane for $t {
            type Mask = $m;
            #[inline(always)]
            fn of(x: f64) -> Self {
                $t([x as $e; _])
            }
            #[inline(always)]
            fn lt(self, o: Self) -> $m {
                $m(std::array::from_fn(|i| <$u>::from(self.0[i] < o.0[i]).wrapping_neg()))
            }
            #[inline(always)]
            fn le(self, o: Self) -> $m {
                $m(std::array::from_fn(|i| <$u>::from(self.0[i] <= o.0[i]).wrapping_neg()))
            }
            #[inline(always)]
            fn eq(self, o: Self) -> $m {
                $m(std::array::from_fn(|i| <$u>::from(self.0[i] == o.0[i]).wrapping_neg()))
            }
            #[inline(always)]
            fn select(k: $m, a: Self, b: Self) -> Self {
                $t(std::array::from_fn(|i| {
                    <$e>::from_bits((a.0[i].to_bits() & k.0[i]) | (b.0[i].to_bits() & !k.0[i]))
                }))
            }
            #[inline(always)]
            fn floor(self) -> Self {
                $t(self.0.map(<$e>::floor))
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $t(self.0.map(<$e>::sqrt))
            }
            #[inline(always)]
            fn abs(self) -> Self {
                $t(self.0.map(<$e>::abs))
            }
            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                ($t(self.0.map(<$e>::sin)), $t(self.0.map(<$e>::cos)))
            }
            #[inline(always)]
            fn atan2(self, x: Self) -> Self {
                $t(std::array::from_fn(|i| self.0[i].atan2(x.0[i])))
            }
        }
    };
}

float_lanes!(W8, M8, f32, u32);
float_lanes!(D4, M4, f64, u64);
