//! The order in which a block stores the columns of a sparse forward solve: by the first row
//! each column can be nonzero in, so that the triangular solve and the product below it skip
//! the leading zero rows of each group of columns.
//!
//! In L x = b restricted to one block, a column whose right-hand side vanishes above row r has
//! a solution that vanishes above r. On the root separator of a nested-dissection factor the
//! columns arriving through one child start at that child's first pattern row: on the L bench
//! cell half of the 764 columns start 978 rows into the 3,240-row root, and skipping their
//! zeros saves 28 % of the root's triangular solve.

use std::ops::Range;

/// Blocks with fewer multiply-adds in their triangular solve keep their columns ascending.
const MIN_SOLVE_FLOPS: usize = 1 << 16;
/// Columns join a group whose first row is at most this many rows (or a 32nd of the width)
/// above their own.
const SLACK_ROWS: usize = 8;
/// Smaller groups join the one before (small panels run the dense kernels slowly).
const MIN_GROUP: usize = 8;
/// The layout is used when it saves at least this share of the block's flops.
const MIN_SAVING: f64 = 0.1;

/// A block's columns in storage order, in groups that share a first row.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ColumnLayout {
    /// Storage position → index among the block's columns (ascending column numbers).
    pub(crate) order: Vec<usize>,
    /// Index among the block's columns → storage position.
    pub(crate) position: Vec<usize>,
    /// Consecutive storage columns and the row above which they all vanish.
    pub(crate) groups: Vec<(Range<usize>, usize)>,
}

impl ColumnLayout {
    /// Whether a block `width` wide reached by `columns` columns is large enough to try.
    pub(crate) fn may_pay(width: usize, columns: usize) -> bool {
        columns >= 2 * MIN_GROUP && width * width * columns >= MIN_SOLVE_FLOPS
    }

    /// The layout of a block `width` wide with `below` rows under it whose columns can be
    /// nonzero from rows `first` on (`width`: never), or `None` when ascending order is as
    /// cheap (within [`MIN_SAVING`]).
    pub(crate) fn by_first_rows(first: &[usize], width: usize, below: usize) -> Option<Self> {
        let m = first.len();
        if !Self::may_pay(width, m) {
            return None;
        }
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by_key(|&c| (first[c].min(width), c));
        let slack = SLACK_ROWS.max(width / 32);
        let mut groups: Vec<(Range<usize>, usize)> = Vec::new();
        for (q, &c) in order.iter().enumerate() {
            let row = first[c].min(width);
            match groups.last_mut() {
                Some((range, low)) if row <= *low + slack || range.len() < MIN_GROUP => {
                    range.end = q + 1;
                }
                _ => groups.push((q..q + 1, row)),
            }
        }
        if let [.., (before, _), (last, _)] = groups.as_mut_slice() {
            if last.len() < MIN_GROUP {
                before.end = last.end;
                groups.pop();
            }
        }
        let cost = |low: usize| {
            let rows = width - low;
            (rows * rows + 2 * below * rows) as f64
        };
        let full = m as f64 * cost(0);
        let grouped: f64 = groups
            .iter()
            .map(|(r, low)| r.len() as f64 * cost(*low))
            .sum();
        if grouped > (1.0 - MIN_SAVING) * full {
            return None;
        }
        let mut position = vec![0; m];
        for (q, &c) in order.iter().enumerate() {
            position[c] = q;
        }
        Some(ColumnLayout {
            order,
            position,
            groups,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_are_grouped_by_first_row_and_the_groups_start_at_their_lowest() {
        // 20 columns from row 0, 20 from about 600 (spread by 5 rows), interleaved.
        let first: Vec<usize> = (0..40)
            .map(|c| if c % 2 == 0 { 0 } else { 600 + c % 5 })
            .collect();
        let layout = ColumnLayout::by_first_rows(&first, 1000, 0).unwrap();
        assert_eq!(layout.groups, vec![(0..20, 0), (20..40, 600)]);
        for (q, &c) in layout.order.iter().enumerate() {
            assert_eq!(layout.position[c], q);
            let (range, low) = layout.groups.iter().find(|(r, _)| r.contains(&q)).unwrap();
            assert!(first[c] >= *low && range.contains(&q));
        }
        // The even columns keep their relative order.
        assert_eq!(&layout.order[..3], &[0, 2, 4]);
    }

    #[test]
    fn no_layout_when_the_saving_is_small_or_the_block_tiny() {
        // All from row 0, or a few rows in: nothing to skip.
        assert_eq!(ColumnLayout::by_first_rows(&[0; 40], 1000, 50), None);
        assert_eq!(ColumnLayout::by_first_rows(&[20; 40], 1000, 50), None);
        // A tiny block.
        let first: Vec<usize> = (0..40).map(|c| c % 2).collect();
        assert_eq!(ColumnLayout::by_first_rows(&first, 2, 0), None);
        // A short trailing group joins the one before: 30 from 0, 5 from 900.
        let first: Vec<usize> = (0..35).map(|c| if c < 30 { 0 } else { 900 }).collect();
        assert_eq!(ColumnLayout::by_first_rows(&first, 1000, 0), None);
    }
}
