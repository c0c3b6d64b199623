# robocal's single entry point. The two commands a new machine needs:
#   make serve   build everything and serve the web app on http://127.0.0.1:8080
#   make test    run every test tier (native, wasm in node, npm package, browser)

SHELL := /bin/bash
export PATH := $(HOME)/.cargo/bin:$(PATH)

WASM_TARGET := wasm32-unknown-unknown
WASM_FILE := target/$(WASM_TARGET)/wasm/robocal.wasm
CLI := target/release/robocal
PORT ?= 8080

.PHONY: serve test setup wasm web pkg cli test-native test-wasm test-node test-e2e check-wasm-core bench clean-web fuzz

setup:
	tools/setup.sh build

# The wasm is built in its own cargo invocation so that the native CLI's
# features never unify into it.
wasm: setup
	cargo build --lib --profile wasm --target $(WASM_TARGET) --features wasm

web: wasm
	wasm-bindgen --target web --out-dir www/pkg --out-name robocal --no-typescript --remove-name-section --remove-producers-section $(WASM_FILE)
	@tools/wasm-size.sh www/pkg/robocal_bg.wasm

cli:
	cargo build --release --bin robocal

serve: web cli
	$(CLI) serve --dir www --port $(PORT)

pkg: wasm
	rm -rf pkg
	wasm-bindgen --target nodejs --out-dir pkg/node --out-name robocal --remove-name-section --remove-producers-section $(WASM_FILE)
	wasm-bindgen --target web --out-dir pkg/web --out-name robocal --remove-name-section --remove-producers-section $(WASM_FILE)
	node tools/make-pkg.mjs
	@tools/wasm-size.sh pkg/node/robocal_bg.wasm

check-wasm-core: setup
	cargo check --lib --target $(WASM_TARGET)

test-native:
	cargo test

test-wasm: setup
	CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner cargo test --lib --target $(WASM_TARGET)

test-node: pkg cli
	tools/setup.sh node
	node tests/node/smoke.mjs

test-e2e: web cli
	tools/setup.sh e2e
	node tests/e2e/run.mjs

test: test-native check-wasm-core test-wasm test-node test-e2e
	@echo "make test: all tiers passed"

bench:
	cargo bench

# Fuzzing (not part of `make test`): every target in fuzz/ for FUZZ_S seconds,
# one after another (one fuzzer process at a time), on a seed corpus written
# into fuzz/corpus/<target>/ from fixtures/ and small renders. No sanitizer:
# the crate has no unsafe code, and panics, hangs (-timeout) and memory
# blow-ups (-rss_limit_mb) are what is looked for. A failing input lands in
# fuzz/artifacts/<target>/; it then belongs in fixtures/fuzz/<target>/
# (replayed by tests/detect/fuzz_regressions.rs). RELIABILITY.md has the record.
FUZZ_S ?= 60
FUZZ_TARGETS := image_decode detect robot_poses camera_files targets_detections calib_json handeye_json workflows
FUZZ_FLAGS := -timeout=10 -rss_limit_mb=2048 -print_final_stats=1

fuzz:
	@command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz
	cargo +nightly fuzz build -s none
	cargo run --release --manifest-path fuzz/Cargo.toml -p robocal-fuzz-seeds -- . fuzz/corpus
	for t in $(FUZZ_TARGETS); do \
		cargo +nightly fuzz run -s none $$t fuzz/corpus/$$t -- -max_total_time=$(FUZZ_S) $(FUZZ_FLAGS) || exit 1; \
	done
	@echo "make fuzz: $(FUZZ_TARGETS): no failure in $(FUZZ_S) s each"
