//! The load of the out-of-plane pressure problem Θ (thesis 3.28, 5.2): a uniform pressure p on
//! the top face of the cell, balanced by a uniform body force (the δ term of 5.2, so the load is
//! self-equilibrated and the periodic problem solvable), with zero macroscopic strain.
//!
//! For a network of beams the "top face" is what a view from above sees: the cell is sampled on
//! a grid of pixels, every pixel takes the fiber whose surface is highest over its centre
//! (periodic images included) and puts the force p · pixel area, pointing down, on that fiber's
//! centerline at the pixel — as consistent nodal loads through the element's own shape functions
//! (Lemma 4.26), so forces and moments are exact for the beam. Pixels that see no fiber (pores)
//! carry nothing: the pressure acts on the covered fraction of the cell. The same total force
//! acts upwards as a body force, uniform per unit fiber volume.

use crate::cell::CellGeometry;
use crate::contact::centerline_interpolation;
use crate::model::Model;
use nalgebra::{SMatrix, Vector3};
use rayon::prelude::*;

/// At most this many pixels (the pixel grows beyond it).
const MAX_PIXELS: usize = 4_000_000;

/// The Θ load on element images: consistent 12-vectors (two nodes × 6 DOFs) per loaded
/// (element, period shift of its image).
#[derive(Clone, Debug, PartialEq)]
pub struct PressureLoad {
    /// Loads per element image, sorted by (element, shift).
    pub elements: Vec<(usize, [i32; 2], SMatrix<f64, 12, 1>)>,
    /// Fraction of the cell area that sees a fiber from above.
    pub coverage: f64,
    /// Pixel size used (m).
    pub pixel: f64,
    /// Total downward pressure force p · covered area (N), balanced by the body force.
    pub force: f64,
}

/// Default pixel: a quarter of the smallest fiber radius.
pub fn default_pixel(model: &Model) -> f64 {
    0.25 * model
        .fibers
        .iter()
        .map(|f| f.section.radius)
        .fold(f64::INFINITY, f64::min)
}

/// The pressure load of `model` in the cell `g` for pressure `p` (Pa, pushing down) sampled
/// with pixels of about `pixel` (m).
pub fn pressure_load(model: &Model, g: &CellGeometry, p: f64, pixel: f64) -> PressureLoad {
    let els = model.elements();
    let [lx, ly] = g.size;
    let mut h = pixel.max(f64::MIN_POSITIVE);
    if (lx / h).ceil() * (ly / h).ceil() > MAX_PIXELS as f64 {
        h = (lx * ly / MAX_PIXELS as f64).sqrt();
    }
    let (nx, ny) = ((lx / h).ceil() as usize, (ly / h).ceil() as usize);
    let (hx, hy) = (lx / nx as f64, ly / ny as f64);
    let interpolation = |e: usize, t: f64| {
        let [a, b] = els[e].nodes.map(|n| model.nodes[n].x);
        centerline_interpolation(&a, &b, t)
    };
    let radius = |e: usize| model.fibers[els[e].fiber].section.radius;
    let ends = |e: usize, s: [i32; 2]| {
        els[e].nodes.map(|n| {
            let x = model.nodes[n].x;
            Vector3::new(
                x[0] + f64::from(s[0]) * lx,
                x[1] + f64::from(s[1]) * ly,
                x[2],
            )
        })
    };
    // Every element image (element, shift) that reaches into the cell, with its pixel rows.
    let mut images: Vec<(usize, [i32; 2], usize, usize)> = Vec::new();
    for e in 0..els.len() {
        let r = radius(e);
        for i in -1..=1 {
            for j in -1..=1 {
                let [a, b] = ends(e, [i, j]);
                let lo = [
                    a[0].min(b[0]) - r - g.origin[0],
                    a[1].min(b[1]) - r - g.origin[1],
                ];
                let hi = [
                    a[0].max(b[0]) + r - g.origin[0],
                    a[1].max(b[1]) + r - g.origin[1],
                ];
                if hi[0] < 0.0 || hi[1] < 0.0 || lo[0] > lx || lo[1] > ly {
                    continue;
                }
                let row = |y: f64| ((y / hy - 0.5).floor().max(0.0) as usize).min(ny - 1);
                images.push((e, [i, j], row(lo[1]), (row(hi[1]) + 1).min(ny - 1)));
            }
        }
    }
    // Rasterize band by band (in parallel): per pixel the highest fiber surface over its centre,
    // ties to the first image in (element, shift) order; each image sums the Lagrange weights
    // of its pixels' centerline parameters.
    const BAND: usize = 128;
    let pixel_force = p * hx * hy;
    let bands: Vec<Vec<(u32, u32, Weights)>> = (0..ny.div_ceil(BAND))
        .into_par_iter()
        .map(|band| {
            let v0 = band * BAND;
            let v1 = (v0 + BAND).min(ny);
            let mut top = vec![f64::NEG_INFINITY; (v1 - v0) * nx];
            let mut hit: Vec<(u32, f64)> = vec![(u32::MAX, 0.0); (v1 - v0) * nx];
            // The images reaching into this band, in (element, shift) order; `hit` holds
            // positions in this list.
            let mut present: Vec<u32> = Vec::new();
            for (k, &(e, s, r0, r1)) in images.iter().enumerate() {
                if r1 < v0 || r0 >= v1 {
                    continue;
                }
                let local = present.len() as u32;
                present.push(k as u32);
                let [a, b] = ends(e, s);
                let r = radius(e);
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let len2 = dx * dx + dy * dy;
                let x_lo = a[0].min(b[0]) - r - g.origin[0];
                let x_hi = a[0].max(b[0]) + r - g.origin[0];
                let u0 = ((x_lo / hx - 0.5).floor().max(0.0) as usize).min(nx - 1);
                let u1 = ((x_hi / hx - 0.5).ceil().max(0.0) as usize).min(nx - 1);
                for v in r0.max(v0)..=r1.min(v1 - 1) {
                    let py = g.origin[1] + (v as f64 + 0.5) * hy;
                    for u in u0..=u1 {
                        let px = g.origin[0] + (u as f64 + 0.5) * hx;
                        let t = if len2 > 0.0 {
                            (((px - a[0]) * dx + (py - a[1]) * dy) / len2).clamp(0.0, 1.0)
                        } else {
                            0.0
                        };
                        let (cx, cy) = (a[0] + t * dx, a[1] + t * dy);
                        let d2 = (px - cx).powi(2) + (py - cy).powi(2);
                        if d2 > r * r {
                            continue;
                        }
                        let z = a[2] + t * (b[2] - a[2]) + (r * r - d2).sqrt();
                        let idx = (v - v0) * nx + u;
                        if z > top[idx] {
                            top[idx] = z;
                            hit[idx] = (local, t);
                        }
                    }
                }
            }
            let mut sums: Vec<(u32, Weights)> = vec![(0, [0.0; 4]); present.len()];
            for &(local, t) in &hit {
                if local == u32::MAX {
                    continue;
                }
                let (count, w) = &mut sums[local as usize];
                *count += 1;
                for (wj, lj) in w.iter_mut().zip(lagrange(t)) {
                    *wj += lj;
                }
            }
            present
                .into_iter()
                .zip(sums)
                .filter(|(_, (count, _))| *count > 0)
                .map(|(k, (count, w))| (k, count, w))
                .collect()
        })
        .collect();
    let mut weights: Vec<Weights> = vec![[0.0; 4]; images.len()];
    let mut loaded = vec![false; images.len()];
    let mut hits = 0usize;
    for (k, count, w) in bands.into_iter().flatten() {
        hits += count as usize;
        loaded[k as usize] = true;
        for (a, b) in weights[k as usize].iter_mut().zip(w) {
            *a += b;
        }
    }
    let force = pixel_force * hits as f64;
    let coverage = hits as f64 / (nx * ny) as f64;
    // The balancing body force: per unit fiber volume, w_e = force · V_e / V on element e,
    // upwards; its Lagrange weights are ∫ℓ_j = (1, 3, 3, 1)/8 (exact for the cubic shape
    // functions).
    let volumes: Vec<f64> = els
        .iter()
        .enumerate()
        .map(|(e, el)| model.fibers[el.fiber].section.area() * element_length(model, e))
        .collect();
    let volume: f64 = volumes.iter().sum();
    let body = |e: usize| {
        if volume > 0.0 && force != 0.0 {
            force * volumes[e] / volume
        } else {
            0.0
        }
    };
    // Per loaded (element, shift), in that order: the pressure's weights −F W and, on the
    // unshifted image, the body force's.
    let mut entries: Vec<(usize, [i32; 2], Weights)> = Vec::with_capacity(images.len());
    let mut next = 0;
    for e in 0..els.len() {
        let w_body = body(e);
        let mut body_placed = w_body == 0.0;
        while next < images.len() && images[next].0 == e {
            let s = images[next].1;
            if !body_placed && s >= [0, 0] {
                if s == [0, 0] {
                    body_placed = true;
                    let w = weights[next].map(|w| -pixel_force * w);
                    entries.push((e, s, add_body(w, w_body)));
                    next += 1;
                    continue;
                }
                entries.push((e, [0, 0], add_body([0.0; 4], w_body)));
                body_placed = true;
            }
            if loaded[next] {
                entries.push((e, s, weights[next].map(|w| -pixel_force * w)));
            }
            next += 1;
        }
        if !body_placed {
            entries.push((e, [0, 0], add_body([0.0; 4], w_body)));
        }
    }
    let elements = entries
        .into_par_iter()
        .map(|(e, s, w)| {
            let mut f = SMatrix::<f64, 12, 1>::zeros();
            for (tau, wj) in LAGRANGE_NODES.into_iter().zip(w) {
                f += interpolation(e, tau).row(2).transpose() * wj;
            }
            (e, s, f)
        })
        .collect();
    PressureLoad {
        elements,
        coverage,
        pixel: hx.max(hy),
        force,
    }
}

/// Sums over an image's pixels of the four cubic Lagrange basis functions on
/// [`LAGRANGE_NODES`] at the pixels' centerline parameters: Σ_pixels N(t) = Σ_j W_j N(τ_j)
/// for any cubic N, such as the element's shape functions.
type Weights = [f64; 4];

/// The nodes τ_j of the cubic Lagrange basis.
const LAGRANGE_NODES: [f64; 4] = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0];

/// The cubic Lagrange basis ℓ_j(t) on [`LAGRANGE_NODES`].
fn lagrange(t: f64) -> Weights {
    let (a, b, c, d) = (t, t - 1.0 / 3.0, t - 2.0 / 3.0, t - 1.0);
    [
        -4.5 * b * c * d,
        13.5 * a * c * d,
        -13.5 * a * b * d,
        4.5 * a * b * c,
    ]
}

/// `w` plus an upward body force `w_body` spread with the weights ∫ℓ_j = (1, 3, 3, 1)/8.
fn add_body(w: Weights, w_body: f64) -> Weights {
    let simpson = [0.125, 0.375, 0.375, 0.125];
    std::array::from_fn(|j| w[j] + w_body * simpson[j])
}

fn element_length(model: &Model, e: usize) -> f64 {
    let [a, b] = model.elements()[e]
        .nodes
        .map(|n| Vector3::from(model.nodes[n].x));
    (b - a).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pixel sums go through four Lagrange weights: Σ_i N(t_i) = Σ_j W_j N(τ_j) must hold
    /// for the element's own (cubic) shape functions, to round-off.
    #[test]
    fn lagrange_weights_sum_the_shape_functions_exactly() {
        let (a, b) = ([0.1, -0.3, 0.2], [1.4, 0.5, -0.6]);
        let ts: Vec<f64> = (0..37)
            .map(|i| (f64::from(i) * 0.618_034).fract())
            .collect();
        let direct: SMatrix<f64, 3, 12> = ts
            .iter()
            .map(|&t| centerline_interpolation(&a, &b, t))
            .sum();
        let mut w = [0.0; 4];
        for &t in &ts {
            for (wj, lj) in w.iter_mut().zip(lagrange(t)) {
                *wj += lj;
            }
        }
        let via: SMatrix<f64, 3, 12> = LAGRANGE_NODES
            .iter()
            .zip(w)
            .map(|(&tau, wj)| centerline_interpolation(&a, &b, tau) * wj)
            .sum();
        assert!(
            (direct - via).amax() <= 1e-13 * direct.amax(),
            "{direct} vs {via}"
        );
        // Partition of unity and the integrals of the basis (Simpson's 3/8 rule).
        assert!((w.iter().sum::<f64>() - ts.len() as f64).abs() < 1e-12);
        let simpson = add_body([0.0; 4], 1.0);
        let quad: f64 = (0..1000)
            .map(|i| lagrange((f64::from(i) + 0.5) / 1000.0)[1] / 1000.0)
            .sum();
        assert!((quad - simpson[1]).abs() < 1e-6, "{quad}");
    }
}
