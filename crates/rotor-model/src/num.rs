//! Numbers as written: a value in a message as the user would write it back ([`Num`]), and
//! a value rounded to significant digits for a file ([`round_sig`]).

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

/// How [`round_sig`] lands on its digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rounding {
    /// To nearest, as the quotient `round(x·10^k)/10^k` computed in doubles: it may lie an
    /// ulp off the decimal it stands for (the reference files hold such values, so they stay);
    /// ±0 is kept.
    Scaled,
    /// To nearest, as the double nearest the decimal (it prints as written: no
    /// `4.5778000000000001`); `|x| < floor` gives 0, and so does −0 (never −0).
    Decimal {
        /// Magnitudes below it round to 0.
        floor: f64,
    },
    /// Up, for `x ≥ 0` (a stated error never shrinks): the decimal `⌈x·10^k⌉/10^k`, nudged up
    /// by an ulp if its nearest double lies below `x`; ±0 is kept.
    Up,
}

/// `x` rounded to `digits` significant digits as `how` says. A non-finite `x` is returned as
/// it is, and so is one so near the end of the double range that `x·10^k` overflows.
pub fn round_sig(x: f64, digits: u32, how: Rounding) -> f64 {
    if !x.is_finite() {
        return x;
    }
    if let Rounding::Decimal { floor } = how
        && (x.abs() < floor || x == 0.0)
    {
        return 0.0;
    }
    if x == 0.0 {
        return x;
    }
    let e = x.abs().log10().floor() as i32;
    let scale = 10f64.powi(digits as i32 - 1 - e);
    let r = match how {
        Rounding::Up => (x * scale).ceil() / scale,
        Rounding::Scaled | Rounding::Decimal { .. } => (x * scale).round() / scale,
    };
    if !r.is_finite() {
        return x;
    }
    match how {
        Rounding::Scaled => r,
        // Re-parse the decimal, so that the value is the double nearest it.
        Rounding::Decimal { .. } => format!("{:.*e}", digits.saturating_sub(1) as usize, r)
            .parse()
            .unwrap_or(r),
        Rounding::Up if r >= x => r,
        Rounding::Up => r.next_up(),
    }
}

#[cfg(test)]
mod tests {
    use super::{Num, Rounding, round_sig};

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

    #[test]
    fn decimal_rounding_keeps_significant_digits_and_floors_small_values() {
        let r = |v, d, floor| round_sig(v, d, Rounding::Decimal { floor });
        assert_eq!(r(4.577757971, 5, 1e-9), 4.5778);
        assert_eq!(r(-0.000123456789, 3, 1e-9), -0.000123);
        assert_eq!(r(6.3361e-10, 5, 1e-9), 0.0);
        assert_eq!(r(-3e-12, 5, 1e-9), 0.0);
        assert!(r(-3e-12, 5, 1e-9).is_sign_positive());
        assert!(r(-0.0, 5, 0.0).is_sign_positive());
        assert_eq!(r(99999.7, 5, 1e-9), 100000.0);
        assert_eq!(format!("{}", r(0.1 + 0.2, 5, 0.0)), "0.3");
    }

    /// The scaled quotient is kept as computed, ±0 too; rounding up never goes below `x`.
    #[test]
    fn scaled_and_upward_rounding() {
        assert_eq!(round_sig(4.577757971, 5, Rounding::Scaled), 4.5778);
        assert!(round_sig(-0.0, 5, Rounding::Scaled).is_sign_negative());
        assert_eq!(
            round_sig(f64::NAN, 5, Rounding::Scaled).to_bits(),
            f64::NAN.to_bits()
        );
        // 1.234567e-13 to 12 digits: 10^24 is not a double, and the quotient lies an ulp
        // off the decimal, which the decimal rounding corrects.
        let x = 1.234567890123456e-13;
        let (s, d) = (
            round_sig(x, 12, Rounding::Scaled),
            round_sig(x, 12, Rounding::Decimal { floor: 0.0 }),
        );
        assert_eq!(d, 1.23456789012e-13);
        assert!((s - d).abs() <= 2.0 * (d.next_up() - d), "{s:e} {d:e}");
        assert_eq!(round_sig(3.21e-11, 2, Rounding::Up), 3.3e-11);
        assert_eq!(round_sig(3.2e-11, 2, Rounding::Up), 3.2e-11);
        assert!(round_sig(3.2e-11, 2, Rounding::Up) >= 3.2e-11);
        assert_eq!(round_sig(0.0, 2, Rounding::Up), 0.0);
    }
}
