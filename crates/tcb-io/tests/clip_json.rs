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

/// Written through serde in the clip layout: one line per field of a track,
/// numbers in their shortest round-trip form (f32 values as f32, whole
/// numbers without `.0`), read back exactly.
#[test]
fn written_clips_are_laid_out_by_field_and_read_back_exactly() {
    let awkward = [0.1f32, -0.0, 1e-42, 16777216.0, f32::MAX, 1.0 / 3.0];
    let values: Vec<String> = awkward.iter().map(|x| format!("{x:e}")).collect();
    let text = format!(
        r#"{{"format": "tcb-clip/1", "name": "n", "defaults": {{"ends": "zero"}},
        "tracks": [{{"name": "s", "kind": "scalar", "times": [1e-9, 0.25, 1, 2, 3, 1e300],
        "values": [{}], "keys": [{{}}, {{"in": 2.5}}, {{}}, {{}}, {{"interp": "step"}}, {{}}],
        "post": "repeat"}}]}}"#,
        values.join(", ")
    );
    let doc = ClipDoc::parse(&text).unwrap();
    assert_eq!(doc.tracks[0].values[5][0], 1.0 / 3.0);
    let json = doc.to_json();
    let again = ClipDoc::parse(&json).unwrap();
    assert_eq!(again, doc);
    for (a, b) in again.tracks[0].values.iter().zip(&doc.tracks[0].values) {
        assert_eq!(a[0].to_bits(), b[0].to_bits(), "{json}");
    }
    let lines: Vec<&str> = json.lines().collect();
    assert_eq!(lines[0], "{");
    assert_eq!(lines[1], r#"  "format": "tcb-clip/1","#);
    assert!(
        lines.contains(&r#"      "times": [1e-9, 0.25, 1, 2, 3, 1e300],"#),
        "{json}"
    );
    assert!(
        lines.contains(&r#"      "values": [0.1, -0, 1e-42, 16777216, 3.4028235e38, 0.33333334],"#),
        "{json}"
    );
    assert!(
        lines.contains(&r#"      "keys": [{}, {"in": 2.5}, {}, {}, {"interp": "step"}, {}],"#),
        "{json}"
    );
    assert!(lines.contains(&r#"      "post": "repeat""#), "{json}");
    assert_eq!(*lines.last().unwrap(), "}");
}

fn error(text: &str) -> String {
    ClipDoc::parse(text).unwrap_err().to_string()
}

fn track(fields: &str) -> String {
    format!(r#"{{"format": "tcb-clip/1", "tracks": [{{"name": "bad", {fields}}}]}}"#)
}

/// Errors serde finds (types, shapes, unknown and missing fields) name the
/// track and the key as the checks after it do.
#[test]
fn serde_errors_name_the_track_and_key() {
    let cases = [
        (
            track(r#""kind": "scalar", "times": [0, "x"], "values": [1, 2]"#),
            r#"track 'bad': key 1: time: invalid type: string "x", expected a number"#,
        ),
        (
            track(
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "keys": [{}, {"tcb": [0, 1]}]"#,
            ),
            "track 'bad': key 1: tcb: invalid length 2",
        ),
        (
            track(
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "keys": [{}, {"bias": 1}]"#,
            ),
            r#"track 'bad': key 1: unknown field "bias""#,
        ),
        (
            track(r#""kind": "scalar", "values": [1, 2]"#),
            r#"track 'bad': missing field "times""#,
        ),
        (
            track(r#""kind": "vec9", "times": [0, 1], "values": [1, 2]"#),
            r#"track 'bad': unknown kind "vec9""#,
        ),
        (
            track(r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "pre": "loop""#),
            r#"track 'bad': unknown pre "loop" (expected one of: constant, reset"#,
        ),
        (
            track(r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "match_speed": 1"#),
            "track 'bad': match_speed: invalid type: integer",
        ),
        (
            track(
                r#""kind": "vec2", "times": [0, 1], "values": [[1, 2], [3, 4]], "keys": [{}, {"out": [1, 2, 3]}]"#,
            ),
            "track 'bad': key 1: out of a vec2 track must have 2 numbers, found 3",
        ),
        (
            track(
                r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "extras": {"a": [1e999]}"#,
            ),
            "track 'bad': extras 1e999 is not a finite number",
        ),
        (
            track(&format!(
                r#""kind": "vec3", "times": [0, 1], "values": [[1, 2, 3], [{}0]]"#,
                "0, ".repeat(99)
            )),
            "track 'bad': key 1: value of a vec3 track must have 3 numbers, found 100",
        ),
        (
            r#"{"format": "tcb-clip/1", "defaults": {"ends": 3}, "tracks": []}"#.to_owned(),
            "defaults: ends: invalid type: integer",
        ),
        (
            r#"{"format": "tcb-clip/1", "tracks": []} []"#.to_owned(),
            "line 1, column 40: trailing characters",
        ),
        (
            r#"{"format": 2, "tracks": [], "other": 1}"#.to_owned(),
            "format is 2, expected \"tcb-clip/1\"",
        ),
    ];
    for (text, message) in cases {
        let err = error(&text);
        assert!(
            err.starts_with(message),
            "{text}\n  gave {err}\n  wanted {message}"
        );
    }
}

/// A clip nested 10,000 deep is refused with the limit named, wherever the
/// nesting is, and nothing recurses on it: typed fields stop at the first
/// level that is not what the contract says, and `extras` (walked, not
/// kept) stops at the JSON reader's 128 levels. Without that limit
/// (serde_json's `disable_recursion_limit`) the `extras` cases fail: the
/// walk would go 10,000 deep.
#[test]
fn deep_nesting_is_refused() {
    let deep = format!("{}{}", "[".repeat(10_000), "]".repeat(10_000));
    let err = error(&format!(
        r#"{{"format": "tcb-clip/1", "extras": {deep}, "tracks": []}}"#
    ));
    assert!(err.contains("nested deeper than 128 levels"), "{err}");
    let err = error(&track(&format!(
        r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "extras": {{"mine": {deep}}}"#
    )));
    assert!(err.contains("nested deeper than 128 levels"), "{err}");
    let err = error(&track(&format!(
        r#""kind": "scalar", "times": [0, 1], "values": [{deep}, 2]"#
    )));
    assert!(err.starts_with("track 'bad': key 0: value"), "{err}");
    let err = error(&format!(r#"{{"format": {deep}, "tracks": []}}"#));
    assert!(err.starts_with("format: invalid type: sequence"), "{err}");
    // Shallow extras are the user's, and fine.
    let ok = track(
        r#""kind": "scalar", "times": [0, 1], "values": [1, 2], "extras": {"a": [[1, {"b": null}]]}"#,
    );
    ClipDoc::parse(&ok).unwrap().build().unwrap();
}
