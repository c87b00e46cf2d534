//! The fixture catalog (`fixtures/cells/`, written by `cargo run --release --example
//! fixtures`): each parameter file regenerates exactly the committed cell, and the cell still
//! gives its committed reference results — a regression check of the generators, the contact
//! search and the homogenization together (their physics is validated against closed forms in
//! the other tests). Counts must match exactly; lengths to 1e-12; the ABD to 1e-5 of each
//! block's scale √(A_ii A_jj): loosely held fibers make K of the non-woven cells ill-conditioned,
//! so roundoff alone moves their bending blocks: in D16 of `nonwoven_medium`, faer and CHOLMOD on
//! the same matrix differ by 1.2e-7 of the scale, and summing the entries of K in another order
//! (the colored parallel fill against the earlier serial one) moves it by 1.2e-6.

use fibercell::io::read_description;
use fibercell::io::{cell_digest, read_cell_params, reference_results, ReferenceResults};
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

/// The one cell of the catalog that is regenerated from its parameters instead of committed.
const UNCOMMITTED: &str = "nonwoven_medium";

fn check(name: &str) {
    let dir = Path::new("fixtures/cells");
    let params = read_cell_params(&dir.join(format!("{name}.params.toml"))).unwrap();
    let cell = params.generate().unwrap();
    let text = std::fs::read_to_string(dir.join(format!("{name}.reference.json"))).unwrap();
    let want: ReferenceResults = serde_json::from_str(&text).unwrap();
    // The parameters regenerate exactly the cell: its digest for every cell, and the committed
    // file itself for all but the medium non-woven (1,000 fibers, not committed).
    assert_eq!(
        cell_digest(&cell).unwrap(),
        want.cell_digest,
        "{name}: regenerated cell"
    );
    let committed = dir.join(format!("{name}.toml"));
    if name == UNCOMMITTED {
        assert!(
            !committed.exists(),
            "{name} is committed: check it as the others"
        );
    } else {
        assert_eq!(
            read_description(&committed).unwrap(),
            cell,
            "{name}: regenerated cell"
        );
    }
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

/// Every parameter file in `fixtures/cells/` is a cell the tests above check, and every one
/// of them has its reference results (a new fixture the list forgot fails here).
#[test]
fn the_catalog_is_complete() {
    let mut on_disk: Vec<String> = std::fs::read_dir("fixtures/cells")
        .unwrap()
        .filter_map(|e| {
            let file = e.ok()?.file_name().into_string().ok()?;
            file.strip_suffix(".params.toml").map(str::to_string)
        })
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = NAMES.iter().map(|n| n.to_string()).collect();
    listed.sort();
    assert_eq!(on_disk, listed, "parameter files vs the checked names");
    for name in NAMES {
        assert!(Path::new(&format!("fixtures/cells/{name}.reference.json")).exists());
    }
}
