//! What a stick/slip run builds once: the contact pairs on generalized nodes, the pattern of
//! elements and every candidate contact block, the elastic values and load, the contact
//! colors for parallel scattering, and the run's contact law and tolerances.

use super::options::SLIP_DIRECTION_TOLERANCE;
use super::return_mapping::Law;
use super::shared_reference::SharedReference;
use super::IncrementalOptions;
use crate::assembly::{color_blocks, ContactColumns, ElementBlocks, Pattern};
use crate::constraints::Discretization;
use crate::contact::{ContactPair, ContactSet, Friction};
use crate::model::Model;
use crate::solve::SolverConfig;
use crate::Error;
use fibercell_solver::SolverError;
use nalgebra::{Vector2, Vector3};
use std::borrow::Cow;
use std::sync::Arc;

/// Everything of a run that does not change with the increments: borrowed by a run, owned
/// (`Setup<'static>`) by a [`crate::Cell`] whose states run on it.
pub(crate) struct Setup<'a> {
    pub model: Cow<'a, Model>,
    pub disc: Cow<'a, Discretization>,
    pub opts: Cow<'a, IncrementalOptions>,
    /// The contacts as found (pairs on the model's nodes, origins).
    pub set: Arc<ContactSet>,
    /// Contact jumps on generalized nodes: B T.
    pub pairs: Vec<ContactPair>,
    pub(super) law: Law,
    /// Coulomb sliding by a fixed point on the bounds (see
    /// [`IncrementalOptions::consistent_coulomb_tangent`]).
    pub bound_fixed_point: bool,
    /// Per contact, the slip direction of a frictionless pre-run (thesis Remark 4.38), when
    /// [`IncrementalOptions::fixed_slip_direction`] asks for it.
    pub fixed: Vec<Option<Vector2<f64>>>,
    pub elastic: ElementBlocks,
    /// Elements ∪ every candidate contact block, on the free DOFs.
    pub pattern: Pattern,
    /// K of the elements in the pattern's slots, kept where it is read repeatedly: without
    /// low-rank solves (every iteration assembles anew) and in a stateful cell (tangents).
    /// A run with low-rank solves reads it once, before its first reference factorization,
    /// and fills it again then instead ([`Setup::elastic_values`]): 0.23 GB on L.
    k_elastic: Option<Vec<f64>>,
    /// Contacts by color: no two of a color share a generalized node (the driver, which has no
    /// rows, aside), so a color's contacts add their loads in parallel.
    pub contact_colors: Vec<Vec<usize>>,
    /// The contacts by the nodes whose matrix columns they fill.
    pub contact_columns: ContactColumns,
    /// The elastic load at α = 1: F and the elements' products with prescribed DOFs.
    pub rhs_full: Vec<f64>,
    /// The nodal loads F on the free DOFs (α = 1).
    pub applied_free: Vec<f64>,
    /// The nodal loads summed per DOF (α = 1).
    pub applied_full: [f64; 6],
    /// Per contact, its block columns on prescribed DOFs (their products go to the load).
    pub prescribed: Vec<Vec<usize>>,
    pub solver_config: SolverConfig,
    /// Low-rank solves need a direct symmetric backend.
    pub low_rank_possible: bool,
    /// Lengths below this are roundoff (1e-12 of the model size).
    pub length_tol: f64,
    /// See [`SLIP_DIRECTION_TOLERANCE`].
    pub direction_tol: f64,
    pub stabilization: f64,
    /// A cell's factorization at rest, shared by its states (none in a single run).
    pub(super) shared: Option<SharedReference>,
}

impl<'a> Setup<'a> {
    /// Checks the options and builds the run's fixed data.
    pub fn new(
        model: Cow<'a, Model>,
        disc: Cow<'a, Discretization>,
        set: ContactSet,
        opts: Cow<'a, IncrementalOptions>,
    ) -> Result<Self, Error> {
        if opts.max_state_iterations == 0 {
            return Err(Error::InvalidOption(
                "max_state_iterations must be at least 1".into(),
            ));
        }
        let stabilization = opts.stabilization;
        if !(stabilization.is_finite() && stabilization >= 0.0) {
            return Err(Error::InvalidOption(format!(
                "stabilization = {stabilization} must be finite and ≥ 0"
            )));
        }
        let friction = model
            .contact
            .as_ref()
            .map_or(Friction::None, |c| c.friction);
        let bonded = opts.bonded || model.contact.as_ref().is_some_and(|c| c.bonded);
        let bound_fixed_point = matches!(friction, Friction::Coulomb { mu, .. } if mu > 0.0)
            && !opts.consistent_coulomb_tangent;
        let fixed = fixed_directions(&model, &disc, &set, &opts)?;
        let pairs: Vec<ContactPair> = set.pairs.iter().map(|p| disc.contact_pair(p)).collect();
        let elastic = ElementBlocks::new(&model, &disc);
        let mut blocks: Vec<Vec<usize>> = (0..model.elements().len())
            .map(|e| elastic.gnodes_of(&model, e).to_vec())
            .collect();
        blocks.extend(pairs.iter().map(|p| p.jump.nodes.clone()));
        let block_refs: Vec<&[usize]> = blocks.iter().map(|b| &b[..]).collect();
        let pattern = Pattern::from_blocks(
            disc.reduced_indices(),
            disc.n_free(),
            &block_refs,
            model.elements().len(),
        )?;
        let contact_colors = color_blocks(
            disc.n_gnodes(),
            pairs.iter().map(|p| &p.jump.nodes[..]),
            disc.driver(),
        );
        let contact_columns = ContactColumns::new(disc.n_gnodes(), disc.driver(), &pairs, &pattern);
        let mut applied_full = [0.0; 6];
        for l in &model.loads {
            applied_full[l.dof.index()] += l.value;
        }
        let prescribed = pairs
            .iter()
            .map(|p| {
                (0..p.size())
                    .filter(|&c| disc.reduced(6 * p.jump.nodes[c / 6] + c % 6).is_none())
                    .collect()
            })
            .collect();
        let solver_config = opts.solve.solver_config(disc.node_block_starts());
        let low_rank_possible = opts.reuse_factor
            && solver_config
                .build()
                .is_ok_and(|s| !s.capabilities().iterative);
        let k_elastic = if low_rank_possible {
            None
        } else {
            let mut k = vec![0.0; pattern.nnz()];
            elastic.fill(&model, &pattern, &mut k, opts.solve.fill)?;
            Some(k)
        };
        let (length_tol, direction_tol) = (
            1e-12 * model.size(),
            SLIP_DIRECTION_TOLERANCE * model.size(),
        );
        Ok(Setup {
            rhs_full: elastic.rhs(&model, &disc),
            applied_free: ElementBlocks::applied(&model, &disc),
            model,
            disc,
            opts,
            set: Arc::new(set),
            pairs,
            law: Law { friction, bonded },
            bound_fixed_point,
            fixed,
            elastic,
            pattern,
            k_elastic,
            contact_colors,
            contact_columns,
            applied_full,
            prescribed,
            solver_config,
            low_rank_possible,
            length_tol,
            direction_tol,
            stabilization,
            shared: None,
        })
    }

    /// Factorizes the rest state once for every state run on this setup to share (see
    /// [`SharedReference`]).
    pub fn share_rest_factorization(&mut self) -> Result<(), Error> {
        if self.k_elastic.is_none() {
            // A cell's states read them for every tangent.
            let mut k = Vec::new();
            self.elastic_values(&mut k)?;
            self.k_elastic = Some(k);
        }
        self.shared = SharedReference::build(self)?;
        Ok(())
    }

    /// The bytes of the shared rest factor's values, when there is one (tests).
    #[cfg(test)]
    pub(crate) fn shared_factor_bytes(&self) -> Option<usize> {
        self.shared.as_ref().and_then(|s| s.factor_bytes())
    }

    /// Writes K of the elements into `values` (resized to the pattern's slots): the kept
    /// copy, or filled anew.
    pub fn elastic_values(&self, values: &mut Vec<f64>) -> Result<(), Error> {
        values.resize(self.pattern.nnz(), 0.0);
        match &self.k_elastic {
            Some(k) => values.copy_from_slice(k),
            None => self
                .elastic
                .fill(&self.model, &self.pattern, values, self.opts.solve.fill)?,
        }
        Ok(())
    }

    /// The run's friction law.
    pub fn friction(&self) -> Friction {
        self.law.friction
    }

    /// Unknowns of the linear systems.
    pub fn n_free(&self) -> usize {
        self.disc.n_free()
    }

    /// A solver error with its row named as a node and DOF of the model.
    pub fn locate(&self, e: SolverError) -> Error {
        self.disc.locate(&self.model, e)
    }
}

/// The slip directions of a frictionless pre-run when
/// [`IncrementalOptions::fixed_slip_direction`] asks for them (thesis Remark 4.38), else none.
fn fixed_directions(
    model: &Model,
    disc: &Discretization,
    set: &ContactSet,
    opts: &IncrementalOptions,
) -> Result<Vec<Option<Vector2<f64>>>, Error> {
    let friction = model
        .contact
        .as_ref()
        .map_or(Friction::None, |c| c.friction);
    if !opts.fixed_slip_direction || friction == Friction::None {
        return Ok(vec![None; set.pairs.len()]);
    }
    let mut frictionless = model.clone();
    if let Some(c) = frictionless.contact.as_mut() {
        c.friction = Friction::None;
    }
    let pre = super::run_incremental(
        &frictionless,
        disc,
        set.clone(),
        &IncrementalOptions {
            fixed_slip_direction: false,
            deadline: None,
            ..opts.clone()
        },
        None,
    )?;
    let last = pre.contact_results.last().cloned().unwrap_or_default();
    Ok(set
        .pairs
        .iter()
        .zip(&last)
        .map(|(p, r)| {
            let g = Vector3::from(r.relative_tangential);
            let d = Vector2::new(p.tangents[0].dot(&g), p.tangents[1].dot(&g));
            (d.norm() > 0.0).then(|| d / d.norm())
        })
        .collect())
}
