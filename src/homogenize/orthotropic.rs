//! The thesis's moduli and the orthotropic constants of §5.1.2.

use serde::Serialize;

/// The thesis's names for the membrane and bending moduli (per unit width, from A and D).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ThesisModuli {
    /// ā₁₁¹¹ = A11 (N/m).
    pub a11_11: f64,
    /// ā₂₂²² = A22 (N/m).
    pub a22_22: f64,
    /// ā₁₂¹² = A12, the coupling of the two normal directions (N/m).
    pub a12_12: f64,
    /// ā₂₂¹¹ = A66, the in-plane shear modulus (N/m) — the thesis's label.
    pub a22_11: f64,
    /// c₁₁₁₁ = D11 (N·m).
    pub c1111: f64,
    /// c₁₁₂₂ = D12 (N·m).
    pub c1122: f64,
    /// c₂₂₂₂ = D22 (N·m).
    pub c2222: f64,
}

/// In-plane orthotropic constants (thesis §5.1.2), per unit width (N/m) and as moduli in Pa
/// (divided by the cell thickness).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Orthotropic {
    /// E1 = A11 − A12²/A22 (N/m).
    pub e1: f64,
    /// E2 = A22 − A12²/A11 (N/m).
    pub e2: f64,
    /// ν12 = −ε22/ε11 under a uniaxial N11 (N22 = N12 = 0) = A12/A22: the common convention
    /// (first index the load, second the contraction; E1 ν21 = E2 ν12). The thesis calls this
    /// ratio ν21 (see [`Orthotropic::thesis_nu21`]).
    pub nu12: f64,
    /// ν21 = −ε11/ε22 under a uniaxial N22 = A12/A11 (the thesis's ν12).
    pub nu21: f64,
    /// The thesis's ν12 = A12/A11 (§5.1.2), which is [`Orthotropic::nu21`] here.
    pub thesis_nu12: f64,
    /// The thesis's ν21 = A12/A22, which is [`Orthotropic::nu12`] here.
    pub thesis_nu21: f64,
    /// G12 = A66 (N/m).
    pub g12: f64,
    /// E1 / h (Pa).
    pub e1_pa: f64,
    /// E2 / h (Pa).
    pub e2_pa: f64,
    /// G12 / h (Pa).
    pub g12_pa: f64,
}

impl ThesisModuli {
    /// From the 6×6 ABD matrix (rows/columns ε11, ε22, γ12, κ11, κ22, κ12).
    pub fn from_abd(abd: &[[f64; 6]; 6]) -> Self {
        ThesisModuli {
            a11_11: abd[0][0],
            a22_22: abd[1][1],
            a12_12: abd[0][1],
            a22_11: abd[2][2],
            c1111: abd[3][3],
            c1122: abd[3][4],
            c2222: abd[4][4],
        }
    }
}

impl Orthotropic {
    /// From the membrane block of ABD and the thickness.
    pub fn from_abd(abd: &[[f64; 6]; 6], thickness: f64) -> Self {
        let (a11, a22, a12, a66) = (abd[0][0], abd[1][1], abd[0][1], abd[2][2]);
        let e1 = a11 - a12 * a12 / a22;
        let e2 = a22 - a12 * a12 / a11;
        Orthotropic {
            e1,
            e2,
            nu12: a12 / a22,
            nu21: a12 / a11,
            thesis_nu12: a12 / a11,
            thesis_nu21: a12 / a22,
            g12: a66,
            e1_pa: e1 / thickness,
            e2_pa: e2 / thickness,
            g12_pa: a66 / thickness,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_the_thesis_second_geotextile_constants() {
        // Thesis §5.3.4: ā₁₁¹¹ = 0.415201e6, ā₂₂²² = 1.420008e6, ā₁₂¹² = 0.844399e4,
        // ā₂₂¹¹ = 1.359719e4 give ν12 = 0.0203, ν21 = 0.0059, E1 = 0.4151e6, E2 = 1.4198e6.
        let mut abd = [[0.0; 6]; 6];
        abd[0][0] = 0.415201e6;
        abd[1][1] = 1.420008e6;
        abd[0][1] = 0.844399e4;
        abd[1][0] = 0.844399e4;
        abd[2][2] = 1.359719e4;
        let o = Orthotropic::from_abd(&abd, 1.0);
        // The thesis prints four digits, truncated (E1 = 415,150.8 appears as 0.4151e6).
        assert!((o.thesis_nu12 - 0.0203).abs() < 1e-4, "{}", o.thesis_nu12);
        assert!((o.thesis_nu21 - 0.0059).abs() < 1e-4, "{}", o.thesis_nu21);
        assert_eq!((o.nu12, o.nu21), (o.thesis_nu21, o.thesis_nu12));
        assert!((o.e1 - 0.4151e6).abs() < 0.0001e6, "{}", o.e1);
        assert!((o.e2 - 1.4198e6).abs() < 0.0001e6, "{}", o.e2);
        assert_eq!(o.g12, 1.359719e4);
    }

    /// ν12 is the contraction −ε22/ε11 under a uniaxial N11, solved from the membrane block
    /// (Cramer's rule on [[A11, A12], [A12, A22]] ε = (N, 0)), and E1 ν21 = E2 ν12.
    #[test]
    fn nu12_is_the_contraction_under_load_in_direction_1() {
        let (a11, a22, a12) = (3.0e5, 1.2e5, 4.0e4);
        let mut abd = [[0.0; 6]; 6];
        abd[0][0] = a11;
        abd[1][1] = a22;
        abd[0][1] = a12;
        abd[1][0] = a12;
        abd[2][2] = 1.0e4;
        let o = Orthotropic::from_abd(&abd, 1.0);
        let n = 1.0;
        let det = a11 * a22 - a12 * a12;
        let (e11, e22) = (n * a22 / det, -n * a12 / det);
        assert!((o.nu12 - (-e22 / e11)).abs() <= 1e-15 * o.nu12);
        assert!(
            (o.e1 - n / e11).abs() <= 1e-12 * o.e1,
            "E1 = N11/ε11 under uniaxial N11"
        );
        assert!((o.e1 * o.nu21 - o.e2 * o.nu12).abs() <= 1e-12 * o.e1 * o.nu21);
        // The two differ here, so the labels cannot be mixed up unnoticed.
        assert!((o.nu12 - o.nu21).abs() > 0.1);
    }
}
