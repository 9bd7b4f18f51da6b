//! A bad input, worded once for every front end: [`FieldError`].

use thiserror::Error;

use crate::Num;

/// An input out of its admissible range: the field as the library names it (`t_end`,
/// `lower.t_s`, `compare.dt`), its value as the user would write it back (`0.001`, `1e300`,
/// `"rk4"`), and why.
///
/// It displays as `field = value: reason`, the form of a file's key and of a Python keyword;
/// a front end that takes flags spells the field as its flag ([`FieldError::as_flag`]). Each
/// crate's error enum holds it where a value is out of range, with what it adds (the file, a
/// prefix).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{field} = {value}: {reason}")]
pub struct FieldError {
    /// The field as the library names it (`t_end`, `lower.t_s`, `x0[omega_l]`).
    pub field: String,
    /// Its value as the user would write it back (`0.001`, `"rk4"`).
    pub value: String,
    /// Why it is refused (the admissible range, or the valid names).
    pub reason: String,
}

impl FieldError {
    /// The field, its value as written back, and why.
    pub fn new(
        field: impl Into<String>,
        value: impl Into<String>,
        reason: impl Into<String>,
    ) -> FieldError {
        FieldError {
            field: field.into(),
            value: value.into(),
            reason: reason.into(),
        }
    }

    /// A number, written back as [`Num`] writes it (`0.001`, `1e300`, `NaN`).
    pub fn num(field: impl Into<String>, value: f64, reason: impl Into<String>) -> FieldError {
        FieldError::new(field, Num(value).to_string(), reason)
    }

    /// The field as a command-line flag: `--` and the name with `-` for `_` (`t_end` is
    /// `--t-end`); a field `a/b` (two inputs refused together) is `--a/--b`.
    pub fn flag(&self) -> String {
        self.field
            .split('/')
            .map(|f| format!("--{}", f.replace('_', "-")))
            .collect::<Vec<_>>()
            .join("/")
    }

    /// The message as the command line spells it: `--t-end 0: must be positive and finite`.
    pub fn as_flag(&self) -> String {
        format!("{} {}: {}", self.flag(), self.value, self.reason)
    }
}

#[cfg(test)]
mod tests {
    use super::FieldError;

    #[test]
    fn named_as_a_key_or_as_a_flag() {
        let e = FieldError::num("t_end", 0.0, "must be positive and finite");
        assert_eq!(e.to_string(), "t_end = 0: must be positive and finite");
        assert_eq!(e.as_flag(), "--t-end 0: must be positive and finite");
        let e = FieldError::num("tol", 1e-300, "must lie in (0, 1)");
        assert_eq!(e.to_string(), "tol = 1e-300: must lie in (0, 1)");
        let e = FieldError::new("u/param", "\"3 x 4 points\"", "too many");
        assert_eq!(e.as_flag(), "--u/--param \"3 x 4 points\": too many");
    }
}
