//! Clips more than one of tcb-runtime's test files build (each file uses
//! some of them).
#![allow(dead_code)]

use glam::Quat;
use tcb_core::{KeyParams, NamedTrack, RotationMode, RotationTrack, TrackData, TrackSettings};

/// `tracks` `hermite` rotations on keys 0, 1, 2, the one at `at` with
/// explicit tangents of 2.3e36 at its middle key: the cubic's squared
/// length overflows f32 there (alone it is a loose lane; among 9 or more
/// rotations it takes the group kernel, whose range check redoes the
/// block scaled).
pub fn huge_tangent_rotations(tracks: usize, at: usize) -> tcb_core::SourceClip {
    let t = vec![0.0, 1.0, 2.0];
    let q = vec![
        Quat::from_rotation_x(0.3),
        Quat::from_rotation_y(1.2),
        Quat::IDENTITY,
    ];
    let huge = Quat::from_xyzw(2.3e36, 1.9, 1.9, 7.0);
    let s = TrackSettings {
        rotation: RotationMode::Hermite,
        ..TrackSettings::default()
    };
    let named = (0..tracks)
        .map(|i| {
            let mut keys = vec![KeyParams::default(); 3];
            if i == at {
                keys[1].tangent_in = Some(huge);
                keys[1].tangent_out = Some(huge);
            }
            let track =
                RotationTrack::new(t.clone(), q.clone(), keys, &s).expect("finite tangents");
            NamedTrack {
                name: format!("r{i}"),
                data: TrackData::Quat(track),
            }
        })
        .collect();
    tcb_core::SourceClip::new("huge", named).expect("unique track names")
}

/// The bundled CMU capture (hermite), and it quantized with steps of 2^-14
/// (rotations) and 2^-8 (the root translation, in the clip's units).
pub fn quantized_cmu() -> (tcb_core::SourceClip, tcb_runtime::PackSource) {
    let bvh = include_str!("../../../../data/cmu-01_01.bvh");
    let bvh = tcb_io::bvh::Bvh::parse(bvh).unwrap();
    let clip = bvh
        .to_clip_doc("cmu", RotationMode::Hermite)
        .unwrap()
        .build()
        .unwrap();
    let steps: Vec<f32> = clip
        .tracks()
        .iter()
        .map(|t| {
            if t.name.ends_with("translation") {
                1.0 / 256.0
            } else {
                1.0 / 16384.0
            }
        })
        .collect();
    let source = tcb_runtime::PackSource::quantize(&clip, &steps).unwrap();
    (clip, source)
}
