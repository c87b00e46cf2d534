//! Value fill of the reduced stiffness through the slot map, serial or parallel.

use super::{color_elements, BlockSlots, Pattern, SharedMut, NO_SLOT};
use crate::element::{global_stiffness, FrameStiffness, Matrix12};
use crate::model::{Fiber, Model};
use fibercell_solver::SolverError;
use rayon::prelude::*;

/// Serial or rayon-parallel fill.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FillMode {
    /// One thread, elements in model order.
    Serial,
    /// Elements colored so no two of a color share a node; colors one after another, the
    /// elements of a color in parallel.
    #[default]
    Parallel,
}

/// Section stiffnesses of a fiber (EA, EI₂ = EI₃, GJ of its circular section).
pub fn fiber_stiffness(model: &Model, fiber: &Fiber) -> FrameStiffness {
    let m = &model.materials[fiber.material];
    let s = &fiber.section;
    FrameStiffness {
        ea: m.young * s.area(),
        ei2: m.young * s.second_moment(),
        ei3: m.young * s.second_moment(),
        gj: m.shear * s.torsion_constant(),
    }
}

/// Global stiffness of element `e` of `model`.
pub fn element_stiffness(model: &Model, e: usize) -> Matrix12 {
    let el = model.elements()[e];
    let p = fiber_stiffness(model, &model.fibers[el.fiber]);
    global_stiffness(&model.nodes[el.nodes[0]].x, &model.nodes[el.nodes[1]].x, &p)
}

/// Fills the values of a [`Pattern`]; holds the element coloring for parallel fills.
#[derive(Clone, Debug)]
pub struct Assembler {
    colors: Vec<Vec<usize>>,
}

fn scatter(k: &Matrix12, slots: BlockSlots<'_>, mut add: impl FnMut(usize, f64)) {
    for r in 0..12 {
        for c in 0..12 {
            let s = slots.get(r, c);
            if s != NO_SLOT {
                add(s as usize, k[(r, c)]);
            }
        }
    }
}

impl Assembler {
    /// Colors the elements of `model`.
    pub fn new(model: &Model) -> Self {
        let els: Vec<[usize; 2]> = model.elements().iter().map(|e| e.nodes).collect();
        Assembler {
            colors: color_elements(model.nodes.len(), &els),
        }
    }

    /// Number of colors.
    pub fn n_colors(&self) -> usize {
        self.colors.len()
    }

    /// Overwrites `values` (length `pattern.nnz()`) with the reduced stiffness K.
    pub fn fill(
        &self,
        model: &Model,
        pattern: &Pattern,
        values: &mut [f64],
        mode: FillMode,
    ) -> Result<(), SolverError> {
        pattern.check_values(values)?;
        values.iter_mut().for_each(|v| *v = 0.0);
        match mode {
            FillMode::Serial => {
                for e in 0..model.elements().len() {
                    let k = element_stiffness(model, e);
                    scatter(&k, pattern.element_slots(e), |s, v| values[s] += v);
                }
            }
            FillMode::Parallel => {
                let shared = SharedMut::new(values);
                for color in &self.colors {
                    color.par_iter().with_min_len(64).for_each(|&e| {
                        let k = element_stiffness(model, e);
                        // SAFETY: every slot of element e lies in a column of one of its nodes;
                        // elements of one color share no node, so no two tasks touch the same
                        // slot.
                        scatter(&k, pattern.element_slots(e), |s, v| unsafe {
                            *shared.get(s) += v;
                        });
                    });
                }
            }
        }
        Ok(())
    }
}
