//! Writes the plain-weave fixture `fixtures/woven_plain.toml` (thesis §5.3.4: E = 10⁶ Pa,
//! ν = 0.3, μ = 0.3, two warps and two wefts, four crossovers) and prints a penalty-convergence
//! table like Table 5.5: the all-stick moduli (in Pa, ÷ thickness) as the normal penalty grows.
//!
//! `cargo run --release --example woven_fixture`

use fibercell::generate::{weave, Weave};
use fibercell::homogenize::homogenize_elastic;
use fibercell::solve::SolveOptions;
use fibercell::Model;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let d = weave(&Weave::default())?;
    let text = fibercell::io::to_toml(&d)?;
    let header = "# A plain-weave cell like thesis §5.3.4, written by `cargo run --release --example woven_fixture`.\n\
                  # Try: cargo run --release -- homogenize fixtures/woven_plain.toml\n";
    fibercell::io::write_atomic(
        std::path::Path::new("fixtures/woven_plain.toml"),
        format!("{header}{text}").as_bytes(),
    )?;
    let m = Model::from_description(&d)?;
    println!(
        "fixtures/woven_plain.toml: {} nodes, {} elements, {} DOFs",
        m.nodes.len(),
        m.elements().len(),
        6 * m.nodes.len()
    );
    println!("| p_N (N/m) | ā₁₁¹¹ (Pa) | ā₂₂²² (Pa) | ā₁₂¹² (Pa) | ā₂₂¹¹ (Pa) |");
    println!("|---|---|---|---|---|");
    for k in 0..=7 {
        let p = 10f64.powi(k);
        let d = weave(&Weave {
            penalty_normal: Some(p),
            ..Weave::default()
        })?;
        let h = homogenize_elastic(&Model::from_description(&d)?, &SolveOptions::default())?;
        let t = h.thickness;
        let m = &h.moduli;
        println!(
            "| 1e{k} | {:.6e} | {:.6e} | {:.6e} | {:.6e} |",
            m.a11_11 / t,
            m.a22_22 / t,
            m.a12_12 / t,
            m.a22_11 / t
        );
    }
    Ok(())
}
