# tinsmith: `make demo` meshes the bundled sample DEM and verifies it; `make test` runs
# every check CI runs. Both install the system packages they need first (Debian).

SHELL := /bin/bash
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
DEMO_DEM := data/becmodel_dem_bc_albers_50m.tif
DEMO_ERROR := 5

.PHONY: deps demo test bench-results bench-tiles

## Install Debian's GDAL (headers, tools) and pkg-config when missing.
deps:
	@if ! pkg-config --exists gdal 2>/dev/null || ! command -v ogrinfo >/dev/null; then \
	  echo "installing libgdal-dev gdal-bin pkg-config"; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends \
	    libgdal-dev gdal-bin pkg-config build-essential ca-certificates curl; \
	fi
	@command -v cargo >/dev/null || { echo "Rust is missing: install it from https://rustup.rs"; exit 1; }

## Mesh the sample DEM at $(DEMO_ERROR) m, then prove the bound with the verifier.
demo: deps
	cargo build --release --quiet
	mkdir -p out
	target/release/tinsmith info $(DEMO_DEM)
	target/release/tinsmith mesh $(DEMO_DEM) --max-error $(DEMO_ERROR) -o out/demo.ply --report out/demo-report.json
	target/release/tinsmith verify $(DEMO_DEM) out/demo.ply --max-error $(DEMO_ERROR)

## Format, lints, docs and the whole test suite.
test: deps
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --quiet
	cargo test --workspace

## Regenerate docs/results.md's decimation table from ../shared/data.
bench-results:
	cargo build --release --quiet
	python3 bench/paper_table.py

## Benchmark the tiled engine on a 16384^2 DEM built from ../shared/data (about an hour).
bench-tiles:
	cargo build --release --quiet
	python3 bench/tiles.py --out /tmp/tinsmith-bench/results.md
