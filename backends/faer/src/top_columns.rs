//! Where the subtree tasks of a sparse forward solve add to the top blocks' columns.
//!
//! A column of the right-hand sides reaches the top blocks through the subtrees it has
//! nonzeros in. The first task reaching it (in task order) subtracts from its top-block values
//! directly; any other task reaching it does so in a private column, summed in afterwards. Most
//! columns enter through one subtree only, so the private columns are few, instead of a private
//! copy of every top block per task.

use crate::block_tree::NONE;
use std::marker::PhantomData;

/// Marks a column a task does not reach (and must not write).
const UNREACHED: usize = NONE - 1;

/// The top blocks' solution values as the tasks share them: one base pointer per top block
/// (its `width × columns` values, column-major in storage order).
#[derive(Clone, Copy)]
struct Base(*mut f64);
// SAFETY: each task writes only the columns it owns (see `TopColumns::column`); the top
// blocks' vectors stay mutably borrowed by the accesses until `TopColumns::join` takes them
// all back.
unsafe impl Send for Base {}
unsafe impl Sync for Base {}

/// One task's access to the top blocks' columns.
pub(crate) struct TopColumns<'a> {
    /// Per top block: its values and its width.
    bases: Vec<(Base, usize)>,
    /// Per top block, per storage column: `NONE` when this task owns the column (writes it
    /// directly), `UNREACHED` when it does not reach it, else the offset of its private column
    /// in `private`.
    private_at: Vec<Vec<usize>>,
    /// The private columns, zero until the task subtracts from them.
    private: Vec<f64>,
    /// The top blocks' vectors, borrowed while the accesses live.
    top: PhantomData<&'a mut [Vec<f64>]>,
}

impl<'a> TopColumns<'a> {
    /// Per task: its access to `top` (the top blocks' values, each `widths[b]` rows per storage
    /// column), where `reached[g]` marks the columns task `g` reaches, `storage[b]` names the
    /// column of each storage column of top block `b`, and a column is owned by the first task
    /// reaching it.
    ///
    /// The accesses borrow `top` until [`TopColumns::join`] adds their private columns in.
    pub(crate) fn split(
        top: &'a mut [Vec<f64>],
        widths: &[usize],
        storage: &[&[usize]],
        reached: &[Vec<bool>],
    ) -> Vec<TopColumns<'a>> {
        let columns = reached.first().map_or(0, Vec::len);
        let mut owner = vec![NONE; columns];
        for (g, marks) in reached.iter().enumerate() {
            for (j, _) in marks.iter().enumerate().filter(|(_, &r)| r) {
                if owner[j] == NONE {
                    owner[j] = g;
                }
            }
        }
        let bases: Vec<(Base, usize)> = top
            .iter_mut()
            .zip(widths)
            .zip(storage)
            .map(|((values, &w), cols)| {
                assert_eq!(values.len(), w * cols.len(), "top block of another shape");
                (Base(values.as_mut_ptr()), w)
            })
            .collect();
        reached
            .iter()
            .enumerate()
            .map(|(g, marks)| {
                let mut len = 0;
                let private_at = storage
                    .iter()
                    .zip(widths)
                    .map(|(cols, &w)| {
                        cols.iter()
                            .map(|&j| {
                                if !marks[j] {
                                    UNREACHED
                                } else if owner[j] == g {
                                    NONE
                                } else {
                                    len += w;
                                    len - w
                                }
                            })
                            .collect()
                    })
                    .collect();
                TopColumns {
                    bases: bases.clone(),
                    private_at,
                    private: vec![0.0; len],
                    top: PhantomData,
                }
            })
            .collect()
    }

    /// Storage column `at` of top block `block`, one of the columns this task reaches.
    ///
    /// # Panics
    /// On a column this task does not reach (another task may own it).
    pub(crate) fn column(&mut self, block: usize, at: usize) -> &mut [f64] {
        let (base, w) = self.bases[block];
        match self.private_at[block][at] {
            UNREACHED => panic!("top column {at} of block {block} is not this task's"),
            // SAFETY: this task owns the column (no other access writes or reads it before
            // `join`), and `at` indexes `private_at`, so the column lies within the block's
            // `width × columns` values (asserted in `split`).
            NONE => unsafe { std::slice::from_raw_parts_mut(base.0.add(at * w), w) },
            offset => &mut self.private[offset..offset + w],
        }
    }

    /// Adds every access's private columns into the top blocks, ending the borrow.
    pub(crate) fn join(tasks: Vec<TopColumns<'a>>) {
        for task in tasks {
            for (&(base, w), offsets) in task.bases.iter().zip(&task.private_at) {
                for (at, &offset) in offsets.iter().enumerate() {
                    if offset == NONE || offset == UNREACHED {
                        continue;
                    }
                    // SAFETY: every access has been given back, so nothing else touches the
                    // top blocks; the column lies within the block (as in `column`).
                    let column = unsafe { std::slice::from_raw_parts_mut(base.0.add(at * w), w) };
                    column
                        .iter_mut()
                        .zip(&task.private[offset..offset + w])
                        .for_each(|(t, p)| *t += p);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tasks on one top block of width 2 with three storage columns (columns 4, 0, 2):
    /// column 0 is reached by both (task 0 owns it, task 1 writes privately), column 2 by task 1
    /// only (owned), column 4 by task 0 only; the private part is summed in.
    #[test]
    fn first_task_owns_a_column_and_later_ones_add_privately() {
        let mut top = vec![vec![1.0; 6]];
        let storage: [&[usize]; 1] = [&[4, 0, 2]];
        let mut reached = vec![vec![false; 5]; 2];
        reached[0][0] = true;
        reached[0][4] = true;
        reached[1][0] = true;
        reached[1][2] = true;
        let mut tasks = TopColumns::split(&mut top, &[2], &storage, &reached);
        assert_eq!(tasks[0].private.len(), 0);
        assert_eq!(tasks[1].private.len(), 2);
        tasks[0].column(0, 0).iter_mut().for_each(|v| *v -= 1.0);
        tasks[0].column(0, 1).iter_mut().for_each(|v| *v -= 2.0);
        tasks[1].column(0, 1).iter_mut().for_each(|v| *v -= 4.0);
        tasks[1].column(0, 2).iter_mut().for_each(|v| *v -= 8.0);
        TopColumns::join(tasks);
        assert_eq!(top[0], vec![0.0, 0.0, -5.0, -5.0, -7.0, -7.0]);
    }

    /// A task asking for a column it does not reach (owned by another task) is refused.
    #[test]
    #[should_panic(expected = "not this task's")]
    fn a_column_the_task_does_not_reach_is_refused() {
        let mut top = vec![vec![0.0; 4]];
        let reached = vec![vec![true, false], vec![false, true]];
        let mut tasks = TopColumns::split(&mut top, &[2], &[&[0, 1]], &reached);
        tasks[1].column(0, 0);
    }
}
