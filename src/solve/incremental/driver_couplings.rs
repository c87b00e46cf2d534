//! The couplings of a periodic cell's unknowns to its six macroscopic drivers, K_fE and K_EE,
//! from the stick/slip run's own blocks: with a factorization of K_ff they give the elastic
//! ABD = (K_EE − K_Ef K_ff⁻¹ K_fE) / area of the cell problems (thesis 5.5).

use super::assemble::contact_block;
use super::contact_states::ContactStates;
use super::setup::Setup;
use crate::contact::{ContactBlock, ContactState};
use nalgebra::SMatrix;

/// K_fE (per free unknown, its coupling to the six drivers) and K_EE of a periodic cell.
#[derive(Clone, Debug, PartialEq)]
pub struct DriverCouplings {
    /// K_fE, one row of six per free unknown.
    pub coupling: Vec<[f64; 6]>,
    /// K_EE.
    pub k_ee: SMatrix<f64, 6, 6>,
}

impl DriverCouplings {
    /// The blocks of the elements and of the contacts in `contacts`' states that touch the
    /// driver, in the run's numbering; None without a driver (a supported structure) or when a
    /// contact slides (only stick and open states are summed: stuck contacts as
    /// K_N + K_T^st + K_R, open ones as their stabilizer ε (K_N + K_T^st + K_R), the blocks the
    /// all-stick matrix is assembled with).
    pub(super) fn of(setup: &Setup<'_>, contacts: &ContactStates) -> Option<Self> {
        if contacts.states.contains(&ContactState::Slip) {
            return None;
        }
        Self::with_blocks(setup, |i| contact_block(setup, contacts, i))
    }

    /// K_fE and K_EE with contact i's block `block(i)`, any state (None without a driver).
    /// K_fE of the transposed blocks is K_Efᵀ (the elements are symmetric).
    pub(super) fn with_blocks(
        setup: &Setup<'_>,
        block: impl Fn(usize) -> ContactBlock,
    ) -> Option<Self> {
        let (model, disc) = (&setup.model, &setup.disc);
        let driver = disc.driver()?;
        let mut out = DriverCouplings {
            coupling: vec![[0.0; 6]; disc.n_free()],
            k_ee: SMatrix::zeros(),
        };
        let mut add = |gnodes: &[usize], k: &dyn Fn(usize, usize) -> f64| {
            let m = 6 * gnodes.len();
            for c in (0..m).filter(|&c| gnodes[c / 6] == driver) {
                for r in 0..m {
                    let v = k(r, c);
                    if gnodes[r / 6] == driver {
                        out.k_ee[(r % 6, c % 6)] += v;
                    } else if let Some(i) = disc.reduced(6 * gnodes[r / 6] + r % 6) {
                        out.coupling[i][c % 6] += v;
                    }
                }
            }
        };
        let elastic = &setup.elastic;
        for e in 0..model.elements().len() {
            let gnodes = elastic.gnodes_of(model, e);
            if gnodes.contains(&driver) {
                let k = elastic.matrix(model, e);
                add(gnodes, &|r, c| k[(r, c)]);
            }
        }
        out.k_ee +=
            setup
                .contact_columns
                .add_driver_columns(&setup.pairs, disc, &mut out.coupling, block);
        Some(out)
    }
}
