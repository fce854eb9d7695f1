//! Timing for the report: implementations measured round-robin in the same
//! process, so that machine noise hits them alike and their ratios hold
//! across machines; every round is kept, for medians and spreads
//! ([`crate::noise`]).

use std::time::{Duration, Instant};

/// Something to time: one call is one pass (every frame of a scenario).
pub struct Subject<'a> {
    /// Column name (`baseline`, `runtime`, ...).
    pub name: &'static str,
    /// Channel-samples in one pass (what the time is divided by).
    pub samples: f64,
    /// One pass.
    pub run: Box<dyn FnMut() + 'a>,
}

/// Seconds per pass of each subject in every round: each is calibrated to
/// about `slice` per timing, then `rounds` rounds time every subject once
/// each (so round `i` of two subjects ran back to back).
pub fn rounds_seconds(subjects: &mut [Subject], rounds: usize, slice: Duration) -> Vec<Vec<f64>> {
    let mut iters = Vec::with_capacity(subjects.len());
    for s in subjects.iter_mut() {
        (s.run)(); // warm caches and cursors
        let start = Instant::now();
        let mut n = 0u64;
        while start.elapsed() < slice / 4 || n == 0 {
            (s.run)();
            n += 1;
        }
        let per = start.elapsed().as_secs_f64() / n as f64;
        iters.push(((slice.as_secs_f64() / per).ceil() as u64).max(1));
    }
    let mut samples = vec![Vec::with_capacity(rounds); subjects.len()];
    for _ in 0..rounds {
        for (i, s) in subjects.iter_mut().enumerate() {
            let start = Instant::now();
            for _ in 0..iters[i] {
                (s.run)();
            }
            samples[i].push(start.elapsed().as_secs_f64() / iters[i] as f64);
        }
    }
    samples
}
