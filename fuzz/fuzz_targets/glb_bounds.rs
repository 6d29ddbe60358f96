//! GLB reader used for Kenney furniture bounds on arbitrary bytes: an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = inbetween_script::catalogue::kenney::glb_bounds(data);
});
