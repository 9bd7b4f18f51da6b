//! Chains of N discs: the rig's model with the number of discs, the state's size and each
//! disc's friction law as data.
//!
//! Discs `1..N` (disc 1 driven by the motor, disc N at the bottom), disc i and i + 1 joined by
//! a spring `k_i` and an optional viscous coupling `c_i`, each disc with its own friction law.
//! The state is `x = [α_1 … α_{N−1}, ω_1 … ω_N]` with `α_i = θ_i − θ_{i+1}`:
//!
//! ```text
//! α̇_i    = ω_i − ω_{i+1}
//! J_i ω̇_i = [i = 1] k_m u + k_{i−1} α_{i−1} + c_{i−1}(ω_{i−1} − ω_i)
//!                         − k_i α_i − c_i(ω_i − ω_{i+1}) − T_fi(ω_i)
//! ```
//!
//! (terms whose spring index lies outside `1..N−1` are absent). The inertia is diagonal and
//! the couplings act through the state only, so a disc's applied torque — everything but its
//! own friction — does not depend on any acceleration: each disc sticks while its applied
//! torque lies in its own stick interval, whichever other discs are stuck (docs/model.md,
//! "Chains of N discs").
//!
//! The rig is the chain of two with `c = 0`: [`ChainParams::from_params`] and
//! [`ChainParams::to_params`] convert, and [`ChainModel`]'s field equals [`crate::Model`]'s bit
//! for bit there (a test). Indices in code are 0-based (disc `i` is the file's disc `i + 1`);
//! messages number discs from 1, as the file does.

use std::path::Path;

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::params::{
    ParamsError, check_finite, check_lower, check_upper, lower_fields, one_line, upper_fields,
};
use crate::{Disc, DiscMode, FieldError, Friction, LowerFriction, Mode, Params, UpperFriction};

/// The friction law of one disc of a chain, by family as the file names it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DiscLaw {
    /// `viscous` {b}: `T_f = b ω`, no stick interval.
    Viscous {
        /// b [N m s/rad]: viscous coefficient.
        b: f64,
    },
    /// `upper` {t_s, dt_s, b, db}: the rig's upper-disc law, eq. (4).
    Upper(UpperFriction),
    /// `exponential` or `stribeck`: the rig's lower-disc laws.
    Lower(LowerFriction),
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// A law as the file writes it: `family`, then its fields.
impl Serialize for DiscLaw {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let fields = self.fields();
        let mut m = s.serialize_map(Some(fields.len() + 1))?;
        m.serialize_entry("family", self.family())?;
        for (key, value) in &fields {
            m.serialize_entry(key.trim_start_matches("friction."), value)?;
        }
        m.end()
    }
}

impl DiscLaw {
    /// The family's name as written in a parameter file.
    pub fn family(&self) -> &'static str {
        match self {
            DiscLaw::Viscous { .. } => "viscous",
            DiscLaw::Upper(_) => "upper",
            DiscLaw::Lower(l) => l.family(),
        }
    }

    /// The law as the solvers evaluate it. A viscous law is eq. (4) with its levels and
    /// asymmetries 0.
    pub fn friction(&self) -> Friction {
        match *self {
            DiscLaw::Viscous { b } => Friction::upper(UpperFriction {
                t_s: 0.0,
                dt_s: 0.0,
                b,
                db: 0.0,
            }),
            DiscLaw::Upper(u) => Friction::upper(u),
            DiscLaw::Lower(l) => Friction::lower(l),
        }
    }

    /// The law's fields as `friction.<key>`, in file order.
    fn fields(&self) -> Vec<(String, f64)> {
        match self {
            DiscLaw::Viscous { b } => vec![("friction.b".to_owned(), *b)],
            DiscLaw::Upper(u) => upper_fields(u, "friction."),
            DiscLaw::Lower(l) => lower_fields(l, "friction."),
        }
    }

    /// The law's ranges, with the same rules as the rig's laws.
    fn check(&self) -> Result<(), FieldError> {
        match self {
            DiscLaw::Viscous { b } if *b < 0.0 => Err(FieldError::num(
                "friction.b",
                *b,
                "viscous coefficient must be >= 0",
            )),
            DiscLaw::Viscous { .. } => Ok(()),
            DiscLaw::Upper(u) => check_upper(u, "friction."),
            DiscLaw::Lower(l) => check_lower(l, "friction.", "disc's"),
        }
    }
}

/// One disc of a chain: its inertia, its coupling to the disc above and its friction law.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChainDisc {
    /// J [kg m²]: inertia.
    pub j: f64,
    /// k [N m/rad]: stiffness of the spring to the disc above (0 for disc 1, which has none;
    /// not written then, as a file must not give it).
    #[serde(skip_serializing_if = "is_zero")]
    pub k: f64,
    /// c [N m s/rad]: viscous coupling to the disc above (0 for disc 1; not written when 0,
    /// the file's default).
    #[serde(skip_serializing_if = "is_zero")]
    pub c: f64,
    /// The disc's friction law.
    #[serde(rename = "friction")]
    pub law: DiscLaw,
}

/// A validated chain of N ≥ 2 discs. It serializes in the file's chain form (`k_m`, then a
/// `disc` list of `j`, `k`, `c` and `friction` with its `family`), which a job file carries.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChainParams {
    /// k_m [N m/V]: motor constant (the motor drives disc 1).
    pub k_m: f64,
    /// The discs, top (driven) first.
    #[serde(rename = "disc")]
    pub discs: Vec<ChainDisc>,
}

/// Where in a chain a value is refused: the chain as a whole, or one disc (numbered from 1).
#[derive(Debug, Clone, PartialEq)]
pub enum ChainFieldError {
    /// `k_m` or the number of discs.
    Chain(FieldError),
    /// A disc's field.
    Disc(usize, FieldError),
}

impl std::fmt::Display for ChainFieldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ChainFieldError::Chain(e) => e.fmt(f),
            ChainFieldError::Disc(d, e) => write!(f, "disc {d}: {e}"),
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawChain {
    #[serde(default)]
    #[allow(dead_code)]
    name: Option<String>,
    #[serde(default)]
    #[allow(dead_code)]
    description: Option<String>,
    k_m: f64,
    disc: Vec<RawDisc>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDisc {
    j: f64,
    k: Option<f64>,
    c: Option<f64>,
    friction: RawLaw,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLaw {
    family: String,
    t_s: Option<f64>,
    dt_s: Option<f64>,
    b: Option<f64>,
    db: Option<f64>,
    t_1: Option<f64>,
    t_2: Option<f64>,
    w_1: Option<f64>,
    w_2: Option<f64>,
    t_c: Option<f64>,
    omega_s: Option<f64>,
    delta: Option<f64>,
}

/// The families and their keys: required, then optional (default 0).
const FAMILIES: [(&str, &[&str], &[&str]); 4] = [
    ("viscous", &["b"], &[]),
    ("upper", &["t_s", "b"], &["dt_s", "db"]),
    (
        "exponential",
        &["t_s", "t_1", "t_2", "w_1", "w_2", "b"],
        &[],
    ),
    ("stribeck", &["t_s", "t_c", "omega_s", "delta", "b"], &[]),
];

impl RawLaw {
    fn get(&self, key: &str) -> Option<f64> {
        match key {
            "t_s" => self.t_s,
            "dt_s" => self.dt_s,
            "b" => self.b,
            "db" => self.db,
            "t_1" => self.t_1,
            "t_2" => self.t_2,
            "w_1" => self.w_1,
            "w_2" => self.w_2,
            "t_c" => self.t_c,
            "omega_s" => self.omega_s,
            "delta" => self.delta,
            _ => None,
        }
    }

    const KEYS: [&'static str; 11] = [
        "t_s", "dt_s", "b", "db", "t_1", "t_2", "w_1", "w_2", "t_c", "omega_s", "delta",
    ];

    /// The law of its family; the error is a disc's field, or a parse message.
    fn law(&self) -> Result<DiscLaw, Result<FieldError, String>> {
        let Some(&(family, required, optional)) =
            FAMILIES.iter().find(|(f, _, _)| *f == self.family)
        else {
            return Err(Ok(FieldError::new(
                "friction.family",
                format!("{:?}", self.family),
                "unknown friction family (expected \"viscous\", \"upper\", \"exponential\" or \
                 \"stribeck\")",
            )));
        };
        for key in RawLaw::KEYS {
            if let Some(v) = self.get(key)
                && !required.contains(&key)
                && !optional.contains(&key)
            {
                return Err(Ok(FieldError::num(
                    format!("friction.{key}"),
                    v,
                    format!("not a parameter of the '{family}' family"),
                )));
            }
        }
        let need = |key: &str| {
            self.get(key).ok_or_else(|| {
                Err(format!(
                    "friction.{key}: missing (required by family '{family}')"
                ))
            })
        };
        let opt = |key: &str| self.get(key).unwrap_or(0.0);
        Ok(match family {
            "viscous" => DiscLaw::Viscous { b: need("b")? },
            "upper" => DiscLaw::Upper(UpperFriction {
                t_s: need("t_s")?,
                dt_s: opt("dt_s"),
                b: need("b")?,
                db: opt("db"),
            }),
            "exponential" => DiscLaw::Lower(LowerFriction::Exponential {
                t_s: need("t_s")?,
                t_1: need("t_1")?,
                t_2: need("t_2")?,
                w_1: need("w_1")?,
                w_2: need("w_2")?,
                b: need("b")?,
            }),
            _ => DiscLaw::Lower(LowerFriction::Stribeck {
                t_s: need("t_s")?,
                t_c: need("t_c")?,
                omega_s: need("omega_s")?,
                delta: need("delta")?,
                b: need("b")?,
            }),
        })
    }
}

impl ChainParams {
    /// The rig as a chain of two: disc 1 the upper disc (J_u, eq. (4)), disc 2 the lower disc
    /// (J_l, its law) on the spring k_θ, no viscous coupling.
    pub fn from_params(p: &Params) -> ChainParams {
        ChainParams {
            k_m: p.k_m,
            discs: vec![
                ChainDisc {
                    j: p.j_u,
                    k: 0.0,
                    c: 0.0,
                    law: DiscLaw::Upper(p.upper),
                },
                ChainDisc {
                    j: p.j_l,
                    k: p.k_theta,
                    c: 0.0,
                    law: DiscLaw::Lower(p.lower),
                },
            ],
        }
    }

    /// The rig's parameter set, if this chain is one: two discs, no viscous coupling, an
    /// upper-disc (or viscous) law on disc 1 and a lower-disc law on disc 2.
    pub fn to_params(&self) -> Option<Params> {
        let [top, bottom] = self.discs.as_slice() else {
            return None;
        };
        let upper = match top.law {
            DiscLaw::Upper(u) => u,
            DiscLaw::Viscous { b } => UpperFriction {
                t_s: 0.0,
                dt_s: 0.0,
                b,
                db: 0.0,
            },
            DiscLaw::Lower(_) => return None,
        };
        let DiscLaw::Lower(lower) = bottom.law else {
            return None;
        };
        (bottom.c == 0.0).then_some(Params {
            j_u: top.j,
            k_m: self.k_m,
            k_theta: bottom.k,
            j_l: bottom.j,
            upper,
            lower,
        })
    }

    /// Why this chain is not the rig's shape, if it is not: its number of discs, a viscous
    /// coupling, or a law the rig's disc does not take.
    pub fn not_rig_shaped(&self) -> Option<String> {
        if self.discs.len() != 2 {
            return Some(format!("{} discs", self.discs.len()));
        }
        let [top, bottom] = [self.discs[0], self.discs[1]];
        if bottom.c != 0.0 {
            return Some(format!(
                "a viscous coupling c = {} on disc 2",
                crate::Num(bottom.c)
            ));
        }
        if let DiscLaw::Lower(_) = top.law {
            return Some(format!("disc 1 with the '{}' family", top.law.family()));
        }
        if !matches!(bottom.law, DiscLaw::Lower(_)) {
            return Some(format!("disc 2 with the '{}' family", bottom.law.family()));
        }
        None
    }

    /// The rig's parameter set of a chain in its shape ([`ChainParams::to_params`]), or an
    /// error naming the file and what makes it another chain.
    pub fn into_rig(self, path: &Path) -> Result<Params, ParamsError> {
        match (self.to_params(), self.not_rig_shaped()) {
            (Some(p), _) => Ok(p),
            (None, why) => Err(ParamsError::Parse {
                path: path.to_owned(),
                message: format!(
                    "a chain with {}: this reads the two-disc rig's shape only (2 discs, no \
                     viscous coupling, disc 1 'upper' or 'viscous', disc 2 'exponential' or \
                     'stribeck'); `rotor simulate` and `rotor steady` take any chain",
                    why.unwrap_or_default()
                ),
            }),
        }
    }

    /// Reads a parameter file in either form: chain form (`[[disc]]` tables) or the rig's
    /// two-disc form, which means the same chain of two ([`ChainParams::from_params`]).
    pub fn from_file(path: &Path) -> Result<ChainParams, ParamsError> {
        let bytes = crate::params::read_small(path).map_err(|e| ParamsError::Io {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        let text = crate::params::text_of(bytes).map_err(|message| ParamsError::Parse {
            path: path.to_owned(),
            message,
        })?;
        ChainParams::from_toml_str(&text, path)
    }

    /// Whether a parameter file's text is in chain form (it has a top-level `disc` key).
    pub fn is_chain_form(text: &str) -> bool {
        text.parse::<toml::Table>()
            .is_ok_and(|t| t.contains_key("disc"))
    }

    /// Parses and validates a parameter file's text in either form; `path` names it in
    /// messages.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<ChainParams, ParamsError> {
        if !ChainParams::is_chain_form(text) {
            return Ok(ChainParams::from_params(&Params::from_toml_str(
                text, path,
            )?));
        }
        let raw: RawChain = toml::from_str(text).map_err(|e| ParamsError::Parse {
            path: path.to_owned(),
            message: one_line(&e.to_string()),
        })?;
        ChainParams::from_raw(raw, path)
    }

    /// Validates a chain given as a table of the file's keys (the Python package's dict);
    /// `origin` names it in messages.
    pub fn from_table(table: toml::Table, origin: &Path) -> Result<ChainParams, ParamsError> {
        if !table.contains_key("disc") {
            return Ok(ChainParams::from_params(&Params::from_table(
                table, origin,
            )?));
        }
        let raw =
            RawChain::deserialize(toml::Value::Table(table)).map_err(|e| ParamsError::Parse {
                path: origin.to_owned(),
                message: one_line(&e.to_string()),
            })?;
        ChainParams::from_raw(raw, origin)
    }

    fn from_raw(raw: RawChain, path: &Path) -> Result<ChainParams, ParamsError> {
        let parse = |message: String| ParamsError::Parse {
            path: path.to_owned(),
            message,
        };
        let mut discs = Vec::with_capacity(raw.disc.len());
        for (i, d) in raw.disc.iter().enumerate() {
            let number = i + 1;
            let on_disc = |error| ParamsError::Disc {
                path: path.to_owned(),
                disc: number,
                error: Box::new(error),
            };
            let law = d.friction.law().map_err(|e| match e {
                Ok(error) => on_disc(error),
                Err(message) => parse(format!("disc {number}: {message}")),
            })?;
            let (k, c) = if i == 0 {
                for (key, v) in [("k", d.k), ("c", d.c)] {
                    if let Some(v) = v {
                        return Err(on_disc(FieldError::num(
                            key,
                            v,
                            "disc 1 has no disc above it (the motor drives it)",
                        )));
                    }
                }
                (0.0, 0.0)
            } else {
                let k = d.k.ok_or_else(|| {
                    parse(format!(
                        "disc {number}: k: missing (the spring to the disc above)"
                    ))
                })?;
                (k, d.c.unwrap_or(0.0))
            };
            discs.push(ChainDisc { j: d.j, k, c, law });
        }
        let chain = ChainParams {
            k_m: raw.k_m,
            discs,
        };
        chain.validate().map_err(|e| match e {
            ChainFieldError::Chain(error) => ParamsError::Invalid {
                path: path.to_owned(),
                error,
            },
            ChainFieldError::Disc(disc, error) => ParamsError::Disc {
                path: path.to_owned(),
                disc,
                error: Box::new(error),
            },
        })?;
        Ok(chain)
    }

    /// Checks that every value is finite and in its range: at least two discs, `k_m ≠ 0`,
    /// each disc's `j > 0`, `k > 0` and `c ≥ 0` below disc 1, and its law by the rig's rules.
    /// The error names the first violation and its disc.
    pub fn validate(&self) -> Result<(), ChainFieldError> {
        if self.discs.len() < 2 {
            return Err(ChainFieldError::Chain(FieldError::new(
                "disc",
                format!("{} disc(s)", self.discs.len()),
                "a chain needs at least 2 discs",
            )));
        }
        if self.discs.len() > Mode::MAX_DISCS {
            return Err(ChainFieldError::Chain(FieldError::new(
                "disc",
                format!("{} discs", self.discs.len()),
                format!("a chain holds at most {} discs", Mode::MAX_DISCS),
            )));
        }
        if !self.k_m.is_finite() {
            return Err(ChainFieldError::Chain(FieldError::num(
                "k_m",
                self.k_m,
                "must be a finite number",
            )));
        }
        if self.k_m == 0.0 {
            return Err(ChainFieldError::Chain(FieldError::num(
                "k_m",
                self.k_m,
                "must be non-zero",
            )));
        }
        for (i, d) in self.discs.iter().enumerate() {
            let on = |e| ChainFieldError::Disc(i + 1, e);
            let mut fields = vec![("j".to_owned(), d.j)];
            if i > 0 {
                fields.extend([("k".to_owned(), d.k), ("c".to_owned(), d.c)]);
            }
            fields.extend(d.law.fields());
            check_finite(&fields).map_err(on)?;
            if d.j <= 0.0 {
                return Err(on(FieldError::num("j", d.j, "must be positive")));
            }
            if i > 0 && d.k <= 0.0 {
                return Err(on(FieldError::num("k", d.k, "must be positive")));
            }
            if i > 0 && d.c < 0.0 {
                return Err(on(FieldError::num(
                    "c",
                    d.c,
                    "viscous coupling must be >= 0",
                )));
            }
            d.law.check().map_err(on)?;
        }
        Ok(())
    }

    /// Number of discs N.
    pub fn len(&self) -> usize {
        self.discs.len()
    }

    /// Whether the chain has no discs (never, once validated).
    pub fn is_empty(&self) -> bool {
        self.discs.is_empty()
    }

    /// The chain of N discs the scaling benchmark uses: the rig's top disc followed by N − 1
    /// copies of its lower disc, each on the rig's spring.
    pub fn rig_copies(p: &Params, n: usize) -> ChainParams {
        let rig = ChainParams::from_params(p);
        let mut discs = vec![rig.discs[0]];
        discs.extend(std::iter::repeat_n(rig.discs[1], n.saturating_sub(1)));
        ChainParams {
            k_m: rig.k_m,
            discs,
        }
    }
}

/// `alpha_1 … alpha_{n−1}, omega_1 … omega_n`: the state's components of a chain of `n`.
pub fn chain_state_names(n: usize) -> Vec<String> {
    let alphas = (1..n).map(|i| format!("alpha_{i}"));
    alphas
        .chain((1..=n).map(|i| format!("omega_{i}")))
        .collect()
}

/// The vector field of a chain: [`ChainParams`] with each disc's law built, on states of size
/// `2N − 1` held in slices.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainModel {
    k_m: f64,
    j: Vec<f64>,
    /// `k[i]`, `c[i]`: the spring and coupling between disc i and i + 1 (0-based).
    k: Vec<f64>,
    c: Vec<f64>,
    friction: Vec<Friction>,
}

impl ChainModel {
    /// The model of a validated chain.
    pub fn new(p: &ChainParams) -> ChainModel {
        ChainModel {
            k_m: p.k_m,
            j: p.discs.iter().map(|d| d.j).collect(),
            k: p.discs[1..].iter().map(|d| d.k).collect(),
            c: p.discs[1..].iter().map(|d| d.c).collect(),
            friction: p.discs.iter().map(|d| d.law.friction()).collect(),
        }
    }

    /// Number of discs N.
    #[inline]
    pub fn discs(&self) -> usize {
        self.j.len()
    }

    /// Size of the state, `2N − 1`.
    #[inline]
    pub fn dim(&self) -> usize {
        2 * self.j.len() - 1
    }

    /// The names of the state's components, `alpha_1 … alpha_{N−1}, omega_1 … omega_N`: the
    /// header of a chain's trace.
    pub fn state_names(&self) -> Vec<String> {
        chain_state_names(self.j.len())
    }

    /// Index of disc `i`'s velocity ω_i in the state (0-based disc).
    #[inline]
    pub fn omega(&self, i: usize) -> usize {
        self.j.len() - 1 + i
    }

    /// Friction law of disc `i`.
    #[inline]
    pub fn friction(&self, i: usize) -> &Friction {
        &self.friction[i]
    }

    /// Inertia of disc `i`.
    #[inline]
    pub fn inertia(&self, i: usize) -> f64 {
        self.j[i]
    }

    /// Motor constant `k_m` (the motor drives disc 0).
    #[inline]
    pub fn k_m(&self) -> f64 {
        self.k_m
    }

    /// Stiffness `k_i` of the spring between disc `i` and `i + 1`.
    #[inline]
    pub fn spring(&self, i: usize) -> f64 {
        self.k[i]
    }

    /// Viscous coupling `c_i` between disc `i` and `i + 1` (0 where there is none).
    #[inline]
    pub fn coupling(&self, i: usize) -> f64 {
        self.c[i]
    }

    /// Torque on disc `i` from everything but its own friction, with the discs' velocities
    /// read by `w`:
    /// `[i = 1] k_m u + k_{i−1} α_{i−1} + c_{i−1}(ω_{i−1} − ω_i) − k_i α_i − c_i(ω_i − ω_{i+1})`.
    #[inline]
    fn torque_with(&self, i: usize, x: &[f64], u: f64, w: impl Fn(usize) -> f64) -> f64 {
        let n = self.j.len();
        // Written in the rig's order (k_m u − k α above, k α below) so that the chain of two
        // evaluates the rig's field bit for bit.
        let mut t = if i == 0 {
            self.k_m * u
        } else {
            let mut from_above = self.k[i - 1] * x[i - 1];
            if self.c[i - 1] != 0.0 {
                from_above += self.c[i - 1] * (w(i - 1) - w(i));
            }
            from_above
        };
        if i + 1 < n {
            t -= self.k[i] * x[i];
            if self.c[i] != 0.0 {
                t -= self.c[i] * (w(i) - w(i + 1));
            }
        }
        t
    }

    /// Torque on disc `i` from everything but its own friction (the velocities as stored in
    /// `x`; a solver stores a stuck disc's as 0).
    #[inline]
    pub fn applied_torque(&self, i: usize, x: &[f64], u: f64) -> f64 {
        self.torque_with(i, x, u, |d| x[self.omega(d)])
    }

    /// Whether disc `i`'s applied torque lies inside its stick interval (so stick persists).
    #[inline]
    pub fn can_stick(&self, i: usize, x: &[f64], u: f64) -> bool {
        let (lo, hi) = self.friction[i].static_interval();
        let t = self.applied_torque(i, x, u);
        lo <= t && t <= hi
    }

    /// The slip direction stuck disc `i` leaves toward, if its applied torque is outside its
    /// stick interval: `SlipPos` above it, `SlipNeg` below it, `None` inside.
    #[inline]
    pub fn stick_exit(&self, i: usize, x: &[f64], u: f64) -> Option<DiscMode> {
        let (lo, hi) = self.friction[i].static_interval();
        let t = self.applied_torque(i, x, u);
        if t > hi {
            Some(DiscMode::SlipPos)
        } else if t < lo {
            Some(DiscMode::SlipNeg)
        } else {
            None
        }
    }

    /// The smooth vector field of a mode, `ẋ = f_mode(x, u)`, written into `out` (length
    /// `2N − 1`). A stuck disc's velocity is taken as exactly 0 (whatever `x` holds) and its
    /// acceleration is 0.
    #[inline]
    pub fn rhs_into(&self, x: &[f64], u: f64, mode: Mode, out: &mut [f64]) {
        let n = self.j.len();
        if n == 2 && self.c[0] == 0.0 {
            return self.rig_rhs_into(x, u, mode, out);
        }
        let (x, out) = (&x[..2 * n - 1], &mut out[..2 * n - 1]);
        let w = |i: usize| {
            if mode.is_stuck(Disc::at(i)) {
                0.0
            } else {
                x[n - 1 + i]
            }
        };
        for (i, a) in out[..n - 1].iter_mut().enumerate() {
            *a = w(i) - w(i + 1);
        }
        for i in 0..n {
            out[n - 1 + i] = match mode.of(Disc::at(i)).branch() {
                None => 0.0,
                Some(s) => {
                    (self.torque_with(i, x, u, w) - self.friction[i].torque(x[n - 1 + i], s))
                        / self.j[i]
                }
            };
        }
    }

    /// [`ChainModel::rhs_into`] on a chain of two discs without a viscous coupling (the rig):
    /// the same operations unrolled, `[ω_1 − ω_2, (k_m u − k α − T_f,1)/J_1, (k α − T_f,2)/J_2]`
    /// with a stuck disc's velocity and acceleration 0. The general loop costs twice the
    /// instructions of this on the rig's hot path.
    #[inline(always)]
    fn rig_rhs_into(&self, x: &[f64], u: f64, mode: Mode, out: &mut [f64]) {
        // One length check per list instead of one per element.
        let (&[alpha, wu, wl], [d_alpha, d_wu, d_wl], [f_u, f_l], &[j_u, j_l], &[k]) = (
            &x[..3],
            &mut out[..3],
            &self.friction[..],
            &self.j[..],
            &self.k[..],
        ) else {
            unreachable!("the caller checked a chain of two");
        };
        let (top, bottom) = (Disc::UPPER, Disc::LOWER);
        let w0 = if mode.is_stuck(top) { 0.0 } else { wu };
        let w1 = if mode.is_stuck(bottom) { 0.0 } else { wl };
        *d_alpha = w0 - w1;
        let spring = k * alpha;
        *d_wu = match mode.of(top).branch() {
            None => 0.0,
            Some(s) => (self.k_m * u - spring - f_u.torque(wu, s)) / j_u,
        };
        *d_wl = match mode.of(bottom).branch() {
            None => 0.0,
            Some(s) => (spring - f_l.torque(wl, s)) / j_l,
        };
    }

    /// Acceleration of disc `i` in `mode`, the component `ω_i` of [`ChainModel::rhs_into`]:
    /// `(T_ex,i − T_f,i^s(ω_i))/J_i` with stuck discs' velocities taken as 0, or 0 if disc `i`
    /// is stuck.
    #[inline]
    pub fn disc_accel(&self, i: usize, x: &[f64], u: f64, mode: Mode) -> f64 {
        let n = self.j.len();
        match mode.of(Disc::at(i)).branch() {
            None => 0.0,
            Some(s) => {
                let w = |d: usize| {
                    if mode.is_stuck(Disc::at(d)) {
                        0.0
                    } else {
                        x[n - 1 + d]
                    }
                };
                (self.torque_with(i, x, u, w) - self.friction[i].torque(x[n - 1 + i], s))
                    / self.j[i]
            }
        }
    }

    /// Rate of disc `i`'s applied torque along a rate `v` of the state, at a fixed input (the
    /// torque is linear in the state):
    /// `k_{i−1} v_{α,i−1} + c_{i−1}(v_{ω,i−1} − v_{ω,i}) − k_i v_{α,i} − c_i(v_{ω,i} − v_{ω,i+1})`.
    /// The input's own rate, `k_m·du/dt` on disc 0, is the caller's to add.
    #[inline]
    pub fn applied_torque_rate(&self, i: usize, v: &[f64]) -> f64 {
        let n = self.j.len();
        self.torque_with(i, v, 0.0, |d| v[n - 1 + d])
    }

    /// Row `ω_i` of the Jacobian times `v`, `(∂f_mode/∂x · v)_{ω_i}`, without forming the
    /// matrix: the rate of disc `i`'s acceleration along `v`. The row's entries are those of
    /// [`ChainModel::jacobian`], summed in column order (so a chain of two gives the rig's
    /// matrix product to the bit).
    #[inline]
    pub fn accel_rate(&self, i: usize, x: &[f64], mode: Mode, v: &[f64]) -> f64 {
        let n = self.j.len();
        let Some(s) = mode.of(Disc::at(i)).branch() else {
            return 0.0;
        };
        let slipping = |d: usize| !mode.is_stuck(Disc::at(d));
        let (row, ji) = (n - 1 + i, self.j[i]);
        let mut own = -self.friction[i].dtorque(x[row], s);
        let mut acc = 0.0;
        if i > 0 {
            acc += self.k[i - 1] / ji * v[i - 1];
            own -= self.c[i - 1];
        }
        if i + 1 < n {
            acc += -self.k[i] / ji * v[i];
            own -= self.c[i];
        }
        if i > 0 && slipping(i - 1) && self.c[i - 1] != 0.0 {
            acc += self.c[i - 1] / ji * v[row - 1];
        }
        acc += own / ji * v[row];
        if i + 1 < n && slipping(i + 1) && self.c[i] != 0.0 {
            acc += self.c[i] / ji * v[row + 1];
        }
        acc
    }

    /// `∂f_mode/∂x · v` at `x`, written into `out`: [`ChainModel::jacobian`] applied to `v`
    /// without forming it, each row summed in column order.
    pub fn jacobian_times(&self, x: &[f64], mode: Mode, v: &[f64], out: &mut [f64]) {
        let n = self.j.len();
        let slipping = |d: usize| !mode.is_stuck(Disc::at(d));
        for (i, o) in out[..n - 1].iter_mut().enumerate() {
            let mut a = 0.0;
            if slipping(i) {
                a += v[n - 1 + i];
            }
            if slipping(i + 1) {
                a += -v[n + i];
            }
            *o = a;
        }
        for i in 0..n {
            out[n - 1 + i] = self.accel_rate(i, x, mode, v);
        }
    }

    /// `|∂f_mode/∂x| · v` at `x` (for `v ≥ 0`), written into `out`: the magnitudes of
    /// [`ChainModel::jacobian`]'s entries applied to `v`, without forming it. A bound on how
    /// far errors `v` in the state move the field, for rounding levels.
    pub fn jacobian_abs_times(&self, x: &[f64], mode: Mode, v: &[f64], out: &mut [f64]) {
        let n = self.j.len();
        let slipping = |d: usize| !mode.is_stuck(Disc::at(d));
        for (i, o) in out[..n - 1].iter_mut().enumerate() {
            let mut a = 0.0;
            if slipping(i) {
                a += v[n - 1 + i];
            }
            if slipping(i + 1) {
                a += v[n + i];
            }
            *o = a;
        }
        for i in 0..n {
            let row = n - 1 + i;
            let Some(s) = mode.of(Disc::at(i)).branch() else {
                out[row] = 0.0;
                continue;
            };
            let ji = self.j[i];
            let mut own = -self.friction[i].dtorque(x[row], s);
            let mut acc = 0.0;
            if i > 0 {
                acc += (self.k[i - 1] / ji).abs() * v[i - 1];
                own -= self.c[i - 1];
                if slipping(i - 1) {
                    acc += (self.c[i - 1] / ji).abs() * v[row - 1];
                }
            }
            if i + 1 < n {
                acc += (self.k[i] / ji).abs() * v[i];
                own -= self.c[i];
                if slipping(i + 1) {
                    acc += (self.c[i] / ji).abs() * v[row + 1];
                }
            }
            out[row] = acc + (own / ji).abs() * v[row];
        }
    }

    /// Disc `i`'s friction time scale `τ_fric,i = v_i/(T_i/J_i)` and its law's velocity scale
    /// `v_i` (both ∞ for a law without a velocity scale), as [`crate::TimeScales`] defines them
    /// for the rig.
    pub fn friction_scales(&self, i: usize) -> (f64, f64) {
        let f = &self.friction[i];
        let v = f.velocity_scale().unwrap_or(f64::INFINITY);
        let a = f.torque_scale() / self.j[i];
        let tau = if v.is_finite() && a > 0.0 {
            v / a
        } else {
            f64::INFINITY
        };
        (tau, v)
    }

    /// The Filippov-consistent mode of each disc at a state: slip by the sign of its velocity;
    /// a disc at ω = 0 sticks if its applied torque is inside its interval, else slips toward
    /// the exit; a law without an interval slips the way the torque pushes.
    pub fn mode_at(&self, x: &[f64], u: f64) -> Mode {
        let mut mode = Mode::SLIP;
        for i in 0..self.discs() {
            let w = x[self.omega(i)];
            let m = if w != 0.0 {
                DiscMode::slip_of(w)
            } else if !self.friction[i].is_set_valued() {
                let (_, hi) = self.friction[i].static_interval();
                DiscMode::slip_of(self.applied_torque(i, x, u) - hi)
            } else {
                self.stick_exit(i, x, u).unwrap_or(DiscMode::Stick)
            };
            mode.set(Disc::at(i), m);
        }
        mode
    }

    /// Analytic Jacobian `∂f_mode/∂x` (`2N − 1` square). A stuck disc's row is 0 and its
    /// velocity enters no other row (it is held at 0).
    pub fn jacobian(&self, x: &[f64], mode: Mode) -> DMatrix<f64> {
        let n = self.j.len();
        let dim = self.dim();
        let mut jac = DMatrix::zeros(dim, dim);
        let slipping = |i: usize| !mode.is_stuck(Disc::at(i));
        for i in 0..n - 1 {
            if slipping(i) {
                jac[(i, n - 1 + i)] = 1.0;
            }
            if slipping(i + 1) {
                jac[(i, n + i)] = -1.0;
            }
        }
        for i in 0..n {
            let Some(s) = mode.of(Disc::at(i)).branch() else {
                continue;
            };
            let (row, ji) = (n - 1 + i, self.j[i]);
            let mut own = -self.friction[i].dtorque(x[row], s);
            if i > 0 {
                jac[(row, i - 1)] = self.k[i - 1] / ji;
                own -= self.c[i - 1];
                if slipping(i - 1) {
                    jac[(row, row - 1)] = self.c[i - 1] / ji;
                }
            }
            if i + 1 < n {
                jac[(row, i)] = -self.k[i] / ji;
                own -= self.c[i];
                if slipping(i + 1) {
                    jac[(row, row + 1)] = self.c[i] / ji;
                }
            }
            jac[(row, row)] = own / ji;
        }
        jac
    }

    /// Mechanical energy `Σ ½J_i ω_i² + Σ ½k_i α_i²`.
    pub fn energy(&self, x: &[f64]) -> f64 {
        let n = self.j.len();
        let kinetic: f64 = (0..n).map(|i| 0.5 * self.j[i] * x[n - 1 + i].powi(2)).sum();
        let spring: f64 = (0..n - 1).map(|i| 0.5 * self.k[i] * x[i].powi(2)).sum();
        kinetic + spring
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Model, State};

    const DESIGN_EXAMPLE: &str = r#"
name = "chain3"
k_m = 3.9950                 # N m / V, motor on disc 1
[[disc]]                     # disc 1
j = 0.4765                   # kg m^2
friction = { family = "upper", t_s = 0.0, dt_s = 0.0, b = 2.2247, db = 0.0 }
[[disc]]                     # disc 2
j = 0.0326
k = 0.0727                   # N m/rad, spring to the disc above
c = 0.0                      # N m s/rad, coupling to the disc above (default 0)
friction = { family = "exponential", t_s = 0.1642, t_1 = 0.0603, t_2 = -0.2267, w_1 = 5.7468, w_2 = 0.2941, b = 0.0109 }
[[disc]]                     # disc 3
j = 0.0326
k = 0.0727
friction = { family = "stribeck", t_s = 0.2, t_c = 0.1, omega_s = 1.5, delta = 2.0, b = 0.01 }
"#;

    fn stribeck_set() -> Params {
        Params::from_toml_str(
            include_str!("../../../fixtures/params/stribeck.toml"),
            Path::new("stribeck.toml"),
        )
        .unwrap()
    }

    fn chain(text: &str) -> Result<ChainParams, String> {
        ChainParams::from_toml_str(text, Path::new("c.toml")).map_err(|e| e.to_string())
    }

    /// A chain serializes in the file's form: written back as TOML and read again it is the
    /// same chain, for every family; as JSON (a job file's `params`) its discs are a `disc`
    /// list with each law's `family`.
    #[test]
    fn a_chain_serializes_in_the_files_form() {
        let mut p = chain(DESIGN_EXAMPLE).unwrap();
        p.discs[1].c = 0.002;
        p.discs.push(ChainDisc {
            j: 0.01,
            k: 0.05,
            c: 0.0,
            law: DiscLaw::Viscous { b: 0.3 },
        });
        let table = toml::Table::try_from(&p).unwrap();
        assert_eq!(
            ChainParams::from_table(table, Path::new("again.toml")).unwrap(),
            p
        );
        let json = serde_json::to_value(&p).unwrap();
        assert_eq!(json["disc"].as_array().unwrap().len(), 4);
        assert_eq!(json["disc"][2]["friction"]["family"], "stribeck");
        assert_eq!(json["disc"][2]["friction"]["omega_s"], 1.5);
        assert_eq!(json["disc"][3]["friction"]["family"], "viscous");
        assert_eq!(json["k_m"], 3.995);
    }

    fn modes3() -> [DiscMode; 3] {
        [DiscMode::SlipPos, DiscMode::SlipNeg, DiscMode::Stick]
    }

    /// The chain of two is the rig: the same field, torques and modes, bit for bit, for both
    /// parameter sets, every mode and states on both sides of every surface.
    #[test]
    fn the_chain_of_two_is_the_rig_bit_for_bit() {
        for p in [Params::table1(), stribeck_set()] {
            let rig = Model::new(p);
            let chain = ChainModel::new(&ChainParams::from_params(&p));
            assert_eq!(chain.dim(), 3);
            for x in [
                State::new(0.3, 2.0, 1.0),
                State::new(-1.0, 0.7, -3.0),
                State::new(2.5, 0.0, 0.0),
                State::new(3.708, 1e-9, -1e-12),
            ] {
                for u in [0.0, 0.4, 1.5, 6.0, -2.0] {
                    for upper in modes3() {
                        for lower in modes3() {
                            let mode = Mode::rig(upper, lower);
                            let mut out = [0.0; 3];
                            chain.rhs_into(x.as_slice(), u, mode, &mut out);
                            let f = rig.rhs(&x, u, mode);
                            for r in 0..3 {
                                assert_eq!(out[r].to_bits(), f[r].to_bits(), "{x:?} {u} {mode:?}");
                            }
                            let jc = chain.jacobian(x.as_slice(), mode);
                            let jr = rig.jacobian(&x, u, mode);
                            for r in 0..3 {
                                for c in 0..3 {
                                    assert_eq!(jc[(r, c)], jr[(r, c)], "{x:?} {mode:?} ({r},{c})");
                                }
                            }
                        }
                    }
                    for (i, d) in Disc::BOTH.into_iter().enumerate() {
                        let (a, b) = (
                            chain.applied_torque(i, x.as_slice(), u),
                            rig.applied_torque(d, &x, u),
                        );
                        assert_eq!(a.to_bits(), b.to_bits());
                        assert_eq!(
                            chain.stick_exit(i, x.as_slice(), u),
                            rig.stick_exit(d, &x, u)
                        );
                    }
                    assert_eq!(chain.mode_at(x.as_slice(), u), rig.mode_at(&x, u));
                    assert_eq!(chain.energy(x.as_slice()), rig.energy(&x));
                }
            }
        }
    }

    /// The state's names: the rig's for three values, a chain's numbered ones (the header of
    /// a chain's trace, DESIGN's contract) for 2N − 1, by index for an even length.
    #[test]
    fn state_names_follow_the_states_size() {
        assert_eq!(crate::state_names(3), ["alpha", "omega_u", "omega_l"]);
        let three = ChainModel::new(&chain(DESIGN_EXAMPLE).unwrap());
        let want = ["alpha_1", "alpha_2", "omega_1", "omega_2", "omega_3"];
        assert_eq!(three.state_names(), want);
        assert_eq!(crate::state_names(5), want);
        assert_eq!(crate::state_names(2), ["x[0]", "x[1]"]);
        let two = ChainModel::new(&ChainParams::from_params(&Params::table1()));
        assert_eq!(two.state_names(), ["alpha_1", "omega_1", "omega_2"]);
        assert_eq!(Model::table1().state_names().len(), Model::table1().dim());
    }

    /// Today's two-disc files mean the same chain of two, and a chain of two in rig shape
    /// converts back to the rig's parameter set.
    #[test]
    fn two_disc_files_read_as_the_same_chain_of_two() {
        for (text, p) in [
            (
                include_str!("../../../fixtures/params/table1.toml"),
                Params::table1(),
            ),
            (
                include_str!("../../../fixtures/params/stribeck.toml"),
                stribeck_set(),
            ),
        ] {
            let c = chain(text).unwrap();
            assert_eq!(c, ChainParams::from_params(&p));
            assert_eq!(c.to_params(), Some(p));
        }
        let three = chain(DESIGN_EXAMPLE).unwrap();
        assert_eq!(three.len(), 3);
        assert_eq!(three.to_params(), None);
        assert_eq!(three.discs[1].c, 0.0);
        assert_eq!(three.discs[2].law.family(), "stribeck");
        // The first two discs of the example are Table 1's rig.
        let two = ChainParams {
            k_m: three.k_m,
            discs: three.discs[..2].to_vec(),
        };
        assert_eq!(two.to_params(), Some(Params::table1()));
        let mut coupled = two.clone();
        coupled.discs[1].c = 0.01;
        assert_eq!(coupled.to_params(), None, "a coupling is not the rig");
    }

    /// Bad values are refused naming the disc (from 1), the field and the value; negative
    /// controls first: each line alone breaks a valid file.
    #[test]
    fn validation_names_the_disc_and_the_field() {
        let cases: [(&str, &str, &str); 12] = [
            (
                "friction = { family = \"stribeck\", t_s = 0.2,",
                "friction = { family = \"stribeck\", t_s = -1,",
                "disc 3: friction.t_s = -1: static level must be >= 0",
            ),
            ("j = 0.4765", "j = 0", "disc 1: j = 0: must be positive"),
            (
                "k = 0.0727                   #",
                "k = -0.5 #",
                "disc 2: k = -0.5: must be positive",
            ),
            (
                "c = 0.0  ",
                "c = -0.1 ",
                "disc 2: c = -0.1: viscous coupling must be >= 0",
            ),
            ("k_m = 3.9950", "k_m = 0", "k_m = 0: must be non-zero"),
            (
                "j = 0.4765",
                "j = 0.4765\nk = 1.0",
                "disc 1: k = 1: disc 1 has no disc above it",
            ),
            (
                "family = \"upper\", t_s = 0.0, dt_s = 0.0,",
                "family = \"upper\", t_s = 0.0, dt_s = 0.5,",
                "disc 1: friction.dt_s = 0.5: |dt_s| must not exceed t_s",
            ),
            (
                "family = \"stribeck\"",
                "family = \"coulomb\"",
                "disc 3: friction.family = \"coulomb\": unknown friction family",
            ),
            (
                "t_c = 0.1, omega_s",
                "t_c = 0.1, t_1 = 0.2, omega_s",
                "disc 3: friction.t_1 = 0.2: not a parameter of the 'stribeck' family",
            ),
            (
                "t_2 = -0.2267",
                "t_2 = -0.9",
                "disc 2: friction.t_2 = -0.9: makes the disc's friction law negative",
            ),
            (
                "t_c = 0.1, omega_s = 1.5,",
                "omega_s = 1.5,",
                "disc 3: friction.t_c: missing (required by family 'stribeck')",
            ),
            (
                "j = 0.0326\nk = 0.0727\nfriction",
                "j = 0.0326\nfriction",
                "disc 3: k: missing (the spring to the disc above)",
            ),
        ];
        assert!(chain(DESIGN_EXAMPLE).is_ok());
        for (from, to, want) in cases {
            assert!(DESIGN_EXAMPLE.contains(from), "{from}");
            let text = DESIGN_EXAMPLE.replacen(from, to, 1);
            let err = chain(&text).expect_err(to);
            assert!(err.starts_with("c.toml: "), "{err}");
            assert!(err.contains(want), "{to}: got {err}, want {want}");
        }
        let one = DESIGN_EXAMPLE
            .split("[[disc]]                     # disc 2")
            .next();
        let err = chain(one.unwrap()).unwrap_err();
        assert!(err.contains("a chain needs at least 2 discs"), "{err}");
        // The mode's bit sets hold 64 discs: a chain of 64 is read, one of 65 refused.
        let tail =
            "[[disc]]\nj = 0.0326\nk = 0.0727\nfriction = { family = \"viscous\", b = 0.01 }\n";
        let with = |n: usize| format!("{}{}", one.unwrap(), tail.repeat(n - 1));
        assert_eq!(chain(&with(Mode::MAX_DISCS)).map(|c| c.len()), Ok(64));
        let err = chain(&with(Mode::MAX_DISCS + 1)).unwrap_err();
        assert!(
            err.contains("disc = 65 discs: a chain holds at most 64 discs"),
            "{err}"
        );
        let nan = DESIGN_EXAMPLE.replacen("j = 0.0326", "j = nan", 1);
        assert!(
            chain(&nan)
                .unwrap_err()
                .contains("disc 2: j = NaN: must be a finite number")
        );
    }

    fn coupled_chain() -> ChainModel {
        let mut p = chain(DESIGN_EXAMPLE).unwrap();
        p.discs.push(ChainDisc {
            j: 0.05,
            k: 0.1,
            c: 0.02,
            law: DiscLaw::Viscous { b: 0.03 },
        });
        p.discs[2].c = 0.015;
        p.discs[0].law = DiscLaw::Upper(UpperFriction {
            t_s: 0.38,
            dt_s: -0.006,
            b: 2.0,
            db: 0.1,
        });
        p.validate().unwrap();
        ChainModel::new(&p)
    }

    fn all_modes(n: usize) -> Vec<Mode> {
        all_disc_modes(n)
            .iter()
            .map(|m| Mode::from_discs(m))
            .collect()
    }

    fn all_disc_modes(n: usize) -> Vec<Vec<DiscMode>> {
        let mut out = vec![vec![]];
        for _ in 0..n {
            out = out
                .into_iter()
                .flat_map(|m| {
                    modes3().map(|d| {
                        let mut m = m.clone();
                        m.push(d);
                        m
                    })
                })
                .collect();
        }
        out
    }

    /// The analytic Jacobian of a coupled chain of four (every family, couplings on two
    /// springs) against central differences, in every one of its 81 modes.
    #[test]
    fn chain_jacobian_matches_finite_differences() {
        let m = coupled_chain();
        let x = [0.4, -0.7, 1.1, 1.3, 0.6, -2.1, 0.9];
        for modes in all_modes(4) {
            let jac = m.jacobian(&x, modes);
            for k in 0..7 {
                let d = 1e-6;
                let (mut xp, mut xm) = (x, x);
                xp[k] += d;
                xm[k] -= d;
                let (mut fp, mut fm) = ([0.0; 7], [0.0; 7]);
                m.rhs_into(&xp, 1.5, modes, &mut fp);
                m.rhs_into(&xm, 1.5, modes, &mut fm);
                for r in 0..7 {
                    let fd = (fp[r] - fm[r]) / (2.0 * d);
                    // Central differences: O(d²) truncation + ε|f|/d rounding ≈ 1e-8 for
                    // |f| ≲ 50: 1e-6 absolute, 100×.
                    assert!(
                        (jac[(r, k)] - fd).abs() <= 1e-6 * (1.0 + fd.abs()),
                        "{modes:?} ({r},{k}): {} vs {fd}",
                        jac[(r, k)]
                    );
                }
            }
        }
    }

    /// The matrix-free products the event solver uses (`jacobian_times`, its rows
    /// `accel_rate`, the magnitudes' `jacobian_abs_times`) are the Jacobian's, which the test
    /// above holds to finite differences, in every mode of the coupled chain of four;
    /// `disc_accel` is `rhs_into`'s component; `applied_torque_rate` is the applied torque's
    /// change along the rate (it is linear). Sums in another order than the matrix product:
    /// rounding, 1e-14 relative (the torques are O(10): 1e-13 absolute).
    #[test]
    fn matrix_free_products_are_the_jacobians() {
        let m = coupled_chain();
        let x = [0.4, -0.7, 1.1, 1.3, 0.6, -2.1, 0.9];
        let v = [0.3, -1.2, 0.5, 2.0, -0.4, 0.8, -1.5];
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * (1.0 + b.abs());
        for modes in all_modes(4) {
            let jac = m.jacobian(&x, modes);
            let jv = &jac * nalgebra::DVector::from_column_slice(&v);
            let jav = jac.abs() * nalgebra::DVector::from_column_slice(&v.map(f64::abs));
            let (mut a, mut b) = ([0.0; 7], [0.0; 7]);
            m.jacobian_times(&x, modes, &v, &mut a);
            m.jacobian_abs_times(&x, modes, &v.map(f64::abs), &mut b);
            let mut f = [0.0; 7];
            m.rhs_into(&x, 1.5, modes, &mut f);
            for r in 0..7 {
                assert!(
                    close(a[r], jv[r]),
                    "{modes:?} row {r}: {} vs {}",
                    a[r],
                    jv[r]
                );
                assert!(
                    close(b[r], jav[r]),
                    "{modes:?} row {r}: {} vs {}",
                    b[r],
                    jav[r]
                );
            }
            for i in 0..4 {
                // The applied torque is linear in the state: its rate along v is its change.
                let xv: Vec<f64> = x.iter().zip(&v).map(|(p, q)| p + q).collect();
                let change = m.applied_torque(i, &xv, 1.5) - m.applied_torque(i, &x, 1.5);
                assert!((m.applied_torque_rate(i, &v) - change).abs() <= 1e-14 * 10.0);
                assert!(close(m.accel_rate(i, &x, modes, &v), jv[3 + i]));
                assert_eq!(
                    m.disc_accel(i, &x, 1.5, modes),
                    f[3 + i],
                    "{modes:?} disc {i}"
                );
            }
        }
    }

    /// The power balance derived independently of the field's code: along any mode,
    /// `dE/dt = k_m u ω_1 − Σ_i T_fi ω_i − Σ_i c_i (ω_i − ω_{i+1})²` with stuck discs at rest.
    #[test]
    fn power_is_work_minus_friction_and_coupling_dissipation() {
        let m = coupled_chain();
        let (u, n) = (2.0, 4);
        for modes in all_modes(n) {
            let mut x: [f64; 7] = [0.4, -0.7, 1.1, 1.3, 0.6, -2.1, 0.9];
            for i in 0..n {
                if modes.is_stuck(Disc::at(i)) {
                    x[n - 1 + i] = 0.0;
                } else if modes.of(Disc::at(i)).branch() == Some(-1.0) {
                    x[n - 1 + i] = -x[n - 1 + i].abs();
                } else {
                    x[n - 1 + i] = x[n - 1 + i].abs();
                }
            }
            let mut f = [0.0; 7];
            m.rhs_into(&x, u, modes, &mut f);
            let de: f64 = (0..n)
                .map(|i| m.j[i] * x[n - 1 + i] * f[n - 1 + i])
                .sum::<f64>()
                + (0..n - 1).map(|i| m.k[i] * x[i] * f[i]).sum::<f64>();
            let w = |i: usize| x[n - 1 + i];
            let mut want = m.k_m * u * w(0);
            for i in 0..n {
                want -= m.friction[i].curve(w(i)) * w(i);
            }
            for i in 0..n - 1 {
                want -= m.c[i] * (w(i) - w(i + 1)).powi(2);
            }
            // Sums of ~20 terms of size ≲ 10: rounding ≲ 1e-14; 1e-12 = 100×.
            assert!((de - want).abs() < 1e-12, "{modes:?}: {de} vs {want}");
        }
    }

    /// The stick conditions decouple: a stuck disc's acceleration is 0 and its applied torque
    /// depends on the other discs' state only, whichever of them are stuck.
    #[test]
    fn a_stuck_disc_is_held_whatever_the_others_do() {
        let m = coupled_chain();
        let x = [0.4, -0.7, 1.1, 1.3, 0.0, -2.1, 0.9];
        for modes in all_modes(4).into_iter().filter(|m| m.is_stuck(Disc::at(1))) {
            let mut f = [0.0; 7];
            m.rhs_into(&x, 1.5, modes, &mut f);
            assert_eq!(f[m.omega(1)], 0.0);
            // α̇_1 = ω_1 − 0, α̇_2 = 0 − ω_3 (or 0 where those discs are stuck too).
            let w = |i: usize| {
                if modes.is_stuck(Disc::at(i)) {
                    0.0
                } else {
                    x[3 + i]
                }
            };
            assert_eq!(f[0], w(0));
            assert_eq!(f[1], -w(2));
        }
        // Its applied torque: k_1 α_1 + c_1 (ω_1 − ω_2) − k_2 α_2 − c_2 (ω_2 − ω_3), with
        // c_1 = 0 (the example's), k_2 = 0.0727, c_2 = 0.015 and ω_2 = 0.
        let want = 0.0727 * 0.4 - 0.0727 * (-0.7) - 0.015 * (0.0 - (-2.1));
        // The same three products (each ≲ 0.05 N m) summed in another order: rounding ≲ 1e-17;
        // 1e-15 is 100×.
        assert!((m.applied_torque(1, &x, 1.5) - want).abs() < 1e-15);
    }

    #[test]
    fn rig_copies_is_the_top_disc_and_lower_discs() {
        let c = ChainParams::rig_copies(&Params::table1(), 8);
        assert_eq!(c.len(), 8);
        c.validate().unwrap();
        assert!(c.discs[1..].iter().all(|d| d.law.family() == "exponential"));
        assert_eq!(
            ChainParams::rig_copies(&Params::table1(), 2).to_params(),
            Some(Params::table1())
        );
        assert_eq!(ChainModel::new(&c).dim(), 15);
    }

    /// Every front end reads parameters through [`Params`]: a chain of two in the rig's shape,
    /// written in chain form, is the rig; any other chain is refused naming what it has.
    #[test]
    fn a_rig_shaped_chain_file_is_the_rig_and_other_chains_are_refused_by_name() {
        let two = DESIGN_EXAMPLE
            .split("[[disc]]                     # disc 3")
            .next()
            .unwrap();
        let p = Params::from_toml_str(two, Path::new("c.toml")).unwrap();
        assert_eq!(p, Params::table1());
        let table: toml::Table = two.parse().unwrap();
        assert_eq!(Params::from_table(table, Path::new("params")), Ok(p));
        for (text, why) in [
            (DESIGN_EXAMPLE.to_owned(), "a chain with 3 discs:"),
            (
                two.replacen("c = 0.0  ", "c = 0.01 ", 1),
                "a chain with a viscous coupling c = 0.01 on disc 2:",
            ),
            (
                two.replacen(
                    "{ family = \"upper\", t_s = 0.0, dt_s = 0.0, b = 2.2247, db = 0.0 }",
                    "{ family = \"viscous\", b = 2.2247 }",
                    1,
                )
                .replacen(
                    "{ family = \"exponential\", t_s = 0.1642, t_1 = 0.0603, t_2 = -0.2267, w_1 = 5.7468, w_2 = 0.2941, b = 0.0109 }",
                    "{ family = \"viscous\", b = 0.0109 }",
                    1,
                ),
                "a chain with disc 2 with the 'viscous' family:",
            ),
        ] {
            let err = Params::from_toml_str(&text, Path::new("c.toml")).unwrap_err();
            assert!(err.to_string().starts_with(&format!("c.toml: {why}")), "{err}");
        }
        // A viscous top disc is the rig's upper law with its levels 0.
        let viscous_top = two.replacen(
            "{ family = \"upper\", t_s = 0.0, dt_s = 0.0, b = 2.2247, db = 0.0 }",
            "{ family = \"viscous\", b = 2.2247 }",
            1,
        );
        assert_eq!(
            Params::from_toml_str(&viscous_top, Path::new("c.toml")),
            Ok(Params::table1())
        );
        // A disc's bad value reaches the rig's reader with its disc.
        let bad = two.replacen("j = 0.0326", "j = -1", 1);
        let err = Params::from_toml_str(&bad, Path::new("c.toml")).unwrap_err();
        assert_eq!(err.to_string(), "c.toml: disc 2: j = -1: must be positive");
    }
}
