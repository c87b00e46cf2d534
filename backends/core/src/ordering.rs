//! Fill-reducing orderings: approximate minimum degree (faer's AMD), nested dissection (METIS
//! `METIS_NodeND`), natural, or a permutation given by the caller.

use crate::{CscRef, SolverError};

/// Which fill-reducing ordering a direct solver uses.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum FillOrdering {
    /// The backend's choice (faer and [`compute_ordering`]: the better of AMD and nested
    /// dissection by predicted flops; CHOLMOD: its own default strategy).
    #[default]
    Auto,
    /// No reordering.
    Natural,
    /// Approximate minimum degree (faer's) on the [`NodeGraph`].
    Amd,
    /// Nested dissection through METIS `METIS_NodeND` (the better of two separators at each
    /// level) on the [`NodeGraph`], after the nodes whose elimination removes more edges than
    /// it adds (a fiber's free ends and chains among them).
    NestedDissection,
    /// A caller's permutation: `perm[new] = old`.
    Given(Vec<usize>),
}

impl FillOrdering {
    /// A short name for reports.
    pub fn name(&self) -> &'static str {
        match self {
            FillOrdering::Auto => "auto",
            FillOrdering::Natural => "natural",
            FillOrdering::Amd => "amd",
            FillOrdering::NestedDissection => "nested-dissection",
            FillOrdering::Given(_) => "given",
        }
    }

    /// The names [`FillOrdering::parse`] takes, as the CLI's `--ordering` lists them.
    pub const NAMES: [&'static str; 4] = ["auto", "amd", "nd", "natural"];

    /// The ordering called `name` (one of [`FillOrdering::NAMES`]; `nested-dissection` too).
    pub fn parse(name: &str) -> Result<FillOrdering, String> {
        match name {
            "auto" => Ok(FillOrdering::Auto),
            "amd" => Ok(FillOrdering::Amd),
            "nd" | "nested-dissection" => Ok(FillOrdering::NestedDissection),
            "natural" => Ok(FillOrdering::Natural),
            _ => Err(format!(
                "unknown ordering \"{name}\" (use auto, amd, nd or natural)"
            )),
        }
    }
}

/// A permutation with its inverse: `fwd[new] = old`, `inv[old] = new`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Permutation {
    /// New position → old index.
    pub fwd: Vec<usize>,
    /// Old index → new position.
    pub inv: Vec<usize>,
}

impl Permutation {
    /// Checks that `fwd` is a permutation of 0..n and builds the inverse.
    pub fn from_fwd(fwd: Vec<usize>, n: usize) -> Result<Self, SolverError> {
        if fwd.len() != n {
            return Err(SolverError::DimensionMismatch(format!(
                "permutation has {} entries for a matrix of order {n}",
                fwd.len()
            )));
        }
        let mut inv = vec![usize::MAX; n];
        for (new, &old) in fwd.iter().enumerate() {
            if old >= n || inv[old] != usize::MAX {
                return Err(SolverError::InvalidMatrix(format!(
                    "given ordering is not a permutation of 0..{n} (entry {new} = {old})"
                )));
            }
            inv[old] = new;
        }
        Ok(Permutation { fwd, inv })
    }

    /// The identity of order n.
    pub fn identity(n: usize) -> Self {
        Permutation {
            fwd: (0..n).collect(),
            inv: (0..n).collect(),
        }
    }
}

/// Computes the permutation of `ordering` from the pattern of the square, structurally
/// symmetric matrix `a` (checked: AMD and METIS need a symmetric graph and hang or return
/// nonsense on one triangle). AMD and nested dissection run on the matrix's [`NodeGraph`];
/// [`FillOrdering::Auto`] is the one of the two with fewer predicted flops.
pub fn compute_ordering(
    a: CscRef<'_>,
    ordering: &FillOrdering,
) -> Result<Permutation, SolverError> {
    let n = a.ncols();
    if a.nrows() != n {
        return Err(SolverError::DimensionMismatch(format!(
            "matrix is {}×{n}, not square",
            a.nrows()
        )));
    }
    match ordering {
        FillOrdering::Natural => Ok(Permutation::identity(n)),
        FillOrdering::Given(p) => Permutation::from_fwd(p.clone(), n),
        o => Ok(NodeGraph::of(a)?.order(o)?.0),
    }
}

#[cfg(feature = "metis")]
mod metis;
mod node_graph;
mod node_tree;
mod pre_elimination;
pub use node_graph::{FillEstimate, NodeGraph, OrderedNodes};
pub use node_tree::{NodeTree, ReachPattern, ScalarTree};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CscMatrix;

    fn grid_laplacian(k: usize, dofs: usize) -> CscMatrix {
        let idx = |i: usize, j: usize| i * k + j;
        let mut t = Vec::new();
        for i in 0..k {
            for j in 0..k {
                let mut nb = vec![idx(i, j)];
                if i + 1 < k {
                    nb.push(idx(i + 1, j));
                }
                if j + 1 < k {
                    nb.push(idx(i, j + 1));
                }
                for &p in &nb {
                    for &q in &nb {
                        for a in 0..dofs {
                            for b in 0..dofs {
                                let v = if p == q && a == b { 8.0 } else { -0.1 };
                                t.push((p * dofs + a, q * dofs + b, v));
                            }
                        }
                    }
                }
            }
        }
        CscMatrix::from_triplets(k * k * dofs, k * k * dofs, &t).unwrap()
    }

    /// Nested dissection gives the same permutation when several threads order at once (each
    /// METIS call draws from its own thread's seeded state: vendor/metis-sys/PATCHES.md; with
    /// crates.io's metis-sys, which draws from the C library's `rand`, this test fails).
    #[cfg(feature = "metis")]
    #[test]
    fn nested_dissection_is_the_same_on_concurrent_threads() {
        let a = grid_laplacian(30, 3);
        let want = compute_ordering(a.as_ref(), &FillOrdering::NestedDissection).unwrap();
        std::thread::scope(|scope| {
            let runs: Vec<_> = (0..4)
                .map(|_| {
                    scope.spawn(|| {
                        (0..20)
                            .map(|_| compute_ordering(a.as_ref(), &FillOrdering::NestedDissection))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            for run in runs {
                for p in run.join().unwrap() {
                    assert_eq!(p.unwrap().fwd, want.fwd);
                }
            }
        });
    }

    #[test]
    fn every_ordering_is_a_permutation() {
        let a = grid_laplacian(12, 3);
        let mut orderings = vec![FillOrdering::Natural, FillOrdering::Amd];
        if cfg!(feature = "metis") {
            orderings.push(FillOrdering::NestedDissection);
        }
        for o in orderings {
            let p = compute_ordering(a.as_ref(), &o).unwrap();
            let mut seen = p.fwd.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..a.as_ref().ncols()).collect::<Vec<_>>());
            for (new, &old) in p.fwd.iter().enumerate() {
                assert_eq!(p.inv[old], new);
            }
        }
    }

    #[cfg(feature = "metis")]
    #[test]
    fn nested_dissection_keeps_supervariables_together() {
        let a = grid_laplacian(10, 6);
        let p = compute_ordering(a.as_ref(), &FillOrdering::NestedDissection).unwrap();
        for chunk in p.fwd.chunks(6) {
            assert_eq!(chunk[0] % 6, 0);
            for (k, &c) in chunk.iter().enumerate() {
                assert_eq!(c, chunk[0] + k);
            }
        }
    }

    /// Without METIS, nested dissection is unavailable (a typed error, no panic).
    #[cfg(not(feature = "metis"))]
    #[test]
    fn nested_dissection_needs_the_metis_feature() {
        let a = grid_laplacian(3, 1);
        let e = compute_ordering(a.as_ref(), &FillOrdering::NestedDissection);
        assert!(matches!(
            e,
            Err(SolverError::Unavailable {
                backend: "metis",
                ..
            })
        ));
    }

    #[test]
    fn given_ordering_is_checked() {
        let a = grid_laplacian(3, 1);
        let e = compute_ordering(
            a.as_ref(),
            &FillOrdering::Given(vec![0, 1, 1, 3, 4, 5, 6, 7, 8]),
        );
        assert!(matches!(e, Err(SolverError::InvalidMatrix(_))));
        let e = compute_ordering(a.as_ref(), &FillOrdering::Given(vec![0]));
        assert!(matches!(e, Err(SolverError::DimensionMismatch(_))));
    }
}
