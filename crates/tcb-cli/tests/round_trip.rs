//! `tcb reduce`'s output reads back bit for bit (issue 29, class 1): the
//! clip verified in memory is the clip a reader of the written file gets,
//! key times (frame times such as `348 * 0.0083333`, which a reader that is
//! not round-trip exact reads 1 ulp off), values and tangents alike.

mod common;

use common::{assert_success, scratch, short_cmu, tcb_to};
use std::path::PathBuf;
use tcb_test_support::debug_difference;

/// This binary's scratch folder.
fn dir() -> PathBuf {
    scratch("round-trip-test")
}

#[test]
fn a_reduced_clip_written_then_read_is_the_clip_verified() {
    let input = short_cmu(400);
    let loaded = tcb_io::load(&input).unwrap();
    // Tight: most frames stay keys, among them frame times that a
    // reader that is not round-trip exact misreads.
    let options = tcb_fit::ReduceOptions::default().tolerance(Some(0.005));
    let reduced = tcb_fit::reduce(
        tcb_fit::reduce::Input {
            doc: &loaded.doc,
            clip: &loaded.clip,
            skeleton: loaded.skeleton.as_ref(),
        },
        &options,
        &|_, _| {},
    )
    .unwrap();
    let path = dir().join("reduced.json");
    tcb_io::write_clip_doc(&reduced.doc, &path).unwrap();
    let read = tcb_io::read_clip_doc(&path).unwrap();
    if let Some(d) = debug_difference(&read, &reduced.doc) {
        panic!("{d}");
    }

    // `tcb reduce` writes that same text.
    let out = dir().join("reduced-by-tcb.json");
    let o = tcb_to("reduce", &input, &out, &["--tolerance", "0.005"]);
    assert_success(&o);
    assert!(
        std::fs::read_to_string(&out).unwrap() == reduced.doc.to_json(),
        "tcb reduce wrote another clip than tcb_fit::reduce made"
    );
}
