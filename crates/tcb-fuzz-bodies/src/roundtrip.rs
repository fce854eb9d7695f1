//! The `roundtrip` target: every clip document the reader accepts (or a
//! structured one whose numbers JSON can hold) is written and read back
//! bit for bit.

use arbitrary::{Arbitrary, Unstructured};
use tcb_io::ClipDoc;

/// The first byte chooses: JSON text (the rest, as `clip_json` reads it)
/// or a structured document (as `runtime`'s, with times and values
/// sometimes replaced by arbitrary finite bit patterns, subnormals and
/// ±MAX included). Components past a track's kind and keys that say
/// nothing are not part of a document (see `cut_unused`). A document the
/// reader accepts, or a structured one
/// whose numbers are all finite, writes JSON that reads back to the same
/// document bit for bit (compared by `{:?}`, which prints every f64 and f32
/// in its shortest round-trip form and tells -0 from 0), and writing that
/// again gives the same text. A document that builds still builds.
pub fn roundtrip(data: &[u8]) {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let mut doc = if first % 2 == 0 {
        let Ok(text) = std::str::from_utf8(rest) else {
            return;
        };
        let Ok(doc) = ClipDoc::parse(text) else {
            return;
        };
        doc
    } else {
        let mut u = Unstructured::new(rest);
        let Ok(mut doc) = crate::inputs::arbitrary_doc(&mut u) else {
            return;
        };
        for t in &mut doc.tracks {
            if u.ratio(1, 2u8).unwrap_or(false) {
                for x in &mut t.times {
                    *x = finite_f64(&mut u, *x);
                }
            }
            if u.ratio(1, 2u8).unwrap_or(false) {
                for v in &mut t.values {
                    for x in v.iter_mut() {
                        *x = finite_f32(&mut u, *x);
                    }
                }
            }
        }
        cut_unused(&mut doc);
        if !all_finite(&doc) {
            return;
        }
        doc
    };
    cut_unused(&mut doc);
    let text = doc.to_json();
    let back = ClipDoc::parse(&text)
        .unwrap_or_else(|e| panic!("the written clip does not read back: {e}\n{text}"));
    let (a, b) = (format!("{doc:?}"), format!("{back:?}"));
    if a != b {
        panic!("{}", first_difference(&a, &b));
    }
    assert_eq!(back.to_json(), text, "written again, the text differs");
    if doc.build().is_ok() {
        back.build().expect("the clip built before it was written");
    }
}

/// Components past a track's kind's zeroed: they are not part of the
/// document (the writer writes `kind.dim()` of them; the reader pads).
/// Keys that all say nothing dropped (the writer leaves `keys` out then).
pub(crate) fn cut_unused(doc: &mut ClipDoc) {
    for t in &mut doc.tracks {
        if t.keys.iter().all(|k| *k == tcb_io::KeyDoc::default()) {
            t.keys.clear();
        }
        let dim = t.kind.dim();
        let cut = |v: &mut [f32; 4]| v[dim..].iter_mut().for_each(|x| *x = 0.0);
        t.values.iter_mut().for_each(cut);
        for k in &mut t.keys {
            k.tangent_in.as_mut().map(cut);
            k.tangent_out.as_mut().map(cut);
        }
    }
}

/// Where two `{:?}` renderings first differ, with some context.
pub(crate) fn first_difference(a: &str, b: &str) -> String {
    let at = a
        .bytes()
        .zip(b.bytes())
        .position(|(x, y)| x != y)
        .unwrap_or(a.len().min(b.len()));
    let from = a[..at].rfind('[').unwrap_or(0).max(at.saturating_sub(80));
    let show = |s: &str| {
        s.get(from..(at + 60).min(s.len()))
            .unwrap_or("")
            .to_string()
    };
    format!(
        "read back differs from what was written:\n written: ...{}\n read:    ...{}",
        show(a),
        show(b)
    )
}

fn finite_f64(u: &mut Unstructured, x: f64) -> f64 {
    let y = match u.int_in_range(0..=3u8).unwrap_or(0) {
        0 => f64::from_bits(u64::arbitrary(u).unwrap_or(0)),
        1 => crate::edges::ulps(
            *u.choose(&[
                0.1,
                1.0 / 3.0,
                1e6 + 0.1,
                5e-324,
                f64::MAX,
                -f64::MAX,
                2.2250738585072014e-308,
            ])
            .unwrap_or(&0.1),
            i32::from(u.int_in_range(-3..=3i8).unwrap_or(0)),
        ),
        _ => x,
    };
    if y.is_finite() { y } else { x }
}

fn finite_f32(u: &mut Unstructured, x: f32) -> f32 {
    let y = match u.int_in_range(0..=3u8).unwrap_or(0) {
        0 => f32::from_bits(u32::arbitrary(u).unwrap_or(0)),
        1 => *u
            .choose(&[
                1e-45,
                f32::MAX,
                -f32::MAX,
                f32::MIN_POSITIVE,
                0.1,
                16_777_217.0,
            ])
            .unwrap_or(&0.1),
        _ => x,
    };
    if y.is_finite() { y } else { x }
}

/// Whether every number of `doc` is finite (JSON has no NaN or infinity).
fn all_finite(doc: &ClipDoc) -> bool {
    let f64s = |x: &[f64]| x.iter().all(|x| x.is_finite());
    let f32s = |x: &[f32]| x.iter().all(|x| x.is_finite());
    let settings = |s: &tcb_io::SettingsDoc| s.tcb.is_none_or(|t| f64s(&t));
    settings(&doc.defaults)
        && doc.tracks.iter().all(|t| {
            settings(&t.settings)
                && f64s(&t.times)
                && t.values.iter().all(|v| f32s(v))
                && t.keys.iter().all(|k| {
                    k.tcb.is_none_or(|x| f64s(&x))
                        && k.ease.is_none_or(|x| f64s(&x))
                        && k.tangent_in.is_none_or(|x| f32s(&x))
                        && k.tangent_out.is_none_or(|x| f32s(&x))
                })
        })
}
