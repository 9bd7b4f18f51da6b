# Shortcuts; the README's two commands never need just (install: pip install rust-just).
test:
    cargo test --release --workspace
report:
    cargo run --release
# Rewrite the suite's reference data (every scenario; a few seconds). Without --out,
# `rotor reference` writes to the current directory.
reference:
    cargo run --release -- reference --out fixtures/reference
ci:
    bash .ci/run
lint:
    cargo fmt --all -- --check
    cargo clippy --workspace --all-targets --release -- -D warnings
# Numerical stress, full form (1e5 s horizon, whole tolerance and step ladders; ~25 s).
# `cargo test` runs the fast form; .ci/run runs both.
stress:
    ROTOR_STRESS=full cargo test --release -p rotor-harness -p rotor-analysis stress -- --nocapture
# Every property test with thousands of fresh draws (CI draws a fixed seed; run this before a
# change lands and keep what it finds in the *.proptest-regressions files). About 10 minutes.
proptest-long:
    PROPTEST_CASES=3000 cargo test --release -p rotor-harness --test stress stress_random
    PROPTEST_CASES=50000 cargo test --release -p rotor-moreau --test integration properties
    PROPTEST_CASES=20000 cargo test --release -p rotor-model --test fuzz_files
    PROPTEST_CASES=2000 cargo test --release -p rotor-harness --test benchmark mutated
# The whole suite's work-precision benchmark with the peers (scipy DOP853, Radau, BDF, LSODA;
# Siconos; GNU Octave; any other peer registered in crates/rotor-harness/src/bench/peers.rs, when installed) and
# the tanh-regularised and first-order clients (bench/clients/), so that the published results
# place a wrong method and an honest first-order one beside the solvers and peers:
# reports/bench/results.md (+ bench.svg, .json, .csv, .txt). 6 to 9 minutes on 2 idle cores.
bench:
    mkdir -p target && cc -O2 -o target/first_order bench/clients/first_order.c -lm
    cargo run --release -- bench --external "tanh=python3 bench/clients/tanh_regularised.py" --external "first_order:h=target/first_order" --json reports/bench/bench.json --svg reports/bench/bench.svg --csv reports/bench/bench.csv --results reports/bench/results.md > reports/bench/bench.txt
# The peer tests, failing if scipy, Siconos or Octave is missing (.ci/run installs them and runs this).
peers:
    ROTOR_REQUIRE_PEERS=1 cargo test --release -p rotor-harness --test peers
