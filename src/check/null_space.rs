//! The null space of a cell's system before its anchor: the three rigid translations.
//!
//! A periodic cell without its anchor node has every translation as an unknown; a uniform
//! translation moves no element and opens no contact, so K t_d = 0 for d = x, y, z. Together
//! with the anchored matrix being positive definite (fixing the anchor's three translations
//! leaves no null space), this makes the null space exactly the translations: fixing three
//! DOFs removes at most three dimensions.

use crate::homogenize::PeriodicSystem;
use crate::model::Dof;
use crate::{Error, Model};
use serde::Serialize;

/// ‖K t_d‖∞ / (‖K‖∞ ‖t_d‖∞) of the unanchored cell matrix for the translations along x, y, z.
#[derive(Clone, Debug, Serialize)]
pub struct TranslationResiduals {
    /// One per direction.
    pub relative: [f64; 3],
    /// Unknowns of the unanchored system.
    pub n: usize,
}

/// The unanchored cell matrix applied to the three unit translations.
pub fn translation_residuals(model: &Model) -> Result<TranslationResiduals, Error> {
    let sys = PeriodicSystem::unanchored(model)?;
    let values = sys.assemble(model);
    let a = sys.pattern.matrix(&values.values)?;
    let n = sys.n_free();
    // ‖K‖∞ = ‖K‖₁ for the symmetric K.
    let norm = fibercell_solver::norm1(a);
    let mut relative = [0.0; 3];
    for (r, dof) in relative.iter_mut().zip([Dof::Ux, Dof::Uy, Dof::Uz]) {
        let t: Vec<f64> = (0..n)
            .map(|k| if sys.node_dof(k).1 == dof { 1.0 } else { 0.0 })
            .collect();
        let mut kt = vec![0.0; n];
        a.mul_vec(&t, &mut kt);
        let worst = kt.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        *r = if norm > 0.0 { worst / norm } else { 0.0 };
    }
    Ok(TranslationResiduals { relative, n })
}
