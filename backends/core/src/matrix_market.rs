//! Reading Matrix Market files: sparse `coordinate` matrices (`real` or `integer`; `general`,
//! `symmetric` or `skew-symmetric`) into a [`CscMatrix`] with both triangles stored, and dense
//! `array` columns (right-hand sides) into vectors. Errors name the line and what is wrong.

use crate::{CscMatrix, SolverError};

/// The header of a Matrix Market file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layout {
    Coordinate,
    Array,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Symmetry {
    General,
    Symmetric,
    SkewSymmetric,
}

fn bad(line: usize, what: impl std::fmt::Display) -> SolverError {
    SolverError::InvalidMatrix(format!("Matrix Market line {line}: {what}"))
}

/// A file's layout and symmetry, and its data lines (comments skipped) with their 1-based
/// line numbers.
struct Parsed<'a> {
    layout: Layout,
    symmetry: Symmetry,
    data: Vec<(usize, &'a str)>,
}

/// The header's layout and symmetry, and the data lines after it.
fn parse_header(text: &str) -> Result<Parsed<'_>, SolverError> {
    let mut lines = text.lines().enumerate().map(|(k, l)| (k + 1, l));
    let (_, header) = lines.next().ok_or_else(|| bad(1, "empty file"))?;
    let words: Vec<String> = header.split_whitespace().map(str::to_lowercase).collect();
    if words.len() != 5 || words[0] != "%%matrixmarket" || words[1] != "matrix" {
        return Err(bad(
            1,
            "expected \"%%MatrixMarket matrix <layout> <field> <symmetry>\"",
        ));
    }
    let layout = match words[2].as_str() {
        "coordinate" => Layout::Coordinate,
        "array" => Layout::Array,
        other => return Err(bad(1, format!("unknown layout \"{other}\""))),
    };
    match words[3].as_str() {
        "real" | "integer" | "double" => {}
        other => {
            return Err(bad(
                1,
                format!("field \"{other}\" is not supported (real or integer)"),
            ))
        }
    }
    let symmetry = match words[4].as_str() {
        "general" => Symmetry::General,
        "symmetric" => Symmetry::Symmetric,
        "skew-symmetric" => Symmetry::SkewSymmetric,
        other => return Err(bad(1, format!("symmetry \"{other}\" is not supported"))),
    };
    let data = lines
        .filter(|(_, l)| !l.trim_start().starts_with('%') && !l.trim().is_empty())
        .collect();
    Ok(Parsed {
        layout,
        symmetry,
        data,
    })
}

fn number<T: std::str::FromStr>(
    line: usize,
    word: Option<&str>,
    what: &str,
) -> Result<T, SolverError> {
    let word = word.ok_or_else(|| bad(line, format!("missing {what}")))?;
    word.parse().map_err(|_| {
        bad(
            line,
            format!("{what} \"{word}\" is not a number of the right kind"),
        )
    })
}

/// The size line after the header: its line number and its `N` counts, named by `what`.
fn size_line<'a, const N: usize>(
    data: &mut impl Iterator<Item = (usize, &'a str)>,
    what: [&str; N],
) -> Result<(usize, [usize; N]), SolverError> {
    let (line, size) = data.next().ok_or_else(|| bad(2, "missing the size line"))?;
    let mut words = size.split_whitespace();
    let mut counts = [0usize; N];
    for (c, w) in counts.iter_mut().zip(what) {
        *c = number(line, words.next(), w)?;
    }
    Ok((line, counts))
}

fn finite(line: usize, v: f64) -> Result<f64, SolverError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(bad(line, format!("value {v} is not finite")))
    }
}

/// A sparse matrix from the text of a `coordinate` Matrix Market file. A `symmetric` or
/// `skew-symmetric` file stores one triangle; the result stores both (what the symmetric
/// backends need). Duplicate entries are summed, as the format allows.
///
/// ```
/// let text = "%%MatrixMarket matrix coordinate real symmetric\n\
///             3 3 4\n1 1 4.0\n2 1 -1.0\n2 2 4.0\n3 3 2.5\n";
/// let a = fibercell_solver::read_matrix_market(text)?;
/// assert_eq!((a.as_ref().ncols(), a.as_ref().nnz()), (3, 5)); // both triangles
/// # Ok::<(), fibercell_solver::SolverError>(())
/// ```
pub fn read_matrix_market(text: &str) -> Result<CscMatrix, SolverError> {
    let Parsed {
        layout,
        symmetry,
        data,
    } = parse_header(text)?;
    if layout != Layout::Coordinate {
        return Err(bad(1, "a sparse matrix needs the coordinate layout"));
    }
    let mut data = data.into_iter();
    let (line, [nrows, ncols, nnz]) =
        size_line(&mut data, ["row count", "column count", "entry count"])?;
    if symmetry != Symmetry::General && nrows != ncols {
        return Err(bad(line, "a symmetric matrix must be square"));
    }
    // Refuse absurd sizes before allocating: every entry needs a line.
    if nnz > text.len() {
        return Err(bad(line, format!("{nnz} entries cannot fit in the file")));
    }
    let last = text.lines().count();
    let mut triplets = Vec::with_capacity(2 * nnz);
    for _ in 0..nnz {
        let (line, entry) = data
            .next()
            .ok_or_else(|| bad(last, format!("the file ends before its {nnz} entries")))?;
        let mut words = entry.split_whitespace();
        let i: usize = number(line, words.next(), "row index")?;
        let j: usize = number(line, words.next(), "column index")?;
        let v = finite(line, number(line, words.next(), "value")?)?;
        if i == 0 || j == 0 || i > nrows || j > ncols {
            return Err(bad(
                line,
                format!("entry ({i}, {j}) outside the {nrows} × {ncols} matrix (1-based)"),
            ));
        }
        let (i, j) = (i - 1, j - 1);
        if symmetry != Symmetry::General && i < j {
            return Err(bad(line, "a symmetric file stores the lower triangle only"));
        }
        triplets.push((i, j, v));
        if i != j {
            match symmetry {
                Symmetry::General => {}
                Symmetry::Symmetric => triplets.push((j, i, v)),
                Symmetry::SkewSymmetric => triplets.push((j, i, -v)),
            }
        } else if symmetry == Symmetry::SkewSymmetric {
            return Err(bad(line, "a skew-symmetric matrix has no diagonal"));
        }
    }
    if let Some((line, _)) = data.next() {
        return Err(bad(
            line,
            format!("more than the {nnz} entries the size line gives"),
        ));
    }
    CscMatrix::from_triplets(nrows, ncols, &triplets)
}

/// The columns of a dense `array` Matrix Market file (column after column, as the format
/// stores them), e.g. right-hand sides: (rows, columns, values).
pub fn read_matrix_market_dense(text: &str) -> Result<(usize, usize, Vec<f64>), SolverError> {
    let Parsed {
        layout,
        symmetry,
        data,
    } = parse_header(text)?;
    if layout != Layout::Array || symmetry != Symmetry::General {
        return Err(bad(1, "a dense block needs \"array real general\""));
    }
    let mut data = data.into_iter();
    let (line, [nrows, ncols]) = size_line(&mut data, ["row count", "column count"])?;
    let count = nrows
        .checked_mul(ncols)
        .filter(|&c| c <= text.len())
        .ok_or_else(|| {
            bad(
                line,
                format!("{nrows} × {ncols} values cannot fit in the file"),
            )
        })?;
    let mut values = Vec::with_capacity(count);
    for (line, entry) in data {
        for word in entry.split_whitespace() {
            values.push(finite(line, number(line, Some(word), "value")?)?);
        }
    }
    if values.len() != count {
        return Err(bad(
            text.lines().count(),
            format!("{} values for a {nrows} × {ncols} array", values.len()),
        ));
    }
    Ok((nrows, ncols, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symmetric_files_expand_to_both_triangles() {
        let text = "%%MatrixMarket matrix coordinate real symmetric\n% a comment\n3 3 4\n1 1 4\n2 1 -1\n2 2 4\n3 3 2.5\n";
        let a = read_matrix_market(text).unwrap();
        let want = CscMatrix::from_triplets(
            3,
            3,
            &[
                (0, 0, 4.0),
                (1, 0, -1.0),
                (0, 1, -1.0),
                (1, 1, 4.0),
                (2, 2, 2.5),
            ],
        )
        .unwrap();
        assert_eq!(a, want);
        assert!(a.as_ref().structural_asymmetry().is_none());
    }

    #[test]
    fn general_and_skew_files() {
        let g = read_matrix_market(
            "%%MatrixMarket matrix coordinate integer general\n2 3 2\n1 3 7\n2 1 -2\n",
        )
        .unwrap();
        assert_eq!(
            (g.as_ref().nrows(), g.as_ref().ncols(), g.as_ref().nnz()),
            (2, 3, 2)
        );
        let s = read_matrix_market(
            "%%MatrixMarket matrix coordinate real skew-symmetric\n2 2 1\n2 1 3\n",
        )
        .unwrap();
        assert_eq!(s.as_ref().col(0), (&[1usize][..], &[3.0][..]));
        assert_eq!(s.as_ref().col(1), (&[0usize][..], &[-3.0][..]));
    }

    #[test]
    fn errors_name_the_line() {
        for (text, needle) in [
            (
                "%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1\n",
                "complex",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 1\n",
                "line 3",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1\n",
                "ends before",
            ),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 2 1\n",
                "lower triangle",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 nan\n",
                "not finite",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 99999999\n1 1 1\n",
                "cannot fit",
            ),
            (
                "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n2 2 1\n",
                "more than",
            ),
            ("hello\n", "expected"),
        ] {
            let e = read_matrix_market(text).unwrap_err().to_string();
            assert!(e.contains(needle), "{needle}: {e}");
        }
    }

    #[test]
    fn dense_columns() {
        let (n, k, v) = read_matrix_market_dense(
            "%%MatrixMarket matrix array real general\n3 2\n1\n2\n3\n4\n5\n6\n",
        )
        .unwrap();
        assert_eq!((n, k, v), (3, 2, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
        assert!(
            read_matrix_market_dense("%%MatrixMarket matrix array real general\n3 1\n1\n2\n")
                .is_err()
        );
    }
}
