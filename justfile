# Shortcuts; the README's two commands never need just (install: pip install rust-just).
test:
    cargo test --release --workspace
report:
    cargo run --release
ci:
    bash .ci/run
lint:
    cargo fmt --all -- --check
    cargo clippy --workspace --all-targets --release -- -D warnings
# Numerical stress, full form (1e5 s horizon, whole tolerance and step ladders; minutes).
# CI runs the fast form as part of `cargo test`.
stress:
    ROTOR_STRESS=full cargo test --release -p rotor-compare stress -- --nocapture
# The random stress case with 3000 draws instead of 24 (about a minute).
proptest-long:
    PROPTEST_CASES=3000 cargo test --release -p rotor-compare --test stress stress_random
# Work-precision benchmark with peers (scipy, Siconos when installed), into reports/bench/.
bench:
    cargo run --release -- bench --json reports/bench/bench.json --svg reports/bench/bench.svg --csv reports/bench/bench.csv
# The peer tests, failing if scipy or Siconos is missing (CI has neither: it skips them).
peers:
    ROTOR_REQUIRE_PEERS=1 cargo test --release -p rotor-bench --test peers
