#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| tcb_fuzz::clip_json(data));
