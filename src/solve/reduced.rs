//! The assembled reduced system K_ff u_f = F_f − K_fc u_c.

use crate::assembly::{Assembler, ElementBlocks, FillMode, Pattern};
use crate::constraints::Discretization;
use crate::model::Model;
use crate::Error;
use fibercell_solver::CscRef;
use std::time::Instant;

/// Numbering, pattern, values and right-hand side of the reduced system.
#[derive(Clone, Debug)]
pub struct ReducedSystem {
    /// The numbering of the unknowns (supports prescribe DOFs).
    pub dofs: Discretization,
    /// Sparsity pattern with slot map.
    pub pattern: Pattern,
    /// Element coloring for parallel refills.
    pub assembler: Assembler,
    /// The element blocks (the right-hand side and the internal forces).
    pub elements: ElementBlocks,
    /// Values of K_ff (both triangles).
    pub values: Vec<f64>,
    /// F_f − K_fc u_c.
    pub rhs: Vec<f64>,
    /// Seconds spent building the pattern and filling values.
    pub seconds: (f64, f64),
}

impl ReducedSystem {
    /// Numbers the DOFs, builds the pattern and fills values and right-hand side.
    pub fn assemble(model: &Model, mode: FillMode) -> Result<Self, Error> {
        let t0 = Instant::now();
        let dofs = Discretization::supported(model);
        let pattern = Pattern::new(model, dofs.reduced_indices(), dofs.n_free())?;
        let assembler = Assembler::new(model);
        let t1 = Instant::now();
        let mut values = vec![0.0; pattern.nnz()];
        assembler.fill(model, &pattern, &mut values, mode)?;
        let elements = ElementBlocks::new(model, &dofs);
        let rhs = elements.rhs(model, &dofs);
        let t2 = Instant::now();
        Ok(ReducedSystem {
            dofs,
            pattern,
            assembler,
            elements,
            values,
            rhs,
            seconds: ((t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64()),
        })
    }

    /// The matrix K_ff.
    pub fn matrix(&self) -> Result<CscRef<'_>, Error> {
        Ok(self.pattern.matrix(&self.values)?)
    }
}
