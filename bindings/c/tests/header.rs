//! The committed `include/fibercell.h` is what cbindgen generates from `src/lib.rs` with
//! `cbindgen.toml`; `FIBERCELL_BLESS=1` writes it anew.

use std::path::Path;

#[test]
fn the_committed_header_is_the_generated_one() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("config");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen runs")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8");
    let path = crate_dir.join("include/fibercell.h");
    if std::env::var_os("FIBERCELL_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "include/fibercell.h is stale: run FIBERCELL_BLESS=1 cargo test -p fibercell-c --test header"
    );
    for name in [
        "fc_last_error",
        "fc_homogenize",
        "fc_curve",
        "fc_solver_factorize",
        "fc_cell_update",
        "FcCellResponse",
        "FC_OK",
    ] {
        assert!(generated.contains(name), "{name} is not in the header");
    }
}
