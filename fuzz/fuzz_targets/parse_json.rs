//! Any text: parsing as json and validating return Ok or a typed error, never panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(d) = fibercell::io::parse_json(text, "fuzz") {
            let _ = fibercell::Model::from_description(&d);
        }
    }
});
