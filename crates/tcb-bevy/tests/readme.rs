//! The bevy lines of tcb-bevy's README are `examples/readme.rs`, which the
//! build compiles (the README is no crate's docs, so its block, marked
//! `rust,ignore`, is no doctest): this test keeps the two the same.

#[test]
fn the_readme_shows_the_example_that_compiles() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let readme = std::fs::read_to_string(format!("{dir}/README.md")).unwrap();
    let example = std::fs::read_to_string(format!("{dir}/examples/readme.rs")).unwrap();
    let start = readme.find("```rust,ignore\n").expect("its code block") + "```rust,ignore\n".len();
    let block = &readme[start..start + readme[start..].find("```").unwrap()];
    let code = &example[example.find("use bevy::prelude::*;").unwrap()..];
    assert_eq!(
        block, code,
        "crates/tcb-bevy/README.md's block differs from examples/readme.rs"
    );
    assert!(block.lines().count() <= 20, "keep it short");
}

/// The workspace's README shows the same lines (issue 32: the README shows
/// what a bevy user adds), keeps its bevy section short and points here.
#[test]
fn the_workspace_readme_shows_them_and_points_here() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let section = &readme[readme
        .find("## In bevy: tcb-bevy")
        .expect("the README's bevy section")..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |e| e + 3)];
    assert!(section.contains("(crates/tcb-bevy/README.md)"));
    let example =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/readme.rs"))
            .unwrap();
    let code = &example[example.find("use bevy::prelude::*;").unwrap()..];
    assert!(
        section.contains(&format!("```rust,ignore\n{code}```")),
        "README.md's bevy block differs from crates/tcb-bevy/examples/readme.rs"
    );
    assert!(section.lines().count() <= 32, "keep it short");
}
