#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| tcb_fuzz_bodies::compress(data));
