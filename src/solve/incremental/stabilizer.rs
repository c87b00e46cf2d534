//! The stabilizing springs of open and sliding contacts (see
//! [`IncrementalOptions::stabilization`](super::IncrementalOptions::stabilization)).

#[cfg(test)]
use crate::contact::BlockMatrix;
use crate::contact::{BlockVector, ContactPair, ContactState};

/// The unscaled stabilizing spring of a contact in `state` (see
/// [`IncrementalOptions::stabilization`](super::IncrementalOptions::stabilization)): K_N +
/// K_T^st + K_R when open, K_T^st when sliding; the independent form the test checks
/// [`stabilizer_force`] against.
#[cfg(test)]
fn stabilizer(pair: &ContactPair, state: ContactState) -> BlockMatrix {
    let (p_n, p_t, p_r) = (
        pair.penalty_normal,
        pair.penalty_tangent,
        pair.penalty_rotation,
    );
    let k = match state {
        ContactState::Open => pair.springs(p_n, p_t, p_r),
        _ => pair.springs(0.0, p_t, 0.0),
    };
    let m = pair.size();
    BlockMatrix::from_fn(|r, c| if r < m && c < m { k(r, c) } else { 0.0 })
}

/// [`stabilizer`]`(pair, state) q` from the jump basis G, Σₐ dₐ gₐ (gₐ · q) with the stick
/// coefficients d (open) or their tangential ones (sliding): the 30 × 30 block is never formed
/// (G D Gᵀ equals the assembled blocks, see `block_coefficients`).
pub(super) fn stabilizer_force(
    pair: &ContactPair,
    state: ContactState,
    q: &BlockVector,
) -> BlockVector {
    let (pn, pt, pr) = (
        pair.penalty_normal,
        pair.penalty_tangent,
        pair.penalty_rotation,
    );
    let d = match state {
        ContactState::Open => [pn, pt, pt, pr, pr, pr],
        _ => [0.0, pt, pt, 0.0, 0.0, 0.0],
    };
    pair.jump_basis()
        .iter()
        .zip(d)
        .filter(|(_, da)| *da != 0.0)
        .fold(BlockVector::zeros(), |f, (ga, da)| {
            f + ga * (da * ga.dot(q))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactSet;
    use crate::generate::crossing_grid;
    use crate::model::Model;

    /// The stabilizing force from the jump basis equals the 30 × 30 stabilizer times q (open
    /// and sliding), to rounding, on every contact of a crossing grid.
    #[test]
    fn stabilizer_force_is_the_stabilizer_block_times_q() {
        let model = Model::from_description(&crossing_grid(3, 2, 1e-3, 1e-4)).unwrap();
        let set = ContactSet::build(&model).unwrap();
        assert!(!set.pairs.is_empty());
        let q = BlockVector::from_fn(|r, _| ((r * 37) % 11) as f64 * 1e-5 - 4e-5);
        for pair in &set.pairs {
            for state in [ContactState::Open, ContactState::Slip] {
                let want = stabilizer(pair, state) * q;
                let got = stabilizer_force(pair, state, &q);
                let scale = stabilizer(pair, ContactState::Open).amax() * q.amax();
                assert!((got - want).amax() <= 1e-12 * scale, "{state:?}");
            }
        }
    }
}
