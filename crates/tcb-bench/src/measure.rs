//! Timing for the report: implementations measured round-robin in the same
//! process, so that machine noise hits them alike and their ratios hold
//! across machines; medians, not means.

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

/// Median seconds per pass of each subject: each is calibrated to about
/// `slice` per timing, then `rounds` rounds time every subject once each.
pub fn median_seconds(subjects: &mut [Subject], rounds: usize, slice: Duration) -> Vec<f64> {
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
    samples.into_iter().map(median).collect()
}

/// The median (the mean of the middle two for an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}
