//! The formulas the runtime's SIMD kernels share with the reference, over
//! lane types (`f32`, `f64`, `wide`'s `f32x8` and `f64x4`, and [`w8::W8`]
//! and [`w8::D4`], eight and four lanes for kernels compiled for AVX2 at
//! run time): the lane
//! trait, the Hermite basis row, squad in power form and extrapolation over
//! lanes with per-lane mode masks.
//!
//! **Not a stable API.** These modules exist so that `tcb-runtime` runs the
//! reference's own formulas on 8 lanes; their signatures follow the
//! runtime's needs and the `wide` version in use, and may change in any
//! release. What a user needs is public elsewhere: [`crate::Track`],
//! [`crate::RotationTrack`] and [`crate::SourceClip`] sample, and
//! [`crate::rotation`] has slerp, squad and quaternion log and exp on
//! `glam` types.
//!
//! ```compile_fail
//! use tcb_core::lane::Lane; // not at the crate's root: `tcb_core::simd::lane`
//! ```

pub mod basis;
pub mod extrapolate;
pub mod lane;
pub mod squad;
pub mod w8;
