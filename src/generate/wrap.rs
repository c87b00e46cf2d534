//! Cutting an unwrapped 3D polyline at the faces of a periodic cell into pieces that lie in
//! the cell, with end nodes exactly on the faces (the piece leaving through x = L_x continues
//! as the piece entering at x = 0, and their end nodes pair).

use crate::model::{FiberSpec, ModelDescription, NodeSpec};

/// A face line: axis (0: x, 1: y) and m in x_axis = m L_axis.
type Face = (usize, i64);

/// Appends a fiber through new nodes at `points` (ids continue the description's numbering).
pub fn push_fiber(d: &mut ModelDescription, points: &[[f64; 3]], radius: f64, material: &str) {
    let ids = points
        .iter()
        .map(|&x| {
            let id = d.nodes.len() as u64 + 1;
            d.nodes.push(NodeSpec { id, x });
            id
        })
        .collect();
    d.fibers.push(FiberSpec {
        id: d.fibers.len() as u64 + 1,
        nodes: ids,
        radius,
        material: material.into(),
    });
}

/// The pieces of the polyline `points` (cell origin at 0, periods `period`): a node is added
/// where a segment crosses a face line x = m L_x or y = m L_y (z interpolated), interior
/// vertices closer than `min_spacing` to such a node are dropped, and each run between face
/// nodes is moved into the cell by whole periods. The polyline's own ends are kept as they are.
pub fn wrap_polyline(
    points: &[[f64; 3]],
    period: [f64; 2],
    min_spacing: f64,
) -> Vec<Vec<[f64; 3]>> {
    // (position, on a face: (axis, m))
    let mut nodes: Vec<([f64; 3], Option<Face>)> = Vec::with_capacity(points.len() + 8);
    let on_face = |x: [f64; 3]| {
        (0..2).find_map(|axis| {
            let m = (x[axis] / period[axis]).round();
            ((x[axis] - m * period[axis]).abs() < 1e-12 * period[axis]).then_some((axis, m as i64))
        })
    };
    let n = points.len();
    for (k, &p) in points.iter().enumerate() {
        if k > 0 {
            let prev = points[k - 1];
            let mut hits: Vec<(f64, usize, i64)> = Vec::new();
            for axis in 0..2 {
                let (a, b) = (prev[axis] / period[axis], p[axis] / period[axis]);
                for m in (a.min(b).ceil() as i64)..=(a.max(b).floor() as i64) {
                    let t = (m as f64 - a) / (b - a);
                    if t > 1e-12 && t < 1.0 - 1e-12 {
                        hits.push((t, axis, m));
                    }
                }
            }
            hits.sort_by(|x, y| x.0.total_cmp(&y.0));
            for (t, axis, m) in hits {
                let mut q = [0, 1, 2].map(|i| prev[i] + t * (p[i] - prev[i]));
                q[axis] = m as f64 * period[axis];
                // An interior vertex just before the face gives way to it.
                while nodes.len() > 1
                    && nodes
                        .last()
                        .is_some_and(|(x, f)| f.is_none() && dist(*x, q) < min_spacing)
                {
                    nodes.pop();
                }
                nodes.push((q, Some((axis, m))));
            }
        }
        let face = on_face(p);
        let last_is_face = nodes.last().is_some_and(|(_, f)| f.is_some());
        let interior = k > 0 && k + 1 < n;
        if interior
            && face.is_none()
            && last_is_face
            && dist(nodes[nodes.len() - 1].0, p) < min_spacing
        {
            continue; // just after a face node
        }
        nodes.push((p, if interior { face } else { None }));
    }
    let mut pieces = Vec::new();
    let mut start = 0;
    for k in 1..nodes.len() {
        if nodes[k].1.is_some() || k == nodes.len() - 1 {
            let run = &nodes[start..=k];
            let (a, b) = (run[0].0, run[1].0);
            let cell = [0, 1].map(|i| (0.5 * (a[i] + b[i]) / period[i]).floor());
            let piece = run
                .iter()
                .map(|&(x, face)| {
                    let mut y = [x[0] - cell[0] * period[0], x[1] - cell[1] * period[1], x[2]];
                    if let Some((axis, m)) = face {
                        y[axis] = (m as f64 - cell[axis]) * period[axis];
                    }
                    y
                })
                .collect();
            pieces.push(piece);
            start = k;
        }
    }
    pieces
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_diagonal_line_is_cut_at_every_face_and_wrapped() {
        // From (0.5, 0.2) to (2.5, 1.7) in a 1 × 1 cell: crosses x = 1, 2 and y = 1.
        let pts: Vec<[f64; 3]> = (0..=20)
            .map(|k| {
                let t = k as f64 / 20.0;
                [0.5 + 2.0 * t, 0.2 + 1.5 * t, t]
            })
            .collect();
        let pieces = wrap_polyline(&pts, [1.0, 1.0], 1e-3);
        assert_eq!(pieces.len(), 4);
        for w in pieces.windows(2) {
            // The end of one piece and the start of the next are the same point modulo a period.
            let (a, b) = (w[0][w[0].len() - 1], w[1][0]);
            let d = [a[0] - b[0], a[1] - b[1]];
            assert!(
                d.iter().all(|v| (v - v.round()).abs() < 1e-12),
                "{a:?} {b:?}"
            );
            assert_eq!(a[2], b[2]);
        }
        for p in pieces.iter().flatten() {
            assert!(
                (0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1]),
                "{p:?}"
            );
        }
    }
}
