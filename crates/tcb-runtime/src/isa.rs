//! Which instructions the sampling pass runs, chosen when it first runs.
//!
//! `wide` picks its instructions when the crate is compiled, from the
//! target features: a default x86-64 build has SSE2 and nothing newer, so
//! every block of eight lanes is two SSE halves in the two-operand form,
//! with copies between registers. The sampling pass is therefore compiled
//! twice from the same code: once for the build's own features and once
//! with AVX2 and FMA enabled (three-operand VEX forms; `wide`'s lanes are
//! still the build's, so every operation and its order, and so every
//! result, is the same bit for bit). The second runs on CPUs that have
//! those features. A build with them enabled at compile time
//! (`-C target-cpu=native` on such a CPU) has only one pass.
//!
//! [`set_isa`] picks one by hand: to compare the two, or to pin a
//! benchmark or an instruction count to one path.
//!
//! ```
//! use tcb_runtime::isa::{Isa, isa, set_isa};
//! let chosen = isa();
//! set_isa(Isa::Baseline).unwrap(); // always available
//! assert_eq!(isa(), Isa::Baseline);
//! set_isa(chosen).unwrap();
//! ```

use std::sync::atomic::{AtomicU8, Ordering};

/// An instruction set the sampling pass is compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Isa {
    /// The build's own target features (SSE2 in a default x86-64 build).
    Baseline,
    /// x86-64 with AVX2 and FMA, detected at run time.
    Avx2,
}

impl Isa {
    /// Every instruction set, baseline first.
    pub const ALL: [Isa; 2] = [Isa::Baseline, Isa::Avx2];

    /// Its name: `baseline` or `avx2`.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Baseline => "baseline",
            Isa::Avx2 => "avx2",
        }
    }

    /// The one named `name` ([`Isa::name`]).
    pub fn from_name(name: &str) -> Option<Isa> {
        Isa::ALL.into_iter().find(|i| i.name() == name)
    }

    /// Whether this CPU can run it.
    pub fn available(self) -> bool {
        match self {
            Isa::Baseline => true,
            Isa::Avx2 => avx2_detected(),
        }
    }

    /// Whether the build already has it at compile time (then the two
    /// passes are the same code).
    pub fn compiled_in(self) -> bool {
        match self {
            Isa::Baseline => true,
            Isa::Avx2 => cfg!(all(
                target_arch = "x86_64",
                target_feature = "avx2",
                target_feature = "fma"
            )),
        }
    }
}

impl std::fmt::Display for Isa {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The best instruction set this CPU runs.
pub fn detect() -> Isa {
    if avx2_detected() {
        Isa::Avx2
    } else {
        Isa::Baseline
    }
}

fn avx2_detected() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// 0: not chosen yet; otherwise 1 + the index in [`Isa::ALL`].
static CHOSEN: AtomicU8 = AtomicU8::new(0);

/// The instruction set sampling runs: [`set_isa`]'s choice, or else
/// [`detect`]'s (once, on first use).
#[inline]
pub fn isa() -> Isa {
    match CHOSEN.load(Ordering::Relaxed) {
        1 => Isa::Baseline,
        2 => Isa::Avx2,
        _ => {
            let d = detect();
            CHOSEN.store(code(d), Ordering::Relaxed);
            d
        }
    }
}

fn code(i: Isa) -> u8 {
    match i {
        Isa::Baseline => 1,
        Isa::Avx2 => 2,
    }
}

/// Sampling in every thread runs `i` from now on; an error, and no change,
/// if this CPU cannot run it.
pub fn set_isa(i: Isa) -> Result<(), IsaError> {
    if !i.available() {
        return Err(IsaError(i));
    }
    CHOSEN.store(code(i), Ordering::Relaxed);
    Ok(())
}

/// [`set_isa`] asked for an instruction set this CPU lacks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IsaError(pub Isa);

impl std::fmt::Display for IsaError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "this CPU cannot run the {} sampling pass", self.0)
    }
}

impl std::error::Error for IsaError {}

/// Proof that sampling runs the AVX2 pass: [`isa`] is [`Isa::Avx2`], so
/// this CPU has AVX2 and FMA. Only [`Avx2::chosen`] makes one.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx2(());

impl Avx2 {
    /// One if [`isa`] is [`Isa::Avx2`] (never in a build that has AVX2 and
    /// FMA at compile time: its baseline pass is already that).
    #[inline(always)]
    pub(crate) fn chosen() -> Option<Avx2> {
        if Isa::Avx2.compiled_in() || !cfg!(target_arch = "x86_64") || isa() != Isa::Avx2 {
            return None;
        }
        Some(Avx2(()))
    }

    /// Run `f` with AVX2 and FMA enabled: `f`'s body, and whatever it
    /// inlines, is compiled for them (so `f` is an `#[inline(always)]`
    /// closure, and the kernels it calls are inlined).
    #[inline(always)]
    pub(crate) fn run<R>(self, f: impl FnOnce() -> R) -> R {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: an `Avx2` exists only when `isa()` was `Avx2`, which
            // `detect` or `set_isa` chose only after `avx2_detected()`
            // held: this CPU has the features `avx2` enables.
            #[allow(unsafe_code)]
            unsafe {
                avx2(f)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        f()
    }
}

/// `f` with AVX2 and FMA enabled.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma")]
fn avx2<R>(f: impl FnOnce() -> R) -> R {
    f()
}
