//! Numbers in messages: a value as the user would write it back.

use std::fmt;

/// Displays an `f64` in plain decimal where that is short (`0.0727`, `1000`), in scientific
/// notation where plain decimal would spell out hundreds of digits or leading zeros
/// (`1e308`, `2.5e-12`). Both forms parse back to the same value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Num;

    #[test]
    fn short_forms_that_parse_back() {
        for (v, s) in [
            (0.0727, "0.0727"),
            (1000.0, "1000"),
            (-0.5, "-0.5"),
            (0.0, "0"),
            (1e308, "1e308"),
            (-1e308, "-1e308"),
            (2.5e-12, "2.5e-12"),
            (5e-324, "5e-324"),
            (f64::INFINITY, "inf"),
            (f64::NAN, "NaN"),
        ] {
            let shown = Num(v).to_string();
            assert_eq!(shown, s);
            let back: f64 = shown.parse().unwrap();
            assert!(back == v || v.is_nan() && back.is_nan(), "{v}");
        }
    }
}
