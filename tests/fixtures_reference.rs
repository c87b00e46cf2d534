//! The fixture catalog (`fixtures/cells/`, written by `cargo run --release --example
//! fixtures`): each parameter file regenerates exactly the committed cell, and the cell still
//! gives its committed reference results — a regression check of the generators, the contact
//! search and the homogenization together (their physics is validated against closed forms in
//! the other tests). Counts must match exactly; lengths to 1e-12; the ABD to 1e-5 of each
//! block's scale √(A_ii A_jj): loosely held fibers make K of the non-woven cells ill-conditioned,
//! so roundoff alone moves their bending blocks: in D16 of `nonwoven_medium`, faer and CHOLMOD on
//! the same matrix differ by 1.2e-7 of the scale, and summing the entries of K in another order
//! (the colored parallel fill against the earlier serial one) moves it by 1.2e-6.

use fibercell::generate::{reference_results, CellParams, ReferenceResults};
use fibercell::io::read_description;
use std::path::Path;

const NAMES: [&str; 8] = [
    "woven_small",
    "woven_medium",
    "geotextile_small",
    "geotextile_medium",
    "knitted_small",
    "knitted_medium",
    "nonwoven_small",
    "nonwoven_medium",
];

fn check(name: &str) {
    let dir = Path::new("fixtures/cells");
    let params = CellParams::read(&dir.join(format!("{name}.params.toml"))).unwrap();
    let cell = params.generate().unwrap();
    let committed = dir.join(format!("{name}.toml"));
    if committed.exists() {
        assert_eq!(
            read_description(&committed).unwrap(),
            cell,
            "{name}: regenerated cell"
        );
    }
    let text = std::fs::read_to_string(dir.join(format!("{name}.reference.json"))).unwrap();
    let want: ReferenceResults = serde_json::from_str(&text).unwrap();
    let got = reference_results(&cell).unwrap();
    assert_eq!(
        (got.fibers, got.elements, got.contacts),
        (want.fibers, want.elements, want.contacts),
        "{name}: counts"
    );
    assert!((got.total_length - want.total_length).abs() <= 1e-12 * want.total_length);
    assert!((got.volume_fraction - want.volume_fraction).abs() <= 1e-12);
    for r in 0..6 {
        for c in 0..6 {
            let scale = (want.abd[r][r] * want.abd[c][c]).abs().sqrt();
            assert!(
                (got.abd[r][c] - want.abd[r][c]).abs() <= 1e-5 * scale,
                "{name}: ABD[{r}][{c}] = {:e}, reference {:e}",
                got.abd[r][c],
                want.abd[r][c]
            );
        }
    }
}

#[test]
fn small_cells_match_their_references() {
    for name in NAMES.iter().filter(|n| n.ends_with("small")) {
        check(name);
    }
}

#[test]
fn medium_cells_match_their_references() {
    for name in NAMES.iter().filter(|n| n.ends_with("medium")) {
        check(name);
    }
}

#[test]
fn the_catalog_is_complete() {
    for family in ["woven", "geotextile", "knitted", "nonwoven"] {
        for size in ["small", "medium"] {
            let name = format!("{family}_{size}");
            assert!(NAMES.contains(&name.as_str()));
            assert!(Path::new(&format!("fixtures/cells/{name}.reference.json")).exists());
        }
    }
}
