//! The median of repeated timings, as `solve-matrix`, the bench and the examples report them.

/// The median of `times`: the upper of the two middle values of an even count, 0 when there
/// are none.
pub fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times.get(times.len() / 2).copied().unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn the_middle_value_the_upper_of_two_and_zero_for_none() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 3.0);
        assert_eq!(median(vec![0.5]), 0.5);
        assert_eq!(median(Vec::new()), 0.0);
    }
}
