//! Post-processing: recorded time histories, spectra, the sweep table, figures, and the
//! all-or-nothing output folders they are written to.

pub mod filter;
pub mod history;
pub mod output;
pub mod plot;
pub mod spectrum;
pub mod sweep;

/// A number for people: three significant digits, no trailing zeros (0.01, 0.2, 0.0123,
/// 12.3, 1500; below 10⁻⁴ in scientific notation, 3.21e-11).
pub fn format_number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if x.abs() < 1e-4 {
        // "3.21e-11", not "0.0000000000321".
        return trim_mantissa(&format!("{x:.2e}"));
    }
    let digits = (2 - x.abs().log10().floor() as i64).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A number in Rust's scientific notation without the trailing zeros of its mantissa:
/// "5.00e-10" → "5e-10", "1.50e-6" → "1.5e-6".
pub fn trim_mantissa(text: &str) -> String {
    match text.split_once('e') {
        Some((mantissa, exponent)) if mantissa.contains('.') => format!(
            "{}e{exponent}",
            mantissa.trim_end_matches('0').trim_end_matches('.')
        ),
        _ => text.to_string(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn numbers_for_people() {
        use super::format_number as f;
        assert_eq!(f(0.01), "0.01");
        assert_eq!(f(0.2), "0.2");
        assert_eq!(f(0.0123456), "0.0123");
        assert_eq!(f(12.345), "12.3");
        assert_eq!(f(1500.0), "1500");
        assert_eq!(f(-0.05), "-0.05");
        assert_eq!(f(0.0), "0");
        assert_eq!(f(0.0005), "0.0005");
        assert_eq!(f(3.21e-11), "3.21e-11");
        assert_eq!(f(-5e-10), "-5e-10");
    }
}
