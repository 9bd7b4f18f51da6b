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
