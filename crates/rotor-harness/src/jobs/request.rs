//! What a user asks for, checked in one place for every front end.
//!
//! `rotor simulate`/`rotor steady` and the Python package's `simulate`/`steady`/`sweep` take
//! the same inputs (a solver name, u, x0, a horizon, tol or h). A [`Request`] turns them into
//! a solver and a validated [`Scene`], and refuses bad input with a [`FieldError`] that names
//! the input and the value. The reason is worded once, here and in [`rotor_analysis::solvers`]
//! ([`check_number`], [`solver_kind`]); each front end only spells the name its own way
//! ([`FieldError::as_flag`] for the command line, `name = value` for Python).

use rotor_model::seam::scene::{DEFAULT_STEP, DEFAULT_TOL};
use rotor_model::seam::{Accuracy, Input, Output, Scene, Stats};
use rotor_model::{FieldError, Num, state_names};

use rotor_analysis::solvers::{Knob, SolverKind};
pub use rotor_analysis::solvers::{check_number, solver_kind};
use rotor_analysis::steady::SteadyOptions;

/// A setting the chosen solver has no use for (the adaptive solvers take no step size,
/// Moreau–Jean no tolerance): said so, not silently dropped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ignored {
    /// `tol` or `h`.
    pub name: &'static str,
    /// The solver.
    pub solver: &'static str,
    /// What sets its accuracy instead.
    pub instead: &'static str,
    /// Whether the solver takes fixed steps (Moreau–Jean) rather than adaptive ones.
    pub fixed_step: bool,
}

impl Ignored {
    fn text(&self, spell: impl Fn(&str) -> String) -> String {
        let how = if self.fixed_step {
            "fixed steps"
        } else {
            "adaptive steps"
        };
        format!(
            "{} is ignored by {} ({how}: its accuracy is set by {})",
            spell(self.name),
            self.solver,
            spell(self.instead)
        )
    }

    /// `tol is ignored by moreau (fixed steps: its accuracy is set by h)`.
    pub fn message(&self) -> String {
        self.text(str::to_owned)
    }

    /// The command line's spelling: `--tol is ignored by moreau (... set by --h)`.
    pub fn as_flag(&self) -> String {
        self.text(|n| format!("--{n}"))
    }
}

/// Moreau–Jean steps whose step problem did not converge are answers to distrust: the
/// warning, if any, naming the step size as the front end spells it (`h`, `--h`).
pub fn inexact_warning(stats: &Stats, h: &str) -> Option<String> {
    (stats.inexact_steps > 0).then(|| {
        format!(
            "{} of {} steps fell back to an inexact iteration (the step is too large for the \
             friction law's slope); reduce {h}",
            stats.inexact_steps, stats.steps
        )
    })
}

/// One run as asked: the solver's name, the input voltage, the initial state and the
/// solver's accuracy setting (`tol` for the adaptive solvers, `h` for Moreau–Jean; `None`
/// takes [`Scene::default`]'s).
#[derive(Debug, Clone, PartialEq)]
pub struct Request<'a> {
    /// The solver's name as typed (`event`, `switch`, `moreau`); checked by
    /// [`Request::solver_kind`].
    pub solver: &'a str,
    /// Motor input voltage u \[V\] (unused with `input`).
    pub u: f64,
    /// A time-varying input u(t) instead of `u` (`--input FILE`, Python's `input=`).
    pub input: Option<Input>,
    /// Initial state, a list of the model's size: `[α, ω_u, ω_l]` for the rig (rad, rad/s,
    /// rad/s). Its size is checked against the model where the run starts.
    pub x0: Vec<f64>,
    /// Tolerance of the adaptive solvers (relative = absolute), if given.
    pub tol: Option<f64>,
    /// Step of Moreau–Jean \[s\], if given.
    pub h: Option<f64>,
}

impl Request<'_> {
    /// The solver asked for.
    pub fn solver_kind(&self) -> Result<SolverKind, FieldError> {
        solver_kind(self.solver)
    }

    /// The setting the solver ignores, if one was given.
    pub fn ignored(&self) -> Option<Ignored> {
        let kind = SolverKind::by_name(self.solver)?;
        let fixed = kind.is_fixed_step();
        let (given, instead) = if fixed {
            (self.tol.map(|_| "tol"), "h")
        } else {
            (self.h.map(|_| "h"), "tol")
        };
        given.map(|name| Ignored {
            name,
            solver: kind.name(),
            instead,
            fixed_step: fixed,
        })
    }

    /// The scene of a run by `kind` over `[0, t_end]` keeping `output`, at `kind`'s setting:
    /// u finite, x0 finite, tol in (0, 1), h in (0, t_end] (the default step shrinks to a
    /// horizon shorter than itself; an explicit h does not).
    pub fn scene(&self, kind: SolverKind, t_end: f64, output: Output) -> Result<Scene, FieldError> {
        // A table of one value is the constant input: the same run, bit for bit, as `u`.
        let (u, input) = match &self.input {
            None => (self.u, None),
            Some(i) => match i.constant() {
                Some(u) => (u, None),
                None => (i.at(0.0), Some(i.clone())),
            },
        };
        check_number("u", u, true, "must be a finite number")?;
        if let Some(k) = self.x0.iter().position(|v| !v.is_finite()) {
            let shown: Vec<String> = self.x0.iter().map(|&x| Num(x).to_string()).collect();
            return Err(FieldError::new(
                "x0",
                format!("{shown:?}"),
                format!(
                    "component {} ({}) is not finite",
                    k + 1,
                    state_names(self.x0.len())[k]
                ),
            ));
        }
        let tol = self.tol.unwrap_or(DEFAULT_TOL);
        check_number("tol", tol, tol > 0.0 && tol < 1.0, "must lie in (0, 1)")?;
        let h = self.h.unwrap_or(DEFAULT_STEP.min(t_end));
        check_number(
            "h",
            h,
            h > 0.0 && h <= t_end,
            &format!("must lie in (0, {}] s (the run's horizon)", Num(t_end)),
        )?;
        // The solver's own setting; the other one was checked all the same, and is ignored
        // (with the warning of [`Request::ignored`]).
        let accuracy = match kind.info().knob {
            Knob::Tolerance => Accuracy::Tol(tol),
            Knob::Step => Accuracy::Step(h),
        };
        Ok(Scene {
            u,
            input,
            x0: self.x0.clone(),
            t_end,
            accuracy,
            output,
            metrics_from: None,
        })
    }

    /// A simulation over `[0, t_end]` sampled every `dt`: the solver and the scene.
    pub fn simulation(&self, t_end: f64, dt: f64) -> Result<(SolverKind, Scene), FieldError> {
        check_number("t_end", t_end, t_end > 0.0, "must be positive and finite")?;
        check_number("dt", dt, dt > 0.0, "must be positive and finite")?;
        let kind = self.solver_kind()?;
        Ok((kind, self.scene(kind, t_end, Output::Grid { dt })?))
    }

    /// Refuses a time-varying input for `what` (a steady state, a sweep), which assumes a
    /// time-invariant system: the error names `input`.
    pub fn constant_input(&self, what: &str) -> Result<(), FieldError> {
        match &self.input {
            Some(i) if i.constant().is_none() => Err(FieldError::new(
                "input",
                i.to_string(),
                format!(
                    "{what} needs a constant input (a steady state of a time-invariant \
                     system): give u"
                ),
            )),
            _ => Ok(()),
        }
    }

    /// A steady-state computation ([`rotor_analysis::steady::steady`]): the solver, the scene and the options
    /// (the event-driven solver's refinement runs at `tol`).
    pub fn steady(&self) -> Result<(SolverKind, Scene, SteadyOptions), FieldError> {
        self.constant_input("steady")?;
        let mut opts = SteadyOptions::default();
        if let Some(tol) = self.tol {
            check_number("tol", tol, tol > 0.0 && tol < 1.0, "must lie in (0, 1)")?;
            opts.event.tol = tol;
        }
        let kind = self.solver_kind()?;
        Ok((
            kind,
            self.scene(kind, opts.settle.chunk, Output::Final)?,
            opts,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn req() -> Request<'static> {
        Request {
            solver: "event",
            u: 1.5,
            input: None,
            x0: vec![0.0; 3],
            tol: None,
            h: None,
        }
    }

    #[test]
    fn an_input_table_of_one_value_is_u_and_a_varying_one_is_refused_by_steady() {
        let flat = Request {
            input: Some(Input::new(&[[0.0, 2.0], [5.0, 2.0]]).unwrap()),
            ..req()
        };
        let (_, scene) = flat.simulation(10.0, 0.1).unwrap();
        assert_eq!((scene.u, scene.input), (2.0, None));
        assert!(flat.steady().is_ok());
        let step = Request {
            input: Some(Input::new(&[[5.0, 1.5], [5.0, 2.5]]).unwrap()),
            ..req()
        };
        let (_, scene) = step.simulation(10.0, 0.1).unwrap();
        assert!(scene.is_time_varying());
        assert_eq!(scene.u, 1.5, "u is the input at t = 0");
        let e = step.steady().unwrap_err();
        assert_eq!(e.field, "input");
        assert!(e.to_string().contains("constant input"), "{e}");
    }

    #[test]
    fn bad_inputs_name_the_input_and_the_value() {
        let e = Request {
            solver: "rk4",
            ..req()
        }
        .simulation(10.0, 0.01)
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "solver = \"rk4\": unknown solver (expected one of: event, switch, moreau)"
        );
        assert_eq!(
            e.as_flag(),
            "--solver \"rk4\": unknown solver (expected one of: event, switch, moreau)"
        );
        let e = req().simulation(0.0, 0.01).unwrap_err();
        assert_eq!(e.as_flag(), "--t-end 0: must be positive and finite");
        let e = Request {
            tol: Some(2.0),
            ..req()
        }
        .steady()
        .unwrap_err();
        assert_eq!(e.to_string(), "tol = 2: must lie in (0, 1)");
        let e = Request {
            h: Some(20.0),
            solver: "moreau",
            ..req()
        }
        .simulation(10.0, 0.01)
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "h = 20: must lie in (0, 10] s (the run's horizon)"
        );
        let e = Request {
            x0: vec![0.0, f64::NAN, 0.0],
            ..req()
        }
        .simulation(10.0, 0.01)
        .unwrap_err();
        assert_eq!(e.field, "x0");
        assert!(e.reason.contains("omega_u"), "{e}");
    }

    #[test]
    fn an_unused_setting_is_named_with_what_sets_the_accuracy() {
        let i = Request {
            solver: "moreau",
            tol: Some(1e-8),
            ..req()
        }
        .ignored()
        .unwrap();
        assert_eq!(
            i.as_flag(),
            "--tol is ignored by moreau (fixed steps: its accuracy is set by --h)"
        );
        assert_eq!(
            i.message(),
            "tol is ignored by moreau (fixed steps: its accuracy is set by h)"
        );
        let i = Request {
            h: Some(1e-3),
            ..req()
        }
        .ignored()
        .unwrap();
        assert_eq!(i.name, "h");
        assert!(req().ignored().is_none());
    }

    #[test]
    fn the_default_step_shrinks_to_a_short_horizon() {
        let (_, sc) = Request {
            solver: "moreau",
            ..req()
        }
        .simulation(1e-4, 1e-5)
        .unwrap();
        assert_eq!(sc.accuracy, Accuracy::Step(1e-4));
    }
}
