//! Shape functions on an element of length l, s ∈ [0, l] (thesis 4.25, 4.26 with the corrected
//! H₂(s) = s − 2s²/l + s³/l²).

/// Linear shape functions N₁ = 1 − s/l, N₂ = s/l (4.25).
pub fn linear(s: f64, l: f64) -> [f64; 2] {
    [1.0 - s / l, s / l]
}

/// dN/ds.
pub fn linear_d1(_s: f64, l: f64) -> [f64; 2] {
    [-1.0 / l, 1.0 / l]
}

/// Hermite cubics H₁…H₄ (4.26): deflection and slope at node 1, deflection and slope at node 2.
pub fn hermite(s: f64, l: f64) -> [f64; 4] {
    let (x, x2, x3) = (s, s * s, s * s * s);
    [
        1.0 - 3.0 * x2 / (l * l) + 2.0 * x3 / (l * l * l),
        x - 2.0 * x2 / l + x3 / (l * l),
        3.0 * x2 / (l * l) - 2.0 * x3 / (l * l * l),
        -x2 / l + x3 / (l * l),
    ]
}

/// d²H/ds², the curvature rows of the strain-displacement matrix B.
pub fn hermite_d2(s: f64, l: f64) -> [f64; 4] {
    [
        -6.0 / (l * l) + 12.0 * s / (l * l * l),
        -4.0 / l + 6.0 * s / (l * l),
        6.0 / (l * l) - 12.0 * s / (l * l * l),
        -2.0 / l + 6.0 * s / (l * l),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_interpolates_values_and_slopes() {
        let l = 2.5;
        let h0 = hermite(0.0, l);
        let hl = hermite(l, l);
        assert_eq!(h0, [1.0, 0.0, 0.0, 0.0]);
        assert!(
            (hl[2] - 1.0).abs() < 1e-15
                && hl[0].abs() < 1e-15
                && hl[1].abs() < 1e-15
                && hl[3].abs() < 1e-15
        );
        // Slopes by central differences: H2'(0) = 1, H4'(l) = 1, the others 0.
        let e = 1e-6;
        let d0: Vec<f64> = (0..4)
            .map(|k| (hermite(e, l)[k] - hermite(-e, l)[k]) / (2.0 * e))
            .collect();
        let dl: Vec<f64> = (0..4)
            .map(|k| (hermite(l + e, l)[k] - hermite(l - e, l)[k]) / (2.0 * e))
            .collect();
        for (k, want) in [0.0, 1.0, 0.0, 0.0].iter().enumerate() {
            assert!((d0[k] - want).abs() < 1e-8);
        }
        for (k, want) in [0.0, 0.0, 0.0, 1.0].iter().enumerate() {
            assert!((dl[k] - want).abs() < 1e-8);
        }
        // Partition of unity for the deflection functions.
        assert!((hermite(0.7, l)[0] + hermite(0.7, l)[2] - 1.0).abs() < 1e-15);
    }
}
