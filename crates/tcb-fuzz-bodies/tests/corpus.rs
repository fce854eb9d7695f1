//! Replays the committed fuzz corpus (`fuzz/corpus/<target>/`: seeds and
//! every crash found, each kept under a name that says what it found)
//! through the fuzz targets' own bodies (this crate) on stable Rust, so CI
//! guards the findings without nightly or cargo-fuzz.

use std::path::Path;
use tcb_fuzz_bodies as bodies;

fn replay(target: &str, body: fn(&[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("corpus entry").path())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no corpus in {}", dir.display());
    for f in files {
        let bytes = std::fs::read(&f).expect("read corpus file");
        let r = std::panic::catch_unwind(|| body(&bytes));
        assert!(r.is_ok(), "{target}: {} fails again", f.display());
    }
}

/// [`replay`] of a target whose body chooses the instruction set from
/// each input's last byte (`tcb_fuzz_bodies::fix_simd`): every input on
/// every instance the host runs (what the CPU has, the AVX2 instance
/// where it has AVX-512, the baseline), whatever its last byte says. The
/// switches are global: one such target at a time.
fn replay_on_every_instance(target: &str, body: fn(&[u8])) {
    static SWITCHES: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one = SWITCHES.lock().unwrap_or_else(|e| e.into_inner());
    for mode in [0, 1, 2] {
        bodies::fix_simd(Some(mode));
        replay(target, body);
    }
    bodies::fix_simd(None);
    tcb_runtime::force_baseline_simd(false);
    tcb_runtime::force_no_avx512(false);
}

#[test]
fn clip_json_corpus() {
    replay("clip_json", bodies::clip_json);
}

#[test]
fn bvh_corpus() {
    replay("bvh", bodies::bvh);
}

#[test]
fn gltf_corpus() {
    replay("gltf", bodies::gltf);
}

#[test]
fn runtime_corpus() {
    replay_on_every_instance("runtime", bodies::runtime);
}

#[test]
fn blend_corpus() {
    replay("blend", bodies::blend);
}

#[test]
fn compress_corpus() {
    replay_on_every_instance("compress", bodies::compress);
}

#[test]
fn reduce_corpus() {
    replay("reduce", bodies::reduce);
}

#[test]
fn tcbc_corpus() {
    replay_on_every_instance("tcbc", bodies::tcbc);
}

#[test]
fn pack_corpus() {
    replay_on_every_instance("pack", bodies::pack);
}

#[test]
fn quantize_corpus() {
    replay("quantize", bodies::quantize);
}

#[test]
fn playback_corpus() {
    replay("playback", bodies::playback);
}

#[test]
fn roundtrip_corpus() {
    replay("roundtrip", bodies::roundtrip);
}

#[test]
fn export_corpus() {
    replay("export", bodies::export);
}

#[test]
fn reduce_readback_corpus() {
    replay("reduce_readback", bodies::reduce_readback);
}
