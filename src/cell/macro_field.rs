//! Plate kinematics of the macroscopic strain E = (ε11, ε22, γ12, κ11, κ22, κ12) (engineering
//! shear γ12 = 2ε12 and twist κ12 = −2 w,xy):
//!
//! u_α = ε_αβ x_β + z κ_αβ x_β,  w = −½ (κ11 x² + κ22 y² + κ12 x y),
//! θ_x = w,y,  θ_y = −w,x,  θ_z = 0,
//!
//! with (x, y) measured from the cell origin and z from the cell's mid-surface.

use nalgebra::SMatrix;

/// Names of the six macroscopic quantities, in order.
pub const MACRO_NAMES: [&str; 6] = ["e11", "e22", "g12", "k11", "k22", "k12"];

/// A macroscopic strain E = (ε11, ε22, γ12, κ11, κ22, κ12) (1, 1, 1, 1/m, 1/m, 1/m).
pub type MacroStrain = [f64; 6];

/// Parses a macroscopic strain written as comma-separated `name=value` pairs with the names of
/// [`MACRO_NAMES`], e.g. `e11=0.02` or `g12=0.01,k11=2`; components not named are zero.
pub fn parse_macro_strain(s: &str) -> Result<MacroStrain, String> {
    let mut e = [0.0; 6];
    let mut seen = [false; 6];
    for part in s.split(',').filter(|p| !p.trim().is_empty()) {
        let (name, value) = part
            .split_once('=')
            .ok_or_else(|| format!("\"{part}\" is not name=value"))?;
        let name = name.trim();
        let k = MACRO_NAMES.iter().position(|n| *n == name).ok_or_else(|| {
            format!("unknown strain component \"{name}\" (use e11 e22 g12 k11 k22 k12)")
        })?;
        if seen[k] {
            return Err(format!("strain component {name} given twice"));
        }
        seen[k] = true;
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|_| format!("\"{}\" is not a number", value.trim()))?;
        if !v.is_finite() {
            return Err(format!("{name} = {v} is not finite"));
        }
        e[k] = v;
    }
    if !seen.iter().any(|&s| s) {
        return Err("no strain component given (e.g. e11=0.02)".into());
    }
    Ok(e)
}

/// The 6×6 matrix M(x) with (u, θ)(x) = M(x) E at the point (x, y, z) (relative coordinates).
pub fn macro_matrix(x: f64, y: f64, z: f64) -> SMatrix<f64, 6, 6> {
    let mut m = SMatrix::<f64, 6, 6>::zeros();
    // u_x = ε11 x + γ/2 y + z (κ11 x + κ12/2 y)
    m[(0, 0)] = x;
    m[(0, 2)] = 0.5 * y;
    m[(0, 3)] = z * x;
    m[(0, 5)] = 0.5 * z * y;
    // u_y = γ/2 x + ε22 y + z (κ12/2 x + κ22 y)
    m[(1, 1)] = y;
    m[(1, 2)] = 0.5 * x;
    m[(1, 4)] = z * y;
    m[(1, 5)] = 0.5 * z * x;
    // w = −½ (κ11 x² + κ22 y² + κ12 x y)
    m[(2, 3)] = -0.5 * x * x;
    m[(2, 4)] = -0.5 * y * y;
    m[(2, 5)] = -0.5 * x * y;
    // θ_x = w,y = −κ22 y − κ12 x / 2
    m[(3, 4)] = -y;
    m[(3, 5)] = -0.5 * x;
    // θ_y = −w,x = κ11 x + κ12 y / 2
    m[(4, 3)] = x;
    m[(4, 5)] = 0.5 * y;
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    #[test]
    fn strain_strings_parse_or_name_the_fault() {
        assert_eq!(
            parse_macro_strain("e11=0.02, k12 = -3").unwrap(),
            [0.02, 0.0, 0.0, 0.0, 0.0, -3.0]
        );
        for (bad, says) in [
            ("e11", "not name=value"),
            ("e33=1", "unknown strain component \"e33\""),
            ("e11=abc", "not a number"),
            ("e11=NaN", "not finite"),
            ("e11=inf", "not finite"),
            ("e11=1,e11=2", "given twice"),
            ("", "no strain component"),
        ] {
            let e = parse_macro_strain(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn rotations_are_the_curl_of_the_displacement_field() {
        // θ = ½ curl u at z = 0 must hold for the Kirchhoff field (θ_z = ½(u_y,x − u_x,y) = 0).
        let e = SVector::<f64, 6>::from([0.01, -0.02, 0.03, 0.4, -0.5, 0.6]);
        let (x, y, z, h) = (0.3, -0.7, 0.0, 1e-6);
        let f = |x: f64, y: f64, z: f64| macro_matrix(x, y, z) * e;
        let du = |k: usize, d: [f64; 3]| {
            (f(x + d[0], y + d[1], z + d[2])[k] - f(x - d[0], y - d[1], z - d[2])[k]) / (2.0 * h)
        };
        let curl = [
            0.5 * (du(2, [0.0, h, 0.0]) - du(1, [0.0, 0.0, h])),
            0.5 * (du(0, [0.0, 0.0, h]) - du(2, [h, 0.0, 0.0])),
            0.5 * (du(1, [h, 0.0, 0.0]) - du(0, [0.0, h, 0.0])),
        ];
        let th = f(x, y, z);
        // Kirchhoff: u_α,z = −w,α, so ½(w,y − v,z) = w,y etc.
        for k in 0..3 {
            assert!(
                (curl[k] - th[3 + k]).abs() < 1e-8,
                "{k}: {} vs {}",
                curl[k],
                th[3 + k]
            );
        }
    }
}
