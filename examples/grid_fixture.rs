//! Writes the benchmark fixture `fixtures/ok_grid30.json`: a clamped 30×30 grid of steel fibers
//! (radius 0.2 mm, 5 mm apart, 4 elements between crossings).
//!
//! `cargo run --release --example grid_fixture`

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let d = fibercell::generate::clamped_grid(30, 4, 5e-3, 2e-4);
    let json = fibercell::io::to_json(&d)?;
    fibercell::io::write_atomic(
        std::path::Path::new("fixtures/ok_grid30.json"),
        json.as_bytes(),
    )?;
    let m = fibercell::Model::from_description(&d)?;
    println!(
        "fixtures/ok_grid30.json: {} nodes, {} fibers, {} elements",
        m.nodes.len(),
        m.fibers.len(),
        m.elements().len()
    );
    Ok(())
}
