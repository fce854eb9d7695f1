//! # tcb-fit
//!
//! Key reduction (`tcb reduce`, the project's `spec/reduce.md`): dense
//! animation, such as motion capture with a key per frame, replaced by far
//! fewer cubic Hermite keys that stay within a stated error of the original
//! at every check time.
//!
//! | module | what |
//! |---|---|
//! | [`fit`] | least-squares Hermite fits with greedy key insertion and removal |
//! | [`metric`] | check times, playing clips on the runtime, the `shell` and `value` errors |
//! | [`reduce`] | the whole job: tolerances per track, knot sharing, verification, the written clip |

#![forbid(unsafe_code)]

mod band;
pub mod fit;
pub mod metric;
pub mod reduce;

pub use fit::{Norm, Tangents};
pub use reduce::{Knots, Metric, ReduceError, ReduceOptions, Reduced, reduce};
