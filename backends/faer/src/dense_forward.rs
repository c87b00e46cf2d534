//! The forward half x ← L⁻¹ x of one dense right-hand side, as cursors over the groups of a
//! [`SolveSchedule`] that advance block by block on demand.
//!
//! On its own it runs each subtree task to its end, sums the tasks' updates of the top rows
//! and runs the top blocks. A sparse forward solve advances the same cursors alongside its
//! own blocks and eliminates the right-hand side in the blocks its columns read as one more
//! column of their kernels, so that those blocks of L are read once (see
//! [`crate::sparse_forward`]).

use crate::block_kernels::{forward_block, top_par, Shared, SolveSchedule};
use crate::block_tree::{BlockTree, NONE};
use crate::prefetch::prefetch_block;
use crate::symbolic::Symbolic;
use faer::Par;
use rayon::prelude::*;
use std::marker::PhantomData;

/// One right-hand side in the factor's row order, borrowed for its forward half.
pub(crate) struct DenseForward<'a> {
    tree: &'a BlockTree,
    schedule: &'a SolveSchedule,
    symbolic: &'a Symbolic,
    values: &'a [f64],
    x: &'a mut [f64],
}

/// Where one group's blocks eliminate the right-hand side.
pub(crate) struct ForwardCursor<'a> {
    tree: &'a BlockTree,
    schedule: &'a SolveSchedule,
    symbolic: &'a Symbolic,
    values: &'a [f64],
    /// The group's blocks, ascending (children before parents).
    blocks: &'a [usize],
    /// How many of them are done.
    done: usize,
    x: Shared,
    /// A subtree task's updates of the top rows (by the schedule's top index), kept privately;
    /// `None` for the top group, which writes every row directly.
    updates: Option<Vec<f64>>,
    below: Vec<f64>,
    /// The right-hand side stays mutably borrowed while the cursor lives.
    rows: PhantomData<&'a mut [f64]>,
}

impl<'a> DenseForward<'a> {
    /// The forward half of `x` (factor order) on the factor with block tree `tree`.
    pub(crate) fn new(
        tree: &'a BlockTree,
        schedule: &'a SolveSchedule,
        symbolic: &'a Symbolic,
        values: &'a [f64],
        x: &'a mut [f64],
    ) -> Self {
        DenseForward {
            tree,
            schedule,
            symbolic,
            values,
            x,
        }
    }

    /// x ← L⁻¹ x: the subtree tasks in parallel, then the top blocks.
    pub(crate) fn run(mut self) {
        let updates: Vec<Vec<f64>> = self
            .task_cursors()
            .into_par_iter()
            .map(ForwardCursor::into_updates)
            .collect();
        self.add_updates(&updates);
        self.top_cursor().finish();
    }

    /// One cursor per subtree task of the schedule, in task order (none when it is not
    /// parallel). They write disjoint rows; each must end with [`ForwardCursor::into_updates`],
    /// whose results go to [`DenseForward::add_updates`] before the top cursor runs.
    pub(crate) fn task_cursors(&mut self) -> Vec<ForwardCursor<'_>> {
        let x = Shared(self.x.as_mut_ptr());
        let top_rows = self.schedule.top_rows();
        self.schedule
            .task_blocks()
            .iter()
            .map(|blocks| self.cursor(blocks, x, Some(vec![0.0; top_rows])))
            .collect()
    }

    /// Adds the subtree tasks' updates of the top rows.
    pub(crate) fn add_updates(&mut self, updates: &[Vec<f64>]) {
        let top_index = self.schedule.top_index();
        for update in updates {
            for &s in self.schedule.top_blocks() {
                let b = &self.tree.shapes[s];
                let rows = b.begin..b.begin + b.width;
                for (xi, &k) in self.x[rows.clone()].iter_mut().zip(&top_index[rows]) {
                    *xi += update[k];
                }
            }
        }
    }

    /// The cursor of the top blocks (every block when the schedule is not parallel), to run
    /// after the tasks' updates were added.
    pub(crate) fn top_cursor(&mut self) -> ForwardCursor<'_> {
        let x = Shared(self.x.as_mut_ptr());
        self.cursor(self.schedule.top_blocks(), x, None)
    }

    fn cursor<'s>(
        &'s self,
        blocks: &'s [usize],
        x: Shared,
        updates: Option<Vec<f64>>,
    ) -> ForwardCursor<'s> {
        ForwardCursor {
            tree: self.tree,
            schedule: self.schedule,
            symbolic: self.symbolic,
            values: self.values,
            blocks,
            done: 0,
            x,
            updates,
            below: Vec::new(),
            rows: PhantomData,
        }
    }
}

impl ForwardCursor<'_> {
    /// Eliminates the group's blocks before block `s` (all of them for [`NONE`]).
    pub(crate) fn advance_to(&mut self, s: usize) {
        while let Some(&t) = self.blocks.get(self.done).filter(|&&t| t < s) {
            self.done += 1;
            if let Some(&next) = self.blocks.get(self.done) {
                prefetch_block(self.tree, self.values, next);
            }
            let b = self.tree.block(self.symbolic, self.values, t);
            // SAFETY: a task's blocks and the rows below them that are not top rows lie in its
            // subtrees, which no other cursor writes while the tasks run; top rows go to its
            // private updates. The top cursor runs alone.
            let own = unsafe { std::slice::from_raw_parts_mut(self.x.at(b.begin), b.width) };
            let par = match self.updates {
                Some(_) => Par::Seq,
                None => top_par(&b, self.schedule),
            };
            let mut below = std::mem::take(&mut self.below);
            forward_block(&b, own, &mut below, par);
            self.subtract(b.pattern, &below);
            self.below = below;
        }
    }

    /// The right-hand side's rows of block `s`, the group's next block, for a caller that
    /// eliminates the block itself: it solves them in place and hands what its pattern rows
    /// lose to [`ForwardCursor::eliminated`].
    pub(crate) fn rows_of(&mut self, s: usize) -> &mut [f64] {
        self.assert_next(s);
        let b = &self.tree.shapes[s];
        // SAFETY: as in `advance_to`: block `s` is the group's own.
        unsafe { std::slice::from_raw_parts_mut(self.x.at(b.begin), b.width) }
    }

    /// Block `s` (see [`ForwardCursor::rows_of`]) eliminated by the caller: subtracts `below`,
    /// its product with the block's rows below the diagonal, and moves past it.
    pub(crate) fn eliminated(&mut self, s: usize, below: &[f64]) {
        self.assert_next(s);
        self.done += 1;
        let b = self.tree.block(self.symbolic, self.values, s);
        self.subtract(b.pattern, below);
    }

    /// Panics unless block `s` is the group's next (a caller's walk out of step).
    fn assert_next(&self, s: usize) {
        assert_eq!(
            self.blocks.get(self.done),
            Some(&s),
            "block {s} is not next"
        );
    }

    /// x[pattern] −= below, a subtree task's top rows into its private updates.
    fn subtract(&mut self, pattern: &[usize], below: &[f64]) {
        let top_index = self.schedule.top_index();
        for (&row, v) in pattern.iter().zip(below) {
            match (
                &mut self.updates,
                top_index.get(row).copied().unwrap_or(NONE),
            ) {
                (Some(update), k) if k != NONE => update[k] -= v,
                // SAFETY: as in `advance_to`.
                _ => unsafe { *self.x.at(row) -= v },
            }
        }
    }

    /// Eliminates the rest of the group's blocks.
    pub(crate) fn finish(&mut self) {
        self.advance_to(NONE);
    }

    /// Finishes a subtree task's cursor: its updates of the top rows.
    pub(crate) fn into_updates(mut self) -> Vec<f64> {
        self.finish();
        self.updates.take().unwrap_or_default()
    }
}
