//! What the two-parameter analysis computes ([`PlaneOptions`]), the options checked before
//! any work ([`validate`]), and the parameter set at a value of the parameter.

use crate::bifurcation::{BifError, DiagramOptions};
use rotor_model::{FieldError, Params};

/// What [`crate::plane::plane`] computes.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneOptions {
    /// The parameter: a field of the parameter file as a dotted path.
    pub param: String,
    /// The parameter's range: `[p_min, p_max]`.
    pub p_min: f64,
    /// See `p_min`.
    pub p_max: f64,
    /// The input's range \[V\]: `[u_min, u_max]` (that of the one-parameter diagram).
    pub u_min: f64,
    /// See `u_min`.
    pub u_max: f64,
    /// Integration tolerance of the flows.
    pub tol: f64,
    /// Most points per curve direction.
    pub max_points: usize,
    /// Cells per axis of the coarse grid whose simulations name the regions.
    pub region_cells: usize,
    /// Where the curves are started (the one-parameter diagram is computed there); default
    /// the file's value if it lies in the range, else the middle of the range.
    pub p_start: Option<f64>,
}

impl PlaneOptions {
    /// Defaults for a parameter over `[p_min, p_max]` and u over `[0, 7]`.
    pub fn new(param: &str, p_min: f64, p_max: f64) -> PlaneOptions {
        PlaneOptions {
            param: param.to_owned(),
            p_min,
            p_max,
            u_min: 0.0,
            u_max: 7.0,
            tol: 1e-10,
            max_points: 60,
            region_cells: 8,
            p_start: None,
        }
    }
}

/// The parameter set with `name` = `p` (validated).
pub(crate) fn params_at(base: &Params, name: &str, p: f64) -> Result<Params, BifError> {
    base.with(name, p)
        .map_err(|e| BifError::Degenerate(format!("parameter {name} = {p}: {e}")))
}

/// Checks the options and that every parameter value of the range is admissible (both ends
/// and 64 values between).
pub fn validate(base: &Params, opts: &PlaneOptions) -> Result<(), BifError> {
    let bad = |field: &str, value: f64, reason: &str| {
        Err(BifError::InvalidOption(FieldError::num(
            field, value, reason,
        )))
    };
    base.get(&opts.param)
        .map_err(|e| BifError::Degenerate(e.to_string()))?;
    // Each check names the option that is wrong.
    if !opts.p_min.is_finite() {
        return bad("p_min", opts.p_min, "must be finite");
    }
    if !opts.p_max.is_finite() {
        return bad("p_max", opts.p_max, "must be finite");
    }
    if opts.p_max <= opts.p_min {
        return bad("p_max", opts.p_max, "must be greater than p_min");
    }
    // The u window and the flows' tolerance are the one-parameter diagram's.
    DiagramOptions {
        u_min: opts.u_min,
        u_max: opts.u_max,
        tol: opts.tol,
        ..DiagramOptions::default()
    }
    .validate()?;
    if opts.max_points < 2 {
        return bad("max_points", opts.max_points as f64, "must be at least 2");
    }
    if let Some(p) = opts.p_start
        && !(opts.p_min..=opts.p_max).contains(&p)
    {
        return bad("p_start", p, "must lie in [p_min, p_max]");
    }
    for k in 0..=64 {
        let p = opts.p_min + (opts.p_max - opts.p_min) * k as f64 / 64.0;
        base.with(&opts.param, p).map_err(|e| {
            BifError::Degenerate(format!(
                "--param {} over [{}, {}]: {e}",
                opts.param,
                rotor_model::Num(opts.p_min),
                rotor_model::Num(opts.p_max)
            ))
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each bad option is refused with its own name, whatever else is wrong or right.
    #[test]
    fn options_are_validated_with_the_field_named() {
        let base = Params::table1();
        let ok = PlaneOptions::new("k_theta", 0.05, 0.1);
        assert!(validate(&base, &ok).is_ok());
        type Spoil = fn(&mut PlaneOptions);
        let cases: [(Spoil, &str); 12] = [
            (|o| o.p_min = f64::NAN, "p_min"),
            (|o| o.p_max = f64::INFINITY, "p_max"),
            (|o| o.p_max = o.p_min, "p_max"),
            (|o| o.u_min = -5.0, "u_min"),
            (|o| o.u_min = f64::NAN, "u_min"),
            (|o| o.u_max = 1e300, "u_max"),
            (|o| o.u_max = 0.0, "u_max"),
            (|o| o.tol = 0.0, "tol"),
            (|o| o.max_points = 1, "max_points"),
            (|o| o.p_start = Some(1.0), "p_start"),
            (|o| o.p_start = Some(f64::NAN), "p_start"),
            (|o| o.p_min = -1.0, "k_theta"),
        ];
        for (spoil, field) in cases {
            let mut o = ok.clone();
            spoil(&mut o);
            let e = validate(&base, &o).unwrap_err();
            if let BifError::InvalidOption(f) = &e {
                assert_eq!(f.field, field);
            }
            assert!(e.to_string().contains(field), "{field}: {e}");
        }
        // Numbers are written as one would type them back, not in 300 digits.
        let mut o = ok.clone();
        o.u_max = 1e300;
        let e = validate(&base, &o).unwrap_err().to_string();
        assert_eq!(
            e,
            "invalid option u_max = 1e300: must be <= 1000 V: the Hopf search samples omega up \
             to 1e4 rad/s"
        );
        o = PlaneOptions::new("k_theta", -1e-300, 0.1);
        let e = validate(&base, &o).unwrap_err().to_string();
        assert!(
            e.starts_with("--param k_theta over [-1e-300, 0.1]: "),
            "{e}"
        );
    }
}
