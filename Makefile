# gonio — the only entry points a newcomer needs.
#   make demo   build, render scenes/demo.xml to out/demo.png, then check three models' physics with `gonio check` (about a minute)
#   make check-all  every example model of every plugin through the harness (`gonio check --all`, ~10 min on 2 cores)
#   make test   build, then run the Rust tests, the Python tests (incl. the Mitsuba 3 cross-checks) and the lane code's tests in the portable build
#   make bench  criterion benchmarks, and gonio vs Mitsuba 3 timings, errors and scaling tables
#   make gallery  regenerate docs/gallery/*.png and docs/gallery/README.md (the lecture's figures, < 10 min on 2 cores)
#   make fuzz   run one loader's fuzz target (TARGET=ply FUZZ_SECONDS=600; docs/fuzzing.md)
#   make fit-table  fit every `gonio fit` model to each RGL material; residuals to docs/fitting.md (by hand)

PYTHON ?= python3
VENV   := .venv
VPY    := $(VENV)/bin/python
CARGO  ?= cargo

# Every build here is for this machine's CPU: `make build`'s binary and Python extension are the fast ones
# (with AVX2 and FMA the renderer's `Float8` is one AVX register and `Real::mad` fuses; on the machines
# here that is half the time of the portable x86-64 build, 2026-12-04: Cornell box 0.35 s against 0.67 s
# of CPU at 16 spp). A build for other machines sets the CPU: `make build GONIO_CPU=x86-64-v3` (or
# `x86-64` for any x86-64 CPU), or sets RUSTFLAGS itself. The portable lane code is still tested
# (`test-portable`), and the batch drivers choose AVX2 or AVX-512 at run time in any build.
GONIO_CPU ?= native
export RUSTFLAGS ?= -C target-cpu=$(GONIO_CPU)

.PHONY: all build cli venv python demo check-all test test-portable test-rust test-python browser bench gallery fit-table fuzz fmt lint clean

all: build

build: cli python

cli:
	$(CARGO) build --release -p gonio-cli

$(VPY):
	$(PYTHON) -m venv $(VENV)

# Re-run pip only when requirements-dev.txt changes (the stamp lives inside .venv, touched only when every
# install succeeded). A venv whose python or pip no longer runs (e.g. `pip install --upgrade pip` interrupted
# halfway leaves pip unimportable) is made anew rather than failing on every `make` from then on.
$(VENV)/.requirements-stamp: requirements-dev.txt | $(VPY)
	@$(VPY) -m pip --version >/dev/null 2>&1 || { \
		echo "make: $(VENV) is broken ($(VPY) -m pip does not run; an interrupted install?): making it anew"; \
		rm -rf $(VENV) && $(PYTHON) -m venv $(VENV); }
	$(VPY) -m pip install --quiet --upgrade pip
	$(VPY) -m pip install --quiet -r requirements-dev.txt
	touch $@

venv: $(VENV)/.requirements-stamp

python: venv
	VIRTUAL_ENV=$(CURDIR)/$(VENV) PATH=$(CURDIR)/$(VENV)/bin:$$PATH \
		$(VENV)/bin/maturin develop --release --quiet -m crates/gonio-py/Cargo.toml
	$(VPY) -c "import gonio; print('gonio', gonio.__version__, 'for Python installed in $(VENV):', ', '.join(gonio.plugins()))"

# The demo: one render and a real check of three models (each a chi-square of sample against pdf at 10⁶
# samples, sample weights, reciprocity, energy, a NaN/Inf sweep), a couple of minutes in all after the build;
# `make check-all` runs the same harness on every example model of every plugin.
DEMO_MODELS := '{"type": "diffuse"}' '{"type": "roughconductor", "material": "Au", "alpha": 0.2}' '{"type": "dielectric"}'

demo: build
	@mkdir -p out
	./target/release/gonio render scenes/demo.xml -o out/demo.png --spp 64
	@echo "demo: rendered scenes/demo.xml (paper, rough gold, glass, Oren-Nayar moon, aluminium) to out/demo.png"
	@for m in $(DEMO_MODELS); do echo "./target/release/gonio check '$$m'"; ./target/release/gonio check "$$m" || exit 1; done
	@echo "demo: gonio check ran the verification harness (chi-square of sample against pdf, sample weights, reciprocity, energy conservation, NaN/Inf sweep) on three models; exit status 0 means every check passed. Every model of every plugin: make check-all"

check-all: cli
	./target/release/gonio check --all

test: build browser
	$(CARGO) test --release -p gonio -p gonio-cli
	$(VPY) -m pytest -q -rxX crates/gonio-py/tests
	$(MAKE) test-portable

# The renderer's lane code in the portable x86-64 build (no AVX2 at compile time: `Float8` is two SSE
# registers and `Pcg32x8` steps lane by lane), which the builds above do not compile on a CPU with AVX2.
# Its tests (lanes against scalar code, bit for bit) in their own target directory (about 5 minutes of
# build on 2 cores, 2026-12-05).
test-portable:
	RUSTFLAGS= CARGO_TARGET_DIR=target/portable \
		$(CARGO) test --release -p gonio --lib -- \
		math:: sampling:: geometry:: scene:: integrator:: render

test-rust:
	$(CARGO) test --release -p gonio -p gonio-cli

test-python:
	$(VPY) -m pytest -q -rxX crates/gonio-py/tests

# The explorer's browser test (crates/gonio-py/tests/test_explore_browser.py) drives Debian's Chromium with
# Playwright (requirements-dev.txt; Playwright's own browser download is not used). Best effort: where apt
# cannot install it the test skips and says so.
browser:
	-command -v chromium >/dev/null 2>&1 || (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium)

# Benchmarks, run by hand (never part of `make test`): criterion micro-benchmarks, then gonio against
# Mitsuba 3 (scalar_rgb, llvm_ad_rgb) on ../shared/scenes with the scaling tables (bench/render_vs_mitsuba.py),
# the benchmark suite (bench/suite.py: bench/scenes/, time and MSE ratios against llvm_ad_rgb, their
# geometric mean and worst scene), the variance suite (bench/variance.py: every BSDF shared with Mitsuba ×
# every light type, gonio's MSE over llvm_ad_rgb's at equal spp, worst cell, geometric mean, fireflies),
# the Python package's batched f/pdf/sample against Mitsuba's (bench/python_bsdf_vs_mitsuba.py), and
# gonio.distributed's scaling on a local two-node Ray cluster (bench/distributed.py: render and fit
# efficiency over one node, overhead per task; docs/distributed.md).
# gonio is timed as `make build` builds it (target/release/gonio, for this machine's CPU, as Mitsuba's
# llvm_ad_rgb JIT-compiles its kernels for it).
bench: cli python
	$(CARGO) bench -p gonio-bench
	GONIO_BIN=target/release/gonio $(VPY) bench/render_vs_mitsuba.py
	$(VPY) bench/suite.py --gonio target/release/gonio --json bench/.cache/suite.json
	$(VPY) bench/real_scenes.py --gonio target/release/gonio
	$(VPY) bench/variance.py --gonio target/release/gonio --json bench/.cache/variance.json
	$(VPY) bench/python_bsdf_vs_mitsuba.py
	$(VPY) bench/distributed.py

# The gallery: every picture with the command that made it (docs/gallery/make_gallery.sh; REFIT=1 re-runs
# `gonio fit` for the measured materials instead of using docs/gallery/fits/*.xml).
gallery: cli
	docs/gallery/make_gallery.sh

# The fitting residuals of every `gonio fit` model on each RGL material (by hand: minutes of CPU; writes
# docs/fitting.md through bench/fit_rgl_table.sh).
fit-table: cli
	bench/fit_rgl_table.sh

# One fuzz target for FUZZ_SECONDS (by hand, never part of `make test`; needs `cargo install cargo-fuzz`;
# stable Rust, sanitizer off): make fuzz TARGET=ply. Targets and results: docs/fuzzing.md.
TARGET       ?= xml_scene
FUZZ_SECONDS ?= 600
fuzz:
	mkdir -p fuzz/corpus-work/$(TARGET) fuzz/artifacts/$(TARGET)
	cd fuzz && nice -n 19 $(CARGO) fuzz run -s none --release $(TARGET) corpus-work/$(TARGET) seeds/$(TARGET) -- \
		-max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=artifacts/$(TARGET)/

fmt:
	$(CARGO) fmt --all

lint:
	$(CARGO) clippy --workspace --all-targets -- -D warnings

clean:
	$(CARGO) clean
	rm -rf $(VENV)
