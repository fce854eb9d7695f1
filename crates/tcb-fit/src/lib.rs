//! # tcb-fit
//!
//! Key reduction (`tcb reduce`, the project's `docs/reduce.md`): dense
//! animation, such as motion capture with a key per frame, replaced by far
//! fewer cubic Hermite keys that stay within a stated error of the original
//! at every check time.
//!
//! | module | what |
//! |---|---|
//! | [`fit`] | least-squares Hermite fits with greedy key insertion and removal |
//! | [`metric`] | check times, playing clips on the runtime, the `shell` and `value` errors |
//! | [`mod@reduce`] | the whole job: tolerances per track, knot sharing, verification, the written clip |
//! | [`cost`] | a compiled clip's estimated instructions per frame, so that a reduced clip plays no slower than its source |
//!
//! ```
//! // A dense track: one key per frame of a smooth motion, 120 fps for 2 s.
//! let times: Vec<String> = (0..=240).map(|i| format!("{}", i as f64 / 120.0)).collect();
//! let values: Vec<String> = (0..=240)
//!     .map(|i| format!("{}", (i as f64 / 120.0 * 3.0).sin()))
//!     .collect();
//! let text = format!(
//!     r#"{{"format": "tcb-clip/1", "tracks": [{{"name": "x", "kind": "scalar",
//!        "times": [{}], "values": [{}]}}]}}"#,
//!     times.join(","),
//!     values.join(",")
//! );
//! let doc = tcb_io::ClipDoc::parse(&text)?;
//! let clip = doc.build()?;
//! let input = tcb_fit::reduce::Input { doc: &doc, clip: &clip, skeleton: None };
//! let reduced = tcb_fit::reduce(input, &tcb_fit::ReduceOptions::default(), &|_, _| {})?;
//! // Within 1e-4 (the value metric's default) with far fewer keys.
//! assert!(reduced.worst.error <= 1e-4);
//! assert!(reduced.after.keys < 30, "{}", reduced.summary_line());
//! println!("{}", reduced.summary_line());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![forbid(unsafe_code)]

mod band;
pub mod compress;
pub mod cost;
pub mod fit;
pub mod metric;
pub mod reduce;

pub use compress::{CompressOptions, Compressed, compress};
pub use fit::{Norm, Tangents};
pub use reduce::{Knots, Metric, ReduceError, ReduceOptions, Reduced, Speed, reduce};
