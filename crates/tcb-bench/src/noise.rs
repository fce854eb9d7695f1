//! Whether a wall-clock time moved beyond the noise its rounds measured.
//!
//! Two runs on one machine differ by more than their rounds scatter
//! within a run: a shared machine's load comes and goes. A comparison of
//! medians alone calls that noise a regression. The rule here asks for
//! both a shift beyond the measured scatter and a shift that matters:
//!
//! ```text
//! spread  = max(MAD(old rounds), MAD(new rounds))   (median absolute deviation)
//! slower  = median(new) - median(old)
//! regression  <=>  slower > k * spread  and  slower / median(old) > min_rel
//! ```
//!
//! Samples are "higher is worse" (times, or a time over a reference's).

/// The median (the mean of the middle two for an even count; NaN for none).
pub fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
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

/// The median absolute deviation from the median: a spread that one
/// disturbed round does not move (about 0.67 standard deviations for
/// normal noise).
pub fn mad(v: &[f64]) -> f64 {
    let m = median(v);
    let d: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
    median(&d)
}

/// The rule: how many spreads, and the smallest relative change, a
/// regression needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rule {
    /// Spreads (MADs) the medians must differ by.
    pub k: f64,
    /// Smallest relative slowdown, as a fraction (0.10 = 10%).
    pub min_rel: f64,
}

impl Rule {
    /// The rule in words, printed with a comparison.
    pub fn describe(&self) -> String {
        format!(
            "by more than {} MADs of the rounds (the larger of the two runs') and by more than {}%",
            self.k,
            self.min_rel * 100.0
        )
    }
}

/// What [`compare`] found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shift {
    /// Median of the old samples.
    pub old: f64,
    /// Median of the new samples.
    pub new: f64,
    /// The larger MAD of the two.
    pub spread: f64,
    /// `new / old - 1`.
    pub change: f64,
    /// Whether it is a slowdown by the rule.
    pub slower: bool,
}

/// Compare two sets of rounds by `rule`. Non-finite samples are dropped;
/// with no finite sample on a side the answer is "not slower" (NaN
/// medians).
pub fn compare(old: &[f64], new: &[f64], rule: Rule) -> Shift {
    let finite = |v: &[f64]| {
        v.iter()
            .copied()
            .filter(|x| x.is_finite())
            .collect::<Vec<_>>()
    };
    let (old, new) = (finite(old), finite(new));
    let (mo, mn) = (median(&old), median(&new));
    let spread = mad(&old).max(mad(&new));
    let change = mn / mo - 1.0;
    let slower = mn - mo > rule.k * spread && change > rule.min_rel;
    Shift {
        old: mo,
        new: mn,
        spread,
        change,
        slower,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RULE: Rule = Rule {
        k: 3.0,
        min_rel: 0.10,
    };

    /// 11 rounds around `m` with a relative scatter `s`, in a fixed order.
    fn rounds(m: f64, s: f64) -> Vec<f64> {
        [0.0, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 0.2, -0.2, 3.0, -0.8]
            .iter()
            .map(|d| m * (1.0 + s * d))
            .collect()
    }

    #[test]
    fn identical_samples_are_not_a_regression() {
        let a = rounds(100.0, 0.02);
        let s = compare(&a, &a, RULE);
        assert!(!s.slower);
        assert_eq!(s.change, 0.0);
        // Even with no scatter at all.
        let flat = vec![5.0; 11];
        assert!(!compare(&flat, &flat, RULE).slower);
    }

    #[test]
    fn a_clear_shift_is_a_regression() {
        let s = compare(&rounds(100.0, 0.01), &rounds(130.0, 0.01), RULE);
        assert!(s.slower, "{s:?}");
        assert!((s.change - 0.30).abs() < 1e-9, "{s:?}");
        // Faster is never a regression.
        assert!(!compare(&rounds(130.0, 0.01), &rounds(100.0, 0.01), RULE).slower);
    }

    #[test]
    fn a_shift_inside_the_noise_or_below_the_threshold_is_not() {
        // 20% slower, but the rounds scatter by about 10% each: inside 3 MADs.
        let s = compare(&rounds(100.0, 0.10), &rounds(120.0, 0.10), RULE);
        assert!(!s.slower, "{s:?}");
        // 5% slower with almost no scatter: beyond the noise, below 10%.
        let s = compare(&rounds(100.0, 0.001), &rounds(105.0, 0.001), RULE);
        assert!(s.change > 0.04 && !s.slower, "{s:?}");
        // One wild round does not widen the spread (MAD, not range).
        let mut old = rounds(100.0, 0.005);
        old[3] = 1000.0;
        assert!(compare(&old, &rounds(125.0, 0.005), RULE).slower);
    }

    #[test]
    fn empty_or_non_finite_sides_are_not_a_regression() {
        assert!(!compare(&[], &[1.0, 2.0], RULE).slower);
        assert!(!compare(&[1.0], &[f64::NAN, f64::INFINITY], RULE).slower);
        assert_eq!(median(&[3.0, 1.0, 2.0, 4.0]), 2.5);
        assert_eq!(mad(&[1.0, 2.0, 3.0, 4.0, 100.0]), 1.0);
    }
}
