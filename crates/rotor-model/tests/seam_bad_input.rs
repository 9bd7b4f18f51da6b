//! Bad scenes: a tolerance below roundoff and a grid that would exhaust memory are refused
//! by `Scene::validate`, with a message that names the field and its value. (Bad parameter
//! files are rotor-model's tests/bad_input.rs, bad scenario files rotor_model::scenario's.)

use rotor_model::seam::scene::{MAX_GRID_ROWS, MIN_TOL};
use rotor_model::seam::{Accuracy, Output, Scene};

#[test]
fn scene_tolerance_below_roundoff_is_refused() {
    let at = |tol| {
        Scene {
            ..Scene::with_tol(tol)
        }
        .validate()
    };
    assert!(at(1e-13).is_ok());
    assert!(at(MIN_TOL).is_ok());
    let e = at(1e-20).unwrap_err().to_string();
    assert!(e.contains("tol = 1e-20") && e.contains("roundoff"), "{e}");
}

#[test]
fn scene_grid_that_would_exhaust_memory_is_refused() {
    let ok = Scene {
        t_end: 100.0,
        output: Output::Grid {
            dt: 100.0 / MAX_GRID_ROWS,
        },
        ..Scene::default()
    };
    ok.validate().unwrap();
    let e = Scene {
        output: Output::Grid { dt: 1e-12 },
        ..ok.clone()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("dt = 1e-12") && e.contains("1e7"), "{e}");
    let e = Scene {
        t_end: 1e300,
        accuracy: Accuracy::Step(1.0),
        output: Output::Grid { dt: 1.0 },
        ..ok
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("dt = 1"), "{e}");
}
