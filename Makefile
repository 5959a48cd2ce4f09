# tinsmith: `make demo` meshes the bundled sample DEM and verifies it; `make test` runs
# every check CI runs. Both install the system packages they need first (Debian).

SHELL := /bin/bash
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
DEMO_DEM := data/becmodel_dem_bc_albers_50m.tif
DEMO_ERROR := 5
VENV := .venv
TOOLS := .tools
# trimesh and numpy read our meshes back (tests/formats.rs); moto's standalone S3 server
# and boto3 are a local S3 and an independent client (tests/object_storage.rs), and
# azure-storage-blob the client for Azurite (npm, below); Dask runs the shards of a
# pyramid (tools/dask_tiles.py, tests/dask.rs); PyYAML reads deploy/; Pillow reads the
# previews back (tests/preview.rs); maturin builds the Python package (crates/python),
# pytest runs its tests (make python-test), which hand it affine's transforms and ask it
# for shapely's lines; rasterio and rioxarray run the README's Python examples;
# laspy (with its lazrs LAZ backend) reads our point fixtures back and copclib writes
# COPC files for them (tests/points.rs).
PY_ORACLES := trimesh==4.12.2 numpy==2.2.6 moto[server]==5.2.5 boto3==1.44.5 \
  azure-storage-blob==12.27.1 dask[distributed]==2026.8.0 pyyaml==6.0.4 pillow==11.3.0 \
  maturin==1.16.0 pytest==9.2.0 affine==3.0.1 shapely==2.2.0 rasterio==1.4.4 \
  rioxarray==0.19.0 xarray==2026.9.0 pandas==3.1.1 pyproj==3.7.2 laspy[lazrs]==2.7.0 \
  copclib==2.6.3
NPM_ORACLES := gltf-validator@2.0.0-dev.3.10

.PHONY: deps gdal oracles demo pictures test python-test bench-python bench-ctb bench-results bench-contour bench-compare bench-tiles bench-shards bench-preview bench-points bench-variables

## Everything the tests need: GDAL, then the independent oracles.
deps: gdal
	@$(MAKE) --no-print-directory oracles

## Install Debian's GDAL (headers, tools) and pkg-config when missing; check for Rust.
gdal:
	@if ! pkg-config --exists gdal 2>/dev/null || ! command -v ogrinfo >/dev/null; then \
	  echo "installing libgdal-dev gdal-bin pkg-config"; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends \
	    libgdal-dev gdal-bin pkg-config build-essential ca-certificates curl; \
	fi
	@command -v cargo >/dev/null || { echo "Rust is missing: install it from https://rustup.rs"; exit 1; }

## The independent readers the format tests check our files with (tests/formats.rs):
## trimesh, moto, boto3, Dask and PyYAML in .venv (PyPI), GNU time (the Dask driver
## measures each shard with it) and the Khronos glTF validator in .tools (npm). Idempotent.
oracles: py-oracles gnu-time $(TOOLS)/node_modules/gltf-validator/package.json qm-oracles

## .venv/.ok records the PY_ORACLES installed: a venv made for another list is brought up
## to this one. Debian's python3 needs python3-venv (ensurepip) to create a venv.
.PHONY: py-oracles
py-oracles:
	@if [ "$$(cat $(VENV)/.ok 2>/dev/null)" != "$(PY_ORACLES)" ]; then \
	  if [ ! -x $(VENV)/bin/pip ]; then \
	    echo "creating $(VENV)"; \
	    python3 -m venv $(VENV) 2>/dev/null || { rm -rf $(VENV); \
	      $(SUDO) apt-get update -qq && \
	      DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends python3-venv && \
	      python3 -m venv $(VENV); } || exit 1; \
	  fi; \
	  echo "installing $(PY_ORACLES) into $(VENV)"; \
	  $(VENV)/bin/pip install --quiet --disable-pip-version-check $(foreach p,$(PY_ORACLES),'$(p)') && \
	  echo "$(PY_ORACLES)" > $(VENV)/.ok; \
	fi

## GNU time: tools/dask_tiles.py measures each shard's own process with it (tests/dask.rs).
.PHONY: gnu-time
gnu-time:
	@[ -x /usr/bin/time ] || { echo "installing time"; $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends time; }

$(TOOLS)/node_modules/gltf-validator/package.json:
	@command -v npm >/dev/null || { \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends nodejs npm; }
	mkdir -p $(TOOLS)
	npm install --prefix $(TOOLS) --no-audit --no-fund --silent $(NPM_ORACLES)

## The quantized-mesh oracles, pinned, in .tools/: the HERE quantized-mesh decoder (npm),
## CesiumJS and playwright-core (npm) with Debian's Chromium for the real-client test;
## Azurite, Microsoft's Azure Storage emulator, for the az:// tests.
## Tests that need an oracle fail (never skip) when it is missing.
ORACLES_NPM := @here/quantized-mesh-decoder@1.2.8 cesium@1.140.0 playwright-core@1.64.1 \
  azurite@3.37.0
.PHONY: qm-oracles
qm-oracles:
	@command -v npm >/dev/null || { echo "installing nodejs npm"; $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends nodejs npm; }
	@command -v chromium >/dev/null || { echo "installing chromium"; $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends chromium; }
	@if [ ! -f .tools/node_modules/@here/quantized-mesh-decoder/package.json ] || \
	    [ ! -f .tools/node_modules/cesium/Build/Cesium/Cesium.js ] || \
	    [ ! -f .tools/node_modules/playwright-core/package.json ] || \
	    [ ! -f .tools/node_modules/azurite/package.json ]; then \
	  mkdir -p .tools && npm install --silent --no-audit --no-fund --prefix .tools $(ORACLES_NPM); \
	fi

## Mesh the sample DEM at $(DEMO_ERROR) m, then prove the bound with the verifier.
demo: gdal
	cargo build --release --quiet
	mkdir -p out
	target/release/tinsmith info $(DEMO_DEM)
	target/release/tinsmith mesh $(DEMO_DEM) --max-error $(DEMO_ERROR) -o out/demo.ply --report out/demo-report.json
	target/release/tinsmith verify $(DEMO_DEM) out/demo.ply --max-error $(DEMO_ERROR)

## The docs' pictures: the README's (the demo DEM's TIN at 20 m over its hillshade), and
## tinsmith's TIN beside hmm's on two DEMs of ../shared (docs/results.md, "Pictures").
pictures: deps
	cargo build --release --quiet
	mkdir -p out docs/images
	target/release/tinsmith mesh $(DEMO_DEM) --max-error 20 -o out/picture.ply -q
	target/release/tinsmith preview $(DEMO_DEM) out/picture.ply -o docs/images/demo-tin.png --size 640
	$(VENV)/bin/pip install --quiet --disable-pip-version-check pydelatin rasterio
	$(VENV)/bin/python bench/pictures.py --shared ../shared

## Format, lints, docs and the whole test suite. The tests that read our files back with
## the oracles `make deps` installs are #[ignore]d, so that a bare `cargo test` passes with
## only GDAL; `--include-ignored` runs them here, and a missing oracle fails them.
test: deps
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --quiet
	cargo test --workspace -- --include-ignored
	@$(MAKE) --no-print-directory python-test
	@$(MAKE) --no-print-directory fuzz-smoke

## The Python package (crates/python, docs/python.md): built from this tree into .venv
## (maturin, through pip), then its pytest suite and docstring examples; the tests compare
## files with the release CLI's (built here) and read them back with trimesh and ogr2ogr.
.PHONY: python-test python-package
python-test: gdal python-package
	cargo build --release --quiet --bin tinsmith
	$(VENV)/bin/python -m pytest -q -p no:cacheprovider crates/python/tests

## The Python package built from this tree (release) and installed into .venv.
python-package: py-oracles
	PATH="$(abspath $(VENV))/bin:$$PATH" $(VENV)/bin/pip install --quiet \
	  --disable-pip-version-check --no-build-isolation --no-deps --force-reinstall ./crates/python

## The fuzz targets (fuzz/, docs/fuzzing.md) build, and each runs for a few seconds from its
## seeds without a finding. Installs the nightly toolchain (minimal) and cargo-fuzz when
## missing. The fuzz crate is its own workspace, built in fuzz/target, unoptimized
## (`--dev`: 39 s from nothing here, where the optimized fuzzing build takes minutes).
FUZZ_SMOKE_SECONDS := 3
CARGO_FUZZ_VERSION := 0.13.2
.PHONY: fuzz-tools fuzz-smoke
fuzz-tools:
	@rustup toolchain list | grep -q '^nightly' || rustup toolchain install nightly --profile minimal
	@cargo fuzz --version >/dev/null 2>&1 || cargo install cargo-fuzz --locked --version $(CARGO_FUZZ_VERSION)

fuzz-smoke: fuzz-tools
	cargo fmt --manifest-path fuzz/Cargo.toml --check
	env -u CARGO_TARGET_DIR cargo +nightly fuzz build --dev
	@smoke=$$(mktemp -d) && trap 'rm -rf "$$smoke"' EXIT && \
	  fuzz/seed.sh "$$smoke" >/dev/null && \
	  for target in $$(cargo +nightly fuzz list); do \
	    if env -u CARGO_TARGET_DIR cargo +nightly fuzz run --dev $$target "$$smoke/$$target" -- \
	        -max_total_time=$(FUZZ_SMOKE_SECONDS) -timeout=10 >"$$smoke/$$target.log" 2>&1; then \
	      echo "fuzz smoke: $$target: $$(grep -E '^Done' "$$smoke/$$target.log")"; \
	    else \
	      tail -n 40 "$$smoke/$$target.log"; echo "fuzz smoke: $$target failed"; exit 1; \
	    fi; \
	  done

## Regenerate docs/results.md's decimation table from ../shared/data.
bench-results:
	cargo build --release --quiet
	python3 bench/paper_table.py

## Contours on the TIN vs gdal_contour on the full grid (docs/results.md, "Contours").
bench-contour: deps
	cargo build --release --quiet
	python3 bench/contour_compare.py --shared ../shared

## tinsmith vs hmm (pydelatin) on real DEMs, both verified (docs/results.md, "tinsmith vs hmm").
bench-compare: deps
	cargo build --release --quiet
	$(VENV)/bin/pip install --quiet --disable-pip-version-check pydelatin rasterio
	$(VENV)/bin/python bench/compare.py --shared ../shared

## Several variables over one mesh (`mesh --bands`): the heart's 16 MR frames and the
## CODEM pair, decimation and time against the single-band meshes and the bands'
## correlation (docs/results.md, "Several variables over one mesh"; a few minutes).
bench-variables: deps
	cargo build --release --quiet
	$(VENV)/bin/python bench/variables.py --shared ../shared --repeat 7

## tinsmith.mesh vs pydelatin in one Python process, one thread each, on the DEMs of
## bench-compare: triangles, seconds, errors, peak memory, and the binding's per-call
## overhead (docs/results.md, "Python package"; about 5 minutes).
bench-python: python-package
	$(VENV)/bin/pip install --quiet --disable-pip-version-check pydelatin==0.4.0 rasterio
	$(VENV)/bin/python bench/python_vs_pydelatin.py --shared ../shared

## Terrain pyramids against ctb's quantized-mesh fork, built from a checkout you give:
## make bench-ctb CTB=~/src/cesium-terrain-builder (bench/README-ctb.md; about 3 minutes).
bench-ctb:
	@test -n "$(CTB)" || { echo "give CTB=PATH, a checkout of ctb's quantized-mesh fork (bench/README-ctb.md)"; exit 2; }
	cargo build --release --quiet
	python3 bench/pyramid_vs_ctb.py --ctb "$(CTB)" --shared ../shared

## Benchmark the tiled engine on a 16384^2 DEM built from ../shared/data (about an hour).
bench-tiles:
	cargo build --release --quiet
	python3 bench/tiles.py --out /tmp/tinsmith-bench/results.md

## Peak memory of `preview` on rasters up to 16384^2 (docs/results.md, "Pictures"; about
## 15 minutes, most of it meshing). Work files in /tmp/tinsmith-preview.
bench-preview:
	cargo build --release --quiet
	python3 bench/preview_memory.py --shared ../shared --out /tmp/tinsmith-preview/results.md

## Point input: points/s and bytes per point for read, triangulate and decimate on the
## LAS/LAZ files of ../shared/data/points and 1 M points sampled from a DEM, and triangles
## kept against the full Delaunay (docs/results.md, "Points"; about a minute).
bench-points: py-oracles
	cargo build --release --quiet
	$(VENV)/bin/pip install --quiet --disable-pip-version-check pydelatin==0.4.0 scipy rasterio
	$(VENV)/bin/python bench/points.py --shared ../shared

## Sharded pyramids: ETOPO5 and a 16384 x 8192 resample in one process vs 4 shards on a
## Dask LocalCluster, and 1000 shards of a planet-size VRT (docs/results.md, "Sharded
## pyramids"; about 20 minutes). Work files in /tmp/tinsmith-shards.
bench-shards: deps
	cargo build --release --quiet
	$(VENV)/bin/python bench/shards.py --shared ../shared --out /tmp/tinsmith-shards/results.md
