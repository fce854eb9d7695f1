//! The small vector interface the tangent rules are written against, and the
//! value types a [`crate::Track`] can hold.
//!
//! Tangents are linear combinations of chords with scalar weights, so the
//! rules need only `+`, `-`, scaling and a Euclidean norm. [`Vector`] is
//! implemented by the track value types (`f32`, `Vec2`, `Vec3`, `Vec4`) and by
//! `DVec3`, the log-space chords of rotation tracks, so one implementation of
//! each rule serves positions and rotations.

use glam::{DVec3, Vec2, Vec3, Vec4};
use std::fmt::Debug;

/// A vector space element with a Euclidean norm.
pub trait Vector: Copy + Debug + PartialEq + Send + Sync + 'static {
    /// The zero vector.
    const ZERO: Self;
    /// `self + o`.
    fn add(self, o: Self) -> Self;
    /// `self - o`.
    fn sub(self, o: Self) -> Self;
    /// `self * f` (for `f32` components, `f` is rounded to `f32` first).
    fn scale(self, f: f64) -> Self;
    /// Euclidean length.
    fn norm(self) -> f64;
    /// Every component finite.
    fn is_finite(self) -> bool;

    /// `a * self + b * o`, the shape of every tangent rule.
    fn combine(self, a: f64, o: Self, b: f64) -> Self {
        self.scale(a).add(o.scale(b))
    }
}

/// A value a track can hold: a [`Vector`] of 1 to 4 `f32` components.
pub trait Value: Vector {
    /// Number of components (1 to 4).
    const DIM: usize;
    /// The components, padded with zeros to four.
    fn to_array(self) -> [f32; 4];
    /// From the first [`Value::DIM`] components of `a`.
    fn from_array(a: [f32; 4]) -> Self;
}

impl Vector for f32 {
    const ZERO: Self = 0.0;
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn scale(self, f: f64) -> Self {
        self * f as f32
    }
    fn norm(self) -> f64 {
        f64::from(self.abs())
    }
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

impl Value for f32 {
    const DIM: usize = 1;
    fn to_array(self) -> [f32; 4] {
        [self, 0.0, 0.0, 0.0]
    }
    fn from_array(a: [f32; 4]) -> Self {
        a[0]
    }
}

macro_rules! glam_vector {
    ($t:ty, $dim:literal, [$($i:literal),+]) => {
        impl Vector for $t {
            const ZERO: Self = <$t>::ZERO;
            fn add(self, o: Self) -> Self {
                self + o
            }
            fn sub(self, o: Self) -> Self {
                self - o
            }
            fn scale(self, f: f64) -> Self {
                self * f as f32
            }
            fn norm(self) -> f64 {
                // Summed in f64 so that the norm of a tiny or huge f32 vector
                // neither underflows nor overflows.
                let a = self.to_array();
                a.iter().map(|&x| f64::from(x) * f64::from(x)).sum::<f64>().sqrt()
            }
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
        }

        impl Value for $t {
            const DIM: usize = $dim;
            fn to_array(self) -> [f32; 4] {
                let a = <$t>::to_array(&self);
                let mut out = [0.0; 4];
                out[..$dim].copy_from_slice(&a);
                out
            }
            fn from_array(a: [f32; 4]) -> Self {
                <$t>::new($(a[$i]),+)
            }
        }
    };
}

glam_vector!(Vec2, 2, [0, 1]);
glam_vector!(Vec3, 3, [0, 1, 2]);
glam_vector!(Vec4, 4, [0, 1, 2, 3]);

/// f64 vectors (rotation log-space chords, and scalars in tests): no rounding.
macro_rules! f64_vector {
    ($t:ty, $zero:expr, $norm:expr, $finite:expr) => {
        impl Vector for $t {
            const ZERO: Self = $zero;
            fn add(self, o: Self) -> Self {
                self + o
            }
            fn sub(self, o: Self) -> Self {
                self - o
            }
            fn scale(self, f: f64) -> Self {
                self * f
            }
            fn norm(self) -> f64 {
                ($norm)(self)
            }
            fn is_finite(self) -> bool {
                ($finite)(self)
            }
        }
    };
}

f64_vector!(f64, 0.0, f64::abs, f64::is_finite);
f64_vector!(DVec3, DVec3::ZERO, DVec3::length, DVec3::is_finite);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_round_trip() {
        let v = Vec3::new(1.0, -2.0, 3.5);
        assert_eq!(v.to_array(), [1.0, -2.0, 3.5, 0.0]);
        assert_eq!(<Vec3 as Value>::from_array([1.0, -2.0, 3.5, 9.0]), v);
        assert_eq!(<f32 as Value>::from_array([7.0, 1.0, 1.0, 1.0]), 7.0);
    }

    #[test]
    fn norm_does_not_overflow() {
        let v = Vec2::new(3e30, 4e30);
        assert!((v.norm() - 5e30).abs() < 1e24);
        assert_eq!((-2.0f32).norm(), 2.0);
    }
}
