//! The instruction set of the sampling kernels, chosen at run time.
//!
//! A default x86-64 build runs `wide`'s `f32x8` as two SSE2 halves. Where
//! the CPU has AVX2 and FMA (and BMI1, BMI2, LZCNT and POPCNT, which
//! every such CPU has: x86-64-v3's set), the group kernels (vector channels, and
//! rotation values), the expansion of 16-bit controls, the loose
//! tracks' blocks and the packed clips' decoder run an instance compiled
//! for them instead, on
//! [`tcb_core::simd::w8::W8`], `D4` and `I8`: the same
//! formulas, the same IEEE operations per lane in the same order, so the
//! same bits (`tests/isa.rs` compares the two on every scenario shape).
//! Where the CPU has AVX-512 F, VL, BW and DQ too, the decoder runs an
//! instance compiled with them ([`Simd::Avx512`]; the same source, which
//! the compiler then gives 32 registers and AVX-512's instructions on
//! 256-bit registers: no 512-bit ones, which slow the work beside them on
//! Intel cores; `tools/check/no-512-bit.sh` checks the binary).
//! Builds with `-C target-cpu=x86-64-v3` or `native` have `wide` in AVX2
//! already: their group kernels stay `wide`'s (the `W8` instance took 11%
//! more instructions on `character-hermite` in such a build), and their
//! decoder runs the AVX2 instance, which gathers each key's residuals from
//! the stream where the baseline unpacks them lane by lane.
//!
//! ```
//! use tcb_runtime::Simd;
//! let now = tcb_runtime::simd();
//! tcb_runtime::force_baseline_simd(true);
//! assert_eq!(tcb_runtime::simd(), Simd::Baseline);
//! tcb_runtime::force_baseline_simd(false);
//! assert_eq!(tcb_runtime::simd(), now);
//! ```

use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};

/// Which instance of the kernels sampling runs (more may come: match
/// with a wildcard arm).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Simd {
    /// The build's own instructions (`wide` as compiled).
    Baseline,
    /// AVX2 and FMA (with x86-64-v3's BMI1, BMI2, LZCNT and POPCNT):
    /// detected at run time in a default x86-64 build, or enabled by the
    /// build.
    Avx2,
    /// As [`Avx2`](Self::Avx2), and the packed clips' decoder compiled
    /// with AVX-512 F, VL, BW and DQ too (the same source; the compiler
    /// then has 32 registers and AVX-512's instructions, on 256-bit
    /// registers): detected at run time, unless
    /// [`force_no_avx512`] says otherwise.
    Avx512,
}

/// What [`avx2`] answers: not yet detected, the AVX2 instance, or the
/// baseline (detected or forced).
const UNKNOWN: u8 = 0;
const AVX2: u8 = 1;
const BASELINE: u8 = 2;
const AVX512: u8 = 3;
static STATE: AtomicU8 = AtomicU8::new(UNKNOWN);
/// [`force_no_avx512`]'s switch.
static NO_AVX512: AtomicBool = AtomicBool::new(false);

/// The instance sampling runs now, on this CPU and in this build.
pub fn simd() -> Simd {
    match (avx2(), avx512()) {
        (true, true) => Simd::Avx512,
        (true, false) => Simd::Avx2,
        _ => Simd::Baseline,
    }
}

/// Run the packed decoder's AVX2 instance even where AVX-512 was detected
/// (`true`), or go back to detection (`false`), for every thread: to
/// compare the instances, to count instructions under valgrind (which
/// does not decode AVX-512), or where AVX-512 costs clock speed. A
/// forced baseline ([`force_baseline_simd`]) stays forced.
pub fn force_no_avx512(on: bool) {
    // Only the switch: `avx512` reads it beside the detected state, so no
    // call here can undo another thread's `force_baseline_simd`.
    NO_AVX512.store(on, Ordering::Relaxed);
}

/// Run the build's own instructions even where AVX2 was detected (`true`),
/// or go back to detection (`false`), for every thread: to compare the two
/// instances, or to count the same instructions on every CPU (the
/// instruction-count gate does). Takes effect from the next kernel call.
pub fn force_baseline_simd(on: bool) {
    STATE.store(if on { BASELINE } else { detect() }, Ordering::Relaxed);
}

/// Whether the group kernels (and the 16-bit expansion and the loose
/// lanes' blocks) run the AVX2 instance: in builds without AVX2, where it
/// was detected (module docs).
#[inline(always)]
pub(crate) fn avx2_kernels() -> bool {
    !cfg!(target_feature = "avx2") && avx2()
}

/// Proof that [`avx2_kernels`] said yes: a function that takes one may run
/// AVX2 and FMA instructions. Only [`Avx2Kernels::now`] makes one.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx2Kernels(());

impl Avx2Kernels {
    /// One where [`avx2_kernels`] says so, for a caller that asks once and
    /// passes it on to several kernels.
    #[inline(always)]
    pub(crate) fn now() -> Option<Self> {
        avx2_kernels().then_some(Avx2Kernels(()))
    }
}

/// Whether the AVX2 instance of the packed decoder runs (detected, or
/// enabled by the build, and not forced off): one load once detected.
#[inline(always)]
pub(crate) fn avx2() -> bool {
    match STATE.load(Ordering::Relaxed) {
        AVX2 | AVX512 => true,
        UNKNOWN => first() != BASELINE,
        _ => false,
    }
}

/// Whether the packed decoder runs its AVX-512 instance (detected with
/// AVX2, and not forced off by [`force_no_avx512`]). True only where the
/// CPU has AVX-512 F, VL, BW and DQ: only `detect` finds `AVX512`.
#[inline(always)]
pub(crate) fn avx512() -> bool {
    let detected = match STATE.load(Ordering::Relaxed) {
        AVX512 => true,
        UNKNOWN => first() == AVX512,
        _ => false,
    };
    detected && !NO_AVX512.load(Ordering::Relaxed)
}

/// Whether this CPU has the decoder's AVX2 instance's features (AVX2 and
/// FMA), and the AVX-512 instance's, whatever is forced: what the
/// instances' debug checks read, since a switch that another thread
/// flips while one runs does not make it run on a CPU without them.
#[cfg(target_arch = "x86_64")]
pub(crate) fn cpu_avx2() -> bool {
    detect() != BASELINE
}

#[cfg(target_arch = "x86_64")]
pub(crate) fn cpu_avx512() -> bool {
    detect() == AVX512
}

/// Whether BMI2's `pdep` is one fast instruction here, as on Intel and
/// on AMD from Zen 3 on; on Zen 1 and Zen 2 (AMD family 0x17, Hygon 0x18)
/// it is microcoded, at a cost per set bit of its mask, and the decoder's
/// headers spread their fields with shifts and masks instead.
#[cfg(target_arch = "x86_64")]
pub(crate) fn fast_pdep() -> bool {
    static FAST: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *FAST.get_or_init(|| !slow_pdep_cpu())
}

/// AMD or Hygon before family 0x19 (`cpuid` leaves 0 and 1).
#[cfg(target_arch = "x86_64")]
#[cold]
fn slow_pdep_cpu() -> bool {
    use std::arch::x86_64::__cpuid;
    let v = __cpuid(0);
    let mut vendor = [0u8; 12];
    for (out, r) in vendor.chunks_exact_mut(4).zip([v.ebx, v.edx, v.ecx]) {
        out.copy_from_slice(&r.to_le_bytes());
    }
    slow_pdep(&vendor, __cpuid(1).eax)
}

/// [`slow_pdep_cpu`] from the vendor string (`cpuid` leaf 0's `ebx edx
/// ecx`) and leaf 1's `eax` (the family: base, plus extended where base
/// is 0xf).
#[cfg(target_arch = "x86_64")]
fn slow_pdep(vendor: &[u8; 12], eax: u32) -> bool {
    if vendor != b"AuthenticAMD" && vendor != b"HygonGenuine" {
        return false;
    }
    let base = (eax >> 8) & 0xf;
    let family = if base == 0xf {
        base + ((eax >> 20) & 0xff)
    } else {
        base
    };
    family < 0x19
}

/// The first call: detect, and remember (out of line).
#[cold]
#[inline(never)]
fn first() -> u8 {
    let state = detect();
    STATE.store(state, Ordering::Relaxed);
    state
}

/// The CPU has AVX2 and FMA (constant where the build enables them) and
/// the scalar bit instructions every such CPU has (x86-64-v3's BMI1, BMI2,
/// LZCNT and POPCNT, which the decoder's instances compile with), and
/// AVX-512 F, VL, BW and DQ besides.
fn detect() -> u8 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
        && std::arch::is_x86_feature_detected!("lzcnt")
        && std::arch::is_x86_feature_detected!("popcnt")
    {
        let avx512 = std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx512bw")
            && std::arch::is_x86_feature_detected!("avx512dq");
        return if avx512 { AVX512 } else { AVX2 };
    }
    BASELINE
}

#[cfg(test)]
mod tests {
    /// Leaf 1's `eax` of real parts: Zen 1, Zen 2 and Hygon Dhyana have a
    /// microcoded `pdep`; Zen 3 and later, and Intel, do not.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn pdep_is_slow_on_zen_1_and_2_only() {
        use super::slow_pdep;
        let (amd, hygon, intel) = (b"AuthenticAMD", b"HygonGenuine", b"GenuineIntel");
        assert!(slow_pdep(amd, 0x0080_0F12), "Zen 1 (family 0x17)");
        assert!(slow_pdep(amd, 0x0083_0F10), "Zen 2 (family 0x17)");
        assert!(slow_pdep(hygon, 0x0090_0F01), "Hygon (family 0x18)");
        assert!(!slow_pdep(amd, 0x00A0_0F11), "Zen 3 (family 0x19)");
        assert!(!slow_pdep(amd, 0x00A1_0F11), "Zen 4 (family 0x19)");
        assert!(!slow_pdep(amd, 0x00B4_0F40), "Zen 5 (family 0x1A)");
        assert!(!slow_pdep(intel, 0x0008_06F8), "Sapphire Rapids");
        assert!(!slow_pdep(intel, 0x0000_0F41), "an Intel family 0xf part");
    }
}
