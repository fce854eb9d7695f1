//! # tcb-bench
//!
//! How the runtime compares, on real data, with the straightforward
//! implementation ([`baseline`]) and with the `splines` crate ([`peer`]),
//! named wall-clock baselines with a machine fingerprint, and the
//! instruction-count gate ([`icount`]).
//!
//! ```text
//! cargo run --release -p tcb-bench -- --quick            # a first look, under 10 s
//! cargo run --release -p tcb-bench                       # the full report
//! cargo run --release -p tcb-bench -- --save-baseline before   # then --baseline before
//! cargo run --release -p tcb-bench -- --markdown docs/benchmarks.md   # this machine's current table
//! cargo run --release -p tcb-bench -- --icount --icount-check benches/icount.json   # the gate
//! ```
//!
//! The scenarios ([`scenarios`]) are shared by the report and by the
//! criterion benches (`benches/scenarios.rs`).

#![forbid(unsafe_code)]

pub mod baseline;
pub mod icount;
pub mod markdown;
pub mod measure;
pub mod noise;
pub mod peer;
pub mod report;
pub mod scenarios;

pub use baseline::Baseline;

/// A small deterministic generator (xorshift64*), so scenarios are the same
/// on every machine.
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[a, b)`.
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next_f64()
    }
}
