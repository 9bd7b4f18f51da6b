//! Parameter sets: TOML files with every value and its unit, validated into [`Params`].
//!
//! The file format (see `fixtures/params/table1.toml`):
//!
//! ```toml
//! name = "table1"
//! j_u = 0.4765      # kg m^2
//! k_m = 3.9950      # N m / V
//! k_theta = 0.0727  # N m / rad
//! j_l = 0.0326      # kg m^2
//! [upper]           # eq. (4): T_su, ΔT_su, b_u, Δb_u
//! t_s = 0.0
//! dt_s = 0.0
//! b = 2.2247
//! db = 0.0
//! [lower]
//! family = "exponential"   # or "stribeck"
//! t_s = 0.1642
//! t_1 = 0.0603
//! t_2 = -0.2267
//! w_1 = 5.7468
//! w_2 = 0.2941
//! b = 0.0109
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::FieldError;

/// A parameter file could not be read or is not an admissible parameter set.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ParamsError {
    /// The file could not be read.
    #[error("{}: cannot read parameter file: {message}", shown(.path))]
    Io {
        /// The file that was asked for.
        path: PathBuf,
        /// The operating system's reason (not found, permission denied, too large, ...).
        message: String,
    },
    /// The file is not valid TOML, or a key is unknown, missing or of the wrong type.
    #[error("{}: {message}", shown(.path))]
    Parse {
        /// The file, or the origin a table was named by ([`Params::from_table`]).
        path: PathBuf,
        /// The parser's message on one line (see [`one_line`]), naming the key.
        message: String,
    },
    /// A value set by name (not read from a file) is unknown or out of its range.
    #[error(transparent)]
    Value(FieldError),
    /// A value of one disc of a chain is out of its admissible range:
    /// `chain3.toml: disc 3: friction.t_s = -1: static level must be >= 0`.
    #[error("{}: disc {disc}: {error}", shown(.path))]
    Disc {
        /// The file.
        path: PathBuf,
        /// The disc's number, from 1 (the driven disc).
        disc: usize,
        /// The field (`j`, `k`, `c`, `friction.t_s`), its value and why it is refused (boxed:
        /// every error of the crate carries this enum, and this variant would widen it).
        error: Box<FieldError>,
    },
    /// A value is out of its admissible range.
    #[error("{}: {error}", shown(.path))]
    Invalid {
        /// The file the value was read from.
        path: PathBuf,
        /// The field, its value as printed by [`crate::Num`], and why it is refused.
        error: FieldError,
    },
}

/// Friction law of the upper disc, eq. (4) of the source:
/// `T_cu(ω) = T_su + ΔT_su·sgn(ω) + b_u·|ω| + Δb_u·ω`.
///
/// The friction torque is `T_fu = T_cu(ω)·sign(ω) = ΔT_su + Δb_u|ω| + b_u ω + T_su sign(ω)`,
/// so its set at ω = 0 is `ΔT_su + T_su·[−1, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UpperFriction {
    /// T_su [N m]: static level (half-width of the stick interval).
    pub t_s: f64,
    /// ΔT_su [N m]: asymmetry of the static level.
    #[serde(default)]
    pub dt_s: f64,
    /// b_u [N m s/rad]: viscous coefficient.
    pub b: f64,
    /// Δb_u [N m s/rad]: asymmetry of the viscous coefficient.
    #[serde(default)]
    pub db: f64,
}

/// Friction law of the lower disc: one of the two families of docs/model.md.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "family", rename_all = "lowercase")]
pub enum LowerFriction {
    /// `T_cl(ω) = T_sl + T_1(1 − 2/(1+e^{w_1|ω|})) + T_2(1 − 2/(1+e^{w_2|ω|})) + b_l|ω|`
    /// (the family of Table 1; not in the source, which gives only eq. (5): a reconstruction
    /// after Mihajlović's thesis (TU Eindhoven 2005) and Mihajlović et al., J. Dyn. Sys. Meas.
    /// Control 126 (2004) 709–720, see docs/model.md §2.4).
    Exponential {
        /// T_sl [N m]: static level, the law's value at ω = 0 (half-width of the stick
        /// interval).
        t_s: f64,
        /// T_1 [N m]: amplitude of the fast tanh term (Table 1: positive, the level rises).
        t_1: f64,
        /// T_2 [N m]: amplitude of the slow tanh term (Table 1: negative, the falling branch
        /// that drives the limit cycles).
        t_2: f64,
        /// w_1 [s/rad]: rate of the fast term; it saturates over |ω| ≈ 2/w_1.
        w_1: f64,
        /// w_2 [s/rad]: rate of the slow term; it saturates over |ω| ≈ 2/w_2.
        w_2: f64,
        /// b_l [N m s/rad]: viscous coefficient.
        b: f64,
    },
    /// `T_cl(ω) = T_cl + (T_sl − T_cl)·exp(−|ω/ω_sl|^δ_sl) + b_l|ω|` (eq. 5 of the source).
    Stribeck {
        /// T_sl [N m]: static level, the law's value at ω = 0 (half-width of the stick
        /// interval).
        t_s: f64,
        /// T_cl [N m]: Coulomb level, the level the law falls to at large |ω| (before the
        /// viscous term).
        t_c: f64,
        /// ω_sl [rad/s]: Stribeck velocity, the width of the fall from T_sl to T_cl.
        omega_s: f64,
        /// δ_sl [–]: Stribeck exponent, the shape of that fall.
        delta: f64,
        /// b_l [N m s/rad]: viscous coefficient.
        b: f64,
    },
}

impl LowerFriction {
    /// Static level T_sl: half-width of the stick interval.
    pub fn static_level(&self) -> f64 {
        match *self {
            LowerFriction::Exponential { t_s, .. } | LowerFriction::Stribeck { t_s, .. } => t_s,
        }
    }

    /// Viscous coefficient b_l.
    pub fn viscous(&self) -> f64 {
        match *self {
            LowerFriction::Exponential { b, .. } | LowerFriction::Stribeck { b, .. } => b,
        }
    }

    /// Name of the family as written in parameter files.
    pub fn family(&self) -> &'static str {
        match self {
            LowerFriction::Exponential { .. } => "exponential",
            LowerFriction::Stribeck { .. } => "stribeck",
        }
    }
}

/// A validated parameter set of the two-disc rotor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Params {
    /// J_u [kg m²]: inertia of the upper disc.
    pub j_u: f64,
    /// k_m [N m/V]: motor constant.
    pub k_m: f64,
    /// k_θ [N m/rad]: torsional stiffness.
    pub k_theta: f64,
    /// J_l [kg m²]: inertia of the lower disc.
    pub j_l: f64,
    /// Upper-disc friction, eq. (4).
    pub upper: UpperFriction,
    /// Lower-disc friction.
    pub lower: LowerFriction,
}

/// The on-disk form; every field optional in the lower table so that the family decides
/// which keys are required, and every key unknown to all families is rejected by serde.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParams {
    #[serde(default)]
    #[allow(dead_code)]
    name: Option<String>,
    #[serde(default)]
    #[allow(dead_code)]
    description: Option<String>,
    j_u: f64,
    k_m: f64,
    k_theta: f64,
    j_l: f64,
    upper: UpperFriction,
    lower: RawLower,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLower {
    family: String,
    t_s: Option<f64>,
    t_1: Option<f64>,
    t_2: Option<f64>,
    w_1: Option<f64>,
    w_2: Option<f64>,
    t_c: Option<f64>,
    omega_s: Option<f64>,
    delta: Option<f64>,
    b: Option<f64>,
}

impl Params {
    /// The source's Table 1 (exponential family; T_su = ΔT_su = Δb_u = 0).
    pub fn table1() -> Params {
        Params {
            j_u: 0.4765,
            k_m: 3.9950,
            k_theta: 0.0727,
            j_l: 0.0326,
            upper: UpperFriction {
                t_s: 0.0,
                dt_s: 0.0,
                b: 2.2247,
                db: 0.0,
            },
            lower: LowerFriction::Exponential {
                t_s: 0.1642,
                t_1: 0.0603,
                t_2: -0.2267,
                w_1: 5.7468,
                w_2: 0.2941,
                b: 0.0109,
            },
        }
    }

    /// Reads and validates a parameter file.
    pub fn from_file(path: &Path) -> Result<Params, ParamsError> {
        let bytes = read_small(path).map_err(|e| ParamsError::Io {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        let text = text_of(bytes).map_err(|message| ParamsError::Parse {
            path: path.to_owned(),
            message,
        })?;
        Params::from_toml_str(&text, path)
    }

    /// Parses and validates parameter TOML; `path` is only used in messages. A file in chain
    /// form (`[[disc]]` tables, [`crate::chain`]) is read as a chain and taken if it has the
    /// rig's shape; any other chain is refused, saying what makes it one.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Params, ParamsError> {
        if text.trim().is_empty() {
            return Err(ParamsError::Parse {
                path: path.to_owned(),
                message: "the file is empty".into(),
            });
        }
        if crate::ChainParams::is_chain_form(text) {
            return crate::ChainParams::from_toml_str(text, path)?.into_rig(path);
        }
        let raw: RawParams = toml::from_str(text).map_err(|e| ParamsError::Parse {
            path: path.to_owned(),
            message: one_line(&e.to_string()),
        })?;
        Params::from_raw(raw, path)
    }

    /// Validates parameters given as a table of the file's keys (the Python package's dict);
    /// `origin` names them in messages. A table in chain form is taken as
    /// [`Params::from_toml_str`] takes a file in it.
    pub fn from_table(table: toml::Table, origin: &Path) -> Result<Params, ParamsError> {
        use serde::Deserialize;
        if table.contains_key("disc") {
            return crate::ChainParams::from_table(table, origin)?.into_rig(origin);
        }
        let raw =
            RawParams::deserialize(toml::Value::Table(table)).map_err(|e| ParamsError::Parse {
                path: origin.to_owned(),
                message: one_line(&e.to_string()),
            })?;
        Params::from_raw(raw, origin)
    }

    /// The parameters as a table of the file's keys (the inverse of [`Params::from_table`]).
    pub fn to_table(&self) -> toml::Table {
        match toml::Table::try_from(self) {
            Ok(t) => t,
            Err(e) => unreachable!("plain numbers and a family name serialize: {e}"),
        }
    }

    fn from_raw(raw: RawParams, path: &Path) -> Result<Params, ParamsError> {
        let invalid = |error| ParamsError::Invalid {
            path: path.to_owned(),
            error,
        };
        let bad =
            |field: &str, value: f64, reason: &str| invalid(FieldError::num(field, value, reason));
        let lower = match raw.lower.family.as_str() {
            "exponential" => {
                let l = &raw.lower;
                for (name, v) in [("t_c", l.t_c), ("omega_s", l.omega_s), ("delta", l.delta)] {
                    if let Some(v) = v {
                        return Err(bad(
                            &format!("lower.{name}"),
                            v,
                            "not a parameter of the 'exponential' family",
                        ));
                    }
                }
                let need = |name: &str, v: Option<f64>| {
                    v.ok_or_else(|| ParamsError::Parse {
                        path: path.to_owned(),
                        message: format!(
                            "lower.{name}: missing (required by family 'exponential')"
                        ),
                    })
                };
                LowerFriction::Exponential {
                    t_s: need("t_s", l.t_s)?,
                    t_1: need("t_1", l.t_1)?,
                    t_2: need("t_2", l.t_2)?,
                    w_1: need("w_1", l.w_1)?,
                    w_2: need("w_2", l.w_2)?,
                    b: need("b", l.b)?,
                }
            }
            "stribeck" => {
                let l = &raw.lower;
                for (name, v) in [
                    ("t_1", l.t_1),
                    ("t_2", l.t_2),
                    ("w_1", l.w_1),
                    ("w_2", l.w_2),
                ] {
                    if let Some(v) = v {
                        return Err(bad(
                            &format!("lower.{name}"),
                            v,
                            "not a parameter of the 'stribeck' family",
                        ));
                    }
                }
                let need = |name: &str, v: Option<f64>| {
                    v.ok_or_else(|| ParamsError::Parse {
                        path: path.to_owned(),
                        message: format!("lower.{name}: missing (required by family 'stribeck')"),
                    })
                };
                LowerFriction::Stribeck {
                    t_s: need("t_s", l.t_s)?,
                    t_c: need("t_c", l.t_c)?,
                    omega_s: need("omega_s", l.omega_s)?,
                    delta: need("delta", l.delta)?,
                    b: need("b", l.b)?,
                }
            }
            other => {
                return Err(invalid(FieldError::new(
                    "lower.family",
                    format!("{other:?}"),
                    "unknown friction family (expected \"exponential\" or \"stribeck\")",
                )));
            }
        };
        let p = Params {
            j_u: raw.j_u,
            k_m: raw.k_m,
            k_theta: raw.k_theta,
            j_l: raw.j_l,
            upper: raw.upper,
            lower,
        };
        p.validate().map_err(invalid)?;
        Ok(p)
    }

    /// The fields of this parameter set as dotted paths (`k_theta`, `upper.b`, `lower.t_s`,
    /// ...), those of its lower friction family included, in file order.
    pub fn field_names(&self) -> Vec<&'static str> {
        let mut v = vec![
            "j_u",
            "k_m",
            "k_theta",
            "j_l",
            "upper.t_s",
            "upper.dt_s",
            "upper.b",
            "upper.db",
        ];
        match self.lower {
            LowerFriction::Exponential { .. } => v.extend([
                "lower.t_s",
                "lower.t_1",
                "lower.t_2",
                "lower.w_1",
                "lower.w_2",
                "lower.b",
            ]),
            LowerFriction::Stribeck { .. } => v.extend([
                "lower.t_s",
                "lower.t_c",
                "lower.omega_s",
                "lower.delta",
                "lower.b",
            ]),
        }
        v
    }

    /// A mutable reference to the field at a dotted path, if this set has it.
    fn field_mut(&mut self, name: &str) -> Option<&mut f64> {
        Some(match name {
            "j_u" => &mut self.j_u,
            "k_m" => &mut self.k_m,
            "k_theta" => &mut self.k_theta,
            "j_l" => &mut self.j_l,
            "upper.t_s" => &mut self.upper.t_s,
            "upper.dt_s" => &mut self.upper.dt_s,
            "upper.b" => &mut self.upper.b,
            "upper.db" => &mut self.upper.db,
            _ => match (&mut self.lower, name) {
                (LowerFriction::Exponential { t_s, .. }, "lower.t_s")
                | (LowerFriction::Stribeck { t_s, .. }, "lower.t_s") => t_s,
                (LowerFriction::Exponential { b, .. }, "lower.b")
                | (LowerFriction::Stribeck { b, .. }, "lower.b") => b,
                (LowerFriction::Exponential { t_1, .. }, "lower.t_1") => t_1,
                (LowerFriction::Exponential { t_2, .. }, "lower.t_2") => t_2,
                (LowerFriction::Exponential { w_1, .. }, "lower.w_1") => w_1,
                (LowerFriction::Exponential { w_2, .. }, "lower.w_2") => w_2,
                (LowerFriction::Stribeck { t_c, .. }, "lower.t_c") => t_c,
                (LowerFriction::Stribeck { omega_s, .. }, "lower.omega_s") => omega_s,
                (LowerFriction::Stribeck { delta, .. }, "lower.delta") => delta,
                _ => return None,
            },
        })
    }

    /// The value of the field at a dotted path; the error lists the valid names.
    pub fn get(&self, name: &str) -> Result<f64, ParamsError> {
        let mut copy = *self;
        copy.field_mut(name)
            .map(|v| *v)
            .ok_or_else(|| self.unknown(name))
    }

    /// A copy with the field at a dotted path set to `value`, validated; the error names the
    /// field and the value (or lists the valid names).
    pub fn with(&self, name: &str, value: f64) -> Result<Params, ParamsError> {
        let mut copy = *self;
        *copy.field_mut(name).ok_or_else(|| self.unknown(name))? = value;
        copy.validate().map_err(|e| {
            // A value set by name has always been written as Rust writes an f64 (`0.00001`,
            // not `1e-5` as a file's value is): kept so, so that no message changes.
            let value = copy
                .get(&e.field)
                .map_or(e.value.clone(), |v| v.to_string());
            ParamsError::Value(FieldError { value, ..e })
        })?;
        Ok(copy)
    }

    fn unknown(&self, name: &str) -> ParamsError {
        ParamsError::Value(FieldError::new(
            "param",
            format!("{name:?}"),
            format!(
                "not a parameter of this {} set (valid: {})",
                self.lower.family(),
                self.field_names().join(", ")
            ),
        ))
    }

    /// Checks that every value is finite and in its admissible range; the error names the
    /// first violation (its field as a dotted path, `lower.t_s`).
    pub fn validate(&self) -> Result<(), FieldError> {
        let mut fields: Vec<(String, f64)> = [
            ("j_u", self.j_u),
            ("k_m", self.k_m),
            ("k_theta", self.k_theta),
            ("j_l", self.j_l),
        ]
        .map(|(f, v)| (f.to_owned(), v))
        .into();
        fields.extend(upper_fields(&self.upper, "upper."));
        fields.extend(lower_fields(&self.lower, "lower."));
        check_finite(&fields)?;
        for (f, v) in [
            ("j_u", self.j_u),
            ("j_l", self.j_l),
            ("k_theta", self.k_theta),
        ] {
            if v <= 0.0 {
                return Err(FieldError::num(f, v, "must be positive"));
            }
        }
        if self.k_m == 0.0 {
            return Err(FieldError::num("k_m", self.k_m, "must be non-zero"));
        }
        check_upper(&self.upper, "upper.")?;
        check_lower(&self.lower, "lower.", "lower")
    }
}

/// The first of `fields` that is not a finite number, as an error.
pub(crate) fn check_finite(fields: &[(String, f64)]) -> Result<(), FieldError> {
    match fields.iter().find(|(_, v)| !v.is_finite()) {
        Some((f, v)) => Err(FieldError::num(f.as_str(), *v, "must be a finite number")),
        None => Ok(()),
    }
}

/// The upper law's fields, named `{prefix}t_s`, ..., in file order.
pub(crate) fn upper_fields(u: &UpperFriction, prefix: &str) -> Vec<(String, f64)> {
    [("t_s", u.t_s), ("dt_s", u.dt_s), ("b", u.b), ("db", u.db)]
        .map(|(f, v)| (format!("{prefix}{f}"), v))
        .into()
}

/// A lower law's fields, named `{prefix}t_s`, ..., in file order.
pub(crate) fn lower_fields(l: &LowerFriction, prefix: &str) -> Vec<(String, f64)> {
    let named: Vec<(&str, f64)> = match *l {
        LowerFriction::Exponential {
            t_s,
            t_1,
            t_2,
            w_1,
            w_2,
            b,
        } => vec![
            ("t_s", t_s),
            ("t_1", t_1),
            ("t_2", t_2),
            ("w_1", w_1),
            ("w_2", w_2),
            ("b", b),
        ],
        LowerFriction::Stribeck {
            t_s,
            t_c,
            omega_s,
            delta,
            b,
        } => vec![
            ("t_s", t_s),
            ("t_c", t_c),
            ("omega_s", omega_s),
            ("delta", delta),
            ("b", b),
        ],
    };
    named
        .into_iter()
        .map(|(f, v)| (format!("{prefix}{f}"), v))
        .collect()
}

/// The upper law's ranges (eq. (4): levels and slopes >= 0 on both sides); fields named
/// `{prefix}t_s`, ...
pub(crate) fn check_upper(u: &UpperFriction, prefix: &str) -> Result<(), FieldError> {
    let err = |f: &str, v: f64, r: &str| Err(FieldError::num(format!("{prefix}{f}"), v, r));
    if u.t_s < 0.0 {
        return err("t_s", u.t_s, "static level must be >= 0");
    }
    if u.dt_s.abs() > u.t_s {
        return err(
            "dt_s",
            u.dt_s,
            "|dt_s| must not exceed t_s (T_cu(0+) and T_cu(0-) must be >= 0)",
        );
    }
    if u.b < 0.0 {
        return err("b", u.b, "viscous coefficient must be >= 0");
    }
    if u.db.abs() > u.b {
        return err(
            "db",
            u.db,
            "|db| must not exceed b (both viscous slopes must be >= 0)",
        );
    }
    Ok(())
}

/// A lower law's ranges; fields named `{prefix}t_s`, ...; `law` names the law in a message
/// (`"lower"`: "makes the lower friction law negative").
pub(crate) fn check_lower(l: &LowerFriction, prefix: &str, law: &str) -> Result<(), FieldError> {
    let err = |f: &str, v: f64, r: &str| Err(FieldError::num(format!("{prefix}{f}"), v, r));
    match *l {
        LowerFriction::Exponential {
            t_s,
            t_1,
            t_2,
            w_1,
            w_2,
            b,
        } => {
            if t_s < 0.0 {
                return err("t_s", t_s, "static level must be >= 0");
            }
            if w_1 <= 0.0 {
                return err("w_1", w_1, "must be positive");
            }
            if w_2 <= 0.0 {
                return err("w_2", w_2, "must be positive");
            }
            if b < 0.0 {
                return err("b", b, "viscous coefficient must be >= 0");
            }
            // t_1 and t_2 may be negative (Table 1's t_2 is), but not so negative that
            // the friction drives the disc: T_cl(ω) >= 0 for every slip velocity.
            let (w, tc) = exponential_law_minimum(t_s, t_1, t_2, w_1, w_2, b);
            if tc < 0.0 {
                let (f, v) = if t_1 * (0.5 * w_1 * w).tanh() <= t_2 * (0.5 * w_2 * w).tanh() {
                    ("t_1", t_1)
                } else {
                    ("t_2", t_2)
                };
                return err(
                    f,
                    v,
                    &format!(
                        "makes the {law} friction law negative, T_cl = {tc:.3e} N m at \
                         |ω| = {w:.3e} rad/s (friction must oppose the motion)"
                    ),
                );
            }
        }
        LowerFriction::Stribeck {
            t_s,
            t_c,
            omega_s,
            delta,
            b,
        } => {
            if t_s < 0.0 {
                return err("t_s", t_s, "static level must be >= 0");
            }
            if t_c < 0.0 {
                return err("t_c", t_c, "Coulomb level must be >= 0");
            }
            if omega_s <= 0.0 {
                return err("omega_s", omega_s, "Stribeck velocity must be positive");
            }
            if delta <= 0.0 {
                return err("delta", delta, "Stribeck exponent must be positive");
            }
            if b < 0.0 {
                return err("b", b, "viscous coefficient must be >= 0");
            }
        }
    }
    Ok(())
}

/// The smallest value of the exponential law for slip, `min_{ω>0} T_cl(ω)` with
/// `T_cl(ω) = t_s + t_1 tanh(w_1 ω/2) + t_2 tanh(w_2 ω/2) + b ω` (the reconstructed
/// exponential law of docs/model.md §2.4 with `1 − 2/(1+e^x) = tanh(x/2)`), and where it is
/// taken: `(ω, T_cl)`.
///
/// Past `ω_max = 40/min(w_1, w_2)` both tanh terms are within e^{−40} of their limits, so the
/// law is `t_s + t_1 + t_2 + b ω` there, non-decreasing: the minimum lies in `(0, ω_max]`. It
/// is bracketed on a log grid (64 points per decade from 1e-9 ω_max: the terms vary on the
/// scales 1/w_i, far wider than a grid cell) and refined by golden-section search.
fn exponential_law_minimum(t_s: f64, t_1: f64, t_2: f64, w_1: f64, w_2: f64, b: f64) -> (f64, f64) {
    let law = |w: f64| t_s + t_1 * (0.5 * w_1 * w).tanh() + t_2 * (0.5 * w_2 * w).tanh() + b * w;
    let w_max = 40.0 / w_1.min(w_2);
    let n = 9 * 64;
    let grid = |k: usize| w_max * 10f64.powf(-9.0 * (n - k) as f64 / n as f64);
    // The law on the grid, each point once; the first of equal minima.
    let values: Vec<f64> = (0..=n).map(|k| law(grid(k))).collect();
    let k = (0..=n)
        .min_by(|&i, &j| values[i].total_cmp(&values[j]))
        .unwrap_or(n);
    let (mut a, mut c) = (grid(k.saturating_sub(1)), grid((k + 1).min(n)));
    if k == 0 {
        a = 0.0;
    }
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..100 {
        let (x1, x2) = (c - g * (c - a), a + g * (c - a));
        if law(x1) <= law(x2) {
            c = x2;
        } else {
            a = x1;
        }
    }
    let w = 0.5 * (a + c);
    (w, law(w))
}

/// A path as it appears in a one-line message: control characters (a newline is legal in a
/// Unix file name) escaped.
pub fn shown(path: &Path) -> String {
    escape_controls(&path.to_string_lossy())
}

fn escape_controls(s: &str) -> String {
    s.chars()
        .flat_map(|c| {
            if c.is_control() {
                c.escape_default().collect::<Vec<_>>()
            } else {
                vec![c]
            }
        })
        .collect()
}

/// The largest parameter or scenario file that is read: such a file is under 4 kB, and the
/// cap keeps a wrong path (a binary file, `/dev/zero`) from being read into memory whole.
pub const MAX_FILE: u64 = 1 << 20;

/// The bytes of the file at `path`, refused once it runs past [`MAX_FILE`] bytes.
pub(crate) fn read_small(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(MAX_FILE + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_FILE {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("larger than {MAX_FILE} bytes: not a TOML file of this kind"),
        ));
    }
    Ok(bytes)
}

/// The bytes of a file as text, or why it is not a text file: not UTF-8, or it holds a NUL
/// byte (a binary file that happens to be valid UTF-8). Names the byte offset.
pub(crate) fn text_of(bytes: Vec<u8>) -> Result<String, String> {
    let text = String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let byte = e.as_bytes()[at];
        format!("not a UTF-8 text file (byte 0x{byte:02x} at offset {at})")
    })?;
    if let Some(at) = text.find('\0') {
        return Err(format!(
            "not a text file (NUL byte at offset {at}: a binary file?)"
        ));
    }
    Ok(text)
}

/// Drops a TOML comment from a source line (a `#` outside a string), and trims it.
fn strip_comment(src: &str) -> &str {
    let mut quote: Option<char> = None;
    let mut escaped = false;
    for (i, c) in src.char_indices() {
        match quote {
            Some(q) => {
                if escaped {
                    escaped = false;
                } else if c == '\\' && q == '"' {
                    escaped = true;
                } else if c == q {
                    quote = None;
                }
            }
            None if c == '"' || c == '\'' => quote = Some(c),
            None if c == '#' => return src[..i].trim(),
            None => {}
        }
    }
    src.trim()
}

/// Collapses a multi-line parser message into one line. toml prints a source excerpt
/// (`6 | j_u = "heavy"` and a caret line); the excerpt's source line is kept, since it shows
/// the offending key and value.
pub fn one_line(s: &str) -> String {
    let mut head: Vec<&str> = Vec::new();
    let mut at: Option<&str> = None;
    for line in s.lines() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        if let Some((num, src)) = t.split_once('|') {
            let num = num.trim();
            if !num.is_empty() && num.chars().all(|c| c.is_ascii_digit()) {
                at = Some(src.trim());
            }
            // Caret and gutter lines carry nothing more.
            continue;
        }
        head.push(t);
    }
    let mut out = head.join(": ");
    // The excerpt without its comment; a line that is only a comment (toml points at line 1
    // for a key missing from the top level) tells nothing.
    if let Some(src) = at.map(strip_comment).filter(|s| !s.is_empty()) {
        out.push_str(&format!(" (in `{src}`)"));
    }
    // Control characters (a stray carriage return, bytes of a binary file) would break the
    // one-line message or the terminal: escape them.
    escape_controls(&out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLE1: &str = include_str!("../../../fixtures/params/table1.toml");
    const STRIBECK: &str = include_str!("../../../fixtures/params/stribeck.toml");

    #[test]
    fn fixture_table1_matches_builtin() {
        let p = Params::from_toml_str(TABLE1, Path::new("table1.toml")).unwrap();
        assert_eq!(p, Params::table1());
    }

    #[test]
    fn fixture_stribeck_parses() {
        let p = Params::from_toml_str(STRIBECK, Path::new("stribeck.toml")).unwrap();
        assert_eq!(p.lower.family(), "stribeck");
        assert!(p.upper.t_s > 0.0);
    }

    fn err_of(text: &str) -> String {
        Params::from_toml_str(text, Path::new("p.toml"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn unknown_key_is_named() {
        let t = TABLE1.replace("j_u =", "j_uu =");
        let e = err_of(&t);
        assert!(e.contains("j_uu"), "{e}");
        assert!(e.starts_with("p.toml"), "{e}");
        assert!(!e.contains('\n'), "one line: {e}");
    }

    #[test]
    fn negative_inertia_is_named_with_value() {
        let t = TABLE1.replace("j_l = 0.0326", "j_l = -0.5");
        let e = err_of(&t);
        assert!(e.contains("j_l = -0.5"), "{e}");
    }

    #[test]
    fn non_finite_is_rejected() {
        let t = TABLE1.replace("k_theta = 0.0727", "k_theta = nan");
        assert!(err_of(&t).contains("k_theta = NaN"));
        let t = TABLE1.replace("k_theta = 0.0727", "k_theta = inf");
        assert!(err_of(&t).contains("k_theta = inf"));
    }

    /// Table 1's t_2 is negative and allowed (the law's minimum is 0.124 N m, at 7.9 rad/s);
    /// doubled, it makes the law negative past ~1.6 rad/s and is refused, naming t_2.
    #[test]
    fn a_negative_level_that_makes_friction_drive_the_disc_is_refused() {
        let t = TABLE1.replace("t_2 = -0.2267", "t_2 = -0.4534");
        let e = err_of(&t);
        assert!(
            e.contains("lower.t_2 = -0.4534") && e.contains("negative"),
            "{e}"
        );
        // With b = 0 the law tends to t_s + t_1 + t_2 = -0.0022 N m: negative far out.
        let t = TABLE1.replace("b = 0.0109", "b = 0.0");
        let e = err_of(&t);
        assert!(e.contains("lower.t_2 = -0.2267"), "{e}");
    }

    /// The minimum search against brute force: the law on a uniform grid of 2e6 points over
    /// [0, 2 ω_max]. The grid misses the true minimum by at most ½ max|T''| (Δ/2)², with
    /// `|d²/dω² tanh(wω/2)| ≤ w²/2 · 2/(3√3)`; the search must lie below the grid's minimum
    /// (it finds the true one) by no more than that bound, plus rounding (1e-14 N m).
    #[test]
    fn exponential_law_minimum_matches_brute_force() {
        for (t_s, t_1, t_2, w_1, w_2, b) in [
            (0.1642, 0.0603, -0.2267, 5.7468, 0.2941, 0.0109),
            (0.1313, 0.0897, -0.9, 5.9271, 0.2077, 0.0194),
            (0.05, -0.04, 0.1, 30.0, 0.5, 0.0),
            (0.2, 0.1, 0.05, 1.0, 2.0, 0.01),
        ] {
            let law =
                |w: f64| t_s + t_1 * (0.5 * w_1 * w).tanh() + t_2 * (0.5 * w_2 * w).tanh() + b * w;
            let w_max = 40.0 / f64::min(w_1, w_2);
            let n = 2_000_000;
            let dw = 2.0 * w_max / n as f64;
            let brute = (0..=n)
                .map(|k| law(dw * k as f64))
                .fold(f64::INFINITY, f64::min);
            let curv = 1.0 / (3.0 * 3f64.sqrt()) * (t_1.abs() * w_1 * w_1 + t_2.abs() * w_2 * w_2);
            let bound = 0.5 * curv * (0.5 * dw).powi(2);
            let (w, tc) = exponential_law_minimum(t_s, t_1, t_2, w_1, w_2, b);
            assert_eq!(tc, law(w));
            assert!(
                tc <= brute + 1e-14 && brute - tc <= bound + 1e-14,
                "{tc} at {w} vs grid {brute} (bound {bound:e})"
            );
        }
    }

    #[test]
    fn unknown_family_is_named() {
        let t = TABLE1.replace("\"exponential\"", "\"dahl\"");
        let e = err_of(&t);
        assert!(e.contains("lower.family") && e.contains("dahl"), "{e}");
    }

    #[test]
    fn wrong_family_key_is_named() {
        let t = STRIBECK.replace("delta =", "w_1 = 1.0\ndelta =");
        let e = err_of(&t);
        assert!(e.contains("lower.w_1"), "{e}");
    }

    #[test]
    fn missing_key_is_named() {
        let t = TABLE1.replace("w_2 = 0.2941", "");
        let e = err_of(&t);
        assert!(e.contains("w_2"), "{e}");
        let t = TABLE1.replace("k_m = 3.9950", "");
        let e = err_of(&t);
        assert!(e.contains("k_m"), "{e}");
    }

    #[test]
    fn stribeck_exponent_must_be_positive() {
        let t = STRIBECK.replace("delta = 2.0575", "delta = 0.0");
        let e = err_of(&t);
        assert!(e.contains("lower.delta = 0"), "{e}");
    }

    #[test]
    fn wrong_type_and_empty_file() {
        let t = TABLE1.replace("j_u = 0.4765", "j_u = \"heavy\"");
        let e = err_of(&t);
        assert!(e.contains("j_u"), "{e}");
        assert!(err_of("  \n").contains("empty"));
    }

    #[test]
    fn fields_are_read_and_set_by_dotted_path() {
        let p = Params::table1();
        assert_eq!(p.get("k_theta").unwrap(), 0.0727);
        assert_eq!(p.get("lower.w_1").unwrap(), 5.7468);
        let q = p.with("lower.t_s", 0.2).unwrap();
        assert_eq!(q.get("lower.t_s").unwrap(), 0.2);
        assert_eq!(p.field_names().len(), 14);
        for name in p.field_names() {
            assert_eq!(p.with(name, p.get(name).unwrap()).unwrap(), p, "{name}");
        }
        let e = p.get("lower.omega_s").unwrap_err().to_string();
        assert!(
            e.contains("\"lower.omega_s\"") && e.contains("k_theta, j_l"),
            "{e}"
        );
        let e = p.with("k_theta", -0.1).unwrap_err().to_string();
        assert_eq!(e, "k_theta = -0.1: must be positive");
    }

    /// A parameter set given as a table (the Python package's dict) reads back as itself,
    /// and a bad table is refused naming the origin and the field, as a file is.
    #[test]
    fn tables_round_trip_and_name_bad_fields() {
        for text in [TABLE1, STRIBECK] {
            let p = Params::from_toml_str(text, Path::new("f.toml")).unwrap();
            let back = Params::from_table(p.to_table(), Path::new("params")).unwrap();
            assert_eq!(back, p);
        }
        let mut t = Params::table1().to_table();
        t.insert("k_theta".into(), toml::Value::Float(-1.0));
        let e = Params::from_table(t, Path::new("params")).unwrap_err();
        assert_eq!(e.to_string(), "params: k_theta = -1: must be positive");
        let mut t = Params::table1().to_table();
        t.insert("k_thta".into(), toml::Value::Float(1.0));
        let e = Params::from_table(t, Path::new("params")).unwrap_err();
        assert!(
            e.to_string().starts_with("params: unknown field `k_thta`"),
            "{e}"
        );
    }
}
