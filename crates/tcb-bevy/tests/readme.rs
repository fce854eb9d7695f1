//! The README's bevy lines are `examples/readme.rs` (which the build
//! compiles): the README block is marked `rust,ignore` only because the
//! README's other blocks run as tcb-runtime's doctests, without bevy.

#[test]
fn the_readme_shows_the_example_that_compiles() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let example =
        std::fs::read_to_string(format!("{root}/crates/tcb-bevy/examples/readme.rs")).unwrap();
    let section = &readme[readme
        .find("## In bevy: tcb-bevy")
        .expect("the README's bevy section")..];
    let start =
        section.find("```rust,ignore\n").expect("its code block") + "```rust,ignore\n".len();
    let block = &section[start..start + section[start..].find("```").unwrap()];
    let code = &example[example.find("use bevy::prelude::*;").unwrap()..];
    assert_eq!(
        block, code,
        "README.md's bevy block differs from examples/readme.rs"
    );
    assert!(block.lines().count() <= 20, "keep it short");
}
