//! The `reduce_readback` target: what `tcb reduce` writes, read back as a
//! user's next command reads it, and measured again.

use arbitrary::Unstructured;
use std::sync::Arc;
use tcb_io::ClipDoc;

/// `tcb reduce`'s input as the `reduce` target draws it. A reduction that
/// succeeds is written (`to_json`, as `tcb reduce` writes its output), read
/// back bit for bit (`{:?}` of the documents equal), builds, and the clip
/// read back, compiled and played as `tcb sample` plays it, is within the
/// tolerance by the reduction's own metric and settings (`value`: vectors
/// per component, rotations in degrees; `shell`: joints' model-space
/// points) at the check times, measured afresh against the input.
pub fn reduce_readback(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Some((doc, clip, skeleton, options)) = crate::inputs::reduce_input(&mut u) else {
        return;
    };
    let input = tcb_fit::reduce::Input {
        doc: &doc,
        clip: &clip,
        skeleton: skeleton.as_ref(),
    };
    let Ok(r) = tcb_fit::reduce(input, &options, &|_, _| {}) else {
        return;
    };
    let text = r.doc.to_json();
    let back = ClipDoc::parse(&text).expect("the reduced clip reads back");
    let mut doc = r.doc.clone();
    crate::roundtrip::cut_unused(&mut doc);
    let (written, read) = (format!("{doc:?}"), format!("{back:?}"));
    if written != read {
        panic!(
            "the reduced clip: {}",
            crate::roundtrip::first_difference(&written, &read)
        );
    }
    let built = back.build().expect("the reduced clip builds");
    let reduced = Arc::new(tcb_runtime::Clip::compile(&built));
    let s = &r.settings;
    let measured = crate::inputs::measure_again(&clip, skeleton.as_ref(), &reduced, s);
    assert!(
        measured.worst.ratio <= 1.0,
        "read back, the reduced clip is beyond its tolerance: {:?} (reported {:?}; {s:?})",
        measured.worst,
        r.worst
    );
}
