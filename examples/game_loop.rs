//! A game loop on the bundled motion capture: a few characters, a fixed
//! time step, a cross-fade between two clips of one rig, and model-space
//! joint transforms through the skeleton, with the cost per frame.
//!
//! ```text
//! cargo run --release --example game_loop [-- --frames 600] [-- FILE.bvh]
//! ```

use std::sync::Arc;
use std::time::Instant;
use tcb_core::RotationMode;
use tcb_runtime::{Clip, Instance, Rig, SkeletonBinding, blend};

/// The CMU capture, built into the example so it runs from any directory.
const CMU: &str = include_str!("../data/cmu-01_01.bvh");

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frames: usize = match args.iter().position(|a| a == "--frames") {
        Some(i) => args.get(i + 1).ok_or("--frames needs a number")?.parse()?,
        None => 600,
    };
    let text = match args.iter().find(|a| a.ends_with(".bvh")) {
        Some(path) => std::fs::read_to_string(path)?,
        None => CMU.to_string(),
    };
    let bvh = tcb_io::bvh::Bvh::parse(&text)?;
    // Two clips of one rig: the capture as squad rotations (3ds Max TCB) and
    // as hermite rotations (glTF style). Real games blend a walk and a run.
    let walk = Arc::new(Clip::compile(
        &bvh.to_clip_doc("walk", RotationMode::Squad)?.build()?,
    ));
    let run = Arc::new(Clip::compile(
        &bvh.to_clip_doc("run", RotationMode::Hermite)?.build()?,
    ));
    let rig = Arc::new(Rig::from_skeleton(bvh.skeleton())?);
    let binding = SkeletonBinding::for_layout(bvh.skeleton().clone(), rig.layout());
    let joints = bvh.skeleton().joints().len();

    // Four characters, each with its two layers and its blended pose.
    struct Character {
        walk: Instance,
        run: Instance,
        phase: f64,
    }
    let mut characters: Vec<Character> = (0..4)
        .map(|i| {
            Ok(Character {
                walk: Instance::with_rig(walk.clone(), &rig)?,
                run: Instance::with_rig(run.clone(), &rig)?,
                phase: 1.7 * f64::from(i),
            })
        })
        .collect::<Result<_, tcb_runtime::RigError>>()?;
    let mut pose = rig.rest_pose();
    let mut local = vec![Default::default(); joints];
    let mut model = vec![glam::Affine3A::IDENTITY; joints];

    // A fixed 60 Hz step; the clock is a f64 in seconds.
    let dt = 1.0 / 60.0;
    let mut clock = 0.0f64;
    let mut spent = std::time::Duration::ZERO;
    let mut head_height = 0.0f32;
    // Look joints up once, not per frame.
    let head = bvh.skeleton().joint("Head").unwrap_or(0);
    for _ in 0..frames {
        clock += dt;
        let started = Instant::now();
        for c in &mut characters {
            let t = clock + c.phase;
            // Cross-fade from walk to run and back every 4 seconds.
            let w = (0.5 + 0.5 * (t * std::f64::consts::PI / 4.0).sin()) as f32;
            c.walk.sample(t);
            c.run.sample(t);
            blend(
                &mut pose,
                &[(c.walk.pose(), 1.0 - w), (c.run.pose(), w)],
                None,
            )?;
            binding.model_transforms(&pose, &mut local, &mut model)?;
            head_height = head_height.max(model[head].translation.y);
        }
        spent += started.elapsed();
    }
    let per_frame = spent.as_secs_f64() / frames.max(1) as f64;
    println!(
        "{frames} frames of {} characters ({joints} joints each): {:.2} us of wall clock per frame \
         for all of them, {:.1} ns per joint (each joint: two clips sampled, blended and composed \
         into model space); a 60 fps frame has 16,667 us",
        characters.len(),
        per_frame * 1e6,
        per_frame * 1e9 / (characters.len() * joints) as f64
    );
    println!("highest head: {head_height:.2} BVH units above the origin (the file's units)");
    Ok(())
}
