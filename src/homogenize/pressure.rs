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

/// A consistent load on an element image: ((element, period shift), 12-vector).
type ImageLoad = ((usize, [i32; 2]), SMatrix<f64, 12, 1>);

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
    // ties to the first image in (element, shift) order; then the pixel's force on that image.
    const BAND: usize = 128;
    let pixel_force = p * hx * hy;
    let bands: Vec<(usize, Vec<ImageLoad>)> = (0..ny.div_ceil(BAND))
        .into_par_iter()
        .map(|band| {
            let v0 = band * BAND;
            let v1 = (v0 + BAND).min(ny);
            let mut top = vec![f64::NEG_INFINITY; (v1 - v0) * nx];
            let mut hit: Vec<(u32, f64)> = vec![(u32::MAX, 0.0); (v1 - v0) * nx];
            for (k, &(e, s, r0, r1)) in images.iter().enumerate() {
                if r1 < v0 || r0 >= v1 {
                    continue;
                }
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
                            hit[idx] = (k as u32, t);
                        }
                    }
                }
            }
            let mut count = 0;
            let mut loads: Vec<ImageLoad> = Vec::new();
            for &(k, t) in &hit {
                if k == u32::MAX {
                    continue;
                }
                count += 1;
                let (e, s, ..) = images[k as usize];
                let f = interpolation(e, t).transpose() * Vector3::new(0.0, 0.0, -pixel_force);
                loads.push(((e, s), f));
            }
            loads.sort_by_key(|&(key, _)| key);
            let mut merged: Vec<ImageLoad> = Vec::new();
            for (key, f) in loads {
                match merged.last_mut() {
                    Some(last) if last.0 == key => last.1 += f,
                    _ => merged.push((key, f)),
                }
            }
            (count, merged)
        })
        .collect();
    let hits: usize = bands.iter().map(|b| b.0).sum();
    let force = pixel_force * hits as f64;
    let coverage = hits as f64 / (nx * ny) as f64;
    let mut loads: Vec<(usize, [i32; 2], SMatrix<f64, 12, 1>)> = bands
        .into_iter()
        .flat_map(|(_, l)| l.into_iter().map(|((e, s), f)| (e, s, f)))
        .collect();
    // The balancing body force: per unit fiber volume, integrated with 3-point Gauss (exact for
    // the cubic shape functions).
    let volumes: Vec<f64> = els
        .iter()
        .enumerate()
        .map(|(e, el)| model.fibers[el.fiber].section.area() * element_length(model, e))
        .collect();
    let volume: f64 = volumes.iter().sum();
    if volume > 0.0 && force != 0.0 {
        let gauss = [
            (0.5 - 0.5 * 0.6f64.sqrt(), 5.0 / 18.0),
            (0.5, 8.0 / 18.0),
            (0.5 + 0.5 * 0.6f64.sqrt(), 5.0 / 18.0),
        ];
        for (e, v) in volumes.iter().enumerate() {
            let w = force * v / volume;
            let mut f = SMatrix::<f64, 12, 1>::zeros();
            for (t, weight) in gauss {
                f += interpolation(e, t).transpose() * Vector3::new(0.0, 0.0, w * weight);
            }
            loads.push((e, [0, 0], f));
        }
    }
    loads.sort_by_key(|&(e, s, _)| (e, s));
    let mut merged: Vec<(usize, [i32; 2], SMatrix<f64, 12, 1>)> = Vec::with_capacity(loads.len());
    for (e, s, f) in loads {
        match merged.last_mut() {
            Some(last) if last.0 == e && last.1 == s => last.2 += f,
            _ => merged.push((e, s, f)),
        }
    }
    PressureLoad {
        elements: merged,
        coverage,
        pixel: hx.max(hy),
        force,
    }
}

fn element_length(model: &Model, e: usize) -> f64 {
    let [a, b] = model.elements()[e]
        .nodes
        .map(|n| Vector3::from(model.nodes[n].x));
    (b - a).norm()
}
