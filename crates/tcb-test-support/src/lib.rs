//! What tcb's test suites share across crates (not published; a
//! dev-dependency only, which `cargo package` leaves out of the published
//! manifests).

mod alloc;

pub use alloc::{
    Allocations, CountingAllocator, count_allocations, start_counting, stop_counting, take_counted,
};
use proptest::test_runner::{Config, RngSeed};
use std::fmt::Debug;

/// Cases and seed: deterministic by default so that CI cannot flake;
/// `PROPTEST_CASES` and `PROPTEST_RNG_SEED` override them for deeper runs.
pub fn proptest_config(cases: u32) -> Config {
    let env = Config::default();
    let set = |name: &str| std::env::var_os(name).is_some();
    Config {
        cases: if set("PROPTEST_CASES") {
            env.cases
        } else {
            cases
        },
        rng_seed: if set("PROPTEST_RNG_SEED") {
            env.rng_seed
        } else {
            RngSeed::Fixed(0x7cb_1984)
        },
        ..env
    }
}

/// Where the `Debug` texts of `read` and `written` first differ, with
/// some text around it (`None`: the same text). `Debug` prints every float
/// in its shortest round-trip form, so equal text is equal bits (`-0` and
/// `0` differ), where `==` would call `-0.0` and `0.0` equal.
pub fn debug_difference(read: &impl Debug, written: &impl Debug) -> Option<String> {
    let (a, b) = (format!("{read:?}"), format!("{written:?}"));
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let at = a
        .iter()
        .zip(&b)
        .position(|(x, y)| x != y)
        .or_else(|| (a.len() != b.len()).then(|| a.len().min(b.len())))?;
    let around = |s: &[char]| -> String {
        s[at.saturating_sub(80)..(at + 40).min(s.len())]
            .iter()
            .collect()
    };
    Some(format!(
        "read back:\n  ...{}...\nwritten:\n  ...{}...",
        around(&a),
        around(&b)
    ))
}

#[cfg(test)]
mod tests {
    use super::debug_difference;

    #[test]
    fn equal_text_is_no_difference_and_signed_zeros_differ() {
        assert_eq!(debug_difference(&[1.0f32, 0.0], &[1.0f32, 0.0]), None);
        let d = debug_difference(&[1.0f32, -0.0], &[1.0f32, 0.0]).unwrap();
        assert_eq!(
            d,
            "read back:\n  ...[1.0, -0.0]...\nwritten:\n  ...[1.0, 0.0]..."
        );
        // One text a prefix of the other: they differ where the shorter ends.
        assert!(debug_difference(&"ab", &"abc").is_some());
    }
}
