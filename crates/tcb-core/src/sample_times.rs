//! Sample-time grids: the paper's inbetweens and fixed frame rates.

/// The paper's inbetweens: every key time and `n` evenly spaced times inside
/// each interval between consecutive ones, at `1/(n+1) .. n/(n+1)` of it.
///
/// `key_times` must be sorted; duplicates are skipped.
///
/// ```
/// use tcb_core::sample_times::inbetweens;
/// assert_eq!(inbetweens(&[0.0, 1.0, 3.0], 1), [0.0, 0.5, 1.0, 2.0, 3.0]);
/// ```
pub fn inbetweens(key_times: &[f64], n: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(key_times.len().saturating_mul(n + 1));
    for (i, &t) in key_times.iter().enumerate() {
        if out.last() == Some(&t) {
            continue;
        }
        if let Some(&prev) = i.checked_sub(1).and_then(|p| key_times.get(p)) {
            let d = t - prev;
            out.extend((1..=n).map(|j| prev + d * (j as f64 / (n + 1) as f64)));
        }
        out.push(t);
    }
    out
}

/// How many samples `frame_times(from, to, fps)` gives, or `None` when the
/// arguments do not describe a finite grid (`fps` not positive and finite,
/// `to < from`, or a count beyond `u64`).
pub fn frame_count(from: f64, to: f64, fps: f64) -> Option<u64> {
    if !(fps > 0.0 && fps.is_finite() && from.is_finite() && to.is_finite() && to >= from) {
        return None;
    }
    // A tiny allowance so that `to` counts as on the grid despite rounding.
    let steps = ((to - from) * fps * (1.0 + 1e-12) + 1e-9).floor();
    // `then`, not `then_some`: the count must not be computed (and
    // overflow) when there are too many to count.
    (steps < u64::MAX as f64).then(|| steps as u64 + 1)
}

/// `from + i / fps` for `i = 0, 1, ..` up to `to` (included when on the grid).
///
/// ```
/// use tcb_core::sample_times::frame_times;
/// assert_eq!(frame_times(0.0, 1.0, 4.0).collect::<Vec<_>>(), [0.0, 0.25, 0.5, 0.75, 1.0]);
/// assert_eq!(frame_times(-1.0, 0.1, 2.0).collect::<Vec<_>>(), [-1.0, -0.5, 0.0]);
/// ```
pub fn frame_times(from: f64, to: f64, fps: f64) -> impl Iterator<Item = f64> {
    let count = frame_count(from, to, fps).unwrap_or(0);
    (0..count).map(move |i| from + i as f64 / fps)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_includes_the_end_when_on_it() {
        assert_eq!(frame_count(0.0, 2.0, 60.0), Some(121));
        assert_eq!(frame_count(0.0, 2.0 - 1e-3, 60.0), Some(120));
        assert_eq!(frame_count(0.1, 0.7, 10.0), Some(7));
        assert_eq!(frame_count(0.0, 1.0, 0.0), None);
        // More than u64 can count: None, not an overflow.
        assert_eq!(frame_count(0.0, 2.0, 1e300), None);
        assert_eq!(frame_count(1.0, 0.0, 10.0), None);
        assert_eq!(frame_count(0.0, 1.0, f64::NAN), None);
        assert_eq!(frame_count(0.0, 0.0, 30.0), Some(1));
    }

    #[test]
    fn inbetweens_skip_duplicates() {
        assert_eq!(inbetweens(&[0.0, 0.0, 2.0], 3), [0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(inbetweens(&[], 3), Vec::<f64>::new());
        assert_eq!(inbetweens(&[1.0, 2.0], 0), [1.0, 2.0]);
    }
}
