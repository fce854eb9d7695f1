//! The sampling pass, blending and additive layers compiled for each
//! instruction set (`tcb_runtime::isa`) give the same poses bit for bit. One test in its own process, because
//! it switches the process-wide choice.

use std::sync::Arc;
use tcb_core::RotationMode;
use tcb_runtime::isa::{Isa, detect, isa, set_isa};
use tcb_runtime::{BlendMask, Clip, CompileOptions, Instance};

mod common;
use common::*;

/// Every value and velocity of `clip` at `times` (in that order, so
/// forward runs stream and jumps seek), with and without velocities, and
/// each pose blended with, and added to, another time's.
fn rows(clip: &Arc<Clip>, channels: usize, times: &[f64]) -> Vec<u32> {
    let mut with = Instance::new(clip.clone()).with_velocities();
    let mut plain = Instance::new(clip.clone());
    let (mut v, mut d) = (vec![0.0f32; channels], vec![0.0f32; channels]);
    let mut other = Instance::new(clip.clone()).with_velocities();
    let mask = BlendMask::new(clip, |id| (id.index() % 3) as f32 * 0.4);
    let mut out = Vec::new();
    let mut put = |p: &tcb_runtime::Pose, out: &mut Vec<u32>| {
        p.write_row(&mut v, Some(&mut d));
        out.extend(v.iter().chain(&d).map(|x| x.to_bits()));
    };
    for &t in times {
        let a = with.sample(t).clone();
        put(&a, &mut out);
        put(plain.sample(t), &mut out);
        // Blended with and added to another time's pose.
        let b = other.sample(0.7 * t + 0.1);
        let mut blended = a.clone();
        tcb_runtime::blend(&mut blended, &[(&a, 0.3), (b, 0.7)], None).unwrap();
        put(&blended, &mut out);
        tcb_runtime::blend(&mut blended, &[(&a, 1.0), (b, 1.0)], Some(&[&mask, &mask])).unwrap();
        put(&blended, &mut out);
        let mut added = a.clone();
        tcb_runtime::blend::add(&mut added, b, &a, 0.5, Some(&mask)).unwrap();
        put(&added, &mut out);
    }
    out
}

#[test]
fn every_pass_samples_the_same_bits() {
    assert_eq!(detect() == Isa::Avx2, Isa::Avx2.available());
    assert!(Isa::Baseline.available());
    let passes: Vec<Isa> = Isa::ALL.into_iter().filter(|i| i.available()).collect();
    if passes.len() < 2 {
        eprintln!("only the baseline pass runs on this CPU: nothing to compare");
    }
    let mut clips = Vec::new();
    for channels in [0, 1, 7, 8, 9, 63, 64, 65] {
        for seed in 0..6 {
            let clip = random_clip(seed * 1000 + channels as u64 + 17, channels);
            if !clip.tracks().is_empty() {
                clips.push(clip);
            }
        }
    }
    let bvh = include_str!("../../../data/cmu-01_01.bvh");
    let bvh = tcb_io::bvh::Bvh::parse(bvh).unwrap();
    for mode in [RotationMode::Squad, RotationMode::Hermite] {
        clips.push(bvh.to_clip_doc("cmu", mode).unwrap().build().unwrap());
    }
    let exact = CompileOptions {
        exact_velocities: true,
        ..Default::default()
    };
    let chosen = isa();
    for (i, clip) in clips.iter().enumerate() {
        let mut rng = Rng(i as u64 + 1);
        let mut times = sample_times(&mut rng, clip);
        times.truncate(times.len().min(400));
        let mut forward: Vec<f64> = times.iter().copied().filter(|t| t.is_finite()).collect();
        forward.sort_by(f64::total_cmp);
        times.extend(forward);
        let n = clip.channel_count();
        for compiled in [Clip::compile(clip), Clip::compile_with(clip, &exact)] {
            let compiled = Arc::new(compiled);
            let mut first: Option<Vec<u32>> = None;
            for &pass in &passes {
                set_isa(pass).unwrap();
                assert_eq!(isa(), pass);
                let got = rows(&compiled, n, &times);
                match &first {
                    None => first = Some(got),
                    Some(want) => {
                        let at = want.iter().zip(&got).position(|(a, b)| a != b);
                        assert!(
                            at.is_none() && want.len() == got.len(),
                            "clip {} ({}): the {pass} pass differs from the baseline at row \
                             value {at:?}",
                            i,
                            clip.name()
                        );
                    }
                }
            }
        }
    }
    set_isa(chosen).unwrap();
}
