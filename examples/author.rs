//! Author a clip in code with the paper's presets, write it as a clip file,
//! read it back and sample it.
//!
//! ```text
//! cargo run --example author [-- OUT.json]
//! ```

use tcb_core::Tcb;
use tcb_io::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("tcb-author.json"));
    // A ball: up, a corner where it hits (continuity -1, the paper's
    // `LINEAR` preset), an overshoot after it (`OVERSHOOT`), then a stop
    // (`STOP`: tension 1).
    let key = |tcb: Tcb| KeyDoc {
        tcb: Some(tcb.to_array()),
        ..KeyDoc::default()
    };
    let doc = ClipDoc {
        name: "authored".into(),
        defaults: SettingsDoc::default(),
        tracks: vec![TrackDoc {
            name: "ball.translation".into(),
            kind: tcb_core::TrackKind::Vec3,
            times: vec![0.0, 0.5, 1.0, 1.4, 2.0],
            values: vec![
                [0.0, 0.0, 0.0, 0.0],
                [1.0, 2.0, 0.0, 0.0],
                [2.0, 0.0, 0.0, 0.0],
                [2.6, 0.8, 0.0, 0.0],
                [3.0, 0.0, 0.0, 0.0],
            ],
            keys: vec![
                key(Tcb::DEFAULT),
                key(Tcb::DEFAULT),
                key(Tcb::LINEAR),
                key(Tcb::OVERSHOOT),
                key(Tcb::STOP),
            ],
            settings: SettingsDoc::default(),
        }],
        skeleton: None,
    };
    tcb_io::write_clip_doc(&doc, &out)?;
    let clip = tcb_io::load(&out)?.clip;
    println!(
        "wrote {}; sampled back (positions in the clip's units, velocities in units per second):",
        out.display()
    );
    let mut row = [0.0f32; 3];
    let mut vel = [0.0f32; 3];
    for i in 0..=8 {
        let t = f64::from(i) * 0.25;
        clip.sample_into(t, &mut row, Some(&mut vel));
        println!("  t = {t:4.2} s: position {row:6.3?}, velocity {vel:7.3?}");
    }
    Ok(())
}
