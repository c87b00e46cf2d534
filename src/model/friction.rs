//! The friction law of a model's contacts, validated from its `FrictionSpec`.

/// The friction law.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Friction {
    /// Frictionless: no tangential terms.
    #[default]
    None,
    /// Coulomb with cohesion: |F_t| ≤ c + μ max(N, 0).
    Coulomb {
        /// Friction coefficient μ ≥ 0.
        mu: f64,
        /// Cohesion c ≥ 0 (N): the bound at zero normal force.
        cohesion: f64,
    },
    /// Tresca: |F_t| ≤ G, independent of N.
    Tresca {
        /// Friction bound G ≥ 0 (N).
        bound: f64,
    },
}
