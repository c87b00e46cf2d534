//! The factorizations of a stick/slip run: the backends, the reference factorization A₀ with
//! the contact blocks it was built from, and the low-rank correction accumulated on it.

use crate::contact::ContactPair;
use crate::contact::{BlockCoefficients, BlockState, ContactState, Friction};
use crate::solve::affine_reference::AffineReferences;
use crate::solve::low_rank::{LowRankCorrection, Reference};
use fibercell_solver::LinearSolver;
use nalgebra::{Vector2, Vector6};

/// What an assembled matrix was built from: symmetry, states, slip directions, k⊥ of each
/// contact.
pub(super) type AssembledKey = (bool, Vec<ContactState>, Vec<Vector2<f64>>, Vec<f64>);

/// The solvers of a run, each analyzed once on the pattern.
#[derive(Default)]
pub(super) struct Backends {
    pub symmetric: Option<Box<dyn LinearSolver>>,
    pub general: Option<Box<dyn LinearSolver>>,
    /// The reference factorization A₀ of the low-rank solves, kept apart from `symmetric`
    /// so that direct solves in between do not discard the correction's columns.
    pub reference: Option<Box<dyn LinearSolver>>,
    /// A stateful cell's consistent tangent matrix (nonsymmetric?, its solver), apart from
    /// the run's so that computing a tangent changes no increment.
    pub tangent: Option<TangentSolver>,
}

/// The solver of a stateful cell's tangent matrices, analyzed on the first.
pub(super) struct TangentSolver {
    /// LU for nonsymmetric tangents, else the run's symmetric backend.
    pub nonsymmetric: bool,
    pub solver: Box<dyn LinearSolver>,
    pub analyzed: bool,
}

/// What a factorization and the capacitance factorization cost in this run, measured: a
/// low-rank solve (the capacitance factorization and one solve with A₀, against a
/// factorization and one solve) is done while its capacitance factorization is predicted
/// cheaper than a factorization. New columns of U are not charged: each is computed once (a
/// solve among many right-hand sides) and serves every later solve on the same reference.
pub(super) struct LowRankCost {
    pub factorize: Option<f64>,
    /// Flops per second of the capacitance factorization (2/3 R³ flops as an LU), last measured.
    pub lu_rate: f64,
}

impl LowRankCost {
    pub fn worth(&self, order: usize) -> bool {
        let lu = 2.0 / 3.0 * (order as f64).powi(3) / self.lu_rate;
        self.factorize.is_some_and(|f| lu <= f)
    }

    /// The crossover: the capacitance order whose factorization is predicted to cost one
    /// factorization of the matrix, (3/2 · t_factorize · rate)^⅓ (None before the first
    /// factorization is timed).
    pub fn crossover(&self) -> Option<usize> {
        self.factorize
            .map(|f| (1.5 * f * self.lu_rate).cbrt().floor() as usize)
    }
}

/// A contact as the reference factorization has it: block coefficients, what they and the
/// load were computed from, and the anchor of the k⊥ spring.
#[derive(Clone)]
pub(super) struct ReferenceBlock {
    pub stiffness: BlockCoefficients,
    pub state: BlockState,
    /// The contact's friction law in the reference (a Coulomb contact's bound there).
    pub friction: Friction,
    pub anchor: Vector2<f64>,
    /// The slip its load was computed at: the reference load b₀ keeps it, so that b₀ changes
    /// with α only (see [`AffineReferences`]); a contact whose slip moved since is a change.
    pub slip: Vector2<f64>,
    /// A frozen tangent's offset in its load (see `ContactStates::frozen_offset`).
    pub offset: Vector2<f64>,
}

impl ReferenceBlock {
    /// The load coefficients of the contact in the reference.
    pub fn load(&self, pair: &ContactPair) -> Vector6<f64> {
        let phi = pair.load_coefficients(&self.state, &self.anchor, &self.slip, self.friction);
        super::contact_states::with_frozen_offset(phi, self.state.state, self.offset)
    }
}

/// The factorizations and what the low-rank solves keep on the reference.
pub(super) struct Factors {
    pub backends: Backends,
    /// Set when the correction outgrew its columns or missed its accuracy: the next symmetric
    /// factorization becomes the new reference.
    pub refresh_reference: bool,
    /// What the current factorization of `symmetric` or `general` was built from (None:
    /// nothing factorized yet).
    pub factorized: Option<AssembledKey>,
    pub cost: LowRankCost,
    /// The block coefficients of every contact in the reference A₀.
    pub reference: Option<Vec<ReferenceBlock>>,
    /// A₀⁻¹ b₀ for this increment, b₀ the load with every contact as in the reference (its
    /// state, slip direction and slip there).
    pub reference_solution: Option<Reference>,
    /// The correction accumulated on A₀.
    pub low_rank: LowRankCorrection,
    /// The references of earlier increments' b₀ on it, when b₀ is affine in α.
    pub affine: AffineReferences,
    /// The reference's own direct solve, once factorized.
    pub reference_solve: Option<ReferenceSolve>,
    /// The bytes of a symmetric factor's values, from its analysis (None: not analyzed here).
    pub factor_bytes: Option<usize>,
}

/// The direct solve that factorized the reference.
#[derive(Clone, Copy, Debug)]
pub struct ReferenceSolve {
    /// The increment it belongs to.
    pub step: usize,
    /// Its backward error: what a low-rank solve on the reference must come close to (see
    /// [`super::options::LOW_RANK_MATCH`]).
    pub backward_error: f64,
}

impl Factors {
    pub fn new(n_free: usize, contacts: usize) -> Self {
        Factors {
            backends: Backends::default(),
            refresh_reference: false,
            factorized: None,
            cost: LowRankCost {
                factorize: None,
                lu_rate: 1e10,
            },
            reference: None,
            reference_solution: None,
            low_rank: LowRankCorrection::new(n_free, contacts),
            affine: AffineReferences::default(),
            reference_solve: None,
            factor_bytes: None,
        }
    }

    /// New, empty factors of the same sizes (a copied state's own caches).
    pub fn emptied(&self) -> Self {
        let (n_free, contacts) = self.low_rank.sizes();
        Factors::new(n_free, contacts)
    }
}
