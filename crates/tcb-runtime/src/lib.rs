//! # tcb-runtime
//!
//! Sampling Kochanek–Bartels animation in a game loop.
//!
//! ```
//! use std::sync::Arc;
//! use tcb_runtime::{Clip, Instance, blend};
//!
//! // Load once: validate, compile to structure-of-arrays, share by Arc.
//! # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/clips/bounce.json");
//! # /*
//! let path = "examples/clips/bounce.json"; // from the repository's root
//! # */
//! let clip = Arc::new(Clip::compile(&tcb_io::load(path).unwrap().clip));
//! let ball = clip.track("ball.position").unwrap();
//!
//! // Instances: a cursor per time grid and a pose each; no allocation after this.
//! let mut walk = Instance::new(clip.clone());
//! let mut run = Instance::new(clip.clone());
//! let mut out = walk.pose().clone();
//!
//! // Fixed-step loop: sample both, cross-fade.
//! let dt = 1.0 / 60.0;
//! for frame in 0..120 {
//!     let t = frame as f64 * dt;
//!     walk.sample(t);
//!     run.sample(t + 0.5);
//!     let fade = (frame as f32 / 120.0).min(1.0);
//!     blend(&mut out, &[(walk.pose(), 1.0 - fade), (run.pose(), fade)], None).unwrap();
//!     let p = out.vec3(ball).unwrap(); // None if `ball` were not a vec3 of this clip
//!     assert!(p.is_finite());
//! }
//! ```
//!
//! What allocates: loading and compiling (`Clip::compile`,
//! `Clip::from_bytes`), `Instance::new` and `Instance::with_rig`, `Rig::new`
//! and `SkeletonBinding`'s constructors. What does not, once those are
//! made: `Instance::sample` and `sample_to`, `blend` and `blend::add`,
//! sampling through a rig (`tests/no_alloc.rs` counts these), and
//! `SkeletonBinding`'s transforms, which write into the caller's slices.
//! The cost of sampling
//! through a rig against plain sampling has not been measured yet.
//!
//! How it works: see [`clip`] (the layout), `grid.rs` (the per-frame basis
//! and the sentinels that keep the kernels free of per-channel branches).

// Denied rather than forbidden: the AVX2 instances (`v3` in `kernel`,
// `quant`, `loose` and `pack::store`) are called, after detecting the
// CPU's features, from `#[allow]`ed blocks there, and the packed decoder's
// gathers read the stream through raw pointers inside bounds it checks
// first; nothing else is unsafe.
#![deny(unsafe_code)]

pub mod blend;
pub mod clip;
mod compile;
mod exact;
pub(crate) mod grid;
mod group;
mod instance;
mod isa;
mod kernel;
mod layout;
mod loose;
pub mod pack;
mod pose;
mod quant;
pub mod rig;
mod segment;
mod skeleton;
mod store;

#[cfg(feature = "rayon")]
pub mod batch;

pub use blend::{BlendMask, blend};
pub use clip::{Clip, ClipStats, GridStats};
pub use compile::CompileOptions;
pub use instance::{Instance, OutputLength, Playback, PlaybackError};
pub use isa::{Simd, force_baseline_simd, force_no_avx512, simd};
pub use layout::{PoseLayout, TrackId, TrackSlot};
pub use pack::{BlockScales, KeyValues, PackError, PackSource, PackTrack, Packed};

/// The `mint` crate (feature `mint`): poses' glam values convert with
/// `.into()`, so an engine on another glam version, nalgebra or cgmath
/// converts at the boundary.
///
/// ```
/// # #[cfg(feature = "mint")] {
/// let q: tcb_runtime::mint::Quaternion<f32> = glam::Quat::IDENTITY.into();
/// let v: glam::Vec3 = tcb_runtime::mint::Vector3 { x: 1.0, y: 2.0, z: 3.0 }.into();
/// assert_eq!((q.s, v.z), (1.0, 3.0));
/// # }
/// ```
#[cfg(feature = "mint")]
pub use mint;
pub use pose::Pose;
pub use rig::{Rig, RigError, RigTrack};
pub use skeleton::{BindingError, SkeletonBinding};

/// The README's examples, compiled as doctests so that they stay true
/// (here, where every crate they use is a dependency).
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
