//! The grade of `rotor check`, both ways: wrong traces that must fail (each quantity alone,
//! mid-run, events, phase), honest ones that must pass, the file's precision, and the levels
//! against the reference's own error.

use std::path::{Path, PathBuf};

use rotor_analysis::solvers::{SolverKind, load_scenario, run::scene_for};
use rotor_harness::grade::check::{
    CheckError, CheckReport, LOOSE_DIGITS, Level, STRICT_DIGITS, check, reference_error,
    state_scales, stuck_threshold,
};
use rotor_harness::grade::reference::{self, REQUIRED_DIGITS, Reference};
use rotor_harness::grade::trace::{EventsFile, Trace, parse_trace, read_events, read_trace};
use rotor_model::scenario::Scenario;
use rotor_model::seam::{Event, RigSteady, Scene, Solver};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

fn scenario(name: &str) -> (Scenario, Reference) {
    let sc = load_scenario(&fixtures().join(format!("scenarios/{name}.toml"))).unwrap();
    let r = reference::read(&fixtures().join("reference"), name).unwrap();
    (sc, r)
}

fn all_scenarios() -> Vec<(Scenario, Reference)> {
    Scenario::list_dir(&fixtures().join("scenarios"))
        .unwrap()
        .iter()
        .map(|f| {
            let sc = load_scenario(f).unwrap();
            let r = reference::read(&fixtures().join("reference"), &sc.name).unwrap();
            (sc, r)
        })
        .collect()
}

/// The reference's own files as a client would hand them in.
fn own(r: &Reference) -> (Trace, EventsFile) {
    (
        Trace::of_samples("ref.csv", r.samples.clone()),
        EventsFile::of_run("ref.events.csv", &r.events),
    )
}

fn grade(sc: &Scenario, r: &Reference, t: &Trace, e: Option<&EventsFile>, l: Level) -> CheckReport {
    check(sc, r, t, e, l).unwrap_or_else(|err| panic!("{err}"))
}

fn failing(rep: &CheckReport) -> Vec<String> {
    rep.failing().iter().map(|s| s.to_string()).collect()
}

const LEVELS: [Level; 2] = [Level::Strict, Level::Loose];

/// The wrong traces a solver developer tried on the old grade, every one of which it passed:
/// each fails at strict, and the gross ones at loose too.
#[test]
fn wrong_traces_fail() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let (base, ev) = own(&r);
    let idx = |t: f64| (t / sc.compare.dt).round() as usize;
    // (name, trace, events, fails at loose too)
    let mut cases: Vec<(&str, Trace, EventsFile, bool)> = Vec::new();
    let mut t = base.clone();
    for s in &mut t.samples[idx(30.0)..=idx(90.0)] {
        s.x[2] += 0.5;
    }
    cases.push(("omega_l + 0.5 over 30-90 s", t, ev.clone(), true));
    let mut t = base.clone();
    for s in &mut t.samples[idx(150.0)..=idx(160.0)] {
        s.x[2] += 1e-4;
    }
    cases.push(("omega_l + 1e-4 over 150-160 s", t, ev.clone(), false));
    let mut t = base.clone();
    for s in &mut t.samples[idx(120.0)..=idx(121.0)] {
        s.x[0] += 1e-4;
    }
    cases.push(("alpha + 1e-4 over 120-121 s", t, ev.clone(), false));
    let mut t = base.clone();
    t.samples[idx(70.0)].x[1] += 1e-5;
    cases.push(("omega_u + 1e-5 at one sample", t, ev.clone(), false));
    let mut e = ev.clone();
    for x in e.events.iter_mut().filter(|x| x.t > 100.0) {
        x.t += 0.01;
    }
    cases.push(("every event after 100 s 0.01 s late", base.clone(), e, true));
    // The steady cycle taken 0.02 s (two samples) ahead from 100 s on, its events with it.
    let mut t = base.clone();
    let k0 = idx(100.0);
    for k in k0..t.samples.len() {
        t.samples[k].x = r.samples[(k + 2).min(r.samples.len() - 1)].x;
    }
    let mut e = ev.clone();
    for x in e.events.iter_mut().filter(|x| x.t > 100.0) {
        x.t -= 0.02;
    }
    cases.push(("the cycle 0.02 s ahead from 100 s on", t, e, true));
    // One stick phase lost: the disc creeps at 1e-6 rad/s instead of sticking.
    let mut t = base.clone();
    let stuck: Vec<usize> = (idx(140.0)..idx(150.0))
        .filter(|&k| t.samples[k].x[2] == 0.0)
        .collect();
    assert!(stuck.len() > 10);
    for k in stuck {
        t.samples[k].x[2] = 1e-6;
    }
    cases.push(("a stick phase crept through", t, ev.clone(), false));
    // An event missing, an extra one, one of the wrong kind.
    let mut e = ev.clone();
    e.events.remove(20);
    e.lines.pop();
    cases.push(("an event missing", base.clone(), e, true));
    let mut e = ev.clone();
    let extra = Event {
        t: 150.005,
        ..e.events[0].clone()
    };
    let at = e.events.partition_point(|x| x.t < extra.t);
    e.events.insert(at, extra);
    e.lines.push(e.lines.len() as u64 + 2);
    cases.push(("an extra event", base.clone(), e, true));
    // The run at u = 1.52 V: the right kind of cycle, at the wrong input.
    let wrong_u = Scenario {
        u: 1.52,
        ..sc.clone()
    };
    let tr = SolverKind::EVENT
        .solver()
        .simulate(&sc.model, &scene_for(SolverKind::EVENT, &wrong_u))
        .unwrap();
    let t = Trace::of_run("u1.52.csv", &tr.samples);
    let e = EventsFile::of_run("u1.52.events.csv", &tr.events);
    cases.push(("the run at u = 1.52 V", t, e, true));

    let mut wrong = Vec::new();
    for (name, t, e, gross) in &cases {
        for level in LEVELS {
            let rep = grade(&sc, &r, t, Some(e), level);
            let must_fail = level == Level::Strict || *gross;
            if must_fail && rep.passed {
                wrong.push(format!(
                    "{name} passed at {}:\n{}",
                    level.name(),
                    rep.table()
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    // And the reference itself passes both, with all its events.
    for level in LEVELS {
        let rep = grade(&sc, &r, &base, Some(&ev), level);
        assert!(rep.passed && rep.not_graded.is_empty(), "{}", rep.table());
    }
}

/// A correct trace without events is graded on everything else and says so on its verdict
/// line: never a plain PASSED.
#[test]
fn a_trace_without_events_says_events_not_graded() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let (t, _) = own(&r);
    let rep = grade(&sc, &r, &t, None, Level::Strict);
    assert!(rep.passed);
    assert_eq!(rep.not_graded, ["events"]);
    let v = rep.verdict();
    assert!(
        v.contains("PASSED") && v.contains("events not graded"),
        "{v}"
    );
    assert!(!rep.quantities.iter().any(|q| q.name == "events"));
    // The stick intervals are graded all the same.
    assert!(rep.quantities.iter().any(|q| q.name == "stick_lower"));
}

/// Each quantity alone, moved by 2× its tolerance, fails; by 0.5×, passes; at both levels.
/// The samples are moved in the transient (before `steady_from`) at a time where the lower
/// disc slips fast, so that no other quantity moves: each perturbation changes exactly the
/// quantity it targets.
#[test]
fn each_quantity_alone_fails_at_twice_its_tolerance_and_passes_at_half() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let (base, ev) = own(&r);
    let k = r
        .samples
        .iter()
        .position(|s| s.t > 50.0 && s.x[2] > 3.0)
        .unwrap();
    for level in LEVELS {
        let reference = grade(&sc, &r, &base, Some(&ev), level);
        let tol = |name: &str| {
            reference
                .quantities
                .iter()
                .find(|q| q.name == name)
                .unwrap()
                .tolerance
        };
        let mut checked = Vec::new();
        for factor in [2.0, 0.5] {
            for (i, name) in ["alpha", "omega_u", "omega_l"].into_iter().enumerate() {
                let mut t = base.clone();
                t.samples[k].x[i] += factor * tol(name);
                let rep = grade(&sc, &r, &t, Some(&ev), level);
                let expect: Vec<String> = if factor > 1.0 {
                    vec![name.into()]
                } else {
                    vec![]
                };
                assert_eq!(
                    failing(&rep),
                    expect,
                    "{name} ×{factor} at {}",
                    level.name()
                );
                // Alone: every other quantity is exactly as for the reference.
                for (q, q0) in rep.quantities.iter().zip(&reference.quantities) {
                    if q.name != name {
                        assert_eq!(q.difference, q0.difference, "{} moved", q.name);
                    }
                }
                checked.push(name);
            }
            // One event (a stick onset in the transient) moved.
            let mut e = ev.clone();
            let j = e.events.iter().position(|x| x.t > 40.0).unwrap();
            e.events[j].t += factor * tol("events");
            let rep = grade(&sc, &r, &base, Some(&e), level);
            let expect: Vec<String> = if factor > 1.0 {
                vec!["events".into()]
            } else {
                vec![]
            };
            assert_eq!(
                failing(&rep),
                expect,
                "events ×{factor} at {}",
                level.name()
            );
            // A steady sample moved off the orbit, normally to it (a move along the orbit is
            // a phase, which the orbit's shape does not see): `orbit` fails at 2×, and
            // nothing at 0.5×.
            let ks = r
                .samples
                .iter()
                .position(|s| s.t > 150.0 && s.x[2] > 3.0)
                .unwrap();
            let sc_ = [0, 1, 2].map(|i| {
                r.samples
                    .iter()
                    .map(|s| s.x[i].abs())
                    .fold(rotor_harness::grade::check::FLOOR, f64::max)
            });
            let tangent: Vec<f64> = (0..3)
                .map(|i| (r.samples[ks + 1].x[i] - r.samples[ks - 1].x[i]) / sc_[i])
                .collect();
            let tn = tangent.iter().map(|x| x * x).sum::<f64>().sqrt();
            let tau: Vec<f64> = tangent.iter().map(|x| x / tn).collect();
            // e_α minus its tangential part, normalised.
            let mut n: Vec<f64> = (0..3)
                .map(|i| f64::from(i == 0) - tau[0] * tau[i])
                .collect();
            let nn = n.iter().map(|x| x * x).sum::<f64>().sqrt();
            n.iter_mut().for_each(|x| *x /= nn);
            let mut t = base.clone();
            for i in 0..3 {
                t.samples[ks].x[i] += factor * tol("orbit") * n[i] * sc_[i];
            }
            let rep = grade(&sc, &r, &t, Some(&ev), level);
            let f = failing(&rep);
            if factor > 1.0 {
                assert!(f.contains(&"orbit".to_string()), "{f:?}");
            } else {
                assert!(f.is_empty(), "{f:?} at {}:\n{}", level.name(), rep.table());
            }
        }
        assert_eq!(checked.len(), 6);
    }
}

/// The stick intervals visible on the grid are graded against the reference's exact onsets
/// and exits: one more stuck sample at an onset moves the trace's onset a step early, which
/// fails exactly when the reference's onset lies farther than the tolerance outside that
/// step (unless the reference's own sample there is within the level's stuck threshold: then
/// the reference shows its onset in that step too, and nothing is charged); a stick phase
/// split in two (a sample above the threshold) is an extra interval.
#[test]
fn stick_intervals_are_graded_from_the_grid() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let (base, ev) = own(&r);
    let s_l = state_scales(&r.samples)[2];
    let ons: Vec<f64> = r
        .events
        .iter()
        .filter(|e| e.kind == rotor_model::seam::EventKind::StickStart(rotor_model::Disc::LOWER))
        .map(|e| e.t)
        .collect();
    for level in LEVELS {
        let stuck = stuck_threshold(s_l, level);
        let mut charged = 0;
        for &on in ons.iter().take(6) {
            let a = r.samples.partition_point(|s| s.t < on); // first stuck sample
            assert_eq!(r.samples[a].x[2], 0.0);
            let mut t = base.clone();
            t.samples[a - 1].x[2] = 0.0;
            // The trace now shows its onset in (t[a-2], t[a-1]]: `on` lies past it by:
            let outside = if r.samples[a - 1].x[2].abs() <= stuck {
                0.0
            } else {
                charged += 1;
                on - r.samples[a - 1].t
            };
            let rep = grade(&sc, &r, &t, Some(&ev), level);
            let q = rep
                .quantities
                .iter()
                .find(|q| q.name == "stick_lower")
                .unwrap();
            assert!(
                (q.difference - outside).abs() < 1e-12,
                "{} vs {outside}",
                q.difference
            );
            assert_eq!(q.passed, outside <= q.tolerance);
        }
        // Most onsets are charged (measured: 6 of 6 at strict, 5 of 6 at loose, where the
        // reference's last slipping sample is within 6.3e-3 rad/s of 0 at one of them).
        assert!(charged >= 3, "{} of 6 at {}", charged, level.name());
        // A stuck sample that slips in mid-stick: two intervals where the reference has one.
        let mid = r.samples.partition_point(|s| s.t < ons[3]) + 20;
        let mut t = base.clone();
        t.samples[mid].x[2] = 2.0 * stuck;
        let rep = grade(&sc, &r, &t, Some(&ev), level);
        let q = rep
            .quantities
            .iter()
            .find(|q| q.name == "stick_lower")
            .unwrap();
        assert!(!q.passed && q.note.as_ref().unwrap().contains("not in the reference"));
    }
}

/// Events are checked before they are graded: out of order or out of the run is unusable
/// input naming the line; an unmatched one is named in the grade.
#[test]
fn unsorted_out_of_range_and_unmatched_events() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let (t, ev) = own(&r);
    let mut e = ev.clone();
    e.events.swap(3, 4);
    let m = check(&sc, &r, &t, Some(&e), Level::Loose)
        .unwrap_err()
        .to_string();
    assert!(
        m.contains("line 6") && m.contains("before the previous event"),
        "{m}"
    );
    let mut e = ev.clone();
    let last = e.events.len() - 1;
    e.events[last].t = sc.t_end + 1.0;
    let m = check(&sc, &r, &t, Some(&e), Level::Loose)
        .unwrap_err()
        .to_string();
    assert!(m.contains("outside [0, 200]"), "{m}");
    let mut e = ev.clone();
    e.events[7].kind = rotor_model::seam::EventKind::Reversal(rotor_model::Disc::LOWER);
    let rep = grade(&sc, &r, &t, Some(&e), Level::Loose);
    let q = rep.quantities.iter().find(|q| q.name == "events").unwrap();
    let note = q.note.as_deref().unwrap();
    assert!(
        !q.passed && note.contains("1 missing") && note.contains("lower reversal"),
        "{note}"
    );
}

/// The file's precision is not the solver's error: a correct trace written with printf's
/// `%g` (6 significant digits) passes the loose level, and is refused (not failed) at strict,
/// naming its precision.
#[test]
fn a_six_digit_trace_is_graded_where_six_digits_suffice_and_refused_where_not() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let g = |x: f64| {
        // printf("%g"): 6 significant digits, trailing zeros dropped.
        let s = format!("{x:.5e}");
        let v: f64 = s.parse().unwrap();
        format!("{v}")
    };
    let mut text = String::from("t,alpha,omega_u,omega_l\n");
    for s in &r.samples {
        text.push_str(&format!(
            "{},{},{},{}\n",
            g(s.t),
            g(s.x[0]),
            g(s.x[1]),
            g(s.x[2])
        ));
    }
    let t = parse_trace(text.as_bytes(), Path::new("g.csv")).unwrap();
    assert_eq!(t.digits, 6);
    let (_, ev) = own(&r);
    let rep = grade(&sc, &r, &t, Some(&ev), Level::Loose);
    assert!(rep.passed, "{}", rep.table());
    let e = check(&sc, &r, &t, Some(&ev), Level::Strict).unwrap_err();
    assert!(
        matches!(
            e,
            CheckError::Precision {
                digits: 6,
                needed: 8,
                ..
            }
        ),
        "{e}"
    );
    let m = e.to_string();
    assert!(
        m.contains("g.csv") && m.contains("6 significant digits") && m.contains("%.17g"),
        "{m}"
    );
    // --digits 5 needs 6: graded.
    assert!(check(&sc, &r, &t, Some(&ev), Level::Digits(5)).is_ok());
}

/// Strict sits a full digit inside what every reference can grade: every graded quantity of
/// every scenario has a stated error (`steady_kind`, 0 or ∞, has none) that verifies it to at
/// least [`REQUIRED_DIGITS`] = strict + 2 digits (a level is graded at most to one digit
/// below the reference, so strict could be graded even if a reference lost most of a digit).
/// Measured: the weakest is st-u2.5-rest's α and ω_l, 9.2 digits
/// (`cargo run --release -p rotor-harness --example grade_digits`, "reference verified"). And
/// `--digits` beyond what the reference allows is refused, naming the quantity.
#[test]
fn strict_is_a_full_digit_inside_every_reference() {
    assert_eq!(REQUIRED_DIGITS, f64::from(STRICT_DIGITS) + 2.0);
    let mut worst: Option<(f64, String)> = None;
    let mut weakest: Option<String> = None;
    for (sc, r) in all_scenarios() {
        let (t, ev) = own(&r);
        let rep = grade(&sc, &r, &t, Some(&ev), Level::Loose);
        for q in rep.quantities.iter().filter(|q| q.name != "steady_kind") {
            let err = reference_error(&r, &q.name)
                .unwrap_or_else(|| panic!("{} {}: no stated error", sc.name, q.name));
            let d = -(err / q.scale).log10();
            if worst.as_ref().is_none_or(|w| d < w.0) {
                worst = Some((d, format!("{} {}", sc.name, q.name)));
                weakest = Some(sc.name.clone());
            }
        }
        assert!(
            rep.quantities.iter().any(|q| q.name == "orbit")
                == matches!(r.steady(), Some(RigSteady::LimitCycle { .. })),
            "{}: orbit graded for a cycle only",
            sc.name
        );
    }
    let (d, at) = worst.unwrap();
    assert!(
        d >= REQUIRED_DIGITS && LOOSE_DIGITS < STRICT_DIGITS,
        "strict asks {STRICT_DIGITS} digits; the reference is verified to {d:.2} at {at}, \
         fewer than {REQUIRED_DIGITS}"
    );
    // The weakest reference graded one digit past what its error allows is refused.
    let (sc, r) = scenario(&weakest.unwrap());
    let (t, ev) = own(&r);
    let asked = d.floor() as u32 + 1;
    let e = check(&sc, &r, &t, Some(&ev), Level::Digits(asked)).unwrap_err();
    assert!(
        matches!(e, CheckError::BeyondReference { asked: a, .. } if a == asked),
        "{e}"
    );
}

/// The orbit is phase-free: the reference's steady cycle taken 0.02 s (two samples) ahead from
/// `steady_from` on fails at equal times (ω_l) but not in `orbit`, even at the most digits the
/// reference allows there (8; measured 1.9e-10, 9.7 digits: the dense orbit's chords, which
/// the reference's own offsets no longer cancel at shifted times); moved by 2e-6 of the scale
/// along ω_l at every moving steady sample (across the orbit where ω_l turns) it fails `orbit`
/// at 6 digits and more (measured: a move of 1e-6 gives 1.0e-6).
#[test]
fn the_orbit_sees_a_wrong_shape_and_not_a_phase() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let (base, _) = own(&r);
    let k0 = r
        .samples
        .partition_point(|s| s.t < sc.compare.steady_from.unwrap() - 1e-9);
    let mut ahead = base.clone();
    for k in k0..ahead.samples.len() {
        ahead.samples[k].x = r.samples[(k + 2).min(r.samples.len() - 1)].x;
    }
    let orbit = |rep: &CheckReport| rep.quantities.iter().find(|q| q.name == "orbit").cloned();
    let rep = grade(&sc, &r, &ahead, None, Level::Digits(8));
    assert!(orbit(&rep).unwrap().difference > 0.0);
    assert!(failing(&rep).contains(&"omega_l".to_string()));
    let o = orbit(&rep).unwrap();
    assert!(o.passed, "{}", rep.table());
    // Across: every moving steady sample moved by 2e-6 of S_l along ω_l, which is across the
    // orbit where ω_l turns (its maxima).
    let s_l = state_scales(&r.samples)[2];
    let mut across = base.clone();
    for s in &mut across.samples[k0..] {
        if s.x[2] != 0.0 {
            s.x[2] += 2e-6 * s_l;
        }
    }
    for (d, fails) in [(5, false), (6, true), (7, true)] {
        let rep = grade(&sc, &r, &across, None, Level::Digits(d));
        let o = orbit(&rep).unwrap();
        assert_eq!(!o.passed, fails, "digits={d}: {o:?}");
    }
}

/// Each reference's own files (its CSV trace and events, read as a client's) pass at the
/// highest level its stated errors allow, `--digits N` with N = ⌊verified − 1⌋ of its weakest
/// quantity (the orbit included: the reference scores exactly 0 there, its offsets being the
/// ones the orbit quantity subtracts), and N + 1 is refused as beyond the reference.
#[test]
fn each_reference_passes_at_the_highest_level_its_errors_allow() {
    let dir = fixtures().join("reference");
    for (sc, r) in all_scenarios() {
        let t = read_trace(&dir.join(format!("{}.csv", sc.name)), usize::MAX).unwrap();
        let ev = read_events(&dir.join(format!("{}.events.csv", sc.name))).unwrap();
        let rep = grade(&sc, &r, &t, Some(&ev), Level::Loose);
        let most = rep
            .quantities
            .iter()
            .filter_map(|q| {
                let err = reference_error(&r, &q.name)?;
                Some((-(err / q.scale).log10() - 1.0).floor() as u32)
            })
            .min()
            .unwrap();
        assert!(most > STRICT_DIGITS, "{}: {most}", sc.name);
        let top = grade(&sc, &r, &t, Some(&ev), Level::Digits(most));
        assert!(top.passed, "{} at digits={most}:\n{}", sc.name, top.table());
        let beyond = check(&sc, &r, &t, Some(&ev), Level::Digits(most + 1));
        assert!(
            matches!(beyond, Err(CheckError::BeyondReference { .. })),
            "{}: digits={} {beyond:?}",
            sc.name,
            most + 1
        );
    }
}

/// A client that holds a stuck disc anywhere in a band |ω| ≤ 1e-6 rad/s (a switch model, a
/// Karnopp-type law) is graded by the level's stuck threshold, `S_ω·10^−digits`: where the
/// level's sample tolerance admits 1e-6 (up to 6 digits on t1-u1.5-rest, S_l = 6.3 rad/s) its
/// stick intervals are the reference's; where it does not (7 digits and more: 6.3e-7 rad/s)
/// they fail, as its ω samples do.
///
/// Two such clients: the reference trace with every stuck ω_l = 0 replaced by a value of up
/// to 1e-6 in magnitude, either sign; and this repository's switch model at η = 1e-6, whose
/// stuck disc keeps ω = ±η.
#[test]
fn a_band_of_1e_6_passes_where_its_samples_agree_and_fails_where_not() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let s_l = state_scales(&r.samples)[2];
    let (base, ev) = own(&r);
    let mut band = base.clone();
    let mut moved = 0;
    for (k, s) in band.samples.iter_mut().enumerate() {
        if s.x[2] == 0.0 {
            s.x[2] = 1e-6 * ((k % 7) as f64 - 3.0) / 3.0;
            moved += usize::from(s.x[2] != 0.0);
        }
    }
    assert!(moved > 1000, "{moved}");
    for d in 1..=8 {
        let level = Level::Digits(d);
        let coarse_enough = stuck_threshold(s_l, level) >= 1e-6;
        let rep = grade(&sc, &r, &band, Some(&ev), level);
        let f = failing(&rep);
        if coarse_enough {
            assert!(rep.passed, "digits={d}:\n{}", rep.table());
        } else {
            assert!(
                f.contains(&"stick_lower".to_string()) && f.contains(&"omega_l".to_string()),
                "digits={d}: {f:?}"
            );
        }
        assert_eq!(coarse_enough, d <= 6, "S_l = {s_l}");
    }

    let switch = rotor_switch::SwitchSolver {
        options: rotor_switch::SwitchOptions {
            eta: 1e-6,
            ..Default::default()
        },
    };
    let tr = switch
        .simulate(&sc.model, &scene_for(SolverKind::SWITCH, &sc))
        .unwrap();
    let stuck_at_eta = tr
        .samples
        .iter()
        .filter(|s| s.x[2].abs() > 1e-9 && s.x[2].abs() <= 1e-6)
        .count();
    assert!(stuck_at_eta > 1000, "{stuck_at_eta}");
    let t = Trace::of_run("switch-eta-1e-6.csv", &tr.samples);
    let e = EventsFile::of_run("switch-eta-1e-6.events.csv", &tr.events);
    let loose = grade(&sc, &r, &t, Some(&e), Level::Loose);
    assert!(loose.passed, "{}", loose.table());
    let strict = grade(&sc, &r, &t, Some(&e), Level::Strict);
    assert!(
        failing(&strict).contains(&"stick_lower".to_string()),
        "{}",
        strict.table()
    );
}

/// Honest solvers of other kinds pass, and a converging method's digits rise with its
/// accuracy: Moreau–Jean (second order) at h = 1e-3 and 1e-4, the event-driven solver at
/// tol 1e-8 and 1e-11.
#[test]
fn digits_rise_as_a_method_converges() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let digits = |kind: SolverKind, setting: f64| {
        let scene = Scene {
            accuracy: kind.accuracy(setting),
            ..scene_for(kind, &sc)
        };
        let tr = kind.solver().simulate(&sc.model, &scene).unwrap();
        let t = Trace::of_run("run", &tr.samples);
        let e = EventsFile::of_run("run.events", &tr.events);
        grade(&sc, &r, &t, Some(&e), Level::Loose).digits
    };
    let (m3, m4) = (
        digits(SolverKind::MOREAU, 1e-3),
        digits(SolverKind::MOREAU, 1e-4),
    );
    let (e8, e11) = (
        digits(SolverKind::EVENT, 1e-8),
        digits(SolverKind::EVENT, 1e-11),
    );
    // Second order: 10× smaller h gains about 2 digits (measured 4.1 -> 6.5); at least 1.5.
    assert!(m4 - m3 >= 1.5 && m3 >= f64::from(LOOSE_DIGITS), "{m3} {m4}");
    // Tolerance proportionality: 1000× tighter gains about 3 (measured 5.9 -> 8.7); at least 2.
    assert!(
        e11 - e8 >= 2.0 && e11 >= f64::from(STRICT_DIGITS),
        "{e8} {e11}"
    );
}

/// The steady extrema are read off the grid by integrating from the sample before each
/// extremum, so they cannot be moved without moving that sample: a move of the samples
/// around the last cycle's ω_l and ω_u maxima by 2× the tolerance fails the extremum (with
/// the sample it moved), by 0.5× passes everything, at both levels.
#[test]
fn the_steady_extrema_fail_at_twice_their_tolerance_and_pass_at_half() {
    let (sc, r) = scenario("t1-u1.5-rest");
    let (base, ev) = own(&r);
    // The last cycle's largest samples of each velocity (within the last period).
    let last = |i: usize| {
        let from = r.samples.len() - 1 - (4.6 / sc.compare.dt) as usize;
        (from..r.samples.len())
            .max_by(|&a, &b| r.samples[a].x[i].total_cmp(&r.samples[b].x[i]))
            .unwrap()
    };
    for level in LEVELS {
        let reference = grade(&sc, &r, &base, Some(&ev), level);
        for (i, metric) in [(2, "steady_omega_l_max"), (1, "steady_omega_u_max")] {
            let tol = reference
                .quantities
                .iter()
                .find(|q| q.name == metric)
                .unwrap()
                .tolerance;
            let k = last(i);
            for factor in [2.0, 0.5] {
                let mut t = base.clone();
                for j in k - 2..=k + 2 {
                    t.samples[j].x[i] += factor * tol;
                }
                let rep = grade(&sc, &r, &t, Some(&ev), level);
                let f = failing(&rep);
                if factor > 1.0 {
                    assert!(f.contains(&metric.to_string()), "{metric} ×2: {f:?}");
                } else {
                    assert!(f.is_empty(), "{metric} ×0.5 at {}: {f:?}", level.name());
                }
            }
        }
    }
}
