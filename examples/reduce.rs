//! Key reduction: fit the bundled motion capture with far fewer keys within
//! the default model-space tolerance, and print what it saves. The same
//! as `tcb reduce data/cmu-01_01.bvh --rotation hermite -o OUT.json` (the
//! skeleton with its End Sites, so the same height and tolerance).
//!
//! ```text
//! cargo run --release --example reduce
//! ```

const CMU: &str = include_str!("../data/cmu-01_01.bvh");

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bvh = tcb_io::bvh::Bvh::parse(CMU)?;
    let doc = bvh.to_clip_doc("cmu", tcb_core::RotationMode::Hermite)?;
    let clip = doc.build()?;
    let skeleton = bvh.skeleton_with_end_sites();
    let input = tcb_fit::reduce::Input {
        doc: &doc,
        clip: &clip,
        skeleton: Some(&skeleton),
    };
    let reduced = tcb_fit::reduce(input, &Default::default(), &|_, _| {})?;
    println!("{}", reduced.summary_line());
    let s = &reduced.settings;
    println!(
        "max error: the farthest a point at a joint or {:.3} units from it (the shell, about 3 cm \
         on a 1.7 m figure {:.1} units tall) moved, in the BVH's units, over every frame and 3 \
         inbetweens; allowed: {:.3e} units (about 0.1 mm); time in seconds",
        s.shell, s.height, s.tolerance
    );
    println!(
        "compiled runtime clip (hermite rotations): {} -> {} bytes ({:.2}x fewer), keys {} -> {}",
        reduced.before.bytes,
        reduced.after.bytes,
        reduced.before.bytes as f64 / reduced.after.bytes as f64,
        reduced.before.keys,
        reduced.after.keys
    );
    Ok(())
}
