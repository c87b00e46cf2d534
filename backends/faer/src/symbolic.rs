//! The symbolic factor an analysis keeps: faer's own analysis, faer's supernodal structure
//! built from the node graph's elimination tree without a scalar analysis, or this crate's
//! supernodes built from that tree alone ([`Supernodes`]).
//!
//! faer's `factorize_symbolic_cholesky` permutes the scalar pattern, computes the scalar
//! elimination tree and column counts, then the supernodes (on the L non-woven, n = 934,683,
//! ≈ 0.35 s on one core). For an ordering made on the node graph the tree and counts are the
//! node tree's expanded ([`fibercell_solver::NodeTree::scalar_tree`]) and the supernodes'
//! rows follow from one entry per neighbour node ([`fibercell_solver::NodeTree::reach_pattern`]),
//! so faer's supernodal step runs on that alone and gives the same structure; faer's LDLᵀ and
//! small LLᵀ factors, whose kernels and solves are faer's, keep that. A large LLᵀ factor,
//! factorized and solved by this crate's kernels only, takes [`Supernodes::of_node_tree`].

use crate::supernodes::{Supernodes, SupernodesRef};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::simplicial::{EliminationTreeRef, SymbolicSimplicialCholesky};
use faer::sparse::linalg::cholesky::supernodal::{
    factorize_supernodal_symbolic_cholesky, factorize_supernodal_symbolic_cholesky_scratch,
    SymbolicSupernodalCholesky,
};
use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::linalg::SymbolicSupernodalParams;
use faer::sparse::SymbolicSparseColMatRef;
use fibercell_solver::{FillEstimate, NodeGraph, NodeTree, SolverError};

/// A symbolic Cholesky factor.
pub(crate) enum Symbolic {
    /// faer's analysis of the matrix (it holds the permutation and permutes in its solves).
    Faer(SymbolicCholesky<usize>),
    /// faer's supernodes of the matrix already in the factor's order (the caller permutes).
    Supernodal(SymbolicSupernodalCholesky<usize>),
    /// This crate's supernodes, the same as faer's, in the factor's order: for this crate's
    /// LLᵀ kernel and block solves only.
    Nodes(Supernodes),
}

/// The structure of a [`Symbolic`].
#[derive(Clone, Copy)]
pub(crate) enum Raw<'a> {
    Simplicial(&'a SymbolicSimplicialCholesky<usize>),
    Supernodal(SupernodesRef<'a>),
}

impl Symbolic {
    pub(crate) fn raw(&self) -> Raw<'_> {
        match self {
            Symbolic::Faer(s) => match s.raw() {
                SymbolicCholeskyRaw::Simplicial(f) => Raw::Simplicial(f),
                SymbolicCholeskyRaw::Supernodal(f) => Raw::Supernodal(SupernodesRef::of_faer(f)),
            },
            Symbolic::Supernodal(f) => Raw::Supernodal(SupernodesRef::of_faer(f)),
            Symbolic::Nodes(s) => Raw::Supernodal(s.as_ref()),
        }
    }

    /// The supernodal structure, if the factor is supernodal.
    pub(crate) fn supernodal(&self) -> Option<SupernodesRef<'_>> {
        match self.raw() {
            Raw::Supernodal(f) => Some(f),
            Raw::Simplicial(_) => None,
        }
    }

    /// faer's supernodal structure, which faer's supernodal kernels and solves take; `None`
    /// for a simplicial factor or this crate's [`Supernodes`].
    pub(crate) fn faer_supernodal(&self) -> Option<&SymbolicSupernodalCholesky<usize>> {
        match self {
            Symbolic::Faer(s) => match s.raw() {
                SymbolicCholeskyRaw::Supernodal(f) => Some(f),
                SymbolicCholeskyRaw::Simplicial(_) => None,
            },
            Symbolic::Supernodal(f) => Some(f),
            Symbolic::Nodes(_) => None,
        }
    }

    /// Whether only this crate's kernel and block solves can read the factor.
    pub(crate) fn is_ours(&self) -> bool {
        matches!(self, Symbolic::Nodes(_))
    }

    /// faer's own analysis: the simplicial factors' (only faer's analysis makes those).
    pub(crate) fn faer(&self) -> Result<&SymbolicCholesky<usize>, SolverError> {
        match self {
            Symbolic::Faer(s) => Ok(s),
            Symbolic::Supernodal(_) | Symbolic::Nodes(_) => Err(internal(
                "a simplicial step on a node-tree supernodal structure",
            )),
        }
    }

    /// Order of the matrix.
    pub(crate) fn nrows(&self) -> usize {
        match self.raw() {
            Raw::Simplicial(f) => f.nrows(),
            Raw::Supernodal(f) => f.nrows(),
        }
    }

    /// Stored values of L (supernodes hold square diagonal blocks and relaxed zeros).
    pub(crate) fn len_val(&self) -> usize {
        match self.raw() {
            Raw::Simplicial(f) => f.len_val(),
            Raw::Supernodal(f) => f.len_val(),
        }
    }
}

/// faer's threshold for a supernodal factor: more than 40 flops per entry of L (its
/// `CHOLESKY_SUPERNODAL_RATIO_FACTOR` at the default `SupernodalThreshold::AUTO`), flops
/// counted as faer does, Σ c + c(c + 1)/2 over the column counts c.
const SUPERNODAL_FLOPS_PER_ENTRY: f64 = 40.0;

/// Whether faer makes a supernodal factor of this fill: its flop count Σ c + c(c + 1)/2 is
/// Σ c²/2 + 3/2 Σ c over the column counts c (integer sums, exact in f64 far beyond L).
pub(crate) fn supernodal_fill(fill: &FillEstimate) -> bool {
    let entries = fill.nnz_l as f64;
    fill.nnz_l > 0 && (fill.flops / 2.0 + 1.5 * entries) / entries > SUPERNODAL_FLOPS_PER_ENTRY
}

/// faer's supernodal structure of the matrix permuted by `tree`'s order (in that order), from
/// the node tree, for an order whose fill faer makes supernodal ([`supernodal_fill`]). Same
/// supernodes, rows and value layout as `factorize_symbolic_cholesky` with that permutation
/// (tested exactly).
pub(crate) fn supernodal_of_node_tree(
    graph: &NodeGraph,
    tree: &NodeTree,
) -> Result<SymbolicSupernodalCholesky<usize>, SolverError> {
    let scalar = tree.scalar_tree(graph);
    let n = scalar.counts.len();
    // faer's supernodal step trusts its tree: check what `from_inner` asks (a parent after
    // its child, in range, or −1 at a root) in O(n).
    let valid = scalar
        .parent
        .iter()
        .enumerate()
        .all(|(j, &p)| p == -1 || (p > j as isize && (p as usize) < n));
    if !valid {
        return Err(internal(
            "the node tree's scalar expansion is not an elimination tree",
        ));
    }
    let reach = tree.reach_pattern(graph);
    let pattern = SymbolicSparseColMatRef::new_checked(n, n, &reach.col_ptr, None, &reach.row_idx);
    // SAFETY: `from_inner` asks for an elimination tree of order n (each entry −1 or an index
    // in range): every entry was just checked to be −1 or a later column below n. The array
    // is the scalar elimination tree itself (equal to faer's `prefactorize_symbolic_cholesky`
    // of the permuted matrix, tested in fibercell-solver), so faer's structure is its own.
    let etree = unsafe { EliminationTreeRef::<usize>::from_inner(&scalar.parent) };
    let mut buf = MemBuffer::try_new(factorize_supernodal_symbolic_cholesky_scratch::<usize>(n))
        .map_err(|_| SolverError::OutOfMemory)?;
    factorize_supernodal_symbolic_cholesky(
        pattern,
        etree,
        &scalar.counts,
        MemStack::new(&mut buf),
        SymbolicSupernodalParams::default(),
    )
    .map_err(|e| internal(&format!("supernodal symbolic factorization failed: {e:?}")))
}

pub(crate) fn internal(message: &str) -> SolverError {
    SolverError::Backend {
        backend: "faer-cholesky",
        code: -4,
        message: message.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::supernodes::assert_same_supernodes;
    use crate::test_matrices::structure_cases;
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
    };
    use faer::Side;
    use fibercell_solver::{CscMatrix, FillOrdering};

    /// faer's own supernodal analysis of `a` under `fwd`/`inv`, if it makes one.
    fn faer_supernodal(a: &CscMatrix, fwd: &[usize], inv: &[usize]) -> Option<Symbolic> {
        let a = a.as_ref();
        let n = a.ncols();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, a.col_ptr(), None, a.row_idx());
        let s = factorize_symbolic_cholesky(
            pattern,
            Side::Lower,
            SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, n)),
            CholeskySymbolicParams::default(),
        )
        .unwrap();
        let s = Symbolic::Faer(s);
        s.supernodal().is_some().then_some(s)
    }

    /// The node tree's structure is faer's own, array for array: same supernodes, rows and
    /// value layout (so the same factor, value for value), for every ordering on networks of
    /// mixed node widths and on a scalar grid; where faer makes a simplicial factor, none.
    #[test]
    fn the_node_tree_gives_faers_supernodal_structure() {
        let cases = structure_cases();
        let mut supernodal = 0;
        for (name, a) in &cases {
            let g = NodeGraph::of(a.as_ref()).unwrap();
            // fibercell-solver's default features hold METIS.
            let orderings = [
                FillOrdering::Amd,
                FillOrdering::NestedDissection,
                FillOrdering::Auto,
            ];
            for o in orderings {
                let ordered = g.ordered(&o).unwrap();
                let p = &ordered.permutation;
                let ours = supernodal_fill(&ordered.fill)
                    .then(|| supernodal_of_node_tree(&g, &ordered.tree).unwrap());
                let theirs = faer_supernodal(a, &p.fwd, &p.inv);
                let (Some(ours), Some(theirs)) = (ours, &theirs) else {
                    assert!(theirs.is_none(), "{name}, {}: faer is supernodal", o.name());
                    continue;
                };
                let theirs = theirs.supernodal().unwrap();
                let what = format!("{name}, {}", o.name());
                assert_same_supernodes(SupernodesRef::of_faer(&ours), theirs, &what);
                supernodal += 1;
            }
        }
        // The networks of 400 and 3000 nodes and the 12³ and 20³ grids are supernodal under
        // every ordering.
        assert!(supernodal >= 12, "only {supernodal} supernodal cases");
    }
}
