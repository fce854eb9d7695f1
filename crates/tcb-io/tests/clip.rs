//! The clip file's `hemisphere` setting: parsed, applied, written back.

use tcb_io::ClipDoc;

const CLIP: &str = r#"{"format": "tcb-clip/1", "defaults": {"hemisphere": "keep"},
 "tracks": [
  {"name": "a.rotation", "kind": "quat", "rotation": "hermite", "times": [0, 1], "values": [[0,0,0,1],[0,0,-0.2588190,-0.9659258]]},
  {"name": "b.rotation", "kind": "quat", "hemisphere": "nearest", "times": [0, 1], "values": [[0,0,0,1],[0,0,-0.2588190,-0.9659258]]}
 ]}"#;

#[test]
fn hemisphere_round_trips_and_is_applied() {
    let doc = ClipDoc::parse(CLIP).unwrap();
    assert_eq!(doc.defaults.hemisphere, Some(tcb_core::Hemisphere::Keep));
    assert_eq!(
        doc.tracks[1].settings.hemisphere,
        Some(tcb_core::Hemisphere::Nearest)
    );
    let again = ClipDoc::parse(&doc.to_json()).unwrap();
    assert_eq!(again, doc);
    let clip = doc.build().unwrap();
    let mut row = [0.0f32; 8];
    clip.sample_into(1.0, &mut row, None);
    // Kept as written, and flipped to the first key's hemisphere.
    assert!(row[3] < 0.0 && row[7] > 0.0, "{row:?}");
}

#[test]
fn a_bad_hemisphere_is_a_clear_error() {
    let bad = CLIP.replace(r#""hemisphere": "nearest""#, r#""hemisphere": "shortest""#);
    let err = ClipDoc::parse(&bad).unwrap_err().to_string();
    assert!(err.contains("hemisphere"), "{err}");
    assert!(err.contains("nearest") && err.contains("keep"), "{err}");
}
