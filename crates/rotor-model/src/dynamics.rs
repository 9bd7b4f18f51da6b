//! The equations of motion (1) of the source, per friction mode.
//!
//! State `x = [α, ω_u, ω_l]`, `α = θ_u − θ_l`:
//!
//! ```text
//! α̇       = ω_u − ω_l
//! J_u ω̇_u = k_m u − k_θ α − T_fu(ω_u)
//! J_l ω̇_l =          k_θ α − T_fl(ω_l)
//! ```
//!
//! In a *slip* mode with branch `s = ±1` the friction is the branch torque `T_f^s(ω)`
//! (smooth, continued across ω = 0). In *stick* the disc's velocity is held at exactly 0
//! and its friction equals the applied torque (Utkin's equivalent control), so ω̇ = 0.
//! Because the mass matrix is diagonal and the discs couple only through α, the two stick
//! torques are independent: `T_ex,u = k_m u − k_θ α`, `T_ex,l = k_θ α`.

use nalgebra::{Matrix3, Vector3};

use crate::friction::Friction;
use crate::params::Params;

/// State `[α, ω_u, ω_l]` in rad, rad/s, rad/s.
pub type State = Vector3<f64>;

/// Index of α in [`State`].
pub const ALPHA: usize = 0;
/// Index of ω_u in [`State`].
pub const OMEGA_U: usize = 1;
/// Index of ω_l in [`State`].
pub const OMEGA_L: usize = 2;
/// The rig's state components by name, in [`State`]'s order: the CSV header's columns, the
/// job file's and `--x0`'s order.
pub const RIG_STATE_NAMES: [&str; 3] = ["alpha", "omega_u", "omega_l"];

/// The names of a state's components, from its length: the rig's ([`RIG_STATE_NAMES`]) for
/// three values, a chain's `alpha_1 … alpha_{N−1}, omega_1 … omega_N` for `2N − 1` of them
/// ([`crate::ChainModel::state_names`]); `x[k]` for a length no chain has.
pub fn state_names(len: usize) -> Vec<String> {
    if len == 3 {
        RIG_STATE_NAMES.map(str::to_owned).to_vec()
    } else if len % 2 == 1 {
        crate::chain::chain_state_names(len.div_ceil(2))
    } else {
        (0..len).map(|k| format!("x[{k}]")).collect()
    }
}

/// A disc, by its position in the chain from the top: position 0 is the motor-driven disc,
/// the last one the bottom. The rig is the chain of two ([`Disc::UPPER`], [`Disc::LOWER`]);
/// its words `upper` and `lower` are a view of positions 0 and 1 ([`Disc::rig_word`]), and a
/// chain's discs are numbered from 1 ([`Disc::number`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Disc(u16);

impl Disc {
    /// The rig's motor-driven disc (J_u, ω_u, friction T_fu, eq. (4)): position 0.
    pub const UPPER: Disc = Disc(0);
    /// The rig's disc at the end of the string, loaded by the brake (J_l, ω_l, friction
    /// T_fl): position 1.
    pub const LOWER: Disc = Disc(1);
    /// Both discs of the rig, upper first.
    pub const BOTH: [Disc; 2] = [Disc::UPPER, Disc::LOWER];

    /// The disc at `position` (0 = the top). Positions beyond [`Mode::MAX_DISCS`] have no
    /// mode and are refused where a chain is read.
    ///
    /// # Panics
    ///
    /// If `position ≥` [`Mode::MAX_DISCS`]: a mode's bit for it would wrap onto another
    /// disc's, so such a disc is a bug, never a value.
    #[inline]
    pub const fn at(position: usize) -> Disc {
        assert!(
            position < Mode::MAX_DISCS,
            "a disc's position is below Mode::MAX_DISCS"
        );
        Disc(position as u16)
    }

    /// Position from the top, 0-based.
    #[inline]
    pub const fn position(self) -> usize {
        self.0 as usize
    }

    /// The disc's number as a chain file counts it, 1-based.
    #[inline]
    pub const fn number(self) -> usize {
        self.0 as usize + 1
    }

    /// The discs `0..n`, top first.
    pub fn all(n: usize) -> impl DoubleEndedIterator<Item = Disc> + ExactSizeIterator {
        (0..n).map(Disc::at)
    }

    /// The rig's word for this disc, `upper` or `lower`; `None` beyond the rig's two.
    pub const fn rig_word(self) -> Option<&'static str> {
        match self.0 {
            0 => Some("upper"),
            1 => Some("lower"),
            _ => None,
        }
    }

    /// The disc's name in a chain of `n` as a person reads it: the rig's word for the two
    /// discs of the rig (`n = 2`), else `disc <number>`.
    pub fn name_in(self, n: usize) -> std::borrow::Cow<'static, str> {
        match self.rig_word() {
            Some(w) if n == 2 => w.into(),
            _ => format!("disc {}", self.number()).into(),
        }
    }

    /// Index of this disc's velocity in the rig's [`State`] (`ω_u` at 1, `ω_l` at 2): the
    /// state holds the one twist angle first. In a chain of N the velocities follow its
    /// N − 1 angles ([`crate::ChainModel::omega`]).
    pub const fn index(self) -> usize {
        OMEGA_U + self.0 as usize
    }
}

/// Friction mode of one disc.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiscMode {
    /// ω > 0 (branch s = +1).
    SlipPos,
    /// ω < 0 (branch s = −1).
    SlipNeg,
    /// ω ≡ 0, friction = applied torque.
    Stick,
}

impl DiscMode {
    /// The slip branch `s` (±1), or `None` in stick.
    pub fn branch(self) -> Option<f64> {
        match self {
            DiscMode::SlipPos => Some(1.0),
            DiscMode::SlipNeg => Some(-1.0),
            DiscMode::Stick => None,
        }
    }

    /// The slip mode of velocity `w` (≠ 0); `w = 0` gives `SlipPos`.
    pub fn slip_of(w: f64) -> DiscMode {
        if w < 0.0 {
            DiscMode::SlipNeg
        } else {
            DiscMode::SlipPos
        }
    }
}

/// The friction modes of the discs, one [`DiscMode`] per disc position.
///
/// Held as two bit sets (the stuck discs and the discs slipping backward; every other disc
/// slips forward), so a mode of any chain up to [`Mode::MAX_DISCS`] discs is `Copy`,
/// hashable and compared in two instructions, and changing one disc's mode allocates
/// nothing. A mode does not store the number of discs: positions past a chain's last disc
/// read as [`DiscMode::SlipPos`] and are never asked.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Mode {
    stuck: u64,
    backward: u64,
}

impl Mode {
    /// The most discs a mode holds (the width of its bit sets). A chain file with more is
    /// refused by name.
    pub const MAX_DISCS: usize = 64;

    /// Every disc slipping forward.
    pub const SLIP: Mode = Mode {
        stuck: 0,
        backward: 0,
    };

    /// The rig's mode: the upper disc's, then the lower disc's.
    pub const fn rig(upper: DiscMode, lower: DiscMode) -> Mode {
        Mode::SLIP.with(Disc::UPPER, upper).with(Disc::LOWER, lower)
    }

    /// Every one of `n` discs in mode `m`.
    pub fn uniform(n: usize, m: DiscMode) -> Mode {
        Disc::all(n).fold(Mode::SLIP, |acc, d| acc.with(d, m))
    }

    /// The mode of each disc in position order.
    pub fn from_discs(modes: &[DiscMode]) -> Mode {
        modes
            .iter()
            .enumerate()
            .fold(Mode::SLIP, |acc, (i, &m)| acc.with(Disc::at(i), m))
    }

    /// Mode of one disc.
    #[inline]
    pub const fn of(&self, d: Disc) -> DiscMode {
        let bit = 1u64 << d.0;
        if self.stuck & bit != 0 {
            DiscMode::Stick
        } else if self.backward & bit != 0 {
            DiscMode::SlipNeg
        } else {
            DiscMode::SlipPos
        }
    }

    /// This mode with one disc's mode replaced.
    #[inline]
    pub const fn with(self, d: Disc, m: DiscMode) -> Mode {
        let bit = 1u64 << d.0;
        let (stuck, backward) = (self.stuck & !bit, self.backward & !bit);
        match m {
            DiscMode::SlipPos => Mode { stuck, backward },
            DiscMode::SlipNeg => Mode {
                stuck,
                backward: backward | bit,
            },
            DiscMode::Stick => Mode {
                stuck: stuck | bit,
                backward,
            },
        }
    }

    /// Sets the mode of one disc.
    #[inline]
    pub fn set(&mut self, d: Disc, m: DiscMode) {
        *self = self.with(d, m);
    }

    /// Whether the disc is stuck.
    #[inline]
    pub const fn is_stuck(&self, d: Disc) -> bool {
        self.stuck & (1u64 << d.0) != 0
    }

    /// Mode of the rig's upper disc.
    #[inline]
    pub const fn upper(&self) -> DiscMode {
        self.of(Disc::UPPER)
    }

    /// Mode of the rig's lower disc.
    #[inline]
    pub const fn lower(&self) -> DiscMode {
        self.of(Disc::LOWER)
    }
}

/// Lists the modes up to the last disc that is not slipping forward (at least the rig's
/// two): `Mode[SlipPos, Stick]`.
impl std::fmt::Debug for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let used = 64 - (self.stuck | self.backward).leading_zeros() as usize;
        f.write_str("Mode")?;
        f.debug_list()
            .entries(Disc::all(used.max(2)).map(|d| self.of(d)))
            .finish()
    }
}

/// The rotor model: a validated parameter set with the vector fields built on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Model {
    /// The parameter set the friction laws were built from.
    pub params: Params,
    upper: Friction,
    lower: Friction,
}

impl Model {
    /// Builds the model of a validated parameter set.
    pub fn new(params: Params) -> Model {
        Model {
            params,
            upper: Friction::upper(params.upper),
            lower: Friction::lower(params.lower),
        }
    }

    /// Size of the state, 3.
    pub const fn dim(&self) -> usize {
        3
    }

    /// The names of the state's components, [`RIG_STATE_NAMES`].
    pub const fn state_names(&self) -> [&'static str; 3] {
        RIG_STATE_NAMES
    }

    /// The Table 1 model.
    pub fn table1() -> Model {
        Model::new(Params::table1())
    }

    /// Friction law of a disc.
    #[inline]
    pub fn friction(&self, d: Disc) -> &Friction {
        if d == Disc::UPPER {
            &self.upper
        } else {
            &self.lower
        }
    }

    /// Inertia of a disc.
    #[inline]
    pub fn inertia(&self, d: Disc) -> f64 {
        if d == Disc::UPPER {
            self.params.j_u
        } else {
            self.params.j_l
        }
    }

    /// Torque on a disc from everything but its own friction:
    /// `T_ex,u = k_m u − k_θ α`, `T_ex,l = k_θ α`.
    #[inline]
    pub fn applied_torque(&self, d: Disc, x: &State, u: f64) -> f64 {
        let spring = self.params.k_theta * x[ALPHA];
        if d == Disc::UPPER {
            self.params.k_m * u - spring
        } else {
            spring
        }
    }

    /// Whether the applied torque lies inside the disc's stick interval (so stick persists).
    pub fn can_stick(&self, d: Disc, x: &State, u: f64) -> bool {
        let (lo, hi) = self.friction(d).static_interval();
        let t = self.applied_torque(d, x, u);
        lo <= t && t <= hi
    }

    /// The slip direction a stuck disc leaves toward, if the applied torque is outside the
    /// stick interval: `SlipPos` above it, `SlipNeg` below it, `None` inside.
    pub fn stick_exit(&self, d: Disc, x: &State, u: f64) -> Option<DiscMode> {
        let (lo, hi) = self.friction(d).static_interval();
        let t = self.applied_torque(d, x, u);
        if t > hi {
            Some(DiscMode::SlipPos)
        } else if t < lo {
            Some(DiscMode::SlipNeg)
        } else {
            None
        }
    }

    /// Acceleration of one disc in a given mode: `(T_ex − T_f^s(ω))/J`, or 0 in stick.
    #[inline]
    pub fn disc_accel(&self, d: Disc, x: &State, u: f64, m: DiscMode) -> f64 {
        match m.branch() {
            None => 0.0,
            Some(s) => {
                let w = x[d.index()];
                (self.applied_torque(d, x, u) - self.friction(d).torque(w, s)) / self.inertia(d)
            }
        }
    }

    /// The smooth vector field of a mode, `ẋ = f_mode(x, u)`. In stick the disc's velocity
    /// is taken as exactly 0 (whatever is stored in `x`).
    #[inline]
    pub fn rhs(&self, x: &State, u: f64, mode: Mode) -> State {
        let wu = if mode.is_stuck(Disc::UPPER) {
            0.0
        } else {
            x[OMEGA_U]
        };
        let wl = if mode.is_stuck(Disc::LOWER) {
            0.0
        } else {
            x[OMEGA_L]
        };
        State::new(
            wu - wl,
            self.disc_accel(Disc::UPPER, x, u, mode.upper()),
            self.disc_accel(Disc::LOWER, x, u, mode.lower()),
        )
    }

    /// Analytic Jacobian `∂f_mode/∂x`.
    pub fn jacobian(&self, x: &State, _u: f64, mode: Mode) -> Matrix3<f64> {
        let p = &self.params;
        let mut j = Matrix3::zeros();
        if let Some(s) = mode.upper().branch() {
            j[(ALPHA, OMEGA_U)] = 1.0;
            j[(OMEGA_U, ALPHA)] = -p.k_theta / p.j_u;
            j[(OMEGA_U, OMEGA_U)] = -self.upper.dtorque(x[OMEGA_U], s) / p.j_u;
        }
        if let Some(s) = mode.lower().branch() {
            j[(ALPHA, OMEGA_L)] = -1.0;
            j[(OMEGA_L, ALPHA)] = p.k_theta / p.j_l;
            j[(OMEGA_L, OMEGA_L)] = -self.lower.dtorque(x[OMEGA_L], s) / p.j_l;
        }
        j
    }

    /// `∂f_mode/∂u`.
    pub fn d_rhs_du(&self, mode: Mode) -> State {
        let mut v = State::zeros();
        if !mode.is_stuck(Disc::UPPER) {
            v[OMEGA_U] = self.params.k_m / self.params.j_u;
        }
        v
    }

    /// The Filippov-consistent mode at a state: slip by the sign of each velocity; a disc at
    /// ω = 0 sticks if the applied torque is inside its interval, else slips toward the exit.
    pub fn mode_at(&self, x: &State, u: f64) -> Mode {
        let mut m = Mode::SLIP;
        for d in Disc::BOTH {
            let w = x[d.index()];
            let dm = if w != 0.0 {
                DiscMode::slip_of(w)
            } else if !self.friction(d).is_set_valued() {
                // Zero-width interval: no stick; slip the way the applied torque pushes.
                let (_, hi) = self.friction(d).static_interval();
                DiscMode::slip_of(self.applied_torque(d, x, u) - hi)
            } else {
                self.stick_exit(d, x, u).unwrap_or(DiscMode::Stick)
            };
            m.set(d, dm);
        }
        m
    }

    /// Mechanical energy `½J_u ω_u² + ½J_l ω_l² + ½k_θ α²`.
    pub fn energy(&self, x: &State) -> f64 {
        let p = &self.params;
        0.5 * p.j_u * x[OMEGA_U].powi(2)
            + 0.5 * p.j_l * x[OMEGA_L].powi(2)
            + 0.5 * p.k_theta * x[ALPHA].powi(2)
    }

    /// Power balance `dE/dt = k_m u ω_u − T_fu ω_u − T_fl ω_l` along a mode's field.
    pub fn power(&self, x: &State, u: f64, mode: Mode) -> f64 {
        let f = self.rhs(x, u, mode);
        let p = &self.params;
        p.j_u * x[OMEGA_U] * f[OMEGA_U]
            + p.j_l * x[OMEGA_L] * f[OMEGA_L]
            + p.k_theta * x[ALPHA] * f[ALPHA]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn the_last_disc_a_mode_holds_is_its_own() {
        let last = Disc::at(Mode::MAX_DISCS - 1);
        let m = Mode::uniform(Mode::MAX_DISCS, DiscMode::SlipPos).with(last, DiscMode::Stick);
        assert!(m.is_stuck(last) && !m.is_stuck(Disc::UPPER));
    }

    #[test]
    #[should_panic(expected = "below Mode::MAX_DISCS")]
    fn a_disc_beyond_the_modes_is_a_bug() {
        let _ = Disc::at(Mode::MAX_DISCS);
    }

    fn models() -> Vec<Model> {
        let st = Params::from_toml_str(
            include_str!("../../../fixtures/params/stribeck.toml"),
            std::path::Path::new("s"),
        )
        .unwrap();
        vec![Model::table1(), Model::new(st)]
    }

    /// docs/model.md §3.1: Table 1 has T_su = ΔT_su = 0. With upper static friction c =
    /// T_su + ΔT_su (and Δb_u = 0) the upper law is c + b_u ω while ω_u > 0, so the field of
    /// every mode with the upper disc slipping forward is Table 1's at u − c/k_m: every
    /// u-location moves up by c/k_m. Checked on the fields (to rounding: the two sides add
    /// the same terms in another order) and on the slipping equilibria.
    #[test]
    fn upper_static_friction_shifts_every_u_location_by_its_level_over_k_m() {
        let t1 = Model::table1();
        let mut p = Params::table1();
        (p.upper.t_s, p.upper.dt_s) = (0.37975, -0.00575); // the Stribeck set's values
        let with = Model::new(p);
        let shift = (p.upper.t_s + p.upper.dt_s) / p.k_m;
        for u in [0.5, 1.5, 2.5, 4.5] {
            for x in [
                State::new(0.3, 2.0, 1.0),
                State::new(-1.0, 0.7, -3.0),
                State::new(2.5, 5.0, 0.0),
            ] {
                for lower in [DiscMode::SlipPos, DiscMode::SlipNeg, DiscMode::Stick] {
                    let m = Mode::rig(DiscMode::SlipPos, lower);
                    let (a, b) = (with.rhs(&x, u, m), t1.rhs(&x, u - shift, m));
                    // 1e-14: a few ulps of the O(1) accelerations.
                    assert!(
                        (a - b).amax() < 1e-14,
                        "u={u} x={x:?} {m:?}: {a:?} vs {b:?}"
                    );
                }
            }
            let (e, f) = (with.slip_equilibria(u), t1.slip_equilibria(u - shift));
            assert_eq!(e.len(), f.len(), "u={u}");
            for (e, f) in e.iter().zip(&f) {
                // The same cubic-like root found from shifted data: 1e-12 relative.
                assert_relative_eq!(e.omega, f.omega, max_relative = 1e-12);
                assert_relative_eq!(e.alpha, f.alpha, max_relative = 1e-12);
            }
        }
    }

    fn all_modes() -> Vec<Mode> {
        let ms = [DiscMode::SlipPos, DiscMode::SlipNeg, DiscMode::Stick];
        let mut v = Vec::new();
        for upper in ms {
            for lower in ms {
                v.push(Mode::rig(upper, lower));
            }
        }
        v
    }

    /// A mode holds each disc's mode independently at every position its bit sets have, the
    /// last change of a disc wins, and the rig's constructor and accessors are the view of
    /// positions 0 and 1.
    #[test]
    fn a_mode_holds_each_discs_mode_independently() {
        let ms = [DiscMode::SlipPos, DiscMode::SlipNeg, DiscMode::Stick];
        assert_eq!(Mode::default(), Mode::SLIP);
        for (k, &a) in ms.iter().enumerate() {
            for &b in &ms {
                for far in [2, 31, 32, 63] {
                    let (d0, d1, dn) = (Disc::UPPER, Disc::LOWER, Disc::at(far));
                    let mut m = Mode::rig(b, a).with(dn, ms[(k + 1) % 3]);
                    assert_eq!((m.of(d0), m.of(d1)), (b, a));
                    assert_eq!((m.upper(), m.lower()), (b, a));
                    assert_eq!(m.of(dn), ms[(k + 1) % 3]);
                    assert_eq!(m.is_stuck(dn), ms[(k + 1) % 3] == DiscMode::Stick);
                    // Every disc's mode can be changed to every other; the rest stay.
                    for &c in &ms {
                        m.set(d1, c);
                        assert_eq!((m.of(d0), m.of(d1), m.of(dn)), (b, c, ms[(k + 1) % 3]));
                    }
                    m.set(d1, a);
                    m.set(dn, DiscMode::SlipPos);
                    assert_eq!(m, Mode::rig(b, a), "far {far}");
                }
            }
        }
        let chain = [
            DiscMode::Stick,
            DiscMode::SlipPos,
            DiscMode::SlipNeg,
            DiscMode::Stick,
        ];
        let m = Mode::from_discs(&chain);
        assert_eq!(Disc::all(4).map(|d| m.of(d)).collect::<Vec<_>>(), chain);
        assert_eq!(format!("{m:?}"), "Mode[Stick, SlipPos, SlipNeg, Stick]");
        assert_eq!(format!("{:?}", Mode::SLIP), "Mode[SlipPos, SlipPos]");
        assert_eq!(
            Mode::uniform(3, DiscMode::Stick),
            Mode::from_discs(&[DiscMode::Stick; 3])
        );
        assert_eq!(
            Mode::uniform(Mode::MAX_DISCS, DiscMode::SlipNeg).of(Disc::at(63)),
            DiscMode::SlipNeg
        );
    }

    /// A disc is its position: the rig's two are positions 0 and 1 with their words, a
    /// chain numbers its discs from 1, and the rig's state holds ω_u, ω_l at 1, 2.
    #[test]
    fn a_disc_is_its_position_with_the_rigs_words_as_a_view() {
        assert_eq!(Disc::BOTH, [Disc::at(0), Disc::at(1)]);
        assert!(Disc::UPPER < Disc::LOWER);
        assert_eq!(
            (Disc::UPPER.index(), Disc::LOWER.index()),
            (OMEGA_U, OMEGA_L)
        );
        assert_eq!(Disc::LOWER.number(), 2);
        assert_eq!(
            (Disc::UPPER.name_in(2), Disc::LOWER.name_in(2)),
            ("upper".into(), "lower".into())
        );
        assert_eq!(Disc::LOWER.name_in(3), "disc 2");
        assert_eq!(Disc::at(2).rig_word(), None);
        assert_eq!(
            Disc::all(3).map(Disc::position).collect::<Vec<_>>(),
            [0, 1, 2]
        );
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for m in models() {
            for mode in all_modes() {
                for x in [
                    State::new(1.3, 0.7, 2.1),
                    State::new(-0.4, -0.3, -1.6),
                    State::new(4.0, 3.0, 0.2),
                ] {
                    let u = 1.5;
                    let j = m.jacobian(&x, u, mode);
                    for k in 0..3 {
                        let d = 1e-6;
                        let mut xp = x;
                        let mut xm = x;
                        xp[k] += d;
                        xm[k] -= d;
                        let col = (m.rhs(&xp, u, mode) - m.rhs(&xm, u, mode)) / (2.0 * d);
                        for r in 0..3 {
                            // Central differences: O(d²) truncation + ε|f|/d rounding ≈ 4e-9
                            // (|f| ≲ 20); measured ≤ 2.1e-9 absolute, 1.0e-8 relative: 50×, 100×.
                            assert_relative_eq!(
                                j[(r, k)],
                                col[r],
                                epsilon = 1e-7,
                                max_relative = 1e-6
                            );
                        }
                    }
                    let du = (m.rhs(&x, u + 1e-6, mode) - m.rhs(&x, u - 1e-6, mode)) / 2e-6;
                    // f is linear in u: rounding ε|f|/d only; measured ≤ 1.8e-9, 1e-7 = 55×.
                    assert_relative_eq!(m.d_rhs_du(mode), du, epsilon = 1e-7);
                }
            }
        }
    }

    #[test]
    fn stick_holds_velocity_and_uses_equivalent_control() {
        let m = Model::table1();
        let x = State::new(1.0, 0.5, 0.0);
        let mode = Mode::rig(DiscMode::SlipPos, DiscMode::Stick);
        let f = m.rhs(&x, 1.5, mode);
        assert_eq!(f[OMEGA_L], 0.0);
        assert_eq!(f[ALPHA], 0.5);
        // Stick persists while |k_θ α| ≤ T_sl = 0.1642: α = 1 gives 0.0727 (inside).
        assert!(m.can_stick(Disc::LOWER, &x, 1.5));
        let x_out = State::new(3.0, 0.5, 0.0); // k_θ α = 0.218 > T_sl
        assert_eq!(
            m.stick_exit(Disc::LOWER, &x_out, 1.5),
            Some(DiscMode::SlipPos)
        );
    }

    #[test]
    fn power_balance_is_work_minus_dissipation() {
        for m in models() {
            let x = State::new(0.8, 1.1, 2.3);
            let u = 2.0;
            let mode = m.mode_at(&x, u);
            let p = &m.params;
            let expect = p.k_m * u * x[OMEGA_U]
                - m.friction(Disc::UPPER).curve(x[OMEGA_U]) * x[OMEGA_U]
                - m.friction(Disc::LOWER).curve(x[OMEGA_L]) * x[OMEGA_L];
            // Two sums of the same terms (≲ 10): measured ≤ 8.9e-16 (1 ulp of 5.7); 1e-13 ≈ 110×.
            assert_relative_eq!(m.power(&x, u, mode), expect, epsilon = 1e-13);
        }
    }
}
