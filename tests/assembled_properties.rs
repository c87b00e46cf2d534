//! Properties of the assembled systems of generated cells (proptest over every generator's
//! family, sizes and seeds drawn by the strategy): the cell-problem matrix with the closed
//! contacts in stick is symmetric to 1e-14 relative and positive definite, before the anchor
//! its null space is the three rigid translations, serial and parallel assembly agree bit for
//! bit, A^elas (ABD) is symmetric and positive definite, and every contact's Coulomb slip block
//! has the nonsymmetric part of its closed form. The inputs shrink towards the smallest cell
//! (fewest fibers, loops or elements, seed 0) when a property fails.

use fibercell::check::{check_model, rigid_mode_residuals, CheckOptions};
use fibercell::contact::{BlockState, ContactSet, ContactState, Friction};
use fibercell::generate::{
    geotextile, knitted, nonwoven, weave, FiberAmount, Geotextile, Knit, LengthDistribution,
    NonWoven, Weave, WeavePattern,
};
use fibercell::homogenize::{elastic_abd, PeriodicSystem};
use fibercell::model::ModelDescription;
use fibercell::solve::SolveOptions;
use fibercell::Model;
use nalgebra::{Matrix6, Vector2};
use proptest::prelude::*;

/// A generated cell, small enough for a property case to take well under a second.
#[derive(Clone, Debug)]
enum Cell {
    /// `fibers` fibers of 1.2 mm in a 3 mm square (the generator's defaults otherwise).
    NonWoven {
        fibers: usize,
        seed: u64,
    },
    /// A plain weave (over = 0) or an over/under twill, `elements` per half pitch.
    Woven {
        over: usize,
        under: usize,
        elements: usize,
    },
    Knitted {
        wales: usize,
        courses: usize,
    },
    /// The default geotextile with elements of 1/`refine` of the default length.
    Geotextile {
        refine: usize,
    },
}

impl Cell {
    /// The generated model; a non-woven the generator refuses (a typed error) is `Err`, any
    /// other family's refusal of its defaults a failure.
    fn description(&self) -> Result<ModelDescription, fibercell::Error> {
        Ok(match *self {
            Cell::NonWoven { fibers, seed } => {
                nonwoven(&NonWoven {
                    size: [3e-3, 3e-3],
                    amount: FiberAmount::Count { fibers },
                    length: LengthDistribution::Fixed { length: 1.2e-3 },
                    element_length: 2.5e-4,
                    seed,
                    ..NonWoven::default()
                })?
                .description
            }
            Cell::Woven {
                over,
                under,
                elements,
            } => weave(&Weave {
                pattern: if over == 0 {
                    WeavePattern::Plain
                } else {
                    WeavePattern::Twill { over, under }
                },
                half_pitch_elements: elements,
                ..Weave::default()
            })
            .expect("weave"),
            Cell::Knitted { wales, courses } => knitted(&Knit {
                wales,
                courses,
                ..Knit::default()
            })
            .expect("knit"),
            Cell::Geotextile { refine } => {
                let g = Geotextile::default();
                geotextile(&Geotextile {
                    element_length: g.element_length / refine as f64,
                    ..g
                })
                .expect("geotextile")
            }
        })
    }
}

/// Every family (non-wovens three times as often), shrinking towards its smallest cell. Non-wovens of 40–80 fibers in the 3 mm
/// square percolate for the seeds tried; one that does not is skipped (a typed error).
fn cells() -> impl Strategy<Value = Cell> {
    prop_oneof![
        3 => (40usize..80, 0u64..1000).prop_map(|(fibers, seed)| Cell::NonWoven { fibers, seed }),
        1 => (0usize..3, 1usize..3, 2usize..4).prop_map(|(over, under, elements)| Cell::Woven {
            over,
            under,
            elements
        }),
        1 => (1usize..3, 1usize..3).prop_map(|(wales, courses)| Cell::Knitted { wales, courses }),
        1 => (1usize..3).prop_map(|refine| Cell::Geotextile { refine }),
    ]
}

/// The model of `cell`, or a rejection of the case when the non-woven generator or the cell's
/// setup refuses it with a typed error (a non-woven that does not percolate).
fn model_or_reject(cell: &Cell) -> Result<Model, TestCaseError> {
    let reject = |e: fibercell::Error| TestCaseError::reject(format!("{cell:?}: {e}"));
    let model = Model::from_description(&cell.description().map_err(reject)?).expect("model");
    PeriodicSystem::new(&model).map_err(reject)?;
    Ok(model)
}

proptest! {
    // A fixed seed: every run draws the same cells (the generated non-wovens' κ₁ reaches
    // 10¹² in 52 draws, near the definiteness check's pivot bound), and a failure found once
    // is kept in the regressions file.
    #![proptest_config(ProptestConfig {
        cases: 12,
        rng_seed: proptest::test_runner::RngSeed::Fixed(20_261_127),
        ..ProptestConfig::default()
    })]

    /// The six cell problems' matrix (closed contacts in stick) is symmetric to 1e-14 relative
    /// and positive definite (Cholesky succeeds), and before the anchor the three unit
    /// translations are in its null space to 1e-12 relative (with the anchored matrix
    /// definite, the null space is exactly them).
    #[test]
    fn the_cell_matrix_is_symmetric_definite_with_translations_as_null_space(cell in cells()) {
        let model = model_or_reject(&cell)?;
        let report = check_model(&model, &CheckOptions {
            penalty_study: false,
            ..CheckOptions::default()
        }).expect("checks run");
        let m = &report.matrix;
        prop_assert!(m.asymmetry <= 1e-14, "{cell:?}: asymmetry {:e}", m.asymmetry);
        prop_assert!(m.positive_definite, "{cell:?}: {:?}", m.definiteness_error);
        let t = report.translations.expect("a cell");
        prop_assert!(t.relative.iter().all(|&r| r <= 1e-12), "{cell:?}: {:?}", t.relative);
    }

    /// The same cell without its `[cell]` and with no supports is a free model: its matrix
    /// (elements and the closed contacts found without periodic images, in stick) has the six
    /// rigid modes of each connected piece in its null space to 1e-12 relative (translations,
    /// and rotations about each piece's centroid, which strain no element and move no contact
    /// jump), and it is positive definite once one node of every piece is held — so the null
    /// space is exactly those 6 × pieces modes. `check` fails such a model on definiteness
    /// and reports the modes.
    #[test]
    fn a_free_model_has_the_six_rigid_modes_of_each_piece_as_null_space(cell in cells()) {
        let mut model = model_or_reject(&cell)?;
        model.cell = None;
        let modes = rigid_mode_residuals(&model, &SolveOptions::default()).expect("modes");
        prop_assert!(modes.pieces >= 1);
        prop_assert!(
            modes.relative.iter().all(|&r| r <= 1e-12),
            "{cell:?}: {} pieces, {:?}", modes.pieces, modes.relative
        );
        prop_assert!(modes.held_positive_definite, "{cell:?}: {} pieces", modes.pieces);
        let report = check_model(&model, &CheckOptions::default()).expect("checks run");
        prop_assert!(!report.matrix.positive_definite && !report.passed());
        prop_assert_eq!(report.rigid_modes.map(|m| m.pieces), Some(modes.pieces));
    }

    /// Assembly on one thread and on every thread gives the same matrix and driver couplings
    /// bit for bit (colored element blocks, contacts by the columns they fill).
    #[test]
    fn serial_and_parallel_assembly_agree_bitwise(cell in cells()) {
        let model = model_or_reject(&cell)?;
        let sys = PeriodicSystem::new(&model).expect("cell system");
        let serial = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("pool")
            .install(|| sys.assemble(&model));
        let parallel = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .expect("pool")
            .install(|| sys.assemble(&model));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        prop_assert!(bits(&serial.values) == bits(&parallel.values), "{cell:?}");
        let k_ee = |p: &fibercell::homogenize::PeriodicValues| bits(p.couplings.k_ee.as_slice());
        prop_assert!(k_ee(&serial) == k_ee(&parallel), "{cell:?}");
        for (a, b) in serial.couplings.coupling.iter().zip(&parallel.couplings.coupling) {
            prop_assert!(bits(a) == bits(b), "{cell:?}");
        }
    }

    /// A^elas (ABD per unit area) is symmetric and positive definite (Cholesky of the 6 × 6
    /// matrix scaled to unit diagonal). The six cell problems are solved separately, so the
    /// mirror entries differ by the solves' forward error, bounded by κ₁ ε of the largest entry
    /// (κ₁ of the scaled cell matrix, as `fibercell check` estimates it), at least 10⁻¹⁰.
    /// Sparse non-wovens near their percolation threshold are ill-conditioned: 48 fibers,
    /// seed 885, κ₁ 3.9·10¹¹, mirror entries 1.1·10⁻⁹ apart (47 fibers, seed 884: 4.6·10⁻⁹,
    /// which a fixed 10⁻⁹ failed); the wovens, knits and geotextiles 10⁻¹⁴ and below.
    #[test]
    fn abd_is_symmetric_positive_definite(cell in cells()) {
        let model = model_or_reject(&cell)?;
        let abd = elastic_abd(&model, &SolveOptions::default()).expect("ABD");
        let kappa = check_model(&model, &CheckOptions {
            penalty_study: false,
            ..CheckOptions::default()
        })
        .expect("checks run")
        .matrix
        .condition_estimate
        .expect("definite");
        let a = Matrix6::from_fn(|i, j| abd[i][j]);
        let tolerance = (kappa * f64::EPSILON).max(1e-10);
        prop_assert!(
            (a - a.transpose()).amax() <= tolerance * a.amax(),
            "{cell:?} (κ₁ {kappa:e}): {a}"
        );
        let s = Matrix6::from_diagonal(&a.diagonal().map(|d| 1.0 / d.sqrt()));
        let scaled = s * (a + a.transpose()) * 0.5 * s;
        prop_assert!(scaled.cholesky().is_some(), "{cell:?}: {a}");
    }

    /// Every contact of the cell sliding along `angle` under Coulomb friction: its block
    /// coefficients D differ from their transpose by exactly μ p_N (d e_nᵀ − e_n dᵀ) in the
    /// tangential rows/columns of the normal (K_T^sl = μ p_N Bᵀd nᵀB, 4.63; all else symmetric),
    /// to 1e-14 of p_N.
    #[test]
    fn the_coulomb_slip_block_has_its_closed_form_nonsymmetric_part(
        cell in cells(),
        angle in 0.0f64..std::f64::consts::TAU,
        mu in 0.05f64..1.0,
    ) {
        let model = model_or_reject(&cell)?;
        let periodicity = fibercell::cell::pair_boundary_nodes(&model).expect("pairing");
        let set = ContactSet::build_with(&model, Some(&periodicity)).expect("contacts");
        let d = Vector2::new(angle.cos(), angle.sin());
        let friction = Friction::Coulomb { mu, cohesion: 0.0 };
        prop_assume!(!set.pairs.is_empty(), "no contacts");
        for pair in &set.pairs {
            let s = BlockState {
                state: ContactState::Slip,
                direction: d,
                k_perp: 0.5 * pair.penalty_tangent,
            };
            let coefficients = pair.block_coefficients(&s, friction, 1e-8);
            let skew = coefficients - coefficients.transpose();
            let mut expected = Matrix6::zeros();
            let c = mu * pair.penalty_normal;
            for a in 0..2 {
                expected[(1 + a, 0)] = c * d[a];
                expected[(0, 1 + a)] = -c * d[a];
            }
            prop_assert!(
                (skew - expected).amax() <= 1e-14 * pair.penalty_normal,
                "{cell:?}: {skew}"
            );
        }
    }
}
