//! Real numbers in the at most 20 characters an Abaqus or CalculiX data field holds (both read
//! a field of 20; CalculiX cuts a longer one, dropping the exponent of
//! `-1.2345678901234567e-5`).

/// The widest data field of an input file.
pub const MAX_FIELD: usize = 20;

/// `x` in at most [`MAX_FIELD`] characters: its shortest round-trip digits written plain, with
/// an exponent, or as an integer mantissa with an exponent (`-123456789012345e-29`, which
/// both read), whichever is shortest — exact whenever that fits: every number of up to 15
/// significant digits with an exponent of up to two digits, 16 when positive, 17 from 0.01 to
/// 1; otherwise rounded to the most significant digits that fit (at least 15 with such an
/// exponent, 14 with three: a relative change below 5·10⁻¹⁴). The exporter keeps the exact
/// coordinates of the nodes it had to round in a comment that fibercell reads back.
pub fn inp_number(x: f64) -> String {
    let plain = format!("{x:?}");
    let best = shortest([plain, compact(&format!("{x:e}"))]);
    if best.len() <= MAX_FIELD {
        return best;
    }
    (0..17)
        .rev()
        .map(|digits| compact(&format!("{x:.digits$e}")))
        // Rounding up may leave the finite range (f64::MAX to 15 digits): take fewer then.
        .find(|s| s.len() <= MAX_FIELD && s.parse::<f64>().is_ok_and(f64::is_finite))
        .unwrap_or(best)
}

/// The shorter of `d.ddde-N` and the same digits as an integer mantissa, `dddde-M`.
fn compact(scientific: &str) -> String {
    let Some((mantissa, exponent)) = scientific.split_once('e') else {
        return scientific.to_string();
    };
    let (Some((whole, fraction)), Ok(e)) = (mantissa.split_once('.'), exponent.parse::<i32>())
    else {
        return scientific.to_string();
    };
    let integer = format!("{whole}{fraction}e{}", e - fraction.len() as i32);
    shortest([scientific.to_string(), integer])
}

/// The shortest of `candidates` (the first of equal lengths).
fn shortest<const N: usize>(candidates: [String; N]) -> String {
    candidates
        .into_iter()
        .reduce(|a, b| if b.len() < a.len() { b } else { a })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every written number fits, reads back exactly when its shortest form fits (17 digits
    /// from 0.01 to 1, 15 digits with a sign and a two-digit exponent as an integer mantissa,
    /// ±1.5e-300, 1e300), and otherwise within 5e-14 (17 digits below 0.01 or negative, a
    /// three-digit exponent).
    #[test]
    fn numbers_fit_the_field_and_round_trip_where_they_can() {
        let exact = [
            0.0,
            -0.0,
            0.012074569909945442,
            0.0009224032982700329,
            1e-5,
            2.1e11,
            -1.5e-300,
            1e300,
            0.3,
            -3.0,
            -1.23456789012345e-15,
            1.234567890123456e-15,
        ];
        for x in exact {
            let s = inp_number(x);
            assert!(s.len() <= MAX_FIELD, "{s}");
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
        for x in [
            0.0012074569909945442,
            -0.00012074569909945442,
            -1.2345678901234567e-15,
            -1.2345678901234567e-150,
            f64::MIN,
            -f64::MIN_POSITIVE,
        ] {
            let s = inp_number(x);
            assert!(s.len() <= MAX_FIELD, "{s}");
            let back: f64 = s.parse().unwrap();
            assert!((back - x).abs() <= 5e-14 * x.abs(), "{s} for {x:e}");
            assert_ne!(format!("{x:e}").len(), s.len(), "{s} was rounded");
        }
    }
}
