//! Writes the fixture catalog `fixtures/cells/`: for a small and a medium cell of each family
//! the parameter file `<name>.params.toml`, the cell `<name>.toml` (except the medium
//! non-woven, whose 1,000 fibers are regenerated from its seed) and the reference results
//! `<name>.reference.json` (statistics and elastic ABD), which `tests/fixtures_reference.rs`
//! checks.
//!
//! `cargo run --release --example fixtures`

use fibercell::generate::{
    nonwoven_preset, CellParams, FiberAmount, FiberFamily, Geotextile, Knit, LayerJunction, Weave,
    WeavePattern,
};
use fibercell::io::{reference_results, to_toml, write_atomic};
use std::path::Path;

fn catalog() -> Result<Vec<(&'static str, CellParams)>, fibercell::Error> {
    let s3 = 3f64.sqrt();
    let family = |angle_degrees, spacing, layer| FiberFamily {
        angle_degrees,
        spacing,
        radius: 5e-4,
        offset: None,
        layer,
    };
    let mut small_nonwoven = nonwoven_preset("S", 1)?;
    small_nonwoven.size = [5e-3, 5e-3];
    small_nonwoven.amount = FiberAmount::Count { fibers: 140 };
    Ok(vec![
        ("woven_small", CellParams::Woven(Weave::default())),
        (
            "woven_medium",
            CellParams::Woven(Weave {
                pattern: WeavePattern::Twill { over: 2, under: 2 },
                size: [8e-3, 8e-3],
                half_pitch_elements: 4,
                ..Weave::default()
            }),
        ),
        (
            "geotextile_small",
            CellParams::Geotextile(Geotextile::default()),
        ),
        (
            "geotextile_medium",
            CellParams::Geotextile(Geotextile {
                size: [1e-2, 1e-2 * s3],
                families: vec![
                    family(0.0, 2.5e-3 * s3, 0),
                    family(60.0, 2.5e-3 * s3, 0),
                    family(120.0, 2.5e-3 * s3, 0),
                    family(90.0, 5e-3, 1),
                ],
                layer_junction: LayerJunction::Contact { mu: 0.3 },
                ..Geotextile::default()
            }),
        ),
        ("knitted_small", CellParams::Knitted(Knit::default())),
        (
            "knitted_medium",
            CellParams::Knitted(Knit {
                wales: 4,
                courses: 4,
                ..Knit::default()
            }),
        ),
        ("nonwoven_small", CellParams::Nonwoven(small_nonwoven)),
        (
            "nonwoven_medium",
            CellParams::Nonwoven(nonwoven_preset("M", 1)?),
        ),
    ])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = Path::new("fixtures/cells");
    for (name, params) in catalog()? {
        let header =
            format!("# Fixture {name}: written by `cargo run --release --example fixtures`.\n");
        let text = toml::to_string(&params)?;
        write_atomic(
            &dir.join(format!("{name}.params.toml")),
            format!("{header}{text}").as_bytes(),
        )?;
        let cell = params.generate()?;
        if name != "nonwoven_medium" {
            let model = to_toml(&cell).map_err(|e| format!("{name}: {e}"))?;
            write_atomic(
                &dir.join(format!("{name}.toml")),
                format!("{header}{model}").as_bytes(),
            )?;
        }
        let reference = reference_results(&cell)?;
        write_atomic(
            &dir.join(format!("{name}.reference.json")),
            serde_json::to_string_pretty(&reference)?.as_bytes(),
        )?;
        println!(
            "{name}: {} fibers, {} elements, {} contacts, A11 {:.4e} N/m",
            reference.fibers, reference.elements, reference.contacts, reference.abd[0][0]
        );
    }
    Ok(())
}
