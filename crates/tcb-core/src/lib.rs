//! # tcb-core
//!
//! Kochanek–Bartels splines (Kochanek & Bartels 1984, "Interpolating Splines
//! with Local Tension, Continuity, and Bias Control"): per-key tangents from
//! tension, continuity and bias on even and uneven key times, end
//! conditions, ease, extrapolation and rotations, with a scalar reference
//! spline that the SIMD runtime is checked against.
//!
//! The mathematics follows the project's contract (`docs/math.md`) exactly;
//! each module's documentation carries its formulas:
//!
//! | module | what |
//! |---|---|
//! | [`tangent`] | TCB weights, the four tangent rules, `match_speed`, ends, overrides |
//! | [`ease`] | 3ds Max ease to / ease from |
//! | [`track`] | [`Track`], the reference spline for `f32`, `Vec2`, `Vec3`, `Vec4` |
//! | [`rotation`] | [`RotationTrack`]: `squad` and `hermite` on quaternions |
//! | `source_clip` | [`SourceClip`]: named tracks sampled together |
//! | [`sample_times`] | the paper's inbetweens, frame grids |
//! | [`simd`] | the formulas over lane types the runtime's kernels share (not a stable API) |
//!
//! Tracks are validated once when built ([`TrackError`] names the key at
//! fault); after that, sampling never fails and never panics, for any f64
//! time including NaN and infinities (see [`Extrapolation`]).
//!
//! ```
//! use glam::Vec3;
//! use tcb_core::{KeyParams, Tcb, Track, TrackSettings};
//!
//! // The ball careening off a tree: a corner (c = -1) at the middle key.
//! let mut keys = vec![KeyParams::default(); 3];
//! keys[1] = KeyParams::with_tcb(Tcb::new(0.0, -1.0, 0.0));
//! let path = Track::new(
//!     vec![0.0, 1.0, 2.0],
//!     vec![Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::new(2.0, 0.0, 0.0)],
//!     keys,
//!     &TrackSettings::default(),
//! )
//! .unwrap();
//! for frame in 0..=8 {
//!     let p = path.sample(frame as f64 * 0.25);
//!     assert!(p.y >= 0.0 && p.y <= 1.0);
//! }
//! ```

#![forbid(unsafe_code)]

pub mod ease;
mod error;
pub mod params;
pub mod quat;
pub mod rotation;
pub mod sample_times;
pub mod simd;
pub mod skeleton;
mod source_clip;
pub mod tangent;
pub mod track;
pub mod vector;

pub use error::TrackError;
pub use params::{
    Ease, Ends, Extrapolation, Hemisphere, Interp, KeyParams, RotationMode, TangentRule, Tcb,
    TrackSettings,
};
pub use rotation::RotationTrack;
pub use source_clip::{DuplicateTrack, NamedTrack, SourceClip, TrackData, TrackKind};
pub use track::Track;
pub use vector::{Value, Vector};
