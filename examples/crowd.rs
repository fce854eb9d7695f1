//! A crowd: a thousand instances of one clip at their own phases, sampled
//! in parallel with rayon (`tcb_runtime::batch`), against one thread.
//!
//! ```text
//! cargo run --release --example crowd [-- --frames 120]
//! ```

use std::sync::Arc;
use std::time::Instant;
use tcb_runtime::{Clip, Instance, batch};

const CMU: &str = include_str!("../data/cmu-01_01.bvh");

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frames: usize = match args.iter().position(|a| a == "--frames") {
        Some(i) => args.get(i + 1).ok_or("--frames needs a number")?.parse()?,
        None => 120,
    };
    let bvh = tcb_io::bvh::Bvh::parse(CMU)?;
    let clip = bvh
        .to_clip_doc("cmu", tcb_core::RotationMode::Hermite)?
        .build()?;
    let end = clip.time_range().map_or(1.0, |r| r.1);
    let clip = Arc::new(Clip::compile(&clip));
    let n = 1000;
    let mut crowd: Vec<Instance> = (0..n).map(|_| Instance::new(clip.clone())).collect();
    let phases: Vec<f64> = (0..n).map(|i| (i as f64 * 0.618_034 * end) % end).collect();
    let mut times = vec![0.0; n];
    for (name, parallel) in [("one thread", false), ("rayon", true)] {
        let started = Instant::now();
        for f in 0..frames {
            let t = f as f64 / 60.0;
            for (time, phase) in times.iter_mut().zip(&phases) {
                *time = t + phase;
            }
            if parallel {
                batch::sample_all(&mut crowd, &times).expect("a time per instance");
            } else {
                batch::sample_all_sequential(&mut crowd, &times).expect("a time per instance");
            }
        }
        let per = started.elapsed().as_secs_f64() / frames.max(1) as f64;
        println!(
            "{name:>10}: {n} instances, {:.3} ms per frame ({} threads available)",
            per * 1e3,
            rayon::current_num_threads()
        );
    }
    Ok(())
}
