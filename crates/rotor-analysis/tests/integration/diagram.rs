//! The diagram for both parameter sets, checked against independent facts.

use rotor_analysis::bifurcation::continuation::Continuer;
use rotor_analysis::bifurcation::equilibria::{complex_pair, hopf_points, omega_reaching};
use rotor_analysis::bifurcation::periodic::{Shooter, eig2};
use rotor_analysis::bifurcation::{Diagram, DiagramOptions, diagram, start_point};
use rotor_event::{EventOptions, SteadyOptions, steady_state};
use rotor_model::seam::RigSteady;
use rotor_model::{Model, State};

use crate::common::{cont_options, model, points, st_diagram, t1_diagram};

fn shooter(m: &Model) -> Shooter<'_> {
    Shooter {
        model: m,
        tol: 1e-11,
    }
}

#[test]
fn hopf_points_are_roots_and_bracketed_by_simulation() {
    let m = model("table1");
    let hs = hopf_points(&m, omega_reaching(&m, 7.0).unwrap());
    assert_eq!(hs.len(), 2);
    for h in &hs {
        // Bisection to the last representable bracket in ω: Re λ is at rounding level of
        // the 3×3 eigenvalue computation (|J| ~ 10, ε·|J| ~ 2e-15; 1e-13 leaves a margin).
        assert!(h.re.abs() < 1e-13, "Re λ = {:e}", h.re);
        // The sign of Re λ differs 1e-9 rad/s on either side (slope |dRe/dω| ~ 0.1-1):
        // a root, not a touch.
        let w = h.equilibrium.omega;
        let l = complex_pair(&m, w - 1e-9).unwrap().re;
        let r = complex_pair(&m, w + 1e-9).unwrap().re;
        assert!(l * r < 0.0, "{l:e} {r:e}");
    }
    // Independently simulated facts (rotor-event; docs/model.md): stable equilibrium at 0.3 V,
    // slipping cycle at 0.5 V; equilibrium unstable at 2.5 V and stable at 4.5 V (bistable)
    // and 6.0 V. So the second (subcritical) Hopf point lies in (2.5, 4.5); what lies in
    // (4.5, 6.0) is the fold E (checked in `table1_diagram_structure`).
    assert!(0.3 < hs[0].equilibrium.u && hs[0].equilibrium.u < 0.5);
    assert!(2.5 < hs[1].equilibrium.u && hs[1].equilibrium.u < 4.5);
    assert!(!hs[0].stabilizing && hs[1].stabilizing);
}

#[test]
fn stick_slip_multipliers_agree_at_two_steps_and_with_the_section_map() {
    let m = model("table1");
    let sh = shooter(&m);
    let u = 1.5;
    let (z0, c) = start_point(&sh, u).unwrap();
    let z = sh.section_fixed_point(u, c, z0, 1e-10).unwrap();
    let exit = sh.next_exit(u, State::new(z[0], z[1], c)).unwrap();
    let w = sh.stick_exit_fixed_point(u, exit.x[1], 1e-11).unwrap();
    let l6 = sh.stick_exit_multiplier(u, w, 1e-6).unwrap();
    let l5 = sh.stick_exit_multiplier(u, w, 1e-5).unwrap();
    // Central differences: truncation O(h²) is negligible; the noise is the integration
    // error difference over 2h. Were the two starts to take different steps it could reach
    // tol / 2h = 1e-11 / 2e-6 = 5e-6; nearby starts take the same steps, and the measured
    // differences here are ≤ 1.5e-9 (this one 6.4e-10, the section map's below 1.5e-9).
    // 1e-6 absolute: ~700x the measurement, below the different-steps bound.
    assert!((l6 - l5).abs() < 1e-6, "{l6:e} vs {l5:e}");
    assert!(l6.abs() < 1.0, "stable at 1.5 V (simulated fact)");
    // The 2-D section map of a stick-slip cycle has rank 1: eigenvalues 0 and λ (the same
    // nontrivial multiplier from a different map, section and differencing): same 1e-6.
    let j = sh.section_jacobian(u, c, z, 1e-6).unwrap();
    let mut e = eig2(&j).map(|x| x.re);
    e.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
    assert!(e[0].abs() < 1e-6, "{e:?}");
    assert!((e[1] - l6).abs() < 1e-6, "{e:?} vs {l6:e}");
}

#[test]
fn slipping_cycle_multipliers_agree_at_two_steps() {
    let m = model("table1");
    let sh = shooter(&m);
    let u = 0.5; // small slipping cycle (simulated fact)
    let (z0, c) = start_point(&sh, u).unwrap();
    let z = sh.section_fixed_point(u, c, z0, 1e-10).unwrap();
    assert!(!sh.section_map(u, c, z).unwrap().stuck);
    let e6 = eig2(&sh.section_jacobian(u, c, z, 1e-6).unwrap());
    let e5 = eig2(&sh.section_jacobian(u, c, z, 1e-5).unwrap());
    for k in 0..2 {
        // Same origin and gate as the stick-slip cycle's (measured ≤ 7.7e-10): 1e-6.
        assert!((e6[k] - e5[k]).norm() < 1e-6, "{e6:?} vs {e5:?}");
    }
    assert!(
        e6.iter().all(|l| l.norm() < 1.0),
        "the 0.5 V cycle is stable (simulated)"
    );
}

#[test]
fn branch_period_matches_steady_state_refinement() {
    // rotor_event::steady_state reaches the 1.5 V cycle by a settling run and a secant on the
    // stick-exit map: an independent path to the same orbit.
    let m = model("table1");
    let st = steady_state(
        &m,
        1.5,
        State::zeros(),
        &SteadyOptions::default(),
        &EventOptions::default(),
    )
    .unwrap()
    .state;
    let RigSteady::LimitCycle {
        period,
        omega_l_max,
        ..
    } = st
    else {
        panic!("{st:?}")
    };
    let sh = shooter(&m);
    let (z0, c) = start_point(&sh, 1.5).unwrap();
    let z = sh.section_fixed_point(1.5, c, z0, 1e-10).unwrap();
    let cont = Continuer {
        sh,
        opts: cont_options(0.035, 1e-9, 10),
    };
    let info = cont.describe(1.5, c, z).unwrap();
    // Both fixed points to ~1e-10; periods at tolerance 1e-11/1e-12. Measured: period
    // 1.8e-11 s, max ω_l 8.3e-11 rad/s; 1e-9 and 5e-9 (55×, 60×).
    assert!(
        (info.period - period).abs() < 1e-9,
        "{} vs {period}",
        info.period
    );
    assert!(
        (info.omega_l_max - omega_l_max).abs() < 5e-9,
        "{} vs {omega_l_max}",
        info.omega_l_max
    );
    assert!(info.stick_slip && info.stable);
}

#[test]
fn table1_diagram_structure() {
    let d = t1_diagram();
    let hopf = points(d, "hopf");
    let graz = points(d, "grazing");
    let fold = points(d, "fold");
    assert_eq!(hopf.len(), 2);
    assert_eq!(graz.len(), 2);
    assert_eq!(fold.len(), 1);
    // Order along u: Hopf (supercritical) < grazing < grazing < fold E; subcritical Hopf < E.
    assert!(hopf[0].u < graz[0].u && graz[0].u < graz[1].u && graz[1].u < fold[0].u);
    assert!(hopf[1].u < fold[0].u);
    assert!(hopf[0].detail.starts_with("supercritical"));
    assert!(hopf[1].detail.starts_with("subcritical"));
    // Simulated facts: 4.5 V lies in the bistable window [Hopf₂, E] and has stick-slip;
    // 6.0 V is above E (equilibrium only); 0.5 V slipping (below the first grazing).
    assert!(hopf[1].u < 4.5 && 4.5 < fold[0].u && fold[0].u < 6.0);
    assert!(4.5 < graz[1].u && 0.5 < graz[0].u);
    assert!(d.periodic.len() >= 200);
    // Near each Hopf point the cycles' period tends to 2π/β (β the crossing frequency): the
    // branch ends there have ω_l amplitudes ≤ 0.3 rad/s, so the O(amplitude²) period shift is
    // far below 1e-3 relative (measured 1.5e-4, 1.5e-8). The branch stops where its amplitude
    // falls to amp_stop = 0.02 rad/s, next to the Hopf point: measured 2.4e-4 and 1.3e-6 V
    // away; 0.02 V ≈ 80×.
    for h in &hopf {
        let t_h = h.period.unwrap();
        let p = d
            .periodic
            .iter()
            .min_by(|a, b| (a.u - h.u).abs().total_cmp(&(b.u - h.u).abs()))
            .unwrap();
        assert!(
            (p.u - h.u).abs() < 0.02 && ((p.period - t_h) / t_h).abs() < 1e-3,
            "{p:?} vs {t_h}"
        );
    }
    // Stable cycles at 1.5, 2.5 and 4.5 V: the branch point nearest is stable and stick-slip.
    // Branch steps are ≤ 7/200 = 0.035 in arclength, so the nearest node is within 0.0175 V
    // (measured ≤ 5.9e-3 V): 0.02 V.
    for u in [1.5, 2.5, 4.5] {
        let p = d
            .periodic
            .iter()
            .filter(|p| p.stable)
            .min_by(|a, b| (a.u - u).abs().total_cmp(&(b.u - u).abs()))
            .unwrap();
        assert!((p.u - u).abs() < 0.02 && p.stick_slip, "{u}: {p:?}");
    }
    // The equilibrium table: unstable between the Hopf points, stable outside.
    for e in d.equilibria.iter().filter(|e| e.kind.as_str() == "slip") {
        let inside = hopf[0].u < e.u && e.u < hopf[1].u;
        assert_eq!(e.stable, !inside, "{e:?}");
    }
    let json = d.to_json().unwrap();
    assert!(json.contains("\"equilibria\"") && json.contains("\"multipliers\""));
    let mut csv = Vec::new();
    d.write_csv(&mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    assert_eq!(
        csv.lines().filter(|l| l.starts_with("periodic,")).count(),
        d.periodic.len()
    );
}

/// Ranges up to 140 times wider than the source's find the same special points as [0, 7] V:
/// the branch step does not grow with the range (a 1.5 V step over [0, 300] V once walked past
/// the grazing point at 0.6 V).
#[test]
fn the_widest_range_finds_the_same_special_points() {
    let m = model("table1");
    let d = t1_diagram();
    let kinds = |d: &Diagram| {
        let mut v: Vec<(&str, f64)> = d.points.iter().map(|p| (p.kind.as_str(), p.u)).collect();
        v.sort_by(|a, b| a.0.cmp(b.0).then(a.1.total_cmp(&b.1)));
        v
    };
    // 300 V is the range that lost the grazing point; U_MAX the widest admitted.
    for u_max in [300.0, rotor_analysis::bifurcation::U_MAX] {
        let wide = diagram(
            &m,
            &DiagramOptions {
                u_max,
                ..Default::default()
            },
        )
        .unwrap();
        let (a, b) = (kinds(d), kinds(&wide));
        assert_eq!(a.len(), b.len(), "{u_max} V: {a:?} vs {b:?}");
        for ((ka, ua), (kb, ub)) in a.iter().zip(&b) {
            // Each point is located to point_tol-level accuracy independently of the branch's
            // sampling: measured 0 here; another sampling (the [4, 6] V window in output.rs)
            // moves the fold by 1.7e-11 V. 1e-9 V (below the diagram's promised 1e-8).
            assert!(ka == kb && (ua - ub).abs() < 1e-9, "{ka} {ua} vs {kb} {ub}");
        }
    }
}

#[test]
fn stribeck_diagram_structure() {
    let d = st_diagram();
    let hopf = points(d, "hopf");
    assert_eq!(hopf.len(), 2);
    // Both Hopf points subcritical with this set (small unstable cycles next to each).
    assert!(
        hopf.iter().all(|h| h.detail.starts_with("subcritical")),
        "{hopf:?}"
    );
    let folds = points(d, "fold");
    // Two discontinuous folds and no smooth one. D: just below Hopf point 1, the unstable
    // slipping cycles born there graze and turn into the stable stick-slip branch. E: the
    // stable stick-slip branch meets the unstable slipping branch of Hopf C at a grazing orbit:
    // above Hopf C, with 2.5 V inside the window and 4.5 V above it (the source's narrative:
    // coexistence at 2.5, equilibrium only at 4.5).
    assert_eq!(folds.len(), 2, "{folds:?}");
    assert!(folds.iter().all(|f| f.discontinuous == Some(true)));
    let (dl, e) = (folds[0], folds[1]);
    assert!(dl.u < hopf[0].u && hopf[0].u - dl.u < 1e-3, "{dl:?}");
    assert!(hopf[1].u < 2.5 && 2.5 < e.u && e.u < 4.5);
    let st = d
        .periodic
        .iter()
        .filter(|p| p.stable)
        .min_by(|a, b| (a.u - 1.5).abs().total_cmp(&(b.u - 1.5).abs()))
        .unwrap();
    assert!(st.stick_slip && (st.u - 1.5).abs() < 0.05);
    // Both discs stuck at small u (the equilibrium set).
    assert!(
        d.equilibria
            .iter()
            .any(|e| e.kind.as_str() == "stuck" && e.u < 0.1)
    );
}

#[test]
fn hysteresis_of_a_brute_force_sweep_matches_the_bistable_window() {
    use rotor_model::seam::{Output, Scene, Solver};
    let d = t1_diagram();
    let hopf = points(d, "hopf")[1].u;
    let fold = points(d, "fold")[0].u;
    let m = model("table1");
    let solver = rotor_event::EventSolver::default();
    // Two successive runs of 300 s (≈70 periods each), amplitude of ω_l over the last 100 s
    // of each (a1, a2). The state is on (or leaving toward) a cycle if a2 > 1 rad/s (the
    // stable cycles here have amplitudes ≥ 8 rad/s) or if the oscillation grows (a2 > a1:
    // an unstable equilibrium, Re λ > 0); it is on (or settling to) the equilibrium
    // otherwise. The growth test needs no threshold on the slow transients near the Hopf point.
    let amp = |s: &Option<RigSteady>| match s {
        Some(RigSteady::LimitCycle {
            omega_l_max,
            omega_l_min,
            ..
        }) => omega_l_max - omega_l_min,
        _ => 0.0,
    };
    let run = |u: f64, x0: State| {
        let scene = Scene {
            u,
            x0: x0.as_slice().to_vec(),
            t_end: 300.0,
            output: Output::Final,
            metrics_from: Some(200.0),
            ..Scene::with_tol(1e-9)
        };
        let t1 = solver.simulate(&m, &scene).unwrap();
        let t2 = solver
            .simulate(
                &m,
                &Scene {
                    x0: t1.x_final.clone(),
                    ..scene
                },
            )
            .unwrap();
        let (a1, a2) = (amp(&t1.rig_metrics()), amp(&t2.rig_metrics()));
        (a2 > 1.0 || a2 > a1, t2.final_state().unwrap())
    };
    let us: Vec<f64> = (0..20).map(|k| 4.025 + 0.05 * k as f64).collect();
    // Up: from the 4.025 V cycle (reached from rest), each run from the previous final state.
    let mut x = State::zeros();
    let mut up_jump = None;
    for &u in &us {
        let (cyc, xf) = run(u, x);
        x = xf;
        if !cyc {
            up_jump = Some(u);
            break;
        }
    }
    // Down: from the 4.975 V equilibrium; each run starts from the previous final state plus
    // 1e-3 rad/s on ω_l (the set-up's noise; far inside the unstable cycle, whose amplitude
    // is > 1 rad/s at 4.225 V and more above), so a loss of stability shows as growth.
    let e = m.slip_equilibria(4.975)[0];
    let mut x = e.state();
    let mut down_jump = None;
    for &u in us.iter().rev() {
        let (cyc, xf) = run(u, x + State::new(0.0, 0.0, 1e-3));
        x = xf;
        if cyc {
            down_jump = Some(u);
            break;
        }
    }
    let (up, down) = (up_jump.unwrap(), down_jump.unwrap());
    // Within the sweep's resolution (0.05 V): the cycle is lost in the step past E, the
    // equilibrium in the step past the subcritical Hopf point.
    assert!(
        up - 0.05 < fold && fold < up,
        "up jump at {up}, fold E at {fold}"
    );
    assert!(
        down < hopf && hopf < down + 0.05,
        "down jump at {down}, Hopf at {hopf}"
    );
}

/// Grazing of the upper disc. On the Stribeck set the upper disc has static
/// friction (T_su = 0.38 N m), so a cycle reaching ω_u = 0 would be a special point of its own.
/// No cycle of the diagram comes near it: the smallest ω_u over every periodic branch point is
/// 0.0577 rad/s, on the slipping cycles next to D (0.18378 V, where the cycles' mean ω_u is
/// smallest), against an integration error of ~1e-9 rad/s. Table 1 (T_su = 0: a purely
/// viscous upper disc, whose ω_u = 0 is no sliding surface) stays above 0.59 rad/s.
#[test]
fn no_cycle_of_the_diagrams_touches_omega_u_zero() {
    for (name, d, floor) in [
        // Floors: the measured minima (0.0577, 0.5954 rad/s) rounded down to one digit.
        ("stribeck", st_diagram(), 0.05),
        ("table1", t1_diagram(), 0.5),
    ] {
        let low = d
            .periodic
            .iter()
            .min_by(|a, b| a.omega_u_min.total_cmp(&b.omega_u_min))
            .unwrap();
        assert!(
            low.omega_u_min > floor,
            "{name}: min omega_u {} at u = {}",
            low.omega_u_min,
            low.u
        );
        // The minimum is the velocity's minimum over the cycle, not a sample: never above the
        // upper disc's velocity at the cycle's section point.
        for r in &d.periodic {
            assert!(r.omega_u_min <= r.section_state[1] + 1e-9, "{name} {r:?}");
        }
    }
}
