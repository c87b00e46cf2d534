//! `fibercell homogenize`: the six cell problems and the ABD matrix.

use crate::output::{to_pretty, write};
use fibercell::io::NetworkFormat;
use fibercell::solve::SolveOptions;
use fibercell::{io, Error};
use std::path::Path;

pub(crate) fn homogenize(
    model_path: &Path,
    options: SolveOptions,
    json: bool,
    (out, vtk): (Option<&Path>, io::VtkEncoding),
) -> Result<(), Error> {
    let model = io::load_model(model_path)?;
    let h = fibercell::homogenize::homogenize_elastic(&model, &options)?;
    let pretty = to_pretty(&h)?;
    if let Some(out) = out {
        // homogenized.json is written last: a folder that holds it is complete.
        io::begin_results(out, "homogenized.json")?;
        for (k, case) in h.cases.iter().enumerate() {
            let name = format!("case_{}.vtp", fibercell::cell::MACRO_NAMES[k]);
            write(
                &out.join(name),
                &io::network_vtk(&model, case, NetworkFormat::PolyData, vtk),
            )?;
        }
        write(
            &out.join("case_pressure.vtp"),
            &io::network_vtk(
                &model,
                &h.pressure.displacements,
                NetworkFormat::PolyData,
                vtk,
            ),
        )?;
        write(&out.join("homogenized.json"), &pretty)?;
    }
    if json {
        println!("{pretty}");
        return Ok(());
    }
    println!(
        "{}: cell {:.4e} m² ({} free DOFs, {} paired boundary nodes), thickness {:.4e} m, backend {}",
        model_path.display(),
        h.area,
        h.free_dofs,
        h.paired_nodes,
        h.thickness,
        h.backend
    );
    println!(
        "ABD per unit area (rows/columns e11 e22 g12 k11 k22 k12; A in N/m, B in N, D in N·m):"
    );
    for row in &h.abd {
        println!(
            "  {}",
            row.iter()
                .map(|v| format!("{v:>13.5e}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    println!("asymmetry max|ABD − ABDᵀ|/max|ABD| = {:.2e}", h.asymmetry);
    println!(
        "solves: backward error {:.2e}, relative residual {:.2e} (largest of the seven)",
        h.backward_error, h.relative_residual
    );
    let m = &h.moduli;
    println!(
        "moduli: a11_11 {:.5e}  a22_22 {:.5e}  a12_12 {:.5e}  a22_11 {:.5e} N/m;  c1111 {:.5e}  c1122 {:.5e}  c2222 {:.5e} N·m",
        m.a11_11, m.a22_22, m.a12_12, m.a22_11, m.c1111, m.c1122, m.c2222
    );
    let o = &h.orthotropic;
    println!(
        "orthotropic: E1 {:.5e} N/m ({:.5e} Pa)  E2 {:.5e} N/m ({:.5e} Pa)  G12 {:.5e} N/m ({:.5e} Pa)\n  nu12 {:.5} (-e22/e11 under N11 = A12/A22, the thesis's nu21)  nu21 {:.5} (-e11/e22 under N22 = A12/A11, the thesis's nu12)",
        o.e1, o.e1_pa, o.e2, o.e2_pa, o.g12, o.g12_pa, o.nu12, o.nu21
    );
    let b = &h.pressure.b_hom;
    println!(
        "pressure (1 Pa down on the {:.1} % of the cell seen from above, balanced by a body force): B_hom N11 {:.5e} N22 {:.5e} N12 {:.5e} m;  M11 {:.5e} M22 {:.5e} M12 {:.5e} m²",
        100.0 * h.pressure.coverage,
        b[0], b[1], b[2], b[3], b[4], b[5]
    );
    let t = &h.timings;
    println!(
        "time (s): setup {:.3}  assembly {:.3}  analysis {:.3}  factorization {:.3}  pressure load {:.3} (beside the analysis)  7 solves {:.3}  post {:.3}  total {:.3}",
        t.setup, t.assembly, t.analysis, t.factorization, t.pressure_load, t.solve, t.post, t.total
    );
    Ok(())
}
