//! Counts steps whose one-step problem was not solved exactly (Picard fallback without
//! convergence) per fixture and step size.
use rotor_model::scenario::Scenario;
use rotor_moreau::{MoreauOptions, Stepper};

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenarios");
    for h in [0.01, 0.05, 0.1, 0.25, 0.5] {
        let (mut bad, mut total) = (0u64, 0u64);
        let mut names = Vec::new();
        for p in Scenario::list_dir(&dir).unwrap() {
            let sc = Scenario::from_file(&p).unwrap();
            let st = Stepper::new(&sc.model, sc.u, &MoreauOptions::default());
            let mut x = rotor_model::State::from_column_slice(&sc.x0);
            let n = (sc.t_end / h).round() as u64;
            let mut b = 0;
            for k in 0..n {
                let o = st.step(k as f64 * h, &x, h).unwrap();
                if !o.exact {
                    b += 1;
                }
                x = o.x;
            }
            if b > 0 {
                names.push(format!("{}:{b}", sc.name));
            }
            bad += b;
            total += n;
        }
        println!("h={h}: {bad} inexact of {total} steps {names:?}");
    }
}
