//! Any parameter file of the fixture catalog's form (`family = "woven" | "geotextile" |
//! "knitted"`, then the generator's fields): read, validated and generated without panicking.
//! Validation bounds the sizes of these generators; non-woven files are skipped (a valid file
//! may legitimately ask for millions of fibers).
#![no_main]
use fibercell::generate::CellParams;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(p) = fibercell::io::parse_toml_as::<CellParams>(text, "fuzz") {
        if !matches!(p, CellParams::Nonwoven(_)) {
            let _ = p.generate();
        }
    }
});
