//! Many instances at once with rayon; the result is identical to sampling
//! them one after another (each instance is independent).

use crate::instance::Instance;
use rayon::prelude::*;
use std::fmt;

/// [`sample_all`] given as many times as instances, or not: nothing is
/// sampled then.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LengthMismatch {
    /// Instances given.
    pub instances: usize,
    /// Times given.
    pub times: usize,
}

impl fmt::Display for LengthMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} instances and {} times: give one time per instance",
            self.instances, self.times
        )
    }
}

impl std::error::Error for LengthMismatch {}

fn check(instances: &[Instance], times: &[f64]) -> Result<(), LengthMismatch> {
    if instances.len() == times.len() {
        Ok(())
    } else {
        Err(LengthMismatch {
            instances: instances.len(),
            times: times.len(),
        })
    }
}

/// Sample `instances[i]` at `times[i]`, in parallel; as many times as
/// instances, else an error and nothing sampled.
///
/// In a pool of one thread (`RAYON_NUM_THREADS=1`, or a one-thread pool
/// this is `install`ed in) it is the plain loop of [`sample_all_sequential`]
/// on the calling thread: handing each frame to the pool's one worker and
/// waiting for it would cost the hand-over and gain nothing.
///
/// ```
/// # use std::sync::Arc;
/// # let text = r#"{"format": "tcb-clip/1", "tracks": [{"name": "x", "kind": "scalar", "times": [0, 1], "values": [0, 1]}]}"#;
/// # let clip = Arc::new(tcb_runtime::Clip::compile(&tcb_io::ClipDoc::parse(text).unwrap().build().unwrap()));
/// let mut crowd: Vec<_> = (0..100).map(|_| tcb_runtime::Instance::new(clip.clone())).collect();
/// let times: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
/// tcb_runtime::batch::sample_all(&mut crowd, &times).unwrap();
/// assert!(tcb_runtime::batch::sample_all(&mut crowd, &times[..99]).is_err());
/// ```
pub fn sample_all(instances: &mut [Instance], times: &[f64]) -> Result<(), LengthMismatch> {
    if rayon::current_num_threads() <= 1 {
        return sample_all_sequential(instances, times);
    }
    check(instances, times)?;
    instances
        .par_iter_mut()
        .zip(times.par_iter())
        .for_each(|(inst, &t)| {
            inst.sample(t);
        });
    Ok(())
}

/// As [`sample_all`], one after another on this thread.
pub fn sample_all_sequential(
    instances: &mut [Instance],
    times: &[f64],
) -> Result<(), LengthMismatch> {
    check(instances, times)?;
    for (inst, &t) in instances.iter_mut().zip(times) {
        inst.sample(t);
    }
    Ok(())
}
